//! BCD: boustrophedon cellular decomposition, the offline (known-map) reference planner.
//!
//! H. Choset and P. Pignon, "Coverage path planning: the boustrophedon cellular decomposition",
//! *Field and Service Robotics* (1997 conference, Springer 1998), and H. Choset, "Coverage of
//! known spaces: the boustrophedon cellular decomposition", *Autonomous Robots* 9, 2000; named
//! by seed 000 as the offline reference for BA*.
//!
//! **Offline**: it reads the whole true map (through the [`World`]) before moving, plans the
//! whole path, checks every straight move of it against the true map, and then replays it.
//!
//! What it follows from the paper, and where it deviates:
//! 1. **Decomposition.** The robot's *configuration space* (the reachable C-free pixel centres,
//!    so every lane is drivable by construction) is cut by a sweep line: each line of pixels is
//!    split into runs of C-free pixels; a cell continues while exactly one run of the previous
//!    line overlaps exactly one run of the current line; at every other event (split, merge,
//!    birth, death — the paper's critical points, found on the pixel grid instead of on a
//!    polygonal map) the involved cells close and new ones open. Both a west-to-east sweep
//!    (vertical lines) and a north-to-south sweep (horizontal lines) are decomposed; the one
//!    whose cells are estimated cheaper (path length plus `turn_cost_m` per turn) is used.
//!    The estimate prices lanes and turns inside the cells but not the transfers between
//!    them, and the two sweeps' estimates are often within a few percent, so on the pixel
//!    lattice alone (no turned lattice, below) the plain plan (no headland) is also made on
//!    the other sweep, and the cheaper plan is kept; every plan then tours its cells whole,
//!    and the cell set with even cells cut (step 4) is toured on the best plan's cells
//!    only, whichever it is (before, the headland plan was never toured cut). On the 14
//!    shared maps (r = 0.15 m) the mean path ratio goes from 1.1656 to 1.1578
//!    (`mit_building_31` 1.195 to 1.160, `aws_small_warehouse_002` 1.244 to 1.228,
//!    `nav2_depot` 1.106 to 1.095 with 598 turns instead of 736, all three by the other
//!    sweep; `teb_maze` 1.145 to 1.098 by its headland plan's cells cut; no map worse) and
//!    the mean turns from 1242 to 1239, for about 14 % more CPU time of the bench.
//!    **Turned lattice** (not in the paper): when the walls run at an angle to the pixel axes
//!    (the C-free boundary's projections are most concentrated at an angle more than 4
//!    degrees off them; then that angle and, when also off the axes, the best other one at
//!    least 10 degrees away),
//!    the whole plan is made again with the sweep lines on a lattice of points one pixel apart
//!    turned by that angle (a point is free where its pixel is reachable C-free and the
//!    robot's disk there touches nothing) and by angles half a degree, one degree, ... beside
//!    it (`angle_tries` lattices per angle: a plan's cost reacts strongly to where the lattice
//!    lines fall), and the plan that sweeps `min_coverage` of the floor (estimated; a plan
//!    below it loses to one that reaches it, whatever their costs; of two plans below it, the
//!    one that misses less by steps of `1 - rim_coverage` of the floor wins: this is the rule
//!    for every choice between plans below), then skips fewer moves, then costs less (length
//!    plus `turn_cost_m` per turn), is kept. Maps drawn along the axes get the
//!    pixel lattice's plan unchanged.
//! 2. **Lanes fitted to each cell** (the paper's boustrophedon motions). Per cell, lanes run
//!    along the sweep line or, when the cell is monotone the other way too, across it — the
//!    direction with the lower estimated cost (fewer, longer lanes: fewer turns). A cell
//!    elongated along its lines that is not monotone across only because of its ends (the
//!    rounded C-free corners beside an obstacle) is first cut into its two ends (at most
//!    `2 sp` lines each) and a middle that can take lanes across, so a corridor cell gets a few
//!    long lanes instead of many short ones (not in the paper, whose cells keep one
//!    direction). A cell whose runs change length abruptly from one line to the next (more
//!    than `sp / 2`, as where a corridor leaves a room inside one cell) is cut there when the
//!    two parts, each with its own cheaper direction, are estimated cheaper than the whole
//!    (the room's lanes along the room, the corridor's along the corridor, instead of one
//!    direction for both). **Jagged walls** (not in the paper): along a scanned wall whose
//!    bumps, a pixel or two deep, meet the cell's lines one after the other, no line across
//!    meets the cell in one run, so its lanes must run along the lines: short lanes, each
//!    ending at a bump. The view across may then leave out the band of the bumps, up to
//!    `2 sp` deep (`Cell::transposed_trim`): the edge lane beside the band sweeps most of it
//!    and the rim passes (step 3) the rest. The estimate does not price the band, so these
//!    views are not in every plan: the best plan's kind is made again with them, at the
//!    user's turn cost and at half of it (step 6), and kept where it is cheaper. On the 14
//!    shared maps (r = 0.15 m) the mean turns go from 1203 to 1162 and the mean path ratio
//!    from 1.1350 to 1.1354 (`tuw_freihaus_eg` 1314 to 773 turns at path ratio 1.009 to
//!    1.014, `nav2_depot` 604 to 571, `aws_small_house` 480 to 474, no map dearer on the
//!    user's cost), for about 1.27 times the CPU time of the bcd bench. Lanes are evenly spaced at most `2 r_tool` apart (`lane_spacing_m`). The
//!    first and last lanes lie on the cell's edge where the edge is an obstacle (the lane at clearance sweeps the wall's
//!    rim) and `r_tool` inside it where the edge is shared with neighbouring cells (whose own
//!    lanes sweep up to the shared edge), so neighbours do not drive two lanes side by side.
//!    Lanes between shared edges lie on one lattice of lines `sp` apart (so they continue
//!    across neighbours); a cell closed on both sides spreads as few lanes as keep the gaps
//!    within `sp` evenly between its edges instead (a lattice line just inside an edge would
//!    cost a whole extra lane: `|.|.....|.....|.|` becomes `|....|....|....|`). A cell whose
//!    pixels the lanes of other cells already sweep gets no lanes of its own (the slivers
//!    that critical points leave beside a cell, a few lines wide, smallest first):
//!
//!    ```text
//!    ####################      | = the wide cell's lanes; its last lane (column 19)
//!    |.....|.....|......|ss##  sweeps r_tool = 3 lines beyond it, so the sliver `ss`
//!    |.....|.....|......|ss##  (columns 20-21, cut off by a critical point of the
//!    |.....|.....|......|......  obstacle `##`) needs no lane and no transfer
//!    ```
//!    Lane ends facing an obstacle are pushed from the pixel centre to the exact contact
//!    distance (minus a 0.05 px safety gap) with the simulator's own swept-disk test, so the
//!    tool reaches as close to the wall as the robot can.
//! 3. **Rim.** Consecutive lanes are joined along the cell's boundary (the lane ends of every
//!    pixel line in between, merged into straight collision-free segments that stay within
//!    half a pixel of it), so the joins sweep the wall rim between lanes. What no lane or join
//!    reaches — the rim at the unjoined lane ends, notches, the faces of the obstacles at split
//!    and merge events — is found by sweeping the planned path over the map's accessible
//!    surface; the missed pixels are grouped, each group is swept by a contour pass through the
//!    nearest C-free positions (merged into straight collision-free segments) inserted as a
//!    detour at the cheapest point of the path. Groups whose detour would sweep less than
//!    `rim_min_yield` of a lane's sweep rate are skipped, and so are the lowest-yield groups
//!    (pixels swept per pixel of pass) while what is left stays within `1 - rim_coverage` of the
//!    accessible floor (default 0.999: the sawtooth of lane ends along a wall costs a whole
//!    wall-long pass for well under a percent of the floor). This step is not in the paper (a
//!    point robot's lanes reach the boundary; a disk's do not). The passes are placed two ways
//!    and the plan that is cheaper (length plus `turn_cost_m` per turn) is kept: as pieces of
//!    the cell tour (step 4; chained passes along one wall), or inserted into the finished
//!    tour as out-and-back detours at its nearest point, followed by a second mop-up of what
//!    the detours and the smoothing left (a pass that runs past a lane end often costs less
//!    as a detour from that lane than as a stop of the tour):
//!
//!    ```text
//!    |    |    |      rim pass ppp along the wall where the lanes | end:
//!    |    |    |      in the tour:  ... cell A, hop, ppp, hop, cell B ...
//!    |____|    |ppp   inserted:     ... down the lane, out along ppp and back, ...
//!    ###############
//!    ```
//!
//!    **Headland** (not in the paper; the headland of field coverage planners, applied to
//!    walls; option `headland_min_m`, default 6 m). The plan is made a second time with a
//!    contour pass along the C-free boundary of every obstacle whose boundary is at least
//!    `headland_min_m` long (the robot's centre on the C-free boundary sweeps the band up to
//!    `2 r_tool` from it, with the cusps between lane ends, notches and parallel-wall rims
//!    in one pass), and with the cells decomposed and laned only on the interior: the
//!    C-free positions at least `2 r_tool` inside the passes (exact distance transform), so
//!    the interior's edge lanes sweep up to the band. Each pass is a piece of the tour, a
//!    closed loop enterable at up to 16 points along it; whatever is left is swept by
//!    inserted detours. The cheaper of the two plans is kept. Per metre of wall the pass
//!    costs about what the lanes save by ending `2 r_tool` earlier, so it pays only where
//!    the rim work it replaces is large (narrow corridors, plain rooms):
//!
//!    ```text
//!    ################     h = the headland pass at clearance around the room
//!    #hhhhhhhhhhhhhh#     |, + = interior lanes and their joins, their ends
//!    #h  +--+  +--+h#            2 r_tool inside the pass
//!    #h  |  |  |  |h#
//!    #h  |  +--+  |h#
//!    #hhhhhhhhhhhhhh#
//!    ################
//!    ```
//!
//!    **Peeled plan** (not in the paper; the contour-parallel pattern of coverage planning,
//!    as the spirals of BSA, Gonzalez et al., ICRA 2005, laid on the known map). With the
//!    headland on, a third plan on the pixel lattice has no lanes at all: besides the
//!    headland passes, offset loops run through the free points at `1 + k * 2 r_tool`
//!    lattice steps from the outer walls (the obstacles that reach the map's border, exact
//!    distance transform), `k = 1, 2, ...`, until the floor is used up; what they leave is
//!    swept by inserted detours and the turn pruning may drop a loop whose floor the loops
//!    beside it already sweep. On a ring (`nobleo_grid`: 2.5 m wide around a 10 m block)
//!    lanes along it need 9 passes 0.275 m apart and lanes across it two turns per 0.3 m;
//!    loops laid from the outer wall in put the overlap the width leaves on the innermost,
//!    shortest loop, with 4 turns per loop (path ratio 1.102 to 0.973, 70 to 41 turns;
//!    1.072 with every loop kept). The plan is made only while the loops are at most 32 walks
//!    (a floor that falls apart into more offset pieces is left to the lanes) and kept where
//!    it is cheaper, like the other plans:
//!
//!    ```text
//!    +----------------+     o = offset loops 2 r_tool apart from the outer wall in,
//!    | oooooooooooooo |     b = the block's headland pass
//!    | o oooooooooo o |
//!    | o o bbbbbb o o |
//!    | o o b####b o o |
//!    | o o bbbbbb o o |
//!    | o oooooooooo o |
//!    | oooooooooooooo |
//!    +----------------+
//!    ```
//! 4. **Cell tour.** Instead of the paper's depth-first walk of the adjacency graph, the cells
//!    are ordered as an open travelling-salesman path over their entry and exit points (each
//!    cell can be started at any of its four corners): nearest-neighbour construction, then
//!    2-opt, Or-opt and an exact choice of every cell's corner for the order (module `bcd::tsp`;
//!    a move whose new hops cost too much already in a straight line is not costed on the hop
//!    table, which leaves every tour the same: `stage_willow_full` 6.9 s to 4.6 s of CPU).
//!    An Or-opt move of a single cell also tries the cell's other corners at its new place
//!    (not only the same path driven backwards): on the 14 shared maps (r = 0.15 m) the mean
//!    path ratio goes from 1.1671 to 1.1656 and the mean turns from 1244 to 1242, in the same
//!    planning time (`stage_willow_full` 1.336 to 1.320, `tuw_single_corridors` 1.107 to
//!    1.080; `aws_small_warehouse_002` 1.222 to 1.244 and `aws_small_house` 1.211 to 1.220
//!    are worse: a lower tour estimate is not always a shorter plan after the rim passes).
//!    **Lane parity** (not in the paper): a cell with an even number of lanes leaves on the
//!    side it entered, so reaching the next cell may cost a transfer back along the whole
//!    cell. The tour is therefore also made (through steps 3-5) over the same cells with every
//!    such cell cut into two runs of an odd number of lanes each, which the tour may drive at
//!    different times (or one after the other, which rebuilds the cell); the cheaper plan
//!    (length plus `turn_cost_m` per turn) is kept. On `tuw_single_corridors` (r = 0.15 m)
//!    this takes the path ratio from 1.330 to 1.297. It costs a second tour: the plans
//!    (lattices, sweeps, headland; step 1) are made in parallel with their cells whole, and
//!    the cut cells are toured on the best of them only (the lattice or the sweep moves a
//!    plan's cost more than the cut; on `rmf_office_scan` this saves two of six tours).
//!    Parallel plans are compared in a fixed order, so the choice is the same as one after
//!    the other. Hop
//!    costs come from a coarse grid of the C-free set, one bounded Dijkstra per end-point node
//!    computed once per tour (module `bcd::hops`), not a search per pair. The grid's blocks
//!    are split into their connected C-free parts, so a wall or a squeeze inside a block is
//!    gone round: on the 14 shared maps this took the mean path ratio from 1.1470 to 1.1350
//!    and the mean turns from 1249 to 1203, and on the bench map `cluttered_2000` (where a
//!    block-level grid costed some hops of a few pixels that are thousands when routed) the
//!    planning time from 20.6 s to 9.4 s (paired runs). **Hop correction**
//!    (not in the paper): a path over blocks is still only an estimate of one over pixels,
//!    so some hops of the tour are longer when routed. The tour's hops are therefore routed on the true map, every hop whose route
//!    is longer than its cost in the tour takes the route's length as its cost, and the tour is
//!    improved once more; twice, and the tour with the lowest routed cost is kept. This is done
//!    for the tour of the cells (and headland passes); the tour with the rim passes among its
//!    pieces keeps its estimates (corrected, it wins on cost with fewer turns but a longer
//!    path: `rmf_office_scan` 1.52 to 1.57). On the 14 shared maps (r = 0.15 m) the mean path
//!    ratio goes from 1.1833 to 1.1788 and the mean turns from 1250 to 1245, for about 15 %
//!    more planning time. Transfers are
//!    straight when collision-free, else A* over the C-free pixel centres (8-connected, octile costs, no corner cutting), shortened
//!    by line-of-sight checks on the true map.
//!
//! 5. **Turn pruning** (not in the paper; module `bcd::prune`). The finished plan's turns are cut where
//!    that costs least floor: a run of up to four vertices is replaced by the straight move
//!    across it when that move is free on the true map (a corner, a short detour into a sliver
//!    cell and back, the wiggles of a transfer through clutter), fewest accessible pixels lost
//!    per unit of cost saved first (the path saved plus three times `turn_cost_m` per turn
//!    saved; on the 14 shared maps this lowers the path ratio of every map against ranking by
//!    turns alone), while the floor the plan sweeps (estimated with the metric's own
//!    capsule test, so the estimate is the measured `effective_coverage`) stays at least
//!    `min_coverage` of the accessible floor (default 0.9952). Then two to four turns in a
//!    row become one where the moves before and after them meet, extended beyond the turns
//!    (for at most `turn_cost_m` of extra path per turn saved) or cut short before them (a
//!    bump cut off), and the runs are pruned once more:
//!
//!    ```text
//!    u ----- v1                u ---------- x
//!              \        ->                 |
//!               v2                         |
//!               |  w                       w
//!    ```
//!
//!    A U-turn between two lanes whose join bends round a speck or a bump of the wall (three
//!    or four turns where no straight move across them is free) competes with the spans in
//!    the same ranking as two turns: both lanes cut short or extended to the depth of one of
//!    the bend's vertices and joined by one straight move. On the 14 shared maps (r = 0.15 m)
//!    the mean turns go from 1123.5 to 1114.6 and the mean path ratio from 1.1344 to 1.1349
//!    (`tuw_freihaus_eg` 767 to 732 turns, `mit_building_31` 3155 to 3129, `teb_empty_box`
//!    51 to 39 at path ratio 0.990 to 1.022; `aws_bookstore`, `aws_small_house` and
//!    `rmf_office_scan` 2-3 turns more), for about 18 % more CPU time of the bcd bench:
//!
//!    ```text
//!    u ---------- v1             u --------------- x
//!                   \    #  ->                    |
//!                    v2  #                        |
//!                   /    #                        |
//!    w ---------- v3             w --------------- y
//!    ```
//!
//! 6. **Lower turn costs as a second opinion** (not in the paper). The choices of steps 1-5
//!    rest on estimates priced with `turn_cost_m` (a cell's lane direction, the sweep, which
//!    turns pruning cuts first), and an estimate that prices turns lower sometimes leads to a
//!    plan that is cheaper on the user's own cost too (length plus `turn_cost_m` per turn).
//!    So the best plan's kind (lattice, sweep, headland or peeled) is made again with half
//!    and with none of `turn_cost_m` in its choices, each plan still judged by the user's
//!    cost, and the cut-cell tour of step 4 is made on the best plan of the user's turn cost
//!    and on the overall best when that differs: no plan is dearer than without this step.
//!    On the 14 shared maps (r = 0.15 m) the mean path ratio goes from 1.1578 to 1.1470 and
//!    the mean turns from 1239 to 1249, no map dearer on the user's cost
//!    (`tuw_single_corridors` 1.080 to 0.961 with 189 turns instead of 109, `aws_bookstore`
//!    1.335 to 1.305 with 774 instead of 738), for about 1.5 times the planning time.
//!
//! Deterministic: fixed scan orders and tie-breaks, no hashing. The plan is made in grid
//! coordinates (pixels): the contact and free-move tests against the map take grid points
//! ([`World::first_contact_grid`], [`World::segment_free_grid`]) and ranking keys are integers,
//! so a map moved far from the world's origin (where world coordinates carry rounding) gets
//! the same plan. Regions = cells (`RegionStart`
//! per cell); transfers between cells (and to and between rim passes) that move the robot are
//! marked as backtracks.
//!
//! ```
//! use ccpp_core::{GridMap, Pose};
//! use ccpp_core::world::{Robot, World};
//! use ccpp_core::planners::bcd::{Bcd, BcdOptions};
//! use ccpp_core::sim::{simulate, SimConfig};
//! let art = "##########\n#........#\n#..##....#\n#..##....#\n#........#\n##########";
//! let map = GridMap::from_ascii_scaled(art, 10, 0.02).unwrap();
//! let world = World::new(map, Robot::new(0.08), Some(Pose::new(0.3, 0.3, 0.0))).unwrap();
//! let mut p = Bcd::new(&world, &BcdOptions::default());
//! let out = simulate(&world, &mut p, &SimConfig::default());
//! let m = ccpp_core::metrics::compute(&world, &out, "box");
//! assert_eq!(m.collisions, 0);
//! assert!(m.effective_coverage > 0.995, "{}", m.effective_coverage);
//! assert!(m.regions >= 1); // one region per cell
//! ```

