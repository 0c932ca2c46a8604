//! End-to-end tests of the `ccpp` binary.
#![allow(clippy::unwrap_used)]

use std::path::{Path, PathBuf};

use assert_cmd::Command;

use crate::common::{ccpp, data, read_json, shared_maps};

#[test]
fn planners_lists_random_bounce() {
    let out = ccpp()
        .arg("planners")
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let s = String::from_utf8(out).unwrap();
    assert!(s.lines().any(|l| l.starts_with("random-bounce")), "{s}");
}

/// `planners --defaults` prints a `--config` file of every option at its default: each
/// planner run with it writes the same path as without; naming planners keeps their sections
/// only; an unknown name is refused.
#[test]
fn planners_defaults_is_a_config_of_the_defaults() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let all = ccpp()
        .args(["planners", "--defaults"])
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let text = String::from_utf8(all).unwrap();
    let cfg = d.join("defaults.yaml");
    std::fs::write(&cfg, &text).unwrap();
    let map = crate::common::pillars(d);
    let planners = ccpp_core::planners::CATALOG;
    assert_eq!(planners.len(), 8);
    for p in planners {
        let section = format!("\n{}:\n", p.name.replace('-', "_"));
        assert!(text.contains(&section), "{section} in {text}");
        let plain = crate::common::run_ok(d, &format!("{}-plain", p.name), &map, p.name, &[]);
        let with = crate::common::run_ok(
            d,
            &format!("{}-cfg", p.name),
            &map,
            p.name,
            &["--config", cfg.to_str().unwrap()],
        );
        assert_eq!(
            std::fs::read(plain.join("path.csv")).unwrap(),
            std::fs::read(with.join("path.csv")).unwrap(),
            "{}",
            p.name
        );
    }
    assert!(text.contains("plans_at_a_time: null"), "{text}");
    // The file gives every option, at its default: a flag of another value beside it would
    // replace the file's value without a word (it did), so the pair is refused; a flag of the
    // same value agrees.
    for (planner, flag, clashing, agreeing, field) in [
        ("random-bounce", "--seed", "5", "0", "random_bounce.seed: 0"),
        (
            "ba-star",
            "--smoothing",
            "off",
            "on",
            "ba_star.smoothing: true",
        ),
        ("bsa", "--side", "right", "left", "bsa.side: left"),
        (
            "ba-star",
            "--tile-side",
            "0.4",
            "",
            "ba_star.tile_side_m: null",
        ),
        (
            "rect-boustrophedon",
            "--length",
            "0.5",
            "",
            "rect_boustrophedon.length_m: null",
        ),
        ("bsa-bfs", "--exec", "ideal", "pid", "bsa_bfs.exec"),
    ] {
        let out = d.join("clash");
        let a = ccpp()
            .args(["run", "--planner", planner, "--map", map.to_str().unwrap()])
            .args(["--config", cfg.to_str().unwrap(), flag, clashing, "--out"])
            .arg(&out)
            .assert()
            .code(1);
        let err = String::from_utf8_lossy(&a.get_output().stderr).into_owned();
        assert!(
            err.contains(field) && err.contains("defaults.yaml"),
            "{planner} {flag}: {err}"
        );
        assert!(!out.exists());
        if !agreeing.is_empty() {
            crate::common::run_ok(
                d,
                &format!("{planner}-agree"),
                &map,
                planner,
                &["--config", cfg.to_str().unwrap(), flag, agreeing],
            );
        }
    }
    let some = ccpp()
        .args(["planners", "--defaults", "bcd,bsa-bfs"])
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let some = String::from_utf8(some).unwrap();
    let sections: Vec<&str> = some
        .lines()
        .filter(|l| !l.starts_with([' ', '#']))
        .collect();
    // In the catalogue's order.
    assert_eq!(sections, ["bsa_bfs:", "bcd:"], "{some}");
    let bad = ccpp()
        .args(["planners", "--defaults", "bcd,zigzag"])
        .assert()
        .code(1);
    let err = String::from_utf8_lossy(&bad.get_output().stderr).into_owned();
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.starts_with("error: ") && err.contains("zigzag"),
        "{err}"
    );
    // `all` is `--defaults` alone; an empty name names nothing (it printed every planner).
    let every = |args: &[&str]| {
        String::from_utf8(
            ccpp()
                .args(args)
                .assert()
                .success()
                .get_output()
                .stdout
                .clone(),
        )
        .unwrap()
    };
    assert_eq!(
        every(&["planners", "--defaults", "all"]),
        every(&["planners", "--defaults"])
    );
    for empty in ["", "bcd,", ",bcd"] {
        let bad = ccpp()
            .args(["planners", "--defaults", empty])
            .assert()
            .code(1);
        let err = String::from_utf8_lossy(&bad.get_output().stderr).into_owned();
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains("an empty planner name"), "{empty:?}: {err}");
    }
    // `all` beside names is no planner: said so (it was `unknown planner "all"`).
    for mixed in ["all,bcd", "bcd,all"] {
        let bad = ccpp()
            .args(["planners", "--defaults", mixed])
            .assert()
            .code(1);
        let err = String::from_utf8_lossy(&bad.get_output().stderr).into_owned();
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(
            err.contains("\"all\" stands alone (every planner)"),
            "{mixed:?}: {err}"
        );
    }
}

