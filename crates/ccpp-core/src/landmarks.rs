//! Pose correction from **non-unique** landmarks (seed 001).
//!
//! Seed 001 localizes a Jetbot with `AprilTags` whose ids repeat: every tag bearing the seen id
//! implies one candidate global pose of the robot (tag pose in the world composed with the
//! inverse of the tag's pose relative to the robot), and the candidate **closest to the
//! odometry estimate** is taken as the robot's pose. The choice is right whenever the odometry
//! error is below half the distance between the candidate positions (the seed's argument:
//! tags far apart, small motion steps).
//!
//! A [`Landmark`] here is such a tag: an id, a position and a heading (the tag's own x axis;
//! `0` = east). An [`Observation`] is the tag's pose in the robot frame, as a camera that
//! detects tags would report it. The simulator ([`crate::sim`]) observes the nearest landmark
//! within [`LandmarkConfig::range_m`] of the true pose every [`LandmarkConfig::period_s`] seconds
//! of PID execution and resets its estimate to [`choose_pose`]'s answer.
//!
//! ```
//! use ccpp_core::landmarks::{choose_pose, observe, Landmark};
//! use ccpp_core::Pose;
//! // Two tags with the same id, 4 m apart.
//! let tags = [Landmark::new(1, 1.0, 0.0), Landmark::new(1, 5.0, 0.0)];
//! let truth = Pose::new(4.0, -0.5, 0.3);
//! let obs = observe(truth, &tags[1]);
//! // Odometry believes the robot is 0.8 m off: still closer to the right candidate.
//! let estimate = Pose::new(4.6, 0.0, 0.25);
//! let p = choose_pose(estimate, &obs, &tags).unwrap();
//! assert!((p.x - 4.0).abs() < 1e-9 && (p.y + 0.5).abs() < 1e-9);
//! ```

use serde::{Deserialize, Serialize};

use crate::geometry::{wrap_angle, Point, Pose};

/// A landmark (tag) on the map. Ids need not be unique. An unknown field is refused (a
/// misspelt `thta` was dropped, the tag then facing east).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Landmark {
    /// Identifier shown by the tag (may be shared by several tags).
    pub id: u32,
    /// World x, metres.
    pub x: f64,
    /// World y, metres.
    pub y: f64,
    /// Heading of the tag's x axis, radians (default 0 = east).
    #[serde(default)]
    pub theta: f64,
}

impl Landmark {
    /// A landmark facing east.
    pub fn new(id: u32, x: f64, y: f64) -> Self {
        Self {
            id,
            x,
            y,
            theta: 0.0,
        }
    }

    /// The tag's pose.
    pub fn pose(&self) -> Pose {
        Pose::new(self.x, self.y, self.theta)
    }
}

/// What a tag detector reports: the id and the tag's pose relative to the robot
/// (x forward, y left, heading relative to the robot's).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Observation {
    /// Seen id.
    pub id: u32,
    /// Tag pose in the robot frame.
    pub relative: Pose,
}

/// Landmark settings of the simulator.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LandmarkConfig {
    /// The landmarks (empty = no correction).
    pub landmarks: Vec<Landmark>,
    /// Detection range, metres (from the robot centre).
    pub range_m: f64,
    /// Time between observations during PID execution, seconds.
    pub period_s: f64,
}

impl Default for LandmarkConfig {
    fn default() -> Self {
        Self {
            landmarks: Vec::new(),
            range_m: 3.0,
            period_s: 0.5,
        }
    }
}

/// `a ∘ b`: pose `b` expressed in frame `a`, mapped to `a`'s parent frame.
pub fn compose(a: Pose, b: Pose) -> Pose {
    let (s, c) = a.theta.sin_cos();
    Pose::new(
        a.x + c * b.x - s * b.y,
        a.y + s * b.x + c * b.y,
        a.theta + b.theta,
    )
}

/// The inverse transform of `a`.
pub fn inverse(a: Pose) -> Pose {
    let (s, c) = a.theta.sin_cos();
    Pose::new(-(c * a.x + s * a.y), s * a.x - c * a.y, -a.theta)
}

/// The observation of `landmark` by a robot at `truth` (exact).
pub fn observe(truth: Pose, landmark: &Landmark) -> Observation {
    Observation {
        id: landmark.id,
        relative: compose(inverse(truth), landmark.pose()),
    }
}

