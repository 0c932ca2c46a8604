//! The simulator: holds the truth, executes each planner [`Step`], checks every motion against
//! the true map, stops on contact (the bumper) and records the [`Trace`].
//!
//! Two execution modes ([`Execution`], chosen by [`SimConfig::exec`] or, when that is `None`,
//! by the planner's [`Planner::preferred_execution`]):
//!
//! * **ideal** (the default): exact in-place rotations and straight translations; one pose
//!   record per motion;
//! * **PID** ([`crate::exec`]): a unicycle stepped every `dt_s` seconds under linear and angular
//!   PID control. Each small motion of the **true** pose is collision-checked (the chord of the
//!   arc against the true map; contact stops the motion and counts a collision, as in ideal
//!   mode). The controller and the planner see the pose **estimate** ([`Sensor::pose`]): equal
//!   to the truth without noise, dead-reckoned from the commanded speeds with
//!   [`crate::exec::OdometryNoise`] (the truth then moves with perturbed speeds), and reset from
//!   landmark observations when [`SimConfig::landmarks`] has some ([`crate::landmarks`]).
//!   The trace gets an [`Event::Execution`] at the start, an [`Event::PlannedSegment`] before
//!   each translation, and true poses every `record_every` control steps plus at the end of
//!   each motion and where the robot starts or stops turning in place, except the poses inside
//!   a straight glide along a map axis (see `Glide`: they lie exactly on the segment between
//!   the poses kept, so the recorded path is the same). `MoveTo` follows the
//!   segment from the previous planned goal (when the last motion ended without contact) to
//!   the new one, so the robot steers back onto the plan.
//!
//! The sensor scan is always taken around the **true** position and returned in map
//! coordinates (a scan registered to the map), whatever the estimate.

use serde::{Deserialize, Serialize};
use std::ops::{Add, Sub};
use std::sync::atomic::{AtomicBool, Ordering};

use crate::exec::{Execution, Goal, PidOptions, Tracker, Unicycle};
use crate::geometry::{atan2_exact, dist_exact, wrap_angle, Point, Pose};
use crate::grid::MapFrame;
use crate::landmarks::{choose_pose, nearest_in_range, observe, LandmarkConfig};
use crate::planner::{Planner, Scan, Sensor, Step};
use crate::rng::SplitMix64;
use crate::trace::{Event, Trace};
use crate::world::{Robot, World};

pub use crate::planner::MIN_ROTATION;

/// Whether the rotation `turn` (radians) before a straight move of `dist` metres from `a` to
/// `b` is rounding, not a turn: it would move the end of the move sideways by less than the
/// precision of the coordinates themselves (16 ulps of the largest of them). Far from the map
/// frame's origin, the heading between two points of one straight line is off by about
/// `ulp(coordinate) / dist`: with the origin at (1e6, 2e6) m, bcd's path on `rmf_office_scan`
/// turned by 1e-9 to 3e-9 rad in the middle of 23 straight lanes, each such "turn" a waypoint
/// of its exports and a turn of its metrics (1188 against 1165 at the map's own origin).
fn is_rounding_turn(turn: f64, dist: f64, a: Point, b: Point) -> bool {
    let scale = a.x.abs().max(a.y.abs()).max(b.x.abs()).max(b.y.abs());
    turn.abs() * dist <= 16.0 * f64::EPSILON * scale
}

/// Simulator settings (deserialized with unknown fields refused: a misspelt `max_step` was
/// dropped).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimConfig {
    /// Sensor range in metres; `None` = `4 r` (enough to classify all 8 neighbour tiles). A
    /// run built from a scenario (the CLI's, Python's) raises a `None` to the planner's
    /// [`least_sensor_range`](crate::planners::PlannerSettings::least_sensor_range) where
    /// that is more. Ranges beyond twice the map's diagonal run as that ([`SimConfig::sensor_range_on`]).
    pub sensor_range: Option<f64>,
    /// Safety cap on planner steps (default 50 million): a bound on the run's time and trace
    /// that no finishing planner comes near (the bench's longest run, random-bounce on the
    /// largest map, takes about half a million steps). A robot that stops making progress is
    /// ended long before it, after [`STALL_STEPS`] motions ([`StopReason::Stalled`]).
    pub max_steps: u64,
    /// How motions are executed; `None` = the planner's
    /// [`preferred_execution`](Planner::preferred_execution), else [`Execution::Ideal`].
    pub exec: Option<Execution>,
    /// Landmarks for pose correction under PID execution (ignored in ideal mode, where the
    /// estimate is the truth).
    pub landmarks: LandmarkConfig,
}

impl SimConfig {
    /// The sensor range asked for `robot`: [`sensor_range`](Self::sensor_range) or `4 r`.
    pub fn sensor_range_for(&self, robot: &Robot) -> f64 {
        self.sensor_range.unwrap_or(4.0 * robot.radius)
    }

    /// The sensor range in force for `robot` on a map of `frame`: [`sensor_range_for`]
    /// capped at twice the frame's diagonal. From anywhere on the map such a sensor sees the
    /// whole map, and a planner that looks ahead by the range (random-bounce's straight runs)
    /// is not held back by it, so every larger range (up to `1e300`) runs exactly as this one,
    /// and estimates built on the range stay finite.
    ///
    /// [`sensor_range_for`]: Self::sensor_range_for
    pub fn sensor_range_on(&self, robot: &Robot, frame: &MapFrame) -> f64 {
        let cap = 2.0 * frame.width_m().hypot(frame.height_m());
        self.sensor_range_for(robot).min(cap)
    }
}

impl Default for SimConfig {
    fn default() -> Self {
        Self {
            sensor_range: None,
            max_steps: 50_000_000,
            exec: None,
            landmarks: LandmarkConfig::default(),
        }
    }
}

/// Motion steps in a row (rotations, translations, moves; marks do not count) after which a
/// robot whose true position has stayed within half a map pixel (or half its radius, when
/// that is smaller) of where they began is stopped as [`StopReason::Stalled`]. A planner that keeps driving into a wall it does not
/// see where it is (its pose estimate drifted under odometry noise, so each motion meets the
/// wall at once) would otherwise repeat that motion up to [`SimConfig::max_steps`] times: tens
/// of millions of collisions and gigabytes of trace before an answer. A working run moves at
/// least every few steps (a turn, then a stride of at least a tile or a lane), so the rule never
/// ends one.
pub const STALL_STEPS: u64 = 1000;

/// Why a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// The planner said it was done.
    Done,
    /// The step cap was reached.
    MaxSteps,
    /// The robot made no progress for [`STALL_STEPS`] motions in a row.
    Stalled,
}

impl StopReason {
    /// The name used in the trace's `finished` event and in the metrics: `done`, `max_steps`,
    /// `stalled`.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Done => "done",
            Self::MaxSteps => "max_steps",
            Self::Stalled => "stalled",
        }
    }

    /// The reason named `name` ([`Self::as_str`]'s inverse), if any.
    pub fn from_name(name: &str) -> Option<Self> {
        [Self::Done, Self::MaxSteps, Self::Stalled]
            .into_iter()
            .find(|s| s.as_str() == name)
    }
}

