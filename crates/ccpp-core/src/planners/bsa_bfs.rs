//! `bsa-bfs`: the vacuum-robot BSA variant with BFS return (seed 003), online.
//!
//! Seed 003 adapts BSA (González, Álvarez, Díaz, Parra & Bustacara, "BSA: a complete coverage
//! algorithm", ICRA 2005) to a vacuum robot: the floor is split into cells, and a state machine
//!
//! * **PLAN** enters a cell and marks it visited; its free unvisited 4-neighbours, taken in the
//!   order `+x, +y, -x, -y` of cell indices, give the next cell (the first) and **return cells**
//!   (the others, pushed on a stack);
//! * at a dead end (a *critical* cell) pops return cells until an unvisited one and switches to
//!   **`BFS_PLAN`**: a breadth-first search over visited cells from the critical cell to it, whose
//!   path is spliced into the plan;
//! * **MOVE** executes the plan cell to cell with linear and angular PID controllers;
//! * **FINISHED** when no return cell is left.
//!
//! Here the planner is **online**: it decides one cell at a time from what its sensor has shown
//! (a [`KnownMap`]); MOVE is the simulator's PID execution of the `MoveTo` waypoints (this
//! planner's [`preferred_execution`](Planner::preferred_execution) is
//! [`Execution::Pid`] unless its options say otherwise). Cells have side `cell_side_m`
//! (default `2 r`) and are anchored so that the start is a cell centre. A neighbour is free when
//! the robot can stand at its centre and the straight move between the centres is free, both
//! judged on sensed pixels only. Return paths are merged into straight runs of collinear cells.
//!
//! Seed 003 also grows obstacles by an erosion kernel before planning: that is
//! [`crate::inflate::inflate`] (`--inflate`), and its pixel <-> world affine fit is
//! [`crate::georef::fit_affine`].
//!
//! Trace marks: `region_start` / `region_end` around each exploration run, `critical_point` at
//! dead ends, `backtrack_point` for each return cell pushed, `backtrack_start` / `path_raw` /
//! `backtrack_end` around each BFS return.
//!
//! ```
//! use ccpp_core::GridMap;
//! use ccpp_core::world::{Robot, World};
//! use ccpp_core::planners::bsa_bfs::{BsaBfs, BsaBfsOptions};
//! use ccpp_core::sim::{simulate, SimConfig};
//! let map = GridMap::from_ascii_scaled(
//!     "##########\n#........#\n#..##....#\n#..##....#\n#........#\n##########", 6, 0.05,
//! ).unwrap();
//! let world = World::new(map, Robot::new(0.15), None).unwrap();
//! let mut p = BsaBfs::new(BsaBfsOptions::default());
//! let out = simulate(&world, &mut p, &SimConfig::default()); // PID execution by default
//! let m = ccpp_core::metrics::compute(&world, &out, "room");
//! assert_eq!(m.coverage_rate, Some(1.0));
//! assert_eq!(m.collisions, 0);
//! assert!(m.tracking_error_max_m.unwrap() < 0.01);
//! ```

use std::collections::VecDeque;

use serde::{Deserialize, Serialize};

use crate::exec::{Execution, PidOptions};
use crate::geometry::Point;
use crate::planner::{KnownMap, Planner, Sensor, Step};
use crate::search::SearchSpace;
use crate::trace::Event;

/// Options of [`BsaBfs`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BsaBfsOptions {
    /// Cell side in metres; `None` = `2 r`. The sensor range must reach a neighbour's disk
    /// (`cell side + r + 1 px`), or neighbours read as blocked.
    pub cell_side_m: Option<f64>,
    /// Extra clearance (metres) the planner demands beyond the robot radius when it judges a
    /// cell or a move free. 0 plans exactly like the `coverage_rate` ground truth.
    pub clearance_margin_m: f64,
    /// The execution this planner asks the simulator for (seed 003: PID).
    pub exec: Execution,
}