mod angles;
mod cells;
mod finish;
mod headland;
mod hops;
mod lanes;
mod lattice;
mod plan;
mod prune;
mod rim;
#[cfg(test)]
mod tests;
mod transfer;
mod tsp;

use std::sync::atomic::AtomicBool;

use serde::{Deserialize, Serialize};

use crate::planner::{Planner, Sensor, Step};
use crate::planners::replay::Replay;
use crate::world::World;

/// Options of [`Bcd`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BcdOptions {
    /// Largest lane spacing in metres (lanes are spread evenly, at most this far apart);
    /// `None` = `2 r_tool`. Must be at least the map's resolution and at most `2 r_tool`
    /// (wider lanes leave strips unswept; the planner settings' `check` refuses them against
    /// the robot). Below `2 r_tool` the lanes overlap: the plan then counts swept floor with
    /// half the spacing as the tool's radius, so no lane is dropped as already swept.
    pub lane_spacing_m: Option<f64>,
    /// Extra clearance (pixels, >= 0) that transfer paths keep from obstacles when they can,
    /// apart from the stretches next to their ends (a lane end may sit at plain clearance);
    /// where no such path exists they fall back to the plain C-free set, and the plan says
    /// how many of its transfers did (a [`MARGIN_NOTE`], a warning of `ccpp run` and `plan`).
    pub margin_px: f64,
    /// Cost of one turn, in metres of path, when choosing sweep directions (from 0 to
    /// [`MAX_TURN_COST_M`]).
    pub turn_cost_m: f64,
    /// Sweep the rim that lanes miss (step 3 of the module docs).
    pub rim: bool,
    /// Skip a rim detour whose swept new area per metre is below this fraction of a lane's
    /// (`2 r_tool` per metre); 0 sweeps every reachable missed group. In `[0, 1]`.
    pub rim_min_yield: f64,
    /// Rim passes stop at this share of the accessible floor: the lowest-yield missed groups
    /// are left out while the pixels they hold (with whatever no pass can reach) stay within
    /// `1 - rim_coverage` of it, as estimated on the plan. 1 sweeps every group. In `[0, 1]`.
    pub rim_coverage: f64,
    /// Improvement rounds of the cell tour (0 = nearest-neighbour order only); the rounds stop
    /// early once one changes nothing. At most [`MAX_TOUR_ROUNDS`].
    pub tour_rounds: u32,
    /// Turn pruning of the finished plan (step 5 of the module docs) drops turns while the
    /// plan's estimated effective coverage stays at least this; 1 drops only turns whose
    /// removal loses no floor. In `[0, 1]`.
    ///
    /// The last percent of the floor is the dearest in turns: on the 14 shared maps
    /// (r = 0.15 m, `ccpp bench --planners bcd --config` with `bcd: { min_coverage: .. }`)
    ///
    /// | `min_coverage` | mean effective coverage | mean path ratio | mean turns |
    /// |---|---:|---:|---:|
    /// | 0.97 | 0.9720 | 1.047 | 762 |
    /// | 0.98 | 0.9818 | 1.070 | 849 |
    /// | 0.99 | 0.9906 | 1.104 | 992 |
    /// | 0.9952 (default) | 0.9960 | 1.135 | 1115 |
    pub min_coverage: f64,
    /// Turned lattices tried per off-axis wall angle (step 1 of the module docs): at the
    /// angle, then half a degree above and below it, one degree, ...; the cheapest plan of
    /// all is kept (a plan's cost reacts strongly to where the lattice's lines fall). 0 plans
    /// on the pixel lattice only; 1 (the default) on the lattice turned to the wall angle. More
    /// tries cost one whole plan each. On `rmf_office_scan` at r = 0.15 m the plans of 1, 2, 3
    /// and 9 tries are now the same (1165 turns, path ratio 1.440; 9 tries take about 3 times
    /// the time); at r = 0.2 m 3 tries find a cheaper plan (path ratio 1.438 and 931 turns
    /// instead of 1.535 and 878) in 1.4 s instead of 0.9 s. Maps drawn along the axes have no
    /// off-axis angle, and the value changes nothing there.
    pub angle_tries: u32,
    /// Headland (step 3 of the module docs): `Some(m)` also plans with contour passes along
    /// the C-free boundary of every obstacle whose boundary is at least `m` metres long and
    /// lanes only in the interior at least `2 r_tool` inside those passes, and keeps that
    /// plan where it is cheaper (length plus `turn_cost_m` per turn). `None` (`null` in an
    /// options file): no headland. Must be finite and >= 0. Default
    /// `Some(`[`DEFAULT_HEADLAND_MIN_M`]`)`: on the 14 shared maps (r = 0.15 m, measured on
    /// the current code) the mean path ratio is 1.1349 with it and 1.1730 with `None`
    /// (`tuw_single_corridors` 0.957 instead of 1.295, `teb_empty_box` 1.022 instead of
    /// 1.040), for about 1.25 times the planning time of the 14-map bench (the headland plan
    /// is made beside the plain one; up to twice as long on the largest maps). It also enables
    /// the peeled plan (offset loops from the outer walls in, module docs step 3), which takes
    /// `nobleo_grid` from 1.102 to 0.973. (When the headland came, against the code of its
    /// day, it took the mean from 1.1985 to 1.1833 and the peeled plan on to 1.1716.)
    pub headland_min_m: Option<f64>,
    /// Most plans made at the same time: planning runs on a pool of this many threads of its
    /// own. `None` (`null`): on the process's pool, one plan per thread (`RAYON_NUM_THREADS`,
    /// else one per core). Every plan holds state the size of the map (the memory estimate
    /// counts 32 bytes a pixel a plan, for up to 4), so fewer at a time bound the memory at
    /// the cost of time; the plan kept is the same whatever the count (the plans are
    /// independent and compared in a fixed order). From 1 to [`MAX_PLANS_AT_A_TIME`].
    pub plans_at_a_time: Option<u32>,
    /// React to bumper contacts while replaying the plan (module [`crate::planners::replay`]:
    /// mark the obstacle, route round it, give a waypoint up after
    /// [`MAX_TRIES`](crate::planners::replay::MAX_TRIES) contacts). `false` replays the plan
    /// as planned, as a robot without a costmap would, to compare: under odometry noise it
    /// often ends pinned against an obstacle, and the simulator stops the run as stalled.
    /// Only a run with odometry noise meets obstacles, so `false` is refused without it.
    pub bumper_reaction: bool,
}