/// The outcome of a simulated run.
#[derive(Clone, Debug)]
pub struct RunOutput {
    /// Everything that happened.
    pub trace: Trace,
    /// Why it ended.
    pub stop: StopReason,
    /// The planner's tile side, if tile-based.
    pub tile_side: Option<f64>,
    /// Planner name.
    pub planner: &'static str,
    /// Wall time of planning + simulation, seconds.
    pub wall_time_s: f64,
}

/// The cosine and sine of the last few headings translated along (a lawnmower run uses a
/// handful), keyed by the heading's bits: the same values as computing them anew.
#[derive(Clone, Debug, Default)]
struct TrigMemo {
    /// `(heading bits, cos, sin)`; `None` slots are empty.
    slots: [Option<(u64, f64, f64)>; 4],
    /// The slot the next miss overwrites.
    next: usize,
}

impl TrigMemo {
    #[inline]
    fn cos_sin(&mut self, a: f64) -> (f64, f64) {
        let key = a.to_bits();
        for &(k, c, s) in self.slots.iter().flatten() {
            if k == key {
                return (c, s);
            }
        }
        let (c, s) = (a.cos(), a.sin());
        self.slots[self.next] = Some((key, c, s));
        self.next = (self.next + 1) % self.slots.len();
        (c, s)
    }
}

/// The pose records of one PID motion, without the control steps of a straight glide.
///
/// A robot driving straight along a map axis (bsa-bfs from cell to cell) keeps its heading
/// and one coordinate bit for bit while the other one runs on: such a pose lies exactly on
/// the segment between the poses before and after it, so it adds nothing to the recorded path
/// (its length, its swept floor, the tile centres it passes, its turns). It is held back and
/// dropped once the next pose carries the glide on; the glide's last pose is recorded. Every
/// other pose is recorded as it comes (on a diagonal, or while the heading drifts under
/// odometry noise, nothing is dropped). Without this, `bsa-bfs` on `tuw_freihaus_eg` recorded 4 070 276 poses, 98.5 % of
/// them inside such glides, and wrote a 305 MB `trace.jsonl`.
struct Glide {
    /// The last pose recorded in the trace.
    last: Pose,
    /// A pose not recorded yet, on the glide from `last`.
    held: Option<Pose>,
}

impl Glide {
    /// A motion from `last`, the trace's last pose.
    fn at(last: Pose) -> Self {
        Self { last, held: None }
    }

    /// Records `p` (at step `t`) unless it may lie inside a straight glide.
    fn offer(&mut self, trace: &mut Trace, t: u64, p: Pose) {
        if let Some(h) = self.held {
            if glides_on(self.last, h, p) {
                self.held = Some(p);
                return;
            }
            trace.push_pose(t, h);
            self.last = h;
            self.held = None;
        }
        if glide_step(self.last, p).is_some() {
            self.held = Some(p);
        } else {
            trace.push_pose(t, p);
            self.last = p;
        }
    }

    /// Records the held pose, if any (before an event, and at the end of the motion).
    fn flush(&mut self, trace: &mut Trace, t: u64) {
        if let Some(h) = self.held.take() {
            trace.push_pose(t, h);
            self.last = h;
        }
    }
}

/// Whether `b` moves on from `a` along a map axis without turning (heading and one coordinate
/// the same bit for bit, the other one different): `Some(true)` along x, `Some(false)` along y.
fn glide_step(a: Pose, b: Pose) -> Option<bool> {
    let same = |u: f64, v: f64| u.to_bits() == v.to_bits();
    if !same(a.theta, b.theta) {
        return None;
    }
    match (same(a.x, b.x), same(a.y, b.y)) {
        (false, true) => Some(true),
        (true, false) => Some(false),
        _ => None,
    }
}

/// Whether `a -> h -> p` is one straight glide along an axis with `h` strictly between `a`
/// and `p` (so dropping `h` leaves the path exactly as it was).
fn glides_on(a: Pose, h: Pose, p: Pose) -> bool {
    let between = |a: f64, h: f64, p: f64| (a < h && h < p) || (a > h && h > p);
    match (glide_step(a, h), glide_step(h, p)) {
        (Some(true), Some(true)) => between(a.x, h.x, p.x),
        (Some(false), Some(false)) => between(a.y, h.y, p.y),
        _ => false,
    }
}

/// PID execution state.
struct PidState {
    opts: PidOptions,
    tracker: Tracker,
    noise_rng: Option<SplitMix64>,
    /// Planned position after the last motion that ended without contact.
    anchor: Option<Point>,
    landmarks: LandmarkConfig,
    /// Control steps since the last landmark observation.
    since_fix: u64,
    /// Motions stopped at `max_steps_per_motion` before their goal, so far.
    cut: u64,
    /// The planned segment in force (the last [`Event::PlannedSegment`]).
    seg: Option<(Point, Point)>,
    /// The tracking error so far ([`Event::Tracking`]).
    tracking: TrackingTally,
}

/// Distances of the true pose from the planned segment, summed over the control steps.
#[derive(Clone, Copy, Debug, Default)]
struct TrackingTally {
    sum: f64,
    max: f64,
    n: u64,
}

impl TrackingTally {
    /// Measures pose `p` against `seg` (nothing before the first segment).
    fn add(&mut self, seg: Option<(Point, Point)>, p: Pose) {
        if let Some((a, b)) = seg {
            let d = crate::geometry::point_segment_dist(p.position(), a, b);
            self.sum += d;
            self.max = self.max.max(d);
            self.n += 1;
        }
    }
}

/// Drives a planner over a world.
pub struct Simulator<'w> {
    world: &'w World,
    /// The true pose.
    pose: Pose,
    /// The pose estimate (equal to `pose` in ideal mode).
    est: Pose,
    bumped: bool,
    range: f64,
    t: u64,
    trace: Trace,
    pid: Option<PidState>,
    landmarks: LandmarkConfig,
    exec_set: bool,
    trig: TrigMemo,
}

impl<'w> Simulator<'w> {
    /// A simulator at the world's start pose. With `config.exec == Some(..)` the execution mode
    /// is fixed now; with `None` it is chosen at [`run`](Self::run) from the planner (ideal
    /// when stepping through [`execute`](Self::execute) directly).
    pub fn new(world: &'w World, config: &SimConfig) -> Self {
        let range = config.sensor_range_on(&world.robot(), world.frame());
        let pose = world.initial_pose();
        let mut trace = Trace::default();
        trace.push_pose(0, pose);
        let mut sim = Self {
            world,
            pose,
            est: pose,
            bumped: false,
            range,
            t: 0,
            trace,
            pid: None,
            landmarks: config.landmarks.clone(),
            exec_set: false,
            trig: TrigMemo::default(),
        };
        sim.drive_approach();
        if let Some(e) = config.exec {
            sim.set_execution(e);
        }
        sim
    }

