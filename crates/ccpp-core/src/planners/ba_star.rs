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

use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};

use serde::{Deserialize, Serialize};

use crate::bits::IndexSet;
use crate::collide::contact_radius_px;
use crate::geometry::{
    ceil_i32, ceil_i64, first_entry, floor_i32, floor_i64, point_segment_dist2, wrap_angle, Point,
    Pose,
};
use crate::grid::MapFrame;
use crate::planner::{disk_row_span, disk_rows, DiskState, KnownMap, Planner, Sensor, Step};
use crate::tiles::{Tile, TileGrid, N8};
use crate::trace::Event;

/// Options of [`BaStar`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BaStarOptions {
    /// Tile side in metres; `None` = `2 r` (the paper's tiles).
    pub tile_side_m: Option<f64>,
    /// A*SPT smoothing of the backtracking paths (`false` follows the raw A* path, to compare).
    pub smoothing: bool,
    /// Record the backtracking list `L` at every critical point (`backtrack_list` events). Large
    /// maps produce big traces; switch off when only the metrics matter.
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

/// A three-valued verdict from partial knowledge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Judgement {
    /// Not all pixels that matter have been seen and none of the seen ones blocks.
    Undetermined = 0,
    /// Every pixel that matters has been seen and none blocks.
    Free = 1,
    /// A seen blocked pixel (or the outside of the map) blocks.
    Blocked = 2,
}

impl Judgement {
    #[inline]
    fn from_bits(b: u8) -> Self {
        match b & 3 {
            1 => Judgement::Free,
            2 => Judgement::Blocked,
            _ => Judgement::Undetermined,
        }
    }
}

/// Judges the straight motion of the robot disk (radius `r` metres) from world point `a` to `b`
/// (`a == b`: standing at `a`) on the known map. `Free` is exactly [`KnownMap::segment_free`]
/// (resp. [`KnownMap::disk_free`]); `Blocked` means blocked whatever the unseen pixels hold.
///
/// Visits only the pixels near the segment (row spans of the swept capsule), so long segments
/// cost `O(length * r)`, not the area of their bounding box.
pub fn judge_motion(known: &KnownMap, a: Point, b: Point, r: f64) -> Judgement {
    let frame = known.frame();
    let ga = frame.world_to_grid(a);
    let gb = frame.world_to_grid(b);
    let rc = contact_radius_px(r / frame.resolution);
    judge_motion_px(known, ga, gb, rc)
}

/// [`judge_motion`] between grid points `ga` and `gb` (continuous grid coordinates of the two
/// world points) for the contact radius `rc` pixels of the robot.
fn judge_motion_px(known: &KnownMap, ga: Point, gb: Point, rc: f64) -> Judgement {
    let frame = *known.frame();
    let rc2 = rc * rc;
    let h = frame.height as f64;
    if ga == gb {
        return judge_point(known, ga, rc);
    }
    let (dx, dy) = (gb.x - ga.x, gb.y - ga.y);
    let ylo = ga.y.min(gb.y) - rc;
    let yhi = ga.y.max(gb.y) + rc;
    // Pixel centre of row `row` is at gy = h - row - 0.5.
    let row0 = floor_i64(h - yhi - 0.5) - 1;
    let row1 = ceil_i64(h - ylo - 0.5) + 1;
    let (w, hh) = (frame.width as i64, frame.height as i64);
    // Fast path: every pixel that can touch has its centre within `rc` of the segment, so in
    // the capsule's bounding box grown by `rc` (with a margin for rounding far below the
    // contact epsilon, so the pixels at exactly `r + 1/2` from a tile centre, which never
    // touch, stay out: for one-pixel tiles the box of a move is then just its two pixels).
    // That box inside the image and entirely known free: free.
    let eps = 1e-7;
    let cmin = ceil_i64(ga.x.min(gb.x) - rc - 0.5 - eps);
    let cmax = floor_i64(ga.x.max(gb.x) + rc - 0.5 + eps);
    let rmin = ceil_i64(h - yhi - 0.5 - eps);
    let rmax = floor_i64(h - ylo - 0.5 + eps);
    if 0 <= rmin
        && rmin <= rmax
        && rmax < hh
        && cmin <= cmax
        && cmin >= 0
        && cmax < w
        && (rmax - rmin + 1) * (cmax - cmin + 1) <= 1024
        && known.rect_known_free(rmin as usize, rmax as usize, cmin as usize, cmax as usize)
    {
        return Judgement::Free;
    }
    let mut undetermined = false;
    for row in row0..=row1 {
        let gy = h - row as f64 - 0.5;
        // Parameter range of the segment whose y lies within rc of this row.
        let (tl, th) = if dy == 0.0 {
            if (ga.y - gy).abs() > rc + 1e-9 {
                continue;
            }
            (0.0, 1.0)
        } else {
            let t1 = (gy - rc - ga.y) / dy;
            let t2 = (gy + rc - ga.y) / dy;
            (t1.min(t2).max(0.0), t1.max(t2).min(1.0))
        };
        if tl > th + 1e-12 {
            continue;
        }
        let xa = ga.x + tl * dx;
        let xb = ga.x + th * dx;
        let c0 = floor_i64(xa.min(xb) - rc - 0.5) - 1;
        let c1 = ceil_i64(xa.max(xb) + rc - 0.5) + 1;
        let touches = |col: i64| {
            let q = Point::new(col as f64 + 0.5, gy);
            point_segment_dist2(q, ga, gb) < rc2 && first_entry(ga, gb, q, rc).is_some()
        };
        // Outside the image every pixel is occupied (and seen).
        if row < 0 || row >= hh {
            if (c0..=c1).any(touches) {
                return Judgement::Blocked;
            }
            continue;
        }
        if (c0..=c1.min(-1)).any(touches) || (c0.max(w)..=c1).any(touches) {
            return Judgement::Blocked;
        }
        let (lo, hi) = (c0.max(0), c1.min(w - 1));
        if lo > hi {
            continue;
        }
        // Inside: seen free pixels never matter, whatever their distance; visit the others.
        let mut blocked = false;
        known.for_each_not_known_free(row as usize, lo as usize, hi as usize, |col, seen| {
            if !touches(col as i64) {
                return true;
            }
            if seen {
                blocked = true;
                return false;
            }
            undetermined = true;
            true
        });
        if blocked {
            return Judgement::Blocked;
        }
    }
    if undetermined {
        Judgement::Undetermined
    } else {
        Judgement::Free
    }
}

/// [`judge_motion`] for a motionless disk at grid point `g` (contact radius `rc` pixels): the
/// same predicate (`|q - g|^2 < rc^2` for a pixel centre `q`), by [`KnownMap::disk_state`].
fn judge_point(known: &KnownMap, g: Point, rc: f64) -> Judgement {
    known.disk_state(g, rc).into()
}

impl From<DiskState> for Judgement {
    fn from(s: DiskState) -> Self {
        match s {
            DiskState::Free => Judgement::Free,
            DiskState::Blocked => Judgement::Blocked,
            DiskState::Unseen => Judgement::Undetermined,
        }
    }
}

/// The pairs `(a, b)` of neighbour indices (0-based: `s1` = 0 ... `s8` = 7) summed by `mu`:
/// `(s1,s8), (s1,s2), (s5,s6), (s5,s4), (s7,s6), (s7,s8)`.
pub const MU_PAIRS: [(usize, usize); 6] = [(0, 7), (0, 1), (4, 5), (4, 3), (6, 5), (6, 7)];

/// The pairs `(a, b)` of the lane-end extension counted against an *obstacle* `b`
/// ([`lane_end_score`]): `(s1,s3), (s1,s7), (s5,s3), (s5,s7)`.
pub const LANE_END_PAIRS: [(usize, usize); 4] = [(0, 2), (0, 6), (4, 2), (4, 6)];

/// The pairs `(a, b)` of the lane-end extension counted against a *blocked* `b`
/// ([`lane_end_score`]): `(s7,s1), (s7,s5)`.
pub const START_PAIRS: [(usize, usize); 2] = [(6, 0), (6, 4)];

/// The pairs `(a, b)` of the pixel-level lane-end extension (see `TileModel::open_lane_ends`):
/// the free side `a` (E, W or S) and the lane direction `b` along which it must continue:
/// `(s1,s3), (s1,s7), (s5,s3), (s5,s7), (s7,s1), (s7,s5)`.
pub const SIDE_END_PAIRS: [(usize, usize); 6] = [(0, 2), (0, 6), (4, 2), (4, 6), (6, 0), (6, 4)];

/// The lane-end extension of `mu` (a deviation from the paper, on by default, see
/// [`BaStarOptions::lane_end_corners`]): the pairs of [`LANE_END_PAIRS`] with
/// `free[a] && obstacle[b]` (a side neighbour is free-uncovered while the lane of `s` ends at an
/// obstacle) plus the pairs of [`START_PAIRS`] with `free[a] && blocked[b]` (the south neighbour
/// is free-uncovered while `s` is flanked by a blocked tile).
///
/// Why: the paper's six pairs need a blocked *diagonal*. Property tests found two frontiers
/// without one, where coverage stalls with `L` empty (both kept as regression tests): (1) a lane
/// that ends at obstacles next to an uncovered lane running past both of its ends; (2) the start
/// tile, whose south neighbour BM leaves behind when it goes north first (every other covered
/// tile with a free south neighbour was entered sideways from a tile whose south was blocked, so
/// the paper's `(s7,s6)` / `(s7,s8)` see it). With the extension, every covered tile with a
/// free-uncovered neighbour is in `L` or shares a lane with one that is — on tile-aligned
/// obstacles. Pixel clutter can make a standable neighbour unenterable; the planner then also
/// counts the [`SIDE_END_PAIRS`], judged by moves (a lane that ends at a standable tile it cannot
/// enter was missed, see the regression map `ba_star_pixel_clutter`).
pub fn lane_end_score(free: [bool; 8], obstacle: [bool; 8], blocked: [bool; 8]) -> u32 {
    let a = LANE_END_PAIRS
        .iter()
        .filter(|&&(a, b)| free[a] && obstacle[b])
        .count();
    let b = START_PAIRS
        .iter()
        .filter(|&&(a, b)| free[a] && blocked[b])
        .count();
    (a + b) as u32
}

/// The corner score `mu(s)`: the number of pairs of [`MU_PAIRS`] with `free[a] && blocked[b]`.
/// `free[k]`: neighbour `s(k+1)` is free-uncovered (only read for the 4-neighbours E, W, S);
/// `blocked[k]`: neighbour `s(k+1)` is covered or an obstacle.
pub fn corner_score(free: [bool; 8], blocked: [bool; 8]) -> u32 {
    MU_PAIRS
        .iter()
        .filter(|&&(a, b)| free[a] && blocked[b])
        .count() as u32
}

/// The rotation and translation of seed 000's path following from `pose` to `target`:
/// `(beta, alpha, d)` with `beta = atan2(dy, dx)`, `alpha = wrap(beta - theta)`, `d = |delta|`.
pub fn motion_to(pose: Pose, target: Point) -> (f64, f64, f64) {
    let dx = target.x - pose.x;
    let dy = target.y - pose.y;
    let beta = dy.atan2(dx);
    (beta, wrap_angle(beta - pose.theta), dx.hypot(dy))
}

/// Fixed-point cost of an orthogonal tile step (one tile = 1 000 000).
pub const COST_ORTHO: u64 = 1_000_000;
/// Fixed-point cost of a diagonal tile step (`sqrt 2` rounded up, which keeps the Euclidean
/// heuristic consistent).
pub const COST_DIAG: u64 = 1_414_214;

/// The graph BA* searches: covered tiles, joined when the straight move is free.
pub trait TileGraph {
    /// Inclusive tile bounds `(i0, i1, j0, j1)`; tiles outside are never covered.
    fn bounds(&self) -> (i32, i32, i32, i32);
    /// Is tile `t` covered?
    fn covered(&self, t: Tile) -> bool;
    /// Is the straight move from `t` to its neighbour `t + N8[k]` known to be free?
    fn move_free(&self, t: Tile, k: usize) -> bool;
    /// The edges of `t` as a mask: bit `k` set when [`graph_edge`]`(self, t, k)` holds.
    /// Implementors may override it with a faster equivalent (the searches call it once per
    /// settled tile).
    fn edge_mask(&self, t: Tile) -> u8
    where
        Self: Sized,
    {
        (0..8).fold(0, |m, k| {
            if graph_edge(self, t, k) {
                m | 1 << k
            } else {
                m
            }
        })
    }
}

