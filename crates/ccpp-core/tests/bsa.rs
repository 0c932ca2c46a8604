//! BSA and extended BSA on ASCII maps: coverage, rules RS1-RS4, sides, determinism.

use ccpp_core::metrics::{compute, Metrics};
use ccpp_core::planners::bsa::{Bsa, BsaOptions, Side};
use ccpp_core::planners::bsa_extended::BsaExtendedOptions;
use ccpp_core::sim::{simulate, RunOutput, SimConfig};
use ccpp_core::trace::Event;
use ccpp_core::world::{Robot, World};
use ccpp_core::{GridMap, Pose};

/// Pixels per ASCII character and metres per pixel: one character = one cell of side 0.2 m
/// for a robot of radius 0.1 m.
const SCALE: usize = 4;
const RES: f64 = 0.05;
const R: f64 = 0.1;

/// World of an ASCII map, start at the centre of character (col, row) (row 0 = top line).
fn world(art: &str, col: usize, row: usize, theta: f64) -> World {
    let map = GridMap::from_ascii_scaled(art, SCALE, RES).unwrap();
    let h = map.frame().height as f64 * RES;
    let c = SCALE as f64 * RES;
    let start = Pose::new((col as f64 + 0.5) * c, h - (row as f64 + 0.5) * c, theta);
    World::new(map, Robot::new(R), Some(start)).unwrap()
}

fn run(w: &World, side: Side) -> (RunOutput, Metrics) {
    let mut p = Bsa::new(BsaOptions { side });
    let out = simulate(w, &mut p, &SimConfig::default());
    let m = compute(w, &out, "t");
    (out, m)
}

fn run_ext(w: &World, side: Side) -> (RunOutput, Metrics) {
    let mut p = Bsa::extended(BsaExtendedOptions {
        side,
        ..Default::default()
    });
    let out = simulate(w, &mut p, &SimConfig::default());
    let m = compute(w, &out, "t");
    (out, m)
}

fn room(w: usize, h: usize) -> String {
    let mut s = String::new();
    for r in 0..h {
        for c in 0..w {
            s.push(if r == 0 || c == 0 || r == h - 1 || c == w - 1 {
                '#'
            } else {
                '.'
            });
        }
        s.push('\n');
    }
    s
}

/// The paper starts a spiral "nearby an obstacle, which is situated in the RLS": from a corner
/// an empty room is one spiral, no cell entered twice, ending near the centre.
#[test]
fn empty_room_is_one_spiral_ending_near_the_centre() {
    let art = room(12, 9);
    for (col, side) in [(1, Side::Left), (10, Side::Right)] {
        let w = world(&art, col, 7, 0.0);
        let (out, m) = run(&w, side);
        assert_eq!(m.coverage_rate, Some(1.0), "{side:?}");
        assert_eq!(m.collisions, 0);
        assert_eq!(m.regions, 1, "{side:?}");
        assert_eq!(m.backtracks, 0, "{side:?}");
        assert_eq!(m.revisit_rate, 0.0, "{side:?}");
        let last = out.trace.poses().last().unwrap();
        // Interior: 10 x 7 cells of 0.2 m from (0.2, 0.2): centre (1.2, 0.9); the innermost ring
        // is the 4 x 1 strip x in [0.9, 1.5], y = 0.9.
        assert!(
            (last.x - 1.2).abs() <= 0.31 && (last.y - 0.9).abs() <= 0.01,
            "{side:?} ends at {last:?}"
        );
    }
}

/// From the middle of the room the robot first drives to the wall; that spoke can leave a
/// one-cell pocket at its tip (one short backtrack), coverage stays complete.
#[test]
fn empty_room_from_the_middle_is_complete() {
    let art = room(12, 9);
    for side in [Side::Left, Side::Right] {
        let w = world(&art, 5, 4, 0.0);
        let (_, m) = run(&w, side);
        assert_eq!(m.coverage_rate, Some(1.0), "{side:?}");
        assert_eq!(m.collisions, 0);
        assert!(m.regions <= 2, "{side:?}: {m:?}");
        assert!(m.revisit_rate < 0.1, "{side:?}: {m:?}");
    }
}

/// Debug helper: the order in which cell centres are first reached, drawn on the map.
#[allow(dead_code)]
fn draw(w: &World, out: &RunOutput) -> String {
    let f = w.frame();
    let c = SCALE as f64 * RES;
    let (cw, ch) = (f.width / SCALE, f.height / SCALE);
    let mut grid = vec![vec!["  #".to_string(); cw]; ch];
    for row in 0..ch {
        for col in 0..cw {
            if w.map().get(col * SCALE, row * SCALE).is_free() {
                grid[row][col] = "  .".into();
            }
        }
    }
    let h = f.height as f64 * RES;
    let mut n = 0;
    for p in out.trace.poses() {
        let col = (p.x / c - 0.5).round() as usize;
        let row = ((h - p.y) / c - 0.5).round() as usize;
        if row < ch && col < cw && grid[row][col] == "  ." {
            grid[row][col] = format!("{n:3}");
            n += 1;
        }
    }
    grid.iter().map(|r| r.concat()).collect::<Vec<_>>().join("\n")
}

#[test]
#[ignore = "debug"]
fn show() {
    let art = room(12, 9);
    for (c, r, side) in [(1, 7, Side::Left), (10, 7, Side::Right), (5, 4, Side::Right)] {
        let w = world(&art, c, r, 0.0);
        let (out, m) = run(&w, side);
        println!("{}\n{m:?}", draw(&w, &out));
    }
}