    /// Drives [`World::approach`] (a start outside the work area) exactly, before the planner
    /// gets control: a [`Event::Note`] with its length, then one rotation and translation per
    /// waypoint, checked against the true map like any motion.
    fn drive_approach(&mut self) {
        let world = self.world;
        if world.approach().is_empty() {
            return;
        }
        self.trace.push_event(
            0,
            Event::Note {
                text: format!(
                    "approach: the start is outside the area; driving {:.3} m to ({:.3}, {:.3})",
                    world.approach_length_m(),
                    world.start().x,
                    world.start().y
                ),
            },
        );
        for &p in world.approach() {
            let d = p.sub(self.pose.position());
            let dist = d.norm();
            if dist > 1e-12 {
                self.rotate(wrap_angle(d.y.atan2(d.x) - self.pose.theta));
                self.translate(dist);
            }
        }
    }

    /// Sets the execution mode (before the first step; later calls are ignored).
    fn set_execution(&mut self, exec: Execution) {
        if self.exec_set {
            return;
        }
        self.exec_set = true;
        if let Execution::Pid(opts) = exec {
            self.trace.push_event(
                self.t,
                Event::Execution {
                    mode: "pid".to_string(),
                    dt_s: opts.dt_s,
                    tolerance_m: opts.tolerance_m,
                    noisy: opts.noise.is_some_and(|n| n.draws()),
                },
            );
            self.pid = Some(PidState {
                opts,
                tracker: Tracker::new(&opts),
                noise_rng: opts.noise.map(|n| SplitMix64::new(n.seed)),
                anchor: Some(self.pose.position()),
                landmarks: self.landmarks.clone(),
                since_fix: 0,
                cut: 0,
                seg: None,
                tracking: TrackingTally::default(),
            });
        }
    }

    /// The true pose.
    pub fn true_pose(&self) -> Pose {
        self.pose
    }

    /// The pose estimate (what the planner sees).
    pub fn estimate(&self) -> Pose {
        self.est
    }

    /// The trace so far.
    pub fn trace(&self) -> &Trace {
        &self.trace
    }

    /// The [`Event::Tracking`] of the run so far: PID execution after a planned segment only
    /// (a run ends its trace with it; a caller stepping through [`Self::execute`] appends it
    /// to a copy of the trace for the tracking metrics).
    pub fn tracking(&self) -> Option<Event> {
        let st = self.pid.as_ref()?;
        st.seg?;
        let t = st.tracking;
        Some(Event::Tracking {
            mean_m: if t.n == 0 { 0.0 } else { t.sum / t.n as f64 },
            max_m: t.max,
            steps: t.n,
        })
    }

    /// Executes one step (anything but `Done`).
    pub fn execute(&mut self, step: Step) {
        self.t += 1;
        self.exec_set = true;
        if self.pid.is_some() {
            self.execute_pid(step);
            return;
        }
        match step {
            Step::Rotate(a) => self.rotate(a),
            Step::Translate(d) => self.translate(d),
            Step::MoveTo(p) => {
                // `|p - pose|` and its heading, bit for bit, without the calls for the axis
                // moves of tile-based planners.
                let a = self.pose.position();
                let dist = dist_exact(p, a);
                if dist > 1e-12 {
                    let turn = wrap_angle(atan2_exact(p.y - a.y, p.x - a.x) - self.pose.theta);
                    if !is_rounding_turn(turn, dist, a, p) {
                        self.rotate(turn);
                    }
                    self.translate(dist);
                }
            }
            Step::Mark(e) => self.trace.push_event(self.t, e),
            Step::Done => {}
        }
    }

    fn rotate(&mut self, a: f64) {
        if !a.is_finite() || a.abs() < MIN_ROTATION {
            return;
        }
        self.pose.theta = wrap_angle(self.pose.theta + a);
        self.est = self.pose;
        self.bumped = false;
        self.trace.push_pose(self.t, self.pose);
    }

    /// Longest move that can stay on the map: its diagonal plus the robot's diameter and a
    /// metre. A longer one meets the map's edge first, so it is cut to this length: a move of
    /// 1e307 m met its contact at a fraction of the move below `f64`'s resolution, and the
    /// robot stayed where it was, reported in collision (Python `Env`: hostile pass).
    fn reach_limit(&self) -> f64 {
        let f = self.world.frame();
        f.width_m().hypot(f.height_m()) + 2.0 * self.world.robot().radius + 1.0
    }

    fn translate(&mut self, d: f64) {
        if !d.is_finite() || d == 0.0 {
            return;
        }
        let dir = if d >= 0.0 {
            self.pose.theta
        } else {
            self.pose.theta + std::f64::consts::PI
        };
        let a = self.pose.position();
        let (c, s) = self.trig.cos_sin(dir);
        let len = d.abs().min(self.reach_limit());
        let b = Point::new(a.x + len * c, a.y + len * s);
        match self.world.true_first_contact(a, b) {
            None => {
                self.pose.x = b.x;
                self.pose.y = b.y;
                self.bumped = false;
                self.trace.push_pose(self.t, self.pose);
            }
            Some(t) => {
                let p = a.add(b.sub(a).scale(t));
                self.pose.x = p.x;
                self.pose.y = p.y;
                self.bumped = true;
                if t > 0.0 {
                    self.trace.push_pose(self.t, self.pose);
                }
                self.trace
                    .push_event(self.t, Event::Collision { x: p.x, y: p.y });
            }
        }
        self.est = self.pose;
    }

    fn execute_pid(&mut self, step: Step) {
        let Some(st) = self.pid.as_ref() else { return };
        let est = self.est;
        let anchor = st.anchor;
        match step {
            Step::Rotate(a) => {
                if a.is_finite() && a.abs() >= MIN_ROTATION {
                    self.pid_motion(&Goal::Heading(wrap_angle(est.theta + a)), anchor);
                }
            }
            Step::Translate(d) => {
                if d.is_finite() && d != 0.0 {
                    let d = d.clamp(-self.reach_limit(), self.reach_limit());
                    let from = est.position();
                    let to = Point::new(from.x + d * est.theta.cos(), from.y + d * est.theta.sin());
                    self.push_segment(from, to);
                    self.pid_motion(
                        &Goal::Segment {
                            from,
                            to,
                            reverse: d < 0.0,
                        },
                        Some(to),
                    );
                }
            }
            Step::MoveTo(p) => {
                if p.is_finite() {
                    let from = anchor.unwrap_or(est.position());
                    self.push_segment(from, p);
                    self.pid_motion(
                        &Goal::Segment {
                            from,
                            to: p,
                            reverse: false,
                        },
                        Some(p),
                    );
                }
            }
            Step::Mark(e) => self.trace.push_event(self.t, e),
            Step::Done => {}
        }
    }

    fn push_segment(&mut self, from: Point, to: Point) {
        if let Some(st) = self.pid.as_mut() {
            st.seg = Some((from, to));
        }
        self.trace.push_event(
            self.t,
            Event::PlannedSegment {
                from: [from.x, from.y],
                to: [to.x, to.y],
            },
        );
    }