/// Is the step `t -> t + N8[k]` an edge of the backtracking graph: both tiles covered, a
/// diagonal only when both orthogonal tiles are covered (no corner cutting), the move free.
pub fn graph_edge(g: &impl TileGraph, t: Tile, k: usize) -> bool {
    let (di, dj) = N8[k];
    let v = (t.0 + di, t.1 + dj);
    if !g.covered(v) {
        return false;
    }
    if k % 2 == 1 && !(g.covered((t.0 + di, t.1)) && g.covered((t.0, t.1 + dj))) {
        return false;
    }
    g.move_free(t, k)
}

/// Reusable dense scratch for Dijkstra and A* over a tile rectangle (no hashing; generation
/// stamps avoid clearing between searches). One record per tile, so a visit touches one cache
/// line; heap entries carry the row-major tile index, whose order is the `(j, i)` tie-break.
#[derive(Clone, Debug)]
pub struct TileSearch {
    i0: i32,
    j0: i32,
    w: usize,
    h: usize,
    nodes: Vec<SearchNode>,
    generation: u32,
    heap: MonotoneQueue,
    /// Scratch of [`Self::nearest_of`]: the targets' candidate lists per block.
    blocks: TargetBlocks,
}

/// Side, in tiles, of the blocks of [`TargetBlocks`].
const TARGET_BLOCK: usize = 16;

/// The heuristic of [`TileSearch::nearest_of`]: the least [`octile`] cost from a tile to any
/// of a set of targets, computed from a per-block candidate list (built when the search first
/// reaches the block, reused by every tile of it).
///
/// Block `X` keeps the targets `l` whose octile cost from the nearest tile of `X` is at most
/// `U = min over l' of` the cost from the farthest tile of `X` (a corner: the octile cost is a
/// norm, hence convex). Any other target is farther from every tile of `X` than the target
/// achieving `U`, so the minimum over the list is the minimum over all targets: exact.
///
/// A block's list is taken from the list of its super-block (4 x 4 blocks, built from all
/// targets the same way), which holds it: for `X` inside `Y`, the cost from the nearest tile
/// of `Y` is at most that from the nearest of `X`, and `U` of `X` at most `U` of `Y`. So each
/// target is looked at once per super-block, not once per block.
#[derive(Clone, Debug, Default)]
struct TargetBlocks {
    /// Blocks per row and per column of the search rectangle.
    bw: usize,
    bh: usize,
    /// Per block: the generation its list was built in (0: never).
    stamp: Vec<u32>,
    /// Per block: its list, `arena[range.0..range.1]`.
    range: Vec<(u32, u32)>,
    arena: Vec<Tile>,
    generation: u32,
    targets: Vec<Tile>,
    /// The same per super-block (`SUPER_BLOCKS` blocks a side).
    sbw: usize,
    sstamp: Vec<u32>,
    srange: Vec<(u32, u32)>,
    sarena: Vec<Tile>,
}

/// Blocks a side of a super-block of [`TargetBlocks`].
const SUPER_BLOCKS: usize = 4;

/// The cost of the cheapest 8-neighbour path from `a` to `b` on an unobstructed grid
/// ([`COST_ORTHO`] / [`COST_DIAG`] steps): a lower bound of the search cost, and consistent
/// (it is the path metric of a supergraph with the same edge costs).
#[inline]
pub fn octile(a: Tile, b: Tile) -> u64 {
    octile_gap(u64::from(a.0.abs_diff(b.0)), u64::from(a.1.abs_diff(b.1)))
}

#[inline]
fn octile_gap(dx: u64, dy: u64) -> u64 {
    let (lo, hi) = if dx < dy { (dx, dy) } else { (dy, dx) };
    COST_ORTHO * (hi - lo) + COST_DIAG * lo
}

/// A priority queue of `(key, index)` pairs popping the smallest pair (key, then index) for
/// keys that never go below the last popped key (Dijkstra costs, A* `f` with a consistent
/// heuristic): a radix heap over the keys, plus a binary heap of the indices whose key equals
/// the current minimum. Every pair in a search is distinct, so the pop order is exactly that of
/// a binary heap of the pairs.
#[derive(Clone, Debug)]
struct MonotoneQueue {
    /// The key of the current group (the last popped minimum).
    last: u64,
    /// Indices whose key is `last`.
    current: BinaryHeap<Reverse<u32>>,
    /// Bucket `b` (1..=64) holds the pairs whose key's highest bit differing from `last` is
    /// bit `b - 1`; bucket 0 is unused.
    buckets: Vec<Vec<(u64, u32)>>,
    /// Bit `b` set when bucket `b` may be non-empty.
    nonempty: u128,
}

impl MonotoneQueue {
    fn new() -> Self {
        Self {
            last: 0,
            current: BinaryHeap::new(),
            buckets: vec![Vec::new(); 65],
            nonempty: 0,
        }
    }

    fn clear(&mut self) {
        self.last = 0;
        self.current.clear();
        while self.nonempty != 0 {
            let b = self.nonempty.trailing_zeros() as usize;
            self.nonempty &= self.nonempty - 1;
            self.buckets[b].clear();
        }
    }

    #[inline]
    fn bucket(last: u64, key: u64) -> usize {
        64 - (key ^ last).leading_zeros() as usize
    }

    #[inline]
    fn push(&mut self, key: u64, index: u32) {
        if key < self.last {
            self.lower(key);
        }
        if key == self.last {
            self.current.push(Reverse(index));
        } else {
            let b = Self::bucket(self.last, key);
            self.buckets[b].push((key, index));
            self.nonempty |= 1 << b;
        }
    }

    /// Makes `key` (below the current minimum) the current key, redistributing every pair:
    /// keeps the exact order should a key ever go below the minimum (a heuristic rounding).
    #[cold]
    fn lower(&mut self, key: u64) {
        let mut all: Vec<(u64, u32)> = self
            .current
            .drain()
            .map(|Reverse(i)| (self.last, i))
            .collect();
        for b in &mut self.buckets {
            all.append(b);
        }
        self.nonempty = 0;
        self.last = key;
        for (k, i) in all {
            self.push(k, i);
        }
    }

    #[inline]
    fn pop(&mut self) -> Option<(u64, u32)> {
        if let Some(Reverse(i)) = self.current.pop() {
            return Some((self.last, i));
        }
        if self.nonempty == 0 {
            return None;
        }
        // The lowest non-empty bucket holds the smallest keys: its minimum becomes the new
        // current key and the rest spread into lower buckets.
        let b = self.nonempty.trailing_zeros() as usize;
        self.nonempty &= !(1u128 << b);
        let mut items = std::mem::take(&mut self.buckets[b]);
        let min = items.iter().map(|&(k, _)| k).min().unwrap_or(self.last);
        self.last = min;
        for &(k, i) in &items {
            if k == min {
                self.current.push(Reverse(i));
            } else {
                let nb = Self::bucket(min, k);
                self.buckets[nb].push((k, i));
                self.nonempty |= 1 << nb;
            }
        }
        items.clear();
        self.buckets[b] = items;
        self.current.pop().map(|Reverse(i)| (self.last, i))
    }
}

/// Per-tile search state (16 bytes): labelled in this search when `stamp` is the current
/// generation (even), settled when it is the generation + 1; stamp 0 is "never labelled".
#[derive(Clone, Copy, Debug, Default)]
struct SearchNode {
    dist: u64,
    parent: u32,
    stamp: u32,
}

impl TileSearch {
    /// Scratch for tiles `i0..=i1`, `j0..=j1`.
    pub fn new((i0, i1, j0, j1): (i32, i32, i32, i32)) -> Self {
        let w = (i1 - i0 + 1).max(0) as usize;
        let h = (j1 - j0 + 1).max(0) as usize;
        Self {
            i0,
            j0,
            w,
            h,
            nodes: vec![SearchNode::default(); w * h],
            generation: 0,
            heap: MonotoneQueue::new(),
            blocks: TargetBlocks {
                bw: w.div_ceil(TARGET_BLOCK),
                bh: h.div_ceil(TARGET_BLOCK),
                ..TargetBlocks::default()
            },
        }
    }

    #[inline]
    fn idx(&self, t: Tile) -> Option<usize> {
        let di = t.0 - self.i0;
        let dj = t.1 - self.j0;
        if di < 0 || dj < 0 || di as usize >= self.w || dj as usize >= self.h {
            None
        } else {
            Some(dj as usize * self.w + di as usize)
        }
    }

    #[inline]
    fn tile(&self, k: usize) -> Tile {
        (self.i0 + (k % self.w) as i32, self.j0 + (k / self.w) as i32)
    }

    fn begin(&mut self) {
        self.generation = self.generation.wrapping_add(2);
        if self.generation == 0 {
            for n in &mut self.nodes {
                n.stamp = 0;
            }
            self.generation = 2;
        }
        self.heap.clear();
    }

    /// Is node `k` settled in the current search?
    #[inline]
    fn closed(&self, k: usize) -> bool {
        self.nodes[k].stamp == self.generation + 1
    }

    /// Relaxes the label of node `k` (never called on a settled node).
    #[inline]
    fn relax(&mut self, k: usize, d: u64, parent: u32) -> bool {
        let gen = self.generation;
        let n = &mut self.nodes[k];
        if n.stamp != gen || d < n.dist {
            n.stamp = gen;
            n.dist = d;
            n.parent = parent;
            true
        } else {
            false
        }
    }

    fn path_to(&self, k: usize) -> Vec<Tile> {
        let mut path = vec![self.tile(k)];
        let mut c = k;
        while self.nodes[c].parent != u32::MAX {
            c = self.nodes[c].parent as usize;
            path.push(self.tile(c));
        }
        path.reverse();
        path
    }

    /// Dijkstra from `from` over the graph of [`graph_edge`]; returns the first settled tile
    /// with `is_target` (smallest cost, then smaller `j`, then smaller `i`) and its cost.
    pub fn nearest(
        &mut self,
        g: &impl TileGraph,
        from: Tile,
        is_target: impl Fn(Tile) -> bool,
    ) -> Option<(Tile, u64)> {
        let s = self.idx(from)?;
        self.begin();
        self.relax(s, 0, u32::MAX);
        self.heap.push(0, s as u32);
        while let Some((d, k)) = self.heap.pop() {
            let k = k as usize;
            if self.closed(k) || d > self.nodes[k].dist {
                continue;
            }
            self.nodes[k].stamp = self.generation + 1;
            let t = self.tile(k);
            if is_target(t) {
                return Some((t, d));
            }
            self.expand(g, t, k, d, None);
        }
        None
    }

    /// [`Self::nearest`] when the targets are listed (`targets`: exactly the tiles with
    /// `is_target`): the same tile and cost, found by A* towards the set.
    ///
    /// The heuristic is the least [`octile`] cost to a target (bounded per block of tiles):
    /// consistent, and zero at the targets, whose key is then their cost. Popping in `(key, index)` order,
    /// every tile on a cheapest path to a target of the least cost `d*` is popped, with its
    /// exact cost, before any key above `d*`; so once a target is popped the search goes on
    /// through the key `d*` and answers with the smallest-index target popped at that key:
    /// the first target of the Dijkstra order `(cost, index)`. Targets are not expanded, as
    /// in [`Self::nearest`] (a cheapest path to a target of cost `d*` passes through no other
    /// target: costs are positive). Far targets cost a search of the region between, not of
    /// the disc of radius `d*`.
    pub fn nearest_of(
        &mut self,
        g: &impl TileGraph,
        from: Tile,
        targets: &[Tile],
        is_target: impl Fn(Tile) -> bool,
    ) -> Option<(Tile, u64)> {
        let s = self.idx(from)?;
        self.begin();
        self.blocks.begin(targets);
        self.relax(s, 0, u32::MAX);
        let h0 = self.target_h(from);
        self.heap.push(h0, s as u32);
        let mut best: Option<(usize, u64)> = None;
        while let Some((key, k)) = self.heap.pop() {
            if best.is_some_and(|(_, d)| key > d) {
                break;
            }
            let k = k as usize;
            if self.closed(k) {
                continue;
            }
            self.nodes[k].stamp = self.generation + 1;
            let d = self.nodes[k].dist;
            let t = self.tile(k);
            if is_target(t) {
                if best.is_none_or(|(b, _)| k < b) {
                    best = Some((k, d));
                }
                continue;
            }
            self.expand_to_targets(g, t, k, d);
        }
        best.map(|(k, d)| (self.tile(k), d))
    }

