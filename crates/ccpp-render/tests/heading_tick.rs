//! The start's heading tick in `coverage.png` points along the start heading *in the picture*:
//! with a map origin turned by a yaw, world east is not the image's right. It was drawn with
//! the world angle on the image's axes (with yaw pi/2 it pointed right, at world north).
#![allow(clippy::unwrap_used)]

use ccpp_core::grid::GridMap;
use ccpp_core::trace::Trace;
use ccpp_core::world::{Robot, World};
use ccpp_core::Pose;
use ccpp_render::{coverage_pixmap, CoverageStyle};

const TICK: [u8; 3] = [0, 100, 30];

/// Where the tick's pixels lie from the start disc's centre: (mean dx, mean dy) in canvas
/// pixels (y down).
fn tick_direction(yaw: f64) -> (f64, f64) {
    let map = GridMap::from_ascii_scaled("#######\n#.....#\n#.....#\n#.....#\n#######", 10, 0.05)
        .unwrap()
        .with_placement(0.05, Pose::new(0.0, 0.0, yaw))
        .unwrap();
    let centre = map.frame().grid_to_world(ccpp_core::Point::new(35.0, 25.0));
    // Heading world east.
    let start = Pose::new(centre.x, centre.y, 0.0);
    let world = World::new(map, Robot::new(0.2), Some(start)).unwrap();
    let mut trace = Trace::default();
    trace.push_pose(0, start);
    // No legend: its start swatch has the disc's colour.
    let style = CoverageStyle {
        legend: false,
        ..CoverageStyle::default()
    };
    let pm = coverage_pixmap(&world, &trace, &style).unwrap();
    let (w, h) = (pm.width() as usize, pm.height() as usize);
    let data = pm.data();
    let px = |x: usize, y: usize| {
        let i = 4 * (y * w + x);
        [data[i], data[i + 1], data[i + 2]]
    };
    let (mut disc, mut tick) = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0));
    for y in 0..h {
        for x in 0..w {
            let c = px(x, y);
            let add = |s: &mut (f64, f64, f64)| {
                s.0 += x as f64;
                s.1 += y as f64;
                s.2 += 1.0;
            };
            if c == [0, 170, 60] {
                add(&mut disc);
            } else if c == TICK {
                add(&mut tick);
            }
        }
    }
    assert!(disc.2 > 0.0 && tick.2 > 0.0, "no start disc or tick drawn");
    (
        tick.0 / tick.2 - disc.0 / disc.2,
        tick.1 / tick.2 - disc.1 / disc.2,
    )
}

#[test]
fn the_start_tick_follows_the_origin_yaw() {
    // No yaw: world east is the image's right.
    let (dx, dy) = tick_direction(0.0);
    assert!(dx > 3.0 && dy.abs() < 1.0, "{dx} {dy}");
    // Yaw pi/2: the image's x axis is world north, so world east is the image's down.
    let (dx, dy) = tick_direction(std::f64::consts::FRAC_PI_2);
    assert!(dy > 3.0 && dx.abs() < 1.0, "{dx} {dy}");
}
