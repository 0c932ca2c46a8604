//! Criterion bench: basic and extended BSA on a generated office-like map.

use std::fmt::Write as _;

use ccpp_core::planners::bsa::{Bsa, BsaOptions};
use ccpp_core::planners::bsa_extended::{BsaExtended, BsaExtendedOptions};
use ccpp_core::sim::{simulate, SimConfig};
use ccpp_core::world::{Robot, World};
use ccpp_core::GridMap;
use criterion::{criterion_group, criterion_main, Criterion};

/// 40 x 30 characters of 0.25 m (5 px of 0.05 m): rooms along two walls, pillars, a few
/// clutter blocks (deterministic).
fn office() -> World {
    let (w, h) = (40usize, 30usize);
    let mut art = String::new();
    for r in 0..h {
        for c in 0..w {
            let border = r == 0 || c == 0 || r == h - 1 || c == w - 1;
            let room_wall = (r == 10 || r == 20) && c % 8 != 4;
            let divider = !(10..=20).contains(&r) && c % 8 == 0;
            let pillar = r % 5 == 2 && c % 7 == 3 && (11..20).contains(&r);
            let clutter = (r * 31 + c * 17) % 53 == 0;
            let wall = border || room_wall || divider || pillar || clutter;
            art.push(if wall { '#' } else { '.' });
        }
        writeln!(art).expect("string write");
    }
    let map = GridMap::from_ascii_scaled(&art, 5, 0.05).expect("valid art");
    World::new(map, Robot::new(0.15), None).expect("robot fits")
}

fn bench(c: &mut Criterion) {
    let world = office();
    let cfg = SimConfig::default();
    let mut g = c.benchmark_group("bsa");
    g.sample_size(10);
    g.bench_function("bsa/office", |b| {
        b.iter(|| simulate(&world, &mut Bsa::new(BsaOptions::default()), &cfg));
    });
    g.bench_function("bsa-extended/office", |b| {
        b.iter(|| {
            simulate(
                &world,
                &mut BsaExtended::new(BsaExtendedOptions::default()),
                &cfg,
            )
        });
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
