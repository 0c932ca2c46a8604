//! BSA: the Backtracking Spiral Algorithm (basic version), an online coverage planner on cells
//! of the robot's size.
//!
//! Source: E. González, O. Álvarez, Y. Díaz, C. Parra, C. Bustacara, "BSA: a complete coverage
//! algorithm", ICRA 2005 (seeds 002/004), which summarises the basic algorithm of González,
//! Alarcón, Aristizábal and Parra (IROS 2003). The extended version that also covers partially
//! occupied cells, [`super::bsa_extended`], drives this planner as a host of the generic
//! coverage extension ([`super::extension`]) through a few hooks ([`Bsa::observe`],
//! [`Bsa::will_cover`], [`Bsa::transfer`], [`Bsa::replace_transfer`]).
//!
//! # The algorithm as implemented
//!
//! * **Cells**: squares of side `2 r` anchored at the start position (the same tiling as
//!   [`crate::tiles::TileGrid`], so `coverage_rate` is measured on these cells). A neighbour cell
//!   is *free* when the robot can stand at its centre and move straight to it from the current
//!   cell's centre, as far as the robot knows ([`KnownMap`]: only sensed pixels, unseen pixels
//!   block). With the default sensor range `4 r` every pixel these checks read has been sensed,
//!   so the answer is final and is cached per cell edge.
//! * **Spiral filling** relative to the reference lateral side RLS ([`Side`], default left; OLS
//!   is the other one). Visited cells are virtual obstacles. At each cell the rules are applied
//!   in order: **RS1** all four neighbours blocked: the spiral ends; **RS2** the RLS neighbour is
//!   free: turn to the RLS and move forward; **RS3** the front is blocked: turn to the OLS (and
//!   evaluate again); **RS4** otherwise move forward.
//! * **Backtracking points (BP)**: before every forward move, every free unvisited neighbour
//!   other than the one being entered is recorded (one [`Event::BacktrackPoint`] per new point).
//! * **Spiral end**: BPs that have been visited since are dropped; the closest remaining one by a
//!   breadth-first search over visited cells (4-connected, each step along a known free edge) is
//!   selected. *Ties* (same BFS distance): smaller `j`, then smaller `i` (the rule BA* uses). The
//!   robot goes there over visited cells (collinear steps merged; events
//!   [`Event::StartPoint`], [`Event::BacktrackStart`], [`Event::PathRaw`],
//!   [`Event::BacktrackEnd`]) and starts a new spiral ([`Event::RegionStart`]). Planning stops
//!   when no BP remains. `regions` = spirals.
//! * **Heading of a new spiral** (the paper: "the robot is located nearby an obstacle, which is
//!   situated in the RLS"): with `e` the direction of the move that entered the cell, the first
//!   heading of `e`, `OLS(e)`, `back(e)`, `RLS(e)` whose RLS neighbour is blocked and whose front
//!   is free; failing that the first with a free front.
//! * **First spiral** (the paper assumes the robot starts next to an obstacle): when no
//!   neighbour of the start cell is blocked, the robot first drives straight along its start
//!   heading (rounded to a multiple of 90°), marking and recording BPs as usual, until the cell
//!   ahead is blocked; then it picks the spiral heading by the rule above. In an empty room this
//!   gives one spiral that ends near the centre without revisiting a cell.
//!
//! Every motion is a [`Step::MoveTo`] between cell centres that the planner has checked free on
//! its [`KnownMap`], so a correct run has no collision.
//!
//! ```
//! use ccpp_core::{GridMap, Pose};
//! use ccpp_core::world::{Robot, World};
//! use ccpp_core::planners::bsa::{Bsa, BsaOptions};
//! use ccpp_core::sim::{simulate, SimConfig};
//! // Characters of 0.2 m (5 px of 0.04 m), robot of radius 0.1 m: one cell per character.
//! let art = concat!(
//!     "########\n",
//!     "#......#\n",
//!     "#..##..#\n",
//!     "#......#\n",
//!     "########",
//! );
//! let map = GridMap::from_ascii_scaled(art, 5, 0.04).unwrap();
//! let world = World::new(map, Robot::new(0.1), Some(Pose::new(0.3, 0.3, 0.0))).unwrap();
//! let mut bsa = Bsa::new(BsaOptions::default());
//! let out = simulate(&world, &mut bsa, &SimConfig::default());
//! let m = ccpp_core::metrics::compute(&world, &out, "ring");
//! assert_eq!(m.coverage_rate, Some(1.0));
//! assert_eq!(m.collisions, 0);
//! ```

