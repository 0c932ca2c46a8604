//! What a first-time user reads: the terminal summary shows every metric of `metrics.json`,
//! `ccpp plan` says what robot a rect-boustrophedon plan was made for, and `ccpp bench` counts
//! in the singular and plural.
#![allow(clippy::unwrap_used)]

use std::path::Path;

use crate::common::{ccpp, pillars, read_json};

/// `ccpp run` (no `--json`) in `DIR/SUB`; returns its stdout and the metrics.
fn run_summary(dir: &Path, sub: &str, planner: &str, args: &[&str]) -> (String, serde_json::Value) {
    let map = pillars(dir);
    let out = dir.join(sub);
    let o = ccpp()
        .args(["run", "--planner", planner, "--map"])
        .arg(&map)
        .args(args)
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    let stdout = String::from_utf8(o.get_output().stdout.clone()).unwrap();
    (stdout, read_json(&out.join("metrics.json")))
}

/// Every non-null key of `metrics.json` has a row in the summary, apart from those its first
/// line names (planner, map, radii); `tracking_error_*` and `rect_guarantee` were missing.
fn assert_every_metric_shown(stdout: &str, metrics: &serde_json::Value) {
    let header = ["planner", "map", "robot_radius_m", "tool_radius_m"];
    for (k, v) in metrics.as_object().unwrap() {
        if v.is_null() || header.contains(&k.as_str()) {
            continue;
        }
        assert!(
            stdout
                .lines()
                .any(|l| l.trim_start().starts_with(&format!("{k} "))),
            "{k} is in metrics.json but not in the summary:\n{stdout}"
        );
    }
}

#[test]
fn the_summary_shows_every_metric_of_metrics_json() {
    let dir = tempfile::tempdir().unwrap();
    let (stdout, m) = run_summary(
        dir.path(),
        "pid",
        "bsa-bfs",
        &["--odometry-noise", "0.02", "--seed", "4"],
    );
    assert!(m["tracking_error_mean_m"].is_number(), "{m}");
    assert_every_metric_shown(&stdout, &m);
    let (stdout, m) = run_summary(
        dir.path(),
        "rect",
        "rect-boustrophedon",
        &["--length", "0.3", "--width", "0.3"],
    );
    assert!(m["rect_guarantee"].is_number(), "{m}");
    assert_every_metric_shown(&stdout, &m);
}

#[test]
fn plan_prints_the_rectangle_and_its_clearance_disk() {
    let dir = tempfile::tempdir().unwrap();
    let map = pillars(dir.path());
    let o = ccpp()
        .args(["plan", "--planner", "rect-boustrophedon", "--map"])
        .arg(&map)
        .args(["--length", "0.4", "--width", "0.4", "--out"])
        .arg(dir.path().join("plan"))
        .assert()
        .success();
    let stdout = String::from_utf8(o.get_output().stdout.clone()).unwrap();
    // hypot(0.4, 0.4) / 2 = 0.283 m (a plan has no tool: the rectangle's width is its lanes').
    assert!(
        stdout.contains("(rectangle 0.4 x 0.4 m, clearance disk r = 0.283 m)"),
        "{stdout}"
    );
    assert!(!stdout.contains("(r = 0.15 m)"), "{stdout}");
    let o = ccpp()
        .args(["plan", "--planner", "bcd", "--radius", "0.2", "--map"])
        .arg(&map)
        .arg("--out")
        .arg(dir.path().join("plan-bcd"))
        .assert()
        .success();
    let stdout = String::from_utf8(o.get_output().stdout.clone()).unwrap();
    assert!(stdout.contains("(r = 0.2 m, tool r = 0.2 m)"), "{stdout}");
}

#[test]
fn bench_counts_one_run_on_one_map_in_the_singular() {
    let dir = tempfile::tempdir().unwrap();
    let map = pillars(dir.path());
    let o = ccpp()
        .args(["bench", "--planners", "bcd", "--quiet", "--maps"])
        .arg(&map)
        .arg("--out")
        .arg(dir.path().join("bench"))
        .assert()
        .success();
    let stdout = String::from_utf8(o.get_output().stdout.clone()).unwrap();
    assert!(
        stdout.contains("1 run (0 failed) on 1 map x 1 planner;"),
        "{stdout}"
    );
}
