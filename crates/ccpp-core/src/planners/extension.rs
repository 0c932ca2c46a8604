//! The coverage extension for grid-based structured-filling planners: wall following of the
//! partially occupied cells, online and at map resolution.
//!
//! Seed 002 (González et al., "BSA: a complete coverage algorithm", ICRA 2005, sections III–V)
//! observes that a planner filling a grid of robot-sized cells leaves the *partially occupied
//! cells* — the rims along walls and furniture — unswept, and that the remedy is generic: the
//! structured filling runs as before, and wall-following procedures are invoked when unvisited
//! obstacles are detected; gaps are crossed inside a virtual pipe. This module is that remedy as
//! one component that any such planner can drive (`ba-star-extended` is BA* plus this; see
//! [`super::ba_star_extended`]). It is planner-independent: it knows the host only through a
//! predicate "will the host still sweep this pixel?" and through the motions the host makes.
//!
//! # What is swept, what is left (the targets)
//!
//! The component keeps its own estimate of the swept pixels: every executed straight motion is
//! stamped with the tool radius (the metric's predicate, [`crate::raster::SWEEP_EPS_PX`]
//! included). A **target** is a pixel the sensor has shown free, not swept yet, and not one the
//! host will still sweep. Positions are the pixel centres where the robot disk fits on the known
//! map (`S0`: contact radius, clearance 0, unseen pixels block — `KnownMap::disk_state_px`);
//! two 8-neighbour positions are joined when the straight move between them is known free.
//! A position *gains* when a target lies within the tool radius of it.
//!
//! # A cleaning pass (online, in chunks)
//!
//! 1. **Find a rim**: Dijkstra over positions from the robot to the nearest position that
//!    sweeps at least a tool radius of target pixels (at the end of a host region the search is
//!    bounded by [`ExtensionOptions::reach_r`] robot radii; after the host's coverage it is not,
//!    and a tool radius of pixels, at least 2, is enough — or a single pixel when the
//!    position lies on a *strip* of rim: at least 4 targets within the tool radius plus 3
//!    pixels. Where a wall runs at a sub-pixel offset every position beside it sweeps one pixel
//!    of a one-pixel strip; on `tuw_single_corridors` those strips were 1 % of the floor.
//!    Only specks stay behind).
//! 2. **Follow it**: a greedy walk over positions that prefers the *contour* (positions next to
//!    one where the robot does not fit — the iso-clearance curve at the clearance the robot can
//!    hold, 0), then the largest gain up to a tool radius of pixels, then the smallest
//!    turn. A step along the contour must
//!    gain a pixel, a step off it a tool radius of pixels. This is the wall following of seed
//!    002 for the obstacle boundaries the sensor has revealed, one pixel per step.
//! 3. **Merge** (the cheap motion; [`ExtensionOptions::merge_segments`]): the pixel walk is cut
//!    into straight segments, each as long as the known map proves it free *and* every target
//!    the walk gained along it stays within the tool radius of it (a Douglas–Peucker-like greedy
//!    cut with a free-and-still-sweeps check per merged segment; a segment blocked by a
//!    wiggle of the wall at one point may still reach one a few points farther). A diagonal
//!    wall is then one segment, not a staircase.
//!    **Square corners** ([`ExtensionOptions::corner_slack`]): round a corner at clearance 0
//!    and the centre draws an arc, merged into several short segments (one turn each). Up to
//!    4 such vertices become the point where the segment before and the segment after meet
//!    (`a..b` below becomes `a X b`), when both new segments are known free, every pixel the
//!    pass swept along the arc stays within the tool radius, and the way grows by at most
//!    `corner_slack` robot radii per turn saved:
//!
//!    ```text
//!      a----p             a-------X
//!            \                    |
//!             q       ->          |
//!             |                   |
//!             b                   b
//!    ```
//!    **Simplify** ([`ExtensionOptions::simplify_fraction`]): a vertex of the merged chunk
//!    (trip and walk, the seam between them included) is dropped when the straight way
//!    between its neighbours is known free and leaves at most a tool radius of the walk's
//!    pixels unswept, cheapest loss first (Visvalingam-style on the pixels lost), within a
//!    budget of the known free floor. The pixels lost stay claimed (no later trip goes out for
//!    them). On the 14 shared maps this saves about 7 % of the turns for under 0.1 % of the
//!    floor; most remaining vertices sit where the straight way would touch the wall (the
//!    walk holds clearance 0), not where it would lose pixels.
//! 4. The walk stops where nothing more is gained, or where the next position is not decided
//!    yet (unseen pixels): the robot drives the chunk, senses, and the next chunk continues —
//!    the component never reads the true map.
//!
//! Gained pixels are claimed as the walk goes and executed motions are stamped, so a rim is
//! not swept twice on purpose and a pass never returns to what a lane already swept.
//!
//! # Trips that do not pay (the final clean-up)
//!
//! Nearest-first, the last rims are specks a long way apart: on the 14 shared maps trips
//! between rims were 0.18 of the ideal path on average and walks along rims 0.25, and the
//! longest trips fetched a handful of pixels (on `teb_maze` a 17 m trip for 3 pixels). A trip
//! must pay for itself: a chunk whose walk gains less than [`ExtensionOptions::min_yield`] of
//! what a full-width lane sweeps over the path its leaving saves is left. That saving is the
//! chunk's trip and walk plus the straight way on from its end to the next rim, less the
//! (longer) trip from here to that rim, so a rim on the way stays in the tour. What is left —
//! the walk's pixels and the targets its trip would have swept on the side — is counted, and
//! leaving stops once it reaches [`ExtensionOptions::leave_fraction`] of the known free floor.
//! The search for the next rim goes on where the last one stopped (the robot has not moved).
//!
//! Judged one at a time, a far cluster of specks is always driven: seen from the next speck,
//! each lies on the way. So a chunk that does not pay on its own is judged together with the
//! chunks planned after it (nearest first from the robot, up to
//! [`ExtensionOptions::leave_group`]): the group is left when its pixels do not pay for its
//! tour (first trip, walks, the straight ways between them) plus the way on to the chunk after
//! it, less the direct trip there. On the 14 shared maps the final clean-up had spent 0.08 of
//! the ideal path on trips to rims of at most 3 pixels (on `rmf_office_scan` 0.18).
//!
//! ```text
//!   robot R, rims a (1 px, 9 m away, the next rim b beyond it) and c (3 px, 12 m away, last)
//!
//!   R . . . . a . . . . b~~~~~~~~          a: leaving saves ~0 m (b is behind it): driven
//!   . . . . . . . . . . . . . . . c        c: leaving saves its 12 m trip: left
//! ```
//!
//! **Lane ends** ([`ExtensionOptions::lane_ends`], off by default): where a host lane ends at a
//! known obstacle less than a cell ahead, the robot drives on to the obstacle, along it to the
//! point in front of the next lane, and starts that lane there (`Extension::lane_end`). On the
//! 14 shared maps this sweeps the lane-end rims at once but leaves small cusps between lane
//! pairs that later passes must fetch, and the mean path ratio came out 0.02 higher, hence off.
//!
//! # Virtual pipes and gaps (seed 002, III.D)
//!
//! Transfers (`Extension::route`) run A* over the same position graph (every step known free)
//! and merge it into known-free straight segments; a gap narrower than a cell — which the host's
//! cell graph cannot cross — is crossed by the positions that fit in it, i.e. inside the pipe of
//! pixels the robot disk can occupy, and the search stays inside what the sensor has shown.
//!
//! # Example
//!
//! A room whose size is not a multiple of the robot's cell: the host's cells (`o`, centres
//! `+`) end short of the walls, leaving rims (`~`). One pass walks the contour (`>`) and
//! merges the straight runs into four segments:
//!
//! ```text
//!   ###########        ###########
//!   #~~~~~~~~~#        #>>>>>>>>v#
//!   #~+ + + +~#        #^+ + + +v#
//!   #~+ + + +~#   ->   #^+ + + +v#
//!   #~~~~~~~~~#        #^<<<<<<<<#
//!   ###########        ###########
//! ```
//!
//! ```
//! use ccpp_core::{GridMap, Pose};
//! use ccpp_core::world::{Robot, World};
//! use ccpp_core::planners::ba_star::{BaStar, BaStarOptions};
//! use ccpp_core::planners::ba_star_extended::{BaStarExtended, BaStarExtendedOptions};
//! use ccpp_core::sim::{simulate, SimConfig};
//! use ccpp_core::metrics::compute;
//! // 0.63 m x 0.45 m room, robot radius 0.08 m: tiles of 0.16 m leave rims.
//! let art = "#########\n#.......#\n#.......#\n#.......#\n#########";
//! let map = GridMap::from_ascii_scaled(art, 9, 0.01).unwrap();
//! let world = World::new(map, Robot::new(0.08), Some(Pose::new(0.2, 0.2, 0.0))).unwrap();
//! let plain = simulate(&world, &mut BaStar::new(BaStarOptions::default()), &SimConfig::default());
//! let mut ext = BaStarExtended::new(BaStarExtendedOptions::default());
//! let out = simulate(&world, &mut ext, &SimConfig::default());
//! let (mp, me) = (compute(&world, &plain, "room"), compute(&world, &out, "room"));
//! assert_eq!(me.collisions, 0);
//! assert!(me.effective_coverage > mp.effective_coverage);
//! assert!(me.effective_coverage > 0.99);
//! ```

use std::collections::VecDeque;

use fixedbitset::FixedBitSet;
use serde::{Deserialize, Serialize};

use super::ba_star::{judge_motion, Judgement};
use crate::geometry::{point_segment_dist2, polyline_length, Point};
use crate::grid::MapFrame;
use crate::planner::{pixel_disk_spans, DiskState, KnownMap, Sensor, Step};
use crate::trace::Event;

