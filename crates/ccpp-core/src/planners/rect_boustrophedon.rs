//! `rect-boustrophedon`: known-map lane waypoints for a rectangular robot (seed 001), offline.
//!
//! Seed 001 (a Jetbot homework on coverage with non-unique `AprilTag` landmarks) covers a
//! rectangle `(0,0)-(w,h)` with a robot of length `l` and width `b`: waypoints every `l` along
//! x, lanes `b` apart, direction alternating, the last lane clamped to `y = h`; lane edges that
//! cross an obstacle are dropped and the pieces joined by collision-free shortest paths (the seed
//! used a Voronoi roadmap with Dijkstra). It guarantees coverage of at least `(b - delta) / b` of
//! the area for a lateral tracking tolerance `delta` (the `rect_guarantee` metric).
//!
//! This implementation:
//!
//! * **area**: `RectOptions::area` `[x0, y0, x1, y1]`, by default the bounding box of the
//!   reachable C-free centre positions of the start's component;
//! * **lanes**: [`lanes`] (pure geometry, the seed's rule), then waypoints whose robot disk is
//!   not in the start's reachable C-free component are dropped;
//! * **footprint**: the simulator's robot is a disk, so the rectangle is represented by its
//!   **circumscribed disk** (radius `hypot(l, b) / 2`, or `clearance_radius_m`, never less than
//!   the world robot's radius): every waypoint and every motion is planned collision-free for
//!   that disk, so a rectangle turning in place anywhere along the path stays clear. Run the
//!   simulator with `--radius` equal to that disk to check the rectangle itself; with a smaller
//!   radius (e.g. the inscribed 0.15 m of a 0.3 m square) the robot keeps the larger clearance;
//! * **detours (roadmap)**: when the straight move between consecutive waypoints is not free,
//!   the pieces are joined by an **A\* search over the pixel grid of the clearance disk's
//!   reachable C-free space** (8-connected, every edge checked exactly on the true map),
//!   shortened by line-of-sight string pulling (galloping search for the farthest visible path
//!   point). The search arrays are allocated once per plan (generation stamps), the step costs
//!   are integer octile costs, the heuristic is the maximum of the octile distance and an ALT
//!   landmark bound (exact graph distances from a few far-apart pixels, computed by Dial's
//!   algorithm at the first detour; also answers "not connected" without searching), and moves
//!   between pixels whose clearance (distance transform) proves them free are not re-checked. This is complete on the pixel grid and
//!   keeps the clearance of the circumscribed disk; it replaces the seed's Voronoi roadmap.
//!
//! **Regions and backtracks**: a region is a lane, or the part of a lane after a detour; the
//! detours (round an obstacle on the lane, or to a lane not straight ahead of the last) are the
//! backtracks, transfers between regions as the metrics define them.
//!
//! [`waypoints`] returns the plain waypoint list (lane points and detour points in order);
//! the planner replays it as `MoveTo` steps, under PID execution by default (seed 001 drives to
//! each waypoint until within a tolerance).
//!
//! ```
//! use ccpp_core::GridMap;
//! use ccpp_core::world::{Robot, World};
//! use ccpp_core::planners::rect_boustrophedon::{lanes, RectBoustrophedon, RectOptions};
//! use ccpp_core::sim::{simulate, SimConfig};
//! // The seed's example: area (0,0)-(1.1,0.5), b = 0.1: lanes at y = 0, 0.1, ..., 0.5.
//! let l = lanes([0.0, 0.0, 1.1, 0.5], 0.1, 0.1);
//! assert_eq!(l.len(), 6);
//! assert_eq!(l[5][0].y, 0.5);
//! // On a map: a room with a pillar.
//! let map = GridMap::from_ascii_scaled(
//!     "##########\n#........#\n#...##...#\n#...##...#\n#........#\n##########", 6, 0.05,
//! ).unwrap();
//! let world = World::new(map, Robot::new(0.15), None).unwrap();
//! let opts = RectOptions { length_m: Some(0.2), width_m: Some(0.2), ..Default::default() };
//! let mut p = RectBoustrophedon::new(&world, &opts);
//! let out = simulate(&world, &mut p, &SimConfig::default());
//! let m = ccpp_core::metrics::compute(&world, &out, "room");
//! assert_eq!(m.collisions, 0);
//! assert!(m.rect_guarantee.unwrap() > 0.9);
//! ```

use std::sync::atomic::AtomicBool;

use serde::{Deserialize, Serialize};

use crate::exec::{Execution, PidOptions};
use crate::geometry::Point;
use crate::options::OptionsError;
use crate::planner::{Planner, Sensor, Step};
use crate::planners::replay::Replay;
use crate::search::{DeeperFirst, SearchSpace};
use crate::trace::Event;
use crate::world::{Robot, World};