    /// The heuristic of [`Self::nearest_of`] at tile `t` (in the search rectangle).
    #[inline]
    fn target_h(&mut self, t: Tile) -> u64 {
        let bi = (t.0 - self.i0) as usize / TARGET_BLOCK;
        let bj = (t.1 - self.j0) as usize / TARGET_BLOCK;
        let (lo, hi) = self.blocks.list(bi, bj, (self.i0, self.j0));
        self.blocks.arena[lo..hi]
            .iter()
            .map(|&l| octile(t, l))
            .min()
            .unwrap_or(u64::MAX / 4)
    }

    /// [`Self::expand_within`] for [`Self::nearest_of`]: keys `cost + target_h`.
    fn expand_to_targets(&mut self, g: &impl TileGraph, t: Tile, k: usize, d: u64) {
        let mut mask = g.edge_mask(t);
        let gen = self.generation;
        while mask != 0 {
            let n = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let (di, dj) = N8[n];
            let v = (t.0 + di, t.1 + dj);
            let Some(kv) = self.idx(v) else { continue };
            let nd = d + if n % 2 == 1 { COST_DIAG } else { COST_ORTHO };
            let node = self.nodes[kv];
            if node.stamp == gen + 1 || (node.stamp == gen && nd >= node.dist) {
                continue;
            }
            let f = nd + self.target_h(v);
            let node = &mut self.nodes[kv];
            node.stamp = gen;
            node.dist = nd;
            node.parent = k as u32;
            self.heap.push(f, kv as u32);
        }
    }

    fn expand(&mut self, g: &impl TileGraph, t: Tile, k: usize, d: u64, goal: Option<Tile>) {
        self.expand_within(g, t, k, d, goal, u64::MAX);
    }

    /// Relaxes the edges of the settled tile `t` (index `k`, cost `d`), pushing each improved
    /// neighbour with key `cost + heuristic`; a neighbour whose key would exceed `bound` is left
    /// unlabelled (see [`Self::astar_within`]).
    #[inline]
    fn expand_within(
        &mut self,
        g: &impl TileGraph,
        t: Tile,
        k: usize,
        d: u64,
        goal: Option<Tile>,
        bound: u64,
    ) {
        let mut mask = g.edge_mask(t);
        if mask == 0 {
            return;
        }
        // Interior tiles of the search rectangle reach their neighbours by a fixed index
        // offset; the others go through `idx` (a neighbour outside the rectangle is skipped).
        let (di0, dj0) = (t.0 - self.i0, t.1 - self.j0);
        let interior =
            di0 >= 1 && dj0 >= 1 && (di0 as usize) + 1 < self.w && (dj0 as usize) + 1 < self.h;
        let w = self.w as isize;
        let gen = self.generation;
        while mask != 0 {
            let n = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let (di, dj) = N8[n];
            let v = (t.0 + di, t.1 + dj);
            let kv = if interior {
                (k as isize + di as isize + dj as isize * w) as usize
            } else {
                let Some(kv) = self.idx(v) else { continue };
                kv
            };
            let nd = d + if n % 2 == 1 { COST_DIAG } else { COST_ORTHO };
            let node = &mut self.nodes[kv];
            // Settled (stamp gen + 1), or labelled at least as well: nothing to do.
            if node.stamp == gen + 1 || (node.stamp == gen && nd >= node.dist) {
                continue;
            }
            let f = match goal {
                Some(gl) => {
                    // The octile cost to the goal bounds the remaining cost from below and
                    // is at least the Euclidean heuristic: a label beyond `bound` by it lies
                    // on no path of cost `<= bound` (see [`Self::astar_bounded`]).
                    if bound != u64::MAX && nd + octile(v, gl) > bound {
                        continue;
                    }
                    nd + heuristic(v, gl)
                }
                None => nd,
            };
            if f > bound {
                continue;
            }
            node.stamp = gen;
            node.dist = nd;
            node.parent = k as u32;
            self.heap.push(f, kv as u32);
        }
    }

    /// A* from `from` to `to` over the graph of [`graph_edge`] (costs [`COST_ORTHO`] /
    /// [`COST_DIAG`], Euclidean heuristic); the tile path (both ends included) and its cost.
    pub fn astar(&mut self, g: &impl TileGraph, from: Tile, to: Tile) -> Option<(Vec<Tile>, u64)> {
        self.astar_within(g, from, to, u64::MAX)
    }

    /// [`Self::astar`] when the cost of the best path is known to be `cost` (say from
    /// [`Self::nearest`] on the same graph): the same answer, without labelling a tile whose
    /// label plus the [`octile`] cost to the goal exceeds `cost` (the keys stay `cost +`
    /// Euclidean heuristic; the octile cost is at least that heuristic).
    ///
    /// Why it is the same: the octile cost is a lower bound of the remaining cost, so a
    /// left-out label is either worse than its tile's best cost or belongs to a tile on no
    /// cheapest path to the goal. Call the tiles on cheapest paths *optimal*. With a consistent
    /// heuristic every tile is settled through the label of its best cost, and an optimal
    /// tile's best label is pushed when the first of its optimal predecessors (in settling
    /// order) is expanded, with that predecessor as parent; no left-out or other label of
    /// another tile can set or block it (they are worse, or from tiles that are not optimal
    /// predecessors). So the best labels of optimal tiles are pushed at the same points of the
    /// sequence of optimal settlings in both searches, and as the queue pops pairs in
    /// `(key, index)` order, both settle the optimal tiles in the same order, with the same
    /// parents, up to the goal: the same path and cost. Should the bound be too low (or the
    /// heuristic inconsistent), this search runs dry before the goal and the full search is
    /// run instead.
    pub fn astar_bounded(
        &mut self,
        g: &impl TileGraph,
        from: Tile,
        to: Tile,
        cost: u64,
    ) -> Option<(Vec<Tile>, u64)> {
        self.astar_within(g, from, to, cost)
            .or_else(|| self.astar_within(g, from, to, u64::MAX))
    }

    fn astar_within(
        &mut self,
        g: &impl TileGraph,
        from: Tile,
        to: Tile,
        bound: u64,
    ) -> Option<(Vec<Tile>, u64)> {
        let s = self.idx(from)?;
        self.idx(to)?;
        self.begin();
        self.relax(s, 0, u32::MAX);
        self.heap.push(heuristic(from, to), s as u32);
        while let Some((_, k)) = self.heap.pop() {
            let k = k as usize;
            if self.closed(k) {
                continue;
            }
            self.nodes[k].stamp = self.generation + 1;
            let d = self.nodes[k].dist;
            let t = self.tile(k);
            if t == to {
                return Some((self.path_to(k), d));
            }
            self.expand_within(g, t, k, d, Some(to), bound);
        }
        None
    }
}

impl TargetBlocks {
    /// A new search towards `targets`: every block's list is stale.
    fn begin(&mut self, targets: &[Tile]) {
        if self.stamp.len() != self.bw * self.bh {
            self.stamp = vec![0; self.bw * self.bh];
            self.range = vec![(0, 0); self.bw * self.bh];
            self.sbw = self.bw.div_ceil(SUPER_BLOCKS);
            let n = self.sbw * self.bh.div_ceil(SUPER_BLOCKS);
            self.sstamp = vec![0; n];
            self.srange = vec![(0, 0); n];
        }
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.stamp.fill(0);
            self.sstamp.fill(0);
            self.generation = 1;
        }
        self.arena.clear();
        self.sarena.clear();
        self.targets.clear();
        self.targets.extend_from_slice(targets);
    }

    /// The arena range of block `(bi, bj)` of a search rectangle whose first tile is
    /// `origin`, built on first use.
    #[inline]
    fn list(&mut self, bi: usize, bj: usize, origin: Tile) -> (usize, usize) {
        let b = bj * self.bw + bi;
        if self.stamp[b] != self.generation {
            self.build(bi, bj, origin);
        }
        let (lo, hi) = self.range[b];
        (lo as usize, hi as usize)
    }

    fn build(&mut self, bi: usize, bj: usize, origin: Tile) {
        let (si, sj) = (bi / SUPER_BLOCKS, bj / SUPER_BLOCKS);
        let sb = sj * self.sbw + si;
        if self.sstamp[sb] != self.generation {
            let side = TARGET_BLOCK * SUPER_BLOCKS;
            let lo = self.sarena.len();
            candidates(
                &self.targets,
                block_rect(origin, si, sj, side),
                &mut self.sarena,
            );
            self.srange[sb] = (lo as u32, self.sarena.len() as u32);
            self.sstamp[sb] = self.generation;
        }
        let (slo, shi) = self.srange[sb];
        let lo = self.arena.len();
        candidates(
            &self.sarena[slo as usize..shi as usize],
            block_rect(origin, bi, bj, TARGET_BLOCK),
            &mut self.arena,
        );
        let b = bj * self.bw + bi;
        self.range[b] = (lo as u32, self.arena.len() as u32);
        self.stamp[b] = self.generation;
    }
}

/// The tiles `(x0, x1, y0, y1)` of block `(bi, bj)` of side `side` from `origin` (not clipped
/// to the search rectangle: a larger block keeps every list exact).
fn block_rect(origin: Tile, bi: usize, bj: usize, side: usize) -> (i32, i32, i32, i32) {
    let x0 = origin.0 + (bi * side) as i32;
    let y0 = origin.1 + (bj * side) as i32;
    (x0, x0 + side as i32 - 1, y0, y0 + side as i32 - 1)
}

/// Appends to `out` the targets of `src` kept for the block `(x0, x1, y0, y1)` (see
/// [`TargetBlocks`]), in the order of `src`.
fn candidates(src: &[Tile], (x0, x1, y0, y1): (i32, i32, i32, i32), out: &mut Vec<Tile>) {
    let gap = |v: i32, lo: i32, hi: i32| {
        u64::from(
            lo.saturating_sub(v)
                .max(v.saturating_sub(hi))
                .max(0)
                .unsigned_abs(),
        )
    };
    let near = |l: Tile| octile_gap(gap(l.0, x0, x1), gap(l.1, y0, y1));
    let far = |l: Tile| {
        let dx = u64::from(l.0.abs_diff(x0).max(l.0.abs_diff(x1)));
        let dy = u64::from(l.1.abs_diff(y0).max(l.1.abs_diff(y1)));
        octile_gap(dx, dy)
    };
    let u = src.iter().map(|&l| far(l)).min().unwrap_or(0);
    out.extend(src.iter().copied().filter(|&l| near(l) <= u));
}

/// Euclidean distance between tiles in the fixed-point unit of [`COST_ORTHO`], rounded down
/// (admissible and consistent with the rounded-up diagonal cost).
#[inline]
pub fn heuristic(a: Tile, b: Tile) -> u64 {
    let di = f64::from(a.0 - b.0);
    let dj = f64::from(a.1 - b.1);
    // The product is finite and >= 0, where the truncating cast is the floor (without a call
    // into libm).
    (di.hypot(dj) * COST_ORTHO as f64) as u64
}

/// Squared distance between segment `a`-`b` and the axis-aligned box `lo`-`hi` (0 when they
/// meet).
fn segment_box_dist2(a: Point, b: Point, lo: Point, hi: Point) -> f64 {
    // Liang-Barsky clip: does the segment meet the box?
    let d = Point::new(b.x - a.x, b.y - a.y);
    let mut t0: f64 = 0.0;
    let mut t1: f64 = 1.0;
    let mut meets = true;
    for (p, q) in [
        (-d.x, a.x - lo.x),
        (d.x, hi.x - a.x),
        (-d.y, a.y - lo.y),
        (d.y, hi.y - a.y),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                meets = false;
                break;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
            if t0 > t1 {
                meets = false;
                break;
            }
        }
    }
    if meets {
        return 0.0;
    }
    let pb = |p: Point| {
        let dx = (lo.x - p.x).max(0.0).max(p.x - hi.x);
        let dy = (lo.y - p.y).max(0.0).max(p.y - hi.y);
        dx * dx + dy * dy
    };
    let mut best = pb(a).min(pb(b));
    for c in [lo, Point::new(hi.x, lo.y), hi, Point::new(lo.x, hi.y)] {
        best = best.min(point_segment_dist2(c, a, b));
    }
    best
}

