//! BA* through the simulator and the metrics, plus the seed's unified scenario on tile indices.

#![allow(clippy::unwrap_used)] // helpers of a test file

use std::f64::consts::{FRAC_PI_2, PI};

use ccpp_core::grid::{Cell, GridMap};
use ccpp_core::metrics::{compute, Metrics};
use ccpp_core::planner::{Planner, Sensor, Step};
use ccpp_core::planners::ba_star::{
    corner_score, motion_to, BaStar, BaStarOptions, TileGraph, TileSearch, COST_DIAG, COST_ORTHO,
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

// ---------------------------------------------------------------------------------------------
// The seed's unified scenario on tile indices (tiles of side 10, tile (i, j) centred at
// (10 i, 10 j)): critical point (50,50), candidates (40,50) and (10,10).

/// A hand-made tile graph: covered tiles, every move between them free.
struct Grid {
    covered: Vec<Tile>,
}

impl TileGraph for Grid {
    fn bounds(&self) -> (i32, i32, i32, i32) {
        (0, 8, 0, 8)
    }
    fn covered(&self, t: Tile) -> bool {
        self.covered.contains(&t)
    }
    fn move_free(&self, _: Tile, _: usize) -> bool {
        true
    }
}

fn scenario() -> Grid {
    // Room 1..=6 x 1..=5 covered except (3,5) = (30,50), still unknown (free); the row j = 6 is
    // the north wall.
    let mut covered = Vec::new();
    for j in 1..=5 {
        for i in 1..=6 {
            if (i, j) != (3, 5) {
                covered.push((i, j));
            }
        }
    }
    Grid { covered }
}

#[test]
fn unified_scenario_critical_point_and_mu() {
    let g = scenario();
    let wall = |t: Tile| t.1 >= 6 || t.0 <= 0 || t.0 >= 7 || t.1 <= 0;
    let blocked = |t: Tile| g.covered(t) || wall(t);
    // (50,50): all four neighbours blocked (north wall, the rest covered).
    let cp = (5, 5);
    assert!([0, 2, 4, 6]
        .iter()
        .all(|&k| blocked((cp.0 + N8[k].0, cp.1 + N8[k].1))));
    // (40,50): s5 = (30,50) free, s4 = (30,60) wall, s1 = (50,50) covered.
    let s = (4, 5);
    let mut free = [false; 8];
    let mut bl = [false; 8];
    for (k, &(di, dj)) in N8.iter().enumerate() {
        let n = (s.0 + di, s.1 + dj);
        bl[k] = blocked(n);
        free[k] = k % 2 == 0 && !blocked(n);
    }
    assert!(free[4] && bl[3], "the (s5, s4) pair");
    assert!(corner_score(free, bl) >= 1);
    // Only the (s5, s4) pair and the (s5, s6) pair fire.
    assert_eq!(corner_score(free, bl), 2);
    // The critical point itself has no free 4-neighbour, so mu = 0.
    let mut f0 = [false; 8];
    for k in [0, 4, 6] {
        f0[k] = !blocked((cp.0 + N8[k].0, cp.1 + N8[k].1));
    }
    assert_eq!(corner_score(f0, [true; 8]), 0);
}

#[test]
fn unified_scenario_selection_and_path() {
    let g = scenario();
    let mut search = TileSearch::new(g.bounds());
    let candidates = [(4, 5), (1, 1)];
    let (sp, cost) = search
        .nearest(&g, (5, 5), |t| candidates.contains(&t))
        .unwrap();
    assert_eq!(sp, (4, 5));
    let side = 10.0;
    let j_a = cost as f64 / COST_ORTHO as f64 * side;
    assert!((j_a - 10.0).abs() < 1e-9);
    let (path_b, cost_b) = search.astar(&g, (5, 5), (1, 1)).unwrap();
    let j_b = cost_b as f64 / COST_ORTHO as f64 * side;
    assert!((j_b - 40.0 * 2f64.sqrt()).abs() < 1e-3, "{j_b}");
    assert!(j_b > 56.0 && j_b < 57.0);
    assert_eq!(path_b, vec![(5, 5), (4, 4), (3, 3), (2, 2), (1, 1)]);
    let (path_a, _) = search.astar(&g, (5, 5), (4, 5)).unwrap();
    assert_eq!(path_a, vec![(5, 5), (4, 5)]);
    // Only (1,1) as a candidate: Dijkstra finds it at the same cost as A*.
    let (t, c) = search.nearest(&g, (5, 5), |t| t == (1, 1)).unwrap();
    assert_eq!((t, c), ((1, 1), cost_b));
}

#[test]
fn unified_scenario_execution() {
    let (beta, alpha, d) = motion_to(Pose::new(50.0, 50.0, FRAC_PI_2), Point::new(40.0, 50.0));
    assert!((beta - PI).abs() < 1e-12);
    assert!((alpha - FRAC_PI_2).abs() < 1e-12);
    assert!((d - 10.0).abs() < 1e-12);
}

/// Covered tiles of a pseudo-random 24 x 24 patch (about 70 % covered), on a range larger
/// than the patch (so searches meet the border of the range and tiles outside it).
struct Patch {
    covered: Vec<bool>,
}

impl Patch {
    fn new(seed: u64) -> Self {
        let mut x = seed;
        let covered = (0..24 * 24)
            .map(|_| {
                x = x
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                (x >> 33) % 10 < 7
            })
            .collect();
        Self { covered }
    }
}

impl TileGraph for Patch {
    fn bounds(&self) -> (i32, i32, i32, i32) {
        (-2, 22, -2, 22)
    }
    fn covered(&self, t: Tile) -> bool {
        (0..24).contains(&t.0) && (0..24).contains(&t.1) && self.covered[(t.1 * 24 + t.0) as usize]
    }
    fn move_free(&self, t: Tile, k: usize) -> bool {
        // Some moves blocked, deterministically.
        (t.0 * 7 + t.1 * 13 + k as i32) % 11 != 0
    }
}

#[test]
fn bounded_astar_gives_the_full_search_answer() {
    let mut checked = 0;
    for seed in 0..40 {
        let g = Patch::new(seed);
        let mut s = TileSearch::new(g.bounds());
        let tiles: Vec<Tile> = (0..24 * 24)
            .map(|k| (k % 24, k / 24))
            .filter(|&t| g.covered(t))
            .collect();
        let from = tiles[(seed as usize * 7) % tiles.len()];
        for &to in tiles.iter().step_by(5) {
            let full = s.astar(&g, from, to);
            // The known cost (as from `nearest`), and wrong bounds: too low (the bounded search
            // runs dry and the full one answers) and too high.
            let cost = full.as_ref().map_or(0, |(_, c)| *c);
            for bound in [cost, cost.saturating_sub(1), cost / 2, cost + COST_ORTHO] {
                assert_eq!(
                    s.astar_bounded(&g, from, to, bound),
                    full,
                    "seed {seed}: {from:?} -> {to:?}, bound {bound}"
                );
            }
            if full.is_some() {
                checked += 1;
            }
        }
        // As BA* calls it: the cost from `nearest`.
        if let Some((t, c)) = s.nearest(&g, from, |t| t.0 + t.1 >= 40) {
            assert_eq!(s.astar_bounded(&g, from, t, c), s.astar(&g, from, t));
        }
    }
    assert!(checked > 500, "{checked}");
}

/// The A* towards a listed target set answers exactly as the Dijkstra search: the same tile
/// (least cost, then smaller `j`, then smaller `i`) and cost, over sparse and dense target sets,
/// ties on the cost, sources among the targets, and unreachable targets.
#[test]
fn nearest_of_gives_the_dijkstra_answer() {
    let mut compared = 0;
    for seed in 0..40u64 {
        let g = Patch::new(seed);
        let mut s = TileSearch::new(g.bounds());
        let tiles: Vec<Tile> = (0..24 * 24)
            .map(|k| (k % 24, k / 24))
            .filter(|&t| g.covered(t))
            .collect();
        let mut x = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
        for round in 0..12 {
            // Targets: every `every`-th covered tile from a pseudo-random offset.
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let every = [1, 2, 7, 23, 61, 150][round % 6];
            let targets: Vec<Tile> = tiles
                .iter()
                .copied()
                .skip((x % 13) as usize)
                .step_by(every)
                .collect();
            let from = tiles[(x >> 20) as usize % tiles.len()];
            let want = s.nearest(&g, from, |t| targets.contains(&t));
            let got = s.nearest_of(&g, from, &targets, |t| targets.contains(&t));
            assert_eq!(got, want, "seed {seed} round {round}: from {from:?}");
            // The path search restricted to the tiles on cheapest paths read off that search
            // (one-way moves: the edges are walked back in the right direction).
            if let Some((t, c)) = got {
                let restricted = s.astar_nearest(&g, from, t, c);
                assert_eq!(
                    restricted,
                    s.astar(&g, from, t),
                    "seed {seed} round {round}"
                );
                // No `nearest_of` just before: the plain bounded search answers.
                assert_eq!(s.astar_nearest(&g, from, t, c), restricted);
            }
            compared += usize::from(want.is_some());
        }
        // Symmetric targets around the source: equal costs, the (j, i) order decides.
        let from = (12, 12);
        if g.covered(from) {
            let ring: Vec<Tile> = [(10, 12), (14, 12), (12, 10), (12, 14)]
                .into_iter()
                .filter(|&t| g.covered(t))
                .collect();
            let want = s.nearest(&g, from, |t| ring.contains(&t));
            assert_eq!(s.nearest_of(&g, from, &ring, |t| ring.contains(&t)), want);
        }
    }
    assert!(compared > 300, "{compared}");
}

/// Covered tiles of a pseudo-random 170 x 150 field (about 85 % covered, from -5): many
/// blocks and super-blocks of the target lists of `nearest_of`.
struct Field {
    covered: Vec<bool>,
}

impl TileGraph for Field {
    fn bounds(&self) -> (i32, i32, i32, i32) {
        (-5, 164, -5, 144)
    }
    fn covered(&self, t: Tile) -> bool {
        (-5..165).contains(&t.0)
            && (-5..145).contains(&t.1)
            && self.covered[((t.1 + 5) * 170 + t.0 + 5) as usize]
    }
    fn move_free(&self, _: Tile, _: usize) -> bool {
        true
    }
}

#[test]
fn nearest_of_gives_the_dijkstra_answer_over_many_blocks() {
    let mut x: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let mut found = 0;
    for _ in 0..6 {
        let g = Field {
            covered: (0..170 * 150).map(|_| next() % 100 < 85).collect(),
        };
        let tiles: Vec<Tile> = (0..170 * 150)
            .map(|k| (k % 170 - 5, k / 170 - 5))
            .filter(|&t| g.covered(t))
            .collect();
        let mut s = TileSearch::new(g.bounds());
        for every in [3, 40, 400, 3000] {
            let skip = (next() % 50) as usize;
            let targets: Vec<Tile> = tiles.iter().copied().skip(skip).step_by(every).collect();
            for _ in 0..4 {
                let from = tiles[(next() % tiles.len() as u64) as usize];
                let want = s.nearest(&g, from, |t| targets.contains(&t));
                let got = s.nearest_of(&g, from, &targets, |t| targets.contains(&t));
                assert_eq!(got, want, "every {every}, from {from:?}");
                if let Some((t, c)) = got {
                    let restricted = s.astar_nearest(&g, from, t, c);
                    assert_eq!(restricted, s.astar(&g, from, t), "every {every}");
                }
                found += usize::from(want.is_some());
            }
        }
    }
    assert!(found > 60, "{found}");
}

#[test]
fn astar_needs_both_orthogonal_tiles_for_a_diagonal() {
    // (0,0) and (1,1) covered, (1,0) covered, (0,1) not: the diagonal is not an edge.
    let g = Grid {
        covered: vec![(1, 1), (2, 1), (2, 2)],
    };
    let mut s = TileSearch::new(g.bounds());
    let (p, c) = s.astar(&g, (1, 1), (2, 2)).unwrap();
    assert_eq!(p, vec![(1, 1), (2, 1), (2, 2)]);
    assert_eq!(c, 2 * COST_ORTHO);
    assert!(s.astar(&g, (1, 1), (5, 5)).is_none());
}

// ---------------------------------------------------------------------------------------------
// Invariants on random maps, checked after every planner step.

/// Wraps the planner and checks invariants after every step.
struct Checked {
    p: BaStar,
    errors: Vec<String>,
    criticals: usize,
}

impl Checked {
    fn err(&mut self, e: String) {
        if self.errors.len() < 5 {
            self.errors.push(e);
        }
    }

    /// Independent check that the swept disk of a segment stays on covered tiles: dense samples,
    /// every tile square closer than r to a sample must be covered.
    fn segment_on_covered(&self, a: Point, b: Point) -> Result<(), String> {
        let g = self.p.tile_grid().unwrap();
        let rho = R / g.side;
        let ua = ((a.x - g.anchor.x) / g.side, (a.y - g.anchor.y) / g.side);
        let ub = ((b.x - g.anchor.x) / g.side, (b.y - g.anchor.y) / g.side);
        let n = (((ub.0 - ua.0).hypot(ub.1 - ua.1)) * 64.0).ceil() as usize + 1;
        for s in 0..=n {
            let t = s as f64 / n as f64;
            let (x, y) = (ua.0 + t * (ub.0 - ua.0), ua.1 + t * (ub.1 - ua.1));
            for di in -1..=1 {
                for dj in -1..=1 {
                    let tile = (x.round() as i32 + di, y.round() as i32 + dj);
                    let dx = (f64::from(tile.0) - 0.5 - x)
                        .max(0.0)
                        .max(x - f64::from(tile.0) - 0.5);
                    let dy = (f64::from(tile.1) - 0.5 - y)
                        .max(0.0)
                        .max(y - f64::from(tile.1) - 0.5);
                    if dx.hypot(dy) < rho - 1e-6 && !self.p.is_covered(tile) {
                        return Err(format!("segment {a:?}->{b:?} touches uncovered {tile:?}"));
                    }
                }
            }
        }
        let known = self.p.known_map().unwrap();
        if !known.segment_free(a, b, R) {
            return Err(format!("segment {a:?}->{b:?} not free on the known map"));
        }
        Ok(())
    }
}

impl Planner for Checked {
    fn name(&self) -> &'static str {
        self.p.name()
    }
    fn tile_side(&self) -> Option<f64> {
        self.p.tile_side()
    }
    fn next(&mut self, sensor: &dyn Sensor) -> Step {
        let step = self.p.next(sensor);
        let inc = self.p.backtrack_list();
        let full = self.p.backtrack_list_full();
        if inc != full {
            self.err(format!("L incremental {inc:?} != full {full:?}"));
        }
        match &step {
            Step::MoveTo(pt) if !self.p.is_backtracking() => {
                let g = self.p.tile_grid().unwrap();
                let t = g.tile_of(*pt);
                if self.p.is_covered(t) {
                    self.err(format!("BM enters covered tile {t:?}"));
                }
            }
            Step::Mark(Event::PathSmoothed { points }) => {
                for w in points.windows(2) {
                    let a = Point::new(w[0][0], w[0][1]);
                    let b = Point::new(w[1][0], w[1][1]);
                    if let Err(e) = self.segment_on_covered(a, b) {
                        self.err(e);
                    }
                }
            }
            Step::Mark(Event::CriticalPoint { .. }) => {
                self.criticals += 1;
                if self.criticals <= 4 {
                    if let Err(e) = self.p.check_judgements() {
                        self.err(e);
                    }
                }
            }
            Step::Done => {
                if let Err(e) = self.p.check_judgements() {
                    self.err(e);
                }
                if self.p.frontier_without_candidates() {
                    self.err("safeguard: free tile next to a covered one with L empty".into());
                }
            }
            _ => {}
        }
        step
    }
}

