//! How soon bcd's planning ends once it is given up (the stop flag Python's Ctrl-C sets).
//!
//! `cargo run --release -p ccpp-io --example stop_latency -- MAP.yaml RADIUS_M T1 [T2 ...]`
//! plans bcd on the map once per `T` (seconds, 0 to 86400), sets the stop flag after `T`
//! seconds and prints how long the planning then took to return. A plan that finishes before
//! `T` prints its planning time instead.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use ccpp_core::planners::bcd::{Bcd, BcdOptions};
use ccpp_core::world::{Robot, World};
use ccpp_io::{load_map, LoadOptions};

/// Longest wait before the stop: a day.
const MAX_T: f64 = 86_400.0;

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 4 {
        return Err("usage: stop_latency MAP.yaml RADIUS_M T1 [T2 ...]".into());
    }
    let r: f64 = args[2]
        .parse()
        .map_err(|_| format!("radius {:?} is not a number", args[2]))?;
    let waits = args[3..]
        .iter()
        .map(|t| match t.parse::<f64>() {
            Ok(v) if (0.0..=MAX_T).contains(&v) => Ok(v),
            _ => Err(format!("wait {t:?} must be seconds from 0 to {MAX_T}")),
        })
        .collect::<Result<Vec<f64>, String>>()?;
    let map = load_map(args[1].as_ref(), &LoadOptions::default()).map_err(|e| e.to_string())?;
    let world =
        World::new(map.grid, Robot::new(r), None).map_err(|e| format!("{}: {e}", args[1]))?;
    for t in waits {
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
            // (the planner itself is not wanted: only when its planning returned)
            drop(job.join());
            println!(
                "t={t}: returned {:.3} s after the stop",
                set.elapsed().as_secs_f64()
            );
        });
    }
    Ok(())
}