/// Default of [`BcdOptions::headland_min_m`], metres: walls and obstacles whose C-free
/// boundary is at least this long get a headland pass in the second plan.
pub const DEFAULT_HEADLAND_MIN_M: f64 = 6.0;

/// The start of the [`Event::Note`](crate::trace::Event::Note) written when transfers of the
/// plan come closer to obstacles than [`BcdOptions::margin_px`] asks (no way keeps that
/// clearance, or the smoothing and pruning cut it): the command line and Python say it as a
/// warning, with how many of the plan's transfers it concerns. A margin that could not be
/// kept anywhere (wider than every corridor) used to be dropped without a word.
pub const MARGIN_NOTE: &str = "bcd: margin_px";

/// Most turned lattices [`BcdOptions::angle_tries`] may ask for per wall angle: half-degree
/// steps up to 10 degrees either side, where the second wall direction may begin. Each try is
/// a whole plan, so the bound also bounds the planning time.
pub const MAX_ANGLE_TRIES: u32 = 40;

/// Most threads [`BcdOptions::plans_at_a_time`] may ask for (a count beyond the plans of a
/// round only adds idle threads).
pub const MAX_PLANS_AT_A_TIME: u32 = 64;

/// Largest [`BcdOptions::turn_cost_m`], metres: far beyond any turn's worth (every choice is
/// by turns alone long before it), and a bound that keeps the plan's costs finite (1e308 m
/// became an infinite cost per pixel, every comparison tied, and the plan came out as if
/// turns cost nothing: 249 turns on `teb_maze` against 125 at 1e300; hostile pass, stop 69).
pub const MAX_TURN_COST_M: f64 = 1e6;