/// Calls `f` for every tile whose square the open disk of radius `rho` (in tile units) touches
/// while its centre moves from tile `a`'s centre to tile `b`'s; stops early when `f` returns
/// `false` (and then returns `false`). Tiles merely touching the swept disk's boundary (distance
/// exactly `rho`, as for the side neighbours of a straight move between centres at `rho = 1/2`)
/// are not touched.
pub fn for_each_swept_tile(a: Tile, b: Tile, rho: f64, mut f: impl FnMut(Tile) -> bool) -> bool {
    let pa = Point::new(f64::from(a.0), f64::from(a.1));
    let pb = Point::new(f64::from(b.0), f64::from(b.1));
    let lim = (rho * rho) * (1.0 - 1e-9) - 1e-12;
    let (dx, dy) = (pb.x - pa.x, pb.y - pa.y);
    // Shortcuts from the squared distance of a tile's centre to the segment, exact with wide
    // margins (the unit square holds the disk of radius 1/2 around its centre and lies in the
    // disk of radius sqrt(1/2)): clearly below 1/4, the segment crosses the square (box
    // distance 0 < `lim`); clearly above `(rho + sqrt(1/2))^2`, the square is farther than
    // `rho`. Only the tiles between take the box distance.
    let accept2 = if lim > 1e-9 {
        0.25 * (1.0 - 1e-6)
    } else {
        -1.0
    };
    let reject2 = (rho + std::f64::consts::FRAC_1_SQRT_2 + 1e-6).powi(2);
    let touches = |i: i32, y: f64| {
        let dc2 = point_segment_dist2(Point::new(f64::from(i), y), pa, pb);
        if dc2 < accept2 {
            true
        } else if dc2 >= reject2 {
            false
        } else {
            let lo = Point::new(f64::from(i) - 0.5, y - 0.5);
            let hi = Point::new(f64::from(i) + 0.5, y + 0.5);
            segment_box_dist2(pa, pb, lo, hi) < lim
        }
    };
    let step: i32 = if b.1 >= a.1 { 1 } else { -1 };
    let reach = rho + 0.5;
    let j_first = if step > 0 {
        floor_i32(pa.y - reach)
    } else {
        ceil_i32(pa.y + reach)
    };
    let j_last = if step > 0 {
        ceil_i32(pb.y + reach)
    } else {
        floor_i32(pb.y - reach)
    };
    let mut j = j_first;
    loop {
        let y = f64::from(j);
        let (tl, th) = if dy == 0.0 {
            (0.0, 1.0)
        } else {
            let t1 = (y - reach - pa.y) / dy;
            let t2 = (y + reach - pa.y) / dy;
            (t1.min(t2).max(0.0), t1.max(t2).min(1.0))
        };
        if tl <= th && (dy != 0.0 || (pa.y - y).abs() <= reach) {
            let xa = pa.x + tl * dx;
            let xb = pa.x + th * dx;
            let i_lo = floor_i32(xa.min(xb) - reach);
            let i_hi = ceil_i32(xa.max(xb) + reach);
            let (mut i, i_end, istep) = if dx >= 0.0 {
                (i_lo, i_hi, 1)
            } else {
                (i_hi, i_lo, -1)
            };
            loop {
                if touches(i, y) && !f((i, j)) {
                    return false;
                }
                if i == i_end {
                    break;
                }
                i += istep;
            }
        }
        if j == j_last {
            break;
        }
        j += step;
    }
    true
}

/// A*SPT: from the current waypoint jump to the farthest later tile of `path` for which
/// `visible(from, to)` holds; repeat. Consecutive tiles of the path must be visible (so the
/// result always reaches the last tile).
pub fn smooth_path(path: &[Tile], mut visible: impl FnMut(Tile, Tile) -> bool) -> Vec<Tile> {
    let Some(&first) = path.first() else {
        return Vec::new();
    };
    let mut out = vec![first];
    let mut k = 0;
    let n = path.len();
    while k + 1 < n {
        let mut m = n - 1;
        while m > k + 1 && !visible(path[k], path[m]) {
            m -= 1;
        }
        out.push(path[m]);
        k = m;
    }
    out
}

/// Margin (pixels) added to the contact radius when [`Mind::sense`] bounds the tiles a new
/// pixel can affect: covers the rounding of the world/grid/tile conversions (the exact test
/// follows; a larger margin only costs time).
const CANDIDATE_MARGIN_PX: f64 = 0.01;

/// Margin (pixels) of the box of pixels that can touch a tile's contact disk in
/// [`Mind::sense`] (a pixel centre `q` touches when `|q - g|^2 < rc^2`, so `|q.x - g.x| < rc`
/// and `|q.y - g.y| < rc` up to rounding): far above the rounding of grid coordinates of a
/// few thousand pixels, far below a pixel.
const TIGHT_BOX_MARGIN_PX: f64 = 1e-7;

// Tile state bits.
const ST_STAND: u8 = 0b0011; // Judgement of standing at the centre
const ST_COVERED: u8 = 0b0100;
/// The tile's contact disk is in the [`DiskCache`].
const ST_DISK: u8 = 0b1000;

/// The discovered tiling `M̂` with cached judgements, dense over the frame's tile extent.
#[derive(Clone, Debug)]
struct TileModel {
    grid: TileGrid,
    i0: i32,
    j0: i32,
    w: usize,
    h: usize,
    /// Per tile: standability (2 bits), covered.
    state: Vec<u8>,
    /// Per tile: judgements (2 bits each) of the moves towards s1..s4 (E, NE, N, NW); the
    /// moves towards s5..s8 are stored at the neighbour.
    moves: Vec<u8>,
    /// The backtracking list `L` (row-major tile indices), listed in `O(|L|)`.
    l: IndexSet,
    /// Add [`lane_end_score`] to `mu`.
    lane_end_corners: bool,
}

impl TileModel {
    fn new(grid: TileGrid, frame: &MapFrame) -> Self {
        let (lo, hi) = frame.world_bounds();
        let a = grid.tile_of(lo);
        let b = grid.tile_of(hi);
        let w = (b.0 - a.0 + 1).max(1) as usize;
        let h = (b.1 - a.1 + 1).max(1) as usize;
        Self {
            grid,
            i0: a.0,
            j0: a.1,
            w,
            h,
            state: vec![0; w * h],
            moves: vec![0; w * h],
            l: IndexSet::new(w * h),
            lane_end_corners: true,
        }
    }

    /// Tiles whose disk reaches outside the image are obstacles from the frame alone (the
    /// outside of the map is occupied): judge them once, before any scan.
    fn judge_frame_edges(&mut self, known: &KnownMap, r: f64) {
        let frame = *known.frame();
        let rc = contact_radius_px(r / frame.resolution) + 1.0;
        let (w, h) = (frame.width as f64, frame.height as f64);
        for k in 0..self.state.len() {
            let t = (self.i0 + (k % self.w) as i32, self.j0 + (k / self.w) as i32);
            let p = self.grid.center(t);
            let g = frame.world_to_grid(p);
            if g.x - rc > 0.0 && g.y - rc > 0.0 && g.x + rc < w && g.y + rc < h {
                continue;
            }
            let j = judge_motion(known, p, p, r);
            self.state[k] = (self.state[k] & !ST_STAND) | j as u8;
        }
    }

    fn bounds(&self) -> (i32, i32, i32, i32) {
        (
            self.i0,
            self.i0 + self.w as i32 - 1,
            self.j0,
            self.j0 + self.h as i32 - 1,
        )
    }

    #[inline]
    fn idx(&self, t: Tile) -> Option<usize> {
        let di = t.0 - self.i0;
        let dj = t.1 - self.j0;
        if di < 0 || dj < 0 || di as usize >= self.w || dj as usize >= self.h {
            None
        } else {
            Some(dj as usize * self.w + di as usize)
        }
    }

    #[inline]
    fn covered(&self, t: Tile) -> bool {
        self.idx(t).is_some_and(|k| self.state[k] & ST_COVERED != 0)
    }

    #[inline]
    fn stand(&self, t: Tile) -> Judgement {
        match self.idx(t) {
            Some(k) => Judgement::from_bits(self.state[k] & ST_STAND),
            None => Judgement::Blocked,
        }
    }

    #[inline]
    fn in_l(&self, t: Tile) -> bool {
        self.idx(t).is_some_and(|k| self.l.contains(k))
    }

    /// `(owner tile, slot 0..4)` of the move `t -> t + N8[k]`.
    #[inline]
    fn move_slot(t: Tile, k: usize) -> (Tile, usize) {
        if k < 4 {
            (t, k)
        } else {
            ((t.0 + N8[k].0, t.1 + N8[k].1), k - 4)
        }
    }

    #[inline]
    fn cached_move(&self, t: Tile, k: usize) -> Judgement {
        let (o, s) = Self::move_slot(t, k);
        match self.idx(o) {
            Some(i) => Judgement::from_bits(self.moves[i] >> (2 * s)),
            None => Judgement::Blocked,
        }
    }

    fn set_move(&mut self, t: Tile, k: usize, j: Judgement) {
        let (o, s) = Self::move_slot(t, k);
        if let Some(i) = self.idx(o) {
            self.moves[i] = (self.moves[i] & !(3 << (2 * s))) | ((j as u8) << (2 * s));
        }
    }

    /// Is `M̂(t)` blocked (covered or obstacle)? Out-of-frame tiles are obstacles.
    #[inline]
    fn blocked(&self, t: Tile) -> bool {
        match self.idx(t) {
            Some(k) => {
                self.state[k] & ST_COVERED != 0
                    || Judgement::from_bits(self.state[k] & ST_STAND) == Judgement::Blocked
            }
            None => true,
        }
    }

    /// Free-uncovered 4-neighbour `k` of `s`: not covered and the move `s -> it` judged free.
    #[inline]
    fn free_uncovered(&self, s: Tile, k: usize) -> bool {
        let n = (s.0 + N8[k].0, s.1 + N8[k].1);
        !self.covered(n) && self.cached_move(s, k) == Judgement::Free
    }

    /// `mu(s)` from the cached judgements (plus the lane-end extension when enabled).
    fn mu(&self, s: Tile) -> u32 {
        let mut free = [false; 8];
        let mut blocked = [false; 8];
        for k in [0, 4, 6] {
            free[k] = self.free_uncovered(s, k);
        }
        if !(free[0] || free[4] || free[6]) {
            return 0;
        }
        for (k, &(di, dj)) in N8.iter().enumerate() {
            blocked[k] = self.blocked((s.0 + di, s.1 + dj));
        }
        let mut mu = corner_score(free, blocked);
        if self.lane_end_corners {
            let mut obstacle = [false; 8];
            for k in [2, 6] {
                obstacle[k] = self.stand((s.0 + N8[k].0, s.1 + N8[k].1)) == Judgement::Blocked;
            }
            mu += lane_end_score(free, obstacle, blocked);
            mu += self.open_lane_ends(s, free);
        }
        mu
    }

    /// Does the lane of the covered tile `s` carry its free side `a` on to the neighbour
    /// `n = s + N8[b]`: `n` covered, the move `s -> n` free and `n`'s side `a` free-uncovered?
    #[inline]
    fn side_continues(&self, s: Tile, b: usize, a: usize) -> bool {
        let n = (s.0 + N8[b].0, s.1 + N8[b].1);
        self.covered(n) && self.cached_move(s, b) == Judgement::Free && self.free_uncovered(n, a)
    }