    /// Runs the controller until `goal` is reached, contact, or the per-motion cap. On success
    /// the PID anchor becomes `next_anchor`.
    fn pid_motion(&mut self, goal: &Goal, next_anchor: Option<Point>) {
        let Some(mut st) = self.pid.take() else {
            return;
        };
        st.tracker.reset();
        let dt = st.opts.dt_s;
        let every = u64::from(st.opts.record_every.max(1));
        let fix_every = if st.landmarks.landmarks.is_empty() {
            u64::MAX
        } else {
            ((st.landmarks.period_s / dt).round() as u64).max(1)
        };
        self.bumped = false;
        let mut contact = false;
        let mut moved = false;
        let mut since_record = 0u64;
        // The motion starts where the trace's last pose is.
        let mut glide = Glide::at(self.pose);
        // Control steps run; all of them (and no contact): the motion was cut at the cap.
        let mut ran = 0u32;
        // Whether the last command turned in place (no linear speed).
        let mut was_in_place = None;
        // The controller and the integration work in coordinates relative to the map's origin
        // (a translation: exact at the origin (0, 0)), the world poses being derived from them.
        // In world coordinates far from zero (UTM, 5.4e6 m) every step rounded the pose to
        // 1e-9 m, and the controller's bearing to an aim point a few centimetres ahead turned
        // that into heading errors of 1e-6 rad: rect-boustrophedon on a room moved there made
        // in-place turns of that size, 10 turns instead of 8 (hostile pass).
        let o = self.world.frame().origin.position();
        let local = |p: Pose| Pose::new(p.x - o.x, p.y - o.y, p.theta);
        let world = |p: Pose| Pose::new(p.x + o.x, p.y + o.y, p.theta);
        let goal_l = match *goal {
            Goal::Heading(h) => Goal::Heading(h),
            Goal::Segment { from, to, reverse } => Goal::Segment {
                from: from - o,
                to: to - o,
                reverse,
            },
        };
        let mut est_l = local(self.est);
        let mut pose_l = local(self.pose);
        for _ in 0..st.opts.max_steps_per_motion {
            let Some((v, w)) = st.tracker.command(est_l, &goal_l) else {
                break;
            };
            ran += 1;
            // The pose where the robot starts or stops turning in place is recorded whatever
            // `record_every` is: the metrics count in-place rotations between poses at one
            // position, and a thinned trace that skipped these poses showed none (bsa-bfs on
            // teb_maze: 182 turns at `record_every: 1`, 0 at 1000).
            let in_place = v == 0.0;
            if was_in_place.is_some_and(|was| was != in_place) && moved {
                since_record = 0;
                glide.offer(&mut self.trace, self.t, self.pose);
                moved = false;
            }
            was_in_place = Some(in_place);
            // The truth moves with the (possibly perturbed) speeds; the estimate integrates the
            // commanded (measured) ones.
            let (vt, wt) = match (st.opts.noise, st.noise_rng.as_mut()) {
                (Some(n), Some(rng)) => {
                    // Deviations given per step of the reference period (`OdometryNoise`).
                    let k = (crate::exec::NOISE_REF_DT_S / dt).sqrt();
                    (
                        v * (1.0 + k * n.linear_rel_std * rng.gaussian()),
                        w * (1.0 + k * n.angular_rel_std * rng.gaussian())
                            + k * n.heading_drift_std * v.abs() * rng.gaussian(),
                    )
                }
                _ => (v, w),
            };
            let new_est_l = Unicycle::step(est_l, v, w, dt);
            let new_true_l = Unicycle::step(pose_l, vt, wt, dt);
            let (new_est, new_true) = (world(new_est_l), world(new_true_l));
            let a = self.pose.position();
            let b = new_true.position();
            // A turn in place (no linear speed) cannot touch anything the disk does not touch
            // already; the world-local round trip can still move its position by a rounding
            // error, which, against a wall the robot had bumped, counted as a contact: the
            // robot could never turn away from a wall it touched (ba-star under odometry
            // noise: 1000 contacts in one place, then the stall stop).
            let hit = if a == b || vt == 0.0 {
                None
            } else {
                self.world.true_first_contact(a, b)
            };
            if let Some(t) = hit {
                let p = a + (b - a).scale(t);
                // The estimate advances by the same fraction of its own motion.
                let e0 = self.est.position();
                let e = e0 + (new_est.position() - e0).scale(t);
                self.pose = Pose::new(
                    p.x,
                    p.y,
                    self.pose.theta + t * wrap_angle(new_true.theta - self.pose.theta),
                );
                self.est = Pose::new(
                    e.x,
                    e.y,
                    self.est.theta + t * wrap_angle(new_est.theta - self.est.theta),
                );
                if t > 0.0 {
                    st.tracking.add(st.seg, self.pose);
                    glide.offer(&mut self.trace, self.t, self.pose);
                }
                glide.flush(&mut self.trace, self.t);
                self.trace
                    .push_event(self.t, Event::Collision { x: p.x, y: p.y });
                contact = true;
                break;
            }
            (self.pose, self.est) = (new_true, new_est);
            (pose_l, est_l) = (new_true_l, new_est_l);
            st.tracking.add(st.seg, self.pose);
            moved = true;
            since_record += 1;
            if since_record >= every {
                since_record = 0;
                glide.offer(&mut self.trace, self.t, self.pose);
                moved = false;
            }
            st.since_fix += 1;
            if st.since_fix >= fix_every {
                st.since_fix = 0;
                if let Some(fix) = self.landmark_fix(&st.landmarks) {
                    est_l = local(self.est);
                    glide.flush(&mut self.trace, self.t);
                    self.trace.push_event(self.t, fix);
                }
            }
        }
        if moved {
            glide.offer(&mut self.trace, self.t, self.pose);
        }
        glide.flush(&mut self.trace, self.t);
        if !contact
            && ran == st.opts.max_steps_per_motion
            && st.tracker.command(est_l, &goal_l).is_some()
        {
            // The goal was not reached: the run goes on from where the robot is, which a
            // control period far too short for the cap (`dt_s: 1e-9`) made a run of 0 m that
            // ended "done" without a word. The first cut is noted, then every 1000th.
            st.cut += 1;
            if st.cut == 1 || st.cut % 1000 == 0 {
                self.trace.push_event(
                    self.t,
                    Event::Note {
                        text: format!(
                            "{MOTION_CUT_NOTE} ({} so far; max_steps_per_motion {} at dt_s {} s)",
                            st.cut, st.opts.max_steps_per_motion, dt
                        ),
                    },
                );
            }
        }
        self.bumped = contact;
        st.anchor = if contact {
            None
        } else {
            next_anchor.or(st.anchor)
        };
        self.pid = Some(st);
    }