/// Options of the extension (shared by every planner that uses it).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ExtensionOptions {
    /// How far (path distance, in robot radii) the robot looks for an unswept rim when the host
    /// finishes a region; `0` cleans only once, after the host's coverage.
    pub reach_r: f64,
    /// Drive the host's lane ends on to the wall ahead, along it, and into the next lane
    /// (`false` turns at the last free tile centre as the host does).
    pub lane_ends: bool,
    /// Merge the pixel steps of a wall pass into straight known-free segments (`false` drives
    /// pixel by pixel, to compare).
    pub merge_segments: bool,
    /// Least *yield* of a trip of the final clean-up (a trip must pay for itself): the area the
    /// walk at its end gains over the area a full-width lane as long as the trip would sweep.
    /// A chunk below it is left unswept while [`Self::leave_fraction`] allows, and the next
    /// rim is looked for from where the robot is (`0`: every chunk is driven).
    pub min_yield: f64,
    /// Most of the known free floor (a fraction) the final clean-up may leave in chunks below
    /// [`Self::min_yield`].
    pub leave_fraction: f64,
    /// Most chunks the final clean-up leaves together ([`Self::min_yield`] judged on their
    /// pixels and tour as a whole): a cluster of specks far away is left as one even where
    /// each speck, seen from the next, lies on the way; `1` judges each chunk alone.
    pub leave_group: usize,
    /// Most of the known free floor (a fraction) that simplifying the wall passes may leave:
    /// a vertex of a pass whose straight replacement is known free and loses few of the
    /// pixels the pass gains is dropped (one turn fewer); `0` keeps every pixel.
    pub simplify_fraction: f64,
    /// Most pixels one dropped vertex may lose, in tool radii of pixels (see
    /// [`Self::simplify_fraction`]).
    pub simplify_loss: f64,
    /// Square corners: where a pass rounds a corner in several short segments, up to 4 of its
    /// vertices become the one point where the straight segments before and after meet (known
    /// free, no pixel of the pass lost), when the way grows by at most this many robot radii
    /// per turn saved; `0` keeps the rounded corners.
    pub corner_slack: f64,
}

impl Default for ExtensionOptions {
    fn default() -> Self {
        Self {
            reach_r: 4.0,
            lane_ends: false,
            merge_segments: true,
            min_yield: 0.05,
            leave_fraction: 0.002,
            leave_group: 8,
            simplify_fraction: 0.0015,
            simplify_loss: 1.0,
            corner_slack: 0.1,
        }
    }
}

impl ExtensionOptions {
    /// Checks the values (field names as in the `extension` section).
    ///
    /// # Errors
    /// The first field out of range.
    pub fn validate(&self) -> Result<(), crate::options::OptionsError> {
        for (field, v) in [
            ("extension.reach_r", self.reach_r),
            ("extension.min_yield", self.min_yield),
            ("extension.leave_fraction", self.leave_fraction),
            ("extension.simplify_fraction", self.simplify_fraction),
            ("extension.simplify_loss", self.simplify_loss),
            ("extension.corner_slack", self.corner_slack),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(crate::options::OptionsError::new(
                    field,
                    format!("must be a finite number >= 0, got {v}"),
                ));
            }
        }
        if self.leave_group == 0 {
            return Err(crate::options::OptionsError::new(
                "extension.leave_group",
                "must be at least 1, got 0".to_string(),
            ));
        }
        for (field, v) in [
            ("extension.leave_fraction", self.leave_fraction),
            ("extension.simplify_fraction", self.simplify_fraction),
        ] {
            if v > 1.0 {
                return Err(crate::options::OptionsError::new(
                    field,
                    format!("must be at most 1, got {v}"),
                ));
            }
        }
        Ok(())
    }
}

/// A pixel, signed `(col, row)` (row 0 at the top).
type Px = (i64, i64);

/// Which known-free unswept pixels are targets: those at whose world point the filter holds
/// (`None`: every one).
pub(crate) type Wanted<'a> = Option<&'a dyn Fn(Point) -> bool>;

/// Target counts of the pixels around a bounded search's start, per window row as prefix sums
/// (`pre[row * (w + 1) + c]` = targets in columns `c0..c0 + c`). Built once per search, it
/// answers each settled position's gain with one subtraction per disk row.
/// log2 of the key range one [`BucketQueue`] bucket holds (a sixteenth of an orthogonal step).
const BUCKET_SHIFT: u32 = 6;
/// The last [`BucketQueue`] bucket holds every larger key too (bounds its memory; the order
/// stays exact, only slower, for keys beyond about 65 000 pixel steps).
const BUCKET_MAX: usize = 1 << 20;

/// The position search's priority queue: pops the smallest `(key, index)` first, exactly the
/// order of a binary min-heap on that pair (so plans are unchanged), but cheaper. Keys are
/// search costs (plus a heuristic), integers in steps of about [`COST_ORTHO`]: entries go to
/// the bucket `key >> BUCKET_SHIFT` by a plain push, and a bucket is sorted once, when the
/// queue first pops from it (later pushes into a sorted bucket are inserted in order). The
/// weighted-A* heuristic is not consistent, so a key may fall below the bucket being popped:
/// the cursor then moves back to it.
#[derive(Default)]
struct BucketQueue {
    /// Entries per bucket; a sorted bucket is in descending order (smallest last).
    buckets: Vec<Vec<(u64, u32)>>,
    /// Whether each bucket is sorted.
    sorted: Vec<bool>,
    /// No non-empty bucket lies below this one.
    cur: usize,
    /// One past the highest bucket used since the last clear.
    top: usize,
    /// Entries queued.
    len: usize,
}

impl BucketQueue {
    /// Empties the queue (keeps the buckets' storage).
    fn clear(&mut self) {
        let top = self.top.min(self.buckets.len());
        for b in self.cur.min(top)..top {
            self.buckets[b].clear();
            self.sorted[b] = false;
        }
        self.cur = usize::MAX;
        self.top = 0;
        self.len = 0;
    }

    /// Queues position `i` at `key`.
    #[inline]
    fn push(&mut self, key: u64, i: usize) {
        let b = usize::try_from(key >> BUCKET_SHIFT).map_or(BUCKET_MAX, |b| b.min(BUCKET_MAX));
        if b >= self.buckets.len() {
            self.buckets.resize_with(b + 1, Vec::new);
            self.sorted.resize(b + 1, false);
        }
        let e = (key, i as u32);
        let v = &mut self.buckets[b];
        if self.sorted[b] {
            let at = v.partition_point(|x| *x > e);
            v.insert(at, e);
        } else {
            v.push(e);
        }
        if self.len == 0 || b < self.cur {
            self.cur = b;
        }
        self.top = self.top.max(b + 1);
        self.len += 1;
    }

    /// Removes and returns the position with the smallest `(key, index)`.
    fn pop(&mut self) -> Option<usize> {
        if self.len == 0 {
            return None;
        }
        while self.buckets[self.cur].is_empty() {
            self.sorted[self.cur] = false;
            self.cur += 1;
        }
        let b = self.cur;
        if !self.sorted[b] {
            self.buckets[b].sort_unstable_by(|x, y| y.cmp(x));
            self.sorted[b] = true;
        }
        self.len -= 1;
        self.buckets[b].pop().map(|(_, i)| i as usize)
    }
}

/// One pixel's search state ([`Extension::search`]; generation-stamped), one word: the
/// search cost in bits 20..63 ([`CLOSED`] set once settled), the move from the parent in bits
/// 16..20 (`k + 1` for a step `NB[k]`, 0: a first step from the start) and the generation in
/// bits 0..16. All zero is "never reached", so the table starts as zeroed memory the system
/// maps only where a search goes. (Eight bytes a pixel: the search is bound by memory traffic.)
type Node = u64;

/// Bits of [`Node`] below the search cost.
const NODE_COST_SHIFT: u32 = 20;
/// Generations a [`Node`] tells apart (the table is cleared when they wrap).
const NODE_GENS: u32 = 1 << 16;

/// The [`Node`] of a position reached at cost `dist` by the move `NB[k]` (`None`: from the
/// start) in generation `gen`.
fn node(dist: u64, k: Option<usize>, gen: u32) -> Node {
    // 43 bits of cost: over 8e9 pixel steps, far beyond any map that fits in memory.
    debug_assert!(
        dist < 1 << (63 - NODE_COST_SHIFT),
        "search cost overflows a node"
    );
    debug_assert!(gen < NODE_GENS);
    let m = k.map_or(0, |k| k as u64 + 1);
    dist << NODE_COST_SHIFT | m << 16 | u64::from(gen)
}

/// The search cost recorded in `n`.
fn node_cost(n: Node) -> u64 {
    (n & !CLOSED) >> NODE_COST_SHIFT
}

/// The generation that wrote `n`.
fn node_gen(n: Node) -> u32 {
    (n & 0xFFFF) as u32
}

/// The move from the parent recorded in `n` (an index into [`NB`]).
fn node_move(n: Node) -> Option<usize> {
    let m = (n >> 16) & 0xF;
    (m != 0).then(|| (m - 1) as usize)
}

#[derive(Default)]
struct Window {
    c0: i64,
    r0: i64,
    w: i64,
    h: i64,
    pre: Vec<u32>,
}

