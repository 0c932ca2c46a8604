//! BA*: online complete coverage by boustrophedon motions and A*-based backtracking.
//!
//! Hoang Huu Viet, Viet-Hung Dang, Md Nasir Uddin Laskar, `TaeChoong` Chung, "BA*: an online
//! complete coverage algorithm for cleaning robots", *Applied Intelligence* 39, 217–235 (2013)
//! (seed 000). The resolved choices of `algorithms.md` (section BA*) are followed exactly:
//!
//! 1. **Boustrophedon motion (BM).** From the current tile try N, S, E, W in that fixed order and
//!    move one tile to the first that is *free* and not covered; the robot's tile is marked
//!    covered when it stands on it. All four blocked: the tile is a **critical point**, the BM
//!    (one region) ends.
//! 2. **Backtracking list** `L = { s covered | mu(s) >= 1 }`, with
//!    `mu(s) = b(s1,s8) + b(s1,s2) + b(s5,s6) + b(s5,s4) + b(s7,s6) + b(s7,s8)` (see
//!    [`corner_score`]). Maintained incrementally, checked against a full recomputation in tests.
//!    **Deviation:** by default `mu` also counts [`lane_end_score`] (a side neighbour free while
//!    the lane ends at an obstacle; the start tile's south neighbour) and the same lane ends
//!    judged by *moves* rather than by standability ([`SIDE_END_PAIRS`]: a free side that the
//!    lane does not carry on, which pixel clutter produces at standable but unenterable tiles);
//!    the paper's six pairs alone can miss a frontier and stall.
//! 3. **Selection.** One Dijkstra from the critical point over covered tiles (8-connected, no
//!    corner cutting) stops at the first tile of `L` it settles; ties: smaller `j`, then smaller `i`
//!    ([`TileSearch::nearest`]).
//! 4. **Path.** A* over the same graph, Euclidean heuristic ([`TileSearch::astar`]).
//! 5. **A*SPT smoothing** ([`smooth_path`]): from the current waypoint jump to the farthest later
//!    path tile in line of sight; line of sight = every tile the robot's disk touches along the
//!    segment is covered *and* the segment is free on the known map.
//! 6. Each smoothed segment is one [`Step::MoveTo`] (the simulator turns by
//!    `alpha = wrap(beta - theta)` and translates `d`; see [`motion_to`]).
//! 7. **Heading at `s_sp`**: rotate to the direction of the first BM move.
//! 8. Stop when `L` is empty at a critical point.
//!
//! # Tile model (`M̂`)
//!
//! Tiles have side `2 r` (option [`BaStarOptions::tile_side_m`]) and are anchored so that the
//! start position is the centre of tile `(0, 0)`; `i` east, `j` north. Everything is judged from
//! the pixels the sensor has shown (the planner's own [`KnownMap`]), never from the world:
//!
//! * **standability** of a tile (can the robot stand at its centre?) is [`Judgement::Free`] when
//!   every pixel that could touch the disk has been seen and none is blocked (exactly
//!   [`KnownMap::disk_free`]), [`Judgement::Blocked`] when a *seen* blocked pixel (or the outside
//!   of the map) touches it, and [`Judgement::Undetermined`] otherwise. An undetermined tile is not
//!   an obstacle; it is re-evaluated after every scan that could change it.
//! * a **move** between two tile centres is judged the same way over the swept disk (exactly
//!   [`KnownMap::segment_free`] when free).
//! * `M̂(s)` is *covered* once the robot stood on `s` during BM, *obstacle* when `s` is judged not
//!   standable, *unknown* otherwise (including tiles never looked at and out-of-frame tiles, which
//!   are obstacles).
//!
//! In `mu`, `b(a, b) = 1` when the 4-neighbour `a` of `s` is **free-uncovered**: not covered and
//! the move `s -> a` is judged free (so `a` is enterable from `s`: a restart at `s` can always make
//! a BM move, otherwise the robot would select `s` forever), and the tile `b` is **blocked**:
//! covered or obstacle. This is the seed's `M̂` with "free ⇔ unknown" restricted to unknown tiles
//! that are actually enterable from `s`.
//!
//! **Sensing assumption.** With the default sensor range `4 r` (and any range of at least
//! `side + r + res`), standing on a tile shows every pixel its four moves can touch, so all moves
//! BM, `mu` and the searches use are decided. A shorter range keeps the planner safe (undecided
//! moves are not taken) but may leave tiles uncovered; the planner notes it in the trace.
//!
//! # Code layout
//!
//! This file holds the public planner ([`BaStar`], [`BaStarOptions`], the [`Planner`] impl and
//! the hooks for extensions); the private submodules hold the rest: `judge` (the three-valued
//! judgements of standing and moves), `tile_model` (tile states and cached moves, the
//! backtracking graph), `sensing` (scan integration and the refresh of judgements),
//! `backtrack_list` (`mu` and the incremental list `L`), `search` (Dijkstra and A* over covered
//! tiles), `smoothing` (A*SPT and line of sight) and `motion` (BM steps, critical points,
//! arrival at the start point).
//!
//! # Example
//!
//! ```
//! use ccpp_core::{GridMap, Pose};
//! use ccpp_core::world::{Robot, World};
//! use ccpp_core::planners::ba_star::{BaStar, BaStarOptions};
//! use ccpp_core::sim::{simulate, SimConfig};
//! // One character = 11 px = 0.11 m = one tile of a robot of radius 0.055 m.
//! let art = "\
//!     ......\n\
//!     ..##..\n\
//!     ..##..\n\
//!     ......";
//! let map = GridMap::from_ascii_scaled(art, 11, 0.01).unwrap();
//! let start = Pose::new(0.055, 0.055, std::f64::consts::FRAC_PI_2);
//! let world = World::new(map, Robot::new(0.055), Some(start)).unwrap();
//! let mut planner = BaStar::new(BaStarOptions::default());
//! let out = simulate(&world, &mut planner, &SimConfig::default());
//! let m = ccpp_core::metrics::compute(&world, &out, "block");
//! assert_eq!(m.coverage_rate, Some(1.0));
//! assert_eq!(m.collisions, 0);
//! assert!(m.regions >= 2);
//! assert_eq!(m.regions, m.backtracks + 1);
//! ```

