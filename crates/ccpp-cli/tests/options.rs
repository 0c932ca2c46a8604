//! Every planner option read from a `--config` file changes the run of the planner it belongs
//! to, end to end through `ccpp run`, in the direction its documentation promises where it
//! promises one. (Refusals of out-of-range values and of keys a planner does not have are in
//! `flags.rs`.) One row per option: a value that is not the default and a map on which it has
//! something to change.
#![allow(clippy::unwrap_used)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::common::{pillars, rooms, run_ok};

/// What a row expects of the run with its option against the planner's default run.
#[derive(Clone, Copy, Debug)]
enum Expect {
    /// The driven poses differ.
    Differs,
    /// The trace differs and the metric is lower.
    Less(&'static str),
    /// The trace differs and the metric is higher.
    More(&'static str),
    /// The same path and metrics, and the trace no longer holds this event.
    Drops(&'static str),
    /// The trace differs and is shorter (fewer records).
    FewerRecords,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Map {
    Pillars,
    Rooms,
}

struct Run {
    metrics: serde_json::Value,
    trace: String,
}

fn read_run(out: &Path) -> Run {
    let mut metrics: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    metrics["wall_time_s"] = 0.into();
    Run {
        metrics,
        trace: std::fs::read_to_string(out.join("trace.jsonl")).unwrap(),
    }
}

/// The trace's pose records: the driven path.
fn poses(trace: &str) -> Vec<&str> {
    trace.lines().filter(|l| l.contains("\"pose\"")).collect()
}

fn num(m: &serde_json::Value, key: &str) -> f64 {
    m[key]
        .as_f64()
        .unwrap_or_else(|| panic!("metric {key} missing: {m}"))
}

/// Runs every row (planner, option YAML, map, expectation) and checks it against the
/// planner's default run on the same map.
fn check_rows(rows: &[(&str, &str, Map, Expect)]) {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let maps: BTreeMap<Map, PathBuf> = [(Map::Pillars, pillars(dir)), (Map::Rooms, rooms(dir))]
        .into_iter()
        .collect();
    let mut bases: BTreeMap<(String, Map), Run> = BTreeMap::new();
    let mut failures = Vec::new();
    for (i, &(planner, yaml, map, expect)) in rows.iter().enumerate() {
        let key = (planner.to_string(), map);
        if !bases.contains_key(&key) {
            let out = run_ok(
                dir,
                &format!("base-{planner}-{map:?}"),
                &maps[&map],
                planner,
                &[],
            );
            bases.insert(key.clone(), read_run(&out));
        }
        let base = &bases[&key];
        let cfg = dir.join(format!("row{i}.yaml"));
        std::fs::write(&cfg, format!("{yaml}\n")).unwrap();
        let out = run_ok(
            dir,
            &format!("row{i}"),
            &maps[&map],
            planner,
            &["--config", cfg.to_str().unwrap()],
        );
        let run = read_run(&out);
        let what = format!("{planner} with `{yaml}` on {map:?}");
        if let Err(e) = check_row(base, &run, expect, yaml.contains("noise")) {
            failures.push(format!("{what}: {e}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// One row's expectation of `run` against the planner's default run `base`.
fn check_row(base: &Run, run: &Run, expect: Expect, noisy: bool) -> Result<(), String> {
    // Odometry noise makes the robot bump into what it thinks is free; nothing else may.
    if !noisy && run.metrics["collisions"] != 0 {
        return Err(format!("collisions: {}", run.metrics));
    }
    if let Expect::Drops(event) = expect {
        let tag = format!("\"event\":\"{event}\"");
        return if run.metrics != base.metrics {
            Err("the metrics changed".into())
        } else if !base.trace.contains(&tag) {
            Err(format!("the default run records no {event}"))
        } else if run.trace.contains(&tag) {
            Err(format!("still records {event}"))
        } else {
            Ok(())
        };
    }
    if run.trace == base.trace {
        return Err("changes nothing".into());
    }
    // The robot's own motion must change (a trace that differs only in events, such as the
    // points of `path_smoothed`, is bookkeeping; hostile pass).
    if !matches!(expect, Expect::FewerRecords) && poses(&run.trace) == poses(&base.trace) {
        return Err("the driven poses are the same (only events changed)".into());
    }
    let pair = |k: &str| (num(&run.metrics, k), num(&base.metrics, k));
    match expect {
        Expect::Less(k) => {
            let (x, y) = pair(k);
            if x < y {
                Ok(())
            } else {
                Err(format!("{k} {x} not below the default's {y}"))
            }
        }
        Expect::More(k) => {
            let (x, y) = pair(k);
            if x > y {
                Ok(())
            } else {
                Err(format!("{k} {x} not above the default's {y}"))
            }
        }
        Expect::FewerRecords if run.trace.lines().count() >= base.trace.lines().count() => {
            Err("the trace did not get shorter".into())
        }
        _ => Ok(()),
    }
}

#[test]
fn ba_star_options_change_the_run() {
    use Expect::{Differs, Drops, Less, More};
    use Map::{Pillars, Rooms};
    check_rows(&[
        (
            "ba-star",
            "ba_star: { tile_side_m: 0.4 }",
            Pillars,
            Less("path_length_m"),
        ),
        ("ba-star", "ba_star: { smoothing: false }", Pillars, Differs),
        (
            "ba-star",
            "ba_star: { record_backtrack_list: false }",
            Pillars,
            Drops("backtrack_list"),
        ),
        (
            "ba-star",
            "ba_star: { lane_end_corners: false }",
            Rooms,
            Differs,
        ),
        (
            "ba-star-extended",
            "ba_star_extended: { ba_star: { tile_side_m: 0.4 } }",
            Pillars,
            More("turns"),
        ),
        (
            "ba-star-extended",
            "ba_star_extended: { shorter_backtrack: false }",
            Rooms,
            Differs,
        ),
        // The nested BA* options other than the tile (hostile pass: untested).
        (
            "ba-star-extended",
            "ba_star_extended: { ba_star: { smoothing: false } }",
            Rooms,
            Differs,
        ),
        (
            "ba-star-extended",
            "ba_star_extended: { ba_star: { lane_end_corners: false } }",
            Rooms,
            Differs,
        ),
        (
            "ba-star-extended",
            "ba_star_extended: { ba_star: { record_backtrack_list: false } }",
            Pillars,
            Drops("backtrack_list"),
        ),
        (
            "ba-star-extended",
            "ba_star_extended: { backtrack_sweep: 1 }",
            Rooms,
            Differs,
        ),
        (
            "ba-star-extended",
            "ba_star_extended: { extension: { lane_ends: true } }",
            Rooms,
            Differs,
        ),
        (
            "ba-star-extended",
            "ba_star_extended: { extension: { merge_segments: false } }",
            Pillars,
            More("turns"),
        ),
        (
            "ba-star-extended",
            "ba_star_extended: { extension: { min_yield: 0.5 } }",
            Pillars,
            Less("effective_coverage"),
        ),
        (
            "ba-star-extended",
            "ba_star_extended: { extension: { leave_fraction: 0.0 } }",
            Rooms,
            More("effective_coverage"),
        ),
        (
            "ba-star-extended",
            "ba_star_extended: { extension: { reach_r: 0.5 } }",
            Pillars,
            Differs,
        ),
        (
            "ba-star-extended",
            "ba_star_extended: { extension: { leave_group: 1 } }",
            Pillars,
            Differs,
        ),
    ]);
}

#[test]
fn bsa_options_change_the_run() {
    use Expect::{Differs, Less, More};
    use Map::{Pillars, Rooms};
    check_rows(&[
        ("bsa", "bsa: { side: right }", Pillars, Differs),
        (
            "bsa-extended",
            "bsa_extended: { side: right }",
            Pillars,
            Differs,
        ),
        (
            "bsa-extended",
            "bsa_extended: { strip_walk: false }",
            Rooms,
            More("turns"),
        ),
        (
            "bsa-extended",
            "bsa_extended: { extension: { reach_r: 0.5 } }",
            Rooms,
            Differs,
        ),
        (
            "bsa-extended",
            "bsa_extended: { extension: { merge_segments: false } }",
            Pillars,
            More("turns"),
        ),
        (
            "bsa-extended",
            "bsa_extended: { extension: { min_yield: 0.5 } }",
            Pillars,
            Differs,
        ),
        (
            "bsa-extended",
            "bsa_extended: { extension: { leave_fraction: 0.5 } }",
            Rooms,
            Less("effective_coverage"),
        ),
        (
            "bsa-extended",
            "bsa_extended: { extension: { leave_group: 1 } }",
            Rooms,
            Differs,
        ),
        (
            "random-bounce",
            "random_bounce: { min_turn_deg: 10 }",
            Pillars,
            Differs,
        ),
        (
            "random-bounce",
            "random_bounce: { max_turn_deg: 100 }",
            Pillars,
            Differs,
        ),
        (
            "random-bounce",
            "random_bounce: { seed: 9 }",
            Pillars,
            Differs,
        ),
    ]);
}

#[test]
fn bcd_and_rect_options_change_the_run() {
    use Expect::{Differs, Less, More};
    use Map::{Pillars, Rooms};
    check_rows(&[
        (
            "bcd",
            "bcd: { lane_spacing_m: 0.2 }",
            Pillars,
            More("path_length_m"),
        ),
        ("bcd", "bcd: { turn_cost_m: 3.0 }", Pillars, Less("turns")),
        (
            "bcd",
            "bcd: { rim: false }",
            Pillars,
            Less("effective_coverage"),
        ),
        (
            "bcd",
            "bcd: { rim_min_yield: 0.5 }",
            Rooms,
            Less("path_length_m"),
        ),
        // More rim left unswept. The path need not get shorter: the plans are compared on
        // length plus `turn_cost_m` per turn (on Pillars 153.0 m / 78 turns against the
        // default's 152.5 m / 82 turns, coverage 0.9835 against 0.9953).
        (
            "bcd",
            "bcd: { rim_coverage: 0.98 }",
            Pillars,
            Less("effective_coverage"),
        ),
        ("bcd", "bcd: { tour_rounds: 0 }", Rooms, Differs),
        ("bcd", "bcd: { headland_min_m: 0.0 }", Pillars, Differs),
        ("bcd", "bcd: { headland_min_m: null }", Pillars, Differs),
        // (on Pillars the peeled plan of offset loops wins, whose hops are all straight)
        ("bcd", "bcd: { margin_px: 2 }", Rooms, Differs),
        (
            "bcd",
            "bcd: { min_coverage: 1.0 }",
            Pillars,
            More("effective_coverage"),
        ),
        (
            "rect-boustrophedon",
            "rect_boustrophedon: { clearance_radius_m: 0.2 }",
            Pillars,
            Differs,
        ),
        (
            "rect-boustrophedon",
            "rect_boustrophedon: { exec: ideal }",
            Pillars,
            Differs,
        ),
        (
            "rect-boustrophedon",
            "rect_boustrophedon: { exec: { pid: { dt_s: 0.1 } } }",
            Pillars,
            Differs,
        ),
    ]);
}

#[test]
fn bsa_bfs_and_pid_options_change_the_run() {
    use Expect::{Differs, FewerRecords, Less, More};
    use Map::Pillars;
    let pid = |body: &str| format!("bsa_bfs: {{ exec: {{ pid: {{ {body} }} }} }}");
    let rows: Vec<(String, Expect)> = vec![
        ("bsa_bfs: { cell_side_m: 0.4 }".into(), Differs),
        (
            "bsa_bfs: { clearance_margin_m: 0.05 }".into(),
            Less("effective_coverage"),
        ),
        ("bsa_bfs: { exec: ideal }".into(), Differs),
        (pid("dt_s: 0.1"), FewerRecords),
        (pid("linear: { kp: 1.0 }"), Differs),
        (pid("linear: { ki: 0.5 }"), Differs),
        (pid("linear: { kd: 0.1 }"), Differs),
        (pid("linear: { output_limit: 0.3 }"), Differs),
        (pid("linear: { ki: 0.5, integral_limit: 0.01 }"), Differs),
        (pid("angular: { kp: 2.0 }"), Differs),
        (pid("angular: { output_limit: 1.0 }"), Differs),
        (pid("angular: { kd: 0.2 }"), Differs),
        (pid("angular: { ki: 0.5 }"), Differs),
        (pid("tolerance_m: 0.01"), Differs),
        (pid("heading_tolerance_rad: 0.01"), Differs),
        (pid("align_rad: 0.0"), Differs),
        (pid("min_speed_mps: 0.1"), Differs),
        (pid("min_turn_rate: 0.5"), Differs),
        (pid("lookahead_m: 0.3"), Differs),
        (pid("record_every: 5"), FewerRecords),
        (pid("max_steps_per_motion: 100"), Differs),
        (
            pid("noise: { linear_rel_std: 0.05, angular_rel_std: 0.05 }"),
            More("tracking_error_mean_m"),
        ),
    ];
    let rows: Vec<(&str, &str, Map, Expect)> = rows
        .iter()
        .map(|(y, e)| ("bsa-bfs", y.as_str(), Pillars, *e))
        .collect();
    check_rows(&rows);
}

/// bcd's `margin_px` that no transfer can keep is said by `ccpp run` and `ccpp plan`, as a
/// warning naming how many transfers it concerns: three rooms in a row joined by corridors
/// 0.4 m wide (the robot's 0.3 m fit with 0.05 m to spare), the start in the middle room, so
/// one corridor is driven again as a transfer. Without a margin nothing is said. (A margin
/// wider than every corridor used to fall back to the plain clearance without a word.)
#[test]
fn a_bcd_margin_no_transfer_can_keep_is_said() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let map = crate::common::pgm(dir, "three_rooms.pgm", 182, 42, |x, y| {
        ((41..71).contains(&x) || (111..141).contains(&x)) && !(17..25).contains(&y)
    });
    std::fs::write(dir.join("margin.yaml"), "bcd: { margin_px: 3 }\n").unwrap();
    let said = |sub: &str, out: &str, margin: bool| {
        let mut cmd = crate::common::ccpp();
        cmd.args([sub, "--planner", "bcd", "--start", "4.5,1.0", "--map"])
            .arg(&map)
            .arg("--out")
            .arg(dir.join(out));
        if margin {
            cmd.arg("--config").arg(dir.join("margin.yaml"));
        }
        let o = cmd.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stdout).unwrap() + &String::from_utf8(o.stderr).unwrap()
    };
    for sub in ["run", "plan"] {
        let text = said(sub, &format!("{sub}-margin"), true);
        assert!(
            text.contains("warning: bcd: margin_px 3 was not kept on "),
            "{sub}: {text}"
        );
        assert!(!said(sub, &format!("{sub}-plain"), false).contains("margin_px"));
    }
}
