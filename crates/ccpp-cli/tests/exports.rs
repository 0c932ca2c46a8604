//! Path exports (issue 14 §3): `ccpp run --export FORMAT` and `ccpp plan` write waypoints with
//! headings as CSV and JSON (read back by ccpp's own readers), a ROS `nav_msgs/Path` YAML that
//! parses with the right fields and quaternions matching the headings, and a `GeoJSON`
//! `FeatureCollection` in map coordinates; `path.csv` is the executed path decimated to its
//! segment ends. Each flag changes what it should and is refused where it does not apply.
#![allow(clippy::unwrap_used)]

use std::path::{Path, PathBuf};

use ccpp_core::route::Route;
use ccpp_io::export::{parse_waypoints_csv, read_waypoints, round_m, tidy_heading};
use serde::Deserialize;

use crate::common::{ccpp, pgm, plan_ok, run_ok};

/// A 5 x 4 m room with one pillar.
fn room(dir: &Path) -> PathBuf {
    pgm(dir, "room.pgm", 100, 80, |x, y| {
        (40..55).contains(&x) && (20..50).contains(&y)
    })
}

fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        // (ccpp's stamp, in every folder it writes: `folders.rs` tests it)
        .filter(|n| n != ".ccpp")
        .collect();
    v.sort();
    v
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap()
}