    /// The pixel-level part of the lane-end extension: the pairs `(a, b)` of [`SIDE_END_PAIRS`]
    /// with `a` free-uncovered, `b` not free-uncovered, and the lane not carrying the free side
    /// `a` on to `b` ([`TileModel::side_continues`]).
    ///
    /// Why: [`corner_score`] and [`lane_end_score`] judge the tiles `b` and the diagonals by
    /// *standability* alone. On tile-aligned obstacles a standable neighbour can always be
    /// entered by the straight move, so "not standable" is the same as "not enterable"; pixel
    /// clutter breaks that. A single pixel beside the segment between two standable tile
    /// centres blocks the move while both disks are free, so a lane could end at a standable
    /// but unenterable tile (the regression map `ba_star_pixel_clutter`: the lane end at
    /// `(-2, -1)` with its whole west side uncovered was never put in `L`, BA* stopped at 2/3 of
    /// the reachable tiles), or a standable diagonal could be unenterable from the lane's next
    /// tile. Judged by moves instead, the rule is complete: every covered tile with a
    /// free-uncovered neighbour `a` in E, W, S leads, walking along the lane (N for a side E/W,
    /// E for S) while the free side continues, to a tile where it stops; that tile has a pair
    /// here unless its own next neighbour is free-uncovered, which can only be E for side S
    /// (BM never leaves a covered tile with a free-uncovered north: it goes there first), and
    /// then the E side starts a walk of the first kind. On tile-aligned maps every such pair is
    /// also a pair of [`corner_score`] or [`lane_end_score`], so `L` is unchanged there.
    fn open_lane_ends(&self, s: Tile, free: [bool; 8]) -> u32 {
        SIDE_END_PAIRS
            .iter()
            .filter(|&&(a, b)| {
                free[a] && !self.free_uncovered(s, b) && !self.side_continues(s, b, a)
            })
            .count() as u32
    }

    /// The 3 x 3 block of tile states and move bytes centred on `s` (see [`Block3`]).
    #[inline]
    fn block3(&self, s: Tile) -> Block3 {
        let di = s.0 - self.i0;
        let dj = s.1 - self.j0;
        let mut b = Block3 {
            state: [BLOCK3_OUTSIDE_STATE; 25],
            moves: [BLOCK3_OUTSIDE_MOVES; 25],
            c: 12,
        };
        if di >= 1 && dj >= 1 && di as usize + 1 < self.w && dj as usize + 1 < self.h {
            let sw = (dj as usize - 1) * self.w + di as usize - 1;
            for r in 0..3 {
                let k = sw + r * self.w;
                b.state[6 + 5 * r..9 + 5 * r].copy_from_slice(&self.state[k..k + 3]);
                b.moves[6 + 5 * r..9 + 5 * r].copy_from_slice(&self.moves[k..k + 3]);
            }
        } else {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    if let Some(k) = self.idx((s.0 + dx, s.1 + dy)) {
                        let at = b.at((dx, dy));
                        b.state[at] = self.state[k];
                        b.moves[at] = self.moves[k];
                    }
                }
            }
        }
        b
    }

    /// Recomputes the L membership of `t` (`mu` read off the [`Block3`] around `t`: the same
    /// value as [`TileModel::mu`], which tests check through [`BaStar::backtrack_list_full`]).
    fn update_l(&mut self, t: Tile) {
        let Some(k) = self.idx(t) else { return };
        if self.state[k] & ST_COVERED != 0 && self.block3(t).in_l(self.lane_end_corners) {
            self.l.insert(k);
        } else {
            self.l.remove(k);
        }
    }

    /// [`TileModel::update_l`] of `t` and its eight neighbours. Away from the border of the
    /// range the 5 x 5 block of states and moves they read is copied once, and each tile's
    /// [`Block3`] taken from the copy.
    fn update_l_around(&mut self, t: Tile) {
        let di = t.0 - self.i0;
        let dj = t.1 - self.j0;
        if !(di >= 2 && dj >= 2 && di as usize + 2 < self.w && dj as usize + 2 < self.h) {
            self.update_l(t);
            for (di, dj) in N8 {
                self.update_l((t.0 + di, t.1 + dj));
            }
            return;
        }
        let w = self.w;
        let k = dj as usize * w + di as usize;
        let mut b = Block3 {
            state: [0; 25],
            moves: [0; 25],
            c: 12,
        };
        for r in 0..5 {
            let base = k - 2 * w - 2 + r * w;
            b.state[5 * r..5 * r + 5].copy_from_slice(&self.state[base..base + 5]);
            b.moves[5 * r..5 * r + 5].copy_from_slice(&self.moves[base..base + 5]);
        }
        for (dx, dy) in std::iter::once((0, 0)).chain(N8) {
            // The tile's index in the copy and in the dense arrays.
            let c = ((dy + 2) * 5 + dx + 2) as usize;
            let kc = (k as isize + dy as isize * w as isize + dx as isize) as usize;
            if b.state[c] & ST_COVERED == 0 {
                self.l.remove(kc);
                continue;
            }
            b.c = c;
            if b.in_l(self.lane_end_corners) {
                self.l.insert(kc);
            } else {
                self.l.remove(kc);
            }
        }
    }

    fn l_tiles(&self) -> Vec<Tile> {
        let mut v = Vec::with_capacity(self.l.len());
        self.l
            .for_each(|k| v.push((self.i0 + (k % self.w) as i32, self.j0 + (k / self.w) as i32)));
        v
    }
}

/// State of a tile outside the tiling's range in a [`Block3`]: an obstacle, not covered (as
/// [`TileModel::stand`] and [`TileModel::covered`] read it).
const BLOCK3_OUTSIDE_STATE: u8 = Judgement::Blocked as u8;
/// Move byte of a tile outside the range in a [`Block3`]: all four moves blocked (as
/// [`TileModel::cached_move`] reads it).
const BLOCK3_OUTSIDE_MOVES: u8 = 0b1010_1010;

/// A copy of the tile states and move bytes of a 5 x 5 block of tiles (index
/// `(dj + 2) * 5 + di + 2` for the offset `(di, dj)` from the middle tile), read around the
/// tile at index `c` (whose 3 x 3 tiles must lie in the block): everything `mu` of that tile
/// reads, so `mu` runs on a small local copy instead of bounds-checked lookups into the dense
/// arrays, and the nine tiles around a newly covered one share one copy.
struct Block3 {
    state: [u8; 25],
    moves: [u8; 25],
    c: usize,
}

impl Block3 {
    #[inline]
    fn at(&self, d: Tile) -> usize {
        (self.c as isize + (d.1 * 5 + d.0) as isize) as usize
    }

    #[inline]
    fn covered(&self, d: Tile) -> bool {
        self.state[self.at(d)] & ST_COVERED != 0
    }

    #[inline]
    fn stand_blocked(&self, d: Tile) -> bool {
        Judgement::from_bits(self.state[self.at(d)] & ST_STAND) == Judgement::Blocked
    }

    /// [`TileModel::cached_move`] of the move `d -> d + N8[k]` is free (its owner tile must lie
    /// in the block: true for every move `mu` reads).
    #[inline]
    fn move_free(&self, d: Tile, k: usize) -> bool {
        let (o, slot) = TileModel::move_slot(d, k);
        Judgement::from_bits(self.moves[self.at(o)] >> (2 * slot)) == Judgement::Free
    }

    /// [`TileModel::free_uncovered`] for the neighbour `k` of the block tile `d`.
    #[inline]
    fn free_uncovered(&self, d: Tile, k: usize) -> bool {
        !self.covered((d.0 + N8[k].0, d.1 + N8[k].1)) && self.move_free(d, k)
    }

    /// `mu >= 1` for the centre tile ([`TileModel::mu`]): the same pairs, stopping at the
    /// first that counts.
    #[inline]
    fn in_l(&self, lane_end_corners: bool) -> bool {
        let s = (0, 0);
        let f0 = self.free_uncovered(s, 0);
        let f4 = self.free_uncovered(s, 4);
        let f6 = self.free_uncovered(s, 6);
        if !(f0 || f4 || f6) {
            return false;
        }
        let blocked = |k: usize| self.covered(N8[k]) || self.stand_blocked(N8[k]);
        // corner_score: (s1,s8), (s1,s2), (s5,s6), (s5,s4), (s7,s6), (s7,s8).
        if (f0 && (blocked(7) || blocked(1)))
            || (f4 && (blocked(5) || blocked(3)))
            || (f6 && (blocked(5) || blocked(7)))
        {
            return true;
        }
        if !lane_end_corners {
            return false;
        }
        // lane_end_score: (s1,s3), (s1,s7), (s5,s3), (s5,s7) against obstacles; (s7,s1),
        // (s7,s5) against blocked tiles.
        if ((f0 || f4) && (self.stand_blocked(N8[2]) || self.stand_blocked(N8[6])))
            || (f6 && (blocked(0) || blocked(4)))
        {
            return true;
        }
        let free = [f0, false, false, false, f4, false, f6, false];
        SIDE_END_PAIRS.iter().any(|&(a, b)| {
            free[a] && !self.free_uncovered(s, b) && {
                // Not [`TileModel::side_continues`].
                let n = N8[b];
                !(self.covered(n) && self.move_free(s, b) && self.free_uncovered(n, a))
            }
        })
    }

    /// [`TileModel::mu`] of the centre tile.
    #[cfg(test)]
    fn mu(&self, lane_end_corners: bool) -> u32 {
        let s = (0, 0);
        let mut free = [false; 8];
        for k in [0, 4, 6] {
            free[k] = self.free_uncovered(s, k);
        }
        if !(free[0] || free[4] || free[6]) {
            return 0;
        }
        let mut blocked = [false; 8];
        for (k, &d) in N8.iter().enumerate() {
            blocked[k] = self.covered(d) || self.stand_blocked(d);
        }
        let mut mu = corner_score(free, blocked);
        if lane_end_corners {
            let mut obstacle = [false; 8];
            for k in [2, 6] {
                obstacle[k] = self.stand_blocked(N8[k]);
            }
            mu += lane_end_score(free, obstacle, blocked);
            mu += SIDE_END_PAIRS
                .iter()
                .filter(|&&(a, b)| {
                    free[a] && !self.free_uncovered(s, b) && {
                        // Not [`TileModel::side_continues`].
                        let n = N8[b];
                        !(self.covered(n) && self.move_free(s, b) && self.free_uncovered(n, a))
                    }
                })
                .count() as u32;
        }
        mu
    }
}

impl TileGraph for TileModel {
    fn bounds(&self) -> (i32, i32, i32, i32) {
        TileModel::bounds(self)
    }
    fn covered(&self, t: Tile) -> bool {
        TileModel::covered(self, t)
    }
    fn move_free(&self, t: Tile, k: usize) -> bool {
        self.cached_move(t, k) == Judgement::Free
    }
    /// [`graph_edge`] for all eight neighbours at once, read off the dense arrays (interior
    /// tiles; tiles on the border of the range take the generic path).
    fn edge_mask(&self, t: Tile) -> u8 {
        let di = t.0 - self.i0;
        let dj = t.1 - self.j0;
        if di < 1 || dj < 1 || di as usize + 1 >= self.w || dj as usize + 1 >= self.h {
            return (0..8).fold(0, |m, k| {
                if graph_edge(self, t, k) {
                    m | 1 << k
                } else {
                    m
                }
            });
        }
        let w = self.w;
        let k = dj as usize * w + di as usize;
        // Row-major index of each neighbour s1..s8 (j grows with the index).
        let nb = [
            k + 1,
            k + w + 1,
            k + w,
            k + w - 1,
            k - 1,
            k - w - 1,
            k - w,
            k - w + 1,
        ];
        let cov = |i: usize| self.state[i] & ST_COVERED != 0;
        let mut covered = 0u8;
        for (n, &i) in nb.iter().enumerate() {
            if cov(i) {
                covered |= 1 << n;
            }
        }
        // Move judgements: s1..s4 at `k` (slots 0..3); s5..s8 at the neighbour, slot n - 4.
        let free =
            |i: usize, slot: usize| (self.moves[i] >> (2 * slot)) & 3 == Judgement::Free as u8;
        let mut mask = 0u8;
        for n in 0..8 {
            if covered & (1 << n) == 0 {
                continue;
            }
            // A diagonal needs both orthogonal tiles beside it covered (no corner cutting).
            if n % 2 == 1 && (covered & (1 << (n - 1)) == 0 || covered & (1 << ((n + 1) % 8)) == 0)
            {
                continue;
            }
            let ok = if n < 4 {
                free(k, n)
            } else {
                free(nb[n], n - 4)
            };
            if ok {
                mask |= 1 << n;
            }
        }
        mask
    }
}

