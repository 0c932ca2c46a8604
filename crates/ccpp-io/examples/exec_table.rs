//! Runs `bsa-bfs` and `rect-boustrophedon` (PID execution, their default) on every map of
//! `shared/maps` at r = 0.15 m (rectangle 0.3 x 0.3 m) from the default start and prints one
//! table row per run: coverage rate, effective coverage, collisions, tracking error, wall time
//! (planner construction plus simulation) and the construction time alone (an offline planner
//! plans there).
//!
//! `cargo run --release -p ccpp-io --example exec_table [MAPS_DIR] [PLANNER...]`

use std::path::PathBuf;

use ccpp_core::metrics;
use ccpp_core::planners::{self, PlannerOptions};
use ccpp_core::sim::{simulate, SimConfig};
use ccpp_core::world::{Robot, World};
use ccpp_io::{load_map, LoadOptions};

fn main() {
    let mut args = std::env::args().skip(1);
    let dir = args.next().map_or_else(
        || PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/maps")),
        PathBuf::from,
    );
    let mut which: Vec<String> = args.collect();
    if which.is_empty() {
        which = vec!["bsa-bfs".into(), "rect-boustrophedon".into()];
    }
    let mut maps: Vec<PathBuf> = match std::fs::read_dir(&dir) {
        Ok(rd) => rd
            .filter_map(Result::ok)
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
            .collect(),
        Err(e) => {
            eprintln!("cannot read {}: {e}", dir.display());
            std::process::exit(1);
        }
    };
    maps.sort();
    println!(
        "| map | planner | coverage_rate | effective_coverage | collisions | tracking mean / max (µm) | rect_guarantee | wall s | build s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for path in &maps {
        let name = path
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
        let grid = match load_map(path, &LoadOptions::default()) {
            Ok(m) => m.grid,
            Err(e) => {
                println!("| {name} | - | load error: {e} |");
                continue;
            }
        };
        let world = match World::new(grid, Robot::new(0.15), None) {
            Ok(w) => w,
            Err(e) => {
                println!("| {name} | - | world error: {e} |");
                continue;
            }
        };
        for planner in &which {
            let opts = PlannerOptions::default();
            let started = std::time::Instant::now();
            let mut p = match planners::build(planner, &opts, &world) {
                Ok(p) => p,
                Err(e) => {
                    println!("| {name} | {planner} | {e} |");
                    continue;
                }
            };
            let build_s = started.elapsed().as_secs_f64();
            let mut run = simulate(&world, p.as_mut(), &SimConfig::default());
            run.wall_time_s = started.elapsed().as_secs_f64();
            let m = metrics::compute(&world, &run, &name);
            let f = |v: Option<f64>, k: f64| {
                v.map_or_else(|| "-".to_string(), |x| format!("{:.3}", x * k))
            };
            println!(
                "| {name} | {planner} | {} | {:.4} | {} | {} / {} | {} | {:.2} | {:.2} |",
                m.coverage_rate
                    .map_or_else(|| "-".to_string(), |c| format!("{c:.4}")),
                m.effective_coverage,
                m.collisions,
                f(m.tracking_error_mean_m, 1e6),
                f(m.tracking_error_max_m, 1e6),
                m.rect_guarantee
                    .map_or_else(|| "-".to_string(), |g| format!("{g:.6}")),
                m.wall_time_s,
                build_s,
            );
        }
    }
}