/// The robot poses implied by `obs`: one per landmark bearing its id.
pub fn candidates<'a>(
    obs: &'a Observation,
    landmarks: &'a [Landmark],
) -> impl Iterator<Item = Pose> + 'a {
    let inv = inverse(obs.relative);
    landmarks
        .iter()
        .filter(move |l| l.id == obs.id)
        .map(move |l| compose(l.pose(), inv))
}

/// The candidate pose closest to `estimate` (by position; ties by heading difference, then by
/// landmark order), or `None` when no landmark bears the observed id.
pub fn choose_pose(estimate: Pose, obs: &Observation, landmarks: &[Landmark]) -> Option<Pose> {
    let e = estimate.position();
    let mut best: Option<(f64, f64, Pose)> = None;
    for c in candidates(obs, landmarks) {
        let d = c.position().dist2(e);
        let h = wrap_angle(c.theta - estimate.theta).abs();
        if best.is_none_or(|(bd, bh, _)| d < bd || (d == bd && h < bh)) {
            best = Some((d, h, c));
        }
    }
    best.map(|b| b.2)
}

/// The landmark nearest to `p` within `range` (ties: first in the list).
pub fn nearest_in_range(p: Point, landmarks: &[Landmark], range: f64) -> Option<&Landmark> {
    let mut best: Option<(f64, &Landmark)> = None;
    for l in landmarks {
        let d = p.dist(Point::new(l.x, l.y));
        if d <= range && best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, l));
        }
    }
    best.map(|b| b.1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;
    use proptest::prelude::*;

    #[test]
    fn compose_inverse_roundtrip() {
        let a = Pose::new(1.0, -2.0, 0.7);
        let b = Pose::new(0.3, 0.4, -2.0);
        let id = compose(a, inverse(a));
        assert!(id.x.abs() < 1e-12 && id.y.abs() < 1e-12 && id.theta.abs() < 1e-12);
        let back = compose(inverse(a), compose(a, b));
        assert!((back.x - b.x).abs() < 1e-12 && (back.y - b.y).abs() < 1e-12);
    }

    #[test]
    fn unknown_id_gives_none() {
        let tags = [Landmark::new(1, 0.0, 0.0)];
        let obs = Observation {
            id: 2,
            relative: Pose::new(1.0, 0.0, 0.0),
        };
        assert_eq!(choose_pose(Pose::default(), &obs, &tags), None);
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, rng_seed: proptest::test_runner::RngSeed::Fixed(0x5eed_0103), ..ProptestConfig::default() })]
        /// With a duplicated id, the chosen pose is the true one whenever the odometry error is
        /// below half the distance between the candidate positions.
        #[test]
        fn duplicate_id_picks_the_right_tag(
            seed in any::<u64>(),
            spacing in 0.5f64..10.0,
            angle in -3.1f64..3.1,
            tag_theta in -3.1f64..3.1,
            tx in -5.0f64..5.0, ty in -5.0f64..5.0, th in -3.1f64..3.1,
        ) {
            let a = Landmark { id: 7, x: 0.0, y: 0.0, theta: tag_theta };
            let b = Landmark { id: 7, x: spacing * angle.cos(), y: spacing * angle.sin(), theta: tag_theta };
            let other = Landmark { id: 3, x: 1.0, y: 1.0, theta: 0.0 };
            let tags = [other, a, b];
            let mut rng = SplitMix64::new(seed);
            for which in [1usize, 2] {
                let truth = Pose::new(tags[which].x + tx * 0.2, tags[which].y + ty * 0.2, th);
                let obs = observe(truth, &tags[which]);
                // Same tag orientations: the candidates are `spacing` apart.
                for _ in 0..50 {
                    let mag = rng.range(0.0, 0.4999 * spacing);
                    let dir = rng.range(-std::f64::consts::PI, std::f64::consts::PI);
                    let est = Pose::new(truth.x + mag * dir.cos(), truth.y + mag * dir.sin(),
                        truth.theta + rng.range(-0.3, 0.3));
                    let p = choose_pose(est, &obs, &tags).unwrap();
                    prop_assert!(p.position().dist(truth.position()) < 1e-9);
                    prop_assert!(wrap_angle(p.theta - truth.theta).abs() < 1e-9);
                }
            }
        }
    }
}
