//! Path exports through the library (issue 14 §3, issue 13 "outputs sized to information"):
//! `path.csv` of a PID run on a real building grows with its segments, not its control steps,
//! while the metrics still come from the full trace; `plan_route` gives a known-map planner's
//! route and refuses online planners.

#![allow(clippy::unwrap_used)] // tests may panic on broken fixtures

use std::path::PathBuf;

use ccpp_core::planners::PlannerKind;
use ccpp_core::route::{Route, DEFAULT_TOLERANCE_M};
use ccpp_io::export::{nav_path_yaml, parse_waypoints_csv};
use ccpp_io::plan::{plan_route, plan_route_until, PlanError};
use ccpp_io::scenario::{Scenario, ScenarioError};
use ccpp_io::trace::path_csv;

/// `<repo>/../shared/maps`, valid from any worktree that sits beside `shared/`.
const MAPS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/maps");

fn shared(name: &str) -> Option<PathBuf> {
    let p = PathBuf::from(MAPS).join(name);
    if p.is_file() {
        Some(p)
    } else {
        println!("note: {} is absent; skipping", p.display());
        None
    }
}

#[test]
fn bsa_bfs_files_on_tuw_freihaus_eg_are_small() {
    // bsa-bfs runs under PID execution: about 4 million control steps on this map, which
    // path.csv used to list one a line (194 MB) and trace.jsonl one a line too (305 MB): the
    // trace now keeps the ends of the straight glides along the axes (98.5 % of the steps).
    let Some(map) = shared("tuw_freihaus_eg.yaml") else {
        return;
    };
    let run = Scenario::builder(&map, PlannerKind::BsaBfs)
        .radius(0.15)
        .build()
        .unwrap()
        .run()
        .unwrap();
    let trace = &run.output.trace;
    let poses = trace.poses().count();
    let csv = path_csv(trace);
    let rows = csv.lines().count() - 1;
    assert!((40_000..400_000).contains(&poses), "{poses} poses");
    let jsonl = ccpp_io::trace::trace_jsonl(trace).unwrap();
    assert!(
        jsonl.len() < 40_000_000,
        "trace.jsonl is {} bytes",
        jsonl.len()
    );
    assert!(csv.len() < 3_000_000, "path.csv is {} bytes", csv.len());
    assert!(rows * 20 < poses, "{rows} rows for {poses} poses");
    // The metrics are those of the full trace (the decimated path is not what is measured).
    let all: Vec<_> = trace.poses().collect();
    let full: f64 = all
        .windows(2)
        .map(|w| w[0].position().dist(w[1].position()))
        .sum();
    assert!((run.metrics.path_length_m - full).abs() < 1e-6);
    // The CSV reads back to the route as the exports write it (positions to a nanometre).
    let back = parse_waypoints_csv(&csv, std::path::Path::new("path.csv")).unwrap();
    let route = Route::from_trace(trace, DEFAULT_TOLERANCE_M);
    assert_eq!(back, ccpp_io::export::tidy(&route));
    for (a, b) in back.waypoints.iter().zip(&route.waypoints) {
        assert!((a.x - b.x).abs() <= 5e-10 && (a.y - b.y).abs() <= 5e-10);
        assert!((a.theta - b.theta).sin().abs() <= 1e-9 && (a.theta - b.theta).cos() > 0.0);
    }
}

#[test]
fn plan_route_of_known_map_planners_and_online_refusal() {
    let Some(map) = shared("teb_maze.yaml") else {
        return;
    };
    let scenario = Scenario::builder(&map, PlannerKind::Bcd).build().unwrap();
    let prepared = scenario.map.load().unwrap();
    let plan = plan_route(&scenario, &prepared, DEFAULT_TOLERANCE_M).unwrap();
    // The route is that of the simulated run (bcd executes ideally).
    let run = scenario.run_on(&prepared).unwrap();
    assert_eq!(
        plan.route,
        Route::from_trace(&run.output.trace, DEFAULT_TOLERANCE_M)
    );
    assert!(plan.route.waypoints.len() > 10);
    assert!(nav_path_yaml(&plan.route).starts_with("header:\n"));
    // Deterministic.
    let again = plan_route(&scenario, &prepared, DEFAULT_TOLERANCE_M).unwrap();
    assert_eq!(again.route, plan.route);
    let online = Scenario::builder(&map, PlannerKind::BaStar)
        .build()
        .unwrap();
    let e = plan_route(&online, &prepared, DEFAULT_TOLERANCE_M)
        .err()
        .unwrap();
    assert!(matches!(e, PlanError::Online("ba-star", _)), "{e}");
    // A plan or a run given up before it starts is interrupted, not an empty path; one not
    // given up is the same plan and run.
    let given_up = std::sync::atomic::AtomicBool::new(true);
    let e = plan_route_until(&scenario, &prepared, DEFAULT_TOLERANCE_M, &given_up)
        .err()
        .unwrap();
    assert!(
        matches!(e, PlanError::Scenario(ScenarioError::Interrupted)),
        "{e}"
    );
    assert!(matches!(
        scenario.run_on_until(&prepared, &given_up),
        Err(ScenarioError::Interrupted)
    ));
    let going = std::sync::atomic::AtomicBool::new(false);
    let kept = plan_route_until(&scenario, &prepared, DEFAULT_TOLERANCE_M, &going).unwrap();
    assert_eq!(kept.route, plan.route);
    let kept = scenario.run_on_until(&prepared, &going).unwrap();
    assert_eq!(kept.output.trace, run.output.trace);
}

/// A start far off the map, given through the builder, is the same `start ... is outside the
/// map` error as on the command line: `Scenario::run` panicked on an integer overflow in
/// debug builds (hostile pass), from the build a library user gets by default.
#[test]
fn a_start_far_off_the_map_is_an_error_not_a_panic() {
    let Some(map) = shared("teb_empty_box.yaml") else {
        return;
    };
    for (x, y) in [(1e300, -1e300), (-1e300, 1e300), (1e15, 0.0)] {
        let e = Scenario::builder(&map, PlannerKind::Bcd)
            .radius(0.1)
            .start(x, y, 0.0)
            .build()
            .and_then(|s| s.run().map(|_| ()))
            .expect_err("outside");
        assert!(e.to_string().contains("outside the map"), "{e}");
    }
}