impl Default for BsaBfsOptions {
    fn default() -> Self {
        Self {
            cell_side_m: None,
            clearance_margin_m: 0.0,
            exec: Execution::Pid(PidOptions::default()),
        }
    }
}

/// The planner's state (seed 003's states; MOVE is the queue of pending steps).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum State {
    /// Choosing the next cell.
    Plan,
    /// Planning a return path (transient inside one decision).
    BfsPlan,
    /// Executing queued steps.
    Move,
    /// Done.
    Finished,
}

/// Dense cell storage over the map's extent.
struct Cells {
    anchor: Point,
    side: f64,
    i0: i32,
    j0: i32,
    w: i32,
    h: i32,
}

impl Cells {
    fn idx(&self, c: (i32, i32)) -> Option<usize> {
        let (di, dj) = (c.0 - self.i0, c.1 - self.j0);
        (di >= 0 && dj >= 0 && di < self.w && dj < self.h).then(|| (dj * self.w + di) as usize)
    }
    fn center(&self, c: (i32, i32)) -> Point {
        Point::new(
            self.anchor.x + f64::from(c.0) * self.side,
            self.anchor.y + f64::from(c.1) * self.side,
        )
    }
    fn len(&self) -> usize {
        (self.w * self.h) as usize
    }
}

/// 4-neighbour order of seed 003: `+x, +y, -x, -y`.
pub const ORDER: [(i32, i32); 4] = [(1, 0), (0, 1), (-1, 0), (0, -1)];

/// The BSA-with-BFS-return planner.
pub struct BsaBfs {
    opts: BsaBfsOptions,
    cells: Option<Cells>,
    known: Option<KnownMap>,
    visited: Vec<bool>,
    pushed: Vec<bool>,
    /// Cached standability: 0 unknown, 1 free, 2 blocked.
    stand: Vec<u8>,
    /// Cached move freeness towards +x and +y: 0 unknown, 1 free, 2 blocked.
    edge: Vec<[u8; 2]>,
    return_cells: Vec<(i32, i32)>,
    /// Reusable BFS buffers over the cells.
    search: SearchSpace<u32>,
    cur: (i32, i32),
    queue: VecDeque<Step>,
    state: State,
    region: u32,
    r: f64,
}

impl BsaBfs {
    /// A planner with these options.
    pub fn new(opts: BsaBfsOptions) -> Self {
        Self {
            opts,
            cells: None,
            known: None,
            visited: Vec::new(),
            pushed: Vec::new(),
            stand: Vec::new(),
            edge: Vec::new(),
            return_cells: Vec::new(),
            search: SearchSpace::default(),
            cur: (0, 0),
            queue: VecDeque::new(),
            state: State::Plan,
            region: 0,
            r: 0.0,
        }
    }

    /// The current state.
    pub fn state(&self) -> State {
        self.state
    }

    fn init(&mut self, sensor: &dyn Sensor) {
        let f = *sensor.frame();
        let r = sensor.robot().radius;
        self.r = r + self.opts.clearance_margin_m.max(0.0);
        let side = self.opts.cell_side_m.unwrap_or(2.0 * r);
        let anchor = sensor.pose().position();
        let (lo, hi) = f.world_bounds();
        let i0 = ((lo.x - anchor.x) / side).floor() as i32 - 1;
        let i1 = ((hi.x - anchor.x) / side).ceil() as i32 + 1;
        let j0 = ((lo.y - anchor.y) / side).floor() as i32 - 1;
        let j1 = ((hi.y - anchor.y) / side).ceil() as i32 + 1;
        let cells = Cells {
            anchor,
            side,
            i0,
            j0,
            w: i1 - i0 + 1,
            h: j1 - j0 + 1,
        };
        let n = cells.len();
        self.visited = vec![false; n];
        self.pushed = vec![false; n];
        self.stand = vec![0; n];
        self.edge = vec![[0; 2]; n];
        self.search = SearchSpace::new(n);
        self.known = Some(KnownMap::new(&f));
        self.cur = (0, 0);
        if let Some(k) = cells.idx((0, 0)) {
            self.visited[k] = true;
        }
        self.cells = Some(cells);
    }