/// A random ASCII map and a free start character.
fn random_art(w: usize, h: usize, density: f64, seed: u64) -> Option<(String, usize, usize)> {
    let mut rng = ccpp_core::rng::SplitMix64::new(seed);
    let mut rows = Vec::new();
    let mut free = Vec::new();
    for r in 0..h {
        let mut line = String::new();
        for c in 0..w {
            if rng.next_f64() < density {
                line.push('#');
            } else {
                line.push('.');
                free.push((c, r));
            }
        }
        rows.push(line);
    }
    if free.is_empty() {
        return None;
    }
    let (c, r) = free[(rng.next_u64() % free.len() as u64) as usize];
    Some((rows.join("\n"), c, r))
}

fn check_run(art: &str, col: usize, row: usize, theta: f64) {
    let wd = world(art, col, row, theta);
    let mut c = Checked {
        p: BaStar::new(BaStarOptions::default()),
        errors: Vec::new(),
        criticals: 0,
    };
    let out = simulate(&wd, &mut c, &SimConfig::default());
    assert!(c.errors.is_empty(), "{:?}\n{art}", c.errors);
    let m = compute(&wd, &out, "random");
    assert_eq!(m.coverage_rate, Some(1.0), "{m:?}\n{art}");
    assert_eq!(m.collisions, 0);
    assert_eq!(m.regions, m.backtracks + 1);
    // Identical input, identical trace.
    let (again, _, _) = run(&wd, BaStarOptions::default());
    assert_eq!(out.trace, again.trace);
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 64, rng_seed: proptest::test_runner::RngSeed::Fixed(0x5eed_0105), ..Default::default() })]
    #[test]
    fn random_maps_are_covered(
        w in 5usize..=60,
        h in 5usize..=60,
        density in 0.0f64..0.35,
        seed in proptest::prelude::any::<u64>(),
        heading in 0usize..4,
    ) {
        if let Some((art, c, r)) = random_art(w, h, density, seed) {
            check_run(&art, c, r, heading as f64 * FRAC_PI_2);
        }
    }
}