    /// Observes the nearest landmark in range (from the truth) and resets the estimate to the
    /// candidate closest to it; returns the [`Event::LandmarkFix`] to record, if it did.
    fn landmark_fix(&mut self, cfg: &LandmarkConfig) -> Option<Event> {
        let l = nearest_in_range(self.pose.position(), &cfg.landmarks, cfg.range_m)?;
        let obs = observe(self.pose, l);
        let p = choose_pose(self.est, &obs, &cfg.landmarks)?;
        self.est = p;
        Some(Event::LandmarkFix {
            id: obs.id,
            x: p.x,
            y: p.y,
            theta: p.theta,
        })
    }

    /// Runs `planner` to completion (or the step cap).
    pub fn run(self, planner: &mut dyn Planner, config: &SimConfig) -> RunOutput {
        self.run_tapped(planner, config, &mut |_| {})
    }

    /// [`Self::run`], calling `tap` with the trace after every executed step (to copy out its
    /// [sealed](Trace::sealed_count) pieces while the run goes on). The tap only reads: the
    /// run is the same.
    pub fn run_tapped(
        self,
        planner: &mut dyn Planner,
        config: &SimConfig,
        tap: &mut dyn FnMut(&Trace),
    ) -> RunOutput {
        self.run_stoppable(planner, config, tap, None).0
    }

    /// [`Self::run_tapped`], stopped between two steps once another thread sets `stop`
    /// (looked at every [`STOP_CHECK_STEPS`] steps): `None` when it was stopped. A caller
    /// that gives up on a run (Python's Ctrl-C) ends its work instead of leaving it to run
    /// to the end. The planning an offline planner does before its first step is not stopped.
    pub fn run_until(
        self,
        planner: &mut dyn Planner,
        config: &SimConfig,
        tap: &mut dyn FnMut(&Trace),
        stop: &AtomicBool,
    ) -> Option<RunOutput> {
        match self.run_stoppable(planner, config, tap, Some(stop)) {
            (out, false) => Some(out),
            (_, true) => None,
        }
    }

    /// The run, and whether `stop` ended it.
    fn run_stoppable(
        mut self,
        planner: &mut dyn Planner,
        config: &SimConfig,
        tap: &mut dyn FnMut(&Trace),
        stop_flag: Option<&AtomicBool>,
    ) -> (RunOutput, bool) {
        let started = std::time::Instant::now();
        if !self.exec_set {
            let e = config
                .exec
                .or_else(|| planner.preferred_execution())
                .unwrap_or_default();
            self.set_execution(e);
        }
        let mut stop = StopReason::MaxSteps;
        // The stall rule: motions since the true position last left half a pixel (or half the
        // robot's radius, when smaller) around `anchor`. (A robot much smaller than a pixel
        // moves less than half a pixel per tile: BA* at r = 1e-4 m on a 1 m/px map was
        // stopped as stalled after 0.2 m of correct driving: hostile pass.)
        let near = 0.5 * self.world.frame().resolution.min(self.world.robot().radius);
        let mut anchor = self.pose.position();
        let mut still = 0u64;
        let mut stopped = false;
        for n in 0..config.max_steps {
            if n % STOP_CHECK_STEPS == 0 && stop_flag.is_some_and(|f| f.load(Ordering::Relaxed)) {
                stopped = true;
                break;
            }
            let step = planner.next(&self);
            if step == Step::Done {
                stop = StopReason::Done;
                break;
            }
            let motion = !matches!(step, Step::Mark(_));
            self.execute(step);
            tap(&self.trace);
            if motion {
                let p = self.pose.position();
                if p.sub(anchor).norm() > near {
                    anchor = p;
                    still = 0;
                } else {
                    still += 1;
                    if still >= STALL_STEPS {
                        stop = StopReason::Stalled;
                        break;
                    }
                }
            }
        }
        // The count of cut motions in all (the notes on the way give the first and every
        // 1000th: a warning read from the last of them under-reported up to 999).
        if let Some(st) = &self.pid {
            if st.cut > 1 && st.cut % 1000 != 0 {
                let text = format!(
                    "{MOTION_CUT_NOTE} ({} in all; max_steps_per_motion {} at dt_s {} s)",
                    st.cut, st.opts.max_steps_per_motion, st.opts.dt_s
                );
                self.trace.push_event(self.t, Event::Note { text });
            }
        }
        if let Some(e) = self.tracking() {
            self.trace.push_event(self.t, e);
        }
        self.trace.push_event(
            self.t,
            Event::Finished {
                reason: stop.as_str().to_string(),
            },
        );
        let out = RunOutput {
            trace: self.trace,
            stop,
            tile_side: planner.tile_side(),
            planner: planner.name(),
            wall_time_s: started.elapsed().as_secs_f64(),
        };
        (out, stopped)
    }
}

/// How often (in steps) [`Simulator::run_until`] looks at its stop flag.
pub const STOP_CHECK_STEPS: u64 = 64;

// `pose` is the estimate by design: the planner sees odometry/localization, not the truth.
#[allow(clippy::misnamed_getters)]
impl Sensor for Simulator<'_> {
    fn frame(&self) -> &MapFrame {
        self.world.frame()
    }
    fn robot(&self) -> Robot {
        self.world.robot()
    }
    fn pose(&self) -> Pose {
        self.est
    }
    fn sensor_range(&self) -> f64 {
        self.range
    }
    fn scan(&self) -> Scan<'_> {
        Scan::new(self.world.map(), self.pose.position(), self.range)
    }
    fn bumped(&self) -> bool {
        self.bumped
    }
}

/// The start of the [`Event::Note`] the simulator writes when a PID motion is stopped at
/// `max_steps_per_motion` before reaching its goal (the first time, then every 1000th, with
/// the count so far); the run goes on from where the robot is.
pub const MOTION_CUT_NOTE: &str = "PID motion stopped at max_steps_per_motion before its goal";

/// PID motions of a run stopped at `max_steps_per_motion` before their goal, as the
/// [`MOTION_CUT_NOTE`] notes of `trace` count them (the first, every 1000th and, at the run's
/// end, the count in all); `None` when no motion was cut.
pub fn motions_cut(trace: &Trace) -> Option<u64> {
    let mut last = None;
    for e in trace.entries() {
        if let crate::trace::Entry::Event {
            event: Event::Note { text },
            ..
        } = e
        {
            if let Some(rest) = text.strip_prefix(MOTION_CUT_NOTE) {
                let n = rest
                    .trim_start_matches(" (")
                    .split(' ')
                    .next()
                    .and_then(|n| n.parse::<u64>().ok());
                last = n.or(last);
            }
        }
    }
    last
}

/// [`simulate_tapped`] that another thread can stop ([`Simulator::run_until`]): `None` when
/// `stop` ended it.
pub fn simulate_until(
    world: &World,
    planner: &mut dyn Planner,
    config: &SimConfig,
    tap: &mut dyn FnMut(&Trace),
    stop: &AtomicBool,
) -> Option<RunOutput> {
    Simulator::new(world, config).run_until(planner, config, tap, stop)
}

/// Convenience: simulate `planner` on `world` with `config`.
pub fn simulate(world: &World, planner: &mut dyn Planner, config: &SimConfig) -> RunOutput {
    Simulator::new(world, config).run(planner, config)
}