/// Everything the planner knows once it has seen its first scan.
#[derive(Clone)]
struct Mind {
    known: KnownMap,
    tiles: TileModel,
    search: TileSearch,
    r: f64,
    /// Contact radius in pixels.
    rc_px: f64,
    /// Where the last scan was integrated.
    last_scan: Option<Point>,
    /// The disk of the last scan integrated ([`crate::planner::Scan::disk_px`]): the rows a
    /// new scan shares with it hold nothing new.
    last_disk: Option<(Point, f64)>,
    /// Scratch for [`Mind::sense`]: per row of the last scan, the column span of the pixels
    /// seen for the first time (`(usize::MAX, 0)` when none).
    new_spans: Vec<(usize, usize)>,
    /// Scratch for [`Mind::sense`]: per tile row of the candidate box, the hull of the
    /// candidate tile columns (`(i32::MAX, i32::MIN)` when none).
    candidate_rows: Vec<(i32, i32)>,
    /// Rows of new pixels per candidate band in [`Mind::sense`]: about one tile side.
    band_rows: usize,
    /// Per-tile cache of the contact disk's pixel spans for [`Mind::judge_tile_first`] and
    /// [`Mind::sense`].
    disk: DiskCache,
    /// Grid x of the centre of each tile column (from the tiling's first column) and grid y
    /// of each tile row, when the frame is not rotated (a centre's grid x then depends on its
    /// world x alone, its y on its world y alone); empty otherwise. Exactly
    /// `frame.world_to_grid(center(t))`, computed once.
    gx: Vec<f64>,
    gy: Vec<f64>,
    /// [`Mind::touch_box`] per tile column and per tile row (from `gx`, `gy`).
    touch_cols: Vec<(i64, i64)>,
    touch_rows: Vec<(i64, i64)>,
    /// Per image column `c`: the tile columns `i` (inclusive) whose touch box can hold `c`,
    /// as `(first i whose box ends at or after c, last i whose box starts at or before c)`
    /// (boxes move right with `i`); per image row the same for tile rows. Empty when the
    /// frame is rotated.
    col_tiles: Vec<(i32, i32)>,
    row_tiles: Vec<(i32, i32)>,
}

/// [`Mind::col_tiles`] / [`Mind::row_tiles`]: for each of `n` pixel indices `p`, the range of
/// tile indices (from `first`) whose pixel range `boxes[k]` can hold `p`: `lo(k)` and `hi(k)`
/// must be non-decreasing in `k` (`rev`: non-increasing, the rows).
fn pixel_to_tiles(boxes: &[(i64, i64)], n: usize, first: i32, rev: bool) -> Vec<(i32, i32)> {
    (0..n as i64)
        .map(|p| {
            if rev {
                // Boxes move up (to smaller rows) with k: the first k starting at or above p,
                // the last k ending at or below p.
                let a = boxes.partition_point(|b| b.0 > p);
                let b = boxes.partition_point(|b| b.1 >= p);
                (first + a as i32, first + b as i32 - 1)
            } else {
                let a = boxes.partition_point(|b| b.1 < p);
                let b = boxes.partition_point(|b| b.0 <= p);
                (first + a as i32, first + b as i32 - 1)
            }
        })
        .collect()
}

/// The rows and columns of [`Mind::touch_box`] for a disk of contact radius `rc` pixels at grid
/// point `g` in an image of height `h` pixels: `((row_lo, row_hi), (col_lo, col_hi))`.
#[inline]
fn touch_box_of(g: Point, rc: f64, h: f64) -> ((i64, i64), (i64, i64)) {
    let m = TIGHT_BOX_MARGIN_PX;
    (
        (
            ceil_i64(h - g.y - rc - 0.5 - m),
            floor_i64(h - g.y + rc - 0.5 + m),
        ),
        (ceil_i64(g.x - rc - 0.5 - m), floor_i64(g.x + rc - 0.5 + m)),
    )
}

/// The contact disk of each tile as pixel spans: `rows` slots per tile of `[lo, hi]` column
/// offsets from `col0[k]` for rows `row0[k]..` (`lo > hi`: no pixel in that row). Valid only
/// for tiles with [`ST_DISK`] set; the slots of the others are never read (zero-initialised:
/// pages of tiles never left undetermined by a judgement cost no memory).
#[derive(Clone)]
struct DiskCache {
    rows: usize,
    row0: Vec<i32>,
    col0: Vec<i32>,
    spans: Vec<[u8; 2]>,
    /// One tile's slots while it is judged for the first time.
    scratch: Vec<[u8; 2]>,
}

impl DiskCache {
    fn new(n_tiles: usize, rc_px: f64) -> Self {
        // Rows a disk's span test visits: 2 rc plus the rounding and margin rows.
        let rows = (2.0 * rc_px).ceil() as usize + 4;
        Self {
            rows,
            row0: vec![0; n_tiles],
            col0: vec![0; n_tiles],
            spans: vec![[0, 0]; n_tiles * rows],
            scratch: Vec::with_capacity(rows),
        }
    }
}

impl std::fmt::Debug for Mind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Mind")
            .field("seen_px", &self.known.seen().count_ones(..))
            .field("tiles", &(self.tiles.w, self.tiles.h))
            .field("l", &self.tiles.l.len())
            .finish_non_exhaustive()
    }
}

impl Mind {
    fn center(&self, t: Tile) -> Point {
        self.tiles.grid.center(t)
    }

    /// The image rows and columns (inclusive, signed) whose pixel centres lie within the
    /// contact radius of tile `t`'s centre in each coordinate, with a margin of
    /// [`TIGHT_BOX_MARGIN_PX`]: every pixel that can touch the tile's disk lies in them.
    #[inline]
    fn touch_box(&self, t: Tile) -> ((i64, i64), (i64, i64)) {
        let (di, dj) = (t.0 - self.tiles.i0, t.1 - self.tiles.j0);
        if let (Some(&c), Some(&r)) = (
            usize::try_from(di)
                .ok()
                .and_then(|i| self.touch_cols.get(i)),
            usize::try_from(dj)
                .ok()
                .and_then(|j| self.touch_rows.get(j)),
        ) {
            return (r, c);
        }
        let h = self.known.frame().height as f64;
        touch_box_of(self.grid_center(t), self.rc_px, h)
    }

    /// [`judge_motion`] from the centre of tile `t` to that of its neighbour `n`. First the
    /// fast path of [`judge_motion_px`] on the union of the two tiles' [`Mind::touch_box`]es
    /// (every pixel that touches the swept disk lies within the contact radius of the segment
    /// in each coordinate, so in that box): inside the image and all known free, the move is
    /// free, as the exact test would find.
    fn judge_step(&self, t: Tile, n: Tile) -> Judgement {
        let ((ra, rb), (ca, cb)) = self.touch_box(t);
        let ((rc, rd), (cc, cd)) = self.touch_box(n);
        if self.box_known_free((ra.min(rc), rb.max(rd)), (ca.min(cc), cb.max(cd))) {
            return Judgement::Free;
        }
        judge_motion_px(
            &self.known,
            self.grid_center(t),
            self.grid_center(n),
            self.rc_px,
        )
    }

    /// Are the image rows `r0..=r1` and columns `c0..=c1` (signed) inside the image, at most
    /// 1024 pixels, and all known free?
    #[inline]
    fn box_known_free(&self, (r0, r1): (i64, i64), (c0, c1): (i64, i64)) -> bool {
        let frame = self.known.frame();
        0 <= r0
            && r0 <= r1
            && r1 < frame.height as i64
            && 0 <= c0
            && c0 <= c1
            && c1 < frame.width as i64
            && (r1 - r0 + 1) * (c1 - c0 + 1) <= 1024
            && self
                .known
                .rect_known_free(r0 as usize, r1 as usize, c0 as usize, c1 as usize)
    }

    /// The centre of tile `t` in continuous grid coordinates: `world_to_grid(center(t))`.
    #[inline]
    fn grid_center(&self, t: Tile) -> Point {
        let (di, dj) = (t.0 - self.tiles.i0, t.1 - self.tiles.j0);
        if let (Some(&x), Some(&y)) = (
            usize::try_from(di).ok().and_then(|i| self.gx.get(i)),
            usize::try_from(dj).ok().and_then(|j| self.gy.get(j)),
        ) {
            return Point::new(x, y);
        }
        self.known.frame().world_to_grid(self.center(t))
    }

    /// Judges move `t -> t + N8[k]` (cached once decided).
    fn judge_move(&mut self, t: Tile, k: usize) -> Judgement {
        let c = self.tiles.cached_move(t, k);
        if c != Judgement::Undetermined {
            return c;
        }
        let n = (t.0 + N8[k].0, t.1 + N8[k].1);
        let j = if self.tiles.stand(t) == Judgement::Blocked
            || self.tiles.stand(n) == Judgement::Blocked
        {
            Judgement::Blocked
        } else {
            self.judge_step(t, n)
        };
        if j != Judgement::Undetermined {
            self.tiles.set_move(t, k, j);
        }
        j
    }

    fn set_stand(&mut self, k: usize, t: Tile, j: Judgement) {
        self.tiles.state[k] = (self.tiles.state[k] & !ST_STAND) | j as u8;
        // `mu` reads a standability only as "is it Blocked?" (`blocked`, the lane-end
        // obstacles), so a tile judged Free changes no tile's L membership.
        if j == Judgement::Blocked {
            self.tiles.update_l_around(t);
        }
    }

