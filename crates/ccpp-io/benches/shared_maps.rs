//! Planners on real maps from the shared set.
//!
//! - `shared_maps`: end to end (`World::new` + simulate + metrics): BA* on
//!   `aws_small_warehouse_002` (1536x1504 px, 0.02 m/px) at r = 0.1 m (target: under 1 s), and
//!   BA* / BSA / extended BSA on the small house at r = 0.15 m.
//! - `relative_speed`: BA*, BSA and extended BSA on every shared map at r = 0.15 m, timing what
//!   `wall_time_s` times (planner construction + simulation, the world built once), for the
//!   targets "bsa within 2x of BA*, bsa-extended within 5x" per map. Select one map with e.g.
//!   `cargo bench -p ccpp-io --bench shared_maps -- relative_speed/.*/teb_maze`.
//!
//! Skips with a note when `../shared/maps` is absent.

use std::path::Path;
use std::time::Duration;

use ccpp_core::planners::{build, PlannerOptions};
use ccpp_core::sim::{simulate, SimConfig};
use ccpp_core::world::{Robot, World};
use ccpp_core::GridMap;
use criterion::{criterion_group, criterion_main, Criterion};

fn maps_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/maps")
}

fn load(name: &str) -> Option<GridMap> {
    let p = maps_dir().join(name);
    if !p.is_file() {
        eprintln!("{} not found; skipping", p.display());
        return None;
    }
    ccpp_io::load_map(&p, &ccpp_io::LoadOptions::default())
        .ok()
        .map(|m| m.grid)
}

fn run(map: &GridMap, planner: &str, r: f64) -> f64 {
    let world = World::new(map.clone(), Robot::new(r), None).expect("world");
    let mut opts = PlannerOptions::default();
    opts.ba_star.record_backtrack_list = false;
    let mut p = build(planner, &opts, &world).expect("planner");
    let out = simulate(&world, p.as_mut(), &SimConfig::default());
    let m = ccpp_core::metrics::compute(&world, &out, "bench");
    assert_eq!(m.collisions, 0);
    m.effective_coverage
}

fn shared_maps(c: &mut Criterion) {
    let mut g = c.benchmark_group("shared_maps");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(200))
        .measurement_time(Duration::from_secs(3));
    if let Some(map) = load("aws_small_warehouse_002.yaml") {
        g.bench_function("ba-star/aws_small_warehouse_002/r0.1", |b| {
            b.iter(|| run(&map, "ba-star", 0.1));
        });
    }
    if let Some(map) = load("aws_small_house.yaml") {
        for planner in ["ba-star", "bsa", "bsa-extended"] {
            g.bench_function(format!("{planner}/aws_small_house/r0.15"), |b| {
                b.iter(|| run(&map, planner, 0.15));
            });
        }
    }
    g.finish();
}

fn relative_speed(c: &mut Criterion) {
    let mut g = c.benchmark_group("relative_speed");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(100))
        .measurement_time(Duration::from_millis(1500));
    let mut names: Vec<String> = std::fs::read_dir(maps_dir())
        .map(|d| {
            d.filter_map(Result::ok)
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| {
                    Path::new(n)
                        .extension()
                        .is_some_and(|e| e.eq_ignore_ascii_case("yaml"))
                })
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    let mut opts = PlannerOptions::default();
    opts.ba_star.record_backtrack_list = false;
    let cfg = SimConfig::default();
    for name in names {
        let Some(map) = load(&name) else { continue };
        let world = World::new(map, Robot::new(0.15), None).expect("world");
        let stem = name.trim_end_matches(".yaml");
        for planner in ["ba-star", "bsa", "bsa-extended"] {
            g.bench_function(format!("{planner}/{stem}"), |b| {
                b.iter(|| {
                    let mut p = build(planner, &opts, &world).expect("planner");
                    simulate(&world, p.as_mut(), &cfg)
                });
            });
        }
    }
    g.finish();
}

criterion_group!(benches, shared_maps, relative_speed);
criterion_main!(benches);
