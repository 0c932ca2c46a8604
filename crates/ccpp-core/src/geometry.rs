//! Points, poses and small planar geometry helpers.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use std::ops::{Add, Sub};

/// A point or vector in the plane (metres in the world frame unless a function says otherwise).
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct Point {
    /// x (east).
    pub x: f64,
    /// y (north).
    pub y: f64,
}

/// Length of the polyline `from -> pts[0] -> pts[1] -> ...`, summed in that order (in the
/// points' units); `0.0`, not the `-0.0` of an empty `f64` sum, without points.
pub fn polyline_length(from: Point, pts: &[Point]) -> f64 {
    let mut at = from;
    pts.iter()
        .map(|&p| {
            let d = at.dist(p);
            at = p;
            d
        })
        .fold(0.0, |a, d| a + d)
}

/// Length of the polyline through `pts` (0 for fewer than two points).
pub fn path_length(pts: &[Point]) -> f64 {
    pts.split_first()
        .map_or(0.0, |(&first, rest)| polyline_length(first, rest))
}

impl Point {
    /// A new point.
    #[inline]
    pub const fn new(x: f64, y: f64) -> Self {
        Self { x, y }
    }
    /// Euclidean distance.
    #[inline]
    pub fn dist(self, o: Point) -> f64 {
        (self.x - o.x).hypot(self.y - o.y)
    }
    /// Squared distance.
    #[inline]
    pub fn dist2(self, o: Point) -> f64 {
        let dx = self.x - o.x;
        let dy = self.y - o.y;
        dx * dx + dy * dy
    }
    /// `self * k`.
    #[inline]
    pub fn scale(self, k: f64) -> Point {
        Point::new(self.x * k, self.y * k)
    }
    /// Vector length.
    #[inline]
    pub fn norm(self) -> f64 {
        self.x.hypot(self.y)
    }
    /// Dot product.
    #[inline]
    pub fn dot(self, o: Point) -> f64 {
        self.x * o.x + self.y * o.y
    }
    /// Both coordinates finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite()
    }
}

impl std::ops::Sub for Point {
    type Output = Point;
    #[inline]
    fn sub(self, o: Point) -> Point {
        Point::new(self.x - o.x, self.y - o.y)
    }
}

impl std::ops::Add for Point {
    type Output = Point;
    #[inline]
    fn add(self, o: Point) -> Point {
        Point::new(self.x + o.x, self.y + o.y)
    }
}

/// The largest heading magnitude ccpp accepts, radians: two full turns either way, room for
/// every convention (`[-pi, pi]`, `[0, 2 pi)`, a wrapped `-6.2`) and no more. A map origin's yaw
/// or a start heading beyond it is a typo or degrees (`90` for a quarter turn), not a heading,
/// and is refused rather than wrapped.
pub const MAX_HEADING_RAD: f64 = 4.0 * PI;

/// Why `theta` (radians) is not a heading ccpp accepts, if it is not: non-finite, or beyond
/// [`MAX_HEADING_RAD`].
#[must_use]
pub fn heading_problem(theta: f64) -> Option<String> {
    if !theta.is_finite() {
        Some(format!("{theta} rad is not a finite number"))
    } else if theta.abs() > MAX_HEADING_RAD {
        Some(format!(
            "{} rad is more than two turns (|heading| <= 4 pi = {MAX_HEADING_RAD:.4} rad); \
             headings are in radians, not degrees",
            crate::display::Compact(theta)
        ))
    } else {
        None
    }
}

/// A robot pose `(x, y, theta)`: theta 0 = east, counter-clockwise positive, in (-pi, pi].
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct Pose {
    /// x (east), metres.
    pub x: f64,
    /// y (north), metres.
    pub y: f64,
    /// Heading, radians.
    pub theta: f64,
}

impl Pose {
    /// A new pose (theta is wrapped).
    #[inline]
    pub fn new(x: f64, y: f64, theta: f64) -> Self {
        Self {
            x,
            y,
            theta: wrap_angle(theta),
        }
    }
    /// The position part.
    #[inline]
    pub fn position(&self) -> Point {
        Point::new(self.x, self.y)
    }
}

/// `a.dist(b)` ([`Point::dist`], a `hypot`) bit for bit, without the call for an axis-parallel
/// pair of finite points: `hypot(x, ±0) = |x|` exactly (IEC 60559, C Annex F).
#[inline]
pub(crate) fn dist_exact(a: Point, b: Point) -> f64 {
    if a.y == b.y && a.y.is_finite() {
        (a.x - b.x).abs()
    } else if a.x == b.x && a.x.is_finite() {
        (a.y - b.y).abs()
    } else {
        a.dist(b)
    }
}