use std::collections::VecDeque;

use serde::{Deserialize, Serialize};

use crate::geometry::Point;
use crate::planner::{DiskState, KnownMap, Planner, Sensor, Step};
use crate::search::SearchSpace;
use crate::tiles::{Tile, TileGrid};
use crate::trace::Event;

/// The reference lateral side (RLS): where BSA keeps obstacles while filling a spiral.
///
/// Read without regard to case (`RIGHT`, as `--side RIGHT` is), written in lower case.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// Obstacles on the robot's left (the spiral turns counter-clockwise).
    #[default]
    Left,
    /// Obstacles on the robot's right (the spiral turns clockwise).
    Right,
}

impl<'de> Deserialize<'de> for Side {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        match s.to_ascii_lowercase().as_str() {
            "left" => Ok(Side::Left),
            "right" => Ok(Side::Right),
            _ => Err(serde::de::Error::unknown_variant(&s, &["left", "right"])),
        }
    }
}

impl Side {
    /// The name in option files and on the command line: `left` or `right`.
    pub fn as_str(self) -> &'static str {
        match self {
            Side::Left => "left",
            Side::Right => "right",
        }
    }

    /// The RLS heading of heading `h` (0 E, 1 N, 2 W, 3 S).
    #[inline]
    pub(crate) fn rls(self, h: usize) -> usize {
        match self {
            Side::Left => (h + 1) % 4,
            Side::Right => (h + 3) % 4,
        }
    }

    /// The OLS heading of heading `h`.
    #[inline]
    pub(crate) fn ols(self, h: usize) -> usize {
        match self {
            Side::Left => (h + 3) % 4,
            Side::Right => (h + 1) % 4,
        }
    }
}

/// Options of [`Bsa`] (`--planner bsa`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BsaOptions {
    /// Reference lateral side of the spirals (`left` or `right`).
    pub side: Side,
}

/// Cell headings, counter-clockwise from east: E, N, W, S (tile offsets).
pub const HEADINGS: [Tile; 4] = [(1, 0), (0, 1), (-1, 0), (0, -1)];

/// Cell flag: the robot stood at the centre (a virtual obstacle for the spiral rules).
pub(crate) const VISITED: u8 = 1;
/// Cell flag: recorded as a backtracking point.
pub(crate) const BP: u8 = 2;
/// Cell flag: the robot can stand at the centre (final, from sensed pixels).
pub(crate) const STAND_FREE: u8 = 8;

/// Edge state: the straight move between the centres is free.
pub(crate) const EDGE_FREE: u8 = 1;
/// Edge state: the move is blocked.
pub(crate) const EDGE_BLOCKED: u8 = 2;

#[inline]
pub(crate) fn add(t: Tile, d: usize) -> Tile {
    (t.0 + HEADINGS[d].0, t.1 + HEADINGS[d].1)
}

/// Dense per-cell state over the cells that can lie on the map.
pub(crate) struct Cells {
    i0: i32,
    j0: i32,
    w: usize,
    h: usize,
    flags: Vec<u8>,
    /// Two bits per heading (E, N, W, S): 0 unknown, [`EDGE_FREE`], [`EDGE_BLOCKED`].
    edges: Vec<u8>,
    /// Search scratch: cost and parent per cell, reused across searches.
    search: SearchSpace<u32>,
}

impl Cells {
    fn new((i0, i1, j0, j1): (i32, i32, i32, i32)) -> Self {
        let w = (i1 - i0 + 1).max(0) as usize;
        let h = (j1 - j0 + 1).max(0) as usize;
        let n = w * h;
        Self {
            i0,
            j0,
            w,
            h,
            flags: vec![0; n],
            edges: vec![0; n],
            search: SearchSpace::new(n),
        }
    }