/// Most improvement rounds [`BcdOptions::tour_rounds`] may ask for. Each round costs a pass of
/// 2-opt and Or-opt moves over every cell of the tour; on the shared maps the tour settles
/// within 2-6 rounds, so the bound only keeps a mistyped count from planning for hours.
pub const MAX_TOUR_ROUNDS: u32 = 100;

impl Default for BcdOptions {
    fn default() -> Self {
        Self {
            lane_spacing_m: None,
            margin_px: 0.0,
            turn_cost_m: 0.3,
            rim: true,
            rim_min_yield: 0.0,
            rim_coverage: 0.999,
            tour_rounds: 3,
            min_coverage: 0.9952,
            angle_tries: 1,
            headland_min_m: Some(DEFAULT_HEADLAND_MIN_M),
            plans_at_a_time: None,
            bumper_reaction: true,
        }
    }
}

/// An invalid [`BcdOptions`] value.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum BcdOptionsError {
    /// A value outside its range.
    #[error("bcd option {name} must be {what}, got {value}")]
    OutOfRange {
        /// Option name.
        name: &'static str,
        /// The allowed range.
        what: &'static str,
        /// The value given.
        value: f64,
    },
}

impl BcdOptions {
    /// Checks every value's range.
    ///
    /// # Errors
    /// The first value outside its range.
    pub fn check_ranges(&self) -> Result<(), BcdOptionsError> {
        let bad = |name, what, value| Err(BcdOptionsError::OutOfRange { name, what, value });
        if let Some(s) = self.lane_spacing_m {
            if !(s.is_finite() && s > 0.0) {
                return bad("lane_spacing_m", "a finite number > 0", s);
            }
        }
        if let Some(m) = self.headland_min_m {
            if !(m.is_finite() && m >= 0.0) {
                return bad("headland_min_m", "a finite number >= 0", m);
            }
        }
        if !(self.margin_px.is_finite() && self.margin_px >= 0.0) {
            return bad("margin_px", "a finite number >= 0", self.margin_px);
        }
        if !(0.0..=MAX_TURN_COST_M).contains(&self.turn_cost_m) {
            return bad(
                "turn_cost_m",
                "from 0 to 1000000 (metres of path per turn)",
                self.turn_cost_m,
            );
        }
        if !(0.0..=1.0).contains(&self.rim_min_yield) {
            return bad("rim_min_yield", "in [0, 1]", self.rim_min_yield);
        }
        if !(0.0..=1.0).contains(&self.rim_coverage) {
            return bad("rim_coverage", "in [0, 1]", self.rim_coverage);
        }
        if !(0.0..=1.0).contains(&self.min_coverage) {
            return bad("min_coverage", "in [0, 1]", self.min_coverage);
        }
        if self.tour_rounds > MAX_TOUR_ROUNDS {
            return bad("tour_rounds", "at most 100", f64::from(self.tour_rounds));
        }
        if let Some(n) = self.plans_at_a_time {
            if !(1..=MAX_PLANS_AT_A_TIME).contains(&n) {
                return bad("plans_at_a_time", "from 1 to 64", f64::from(n));
            }
        }
        if self.angle_tries > MAX_ANGLE_TRIES {
            return bad(
                "angle_tries",
                "at most 40 (up to 10 degrees either side of a wall angle)",
                f64::from(self.angle_tries),
            );
        }
        Ok(())
    }
}