    fn standable(&mut self, c: (i32, i32)) -> bool {
        let (Some(cells), Some(known)) = (&self.cells, &self.known) else {
            return false;
        };
        let Some(k) = cells.idx(c) else { return false };
        if self.stand[k] == 0 {
            self.stand[k] = if known.disk_free(cells.center(c), self.r) {
                1
            } else {
                2
            };
        }
        self.stand[k] == 1
    }

    /// Is the move between 4-adjacent cells `a` and `b` free (cached once computed)?
    fn move_free(&mut self, a: (i32, i32), b: (i32, i32)) -> bool {
        if !self.standable(a) || !self.standable(b) {
            return false;
        }
        let (Some(cells), Some(known)) = (&self.cells, &self.known) else {
            return false;
        };
        let (lo, dir) = match (b.0 - a.0, b.1 - a.1) {
            (1, 0) => (a, 0),
            (-1, 0) => (b, 0),
            (0, 1) => (a, 1),
            (0, -1) => (b, 1),
            _ => return false,
        };
        let Some(k) = cells.idx(lo) else { return false };
        if self.edge[k][dir] == 0 {
            self.edge[k][dir] = if known.segment_free(cells.center(a), cells.center(b), self.r) {
                1
            } else {
                2
            };
        }
        self.edge[k][dir] == 1
    }

    fn is_visited(&self, c: (i32, i32)) -> bool {
        self.cells
            .as_ref()
            .and_then(|g| g.idx(c))
            .is_some_and(|k| self.visited[k])
    }

    fn set_visited(&mut self, c: (i32, i32)) {
        if let Some(k) = self.cells.as_ref().and_then(|g| g.idx(c)) {
            self.visited[k] = true;
        }
    }

    fn center(&self, c: (i32, i32)) -> Point {
        self.cells
            .as_ref()
            .map_or(Point::default(), |g| g.center(c))
    }

    /// BFS over visited cells (plus the target) from `self.cur` to `target`, neighbours in
    /// [`ORDER`] (first discovery is the parent); returns the cell path including both ends.
    fn bfs(&mut self, target: (i32, i32)) -> Option<Vec<(i32, i32)>> {
        let g = self.cells.as_ref()?;
        let (i0, j0, w) = (g.i0, g.j0, g.w);
        let start = g.idx(self.cur)? as u32;
        self.search.begin();
        self.search.push_fifo_source(start);
        while let Some((k, _)) = self.search.pop_fifo() {
            let c = (i0 + k as i32 % w, j0 + k as i32 / w);
            if c == target {
                let path = self.search.path_to(k);
                return Some(
                    path.iter()
                        .map(|&k| (i0 + k as i32 % w, j0 + k as i32 / w))
                        .collect(),
                );
            }
            for (di, dj) in ORDER {
                let nb = (c.0 + di, c.1 + dj);
                let Some(kn) = self.cells.as_ref().and_then(|g| g.idx(nb)) else {
                    continue;
                };
                if self.search.is_reached(kn as u32) || !(self.visited[kn] || nb == target) {
                    continue;
                }
                if self.move_free(c, nb) {
                    self.search.discover(k, kn as u32);
                }
            }
        }
        None
    }