#[test]
fn demo_writes_all_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("demo");
    ccpp().args(["demo", "--out"]).arg(&out).assert().success();
    for f in ["metrics.json", "path.csv", "trace.jsonl", "coverage.png"] {
        let p = out.join(f);
        assert!(
            p.is_file() && std::fs::metadata(&p).unwrap().len() > 0,
            "{f}"
        );
    }
    let m = read_json(&out.join("metrics.json"));
    assert_eq!(m["collisions"], 0);
    assert!(m["effective_coverage"].as_f64().unwrap() > 0.5);
    let png = std::fs::read(out.join("coverage.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    // The README shows the demo's picture and GIF: they are the files the demo writes now
    // (outputs are byte-identical run to run), so a change to the planner or the drawing
    // cannot leave them stale (the clean-up's moves were drawn solid there after they became
    // dashed: README truth pass).
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/img");
    for (ours, theirs) in [
        ("coverage.png", "demo-ba-star-extended.png"),
        ("replay.gif", "demo-replay.gif"),
    ] {
        assert!(
            std::fs::read(out.join(ours)).unwrap() == std::fs::read(docs.join(theirs)).unwrap(),
            "docs/img/{theirs} is not what `ccpp demo` draws now: run `ccpp demo` and copy \
             ccpp-demo/{ours} over it"
        );
    }
    // So is the picture of the paper's BA* on the same map.
    let ba = dir.path().join("ba");
    let map = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/aws_small_house.yaml");
    ccpp()
        .args(["run", "--planner", "ba-star", "--map"])
        .arg(&map)
        .arg("--out")
        .arg(&ba)
        .assert()
        .success();
    assert!(
        std::fs::read(ba.join("coverage.png")).unwrap()
            == std::fs::read(docs.join("bench-ba-star-small-house.png")).unwrap(),
        "docs/img/bench-ba-star-small-house.png is not what `ccpp run --planner ba-star` draws \
         on the demo map now: copy that run's coverage.png over it"
    );
}

const METRIC_KEYS: [&str; 18] = [
    "planner",
    "map",
    "robot_radius_m",
    "tool_radius_m",
    "coverage_rate",
    "effective_coverage",
    "path_length_m",
    "path_ratio",
    "redundancy",
    "revisit_rate",
    "regions",
    "backtracks",
    "backtrack_length_m",
    "turns",
    "rotation_rad",
    "collisions",
    "keepout_violations",
    "wall_time_s",
];

#[test]
fn run_json_prints_exactly_the_metrics_and_is_deterministic() {
    let dir = tempfile::tempdir().unwrap();
    let run = |sub: &str| {
        let out = dir.path().join(sub);
        let o = ccpp()
            .args([
                "run",
                "--planner",
                "random-bounce",
                "--seed",
                "7",
                "--json",
                "--map",
            ])
            .arg(data("teb_empty_box.yaml"))
            .arg("--out")
            .arg(&out)
            .assert()
            .success()
            .get_output()
            .stdout
            .clone();
        (out, o)
    };
    let (a, stdout) = run("a");
    let v: serde_json::Value = serde_json::from_slice(&stdout).unwrap();
    let keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
    for k in METRIC_KEYS {
        assert!(keys.contains(&k), "missing {k}");
    }
    assert_eq!(v["map"], "teb_empty_box");
    assert_eq!(v["coverage_rate"], serde_json::Value::Null);
    let (b, _) = run("b");
    for f in ["path.csv", "trace.jsonl", "coverage.png"] {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{f}"
        );
    }
    let (mut ma, mut mb) = (
        read_json(&a.join("metrics.json")),
        read_json(&b.join("metrics.json")),
    );
    ma["wall_time_s"] = 0.into();
    mb["wall_time_s"] = 0.into();
    assert_eq!(ma, mb);
    // path.csv header and rows.
    let csv = std::fs::read_to_string(a.join("path.csv")).unwrap();
    assert!(csv.starts_with("x,y,theta\n"));
    assert!(csv.lines().count() > 10);
}

