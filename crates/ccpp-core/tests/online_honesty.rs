//! Online honesty of every online planner: pixels the sensor never showed cannot change the
//! run. Each online planner runs on a map with a sealed-off part behind a wall thicker than the
//! sensor range; every pixel farther than the sensor range (plus a margin) from every pose of
//! the trace is then flipped (free <-> occupied), and the run must be identical.
//!
//! This also pins random-bounce's default distance budget to what an operator knows (the map
//! frame), not the true accessible area, which the flipped pixels change.
#![allow(clippy::unwrap_used)]

use ccpp_core::grid::{Cell, GridMap};
use ccpp_core::planners::{PlannerConfig, CATALOG};
use ccpp_core::sim::{simulate, SimConfig};
use ccpp_core::trace::Trace;
use ccpp_core::world::{Robot, World};
use ccpp_core::{Point, Pose};

/// A room with furniture (left); a corridor one robot wide leading east to a far room; below
/// them, behind a wall thicker than the sensor range, a sealed part whose clutter varies with
/// `variant`. Planners that explore see the corridor and the far room; random-bounce, which
/// seldom threads a corridor, leaves pixels of its own component unsensed, so the flip below
/// changes the accessible area it could have based its budget on.
fn art(variant: u64) -> String {
    let mut rng = ccpp_core::rng::SplitMix64::new(variant);
    let (w, h) = (60, 24);
    let mut lines = Vec::new();
    for row in 0..h {
        let mut l = String::new();
        for col in 0..w {
            let border = row == 0 || row == h - 1 || col == 0 || col == w - 1;
            let room = (1..16).contains(&col) && (1..11).contains(&row);
            let furniture = col == 6 && (4..7).contains(&row);
            let corridor = (16..48).contains(&col) && (5..7).contains(&row);
            let far_room = (48..59).contains(&col) && (1..11).contains(&row);
            let sealed = row >= 18 && !border;
            let free = if sealed {
                rng.next_f64() >= 0.3
            } else {
                (room && !furniture) || corridor || far_room
            };
            l.push(if free { '.' } else { '#' });
        }
        lines.push(l);
    }
    lines.join("\n")
}

fn run(world: &World, config: &PlannerConfig) -> Trace {
    let mut p = config.build(world).unwrap();
    simulate(world, p.as_mut(), &SimConfig::default()).trace
}

/// Flips every pixel whose centre is farther than `reach` from every pose of `trace`.
fn flip_far(world: &World, trace: &Trace, reach: f64) -> (World, usize) {
    let poses: Vec<Pose> = trace.poses().collect();
    let mut m: GridMap = world.map().clone();
    let f = *m.frame();
    let mut flipped = 0;
    for row in 0..f.height {
        for col in 0..f.width {
            let g = Point::new(col as f64 + 0.5, f.height as f64 - row as f64 - 0.5);
            let p = f.grid_to_world(g);
            let near = poses.iter().any(|q| (q.x - p.x).hypot(q.y - p.y) <= reach);
            if !near {
                let v = if m.get(col, row).is_free() {
                    Cell::Occupied
                } else {
                    Cell::Free
                };
                m.set(col, row, v);
                flipped += 1;
            }
        }
    }
    (
        World::new(m, world.robot(), Some(world.start())).unwrap(),
        flipped,
    )
}

#[test]
fn every_online_planner_ignores_pixels_never_sensed() {
    let robot = Robot::new(0.15);
    let range = SimConfig::default().sensor_range_for(&robot);
    for info in CATALOG.iter().filter(|p| !p.offline) {
        for variant in 0..2u64 {
            let map = GridMap::from_ascii_scaled(&art(variant), 4, 0.05).unwrap();
            let world = World::new(map, robot, Some(Pose::new(0.5, 4.0, 0.0))).unwrap();
            let config = PlannerConfig::new(info.kind);
            let trace = run(&world, &config);
            let (flipped_world, n) = flip_far(&world, &trace, range + 2.0 * 0.05);
            assert!(n > 1000, "{}: only {n} pixels flipped", info.name);
            if info.name == "random-bounce" {
                // The flip reaches into the robot's own component: a budget derived from the
                // true accessible area would differ.
                assert_ne!(
                    flipped_world.accessible_area_m2(),
                    world.accessible_area_m2(),
                    "random-bounce: the flip must change the accessible area"
                );
            }
            let again = run(&flipped_world, &config);
            assert_eq!(trace, again, "{} variant {variant}", info.name);
        }
    }
}