/// Whether lanes `spacing` metres apart leave no strip between them unswept (at most the
/// tool's width, with a relative tolerance for values computed as `2 r_tool`).
fn fits_tool(world: &World, spacing: f64) -> bool {
    spacing <= 2.0 * world.robot().tool_radius * (1.0 + 1e-9)
}

/// Runs `f` on a rayon pool of `threads` threads of its own when given, else on the caller's.
fn on_pool<T: Send>(threads: Option<u32>, f: impl FnOnce() -> T + Send) -> T {
    let Some(n) = threads else {
        return f();
    };
    match rayon::ThreadPoolBuilder::new()
        .num_threads(n as usize)
        .thread_name(|i| format!("bcd-plan-{i}"))
        .build()
    {
        Ok(pool) => pool.install(f),
        // No thread could be started (the system's limit): the same plan on the caller's pool,
        // which already runs; only the bound on plans at a time is not kept.
        Err(_) => f(),
    }
}

/// The BCD planner: a precomputed list of steps.
pub struct Bcd {
    replay: Replay,
    cells: usize,
}

impl Bcd {
    /// Plans the whole coverage of `world` (offline). Invalid options (see
    /// [`BcdOptions::check_ranges`]) are replaced by their defaults; use [`Bcd::try_new`] to refuse
    /// them instead.
    pub fn new(world: &World, opts: &BcdOptions) -> Self {
        Self::new_stoppable(world, opts, None)
    }