#[test]
fn info_reports_counts() {
    let o = ccpp()
        .args(["info", "--json", "--map"])
        .arg(data("teb_empty_box.yaml"))
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let v: serde_json::Value = serde_json::from_slice(&o).unwrap();
    assert_eq!(v["width_px"], 120);
    let total = v["free_px"].as_u64().unwrap()
        + v["occupied_px"].as_u64().unwrap()
        + v["unknown_px"].as_u64().unwrap();
    assert_eq!(total, 120 * 120);
    assert!(v["accessible_m2"].as_f64().unwrap() > 20.0);
    assert_eq!(v["pixels"]["mode"], "trinary");
    assert_eq!(v["pixels"]["occupied_thresh"], 0.65);
    assert_eq!(v["pixels"]["negate"], false);
}

/// A map YAML's mode reaches the classification (`info` names it): the same grey image read as
/// trinary, scale (transparent = unknown) and raw (the grey level is the occupancy in percent),
/// and `--free-thresh` overrides the YAML's.
#[test]
fn info_names_the_map_mode_the_pixels_were_read_by() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // 20 x 10 px: a border of 0 (56 px), one pixel of 100 (raw: occupied; trinary: p = 0.61,
    // unknown), one transparent white pixel, the rest white.
    let mut img = image::RgbaImage::from_pixel(20, 10, image::Rgba([255, 255, 255, 255]));
    for (x, y, p) in img.enumerate_pixels_mut() {
        if x == 0 || y == 0 || x == 19 || y == 9 {
            *p = image::Rgba([0, 0, 0, 255]);
        } else if x == 5 && y == 5 {
            *p = image::Rgba([100, 100, 100, 255]);
        } else if x == 10 && y == 5 {
            *p = image::Rgba([255, 255, 255, 0]);
        }
    }
    img.save(d.join("m.png")).unwrap();
    let info = |mode: &str, extra: &[&str]| -> (serde_json::Value, String) {
        let y = d.join(format!("{mode}.yaml"));
        std::fs::write(
            &y,
            format!("image: m.png\nresolution: 0.05\norigin: [0, 0, 0]\nmode: {mode}\n"),
        )
        .unwrap();
        let run = |json: bool| {
            let mut c = ccpp();
            c.args(["info", "--map"]).arg(&y).args(extra);
            if json {
                c.arg("--json");
            }
            c.assert().success().get_output().stdout.clone()
        };
        (
            serde_json::from_slice(&run(true)).unwrap(),
            String::from_utf8(run(false)).unwrap(),
        )
    };
    let count = |v: &serde_json::Value, k: &str| v[k].as_u64().unwrap();
    let (t, text) = info("trinary", &[]);
    assert!(
        text.contains("pixels         trinary: occupied above p = 0.65, free below 0.196"),
        "{text}"
    );
    assert_eq!((count(&t, "occupied_px"), count(&t, "unknown_px")), (56, 1));
    let (s, text) = info("scale", &[]);
    assert!(text.contains("pixels         scale:"), "{text}");
    assert_eq!(s["pixels"]["mode"], "scale");
    assert_eq!((count(&s, "occupied_px"), count(&s, "unknown_px")), (56, 2));
    // Raw: 0 is free (p = 0), 100 occupied, 255 unknown.
    let (r, text) = info("raw", &[]);
    assert!(text.contains("pixels         raw:"), "{text}");
    assert_eq!(
        (
            count(&r, "free_px"),
            count(&r, "occupied_px"),
            count(&r, "unknown_px")
        ),
        (56, 1, 143)
    );
    // An override of the YAML's threshold is what the pixels were read by.
    let (o, text) = info("trinary", &["--free-thresh", "0.3"]);
    assert!(
        text.contains("occupied above p = 0.65, free below 0.3"),
        "{text}"
    );
    assert_eq!(o["pixels"]["free_thresh"], 0.3);
}