/// [`simulate`] with a tap on the growing trace ([`Simulator::run_tapped`]).
pub fn simulate_tapped(
    world: &World,
    planner: &mut dyn Planner,
    config: &SimConfig,
    tap: &mut dyn FnMut(&Trace),
) -> RunOutput {
    Simulator::new(world, config).run_tapped(planner, config, tap)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridMap;

    /// A rotation is rounding when it moves the end of the move sideways by less than the
    /// coordinates' own precision: 3e-9 rad before a 0.3 m move at (1e6, 2e6) m is; the same
    /// near the origin is a (tiny) turn, and so is a milliradian anywhere.
    #[test]
    fn rounding_turns_are_told_from_turns() {
        let far = (Point::new(1e6, 2e6), Point::new(1e6 + 0.3, 2e6));
        let near = (Point::new(10.0, 20.0), Point::new(10.3, 20.0));
        assert!(is_rounding_turn(3e-9, 0.3, far.0, far.1));
        assert!(!is_rounding_turn(3e-9, 0.3, near.0, near.1));
        assert!(!is_rounding_turn(1e-3, 0.3, far.0, far.1));
        assert!(!is_rounding_turn(std::f64::consts::PI, 0.3, far.0, far.1));
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

    /// A robot much smaller than the map's pixels that sweeps back and forth inside one pixel
    /// (its moves 3 mm, its radius 1 mm, the pixel 1 m) makes progress: it was stopped as
    /// stalled after 1000 motions, its true position never half a pixel from where it began
    /// (hostile pass). One that keeps pushing into a wall still stalls.
    #[test]
    fn a_tiny_robot_sweeping_inside_one_pixel_is_not_stalled() {
        let map = GridMap::from_ascii_scaled("#####\n#...#\n#####", 1, 1.0).unwrap();
        let world = World::new(map, Robot::new(0.001), Some(Pose::new(1.5, 1.5, 0.0))).unwrap();
        let mut steps = Vec::new();
        for k in 0..1500 {
            steps.push(Step::Translate(if (k / 100) % 2 == 0 {
                0.003
            } else {
                -0.003
            }));
        }
        let out = simulate(&world, &mut Script(steps), &SimConfig::default());
        assert_eq!(out.stop, StopReason::Done);
        let mut p = Script(vec![Step::Translate(5.0); 1500]);
        let out = simulate(&world, &mut p, &SimConfig::default());
        assert_eq!(out.stop, StopReason::Stalled);
    }

    #[test]
    fn bumper_stops_at_contact() {
        let map = GridMap::from_ascii_scaled("#####\n#...#\n#####", 10, 0.1).unwrap();
        // Interior x in [1, 4] m, y in [1, 2]. Robot r = 0.3 at (1.5, 1.5) heading east.
        let world = World::new(map, Robot::new(0.3), Some(Pose::new(1.5, 1.5, 0.0))).unwrap();
        let mut p = Script(vec![Step::Translate(5.0)]);
        let out = simulate(&world, &mut p, &SimConfig::default());
        let last = out.trace.poses().last().unwrap();
        // Blocked pixel centres at x = 4.05, y = 1.45 and 1.55 (the robot runs along a pixel
        // boundary): contact when the distance reaches r + res/2 = 0.35.
        let expect = 4.05 - (0.35f64.powi(2) - 0.05f64.powi(2)).sqrt();
        assert!((last.x - expect).abs() < 1e-6, "{last:?} vs {expect}");
        assert_eq!(
            out.trace
                .events()
                .filter(|(_, e)| matches!(e, Event::Collision { .. }))
                .count(),
            1
        );
    }

    /// A move far longer than the map stops at the same contact as a short one that reaches the
    /// wall: one of 1e307 m met its contact at a fraction of the move below `f64`'s resolution,
    /// and the robot stayed where it was, in collision (Python `Env`: hostile pass).
    #[test]
    fn a_move_of_any_length_stops_at_the_wall() {
        let map = GridMap::from_ascii_scaled("#####\n#...#\n#####", 10, 0.1).unwrap();
        let world = World::new(map, Robot::new(0.3), Some(Pose::new(1.5, 1.5, 0.0))).unwrap();
        let end = |d: f64| {
            let out = simulate(
                &world,
                &mut Script(vec![Step::Translate(d)]),
                &SimConfig::default(),
            );
            out.trace.poses().last().unwrap()
        };
        let wall = end(5.0);
        for d in [1e200, 1e307, f64::MAX] {
            assert_eq!(end(d), wall, "{d}");
        }
        let back = end(-5.0);
        assert_eq!(end(-f64::MAX), back);
        assert!(back.x < 1.5 && wall.x > 3.0, "{back:?} {wall:?}");
    }

    use crate::exec::{OdometryNoise, PidOptions};
    use crate::landmarks::Landmark;

    fn big_room() -> World {
        // 8 m x 8 m at 0.05 m/px with a 1-pixel wall; start in the middle.
        let mut art = String::new();
        for r in 0..160 {
            for c in 0..160 {
                art.push(if r == 0 || c == 0 || r == 159 || c == 159 {
                    '#'
                } else {
                    '.'
                });
            }
            art.push('\n');
        }
        let map = GridMap::from_ascii_scaled(&art, 1, 0.05).unwrap();
        World::new(map, Robot::new(0.15), Some(Pose::new(4.0, 4.0, 0.0))).unwrap()
    }

    fn square(n: usize) -> Vec<Step> {
        let mut v = Vec::new();
        for _ in 0..n {
            for (x, y) in [(5.0, 4.0), (5.0, 5.0), (4.0, 5.0), (4.0, 4.0)] {
                v.push(Step::MoveTo(Point::new(x, y)));
            }
        }
        v
    }

    fn pid(noise: Option<OdometryNoise>) -> SimConfig {
        SimConfig {
            exec: Some(Execution::Pid(PidOptions {
                noise,
                ..PidOptions::default()
            })),
            ..SimConfig::default()
        }
    }

    #[test]
    fn a_stop_flag_ends_the_run_between_steps() {
        let world = big_room();
        let cfg = SimConfig::default();
        // Not set: the same run as without a flag.
        let flag = AtomicBool::new(false);
        let free = simulate_until(&world, &mut Script(square(50)), &cfg, &mut |_| {}, &flag)
            .expect("a run whose flag is never set finishes");
        let plain = simulate(&world, &mut Script(square(50)), &cfg);
        let poses = |o: &RunOutput| o.trace.poses().collect::<Vec<_>>();
        assert_eq!(poses(&free), poses(&plain));
        // Set by the tap after the first steps: the run stops within STOP_CHECK_STEPS steps.
        let flag = AtomicBool::new(false);
        let mut steps = 0u64;
        let stopped = simulate_until(
            &world,
            &mut Script(square(50)),
            &cfg,
            &mut |_| {
                steps += 1;
                if steps == 10 {
                    flag.store(true, Ordering::Relaxed);
                }
            },
            &flag,
        );
        assert!(stopped.is_none());
        assert!(steps <= STOP_CHECK_STEPS, "{steps} steps");
    }

    #[test]
    fn square_is_tracked_with_bounded_error() {
        let world = big_room();
        let out = simulate(&world, &mut Script(square(2)), &pid(None));
        let m = crate::metrics::compute(&world, &out, "room");
        assert_eq!(m.collisions, 0);
        let (mean, max) = crate::metrics::tracking_error(&out.trace).unwrap();
        assert!(max < 1e-6, "max tracking error {max}");
        assert!(mean <= max);
        assert_eq!(m.tracking_error_max_m, Some(max));
        // Two laps of 4 m, and the turns are in place.
        assert!((m.path_length_m - 8.0).abs() < 1e-4, "{}", m.path_length_m);
        let end = out.trace.poses().last().unwrap();
        assert!(end.position().dist(Point::new(4.0, 4.0)) < 1e-6);
        // A coarse tolerance still tracks the square within it (plus the lateral overshoot of
        // the corner, bounded by the tolerance too).
        let coarse = SimConfig {
            exec: Some(Execution::Pid(PidOptions {
                tolerance_m: 0.03,
                heading_tolerance_rad: 0.01,
                ..PidOptions::default()
            })),
            ..SimConfig::default()
        };
        let out = simulate(&world, &mut Script(square(1)), &coarse);
        let (_, max) = crate::metrics::tracking_error(&out.trace).unwrap();
        assert!(max < 0.03 + 1e-9, "coarse max {max}");
    }

    /// A PID motion's poses recorded through [`Glide`] make the same path as all of them:
    /// the same metrics (length within rounding, the same swept floor, tiles, turns), with
    /// only the poses inside straight axis glides left out.
    #[test]
    fn glides_record_the_same_path_with_fewer_poses() {
        let world = big_room();
        // Control steps as a PID motion makes them: decelerating along x, a reversal, a spin,
        // a glide along y, a diagonal, steps that repeat a pose, a glide that ends sideways.
        let mut steps: Vec<Pose> = Vec::new();
        let mut x = 4.0;
        for k in 0..40 {
            x += 0.025 * 0.9f64.powi(k);
            steps.push(Pose::new(x, 4.0, 0.0));
        }
        for k in 0..5 {
            steps.push(Pose::new(x - 0.01 * f64::from(k + 1), 4.0, 0.0));
        }
        let x = steps.last().unwrap().x;
        for k in 0..10 {
            steps.push(Pose::new(x, 4.0, 0.15 * f64::from(k + 1)));
        }
        let th = steps.last().unwrap().theta;
        let mut y = 4.0;
        for k in 0..30 {
            y += 0.02 + 0.001 * f64::from(k % 3);
            steps.push(Pose::new(x, y, th));
        }
        steps.push(Pose::new(x, y, th));
        steps.push(Pose::new(x, y, th));
        for k in 0..10 {
            let d = 0.01 * f64::from(k + 1);
            steps.push(Pose::new(x + d, y + d, th));
        }
        let (x, y) = (steps.last().unwrap().x, steps.last().unwrap().y);
        for k in 0..8 {
            steps.push(Pose::new(x + 0.03 * f64::from(k + 1), y, th));
        }
        steps.push(Pose::new(x + 0.24, y + 0.05, th));
        let start = Pose::new(4.0, 4.0, 0.0);
        let mut all = Trace::default();
        all.push_pose(0, start);
        let mut thin = all.clone();
        for &p in &steps {
            all.push_pose(1, p);
        }
        let mut glide = Glide::at(start);
        for &p in &steps {
            glide.offer(&mut thin, 1, p);
        }
        glide.flush(&mut thin, 1);
        let (n_all, n_thin) = (all.poses().count(), thin.poses().count());
        assert!(n_thin * 3 < n_all, "{n_thin} of {n_all} poses recorded");
        // Every pose recorded is one of the motion's, in order, and the last one is there.
        let kept: Vec<Pose> = thin.poses().skip(1).collect();
        let mut it = steps.iter();
        assert!(kept.iter().all(|k| it.any(|p| p == k)));
        assert_eq!(kept.last(), steps.last());
        let metrics = |trace: Trace| {
            let out = RunOutput {
                trace,
                stop: StopReason::Done,
                tile_side: Some(0.3),
                planner: "script",
                wall_time_s: 0.0,
            };
            crate::metrics::compute(&world, &out, "room")
        };
        let (a, b) = (metrics(all), metrics(thin));
        assert!((a.path_length_m - b.path_length_m).abs() < 1e-12);
        assert_eq!(a.effective_coverage, b.effective_coverage);
        assert_eq!(a.coverage_rate, b.coverage_rate);
        assert_eq!(a.revisit_rate, b.revisit_rate);
        assert_eq!(a.turns, b.turns);
        assert!((a.rotation_rad - b.rotation_rad).abs() < 1e-12);
        assert!(a.effective_coverage > 0.0 && a.turns > 0);
    }

    /// A PID run along the axes records the ends of its glides, not its control steps.
    #[test]
    fn a_pid_square_records_its_corners_not_its_control_steps() {
        let world = big_room();
        let out = simulate(&world, &mut Script(square(2)), &pid(None));
        let poses: Vec<Pose> = out.trace.poses().collect();
        // Two laps of four sides: each side's glide is one pose; each corner's turn in place
        // is recorded step by step (its start and end are what `turns` counts).
        let at_corners = poses
            .iter()
            .filter(|p| {
                [(4.0, 4.0), (5.0, 4.0), (5.0, 5.0), (4.0, 5.0)]
                    .iter()
                    .any(|&(x, y)| Point::new(x, y).dist(p.position()) < 1e-6)
            })
            .count();
        assert!(
            poses.len() - at_corners <= 8,
            "{} poses, {at_corners} at corners",
            poses.len()
        );
        let m = crate::metrics::compute(&world, &out, "room");
        assert!((m.path_length_m - 8.0).abs() < 1e-9, "{}", m.path_length_m);
        assert_eq!(m.turns, 7);
    }

    /// Thinning the PID trace keeps the in-place turns: the pose where a turn starts or ends
    /// is recorded whatever `record_every` is (it once gave 0 turns at 1000).
    #[test]
    fn thinned_pid_traces_count_the_same_turns() {
        let world = big_room();
        let every = |record_every| SimConfig {
            exec: Some(Execution::Pid(PidOptions {
                record_every,
                ..PidOptions::default()
            })),
            ..SimConfig::default()
        };
        let full = simulate(&world, &mut Script(square(2)), &every(1));
        let full = crate::metrics::compute(&world, &full, "room");
        // Two laps of four corners; the first move already faces east.
        assert_eq!(full.turns, 7);
        for n in [10, 1000, u32::MAX] {
            let out = simulate(&world, &mut Script(square(2)), &every(n));
            let m = crate::metrics::compute(&world, &out, "room");
            assert_eq!(m.turns, full.turns, "record_every {n}");
            assert!(
                (m.rotation_rad - full.rotation_rad).abs() < 1e-6,
                "record_every {n}: {} against {}",
                m.rotation_rad,
                full.rotation_rad
            );
            assert!((m.path_length_m - full.path_length_m).abs() < 1e-6);
        }
    }

    /// The tracking error is measured over every control step, so thinning the records does
    /// not change it (over the recorded poses, a noisy run's mean moved with `record_every`).
    #[test]
    fn the_tracking_error_does_not_depend_on_the_records_kept() {
        let world = big_room();
        let cfg = |record_every| SimConfig {
            exec: Some(Execution::Pid(PidOptions {
                record_every,
                noise: Some(OdometryNoise {
                    seed: 7,
                    ..OdometryNoise::default()
                }),
                ..PidOptions::default()
            })),
            ..SimConfig::default()
        };
        let full = simulate(&world, &mut Script(square(2)), &cfg(1));
        let (mean, max) = crate::metrics::tracking_error(&full.trace).unwrap();
        assert!(mean > 1e-4 && max > mean, "{mean} {max}");
        // The figure from the records alone, for comparison: the trace without its event.
        let records_only = |trace: &Trace| {
            let mut out = Trace::default();
            for e in trace.entries() {
                match e {
                    crate::trace::Entry::Pose { t, pose } => out.push_pose(t, pose),
                    crate::trace::Entry::Event {
                        event: Event::Tracking { .. },
                        ..
                    } => {}
                    crate::trace::Entry::Event { t, event } => out.push_event(t, event.clone()),
                }
            }
            out
        };
        let records = records_only(&full.trace);
        for n in [3, 10] {
            let thin = simulate(&world, &mut Script(square(2)), &cfg(n));
            assert!(thin.trace.pose_count() < full.trace.pose_count());
            assert_eq!(
                crate::metrics::tracking_error(&thin.trace),
                Some((mean, max)),
                "record_every {n}"
            );
            let rec = records_only(&thin.trace);
            assert_ne!(
                crate::metrics::tracking_error(&rec).map(|m| m.0),
                crate::metrics::tracking_error(&records).map(|m| m.0),
                "record_every {n}: the records alone give another mean"
            );
        }
    }

    /// A robot that bumped a wall turns away from it and drives off: the turn in place is no
    /// contact. The world-local round trip of the PID loop moved the position by a rounding
    /// error during the turn, which against the wall counted as a contact, so every later
    /// motion stopped at once (ba-star under odometry noise: 1000 contacts in one place).
    #[test]
    fn a_robot_at_a_wall_turns_away_and_drives_off() {
        let mut stuck = 0;
        for k in 0..40 {
            // Origins whose world-local round trip rounds (at (0, 0) it is exact).
            let o = Point::new(-10.3 - 0.0137 * f64::from(k), -7.7 + 0.0093 * f64::from(k));
            let world = big_room();
            let map = world
                .map()
                .clone()
                .with_placement(0.05, Pose::new(o.x, o.y, 0.0))
                .unwrap();
            let world = World::new(
                map,
                Robot::new(0.15),
                Some(Pose::new(o.x + 4.0, o.y + 4.0, 0.0)),
            )
            .unwrap();
            let mut sim = Simulator::new(&world, &pid(None));
            // Into the east wall (x = 8 m less the wall pixel), at a slant.
            sim.execute(Step::MoveTo(Point::new(o.x + 9.0, o.y + 4.3)));
            assert!(sim.bumped(), "origin {o:?}: no contact at the wall");
            let at = sim.true_pose().position();
            // Back west, away from the wall.
            sim.execute(Step::MoveTo(Point::new(o.x + 4.0, o.y + 4.0)));
            if sim.bumped() || sim.true_pose().position().dist(at) < 1.0 {
                stuck += 1;
            }
        }
        assert_eq!(stuck, 0, "runs that could not leave the wall");
    }

    #[test]
    fn noise_is_seeded_and_reproducible() {
        let world = big_room();
        let noise = |seed| {
            Some(OdometryNoise {
                seed,
                ..OdometryNoise::default()
            })
        };
        let a = simulate(&world, &mut Script(square(2)), &pid(noise(5)));
        let b = simulate(&world, &mut Script(square(2)), &pid(noise(5)));
        let c = simulate(&world, &mut Script(square(2)), &pid(noise(6)));
        assert_eq!(a.trace, b.trace);
        assert_ne!(a.trace, c.trace);
        // The truth left the planned square while the estimate followed it.
        let (_, max) = crate::metrics::tracking_error(&a.trace).unwrap();
        assert!(max > 1e-3, "{max}");
    }

    /// Drift of the truth from the planned path after `laps` laps, with or without landmarks.
    fn final_drift(landmarks: Vec<Landmark>, laps: usize) -> f64 {
        let world = big_room();
        let mut cfg = pid(Some(OdometryNoise {
            seed: 11,
            linear_rel_std: 0.05,
            angular_rel_std: 0.05,
            heading_drift_std: 0.3,
        }));
        cfg.landmarks.landmarks = landmarks;
        cfg.landmarks.range_m = 2.0;
        let mut sim = Simulator::new(&world, &cfg);
        let mut worst: f64 = 0.0;
        for step in square(laps) {
            sim.execute(step);
            let d = sim.true_pose().position().dist(sim.estimate().position());
            worst = worst.max(d);
        }
        worst
    }

    /// The noise's deviations are per step of the reference period and scaled to the one
    /// run: the truth strays as far at a tenth of the period (it strayed about half as far
    /// when each step drew the full deviation).
    #[test]
    fn the_drift_does_not_depend_on_the_control_period() {
        let world = big_room();
        let mean_stray = |dt_s: f64| {
            let mut sum = 0.0;
            for seed in 1..=16 {
                let cfg = SimConfig {
                    exec: Some(Execution::Pid(PidOptions {
                        dt_s,
                        noise: Some(OdometryNoise {
                            seed,
                            linear_rel_std: 0.0,
                            angular_rel_std: 0.0,
                            heading_drift_std: 0.5,
                        }),
                        ..PidOptions::default()
                    })),
                    ..SimConfig::default()
                };
                let mut sim = Simulator::new(&world, &cfg);
                for step in square(2) {
                    sim.execute(step);
                }
                sum += sim.true_pose().position().dist(sim.estimate().position());
            }
            sum / 16.0
        };
        let (coarse, fine) = (mean_stray(0.05), mean_stray(0.005));
        assert!(coarse > 0.02, "the noise should move the truth: {coarse}");
        let ratio = fine / coarse;
        assert!(
            (0.75..1.33).contains(&ratio),
            "{coarse} at 0.05 s, {fine} at 0.005 s"
        );
    }

    #[test]
    fn landmarks_bound_the_drift() {
        // Two tags with the same id at opposite corners of the square (1.41 m apart).
        let tags = vec![Landmark::new(4, 4.0, 4.0), Landmark::new(4, 5.0, 5.0)];
        let without = final_drift(Vec::new(), 12);
        let with = final_drift(tags, 12);
        assert!(without > 0.1, "dead reckoning should drift: {without}");
        assert!(with < 0.05, "landmarks should bound it: {with}");
    }
}