    /// [`Bcd::new`] that another thread can give up by setting `stop`: the planning then ends
    /// soon and the planner has no steps. Every plan looks before it starts and between its
    /// steps (tour, hop corrections, rim passes, repair, turn pruning), and the long loops
    /// inside them (the hop table's searches, every 16 rows; the tour's improvement passes,
    /// every 64 positions; the rim groups; the pruning's passes, every 256 vertices) look as
    /// they go. Python's Ctrl-C gives a run up this way, so the next run does not wait for a
    /// plan nobody will drive: on the bench map `office_4096` at r = 0.15 m (a 99 s plan)
    /// the planning returned within 0.62 s of the stop at 30, 50, 70, 80, 85 and 90 s into
    /// it (the example `stop_latency` measures it).
    pub fn new_until(world: &World, opts: &BcdOptions, stop: &AtomicBool) -> Self {
        Self::new_stoppable(world, opts, Some(stop))
    }

    fn new_stoppable(world: &World, opts: &BcdOptions, stop: Option<&AtomicBool>) -> Self {
        if Self::check(world, opts).is_ok() {
            Self::plan_on_pool(world, opts, stop)
        } else {
            let d = BcdOptions::default();
            let fixed = BcdOptions {
                lane_spacing_m: opts.lane_spacing_m.filter(|&s| {
                    s.is_finite()
                        && s >= world.frame().resolution * (1.0 - 1e-9)
                        && fits_tool(world, s)
                }),
                margin_px: if opts.margin_px.is_finite() && opts.margin_px >= 0.0 {
                    opts.margin_px
                } else {
                    d.margin_px
                },
                turn_cost_m: if (0.0..=MAX_TURN_COST_M).contains(&opts.turn_cost_m) {
                    opts.turn_cost_m
                } else {
                    d.turn_cost_m
                },
                rim: opts.rim,
                rim_min_yield: if (0.0..=1.0).contains(&opts.rim_min_yield) {
                    opts.rim_min_yield
                } else {
                    d.rim_min_yield
                },
                rim_coverage: if (0.0..=1.0).contains(&opts.rim_coverage) {
                    opts.rim_coverage
                } else {
                    d.rim_coverage
                },
                tour_rounds: opts.tour_rounds.min(MAX_TOUR_ROUNDS),
                angle_tries: if opts.angle_tries <= MAX_ANGLE_TRIES {
                    opts.angle_tries
                } else {
                    d.angle_tries
                },
                headland_min_m: opts.headland_min_m.filter(|m| m.is_finite() && *m >= 0.0),
                plans_at_a_time: opts
                    .plans_at_a_time
                    .filter(|n| (1..=MAX_PLANS_AT_A_TIME).contains(n)),
                min_coverage: if (0.0..=1.0).contains(&opts.min_coverage) {
                    opts.min_coverage
                } else {
                    d.min_coverage
                },
                bumper_reaction: opts.bumper_reaction,
            };
            Self::plan_on_pool(world, &fixed, stop)
        }
    }