/// Runs `ccpp run` with `args`, expects failure with a one-line error containing every needle,
/// no panic and no file in the output folder.
fn expect_error(args: &[&str], map: &Path, needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let a = ccpp()
        .args(["run", "--planner", "random-bounce", "--map"])
        .arg(map)
        .arg("--out")
        .arg(&out)
        .args(args)
        .assert()
        .failure();
    let o = a.get_output();
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    assert!(err.starts_with("error: "), "{err}");
    for n in needles {
        assert!(err.contains(n), "{err:?} should contain {n:?}");
    }
    assert!(
        !out.exists() || std::fs::read_dir(&out).unwrap().next().is_none(),
        "partial output"
    );
    assert!(o.stdout.is_empty());
}

#[test]
fn bad_inputs_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let good = data("teb_empty_box.yaml");
    let gs = good.to_str().unwrap();
    let _ = gs;

    // Missing file.
    expect_error(&[], &d.join("nope.yaml"), &["nope.yaml"]);

    // YAML missing resolution.
    std::fs::copy(data("teb_empty_box.png"), d.join("teb_empty_box.png")).unwrap();
    let y = d.join("nores.yaml");
    std::fs::write(&y, "image: teb_empty_box.png\norigin: [0, 0, 0]\n").unwrap();
    expect_error(&[], &y, &["nores.yaml", "resolution"]);

    // Image named in the YAML absent.
    let y = d.join("noimg.yaml");
    std::fs::write(
        &y,
        "image: missing.png\nresolution: 0.05\norigin: [0, 0, 0]\n",
    )
    .unwrap();
    expect_error(&[], &y, &["noimg.yaml", "missing.png"]);

    // Corrupt PNG.
    let p = d.join("corrupt.png");
    std::fs::write(&p, b"\x89PNG\r\n\x1a\nthis is not a png").unwrap();
    expect_error(&[], &p, &["corrupt.png"]);

    // Malformed YAML.
    let y = d.join("bad.yaml");
    std::fs::write(&y, "image: [unclosed\nresolution: 0.05\n").unwrap();
    expect_error(&[], &y, &["bad.yaml"]);

    // Start in an obstacle (the wall at the west edge), start outside the map.
    expect_error(
        &["--start", "-2.98,0"],
        &good,
        &["teb_empty_box.yaml", "obstacle"],
    );
    expect_error(
        &["--start", "10,0"],
        &good,
        &["teb_empty_box.yaml", "outside"],
    );

    // Radius <= 0 or NaN, tool radius larger than the robot.
    expect_error(&["--radius", "0"], &good, &["radius"]);
    expect_error(&["--radius", "-0.2"], &good, &["radius"]);
    expect_error(&["--radius", "NaN"], &good, &["radius"]);
    expect_error(
        &["--radius", "0.1", "--tool-radius", "0.2"],
        &good,
        &["tool radius"],
    );

    // Robot wider than the map, and robot larger than every free space.
    expect_error(
        &["--radius", "4"],
        &good,
        &["teb_empty_box.yaml", "larger than the map", "fits nowhere"],
    );
    expect_error(
        &["--radius", "2.9"],
        &good,
        &["teb_empty_box.yaml", "does not fit"],
    );

    // Negative inflation, unknown planner.
    expect_error(&["--inflate", "-1"], &good, &["--inflate"]);
    let dir2 = tempfile::tempdir().unwrap();
    let a = ccpp()
        .args(["run", "--planner", "nope", "--map"])
        .arg(&good)
        .arg("--out")
        .arg(dir2.path().join("o"))
        .assert()
        .failure();
    assert!(String::from_utf8_lossy(&a.get_output().stderr).contains("unknown planner"));
}

/// Runs `planner` on every shared map (default start, r = 0.15 m) and returns the metrics.
fn run_on_shared_maps(planner: &str) -> Vec<(String, serde_json::Value)> {
    run_on_shared_maps_with(planner, &[])
}

/// As [`run_on_shared_maps`] with extra arguments.
fn run_on_shared_maps_with(planner: &str, extra: &[&str]) -> Vec<(String, serde_json::Value)> {
    let Some(maps) = shared_maps() else {
        eprintln!("shared maps not found; skipping");
        return Vec::new();
    };
    let mut yamls: Vec<PathBuf> = std::fs::read_dir(&maps)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    yamls.sort();
    assert_eq!(yamls.len(), 14);
    let dir = tempfile::tempdir().unwrap();
    let mut out = Vec::new();
    for y in yamls {
        let name = y.file_stem().unwrap().to_string_lossy().into_owned();
        let o = ccpp()
            .args([
                "run",
                "--radius",
                "0.15",
                "--json",
                "--planner",
                planner,
                "--map",
            ])
            .arg(&y)
            .args(extra)
            .arg("--out")
            .arg(dir.path().join(&name))
            .assert()
            .success()
            .get_output()
            .stdout
            .clone();
        out.push((name, serde_json::from_slice(&o).unwrap()));
    }
    out
}

