//! BCD, the known-map reference planner, on the team's real maps (`shared/maps`,
//! r = `r_tool` = 0.15 m, each map's default start): no collision and at least 99.5 % effective coverage on
//! every map, and the same trace twice.

#![allow(clippy::unwrap_used)] // tests may panic on broken fixtures

use std::path::{Path, PathBuf};

use ccpp_core::metrics;
use ccpp_core::planners::bcd::{Bcd, BcdOptions};
use ccpp_core::sim::{simulate, SimConfig};
use ccpp_core::world::{Robot, World};
use ccpp_io::map::{load_map, LoadOptions};

/// `<repo>/../shared/maps`, valid from any worktree that sits beside `shared/`.
const MAPS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/maps");

fn yamls() -> Vec<PathBuf> {
    let dir = PathBuf::from(MAPS);
    if !dir.is_dir() {
        println!("note: {MAPS} is absent; skipping the BCD shared-map tests");
        return Vec::new();
    }
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    v.sort();
    v
}

fn world(yaml: &Path) -> World {
    let map = load_map(yaml, &LoadOptions::default()).unwrap().grid;
    World::new(map, Robot::new(0.15), None).unwrap()
}

#[test]
fn bcd_covers_every_shared_map_without_contact() {
    for y in yamls() {
        let name = y.file_stem().unwrap().to_string_lossy().into_owned();
        let w = world(&y);
        let mut p = Bcd::new(&w, &BcdOptions::default());
        let out = simulate(&w, &mut p, &SimConfig::default());
        let m = metrics::compute(&w, &out, &name);
        assert_eq!(m.collisions, 0, "{name}");
        assert!(
            m.effective_coverage >= 0.995,
            "{name}: effective coverage {}",
            m.effective_coverage
        );
        assert!(m.regions >= 1, "{name}");
        assert_eq!(empty_transfers(&out.trace), 0, "{name}");
    }
}

/// Transfers (backtrack marks) with no move between them: a transfer between regions moves
/// the robot (`teb_maze` counted 18 backtracks between 16 cells, 5 of them without a move).
fn empty_transfers(trace: &ccpp_core::trace::Trace) -> usize {
    use ccpp_core::trace::{Event, Record};
    let mut at: Option<[f64; 2]> = None;
    // The open transfer: where it started, and whether the robot has left that point since.
    let mut open: Option<(Option<[f64; 2]>, bool)> = None;
    let mut empty = 0;
    for r in trace.records() {
        match r {
            Record::Pose { pose, .. } => {
                at = Some([pose[0], pose[1]]);
                if let Some((from, moved)) = open.as_mut() {
                    *moved |= *from != at;
                }
            }
            Record::Event {
                event: Event::BacktrackStart,
                ..
            } => open = Some((at, false)),
            Record::Event {
                event: Event::BacktrackEnd,
                ..
            } => {
                if open.take().is_some_and(|(_, moved)| !moved) {
                    empty += 1;
                }
            }
            Record::Event { .. } => {}
        }
    }
    empty
}
