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
//!    **Turned lattice** (not in the paper): when the walls run at an angle to the pixel axes
//!    (the C-free boundary's projections are most concentrated at an angle more than 4
//!    degrees off them; then that angle and, when also off the axes, the best other one at
//!    least 10 degrees away),
//!    the whole plan is made again with the sweep lines on a lattice of points one pixel apart
//!    turned by that angle (a point is free where its pixel is reachable C-free and the
//!    robot's disk there touches nothing) and by angles half a degree, one degree, ... beside
//!    it (`angle_tries` lattices per angle: a plan's cost reacts strongly to where the lattice
//!    lines fall), and the plan that skips fewer moves, then costs less (length plus
//!    `turn_cost_m` per turn), is kept. Maps drawn along the axes get the
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
//!    direction for both). Lanes are evenly spaced at most `2 r_tool` apart (`lane_spacing_m`). The
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
//! 4. **Cell tour.** Instead of the paper's depth-first walk of the adjacency graph, the cells
//!    are ordered as an open travelling-salesman path over their entry and exit points (each
//!    cell can be started at any of its four corners): nearest-neighbour construction, then
//!    2-opt, Or-opt and an exact choice of every cell's corner for the order (module `bcd::tsp`). Hop
//!    costs come from a coarse grid of the C-free set, one bounded Dijkstra per end-point block
//!    computed once per tour (module `bcd::hops`), not a search per pair. Transfers are
//!    straight when collision-free, else A* over the C-free pixel centres (8-connected, octile costs, no corner cutting), shortened
//!    by line-of-sight checks on the true map.
//!
//! 5. **Turn pruning** (not in the paper; module `bcd::prune`). The finished plan's turns are cut where
//!    that costs least floor: a run of up to four vertices is replaced by the straight move
//!    across it when that move is free on the true map (a corner, a short detour into a sliver
//!    cell and back, the wiggles of a transfer through clutter), fewest accessible pixels lost
//!    per turn saved first, while the floor the plan sweeps (estimated with the metric's own
//!    capsule test, so the estimate is the measured `effective_coverage`) stays at least
//!    `min_coverage` of the accessible floor (default 0.9952). Then two turns in a row become
//!    one where the moves before and after them, extended, meet (for at most `turn_cost_m` of
//!    extra path), and the runs are pruned once more:
//!
//!    ```text
//!    u ----- v1                u ---------- x
//!              \        ->                 |
//!               v2                         |
//!               |  w                       w
//!    ```
//!
//! Deterministic: fixed scan orders and tie-breaks, no hashing. Regions = cells (`RegionStart`
//! per cell); transfers between cells are marked as backtracks.
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

mod hops;
mod prune;
mod tsp;

use std::borrow::Cow;
use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};
use std::ops::{Add, Sub};

use fixedbitset::FixedBitSet;
use serde::{Deserialize, Serialize};

use crate::geometry::{path_length, point_segment_dist2, Point};
use crate::grid::MapFrame;
use crate::planner::{Planner, Sensor, Step};
use crate::trace::Event;
use crate::world::World;

/// Options of [`Bcd`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BcdOptions {
    /// Largest lane spacing in metres (lanes are spread evenly, at most this far apart);
    /// `None` = `2 r_tool`. Must be > 0.
    pub lane_spacing_m: Option<f64>,
    /// Extra clearance (pixels, >= 0) that transfer paths keep from obstacles when they can;
    /// where no such path exists they fall back to the plain C-free set.
    pub margin_px: f64,
    /// Cost of one turn, in metres of path, when choosing sweep directions (>= 0).
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
    /// Improvement rounds of the cell tour (0 = nearest-neighbour order only).
    pub tour_rounds: u32,
    /// Turn pruning of the finished plan (step 5 of the module docs) drops turns while the
    /// plan's estimated effective coverage stays at least this; 1 drops only turns whose
    /// removal loses no floor. In `[0, 1]`.
    pub min_coverage: f64,
    /// Turned lattices tried per off-axis wall angle (step 1 of the module docs): at the
    /// angle, then half a degree above and below it, one degree, ...; the cheapest plan of
    /// all is kept (a plan's cost reacts strongly to where the lattice's lines fall). 0 plans
    /// on the pixel lattice only; 1 (the default) on the lattice turned to the wall angle. More
    /// tries cost one whole plan each: on `rmf_office_scan` (r = 0.15 m) 3 finds a plan of lower
    /// cost (1263 turns instead of 1390, path ratio 1.549 instead of 1.525) in about 2.4 times
    /// the planning time.
    pub angle_tries: u32,
}

impl Default for BcdOptions {
    fn default() -> Self {
        Self {
            lane_spacing_m: None,
            margin_px: 0.0,
            turn_cost_m: 0.3,
            rim: true,
            rim_min_yield: 0.0,
            rim_coverage: 0.999,
            tour_rounds: 2,
            min_coverage: 0.9952,
            angle_tries: 1,
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
        if !(self.margin_px.is_finite() && self.margin_px >= 0.0) {
            return bad("margin_px", "a finite number >= 0", self.margin_px);
        }
        if !(self.turn_cost_m.is_finite() && self.turn_cost_m >= 0.0) {
            return bad("turn_cost_m", "a finite number >= 0", self.turn_cost_m);
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
        Ok(())
    }
}

/// The BCD planner: a precomputed list of steps.
pub struct Bcd {
    steps: VecDeque<Step>,
    cells: usize,
}

/// One cell of a decomposition: lines `u0..u0 + runs.len()`, and on each line the run
/// `[v0, v1]` of pixels. `cols`: the lines are image columns (`u` = column, `v` = row),
/// otherwise image rows (`u` = row, `v` = column).
#[derive(Clone, Debug)]
struct Cell {
    cols: bool,
    u0: usize,
    runs: Vec<(usize, usize)>,
}

impl Cell {
    fn u1(&self) -> usize {
        self.u0 + self.runs.len() - 1
    }

    /// Pixel `(col, row)` of line `u`, position `v`.
    fn px(&self, u: usize, v: usize) -> (usize, usize) {
        if self.cols {
            (u, v)
        } else {
            (v, u)
        }
    }

    /// The same pixels with lines the other way, if every such line meets the cell in one run.
    fn transposed(&self) -> Option<Cell> {
        let lo = self.runs.iter().map(|r| r.0).min()?;
        let hi = self.runs.iter().map(|r| r.1).max()?;
        // Per position `v`: the first and last line whose run holds it; a line that holds it
        // after a gap makes it two runs.
        let mut runs: Vec<Option<(usize, usize)>> = vec![None; hi - lo + 1];
        for (k, &(a, b)) in self.runs.iter().enumerate() {
            let u = self.u0 + k;
            for r in &mut runs[a - lo..=b - lo] {
                match r {
                    None => *r = Some((u, u)),
                    Some((_, last)) if *last + 1 == u => *last = u,
                    Some(_) => return None,
                }
            }
        }
        let runs = runs.into_iter().collect::<Option<Vec<_>>>()?;
        Some(Cell {
            cols: !self.cols,
            u0: lo,
            runs,
        })
    }
}

/// Cells elongated along their lines (more lines than twice their longest run) that are not
/// monotone the other way only because of their ends (rounded C-free corners) are cut into the
/// two ends (at most `max` lines each) and a middle that can take lanes across (module docs,
/// step 2).
fn split_ends(cells: Vec<Cell>, max: usize) -> Vec<Cell> {
    let mut out = Vec::with_capacity(cells.len());
    for c in cells {
        let n = c.runs.len();
        let longest = c.runs.iter().map(|r| r.1 - r.0 + 1).max().unwrap_or(0);
        if n <= 2 * longest || n <= 2 * max + 1 || c.transposed().is_some() {
            out.push(c);
            continue;
        }
        let sub = |a: usize, b: usize| Cell {
            cols: c.cols,
            u0: c.u0 + a,
            runs: c.runs[a..b].to_vec(),
        };
        let mut cut = None;
        'search: for t in 1..=max {
            for (a, b) in [(t, t), (t, 0), (0, t)] {
                if sub(a, n - b).transposed().is_some() {
                    cut = Some((a, b));
                    break 'search;
                }
            }
        }
        match cut {
            Some((a, b)) => {
                if a > 0 {
                    out.push(sub(0, a));
                }
                out.push(sub(a, n - b));
                if b > 0 {
                    out.push(sub(n - b, n));
                }
            }
            None => out.push(c),
        }
    }
    out
}

/// Cuts cells whose runs change length abruptly (by more than `jump` pixels from one line to
/// the next, as where a corridor leaves a room inside one cell) into the parts on either side
/// where that lowers the estimated cost, so that each part takes its own lane direction
/// (module docs, step 2). `cost` prices a cell (its cheaper view plus the cost of reaching
/// it); the cheapest cut is taken first and both parts are cut again.
fn split_jumps(cells: Vec<Cell>, jump: usize, cost: &dyn Fn(&Cell) -> f64) -> Vec<Cell> {
    let mut out = Vec::with_capacity(cells.len());
    let mut todo: Vec<Cell> = cells.into_iter().rev().collect();
    while let Some(c) = todo.pop() {
        let n = c.runs.len();
        let len = |k: usize| c.runs[k].1 - c.runs[k].0;
        let cuts: Vec<usize> = (1..n)
            .filter(|&k| len(k).abs_diff(len(k - 1)) > jump)
            .collect();
        if cuts.is_empty() {
            out.push(c);
            continue;
        }
        let sub = |a: usize, b: usize| Cell {
            cols: c.cols,
            u0: c.u0 + a,
            runs: c.runs[a..b].to_vec(),
        };
        let whole = cost(&c);
        let mut best: Option<(f64, usize)> = None;
        for &k in &cuts {
            let e = cost(&sub(0, k)) + cost(&sub(k, n));
            if e < whole - 1e-9 && best.is_none_or(|b| e < b.0) {
                best = Some((e, k));
            }
        }
        match best {
            Some((_, k)) => {
                // Second part first on the stack's far side: parts stay in line order.
                todo.push(sub(k, n));
                todo.push(sub(0, k));
            }
            None => out.push(c),
        }
    }
    out
}

/// Decomposes the pixels where `free(u, v)` over lines `u < nu` of length `nv` (module docs,
/// step 1). Cells are numbered in the order they open.
fn decompose(nu: usize, nv: usize, cols: bool, free: &dyn Fn(usize, usize) -> bool) -> Vec<Cell> {
    let mut cells: Vec<Cell> = Vec::new();
    // Runs of the previous line with their cell.
    let mut prev: Vec<(usize, usize, usize)> = Vec::new();
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for u in 0..nu {
        runs.clear();
        let mut v = 0;
        while v < nv {
            if free(u, v) {
                let s = v;
                while v + 1 < nv && free(u, v + 1) {
                    v += 1;
                }
                runs.push((s, v));
            }
            v += 1;
        }
        let overl = |a: (usize, usize), b: (usize, usize)| a.0 <= b.1 && b.0 <= a.1;
        let mut cur: Vec<(usize, usize, usize)> = Vec::with_capacity(runs.len());
        for &run in &runs {
            let mut ov = prev.iter().filter(|p| overl((p.0, p.1), run));
            let continues = match (ov.next(), ov.next()) {
                (Some(p), None) => runs.iter().filter(|&&q| overl((p.0, p.1), q)).count() == 1,
                _ => false,
            };
            let id = if continues {
                let p = prev
                    .iter()
                    .find(|p| overl((p.0, p.1), run))
                    .map_or(0, |p| p.2);
                cells[p].runs.push(run);
                p
            } else {
                cells.push(Cell {
                    cols,
                    u0: u,
                    runs: vec![run],
                });
                cells.len() - 1
            };
            cur.push((run.0, run.1, id));
        }
        prev = cur;
    }
    cells
}

/// Shared geometry: the world, the C-free set and helpers in grid coordinates (pixels, y up).
struct Ctx<'a> {
    world: &'a World,
    frame: MapFrame,
    /// Reachable C-free pixel centres.
    ok: Vec<bool>,
    /// Transfer set: `ok` with the extra margin.
    safe: Vec<bool>,
    /// Tool radius in pixels.
    rt: f64,
}