#[test]
fn random_bounce_on_every_shared_map_is_collision_free() {
    for (name, v) in run_on_shared_maps("random-bounce") {
        assert_eq!(v["collisions"], 0, "{name}");
        assert!(v["effective_coverage"].as_f64().unwrap() > 0.3, "{name}");
    }
}

#[test]
fn ba_star_on_every_shared_map_covers_every_reachable_tile() {
    for (name, v) in run_on_shared_maps("ba-star") {
        assert_eq!(v["collisions"], 0, "{name}");
        assert_eq!(v["coverage_rate"], 1.0, "{name}");
        assert_eq!(
            v["regions"].as_u64().unwrap(),
            v["backtracks"].as_u64().unwrap() + 1,
            "{name}"
        );
    }
}

#[test]
fn bsa_basic_and_extended_on_every_shared_map() {
    let basic = run_on_shared_maps("bsa");
    let extended = run_on_shared_maps("bsa-extended");
    let mut revisit = 0.0;
    for ((name, b), (_, e)) in basic.iter().zip(&extended) {
        assert_eq!(b["collisions"], 0, "bsa {name}");
        assert_eq!(b["coverage_rate"], 1.0, "bsa {name}");
        assert_eq!(e["collisions"], 0, "bsa-extended {name}");
        let (eb, ee) = (
            b["effective_coverage"].as_f64().unwrap(),
            e["effective_coverage"].as_f64().unwrap(),
        );
        // Every shared map has obstacles: extended must do strictly better.
        assert!(ee > eb, "{name}: extended {ee} <= basic {eb}");
        assert!(ee >= 0.97, "{name}: extended effective coverage {ee}");
        revisit += b["revisit_rate"].as_f64().unwrap();
    }
    if !basic.is_empty() {
        eprintln!(
            "bsa mean revisit_rate {:.3} (paper: 0.23)",
            revisit / basic.len() as f64
        );
    }
}

#[test]
fn bsa_bfs_and_rect_boustrophedon_on_every_shared_map() {
    for (name, v) in run_on_shared_maps("bsa-bfs") {
        assert_eq!(v["collisions"], 0, "bsa-bfs {name}");
        assert_eq!(v["coverage_rate"], 1.0, "bsa-bfs {name}");
        assert!(
            v["tracking_error_max_m"].is_number(),
            "bsa-bfs {name}: PID tracking error reported"
        );
    }
    for (name, v) in
        run_on_shared_maps_with("rect-boustrophedon", &["--length", "0.3", "--width", "0.3"])
    {
        assert_eq!(v["collisions"], 0, "rect-boustrophedon {name}");
        assert!(v["rect_guarantee"].as_f64().unwrap() > 0.99, "{name}");
    }
}

/// `ccpp waypoints` writes positions as the exports do, to the nanometre: `0.425`, not the
/// `0.42500000000000004` of the pixel-to-map arithmetic.
#[test]
fn waypoints_carry_no_rounding_noise() {
    let dir = tempfile::tempdir().unwrap();
    let map = crate::common::pillars(dir.path());
    for format in ["csv", "json"] {
        let o = ccpp()
            .args(["waypoints", "--radius", "0.21", "--format", format, "--map"])
            .arg(&map)
            .assert()
            .success()
            .get_output()
            .stdout
            .clone();
        let text = String::from_utf8(o).unwrap();
        let numbers: Vec<&str> = text
            .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'e'))
            .filter(|t| t.contains('.'))
            .collect();
        assert!(numbers.len() > 20, "{text}");
        for n in numbers {
            let decimals = n.split('.').nth(1).unwrap_or("");
            assert!(decimals.len() <= 9, "{format}: {n}");
        }
    }
}