/// Exit 1 and one `error:` line holding every needle.
fn refused(args: &[&str], map: Option<&Path>, needles: &[&str]) {
    let mut c = ccpp();
    c.args(args);
    if let Some(m) = map {
        c.arg("--map").arg(m);
    }
    let a = c.assert().failure();
    let o = a.get_output();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
    assert!(err.starts_with("error: "), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let first = err.lines().next().unwrap_or_default();
    for n in needles {
        assert!(first.contains(n), "{first:?} should contain {n:?}");
    }
}

// nav_msgs/Path as `ros2 topic echo` prints it; unknown fields are errors, so the test checks
// the exact shape.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Stamp {
    sec: i64,
    nanosec: u32,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Header {
    stamp: Stamp,
    frame_id: String,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Xyz {
    x: f64,
    y: f64,
    z: f64,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Quat {
    x: f64,
    y: f64,
    z: f64,
    w: f64,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PoseMsg {
    position: Xyz,
    orientation: Quat,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PoseStamped {
    header: Header,
    pose: PoseMsg,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NavPath {
    header: Header,
    poses: Vec<PoseStamped>,
}

/// The `nav_msgs/Path` parses as YAML, says frame `map`, and holds the route's positions with
/// unit quaternions about z whose yaw is the waypoint's heading.
fn check_nav_path(text: &str, route: &Route) {
    let p: NavPath = serde_saphyr::from_str(text).unwrap();
    assert_eq!(p.header.frame_id, "map");
    assert_eq!((p.header.stamp.sec, p.header.stamp.nanosec), (0, 0));
    assert_eq!(p.poses.len(), route.waypoints.len());
    assert!(p.poses.len() >= 2);
    for (m, w) in p.poses.iter().zip(&route.waypoints) {
        assert_eq!(m.header.frame_id, "map");
        assert_eq!(
            (m.pose.position.x, m.pose.position.y, m.pose.position.z),
            (w.x, w.y, 0.0)
        );
        let q = &m.pose.orientation;
        assert_eq!((q.x, q.y), (0.0, 0.0));
        assert!((q.z * q.z + q.w * q.w - 1.0).abs() < 1e-12);
        let yaw = 2.0 * q.z.atan2(q.w);
        let d = (yaw - w.theta).sin().abs() + (1.0 - (yaw - w.theta).cos());
        assert!(d < 1e-12, "yaw {yaw} vs heading {}", w.theta);
    }
}

/// The `GeoJSON` is a `FeatureCollection` whose first feature is the route as a `LineString` in
/// `[x, y]` order with the planner, robot and metrics as properties.
fn check_geojson(text: &str, route: &Route, metrics: Option<&serde_json::Value>) {
    let v: serde_json::Value = serde_json::from_str(text).unwrap();
    assert_eq!(v["type"], "FeatureCollection");
    let f = &v["features"][0];
    assert_eq!(f["type"], "Feature");
    assert_eq!(f["geometry"]["type"], "LineString");
    let coords = f["geometry"]["coordinates"].as_array().unwrap();
    assert_eq!(coords.len(), route.waypoints.len());
    for (c, w) in coords.iter().zip(&route.waypoints) {
        assert_eq!(c.as_array().unwrap().len(), 2);
        assert_eq!((c[0].as_f64().unwrap(), c[1].as_f64().unwrap()), (w.x, w.y));
    }
    assert_eq!(f["properties"]["frame_id"], "map");
    assert_eq!(f["properties"]["robot"]["radius_m"], 0.15);
    match metrics {
        Some(m) => {
            assert_eq!(f["properties"]["planner"], m["planner"]);
            let mut got = f["properties"]["metrics"].clone();
            let mut want = m.clone();
            // Left out: the one number that differs between identical runs.
            assert!(got.get("wall_time_s").is_none(), "{got}");
            got["wall_time_s"] = 0.into();
            want["wall_time_s"] = 0.into();
            assert_eq!(got, want);
        }
        None => assert!(f["properties"]["metrics"].is_null()),
    }
}

#[test]
fn run_export_writes_each_format_beside_the_other_files() {
    let d = tempfile::tempdir().unwrap();
    let map = room(d.path());
    let base = run_ok(d.path(), "base", &map, "bsa", &[]);
    assert_eq!(
        files(&base),
        [
            "coverage.png",
            "metrics.json",
            "path.csv",
            "run.json",
            "trace.jsonl"
        ]
    );
    let all = [
        "--export", "geojson", "--export", "nav-path", "--export", "json", "--export", "csv",
    ];
    let ex = run_ok(d.path(), "ex", &map, "bsa", &all);
    assert_eq!(
        files(&ex),
        [
            "coverage.png",
            "metrics.json",
            "nav_path.yaml",
            "path.csv",
            "path.geojson",
            "run.json",
            "trace.jsonl",
            "waypoints.csv",
            "waypoints.json"
        ]
    );
    // The same run again gives the same export files, byte for byte (path.geojson's metrics
    // leave the wall time out).
    let again = run_ok(d.path(), "again", &map, "bsa", &all);
    for f in [
        "nav_path.yaml",
        "path.geojson",
        "waypoints.csv",
        "waypoints.json",
    ] {
        assert_eq!(
            std::fs::read(ex.join(f)).unwrap(),
            std::fs::read(again.join(f)).unwrap(),
            "{f}"
        );
    }
    // The exports change nothing else.
    for f in ["path.csv", "trace.jsonl", "coverage.png", "run.json"] {
        assert_eq!(
            std::fs::read(base.join(f)).unwrap(),
            std::fs::read(ex.join(f)).unwrap(),
            "{f}"
        );
    }
    // CSV and JSON read back through ccpp's reader to the same route, which is path.csv's.
    let csv = read_waypoints(&ex.join("waypoints.csv")).unwrap();
    let json = read_waypoints(&ex.join("waypoints.json")).unwrap();
    assert_eq!(csv, json);
    assert_eq!(read(&ex.join("waypoints.csv")), read(&ex.join("path.csv")));
    assert!(csv.waypoints.len() > 10);
    // The route starts at the start pose and ends at the last pose of the trace.
    let trace = ccpp_io::trace::read_trace(&ex.join("trace.jsonl"), None).unwrap();
    let poses: Vec<_> = trace.poses().collect();
    // (positions to a nanometre, headings in (-pi, pi]: `export::tidy`)
    let tidy = |p: &ccpp_core::Pose| {
        ccpp_core::Pose::new(round_m(p.x), round_m(p.y), tidy_heading(p.theta))
    };
    assert_eq!(
        csv.waypoints.first().map(|p| (p.x, p.y)),
        poses.first().map(|p| (round_m(p.x), round_m(p.y)))
    );
    assert_eq!(csv.waypoints.last().copied(), poses.last().map(tidy));
    check_nav_path(&read(&ex.join("nav_path.yaml")), &csv);
    let metrics: serde_json::Value = serde_json::from_str(&read(&ex.join("metrics.json"))).unwrap();
    check_geojson(&read(&ex.join("path.geojson")), &csv, Some(&metrics));
    // One format alone writes one file; the same run twice gives the same bytes.
    let one = run_ok(d.path(), "one", &map, "bsa", &["--export", "nav-path"]);
    assert!(files(&one).contains(&"nav_path.yaml".to_string()));
    assert!(!files(&one).contains(&"waypoints.csv".to_string()));
    assert_eq!(
        read(&one.join("nav_path.yaml")),
        read(&ex.join("nav_path.yaml"))
    );
}

#[test]
fn path_csv_grows_with_segments_not_control_steps() {
    // bsa-bfs runs under PID execution: one trace pose per control step.
    let d = tempfile::tempdir().unwrap();
    let map = room(d.path());
    let out = run_ok(d.path(), "pid", &map, "bsa-bfs", &[]);
    let trace = read(&out.join("trace.jsonl"));
    let pose_lines = trace.lines().filter(|l| l.contains("\"pose\"")).count();
    let segments = trace
        .lines()
        .filter(|l| l.contains("planned_segment"))
        .count();
    let route = parse_waypoints_csv(&read(&out.join("path.csv")), Path::new("path.csv")).unwrap();
    let rows = route.waypoints.len();
    assert!(segments > 10, "{segments}");
    // At most the start and one end per planned straight motion.
    assert!(rows <= segments + 1, "{rows} rows for {segments} segments");
    assert!(pose_lines > 20 * rows, "{pose_lines} poses, {rows} rows");
    // The metrics come from the full trace: the path length is that of every pose.
    let m: serde_json::Value = serde_json::from_str(&read(&out.join("metrics.json"))).unwrap();
    let t = ccpp_io::trace::read_trace(&out.join("trace.jsonl"), None).unwrap();
    let poses: Vec<_> = t.poses().collect();
    let full: f64 = poses
        .windows(2)
        .map(|w| w[0].position().dist(w[1].position()))
        .sum();
    assert!((m["path_length_m"].as_f64().unwrap() - full).abs() < 1e-9);
    // PID tracking here is straight: the route keeps the length within the tolerance.
    assert!((route.length_m() - full).abs() < 1e-3 * rows as f64);
}

#[test]
fn export_is_refused_where_it_does_not_apply() {
    let d = tempfile::tempdir().unwrap();
    let map = room(d.path());
    let out = d.path().join("x");
    let o = out.to_str().unwrap();
    refused(
        &["run", "--planner", "bsa", "--out", o, "--export", "kml"],
        Some(&map),
        &["--export", "kml", "csv, json, nav-path or geojson"],
    );
    refused(
        &["plan", "--planner", "bcd", "--out", o, "--export", "png"],
        Some(&map),
        &["--export", "png"],
    );
    // bench and demo write no paths to export.
    refused(
        &["demo", "--out", o, "--export", "csv"],
        None,
        &["--export"],
    );
    refused(
        &["bench", "--maps", o, "--export", "csv"],
        None,
        &["--export"],
    );
    assert!(!out.exists());
}

#[test]
fn plan_writes_only_the_path_of_a_known_map_planner() {
    let d = tempfile::tempdir().unwrap();
    let map = room(d.path());
    let p = plan_ok(d.path(), "bcd", &map, "bcd", &[]);
    assert_eq!(files(&p), ["nav_path.yaml", "waypoints.csv"]);
    let route = read_waypoints(&p.join("waypoints.csv")).unwrap();
    check_nav_path(&read(&p.join("nav_path.yaml")), &route);
    // The planned route is the path a simulated run of the same planner executes (bcd runs
    // ideally by default).
    let r = run_ok(d.path(), "bcd-run", &map, "bcd", &[]);
    assert_eq!(read(&r.join("path.csv")), read(&p.join("waypoints.csv")));
    // --export replaces the default set.
    let g = plan_ok(
        d.path(),
        "geo",
        &map,
        "bcd",
        &["--export", "geojson", "--export", "json"],
    );
    assert_eq!(files(&g), ["path.geojson", "waypoints.json"]);
    check_geojson(&read(&g.join("path.geojson")), &route, None);
    assert_eq!(read_waypoints(&g.join("waypoints.json")).unwrap(), route);
    // rect-boustrophedon: planned ideally even though its runs default to PID; --length and
    // --width change the plan.
    let rect = plan_ok(d.path(), "rect", &map, "rect-boustrophedon", &[]);
    let rect_run = run_ok(
        d.path(),
        "rect-run",
        &map,
        "rect-boustrophedon",
        &["--exec", "ideal"],
    );
    assert_eq!(
        read(&rect_run.join("path.csv")),
        read(&rect.join("waypoints.csv"))
    );
    for (flag, v) in [("--length", "0.5"), ("--width", "0.5")] {
        let other = plan_ok(
            d.path(),
            &format!("rect{flag}"),
            &map,
            "rect-boustrophedon",
            &[flag, v],
        );
        assert_ne!(
            read(&other.join("waypoints.csv")),
            read(&rect.join("waypoints.csv")),
            "{flag}"
        );
    }
    // The GeoJSON names the robot the route was planned for: the disk planners' disk, and
    // rect-boustrophedon's rectangle, alone in a plan (a disk beside it named a `--radius`
    // default that `plan` calls "changes nothing here" and a tool radius it refuses), beside
    // the simulated disk in a run.
    let bcd_robot = &json(&g.join("path.geojson"))["features"][0]["properties"]["robot"];
    assert!(bcd_robot.get("footprint").is_none(), "{bcd_robot}");
    assert!(bcd_robot["radius_m"].as_f64().is_some(), "{bcd_robot}");
    let args = ["--length", "0.5", "--width", "0.3", "--export", "geojson"];
    let planned = plan_ok(d.path(), "rect-geo", &map, "rect-boustrophedon", &args);
    let ran = run_ok(d.path(), "rect-geo-run", &map, "rect-boustrophedon", &args);
    for (out, simulated) in [(planned, false), (ran, true)] {
        let robot = &json(&out.join("path.geojson"))["features"][0]["properties"]["robot"];
        for key in ["radius_m", "tool_radius_m"] {
            assert_eq!(robot.get(key).is_some(), simulated, "{key}: {robot}");
        }
        let f = &robot["footprint"];
        assert_eq!(f["shape"], "rectangle", "{robot}");
        assert_eq!(
            (f["length_m"].as_f64(), f["width_m"].as_f64()),
            (Some(0.5), Some(0.3))
        );
        let r = f["clearance_radius_m"].as_f64().unwrap();
        assert!((r - 0.5f64.hypot(0.3) / 2.0).abs() < 1e-12, "{r}");
    }
}

fn json(p: &Path) -> serde_json::Value {
    serde_json::from_str(&read(p)).unwrap()
}

#[test]
fn plan_refuses_online_planners_and_foreign_flags() {
    let d = tempfile::tempdir().unwrap();
    let map = room(d.path());
    let out = d.path().join("p");
    let o = out.to_str().unwrap();
    for p in ["ba-star", "bsa-bfs", "random-bounce"] {
        refused(
            &["plan", "--planner", p, "--out", o],
            Some(&map),
            &[p, "online planner", "bcd, rect-boustrophedon"],
        );
    }
    refused(
        &["plan", "--planner", "bcd", "--length", "0.5", "--out", o],
        Some(&map),
        &["--length", "does not apply to bcd"],
    );
    refused(
        &[
            "plan",
            "--planner",
            "rect-boustrophedon",
            "--width",
            "-1",
            "--out",
            o,
        ],
        Some(&map),
        &["--width"],
    );
    // Simulation flags are not plan flags.
    refused(
        &["plan", "--planner", "bcd", "--exec", "pid", "--out", o],
        Some(&map),
        &["--exec"],
    );
    // A plan executes the steps ideally: the planner's own PID settings from the options file
    // would be read, validated and then dropped.
    let cfg = d.path().join("pid.yaml");
    std::fs::write(
        &cfg,
        "rect_boustrophedon: { exec: { pid: { dt_s: 0.1 } } }\n",
    )
    .unwrap();
    refused(
        &[
            "plan",
            "--planner",
            "rect-boustrophedon",
            "--config",
            cfg.to_str().unwrap(),
            "--out",
            o,
        ],
        Some(&map),
        &[
            cfg.file_name().unwrap().to_str().unwrap(),
            "rect_boustrophedon.exec",
            "does not apply to a plan",
        ],
    );
    assert!(!out.exists());
}

/// Points every 2 cm along the route's segments.
fn route_samples(route: &Route) -> Vec<[f64; 2]> {
    let mut out = Vec::new();
    for w in route.waypoints.windows(2) {
        let (a, b) = (w[0], w[1]);
        let n = ((b.x - a.x).hypot(b.y - a.y) / 0.02).ceil().max(1.0) as usize;
        for k in 0..=n {
            let f = k as f64 / n as f64;
            out.push([a.x + f * (b.x - a.x), a.y + f * (b.y - a.y)]);
        }
    }
    out
}

#[test]
fn plan_takes_zones_and_exports_them() {
    let d = tempfile::tempdir().unwrap();
    let map = room(d.path());
    let free = plan_ok(d.path(), "free", &map, "bcd", &["--export", "csv"]);
    let free_route = read_waypoints(&free.join("waypoints.csv")).unwrap();
    let inside =
        |p: &[f64; 2], r: [f64; 4]| p[0] > r[0] && p[0] < r[2] && p[1] > r[1] && p[1] < r[3];
    let keep = [0.5, 0.5, 1.5, 1.5];
    assert!(
        route_samples(&free_route).iter().any(|p| inside(p, keep)),
        "without the keep-out the path crosses the rectangle"
    );
    // --keepout: the path never enters it, the GeoJSON carries it as a closed ring.
    let k = plan_ok(
        d.path(),
        "keep",
        &map,
        "bcd",
        &[
            "--keepout",
            "0.5,0.5,1.5,1.5",
            "--export",
            "csv",
            "--export",
            "geojson",
        ],
    );
    let route = read_waypoints(&k.join("waypoints.csv")).unwrap();
    assert!(route_samples(&route).iter().all(|p| !inside(p, keep)));
    let g: serde_json::Value = serde_json::from_str(&read(&k.join("path.geojson"))).unwrap();
    let zones: Vec<&serde_json::Value> = g["features"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["properties"]["kind"] == "keepout")
        .collect();
    assert_eq!(zones.len(), 1);
    let ring = zones[0]["geometry"]["coordinates"][0].as_array().unwrap();
    assert_eq!(ring.len(), 5);
    assert_eq!(ring[0], ring[4]);
    // --area: the path stays inside it.
    let area = [0.1, 0.1, 1.9, 3.9];
    let a = plan_ok(
        d.path(),
        "area",
        &map,
        "bcd",
        &["--area", "0.1,0.1,1.9,3.9", "--export", "csv"],
    );
    let route = read_waypoints(&a.join("waypoints.csv")).unwrap();
    assert!(route.waypoints.len() > 4);
    assert!(route_samples(&route).iter().all(|p| inside(p, area)));
    assert!(route_samples(&free_route).iter().any(|p| !inside(p, area)));
    // A Nav2 keep-out mask (pixels, no polygon) was left out of the GeoJSON: it is there now
    // as a rectangle of whole pixels (columns 70..80, rows 10..20 from the top of 80: x 3.5 to
    // 4.0 m, y 3.0 to 3.5 m), named `mask`.
    let mut bytes = b"P5\n100 80\n255\n".to_vec();
    for y in 0..80 {
        for x in 0..100 {
            let kept = (70..80).contains(&x) && (10..20).contains(&y);
            bytes.push(if kept { 0 } else { 254 });
        }
    }
    std::fs::write(d.path().join("mask.pgm"), bytes).unwrap();
    let mask = d.path().join("mask.yaml");
    std::fs::write(
        &mask,
        "image: mask.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
    )
    .unwrap();
    let m = plan_ok(
        d.path(),
        "mask",
        &map,
        "bcd",
        &["--keepout", mask.to_str().unwrap(), "--export", "geojson"],
    );
    let g: serde_json::Value = serde_json::from_str(&read(&m.join("path.geojson"))).unwrap();
    let masks: Vec<&serde_json::Value> = g["features"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["properties"]["kind"] == "keepout" && f["properties"]["name"] == "mask")
        .collect();
    assert_eq!(masks.len(), 1, "{g}");
    let ring: Vec<[f64; 2]> =
        serde_json::from_value(masks[0]["geometry"]["coordinates"][0].clone()).unwrap();
    let near = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9;
    let want = [[3.5, 3.0], [4.0, 3.0], [4.0, 3.5], [3.5, 3.5], [3.5, 3.0]];
    assert!(ring.iter().zip(want).all(|(a, b)| near(*a, b)), "{ring:?}");
    // A GeoJSON zone's `properties.name` is carried into the export (it was `null`), for
    // `plan` and for `run`; an unnamed polygon stays `null`.
    let zones = d.path().join("zones.geojson");
    std::fs::write(
        &zones,
        r#"{"type":"FeatureCollection","features":[
            {"type":"Feature","properties":{"name":"rug"},"geometry":{"type":"Polygon","coordinates":[[[0.5,0.5],[1.5,0.5],[1.5,1.5],[0.5,1.5]]]}},
            {"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[3.0,2.0],[3.5,2.0],[3.5,2.5],[3.0,2.5]]]}}]}"#,
    )
    .unwrap();
    let named = |g: &serde_json::Value| -> Vec<serde_json::Value> {
        g["features"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|f| f["properties"]["kind"] == "keepout")
            .map(|f| f["properties"]["name"].clone())
            .collect()
    };
    let want = [serde_json::json!("rug"), serde_json::Value::Null];
    let n = plan_ok(
        d.path(),
        "named",
        &map,
        "bcd",
        &["--keepout", zones.to_str().unwrap(), "--export", "geojson"],
    );
    let g: serde_json::Value = serde_json::from_str(&read(&n.join("path.geojson"))).unwrap();
    assert_eq!(named(&g), want, "{g}");
    let run = d.path().join("named_run");
    ccpp()
        .args([
            "run",
            "--planner",
            "ba-star",
            "--export",
            "geojson",
            "--map",
        ])
        .arg(&map)
        .arg("--keepout")
        .arg(&zones)
        .arg("--out")
        .arg(&run)
        .assert()
        .success();
    let g: serde_json::Value = serde_json::from_str(&read(&run.join("path.geojson"))).unwrap();
    assert_eq!(named(&g), want, "{g}");
}

/// `ccpp plan` says what `ccpp run` says of a path that goes nowhere and of lanes the tool
/// cannot fill (a plan has no coverage figures to show it): a rect-boustrophedon path of one
/// waypoint (its 0.6 m rectangle fits nowhere else beside a keep-out in a 2 x 1.5 m room) was
/// written at 0 m without a word, and bcd's lanes a pixel apart for a tool narrower than a
/// pixel left strips unswept in silence. The usual plans say neither.
#[test]
fn plan_warns_of_a_path_that_goes_nowhere_and_of_lanes_the_tool_cannot_fill() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let small = pgm(dir, "small.pgm", 40, 30, |_, _| false);
    let ko = dir.join("ko.yaml");
    std::fs::write(
        &ko,
        "polygons:\n  - [[1.2955, 0.8735], [0.9918, 1.2711], [0.7468, 0.8642]]\n",
    )
    .unwrap();
    let said = |map: &Path, planner: &str, args: &[&str], out: &str| {
        let o = ccpp()
            .args(["plan", "--planner", planner, "--map"])
            .arg(map)
            .args(args)
            .arg("--out")
            .arg(dir.join(out))
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stdout).unwrap() + &String::from_utf8(o.stderr).unwrap()
    };
    let still = "warning: the path does not move the robot (one waypoint, 0 m)";
    let ko_arg = ko.to_str().unwrap();
    let text = said(
        &small,
        "rect-boustrophedon",
        &["--keepout", ko_arg, "--radius", "0.3"],
        "still",
    );
    assert!(
        text.contains(still) && text.contains("1 waypoints, 0.00 m"),
        "{text}"
    );
    assert!(!said(&small, "rect-boustrophedon", &["--radius", "0.3"], "moves").contains(still));
    let map = room(dir);
    let narrow = "warning: the tool sweeps 0.04 m but bcd's lanes lie at least a map pixel";
    assert!(said(&map, "bcd", &["--tool-radius", "0.02"], "narrow").contains(narrow));
    assert!(!said(&map, "bcd", &[], "wide").contains("warning:"));
}