#[test]
fn block_room_with_checks() {
    let art = "\
        ..........\n\
        ..........\n\
        ...####...\n\
        ...####...\n\
        ...####...\n\
        ..........\n\
        ..........";
    check_run(art, 0, 6, FRAC_PI_2);
    check_run(art, 5, 0, 0.0);
}

// ---------------------------------------------------------------------------------------------
// Online honesty.

fn flip_unseen(wd: &World, p: &BaStar) -> World {
    let known = p.known_map().unwrap();
    let mut m = wd.map().clone();
    let f = *m.frame();
    for row in 0..f.height {
        for col in 0..f.width {
            if !known.is_seen(col, row) {
                let v = if m.get(col, row).is_free() {
                    Cell::Occupied
                } else {
                    Cell::Free
                };
                m.set(col, row, v);
            }
        }
    }
    World::new(m, wd.robot(), Some(wd.start())).unwrap()
}

#[test]
fn trace_ignores_pixels_never_sensed() {
    for seed in 0..6u64 {
        let (art, c, r) = random_art(24, 18, 0.25, seed).unwrap();
        // A sealed-off part behind a wall thicker than the sensor range.
        let art: String = art
            .lines()
            .enumerate()
            .map(|(i, l)| format!("{l}#####{}", if i % 3 == 0 { "..#.." } else { "....." }))
            .collect::<Vec<_>>()
            .join("\n");
        let wd = world(&art, c, r, 0.0);
        let (out, _, p) = run(&wd, BaStarOptions::default());
        let flipped = flip_unseen(&wd, &p);
        let unseen = p.known_map().unwrap().seen().count_zeroes(..);
        assert!(unseen > 0);
        let (out2, m2, _) = run(&flipped, BaStarOptions::default());
        assert_eq!(out.trace, out2.trace, "seed {seed}");
        assert_eq!(m2.collisions, 0);
    }
}