/// Options of [`RectBoustrophedon`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RectOptions {
    /// Robot length `l` (direction of travel): waypoint spacing along a lane, metres; `None`
    /// = the tool's width `2 r_tool`.
    pub length_m: Option<f64>,
    /// Robot width `b`: lane spacing, metres; `None` = the tool's width `2 r_tool` (lanes that
    /// just touch). At most `2 r_tool`: lanes farther apart than the tool sweeps leave strips
    /// between them (a fixed 0.3 m default swept 70 % of the floor at `r = 0.1 m`).
    pub width_m: Option<f64>,
    /// Area to cover `[x0, y0, x1, y1]` (world, metres); `None` = bounding box of the reachable
    /// C-free centres of the start's component.
    pub area: Option<[f64; 4]>,
    /// Radius of the disk planned for; `None` = `hypot(l, b) / 2` (circumscribed disk). Never
    /// less than the world robot's radius.
    pub clearance_radius_m: Option<f64>,
    /// The execution this planner asks the simulator for (seed 001: drive to each waypoint
    /// within a tolerance, i.e. PID).
    pub exec: Execution,
    /// React to bumper contacts while replaying the plan (module [`crate::planners::replay`]:
    /// mark the obstacle, route round it, give a waypoint up after
    /// [`MAX_TRIES`](crate::planners::replay::MAX_TRIES) contacts). `false` replays the plan
    /// as planned, as a robot without a costmap would, to compare: under odometry noise it
    /// often ends pinned against an obstacle, and the simulator stops the run as stalled.
    /// Only a run with odometry noise meets obstacles, so `false` is refused without it.
    pub bumper_reaction: bool,
}

impl Default for RectOptions {
    fn default() -> Self {
        Self {
            length_m: None,
            width_m: None,
            area: None,
            clearance_radius_m: None,
            exec: Execution::Pid(PidOptions::default()),
            bumper_reaction: true,
        }
    }
}

impl RectOptions {
    /// The robot length `l` for `robot`: [`Self::length_m`] or the tool's width.
    pub fn length_for(&self, robot: &Robot) -> f64 {
        self.length_m.unwrap_or(2.0 * robot.tool_radius)
    }

    /// The robot width `b` (lane spacing) for `robot`: [`Self::width_m`] or the tool's width.
    pub fn width_for(&self, robot: &Robot) -> f64 {
        self.width_m.unwrap_or(2.0 * robot.tool_radius)
    }

    /// The radius of the disk the lanes and detours are planned for `robot`:
    /// `clearance_radius_m`, by default the rectangle's circumscribed disk `hypot(l, b) / 2`,
    /// never less than the robot's radius (a start where that disk does not fit is refused by
    /// [`check`]).
    pub fn clearance_radius(&self, robot: &Robot) -> f64 {
        self.rectangle_disk(robot).max(robot.radius)
    }

    /// The disk of [`Self::clearance_radius`] before the robot's radius is laid under it:
    /// `clearance_radius_m`, by default `hypot(l, b) / 2`.
    pub fn rectangle_disk(&self, robot: &Robot) -> f64 {
        self.clearance_radius_m
            .unwrap_or(0.5 * self.length_for(robot).hypot(self.width_for(robot)))
    }
}

/// The seed's lanes over `area = [x0, y0, x1, y1]`: lane `k` at `y0 + k b` (the last one clamped
/// to `y1`), waypoints every `l` from `x0` (the last one clamped to `x1`), even lanes going +x
/// and odd lanes -x. Degenerate input (non-positive sizes, empty area) gives no lane.
pub fn lanes(area: [f64; 4], length: f64, width: f64) -> Vec<Vec<Point>> {
    let [x0, y0, x1, y1] = area;
    let ok = length > 0.0 && width > 0.0 && x1 >= x0 && y1 >= y0;
    if !(ok && area.iter().all(|v| v.is_finite())) {
        return Vec::new();
    }
    let steps = |lo: f64, hi: f64, d: f64| -> Vec<f64> {
        let n = ((hi - lo) / d - 1e-9).ceil().max(0.0) as usize;
        let mut v: Vec<f64> = (0..n).map(|k| lo + k as f64 * d).collect();
        v.push(hi);
        if v.len() > 1 && (v[v.len() - 1] - v[v.len() - 2]).abs() < 1e-12 {
            v.pop();
        }
        v
    };
    let xs = steps(x0, x1, length);
    steps(y0, y1, width)
        .into_iter()
        .enumerate()
        .map(|(k, y)| {
            let mut lane: Vec<Point> = xs.iter().map(|&x| Point::new(x, y)).collect();
            if k % 2 == 1 {
                lane.reverse();
            }
            lane
        })
        .collect()
}

/// A computed plan.
#[derive(Clone, Debug, Default)]
pub struct RectPlan {
    /// Every waypoint in order (lane points and detour points), excluding the start.
    pub waypoints: Vec<Point>,
    /// The planner's steps (marks and moves).
    pub steps: Vec<Step>,
    /// Area covered `[x0, y0, x1, y1]`.
    pub area: [f64; 4],
    /// Radius of the disk planned for.
    pub clearance_radius_m: f64,
    /// Lane waypoints dropped (not reachable by the clearance disk).
    pub dropped: usize,
    /// Of those, the ones in the clearance disk's reachable space that the roadmap found no
    /// way to from where the robot was (0 on every shared and bench map; a note in the trace,
    /// [`UNREACHED_NOTE`], when not).
    pub unreached: usize,
}

/// The plain waypoint list of [`plan`] (for `ccpp waypoints`).
pub fn waypoints(world: &World, opts: &RectOptions) -> Vec<Point> {
    plan(world, opts).waypoints
}

