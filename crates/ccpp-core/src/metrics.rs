//! Run metrics, computed from the world (truth) and the trace only — never reported by planners.
//! Definitions: `world-and-metrics.md`; each field below repeats its own.
//!
//! With work zones ([`crate::zones`]) the accessible surface `A` is that of the allowed floor:
//! free pixels inside the area and outside every keep-out, within `r_tool` of a centre the
//! robot can reach without crossing a virtual wall ([`World::accessible`]). Every figure built
//! on `A` (`effective_coverage`, `path_ratio`) is measured against it, not the whole map.

use fixedbitset::FixedBitSet;
use serde::{Deserialize, Serialize};
use std::ops::Sub;

use crate::geometry::{dist_exact, point_segment_dist2, wrap_angle, Point, Pose};
use crate::grid::MapFrame;
pub(crate) use crate::raster::stamp_capsule;
use crate::sim::RunOutput;
use crate::tiles::{reachable_tiles, Tile, TileGrid, TileSet};
use crate::trace::{Chunk, Entry, Event, Lattice, Piece, Trace};
use crate::world::World;

pub use crate::raster::SWEEP_EPS_PX;

/// The metrics of one run (serialized with exactly these keys).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    /// Planner name.
    pub planner: String,
    /// Map name (file stem).
    pub map: String,
    /// Robot radius `r`, metres.
    pub robot_radius_m: f64,
    /// Tool radius `r_tool`, metres.
    pub tool_radius_m: f64,
    /// Tiles whose centre the robot visited / tiles reachable from the start tile by
    /// collision-free 4-neighbour moves (tile planners; `null` otherwise).
    pub coverage_rate: Option<f64>,
    /// `|swept ∩ A| / |A|` in pixels (`A` restricted to the allowed floor when there are
    /// zones).
    pub effective_coverage: f64,
    /// Total translation, metres.
    pub path_length_m: f64,
    /// `path_length_m / (area(A) / (2 r_tool))`: the path length over the length of an ideal
    /// lane-by-lane sweep of all of `A`. Below 1 when the run leaves part of `A` unswept, and
    /// also possible for a complete sweep, because the tool's reach beyond a lane's ends and
    /// into the corners of its turns covers floor that the `2 r_tool`-wide strip model does not
    /// count.
    pub path_ratio: f64,
    /// `path_length_m * 2 r_tool / area(swept) - 1`: the strip area the path would sweep
    /// without any overlap, over the area it did sweep, minus one. Slightly negative for a run
    /// that repeats little, because the half-discs at the path's ends and the wedges outside its
    /// turns add swept area beyond the strip (one straight pass of length `L`:
    /// `-pi r_tool / (2 L + pi r_tool)`); `None` (JSON `null`) for a zero-length path, where the
    /// ratio means nothing.
    pub redundancy: Option<f64>,
    /// `(tile entries - distinct tiles entered) / distinct tiles entered`.
    pub revisit_rate: f64,
    /// Coverage segments started.
    pub regions: u32,
    /// Transfers between regions.
    pub backtracks: u32,
    /// Total length of the transfers, metres.
    pub backtrack_length_m: f64,
    /// In-place rotations (consecutive rotations merged; zero-angle ones not counted).
    pub turns: u32,
    /// Total absolute rotation, radians.
    pub rotation_rad: f64,
    /// Bumper contacts.
    pub collisions: u32,
    /// Entries into a keep-out zone: times the robot's disk, clear of every keep-out pixel,
    /// starts to overlap one (pixels as the disks inscribed in their squares, as for
    /// obstacles; see [`crate::zones::keepout_entries`]), plus exits from the work area
    /// counted alike (its outside is forbidden floor: [`crate::zones::area_exits`]; the
    /// approach from a start outside the area is none); 0 without zones and for a correct
    /// planner. Only forbidden floor counts: zone pixels that are obstacles (or unknown) on
    /// the true map are walls, and touching them is a collision.
    #[serde(default)]
    pub keepout_violations: u32,
    /// Planning + simulation wall time, seconds (the one non-deterministic figure).
    pub wall_time_s: f64,
    /// PID execution only: mean distance of the true pose from the segment it was following
    /// ([`Event::PlannedSegment`]) over every control step ([`Event::Tracking`]), metres.
    /// Absent for ideal execution.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tracking_error_mean_m: Option<f64>,
    /// PID execution only: largest such distance, metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tracking_error_max_m: Option<f64>,
    /// Rectangular-robot lane sweeps only ([`Event::RectLanes`]): seed 001's coverage guarantee
    /// `(b - delta) / b`, with `b` the lane spacing and `delta` the lateral tolerance: the PID
    /// waypoint tolerance ([`Event::Execution`]), 0 under ideal execution; clamped to [0, 1].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rect_guarantee: Option<f64>,
    /// Why the run ended when the planner did not finish it: `stalled` (the robot made no
    /// progress for [`crate::sim::STALL_STEPS`] motions in a row) or `max_steps` (the
    /// simulator's step cap). Absent for a finished run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stop_reason: Option<String>,
}

/// Tracking error of a PID run: `(mean, max)` distance of the true pose from the planned
/// segment in force (the last [`Event::PlannedSegment`]) over every control step, as the
/// simulator's [`Event::Tracking`] gives it; for a trace without one (written before it
/// existed, or cut short), over the pose records; `None` when the trace has no planned
/// segment (ideal execution).
pub fn tracking_error(trace: &Trace) -> Option<(f64, f64)> {
    let given = trace.events().fold(None, |last, (_, e)| match e {
        Event::Tracking { mean_m, max_m, .. } => Some((*mean_m, *max_m)),
        _ => last,
    });
    if given.is_some() {
        return given;
    }
    pose_tracking(trace).map(|(mean, max, _)| (mean, max))
}

/// The tracking error measured on the trace's poses: `(mean, max, poses measured)`, each pose
/// against the last [`Event::PlannedSegment`] before it; `None` without a planned segment.
fn pose_tracking(trace: &Trace) -> Option<(f64, f64, u64)> {
    // Without a planned segment no pose counts (the events alone tell, without the poses).
    if !trace
        .events()
        .any(|(_, e)| matches!(e, Event::PlannedSegment { .. }))
    {
        return None;
    }
    let mut seg: Option<(Point, Point)> = None;
    let (mut sum, mut max, mut n) = (0.0, 0.0f64, 0u64);
    for r in trace.entries() {
        match r {
            Entry::Event {
                event: Event::PlannedSegment { from, to },
                ..
            } => seg = Some((Point::new(from[0], from[1]), Point::new(to[0], to[1]))),
            Entry::Pose { pose, .. } => {
                if let Some((a, b)) = seg {
                    let d = crate::geometry::point_segment_dist(pose.position(), a, b);
                    sum += d;
                    max = max.max(d);
                    n += 1;
                }
            }
            Entry::Event { .. } => {}
        }
    }
    seg?;
    Some((if n == 0 { 0.0 } else { sum / n as f64 }, max, n))
}

