//! Fingerprints of BA* runs, to check that performance work leaves behaviour unchanged.
//!
//! `cargo run --release -p ccpp-io --example ba_star_hash -- [MAPS_DIR] [NAME_FILTER]`
//! prints, per run, an FNV-1a hash of `serde_json` of the trace and of the metrics (wall time
//! zeroed): the generated 1024 px office (r = 0.1 m) and the shared maps (r = 0.15 m);
//! `NAME_FILTER` = `office4096` (any side) runs that generated office alone.

use std::path::PathBuf;

use ccpp_core::metrics::compute;
use ccpp_core::planners::ba_star::{BaStar, BaStarOptions};
use ccpp_core::sim::{simulate, SimConfig};
use ccpp_core::world::{Robot, World};
use ccpp_core::GridMap;
use ccpp_io::{load_map, LoadOptions};

fn fnv(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

fn run(name: &str, map: GridMap, r: f64) {
    let world = World::new(map, Robot::new(r), None).expect("world");
    let mut p = BaStar::new(BaStarOptions::default());
    let out = simulate(&world, &mut p, &SimConfig::default());
    let mut m = compute(&world, &out, name);
    m.wall_time_s = 0.0;
    let trace = serde_json::to_vec(&out.trace).expect("trace json");
    let metrics = serde_json::to_vec(&m).expect("metrics json");
    println!(
        "{name}: trace {:016x} ({} records) metrics {:016x}",
        fnv(&trace),
        out.trace.len(),
        fnv(&metrics)
    );
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dir = args.get(1).map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/maps"),
        PathBuf::from,
    );
    let filter = args.get(2).cloned().unwrap_or_default();
    if let Some(side) = filter.strip_prefix("office").and_then(|s| s.parse().ok()) {
        // `office2048`, `office4096`, ...: that office only.
        run(&filter, ccpp_core::gen::office(side, side, 0.05, 1), 0.1);
        return;
    }
    if "office1024".contains(&filter) {
        run(
            "office1024",
            ccpp_core::gen::office(1024, 1024, 0.05, 1),
            0.1,
        );
    }
    let mut yamls: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("maps directory")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
        .filter(|p| p.to_string_lossy().contains(&filter))
        .collect();
    yamls.sort();
    for y in &yamls {
        let name = y
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().to_string());
        let loaded = load_map(y, &LoadOptions::default()).expect("map loads");
        run(&name, loaded.grid, 0.15);
    }
}