use std::collections::VecDeque;

use serde::{Deserialize, Serialize};

use crate::geometry::Point;
use crate::planner::{KnownMap, Planner, Sensor, Step};
use crate::tiles::{Tile, TileGrid, N8};
use crate::trace::Event;

mod backtrack_list;
mod judge;
mod motion;
mod search;
mod sensing;
mod smoothing;
#[cfg(test)]
mod tests;
mod tile_model;

pub use backtrack_list::{
    corner_score, lane_end_score, LANE_END_PAIRS, MU_PAIRS, SIDE_END_PAIRS, START_PAIRS,
};
pub(crate) use judge::motion_known_free;
pub use judge::{judge_motion, Judgement};
pub use motion::motion_to;
pub use search::{graph_edge, heuristic, octile, TileGraph, TileSearch, COST_DIAG, COST_ORTHO};
pub use smoothing::{for_each_swept_tile, smooth_path};

use sensing::Mind;
use tile_model::ST_COVERED;

/// Options of [`BaStar`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BaStarOptions {
    /// Tile side in metres; `None` = `2 r` (the paper's tiles).
    pub tile_side_m: Option<f64>,
    /// A*SPT smoothing of the backtracking paths (`false` follows the raw A* path, to compare).
    pub smoothing: bool,
    /// Record the backtracking list `L` at every critical point (`backtrack_list` events), while
    /// the recorded lists hold at most [`LIST_POINTS_PER_TILE`] points a tile and
    /// [`LIST_POINTS_MAX`] in all (then a `note` event says recording stopped). Large maps produce big traces; switch off when only the
    /// metrics matter.
    pub record_backtrack_list: bool,
    /// Extend `mu` by [`lane_end_score`] and the move-judged lane ends of [`SIDE_END_PAIRS`]
    /// (default `true`). `false` is the paper's `mu` exactly, which can leave reachable tiles
    /// uncovered (see [`lane_end_score`]).
    pub lane_end_corners: bool,
}

