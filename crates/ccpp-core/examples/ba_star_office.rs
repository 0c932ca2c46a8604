//! Times BA* end to end on a generated office: `ba_star_office [side_px] [seed] [out.pgm]`.
//! Writes the map (and the visited tiles in grey) to `out.pgm` when given.

use std::io::Write;
use std::time::Instant;

use ccpp_core::planners::ba_star::{BaStar, BaStarOptions};
use ccpp_core::sim::{simulate, SimConfig};
use ccpp_core::world::{Robot, World};

fn main() {
    let mut args = std::env::args().skip(1);
    let side: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(1024);
    let seed: u64 = args.next().and_then(|s| s.parse().ok()).unwrap_or(1);
    let out = args.next();
    let t0 = Instant::now();
    let map = ccpp_core::gen::office(side, side, 0.05, seed);
    let t1 = Instant::now();
    let world = World::new(map, Robot::new(0.1), None).expect("world");
    let t2 = Instant::now();
    let mut p = BaStar::new(BaStarOptions {
        record_backtrack_list: false,
        ..Default::default()
    });
    let run = simulate(&world, &mut p, &SimConfig::default());
    let t3 = Instant::now();
    let m = ccpp_core::metrics::compute(&world, &run, "office");
    let t4 = Instant::now();
    println!(
        "side {side}: gen {:.3}s world {:.3}s sim {:.3}s metrics {:.3}s total {:.3}s",
        (t1 - t0).as_secs_f64(),
        (t2 - t1).as_secs_f64(),
        (t3 - t2).as_secs_f64(),
        (t4 - t3).as_secs_f64(),
        (t4 - t1).as_secs_f64()
    );
    println!(
        "coverage_rate {:?} effective {:.4} regions {} backtracks {} turns {} collisions {} path {:.1} m backtrack {:.1} m records {}",
        m.coverage_rate,
        m.effective_coverage,
        m.regions,
        m.backtracks,
        m.turns,
        m.collisions,
        m.path_length_m,
        m.backtrack_length_m,
        run.trace.len()
    );
    if let Some(path) = out {
        let f = *world.frame();
        let swept = ccpp_core::metrics::swept_pixels(&world, &run.trace);
        let mut bytes = format!("P5\n{} {}\n255\n", f.width, f.height).into_bytes();
        for row in 0..f.height {
            for col in 0..f.width {
                let i = f.index(col, row);
                let v = if !world.map().get(col, row).is_free() {
                    0
                } else if swept.contains(i) {
                    200
                } else if world.accessible().contains(i) {
                    120
                } else {
                    255
                };
                bytes.push(v);
            }
        }
        std::fs::File::create(path)
            .and_then(|mut fh| fh.write_all(&bytes))
            .expect("write");
    }
}