/// What is wrong with the trace's [`Event::Tracking`] record, if anything: a reader that takes
/// the tracking error from it (`ccpp replay`'s check of a run folder) first makes sure that it
/// can be the simulator's. At most one, right before the `finished` record, in a run under
/// PID execution with a planned segment; finite, non-negative figures with the mean at most
/// the largest (both 0 over 0 steps); at least as many steps as poses recorded from the first
/// planned segment on, and a largest distance no smaller than any of theirs (the recorded
/// poses are some of the steps it measured). `None` for a trace without the record.
pub fn tracking_record_problem(trace: &Trace) -> Option<String> {
    let events: Vec<&Event> = trace.events().map(|(_, e)| e).collect();
    let at: Vec<usize> = (0..events.len())
        .filter(|&k| matches!(events[k], Event::Tracking { .. }))
        .collect();
    let &k = at.first()?;
    if at.len() > 1 {
        return Some(format!("{} tracking records (a run writes one)", at.len()));
    }
    if k + 2 != events.len() || !matches!(events[k + 1], Event::Finished { .. }) {
        return Some("the tracking record is not the last before `finished`".into());
    }
    let Event::Tracking {
        mean_m,
        max_m,
        steps,
    } = *events[k]
    else {
        return None;
    };
    if !events
        .iter()
        .any(|e| matches!(e, Event::Execution { mode, .. } if mode == "pid"))
    {
        return Some("a tracking record in a run without PID execution".into());
    }
    if !(mean_m.is_finite() && max_m.is_finite() && mean_m >= 0.0 && max_m >= 0.0) {
        return Some(format!(
            "tracking figures {mean_m} / {max_m} m are not distances"
        ));
    }
    // A mean of distances is at most the largest (the division may round it a few ulps up).
    if mean_m > max_m * (1.0 + 1e-12) {
        return Some(format!(
            "a mean tracking error of {mean_m} m above the largest, {max_m} m"
        ));
    }
    if steps == 0 && (mean_m != 0.0 || max_m != 0.0) {
        return Some(format!("tracking errors {mean_m} / {max_m} m over 0 steps"));
    }
    // The recorded poses: the record's figures must hold for them.
    let Some((_, rec_max, rec_n)) = pose_tracking(trace) else {
        return Some("a tracking record in a run without a planned segment".into());
    };
    if rec_n > steps {
        return Some(format!(
            "{rec_n} poses measured against planned segments but a tracking record of {steps} steps"
        ));
    }
    if rec_max > max_m * (1.0 + 1e-9) + 1e-12 {
        return Some(format!(
            "a recorded pose lies {rec_max} m from its planned segment but the tracking record's \
             largest distance is {max_m} m"
        ));
    }
    None
}

/// The PID waypoint tolerance recorded in the trace ([`Event::Execution`]), if any.
pub fn execution_tolerance(trace: &Trace) -> Option<f64> {
    execution_of(trace).map(|(t, _)| t)
}

/// How near (in tiles) the true path must pass a tile centre for the tile to count visited
/// under odometry noise ([`noisy_execution`]): half a tile.
pub const NOISY_TILE_VISIT_TILES: f64 = 0.5;

/// Whether odometry noise perturbed the run (its `execution` event says `noisy`): a tile
/// centre then counts visited within half a tile of the true path (`coverage_rate`; the
/// replay's tile outlines follow the same rule).
pub fn noisy_execution(trace: &Trace) -> bool {
    execution_of(trace).is_some_and(|(_, noisy)| noisy)
}

/// The PID waypoint tolerance of a run and whether odometry noise perturbed it.
fn execution_of(trace: &Trace) -> Option<(f64, bool)> {
    trace.events().find_map(|(_, e)| match e {
        Event::Execution {
            tolerance_m, noisy, ..
        } => Some((*tolerance_m, *noisy)),
        _ => None,
    })
}

/// The points of the executed centre polyline (grid coordinates) that trace piece `piece`
/// adds, to `add`: a pose's position, a straight run's two ends (its poses lie in order on
/// the segment between them, so the capsules of its steps make up that segment's capsule),
/// nothing for an event.
fn piece_points(
    frame: &MapFrame,
    lattice: Option<Lattice>,
    piece: Piece<'_>,
    mut add: impl FnMut(Point),
) {
    match piece {
        Piece::Pose { pose, .. } => add(frame.world_to_grid(pose.position())),
        Piece::Run(run) => {
            let [x0, y0] = run.from;
            let [x1, y1] = run.to(lattice);
            add(frame.world_to_grid(Point::new(x0, y0)));
            add(frame.world_to_grid(Point::new(x1, y1)));
        }
        Piece::Event { .. } => {}
    }
}

/// The swept pixels of a trace: pixel centres within `r_tool` of the executed centre polyline
/// (inclusive, with [`SWEEP_EPS_PX`]). The start position alone sweeps a disk.
pub fn swept_pixels(world: &World, trace: &Trace) -> FixedBitSet {
    let frame = *world.frame();
    let rt = world.robot().tool_radius / frame.resolution + SWEEP_EPS_PX;
    // The executed polyline with each straight run of the trace reduced to its two ends: a
    // run's poses lie in order on the segment between its ends, so the capsules of its steps
    // make up the capsule of that segment.
    let lattice = trace.lattice();
    let mut points: Vec<Point> = Vec::with_capacity(trace.piece_count() + 1);
    for piece in trace.pieces() {
        piece_points(&frame, lattice, piece, |g| points.push(g));
    }
    // Segments between consecutive distinct points (a lone first point sweeps its disk).
    let sweep = |pts: &[Point], first: bool| {
        let mut swept = FixedBitSet::with_capacity(frame.len());
        if first {
            if let Some(&g) = pts.first() {
                stamp_capsule(&mut swept, &frame, g, g, rt, &mut |_| {});
            }
        }
        for w in pts.windows(2) {
            if w[0] != w[1] {
                stamp_capsule(&mut swept, &frame, w[0], w[1], rt, &mut |_| {});
            }
        }
        swept
    };
    // Long traces: two halves on two threads (sharing the middle point), then the union.
    if points.len() < 1 << 14 {
        return sweep(&points, true);
    }
    let mid = points.len() / 2;
    std::thread::scope(|s| {
        let second = s.spawn(|| sweep(&points[mid..], false));
        let mut swept = sweep(&points[..=mid], true);
        match second.join() {
            Ok(b) => swept.union_with(&b),
            Err(panic) => std::panic::resume_unwind(panic),
        }
        swept
    })
}

/// [`swept_pixels`] fed a trace piece by piece (the [`Chunk`]s of a trace taken while the run
/// goes on, in order): the same pixels.
pub struct TraceSweep {
    frame: MapFrame,
    /// Tool radius in pixels, with [`SWEEP_EPS_PX`].
    rt: f64,
    swept: FixedBitSet,
    /// The last point of the executed polyline (grid coordinates).
    last: Option<Point>,
}