    #[inline]
    pub(crate) fn idx(&self, t: Tile) -> Option<usize> {
        let di = t.0 - self.i0;
        let dj = t.1 - self.j0;
        if di < 0 || dj < 0 || di as usize >= self.w || dj as usize >= self.h {
            None
        } else {
            Some(dj as usize * self.w + di as usize)
        }
    }

    #[inline]
    pub(crate) fn tile(&self, k: usize) -> Tile {
        (self.i0 + (k % self.w) as i32, self.j0 + (k / self.w) as i32)
    }

    #[inline]
    pub(crate) fn has(&self, t: Tile, f: u8) -> bool {
        self.idx(t).is_some_and(|k| self.flags[k] & f != 0)
    }

    #[inline]
    pub(crate) fn set(&mut self, t: Tile, f: u8) {
        if let Some(k) = self.idx(t) {
            self.flags[k] |= f;
        }
    }

    #[inline]
    pub(crate) fn clear(&mut self, t: Tile, f: u8) {
        if let Some(k) = self.idx(t) {
            self.flags[k] &= !f;
        }
    }

    /// Edge state from `t` towards heading `d` (cells off the range: blocked).
    #[inline]
    pub(crate) fn edge(&self, t: Tile, d: usize) -> u8 {
        match (self.idx(t), self.idx(add(t, d))) {
            (Some(k), Some(_)) => (self.edges[k] >> (2 * d)) & 3,
            _ => EDGE_BLOCKED,
        }
    }

    /// Stores an edge state for both directions of the edge.
    fn set_edge(&mut self, t: Tile, d: usize, v: u8) {
        if let Some(k) = self.idx(t) {
            self.edges[k] = (self.edges[k] & !(3 << (2 * d))) | (v << (2 * d));
        }
        let n = add(t, d);
        let back = (d + 2) % 4;
        if let Some(k) = self.idx(n) {
            self.edges[k] = (self.edges[k] & !(3 << (2 * back))) | (v << (2 * back));
        }
    }

    /// Path from the search root to `k` (cells, root first).
    pub(crate) fn path_to(&self, k: usize) -> Vec<Tile> {
        let path = self.search.path_to(k as u32);
        path.iter().map(|&k| self.tile(k as usize)).collect()
    }
}

/// What the planner knows and where it is (built on the first step).
pub(crate) struct Core {
    pub(crate) known: KnownMap,
    pub(crate) grid: TileGrid,
    /// Robot radius, metres.
    pub(crate) r: f64,
    pub(crate) cells: Cells,
    /// Recorded backtracking points (validated at each spiral end).
    pub(crate) bps: Vec<Tile>,
    /// The cell whose centre the robot is at (or will be once the queued steps ran).
    pub(crate) cell: Tile,
    /// Current heading (0 E, 1 N, 2 W, 3 S).
    pub(crate) heading: usize,
    /// Current spiral number.
    pub(crate) region: u32,
}

impl Core {
    fn new(sensor: &dyn Sensor) -> Self {
        let r = sensor.robot().radius;
        let pose = sensor.pose();
        let grid = TileGrid::new(pose.position(), 2.0 * r);
        let cells = Cells::new(grid.bounds_for_frame(sensor.frame()));
        let q = (pose.theta / std::f64::consts::FRAC_PI_2).round() as i64;
        Self {
            known: KnownMap::new(sensor.frame()),
            grid,
            r,
            cells,
            bps: Vec::new(),
            cell: (0, 0),
            heading: q.rem_euclid(4) as usize,
            region: 0,
        }
    }

    #[inline]
    pub(crate) fn center(&self, t: Tile) -> Point {
        self.grid.center(t)
    }

