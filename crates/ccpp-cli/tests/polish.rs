//! End-to-end checks of values that used to be validated and then lost or misreported: a
//! partial `extension` section in `--config` keeps its planner's defaults, zone errors stay one
//! short line whatever the numbers, and zones count in the memory estimate.
#![allow(clippy::unwrap_used)]

use std::path::Path;

use crate::common::{ccpp, pgm, pillars};

/// Runs `ccpp run` with `--config` holding `config`; returns (trace, run.json).
fn run_config(dir: &Path, map: &Path, planner: &str, config: &str) -> (String, serde_json::Value) {
    let n = std::fs::read_dir(dir).unwrap().count();
    let cfg = dir.join(format!("cfg{n}.yaml"));
    std::fs::write(&cfg, config).unwrap();
    let out = dir.join(format!("out{n}"));
    ccpp()
        .args(["run", "--planner", planner, "--radius", "0.15", "--map"])
        .arg(map)
        .arg("--config")
        .arg(&cfg)
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    let trace = std::fs::read_to_string(out.join("trace.jsonl")).unwrap();
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    (trace, run)
}

#[test]
fn a_partial_extension_section_keeps_the_planners_other_defaults() {
    let dir = tempfile::tempdir().unwrap();
    let map = pillars(dir.path());
    for (planner, section) in [
        ("bsa-extended", "bsa_extended"),
        ("ba-star-extended", "ba_star_extended"),
    ] {
        let cfg = |ext: &str| format!("{section}: {{ extension: {{ {ext} }} }}\n");
        let (partial, run) = run_config(dir.path(), &map, planner, &cfg("merge_segments: false"));
        let ext = &run["options"]["extension"];
        assert_eq!(ext["merge_segments"], false, "{planner}: {run}");
        // The planner's own default reach (0), not the component's (4).
        assert_eq!(ext["reach_r"], 0.0, "{planner}: {run}");
        let (explicit, _) = run_config(
            dir.path(),
            &map,
            planner,
            &cfg("merge_segments: false, reach_r: 0"),
        );
        assert!(
            partial == explicit,
            "{planner}: the omitted reach_r is not 0"
        );
        // Both fields change the run on this map, so the comparison above can fail.
        let (reach4, _) = run_config(
            dir.path(),
            &map,
            planner,
            &cfg("merge_segments: false, reach_r: 4"),
        );
        assert!(
            reach4 != partial,
            "{planner}: reach_r 4 changes nothing here"
        );
        let (merged, _) = run_config(dir.path(), &map, planner, &cfg("reach_r: 0"));
        assert!(
            merged != partial,
            "{planner}: merge_segments changes nothing"
        );
    }
}

/// `ccpp ARGS` fails with exit 1 and one short `error:` line holding every needle.
fn fails_short(args: &[&str], extra: &[&Path], needles: &[&str]) {
    let a = ccpp().args(args).args(extra).assert().failure();
    let o = a.get_output();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    assert!(err.starts_with("error: "), "{err}");
    // The map path takes up to about 100 characters; the message itself stays short.
    assert!(err.len() < 320, "{} characters: {err}", err.len());
    for n in needles {
        assert!(err.contains(n), "{err:?} should contain {n:?}");
    }
}

