//! Criterion bench: bcd on a straight corridor 1 m wide (20 px of 0.05 m) and 2500 px or
//! 10 000 px long. Time should grow about in proportion to the length: the rim step grew with
//! its square (chaining the rim's points by a scan of all of them, checking each merged
//! segment against every point it replaces, ring searches over cells outside the corridor),
//! and the 10 000 px corridor took 5.7 s to plan where it now takes about 0.6 s.

use ccpp_core::planners::bcd::{Bcd, BcdOptions};
use ccpp_core::sim::{simulate, SimConfig};
use ccpp_core::world::{Robot, World};
use ccpp_core::{GridMap, Pose};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};

/// A corridor `len` px long and 20 px wide (walls included), 0.05 m/px, robot r = 0.15 m.
fn corridor(len: usize) -> World {
    let mut art = String::with_capacity((len + 1) * 20);
    for r in 0..20 {
        for c in 0..len {
            let wall = r == 0 || r == 19 || c == 0 || c == len - 1;
            art.push(if wall { '#' } else { '.' });
        }
        art.push('\n');
    }
    let map = GridMap::from_ascii_scaled(&art, 1, 0.05).expect("valid art");
    World::new(map, Robot::new(0.15), Some(Pose::new(0.5, 0.5, 0.0))).expect("robot fits")
}

fn bench(c: &mut Criterion) {
    let cfg = SimConfig::default();
    let mut g = c.benchmark_group("bcd-corridor");
    g.sample_size(10);
    for len in [2500usize, 10_000] {
        let world = corridor(len);
        g.bench_with_input(BenchmarkId::from_parameter(len), &world, |b, w| {
            b.iter(|| simulate(w, &mut Bcd::new(w, &BcdOptions::default()), &cfg));
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