    /// Is the move from the current cell towards `d` free? Computed once (the robot is at the
    /// cell centre, so every pixel the check reads has been sensed) and cached for both ends.
    fn probe(&mut self, d: usize) -> bool {
        let c = self.cell;
        match self.cells.edge(c, d) {
            EDGE_FREE => true,
            EDGE_BLOCKED => false,
            _ => {
                let n = add(c, d);
                let free = self.cells.idx(n).is_some()
                    && self
                        .known
                        .segment_free(self.center(c), self.center(n), self.r);
                self.cells
                    .set_edge(c, d, if free { EDGE_FREE } else { EDGE_BLOCKED });
                if free {
                    self.cells.set(n, STAND_FREE);
                }
                free
            }
        }
    }

    /// Free neighbours of the current cell (E, N, W, S) and which of them are blocked for the
    /// spiral rules (not free, or visited: a virtual obstacle).
    pub(crate) fn around(&mut self) -> ([bool; 4], [bool; 4]) {
        let mut free = [false; 4];
        let mut blocked = [true; 4];
        for d in 0..4 {
            free[d] = self.probe(d);
            blocked[d] = !free[d] || self.cells.has(add(self.cell, d), VISITED);
        }
        (free, blocked)
    }

    /// Records `t` as a backtracking point (once).
    pub(crate) fn add_bp(&mut self, t: Tile, queue: &mut VecDeque<Step>) {
        if self.cells.has(t, BP | VISITED) || self.cells.idx(t).is_none() {
            return;
        }
        self.cells.set(t, BP);
        self.bps.push(t);
        let p = self.center(t);
        queue.push_back(Step::Mark(Event::BacktrackPoint { x: p.x, y: p.y }));
    }

    /// Marks `t` visited (a virtual obstacle).
    pub(crate) fn visit(&mut self, t: Tile) {
        self.cells.set(t, VISITED | STAND_FREE);
    }

    /// Drops the BPs that are no longer unvisited.
    pub(crate) fn validate_bps(&mut self) {
        let cells = &mut self.cells;
        self.bps.retain(|&t| {
            let keep = !cells.has(t, VISITED);
            if !keep {
                cells.clear(t, BP);
            }
            keep
        });
    }

    /// Basic BSA selection: breadth-first search over visited cells from the current cell; the
    /// nearest BP entered along a known free edge (ties: smaller `j`, then smaller `i`). Returns
    /// the cell path, current cell first, BP last.
    fn select_basic(&mut self) -> Option<Vec<Tile>> {
        let start = self.cells.idx(self.cell)? as u32;
        let cells = &mut self.cells;
        cells.search.begin();
        cells.search.push_fifo_source(start);
        // The best BP so far, the visited cell it is entered from and that cell's depth.
        let mut best: Option<(Tile, u32, u32)> = None;
        while let Some((k, depth)) = cells.search.pop_fifo() {
            if best.is_some_and(|b| depth > b.2) {
                break;
            }
            let u = cells.tile(k as usize);
            for d in 0..4 {
                if cells.edge(u, d) != EDGE_FREE {
                    continue;
                }
                let n = add(u, d);
                let Some(kn) = cells.idx(n) else {
                    continue;
                };
                if cells.has(n, VISITED) {
                    cells.search.discover(k, kn as u32);
                } else if cells.has(n, BP) && best.is_none_or(|(b, _, _)| (n.1, n.0) < (b.1, b.0)) {
                    best = Some((n, k, depth));
                }
            }
        }
        let (n, k, _) = best?;
        let mut path = cells.path_to(k as usize);
        path.push(n);
        Some(path)
    }
}

/// Phase of the planner.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    /// Nothing done yet.
    Init,
    /// First spiral, before meeting an obstacle: straight along the start heading.
    Approach,
    /// Just arrived at a new spiral's first cell, entered along this heading.
    Arrive(usize),
    /// Spiral filling.
    Spiral,
    /// No BP left.
    Finished,
}

/// The basic BSA planner (also the host of `bsa-extended`, see [`super::bsa_extended`]).
pub struct Bsa {
    side: Side,
    core: Option<Core>,
    phase: Phase,
    queue: VecDeque<Step>,
}

impl Bsa {
    /// Basic BSA (`--planner bsa`).
    pub fn new(opts: BsaOptions) -> Self {
        Self {
            side: opts.side,
            core: None,
            phase: Phase::Init,
            queue: VecDeque::new(),
        }
    }