/// The lattice the cells are decomposed on: points `(c, r)` one pixel apart (`c` to the right,
/// `r` down, as in the image), either the map's own pixel centres or the same lattice turned
/// by an angle about the map's centre (module docs, step 1).
struct Lattice<'a> {
    /// Lattice points per row.
    w: usize,
    /// Rows.
    h: usize,
    /// `(cos, sin)` of the angle the lattice is turned by in the image; `None`: the pixels.
    rot: Option<(f64, f64)>,
    /// Map height in pixels (grid `y` of an image row).
    map_h: f64,
    /// The map's centre in image coordinates.
    centre: (f64, f64),
    /// Lattice points that are reachable and free for the robot's disk (the pixel lattice
    /// borrows the context's mask; a turned one owns its own).
    ok: Cow<'a, [bool]>,
}

impl<'a> Lattice<'a> {
    /// The map's own pixel centres.
    fn pixels(ctx: &'a Ctx<'_>) -> Self {
        let (w, h) = (ctx.frame.width, ctx.frame.height);
        Self {
            w,
            h,
            rot: None,
            map_h: h as f64,
            centre: (w as f64 / 2.0, h as f64 / 2.0),
            ok: Cow::Borrowed(&ctx.ok),
        }
    }

    /// The pixel lattice turned by `angle` (radians, in the image) about the map's centre,
    /// large enough to hold the whole map; a point is free where the pixel holding it is
    /// reachable C-free and the robot's disk centred on it touches no obstacle.
    fn turned(ctx: &Ctx<'_>, angle: f64) -> Self {
        let (mw, mh) = (ctx.frame.width as f64, ctx.frame.height as f64);
        let (co, si) = (angle.cos(), angle.sin());
        let w = (mw * co.abs() + mh * si.abs()).ceil() as usize + 2;
        let h = (mw * si.abs() + mh * co.abs()).ceil() as usize + 2;
        let mut lat = Self {
            w,
            h,
            rot: Some((co, si)),
            map_h: mh,
            centre: (mw / 2.0, mh / 2.0),
            ok: Cow::Borrowed(&[]),
        };
        let mut ok = vec![false; w * h];
        for r in 0..h {
            for c in 0..w {
                let g = lat.grid(c as f64, r as f64);
                let (pc, pr) = ctx.frame.grid_to_pixel_signed(g);
                ok[r * w + c] =
                    ctx.ok_at(pc, pr) && !ctx.world.disk_collides(ctx.frame.grid_to_world(g));
            }
        }
        lat.ok = Cow::Owned(ok);
        lat
    }

    /// Grid point (pixels, y up) of the lattice position `(c, r)` (may be fractional).
    fn grid(&self, c: f64, r: f64) -> Point {
        match self.rot {
            None => Point::new(c + 0.5, self.map_h - r - 0.5),
            Some((co, si)) => {
                let x = c + 0.5 - self.w as f64 / 2.0;
                let y = r + 0.5 - self.h as f64 / 2.0;
                Point::new(
                    self.centre.0 + co * x - si * y,
                    self.map_h - (self.centre.1 + si * x + co * y),
                )
            }
        }
    }

    fn ok_at(&self, c: i64, r: i64) -> bool {
        c >= 0
            && r >= 0
            && (c as usize) < self.w
            && (r as usize) < self.h
            && self.ok[r as usize * self.w + c as usize]
    }
}

/// The dominant direction of the map's walls, in radians in `[0, pi/2)` (image frame): the
/// angle whose projections of the C-free boundary (reachable C-free pixels beside a blocked
/// one) onto it and onto its normal are most concentrated (the largest sum of squared counts
/// of one-pixel bins: walls along the angle pile up in few bins), searched in whole degrees
/// and then in tenths around the best; the same for the best local maximum at least
/// [`SECOND_PEAK_DEG`] away (walls of a wing turned against the rest). Empty when the C-free
/// set has no boundary.
fn dominant_angles(ctx: &Ctx<'_>) -> Vec<f64> {
    let (w, h) = (ctx.frame.width, ctx.frame.height);
    let mut pts: Vec<(f64, f64)> = Vec::new();
    for r in 0..h {
        for c in 0..w {
            if !ctx.ok[r * w + c] {
                continue;
            }
            let (ci, ri) = (c as i64, r as i64);
            if [(1, 0), (-1, 0), (0, 1), (0, -1)]
                .iter()
                .any(|&(dc, dr)| !ctx.ok_at(ci + dc, ri + dr))
            {
                pts.push((c as f64 + 0.5, r as f64 + 0.5));
            }
        }
    }
    if pts.is_empty() {
        return Vec::new();
    }
    let span = (w + h) as f64 * std::f64::consts::SQRT_2;
    let nb = span.ceil() as usize + 2;
    let mut bins = vec![0u32; 2 * nb];
    let mut score = |deg: f64| -> u64 {
        let (si, co) = deg.to_radians().sin_cos();
        bins.fill(0);
        for &(x, y) in &pts {
            let p = x * co + y * si + span / 2.0;
            let q = -x * si + y * co + span / 2.0;
            bins[(p.max(0.0) as usize).min(nb - 1)] += 1;
            bins[nb + (q.max(0.0) as usize).min(nb - 1)] += 1;
        }
        bins.iter().map(|&b| u64::from(b) * u64::from(b)).sum()
    };
    let coarse: Vec<u64> = (0..90).map(|k| score(f64::from(k))).collect();
    let first = (0..90)
        .max_by_key(|&k| (coarse[k], Reverse(k)))
        .unwrap_or(0);
    let away = |k: usize| {
        let d = k.abs_diff(first);
        d.min(90 - d) >= SECOND_PEAK_DEG
    };
    let peak = |k: usize| coarse[k] >= coarse[(k + 1) % 90] && coarse[k] >= coarse[(k + 89) % 90];
    let second = (0..90)
        .filter(|&k| away(k) && peak(k))
        .max_by_key(|&k| (coarse[k], Reverse(k)));
    let mut out = Vec::new();
    for k in std::iter::once(first).chain(second) {
        let mut best = (coarse[k], k as f64);
        for j in -9..=9 {
            let d = k as f64 + f64::from(j) / 10.0;
            let v = score(d);
            if v > best.0 {
                best = (v, d);
            }
        }
        out.push(best.1.to_radians().rem_euclid(std::f64::consts::FRAC_PI_2));
    }
    out
}

/// Degrees between the turned lattices tried around a wall angle (`angle_tries`).
const ANGLE_STEP_DEG: f64 = 0.5;

/// Degrees (at least) between the two wall directions [`dominant_angles`] returns.
const SECOND_PEAK_DEG: usize = 10;

/// A dominant wall direction within this many degrees of the pixel axes is taken as the axes:
/// no turned lattice is tried.
const AXIS_TOL_DEG: f64 = 4.0;

/// Improvement rounds of the first tour (which only picks each cell's path for the rim step).
const FIRST_ROUNDS: u32 = 1;
/// Gap kept between a pushed lane end and the exact contact (pixels).
const BACKOFF_PX: f64 = 0.05;
/// How far a merged boundary segment may stray from the boundary points it replaces (pixels).
const CONTOUR_TOL_PX: f64 = 1.0;

