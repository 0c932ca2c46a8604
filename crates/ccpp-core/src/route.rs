//! A route a robot can drive: the waypoints of an executed path, one per segment end, each with
//! the heading the robot leaves it with.
//!
//! [`Route::from_poses`] reduces a sequence of executed poses (a [`Trace`]'s
//! [`poses`](Trace::poses)) to its segment ends in one pass:
//!
//! * **Collinear moves are merged.** A run of poses becomes one segment when every dropped pose
//!   lies within `tolerance_m` of the straight line from the segment's first waypoint to its
//!   last, and the run never falls back along that line by more than `tolerance_m`. The test is
//!   the "sleeve" of directions from the segment start: each pose farther than the tolerance
//!   from the start narrows the set of directions whose ray passes within the tolerance of it
//!   (by `asin(tolerance / distance)` on either side), and a pose whose own direction lies
//!   outside the set ends the segment at the pose before it. Under PID execution the
//!   control-step samples of a straight motion therefore collapse to its two ends, and a curved
//!   motion becomes the chords that stay within the tolerance.
//! * **Rotations in place are merged.** Poses at the same position (within
//!   [`SAME_POSITION_M`]) are one waypoint whose heading is the last of them: the heading the
//!   robot leaves that point with.
//!
//! The first waypoint is the first pose (with the rotations in place that follow it merged),
//! the last one the last pose. Every waypoint is a recorded pose (positions and headings are
//! copied, never averaged), so the result is a deterministic function of the poses and the
//! tolerance. A tolerance of 0 keeps every pose that is not exactly collinear (up to rounding).
//!
//! Metrics are computed from the full trace, never from a route.

use serde::{Deserialize, Serialize};

use crate::geometry::{atan2_exact, dist_exact, wrap_angle, Point, Pose};
use crate::trace::Trace;

/// The default merging tolerance, metres: 1 mm, far below a map pixel (5 cm on the shared
/// maps) and above the wobble of PID tracking along a straight segment, so a straight motion
/// is one segment whatever its control-step samples.
pub const DEFAULT_TOLERANCE_M: f64 = 0.001;

/// Two poses closer than this are at the same position (a rotation in place), metres.
pub const SAME_POSITION_M: f64 = 1e-9;

/// Waypoints with headings at the ends of the straight segments of a path (see the module
/// documentation for how they are chosen).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Route {
    /// The waypoints in driving order: position (metres, map frame) and the heading the robot
    /// leaves it with (radians, 0 = +x, counter-clockwise; the last one: the final heading).
    pub waypoints: Vec<Pose>,
}

/// The segment being grown by [`Route::from_poses`].
struct Sleeve {
    /// Direction of the first pose beyond the tolerance (angles are kept relative to it).
    reference: Option<f64>,
    /// Allowed direction offsets from `reference`: `[lo, hi]`.
    lo: f64,
    hi: f64,
    /// Largest distance from the segment start seen so far.
    far: f64,
    /// The largest distance of the poses straight along `reference` (offset exactly 0) whose
    /// narrowing is not applied yet (see [`Sleeve::accept`]).
    pending: Option<f64>,
}

impl Sleeve {
    const fn new() -> Self {
        Self {
            reference: None,
            lo: f64::NEG_INFINITY,
            hi: f64::INFINITY,
            far: 0.0,
            pending: None,
        }
    }

    /// Narrows the sleeve by the pending pose straight along the reference.
    fn flush(&mut self, tol: f64) {
        if let Some(d) = self.pending.take() {
            let half = (tol / d).asin();
            self.lo = self.lo.max(0.0 - half);
            self.hi = self.hi.min(0.0 + half);
        }
    }

    /// Whether `p` continues the straight segment from `start` within `tol`; if so the
    /// sleeve is narrowed by it.
    fn accept(&mut self, start: Point, p: Point, tol: f64) -> bool {
        let d = dist_exact(start, p);
        if d + tol < self.far {
            return false;
        }
        if d <= tol {
            // Any line through the start passes within the tolerance of it.
            self.far = self.far.max(d);
            return true;
        }
        let dir = atan2_exact(p.y - start.y, p.x - start.x);
        let reference = *self.reference.get_or_insert(dir);
        let off = wrap_angle(dir - reference);
        if off == 0.0 {
            // A pose straight along the reference (every step of an axis-aligned lane): the
            // test below reads only the signs of `lo` and `hi`, which narrowing by
            // `0 -/+ asin(tol / d)` never changes, and the narrowing of the farthest such pose
            // is the tightest (`asin(tol / d)` shrinks as `d` grows), so one `asin` for the farthest
            // of them, when a pose in another direction comes, narrows the sleeve as one per
            // pose would.
            if 0.0 < self.lo || 0.0 > self.hi {
                return false;
            }
            self.pending = Some(self.pending.map_or(d, |p| p.max(d)));
            self.far = self.far.max(d);
            return true;
        }
        self.flush(tol);
        if off < self.lo || off > self.hi {
            return false;
        }
        let half = (tol / d).asin();
        self.lo = self.lo.max(off - half);
        self.hi = self.hi.min(off + half);
        self.far = self.far.max(d);
        true
    }
}