/// The world the lanes are planned in: the map and start of `world` with the clearance disk
/// (`clearance_radius_m`, by default the circumscribed disk of the robot's rectangle, at least
/// the robot's radius) as robot, and its radius.
///
/// # Errors
/// Why the clearance disk does not fit at the start. The plan does not fall back to the
/// robot's own radius: a route planned for a smaller disk drives the rectangle into walls and
/// keep-outs, and `ccpp plan` and `ccpp waypoints` (which write no trace) said nothing of it.
fn clearance_world(world: &World, opts: &RectOptions) -> Result<(World, f64), String> {
    let robot = world.robot();
    let rad = opts.clearance_radius(&robot);
    World::new(world.map().clone(), Robot::new(rad), Some(world.start()))
        .map(|w| (w, rad))
        .map_err(|e| {
            use crate::world::WorldError as E;
            let p = world.start().position();
            let why = match e {
                E::StartInObstacle { .. } => "it overlaps occupied or unknown pixels there".into(),
                E::StartInKeepout { .. } => "it overlaps a keep-out zone there".into(),
                // (`world.map()` is the planning map: with zones, what the area and keep-outs
                // leave of the floor, so the widest spot is theirs, not the drawn map's)
                E::RobotTooBig { max_clearance, .. } if world.zones().is_some() => {
                    format!("it fits nowhere in what the area and keep-outs leave of the map (the widest free spot there has clearance {} m)", crate::display::fixed(max_clearance, 3))
                }
                E::RobotTooBig { max_clearance, .. } => {
                    format!("it fits nowhere on the map (the widest free spot has clearance {} m)", crate::display::fixed(max_clearance, 3))
                }
                e => e.to_string(),
            };
            let at = if world.approach().is_empty() {
                format!("at the start ({:.3}, {:.3})", p.x, p.y)
            } else {
                // The approach from a start outside the area ends where the clearance disk
                // first fits inside it when the world was built for this planner
                // (`World::with_zones_fitting` with its `start_radius`, as `Scenario` does);
                // a world built for the robot's own disk ends it where that disk fits.
                format!(
                    "where the approach from the start outside the area enters it ({:.3}, {:.3})",
                    p.x, p.y
                )
            };
            format!(
                "the clearance disk of the {} x {} m robot (radius {:.3} m, the circle it turns in) does not fit {at}: {why}; start farther from walls and zones, or give a smaller robot or clearance_radius_m",
                crate::display::Compact(opts.length_for(&robot)),
                crate::display::Compact(opts.width_for(&robot)),
                rad,
            )
        })
}

/// The area the lanes cover in the clearance world `rw`: the bounding box of the reachable
/// pixel centres, clipped to the user's area when there is one. Lanes beyond the reachable
/// floor cannot be driven: an area of 1e119 m would ask for more lanes than memory holds
/// (found by fuzzing), and an area the size of the map anchored its lanes at the map's edge
/// instead of the floor's, which lost 13 points of coverage on `teb_maze` (hostile pass).
fn lane_area(rw: &World, opts: &RectOptions) -> [f64; 4] {
    let floor = reachable_box(rw);
    match opts.area {
        Some(a) => [
            a[0].max(floor[0]),
            a[1].max(floor[1]),
            a[2].min(floor[2]),
            a[3].min(floor[3]),
        ],
        None => floor,
    }
}

/// The bounding box `[x0, y0, x1, y1]` of the reachable pixel centres of `rw`.
fn reachable_box(rw: &World) -> [f64; 4] {
    let f = *rw.frame();
    let (mut x0, mut y0, mut x1, mut y1) = (
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    );
    for i in rw.reachable().ones() {
        let (c, r) = f.col_row(i);
        let p = f.pixel_center(c, r);
        x0 = x0.min(p.x);
        y0 = y0.min(p.y);
        x1 = x1.max(p.x);
        y1 = y1.max(p.y);
    }
    [x0, y0, x1, y1]
}

/// Whether the robot can stop at `p` in the clearance world `rw`: its pixel is reachable
/// from the start and the disk there touches nothing.
fn stop_valid(rw: &World, p: Point) -> bool {
    let f = rw.frame();
    match f.pixel_of(p) {
        Some((c, r)) => rw.reachable().contains(f.index(c, r)) && !rw.disk_collides(p),
        None => false,
    }
}

/// Checks that `world` has a plan for `opts`, building the clearance world once: the robot
/// rectangle's clearance disk ([`RectOptions::clearance_radius`]) fits at the start (the
/// lanes, detours and the approach keep that clearance), and a user area (`opts.area`) holds
/// a lane point where the robot can stop (else the plan would be empty, and the run would
/// "succeed" having done nothing). Without an area the lanes cover the reachable floor's
/// bounding box, which holds the start.
///
/// # Errors
/// `clearance_radius_m`: why the disk does not fit, with the disk, the rectangle and the
/// start. `area`: the area as given and the clearance radius, when no lane point is valid
/// (with the reachable floor's box when the area misses it).
pub fn check(world: &World, opts: &RectOptions) -> Result<(), OptionsError> {
    // (the field the disk comes from: a clearance given, else the rectangle's length and
    // width, which the user may have set; the message named clearance_radius_m for a
    // `length_m: 5` that made the disk too big: hostile pass, stop 70)
    let field = if opts.clearance_radius_m.is_some() {
        "clearance_radius_m"
    } else {
        "length_m / width_m (clearance_radius_m not given: the rectangle's circumscribed disk)"
    };
    let (rw, rad) = clearance_world(world, opts).map_err(|m| OptionsError::new(field, m))?;
    let Some(given) = opts.area else {
        return Ok(());
    };
    let area = lane_area(&rw, opts);
    let robot = world.robot();
    let lanes = lanes(area, opts.length_for(&robot), opts.width_for(&robot));
    if lanes.iter().flatten().any(|&p| stop_valid(&rw, p)) {
        return Ok(());
    }
    // The area as the user gave it (the clipped one, shown before, came out reversed and
    // with rounding noise where the area misses the floor: `0.425,0.375,0.2,0.2` for
    // `0,0,0.2,0.2`), and why when it misses the floor the disk reaches.
    let outside = if area[0] > area[2] || area[1] > area[3] {
        let floor = reachable_box(&rw);
        format!(
            " (it lies outside the box of the floor the disk reaches, {:.3},{:.3},{:.3},{:.3})",
            floor[0], floor[1], floor[2], floor[3]
        )
    } else {
        String::new()
    };
    Err(OptionsError::new(
        "area",
        format!(
            "{} holds no lane point where the robot (clearance disk {:.3} m) fits and that it can reach from the start{outside}",
            crate::display::join(&given),
            rad
        ),
    ))
}