impl Ctx<'_> {
    fn ok_at(&self, c: i64, r: i64) -> bool {
        self.frame
            .checked(c, r)
            .is_some_and(|(c, r)| self.ok[r * self.frame.width + c])
    }

    fn centre(&self, c: usize, r: usize) -> Point {
        self.frame.pixel_center_grid(c, r)
    }

    /// Is the straight move between grid points `a` and `b` free on the true map?
    fn free(&self, a: Point, b: Point) -> bool {
        self.world
            .segment_free(self.frame.grid_to_world(a), self.frame.grid_to_world(b))
    }

    /// Grid point of continuous line coordinate `t` (lattice points at integers) and lattice
    /// position `v` (may be fractional or outside the lattice) of `cell`'s orientation.
    fn at(lat: &Lattice, cols: bool, t: f64, v: f64) -> Point {
        if cols {
            lat.grid(t, v)
        } else {
            lat.grid(v, t)
        }
    }

    /// The end on side `hi` of the lane at line coordinate `t` of `cell` (between the lines
    /// `floor t` and `ceil t`): from the end of the two runs' common part, pushed along the
    /// lane to the exact contact (minus [`BACKOFF_PX`]) or, where nothing is hit, to the end
    /// of the longer run.
    fn lane_end(&self, lat: &Lattice, cell: &Cell, t: f64, hi: bool) -> Point {
        let (u0, u1) = (cell.u0, cell.u1());
        let a = (t.floor().max(u0 as f64) as usize).min(u1);
        let b = (t.ceil().max(u0 as f64) as usize).min(u1);
        let (ra, rb) = (cell.runs[a - u0], cell.runs[b - u0]);
        let (mut i0, mut i1) = (ra.0.max(rb.0), ra.1.min(rb.1));
        let (n0, n1) = (ra.0.min(rb.0), ra.1.max(rb.1));
        if i0 > i1 {
            // The runs do not overlap (cannot happen inside a cell): use the nearer line's.
            let r = if t - a as f64 <= 0.5 { ra } else { rb };
            (i0, i1) = r;
        }
        let (v_in, v_out, v_end) = if hi {
            (i1 as f64, n1 as f64 + 1.0, n1 as f64)
        } else {
            (i0 as f64, n0 as f64 - 1.0, n0 as f64)
        };
        let p = Self::at(lat, cell.cols, t, v_in);
        let q = Self::at(lat, cell.cols, t, v_out);
        let len = (v_out - v_in).abs();
        match self
            .world
            .first_contact(self.frame.grid_to_world(p), self.frame.grid_to_world(q))
        {
            Some(s) if s * len > BACKOFF_PX => p.add(q.sub(p).scale(s - BACKOFF_PX / len)),
            Some(_) => p,
            None => Self::at(lat, cell.cols, t, v_end),
        }
    }

    /// A C-free pixel centre joined to `p` by a free straight move (nearest first).
    fn anchor(&self, p: Point) -> Option<(usize, usize)> {
        let (c0, r0) = self.frame.grid_to_pixel_signed(p);
        let mut best: Option<(f64, (usize, usize))> = None;
        for dr in -2..=2 {
            for dc in -2..=2 {
                let (c, r) = (c0 + dc, r0 + dr);
                if !self.ok_at(c, r) {
                    continue;
                }
                let (c, r) = (c as usize, r as usize);
                let q = self.centre(c, r);
                let d = q.dist(p);
                if best.is_none_or(|b| d < b.0) && self.free(p, q) {
                    best = Some((d, (c, r)));
                }
            }
        }
        best.map(|b| b.1)
    }

    /// Moves from `a` to `b` (excluding `a`): straight when free, else an A* pixel path
    /// shortened by line of sight; `None` when no verified path exists.
    fn route(&self, search: &mut Search, a: Point, b: Point) -> Option<Vec<Point>> {
        if self.free(a, b) {
            return Some(vec![b]);
        }
        let pa = self.anchor(a)?;
        let pb = self.anchor(b)?;
        let diag = |i: usize, j: usize| {
            let w = self.frame.width;
            self.free(self.centre(i % w, i / w), self.centre(j % w, j / w))
        };
        let path = search
            .path(&self.safe, pa, pb, &diag)
            .or_else(|| search.path(&self.ok, pa, pb, &diag))?;
        let mut pts = Vec::with_capacity(path.len() + 2);
        pts.push(a);
        pts.extend(path.iter().map(|&(c, r)| self.centre(c, r)));
        pts.push(b);
        pts.dedup();
        self.shorten(&pts)
    }

    /// Line-of-sight shortening of a chain whose consecutive points are joined by free moves
    /// (not checked: a failing link gives `None`). Returns the points after the first.
    fn shorten(&self, pts: &[Point]) -> Option<Vec<Point>> {
        let mut out = Vec::new();
        let mut i = 0;
        while i + 1 < pts.len() {
            let mut lo = i + 1;
            let mut step = 1;
            let mut hi = None;
            loop {
                let j = (i + step).min(pts.len() - 1);
                if self.free(pts[i], pts[j]) {
                    lo = j;
                    if j == pts.len() - 1 {
                        break;
                    }
                    step *= 2;
                } else {
                    hi = Some(j);
                    break;
                }
            }
            if let Some(mut hi) = hi {
                if hi == i + 1 {
                    return None;
                }
                while hi - lo > 1 {
                    let mid = usize::midpoint(lo, hi);
                    if self.free(pts[i], pts[mid]) {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
            }
            out.push(pts[lo]);
            i = lo;
        }
        Some(out)
    }

    /// Follows the chain `pts` (from `pts[0]`, excluded) with straight free moves that stay
    /// within [`CONTOUR_TOL_PX`] of every point they replace; links that are not free are
    /// routed. Returns the points after the first (`None`: some link has no route).
    fn follow(&self, search: &mut Search, pts: &[Point]) -> Option<Vec<Point>> {
        let mut out = Vec::new();
        let mut i = 0;
        let tol2 = CONTOUR_TOL_PX * CONTOUR_TOL_PX;
        while i + 1 < pts.len() {
            // Farthest j whose chord keeps every point in between within the tolerance.
            let mut jmax = i + 1;
            for j in i + 2..pts.len() {
                if (i + 1..j).all(|m| point_segment_dist2(pts[m], pts[i], pts[j]) <= tol2) {
                    jmax = j;
                } else {
                    break;
                }
            }
            let mut j = jmax;
            while j > i + 1 && !self.free(pts[i], pts[j]) {
                j -= 1;
            }
            if j == i + 1 && !self.free(pts[i], pts[j]) {
                out.extend(self.route(search, pts[i], pts[j])?);
            } else {
                out.push(pts[j]);
            }
            i = j;
        }
        Some(out)
    }
}

/// Share of the pixels of `cell`'s line `u` whose outer neighbour (towards `out` = -1 or +1
/// along the lines) passes `other`, at least one half?
fn side_open(
    lat: &Lattice,
    cell: &Cell,
    u: usize,
    out: i64,
    other: &dyn Fn(usize) -> bool,
) -> bool {
    let (a, b) = cell.runs[u - cell.u0];
    let w = lat.w;
    let n = (a..=b)
        .filter(|&v| {
            let (c, r) = cell.px(u, v);
            let (c, r) = if cell.cols {
                (c as i64 + out, r as i64)
            } else {
                (c as i64, r as i64 + out)
            };
            lat.ok_at(c, r) && other(r as usize * w + c as usize)
        })
        .count();
    2 * n > b - a
}

/// The lane positions (line coordinates) of `cell` (module docs, step 2): a lane on each
/// closed side and the lines `phase + k sp` in between, shared with the neighbours across open
/// sides. A cell closed on both sides shares no lane with a neighbour: its lanes are spread
/// evenly between its two edge lines, as few as keep every gap at most `sp`.
fn lanes_of(cell: &Cell, sp: f64, phase: f64, open_lo: bool, open_hi: bool) -> Vec<f64> {
    let (u0, u1) = (cell.u0 as f64, cell.u1() as f64);
    if !open_lo && !open_hi {
        let gaps = ((u1 - u0) / sp - 1e-9).ceil();
        if gaps < 1.0 {
            return vec![u0];
        }
        return (0..=gaps as usize)
            .map(|k| u0 + (u1 - u0) * k as f64 / gaps)
            .collect();
    }
    let mut lanes: Vec<f64> = Vec::new();
    if !open_lo {
        lanes.push(u0);
    }
    // Lattice lines in [u0 - 1/2, u1 + 1/2): every line belongs to exactly one of the cells
    // that meet along the lines, whatever the rounding.
    let mut k = ((u0 - 0.5 - phase) / sp).floor();
    loop {
        let t = phase + k * sp;
        if t >= u1 + 0.5 {
            break;
        }
        if t >= u0 - 0.5 && lanes.last().is_none_or(|&l| t.max(u0) - l > 1e-6) {
            lanes.push(t.clamp(u0, u1));
        }
        k += 1.0;
    }
    if !open_hi && lanes.last().is_none_or(|&l| u1 - l > 1e-6) {
        lanes.push(u1);
    }
    lanes
}

/// The pixel positions `v` that the lane at line coordinate `t` of `cell` surely spans: the
/// common part of the runs of the lines on either side of it.
fn lane_span(cell: &Cell, t: f64) -> Option<(usize, usize)> {
    let (u0, u1) = (cell.u0, cell.u1());
    let a = (t.floor().max(u0 as f64) as usize).min(u1);
    let b = (t.ceil().max(u0 as f64) as usize).min(u1);
    let (ra, rb) = (cell.runs[a - u0], cell.runs[b - u0]);
    let (v0, v1) = (ra.0.max(rb.0), ra.1.min(rb.1));
    (v0 <= v1).then_some((v0, v1))
}

/// Calls `f` with every pixel index (image `w` x `h`) that the lanes of `cell` surely sweep:
/// the pixel centres within `rt` of a lane, across it, along its sure span.
fn for_lane_pixels(
    cell: &Cell,
    lanes: &[f64],
    w: usize,
    h: usize,
    rt: f64,
    f: &mut dyn FnMut(usize),
) {
    let nu = if cell.cols { w } else { h };
    for &t in lanes {
        let Some((v0, v1)) = lane_span(cell, t) else {
            continue;
        };
        let ua = (t - rt).ceil().max(0.0) as usize;
        let ub = ((t + rt).floor().max(0.0) as usize).min(nu - 1);
        for u in ua..=ub {
            for v in v0..=v1 {
                let (c, r) = cell.px(u, v);
                f(r * w + c);
            }
        }
    }
}

/// Drops the cells whose every pixel the lanes of other cells already sweep (module docs,
/// step 2), the cells with the least lane length first.
fn drop_covered(
    cells: Vec<(Cell, Vec<f64>)>,
    w: usize,
    h: usize,
    rt: f64,
) -> Vec<(Cell, Vec<f64>)> {
    // How many cells' lanes sweep each pixel.
    let mut count = vec![0u16; w * h];
    let mut last = vec![u32::MAX; w * h];
    for (k, (c, l)) in cells.iter().enumerate() {
        for_lane_pixels(c, l, w, h, rt, &mut |i| {
            if last[i] != k as u32 {
                last[i] = k as u32;
                count[i] = count[i].saturating_add(1);
            }
        });
    }
    let lane_len = |c: &Cell, l: &[f64]| -> usize {
        l.iter()
            .filter_map(|&t| lane_span(c, t))
            .map(|(a, b)| b - a + 1)
            .sum()
    };
    let mut order: Vec<usize> = (0..cells.len()).collect();
    order.sort_by_key(|&k| (lane_len(&cells[k].0, &cells[k].1), k));
    let mut keep = vec![true; cells.len()];
    let mut mine = vec![false; w * h];
    let mut touched: Vec<usize> = Vec::new();
    for k in order {
        let (c, l) = &cells[k];
        touched.clear();
        for_lane_pixels(c, l, w, h, rt, &mut |i| {
            if !mine[i] {
                mine[i] = true;
                touched.push(i);
            }
        });
        let covered = c.runs.iter().enumerate().all(|(j, &(a, b))| {
            (a..=b).all(|v| {
                let (cc, rr) = c.px(c.u0 + j, v);
                let i = rr * w + cc;
                count[i] > u16::from(mine[i])
            })
        });
        if covered {
            keep[k] = false;
            for &i in &touched {
                count[i] -= 1;
            }
        }
        for &i in &touched {
            mine[i] = false;
        }
    }
    cells
        .into_iter()
        .zip(keep)
        .filter_map(|(c, k)| k.then_some(c))
        .collect()
}

/// Estimated cost of sweeping `cell` with `lanes`: lane lengths, the span between the first
/// and last lane, and `turn_px` per turn (two per lane).
fn estimate(cell: &Cell, lanes: &[f64], turn_px: f64) -> f64 {
    if lanes.is_empty() {
        return 0.0;
    }
    let len: f64 = lanes
        .iter()
        .map(|&t| {
            let u = (t.round() as usize).clamp(cell.u0, cell.u1());
            let (a, b) = cell.runs[u - cell.u0];
            (b - a) as f64
        })
        .sum();
    let span = lanes[lanes.len() - 1] - lanes[0];
    len + span + turn_px * (2 * lanes.len()) as f64
}

/// A cell's two boustrophedon paths (grid points), starting at the first lane's low end and at
/// its high end.
fn cell_paths(
    ctx: &Ctx<'_>,
    lat: &Lattice,
    search: &mut Search,
    cell: &Cell,
    lanes: &[f64],
) -> [Vec<Point>; 2] {
    let mut out = [Vec::new(), Vec::new()];
    for (k, start_hi) in [false, true].into_iter().enumerate() {
        let mut pts: Vec<Point> = Vec::new();
        let mut hi = start_hi;
        for (i, &u) in lanes.iter().enumerate() {
            let a = ctx.lane_end(lat, cell, u, hi);
            let b = ctx.lane_end(lat, cell, u, !hi);
            if i == 0 {
                pts.push(a);
            } else {
                // Join along the boundary on side `hi` from the previous lane.
                let prev = lanes[i - 1];
                let mut chain = vec![*pts.last().unwrap_or(&a)];
                let mut w = prev.floor() + 1.0;
                while w < u - 1e-9 {
                    chain.push(ctx.lane_end(lat, cell, w, hi));
                    w += 1.0;
                }
                chain.push(a);
                if let Some(v) = ctx.follow(search, &chain) {
                    pts.extend(v);
                } else {
                    // Unreachable along the rim (should not happen inside a cell): route.
                    let from = *pts.last().unwrap_or(&a);
                    if let Some(v) = ctx.route(search, from, a) {
                        pts.extend(v);
                    }
                }
            }
            if ctx.free(a, b) {
                pts.push(b);
            } else if let Some(v) = ctx.route(search, a, b) {
                pts.extend(v);
            }
            hi = !hi;
        }
        pts.dedup();
        out[k] = pts;
    }
    out
}

/// One step of the plan.
#[derive(Clone, Debug)]
enum Item {
    Move(Point),
    Mark(Event),
}

impl Bcd {
    /// Plans the whole coverage of `world` (offline). Invalid options (see
    /// [`BcdOptions::check_ranges`]) are replaced by their defaults; use [`Bcd::try_new`] to refuse
    /// them instead.
    pub fn new(world: &World, opts: &BcdOptions) -> Self {
        if let Ok(p) = Self::try_new(world, opts) {
            p
        } else {
            let d = BcdOptions::default();
            let fixed = BcdOptions {
                lane_spacing_m: opts.lane_spacing_m.filter(|s| s.is_finite() && *s > 0.0),
                margin_px: if opts.margin_px.is_finite() && opts.margin_px >= 0.0 {
                    opts.margin_px
                } else {
                    d.margin_px
                },
                turn_cost_m: if opts.turn_cost_m.is_finite() && opts.turn_cost_m >= 0.0 {
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
                tour_rounds: opts.tour_rounds,
                angle_tries: opts.angle_tries,
                min_coverage: if (0.0..=1.0).contains(&opts.min_coverage) {
                    opts.min_coverage
                } else {
                    d.min_coverage
                },
            };
            Self::plan(world, &fixed)
        }
    }

    /// Plans the whole coverage of `world` (offline).
    ///
    /// # Errors
    /// An option out of range.
    pub fn try_new(world: &World, opts: &BcdOptions) -> Result<Self, BcdOptionsError> {
        opts.check_ranges()?;
        Ok(Self::plan(world, opts))
    }

    /// Number of cells of the decomposition used.
    pub fn cells(&self) -> usize {
        self.cells
    }

    fn plan(world: &World, opts: &BcdOptions) -> Self {
        let frame = *world.frame();
        let (w, h) = (frame.width, frame.height);
        let robot = world.robot();
        let res = frame.resolution;
        let reach = world.reachable();
        let ok: Vec<bool> = (0..w * h).map(|i| reach.contains(i)).collect();
        let need = crate::collide::contact_radius_px(robot.radius / res) + opts.margin_px;
        let safe: Vec<bool> = (0..w * h)
            .map(|i| ok[i] && world.pixel_clearance(i % w, i / w) / res + 0.5 >= need)
            .collect();
        let ctx = Ctx {
            world,
            frame,
            ok,
            safe,
            rt: robot.tool_radius / res,
        };
        let mut search = Search::new(w, h);
        // The plan on the pixel lattice and, when the walls run at an angle to the pixel
        // axes, on the lattice turned to them; the cheaper is kept (module docs, step 1).
        let mut best = Self::plan_on(&ctx, &Lattice::pixels(&ctx), opts, &mut search);
        let off_axis = |a: &f64| {
            let deg = a.to_degrees();
            deg.min(90.0 - deg) > AXIS_TOL_DEG
        };
        let angles = dominant_angles(&ctx);
        // A map whose dominant walls run along the axes is planned on the pixels only.
        let angles: &[f64] = if angles.first().is_some_and(off_axis) {
            &angles
        } else {
            &[]
        };
        for a in angles.iter().copied() {
            if !off_axis(&a) {
                continue;
            }
            for j in 0..opts.angle_tries {
                // 0, +1/2, -1/2, +1, -1, ... degrees around the wall angle.
                let step = f64::from(j.div_ceil(2)) * ANGLE_STEP_DEG;
                let d = if j % 2 == 1 { step } else { -step };
                let t = a + d.to_radians();
                let turned = Self::plan_on(&ctx, &Lattice::turned(&ctx, t), opts, &mut search);
                if (turned.0, turned.1) < (best.0, best.1) {
                    best = turned;
                }
            }
        }
        let (_, _, items, ncells) = best;
        let start = frame.world_to_grid(world.start().position());

        // A region whose moves the smoothing and pruning merged into the moves around it (or
        // a cell whose lane is a single point) has nothing left between its start and end: it
        // is not reported (marks inside it are kept), and the regions left are numbered 1, 2,
        // ... in order.
        let mut steps = VecDeque::with_capacity(items.len());
        let mut at = start;
        // Marks since a region's start while it has no move yet (`None`: no region pending).
        let mut pending: Option<Vec<Event>> = None;
        let mut region = 0u32;
        for it in items {
            match it {
                Item::Move(p) => {
                    if p != at {
                        if let Some(marks) = pending.take() {
                            region += 1;
                            steps.push_back(Step::Mark(Event::RegionStart { region }));
                            steps.extend(marks.into_iter().map(Step::Mark));
                        }
                        steps.push_back(Step::MoveTo(frame.grid_to_world(p)));
                        at = p;
                    }
                }
                Item::Mark(Event::RegionStart { .. }) => {
                    if let Some(marks) = pending.replace(Vec::new()) {
                        steps.extend(marks.into_iter().map(Step::Mark));
                    }
                }
                Item::Mark(Event::RegionEnd { .. }) => match pending.take() {
                    Some(marks) => steps.extend(marks.into_iter().map(Step::Mark)),
                    None => steps.push_back(Step::Mark(Event::RegionEnd { region })),
                },
                Item::Mark(e) => match pending.as_mut() {
                    Some(marks) => marks.push(e),
                    None => steps.push_back(Step::Mark(e)),
                },
            }
        }
        if let Some(marks) = pending {
            steps.extend(marks.into_iter().map(Step::Mark));
        }
        Self {
            steps,
            cells: ncells,
        }
    }

    /// Steps 1-5 of the module docs on the lattice `lat`: the plan's items with the moves it
    /// had to skip, its cost (length plus `turn_cost_m` per turn, pixels) and its cells.
    fn plan_on(
        ctx: &Ctx<'_>,
        lat: &Lattice,
        opts: &BcdOptions,
        search: &mut Search,
    ) -> (usize, f64, Vec<Item>, usize) {
        let world = ctx.world;
        let frame = ctx.frame;
        let robot = world.robot();
        let res = frame.resolution;
        let (w, h) = (lat.w, lat.h);
        let spacing = opts.lane_spacing_m.unwrap_or(2.0 * robot.tool_radius);
        let sp = (spacing / res).max(1.0);
        let turn_px = opts.turn_cost_m / res;
        let start = frame.world_to_grid(world.start().position());

        // 1-2. Both decompositions, each cell's cheaper lane direction, the cheaper total.
        let ok = &lat.ok;
        let by_cols = decompose(w, h, true, &|c, r| ok[r * w + c]);
        let by_rows = decompose(h, w, false, &|r, c| ok[r * w + c]);
        // Each cell's views (along its lines; across them when monotone) with their sides'
        // openness where C-free continues; per decomposition and lattice phase, the cheaper
        // view of every cell and the estimated total.
        let views = |cells: Vec<Cell>| -> Vec<Vec<(Cell, bool, bool)>> {
            cells
                .into_iter()
                .map(|c| {
                    let t = c.transposed();
                    let mut v = Vec::with_capacity(2);
                    for c in std::iter::once(c).chain(t) {
                        let lo = side_open(lat, &c, c.u0, -1, &|_| true);
                        let hi = side_open(lat, &c, c.u1(), 1, &|_| true);
                        v.push((c, lo, hi));
                    }
                    v
                })
                .collect()
        };
        // A cell's estimated cost: its cheaper view plus reaching it.
        let cell_cost = |c: &Cell| -> f64 {
            let view = |c: &Cell| {
                let lo = side_open(lat, c, c.u0, -1, &|_| true);
                let hi = side_open(lat, c, c.u1(), 1, &|_| true);
                let lanes = lanes_of(c, sp, 0.0, lo, hi);
                estimate(c, &lanes, turn_px) + 2.0 * turn_px + sp
            };
            let along = view(c);
            c.transposed().map_or(along, |t| along.min(view(&t)))
        };
        let trim_max = (2.0 * sp).ceil() as usize;
        let jump = (sp / 2.0).ceil() as usize;
        let part_cost = |c: &Cell| -> f64 {
            split_ends(vec![c.clone()], trim_max)
                .iter()
                .map(cell_cost)
                .sum()
        };
        let decs = [
            views(split_ends(split_jumps(by_cols, jump, &part_cost), trim_max)),
            views(split_ends(split_jumps(by_rows, jump, &part_cost), trim_max)),
        ];
        let mut best: Option<(f64, usize, f64, Vec<usize>)> = None;
        for (d, dec) in decs.iter().enumerate() {
            for k in 0..6 {
                let phase = sp * f64::from(k) / 6.0;
                let mut total = 0.0;
                let mut pick = Vec::with_capacity(dec.len());
                for vs in dec {
                    let mut b: Option<(f64, usize)> = None;
                    for (j, (c, lo, hi)) in vs.iter().enumerate() {
                        let lanes = lanes_of(c, sp, phase, *lo, *hi);
                        let mut e = estimate(c, &lanes, turn_px);
                        if !lanes.is_empty() {
                            e += 2.0 * turn_px + sp;
                        }
                        if b.is_none_or(|b| e < b.0) {
                            b = Some((e, j));
                        }
                    }
                    let (e, j) = b.unwrap_or((0.0, 0));
                    total += e;
                    pick.push(j);
                }
                if best.as_ref().is_none_or(|b| total < b.0) {
                    best = Some((total, d, phase, pick));
                }
            }
        }
        let (_, d, phase, pick) = best.unwrap_or((0.0, 0, 0.0, Vec::new()));
        let chosen: Vec<Cell> = decs[d]
            .iter()
            .zip(&pick)
            .map(|(vs, &j)| vs[j].0.clone())
            .collect();
        // Lanes: a side is open where the neighbouring pixels belong to cells with lanes the
        // same way (their lattice lines continue this cell's).
        let mut cols_at = vec![0u8; w * h];
        for c in &chosen {
            for (k, &(a, b)) in c.runs.iter().enumerate() {
                for v in a..=b {
                    let (cc, rr) = c.px(c.u0 + k, v);
                    cols_at[rr * w + cc] = if c.cols { 1 } else { 2 };
                }
            }
        }
        let cells: Vec<(Cell, Vec<f64>)> = chosen
            .into_iter()
            .map(|c| {
                let mine = if c.cols { 1 } else { 2 };
                let same = |i: usize| cols_at[i] == mine;
                let lo = side_open(lat, &c, c.u0, -1, &same);
                let hi = side_open(lat, &c, c.u1(), 1, &same);
                let lanes = lanes_of(&c, sp, phase, lo, hi);
                (c, lanes)
            })
            .filter(|(_, l)| !l.is_empty())
            .collect();
        let cells = drop_covered(cells, w, h, ctx.rt);

        // Cell paths; a first tour over the cells picks each cell's path (corner), the rim
        // contours of what those paths miss join the cells in the final tour, where each cell
        // keeps its path (driven either way).
        let mut paths: Vec<[Vec<Point>; 2]> = Vec::with_capacity(cells.len());
        let mut pieces = Vec::with_capacity(cells.len());
        for (cell, lanes) in &cells {
            let ps = cell_paths(ctx, lat, search, cell, lanes);
            let mut piece = tsp::Piece {
                entry: Vec::new(),
                exit: Vec::new(),
                inner: Vec::new(),
            };
            for p in &ps {
                let (f, l) = (p[0], p[p.len() - 1]);
                let len = path_length(p);
                piece.entry.extend([f, l]);
                piece.exit.extend([l, f]);
                piece.inner.extend([len, len]);
            }
            pieces.push(piece);
            paths.push(ps);
        }
        let coarse = hops::Coarse::new(ctx, sp);
        let far = hops::Coarse::new(ctx, sp * f64::from(hops::FAR_FACTOR));
        let ncells = paths.len();
        // Two ways to sweep the rim (module docs, step 3): its passes as pieces of the tour,
        // or inserted into the finished tour where they cost least; the cheaper plan is kept.
        let cell_pieces = pieces;
        let cell_paths_all = paths;
        let mut best: Option<(usize, f64, Vec<Item>)> = None;
        // The hop table and nearest-neighbour tour of the cells alone serve both plans.
        let cell_table = hops::HopTable::new(&coarse, &far, &cell_pieces, start);
        let cell_nn = cell_table.nearest_tour(&cell_pieces, start);
        // The cells' tour after the first rounds, whether those settled it, and its neighbours.
        let mut cell_tour: Option<(tsp::Tour, bool, Vec<Vec<usize>>)> = None;
        for in_tour in [true, false] {
            if !opts.rim && !in_tour {
                break;
            }
            let mut pieces = cell_pieces.clone();
            let mut paths = cell_paths_all.clone();
            let contours: Vec<Vec<Point>> = if opts.rim && in_tour {
                // The first rounds of the cells' tour, kept: the other plan goes on from there.
                let dist = |a: Point, b: Point| cell_table.dist(a, b);
                let nb = tsp::neighbours(&pieces, &dist);
                let mut first = cell_nn.clone();
                let rounds = opts.tour_rounds.min(FIRST_ROUNDS);
                let settled =
                    rounds > 0 && tsp::improve(&pieces, start, rounds, &dist, &nb, &mut first);
                cell_tour = Some((first.clone(), settled, nb));
                let mut keep = vec![0usize; ncells];
                for &(c, v) in &first {
                    keep[c] = v / 2;
                }
                for (c, k) in keep.iter().enumerate() {
                    if *k == 1 {
                        paths[c].swap(0, 1);
                    }
                    let p = &paths[c][0];
                    let (f, l) = (p[0], p[p.len() - 1]);
                    let len = path_length(p);
                    pieces[c] = tsp::Piece {
                        entry: vec![f, l],
                        exit: vec![l, f],
                        inner: vec![len, len],
                    };
                }
                let lines: Vec<&[Point]> = paths.iter().map(|p| p[0].as_slice()).collect();
                rim_contours(ctx, search, &lines, opts.rim_min_yield, opts.rim_coverage)
                    .into_iter()
                    .map(|c| c.0)
                    .collect()
            } else {
                Vec::new()
            };
            for c in &contours {
                let (f, l) = (c[0], c[c.len() - 1]);
                let len = path_length(c);
                pieces.push(tsp::Piece {
                    entry: vec![f, l],
                    exit: vec![l, f],
                    inner: vec![len, len],
                });
            }
            // Only the rim-in-tour plan changes the pieces (one variant per cell, rim passes
            // added); the other plan tours the cells alone.
            let own =
                (opts.rim && in_tour).then(|| hops::HopTable::new(&coarse, &far, &pieces, start));
            let table = own.as_ref().unwrap_or(&cell_table);
            let dist = |a: Point, b: Point| table.dist(a, b);
            let cont = if own.is_none() {
                cell_tour.take()
            } else {
                None
            };
            let tour = match (&own, cont) {
                (Some(t), _) => {
                    let nn = t.nearest_tour(&pieces, start);
                    tsp::solve(&pieces, start, opts.tour_rounds, &dist, Some(nn))
                }
                // (the rounds left after the first ones; none when they settled the tour)
                (None, Some((mut tour, settled, nb))) => {
                    let done = opts.tour_rounds.min(FIRST_ROUNDS);
                    if !settled && opts.tour_rounds > done {
                        tsp::improve(
                            &pieces,
                            start,
                            opts.tour_rounds - done,
                            &dist,
                            &nb,
                            &mut tour,
                        );
                    }
                    tour
                }
                (None, None) => tsp::solve(
                    &pieces,
                    start,
                    opts.tour_rounds,
                    &dist,
                    Some(cell_nn.clone()),
                ),
            };

            let mut items: Vec<Item> = vec![Item::Move(start)];
            let mut here = start;
            let mut region = 0u32;
            // Pieces and moves this plan had to skip because no route reached them: a plan
            // that skips less is kept before a shorter one (a skip loses floor silently).
            let mut skipped = 0usize;
            for &(cid, v) in &tour {
                if cid >= ncells {
                    let c = &contours[cid - ncells];
                    let pts: Vec<Point> = if v == 0 {
                        c.clone()
                    } else {
                        c.iter().rev().copied().collect()
                    };
                    if pts[0] != here {
                        let Some(hop) = ctx.route(search, here, pts[0]) else {
                            skipped += 1;
                            continue;
                        };
                        items.push(Item::Mark(Event::BacktrackStart));
                        items.extend(hop.into_iter().map(Item::Move));
                        items.push(Item::Mark(Event::BacktrackEnd));
                    }
                    items.extend(pts[1..].iter().copied().map(Item::Move));
                    here = pts[pts.len() - 1];
                    continue;
                }
                let path = &paths[cid][v / 2];
                let pts: Vec<Point> = if v % 2 == 0 {
                    path.clone()
                } else {
                    path.iter().rev().copied().collect()
                };
                let entry = pts[0];
                if entry != here {
                    let Some(hop) = ctx.route(search, here, entry) else {
                        skipped += 1;
                        continue;
                    };
                    items.push(Item::Mark(Event::BacktrackStart));
                    items.extend(hop.into_iter().map(Item::Move));
                    items.push(Item::Mark(Event::BacktrackEnd));
                }
                region += 1;
                items.push(Item::Mark(Event::RegionStart { region }));
                items.extend(pts[1..].iter().copied().map(Item::Move));
                items.push(Item::Mark(Event::RegionEnd { region }));
                here = pts[pts.len() - 1];
            }

            if opts.rim {
                rim_pass(
                    ctx,
                    search,
                    &mut items,
                    opts.rim_min_yield,
                    opts.rim_coverage,
                );
            }
            let mut items = smooth(ctx, repair(ctx, search, items, &mut skipped));
            if opts.rim && !in_tour {
                // A second mop-up of what the inserted passes and the smoothing left.
                rim_pass(
                    ctx,
                    search,
                    &mut items,
                    opts.rim_min_yield,
                    opts.rim_coverage,
                );
                items = smooth(ctx, repair(ctx, search, items, &mut skipped));
            }
            let items = prune::prune(ctx, items, opts.min_coverage, turn_px);
            let pts: Vec<Point> = moves(&items).into_iter().map(|m| m.0).collect();
            let cost = path_length(&pts) + turn_px * turns(&pts) as f64;
            if best.as_ref().is_none_or(|b| (skipped, cost) < (b.0, b.1)) {
                best = Some((skipped, cost, items));
            }
        }
        let ncells = cells.len();
        best.map_or((0, 0.0, Vec::new(), ncells), |b| (b.0, b.1, b.2, ncells))
    }
}

/// Re-checks every move of the plan on the true map and routes the ones that are not free
/// (dropping a move that has no route, and skipping to the next reachable point; `skipped`
/// counts the dropped moves).
fn repair(ctx: &Ctx<'_>, search: &mut Search, items: Vec<Item>, skipped: &mut usize) -> Vec<Item> {
    let mut out = Vec::with_capacity(items.len());
    let mut at: Option<Point> = None;
    for it in items {
        match it {
            Item::Move(p) => match at {
                None => {
                    out.push(Item::Move(p));
                    at = Some(p);
                }
                Some(a) => {
                    if a == p || ctx.free(a, p) {
                        out.push(Item::Move(p));
                        at = Some(p);
                    } else if let Some(v) = ctx.route(search, a, p) {
                        out.extend(v.into_iter().map(Item::Move));
                        at = Some(p);
                    } else {
                        *skipped += 1;
                    }
                }
            },
            Item::Mark(e) => out.push(Item::Mark(e)),
        }
    }
    out
}

/// Largest distance (pixels) a smoothed move may stray from a point of the plan it replaces.
const SMOOTH_TOL_PX: f64 = 0.5;
/// Points a smoothed move may replace at most (bounds the work per point).
const SMOOTH_REACH: usize = 48;

/// Straightens the plan: within each run of consecutive moves (the marks stay where they
/// are), a point is dropped when the straight move that replaces it and its neighbours is
/// free on the true map and stays within [`SMOOTH_TOL_PX`] of every dropped point, so a
/// jagged boundary pass becomes a few straight moves (fewer turns) sweeping almost the same
/// floor.
fn smooth(ctx: &Ctx<'_>, items: Vec<Item>) -> Vec<Item> {
    let tol2 = SMOOTH_TOL_PX * SMOOTH_TOL_PX;
    let mut out = Vec::with_capacity(items.len());
    let mut run: Vec<Point> = Vec::new();
    let flush = |run: &mut Vec<Point>, out: &mut Vec<Item>| {
        let n = run.len();
        if n > 0 {
            out.push(Item::Move(run[0]));
        }
        let mut i = 0;
        while i + 1 < n {
            let mut j = i + 1;
            for k in i + 2..n.min(i + 2 + SMOOTH_REACH) {
                if (i + 1..k).all(|m| point_segment_dist2(run[m], run[i], run[k]) <= tol2)
                    && ctx.free(run[i], run[k])
                {
                    j = k;
                } else {
                    break;
                }
            }
            out.push(Item::Move(run[j]));
            i = j;
        }
        run.clear();
    };
    for it in items {
        match it {
            Item::Move(p) => {
                if run.last() != Some(&p) {
                    run.push(p);
                }
            }
            Item::Mark(e) => {
                flush(&mut run, &mut out);
                out.push(Item::Mark(e));
            }
        }
    }
    flush(&mut run, &mut out);
    out
}

/// Number of heading changes along the polyline `pts` (as the simulator counts turns).
/// Whether turning from heading `from` to heading `to` is a rotation the simulator counts.
fn is_turn(from: f64, to: f64) -> bool {
    crate::geometry::wrap_angle(to - from).abs() > crate::planner::MIN_ROTATION
}

fn turns(pts: &[Point]) -> usize {
    let mut n = 0;
    let mut heading: Option<f64> = None;
    for w in pts.windows(2) {
        let d = w[1].sub(w[0]);
        if d.x == 0.0 && d.y == 0.0 {
            continue;
        }
        let h = d.y.atan2(d.x);
        if heading.is_some_and(|g| is_turn(g, h)) {
            n += 1;
        }
        heading = Some(h);
    }
    n
}

/// The moves of `items` as a polyline with, for each point, its index in `items`.
fn moves(items: &[Item]) -> Vec<(Point, usize)> {
    items
        .iter()
        .enumerate()
        .filter_map(|(i, it)| match it {
            Item::Move(p) => Some((*p, i)),
            Item::Mark(_) => None,
        })
        .collect()
}

/// Step 3 of the module docs: the contour passes (grid polylines) that sweep the accessible
/// pixels the polylines `lines` miss, one per 8-connected group of missed pixels, with the
/// number of pixels each is meant to sweep; groups below `min_yield` are left out, and so are
/// the lowest-yield groups that fit in the budget `1 - target` of the accessible pixels.
fn rim_contours(
    ctx: &Ctx<'_>,
    search: &mut Search,
    lines: &[&[Point]],
    min_yield: f64,
    target: f64,
) -> Vec<(Vec<Point>, usize)> {
    let frame = ctx.frame;
    let (w, h) = (frame.width, frame.height);
    let rt = ctx.rt + crate::raster::SWEEP_EPS_PX;
    let mut swept = FixedBitSet::with_capacity(frame.len());
    for line in lines {
        if let Some(&p) = line.first() {
            crate::raster::stamp_capsule(&mut swept, &frame, p, p, rt, &mut |_| {});
        }
        for s in line.windows(2) {
            if s[0] != s[1] {
                crate::raster::stamp_capsule(&mut swept, &frame, s[0], s[1], rt, &mut |_| {});
            }
        }
    }
    let acc = ctx.world.accessible();
    let mut missed = acc.clone();
    missed.difference_with(&swept);
    if missed.is_clear() {
        return Vec::new();
    }
    // Witness of each missed pixel: the nearest C-free pixel centre within reach of the tool.
    let k = rt.floor() as i64;
    let rt2 = rt * rt;
    let mut offsets: Vec<(i64, i64, i64)> = Vec::new();
    for dr in -k..=k {
        for dc in -k..=k {
            let d2 = dc * dc + dr * dr;
            if (d2 as f64) <= rt2 {
                offsets.push((d2, dr, dc));
            }
        }
    }
    offsets.sort_unstable();
    let mut witness = vec![u32::MAX; frame.len()];
    for i in missed.ones() {
        let (c, r) = ((i % w) as i64, (i / w) as i64);
        for &(_, dr, dc) in &offsets {
            if ctx.ok_at(c + dc, r + dr) {
                witness[i] = ((r + dr) as usize * w + (c + dc) as usize) as u32;
                break;
            }
        }
    }
    // Groups: 8-connected components of missed pixels.
    let mut group_of = vec![u32::MAX; frame.len()];
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for i in missed.ones() {
        if group_of[i] != u32::MAX || witness[i] == u32::MAX {
            continue;
        }
        let g = groups.len() as u32;
        let mut members = vec![i];
        group_of[i] = g;
        let mut q = 0;
        while q < members.len() {
            let j = members[q];
            q += 1;
            let (c, r) = ((j % w) as i64, (j / w) as i64);
            for dr in -1..=1 {
                for dc in -1..=1 {
                    let (nc, nr) = (c + dc, r + dr);
                    if nc < 0 || nr < 0 || nc >= w as i64 || nr >= h as i64 {
                        continue;
                    }
                    let n = nr as usize * w + nc as usize;
                    if missed.contains(n) && group_of[n] == u32::MAX && witness[n] != u32::MAX {
                        group_of[n] = g;
                        members.push(n);
                    }
                }
            }
        }
        groups.push(members);
    }
    let mut out = Vec::with_capacity(groups.len());
    for members in &groups {
        let mut ws: Vec<usize> = members.iter().map(|&i| witness[i] as usize).collect();
        ws.sort_unstable();
        ws.dedup();
        let pts: Vec<Point> = ws.iter().map(|&i| ctx.centre(i % w, i / w)).collect();
        // Chain: from the witness farthest from the first one, nearest neighbour onwards.
        let far = (0..pts.len())
            .max_by(|&a, &b| {
                pts[a]
                    .dist2(pts[0])
                    .total_cmp(&pts[b].dist2(pts[0]))
                    .then(b.cmp(&a))
            })
            .unwrap_or(0);
        let mut used = vec![false; pts.len()];
        let mut chain = vec![pts[far]];
        used[far] = true;
        for _ in 1..pts.len() {
            let last = chain[chain.len() - 1];
            let mut best: Option<(f64, usize)> = None;
            for (j, p) in pts.iter().enumerate() {
                if !used[j] && best.is_none_or(|b| p.dist2(last) < b.0) {
                    best = Some((p.dist2(last), j));
                }
            }
            let Some((_, j)) = best else { break };
            used[j] = true;
            chain.push(pts[j]);
        }
        let Some(tail) = ctx.follow(search, &chain) else {
            continue;
        };
        let mut contour = vec![chain[0]];
        contour.extend(tail);
        let clen = path_length(&contour);
        if (members.len() as f64) < min_yield * clen.max(1.0) * 2.0 * ctx.rt {
            continue;
        }
        out.push((contour, members.len()));
    }

    // The budget: missed pixels allowed by `target`, less those no group holds.
    let grouped: usize = out.iter().map(|c| c.1).sum();
    let allowed = ((1.0 - target) * acc.count_ones(..) as f64).floor() as usize;
    let mut budget = allowed.saturating_sub(missed.count_ones(..) - grouped);
    if budget > 0 {
        // Lowest yield (pixels per pixel of contour) first; ties by group order.
        let mut order: Vec<usize> = (0..out.len()).collect();
        let yield_of = |c: &(Vec<Point>, usize)| c.1 as f64 / path_length(&c.0).max(1.0);
        order.sort_by(|&a, &b| {
            yield_of(&out[a])
                .total_cmp(&yield_of(&out[b]))
                .then(a.cmp(&b))
        });
        let mut drop = vec![false; out.len()];
        for i in order {
            if out[i].1 <= budget {
                budget -= out[i].1;
                drop[i] = true;
            }
        }
        let mut k = 0;
        out.retain(|_| {
            k += 1;
            !drop[k - 1]
        });
    }
    out
}

/// Final mop-up of step 3: sweeps what the assembled plan still misses with contour detours
/// inserted at the cheapest point of the path (out and back).
fn rim_pass(
    ctx: &Ctx<'_>,
    search: &mut Search,
    items: &mut Vec<Item>,
    min_yield: f64,
    target: f64,
) {
    const B: f64 = 16.0;
    let frame = ctx.frame;
    let (w, h) = (frame.width, frame.height);
    let path = moves(items);
    let line: Vec<Point> = path.iter().map(|m| m.0).collect();
    let contours = rim_contours(ctx, search, &[&line], min_yield, target);
    // Spatial index of the path's segments (buckets of 16 px).
    let (bw, bh) = (
        (w as f64 / B).ceil() as usize + 1,
        (h as f64 / B).ceil() as usize + 1,
    );
    let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); bw * bh];
    let bucket = |p: Point| -> (usize, usize) {
        (
            ((p.x / B).floor().max(0.0) as usize).min(bw - 1),
            ((p.y / B).floor().max(0.0) as usize).min(bh - 1),
        )
    };
    for (s, seg) in path.windows(2).enumerate() {
        let (a, b) = (bucket(seg[0].0), bucket(seg[1].0));
        for by in a.1.min(b.1)..=a.1.max(b.1) {
            for bx in a.0.min(b.0)..=a.0.max(b.0) {
                buckets[by * bw + bx].push(s as u32);
            }
        }
    }
    // (insert after path segment s, at parameter t along it, the detour points)
    let mut inserts: Vec<(usize, f64, Vec<Point>)> = Vec::new();
    for (contour, _) in contours {
        let clen = path_length(&contour);
        let (cs, ce) = (contour[0], contour[contour.len() - 1]);
        // Cheapest insertion: segments near the contour's start, widening the search.
        let mut best: Option<(f64, usize, f64, bool)> = None;
        let (bx, by) = bucket(cs);
        for ring in 0..bw.max(bh) {
            let ring_i = ring as i64;
            for y in by as i64 - ring_i..=by as i64 + ring_i {
                for x in bx as i64 - ring_i..=bx as i64 + ring_i {
                    if (y - by as i64).abs() != ring_i && (x - bx as i64).abs() != ring_i {
                        continue;
                    }
                    if x < 0 || y < 0 || x >= bw as i64 || y >= bh as i64 {
                        continue;
                    }
                    for &s in &buckets[y as usize * bw + x as usize] {
                        let s = s as usize;
                        let (a, b) = (path[s].0, path[s + 1].0);
                        for rev in [false, true] {
                            let (i0, i1) = if rev { (ce, cs) } else { (cs, ce) };
                            let t = proj(a, b, i0);
                            let q = a.add(b.sub(a).scale(t));
                            let c = q.dist(i0) + clen + i1.dist(q);
                            if best.is_none_or(|bb| c < bb.0) {
                                best = Some((c, s, t, rev));
                            }
                        }
                    }
                }
            }
            // Stop once the ring is farther than the best detour's approach.
            if let Some(bb) = best {
                if (ring as f64 - 1.0) * B > bb.0 - clen {
                    break;
                }
            }
        }
        let Some((_, s, t, rev)) = best else {
            continue;
        };
        let (a, b) = (path[s].0, path[s + 1].0);
        let q = a.add(b.sub(a).scale(t));
        let mut det: Vec<Point> = vec![q];
        if rev {
            det.extend(contour.iter().rev().copied());
        } else {
            det.extend(contour.iter().copied());
        }
        det.push(q);
        inserts.push((s, t, det));
    }
    // Apply: later segments first so indices stay valid; along a segment, by parameter.
    inserts.sort_by(|x, y| y.0.cmp(&x.0).then(y.1.total_cmp(&x.1)));
    for (s, _, det) in inserts {
        let at = path[s + 1].1;
        let new: Vec<Item> = det.into_iter().map(Item::Move).collect();
        items.splice(at..at, new);
    }
}