    /// What the sensor has shown so far (after the first step).
    pub fn known_map(&self) -> Option<&KnownMap> {
        self.core.as_ref().map(|c| &c.known)
    }

    /// The cells (after the first step).
    pub fn cell_grid(&self) -> Option<TileGrid> {
        self.core.as_ref().map(|c| c.grid)
    }

    /// Hook for extensions: integrates the current scan into the known map (initialising the
    /// planner on its first call) without deciding anything. [`Planner::next`] does the same
    /// before each decision, so calling this first changes nothing.
    pub fn observe(&mut self, sensor: &dyn Sensor) {
        let core = self.core.get_or_insert_with(|| Core::new(sensor));
        core.known.integrate(&sensor.scan());
    }

    /// Hook for extensions: will BSA still stand in the cell holding world point `p` (so that
    /// the cell is swept)? `true` when the cell is not visited and its centre is not known to
    /// be blocked for the robot (a cell BSA cannot enter although it can stand there is found
    /// out only at the end).
    pub fn will_cover(&self, p: Point) -> bool {
        self.core.as_ref().is_some_and(|c| {
            let t = c.grid.tile_of_near_boundary(p);
            if c.cells.idx(t).is_none() || c.cells.has(t, VISITED) {
                return false;
            }
            if c.cells.has(t, STAND_FREE) {
                return true;
            }
            let f = c.known.frame();
            let rc = crate::collide::contact_radius_px(c.r / f.resolution);
            c.known.disk_state(f.world_to_grid(c.center(t)), rc) != DiskState::Blocked
        })
    }

    /// Hook for extensions: the moves of the queued transfer to the next spiral (its last point
    /// the centre of the selected backtracking point), between a spiral's [`Event::RegionEnd`]
    /// and the transfer's [`Event::BacktrackEnd`]; `None` when no transfer is queued.
    pub fn transfer(&self) -> Option<Vec<Point>> {
        let start = self
            .queue
            .iter()
            .position(|s| matches!(s, Step::Mark(Event::BacktrackStart)))?;
        let end = self
            .queue
            .iter()
            .position(|s| matches!(s, Step::Mark(Event::BacktrackEnd)))?;
        let moves: Vec<Point> = self
            .queue
            .range(start..end)
            .filter_map(|s| match s {
                Step::MoveTo(p) => Some(*p),
                _ => None,
            })
            .collect();
        (!moves.is_empty()).then_some(moves)
    }

    /// Hook for extensions: replaces the moves of the queued transfer by `moves` (a known-free
    /// way from `from`, the robot's position when the transfer starts, to
    /// the last point of [`Self::transfer`]). The trace's smoothed path
    /// becomes `from` followed by `moves`.
    pub fn replace_transfer(&mut self, from: Point, moves: &[Point]) {
        let Some(start) = self
            .queue
            .iter()
            .position(|s| matches!(s, Step::Mark(Event::BacktrackStart)))
        else {
            return;
        };
        let Some(end) = self
            .queue
            .iter()
            .position(|s| matches!(s, Step::Mark(Event::BacktrackEnd)))
        else {
            return;
        };
        let old: Vec<Step> = self.queue.drain(start + 1..end).collect();
        let mut new: Vec<Step> = old
            .into_iter()
            .filter(|s| matches!(s, Step::Mark(Event::PathRaw { .. })))
            .collect();
        let mut points = vec![[from.x, from.y]];
        points.extend(moves.iter().map(|p| [p.x, p.y]));
        new.push(Step::Mark(Event::PathSmoothed { points }));
        new.extend(moves.iter().map(|&p| Step::MoveTo(p)));
        for (k, s) in new.into_iter().enumerate() {
            self.queue.insert(start + 1 + k, s);
        }
    }