    /// One PLAN decision at the current cell (after a fresh scan).
    fn plan(&mut self) {
        let cur = self.cur;
        let mut free = Vec::with_capacity(4);
        for (di, dj) in ORDER {
            let n = (cur.0 + di, cur.1 + dj);
            if !self.is_visited(n) && self.move_free(cur, n) {
                free.push(n);
            }
        }
        if let Some(&next) = free.first() {
            for &n in &free[1..] {
                let k = self.cells.as_ref().and_then(|g| g.idx(n));
                if let Some(k) = k {
                    if !self.pushed[k] {
                        self.pushed[k] = true;
                        self.return_cells.push(n);
                        let p = self.center(n);
                        self.queue
                            .push_back(Step::Mark(Event::BacktrackPoint { x: p.x, y: p.y }));
                    }
                }
            }
            self.set_visited(next);
            self.cur = next;
            self.queue.push_back(Step::MoveTo(self.center(next)));
            return;
        }
        // Critical cell.
        let p = self.center(cur);
        self.queue
            .push_back(Step::Mark(Event::CriticalPoint { x: p.x, y: p.y }));
        self.queue.push_back(Step::Mark(Event::RegionEnd {
            region: self.region,
        }));
        self.state = State::BfsPlan;
        while let Some(ret) = self.return_cells.pop() {
            if self.is_visited(ret) {
                continue;
            }
            let Some(path) = self.bfs(ret) else {
                self.queue.push_back(Step::Mark(Event::Note {
                    text: format!("return cell {ret:?} unreachable over visited cells"),
                }));
                continue;
            };
            let pts: Vec<Point> = path.iter().map(|&c| self.center(c)).collect();
            let s = self.center(ret);
            self.queue
                .push_back(Step::Mark(Event::StartPoint { x: s.x, y: s.y }));
            self.queue.push_back(Step::Mark(Event::BacktrackStart));
            self.queue.push_back(Step::Mark(Event::PathRaw {
                points: pts.iter().map(|p| [p.x, p.y]).collect(),
            }));
            // Splice: straight runs of collinear cells become one move; the last move enters
            // the return cell and starts the next region.
            let n = path.len();
            for k in 1..n - 1 {
                let d0 = (path[k].0 - path[k - 1].0, path[k].1 - path[k - 1].1);
                let d1 = (path[k + 1].0 - path[k].0, path[k + 1].1 - path[k].1);
                if d0 != d1 || k + 1 == n - 1 {
                    self.queue.push_back(Step::MoveTo(pts[k]));
                }
            }
            self.queue.push_back(Step::Mark(Event::BacktrackEnd));
            self.region += 1;
            self.queue.push_back(Step::Mark(Event::RegionStart {
                region: self.region,
            }));
            self.queue.push_back(Step::MoveTo(pts[n - 1]));
            self.set_visited(ret);
            self.cur = ret;
            self.state = State::Move;
            return;
        }
        self.state = State::Finished;
    }
}