impl Default for BaStarOptions {
    fn default() -> Self {
        Self {
            tile_side_m: None,
            smoothing: true,
            record_backtrack_list: true,
            lane_end_corners: true,
        }
    }
}

#[derive(Clone, Debug)]
enum Phase {
    Start,
    Bm,
    Backtrack { path: Vec<Tile>, next: usize },
    Finished,
}

/// The start of the trace note BA* writes when it ends with tiles left in its backtracking
/// list that the covered tiles no longer reach (moves its bumper stopped, under odometry
/// noise, lie between); `ccpp run` says it as a warning.
pub const UNREACHABLE_NOTE: &str = "ba-star: no backtracking candidate reachable";

/// The backtracking-list points a run's trace holds at most, per tile of the map (and never
/// more than [`LIST_POINTS_MAX`]): lists are recorded whole at each critical point while they
/// fit, and a `note` event says where the recording stopped (the run's memory estimate counts
/// them: 16 bytes a point). Real maps stay well inside (`office_4096` at r = 0.15 m: about 14
/// per tile).
pub const LIST_POINTS_PER_TILE: usize = 32;

/// The backtracking-list points a run's trace holds at most whatever the map (128 MB at 16
/// bytes a point): with tiles of a pixel or two the per-tile bound alone made the estimate of
/// `cluttered_2000` at r = 0.025 m 4570 MB (refused by the default limit) for a run that
/// peaks at 83 MiB. `office_4096` at r = 0.15 m records about 6.5 million.
pub const LIST_POINTS_MAX: usize = 8_000_000;

/// The BA* planner (see the module docs).
#[derive(Clone, Debug)]
pub struct BaStar {
    opts: BaStarOptions,
    side: Option<f64>,
    mind: Option<Box<Mind>>,
    phase: Phase,
    pending: VecDeque<Step>,
    region: u32,
    /// [`LIST_POINTS_PER_TILE`] (smaller in tests).
    list_points_per_tile: usize,
}

impl BaStar {
    /// A planner with these options.
    pub fn new(opts: BaStarOptions) -> Self {
        Self {
            side: opts.tile_side_m,
            opts,
            mind: None,
            phase: Phase::Start,
            pending: VecDeque::new(),
            region: 0,
            list_points_per_tile: LIST_POINTS_PER_TILE,
        }
    }

    /// The planner with another bound on the recorded backtracking lists (tests).
    #[cfg(test)]
    pub(crate) fn with_list_points_per_tile(mut self, k: usize) -> Self {
        self.list_points_per_tile = k;
        self
    }

    /// The tiling (after the first step).
    pub fn tile_grid(&self) -> Option<TileGrid> {
        self.mind.as_ref().map(|m| m.tiles.grid)
    }

    /// What the sensor has shown so far (after the first step).
    pub fn known_map(&self) -> Option<&KnownMap> {
        self.mind.as_ref().map(|m| &m.known)
    }

    /// Is tile `t` covered?
    pub fn is_covered(&self, t: Tile) -> bool {
        self.mind.as_ref().is_some_and(|m| m.tiles.covered(t))
    }

    /// The covered tiles, row-major (`j`, then `i`).
    pub fn covered_tiles(&self) -> Vec<Tile> {
        let Some(m) = &self.mind else {
            return Vec::new();
        };
        let t = &m.tiles;
        (0..t.state.len())
            .filter(|&k| t.state[k] & ST_COVERED != 0)
            .map(|k| (t.i0 + (k % t.w) as i32, t.j0 + (k / t.w) as i32))
            .collect()
    }

    /// The backtracking list `L` as maintained incrementally, row-major.
    pub fn backtrack_list(&self) -> Vec<Tile> {
        self.mind
            .as_ref()
            .map_or_else(Vec::new, |m| m.tiles.l_tiles())
    }