impl TraceSweep {
    /// Nothing swept yet, in `world`.
    pub fn new(world: &World) -> Self {
        let frame = *world.frame();
        Self {
            frame,
            rt: world.robot().tool_radius / frame.resolution + SWEEP_EPS_PX,
            swept: FixedBitSet::with_capacity(frame.len()),
            last: None,
        }
    }

    /// The next point of the polyline: the first sweeps its disk, each other one the segment
    /// from the point before when they differ.
    fn point(&mut self, g: Point) {
        let from = match self.last {
            None => g,
            Some(l) if l != g => l,
            Some(_) => return,
        };
        stamp_capsule(&mut self.swept, &self.frame, from, g, self.rt, &mut |_| {});
        self.last = Some(g);
    }

    /// The pieces of `chunk`, in order.
    pub fn chunk(&mut self, chunk: &Chunk) {
        let (frame, lattice) = (self.frame, chunk.lattice());
        for piece in chunk.pieces() {
            piece_points(&frame, lattice, piece, |g| self.point(g));
        }
    }

    /// The swept pixels.
    pub fn finish(self) -> FixedBitSet {
        self.swept
    }
}

/// Incremental sweeping: add executed segments one by one and read the swept pixels so far.
pub struct Sweeper<'w> {
    world: &'w World,
    swept: FixedBitSet,
    rt: f64,
}

impl<'w> Sweeper<'w> {
    /// Nothing swept yet.
    pub fn new(world: &'w World) -> Self {
        let f = world.frame();
        Self {
            world,
            swept: FixedBitSet::with_capacity(f.len()),
            rt: world.robot().tool_radius / f.resolution + SWEEP_EPS_PX,
        }
    }

    /// Sweeps the segment `a`-`b` (world points; `a == b` sweeps a disk).
    pub fn add(&mut self, a: Point, b: Point) {
        let f = *self.world.frame();
        stamp_capsule(
            &mut self.swept,
            &f,
            f.world_to_grid(a),
            f.world_to_grid(b),
            self.rt,
            &mut |_| {},
        );
    }

    /// The swept pixels so far.
    pub fn swept(&self) -> &FixedBitSet {
        &self.swept
    }
}

/// Effective coverage as the path unrolls: points `[distance_m, coverage]` at the start and
/// after each travelled `total / samples` metres (and at the end), for coverage-over-distance
/// plots.
pub fn coverage_curve(world: &World, trace: &Trace, samples: usize) -> Vec<[f64; 2]> {
    coverage_curve_and_swept(world, trace, samples).0
}

/// [`coverage_curve`] and the pixels the whole path swept (whose centres lie within the swept
/// radius of a move), from the one sweep.
pub fn coverage_curve_and_swept(
    world: &World,
    trace: &Trace,
    samples: usize,
) -> (Vec<[f64; 2]>, FixedBitSet) {
    let frame = *world.frame();
    let acc = world.accessible();
    let a_count = world.accessible_count().max(1) as f64;
    let rt = world.robot().tool_radius / frame.resolution + SWEEP_EPS_PX;
    let poses: Vec<Pose> = trace.poses().collect();
    let Some(first) = poses.first() else {
        return (Vec::new(), FixedBitSet::with_capacity(frame.len()));
    };
    let total: f64 = poses
        .windows(2)
        .map(|w| w[0].position().dist(w[1].position()))
        .sum();
    let step = if samples == 0 || total == 0.0 {
        f64::INFINITY
    } else {
        total / samples as f64
    };
    let mut swept = FixedBitSet::with_capacity(frame.len());
    let covered = std::cell::Cell::new(0usize);
    let mut on_new = |i: usize| {
        if acc.contains(i) {
            covered.set(covered.get() + 1);
        }
    };
    let g0 = frame.world_to_grid(first.position());
    stamp_capsule(&mut swept, &frame, g0, g0, rt, &mut on_new);
    let mut out = vec![[0.0, covered.get() as f64 / a_count]];
    let mut travelled = 0.0;
    let mut next_mark = step;
    for w in poses.windows(2) {
        let (a, b) = (w[0].position(), w[1].position());
        if a == b {
            continue;
        }
        let (ga, gb) = (frame.world_to_grid(a), frame.world_to_grid(b));
        stamp_capsule(&mut swept, &frame, ga, gb, rt, &mut on_new);
        travelled += a.dist(b);
        if travelled + 1e-9 >= next_mark {
            while next_mark <= travelled + 1e-9 {
                next_mark += step;
            }
            out.push([travelled, covered.get() as f64 / a_count]);
        }
    }
    if out.last().is_some_and(|l| l[0] < travelled) {
        out.push([travelled, covered.get() as f64 / a_count]);
    }
    (out, swept)
}

/// Tile boundaries of the revisit walk lie this far (in tiles) below the half-way lines:
/// tile `k` spans `[k - 0.5 - BOUNDARY_SHIFT, k + 0.5 - BOUNDARY_SHIFT)` along each axis. A
/// path along a boundary (a lane half a tile from the start's lattice) then lies inside one
/// tile whatever the rounding of its coordinates, which moved a point exactly on the line to
/// one side or the other when the map was moved: `revisit_rate` of bcd on `aws_small_house`
/// went from 0.340 to 0.405 with the map's origin moved by (+500 km, +5400 km), the same path.
const BOUNDARY_SHIFT: f64 = 1e-6;

/// The tile of `p` on the revisit walk's boundaries ([`BOUNDARY_SHIFT`]).
fn walk_tile(grid: &TileGrid, p: Point) -> Tile {
    let at = |v: f64, o: f64| {
        let k = ((v - o) / grid.side + 0.5 + BOUNDARY_SHIFT).floor();
        k.clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32
    };
    (at(p.x, grid.anchor.x), at(p.y, grid.anchor.y))
}

/// Tile entries along a polyline (Amanatides-Woo traversal), fed one point at a time; a
/// corner crossing is one entry. Boundaries as [`walk_tile`] draws them.
struct TileWalk {
    /// The tile of the last point and the last point (`None` before the first).
    at: Option<(Tile, Point)>,
}