#[test]
fn huge_numbers_in_zone_and_start_errors_stay_one_short_line() {
    let dir = tempfile::tempdir().unwrap();
    let map = pillars(dir.path());
    let run = |extra: &[&str], needles: &[&str]| {
        let mut args = vec![
            "run",
            "--planner",
            "ba-star",
            "--map",
            map.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let out = dir.path().join("out");
        fails_short(&args, &[Path::new("--out"), &out], needles);
    };
    run(
        &["--area", "0,0,1e300,1e300"],
        &["area rectangle 0,0,1e300,1e300"],
    );
    run(
        &["--area", "-1e300,-1e300,1e300,1e300"],
        &["area rectangle -1e300,-1e300,1e300,1e300"],
    );
    run(
        &["--keepout", "0.5,0.5,1e300,1e300"],
        &["keepout rectangle 0.5,0.5,1e300,1e300"],
    );
    run(
        &["--start", "1e300,1e300"],
        &["start (1.000e300, 1.000e300)"],
    );
    run(&["--radius", "1e300"], &["radius 1e300 m (2e300 m across)"]);
    // A polygon file whose edges cross far away: the edge is shown in scientific notation.
    let poly = dir.path().join("bow.yaml");
    std::fs::write(&poly, "[[0, 0], [1e150, 1e150], [1e150, 0], [0, 1e150]]\n").unwrap();
    run(
        &["--keepout", poly.to_str().unwrap()],
        &["intersects itself", "1.000e150"],
    );
    // rect-boustrophedon's own area option.
    let cfg = dir.path().join("rect.yaml");
    std::fs::write(
        &cfg,
        "rect_boustrophedon: { area: [1e300, 1e300, 2e300, 2e300] }\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    fails_short(
        &[
            "run",
            "--planner",
            "rect-boustrophedon",
            "--map",
            map.to_str().unwrap(),
            "--config",
            cfg.to_str().unwrap(),
        ],
        &[Path::new("--out"), &out],
        &["1e300,1e300,2e300,2e300 lies outside the map"],
    );
}

/// The MB a refused run says it would need.
fn needed_mb(err: &str) -> u64 {
    let tail = err.split("would need about ").nth(1).unwrap();
    tail.split(' ').next().unwrap().parse().unwrap()
}

#[test]
fn zones_count_in_the_memory_estimate() {
    let dir = tempfile::tempdir().unwrap();
    // 20 x 20 m of pixels, of which a 3 x 3 m room is free: big masks, a short run.
    let map = pgm(dir.path(), "big.pgm", 400, 400, |x, y| x > 60 || y > 60);
    let mask_png = dir.path().join("mask.pgm");
    std::fs::copy(&map, &mask_png).unwrap();
    let mask = dir.path().join("mask.yaml");
    std::fs::write(
        &mask,
        "image: mask.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 1\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let attempt = |limit: &str, extra: &[&str]| {
        let mut c = ccpp();
        c.args(["run", "--planner", "ba-star", "--radius", "0.3", "--map"])
            .arg(&map)
            .args(["--max-memory", limit])
            .args(extra)
            .arg("--out")
            .arg(&out);
        let o = c.output().unwrap();
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    // 10 MB: enough for the map's pixels alone (9.8 MB, checked from the image's header before
    // it is decoded), less than every run's whole estimate.
    let need = |extra: &[&str]| {
        let (code, err) = attempt("10", extra);
        assert_eq!(code, Some(1), "{err}");
        needed_mb(&err)
    };
    let plain = need(&[]);
    let rect = need(&["--keepout", "1,1,1.5,1.5"]);
    let file = need(&["--keepout", mask.to_str().unwrap()]);
    let approach = need(&["--area", "0.5,0.5,2.5,2.5", "--start", "0.3,2.8"]);
    assert!(
        plain < rect && rect < file && file < approach,
        "{plain} {rect} {file} {approach}"
    );
    let (_, err) = attempt("10", &["--keepout", mask.to_str().unwrap()]);
    assert!(err.contains("for the zones"), "{err}");
    // At the plain run's need, the plain run is allowed and the zoned ones are refused.
    let limit = plain.to_string();
    let (code, err) = attempt(&limit, &[]);
    assert_eq!(code, Some(0), "{err}");
    let (code, err) = attempt(&limit, &["--keepout", mask.to_str().unwrap()]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("memory limit"), "{err}");
}

#[test]
fn the_replay_of_a_zoned_run_carries_the_zones() {
    let dir = tempfile::tempdir().unwrap();
    let map = pillars(dir.path());
    let out = dir.path().join("out");
    ccpp()
        .args(["run", "--planner", "bcd", "--map"])
        .arg(&map)
        .args([
            "--area",
            "0.2,0.2,4,5.8",
            "--keepout",
            "0.5,3,1.5,4",
            "--replay",
        ])
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    let html = std::fs::read_to_string(out.join("replay.html")).unwrap();
    assert!(
        html.contains(r#""zones":{"area":[["#),
        "no zones in replay.html"
    );
    assert!(html.contains(r#""has_keepout":true,"has_outside":true"#));
    // And a run without zones has none.
    let plain = dir.path().join("plain");
    ccpp()
        .args(["run", "--planner", "bcd", "--map"])
        .arg(&map)
        .arg("--replay")
        .arg("--out")
        .arg(&plain)
        .assert()
        .success();
    let html = std::fs::read_to_string(plain.join("replay.html")).unwrap();
    assert!(html.contains(r#""zones":null"#));
}

/// The output of `args` run on a terminal (`script` gives it a pseudo-terminal; its own
/// output is the terminal's), or `None` where `script` is missing.
fn on_terminal(args: &[&str]) -> Option<String> {
    let bin = assert_cmd::cargo::cargo_bin("ccpp");
    let mut line = bin.display().to_string();
    for a in args {
        line.push(' ');
        line.push_str(a);
    }
    // A terminal type of its own: with `TERM` unset or `dumb` (as on some CI runners) the
    // progress library draws no spinner on a terminal either.
    let out = std::process::Command::new("script")
        .args(["-q", "-e", "-c", &line, "/dev/null"])
        .env("TERM", "xterm-256color")
        .output()
        .ok()?;
    assert!(out.status.success(), "{line}: {out:?}");
    Some(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// On a terminal `run` and `plan` turn a spinner naming the planner, the map and the step
/// while the planner works (and `run` while it writes its files), and clear it before the
/// summary; piped, standard error stays
/// empty and the files are the same.
#[test]
fn a_spinner_shows_a_long_step_on_a_terminal_only() {
    let dir = tempfile::tempdir().unwrap();
    let map = pgm(dir.path(), "hall.pgm", 400, 300, |x, y| {
        (100..140).contains(&x) && (60..200).contains(&y) || (x + y) % 97 == 0 && x > 250
    });
    let m = map.to_str().unwrap();
    let tty_out = dir.path().join("tty");
    let (t, p) = (tty_out.to_str().unwrap(), dir.path().join("piped"));
    let Some(screen) = on_terminal(&["run", "--map", m, "--planner", "bcd", "--out", t]) else {
        eprintln!("`script` is missing: no terminal to test on");
        return;
    };
    let spin = "bcd on hall: planning and simulating (";
    let first = screen.find(spin).expect(&screen);
    let summary = screen.find("bcd on hall (r = ").expect(&screen);
    let writing = screen.find("bcd on hall: writing files (").expect(&screen);
    assert!(first < writing && writing < summary, "{screen}");
    // Cleared ("erase line") before the summary, never drawn after it.
    let clear = screen[..summary].rfind("\u{1b}[2K").expect(&screen);
    assert!(
        clear > first && !screen[summary..].contains(spin),
        "{screen}"
    );
    let piped = ccpp()
        .args(["run", "--map", m, "--planner", "bcd", "--out"])
        .arg(&p)
        .assert()
        .success();
    assert!(piped.get_output().stderr.is_empty(), "{piped:?}");
    for f in ["trace.jsonl", "metrics.json", "path.csv"] {
        let (a, b) = (tty_out.join(f), p.join(f));
        let strip = |s: String| {
            s.lines()
                .filter(|l| !l.contains("wall_time_s"))
                .collect::<Vec<_>>()
                .join("\n")
        };
        assert_eq!(
            strip(std::fs::read_to_string(a).unwrap()),
            strip(std::fs::read_to_string(b).unwrap()),
            "{f}"
        );
    }
    let plan_out = dir.path().join("plan");
    let screen = on_terminal(&[
        "plan",
        "--map",
        m,
        "--planner",
        "bcd",
        "--out",
        plan_out.to_str().unwrap(),
    ])
    .unwrap();
    let first = screen.find("bcd on hall: planning (").expect(&screen);
    assert!(
        first < screen.find("waypoints,").expect(&screen),
        "{screen}"
    );
}

/// `--out DIR/` (as a shell completes a folder) printed `wrote DIR//{...}`: every command that
/// names its output folder prints it once, with one separator.
#[test]
fn an_output_folder_given_with_a_slash_is_printed_with_one() {
    let dir = tempfile::tempdir().unwrap();
    let map = pillars(dir.path());
    let out = |name: &str| format!("{}/", dir.path().join(name).display());
    let stdout = |args: &[&str]| {
        let o = ccpp().args(args).output().unwrap();
        assert!(o.status.success(), "{args:?}: {o:?}");
        String::from_utf8(o.stdout).unwrap()
    };
    let m = map.to_str().unwrap();
    let run = out("run");
    let plan = out("plan");
    let bench = out("bench");
    let cases = [
        (
            stdout(&["run", "--map", m, "--planner", "ba-star", "--out", &run]),
            format!("wrote {run}{{metrics.json"),
        ),
        (
            stdout(&["replay", &run]),
            format!("wrote {run}{{replay.html, replay.gif}}"),
        ),
        (
            stdout(&["plan", "--map", m, "--planner", "bcd", "--out", &plan]),
            format!("wrote {plan}{{"),
        ),
        (
            stdout(&[
                "bench",
                "--maps",
                m,
                "--planners",
                "ba-star",
                "--quiet",
                "--out",
                &bench,
            ]),
            format!("wrote {bench}results.csv"),
        ),
    ];
    for (text, want) in cases {
        assert!(text.contains(&want), "want {want:?} in:\n{text}");
        assert!(!text.contains("//"), "{text}");
    }
}

/// A start in a room holding a little more than half the floor, the other room behind a
/// 0.4 m doorway off the tile lattice: ba-star, bsa and bsa-bfs visited every tile they could
/// reach (`coverage_rate` 1.0) and swept 54 % without a word, because the stranded-tiles
/// warning waited for less than half; rect-boustrophedon, whose clearance disk does not fit
/// through, and random-bounce, whose budget ran out, were silent too (hostile pass). Each now
/// says how much floor it never came near; the planners that go through say nothing.
#[test]
fn a_room_never_entered_is_said_by_every_planner_that_leaves_it() {
    let dir = tempfile::tempdir().unwrap();
    let map = pgm(dir.path(), "two_rooms.pgm", 160, 120, |x, y| {
        (100..102).contains(&x) && !(100..108).contains(&y)
    });
    let run = |planner: &str| {
        let o = ccpp()
            .args(["run", "--planner", planner, "--start", "0.4,0.4", "--map"])
            .arg(&map)
            .arg("--out")
            .arg(dir.path().join(planner))
            .output()
            .unwrap();
        assert!(o.status.success(), "{planner}: {o:?}");
        let m = crate::common::read_json(&dir.path().join(planner).join("metrics.json"));
        let cov = m["effective_coverage"].as_f64().unwrap();
        (String::from_utf8(o.stderr).unwrap(), cov)
    };
    for planner in ["ba-star", "bsa", "bsa-bfs"] {
        let (err, cov) = run(planner);
        assert!(cov > 0.5 && cov < 0.6, "{planner}: {cov}");
        assert!(
            err.contains(
                "visited the tiles it could reach from the start (100 %) but swept only 5"
            ) && err.contains("m2, lies more than 1 m from anything the tool swept"),
            "{planner}: {err}"
        );
    }
    for (planner, why) in [
        ("rect-boustrophedon", "the path never went there"),
        (
            "random-bounce",
            "random-bounce spent its distance budget before it came there",
        ),
    ] {
        let (err, cov) = run(planner);
        assert!(cov > 0.5 && cov < 0.7, "{planner}: {cov}");
        let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("warning:")).collect();
        assert_eq!(lines.len(), 1, "{planner}: {err}");
        assert!(
            lines[0].contains("lies more than 1 m from anything the tool swept")
                && lines[0].contains(why),
            "{planner}: {err}"
        );
    }
    for planner in ["bcd", "ba-star-extended", "bsa-extended"] {
        let (err, cov) = run(planner);
        assert!(cov > 0.99, "{planner}: {cov}");
        assert!(!err.contains("warning:"), "{planner}: {err}");
    }
}

/// Tiles much wider than the tool in an open room leave strips between lanes farther than
/// 1 m from anything swept: that is the wide tiles' doing, said by their own warning, and not
/// a doorway the tiles did not take (review: `--tile-side 4` was told to try another start).
#[test]
fn wide_tiles_in_an_open_room_are_not_taken_for_a_stranded_start() {
    let dir = tempfile::tempdir().unwrap();
    let map = pgm(dir.path(), "open.pgm", 400, 400, |_, _| false);
    let o = ccpp()
        .args(["run", "--planner", "ba-star", "--tile-side", "4", "--map"])
        .arg(&map)
        .arg("--out")
        .arg(dir.path().join("run"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{o:?}");
    let err = String::from_utf8(o.stderr).unwrap();
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("warning:")).collect();
    assert_eq!(lines.len(), 1, "{err}");
    assert!(
        lines[0].contains("the tile side 4 m is wider than the tool sweeps"),
        "{err}"
    );
}

/// A negative PID gain was taken and its sign dropped (the controller drives towards the goal
/// whatever its output's sign): `kp: -2` ran byte-identical to `kp: 2`, and `run.json` said
/// -2. Refused now, as the seed of a noise the options give is refused naming where to set it.
#[test]
fn negative_pid_gains_and_a_seed_for_the_options_noise_are_refused_as_such() {
    let dir = tempfile::tempdir().unwrap();
    let map = pillars(dir.path());
    let refused = |cfg: &str, extra: &[&str], want: &str| {
        let n = std::fs::read_dir(dir.path()).unwrap().count();
        let file = dir.path().join(format!("c{n}.yaml"));
        std::fs::write(&file, cfg).unwrap();
        let out = dir.path().join(format!("o{n}"));
        let o = ccpp()
            .args(["run", "--planner", "bsa-bfs", "--map"])
            .arg(&map)
            .arg("--config")
            .arg(&file)
            .args(extra)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{cfg}: {err}");
        assert!(
            err.starts_with("error: ") && err.contains(want),
            "{cfg}: {err}"
        );
        assert!(!out.exists());
    };
    for (ctl, gain) in [
        ("linear", "kp"),
        ("angular", "kp"),
        ("linear", "ki"),
        ("angular", "kd"),
    ] {
        refused(
            &format!("bsa_bfs: {{ exec: {{ pid: {{ {ctl}: {{ {gain}: -2.0 }} }} }} }}\n"),
            &[],
            &format!("bsa_bfs.exec.pid.{ctl}.{gain}: must be a finite number >= 0, got -2"),
        );
    }
    refused(
        "bsa_bfs: { exec: { pid: { noise: { linear_rel_std: 0.02 } } } }\n",
        &["--seed", "3"],
        "takes its seed from there (noise.seed, 0 when left out): set noise.seed there instead",
    );
}

/// A noisy run that saw a landmark somewhere and still drove into walls said nothing: one
/// landmark by the start of `teb_corridor` gave 824 fixes there, and beyond it the run made 22
/// contacts, strayed 0.54 m from its plan on average and swept 42 % (hostile pass).
#[test]
fn contacts_under_noise_are_said_even_when_a_landmark_was_seen() {
    let Some(maps) = crate::common::shared_maps() else {
        eprintln!("skipped: no shared maps");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let marks = dir.path().join("start.csv");
    std::fs::write(&marks, "1,3,3\n").unwrap();
    let o = ccpp()
        .args([
            "run",
            "--planner",
            "bcd",
            "--odometry-noise",
            "0.05,0.05,0.5",
            "--seed",
            "3",
        ])
        .arg("--map")
        .arg(maps.join("teb_corridor.yaml"))
        .arg("--landmarks")
        .arg(&marks)
        .arg("--out")
        .arg(dir.path().join("run"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{o:?}");
    let m = crate::common::read_json(&dir.path().join("run").join("metrics.json"));
    assert!(m["collisions"].as_u64().unwrap() > 0, "{m}");
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(
        err.contains("bumper contact(s) under odometry noise")
            && err.contains("although the robot saw landmarks ("),
        "{err}"
    );
}

/// The run's warnings show in `coverage.png`: an amber badge and the first warning under the
/// title (a start outside the building showed a green "99.5% covered" and nothing else there;
/// the warning was on stderr only).
#[test]
fn coverage_png_shows_the_runs_warnings() {
    let d = tempfile::tempdir().unwrap();
    // Free to the image's border: the start's free area reaches it.
    let mut bytes = b"P5\n60 40\n255\n".to_vec();
    bytes.extend(std::iter::repeat_n(254u8, 60 * 40));
    let open = d.path().join("open.pgm");
    std::fs::write(&open, bytes).unwrap();
    let amber = |png: &std::path::Path| {
        let img = image::open(png).unwrap().to_rgb8();
        img.pixels().filter(|p| p.0 == [176, 96, 0]).count()
    };
    let out = d.path().join("open");
    let a = crate::common::ccpp()
        .args(["run", "--planner", "ba-star", "--map"])
        .arg(&open)
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    let err = String::from_utf8_lossy(&a.get_output().stderr).into_owned();
    assert!(
        err.contains(
            "warning: the floor open to the robot from the start reaches the map's border"
        ),
        "{err}"
    );
    assert!(amber(&out.join("coverage.png")) > 500);
    // A walled room: no warning, no amber.
    let room = crate::common::pgm(d.path(), "room.pgm", 60, 40, |_, _| false);
    let out = d.path().join("room");
    let a = crate::common::ccpp()
        .args(["run", "--planner", "ba-star", "--map"])
        .arg(&room)
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    assert!(!String::from_utf8_lossy(&a.get_output().stderr).contains("warning"));
    assert_eq!(amber(&out.join("coverage.png")), 0);
}