#[test]
fn waypoints_follow_the_seed_001_example() {
    // A 3 x 2 m free room; the seed's area (0,0)-(1.1,0.5) with B = 0.1 inside it.
    let dir = tempfile::tempdir().unwrap();
    let mut img = image::GrayImage::from_pixel(60, 40, image::Luma([254]));
    for (x, y, p) in img.enumerate_pixels_mut() {
        if x == 0 || y == 0 || x == 59 || y == 39 {
            *p = image::Luma([0]);
        }
    }
    let map = dir.path().join("room.png");
    img.save(&map).unwrap();
    let o = ccpp()
        .args([
            "waypoints",
            "--length",
            "0.1",
            "--width",
            "0.1",
            "--area",
            "0.5,0.5,1.6,1.0",
            "--format",
            "json",
            "--map",
        ])
        .arg(&map)
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let v: serde_json::Value = serde_json::from_slice(&o).unwrap();
    let pts = v["waypoints"].as_array().unwrap();
    let mut ys: Vec<f64> = pts.iter().map(|p| p[1].as_f64().unwrap()).collect();
    ys.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    // Six lanes 0.1 apart, the last one clamped to the top edge.
    assert_eq!(ys.len(), 6, "{ys:?}");
    for (k, y) in ys.iter().enumerate() {
        assert!((y - (0.5 + 0.1 * k as f64)).abs() < 1e-9, "{ys:?}");
    }
    assert!((ys[5] - 1.0).abs() < 1e-9);
    assert_eq!(
        (v["length_m"].as_f64(), v["width_m"].as_f64()),
        (Some(0.1), Some(0.1))
    );
    // Left out, they are the robot's diameter, and the JSON says so (it said `null`).
    let o = ccpp()
        .args(["waypoints", "--radius", "0.06", "--format", "json", "--map"])
        .arg(&map)
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let d: serde_json::Value = serde_json::from_slice(&o).unwrap();
    assert_eq!(
        (d["length_m"].as_f64(), d["width_m"].as_f64()),
        (Some(0.12), Some(0.12))
    );
    let csv = ccpp()
        .args([
            "waypoints",
            "--length",
            "0.1",
            "--width",
            "0.1",
            "--area",
            "0.5,0.5,1.6,1.0",
            "--map",
        ])
        .arg(&map)
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let csv = String::from_utf8(csv).unwrap();
    assert!(csv.starts_with("x,y\n"));
    assert_eq!(csv.lines().count(), pts.len() + 1);
}

#[test]
fn bcd_on_every_shared_map_covers_95_percent() {
    for (name, v) in run_on_shared_maps("bcd") {
        assert_eq!(v["collisions"], 0, "{name}");
        let e = v["effective_coverage"].as_f64().unwrap();
        assert!(e >= 0.95, "{name}: effective coverage {e}");
        assert!(v["regions"].as_u64().unwrap() >= 1, "{name}");
    }
}

