//! Basic vs extended BSA on the shared maps (the paper's Table I, on our maps).
//!
//! `cargo run --release -p ccpp-io --example bsa_table -- [MAPS_DIR] [RADIUS_M] [NAME_FILTER]`
//! (defaults: `../shared/maps` relative to the workspace, 0.15 m, all maps).

use std::path::PathBuf;

use ccpp_core::metrics::compute;
use ccpp_core::planners::bsa::{Bsa, BsaOptions};
use ccpp_core::planners::bsa_extended::{BsaExtended, BsaExtendedOptions};
use ccpp_core::sim::{simulate, SimConfig};
use ccpp_core::world::{Robot, World};
use ccpp_io::{load_map, LoadOptions};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dir = args.get(1).map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/maps"),
        PathBuf::from,
    );
    let r: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(0.15);
    let filter = args.get(3).cloned().unwrap_or_default();
    let mut yamls: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("maps directory")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
        .filter(|p| p.to_string_lossy().contains(&filter))
        .collect();
    yamls.sort();
    println!(
        "| map | bsa eff. cov. | ext. eff. cov. | bsa cov. rate | bsa path ratio | ext. path ratio | bsa revisit | ext. revisit | bsa regions | ext. regions | collisions (bsa/ext) | bsa time s | ext. time s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut revisits = Vec::new();
    for y in &yamls {
        let name = y
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().to_string());
        let loaded = load_map(y, &LoadOptions::default()).expect("map loads");
        let world = World::new(loaded.grid, Robot::new(r), None).expect("world");
        let cfg = SimConfig::default();
        let b = simulate(&world, &mut Bsa::new(BsaOptions::default()), &cfg);
        let mb = compute(&world, &b, &name);
        let e = simulate(
            &world,
            &mut BsaExtended::new(BsaExtendedOptions::default()),
            &cfg,
        );
        let me = compute(&world, &e, &name);
        revisits.push(mb.revisit_rate);
        println!(
            "| {name} | {:.4} | {:.4} | {:.4} | {:.3} | {:.3} | {:.3} | {:.3} | {} | {} | {}/{} | {:.3} | {:.3} |",
            mb.effective_coverage,
            me.effective_coverage,
            mb.coverage_rate.unwrap_or(f64::NAN),
            mb.path_ratio,
            me.path_ratio,
            mb.revisit_rate,
            me.revisit_rate,
            mb.regions,
            me.regions,
            mb.collisions,
            me.collisions,
            mb.wall_time_s,
            me.wall_time_s,
        );
    }
    if !revisits.is_empty() {
        let avg = revisits.iter().sum::<f64>() / revisits.len() as f64;
        println!(
            "\nbsa revisit_rate averaged over {} maps: {:.1} % (paper: 23 % multi-swept cells)",
            revisits.len(),
            100.0 * avg
        );
    }
}
