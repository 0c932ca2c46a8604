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
//! it, less the direct trip there. A host may have a field of one-pixel specks judged as one
//! place (`Extension::set_speck_fields`; `ba-star-extended` does): a chunk within two tool
//! radii of the one before it then does not count towards the group's size. On the 14 shared
//! maps the final clean-up had spent 0.08 of the ideal path on trips to rims of at most 3
//! pixels (on `rmf_office_scan` 0.18).
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
//! # Layout
//!
//! This file holds the options ([`ExtensionOptions`]), the extension's state and its chunks;
//! the steps above live in private submodules: `extension::search` (the position search and
//! transfers), `extension::graph` (where the robot fits, which moves are free, the contour),
//! `extension::targets` (the sweep estimate, target counts, claims), `extension::walk` (one
//! chunk: rim, contour walk, lane ends), `extension::merge` (straight segments, square
//! corners), `extension::simplify`, `extension::cleanup` (passes and the leave judgement) and
//! `extension::drive` (what a host keeps while it drives).
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

mod bulk;
mod cleanup;
mod drive;
mod graph;
mod merge;
mod search;
mod simplify;
mod targets;
mod walk;

use fixedbitset::FixedBitSet;
use serde::{Deserialize, Serialize};

use crate::geometry::{polyline_length, Point};
use crate::grid::MapFrame;
use crate::planner::pixel_disk_spans;
use search::{BucketQueue, Node};
use targets::Window;
use walk::STRIP_PX;

pub(crate) use drive::{Drive, Mode};

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
    /// each speck, seen from the next, lies on the way; `1` judges each chunk alone. In
    /// `ba-star-extended` a chunk that starts within two tool radii of the end of the one
    /// before it (the same field of specks) does not count, up to four times this many chunks
    /// in all.
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

/// One chunk of a cleaning pass ([`Extension::plan_pass`]), world waypoints.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Chunk {
    /// The way to the rim: waypoints up to the first position that sweeps.
    pub(crate) transfer: Vec<Point>,
    /// The sweep along the rim, after the transfer (empty when the pass ends where it starts).
    pub(crate) sweep: Vec<Point>,
    /// The sweep's first move is more way than rim: merging dropped the walk's first position
    /// and joined the way's last stretch to the walk's first in one straight move, most of
    /// whose length lay on the way. It is then driven as the transfer's last move (drawn
    /// dashed, counted in `backtrack_length`) instead of as the pass's first, which drew a move
    /// of metres across an open room as rim sweeping. How the chunk is judged
    /// ([`Chunk::trip_len`], [`Chunk::walk_len`]) does not change.
    pub(crate) lead_in: bool,
    /// Target pixels the chunk's walk claims.
    pub(crate) gained: usize,
    /// Those pixels.
    claimed: Vec<usize>,
    /// Whether one of them is owed ([`Extension::owe_skipped`]).
    pub(crate) owed: bool,
    /// Gained pixels the simplified walk leaves (counted once the chunk is driven).
    simplified: usize,
    /// [`Extension::no_gain`] entries made since the chunk claimed its pixels start at this
    /// (logical) index of `no_gain_log`.
    log_at: usize,
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
// Independent switches of the state, not a mode: bools read best.
#[allow(clippy::struct_excessive_bools)]
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
    /// Per pixel, the move memo: in `[FREE]` bit `k` = the move to neighbour `NB[k]` is known
    /// free, in `[BLOCKED]` known blocked (a seen obstacle stays one, so this never changes
    /// back). One pair per pixel: a search reads both with one memory access.
    edges: Vec<[u8; 2]>,
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
    /// The positions the final clean-up's searches put into `no_gain`, in order, since the
    /// last search that started afresh; `no_gain_log_base` is the logical index of the first.
    /// Giving a chunk's claims back drops only the entries made after it claimed them
    /// (`Extension::unclaim`): the earlier ones were judged with its pixels still targets.
    no_gain_log: Vec<usize>,
    no_gain_log_base: usize,
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
    /// The grid segments of the ways to the chunks `Extension::charge` left in the running
    /// final pass (they sweep no target any more until the pass ends).
    charged_segs: std::collections::BTreeSet<cleanup::SegKey>,
    /// The cuts of the running final pass's transfers (`Extension::merge_transfer`).
    merge_memo: Vec<merge::MergeMemo>,
    /// Where the last search stopped (see `search_with`), while its state is valid.
    resume_at: Option<usize>,
    /// The running search is a final clean-up's (its `done` is false wherever `no_gain`
    /// holds): it may stop once no position can satisfy it (`search::nothing_gains`).
    exhaust_check: bool,
    /// Positions the running search cannot reach, found by `search::cut_off`.
    unreach: FixedBitSet,
    /// The positions set in `unreach` (cleared one by one: most searches mark none, and a
    /// whole-map clear per search cost more than the rest of a short one).
    unreach_marked: Vec<usize>,
    /// Scratch of `search::cut_off` (all clear between calls).
    met: FixedBitSet,
    /// The final clean-up's walk follows a strip of rim off the contour too (see
    /// [`Self::set_strip_walk`]).
    strip_walk: bool,
    /// The final clean-up counts a field of specks once towards
    /// [`ExtensionOptions::leave_group`] (see [`Self::set_speck_fields`]).
    speck_fields: bool,
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
            edges: vec![[0; 2]; n],
            tool: off,
            tool_rows,
            strip_rows,
            swept: FixedBitSet::with_capacity(n),
            scratch: FixedBitSet::with_capacity(n),
            owed: FixedBitSet::with_capacity(n),
            any_owed: false,
            no_gain: FixedBitSet::with_capacity(n),
            no_gain_free: Vec::new(),
            no_gain_log: Vec::new(),
            no_gain_log_base: 0,
            left: 0,
            simplified: 0,
            simplify_per_turn,
            free_count: 0,
            nodes: vec![0; n],
            generation: 0,
            heap: BucketQueue::default(),
            win: Window::default(),
            win_on: false,
            charged_segs: std::collections::BTreeSet::new(),
            merge_memo: Vec::new(),
            resume_at: None,
            exhaust_check: false,
            unreach: FixedBitSet::with_capacity(n),
            unreach_marked: Vec::new(),
            met: FixedBitSet::with_capacity(n),
            strip_walk: false,
            speck_fields: false,
        }
    }

    /// Lets the final clean-up's walk step off the contour onto a position on a strip of rim
    /// (at least 4 targets within the tool radius plus 3 pixels) that gains a single pixel, as
    /// a pass may start there; off (the default) such a step must gain a tool radius of
    /// pixels, and a strip away from the walls is fetched one position per chunk.
    pub(crate) fn set_strip_walk(&mut self, on: bool) {
        self.strip_walk = on;
    }

    /// Lets the final clean-up judge a field of specks as one place: a chunk that starts within
    /// two tool radii of the end of the chunk before it in a group does not count towards
    /// [`ExtensionOptions::leave_group`] (up to four times that many chunks in all). Off (the
    /// default), every chunk counts: `bsa-extended`'s mean path ratio on the 14 shared maps
    /// went from 1.3155 to 1.3186 with it (`aws_small_warehouse_002` 1.454 -> 1.482), while
    /// `ba-star-extended`'s went from 1.3128 to 1.3109.
    pub(crate) fn set_speck_fields(&mut self, on: bool) {
        self.speck_fields = on;
    }

    /// The options.
    pub(crate) fn options(&self) -> &ExtensionOptions {
        &self.opts
    }

    /// The robot radius (metres).
    pub(crate) fn radius(&self) -> f64 {
        self.r
    }
}