#[test]
fn smoothing_off_follows_the_raw_path() {
    let art = "\
        ..............\n\
        ..##......##..\n\
        ..##..##..##..\n\
        ......##......\n\
        ..............";
    let wd = world(art, 0, 4, FRAC_PI_2);
    let opts = BaStarOptions {
        smoothing: false,
        ..Default::default()
    };
    let (out, m, _) = run(&wd, opts);
    assert_eq!(m.coverage_rate, Some(1.0));
    let mut any = false;
    let mut raw = None;
    for (_, e) in out.trace.events() {
        match e {
            Event::PathRaw { points } => raw = Some(points.clone()),
            Event::PathSmoothed { points } => {
                assert_eq!(Some(points), raw.as_ref());
                any = true;
            }
            _ => {}
        }
    }
    assert!(any);
    let (_, ms, _) = run(&wd, BaStarOptions::default());
    assert!(ms.backtrack_length_m <= m.backtrack_length_m + 1e-9);
}

// ---------------------------------------------------------------------------------------------
// The three-valued motion judgement agrees with the known map's own checks.

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 48, rng_seed: proptest::test_runner::RngSeed::Fixed(0x5eed_0106), ..Default::default() })]
    #[test]
    fn judge_motion_matches_known_map(
        seed in proptest::prelude::any::<u64>(),
        r_px in 1.0f64..6.0,
        range_px in 4.0f64..30.0,
    ) {
        use ccpp_core::planner::{KnownMap, Scan};
        use ccpp_core::planners::ba_star::{judge_motion, Judgement};
        let mut rng = ccpp_core::rng::SplitMix64::new(seed);
        let (w, h) = (48usize, 40usize);
        let res = 0.05;
        let mut cells = vec![Cell::Free; w * h];
        for c in &mut cells {
            let u = rng.next_f64();
            if u < 0.04 {
                *c = Cell::Occupied;
            } else if u < 0.05 {
                *c = Cell::Unknown;
            }
        }
        let truth = GridMap::new(ccpp_core::grid::MapFrame::new(w, h, res), cells).unwrap();
        let mut known = KnownMap::new(truth.frame());
        for _ in 0..3 {
            let c = Point::new(rng.range(0.0, w as f64 * res), rng.range(0.0, h as f64 * res));
            known.integrate(&Scan::new(&truth, c, range_px * res));
        }
        // Optimistic map: unseen pixels free.
        let mut opt = truth.clone();
        for row in 0..h {
            for col in 0..w {
                if !known.is_seen(col, row) {
                    opt.set(col, row, Cell::Free);
                }
            }
        }
        let r = r_px * res;
        for _ in 0..40 {
            let a = Point::new(rng.range(-0.2, w as f64 * res + 0.2), rng.range(-0.2, h as f64 * res + 0.2));
            let b = if rng.next_f64() < 0.3 {
                a
            } else {
                Point::new(a.x + rng.range(-1.0, 1.0), a.y + rng.range(-1.0, 1.0))
            };
            let j = judge_motion(&known, a, b, r);
            let pess = if a == b { known.disk_free(a, r) } else { known.segment_free(a, b, r) };
            let f = *truth.frame();
            let opt_blocked = ccpp_core::collide::segment_first_contact(
                &opt, f.world_to_grid(a), f.world_to_grid(b), r / res).is_some();
            proptest::prop_assert_eq!(j == Judgement::Free, pess, "{:?} {:?}", a, b);
            proptest::prop_assert_eq!(j == Judgement::Blocked, opt_blocked, "{:?} {:?}", a, b);
        }
    }

    /// Moves between pixel centres, the tile centres of tiles one pixel (or a few) wide, put
    /// the pixels at exactly `r + 1/2` from the ends, which never touch, at the edge of
    /// `judge_motion`'s fast path: its verdict must still be the known map's.
    #[test]
    fn judge_motion_matches_known_map_between_pixel_centres(
        seed in proptest::prelude::any::<u64>(),
        half_px in 1u32..6,
    ) {
        use ccpp_core::planner::{KnownMap, Scan};
        use ccpp_core::planners::ba_star::{judge_motion, Judgement};
        let mut rng = ccpp_core::rng::SplitMix64::new(seed);
        let (w, h) = (24usize, 20usize);
        let res = 0.05;
        let mut cells = vec![Cell::Free; w * h];
        for c in &mut cells {
            if rng.next_f64() < 0.08 {
                *c = Cell::Occupied;
            }
        }
        let truth = GridMap::new(ccpp_core::grid::MapFrame::new(w, h, res), cells).unwrap();
        let mut known = KnownMap::new(truth.frame());
        known.integrate(&Scan::new(&truth, Point::new(0.6, 0.5), 2.0));
        // Robot radius r = half_px / 2 pixels: tiles of side 2 r are `half_px` pixels wide.
        let r = f64::from(half_px) * 0.5 * res;
        let centre = |col: usize, row: usize| {
            Point::new((col as f64 + 0.5) * res, (h as f64 - row as f64 - 0.5) * res)
        };
        for _ in 0..60 {
            let (col, row) = ((rng.next_u64() % w as u64) as usize, (rng.next_u64() % h as u64) as usize);
            let a = centre(col, row);
            for (di, dj) in N8 {
                let steps = 1 + (rng.next_u64() % 3) as i32;
                let (c2, r2) = (col as i32 + di * steps, row as i32 - dj * steps);
                if c2 < 0 || r2 < 0 || c2 >= w as i32 || r2 >= h as i32 {
                    continue;
                }
                let b = centre(c2 as usize, r2 as usize);
                let j = judge_motion(&known, a, b, r);
                let free = known.segment_free(a, b, r);
                proptest::prop_assert_eq!(j == Judgement::Free, free, "{:?} {:?} r {}", a, b, r);
            }
        }
    }

    #[test]
    fn astar_cost_equals_dijkstra(seed in proptest::prelude::any::<u64>()) {
        let mut rng = ccpp_core::rng::SplitMix64::new(seed);
        let mut covered = Vec::new();
        for j in 0..=8 {
            for i in 0..=8 {
                if rng.next_f64() < 0.7 {
                    covered.push((i, j));
                }
            }
        }
        let g = Grid { covered: covered.clone() };
        let mut s = TileSearch::new(g.bounds());
        let from = covered[0];
        for &to in &covered {
            let d = s.nearest(&g, from, |t| t == to).map(|x| x.1);
            let a = s.astar(&g, from, to);
            proptest::prop_assert_eq!(d, a.as_ref().map(|x| x.1));
            if let Some((p, _)) = a {
                proptest::prop_assert_eq!(p[0], from);
                proptest::prop_assert_eq!(*p.last().unwrap(), to);
            }
        }
    }
}