/// `y.atan2(x)` bit for bit, without the call on the axes (finite, nonzero other component):
/// `atan2(±0, x > 0) = ±0`, `atan2(±0, x < 0) = ±pi`, `atan2(y > 0, ±0) = pi/2`,
/// `atan2(y < 0, ±0) = -pi/2` (C Annex F).
#[inline]
pub(crate) fn atan2_exact(y: f64, x: f64) -> f64 {
    if y == 0.0 && x.is_finite() && x != 0.0 {
        if x > 0.0 {
            y
        } else {
            std::f64::consts::PI.copysign(y)
        }
    } else if x == 0.0 && y.is_finite() && y != 0.0 {
        std::f64::consts::FRAC_PI_2.copysign(y)
    } else {
        y.atan2(x)
    }
}

/// Wraps an angle into (-pi, pi].
#[inline]
pub fn wrap_angle(a: f64) -> f64 {
    if !a.is_finite() {
        return a;
    }
    // `fmod` returns its argument exactly when it is smaller than the modulus: skip the call.
    let mut w = if a.abs() < 2.0 * PI {
        a
    } else {
        a % (2.0 * PI)
    };
    if w <= -PI {
        w += 2.0 * PI;
    } else if w > PI {
        w -= 2.0 * PI;
    }
    w
}

/// `(a - o) x (b - o)`: positive when `o`, `a`, `b` turn left (counter-clockwise).
#[inline]
pub fn cross(o: Point, a: Point, b: Point) -> f64 {
    (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x)
}

/// Distance from point `p` to segment `a`-`b` (the tracking error of a pose against its
/// planned segment: the simulator's per-step figure and the metrics' reading of recorded
/// poses must be the same number).
#[inline]
pub fn point_segment_dist(p: Point, a: Point, b: Point) -> f64 {
    point_segment_dist2(p, a, b).sqrt()
}

/// Squared distance from point `p` to segment `a`-`b`.
#[inline]
pub fn point_segment_dist2(p: Point, a: Point, b: Point) -> f64 {
    let d = b.sub(a);
    let l2 = d.dot(d);
    if l2 == 0.0 {
        return p.dist2(a);
    }
    let t = (p.sub(a).dot(d) / l2).clamp(0.0, 1.0);
    p.dist2(a.add(d.scale(t)))
}

/// First parameter `t` in `[0, 1]` at which the point `a + t (b - a)` comes strictly closer than
/// `radius` to `q`, or `None`. A motion that starts inside and leaves (or is tangent) is
/// not reported unless it is moving inwards at `t = 0`.
#[inline]
pub fn first_entry(a: Point, b: Point, q: Point, radius: f64) -> Option<f64> {
    let d = b.sub(a);
    let f = a.sub(q);
    let aa = d.dot(d);
    let bb = 2.0 * f.dot(d);
    let cc = f.dot(f) - radius * radius;
    if cc < 0.0 {
        // Already inside: a contact now if moving inwards (or not away).
        return if bb < 0.0 || aa == 0.0 {
            Some(0.0)
        } else {
            None
        };
    }
    if aa == 0.0 {
        return None;
    }
    let disc = bb * bb - 4.0 * aa * cc;
    if disc <= 0.0 {
        return None; // misses or only touches
    }
    let t = (-bb - disc.sqrt()) / (2.0 * aa);
    if (0.0..=1.0).contains(&t) {
        Some(t)
    } else {
        None
    }
}

/// `x.floor() as i64`, bit for bit (NaN and infinities included), without a call into libm
/// (the baseline x86-64 target has no rounding instruction).
#[inline]
pub fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// `x.ceil() as i64`, bit for bit, without a call into libm.
#[inline]
pub fn ceil_i64(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) < x {
        t.saturating_add(1)
    } else {
        t
    }
}

/// `x.floor() as i32`, bit for bit (saturating), without a call into libm.
#[inline]
pub fn floor_i32(x: f64) -> i32 {
    floor_i64(x).clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32
}

/// `x.ceil() as i32`, bit for bit (saturating), without a call into libm.
#[inline]
pub fn ceil_i32(x: f64) -> i32 {
    ceil_i64(x).clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32
}