/// Computes the lane plan for `world` (offline: reads the whole map).
pub fn plan(world: &World, opts: &RectOptions) -> RectPlan {
    plan_until(world, opts, None)
}

/// [`plan`] that another thread can give up by setting `stop`: the planning then ends within
/// one lane point, one landmark search or 65 536 settled pixels, with what it has
/// (the caller is giving the run up; Python's Ctrl-C left a large map's planning running on,
/// and the next call waited for it). What comes before the lanes is not stopped: the
/// clearance world (a distance transform of the map and its reachable set) and the roadmap's
/// clearance set, a fraction of a second on `cluttered_2000`.
pub fn plan_until(world: &World, opts: &RectOptions, stop: Option<&AtomicBool>) -> RectPlan {
    let robot = world.robot();
    let (length, width) = (opts.length_for(&robot), opts.width_for(&robot));
    let mut steps = vec![Step::Mark(Event::RectLanes {
        length_m: length,
        width_m: width,
    })];
    // The clearance world: same map and start, the circumscribed disk as robot.
    let (rw, rad) = match clearance_world(world, opts) {
        Ok(v) => v,
        Err(text) => {
            // Unchecked worlds only ([`check`] refuses this first): no route, said so.
            steps.push(Step::Mark(Event::Note { text }));
            return RectPlan {
                steps,
                clearance_radius_m: opts.clearance_radius(&robot),
                ..RectPlan::default()
            };
        }
    };
    let area = lane_area(&rw, opts);
    let mut rm = Roadmap::new(&rw, stop);
    let mut waypoints = Vec::new();
    let mut dropped = 0;
    let mut unreached = 0;
    let mut cur = world.start().position();
    let lane_list = lanes(area, length, width);
    // A region is a lane, or the part of one after a detour: the way round an obstacle on the
    // lane (or to a lane that is not straight ahead) is a transfer between regions, as the
    // metrics define backtracks, not a backtrack inside one. A region starts with its first
    // straight move (the shift from the lane before is its first move).
    let mut region = 0u32;
    // Lane points on the floor the robot's disk reaches (the metrics' reachable set), and of
    // those the ones the clearance disk cannot stop at (for the note below).
    let (mut on_floor, mut off_stop) = (0usize, 0usize);
    let reach = world.reachable();
    let frame = *world.frame();
    'lanes: for lane in &lane_list {
        let mut open = false;
        for &p in lane {
            if rm.stopped() {
                break 'lanes;
            }
            let floor = frame
                .pixel_of(p)
                .is_some_and(|(c, r)| reach.contains(frame.index(c, r)));
            on_floor += usize::from(floor);
            if !rm.valid(p) {
                dropped += 1;
                off_stop += usize::from(floor);
                continue;
            }
            if rw.segment_free(cur, p) {
                if !open {
                    region += 1;
                    steps.push(Step::Mark(Event::RegionStart { region }));
                    open = true;
                }
                steps.push(Step::MoveTo(p));
                waypoints.push(p);
            } else if let Some(path) = rm.path(cur, p) {
                if open {
                    steps.push(Step::Mark(Event::RegionEnd { region }));
                    open = false;
                }
                steps.push(Step::Mark(Event::BacktrackStart));
                steps.push(Step::Mark(Event::PathSmoothed {
                    points: path.iter().map(|q| [q.x, q.y]).collect(),
                }));
                for &q in &path[1..] {
                    steps.push(Step::MoveTo(q));
                    waypoints.push(q);
                }
                steps.push(Step::Mark(Event::BacktrackEnd));
            } else {
                dropped += 1;
                unreached += 1;
                continue;
            }
            cur = p;
        }
        if open {
            steps.push(Step::Mark(Event::RegionEnd { region }));
        }
    }
    if on_floor >= SPARSE_MIN_POINTS && 2 * off_stop > on_floor {
        // Most stops on the floor are left out: clutter or specks of noise where the
        // clearance disk does not fit, lanes far apart for the rooms. A room of salt noise
        // was swept 31 % without a word (hostile pass).
        steps.push(Step::Mark(Event::Note {
            text: format!(
                "{SPARSE_STOPS_NOTE}: {off_stop} of the {on_floor} lane points on the floor the robot reaches are left out, where its clearance disk (r = {rad:.3} m) does not fit (clutter, specks of noise, narrow places); a shorter --length and --width (stop and lane spacing) give it more places to stop"
            ),
        }));
    }
    if unreached > 0 {
        steps.push(Step::Mark(Event::Note {
            text: format!(
                "{UNREACHED_NOTE}: {unreached} lane point(s) in the clearance disk's reachable space had no collision-free way from where the robot was; left out"
            ),
        }));
    }
    RectPlan {
        waypoints,
        steps,
        area,
        clearance_radius_m: rad,
        dropped,
        unreached,
    }
}

