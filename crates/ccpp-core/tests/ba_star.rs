//! BA* through the simulator and the metrics, plus the seed's unified scenario on tile indices.

use std::f64::consts::{FRAC_PI_2, PI};

use ccpp_core::grid::{Cell, GridMap};
use ccpp_core::metrics::{compute, Metrics};
use ccpp_core::planner::{Planner, Sensor, Step};
use ccpp_core::planners::ba_star::{
    corner_score, motion_to, BaStar, BaStarOptions, TileGraph, TileSearch, COST_ORTHO,
};
use ccpp_core::sim::{simulate, RunOutput, SimConfig};
use ccpp_core::tiles::{Tile, N8};
use ccpp_core::trace::{Event, Trace};
use ccpp_core::world::{Robot, World};
use ccpp_core::{Point, Pose};

/// Robot radius: one character = 11 px at 0.01 m = 0.11 m = one tile of side 2r. (An odd number
/// of pixels puts tile centres on pixel centres, so a 1-character corridor is in C-free.)
const R: f64 = 0.055;
const SCALE: usize = 11;
const SIDE: f64 = 0.11;

fn map(art: &str) -> GridMap {
    GridMap::from_ascii_scaled(art, SCALE, 0.01).unwrap()
}

/// World with the start at the centre of character (col, row) (row 0 = top line).
fn world(art: &str, col: usize, row: usize, theta: f64) -> World {
    let m = map(art);
    let rows = m.frame().height / SCALE;
    let x = (col as f64 + 0.5) * SIDE;
    let y = ((rows - 1 - row) as f64 + 0.5) * SIDE;
    World::new(m, Robot::new(R), Some(Pose::new(x, y, theta))).unwrap()
}

fn run(w: &World, opts: BaStarOptions) -> (RunOutput, Metrics, BaStar) {
    let mut p = BaStar::new(opts);
    let out = simulate(w, &mut p, &SimConfig::default());
    let m = compute(w, &out, "test");
    (out, m, p)
}

fn room(w: usize, h: usize) -> String {
    vec![".".repeat(w); h].join("\n")
}

fn moves(trace: &Trace) -> usize {
    let poses: Vec<Pose> = trace.poses().collect();
    poses
        .windows(2)
        .filter(|p| p[0].position().dist(p[1].position()) > 0.0)
        .count()
}

#[test]
fn empty_room_from_a_corner_facing_north() {
    for (w, h) in [(1, 1), (2, 3), (5, 4), (8, 8), (13, 6)] {
        let wd = world(&room(w, h), 0, h - 1, FRAC_PI_2);
        let (out, m, p) = run(&wd, BaStarOptions::default());
        assert_eq!(m.regions, 1, "{w}x{h}");
        assert_eq!(m.backtracks, 0);
        assert_eq!(moves(&out.trace), w * h - 1, "{w}x{h}");
        assert_eq!(m.turns as usize, 2 * (w - 1), "{w}x{h}");
        assert_eq!(m.revisit_rate, 0.0);
        assert_eq!(m.coverage_rate, Some(1.0));
        assert_eq!(m.collisions, 0);
        assert!(!p.frontier_without_candidates());
        assert!(p.backtrack_list().is_empty());
    }
}

#[test]
fn room_with_a_central_block_needs_regions() {
    let art = "\
        ..........\n\
        ..........\n\
        ...####...\n\
        ...####...\n\
        ...####...\n\
        ..........\n\
        ..........";
    let wd = world(art, 0, 6, FRAC_PI_2);
    let (_, m, p) = run(&wd, BaStarOptions::default());
    assert!(m.regions > 1, "{m:?}");
    assert_eq!(m.regions, m.backtracks + 1);
    assert_eq!(m.coverage_rate, Some(1.0));
    assert_eq!(m.collisions, 0);
    assert!(!p.frontier_without_candidates());
}

#[test]
fn corridor_east_west_has_no_turns() {
    let art = "\
        ##########\n\
        ..........\n\
        ##########";
    let wd = world(art, 0, 1, 0.0);
    let (out, m, _) = run(&wd, BaStarOptions::default());
    assert_eq!(m.turns, 0);
    assert_eq!(m.regions, 1);
    assert_eq!(moves(&out.trace), 9);
    assert_eq!(m.coverage_rate, Some(1.0));
}

#[test]
fn boxed_in_start_ends_at_once() {
    let art = "\
        .....\n\
        ..#..\n\
        .#.#.\n\
        ..#..\n\
        .....";
    let wd = world(art, 2, 2, 0.3);
    let (out, m, _) = run(&wd, BaStarOptions::default());
    assert_eq!(m.regions, 1);
    assert_eq!(moves(&out.trace), 0);
    assert_eq!(m.turns, 0);
    assert_eq!(m.coverage_rate, Some(1.0));
    assert!(out
        .trace
        .events()
        .any(|(_, e)| matches!(e, Event::CriticalPoint { .. })));
}
