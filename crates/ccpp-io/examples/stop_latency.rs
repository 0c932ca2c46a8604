//! How soon bcd's planning ends once it is given up (the stop flag Python's Ctrl-C sets).
//!
//! `cargo run --release -p ccpp-io --example stop_latency -- MAP.yaml RADIUS_M T1 [T2 ...]`
//! plans bcd on the map once per `T` (seconds), sets the stop flag after `T` seconds and
//! prints how long the planning then took to return. A plan that finishes before `T` prints
//! its planning time instead.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use ccpp_core::planners::bcd::{Bcd, BcdOptions};
use ccpp_core::world::{Robot, World};
use ccpp_io::{load_map, LoadOptions};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (Some(map), Some(r)) = (args.get(1), args.get(2).and_then(|r| r.parse::<f64>().ok()))
    else {
        eprintln!("usage: stop_latency MAP.yaml RADIUS_M T1 [T2 ...]");
        std::process::exit(2);
    };
    let grid = load_map(map.as_ref(), &LoadOptions::default()).expect("map");
    let world = World::new(grid.grid, Robot::new(r), None).expect("world");
    for t in args[3..].iter().filter_map(|t| t.parse::<f64>().ok()) {
        let stop = AtomicBool::new(false);
        let start = Instant::now();
        std::thread::scope(|s| {
            let job = s.spawn(|| Bcd::new_until(&world, &BcdOptions::default(), &stop));
            while !job.is_finished() && start.elapsed() < Duration::from_secs_f64(t) {
                std::thread::sleep(Duration::from_millis(5));
            }
            if job.is_finished() {
                println!("t={t}: planned in {:.2} s", start.elapsed().as_secs_f64());
                return;
            }
            stop.store(true, Ordering::Relaxed);
            let set = Instant::now();
            drop(job.join());
            println!(
                "t={t}: returned {:.3} s after the stop",
                set.elapsed().as_secs_f64()
            );
        });
    }
}