/// [`Route::from_poses`] fed one pose at a time (for poses that arrive while a run goes on):
/// the same route.
pub struct RouteBuilder {
    /// The merging tolerance, metres (clamped as [`Route::from_poses`] does).
    tol: f64,
    waypoints: Vec<Pose>,
    /// The last pose of the segment being grown (not yet a waypoint unless it is the start).
    last: Option<Pose>,
    sleeve: Sleeve,
}

impl RouteBuilder {
    /// No pose yet; `tolerance_m` as for [`Route::from_poses`].
    pub fn new(tolerance_m: f64) -> Self {
        let tol = if tolerance_m.is_finite() {
            tolerance_m.max(0.0)
        } else {
            0.0
        };
        Self {
            tol,
            waypoints: Vec::new(),
            last: None,
            sleeve: Sleeve::new(),
        }
    }

    /// The next pose (a non-finite one is skipped).
    pub fn push(&mut self, p: Pose) {
        if !(p.x.is_finite() && p.y.is_finite() && p.theta.is_finite()) {
            return;
        }
        let (Some(start), Some(prev)) = (self.waypoints.last().copied(), self.last) else {
            self.waypoints.push(p);
            self.last = Some(p);
            return;
        };
        let at_start = dist_exact(prev.position(), start.position()) <= SAME_POSITION_M;
        if dist_exact(p.position(), prev.position()) <= SAME_POSITION_M {
            // A rotation in place (or a repeated pose): merged into one waypoint.
            if at_start {
                if let Some(w) = self.waypoints.last_mut() {
                    w.theta = p.theta;
                }
            } else {
                self.waypoints.push(Pose::new(prev.x, prev.y, p.theta));
                self.sleeve = Sleeve::new();
            }
            self.last = Some(p);
            return;
        }
        if !self.sleeve.accept(start.position(), p.position(), self.tol) {
            // The segment ends at the previous pose, which starts the next one.
            self.waypoints.push(prev);
            self.sleeve = Sleeve::new();
            let accepted = self.sleeve.accept(prev.position(), p.position(), self.tol);
            debug_assert!(accepted, "a fresh sleeve takes any pose");
        }
        self.last = Some(p);
    }

    /// The route of the poses pushed.
    pub fn finish(mut self) -> Route {
        if let (Some(end), Some(w)) = (self.last, self.waypoints.last_mut()) {
            if dist_exact(end.position(), w.position()) <= SAME_POSITION_M {
                // The run ends where the last waypoint is (a rotation in place there, its
                // position a rounding away under odometry noise): one waypoint, with the
                // heading the robot ends with, as `push` merges rotations in place.
                w.theta = end.theta;
            } else {
                self.waypoints.push(end);
            }
        }
        Route {
            waypoints: self.waypoints,
        }
    }
}

impl Route {
    /// The route of `poses` with the merging tolerance `tolerance_m` (metres; negative or
    /// non-finite values count as 0). Non-finite poses are skipped.
    pub fn from_poses<I: IntoIterator<Item = Pose>>(poses: I, tolerance_m: f64) -> Self {
        let mut b = RouteBuilder::new(tolerance_m);
        for p in poses {
            b.push(p);
        }
        b.finish()
    }

    /// The route of a trace's executed poses ([`Route::from_poses`]).
    pub fn from_trace(trace: &Trace, tolerance_m: f64) -> Self {
        Self::from_poses(trace.poses(), tolerance_m)
    }

