//! `trace.jsonl` in its two forms on the shared maps: every planner that moves tile by tile
//! (and random-bounce, whose fixed steps form step runs) is run on every shared map, its trace
//! written both with runs ([`trace_jsonl`]) and one line per pose ([`trace_jsonl_per_pose`],
//! the earlier form, checked against a plain `serde_json` rendering of each record), and both
//! files are read back: they must give the same poses (bit for bit) and events as the run.
//! Skips with a note when `../shared/maps` is absent.

#![allow(clippy::unwrap_used)] // tests may panic on broken fixtures

use std::path::{Path, PathBuf};

use ccpp_core::planners::{build, PlannerOptions};
use ccpp_core::sim::{simulate, SimConfig};
use ccpp_core::trace::{Record, Trace};
use ccpp_core::world::{Robot, World};
use ccpp_io::trace::{parse_trace, trace_jsonl, trace_jsonl_per_pose};

const MAPS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/maps");

/// Each record as bits (poses) or its JSON (events): equality is exact.
fn exact(t: &Trace) -> Vec<String> {
    t.records()
        .map(|r| match r {
            Record::Pose { t, pose } => format!(
                "{t} {:x} {:x} {:x}",
                pose[0].to_bits(),
                pose[1].to_bits(),
                pose[2].to_bits()
            ),
            r @ Record::Event { .. } => serde_json::to_string(&r).unwrap(),
        })
        .collect()
}

#[test]
fn both_forms_decode_to_the_same_poses_and_events_on_the_shared_maps() {
    let dir = PathBuf::from(MAPS);
    if !dir.is_dir() {
        println!("note: {MAPS} is absent; skipping");
        return;
    }
    let mut names: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    names.sort();
    assert!(names.len() >= 10, "{} maps", names.len());
    let (mut lines_new, mut lines_old) = (0usize, 0usize);
    for path in &names {
        let map = ccpp_io::load_map(path, &ccpp_io::LoadOptions::default())
            .unwrap()
            .grid;
        let world = World::new(map, Robot::new(0.15), None).unwrap();
        for planner in ["ba-star", "bsa", "random-bounce"] {
            let mut p = build(planner, &PlannerOptions::default(), &world).unwrap();
            let out = simulate(&world, p.as_mut(), &SimConfig::default());
            let trace = &out.trace;
            let new = trace_jsonl(trace).unwrap();
            let old = trace_jsonl_per_pose(trace).unwrap();
            // The earlier form is what serde_json writes for each record.
            let serde: String = trace
                .records()
                .map(|r| serde_json::to_string(&r).unwrap() + "\n")
                .collect();
            assert_eq!(old, serde, "{planner} on {}", path.display());
            let margin = world.robot().radius + 2.0 * world.frame().resolution;
            let frame = Some((world.frame(), margin));
            let a = parse_trace(&new, Path::new("new"), frame).unwrap();
            let b = parse_trace(&old, Path::new("old"), frame).unwrap();
            let want = exact(trace);
            assert_eq!(exact(&a), want, "{planner} on {}: runs", path.display());
            assert_eq!(exact(&b), want, "{planner} on {}: per pose", path.display());
            lines_new += new.lines().count();
            lines_old += old.lines().count();
        }
    }
    // Runs pay: the tile planners' traces shrink to well under half the lines.
    assert!(
        lines_new * 2 < lines_old,
        "{lines_new} lines with runs, {lines_old} per pose"
    );
}