impl Planner for BsaBfs {
    fn name(&self) -> &'static str {
        "bsa-bfs"
    }

    fn tile_side(&self) -> Option<f64> {
        self.cells
            .as_ref()
            .map(|c| c.side)
            .or(self.opts.cell_side_m)
    }

    fn preferred_execution(&self) -> Option<Execution> {
        Some(self.opts.exec)
    }

    fn next(&mut self, sensor: &dyn Sensor) -> Step {
        if self.cells.is_none() {
            self.init(sensor);
            self.region = 1;
            self.queue
                .push_back(Step::Mark(Event::RegionStart { region: 1 }));
        }
        loop {
            if let Some(s) = self.queue.pop_front() {
                return s;
            }
            if self.state == State::Finished {
                return Step::Done;
            }
            // The robot is at `cur` (the last queued step was the move there): sense, plan.
            if let Some(k) = self.known.as_mut() {
                k.integrate(&sensor.scan());
            }
            self.state = State::Plan;
            self.plan();
            if self.state == State::Plan {
                self.state = State::Move;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridMap;
    use crate::metrics::compute;
    use crate::sim::{simulate, SimConfig};
    use crate::world::{Robot, World};
    use proptest::prelude::*;

    fn run(art: &str, scale: usize, exec: Option<Execution>) -> crate::metrics::Metrics {
        let map = GridMap::from_ascii_scaled(art, scale, 0.05).unwrap();
        let world = World::new(map, Robot::new(0.15), None).unwrap();
        let mut p = BsaBfs::new(BsaBfsOptions::default());
        let cfg = SimConfig {
            exec,
            ..SimConfig::default()
        };
        let out = simulate(&world, &mut p, &cfg);
        assert_eq!(out.stop, crate::sim::StopReason::Done);
        compute(&world, &out, "t")
    }

    const EMPTY: &str = "
        ############
        #..........#
        #..........#
        #..........#
        #..........#
        #..........#
        ############";
    const BLOCKS: &str = "
        ##############
        #............#
        #..##....#...#
        #..##....#...#
        #............#
        #.....###....#
        #............#
        ##############";
    const TWO_ROOMS: &str = "
        ###############
        #......#......#
        #......#......#
        #.............#
        #......#......#
        #......#......#
        ###############";

    #[test]
    fn ascii_maps_full_coverage_no_collision_under_pid() {
        for (art, name) in [
            (EMPTY, "empty"),
            (BLOCKS, "blocks"),
            (TWO_ROOMS, "two rooms"),
        ] {
            let m = run(art, 10, None);
            assert_eq!(m.coverage_rate, Some(1.0), "{name}: {m:?}");
            assert_eq!(m.collisions, 0, "{name}");
            let te = m.tracking_error_max_m.expect("pid run");
            assert!(te < 0.006, "{name}: tracking {te}");
            // And ideally executed, the same plan.
            assert!(m.effective_coverage > 0.6, "{name}: {m:?}");
            let m = run(art, 10, Some(Execution::Ideal));
            assert_eq!(m.coverage_rate, Some(1.0), "{name} ideal");
            assert_eq!(m.collisions, 0);
            assert_eq!(m.tracking_error_max_m, None);
        }
    }

    #[test]
    fn two_rooms_needs_a_return() {
        let m = run(TWO_ROOMS, 10, Some(Execution::Ideal));
        assert!(m.regions >= 2, "{m:?}");
        assert_eq!(m.backtracks + 1, m.regions);
        assert!(m.backtrack_length_m > 0.0);
    }

    #[test]
    fn expansion_order_is_plus_x_first() {
        // From the start, the first move goes +x.
        let map = GridMap::from_ascii_scaled(EMPTY, 10, 0.05).unwrap();
        let world = World::new(map, Robot::new(0.15), None).unwrap();
        let mut p = BsaBfs::new(BsaBfsOptions::default());
        let out = simulate(
            &world,
            &mut p,
            &SimConfig {
                exec: Some(Execution::Ideal),
                ..SimConfig::default()
            },
        );
        let poses: Vec<_> = out.trace.poses().collect();
        let s = world.start();
        let first_move = poses.iter().find(|q| q.position() != s.position()).unwrap();
        assert!((first_move.x - (s.x + 0.3)).abs() < 1e-9 && (first_move.y - s.y).abs() < 1e-9);
    }

    fn random_map(seed: u64, w: usize, h: usize, density: f64) -> String {
        let mut rng = crate::rng::SplitMix64::new(seed);
        let mut s = String::new();
        for r in 0..h {
            for c in 0..w {
                let border = r == 0 || c == 0 || r == h - 1 || c == w - 1;
                s.push(if border || rng.next_f64() < density {
                    '#'
                } else {
                    '.'
                });
            }
            s.push('\n');
        }
        s
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 12, rng_seed: proptest::test_runner::RngSeed::Fixed(0x5eed_0104), ..ProptestConfig::default() })]
        #[test]
        fn random_maps_cover_everything_without_collision(
            seed in any::<u64>(), w in 6usize..14, h in 6usize..12, density in 0.0f64..0.25
        ) {
            let art = random_map(seed, w, h, density);
            let map = GridMap::from_ascii_scaled(&art, 5, 0.05).unwrap();
            let Ok(world) = World::new(map, Robot::new(0.15), None) else { return Err(TestCaseError::reject("the robot fits nowhere")) };
            let mut p = BsaBfs::new(BsaBfsOptions::default());
            let out = simulate(&world, &mut p, &SimConfig::default());
            let m = compute(&world, &out, "random");
            prop_assert_eq!(m.coverage_rate, Some(1.0), "{}", art);
            prop_assert_eq!(m.collisions, 0, "{}", art);
        }
    }
}