impl TileWalk {
    /// Visits the tiles entered on the way to `b` (the first point's own tile for the first).
    fn to(&mut self, grid: &TileGrid, b: Point, mut visit: impl FnMut(Tile)) {
        let Some((mut cur, a)) = self.at else {
            let t = walk_tile(grid, b);
            visit(t);
            self.at = Some((t, b));
            return;
        };
        if a == b {
            return;
        }
        let target = walk_tile(grid, b);
        // Fast paths, the same visits as the traversal below: staying in the tile visits
        // nothing, and an axis-parallel move (one coordinate equal bit for bit, so the other
        // component of the direction is exactly 0) into the next tile along that axis crosses
        // exactly one boundary, visiting that tile (the traversal's one step, or its fallback).
        if target == cur {
            self.at = Some((cur, b));
            return;
        }
        let along_x = a.y == b.y && target.1 == cur.1 && (target.0 - cur.0).abs() == 1;
        let along_y = a.x == b.x && target.0 == cur.0 && (target.1 - cur.1).abs() == 1;
        if along_x || along_y {
            visit(target);
            self.at = Some((target, b));
            return;
        }
        // Positions in tile units, tile (i, j) spans [i - 0.5, i + 0.5].
        let ua = Point::new(
            (a.x - grid.anchor.x) / grid.side,
            (a.y - grid.anchor.y) / grid.side,
        );
        let ub = Point::new(
            (b.x - grid.anchor.x) / grid.side,
            (b.y - grid.anchor.y) / grid.side,
        );
        let d = ub.sub(ua);
        let step_i = if d.x > 0.0 { 1 } else { -1 };
        let step_j = if d.y > 0.0 { 1 } else { -1 };
        let next_boundary =
            |u: f64, i: i32, s: i32| f64::from(i) + 0.5 * f64::from(s) - BOUNDARY_SHIFT - u;
        let mut t_max_x = if d.x == 0.0 {
            f64::INFINITY
        } else {
            next_boundary(ua.x, cur.0, step_i) / d.x
        };
        let mut t_max_y = if d.y == 0.0 {
            f64::INFINITY
        } else {
            next_boundary(ua.y, cur.1, step_j) / d.y
        };
        let t_dx = if d.x == 0.0 {
            f64::INFINITY
        } else {
            1.0 / d.x.abs()
        };
        let t_dy = if d.y == 0.0 {
            f64::INFINITY
        } else {
            1.0 / d.y.abs()
        };
        let mut guard = 0usize;
        while cur != target && guard < 10_000_000 {
            guard += 1;
            // A corner crossing within a tenth of the boundaries' shift (in tiles) of the
            // corner: rounding of far-out coordinates (1e-9 m at 5e6 m) stays below it.
            let tie = (t_max_x - t_max_y).abs() * d.x.abs().max(d.y.abs()) < 0.1 * BOUNDARY_SHIFT;
            if tie {
                if t_max_x > 1.0 + 1e-9 {
                    break;
                }
                cur = (cur.0 + step_i, cur.1 + step_j);
                t_max_x += t_dx;
                t_max_y += t_dy;
            } else if t_max_x < t_max_y {
                if t_max_x > 1.0 + 1e-9 {
                    break;
                }
                cur.0 += step_i;
                t_max_x += t_dx;
            } else {
                if t_max_y > 1.0 + 1e-9 {
                    break;
                }
                cur.1 += step_j;
                t_max_y += t_dy;
            }
            visit(cur);
        }
        if cur != target {
            cur = target;
            visit(cur);
        }
        self.at = Some((cur, b));
    }
}

/// Computes all metrics of a run.
pub fn compute(world: &World, run: &RunOutput, map_name: &str) -> Metrics {
    compute_swept(world, run, map_name).0
}

/// [`compute`], also returning the swept pixels it computed ([`swept_pixels`]), for the
/// coverage picture to reuse instead of sweeping the trace again.
pub fn compute_swept(world: &World, run: &RunOutput, map_name: &str) -> (Metrics, FixedBitSet) {
    compute_prepared(world, run, map_name, None)
}

/// What the metrics read of the world alone, before any run: the accessible surface (kept in
/// the world) and the tiles reachable on a tiling of a given side. A caller computes it while
/// the planner works (on a second thread), so that [`compute_prepared`] has less left to do.
#[derive(Clone, Debug)]
pub struct WorldPart {
    /// The tile side the reachable tiles are for, metres.
    side: f64,
    /// [`reachable_tiles`] on the tiling of `side` anchored at the world's start.
    reach: TileSet,
}

impl WorldPart {
    /// Computes the accessible surface of `world` and, with a `tile_side`, its reachable tiles
    /// on that tiling (the planner's, when it has one).
    pub fn of(world: &World, tile_side: Option<f64>) -> Option<Self> {
        let _ = world.accessible();
        tile_side.map(|side| Self {
            side,
            reach: reachable_tiles(world, &TileGrid::new(world.start().position(), side)),
        })
    }
}

/// [`compute_swept`] reusing `part` ([`WorldPart::of`] of the same world) when it was computed
/// for the run's tile side (it is computed here otherwise): the same metrics.
pub fn compute_prepared(
    world: &World,
    run: &RunOutput,
    map_name: &str,
    part: Option<WorldPart>,
) -> (Metrics, FixedBitSet) {
    compute_prepared_with(world, run, map_name, part, None, None)
}

/// [`compute_prepared`] with the swept pixels when the caller has them (they must be
/// [`swept_pixels`] of the run's trace, as a [`TraceSweep`] fed the whole trace finds them)
/// and a [`MotionTally`] fed the whole trace.
pub fn compute_prepared_with(
    world: &World,
    run: &RunOutput,
    map_name: &str,
    part: Option<WorldPart>,
    swept: Option<FixedBitSet>,
    tally: Option<MotionTally>,
) -> (Metrics, FixedBitSet) {
    let frame = *world.frame();
    let robot = world.robot();
    let trace = &run.trace;
    let px_area = frame.resolution * frame.resolution;
    let start = world.start().position();
    let two_rt = 2.0 * robot.tool_radius;
    // The swept pixels and the tile coverage are independent of the rest: on other threads.
    std::thread::scope(|scope| {
        let sweeping = swept
            .is_none()
            .then(|| scope.spawn(|| swept_pixels(world, trace)));
        let coverage_rate = scope.spawn(|| {
            // Under PID execution a tile centre counts as visited within the waypoint tolerance;
            // under odometry noise within half a tile of the true path: the robot reaches its
            // waypoints by its estimate, and its true path missed nearly every centre by more
            // than the tolerance (`coverage_rate` 0.009 at 1e-4 relative noise, with
            // `effective_coverage` 0.89).
            let exec = execution_of(trace);
            run.tile_side.map(|side| {
                let exec_tol = exec.map(|(t, noisy)| {
                    if noisy {
                        t.max(NOISY_TILE_VISIT_TILES * side)
                    } else {
                        t
                    }
                });
                let grid = TileGrid::new(start, side);
                let reach = match part {
                    Some(p) if p.side.to_bits() == side.to_bits() => p.reach,
                    _ => reachable_tiles(world, &grid),
                };
                if reach.is_empty() {
                    return 0.0;
                }
                let visited = visited_tile_centres(&grid, trace, &reach, exec_tol);
                visited as f64 / reach.len() as f64
            })
        });
        let mut m = compute_rest(world, run, map_name, tally);
        let swept: FixedBitSet = match swept {
            Some(swept) => swept,
            None => sweeping.map_or_else(|| swept_pixels(world, trace), join),
        };
        m.coverage_rate = join(coverage_rate);
        let swept_count = swept.count_ones(..);
        let covered = swept.intersection(world.accessible()).count();
        let a_count = world.accessible_count();
        m.effective_coverage = if a_count == 0 {
            0.0
        } else {
            covered as f64 / a_count as f64
        };
        let area_a = a_count as f64 * px_area;
        m.path_ratio = if area_a > 0.0 {
            m.path_length_m / (area_a / two_rt)
        } else {
            0.0
        };
        let swept_area = swept_count as f64 * px_area;
        let path_length = m.path_length_m;
        m.redundancy = (path_length > 0.0 && swept_area > 0.0)
            .then(|| path_length * two_rt / swept_area - 1.0);
        (m, swept)
    })
}