/// The start of the [`Event::Note`] written when more than half of the lane points on the
/// reachable floor are left out (the clearance disk does not fit there): the run sweeps little
/// of the floor around them.
pub const SPARSE_STOPS_NOTE: &str = "rect-boustrophedon stops only at lane points";

/// Fewest lane points on the floor for [`SPARSE_STOPS_NOTE`] (a closet's two or three points,
/// one of them left out, are no pattern).
const SPARSE_MIN_POINTS: usize = 8;

/// The start of the [`Event::Note`] written when lane points had no way from the robot.
pub const UNREACHED_NOTE: &str = "rect-boustrophedon: lane points left out";

/// Cost of a straight pixel step in the A\* search (integer octile costs: 99 / 70 ~ sqrt 2).
const STRAIGHT: u32 = 70;
/// Cost of a diagonal pixel step.
const DIAG: u32 = 99;
/// Landmarks of the ALT heuristic.
const LANDMARKS: usize = 12;
/// N8 offsets `(dc, dr)` (rows down), straight ones first.
const N8: [(i64, i64); 8] = [
    (1, 0),
    (0, 1),
    (-1, 0),
    (0, -1),
    (1, 1),
    (-1, 1),
    (-1, -1),
    (1, -1),
];

/// A\* over the reachable C-free pixels of a clearance world.
///
/// The search buffers ([`SearchSpace`]) are allocated once per plan and reused; the pixels
/// whose clearance proves every edge between them free are precomputed from the world's
/// distance transform, and the exact segment checks of the other edges are memoised (the map
/// is static).
struct Roadmap<'a> {
    w: &'a World,
    /// Reachable pixels with clearance `>= r + 0.45 px`: an edge between two of them is free.
    safe: fixedbitset::FixedBitSet,
    /// Per pixel and N8 direction: exact edge check done (bit `k`) / its result (bit `k + 8`).
    edge_memo: Vec<u16>,
    /// A\* buffers over the pixels; ties of equal `f` go to the smaller `h` (deeper nodes
    /// first), then the smaller pixel index.
    space: SearchSpace<u32, DeeperFirst>,
    /// Compact index of each reachable pixel (`u32::MAX` elsewhere), for the landmark tables.
    compact: Vec<u32>,
    /// ALT landmarks: exact search-graph distances from each landmark, by compact index
    /// (`u32::MAX` = not connected); computed at the first detour.
    landmarks: Option<Vec<Vec<u32>>>,
    /// Set by another thread when the planning is given up ([`plan_until`]).
    stop: Option<&'a AtomicBool>,
}

/// Pixels a search settles between two looks at the stop flag ([`plan_until`]).
const STOP_EVERY: usize = 1 << 16;

impl<'a> Roadmap<'a> {
    fn new(w: &'a World, stop: Option<&'a AtomicBool>) -> Self {
        let f = *w.frame();
        let n = f.len();
        let need = w.robot().radius + 0.45 * f.resolution;
        let mut safe = fixedbitset::FixedBitSet::with_capacity(n);
        for i in w.reachable().ones() {
            let (c, r) = f.col_row(i);
            if w.pixel_clearance(c, r) >= need {
                safe.insert(i);
            }
        }
        Self {
            w,
            safe,
            edge_memo: vec![0; n],
            space: SearchSpace::new(n),
            compact: Vec::new(),
            landmarks: None,
            stop,
        }
    }

    /// Has the planning been given up?
    fn stopped(&self) -> bool {
        self.stop
            .is_some_and(|s| s.load(std::sync::atomic::Ordering::Relaxed))
    }

    /// The search-graph successor of pixel `i` along N8 direction `k`, with its step cost: a
    /// reachable pixel, the move checked free on the true map. A diagonal step whose side
    /// pixels are not both reachable is allowed when that check passes: forbidding it (no
    /// corner cutting) cut pockets off the search graph that a straight lane move had entered,
    /// and every later lane point was dropped for want of a way out (`stage_willow_full`
    /// swept 18 % of its floor, 74.5 % now).
    #[inline]
    fn succ(&mut self, i: usize, k: usize) -> Option<(usize, u32)> {
        let f = self.w.frame();
        let (w, hgt) = (f.width as i64, f.height as i64);
        let (c, r) = (i as i64 % w, i as i64 / w);
        let (dc, dr) = N8[k];
        let (nc, nr) = (c + dc, r + dr);
        if nc < 0 || nr < 0 || nc >= w || nr >= hgt {
            return None;
        }
        let j = (nr * w + nc) as usize;
        let reach = self.w.reachable();
        if !reach.contains(j) {
            return None;
        }
        let diag = dc != 0 && dr != 0;
        // A diagonal past a side pixel the disk cannot stand on is checked exactly, never
        // taken as free from the two ends' clearance.
        let cut = diag
            && !(reach.contains((r * w + nc) as usize) && reach.contains((nr * w + c) as usize));
        if !self.edge_free(i, j, k, cut) {
            return None;
        }
        Some((j, if diag { DIAG } else { STRAIGHT }))
    }