    /// `L` recomputed from scratch from the tile judgements, row-major.
    pub fn backtrack_list_full(&self) -> Vec<Tile> {
        let Some(m) = &self.mind else {
            return Vec::new();
        };
        let t = &m.tiles;
        let mut out = Vec::new();
        for k in 0..t.state.len() {
            let tile = (t.i0 + (k % t.w) as i32, t.j0 + (k / t.w) as i32);
            if t.state[k] & ST_COVERED != 0 && t.mu(tile) >= 1 {
                out.push(tile);
            }
        }
        out
    }

    /// `mu(t)` from the current judgements.
    pub fn mu(&self, t: Tile) -> u32 {
        self.mind.as_ref().map_or(0, |m| m.tiles.mu(t))
    }

    /// The safeguard: `true` when `L` is empty yet some uncovered tile can be entered from a
    /// covered one by a move known to be free. BA* must never get there; tests assert it.
    pub fn frontier_without_candidates(&self) -> bool {
        let Some(m) = &self.mind else { return false };
        let t = &m.tiles;
        if t.l.len() > 0 {
            return false;
        }
        self.covered_tiles()
            .into_iter()
            .any(|s| [0, 2, 4, 6].into_iter().any(|k| t.free_uncovered(s, k)))
    }

    /// Checks every cached judgement against a fresh evaluation on the known map, and that the
    /// four moves of every covered tile are decided. `Err` describes the first mismatch.
    ///
    /// # Errors
    /// A description of the first stale or missing judgement.
    #[doc(hidden)]
    pub fn check_judgements(&self) -> Result<(), String> {
        let Some(m) = &self.mind else { return Ok(()) };
        let t = &m.tiles;
        for k in 0..t.state.len() {
            let tile = (t.i0 + (k % t.w) as i32, t.j0 + (k / t.w) as i32);
            let p = m.center(tile);
            let cached = t.stand(tile);
            // Tiles are refreshed only within scan reach; a tile never in reach stays
            // undetermined, which is exactly what a fresh evaluation says.
            let fresh = judge_motion(&m.known, p, p, m.r);
            if cached != fresh {
                return Err(format!("tile {tile:?}: cached {cached:?}, fresh {fresh:?}"));
            }
            for n in 0..4 {
                let c = t.cached_move(tile, n);
                if c != Judgement::Undetermined {
                    let v = (tile.0 + N8[n].0, tile.1 + N8[n].1);
                    // As `Mind::judge_move`: a move with an unstandable end is blocked (in
                    // both directions; `judge_motion` alone lets a disk leave a contact).
                    let f = if cached == Judgement::Blocked || t.stand(v) == Judgement::Blocked {
                        Judgement::Blocked
                    } else {
                        judge_motion(&m.known, p, m.center(v), m.r)
                    };
                    if f != c {
                        return Err(format!("move {tile:?}->{v:?}: cached {c:?}, fresh {f:?}"));
                    }
                }
            }
            let generic = (0..8).fold(0u8, |acc, n| {
                if graph_edge(t, tile, n) {
                    acc | 1 << n
                } else {
                    acc
                }
            });
            if t.edge_mask(tile) != generic {
                return Err(format!("tile {tile:?}: edge mask differs from graph_edge"));
            }
            if t.state[k] & ST_COVERED != 0 {
                for n in [0, 2, 4, 6] {
                    if t.cached_move(tile, n) == Judgement::Undetermined {
                        return Err(format!("covered {tile:?}: move {n} undecided"));
                    }
                }
            }
        }
        Ok(())
    }

    /// `true` while the robot is backtracking (between `BacktrackStart` and `BacktrackEnd`).
    pub fn is_backtracking(&self) -> bool {
        matches!(self.phase, Phase::Backtrack { .. })
    }

