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
    /// Distance budget in metres, at least half a pixel (its shortest move); `None` = 3x the
    /// lane-by-lane length of the map frame's area (`3 * width_m * height_m / (2 r_tool)`, see
    /// [`default_budget`](super::settings::default_budget)), or of the work area's when the
    /// run has one ([`default_budget_in`](super::settings::default_budget_in)): what an
    /// operator knows, not the map's contents.
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
    /// Where the last translation started (its pose estimate) and how long it was asked to
    /// be: counted into `travelled` when the next step is asked for.
    moving: Option<(crate::geometry::Point, f64)>,
    started: bool,
    turns_in_a_row: u32,
    /// The last step was a translation (so a bumper contact now is its doing).
    last_was_translate: bool,
    end: End,
}

/// How far [`RandomBounce`] is from its end.
#[derive(Clone, Copy, PartialEq)]
enum End {
    /// Still driving.
    No,
    /// The next step ends the region (a [`BOXED_IN_NOTE`] was just written).
    Next,
    /// The region is ended: nothing more to do.
    Done,
}

/// Random turns in a row after which the planner turns to a free heading on purpose: the
/// robot has wedged itself where random turns keep facing obstacles (a gap beside a pillar
/// that only the exact way back leads out of). It then gave up after 64 turns and reported
/// "done": 9 m of a 480 m budget driven, 7 % swept, no warning.
pub const RANDOM_TRIES: u32 = 8;

/// Headings looked at for a way out ([`RANDOM_TRIES`]): one a degree.
const HEADINGS: u32 = 360;

/// The start of the [`Event::Note`] written when no heading leads anywhere (the run ends
/// with budget left; the command line and Python say so).
pub const BOXED_IN_NOTE: &str = "random-bounce: boxed in";

impl RandomBounce {
    /// A planner with these options.
    pub fn new(opts: RandomBounceOptions) -> Self {
        let rng = SplitMix64::new(opts.seed);
        Self {
            opts,
            rng,
            known: None,
            travelled: 0.0,
            moving: None,
            started: false,
            turns_in_a_row: 0,
            last_was_translate: false,
            end: End::No,
        }
    }
}

impl Planner for RandomBounce {
    fn name(&self) -> &'static str {
        "random-bounce"
    }

    fn next(&mut self, sensor: &dyn Sensor) -> Step {
        match self.end {
            End::Done => return Step::Done,
            End::Next => {
                self.end = End::Done;
                return Step::Mark(Event::RegionEnd { region: 1 });
            }
            End::No => {}
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
        let pose = sensor.pose();
        // The budget counts what the odometry says the last move drove: a move cut short by
        // the bumper (under odometry noise a wall can be nearer than the estimate puts it)
        // counted whole, and such runs drove as little as two thirds of their budget. A move
        // that went as asked counts as asked (the same bytes as before without noise).
        if let Some((from, asked)) = self.moving.take() {
            let went = pose.position().dist(from);
            self.travelled += if (went - asked).abs() <= 1e-9 * asked.max(1.0) {
                asked
            } else {
                went
            };
        }
        let left = budget - self.travelled;
        let r = sensor.robot().radius;
        let res = sensor.frame().resolution;
        // Everything the disk can touch while moving `look` is inside the sensed circle.
        let look = (sensor.sensor_range() - r - 1.5 * res).max(0.0).min(left);
        let free = known.free_distance(pose.position(), pose.theta, look, r);
        let stride_of = |free: f64| (free - 1e-4 * res).max(0.0);
        // The shortest move it drives: half a pixel.
        let drivable = |stride: f64| stride >= 0.5 * res;
        let stride = stride_of(free);
        // Spent: also when what is left is less than the shortest move (the robot turned on
        // the spot until it gave up, and then, looking for a way out, said it was boxed in).
        if left <= 1e-9 || !drivable(stride_of(left)) {
            self.end = End::Done;
            return Step::Mark(Event::RegionEnd { region: 1 });
        }
        // A bumper contact bounces like a sensed obstacle: under odometry noise the pose
        // estimate can put a wall further off than it is, and driving on would push into it.
        let bounced = sensor.bumped() && self.last_was_translate;
        if !bounced && drivable(stride) {
            self.last_was_translate = true;
            self.turns_in_a_row = 0;
            self.moving = Some((pose.position(), stride));
            return Step::Translate(stride);
        }
        self.last_was_translate = false;
        self.turns_in_a_row += 1;
        if self.turns_in_a_row > RANDOM_TRIES {
            // Wedged: turn to the heading with the longest free move, looking every degree
            // from straight behind (the way in) round both ways; none at all: boxed in.
            let mut best: Option<(f64, f64)> = None;
            for k in 0..HEADINGS {
                let half = f64::from(k.div_ceil(2));
                let side = if k % 2 == 1 { 1.0 } else { -1.0 };
                let turn = crate::geometry::wrap_angle(
                    std::f64::consts::PI
                        + side * half * std::f64::consts::TAU / f64::from(HEADINGS),
                );
                let s = stride_of(known.free_distance(pose.position(), pose.theta + turn, look, r));
                if drivable(s) && best.is_none_or(|(b, _)| s > b) {
                    best = Some((s, turn));
                }
            }
            if let Some((_, turn)) = best {
                return Step::Rotate(turn);
            }
            self.end = End::Next;
            return Step::Mark(Event::Note {
                text: format!(
                    "{BOXED_IN_NOTE}: no heading leads half a pixel anywhere (every direction is blocked as far as the sensor sees); stopped after {} m of its {} m budget",
                    crate::display::Compact(self.travelled),
                    crate::display::Compact(budget),
                ),
            });
        }
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

    /// A robot in a round hole that leaves it less than half a pixel of play in every
    /// direction: no heading leads anywhere, and it says so (the run ended "done" after 64
    /// random turns, without a word).
    #[test]
    fn a_robot_boxed_in_says_so_and_ends() {
        let (n, c) = (21usize, 10.5f64);
        let rc = crate::collide::contact_radius_px(3.0);
        let mut art = String::new();
        for row in 0..n {
            for col in 0..n {
                let (x, y) = (col as f64 + 0.5 - c, row as f64 + 0.5 - c);
                art.push(if x.hypot(y) > rc + 0.1 { '#' } else { '.' });
            }
            art.push('\n');
        }
        let map = GridMap::from_ascii_scaled(art.trim_end(), 1, 0.05).unwrap();
        let world = World::new(map, Robot::new(0.15), Some(Pose::new(0.525, 0.525, 0.0))).unwrap();
        let mut p = RandomBounce::new(RandomBounceOptions {
            budget_m: Some(10.0),
            ..Default::default()
        });
        let out = simulate(&world, &mut p, &SimConfig::default());
        assert_eq!(out.stop, StopReason::Done);
        let notes: Vec<&str> = out
            .trace
            .events()
            .filter_map(|(_, e)| match e {
                Event::Note { text } => Some(text.as_str()),
                _ => None,
            })
            .collect();
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(notes[0].starts_with(BOXED_IN_NOTE), "{}", notes[0]);
        assert!(
            notes[0].contains("after 0 m of its 10 m budget"),
            "{}",
            notes[0]
        );
        let m = crate::metrics::compute(&world, &out, "hole");
        assert_eq!((m.path_length_m, m.collisions), (0.0, 0));
    }

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
        // The budget counts what the odometry says each move drove, not what was asked: the
        // moves the bumper cut short were counted whole, and this run drove 136.3 m of 150.
        assert!(
            (m.path_length_m - 150.0).abs() < 0.02 * 150.0,
            "{} m",
            m.path_length_m
        );
    }
}