/// The 8 neighbour offsets `(dcol, drow)`: E, NE, N, NW, W, SW, S, SE (rows grow downwards).
const NB: [(i64, i64); 8] = [
    (1, 0),
    (1, -1),
    (0, -1),
    (-1, -1),
    (-1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

/// Fixed-point step costs (one pixel = 1000).
const COST_ORTHO: u64 = 1000;
const COST_DIAG: u64 = 1414;

/// Settled positions carry this bit in their search cost.
const CLOSED: u64 = 1 << 63;

/// A strip of rim: at least [`STRIP_N`] targets within the tool radius plus [`STRIP_PX`]
/// pixels (see `plan_pass`).
const STRIP_PX: f64 = 3.0;
const STRIP_N: usize = 4;

/// Heuristic weight of transfer searches.
const ROUTE_WEIGHT: f64 = 1.5;

/// Longest merged segment, in walk points (bounds the quadratic merge check).
const MAX_MERGE: usize = 256;

/// How many points past the first one a merged segment cannot reach the merge still tries
/// (a wiggle of the wall may block one point while a farther one is in sight).
const MERGE_LOOK: usize = 8;

/// Most vertices [`Extension::square_corners`] replaces by one.
const CORNER_RUN: usize = 4;

/// Longest walk of one chunk, in pixel steps.
const MAX_WALK: usize = 20_000;

/// Blocks of the known-free map [`Extension::refresh_no_gain`] compares at a time.
const STRETCH: usize = 64;

/// One chunk of a cleaning pass ([`Extension::plan_pass`]), world waypoints.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Chunk {
    /// The way to the rim: waypoints up to the first position that sweeps.
    pub(crate) transfer: Vec<Point>,
    /// The sweep along the rim, after the transfer (empty when the pass ends where it starts).
    pub(crate) sweep: Vec<Point>,
    /// Target pixels the chunk's walk claims.
    pub(crate) gained: usize,
    /// Those pixels.
    claimed: Vec<usize>,
    /// Whether one of them is owed ([`Extension::owe_skipped`]).
    pub(crate) owed: bool,
    /// Gained pixels the simplified walk leaves (counted once the chunk is driven).
    simplified: usize,
}

impl Chunk {
    /// Length of the way to the rim from world point `pos` (metres).
    pub(crate) fn trip_len(&self, pos: Point) -> f64 {
        polyline_length(pos, &self.transfer)
    }

    /// Length of the sweep along the rim (metres).
    pub(crate) fn walk_len(&self, pos: Point) -> f64 {
        polyline_length(self.start(pos), &self.sweep)
    }

    /// Where the sweep starts (the transfer's end; `pos` without one).
    fn start(&self, pos: Point) -> Point {
        self.transfer.last().copied().unwrap_or(pos)
    }

    /// Where the chunk ends.
    fn end(&self, pos: Point) -> Point {
        self.sweep
            .last()
            .copied()
            .unwrap_or_else(|| self.start(pos))
    }
}

/// The extension's state (see the module docs).
pub(crate) struct Extension {
    opts: ExtensionOptions,
    frame: MapFrame,
    r: f64,
    /// Tool radius in pixels (with the metric's epsilon).
    rt: f64,
    /// `S0` memo per pixel: 0 undecided, 1 the robot fits, 2 it does not.
    s0: Vec<u8>,
    s0_disk: Vec<i64>,
    /// `S1` memo (the robot fits with the clearance that makes every 8-neighbour move between
    /// two such positions free): 0 undecided, 1 fits, 2 not.
    s1: Vec<u8>,
    s1_disk: Vec<i64>,
    /// Per pixel: bit `k` = the move to neighbour `NB[k]` is known free.
    edge_free: Vec<u8>,
    /// Per pixel: bit `k` = the move to neighbour `NB[k]` is known blocked (a seen obstacle
    /// stays one, so this never changes back).
    edge_blocked: Vec<u8>,
    /// The tool disk around a pixel centre, as pixel offsets.
    tool: Vec<(i64, i64)>,
    /// The same disk as row half-widths (entry `|drow|`).
    tool_rows: Vec<i64>,
    /// Row half-widths of the wider disk that tells a strip of rim from a speck
    /// ([`STRIP_PX`] more than the tool radius).
    strip_rows: Vec<i64>,
    /// Pixels swept (executed or claimed by a planned pass).
    swept: FixedBitSet,
    /// Scratch of [`Self::polyline_gains`] (all clear between calls).
    scratch: FixedBitSet,
    /// Pixels a host's transfer would have swept and the shorter way driven instead did not
    /// ([`Self::owe_skipped`]); `any_owed` once one is.
    owed: FixedBitSet,
    any_owed: bool,
    /// Final passes: positions known not to gain enough. Targets only disappear (swept grows)
    /// except where pixels became known free since `no_gain_free` (the known-free blocks when
    /// the memo was last brought up to date): the memo is dropped around those only.
    no_gain: FixedBitSet,
    no_gain_free: Vec<usize>,
    /// Target pixels left in chunks below [`ExtensionOptions::min_yield`].
    left: usize,
    /// Gained pixels the simplified walks leave ([`ExtensionOptions::simplify_fraction`]).
    simplified: usize,
    /// Most pixels one dropped vertex may lose ([`ExtensionOptions::simplify_loss`] tool
    /// radii of pixels).
    simplify_per_turn: usize,
    /// Known free pixels, counted by [`Self::refresh_no_gain`] (valid once the final clean-up
    /// began: `no_gain_free` is then up to date).
    free_count: usize,
    // Dijkstra scratch (generation-stamped).
    /// Per pixel: search cost, parent move and generation in one word ([`Node`]).
    nodes: Vec<Node>,
    generation: u32,
    /// Reused search queue.
    heap: BucketQueue,
    /// Target counts around a bounded search's start, valid during that search only.
    win: Window,
    win_on: bool,
    /// Where the last search stopped (see `search_with`), while its state is valid.
    resume_at: Option<usize>,
    /// The final clean-up's walk follows a strip of rim off the contour too (see
    /// [`Self::set_strip_walk`]).
    strip_walk: bool,
}

impl Extension {
    /// State for a map frame, robot radius `r` and tool radius `tool` (metres).
    pub(crate) fn new(opts: ExtensionOptions, frame: MapFrame, r: f64, tool: f64) -> Self {
        let n = frame.len();
        let r_px = r / frame.resolution;
        let rt = tool / frame.resolution + crate::raster::SWEEP_EPS_PX;
        let reach = rt.ceil() as i64;
        let mut off = Vec::new();
        for dr in -reach..=reach {
            for dc in -reach..=reach {
                if ((dc * dc + dr * dr) as f64) <= rt * rt {
                    off.push((dc, dr));
                }
            }
        }
        let rc = crate::collide::contact_radius_px(r_px);
        let rows = |rad: f64| -> Vec<i64> {
            let reach = rad.ceil() as i64;
            (0..=reach)
                .map(|dr| {
                    (0..=reach)
                        .filter(|dc| ((dc * dc + dr * dr) as f64) <= rad * rad)
                        .max()
                        .unwrap_or(-1)
                })
                .collect()
        };
        let tool_rows = rows(rt);
        let simplify_per_turn = (rt * opts.simplify_loss).ceil() as usize;
        let strip_rows = rows(rt + STRIP_PX);
        Self {
            opts,
            frame,
            r,
            rt,
            s0: vec![0; n],
            s0_disk: pixel_disk_spans(rc),
            // A blocked pixel centre at least R from both ends of a move of length l is at
            // least sqrt(R^2 - l^2/4) from the move: R^2 >= rc^2 + 1/2 keeps diagonal moves
            // out of contact, and every pixel such a move could touch lies in one end's disk.
            s1: vec![0; n],
            s1_disk: pixel_disk_spans((rc * rc + 0.5).sqrt() + 1e-9),
            edge_free: vec![0; n],
            edge_blocked: vec![0; n],
            tool: off,
            tool_rows,
            strip_rows,
            swept: FixedBitSet::with_capacity(n),
            scratch: FixedBitSet::with_capacity(n),
            owed: FixedBitSet::with_capacity(n),
            any_owed: false,
            no_gain: FixedBitSet::with_capacity(n),
            no_gain_free: Vec::new(),
            left: 0,
            simplified: 0,
            simplify_per_turn,
            free_count: 0,
            nodes: vec![0; n],
            generation: 0,
            heap: BucketQueue::default(),
            win: Window::default(),
            win_on: false,
            resume_at: None,
            strip_walk: false,
        }
    }

    /// Lets the final clean-up's walk step off the contour onto a position on a strip of rim
    /// (at least 4 targets within the tool radius plus 3 pixels) that gains a single pixel, as
    /// a pass may start there; off (the default) such a step must gain a tool radius of
    /// pixels, and a strip away from the walls is fetched one position per chunk.
    pub(crate) fn set_strip_walk(&mut self, on: bool) {
        self.strip_walk = on;
    }

    /// The options.
    pub(crate) fn options(&self) -> &ExtensionOptions {
        &self.opts
    }

    /// The robot radius (metres).
    pub(crate) fn radius(&self) -> f64 {
        self.r
    }

    /// Records an executed straight motion (world points) as swept.
    pub(crate) fn record(&mut self, a: Point, b: Point) {
        let f = self.frame;
        crate::raster::stamp_capsule(
            &mut self.swept,
            &f,
            f.world_to_grid(a),
            f.world_to_grid(b),
            self.rt,
            &mut |_| {},
        );
    }

    /// The targets (known free, not swept) that driving the grid polyline `pts` would sweep,
    /// per point: entry `m` holds those first swept by the segment ending at `pts[m]` (entry 0
    /// is empty).
    fn polyline_gains(&mut self, known: &KnownMap, pts: &[Point]) -> Vec<Vec<usize>> {
        let f = self.frame;
        let free = known.known_free();
        let mut stamped = Vec::new();
        let mut gains = vec![Vec::new()];
        for s in pts.windows(2) {
            let start = stamped.len();
            crate::raster::stamp_capsule(&mut self.scratch, &f, s[0], s[1], self.rt, &mut |i| {
                stamped.push(i);
            });
            gains.push(
                stamped[start..]
                    .iter()
                    .copied()
                    .filter(|&i| free.contains(i) && !self.swept.contains(i))
                    .collect(),
            );
        }
        for &i in &stamped {
            self.scratch.set(i, false);
        }
        gains
    }

    /// Driving `alt` instead of the host's transfer `host` (both from world point `from`):
    /// the targets the host's way would sweep and `alt` does not become *owed* — the final
    /// clean-up fetches them even where they are specks below its thresholds, so that a
    /// shorter transfer never sweeps less than the host would. Returns how many were added.
    pub(crate) fn owe_skipped(
        &mut self,
        known: &KnownMap,
        from: Point,
        host: &[Point],
        alt: &[Point],
    ) -> usize {
        let f = self.frame;
        let grid = |pts: &[Point]| -> Vec<Point> {
            std::iter::once(from)
                .chain(pts.iter().copied())
                .map(|p| f.world_to_grid(p))
                .collect()
        };
        let gains = self.polyline_gains(known, &grid(host));
        let alt = grid(alt);
        let rt2 = self.rt * self.rt;
        let mut n = 0;
        for &i in gains.iter().flatten() {
            let c = self.center(self.px_of(i));
            if !alt
                .windows(2)
                .any(|s| point_segment_dist2(c, s[0], s[1]) <= rt2)
            {
                self.owed.insert(i);
                n += 1;
            }
        }
        self.any_owed |= n > 0;
        n
    }

    /// Does position `p` sweep an owed pixel that is still unswept?
    fn sweeps_owed(&self, p: Px) -> bool {
        self.any_owed
            && self.tool.iter().any(|&(dc, dr)| {
                self.idx((p.0 + dc, p.1 + dr))
                    .is_some_and(|i| self.owed.contains(i) && !self.swept.contains(i))
            })
    }

    fn idx(&self, p: Px) -> Option<usize> {
        self.frame
            .checked(p.0, p.1)
            .map(|(c, r)| self.frame.index(c, r))
    }

    fn center(&self, p: Px) -> Point {
        Point::new(
            p.0 as f64 + 0.5,
            (self.frame.height as i64 - p.1) as f64 - 0.5,
        )
    }

    fn px_of(&self, i: usize) -> Px {
        // Searches turn every settled index back into a pixel: a 32-bit division where the
        // index fits (any image up to 4 G pixels) is several times cheaper than a 64-bit one.
        if let (Ok(i), Ok(w)) = (u32::try_from(i), u32::try_from(self.frame.width)) {
            return (i64::from(i % w), i64::from(i / w));
        }
        let (c, r) = self.frame.col_row(i);
        (c as i64, r as i64)
    }

    fn world(&self, g: Point) -> Point {
        self.frame.grid_to_world(g)
    }

    /// Does the robot fit at the centre of pixel `p` (known map, clearance 0)? `None` while an
    /// unseen pixel decides.
    fn in_s0(&mut self, known: &KnownMap, p: Px) -> Option<bool> {
        let i = self.idx(p)?;
        match self.s0[i] {
            1 => return Some(true),
            2 => return Some(false),
            _ => {}
        }
        // The `S1` disk holds the `S0` disk: where it is free (most positions, away from
        // walls) both are decided by one look, and `S1` is memoised as `in_s1` would.
        if self.s1[i] == 0 {
            match known.disk_state_px(p.0, p.1, &self.s1_disk) {
                DiskState::Free => {
                    self.s1[i] = 1;
                    self.s0[i] = 1;
                    return Some(true);
                }
                DiskState::Blocked => self.s1[i] = 2,
                DiskState::Unseen => {}
            }
        }
        match known.disk_state_px(p.0, p.1, &self.s0_disk) {
            DiskState::Free => {
                self.s0[i] = 1;
                Some(true)
            }
            DiskState::Blocked => {
                self.s0[i] = 2;
                Some(false)
            }
            DiskState::Unseen => None,
        }
    }

    /// Does pixel `p` lie in `S1` (see the field)? Unseen counts as no.
    fn in_s1(&mut self, known: &KnownMap, p: Px) -> bool {
        let Some(i) = self.idx(p) else { return false };
        match self.s1[i] {
            1 => return true,
            2 => return false,
            _ => {}
        }
        match known.disk_state_px(p.0, p.1, &self.s1_disk) {
            DiskState::Free => {
                self.s1[i] = 1;
                true
            }
            DiskState::Blocked => {
                self.s1[i] = 2;
                false
            }
            DiskState::Unseen => false,
        }
    }

    /// Is the straight move between grid points `a` and `b` known free?
    fn seg_free(&self, known: &KnownMap, a: Point, b: Point) -> bool {
        judge_motion(known, self.world(a), self.world(b), self.r) == Judgement::Free
    }

    /// Is position `p` usable and the move from `p` to its neighbour `NB[k]` known free?
    fn edge(&mut self, known: &KnownMap, p: Px, k: usize) -> bool {
        let q = (p.0 + NB[k].0, p.1 + NB[k].1);
        let (Some(i), Some(j)) = (self.idx(p), self.idx(q)) else {
            return false;
        };
        if self.edge_free[i] & (1 << k) != 0 {
            return true;
        }
        if self.edge_blocked[i] & (1 << k) != 0 {
            return false;
        }
        match self.in_s0(known, q) {
            Some(true) => {}
            Some(false) => {
                // The robot never fits at `q` (a seen obstacle stays one): the move stays
                // blocked.
                self.edge_blocked[i] |= 1 << k;
                return false;
            }
            None => return false,
        }
        // Between two `S1` positions a move is free; else check it on the known map (once free
        // or blocked, it stays so).
        let judged = if self.in_s1(known, p) && self.in_s1(known, q) {
            Judgement::Free
        } else {
            judge_motion(
                known,
                self.world(self.center(p)),
                self.world(self.center(q)),
                self.r,
            )
        };
        match judged {
            Judgement::Free => {
                self.edge_free[i] |= 1 << k;
                self.edge_free[j] |= 1 << ((k + 4) % 8);
                true
            }
            Judgement::Blocked => {
                self.edge_blocked[i] |= 1 << k;
                self.edge_blocked[j] |= 1 << ((k + 4) % 8);
                false
            }
            Judgement::Undetermined => false,
        }
    }

    /// Is pixel `q` a target?
    fn is_target(&self, known: &KnownMap, q: Px, wanted: Wanted) -> bool {
        let Some(i) = self.idx(q) else { return false };
        known.known_free().contains(i)
            && !self.swept.contains(i)
            && wanted.is_none_or(|w| w(self.world(self.center(q))))
    }

    /// Number of targets within the tool radius of position `p` (stops at `cap`).
    fn gain(&self, known: &KnownMap, p: Px, wanted: Wanted, cap: usize) -> usize {
        if self.win_on {
            if let Some(n) = self.window_count(p, cap) {
                return n;
            }
        }
        self.count_targets(known, p, wanted, cap, &self.tool_rows)
    }

    /// Fills [`Self::win`] with the targets within `rad` pixels (square) of `c`.
    fn build_window(&mut self, known: &KnownMap, c: Px, rad: i64, wanted: Wanted) {
        let f = self.frame;
        let (w_img, h_img) = (f.width as i64, f.height as i64);
        let (c0, c1) = ((c.0 - rad).max(0), (c.0 + rad).min(w_img - 1));
        let (r0, r1) = ((c.1 - rad).max(0), (c.1 + rad).min(h_img - 1));
        if c0 > c1 || r0 > r1 {
            self.win_on = false;
            return;
        }
        let (w, h) = (c1 - c0 + 1, r1 - r0 + 1);
        let mut pre = std::mem::take(&mut self.win.pre);
        pre.clear();
        pre.resize((h * (w + 1)) as usize, 0);
        let free = known.known_free().as_slice();
        let swept = self.swept.as_slice();
        for r in 0..h {
            let row = r0 + r;
            let base = row as usize * f.width;
            let line = &mut pre[(r * (w + 1)) as usize..((r + 1) * (w + 1)) as usize];
            crate::bits::for_each_set(
                base + c0 as usize,
                base + c1 as usize + 1,
                |k| free[k] & !swept[k],
                |i| {
                    let col = (i - base) as i64;
                    if wanted.is_none_or(|wf| wf(self.world(self.center((col, row))))) {
                        line[(col - c0 + 1) as usize] = 1;
                    }
                    true
                },
            );
            for k in 1..line.len() {
                line[k] += line[k - 1];
            }
        }
        self.win = Window { c0, r0, w, h, pre };
        self.win_on = true;
    }

    /// [`Self::count_targets`] over the tool disk from the window; `None` when the disk leaves it.
    fn window_count(&self, p: Px, cap: usize) -> Option<usize> {
        let f = self.frame;
        let (w_img, h_img) = (f.width as i64, f.height as i64);
        let win = &self.win;
        let cap = cap.max(1);
        let rows = &self.tool_rows;
        let reach = rows.len() as i64 - 1;
        let mut n = 0;
        for dr in -reach..=reach {
            let row = p.1 + dr;
            let hw = rows[dr.unsigned_abs() as usize];
            if hw < 0 || row < 0 || row >= h_img {
                continue;
            }
            let (lo, hi) = ((p.0 - hw).max(0), (p.0 + hw).min(w_img - 1));
            if lo > hi {
                continue;
            }
            if row < win.r0 || row >= win.r0 + win.h || lo < win.c0 || hi >= win.c0 + win.w {
                return None;
            }
            let base = ((row - win.r0) * (win.w + 1)) as usize;
            n += (win.pre[base + (hi - win.c0 + 1) as usize]
                - win.pre[base + (lo - win.c0) as usize]) as usize;
            if n >= cap {
                return Some(cap);
            }
        }
        Some(n)
    }

    /// Number of targets in the disk `rows` (row half-widths) around `p` (stops at `cap`).
    fn count_targets(
        &self,
        known: &KnownMap,
        p: Px,
        wanted: Wanted,
        cap: usize,
        rows: &[i64],
    ) -> usize {
        let f = self.frame;
        let (w, h) = (f.width as i64, f.height as i64);
        let free = known.known_free().as_slice();
        let swept = self.swept.as_slice();
        let reach = rows.len() as i64 - 1;
        let mut n = 0;
        for dr in -reach..=reach {
            let row = p.1 + dr;
            let hw = rows[dr.unsigned_abs() as usize];
            if hw < 0 || row < 0 || row >= h {
                continue;
            }
            let (lo, hi) = ((p.0 - hw).max(0), (p.0 + hw).min(w - 1));
            if lo > hi {
                continue;
            }
            let base = row as usize * f.width;
            let Some(wanted) = wanted else {
                // Every target counts: whole words at a time.
                n += count_range(free, swept, base + lo as usize, base + hi as usize + 1);
                if n >= cap.max(1) {
                    return cap.max(1);
                }
                continue;
            };
            let go_on = crate::bits::for_each_set(
                base + lo as usize,
                base + hi as usize + 1,
                |k| free[k] & !swept[k],
                |i| {
                    if wanted(self.world(self.center(((i - base) as i64, row)))) {
                        n += 1;
                    }
                    n < cap
                },
            );
            if !go_on {
                break;
            }
        }
        n
    }

    /// The known free pixels: the count [`Self::refresh_no_gain`] keeps once the final
    /// clean-up began, else counted now.
    fn known_free_count(&self, known: &KnownMap) -> usize {
        if self.no_gain_free.len() == known.known_free().as_slice().len() {
            self.free_count
        } else {
            known.known_free().count_ones(..)
        }
    }

    /// Drops the [`Self::no_gain`] memo around every pixel that became known free since the
    /// last call (a new target there may make positions within the strip disk gain).
    fn refresh_no_gain(&mut self, known: &KnownMap) {
        let free = known.known_free().as_slice();
        if self.no_gain_free.len() != free.len() {
            self.no_gain.clear();
            self.no_gain_free = free.to_vec();
            self.free_count = known.known_free().count_ones(..);
            return;
        }
        let f = self.frame;
        let (w, h) = (f.width as i64, f.height as i64);
        let reach = self.strip_rows.len() as i64 - 1;
        let bits = crate::bits::BLOCK_BITS;
        // The memo is dropped in the square of side `2 reach + 1` around every new pixel: per
        // image row, the new pixels' columns widened by `reach` and merged into runs, each run
        // then cleared in the rows within `reach` (one range per run and row, not per pixel).
        let mut runs: Vec<(i64, i64, i64)> = Vec::new();
        // Most of the map did not change since the last call: compare a stretch of blocks at
        // a time (one slice comparison) and look into the stretches that differ only.
        let changed: Vec<usize> = (0..free.len())
            .step_by(STRETCH)
            .filter(|&s| {
                let e = (s + STRETCH).min(free.len());
                free[s..e] != self.no_gain_free[s..e]
            })
            .collect();
        for b in changed
            .into_iter()
            .flat_map(|s| s..(s + STRETCH).min(free.len()))
        {
            let new = free[b] & !self.no_gain_free[b];
            self.no_gain_free[b] = free[b];
            if new == 0 {
                continue;
            }
            self.free_count += new.count_ones() as usize;
            let mut todo = new;
            while todo != 0 {
                let i = b * bits + todo.trailing_zeros() as usize;
                todo &= todo - 1;
                let (c, r) = f.col_row(i);
                let (c, r) = (c as i64, r as i64);
                let (c0, c1) = ((c - reach).max(0), (c + reach).min(w - 1));
                // Pixels come in index order: a run grows while it stays on its row and overlaps.
                match runs.last_mut() {
                    Some(last) if last.0 == r && c0 <= last.2 + 1 => last.2 = last.2.max(c1),
                    _ => runs.push((r, c0, c1)),
                }
            }
        }
        for (r, c0, c1) in runs {
            for row in (r - reach).max(0)..=(r + reach).min(h - 1) {
                let base = row as usize * f.width;
                self.no_gain
                    .remove_range(base + c0 as usize..base + c1 as usize + 1);
            }
        }
    }

    /// Marks the targets around `p` swept; returns their indices.
    fn claim(&mut self, known: &KnownMap, p: Px, wanted: Wanted) -> Vec<usize> {
        let mut out = Vec::new();
        for k in 0..self.tool.len() {
            let (dc, dr) = self.tool[k];
            let q = (p.0 + dc, p.1 + dr);
            if self.is_target(known, q, wanted) {
                let i = self.idx(q).expect("targets are in the image");
                self.swept.insert(i);
                out.push(i);
            }
        }
        out
    }

    /// Is `p` on the contour of `S0` (a neighbour known not to fit)?
    fn on_contour(&mut self, known: &KnownMap, p: Px) -> bool {
        (0..8).any(|k| {
            let q = (p.0 + NB[k].0, p.1 + NB[k].1);
            self.idx(q).is_none() || self.in_s0(known, q) == Some(false)
        })
    }

    fn begin(&mut self) {
        self.generation = (self.generation + 1) % NODE_GENS;
        if self.generation == 0 {
            self.nodes.fill(0);
            self.generation = 1;
        }
    }

    /// Dijkstra (A* with `goal`) over positions from grid point `from`. Stops at the first
    /// settled position for which `done` holds, or when the cost exceeds `limit`. Returns the
    /// position path (pixel indices), starting next to `from`. With `resume`, goes on from
    /// where the last search (same `from`, `limit` and no `goal`, nothing changed since but
    /// the targets) stopped, when it found a position.
    fn search(
        &mut self,
        known: &KnownMap,
        from: Point,
        limit: Option<u64>,
        goal: Option<Point>,
        resume: bool,
        done: &mut dyn FnMut(&mut Self, Px) -> bool,
    ) -> Option<Vec<usize>> {
        let mut heap = std::mem::take(&mut self.heap);
        if !resume || self.resume_at.is_none() {
            self.begin();
            self.resume_at = None;
            heap.clear();
        }
        // Transfers need a short known-free way, not the shortest: an inflated heuristic
        // (weighted A*) settles far fewer positions; the way is straightened afterwards.
        // Without a goal the heuristic is 0 and compiled away (a search settles up to millions
        // of positions, each queuing up to 8 neighbours).
        let found = match goal {
            None => self.search_with(known, from, limit, &|_: &Self, _: Px| 0, &mut heap, done),
            Some(g) => {
                let h = move |s: &Self, p: Px| -> u64 {
                    (s.center(p).dist(g) * ROUTE_WEIGHT * COST_ORTHO as f64).floor() as u64
                };
                self.search_with(known, from, limit, &h, &mut heap, done)
            }
        };
        self.heap = heap;
        found
    }

    /// [`Self::search`]'s body, on the queue `heap`.
    fn search_with<H: Fn(&Self, Px) -> u64>(
        &mut self,
        known: &KnownMap,
        from: Point,
        limit: Option<u64>,
        h: &H,
        heap: &mut BucketQueue,
        done: &mut dyn FnMut(&mut Self, Px) -> bool,
    ) -> Option<Vec<usize>> {
        let p0 = self.frame.grid_to_pixel_signed(from);
        if let Some(i) = self.resume_at.take() {
            // Go on where the last search from `from` stopped: its settled positions and queue
            // are still valid (the graph has not changed); expand the position it stopped at.
            let p = self.px_of(i);
            self.relax(known, i, p, h, heap);
        } else {
            self.seed(known, from, p0, h, heap);
        }
        while let Some(i) = heap.pop() {
            if self.nodes[i] & CLOSED != 0 {
                continue;
            }
            let d = node_cost(self.nodes[i]);
            if limit.is_some_and(|l| d > l) {
                return None;
            }
            self.nodes[i] |= CLOSED;
            let p = self.px_of(i);
            if done(self, p) {
                self.resume_at = Some(i);
                let mut path = vec![i];
                let mut c = i;
                while let Some(k) = node_move(self.nodes[c]) {
                    let (col, row) = self.px_of(c);
                    c = self
                        .idx((col - NB[k].0, row - NB[k].1))
                        .expect("parents are in the image");
                    path.push(c);
                }
                path.reverse();
                return Some(path);
            }
            self.relax(known, i, p, h, heap);
        }
        None
    }

    /// The positions next to grid point `from` that it reaches by a known-free move, queued.
    fn seed<H: Fn(&Self, Px) -> u64>(
        &mut self,
        known: &KnownMap,
        from: Point,
        p0: Px,
        h: &H,
        heap: &mut BucketQueue,
    ) {
        let gen = self.generation;
        for dr in -1..=1 {
            for dc in -1..=1 {
                let p = (p0.0 + dc, p0.1 + dr);
                let Some(i) = self.idx(p) else { continue };
                if self.in_s0(known, p) != Some(true) || !self.seg_free(known, from, self.center(p))
                {
                    continue;
                }
                let d = (from.dist(self.center(p)) * COST_ORTHO as f64).round() as u64;
                let n = self.nodes[i];
                if node_gen(n) != gen || d < node_cost(n) {
                    self.nodes[i] = node(d, None, gen);
                    heap.push(d + h(self, p), i);
                }
            }
        }
    }

    /// Queues the neighbours of settled position `i` (pixel `p`; search cost in `dist`).
    fn relax<H: Fn(&Self, Px) -> u64>(
        &mut self,
        known: &KnownMap,
        i: usize,
        p: Px,
        h: &H,
        heap: &mut BucketQueue,
    ) {
        let gen = self.generation;
        let d = node_cost(self.nodes[i]);
        let (w, h_img) = (self.frame.width as i64, self.frame.height as i64);
        let edges = self.edge_free[i];
        // Moves known blocked (walls, positions where the robot does not fit) are left out
        // before their neighbour's state is read.
        let blocked = self.edge_blocked[i];
        // The neighbours' states are read first, all at once (independent loads, mostly
        // cache misses, overlap); the loop below writes only neighbours, each once.
        let mut js = [usize::MAX; 8];
        if p.0 > 0 && p.1 > 0 && p.0 < w - 1 && p.1 < h_img - 1 {
            // Inside the image's rim every neighbour is in it: index offsets only.
            for (k, jk) in js.iter_mut().enumerate() {
                if blocked & (1 << k) == 0 {
                    *jk = i.wrapping_add_signed((NB[k].1 * w + NB[k].0) as isize);
                }
            }
        } else {
            for (k, jk) in js.iter_mut().enumerate() {
                let q = (p.0 + NB[k].0, p.1 + NB[k].1);
                if blocked & (1 << k) == 0 && q.0 >= 0 && q.1 >= 0 && q.0 < w && q.1 < h_img {
                    *jk = (q.1 * w + q.0) as usize;
                }
            }
        }
        let ns: [Node; 8] = std::array::from_fn(|k| {
            if js[k] == usize::MAX {
                0
            } else {
                self.nodes[js[k]]
            }
        });
        for k in 0..8 {
            let j = js[k];
            if j == usize::MAX {
                continue;
            }
            let q = (p.0 + NB[k].0, p.1 + NB[k].1);
            let nd = d + if k % 2 == 1 { COST_DIAG } else { COST_ORTHO };
            // Settled or no better: skip before judging the move (judging only fills memos).
            let n = ns[k];
            if node_gen(n) == gen && (n & CLOSED != 0 || nd >= node_cost(n)) {
                continue;
            }
            // The memo first (most moves were judged by an earlier search).
            if edges & (1 << k) == 0 && !self.edge(known, p, k) {
                continue;
            }
            self.nodes[j] = node(nd, Some(k), gen);
            heap.push(nd + h(self, q), j);
        }
    }

    /// Plans the next chunk of a cleaning pass from world point `pos`: the transfer to the rim
    /// (waypoints that reach the first sweeping position) and the sweep along it; both empty
    /// when no rim within `reach_r` robot radii (`bounded`; else anywhere) gains.
    ///
    /// After the host's coverage (`!bounded`) a chunk whose yield is below
    /// [`ExtensionOptions::min_yield`] is left (its pixels stay claimed, so no later search
    /// returns to them) while the pixels left stay within [`ExtensionOptions::leave_fraction`]
    /// of the known free floor, and the next chunk is planned from `pos` instead.
    pub(crate) fn plan_pass(
        &mut self,
        known: &KnownMap,
        pos: Point,
        bounded: bool,
        wanted: Wanted,
    ) -> Chunk {
        let chunk = self.plan_pass_inner(known, pos, bounded, wanted);
        self.simplified += chunk.simplified;
        chunk
    }

    /// One chunk planned from world point `pos` as at the end of a host region but within
    /// `reach_r` robot radii whatever [`ExtensionOptions::reach_r`] says (used by
    /// `ba-star-extended`'s rims swept on the way back, [`Self::drop_chunk`] when it is not
    /// driven as planned).
    pub(crate) fn plan_near(
        &mut self,
        known: &KnownMap,
        pos: Point,
        reach_r: f64,
        wanted: Wanted,
    ) -> Chunk {
        let keep = self.opts.reach_r;
        self.opts.reach_r = reach_r;
        let chunk = self.plan_pass(known, pos, true, wanted);
        self.opts.reach_r = keep;
        chunk
    }

    /// Forgets a planned chunk that will not be driven as planned: its claims are given back
    /// (what the robot drives is stamped as it goes) and its simplification is not counted.
    pub(crate) fn drop_chunk(&mut self, chunk: &Chunk) {
        self.unclaim(chunk);
        self.simplified -= chunk.simplified;
    }

    /// [`Self::plan_pass`] before the chunk's simplification is counted.
    fn plan_pass_inner(
        &mut self,
        known: &KnownMap,
        pos: Point,
        bounded: bool,
        wanted: Wanted,
    ) -> Chunk {
        let mut cur = self.plan_chunk(known, pos, bounded, wanted, false);
        loop {
            if bounded
                || cur.gained == 0
                || cur.owed
                || self.opts.min_yield <= 0.0
                || self.pays(
                    cur.gained,
                    2.0 * cur.trip_len(pos) + 2.0 * cur.walk_len(pos),
                )
            {
                return cur;
            }
            // Leave it, alone or together with the chunks planned after it (nearest first from
            // here: the search goes on where it stopped) when those lie close together and far
            // away — a cluster of specks whose trip does not pay as a whole although each
            // speck, seen from the next one, is on the way.
            let mut group = vec![cur];
            let next = loop {
                let next = self.plan_chunk(known, pos, bounded, wanted, true);
                let gained: usize = group.iter().map(|c| c.gained).sum();
                if !self.pays(gained, group_saving(pos, &group, &next)) {
                    if self.charge(known, pos, &group) {
                        break Some(next);
                    }
                    self.unclaim(&next);
                    break None;
                }
                if group.len() >= self.opts.leave_group
                    || next.gained == 0
                    || next.owed
                    || self.left + gained + next.gained > self.leave_budget(known)
                {
                    self.unclaim(&next);
                    break None;
                }
                group.push(next);
            };
            let Some(next) = next else {
                for c in &group[1..] {
                    self.unclaim(c);
                }
                return group.swap_remove(0);
            };
            cur = next;
        }
    }

    /// Does `chunk`'s walk gain at least [`ExtensionOptions::min_yield`] of what a full-width
    /// lane of `len` metres sweeps?
    fn pays(&self, gained: usize, len: f64) -> bool {
        let res = self.frame.resolution;
        gained as f64 * res * res >= self.opts.min_yield * 2.0 * self.rt * res * len
    }

    /// The known free floor [`ExtensionOptions::leave_fraction`] allows the final clean-up
    /// to leave, in pixels.
    fn leave_budget(&self, known: &KnownMap) -> usize {
        (self.opts.leave_fraction * self.known_free_count(known) as f64) as usize
    }

    /// Counts the chunks of `group` (planned from world point `pos`) as left when the budget
    /// ([`ExtensionOptions::leave_fraction`]) allows; whether it did.
    fn charge(&mut self, known: &KnownMap, pos: Point, group: &[Chunk]) -> bool {
        // Charged: the walks' pixels and the targets the ways there would sweep on the side
        // (specks too small for a pass of their own, which leaving the trips leaves as well).
        let f = self.frame;
        let mut side: Vec<usize> = Vec::new();
        for chunk in group {
            let way: Vec<Point> = std::iter::once(pos)
                .chain(chunk.transfer.iter().copied())
                .map(|p| f.world_to_grid(p))
                .collect();
            side.extend(self.polyline_gains(known, &way).concat());
        }
        side.sort_unstable();
        side.dedup();
        let charged = group.iter().map(|c| c.gained).sum::<usize>() + side.len();
        if self.left + charged > self.leave_budget(known) {
            return false;
        }
        self.left += charged;
        // Left with them: no later pass goes out for them alone.
        for i in side {
            self.swept.insert(i);
        }
        true
    }

    /// Gives the pixels `chunk` claimed back (it will not be driven now).
    fn unclaim(&mut self, chunk: &Chunk) {
        let f = self.frame;
        let (w, h) = (f.width as i64, f.height as i64);
        let reach = self.strip_rows.len() as i64 - 1;
        for &i in &chunk.claimed {
            self.swept.set(i, false);
            // Positions the searches since judged without these targets may gain again.
            let (c, r) = self.px_of(i);
            let (c0, c1) = ((c - reach).max(0), (c + reach).min(w - 1));
            for row in (r - reach).max(0)..=(r + reach).min(h - 1) {
                let base = row as usize * f.width;
                self.no_gain
                    .remove_range(base + c0 as usize..base + c1 as usize + 1);
            }
        }
    }

    /// One chunk of [`Self::plan_pass`]; `resume` goes on with the last search from `pos`
    /// (the last chunk was left).
    fn plan_chunk(
        &mut self,
        known: &KnownMap,
        pos: Point,
        bounded: bool,
        wanted: Wanted,
        resume: bool,
    ) -> Chunk {
        let from = self.frame.world_to_grid(pos);
        let limit = bounded.then(|| {
            (self.opts.reach_r * self.r / self.frame.resolution * COST_ORTHO as f64) as u64
        });
        // Thresholds, in pixels a position must sweep: a trip to a rim must gain a tool radius
        // of pixels (at least 2; after the host's coverage one on a strip of rim: only specks
        // stay), a step off the contour as much, a step along the contour one.
        let tool = self.rt.ceil().max(1.0) as usize;
        let g_start = if bounded { tool } else { tool.max(2) };
        let g_int = tool;
        let g_con = 1;
        // A resumed search follows a chunk left in the same pass: the known map is the same.
        if !bounded && !resume {
            self.refresh_no_gain(known);
        }
        if let Some(l) = limit {
            // Every position the bounded search settles lies within `l` of `from`.
            let rad = (l / COST_ORTHO) as i64 + self.tool_rows.len() as i64 + 2;
            let p0 = self.frame.grid_to_pixel_signed(from);
            self.build_window(known, p0, rad, wanted);
        }
        let transit = self.search(known, from, limit, None, resume, &mut |s, p| {
            let i = s.idx(p).expect("positions are in the image");
            if !bounded && s.no_gain.contains(i) {
                return false;
            }
            let g = s.gain(known, p, wanted, g_start);
            // After the host: a position that sweeps a single pixel starts a pass too when it
            // lies on a strip of rim (enough targets in the wider disk), not on a lone speck.
            let gains = g >= g_start
                || (!bounded
                    && g >= 1
                    && (s.count_targets(known, p, wanted, STRIP_N, &s.strip_rows) >= STRIP_N
                        || s.sweeps_owed(p)));
            if !gains && !bounded {
                s.no_gain.insert(i);
            }
            gains
        });
        self.win_on = false;
        let Some(transit) = transit else {
            return Chunk::default();
        };
        let mut pts: Vec<Point> = vec![from];
        let mut gains: Vec<Vec<usize>> = vec![Vec::new()];
        for &i in &transit[..transit.len() - 1] {
            pts.push(self.center(self.px_of(i)));
            gains.push(Vec::new());
        }
        // The walk.
        // Gains beyond a tool radius of pixels do not outrank a straighter step (fewer turns
        // once merged; on the shared maps 3 % fewer turns for either host).
        let walk_cap = g_int;
        let mut cur = self.px_of(*transit.last().expect("non-empty path"));
        let mut dir: Option<usize> = None;
        pts.push(self.center(cur));
        gains.push(self.claim(known, cur, wanted));
        for _ in 0..MAX_WALK {
            let mut best: Option<(bool, usize, i64, usize)> = None;
            for k in 0..8 {
                if !self.edge(known, cur, k) {
                    continue;
                }
                let q = (cur.0 + NB[k].0, cur.1 + NB[k].1);
                // Counted up to `walk_cap` (>= `g_int` >= `g_con`): every test below reads no more.
                let g = self.gain(known, q, wanted, walk_cap);
                if g < g_con {
                    continue;
                }
                let contour = self.on_contour(known, q);
                // Off the contour a step must gain a tool radius of pixels; with `strip_walk`
                // (final clean-up only) also a step onto a strip of rim, as a pass may start.
                if !contour
                    && g < g_int
                    && !(self.strip_walk
                        && !bounded
                        && self.count_targets(known, q, wanted, STRIP_N, &self.strip_rows)
                            >= STRIP_N)
                {
                    continue;
                }
                let turn = dir.map_or(0, |d| {
                    let t = (k + 8 - d) % 8;
                    t.min(8 - t) as i64
                });
                let key = (contour, g.min(walk_cap), -turn, k);
                let better = best.is_none_or(|b| {
                    (key.0, key.1, key.2) > (b.0, b.1, b.2)
                        || ((key.0, key.1, key.2) == (b.0, b.1, b.2) && key.3 < b.3)
                });
                if better {
                    best = Some(key);
                }
            }
            let Some((_, _, _, k)) = best else { break };
            cur = (cur.0 + NB[k].0, cur.1 + NB[k].1);
            dir = Some(k);
            pts.push(self.center(cur));
            gains.push(self.claim(known, cur, wanted));
        }
        // The transfer (up to the walk's first position, index `nt`) and the walk are merged
        // apart: no segment cuts across from the way there to the rim.
        let nt = transit.len();
        let mut simplified = 0;
        let kept: Vec<usize> = if self.opts.merge_segments {
            let mut kept = self.merge(known, &pts[..=nt], &gains[..=nt]);
            kept.extend(
                self.merge(known, &pts[nt..], &gains[nt..])
                    .into_iter()
                    .map(|k| k + nt),
            );
            let (kept, lost) = self.simplify(known, &pts, &gains, kept);
            simplified = lost;
            kept
        } else {
            (1..pts.len()).collect()
        };
        let verts: Vec<(usize, Point)> = std::iter::once(0)
            .chain(kept)
            .map(|k| (k, pts[k]))
            .collect();
        let verts = if self.opts.merge_segments && self.opts.corner_slack > 0.0 {
            self.square_corners(known, &gains, verts)
        } else {
            verts
        };
        let split = verts.partition_point(|v| v.0 <= nt);
        Chunk {
            transfer: verts[1..split].iter().map(|v| self.world(v.1)).collect(),
            sweep: verts[split..].iter().map(|v| self.world(v.1)).collect(),
            gained: gains.iter().map(Vec::len).sum(),
            claimed: gains.iter().flatten().copied().collect(),
            owed: self.any_owed && gains.iter().flatten().any(|&i| self.owed.contains(i)),
            simplified,
        }
    }

    /// Greedy cut of the polyline `pts` into straight segments, each known free and keeping
    /// every pixel in `gains` of the points it replaces within the tool radius. Returns the kept
    /// point indices (the first point, the robot, excluded).
    fn merge(&self, known: &KnownMap, pts: &[Point], gains: &[Vec<usize>]) -> Vec<usize> {
        let rt2 = self.rt * self.rt;
        // The gained pixels' centres, once (each is checked against many segments), flat
        // with `at[m]..at[m + 1]` those of point `m`.
        let mut at = Vec::with_capacity(gains.len() + 1);
        let mut centres = Vec::with_capacity(gains.iter().map(Vec::len).sum());
        for g in gains {
            at.push(centres.len());
            centres.extend(g.iter().map(|&i| self.center(self.px_of(i))));
        }
        at.push(centres.len());
        let keeps = |a: usize, b: usize| -> bool {
            centres[at[a + 1]..at[b + 1]]
                .iter()
                .all(|&c| point_segment_dist2(c, pts[a], pts[b]) <= rt2)
                && self.seg_free(known, pts[a], pts[b])
        };
        let mut out = Vec::new();
        let mut a = 0;
        while a + 1 < pts.len() {
            let mut b = a + 1;
            while b + 1 < pts.len() && b + 1 - a <= MAX_MERGE && keeps(a, b + 1) {
                b += 1;
            }
            let far = (b + MERGE_LOOK).min(pts.len() - 1).min(a + MAX_MERGE);
            if let Some(c) = (b + 2..=far).rev().find(|&c| keeps(a, c)) {
                b = c;
            }
            out.push(b);
            a = b;
        }
        out
    }

    /// Square corners: where the merged chunk rounds a corner (the contour at clearance 0 is an
    /// arc there, several short segments), a run of up to [`CORNER_RUN`] vertices is replaced
    /// by the one point where the segment entering it and the segment leaving it meet, when
    /// both new segments are known free, every pixel the walk gained along the run that the
    /// chunk still sweeps stays within the tool radius, and the way grows by at most
    /// [`ExtensionOptions::corner_slack`] robot radii per turn saved. Takes and returns the
    /// vertices (index of the walk point each replaces last, grid point), the robot's position
    /// first.
    fn square_corners(
        &self,
        known: &KnownMap,
        gains: &[Vec<usize>],
        mut out: Vec<(usize, Point)>,
    ) -> Vec<(usize, Point)> {
        let rt2 = self.rt * self.rt;
        let slack = self.opts.corner_slack * self.r / self.frame.resolution;
        let near = |c: Point, poly: &[Point]| {
            poly.windows(2)
                .any(|s| point_segment_dist2(c, s[0], s[1]) <= rt2)
        };
        let mut i = 1;
        while i + 2 < out.len() {
            let mut replaced = false;
            for j in (i + 1..=(i + CORNER_RUN - 1).min(out.len() - 2)).rev() {
                let (a, p, q, b) = (out[i - 1].1, out[i].1, out[j].1, out[j + 1].1);
                let (d1, d2) = (p - a, b - q);
                let cross = d1.x * d2.y - d1.y * d2.x;
                if cross.abs() < 1e-9 {
                    continue;
                }
                // a + t d1 = q + s d2.
                let w = q - a;
                let t = (w.x * d2.y - w.y * d2.x) / cross;
                let s = (w.x * d1.y - w.y * d1.x) / cross;
                if t < 1.0 - 1e-9 || s > 1e-9 {
                    continue;
                }
                let x = Point::new(a.x + t * d1.x, a.y + t * d1.y);
                let old: Vec<Point> = out[i - 1..=j + 1].iter().map(|v| v.1).collect();
                let old_len: f64 = old.windows(2).map(|s| s[0].dist(s[1])).sum();
                let new = [a, x, b];
                if a.dist(x) + x.dist(b) - old_len > slack * (j - i) as f64 {
                    continue;
                }
                let keeps = gains[out[i - 1].0 + 1..=out[j + 1].0].iter().all(|g| {
                    g.iter().all(|&k| {
                        let c = self.center(self.px_of(k));
                        !near(c, &old) || near(c, &new)
                    })
                });
                if keeps && self.seg_free(known, a, x) && self.seg_free(known, x, b) {
                    let last = out[j].0;
                    out.splice(i..=j, [(last, x)]);
                    replaced = true;
                    break;
                }
            }
            if !replaced {
                i += 1;
            }
        }
        out
    }

    /// Drops vertices of the merged chunk `kept` (indices into `pts`, the first point excluded)
    /// whose removal leaves few of the walk's gained pixels unswept: cheapest loss first
    /// (Visvalingam-style on the pixels lost), each removal losing at most
    /// [`ExtensionOptions::simplify_loss`] tool radii of pixels, all removals within the budget
    /// ([`ExtensionOptions::simplify_fraction`] of the known free floor). The straight way
    /// that replaces a vertex must be known free. Lost pixels stay claimed (no later pass goes
    /// out for them alone) and count as left. Returns the kept indices and how many pixels
    /// they leave.
    fn simplify(
        &mut self,
        known: &KnownMap,
        pts: &[Point],
        gains: &[Vec<usize>],
        kept: Vec<usize>,
    ) -> (Vec<usize>, usize) {
        if kept.len() < 2 {
            return (kept, 0);
        }
        let mut spent = 0;
        // Counted only when a removal loses a pixel (most lose none).
        let mut budget: Option<usize> = None;
        let per_turn = self.simplify_per_turn;
        let rt2 = self.rt * self.rt;
        // Vertices: the walk's start (index 0) and the kept points; a doubly linked list.
        let verts: Vec<usize> = std::iter::once(0).chain(kept.iter().copied()).collect();
        let n = verts.len();
        let mut prev: Vec<usize> = (0..n).map(|k| k.wrapping_sub(1)).collect();
        let mut next: Vec<usize> = (1..=n).collect();
        let mut alive = vec![true; n];
        let mut version = vec![0u32; n];
        let mut lost: Vec<usize> = Vec::new();
        // Pixels lost so far are marked in `scratch` (cleared before returning).
        let cost = |s: &Self, u: usize, w: usize| -> Option<usize> {
            let (a, b) = (verts[u], verts[w]);
            if b - a > 4 * MAX_MERGE {
                return None;
            }
            let mut c = 0;
            for g in &gains[a + 1..=b] {
                for &i in g {
                    if !s.scratch.contains(i)
                        && point_segment_dist2(s.center(s.px_of(i)), pts[a], pts[b]) > rt2
                    {
                        c += 1;
                    }
                }
            }
            (c <= per_turn && s.seg_free(known, pts[a], pts[b])).then_some(c)
        };
        let mut heap: std::collections::BinaryHeap<std::cmp::Reverse<(usize, usize, u32)>> =
            std::collections::BinaryHeap::new();
        for v in 1..n - 1 {
            if let Some(c) = cost(self, v - 1, v + 1) {
                heap.push(std::cmp::Reverse((c, v, 0)));
            }
        }
        while let Some(std::cmp::Reverse((c, v, ver))) = heap.pop() {
            if !alive[v] || ver != version[v] {
                continue;
            }
            if c > 0 {
                let b = *budget.get_or_insert_with(|| {
                    (self.opts.simplify_fraction * self.known_free_count(known) as f64) as usize
                });
                if self.simplified + spent + c > b {
                    continue;
                }
            }
            let (u, w) = (prev[v], next[v]);
            // Mark what the straight u-w no longer sweeps.
            let (a, b) = (verts[u], verts[w]);
            for g in &gains[a + 1..=b] {
                for &i in g {
                    if !self.scratch.contains(i)
                        && point_segment_dist2(self.center(self.px_of(i)), pts[a], pts[b]) > rt2
                    {
                        self.scratch.insert(i);
                        lost.push(i);
                    }
                }
            }
            spent += c;
            alive[v] = false;
            next[u] = w;
            prev[w] = u;
            for x in [u, w] {
                if x == 0 || x == n - 1 {
                    continue;
                }
                version[x] += 1;
                if let Some(c) = cost(self, prev[x], next[x]) {
                    heap.push(std::cmp::Reverse((c, x, version[x])));
                }
            }
        }
        for i in lost {
            self.scratch.set(i, false);
        }
        (
            (1..n).filter(|&k| alive[k]).map(|k| verts[k]).collect(),
            spent,
        )
    }

    /// Lane ends driven to the wall: the host's lane along heading `theta` ends at world point
    /// `c` and the host moves on to `next` (the start of its next lane, beside `c`). When a
    /// known obstacle lies within `reach` metres ahead of `c`, the robot drives on to it, along
    /// it to the point in front of `next`, and back to `next` (the next lane, started at the
    /// wall); the waypoints, or `None` when there is no wall ahead or nothing to gain there.
    pub(crate) fn lane_end(
        &mut self,
        known: &KnownMap,
        c: Point,
        theta: f64,
        next: Point,
        reach: f64,
        wanted: &dyn Fn(Point) -> bool,
    ) -> Option<Vec<Point>> {
        let res = self.frame.resolution;
        let ahead = |p: Point| -> Option<Point> {
            let d = known.free_distance(p, theta, reach, self.r);
            if d >= reach - 1e-9 {
                return None;
            }
            // Stop a hair short of contact, then make sure.
            let mut d = d - 1e-3 * res;
            for _ in 0..8 {
                let w = Point::new(p.x + d * theta.cos(), p.y + d * theta.sin());
                if d <= 0.0 {
                    return None;
                }
                if judge_motion(known, p, w, self.r) == Judgement::Free {
                    return Some(w);
                }
                d -= 0.05 * res;
            }
            None
        };
        let w = ahead(c)?;
        if w.dist(c) < 0.5 * res {
            return None;
        }
        let gw = self.frame.grid_to_pixel_signed(self.frame.world_to_grid(w));
        if self.gain(known, gw, Some(wanted), 2) < 2 {
            return None;
        }
        let free = |a: Point, b: Point| judge_motion(known, a, b, self.r) == Judgement::Free;
        let out = match ahead(next) {
            Some(w2) if free(w, w2) => vec![w, w2, next],
            _ if free(w, next) => vec![w, next],
            _ => vec![w, c, next],
        };
        for w2 in out.windows(2) {
            self.record(w2[0], w2[1]);
        }
        self.record(c, w);
        Some(out)
    }

    /// A transfer from world point `from` to world point `to` over positions (A*), merged into
    /// known-free straight segments; `None` when no known-free way exists.
    pub(crate) fn route(&mut self, known: &KnownMap, from: Point, to: Point) -> Option<Vec<Point>> {
        let (gf, gt) = (self.frame.world_to_grid(from), self.frame.world_to_grid(to));
        if self.seg_free(known, gf, gt) {
            return Some(vec![to]);
        }
        let path = self.search(known, gf, None, Some(gt), false, &mut |s, p| {
            s.center(p).dist(gt) < 1.5 && s.seg_free(known, s.center(p), gt)
        })?;
        let mut pts = vec![gf];
        pts.extend(path.iter().map(|&i| self.center(self.px_of(i))));
        pts.push(gt);
        // Long known-free lines of sight: gallop forward, then bisect back to a free one.
        let mut out = Vec::new();
        let mut a = 0;
        let n = pts.len();
        while a + 1 < n {
            let (mut good, mut step) = (a + 1, 1);
            let mut bad = n;
            while good + step < n && self.seg_free(known, pts[a], pts[good + step]) {
                good += step;
                step *= 2;
            }
            if good + step < n {
                bad = good + step;
            }
            while bad - good > 1 {
                let mid = good + (bad - good) / 2;
                if self.seg_free(known, pts[a], pts[mid]) {
                    good = mid;
                } else {
                    bad = mid;
                }
            }
            out.push(self.world(pts[good]));
            a = good;
        }
        if let Some(last) = out.last_mut() {
            *last = to;
        }
        Some(out)
    }
}

/// The path leaving `group` saves (chunks planned from world point `pos`, nearest first),
/// with `next` the chunk planned after them: their tour (the first trip, the walks and the
/// straight ways between them, a lower bound) and the way on from the last to `next`, less
/// the (longer) trip from `pos` to `next`.
fn group_saving(pos: Point, group: &[Chunk], next: &Chunk) -> f64 {
    let mut tour = group[0].trip_len(pos);
    for (k, c) in group.iter().enumerate() {
        if k > 0 {
            tour += group[k - 1].end(pos).dist(c.start(pos));
        }
        tour += c.walk_len(pos);
    }
    if next.gained == 0 {
        return tour;
    }
    let last = group[group.len() - 1].end(pos);
    tour + last.dist(next.start(pos)) - next.trip_len(pos)
}

/// Number of bits `a..b` set in `free` and clear in `swept`.
fn count_range(free: &[usize], swept: &[usize], a: usize, b: usize) -> usize {
    use crate::bits::{range_mask, BLOCK_BITS};
    let mut n = 0;
    let mut blk = a / BLOCK_BITS;
    while blk * BLOCK_BITS < b {
        let start = blk * BLOCK_BITS;
        let mask = range_mask(a.max(start) - start, b.min(start + BLOCK_BITS) - start);
        // Mostly none (the target is built without a popcount instruction): test first.
        let bits = free[blk] & !swept[blk] & mask;
        if bits != 0 {
            n += bits.count_ones() as usize;
        }
        blk += 1;
    }
    n
}

/// What a host planner plus the extension keep while they drive (shared by `ba-star-extended`
/// and `bsa-extended`): the steps queued, the waypoints driven since the cleaning began (to
/// retreat by), whether a wall pass is open, and the last position seen (to record each move
/// into the extension).
#[derive(Debug, Default)]
pub(crate) struct Drive {
    /// Steps to return before asking anyone.
    pub queue: VecDeque<Step>,
    /// Waypoints driven since the cleaning began (its start first).
    pub trail: Vec<Point>,
    /// Inside a `wall_follow_start` / `wall_follow_end` pair.
    in_pass: bool,
    last_pos: Option<Point>,
}

impl Drive {
    /// Records the move since the last step into `ext` (made at the first step, when the
    /// sensor tells the robot's size); returns the robot's position.
    pub fn observe(
        &mut self,
        ext: &mut Option<Extension>,
        opts: &ExtensionOptions,
        sensor: &dyn Sensor,
    ) -> Point {
        let pos = sensor.pose().position();
        if let (Some(ext), Some(prev)) = (ext.as_mut(), self.last_pos) {
            if prev != pos {
                ext.record(prev, pos);
            }
        } else {
            let robot = sensor.robot();
            let mut made = Extension::new(
                opts.clone(),
                *sensor.frame(),
                robot.radius,
                robot.tool_radius,
            );
            made.record(pos, pos);
            *ext = Some(made);
        }
        self.last_pos = Some(pos);
        pos
    }

    /// Queues a chunk from `pos`: its trip (a backtracking transfer, drawn dashed and counted in
    /// `backtrack_length`, when it is a robot diameter (`2 radius`) or longer; else part of the
    /// pass) and its wall pass, with their events. `false` when the chunk is empty.
    pub fn queue_chunk(&mut self, pos: Point, chunk: &Chunk, radius: f64) -> bool {
        if chunk.transfer.is_empty() && chunk.sweep.is_empty() {
            return false;
        }
        let transfer = polyline_length(pos, &chunk.transfer) >= 2.0 * radius;
        if transfer {
            self.end_pass();
            self.queue.push_back(Step::Mark(Event::BacktrackStart));
        }
        for &p in &chunk.transfer {
            self.queue.push_back(Step::MoveTo(p));
            self.trail.push(p);
        }
        if transfer {
            self.queue.push_back(Step::Mark(Event::BacktrackEnd));
        }
        if !self.in_pass && !chunk.sweep.is_empty() {
            self.in_pass = true;
            self.queue.push_back(Step::Mark(Event::WallFollowStart));
        }
        for &p in &chunk.sweep {
            self.queue.push_back(Step::MoveTo(p));
            self.trail.push(p);
        }
        true
    }

    /// Closes an open wall pass (`wall_follow_end`).
    pub fn end_pass(&mut self) {
        if self.in_pass {
            self.in_pass = false;
            self.queue.push_back(Step::Mark(Event::WallFollowEnd));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{
        node, node_cost, node_gen, node_move, BucketQueue, BUCKET_MAX, BUCKET_SHIFT, CLOSED,
        NODE_COST_SHIFT, NODE_GENS,
    };
    use proptest::prelude::*;
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;

    /// A key: mostly a few pixel steps of search cost, sometimes past the last bucket.
    fn key() -> impl Strategy<Value = u64> {
        prop_oneof![
            8 => 0u64..20_000,
            1 => Just((BUCKET_MAX as u64) << BUCKET_SHIFT).prop_flat_map(|b| b..b + 5_000),
        ]
    }

    /// A node gives back the cost, move and generation it was made of, with or without the
    /// settled bit, at the extremes of every field.
    #[test]
    fn node_fields_round_trip() {
        let max_cost = (1u64 << (63 - NODE_COST_SHIFT)) - 1;
        for dist in [0, 1, 1414, 123_456_789, max_cost] {
            for k in [None, Some(0), Some(3), Some(7)] {
                for gen in [1, 2, NODE_GENS - 1] {
                    for closed in [0, CLOSED] {
                        let n = node(dist, k, gen) | closed;
                        assert_eq!(node_cost(n), dist);
                        assert_eq!(node_move(n), k);
                        assert_eq!(node_gen(n), gen);
                        assert_eq!(n & CLOSED, closed);
                    }
                }
            }
        }
    }

    proptest! {
        /// The bucket queue pops exactly what a binary min-heap on `(key, index)` pops, for any
        /// mix of pushes (keys below already popped ones included), pops and clears.
        #[test]
        fn bucket_queue_pops_in_heap_order(
            ops in proptest::collection::vec((0u8..10, key(), 0usize..64), 0..400)
        ) {
            let mut q = BucketQueue::default();
            let mut h: BinaryHeap<Reverse<(u64, usize)>> = BinaryHeap::new();
            for (op, k, i) in ops {
                match op {
                    0..=5 => {
                        q.push(k, i);
                        h.push(Reverse((k, i)));
                    }
                    6..=8 => prop_assert_eq!(q.pop(), h.pop().map(|Reverse((_, i))| i)),
                    _ => {
                        q.clear();
                        h.clear();
                    }
                }
            }
            while let Some(Reverse((_, i))) = h.pop() {
                prop_assert_eq!(q.pop(), Some(i));
            }
            prop_assert_eq!(q.pop(), None);
        }
    }
}