    /// Length of the polyline through the waypoints, metres (`0.0`, not `-0.0`, for fewer than
    /// two waypoints: an empty `f64` sum is `-0.0`, which the exports printed).
    pub fn length_m(&self) -> f64 {
        self.waypoints
            .windows(2)
            .map(|w| w[0].position().dist(w[1].position()))
            .fold(0.0, |a, b| a + b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_route_of_one_waypoint_has_length_plus_zero() {
        let one = Route::from_poses([Pose::new(1.0, 2.0, 0.0)], 0.01);
        assert!(one.length_m().is_sign_positive() && one.length_m() == 0.0);
        assert_eq!(serde_json::to_string(&one.length_m()).unwrap(), "0.0");
    }

    fn xy(r: &Route) -> Vec<(f64, f64)> {
        r.waypoints.iter().map(|p| (p.x, p.y)).collect()
    }

    /// A run that ends with a rotation in place at a position a rounding away from the last
    /// corner (odometry noise) ended with two waypoints at the same place and heading.
    #[test]
    fn a_final_rotation_a_rounding_away_is_one_waypoint() {
        let c = 1.0 + f64::EPSILON;
        let poses = [
            Pose::new(0.0, 0.0, 0.0),
            Pose::new(1.0, 0.0, 0.0),
            Pose::new(c, 0.0, 0.5),
        ];
        let r = Route::from_poses(poses, DEFAULT_TOLERANCE_M);
        assert_eq!(xy(&r), vec![(0.0, 0.0), (1.0, 0.0)]);
        assert_eq!(r.waypoints[1].theta, 0.5);
        // Two turns in place at the end: still one waypoint, with the last heading.
        let poses = [
            Pose::new(0.0, 0.0, 0.0),
            Pose::new(1.0, 0.0, 0.0),
            Pose::new(c, 0.0, 0.5),
            Pose::new(1.0, 0.0, 0.7),
        ];
        let r = Route::from_poses(poses, DEFAULT_TOLERANCE_M);
        assert_eq!(r.waypoints.len(), 2);
        assert_eq!(r.waypoints[1].theta, 0.7);
        // A route of one pose, and one that ends moving, are as before.
        assert_eq!(
            Route::from_poses([Pose::new(1.0, 2.0, 0.3)], 0.01)
                .waypoints
                .len(),
            1
        );
        let r = Route::from_poses([Pose::new(0.0, 0.0, 0.0), Pose::new(2.0, 0.0, 0.0)], 0.01);
        assert_eq!(xy(&r), vec![(0.0, 0.0), (2.0, 0.0)]);
    }

    #[test]
    fn collinear_steps_merge_and_corners_stay() {
        let mut poses = vec![Pose::new(0.0, 0.0, 0.0)];
        for k in 1..=10 {
            poses.push(Pose::new(0.1 * f64::from(k), 0.0, 0.0));
        }
        // Rotation in place at (1, 0), then north.
        poses.push(Pose::new(1.0, 0.0, 1.0));
        poses.push(Pose::new(1.0, 0.0, std::f64::consts::FRAC_PI_2));
        for k in 1..=5 {
            poses.push(Pose::new(
                1.0,
                0.2 * f64::from(k),
                std::f64::consts::FRAC_PI_2,
            ));
        }
        let r = Route::from_poses(poses, DEFAULT_TOLERANCE_M);
        assert_eq!(xy(&r), vec![(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)]);
        // The corner carries the heading it is left with.
        assert_eq!(r.waypoints[1].theta, std::f64::consts::FRAC_PI_2);
        assert!((r.length_m() - 2.0).abs() < 1e-12);
    }

    #[test]
    fn start_rotation_merges_into_the_first_waypoint() {
        let poses = [
            Pose::new(0.0, 0.0, 0.0),
            Pose::new(0.0, 0.0, 0.5),
            Pose::new(0.0, 0.0, 1.0),
            Pose::new(0.0, 1.0, 1.0),
        ];
        let r = Route::from_poses(poses, 0.0);
        assert_eq!(
            r.waypoints,
            vec![Pose::new(0.0, 0.0, 1.0), Pose::new(0.0, 1.0, 1.0)]
        );
    }

    #[test]
    fn wobble_within_tolerance_merges_and_beyond_does_not() {
        // A straight line sampled with a +-0.4 mm wobble.
        let poses: Vec<Pose> = (0..=100)
            .map(|k| {
                let w = if k % 2 == 0 { 0.0004 } else { -0.0004 };
                let w = if k == 0 || k == 100 { 0.0 } else { w };
                Pose::new(0.01 * f64::from(k), w, 0.0)
            })
            .collect();
        assert_eq!(Route::from_poses(poses.clone(), 0.001).waypoints.len(), 2);
        assert!(Route::from_poses(poses, 0.0001).waypoints.len() > 50);
    }

    #[test]
    fn going_back_along_the_line_ends_the_segment() {
        let poses = [
            Pose::new(0.0, 0.0, 0.0),
            Pose::new(1.0, 0.0, 0.0),
            Pose::new(2.0, 0.0, 0.0),
            Pose::new(1.5, 0.0, 0.0),
        ];
        let r = Route::from_poses(poses, 0.01);
        assert_eq!(xy(&r), vec![(0.0, 0.0), (2.0, 0.0), (1.5, 0.0)]);
    }

    #[test]
    fn arc_becomes_chords_within_tolerance() {
        // A quarter circle of radius 1 m sampled every 0.5 degrees.
        let poses: Vec<Pose> = (0..=180)
            .map(|k| {
                let a = f64::from(k).to_radians() * 0.5;
                Pose::new(a.cos(), a.sin(), a + std::f64::consts::FRAC_PI_2)
            })
            .collect();
        let tol = 0.01;
        let r = Route::from_poses(poses.clone(), tol);
        assert!(
            r.waypoints.len() > 2 && r.waypoints.len() < 40,
            "{}",
            r.waypoints.len()
        );
        // Every sample lies within the tolerance of the route.
        for p in &poses {
            let d = r
                .waypoints
                .windows(2)
                .map(|w| {
                    crate::geometry::point_segment_dist2(
                        p.position(),
                        w[0].position(),
                        w[1].position(),
                    )
                    .sqrt()
                })
                .fold(f64::INFINITY, f64::min);
            assert!(d <= tol + 1e-12, "{d}");
        }
        // Deterministic.
        assert_eq!(Route::from_poses(poses, tol), r);
    }

    /// The route with one `asin` per pose (the sleeve narrowed at every pose), as
    /// [`Route::from_poses`] was first written: the deferred narrowing must give the same.
    fn eager_route(poses: &[Pose], tol: f64) -> Vec<Pose> {
        struct Eager {
            reference: Option<f64>,
            lo: f64,
            hi: f64,
            far: f64,
        }
        let fresh = || Eager {
            reference: None,
            lo: f64::NEG_INFINITY,
            hi: f64::INFINITY,
            far: 0.0,
        };
        let accept = |s: &mut Eager, start: Point, p: Point| {
            let d = dist_exact(start, p);
            if d + tol < s.far {
                return false;
            }
            if d <= tol {
                s.far = s.far.max(d);
                return true;
            }
            let dir = atan2_exact(p.y - start.y, p.x - start.x);
            let reference = *s.reference.get_or_insert(dir);
            let off = wrap_angle(dir - reference);
            if off < s.lo || off > s.hi {
                return false;
            }
            let half = (tol / d).asin();
            s.lo = s.lo.max(off - half);
            s.hi = s.hi.min(off + half);
            s.far = s.far.max(d);
            true
        };
        let mut waypoints: Vec<Pose> = Vec::new();
        let mut last: Option<Pose> = None;
        let mut sleeve = fresh();
        for &p in poses {
            let (Some(start), Some(prev)) = (waypoints.last().copied(), last) else {
                waypoints.push(p);
                last = Some(p);
                continue;
            };
            let at_start = dist_exact(prev.position(), start.position()) <= SAME_POSITION_M;
            if dist_exact(p.position(), prev.position()) <= SAME_POSITION_M {
                if at_start {
                    if let Some(w) = waypoints.last_mut() {
                        w.theta = p.theta;
                    }
                } else {
                    waypoints.push(Pose::new(prev.x, prev.y, p.theta));
                    sleeve = fresh();
                }
                last = Some(p);
                continue;
            }
            if !accept(&mut sleeve, start.position(), p.position()) {
                waypoints.push(prev);
                sleeve = fresh();
                accept(&mut sleeve, prev.position(), p.position());
            }
            last = Some(p);
        }
        if let (Some(end), Some(w)) = (last, waypoints.last()) {
            if end != *w {
                waypoints.push(end);
            }
        }
        waypoints
    }

    #[test]
    fn deferred_narrowing_matches_narrowing_at_every_pose() {
        let mut rng = crate::rng::SplitMix64::new(13);
        for case in 0..400 {
            // Lattice lanes, diagonal steps, small wobbles, turns back and rotations in place.
            let side = [0.05, 0.025, 0.1][case % 3];
            let mut poses = vec![Pose::new(1.0, 2.0, 0.0)];
            for _ in 0..60 {
                let last = *poses.last().unwrap();
                let steps = 1 + (rng.next_u64() % 40) as usize;
                let (dx, dy) = match rng.next_u64() % 7 {
                    0 => (side, 0.0),
                    1 => (-side, 0.0),
                    2 => (0.0, side),
                    3 => (0.0, -side),
                    4 => (side, side),
                    5 => (side, rng.range(-0.0004, 0.0004)),
                    _ => {
                        poses.push(Pose::new(last.x, last.y, rng.range(-3.0, 3.0)));
                        continue;
                    }
                };
                for k in 1..=steps {
                    let k = k as f64;
                    poses.push(Pose::new(last.x + k * dx, last.y + k * dy, last.theta));
                }
            }
            for tol in [0.0, 0.001, 0.01, 0.2] {
                let got = Route::from_poses(poses.iter().copied(), tol).waypoints;
                assert_eq!(got, eager_route(&poses, tol), "case {case} tol {tol}");
            }
        }
    }

    #[test]
    fn empty_and_single() {
        assert!(Route::from_poses([], 0.1).waypoints.is_empty());
        let one = Route::from_poses([Pose::new(1.0, 2.0, 3.0)], 0.1);
        assert_eq!(one.waypoints, vec![Pose::new(1.0, 2.0, 3.0)]);
        let nan = Route::from_poses([Pose::new(f64::NAN, 2.0, 3.0)], 0.1);
        assert!(nan.waypoints.is_empty());
    }
}