/// The result of a scoped thread (its panic passed on).
fn join<T>(h: std::thread::ScopedJoinHandle<'_, T>) -> T {
    match h.join() {
        Ok(v) => v,
        Err(panic) => std::panic::resume_unwind(panic),
    }
}

/// The figures of the metrics that follow the poses and events one by one: path length,
/// turns, rotation; regions, backtracks, collisions, backtrack length (poses between start and
/// end marks); tile entries for the revisit rate, on the conventions' tiles (side `2 r`, the
/// robot's radius, anchored at the start) whatever the planner's own tiling, so that every
/// planner's figure is on one grid (bcd's was on tiles of `2 r_tool`, ba-star's on its own). Fed
/// the trace's pieces in order, in one go or chunk by chunk while the run goes on (the same
/// figures).
pub struct MotionTally {
    grid: TileGrid,
    distinct: TileSet,
    entries: usize,
    walk: TileWalk,
    path_length: f64,
    turns: u32,
    rotation: f64,
    in_turn: bool,
    regions: u32,
    backtracks: u32,
    collisions: u32,
    backtrack_length: f64,
    in_backtrack: bool,
    prev: Option<Pose>,
}

impl MotionTally {
    /// Nothing counted yet, in `world`.
    pub fn new(world: &World) -> Self {
        let side = 2.0 * world.robot().radius;
        let grid = TileGrid::new(world.start().position(), side);
        let (i0, i1, j0, j1) = grid.bounds_for(world);
        Self {
            grid,
            distinct: TileSet::new(i0, i1, j0, j1),
            entries: 0,
            walk: TileWalk { at: None },
            path_length: 0.0,
            turns: 0,
            rotation: 0.0,
            in_turn: false,
            regions: 0,
            backtracks: 0,
            collisions: 0,
            backtrack_length: 0.0,
            in_backtrack: false,
            prev: None,
        }
    }

    /// The next pose; `tile`: the tile entered, when known (a lattice run's step to the next
    /// tile along an axis, where the walk visits exactly that tile).
    fn pose(&mut self, b: Pose, tile: Option<Tile>) {
        if let Some(a) = self.prev {
            let d = dist_exact(a.position(), b.position());
            if self.in_backtrack {
                self.backtrack_length += d;
            }
            if d > 0.0 {
                self.path_length += d;
                self.in_turn = false;
            } else {
                let ang = wrap_angle(b.theta - a.theta).abs();
                if ang > crate::sim::MIN_ROTATION {
                    self.rotation += ang;
                    if !self.in_turn {
                        self.turns += 1;
                        self.in_turn = true;
                    }
                }
            }
        }
        if let Some(t) = tile {
            self.entries += 1;
            self.distinct.insert(t);
            self.walk.at = Some((t, b.position()));
        } else {
            let (entries, distinct) = (&mut self.entries, &mut self.distinct);
            self.walk.to(&self.grid, b.position(), |t| {
                *entries += 1;
                distinct.insert(t);
            });
        }
        self.prev = Some(b);
    }

    /// The next pieces of the trace, in order (`lattice`: the trace's).
    pub fn pieces<'a>(
        &mut self,
        pieces: impl Iterator<Item = Piece<'a>>,
        lattice: Option<crate::trace::Lattice>,
    ) {
        for piece in pieces {
            match piece {
                Piece::Pose { pose, .. } => self.pose(pose, None),
                Piece::Run(run) => {
                    // On the metrics' own tiling a lattice run's poses after its first enter
                    // its tiles one by one (see `lattice_tiles`; the walk would find the same).
                    let tiles = lattice_tiles(&run, lattice, &self.grid);
                    for (k, (_, pose)) in run.poses(lattice).enumerate() {
                        let tile = tiles.filter(|_| k > 0).and_then(|((i, j), (di, dj))| {
                            let k = i32::try_from(k).ok()?;
                            Some((i + k * di, j + k * dj))
                        });
                        self.pose(pose, tile);
                    }
                }
                Piece::Event { event, .. } => match event {
                    Event::RegionStart { .. } => self.regions += 1,
                    Event::BacktrackStart => {
                        self.backtracks += 1;
                        self.in_backtrack = true;
                    }
                    Event::BacktrackEnd => self.in_backtrack = false,
                    Event::Collision { .. } => self.collisions += 1,
                    _ => {}
                },
            }
        }
    }

    /// The pieces of `chunk` (the next ones of the trace).
    pub fn chunk(&mut self, chunk: &Chunk) {
        self.pieces(chunk.pieces(), chunk.lattice());
    }
}

/// The metrics that follow the poses and events one by one (all but the swept area and the
/// tile coverage, left at 0 / `None`); `tally`, when given, must be a [`MotionTally`] fed the
/// whole trace.
fn compute_rest(
    world: &World,
    run: &RunOutput,
    map_name: &str,
    tally: Option<MotionTally>,
) -> Metrics {
    let robot = world.robot();
    let trace = &run.trace;
    let tally = tally.unwrap_or_else(|| {
        let mut t = MotionTally::new(world);
        t.pieces(trace.pieces(), trace.lattice());
        t
    });
    let MotionTally {
        distinct,
        entries,
        path_length,
        turns,
        rotation,
        regions,
        backtracks,
        collisions,
        backtrack_length,
        ..
    } = tally;
    let nd = distinct.len();
    let revisit_rate = if nd == 0 {
        0.0
    } else {
        (entries - nd) as f64 / nd as f64
    };

    let exec = execution_of(trace);
    let keepout_violations = world.zones().map_or(0, |z| {
        let frame = *world.frame();
        let pts: Vec<Point> = trace
            .poses()
            .map(|p| frame.world_to_grid(p.position()))
            .collect();
        let r_px = robot.radius / frame.resolution;
        // Only forbidden *floor* counts: a zone pixel that is an obstacle on the true map is a
        // wall, and touching it is a collision, counted as one (a bump into a wall the area's
        // border ran behind also counted as an exit from the area: 11 "violations" against 3
        // with the border drawn just beyond the wall, same run: hostile pass).
        let walls = world.true_blocked();
        let mut keepout = z.keepout.clone();
        keepout.difference_with(walls);
        let entries = crate::zones::keepout_entries(&frame, &keepout, &pts, r_px);
        let exits = z.area.as_ref().map_or(0, |area| {
            let mut area = area.clone();
            area.union_with(walls);
            // From the end of the approach to the area (driven from a start outside it, not
            // by the planner): the first pose at the start the planner began from.
            let begin = frame.world_to_grid(world.start().position());
            let from = pts
                .iter()
                .position(|p| p.x == begin.x && p.y == begin.y)
                .unwrap_or(0);
            crate::zones::area_exits(&frame, &area, &pts[from..], r_px)
        });
        entries + exits
    });
    let tracking = tracking_error(trace);
    let rect_guarantee = trace.events().find_map(|(_, e)| match e {
        Event::RectLanes { width_m, .. } if *width_m > 0.0 => {
            // The seed's lateral tolerance: the waypoint tolerance, and under odometry noise
            // the measured largest deviation of the true path from the planned segments
            // (the tolerance alone promised 0.999997 beside 0.72 swept at 0.05 noise).
            let delta = match exec {
                Some((t, true)) => t.max(tracking.map_or(0.0, |(_, max)| max)),
                Some((t, false)) => t,
                None => 0.0,
            };
            Some(((width_m - delta) / width_m).clamp(0.0, 1.0))
        }
        _ => None,
    });
    Metrics {
        planner: run.planner.to_string(),
        map: map_name.to_string(),
        robot_radius_m: robot.radius,
        tool_radius_m: robot.tool_radius,
        coverage_rate: None,
        effective_coverage: 0.0,
        path_length_m: path_length,
        path_ratio: 0.0,
        redundancy: None,
        revisit_rate,
        regions,
        backtracks,
        backtrack_length_m: backtrack_length,
        turns,
        rotation_rad: rotation,
        collisions,
        keepout_violations,
        wall_time_s: run.wall_time_s,
        tracking_error_mean_m: tracking.map(|t| t.0),
        tracking_error_max_m: tracking.map(|t| t.1),
        rect_guarantee,
        stop_reason: (run.stop != crate::sim::StopReason::Done)
            .then(|| run.stop.as_str().to_string()),
    }
}