/// Proptest counterexample (w 40, h 50, density 0.177, seed 16331919354862280521): a lane ends
/// at walls on both sides next to an uncovered lane that runs past both ends, so no diagonal is
/// blocked and the paper's six pairs never put it in L.
#[test]
fn lane_end_extension_completes_the_paper_mu() {
    let (art, c, r) =
        random_art(40, 50, 0.177_443_441_716_639_53, 16_331_919_354_862_280_521).unwrap();
    let wd = world(&art, c, r, 0.0);
    let paper = BaStarOptions {
        lane_end_corners: false,
        ..Default::default()
    };
    let (_, m, p) = run(&wd, paper);
    assert!(m.coverage_rate.unwrap() < 1.0);
    assert!(p.frontier_without_candidates());
    check_run(&art, c, r, 0.0);
}

/// Proptest counterexample (w 37, h 38, density 0.211, seed 2993061010301113817): the start
/// tile sits between two walls; BM goes north first and leaves its free south neighbour, whose
/// diagonals are free, so the paper's pairs never see it.
#[test]
fn start_tile_south_neighbour_is_a_candidate() {
    let (art, c, r) =
        random_art(37, 38, 0.211_171_978_379_263_02, 2_993_061_010_301_113_817).unwrap();
    let wd = world(&art, c, r, 0.0);
    let paper = BaStarOptions {
        lane_end_corners: false,
        ..Default::default()
    };
    let (_, m, p) = run(&wd, paper);
    assert!(m.coverage_rate.unwrap() < 1.0);
    assert!(p.frontier_without_candidates());
    check_run(&art, c, r, 0.0);
    // The smallest form: a start in a 1-wide N-S corridor, in the middle.
    let art = "#.#\n#.#\n#.#\n#.#\n#.#";
    check_run(art, 1, 2, 0.0);
}

