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
        // Every transfer moves, between regions (the trace-mark check of every planner).
        assert_eq!(crate::marks::mark_problem(&out.trace), None, "{name}");
    }
}

#[test]
fn bcd_plans_the_same_trace_twice() {
    for y in yamls() {
        let name = y.file_stem().unwrap().to_string_lossy().into_owned();
        if !["aws_bookstore", "teb_maze", "nobleo_basement"].contains(&name.as_str()) {
            continue;
        }
        let w = world(&y);
        let run = || {
            let mut p = Bcd::new(&w, &BcdOptions::default());
            simulate(&w, &mut p, &SimConfig::default()).trace
        };
        assert_eq!(run(), run(), "{name}");
    }
}