/// Parameter in `[0, 1]` of the point of segment `a`-`b` nearest to `p`.
fn proj(a: Point, b: Point, p: Point) -> f64 {
    let d = b.sub(a);
    let l2 = d.dot(d);
    if l2 == 0.0 {
        0.0
    } else {
        (p.sub(a).dot(d) / l2).clamp(0.0, 1.0)
    }
}

/// Pixel path search (A*, 8-connected, octile integer costs, no corner cutting).
struct Search {
    width: usize,
    height: usize,
    stamp: Vec<u32>,
    gen: u32,
    g: Vec<u32>,
    parent: Vec<u32>,
}

impl Search {
    fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            stamp: vec![0; width * height],
            gen: 0,
            g: vec![0; width * height],
            parent: vec![u32::MAX; width * height],
        }
    }

    fn octile(a: (usize, usize), b: (usize, usize)) -> u32 {
        let dx = a.0.abs_diff(b.0) as u32;
        let dy = a.1.abs_diff(b.1) as u32;
        10 * dx.max(dy) + 4 * dx.min(dy)
    }

    /// A* from `s` to `t` over `ok` (the end pixels need not be in it). A diagonal step whose
    /// two side pixels are not both in `ok` is taken only when `diag(from, to)` allows it. Ties
    /// by cost, then pixel index.
    fn path(
        &mut self,
        ok: &[bool],
        s: (usize, usize),
        t: (usize, usize),
        diag_ok: &dyn Fn(usize, usize) -> bool,
    ) -> Option<Vec<(usize, usize)>> {
        self.gen = self.gen.wrapping_add(1);
        if self.gen == 0 {
            self.stamp.iter_mut().for_each(|x| *x = 0);
            self.gen = 1;
        }
        let w = self.width;
        let ti = t.1 * w + t.0;
        let passable = |j: usize| ok[j] || j == ti;
        let mut heap = BinaryHeap::new();
        let si = s.1 * w + s.0;
        self.stamp[si] = self.gen;
        self.g[si] = 0;
        self.parent[si] = u32::MAX;
        heap.push(Reverse((Self::octile(s, t), 0u32, si as u32)));
        let mut found = false;
        while let Some(Reverse((_, g, i))) = heap.pop() {
            let i = i as usize;
            if g > self.g[i] {
                continue;
            }
            if i == ti {
                found = true;
                break;
            }
            let (c, r) = ((i % w) as i64, (i / w) as i64);
            for (dc, dr) in [
                (1, 0),
                (0, -1),
                (-1, 0),
                (0, 1),
                (1, -1),
                (-1, -1),
                (-1, 1),
                (1, 1),
            ] {
                let (nc, nr) = (c + dc, r + dr);
                if nc < 0 || nr < 0 || nc >= self.width as i64 || nr >= self.height as i64 {
                    continue;
                }
                let j = nr as usize * w + nc as usize;
                if !passable(j) {
                    continue;
                }
                let diag = dc != 0 && dr != 0;
                if diag
                    && !(passable(r as usize * w + nc as usize)
                        && passable(nr as usize * w + c as usize))
                    && !diag_ok(i, j)
                {
                    continue;
                }
                let ng = g + if diag { 14 } else { 10 };
                if self.stamp[j] != self.gen || ng < self.g[j] {
                    self.stamp[j] = self.gen;
                    self.g[j] = ng;
                    self.parent[j] = i as u32;
                    heap.push(Reverse((
                        ng + Self::octile((nc as usize, nr as usize), t),
                        ng,
                        j as u32,
                    )));
                }
            }
        }
        if !found {
            return None;
        }
        let mut out = vec![t];
        let mut k = ti;
        while self.parent[k] != u32::MAX {
            k = self.parent[k] as usize;
            out.push((k % w, k / w));
        }
        out.reverse();
        Some(out)
    }
}