#[test]
fn small_bench_writes_csv_md_and_plots_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let maps = dir.path().join("maps");
    std::fs::create_dir_all(&maps).unwrap();
    for f in ["teb_empty_box.yaml", "teb_empty_box.png"] {
        std::fs::copy(data(f), maps.join(f)).unwrap();
    }
    // A second, smaller map: a bare image (0.05 m/px) with a block in a room.
    let mut img = image::GrayImage::from_pixel(60, 40, image::Luma([254]));
    for (x, y, p) in img.enumerate_pixels_mut() {
        if x == 0 || y == 0 || x == 59 || y == 39 || (25..35).contains(&x) && (15..25).contains(&y)
        {
            *p = image::Luma([0]);
        }
    }
    img.save(maps.join("block_room.png")).unwrap();
    // A broken map must become a failure row, not abort the bench.
    std::fs::write(
        maps.join("broken.yaml"),
        "image: none.png\nresolution: 0.05\norigin: [0,0,0]\n",
    )
    .unwrap();
    let out = dir.path().join("bench");
    let bench = |force: bool| {
        let mut c = ccpp();
        c.args([
            "bench",
            "--quiet",
            "--planners",
            "random-bounce,bcd",
            "--maps",
        ])
        .arg(maps.join("teb_empty_box.yaml"))
        .arg(maps.join("block_room.png"))
        .arg(maps.join("broken.yaml"))
        .arg("--out")
        .arg(&out);
        if force {
            c.arg("--force");
        }
        // The broken map's runs fail, so the bench exits 1 after writing every result.
        c.assert().code(1);
    };
    bench(false);
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    let header: Vec<&str> = lines[0].split(',').collect();
    for k in [
        "map",
        "planner",
        "status",
        "error",
        "effective_coverage",
        "path_ratio",
        "regions",
        "revisit_rate",
        "turns",
        "wall_time_s",
    ] {
        assert!(header.contains(&k), "column {k} in {header:?}");
    }
    assert_eq!(lines.len(), 1 + 3 * 2, "{csv}");
    let ok_rows = lines[1..].iter().filter(|l| l.contains(",ok,")).count();
    let err_rows = lines[1..].iter().filter(|l| l.contains(",error,")).count();
    assert_eq!((ok_rows, err_rows), (4, 2), "{csv}");
    // Every row has as many fields as the header (quoted fields contain no newline).
    for l in &lines[1..] {
        if l.contains(",ok,") {
            assert_eq!(l.split(',').count(), header.len(), "{l}");
        }
    }
    let md = std::fs::read_to_string(out.join("results.md")).unwrap();
    assert!(md.contains("## Summary") && md.contains("## block_room") && md.contains("| bcd |"));
    for f in [
        "summary.svg",
        "summary.png",
        "coverage_block_room.svg",
        "coverage_block_room.png",
        "paths_teb_empty_box.png",
        "tradeoff_summary.svg",
        "tradeoff_summary.png",
        "tradeoff_block_room.svg",
        "tradeoff_teb_empty_box.png",
    ] {
        assert!(out.join("plots").join(f).is_file(), "{f}");
    }
    let svg = std::fs::read_to_string(out.join("plots/summary.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    // The trade-off summary: both planners as labelled points, the better corner marked; no
    // trade-off chart for the broken map, and no temporary file left behind.
    let svg = std::fs::read_to_string(out.join("plots/tradeoff_summary.svg")).unwrap();
    for p in ["random-bounce", "bcd"] {
        assert!(svg.contains(&format!(">{p}</text>")), "{p}");
    }
    assert!(svg.contains(">better corner:</text>") && svg.contains(">mean over maps</text>"));
    assert!(!out.join("plots/tradeoff_broken.svg").exists());
    for e in std::fs::read_dir(out.join("plots")).unwrap() {
        let path = e.unwrap().path();
        let ext = path.extension().and_then(|x| x.to_str());
        assert!(matches!(ext, Some("svg" | "png")), "{}", path.display());
    }
    // Resuming skips finished runs: their trace files are left untouched.
    let trace = out.join("runs/block_room/bcd/trace.jsonl");
    let before = std::fs::metadata(&trace).unwrap().modified().unwrap();
    std::thread::sleep(std::time::Duration::from_millis(20));
    bench(false);
    assert_eq!(
        std::fs::metadata(&trace).unwrap().modified().unwrap(),
        before
    );
    bench(true);
    assert_ne!(
        std::fs::metadata(&trace).unwrap().modified().unwrap(),
        before
    );
}

#[test]
fn replay_page_works_in_headless_chromium() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    ccpp()
        .args(["run", "--planner", "bcd", "--replay", "--map"])
        .arg(data("teb_empty_box.yaml"))
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    let html = std::fs::read_to_string(out.join("replay.html")).unwrap();
    // Self-contained: no network or external file reference.
    for bad in ["http://", "https://", "src=\"/", "<link"] {
        assert!(!html.contains(bad), "replay.html references {bad}");
    }
    let gif = std::fs::read(out.join("replay.gif")).unwrap();
    assert_eq!(&gif[..6], b"GIF89a");
    // `ccpp replay DIR` rebuilds the same page from the run folder.
    std::fs::remove_file(out.join("replay.html")).unwrap();
    ccpp().arg("replay").arg(&out).assert().success();
    assert_eq!(
        std::fs::read_to_string(out.join("replay.html")).unwrap(),
        html
    );

    let Some(chrome) = crate::common::require_chromium() else {
        return;
    };
    let url = format!("file://{}", out.join("replay.html").display());
    let profile = tempfile::tempdir().unwrap();
    let base = || {
        let mut c = crate::common::headless(&chrome, profile.path());
        c.arg("--virtual-time-budget=5000");
        c
    };
    let mut c = base();
    let o = crate::common::output_within_limit(c.arg("--dump-dom").arg(format!("{url}#selftest")));
    let dom = String::from_utf8_lossy(&o.stdout);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        dom.contains("SELFTEST PASS"),
        "self test failed: {}",
        dom.lines()
            .find(|l| l.contains("SELFTEST"))
            .unwrap_or("no result")
    );
    for l in err.lines() {
        let l = l.to_ascii_lowercase();
        assert!(
            !(l.contains("console") && (l.contains("error") || l.contains("uncaught"))),
            "console error: {l}"
        );
    }
    // `#at=F` shows the robot at that fraction of the distance, under way inside a move (it
    // snapped back to the last pose before: 0.0 m at `#at=0.01` of a run whose first move was
    // longer than that).
    for f in [0.013, 0.37] {
        let mut c = base();
        let o =
            crate::common::output_within_limit(c.arg("--dump-dom").arg(format!("{url}#at={f}")));
        let dom = String::from_utf8_lossy(&o.stdout);
        let key = "id=\"now-dist\">";
        let at = dom.find(key).expect("the distance readout") + key.len();
        let text = &dom[at..at + dom[at..].find('<').unwrap()];
        let (shown, total) = text.trim_end_matches(" m").split_once(" / ").unwrap();
        let num = |t: &str| t.replace(',', "").parse::<f64>().unwrap();
        let (shown, total) = (num(shown), num(total));
        assert!(
            (shown - f * total).abs() <= 0.051 + 0.0005 * total,
            "#at={f}: shows {text}"
        );
    }
    // At the last frame "Now" reads the run's own coverage, as "Whole run" does (it read
    // 99.9 % beside 100.0 %: the curve's samples and distances are rounded apart).
    let mut c = base();
    let o =
        crate::common::output_within_limit(c.arg("--dump-dom").arg(format!("{url}#frame=last")));
    let dom = String::from_utf8_lossy(&o.stdout);
    let text_after = |key: &str| {
        let at = dom.find(key).unwrap_or_else(|| panic!("{key}")) + key.len();
        let rest = &dom[at..];
        let open = rest.find('>').unwrap() + 1;
        rest[open..open + rest[open..].find('<').unwrap()].to_string()
    };
    assert_eq!(
        text_after("id=\"now-cov\""),
        text_after("id=\"m-effective_coverage\"")
    );
    // Screenshot of the last frame, kept as a test artefact.
    let shot = Path::new(env!("CARGO_TARGET_TMPDIR")).join("replay-last-frame.png");
    let mut c = base();
    let o = crate::common::output_within_limit(
        c.arg("--window-size=1300,900")
            .arg(format!("--screenshot={}", shot.display()))
            .arg(format!("{url}#frame=last")),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let img = image::open(&shot).unwrap().to_rgb8();
    let swept = img
        .pixels()
        .filter(|p| {
            (i32::from(p[0]) - 120).abs() < 20
                && (i32::from(p[1]) - 190).abs() < 20
                && (i32::from(p[2]) - 245).abs() < 20
        })
        .count();
    assert!(
        swept > 10_000,
        "the last frame shows only {swept} swept-colour pixels ({})",
        shot.display()
    );
    eprintln!("screenshot kept at {}", shot.display());
}

