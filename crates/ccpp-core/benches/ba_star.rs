//! BA* end to end (`World::new` + simulate + metrics) on generated offices of 1024, 2048 and
//! 4096 px a side at 0.05 m/px with a robot of radius 0.1 m.

use std::time::Duration;

use ccpp_core::planners::ba_star::{BaStar, BaStarOptions};
use ccpp_core::sim::{simulate, SimConfig};
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

criterion_group!(benches, ba_star_office);
criterion_main!(benches);
