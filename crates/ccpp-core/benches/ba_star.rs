//! Criterion benches of BA*'s planning core (planner + simulator, `simulate`, no metrics and
//! no files).
//!
//! * `ba_star_office`: generated offices of 1024, 2048 and 4096 px a side at 0.05 m/px with a
//!   robot of radius 0.1 m (`ccpp_core::gen::office`, in memory).
//! * `ba_star_bench_maps`: the shared bench maps of `../shared/bench` (as `ccpp run` loads
//!   them), each at its speed radius, with the backtracking list recorded (the CLI default).
//!   A map that is not there is skipped with a note (the folder lives beside the repository).

use std::path::{Path, PathBuf};
use std::time::Duration;

use ccpp_core::planners::ba_star::{BaStar, BaStarOptions};
use ccpp_core::sim::{simulate, SimConfig, StopReason};
use ccpp_core::world::{Robot, World};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};

fn ba_star_office(c: &mut Criterion) {
    let mut g = c.benchmark_group("ba_star_office");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(100))
        .measurement_time(Duration::from_secs(2));
    for side in [1024usize, 2048, 4096] {
        let map = ccpp_core::gen::office(side, side, 0.05, 1);
        g.bench_with_input(BenchmarkId::from_parameter(side), &map, |b, map| {
            b.iter(|| {
                let world = World::new(map.clone(), Robot::new(0.1), None).expect("world");
                let mut p = BaStar::new(BaStarOptions {
                    record_backtrack_list: false,
                    ..Default::default()
                });
                let run = simulate(&world, &mut p, &SimConfig::default());
                let m = ccpp_core::metrics::compute(&world, &run, "office");
                assert_eq!(m.collisions, 0);
                m
            });
        });
    }
    g.finish();
}

/// The shared bench maps folder: `$CCPP_BENCH_MAPS`, else `../shared/bench` beside the
/// workspace.
fn bench_dir() -> PathBuf {
    std::env::var_os("CCPP_BENCH_MAPS").map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/bench"),
        PathBuf::from,
    )
}

fn ba_star_bench_maps(c: &mut Criterion) {
    let mut g = c.benchmark_group("ba_star_bench_maps");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(100))
        .measurement_time(Duration::from_secs(3));
    let dir = bench_dir();
    for (name, radius) in [
        ("apartment_400x300", 0.025),
        ("office_1024", 0.1),
        ("office_4096", 0.1),
        ("cluttered_2000", 0.025),
    ] {
        let path = dir.join(format!("{name}.yaml"));
        let map = match ccpp_io::map::load_map(&path, &ccpp_io::map::LoadOptions::default()) {
            Ok(m) => m.grid,
            Err(e) => {
                eprintln!("skipping {name}: {e}");
                continue;
            }
        };
        let world = World::new(map, Robot::new(radius), None).expect("world");
        g.bench_with_input(BenchmarkId::from_parameter(name), &world, |b, world| {
            b.iter(|| {
                let mut p = BaStar::new(BaStarOptions::default());
                let run = simulate(world, &mut p, &SimConfig::default());
                assert_eq!(run.stop, StopReason::Done);
                run
            });
        });
    }
    g.finish();
}

criterion_group!(benches, ba_star_office, ba_star_bench_maps);
criterion_main!(benches);