/// Covered tiles like BA*'s late in a run on a cluttered map: a rectangle at a pseudo-random
/// offset (negative corners, sides not multiples of the search's storage blocks), thin walls
/// with gaps, salt noise, and some one-way blocked moves; every fourth seed an open rectangle
/// (all moves free), where many tiles share the cost of the nearest target (ties).
struct Clutter {
    i0: i32,
    j0: i32,
    w: i32,
    h: i32,
    covered: Vec<bool>,
    seed: u64,
}

impl Clutter {
    fn new(seed: u64) -> Self {
        let mut x = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let (w, h) = (29 + (next() % 40) as i32, 23 + (next() % 40) as i32);
        let (i0, j0) = (-((next() % 17) as i32), -((next() % 13) as i32));
        let open = seed % 4 == 3;
        let noise = if open { 0 } else { 6 };
        let mut covered: Vec<bool> = (0..w * h).map(|_| next() % 100 >= noise).collect();
        // Thin walls, a row or a column each, with a gap or two.
        for _ in 0..if open { 0 } else { 4 } {
            let vertical = next() % 2 == 0;
            let at = (next() % 1000) as i32;
            let gap = (next() % 1000) as i32;
            let n = if vertical { h } else { w };
            for s in 0..n {
                if (s - gap % n).abs() <= 1 || s == (gap * 7) % n {
                    continue;
                }
                let (i, j) = if vertical { (at % w, s) } else { (s, at % h) };
                covered[(j * w + i) as usize] = false;
            }
        }
        Self {
            i0,
            j0,
            w,
            h,
            covered,
            seed,
        }
    }