    /// The heading a new spiral starts with, given the heading `e` that entered the cell: the
    /// first of `e`, `OLS(e)`, `back(e)`, `RLS(e)` with the RLS blocked and the front free, else
    /// the first with a free front, else `e`.
    fn initial_heading(side: Side, e: usize, blocked: [bool; 4]) -> usize {
        let cands = [e, side.ols(e), (e + 2) % 4, side.rls(e)];
        cands
            .iter()
            .copied()
            .find(|&h| blocked[side.rls(h)] && !blocked[h])
            .or_else(|| cands.iter().copied().find(|&h| !blocked[h]))
            .unwrap_or(e)
    }

    /// Records the BPs around the current cell (all free unvisited neighbours but heading `h`),
    /// then moves one cell forward along `h`.
    fn forward(core: &mut Core, queue: &mut VecDeque<Step>, h: usize, blocked: [bool; 4]) {
        let c = core.cell;
        for d in 0..4 {
            if d != h && !blocked[d] {
                core.add_bp(add(c, d), queue);
            }
        }
        let n = add(c, h);
        core.heading = h;
        core.visit(n);
        core.cell = n;
        queue.push_back(Step::MoveTo(core.center(n)));
    }

    /// Plans the next steps into the queue (the robot is at the pose the planner expects).
    fn decide(&mut self, sensor: &dyn Sensor) {
        let core = self.core.get_or_insert_with(|| Core::new(sensor));
        core.known.integrate(&sensor.scan());
        if self.phase == Phase::Init {
            core.region = 1;
            self.queue
                .push_back(Step::Mark(Event::RegionStart { region: 1 }));
            let c = core.cell;
            core.visit(c);
            let (_, blocked) = core.around();
            self.phase = if blocked.iter().any(|&b| b) {
                Phase::Arrive(core.heading)
            } else {
                Phase::Approach
            };
        }
        let (_, blocked) = core.around();
        match self.phase {
            Phase::Approach => {
                let h = core.heading;
                if !blocked[h] {
                    Self::forward(core, &mut self.queue, h, blocked);
                    return;
                }
                core.heading = Self::initial_heading(self.side, h, blocked);
                self.phase = Phase::Spiral;
            }
            Phase::Arrive(e) => {
                core.heading = Self::initial_heading(self.side, e, blocked);
                self.phase = Phase::Spiral;
            }
            _ => {}
        }
        // RS1: all around blocked -> the spiral ends.
        if blocked.iter().all(|&b| b) {
            self.end_spiral();
            return;
        }
        let side = self.side;
        let mut h = core.heading;
        if blocked[side.rls(h)] {
            // RS3: front blocked -> turn to the OLS (repeat until the front is free; RS1 rules
            // out all four blocked). RS4: move forward.
            while blocked[h] {
                h = side.ols(h);
            }
        } else {
            // RS2: RLS free -> turn to the RLS and move forward.
            h = side.rls(h);
        }
        Self::forward(core, &mut self.queue, h, blocked);
    }

    /// RS1 fired: end the spiral, select a BP, plan the return path, start the next spiral.
    fn end_spiral(&mut self) {
        let core = self
            .core
            .as_mut()
            .expect("core exists once planning started");
        self.queue.push_back(Step::Mark(Event::RegionEnd {
            region: core.region,
        }));
        core.validate_bps();
        let Some(plan) = core.select_basic().map(|cells| basic_plan(core, &cells)) else {
            self.phase = Phase::Finished;
            return;
        };
        let q = &mut self.queue;
        let p = core.center(plan.target);
        q.push_back(Step::Mark(Event::StartPoint { x: p.x, y: p.y }));
        q.push_back(Step::Mark(Event::BacktrackStart));
        q.push_back(Step::Mark(Event::PathRaw {
            points: plan.raw.iter().map(|p| [p.x, p.y]).collect(),
        }));
        if plan.raw.len() != plan.moves.len() {
            q.push_back(Step::Mark(Event::PathSmoothed {
                points: plan.moves.iter().map(|p| [p.x, p.y]).collect(),
            }));
        }
        for &m in plan.moves.iter().skip(1) {
            q.push_back(Step::MoveTo(m));
        }
        q.push_back(Step::Mark(Event::BacktrackEnd));
        core.region += 1;
        q.push_back(Step::Mark(Event::RegionStart {
            region: core.region,
        }));
        core.visit(plan.target);
        core.cell = plan.target;
        core.heading = plan.entry;
        self.phase = Phase::Arrive(plan.entry);
    }
}