/// Number of tiles of `reach` whose centre lies on the executed polyline (within 1e-6 tile, or
/// within the PID waypoint tolerance `tol` when given).
fn visited_tile_centres(
    grid: &TileGrid,
    trace: &Trace,
    reach: &TileSet,
    tol: Option<f64>,
) -> usize {
    let eps = (1e-6 * grid.side).max(tol.map_or(0.0, |t| t + 1e-9));
    // A tolerance may reach one tile beyond the segment's own tiles.
    let m = i32::from(eps > 0.25 * grid.side);
    let (i0, i1, j0, j1) = reach.bounds();
    let mut v = Visits {
        grid,
        reach,
        eps,
        m,
        hit: TileSet::new(i0, i1, j0, j1),
        prev: None,
    };
    let lattice = trace.lattice();
    for piece in trace.pieces() {
        match piece {
            Piece::Pose { pose, .. } => v.pose(pose.position()),
            Piece::Run(run) => match (m, lattice_tiles(&run, lattice, grid)) {
                (0, Some((t0, (di, dj)))) => {
                    // Each step's box holds its two tiles only (no tolerance margin), both
                    // visited: the step starts on the one's centre and ends on the other's.
                    v.pose(Point::new(run.from[0], run.from[1]));
                    let mut t = t0;
                    for _ in 0..run.n {
                        if reach.contains(t) {
                            v.hit.insert(t);
                        }
                        t = (t.0 + di, t.1 + dj);
                    }
                    let [x, y] = run.to(lattice);
                    v.prev = Some((Point::new(x, y), (t.0 - di, t.1 - dj)));
                }
                _ => {
                    for (_, pose) in run.poses(lattice) {
                        v.pose(pose.position());
                    }
                }
            },
            Piece::Event { .. } => {}
        }
    }
    v.hit.len()
}

/// The state of [`visited_tile_centres`].
struct Visits<'a> {
    grid: &'a TileGrid,
    reach: &'a TileSet,
    /// Visit tolerance, metres.
    eps: f64,
    /// Tile margin around a segment's tiles.
    m: i32,
    /// The visited tiles of `reach` (a visited tile outside it is not counted).
    hit: TileSet,
    /// The previous position and its tile.
    prev: Option<(Point, Tile)>,
}

impl Visits<'_> {
    /// Marks the tile centres visited on the way from the previous position to `b`.
    fn pose(&mut self, b: Point) {
        let (grid, eps, m) = (self.grid, self.eps, self.m);
        let Some((a, ta)) = self.prev else {
            let t = grid.tile_of(b);
            if grid.center(t).dist(b) <= eps && self.reach.contains(t) {
                self.hit.insert(t);
            }
            self.prev = Some((b, t));
            return;
        };
        if a == b {
            return;
        }
        let tb = grid.tile_of(b);
        self.prev = Some((b, tb));
        for j in ta.1.min(tb.1) - m..=ta.1.max(tb.1) + m {
            for i in ta.0.min(tb.0) - m..=ta.0.max(tb.0) + m {
                // A tile already visited stays so (the segment's first tile usually is).
                if !self.hit.contains((i, j))
                    && self.reach.contains((i, j))
                    && point_segment_dist2(grid.center((i, j)), a, b) <= eps * eps
                {
                    self.hit.insert((i, j));
                }
            }
        }
    }
}