    fn tiles(&self) -> Vec<Tile> {
        (0..self.w * self.h)
            .map(|k| (self.i0 + k % self.w, self.j0 + k / self.w))
            .filter(|&t| self.covered(t))
            .collect()
    }

    /// The row-major index of `t` in the bounds (the searches' tie-break order).
    fn index(&self, t: Tile) -> usize {
        ((t.1 - self.j0) * self.w + t.0 - self.i0) as usize
    }
}

impl TileGraph for Clutter {
    fn bounds(&self) -> (i32, i32, i32, i32) {
        (self.i0, self.i0 + self.w - 1, self.j0, self.j0 + self.h - 1)
    }
    fn covered(&self, t: Tile) -> bool {
        let (i, j) = (t.0 - self.i0, t.1 - self.j0);
        (0..self.w).contains(&i)
            && (0..self.h).contains(&j)
            && self.covered[(j * self.w + i) as usize]
    }
    fn move_free(&self, t: Tile, k: usize) -> bool {
        self.seed % 4 == 3 || (t.0 * 5 + t.1 * 11 + k as i32 + self.seed as i32).rem_euclid(23) != 0
    }
}

/// A plain best-first search written independently of [`TileSearch`] (a binary heap of
/// `(key, row-major index)`, labels in a vector, parent set on a strict improvement): with
/// `goal`, A* with the Euclidean heuristic to it; without, Dijkstra stopping at the first
/// settled tile with `is_target`. Returns the tile, its cost and the path to it.
fn reference_search(
    g: &Clutter,
    from: Tile,
    goal: Option<Tile>,
    is_target: impl Fn(Tile) -> bool,
) -> Option<(Tile, u64, Vec<Tile>)> {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    let n = (g.w * g.h) as usize;
    let tile = |k: usize| {
        (
            g.i0 + (k % g.w as usize) as i32,
            g.j0 + (k / g.w as usize) as i32,
        )
    };
    let h = |t: Tile| goal.map_or(0, |gl| ccpp_core::planners::ba_star::heuristic(t, gl));
    let mut dist = vec![u64::MAX; n];
    let mut parent = vec![usize::MAX; n];
    let mut done = vec![false; n];
    let s = g.index(from);
    dist[s] = 0;
    let mut heap = BinaryHeap::new();
    heap.push(Reverse((h(from), s)));
    while let Some(Reverse((_, k))) = heap.pop() {
        if done[k] {
            continue;
        }
        done[k] = true;
        let t = tile(k);
        if goal.map_or_else(|| is_target(t), |gl| gl == t) {
            let mut path = vec![t];
            let mut c = k;
            while parent[c] != usize::MAX {
                c = parent[c];
                path.push(tile(c));
            }
            path.reverse();
            return Some((t, dist[k], path));
        }
        for (m, &(di, dj)) in N8.iter().enumerate() {
            if !ccpp_core::planners::ba_star::graph_edge(g, t, m) {
                continue;
            }
            let v = (t.0 + di, t.1 + dj);
            let kv = g.index(v);
            let nd = dist[k] + if m % 2 == 1 { COST_DIAG } else { COST_ORTHO };
            if !done[kv] && nd < dist[kv] {
                dist[kv] = nd;
                parent[kv] = k;
                heap.push(Reverse((nd + h(v), kv)));
            }
        }
    }
    None
}