impl Planner for Bcd {
    fn name(&self) -> &'static str {
        "bcd"
    }
    fn is_offline(&self) -> bool {
        true
    }
    fn next(&mut self, _sensor: &dyn Sensor) -> Step {
        self.steps.pop_front().unwrap_or(Step::Done)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decomposition_splits_and_merges_around_a_block() {
        let art = "........\n..##....\n..##....\n........";
        let g: crate::grid::GridMap = art.parse().unwrap();
        let d = decompose(8, 4, true, &|c, r| g.get(c, r).is_free());
        // Left part, above the block, below the block, right part.
        assert_eq!(d.len(), 4);
        assert_eq!((d[0].u0, d[0].runs.len()), (0, 2));
        assert_eq!((d[1].u0, d[1].runs.clone()), (2, vec![(0, 0), (0, 0)]));
        assert_eq!((d[2].u0, d[2].runs.clone()), (2, vec![(3, 3), (3, 3)]));
        assert_eq!((d[3].u0, d[3].runs.len()), (4, 4));
    }

    fn block_room() -> World {
        let art = "##########\n#........#\n#..##....#\n#..##....#\n#........#\n##########";
        let map = crate::grid::GridMap::from_ascii_scaled(art, 10, 0.02).unwrap();
        World::new(
            map,
            crate::world::Robot::new(0.08),
            Some(crate::geometry::Pose::new(0.3, 0.3, 0.0)),
        )
        .unwrap()
    }

    /// A 60 x 30 px room turned by `deg` degrees in a 90 x 90 px map (0.05 m/px).
    fn turned_room(deg: f64) -> World {
        let (si, co) = deg.to_radians().sin_cos();
        let mut art = String::new();
        for r in 0..90 {
            for c in 0..90 {
                let (x, y) = (f64::from(c) - 44.5, f64::from(r) - 44.5);
                let (u, v) = (co * x + si * y, -si * x + co * y);
                art.push(if u.abs() < 30.0 && v.abs() < 15.0 {
                    '.'
                } else {
                    '#'
                });
            }
            art.push('\n');
        }
        let map = crate::grid::GridMap::from_ascii_scaled(art.trim_end(), 1, 0.05).unwrap();
        World::new(
            map,
            crate::world::Robot::new(0.15),
            Some(crate::geometry::Pose::new(2.25, 2.25, 0.0)),
        )
        .unwrap()
    }

    #[test]
    fn walls_at_an_angle_get_a_turned_lattice() {
        for deg in [0.0, 30.0] {
            let world = turned_room(deg);
            let frame = *world.frame();
            let n = frame.width * frame.height;
            let reach = world.reachable();
            let ok: Vec<bool> = (0..n).map(|i| reach.contains(i)).collect();
            let ctx = Ctx {
                world: &world,
                frame,
                safe: ok.clone(),
                ok,
                rt: 3.0,
            };
            let a = dominant_angles(&ctx)[0].to_degrees();
            // The image's rows run down: a room turned by +30 degrees there has walls at
            // 30 or 60 degrees (mod 90), whichever way the turn is read.
            let off = [deg, 90.0 - deg]
                .iter()
                .map(|d| (a - d).abs().min(90.0 - (a - d).abs()))
                .fold(f64::INFINITY, f64::min);
            assert!(off < 1.5, "{deg}: found {a}");
        }
        // The turned room's plan covers it without contact and with few turns (lanes along
        // its walls, not staircases across them).
        let world = turned_room(30.0);
        let m = run(&world, &BcdOptions::default());
        assert_eq!(m.collisions, 0);
        assert!(m.effective_coverage >= 0.99, "{}", m.effective_coverage);
        // Its plan on the lattice turned to its walls reaches every piece and costs about what
        // the pixel lattice's does (here the pixels' is kept: the room is small).
        let frame = *world.frame();
        let n = frame.width * frame.height;
        let reach = world.reachable();
        let ok: Vec<bool> = (0..n).map(|i| reach.contains(i)).collect();
        let ctx = Ctx {
            world: &world,
            frame,
            safe: ok.clone(),
            ok,
            rt: 3.0,
        };
        let mut search = Search::new(frame.width, frame.height);
        let opts = BcdOptions::default();
        let a = dominant_angles(&ctx)[0];
        let turned = Bcd::plan_on(&ctx, &Lattice::turned(&ctx, a), &opts, &mut search);
        let pixels = Bcd::plan_on(&ctx, &Lattice::pixels(&ctx), &opts, &mut search);
        assert_eq!(turned.0, 0);
        assert!(turned.1 < 1.2 * pixels.1, "{} vs {}", turned.1, pixels.1);
    }

    #[test]
    fn smoothing_straightens_wiggles_but_keeps_corners_and_marks() {
        let world = block_room();
        let frame = *world.frame();
        let n = frame.width * frame.height;
        let ctx = Ctx {
            world: &world,
            frame,
            ok: vec![true; n],
            safe: vec![true; n],
            rt: 4.0,
        };
        // A wiggle of 0.3 px along a free row, then a corner, then a mark.
        let mut items: Vec<Item> = (0..36)
            .map(|i| {
                Item::Move(Point::new(
                    14.0 + 2.0 * f64::from(i),
                    15.0 + 0.3 * f64::from(i % 2),
                ))
            })
            .collect();
        items.push(Item::Move(Point::new(84.0, 25.0)));
        items.push(Item::Mark(Event::BacktrackStart));
        items.push(Item::Move(Point::new(84.0, 35.0)));
        let out = smooth(&ctx, items);
        let pts: Vec<Point> = moves(&out).into_iter().map(|m| m.0).collect();
        assert_eq!(pts.len(), 4, "{pts:?}");
        assert_eq!(pts[0], Point::new(14.0, 15.0));
        assert_eq!(pts[1], Point::new(84.0, 15.3));
        assert_eq!(pts[2], Point::new(84.0, 25.0));
        assert!(matches!(out[3], Item::Mark(Event::BacktrackStart)));
        // A chord within the tolerance that would hit the block (robot radius 4 px) is not taken.
        let around = vec![
            Item::Move(Point::new(20.0, 43.8)),
            Item::Move(Point::new(40.0, 44.25)),
            Item::Move(Point::new(60.0, 43.8)),
        ];
        assert_eq!(moves(&smooth(&ctx, around)).len(), 3);
    }

    #[test]
    fn repair_counts_the_moves_it_cannot_route() {
        let world = block_room();
        let frame = *world.frame();
        let n = frame.width * frame.height;
        let ctx = Ctx {
            world: &world,
            frame,
            ok: vec![true; n],
            safe: vec![true; n],
            rt: 4.0,
        };
        let mut search = Search::new(frame.width, frame.height);
        // A move into the middle of the block has no route: it is dropped and counted, and
        // the plan goes on from where it was.
        let items = vec![
            Item::Move(Point::new(14.0, 15.0)),
            Item::Move(Point::new(40.0, 30.0)),
            Item::Move(Point::new(84.0, 15.0)),
        ];
        let mut skipped = 0;
        let out = repair(&ctx, &mut search, items, &mut skipped);
        let pts: Vec<Point> = moves(&out).into_iter().map(|m| m.0).collect();
        assert_eq!(skipped, 1);
        assert_eq!(pts, vec![Point::new(14.0, 15.0), Point::new(84.0, 15.0)]);
        // A plan whose moves are all reachable counts nothing.
        let mut none = 0;
        let ok = vec![
            Item::Move(Point::new(14.0, 15.0)),
            Item::Move(Point::new(84.0, 45.0)),
        ];
        let routed = moves(&repair(&ctx, &mut search, ok, &mut none));
        assert_eq!(routed.last().map(|m| m.0), Some(Point::new(84.0, 45.0)));
        assert_eq!(none, 0);
    }

    fn run(world: &World, opts: &BcdOptions) -> crate::metrics::Metrics {
        let mut p = Bcd::try_new(world, opts).unwrap();
        let out = crate::sim::simulate(world, &mut p, &crate::sim::SimConfig::default());
        crate::metrics::compute(world, &out, "block_room")
    }

    #[test]
    fn lanes_sit_on_closed_edges_and_on_the_lattice_between() {
        let cell = Cell {
            cols: true,
            u0: 3,
            runs: vec![(0, 9); 20],
        };
        // Both sides closed: lanes on both edges, as few as keep the gaps within 6 lines,
        // evenly spread (the lattice would take 5: 3, 6, 12, 18, 22).
        let l = lanes_of(&cell, 6.0, 0.0, false, false);
        assert_eq!(l, vec![3.0, 7.75, 12.5, 17.25, 22.0]);
        assert!(l.windows(2).all(|w| w[1] - w[0] <= 6.0));
        let l = lanes_of(&cell, 6.0, 2.0, false, false);
        assert_eq!(l, vec![3.0, 7.75, 12.5, 17.25, 22.0]);
        // One closed side: its edge lane, then the lattice.
        assert_eq!(
            lanes_of(&cell, 6.0, 0.0, false, true),
            vec![3.0, 6.0, 12.0, 18.0]
        );
        // Open sides: only the lattice, shared with the neighbours beyond.
        assert_eq!(lanes_of(&cell, 6.0, 0.0, true, true), vec![6.0, 12.0, 18.0]);
        // A lattice line within half a pixel of the edge belongs to this cell.
        assert_eq!(
            lanes_of(&cell, 6.0, 2.6, true, true),
            vec![3.0, 8.6, 14.6, 20.6]
        );
    }

    #[test]
    fn block_room_is_covered_without_contact() {
        let world = block_room();
        let m = run(&world, &BcdOptions::default());
        assert_eq!(m.collisions, 0);
        assert!(m.effective_coverage >= 0.995, "{}", m.effective_coverage);
    }

    #[test]
    fn rim_option_sweeps_what_lanes_miss() {
        // Every missed group swept (the default leaves the least useful 0.3 % of the floor,
        // which in this small room can be all the lanes miss).
        let all = BcdOptions {
            rim_coverage: 1.0,
            ..BcdOptions::default()
        };
        let world = block_room();
        let with = run(&world, &all);
        let without = run(
            &world,
            &BcdOptions {
                rim: false,
                ..all.clone()
            },
        );
        let picky = run(
            &world,
            &BcdOptions {
                rim_min_yield: 1.0,
                ..all
            },
        );
        assert_eq!(with.collisions + without.collisions + picky.collisions, 0);
        assert!(without.effective_coverage < with.effective_coverage);
        assert!(without.path_length_m < with.path_length_m);
        // A yield of a whole lane per metre is never met by a rim contour.
        assert!(picky.effective_coverage < with.effective_coverage);
    }

    #[test]
    fn rim_coverage_trades_rim_passes_for_floor() {
        let world = block_room();
        let full = run(
            &world,
            &BcdOptions {
                rim_coverage: 1.0,
                min_coverage: 1.0,
                ..BcdOptions::default()
            },
        );
        let part = run(
            &world,
            &BcdOptions {
                rim_coverage: 0.98,
                min_coverage: 1.0,
                ..BcdOptions::default()
            },
        );
        assert_eq!(full.collisions + part.collisions, 0);
        assert!(
            full.effective_coverage >= 0.999,
            "{}",
            full.effective_coverage
        );
        // Leaving up to 2 % of the floor saves rim passes, and no more than that is left.
        assert!(part.path_length_m < full.path_length_m);
        assert!(part.effective_coverage < full.effective_coverage);
        assert!(
            part.effective_coverage >= 0.98,
            "{}",
            part.effective_coverage
        );
    }

    #[test]
    fn same_plan_twice() {
        let world = block_room();
        let a = Bcd::new(&world, &BcdOptions::default());
        let b = Bcd::new(&world, &BcdOptions::default());
        assert_eq!(a.steps, b.steps);
        assert_eq!(a.cells(), b.cells());
    }

    #[test]
    fn min_coverage_trades_floor_for_turns_and_holds_it() {
        let world = block_room();
        let keep = run(
            &world,
            &BcdOptions {
                min_coverage: 1.0,
                ..BcdOptions::default()
            },
        );
        let mut last = keep.clone();
        for floor in [0.995, 0.98, 0.95] {
            let m = run(
                &world,
                &BcdOptions {
                    min_coverage: floor,
                    ..BcdOptions::default()
                },
            );
            assert_eq!(m.collisions, 0);
            // The estimate is the metric's own sweep: the floor holds as measured.
            assert!(
                m.effective_coverage >= floor,
                "{floor}: {}",
                m.effective_coverage
            );
            assert!(m.turns <= last.turns && m.path_length_m <= last.path_length_m + 1e-9);
            last = m;
        }
        assert!(last.turns < keep.turns, "{} vs {}", last.turns, keep.turns);
        assert!(last.effective_coverage < keep.effective_coverage);
    }

    #[test]
    fn invalid_options_are_refused() {
        let world = block_room();
        for bad in [
            BcdOptions {
                lane_spacing_m: Some(0.0),
                ..BcdOptions::default()
            },
            BcdOptions {
                margin_px: -1.0,
                ..BcdOptions::default()
            },
            BcdOptions {
                turn_cost_m: f64::NAN,
                ..BcdOptions::default()
            },
            BcdOptions {
                rim_min_yield: 1.5,
                ..BcdOptions::default()
            },
            BcdOptions {
                rim_coverage: -0.1,
                ..BcdOptions::default()
            },
            BcdOptions {
                min_coverage: 1.5,
                ..BcdOptions::default()
            },
        ] {
            let e = Bcd::try_new(&world, &bad).err().unwrap();
            assert!(e.to_string().starts_with("bcd option "), "{e}");
            // The infallible constructor falls back to the defaults and still plans.
            assert!(!Bcd::new(&world, &bad).steps.is_empty());
        }
    }

    #[test]
    fn elongated_cells_lose_their_rounded_ends() {
        // A strip of 20 columns whose first and last two columns reach further down (the
        // rounded C-free corners beside an obstacle): rows 4 and 5 meet it at both ends only,
        // so it is not monotone across as a whole, but its middle is.
        let mut runs = vec![(0, 3); 20];
        runs[0] = (0, 5);
        runs[1] = (0, 4);
        runs[18] = (0, 4);
        runs[19] = (0, 5);
        let strip = Cell {
            cols: true,
            u0: 5,
            runs,
        };
        assert!(strip.transposed().is_none());
        let parts = split_ends(vec![strip.clone()], 4);
        assert_eq!(parts.len(), 3);
        assert_eq!(parts[1].u0, 7);
        assert_eq!(parts[1].runs.len(), 16);
        assert!(parts[1].transposed().is_some());
        // Every line is kept, once.
        let lines: usize = parts.iter().map(|c| c.runs.len()).sum();
        assert_eq!(lines, 20);
        // Ends longer than the limit: the cell stays whole.
        assert_eq!(split_ends(vec![strip], 1).len(), 1);
    }

    #[test]
    fn cells_that_neighbours_lanes_sweep_are_dropped() {
        // A wide cell (columns 0..=19, rows 0..=9) with lanes up to column 19, and a sliver of
        // columns 20..=21 beside it: its pixels are within rt = 3 of the lane at column 19.
        let wide = Cell {
            cols: true,
            u0: 0,
            runs: vec![(0, 9); 20],
        };
        let sliver = Cell {
            cols: true,
            u0: 20,
            runs: vec![(0, 9); 2],
        };
        let far = Cell {
            cols: true,
            u0: 25,
            runs: vec![(0, 9); 2],
        };
        let cells = vec![
            (wide.clone(), vec![0.0, 6.0, 12.0, 19.0]),
            (sliver, vec![21.0]),
            (far, vec![25.0]),
        ];
        let kept = drop_covered(cells, 30, 10, 3.0);
        assert_eq!(kept.len(), 2);
        assert_eq!(kept[0].0.u0, 0);
        assert_eq!(kept[1].0.u0, 25);
        // When the wide cell's lanes end at column 12 (sweeping up to 15), neither cell's
        // lanes sweep all of the other's pixels: both stay.
        let cells = vec![
            (wide, vec![0.0, 6.0, 12.0]),
            (
                Cell {
                    cols: true,
                    u0: 20,
                    runs: vec![(0, 9); 2],
                },
                vec![21.0],
            ),
        ];
        assert_eq!(drop_covered(cells, 30, 10, 3.0).len(), 2);
    }

    /// A room speckled with single-pixel obstacles at scattered offsets (as scanned maps are):
    /// many small cells, some of whose moves the smoothing and pruning merge into their
    /// neighbours'. Every region the plan reports has a move, and regions count 1, 2, ...
    #[test]
    fn every_reported_region_has_moves_and_regions_count_up() {
        let (w, h) = (90usize, 60usize);
        let mut art = String::new();
        let mut seed = 0x5eed_u64;
        for r in 0..h {
            for c in 0..w {
                seed = seed
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                let border = r == 0 || c == 0 || r + 1 == h || c + 1 == w;
                art.push(if border || (seed >> 33).is_multiple_of(97) {
                    '#'
                } else {
                    '.'
                });
            }
            art.push('\n');
        }
        let map = crate::grid::GridMap::from_ascii_scaled(&art, 1, 0.05).unwrap();
        let world = World::new(
            map,
            crate::world::Robot::new(0.1),
            Some(crate::geometry::Pose::new(0.5, 0.5, 0.0)),
        )
        .unwrap();
        let plan = Bcd::new(&world, &BcdOptions::default());
        let (mut open, mut moved, mut ended) = (None, false, 0u32);
        for s in &plan.steps {
            match s {
                Step::Mark(Event::RegionStart { region }) => {
                    assert_eq!(open, None, "region {region} starts inside another");
                    assert_eq!(*region, ended + 1, "regions count up");
                    open = Some(*region);
                    moved = false;
                }
                Step::MoveTo(_) => moved = true,
                Step::Mark(Event::RegionEnd { region }) => {
                    assert_eq!(open.take(), Some(*region));
                    assert!(moved, "region {region} has no move");
                    ended += 1;
                }
                _ => {}
            }
        }
        assert!(
            ended > 5,
            "{ended} regions: the specks should split the room"
        );
    }

    #[test]
    fn abrupt_cells_are_cut_where_the_parts_are_cheaper() {
        // An L: ten long lines (a room), then ninety short ones (a corridor along the lines).
        let mut runs = vec![(0, 99); 10];
        runs.extend(std::iter::repeat_n((90, 99), 90));
        let l = Cell {
            cols: true,
            u0: 5,
            runs,
        };
        // Price: the fewer lines of the two views (lanes), plus one per cell.
        let cost = |c: &Cell| {
            let t = c.transposed().map_or(usize::MAX, |t| t.runs.len());
            c.runs.len().min(t) as f64 + 1.0
        };
        let parts = split_jumps(vec![l.clone()], 3, &cost);
        assert_eq!(parts.len(), 2);
        assert_eq!((parts[0].u0, parts[0].runs.len()), (5, 10));
        assert_eq!((parts[1].u0, parts[1].runs.len()), (15, 90));
        // No cut where the jump is within the tolerance, nor where it does not pay.
        assert_eq!(split_jumps(vec![l.clone()], 90, &cost).len(), 1);
        assert_eq!(
            split_jumps(vec![l], 3, &|c: &Cell| c.runs.len() as f64 + 1.0).len(),
            1
        );
    }

    #[test]
    fn transposed_cell_needs_one_run_per_line() {
        // An L: rows 0-1 span columns 0-3, rows 2-3 only column 0.
        let l = Cell {
            cols: true,
            u0: 0,
            runs: vec![(0, 3), (0, 1), (0, 1), (0, 1)],
        };
        let t = l.transposed().unwrap();
        assert!(!t.cols);
        assert_eq!(t.runs, vec![(0, 3), (0, 3), (0, 0), (0, 0)]);
        // A U (row 1 meets the cell in columns 0 and 2 only) is not monotone across.
        let u = Cell {
            cols: true,
            u0: 0,
            runs: vec![(0, 2), (0, 0), (0, 2)],
        };
        assert!(u.transposed().is_none());
    }
}