    /// Exact distances over the search graph from pixel `src` (Dial's bucket queue: the
    /// step costs are small integers), by compact index.
    fn distances_from(&mut self, src: usize) -> Vec<u32> {
        let n = self.compact.iter().filter(|&&c| c != u32::MAX).count();
        let mut d = vec![u32::MAX; n];
        let nb = DIAG as usize + 1;
        let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); nb];
        d[self.compact[src] as usize] = 0;
        buckets[0].push(src as u32);
        let mut pending = 1usize;
        let mut cost = 0u32;
        let mut settled = 0usize;
        while pending > 0 {
            let slot = cost as usize % nb;
            while let Some(i) = buckets[slot].pop() {
                pending -= 1;
                settled += 1;
                if settled.is_multiple_of(STOP_EVERY) && self.stopped() {
                    // Given up: the tables are not used.
                    return d;
                }
                let i = i as usize;
                if d[self.compact[i] as usize] != cost {
                    continue;
                }
                for k in 0..8 {
                    let Some((j, step)) = self.succ(i, k) else {
                        continue;
                    };
                    let cj = self.compact[j] as usize;
                    let nc = cost + step;
                    if nc < d[cj] {
                        d[cj] = nc;
                        buckets[nc as usize % nb].push(j as u32);
                        pending += 1;
                    }
                }
            }
            cost += 1;
        }
        d
    }

    /// Picks [`LANDMARKS`] landmarks by farthest-point selection from `seed` and stores their
    /// distance tables.
    fn init_landmarks(&mut self, seed: usize) {
        let f = *self.w.frame();
        let mut compact = vec![u32::MAX; f.len()];
        let mut pixel_of = Vec::new();
        for (k, i) in self.w.reachable().ones().enumerate() {
            compact[i] = k as u32;
            pixel_of.push(i);
        }
        self.compact = compact;
        let mut tables: Vec<Vec<u32>> = Vec::with_capacity(LANDMARKS);
        let first = self.distances_from(seed);
        // min over the landmarks so far of the distance (the seed's table to start with).
        let mut nearest = first;
        for _ in 0..LANDMARKS {
            if self.stopped() {
                break;
            }
            let far = nearest
                .iter()
                .enumerate()
                .filter(|&(_, &d)| d != u32::MAX)
                .max_by_key(|&(k, &d)| (d, std::cmp::Reverse(k)))
                .map(|(k, _)| pixel_of[k]);
            let Some(far) = far else { break };
            let t = self.distances_from(far);
            for (m, &d) in nearest.iter_mut().zip(&t) {
                *m = (*m).min(d);
            }
            tables.push(t);
        }
        self.landmarks = Some(tables);
    }

    /// The ALT lower bound on the distance from `i` to `t` (triangle inequality over the
    /// landmarks; 0 where a table does not know both).
    #[inline]
    fn alt(&self, i: usize, t: usize) -> u32 {
        let (ci, ct) = (self.compact[i] as usize, self.compact[t] as usize);
        self.landmarks.as_ref().map_or(0, |ls| {
            ls.iter()
                .map(|l| {
                    let (a, b) = (l[ci], l[ct]);
                    if a == u32::MAX || b == u32::MAX {
                        0
                    } else {
                        a.abs_diff(b)
                    }
                })
                .max()
                .unwrap_or(0)
        })
    }

    /// Can the clearance disk stand at `p` inside the start's component?
    fn valid(&self, p: Point) -> bool {
        stop_valid(self.w, p)
    }

    /// A reachable pixel next to `p` joined to it by a free segment.
    fn attach(&self, p: Point) -> Option<usize> {
        let f = self.w.frame();
        let (c0, r0) = f.grid_to_pixel_signed(f.world_to_grid(p));
        let mut best: Option<(f64, usize)> = None;
        for dr in -1..=1 {
            for dc in -1..=1 {
                let Some((c, r)) = f.checked(c0 + dc, r0 + dr) else {
                    continue;
                };
                let i = f.index(c, r);
                if !self.w.reachable().contains(i) {
                    continue;
                }
                let q = f.pixel_center(c, r);
                let d = q.dist(p);
                if best.is_none_or(|(bd, _)| d < bd) && self.w.segment_free(p, q) {
                    best = Some((d, i));
                }
            }
        }
        best.map(|b| b.1)
    }

    /// Is the move from pixel `a` to its N8 neighbour `b` (direction `k`) free? `exact`: check
    /// it on the map even where both ends have the clearance that proves an edge free.
    fn edge_free(&mut self, a: usize, b: usize, k: usize, exact: bool) -> bool {
        if !exact && self.safe.contains(a) && self.safe.contains(b) {
            return true;
        }
        let m = self.edge_memo[a];
        if m & (1 << k) != 0 {
            return m & (1 << (k + 8)) != 0;
        }
        let f = self.w.frame();
        let (ca, ra) = f.col_row(a);
        let (cb, rb) = f.col_row(b);
        let free = self
            .w
            .segment_free(f.pixel_center(ca, ra), f.pixel_center(cb, rb));
        // The reverse direction of N8[k] is N8[k ^ 2] (E<->W, N<->S, NE<->SW, NW<->SE).
        let back = k ^ 2;
        let bit = |d: usize| (1u16 << d) | (u16::from(free) << (d + 8));
        self.edge_memo[a] |= bit(k);
        self.edge_memo[b] |= bit(back);
        free
    }

    /// Shortest collision-free path from `a` to `b` (both included), string-pulled.
    fn path(&mut self, a: Point, b: Point) -> Option<Vec<Point>> {
        let f = *self.w.frame();
        let s = self.attach(a)?;
        let t = self.attach(b)?;
        let w = f.width as i64;
        let (tc, tr) = ((t as i64 % w), (t as i64 / w));
        // Octile distance in the same integer units: consistent with the step costs.
        if self.landmarks.is_none() {
            self.init_landmarks(s);
        }
        // Different components of the search graph (the first landmark's table sees all of
        // the seed's component): no path, without searching.
        if let Some(l0) = self.landmarks.as_ref().and_then(|ls| ls.first()) {
            let (ds, dt) = (l0[self.compact[s] as usize], l0[self.compact[t] as usize]);
            if (ds == u32::MAX) != (dt == u32::MAX) {
                return None;
            }
        }
        // Octile distance in the same integer units, and the landmark bound: both consistent
        // with the step costs, so is their maximum.
        let octile = |i: usize| -> u32 {
            let (c, r) = (i as i64 % w, i as i64 / w);
            let (dx, dy) = ((c - tc).unsigned_abs(), (r - tr).unsigned_abs());
            let (lo, hi) = (dx.min(dy) as u32, dx.max(dy) as u32);
            DIAG * lo + STRAIGHT * (hi - lo)
        };
        let h = |me: &Self, i: usize| octile(i).max(me.alt(i, t));
        self.space.begin();
        // Key: f, then h (deeper nodes first on ties), then the index (determinism).
        let hs = h(self, s);
        self.space.push_source(s as u32, 0, hs);
        let mut found = false;
        let mut settled = 0usize;
        while let Some(x) = self.space.pop() {
            let i = x.node as usize;
            if i == t {
                found = true;
                break;
            }
            settled += 1;
            if settled.is_multiple_of(STOP_EVERY) && self.stopped() {
                return None;
            }
            for k in 0..8 {
                let Some((j, step)) = self.succ(i, k) else {
                    continue;
                };
                let cost = x.g + step;
                if !self.space.is_settled(j as u32) && self.space.improves(j as u32, cost) {
                    let hj = h(self, j);
                    self.space.update(x.node, j as u32, cost, hj);
                }
            }
        }
        if !found {
            return None;
        }
        let cells = self.space.path_to(t as u32);
        let mut pts = vec![a];
        pts.extend(cells.iter().map(|&i| {
            let (c, r) = f.col_row(i as usize);
            f.pixel_center(c, r)
        }));
        pts.push(b);
        // String pulling: from each kept point, the farthest path point found visible by a
        // galloping then binary search (consecutive path points are joined by checked moves,
        // so every kept segment is checked free, in O(log n) checks per kept point).
        let visible = |i: usize, j: usize| self.w.segment_free(pts[i], pts[j]);
        let mut out = vec![a];
        let mut i = 0;
        while i + 1 < pts.len() {
            let last = pts.len() - 1;
            let (mut lo, mut hi) = (i + 1, None);
            let mut step = 1;
            while lo < last {
                let cand = (lo + step).min(last);
                if visible(i, cand) {
                    lo = cand;
                    step *= 2;
                } else {
                    hi = Some(cand);
                    break;
                }
            }
            if let Some(mut hi) = hi {
                while hi - lo > 1 {
                    let mid = lo + (hi - lo) / 2;
                    if visible(i, mid) {
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
}

/// The planner: replays [`plan`]'s steps.
pub struct RectBoustrophedon {
    replay: Replay,
    exec: Execution,
    plan: RectPlan,
}

impl RectBoustrophedon {
    /// Plans on `world` (offline).
    pub fn new(world: &World, opts: &RectOptions) -> Self {
        Self::new_until(world, opts, None)
    }

    /// [`Self::new`] that another thread can give up by setting `stop` ([`plan_until`]); a
    /// planner built after `stop` was set must not be driven.
    pub fn new_until(world: &World, opts: &RectOptions, stop: Option<&AtomicBool>) -> Self {
        let plan = plan_until(world, opts, stop);
        Self {
            replay: Replay::new(world, plan.steps.clone().into()).reacting(opts.bumper_reaction),
            exec: opts.exec,
            plan,
        }
    }

    /// The computed plan.
    pub fn plan(&self) -> &RectPlan {
        &self.plan
    }
}

impl Planner for RectBoustrophedon {
    fn name(&self) -> &'static str {
        "rect-boustrophedon"
    }

    fn is_offline(&self) -> bool {
        true
    }

    fn preferred_execution(&self) -> Option<Execution> {
        Some(self.exec)
    }

    fn next(&mut self, sensor: &dyn Sensor) -> Step {
        self.replay.next(sensor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridMap;
    use crate::metrics::compute;
    use crate::sim::{simulate, SimConfig};

    #[test]
    fn seed_example_lanes() {
        // Seed 001: area (0,0)-(1.1,0.5), b = 0.1 (10 cm): ceil(h / b) = 5 increments of y,
        // i.e. 6 lanes at y = 0, 0.1, 0.2, 0.3, 0.4 and the last one at y = h = 0.5; waypoints
        // every l along x up to x = w = 1.1, alternating direction.
        let l = lanes([0.0, 0.0, 1.1, 0.5], 0.1, 0.1);
        assert_eq!(l.len(), 6);
        for (k, lane) in l.iter().enumerate() {
            let y = lane[0].y;
            assert!((y - 0.1 * k as f64).abs() < 1e-12, "lane {k} at {y}");
            assert!(lane.iter().all(|p| p.y == y));
            assert_eq!(lane.len(), 12); // x = 0, 0.1, ..., 1.0, 1.1
            let (first, last) = (lane[0].x, lane[lane.len() - 1].x);
            if k % 2 == 0 {
                assert!(first == 0.0 && (last - 1.1).abs() < 1e-12);
            } else {
                assert!((first - 1.1).abs() < 1e-12 && last == 0.0);
            }
        }
        assert_eq!(l[5][0].y, 0.5);
        // h not a multiple of b: the last lane is clamped to y = h.
        let l = lanes([0.0, 0.0, 1.0, 0.45], 0.2, 0.1);
        assert_eq!(l.len(), 6);
        assert_eq!(l[5][0].y, 0.45);
        assert!((l[4][0].y - 0.4).abs() < 1e-12);
        assert!(lanes([0.0, 0.0, 1.0, 1.0], 0.0, 0.1).is_empty());
    }

    #[test]
    fn a_huge_area_is_clipped_to_the_map() {
        // Found by fuzzing: an area reaching 1e119 m asked for more lanes than memory holds.
        let map = GridMap::from_ascii_scaled("######\n#....#\n#....#\n######", 8, 0.05).unwrap();
        let world = World::new(map, Robot::new(0.15), None).unwrap();
        let opts = RectOptions {
            area: Some([0.2, 0.2, 3e119, 1.4]),
            ..RectOptions::default()
        };
        let p = plan(&world, &opts);
        let (lo, hi) = world.frame().world_bounds();
        assert!(p.area[2] <= hi.x && p.area[3] <= hi.y && p.area[0] >= lo.x);
        assert!(p
            .waypoints
            .iter()
            .all(|w| w.x >= lo.x && w.x <= hi.x && w.y >= lo.y && w.y <= hi.y));
    }

    #[test]
    fn an_area_around_the_whole_floor_plans_as_no_area() {
        // An area the size of the map anchored the lanes at its edge, not the floor's: on
        // `teb_maze` 13 points of coverage lost (hostile pass).
        let map = GridMap::from_ascii_scaled(
            "##########\n#........#\n#..##....#\n#........#\n##########",
            8,
            0.05,
        )
        .unwrap();
        let world = World::new(map, Robot::new(0.15), None).unwrap();
        let none = plan(&world, &RectOptions::default());
        for area in [[0.0, 0.0, 4.0, 2.0], [-50.0, -50.0, 50.0, 50.0]] {
            let opts = RectOptions {
                area: Some(area),
                ..RectOptions::default()
            };
            let p = plan(&world, &opts);
            assert_eq!(p.area, none.area, "{area:?}");
            assert_eq!(p.waypoints, none.waypoints, "{area:?}");
        }
    }

    #[test]
    fn obstacles_are_detoured_with_clearance() {
        let map = GridMap::from_ascii_scaled(
            "############\n#..........#\n#...####...#\n#...####...#\n#..........#\n#..........#\n############",
            8,
            0.05,
        )
        .unwrap();
        let world = World::new(map, Robot::new(0.15), None).unwrap();
        let opts = RectOptions::default();
        let p = plan(&world, &opts);
        assert!((p.clearance_radius_m - 0.5 * 0.3f64.hypot(0.3)).abs() < 1e-12);
        assert!(!p.waypoints.is_empty());
        // Every move is free for the circumscribed disk.
        let rw = World::new(
            world.map().clone(),
            Robot::new(p.clearance_radius_m),
            Some(world.start()),
        )
        .unwrap();
        let mut cur = world.start().position();
        for &q in &p.waypoints {
            assert!(rw.segment_free(cur, q), "{cur:?} -> {q:?}");
            cur = q;
        }
        for exec in [Execution::Ideal, Execution::Pid(PidOptions::default())] {
            let mut planner = RectBoustrophedon::new(&world, &opts);
            let cfg = SimConfig {
                exec: Some(exec),
                ..SimConfig::default()
            };
            let out = simulate(&world, &mut planner, &cfg);
            let m = compute(&world, &out, "t");
            assert_eq!(m.collisions, 0);
            // The circumscribed disk (0.212 m) keeps 0.06 m more from every wall than the
            // 0.15 m tool reaches: a strip along the walls stays unswept in this small room.
            assert!(m.effective_coverage > 0.7, "{m:?}");
            let g = m.rect_guarantee.unwrap();
            match exec {
                Execution::Ideal => assert_eq!(g, 1.0),
                Execution::Pid(o) => assert!((g - (0.3 - o.tolerance_m) / 0.3).abs() < 1e-12),
            }
        }
    }
}