/// Every search of [`TileSearch`] answers as the independent [`reference_search`], over
/// many searches on one scratch (generations and storage blocks reused), sparse and dense
/// target sets, maps at pseudo-random offsets with thin walls and noise. (Seed 29 catches a
/// `nearest_of` that drops labels at the key of the target found first.)
#[test]
fn tile_searches_answer_as_an_independent_search() {
    let (mut found, mut paths) = (0, 0);
    for seed in 0..64u64 {
        let g = Clutter::new(seed);
        let tiles = g.tiles();
        let mut s = TileSearch::new(g.bounds());
        let mut x = seed | 0x51;
        for round in 0..20 {
            x = x
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let every = [1, 3, 17, 97, 400][round % 5];
            let from = tiles[(x >> 20) as usize % tiles.len()];
            let targets: Vec<Tile> = if round % 3 == 2 {
                // Targets on a square or diamond around the source: many at the same cost.
                let r = 2 + (x >> 50) as i32 % 9;
                tiles
                    .iter()
                    .copied()
                    .filter(|&(i, j)| {
                        let (a, b) = ((i - from.0).abs(), (j - from.1).abs());
                        (a.max(b) == r || a + b == r + 3) && (i + 2 * j) % 3 != 0
                    })
                    .collect()
            } else {
                tiles
                    .iter()
                    .copied()
                    .skip((x >> 40) as usize % 11)
                    .step_by(every)
                    .collect()
            };
            let is_target = |t: Tile| targets.contains(&t);
            let want = reference_search(&g, from, None, is_target).map(|(t, c, _)| (t, c));
            assert_eq!(
                s.nearest(&g, from, is_target),
                want,
                "seed {seed} round {round}"
            );
            let got = s.nearest_of(&g, from, &targets, is_target);
            assert_eq!(got, want, "seed {seed} round {round}");
            if let Some((t, c)) = got {
                found += 1;
                let (_, rc, rpath) = reference_search(&g, from, Some(t), |_| false).unwrap();
                assert_eq!(rc, c);
                assert_eq!(
                    s.astar_nearest(&g, from, t, c),
                    Some((rpath.clone(), c)),
                    "seed {seed} round {round}"
                );
                assert_eq!(s.astar(&g, from, t), Some((rpath, c)));
            }
            // A path to an arbitrary tile (often through the walls' gaps, or unreachable).
            let to = tiles[(x >> 8) as usize % tiles.len()];
            let want = reference_search(&g, from, Some(to), |_| false).map(|(_, c, p)| (p, c));
            paths += usize::from(want.is_some());
            assert_eq!(s.astar(&g, from, to), want, "seed {seed} round {round}");
        }
    }
    assert!(found > 300 && paths > 300, "{found} {paths}");
}

/// BA*'s sensor is set to see a neighbour tile's contact disk (side + r + half a pixel), but
/// its own check at the start asked side + r + a whole pixel: every run at the default range
/// wrote a note that "some moves may stay undecided" into its trace, which its coverage denied.
#[test]
fn the_default_sensor_range_writes_no_note_of_undecided_moves() {
    let w = world(&room(6, 4), 0, 0, 0.0);
    // The range the command line gives BA* (its settings' sensor range).
    let sim = SimConfig {
        sensor_range: Some(SIDE + R + 0.5 * 0.01),
        ..SimConfig::default()
    };
    let out = simulate(&w, &mut BaStar::new(BaStarOptions::default()), &sim);
    let m = compute(&w, &out, "test");
    assert_eq!(m.coverage_rate, Some(1.0));
    let notes: Vec<String> = out
        .trace
        .events()
        .filter_map(|(_, e)| match e {
            Event::Note { text } => Some(text.clone()),
            _ => None,
        })
        .collect();
    assert!(notes.is_empty(), "{notes:?}");
}