/// The first tile and the step of a lattice run whose poses are exactly centres of `grid`
/// (the trace's lattice is the grid: same anchor and side, bit for bit) moving one tile along
/// an axis per pose, and small enough (indices and anchor within `1e6` tiles) that the tile
/// of each pose is its lattice index and a step's end lies within `1e-9` tile of the segment
/// it ends; `None` otherwise.
fn lattice_tiles(
    run: &crate::trace::Run,
    lattice: Option<crate::trace::Lattice>,
    grid: &TileGrid,
) -> Option<(Tile, Tile)> {
    let l = lattice?;
    let crate::trace::Advance::Lattice { i, j, di, dj } = run.advance else {
        return None;
    };
    let same = l.anchor[0] == grid.anchor.x && l.anchor[1] == grid.anchor.y && l.side == grid.side;
    let bound = 1e6 * grid.side;
    let small = l.anchor[0].abs() < bound && l.anchor[1].abs() < bound;
    let k = i64::from(run.n) - 1;
    let ends = [
        i64::from(i),
        i64::from(j),
        i64::from(i) + k * i64::from(di),
        i64::from(j) + k * i64::from(dj),
    ];
    let in_range = ends.iter().all(|e| e.abs() < 1_000_000);
    (same && small && in_range && di.abs() + dj.abs() == 1 && grid.side > 0.0)
        .then_some(((i, j), (di, dj)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridMap;
    use crate::planner::{Planner, Sensor, Step};
    use crate::sim::{simulate, SimConfig};
    use crate::world::Robot;

    /// `stamp_capsule` marks exactly the pixel centres within `rt` of the segment, for random
    /// segments (any direction, zero length, partly off the image) and radii down to a pixel.
    #[test]
    fn stamp_capsule_equals_brute_force() {
        let frame = crate::grid::MapFrame {
            width: 40,
            height: 30,
            resolution: 0.05,
            origin: Pose::new(0.0, 0.0, 0.0),
        };
        let mut rng = crate::rng::SplitMix64::new(7);
        for case in 0..4000 {
            let a = Point::new(rng.range(-3.0, 43.0), rng.range(-3.0, 33.0));
            let b = match case % 4 {
                0 => a,
                1 => Point::new(rng.range(-3.0, 43.0), a.y),
                2 => Point::new(a.x, rng.range(-3.0, 33.0)),
                _ => Point::new(rng.range(-3.0, 43.0), rng.range(-3.0, 33.0)),
            };
            let rt = rng.range(0.2, 6.0);
            let mut got = FixedBitSet::with_capacity(frame.len());
            let mut news = 0;
            stamp_capsule(&mut got, &frame, a, b, rt, &mut |_| news += 1);
            let mut want = FixedBitSet::with_capacity(frame.len());
            for row in 0..frame.height {
                for col in 0..frame.width {
                    let q = frame.pixel_center_grid(col, row);
                    if point_segment_dist2(q, a, b) <= rt * rt {
                        want.insert(frame.index(col, row));
                    }
                }
            }
            assert_eq!(got, want, "case {case}: {a:?} {b:?} rt {rt}");
            assert_eq!(news, want.count_ones(..));
        }
    }

    struct Script(Vec<Step>);
    impl Planner for Script {
        fn name(&self) -> &'static str {
            "script"
        }
        fn next(&mut self, _: &dyn Sensor) -> Step {
            if self.0.is_empty() {
                Step::Done
            } else {
                self.0.remove(0)
            }
        }
    }

    /// The metrics of a trace a library user made by hand, with a pose far off the map (1e9 m,
    /// 1e300 m) or not a number, are figures, not a panic (a tile difference overflowed 32
    /// bits: hostile pass). Such poses add no swept floor.
    #[test]
    fn a_hand_made_trace_far_off_the_map_is_measured() {
        let world = World::new(open_room(), Robot::new(0.1), None).unwrap();
        for far in [
            Pose::new(1e9, 1e9, 0.0),
            Pose::new(1e300, -1e300, 0.0),
            Pose::new(f64::NAN, 1.0, 0.0),
        ] {
            let mut trace = Trace::default();
            trace.push_pose(0, world.start());
            trace.push_pose(1, far);
            let out = RunOutput {
                trace,
                stop: crate::sim::StopReason::Done,
                tile_side: None,
                planner: "hand",
                wall_time_s: 0.0,
            };
            let m = compute(&world, &out, "room");
            assert!(m.effective_coverage < 0.05, "{far:?}: {m:?}");
        }
    }

    fn open_room() -> GridMap {
        // 6 m x 4 m at 0.01 m/px with a 1-pixel wall.
        let (w, h) = (600, 400);
        let mut cells = vec![crate::grid::Cell::Free; w * h];
        for r in 0..h {
            for c in 0..w {
                if r == 0 || c == 0 || r == h - 1 || c == w - 1 {
                    cells[r * w + c] = crate::grid::Cell::Occupied;
                }
            }
        }
        GridMap::new(crate::grid::MapFrame::new(w, h, 0.01), cells).unwrap()
    }

    /// Metrics from a [`WorldPart`] computed before the run equal those computed after it,
    /// and a part for another tile side is not used (the tiles are computed again).
    /// The visited tile centres, walked pose by pose over the expanded trace (what
    /// [`visited_tile_centres`] computes with its lattice-run shortcut).
    fn visited_pose_by_pose(
        grid: &TileGrid,
        trace: &Trace,
        reach: &TileSet,
        tol: Option<f64>,
    ) -> usize {
        let eps = (1e-6 * grid.side).max(tol.map_or(0.0, |t| t + 1e-9));
        let m = i32::from(eps > 0.25 * grid.side);
        let (i0, i1, j0, j1) = reach.bounds();
        let mut hit = TileSet::new(i0, i1, j0, j1);
        let poses: Vec<Point> = trace.poses().map(|p| p.position()).collect();
        let t = grid.tile_of(poses[0]);
        if grid.center(t).dist(poses[0]) <= eps {
            hit.insert(t);
        }
        for w in poses.windows(2) {
            let (a, b) = (w[0], w[1]);
            if a == b {
                continue;
            }
            let (ta, tb) = (grid.tile_of(a), grid.tile_of(b));
            for j in ta.1.min(tb.1) - m..=ta.1.max(tb.1) + m {
                for i in ta.0.min(tb.0) - m..=ta.0.max(tb.0) + m {
                    if point_segment_dist2(grid.center((i, j)), a, b) <= eps * eps {
                        hit.insert((i, j));
                    }
                }
            }
        }
        hit.iter().filter(|&t| reach.contains(t)).count()
    }

    #[test]
    fn visited_centres_of_lattice_runs_are_those_of_their_poses() {
        let world =
            World::new(open_room(), Robot::new(0.2), Some(Pose::new(1.0, 1.0, 0.0))).unwrap();
        let config = crate::planners::PlannerConfig::new(crate::planners::PlannerKind::BaStar);
        let out = simulate(
            &world,
            config.build(&world).unwrap().as_mut(),
            &SimConfig::default(),
        );
        assert!(
            out.trace.pieces().any(|p| matches!(p, Piece::Run(_))),
            "the trace has runs"
        );
        let side = out.tile_side.expect("BA* has tiles");
        // The run's own tiling (the shortcut applies), a shifted one and a finer one (it does
        // not), each with and without a tolerance.
        let start = world.start().position();
        for (anchor, s) in [
            (start, side),
            (Point::new(start.x + 0.3 * side, start.y), side),
            (start, 0.5 * side),
        ] {
            let grid = TileGrid::new(anchor, s);
            let reach = reachable_tiles(&world, &grid);
            for tol in [None, Some(0.01 * s), Some(0.4 * s)] {
                let want = visited_pose_by_pose(&grid, &out.trace, &reach, tol);
                assert!(want > 0);
                assert_eq!(visited_tile_centres(&grid, &out.trace, &reach, tol), want);
            }
        }
    }

    #[test]
    fn metrics_with_a_prepared_world_part_are_the_same() {
        let world =
            World::new(open_room(), Robot::new(0.2), Some(Pose::new(1.0, 1.0, 0.0))).unwrap();
        let config = crate::planners::PlannerConfig::new(crate::planners::PlannerKind::BaStar);
        let out = simulate(
            &world,
            config.build(&world).unwrap().as_mut(),
            &SimConfig::default(),
        );
        let side = out.tile_side.expect("BA* has tiles");
        let (want, swept) = compute_swept(&world, &out, "room");
        assert!(want.coverage_rate.is_some_and(|c| c > 0.9));
        for part_side in [side, 2.0 * side] {
            let part = WorldPart::of(&world, Some(part_side));
            let (got, got_swept) = compute_prepared(&world, &out, "room", part);
            assert_eq!(got, want, "part for side {part_side}");
            assert_eq!(got_swept, swept);
        }
        // A part for a coarser tiling holds other tiles: used as is it would change the rate.
        let coarse = WorldPart::of(&world, Some(2.0 * side)).expect("a side was given");
        assert_ne!(
            coarse.reach.len(),
            reachable_tiles(&world, &TileGrid::new(world.start().position(), side)).len()
        );
    }

    /// `revisit_rate` is counted on the conventions' tiles (side `2 r`, anchored at the start)
    /// whatever the planner's tiling and the tool radius: the same path gives the same figure
    /// (it was on the planner's tiles, else `2 r_tool`, so one bench compared figures on
    /// different grids).
    #[test]
    fn revisits_are_counted_on_the_robots_tiles() {
        let start = Some(Pose::new(1.0, 1.0, 0.0));
        let world = World::new(open_room(), Robot::new(0.2), start).unwrap();
        let config = crate::planners::PlannerConfig::new(crate::planners::PlannerKind::BaStar);
        let out = simulate(
            &world,
            config.build(&world).unwrap().as_mut(),
            &SimConfig::default(),
        );
        let want = compute(&world, &out, "room").revisit_rate;
        assert!(want > 0.0);
        let mut other_tiles = out.clone();
        other_tiles.tile_side = Some(0.7);
        assert_eq!(compute(&world, &other_tiles, "room").revisit_rate, want);
        let mut no_tiles = out.clone();
        no_tiles.tile_side = None;
        assert_eq!(compute(&world, &no_tiles, "room").revisit_rate, want);
        let narrow = Robot {
            radius: 0.2,
            tool_radius: 0.1,
        };
        let narrow_tool = World::new(open_room(), narrow, start).unwrap();
        assert_eq!(compute(&narrow_tool, &out, "room").revisit_rate, want);
    }

    #[test]
    fn straight_pass_length_and_swept_area() {
        let world =
            World::new(open_room(), Robot::new(0.2), Some(Pose::new(2.0, 2.0, 0.0))).unwrap();
        let out = simulate(
            &world,
            &mut Script(vec![Step::Translate(2.0)]),
            &SimConfig::default(),
        );
        let m = compute(&world, &out, "room");
        assert!((m.path_length_m - 2.0).abs() < 1e-12);
        let rt = 0.2;
        let expect = 2.0 * 2.0 * rt + std::f64::consts::PI * rt * rt;
        let swept = swept_pixels(&world, &out.trace).count_ones(..) as f64 * 1e-4;
        // Within one pixel row along the pass (2 m x 0.01 m).
        assert!(
            (swept - expect).abs() < 2.0 * 0.01,
            "swept {swept} vs {expect}"
        );
        assert_eq!(m.collisions, 0);
        assert_eq!(m.turns, 0);
        assert_eq!(m.coverage_rate, None);
        // A pass that repeats nothing has a slightly negative redundancy: the end half-discs
        // sweep floor beyond the 2 r_tool strip.
        let pi_r = std::f64::consts::PI * rt;
        let want = -pi_r / (2.0 * 2.0 + pi_r);
        let red = m.redundancy.unwrap();
        assert!(red < 0.0 && (red - want).abs() < 0.01, "{red} vs {want}");
        // Going back over the same pass doubles the length but not the swept area.
        let out = simulate(
            &world,
            &mut Script(vec![
                Step::Translate(2.0),
                Step::Rotate(std::f64::consts::PI),
                Step::Translate(2.0),
            ]),
            &SimConfig::default(),
        );
        let m2 = compute(&world, &out, "room");
        let red2 = m2.redundancy.unwrap();
        assert!((red2 - (2.0 * (1.0 + want) - 1.0)).abs() < 0.02, "{red2}");
    }

    #[test]
    fn zero_length_path_has_no_redundancy() {
        let world =
            World::new(open_room(), Robot::new(0.2), Some(Pose::new(2.0, 2.0, 0.0))).unwrap();
        let out = simulate(
            &world,
            &mut Script(vec![Step::Rotate(1.0)]),
            &SimConfig::default(),
        );
        let m = compute(&world, &out, "room");
        assert_eq!(m.path_length_m, 0.0);
        assert_eq!(m.redundancy, None);
        let v = serde_json::to_value(&m).unwrap();
        assert!(v["redundancy"].is_null(), "{v}");
    }

    #[test]
    fn path_into_wall_collides_and_stops() {
        let world =
            World::new(open_room(), Robot::new(0.2), Some(Pose::new(2.0, 2.0, 0.0))).unwrap();
        let out = simulate(
            &world,
            &mut Script(vec![Step::Translate(10.0)]),
            &SimConfig::default(),
        );
        let m = compute(&world, &out, "room");
        assert!(m.collisions >= 1);
        // Wall pixel centres at x = 5.995, y = 1.995 / 2.005: contact at distance 0.205.
        let expect = 5.995 - (0.205f64.powi(2) - 0.005f64.powi(2)).sqrt() - 2.0;
        assert!(
            (m.path_length_m - expect).abs() < 1e-6,
            "{}",
            m.path_length_m
        );
    }

    #[test]
    fn coverage_curve_ends_at_effective_coverage() {
        let world =
            World::new(open_room(), Robot::new(0.2), Some(Pose::new(2.0, 2.0, 0.0))).unwrap();
        let steps = vec![
            Step::Translate(2.0),
            Step::Rotate(1.0),
            Step::Translate(1.0),
        ];
        let out = simulate(&world, &mut Script(steps), &SimConfig::default());
        let m = compute(&world, &out, "room");
        let c = coverage_curve(&world, &out.trace, 10);
        assert!(c.len() >= 3);
        assert!(c
            .windows(2)
            .all(|w| w[1][0] > w[0][0] && w[1][1] >= w[0][1]));
        let last = c.last().unwrap();
        assert!((last[0] - 3.0).abs() < 1e-9);
        assert!((last[1] - m.effective_coverage).abs() < 1e-12);
    }

    #[test]
    fn turns_merge_and_revisits_count() {
        let world =
            World::new(open_room(), Robot::new(0.2), Some(Pose::new(2.0, 2.0, 0.0))).unwrap();
        let steps = vec![
            Step::Translate(0.4),
            Step::Rotate(1.0),
            Step::Rotate(std::f64::consts::FRAC_PI_2 - 1.0),
            Step::Rotate(0.0),
            Step::Translate(0.4),
            Step::Rotate(std::f64::consts::PI),
            Step::Translate(0.4),
        ];
        let out = simulate(&world, &mut Script(steps), &SimConfig::default());
        let m = compute(&world, &out, "room");
        assert_eq!(m.turns, 2);
        assert!((m.rotation_rad - 1.5 * std::f64::consts::PI).abs() < 1e-9);
        // Tiles of 0.4 m: start tile, east tile, north-east tile, back to the east tile.
        assert!(
            (m.revisit_rate - 1.0 / 3.0).abs() < 1e-9,
            "{}",
            m.revisit_rate
        );
    }
}