    /// Hook for extensions: integrates the current scan into the known map (initialising the
    /// planner on its first call) without deciding anything. [`Planner::next`] does the same
    /// before each decision, so calling this first changes nothing.
    pub fn observe(&mut self, sensor: &dyn Sensor) {
        if self.mind.is_none() {
            self.init(sensor);
        }
        if let Some(m) = self.mind.as_deref_mut() {
            m.sense(sensor);
        }
    }

    /// Hook for extensions: are steps (marks or moves) queued for the next calls?
    pub fn has_pending(&self) -> bool {
        !self.pending.is_empty()
    }

    /// Hook for extensions: has BA* finished (`L` empty at a critical point)?
    pub fn is_finished(&self) -> bool {
        matches!(self.phase, Phase::Finished)
    }

    /// Hook for extensions: the end of the current backtracking path (the centre of the chosen
    /// start tile `s_sp`), while backtracking.
    pub fn backtrack_goal(&self) -> Option<Point> {
        match (&self.phase, self.mind.as_ref()) {
            (Phase::Backtrack { path, .. }, Some(m)) => path.last().map(|&t| m.center(t)),
            _ => None,
        }
    }

    /// Hook for extensions: the rest of the current backtracking path (tile centres still to
    /// drive, the last one [`Self::backtrack_goal`]), while backtracking.
    pub fn backtrack_rest(&self) -> Option<Vec<Point>> {
        match (&self.phase, self.mind.as_ref()) {
            (Phase::Backtrack { path, next }, Some(m)) => Some(
                path.get(*next..)
                    .unwrap_or_default()
                    .iter()
                    .map(|&t| m.center(t))
                    .collect(),
            ),
            _ => None,
        }
    }

    /// Hook for extensions: drops the rest of the current backtracking path; the caller has
    /// driven the robot to [`Self::backtrack_goal`] and the next call arrives there.
    pub fn skip_backtrack(&mut self) {
        if let Phase::Backtrack { path, next } = &mut self.phase {
            *next = path.len();
        }
    }

    /// Hook for extensions: will BA* still sweep the tile holding world point `p`? `true` when
    /// that tile is not covered and not judged an obstacle.
    pub fn will_cover(&self, p: Point) -> bool {
        self.mind.as_ref().is_some_and(|m| {
            let t = m.tiles.grid.tile_of_near_boundary(p);
            !m.tiles.covered(t) && m.tiles.stand(t) != Judgement::Blocked
        })
    }
}

impl Planner for BaStar {
    fn name(&self) -> &'static str {
        "ba-star"
    }

    fn tile_side(&self) -> Option<f64> {
        self.side
    }

    fn next(&mut self, sensor: &dyn Sensor) -> Step {
        if let Some(s) = self.pending.pop_front() {
            return s;
        }
        if matches!(self.phase, Phase::Finished) {
            return Step::Done;
        }
        if self.mind.is_none() {
            self.init(sensor);
        }
        if let Some(m) = self.mind.as_deref_mut() {
            m.sense(sensor);
        }
        match &mut self.phase {
            Phase::Start => {
                self.region = 1;
                self.pending
                    .push_back(Step::Mark(Event::RegionStart { region: 1 }));
                self.phase = Phase::Bm;
                self.pending.pop_front().unwrap_or(Step::Done)
            }
            Phase::Bm => self.bm_step(sensor),
            Phase::Backtrack { path, next } => {
                if *next > 1 && sensor.bumped() {
                    // The bumper stopped the move from `path[next - 2]` to `path[next - 1]`:
                    // judged as `Mind::bumped_leg` says, and the region starts at the tile
                    // the robot last reached.
                    let leg = (path[*next - 2], path[*next - 1]);
                    if let Some(m) = self.mind.as_deref_mut() {
                        m.bumped_leg(leg.0, leg.1);
                    }
                    return self.arrive(sensor);
                }
                let target = path.get(*next).copied();
                *next += 1;
                match (target, self.mind.as_ref()) {
                    (Some(t), Some(m)) => Step::MoveTo(m.tiles.grid.center(t)),
                    _ => self.arrive(sensor),
                }
            }
            Phase::Finished => Step::Done,
        }
    }
}