    /// Integrates a scan taken at `pose` and refreshes every judgement it can change.
    ///
    /// A tile's standability can change only when a pixel of its contact disk is seen for the
    /// first time. The newly seen pixels are kept as one column span per row; an undetermined
    /// tile is judged again — with [`judge_motion`]'s predicate at the tile centre, the
    /// definition itself (tests check the cache against it after every step) — only when its
    /// cached disk runs (before the first judgement: the bounding box of its disk) meet one of
    /// those spans.
    fn sense(&mut self, sensor: &dyn Sensor) {
        // The sensor sees a disk around the robot: turning in place shows nothing new.
        let at = sensor.pose().position();
        if self.last_scan == Some(at) {
            return;
        }
        self.last_scan = Some(at);
        let scan = sensor.scan();
        // Rows come top to bottom, each row's new pixels left to right.
        let mut spans = std::mem::take(&mut self.new_spans);
        spans.clear();
        let mut first_row = 0usize;
        let prev = self.last_disk.replace(scan.disk_px());
        self.known.integrate_rows(&scan, prev, |r, lo, hi| {
            if spans.is_empty() {
                first_row = r;
            }
            let k = r - first_row;
            spans.resize(k, (usize::MAX, 0));
            spans.push((lo, hi));
        });
        if spans.is_empty() {
            self.new_spans = spans;
            return;
        }
        let last_row = first_row + spans.len() - 1;
        // Candidate tiles: a tile's standability can change only when a new pixel lies in its
        // contact disk, i.e. when its centre lies within `rc` of a new pixel's centre. The new
        // pixels are taken in bands of rows about one tile high; each band's box, grown by
        // `rc` plus a margin for rounding, gives (as the hull of its corners in tile indices:
        // tiles are axis-aligned in the world frame) a range of tiles per tile row, kept as the
        // hull per tile row. Tiles are then visited row by row, each at most once.
        let frame = *self.known.frame();
        let h = frame.height as f64;
        let rc = self.rc_px;
        let m = rc + CANDIDATE_MARGIN_PX;
        let grid = self.tiles.grid;
        let unrotated = frame.origin.theta == 0.0;
        let tile_box = |c0: usize, c1: usize, r0: usize, r1: usize| {
            let (x0, x1) = (c0 as f64 + 0.5 - m, c1 as f64 + 0.5 + m);
            let (y0, y1) = (h - r1 as f64 - 0.5 - m, h - r0 as f64 - 0.5 + m);
            let (mut i0, mut i1, mut j0, mut j1) = (i32::MAX, i32::MIN, i32::MAX, i32::MIN);
            // Without rotation a corner's tile column depends on its x alone and its row on
            // its y alone: two opposite corners give the same hull as four.
            let corners: &[(f64, f64)] = if unrotated {
                &[(x0, y0), (x1, y1)]
            } else {
                &[(x0, y0), (x1, y0), (x0, y1), (x1, y1)]
            };
            for &(x, y) in corners {
                let t = grid.tile_of(frame.grid_to_world(Point::new(x, y)));
                i0 = i0.min(t.0);
                i1 = i1.max(t.0);
                j0 = j0.min(t.1);
                j1 = j1.max(t.1);
            }
            (i0, i1, j0, j1)
        };
        let mut ranges = std::mem::take(&mut self.candidate_rows);
        ranges.clear();
        let j0 = if self.row_tiles.is_empty() {
            let (c0, c1) = spans
                .iter()
                .fold((usize::MAX, 0), |(a, b), s| (a.min(s.0), b.max(s.1)));
            let (_, _, j0, j1) = tile_box(c0, c1, first_row, last_row);
            ranges.resize((j1 - j0 + 1) as usize, (i32::MAX, i32::MIN));
            self.band_candidates(&spans, first_row, j0, &mut ranges, tile_box);
            j0
        } else {
            // Unrotated: the tiles whose touch box meets a row's new span, from the tables.
            let (j0, j1) = (self.row_tiles[last_row].0, self.row_tiles[first_row].1);
            if j0 <= j1 {
                ranges.resize((j1 - j0 + 1) as usize, (i32::MAX, i32::MIN));
                for (row, &(lo, hi)) in (first_row..).zip(spans.iter()) {
                    if lo > hi {
                        continue;
                    }
                    let (bj0, bj1) = self.row_tiles[row];
                    let (bi0, bi1) = (self.col_tiles[lo].0, self.col_tiles[hi].1);
                    if bi0 > bi1 {
                        continue;
                    }
                    for j in bj0.max(j0)..=bj1.min(j1) {
                        let r = &mut ranges[(j - j0) as usize];
                        r.0 = r.0.min(bi0);
                        r.1 = r.1.max(bi1);
                    }
                }
            }
            j0
        };
        for (j, &(i0, i1)) in (j0..).zip(ranges.iter()) {
            for i in i0..=i1 {
                let t = (i, j);
                let Some(k) = self.tiles.idx(t) else { continue };
                if self.tiles.state[k] & ST_STAND != Judgement::Undetermined as u8 {
                    continue;
                }
                let judged = if self.tiles.state[k] & ST_DISK == 0 {
                    // Not cached yet: the rows and columns whose pixel centres lie within
                    // `rc` of the centre in each coordinate (every pixel that touches the disk
                    // does), with a margin far above the rounding of the centre and of the
                    // touch test.
                    let ((r_lo, r_hi), (c_lo, c_hi)) = self.touch_box(t);
                    let rows = r_lo.max(first_row as i64)..=r_hi.min(last_row as i64);
                    let hit = rows.into_iter().any(|row| {
                        let s = spans[(row - first_row as i64) as usize];
                        s.0 <= s.1 && (s.0 as i64) <= c_hi && (s.1 as i64) >= c_lo
                    });
                    if !hit {
                        continue;
                    }
                    if self.box_known_free((r_lo, r_hi), (c_lo, c_hi)) {
                        // Every pixel that can touch the disk is known free: free, as the
                        // exact test finds (nothing to cache: the judgement is final).
                        Judgement::Free
                    } else {
                        self.judge_tile_first(k, self.grid_center(t))
                    }
                } else {
                    // Cached: the disk's own pixel runs against the new ones.
                    let n = self.disk.rows;
                    let (row0, col0) = (self.disk.row0[k] as usize, self.disk.col0[k] as usize);
                    let hit = self.disk.spans[k * n..(k + 1) * n].iter().enumerate().any(
                        |(i, &[a, b])| {
                            let row = row0 + i;
                            a <= b && (first_row..=last_row).contains(&row) && {
                                let s = spans[row - first_row];
                                s.0 <= s.1
                                    && s.0 <= col0 + usize::from(b)
                                    && s.1 >= col0 + usize::from(a)
                            }
                        },
                    );
                    if !hit {
                        continue;
                    }
                    let (row0, col0) = (i64::from(self.disk.row0[k]), i64::from(self.disk.col0[k]));
                    Self::spans_state(
                        &self.known,
                        &self.disk.spans[k * n..(k + 1) * n],
                        row0,
                        col0,
                    )
                };
                if judged != Judgement::Undetermined {
                    self.set_stand(k, t, judged);
                }
            }
        }
        self.new_spans = spans;
        self.candidate_rows = ranges;
    }

    /// The candidate tiles of [`Mind::sense`] for a rotated frame: the new pixels of `spans`
    /// (from image row `first_row`) in bands of rows about one tile high, each band's box
    /// given by `tile_box` as tile ranges; the hull per tile row (from tile row `j0`) is kept
    /// in `ranges`.
    fn band_candidates(
        &self,
        spans: &[(usize, usize)],
        first_row: usize,
        j0: i32,
        ranges: &mut [(i32, i32)],
        tile_box: impl Fn(usize, usize, usize, usize) -> (i32, i32, i32, i32),
    ) {
        let j1 = j0 + ranges.len() as i32 - 1;
        for (b, band) in spans.chunks(self.band_rows).enumerate() {
            let (bc0, bc1) = band
                .iter()
                .fold((usize::MAX, 0), |(a, b), s| (a.min(s.0), b.max(s.1)));
            if bc0 > bc1 {
                continue;
            }
            let r0 = first_row + b * self.band_rows;
            let (bi0, bi1, bj0, bj1) = tile_box(bc0, bc1, r0, r0 + band.len() - 1);
            for j in bj0.max(j0)..=bj1.min(j1) {
                let r = &mut ranges[(j - j0) as usize];
                r.0 = r.0.min(bi0);
                r.1 = r.1.max(bi1);
            }
        }
    }

    /// [`judge_point`] for tile `k`, not in the [`DiskCache`] yet, whose centre is at grid
    /// point `g`: the disk's pixel spans are computed by the same predicate and, while the
    /// tile stays undetermined, cached (a tile is judged again each time new pixels reach its
    /// disk, until it is decided; [`Mind::sense`] then reads the cached spans). A tile decided
    /// at its first judgement (the common case for small tiles) never writes the cache, whose
    /// pages then cost no memory.
    ///
    /// The slots start at the first row of [`disk_rows`] and take their column offsets from
    /// one column of margin left of the disk (clamped at 0: any touching column is >= 0, else
    /// blocked).
    fn judge_tile_first(&mut self, k: usize, g: Point) -> Judgement {
        let n = self.disk.rows;
        let frame = *self.known.frame();
        let rc = self.rc_px;
        let (w, hh) = (frame.width as i64, frame.height as i64);
        let rows = disk_rows(&frame, g, rc);
        let (row0, row1) = (*rows.start(), *rows.end());
        let col0 = (floor_i64(g.x - rc - 0.5) - 1).max(0);
        if row1 - row0 + 1 > n as i64 || !(0..=i64::from(i32::MAX)).contains(&row0) {
            return judge_point(&self.known, g, rc);
        }
        let slots = &mut self.disk.scratch;
        slots.clear();
        slots.resize(n, [1, 0]);
        for (slot, row) in slots.iter_mut().zip(rows) {
            let Some((lo, hi)) = disk_row_span(&frame, g, rc, row) else {
                continue;
            };
            if row >= hh || lo < 0 || hi >= w || hi - col0 > 250 {
                // Reaches outside the image (blocked), or too wide to cache.
                return judge_point(&self.known, g, rc);
            }
            *slot = [(lo - col0) as u8, (hi - col0) as u8];
        }
        let j = Self::spans_state(&self.known, slots, row0, col0);
        if j == Judgement::Undetermined {
            self.disk.spans[k * n..(k + 1) * n].copy_from_slice(&self.disk.scratch);
            self.disk.row0[k] = row0 as i32;
            self.disk.col0[k] = col0 as i32;
            self.tiles.state[k] |= ST_DISK;
        }
        j
    }

    /// What `known` says of the disk given as [`DiskCache`] slots from image row `row0`, column
    /// offsets from `col0`.
    #[inline]
    fn spans_state(known: &KnownMap, slots: &[[u8; 2]], row0: i64, col0: i64) -> Judgement {
        let runs = slots
            .iter()
            .zip(row0..)
            .filter(|(&[a, b], _)| a <= b)
            .map(|(&[a, b], row)| (row, col0 + i64::from(a), col0 + i64::from(b)));
        known.runs_state(runs).into()
    }

    /// Marks `t` covered (the robot stands on it), decides its moves and updates L.
    fn cover(&mut self, t: Tile) {
        let Some(k) = self.tiles.idx(t) else { return };
        if self.tiles.state[k] & ST_COVERED != 0 {
            return;
        }
        self.tiles.state[k] |= ST_COVERED;
        // The touch boxes of the 3 x 3 tiles around `t` hold every pixel any of its moves can
        // touch: all known free (and inside the image), every move is free, as
        // `Mind::judge_move` would find (no neighbour can be judged blocked then). The boxes
        // are one box moved with the tile centre, so their hull is that of the four corner
        // tiles' boxes (in a rotated frame too).
        let (mut r0, mut r1, mut c0, mut c1) = (i64::MAX, i64::MIN, i64::MAX, i64::MIN);
        for (di, dj) in [(-1, -1), (1, -1), (-1, 1), (1, 1)] {
            let ((ra, rb), (ca, cb)) = self.touch_box((t.0 + di, t.1 + dj));
            (r0, r1, c0, c1) = (r0.min(ra), r1.max(rb), c0.min(ca), c1.max(cb));
        }
        let all_free = self.box_known_free((r0, r1), (c0, c1));
        for n in 0..8 {
            let v = (t.0 + N8[n].0, t.1 + N8[n].1);
            if n % 2 == 0 || self.tiles.covered(v) {
                if all_free {
                    if self.tiles.cached_move(t, n) == Judgement::Undetermined {
                        self.tiles.set_move(t, n, Judgement::Free);
                    }
                } else {
                    self.judge_move(t, n);
                }
            }
        }
        self.tiles.update_l_around(t);
    }

    /// Line of sight for A*SPT.
    fn visible(&self, a: Tile, b: Tile) -> bool {
        let rho = self.r / self.tiles.grid.side;
        let tiles = &self.tiles;
        for_each_swept_tile(a, b, rho, |t| tiles.covered(t))
            && judge_motion_px(
                &self.known,
                self.grid_center(a),
                self.grid_center(b),
                self.rc_px,
            ) == Judgement::Free
    }
}

#[derive(Clone, Debug)]
enum Phase {
    Start,
    Bm,
    Backtrack { path: Vec<Tile>, next: usize },
    Finished,
}