#[test]
fn ba_star_extended_options_from_a_config_file() {
    let dir = tempfile::tempdir().unwrap();
    let run = |sub: &str, config: Option<&str>| {
        let mut cmd = ccpp();
        cmd.args(["run", "--planner", "ba-star-extended", "--json", "--map"])
            .arg(data("teb_empty_box.yaml"))
            .arg("--out")
            .arg(dir.path().join(sub));
        if let Some(text) = config {
            let path = dir.path().join(format!("{sub}.yaml"));
            std::fs::write(&path, text).unwrap();
            cmd.arg("--config").arg(path);
        }
        cmd
    };
    let metrics = |c: &mut Command| -> serde_json::Value {
        serde_json::from_slice(&c.assert().success().get_output().stdout).unwrap()
    };
    let default = metrics(&mut run("default", None));
    let lanes = metrics(&mut run(
        "lanes",
        Some("ba_star_extended: { extension: { lane_ends: true } }"),
    ));
    assert_eq!(default["collisions"], 0);
    assert_eq!(lanes["collisions"], 0);
    assert!(default["effective_coverage"].as_f64().unwrap() > 0.995);
    assert_ne!(default["path_length_m"], lanes["path_length_m"]);
    // The BA* section of the planner's options reaches the backbone.
    let raw = metrics(&mut run(
        "raw",
        Some("ba_star_extended: { ba_star: { tile_side_m: 0.4 } }"),
    ));
    assert_ne!(default["path_length_m"], raw["path_length_m"]);
    // Unknown fields are refused with one line.
    let out = run("bad", Some("ba_star_extended: { extension: { reach: 2 } }"))
        .assert()
        .failure()
        .code(1)
        .get_output()
        .stderr
        .clone();
    let err = String::from_utf8(out).unwrap();
    assert!(err.starts_with("error:") && err.contains("reach"), "{err}");
}
