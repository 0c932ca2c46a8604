//! Every planner's trace marks mean what the metrics say they count
//! (`../shared/docs/world-and-metrics.md`: `backtracks` are "transfers between regions"): a
//! backtrack never starts inside a region, and every one moves the robot. bcd reported hops
//! that the pruning had merged away (5 of 18 on `teb_maze`), and rect-boustrophedon's detours
//! round obstacles were backtracks inside a lane's region (all 46 on `teb_maze`). Run with each
//! planner's defaults on shared maps whose obstacles cut lanes.

#![allow(clippy::unwrap_used)] // tests may panic on broken fixtures

use std::path::PathBuf;

use ccpp_core::planners::{PlannerConfig, PlannerKind};
use ccpp_core::trace::{Event, Record, Trace};
use ccpp_io::scenario::{MapRecipe, Scenario};

/// `<repo>/../shared/maps`, valid from any worktree that sits beside `shared/`.
const MAPS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/maps");

/// What is wrong with the trace's backtrack marks, if anything.
pub fn mark_problem(trace: &Trace) -> Option<String> {
    let mut at: Option<[f64; 2]> = None;
    let mut in_region = false;
    // The open transfer: where it started, and whether the robot has left that point since.
    let mut open: Option<(Option<[f64; 2]>, bool)> = None;
    for r in trace.records() {
        match r {
            Record::Pose { pose, .. } => {
                at = Some([pose[0], pose[1]]);
                if let Some((from, moved)) = open.as_mut() {
                    *moved |= *from != at;
                }
            }
            Record::Event { t, event } => match event {
                Event::RegionStart { .. } => in_region = true,
                Event::RegionEnd { .. } => in_region = false,
                Event::BacktrackStart if in_region => {
                    return Some(format!("step {t}: a backtrack starts inside a region"));
                }
                Event::BacktrackStart => open = Some((at, false)),
                Event::BacktrackEnd if open.take().is_some_and(|(_, moved)| !moved) => {
                    return Some(format!("step {t}: a backtrack without a move ends"));
                }
                _ => {}
            },
        }
    }
    None
}

#[test]
fn every_planners_backtracks_are_transfers_between_regions_that_move() {
    let dir = PathBuf::from(MAPS);
    if !dir.is_dir() {
        println!("note: {MAPS} is absent; skipping");
        return;
    }
    for name in ["teb_maze", "aws_small_house"] {
        let recipe = MapRecipe::file(dir.join(format!("{name}.yaml")));
        let map = recipe.load().unwrap();
        for &kind in PlannerKind::ALL {
            let scenario = Scenario::configure(recipe.clone(), PlannerConfig::new(kind))
                .build()
                .unwrap();
            let run = scenario.run_owned(map.clone()).unwrap();
            let trace = &run.output.trace;
            if let Some(p) = mark_problem(trace) {
                panic!("{kind} on {name}: {p}");
            }
            let backtracks = trace
                .records()
                .filter(|r| {
                    matches!(
                        r,
                        Record::Event {
                            event: Event::BacktrackStart,
                            ..
                        }
                    )
                })
                .count();
            assert_eq!(
                run.metrics.backtracks as usize, backtracks,
                "{kind} on {name}"
            );
        }
    }
}