/// The BA* planner (see the module docs).
#[derive(Clone, Debug)]
pub struct BaStar {
    opts: BaStarOptions,
    side: Option<f64>,
    mind: Option<Box<Mind>>,
    phase: Phase,
    pending: VecDeque<Step>,
    region: u32,
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
        }
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
            let t = m.tiles.grid.tile_of(p);
            !m.tiles.covered(t) && m.tiles.stand(t) != Judgement::Blocked
        })
    }

    fn init(&mut self, sensor: &dyn Sensor) {
        let r = sensor.robot().radius;
        let side = self.opts.tile_side_m.unwrap_or(2.0 * r);
        self.side = Some(side);
        let frame = *sensor.frame();
        let grid = TileGrid::new(sensor.pose().position(), side);
        let mut tiles = TileModel::new(grid, &frame);
        tiles.lane_end_corners = self.opts.lane_end_corners;
        let known = KnownMap::new(&frame);
        tiles.judge_frame_edges(&known, r);
        let search = TileSearch::new(tiles.bounds());
        let n_tiles = tiles.state.len();
        let rc_px = contact_radius_px(r / frame.resolution);
        let (gx, gy) = if frame.origin.theta == 0.0 {
            let (i0, i1, j0, j1) = tiles.bounds();
            (
                (i0..=i1)
                    .map(|i| frame.world_to_grid(grid.center((i, j0))).x)
                    .collect(),
                (j0..=j1)
                    .map(|j| frame.world_to_grid(grid.center((i0, j))).y)
                    .collect(),
            )
        } else {
            (Vec::new(), Vec::new())
        };
        let touch_cols: Vec<(i64, i64)> = gx
            .iter()
            .map(|&x| touch_box_of(Point::new(x, 0.0), rc_px, 0.0).1)
            .collect();
        let touch_rows: Vec<(i64, i64)> = gy
            .iter()
            .map(|&y| touch_box_of(Point::new(0.0, y), rc_px, frame.height as f64).0)
            .collect();
        let (i0, _, j0, _) = tiles.bounds();
        let range = sensor.sensor_range();
        if range < side + r + frame.resolution {
            self.pending.push_back(Step::Mark(Event::Note {
                text: format!(
                    "ba-star: sensor range {range} m < tile side + r + res = {} m; some moves may \
                     stay undecided",
                    side + r + frame.resolution
                ),
            }));
        }
        self.mind = Some(Box::new(Mind {
            known,
            tiles,
            search,
            r,
            rc_px,
            last_scan: None,
            last_disk: None,
            new_spans: Vec::new(),
            candidate_rows: Vec::new(),
            band_rows: ((side / frame.resolution).floor() as usize).clamp(1, 64),
            disk: DiskCache::new(n_tiles, rc_px),
            col_tiles: if gx.is_empty() {
                Vec::new()
            } else {
                pixel_to_tiles(&touch_cols, frame.width, i0, false)
            },
            row_tiles: if gy.is_empty() {
                Vec::new()
            } else {
                pixel_to_tiles(&touch_rows, frame.height, j0, true)
            },
            touch_cols,
            touch_rows,
            gx,
            gy,
        }));
    }

    fn bm_step(&mut self, sensor: &dyn Sensor) -> Step {
        let Some(m) = self.mind.as_deref_mut() else {
            return Step::Done;
        };
        let c = m.tiles.grid.tile_of(sensor.pose().position());
        m.cover(c);
        for k in [2, 6, 0, 4] {
            let n = (c.0 + N8[k].0, c.1 + N8[k].1);
            if !m.tiles.covered(n) && m.judge_move(c, k) == Judgement::Free {
                return Step::MoveTo(m.center(n));
            }
        }
        // Critical point.
        let cp = m.center(c);
        self.pending
            .push_back(Step::Mark(Event::CriticalPoint { x: cp.x, y: cp.y }));
        self.pending.push_back(Step::Mark(Event::RegionEnd {
            region: self.region,
        }));
        if self.opts.record_backtrack_list {
            let pts = m
                .tiles
                .l_tiles()
                .into_iter()
                .map(|t| {
                    let p = m.center(t);
                    [p.x, p.y]
                })
                .collect();
            self.pending
                .push_back(Step::Mark(Event::BacktrackList { points: pts }));
        }
        if m.tiles.l.len() == 0 {
            self.phase = Phase::Finished;
            return self.pending.pop_front().unwrap_or(Step::Done);
        }
        let tiles = &m.tiles;
        let targets = tiles.l_tiles();
        let found = m.search.nearest_of(tiles, c, &targets, |t| tiles.in_l(t));
        let Some((sp, sp_cost)) = found else {
            // Cannot happen: covered tiles form one connected graph.
            self.pending.push_back(Step::Mark(Event::Note {
                text: "ba-star: no backtracking candidate reachable".to_string(),
            }));
            self.phase = Phase::Finished;
            return self.pending.pop_front().unwrap_or(Step::Done);
        };
        let raw = m
            .search
            .astar_bounded(&m.tiles, c, sp, sp_cost)
            .map_or_else(|| vec![c, sp], |(p, _)| p);
        let smoothed = if self.opts.smoothing {
            let mm = &*m;
            smooth_path(&raw, |a, b| mm.visible(a, b))
        } else {
            raw.clone()
        };
        let to_pts = |p: &[Tile]| {
            p.iter()
                .map(|&t| {
                    let q = m.center(t);
                    [q.x, q.y]
                })
                .collect::<Vec<_>>()
        };
        let spc = m.center(sp);
        self.pending
            .push_back(Step::Mark(Event::StartPoint { x: spc.x, y: spc.y }));
        self.pending.push_back(Step::Mark(Event::PathRaw {
            points: to_pts(&raw),
        }));
        self.pending.push_back(Step::Mark(Event::PathSmoothed {
            points: to_pts(&smoothed),
        }));
        self.pending.push_back(Step::Mark(Event::BacktrackStart));
        self.phase = Phase::Backtrack {
            path: smoothed,
            next: 1,
        };
        self.pending.pop_front().unwrap_or(Step::Done)
    }

    fn arrive(&mut self, sensor: &dyn Sensor) -> Step {
        self.region += 1;
        self.pending.push_back(Step::Mark(Event::BacktrackEnd));
        self.pending.push_back(Step::Mark(Event::RegionStart {
            region: self.region,
        }));
        if let Some(m) = self.mind.as_deref_mut() {
            let c = m.tiles.grid.tile_of(sensor.pose().position());
            // The direction of the first BM move (N, S, E, W order).
            let first = [2, 6, 0, 4].into_iter().find(|&k| {
                let n = (c.0 + N8[k].0, c.1 + N8[k].1);
                !m.tiles.covered(n) && m.judge_move(c, k) == Judgement::Free
            });
            if let Some(k) = first {
                let gamma = f64::from(N8[k].1).atan2(f64::from(N8[k].0));
                let alpha = wrap_angle(gamma - sensor.pose().theta);
                if alpha.abs() > crate::planner::MIN_ROTATION {
                    self.pending.push_back(Step::Rotate(alpha));
                }
            }
        }
        self.phase = Phase::Bm;
        self.pending.pop_front().unwrap_or(Step::Done)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The monotone queue pops exactly what a binary heap of the pairs pops, over a
    /// Dijkstra-like run (pushes at or above the last popped key, ties on the key, keys below
    /// the minimum, reuse after `clear`).
    #[test]
    fn monotone_queue_matches_binary_heap() {
        let mut q = MonotoneQueue::new();
        let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        for round in 0..4 {
            q.clear();
            let mut heap = BinaryHeap::new();
            let mut last = 0u64;
            let mut id = 0u32;
            for step in 0..5000 {
                for _ in 0..(next() % 4) {
                    let r = next();
                    let key = match r % 5 {
                        0 => last,
                        1 if round == 3 && last > 0 => last - 1 - r % last.min(7),
                        _ => last + (r >> 8) % [3, 1_000, 1_414_214, 1 << 40][round],
                    };
                    id = id.wrapping_add(1 + (r >> 40) as u32 % 3) % 100_000;
                    // Every pair distinct, as in a search.
                    let pair = (key, id ^ step);
                    q.push(pair.0, pair.1);
                    heap.push(Reverse(pair));
                }
                if next() % 3 != 0 {
                    let got = q.pop();
                    assert_eq!(got, heap.pop().map(|Reverse(p)| p));
                    if let Some((k, _)) = got {
                        last = k;
                    }
                }
            }
            while let Some(Reverse(p)) = heap.pop() {
                assert_eq!(q.pop(), Some(p));
            }
            assert_eq!(q.pop(), None);
        }
    }

    /// `Block3::in_l` (the early-stopping test the incremental L uses) is `mu >= 1`, over
    /// random blocks of tile states and move judgements.
    #[test]
    fn block_in_l_is_mu_at_least_one() {
        let mut seed: u64 = 0x2545_f491_4f6c_dd1d;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let mut fired = [0usize; 2];
        for _ in 0..200_000 {
            let mut b = Block3 {
                state: [0; 25],
                moves: [0; 25],
                c: 12,
            };
            for k in 0..25 {
                let r = next();
                // Standability 0..=2, covered about half the time; each move slot 0..=2.
                b.state[k] = (r % 3) as u8 | if r >> 8 & 1 == 1 { ST_COVERED } else { 0 };
                b.moves[k] = (0..4).fold(0u8, |m, s| {
                    m | ((((r >> (16 + 2 * s)) % 3) as u8) << (2 * s))
                });
            }
            for lane in [false, true] {
                let want = b.mu(lane) >= 1;
                assert_eq!(
                    b.in_l(lane),
                    want,
                    "{:?} {:?} lane {lane}",
                    b.state,
                    b.moves
                );
                fired[usize::from(lane)] += usize::from(want);
            }
        }
        assert!(fired[0] > 10_000 && fired[1] > fired[0], "{fired:?}");
    }

    #[test]
    fn corner_score_pairs() {
        let mut free = [false; 8];
        let mut blocked = [false; 8];
        assert_eq!(corner_score(free, blocked), 0);
        free[4] = true;
        blocked[3] = true;
        assert_eq!(corner_score(free, blocked), 1);
        blocked[5] = true;
        assert_eq!(corner_score(free, blocked), 2);
        // s3 (north) never starts a pair.
        free[2] = true;
        blocked[1] = true;
        blocked[3] = true;
        assert_eq!(corner_score(free, blocked), 2);
    }

    #[test]
    fn swept_tiles_of_straight_and_diagonal_moves() {
        let collect = |a, b| {
            let mut v = Vec::new();
            for_each_swept_tile(a, b, 0.5, |t| {
                v.push(t);
                true
            });
            v.sort_unstable();
            v
        };
        assert_eq!(collect((0, 0), (1, 0)), vec![(0, 0), (1, 0)]);
        assert_eq!(collect((0, 0), (0, -2)), vec![(0, -2), (0, -1), (0, 0)]);
        assert_eq!(
            collect((0, 0), (1, 1)),
            vec![(0, 0), (0, 1), (1, 0), (1, 1)]
        );
        let v = collect((0, 0), (2, 1));
        assert!(v.contains(&(1, 0)) && v.contains(&(1, 1)) && v.len() >= 4);
    }

    #[test]
    fn segment_box_distance() {
        let lo = Point::new(0.0, 0.0);
        let hi = Point::new(1.0, 1.0);
        let d = segment_box_dist2(Point::new(-1.0, 0.5), Point::new(2.0, 0.5), lo, hi);
        assert_eq!(d, 0.0);
        let d = segment_box_dist2(Point::new(-1.0, 2.0), Point::new(2.0, 2.0), lo, hi);
        assert!((d - 1.0).abs() < 1e-12);
        let d = segment_box_dist2(Point::new(2.0, 3.0), Point::new(3.0, 2.0), lo, hi);
        // Nearest: corner (1,1) to the line x + y = 5: distance 3/sqrt2.
        assert!((d - 4.5).abs() < 1e-12);
    }

    #[test]
    fn heuristic_is_the_floored_euclidean_distance() {
        for di in -60..=60 {
            for dj in -60..=60 {
                let e = (f64::from(di).hypot(f64::from(dj)) * COST_ORTHO as f64).floor() as u64;
                assert_eq!(heuristic((di, dj), (0, 0)), e, "({di}, {dj})");
            }
        }
    }

    /// The shortcuts of [`for_each_swept_tile`] change nothing: the same tiles as the box
    /// distance alone, for segments in every direction and several radii.
    #[test]
    fn swept_tiles_match_the_box_distance() {
        for rho in [0.0, 1e-12, 0.25, 0.5, 0.5 + 1e-12, 0.7, 1.0, 1.5, 2.3] {
            let lim = (rho * rho) * (1.0 - 1e-9) - 1e-12;
            for bx in -7..=7 {
                for by in -7..=7 {
                    let (a, b) = ((0, 0), (bx, by));
                    let mut got = Vec::new();
                    for_each_swept_tile(a, b, rho, |t| {
                        got.push(t);
                        true
                    });
                    got.sort_unstable();
                    let (pa, pb) = (
                        Point::new(0.0, 0.0),
                        Point::new(f64::from(bx), f64::from(by)),
                    );
                    let mut want = Vec::new();
                    for j in -12..=12 {
                        for i in -12..=12 {
                            let (x, y) = (f64::from(i), f64::from(j));
                            let lo = Point::new(x - 0.5, y - 0.5);
                            let hi = Point::new(x + 0.5, y + 0.5);
                            if segment_box_dist2(pa, pb, lo, hi) < lim {
                                want.push((i, j));
                            }
                        }
                    }
                    want.sort_unstable();
                    assert_eq!(got, want, "rho {rho}, to ({bx}, {by})");
                }
            }
        }
    }

    #[test]
    fn heuristic_is_consistent() {
        assert_eq!(heuristic((0, 0), (1, 0)), COST_ORTHO);
        assert!(heuristic((0, 0), (1, 1)) <= COST_DIAG);
        assert!(heuristic((0, 0), (3, 4)) == 5 * COST_ORTHO);
    }
}