    /// Plans on a pool of [`BcdOptions::plans_at_a_time`] threads when it is given, else on
    /// the caller's pool.
    fn plan_on_pool(world: &World, opts: &BcdOptions, stop: Option<&AtomicBool>) -> Self {
        on_pool(opts.plans_at_a_time, || Self::plan(world, opts, stop))
    }

    /// Plans the whole coverage of `world` (offline).
    ///
    /// # Errors
    /// An option out of range.
    pub fn try_new(world: &World, opts: &BcdOptions) -> Result<Self, BcdOptionsError> {
        Self::check(world, opts)?;
        Ok(Self::plan_on_pool(world, opts, None))
    }

    /// The options' ranges, and the lane spacing against `world`'s tool.
    fn check(world: &World, opts: &BcdOptions) -> Result<(), BcdOptionsError> {
        opts.check_ranges()?;
        if let Some(s) = opts.lane_spacing_m.filter(|&s| !fits_tool(world, s)) {
            return Err(BcdOptionsError::OutOfRange {
                name: "lane_spacing_m",
                what: "at most 2 r_tool (wider lanes leave strips unswept)",
                value: s,
            });
        }
        if let Some(s) = opts
            .lane_spacing_m
            .filter(|&s| s < world.frame().resolution * (1.0 - 1e-9))
        {
            return Err(BcdOptionsError::OutOfRange {
                name: "lane_spacing_m",
                what: "at least the map's resolution (lanes lie on its pixel lines)",
                value: s,
            });
        }
        Ok(())
    }

    /// Number of cells of the decomposition used.
    pub fn cells(&self) -> usize {
        self.cells
    }
}

impl Planner for Bcd {
    fn name(&self) -> &'static str {
        "bcd"
    }
    fn is_offline(&self) -> bool {
        true
    }
    fn next(&mut self, sensor: &dyn Sensor) -> Step {
        self.replay.next(sensor)
    }
}