/// The transfer along a cell path over visited cells (collinear steps merged).
fn basic_plan(core: &Core, cells: &[Tile]) -> ReturnPlan {
    let raw: Vec<Point> = cells.iter().map(|&t| core.center(t)).collect();
    let moves = merge_collinear(cells)
        .into_iter()
        .map(|t| core.center(t))
        .collect();
    let target = *cells.last().expect("path ends at the BP");
    let prev = cells[cells.len() - 2];
    ReturnPlan {
        target,
        entry: heading_of(prev, target),
        raw,
        moves,
    }
}

/// A planned transfer to the next spiral's first cell.
pub(crate) struct ReturnPlan {
    /// The selected BP.
    pub(crate) target: Tile,
    /// Heading of the last move (into the BP).
    pub(crate) entry: usize,
    /// Cell centres of the cell path (for the trace).
    pub(crate) raw: Vec<Point>,
    /// Points to drive through, the current position first.
    pub(crate) moves: Vec<Point>,
}

/// Heading from cell `a` to 4-neighbour `b` (E if they are not 4-neighbours).
pub(crate) fn heading_of(a: Tile, b: Tile) -> usize {
    HEADINGS
        .iter()
        .position(|&o| (a.0 + o.0, a.1 + o.1) == b)
        .unwrap_or(0)
}

/// Drops the interior cells of straight runs of a 4-connected cell path.
///
/// ```text
/// (0,0) (1,0) (2,0) (2,1) (2,2) (3,2)  ->  (0,0) (2,0) (2,2) (3,2)
/// ```
pub(crate) fn merge_collinear(cells: &[Tile]) -> Vec<Tile> {
    let mut out: Vec<Tile> = Vec::with_capacity(cells.len());
    for &t in cells {
        if out.len() >= 2 {
            let a = out[out.len() - 2];
            let b = out[out.len() - 1];
            let dir = |p: Tile, q: Tile| ((q.0 - p.0).signum(), (q.1 - p.1).signum());
            if dir(a, b) == dir(b, t) {
                out.pop();
            }
        }
        out.push(t);
    }
    out
}

impl Planner for Bsa {
    fn name(&self) -> &'static str {
        "bsa"
    }

    fn tile_side(&self) -> Option<f64> {
        self.core.as_ref().map(|c| c.grid.side)
    }

    fn next(&mut self, sensor: &dyn Sensor) -> Step {
        loop {
            if let Some(s) = self.queue.pop_front() {
                return s;
            }
            if self.phase == Phase::Finished {
                return Step::Done;
            }
            self.decide(sensor);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merge_collinear_keeps_every_corner() {
        let path = [
            (0, 0),
            (1, 0),
            (2, 0),
            (2, 1),
            (2, 2),
            (2, 3),
            (3, 3),
            (4, 3),
            (4, 2),
        ];
        assert_eq!(
            merge_collinear(&path),
            vec![(0, 0), (2, 0), (2, 3), (4, 3), (4, 2)]
        );
    }

    #[test]
    fn sides_read_in_any_case_and_are_written_in_lower_case() {
        // As the command line's `--side RIGHT` (Python's `side="RIGHT"` was refused).
        for (text, side) in [("\"RIGHT\"", Side::Right), ("\"Left\"", Side::Left)] {
            assert_eq!(serde_json::from_str::<Side>(text).unwrap(), side);
        }
        assert_eq!(serde_json::to_string(&Side::Right).unwrap(), "\"right\"");
        let e = serde_json::from_str::<Side>("\"up\"")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("unknown variant `up`, expected `left` or `right`"),
            "{e}"
        );
    }

    #[test]
    fn sides_turn_the_right_way() {
        assert_eq!(Side::Left.rls(0), 1);
        assert_eq!(Side::Left.ols(0), 3);
        assert_eq!(Side::Right.rls(0), 3);
        assert_eq!(Side::Right.ols(1), 2);
    }
}
