//! Random bounce: the Roomba-like baseline.
//!
//! Drive straight until the (sensed) obstacle ahead stops you, turn in place by a seeded random
//! angle, repeat until a distance budget is spent. The BSA paper (Gonzalez et al., "BSA: a
//! complete coverage algorithm", ICRA 2005, seeds 002/004) cites this behaviour as the
//! inefficient reference; ccpp uses it as the baseline every plot compares against.
//!
//! Online: it stops *before* contact using its range sensor (a virtual bumper), so a correct run
//! has no collisions. When its pose estimate drifts (odometry noise under PID execution) the
//! sensed obstacle can be nearer than it believes; a bumper contact then bounces it like a
//! sensed obstacle (a random turn) instead of driving on into the wall.
//!
//! ```
//! use ccpp_core::{GridMap, Pose};
//! use ccpp_core::world::{Robot, World};
//! use ccpp_core::planners::random_bounce::{RandomBounce, RandomBounceOptions};
//! use ccpp_core::sim::{simulate, SimConfig};
//! let map = GridMap::from_ascii_scaled("######\n#....#\n#....#\n######", 10, 0.05).unwrap();
//! let world = World::new(map, Robot::new(0.1), Some(Pose::new(0.75, 0.75, 0.0))).unwrap();
//! let mut p = RandomBounce::new(RandomBounceOptions { budget_m: Some(20.0), ..Default::default() });
//! let out = simulate(&world, &mut p, &SimConfig::default());
//! let m = ccpp_core::metrics::compute(&world, &out, "box");
//! assert_eq!(m.collisions, 0);
//! assert!(m.path_length_m <= 20.0 + 1e-9);
//! ```

use serde::{Deserialize, Serialize};

use crate::planner::{KnownMap, Planner, Sensor, Step};
use crate::rng::SplitMix64;
use crate::trace::Event;

/// Options of [`RandomBounce`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RandomBounceOptions {
    /// Seed of the turn angles.
    pub seed: u64,
    /// Distance budget in metres; `None` = 3x the lane-by-lane length of the map frame's area
    /// (`3 * width_m * height_m / (2 r_tool)`, see
    /// [`default_budget`](super::settings::default_budget)): what an operator knows, not the
    /// map's contents.
    pub budget_m: Option<f64>,
    /// Smallest turn after a bump, degrees (within
    /// `[-`[`MAX_TURN_DEG`](super::settings::MAX_TURN_DEG)`, MAX_TURN_DEG]`).
    pub min_turn_deg: f64,
    /// Largest turn after a bump, degrees (at least `min_turn_deg`, at most
    /// [`MAX_TURN_DEG`](super::settings::MAX_TURN_DEG)).
    pub max_turn_deg: f64,
}

impl Default for RandomBounceOptions {
    fn default() -> Self {
        Self {
            seed: 0,
            budget_m: None,
            min_turn_deg: 90.0,
            max_turn_deg: 270.0,
        }
    }
}

/// The random bounce planner.
pub struct RandomBounce {
    opts: RandomBounceOptions,
    rng: SplitMix64,
    known: Option<KnownMap>,
    travelled: f64,
    started: bool,
    turns_in_a_row: u32,
    /// The last step was a translation (so a bumper contact now is its doing).
    last_was_translate: bool,
    finished: bool,
}

impl RandomBounce {
    /// A planner with these options.
    pub fn new(opts: RandomBounceOptions) -> Self {
        let rng = SplitMix64::new(opts.seed);
        Self {
            opts,
            rng,
            known: None,
            travelled: 0.0,
            started: false,
            turns_in_a_row: 0,
            last_was_translate: false,
            finished: false,
        }
    }
}

impl Planner for RandomBounce {
    fn name(&self) -> &'static str {
        "random-bounce"
    }

    fn next(&mut self, sensor: &dyn Sensor) -> Step {
        if self.finished {
            return Step::Done;
        }
        if !self.started {
            self.started = true;
            return Step::Mark(Event::RegionStart { region: 1 });
        }
        let known = self
            .known
            .get_or_insert_with(|| KnownMap::new(sensor.frame()));
        known.integrate(&sensor.scan());
        let budget = self.opts.budget_m.unwrap_or(f64::INFINITY);
        let left = budget - self.travelled;
        let pose = sensor.pose();
        let r = sensor.robot().radius;
        let res = sensor.frame().resolution;
        // Everything the disk can touch while moving `look` is inside the sensed circle.
        let look = (sensor.sensor_range() - r - 1.5 * res).max(0.0).min(left);
        let free = known.free_distance(pose.position(), pose.theta, look, r);
        let stride = (free - 1e-4 * res).max(0.0);
        if left <= 1e-9 || self.turns_in_a_row > 64 {
            self.finished = true;
            return Step::Mark(Event::RegionEnd { region: 1 });
        }
        // A bumper contact bounces like a sensed obstacle: under odometry noise the pose
        // estimate can put a wall further off than it is, and driving on would push into it.
        let bounced = sensor.bumped() && self.last_was_translate;
        if !bounced && (stride >= 0.5 * res || (stride > 0.0 && stride >= left - 1e-12)) {
            self.last_was_translate = true;
            self.turns_in_a_row = 0;
            self.travelled += stride;
            return Step::Translate(stride);
        }
        self.last_was_translate = false;
        self.turns_in_a_row += 1;
        let deg = self
            .rng
            .range(self.opts.min_turn_deg, self.opts.max_turn_deg);
        Step::Rotate(crate::geometry::wrap_angle(deg.to_radians()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exec::{Execution, OdometryNoise, PidOptions};
    use crate::sim::{simulate, SimConfig, StopReason};
    use crate::world::{Robot, World};
    use crate::{GridMap, Pose};

    /// A 4 m x 3 m room, dead-reckoned with drifting odometry: the pose estimate soon puts the
    /// walls where they are not, and the robot meets them on its bumper.
    #[test]
    fn a_bumper_contact_bounces_instead_of_pushing_on() {
        let art = "##########\n#........#\n#........#\n#........#\n##########";
        let map = GridMap::from_ascii_scaled(art, 10, 0.05).unwrap();
        let world = World::new(map, Robot::new(0.15), Some(Pose::new(1.0, 1.0, 0.3))).unwrap();
        let cfg = SimConfig {
            exec: Some(Execution::Pid(PidOptions {
                noise: Some(OdometryNoise {
                    seed: 3,
                    linear_rel_std: 0.05,
                    angular_rel_std: 0.05,
                    heading_drift_std: 0.3,
                }),
                ..PidOptions::default()
            })),
            ..SimConfig::default()
        };
        let mut p = RandomBounce::new(RandomBounceOptions {
            budget_m: Some(150.0),
            ..Default::default()
        });
        let out = simulate(&world, &mut p, &cfg);
        let m = crate::metrics::compute(&world, &out, "room");
        // It met walls it did not expect (the test is about those contacts)...
        assert!(m.collisions > 0, "no contact: the noise did not bite");
        // ...and bounced off each: it spent its budget and finished, instead of pushing into
        // one wall until the simulator ended the run as stalled after 1000 contacts.
        assert_eq!(out.stop, StopReason::Done);
        assert!(m.collisions < 200, "{} contacts", m.collisions);
        assert!(m.path_length_m > 100.0, "{} m", m.path_length_m);
    }
}