/// `x.round() as i64` (half away from zero), bit for bit (saturating; NaN gives 0), without a
/// call into libm. `x - trunc(x)` is exact in floating point, so the half test is exact.
#[inline]
pub fn round_i64(x: f64) -> i64 {
    let t = x as i64;
    let f = x - t as f64;
    if f >= 0.5 {
        t.saturating_add(1)
    } else if f <= -0.5 {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// `x.round() as i32`, bit for bit (saturating), without a call into libm.
#[inline]
pub fn round_i32(x: f64) -> i32 {
    round_i64(x).clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32
}

#[cfg(test)]
mod tests {
    /// The axis fast paths give the library's results bit for bit (and the general case is the
    /// library call).
    #[test]
    fn exact_fast_paths_match_the_library() {
        let vals = [
            0.0,
            -0.0,
            1e-300,
            0.05,
            -0.05,
            0.15,
            3.0,
            -7.25,
            56.075,
            59.775_000_000_000_006,
            1e12,
            -1e-9,
            f64::MIN_POSITIVE,
        ];
        for &u in &vals {
            for &v in &vals {
                let y = v * 0.7 + 0.1;
                for (a, b) in [
                    (Point::new(u, y), Point::new(v, y)),
                    (Point::new(y, u), Point::new(y, v)),
                    (Point::new(u, v), Point::new(v, u)),
                ] {
                    assert_eq!(
                        dist_exact(a, b).to_bits(),
                        a.dist(b).to_bits(),
                        "{a:?} {b:?}"
                    );
                }
                assert_eq!(atan2_exact(u, v).to_bits(), u.atan2(v).to_bits(), "{u} {v}");
                assert_eq!(atan2_exact(v, u).to_bits(), v.atan2(u).to_bits(), "{v} {u}");
            }
        }
    }

    use super::*;

    #[test]
    fn polyline_lengths() {
        let pts = [
            Point::new(0.0, 0.0),
            Point::new(3.0, 4.0),
            Point::new(3.0, 6.0),
        ];
        assert_eq!(path_length(&pts), 7.0);
        assert_eq!(polyline_length(Point::new(0.0, -1.0), &pts), 8.0);
        assert_eq!(path_length(&pts[..1]), 0.0);
        assert_eq!(path_length(&[]), 0.0);
        assert_eq!(polyline_length(pts[0], &[]), 0.0);
    }

    #[test]
    fn fast_floor_and_ceil_match_std() {
        let mut v = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            2.5,
            -2.5,
            1e-300,
            -1e-300,
            4_503_599_627_370_495.5,
            -4_503_599_627_370_495.5,
            9.007_199_254_740_993e15,
            2f64.powi(31) - 0.5,
            -(2f64.powi(31)) - 0.5,
            2f64.powi(63),
            -(2f64.powi(63)),
            9.3e18,
            -9.3e18,
            1e300,
            -1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MAX,
            f64::MIN,
            f64::EPSILON,
            0.499_999_999_999_999_94,
            -0.499_999_999_999_999_94,
            1.5,
            -1.5,
            4_503_599_627_370_496.5,
            -4_503_599_627_370_496.5,
        ];
        let mut seed = 7u64;
        for _ in 0..20_000 {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            let u = (seed >> 11) as f64 / (1u64 << 53) as f64;
            let e = (seed % 70) as i32 - 10;
            v.push((u - 0.5) * 2f64.powi(e));
            v.push(f64::from_bits(seed));
        }
        for x in v {
            assert_eq!(floor_i64(x), x.floor() as i64, "{x:e}");
            assert_eq!(ceil_i64(x), x.ceil() as i64, "{x:e}");
            assert_eq!(floor_i32(x), x.floor() as i32, "{x:e}");
            assert_eq!(ceil_i32(x), x.ceil() as i32, "{x:e}");
            assert_eq!(round_i64(x), x.round() as i64, "{x:e}");
            assert_eq!(round_i32(x), x.round() as i32, "{x:e}");
        }
    }

    #[test]
    fn wrap() {
        assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(-PI / 2.0) + PI / 2.0).abs() < 1e-12);
        assert_eq!(wrap_angle(0.0), 0.0);
        // Bit for bit the `fmod` form, on both sides of the skipped call.
        let fmod_form = |a: f64| {
            let mut w = a % (2.0 * PI);
            if w <= -PI {
                w += 2.0 * PI;
            } else if w > PI {
                w -= 2.0 * PI;
            }
            w
        };
        let tau = 2.0 * PI;
        let mut xs = vec![-0.0, 0.0, PI, -PI, tau, -tau, 3.0 * PI, -7.5, 1e9];
        for x in [tau, -tau, PI, -PI] {
            // The two neighbouring doubles.
            xs.extend([
                f64::from_bits(x.to_bits() + 1),
                f64::from_bits(x.to_bits() - 1),
            ]);
        }
        xs.extend((-2000..=2000).map(|k| f64::from(k) * 0.00731));
        for x in xs {
            assert_eq!(wrap_angle(x).to_bits(), fmod_form(x).to_bits(), "{x:e}");
        }
    }

    #[test]
    fn entry() {
        let a = Point::new(0.0, 0.0);
        let b = Point::new(10.0, 0.0);
        let t = first_entry(a, b, Point::new(5.0, 0.0), 1.0).unwrap();
        assert!((t - 0.4).abs() < 1e-12);
        assert_eq!(first_entry(a, b, Point::new(5.0, 1.0), 1.0), None); // tangent
        assert_eq!(first_entry(a, b, Point::new(-0.5, 0.0), 1.0), None); // inside, leaving
        assert_eq!(first_entry(a, b, Point::new(0.5, 0.0), 1.0), Some(0.0));
        assert!((point_segment_dist2(Point::new(5.0, 2.0), a, b) - 4.0).abs() < 1e-12);
    }
}
