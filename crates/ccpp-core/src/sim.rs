//! The simulator: holds the truth, executes each planner [`Step`] with an ideal differential
//! drive (exact in-place rotations and straight translations), checks every motion against the
//! true map, stops on contact (the bumper) and records the [`Trace`].

use std::ops::{Add, Sub};
use serde::{Deserialize, Serialize};

use crate::geometry::{wrap_angle, Point, Pose};
use crate::grid::MapFrame;
use crate::planner::{Planner, Scan, Sensor, Step};
use crate::trace::{Event, Trace};
use crate::world::{Robot, World};

/// Rotations smaller than this (radians) are not executed.
pub const MIN_ROTATION: f64 = 1e-9;

/// Simulator settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SimConfig {
    /// Sensor range in metres; `None` = `4 r` (enough to classify all 8 neighbour tiles).
    pub sensor_range: Option<f64>,
    /// Safety cap on planner steps.
    pub max_steps: u64,
}

impl Default for SimConfig {
    fn default() -> Self {
        Self {
            sensor_range: None,
            max_steps: 50_000_000,
        }
    }
}

/// Why a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// The planner said it was done.
    Done,
    /// The step cap was reached.
    MaxSteps,
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

/// Drives a planner over a world.
pub struct Simulator<'w> {
    world: &'w World,
    pose: Pose,
    bumped: bool,
    range: f64,
    t: u64,
    trace: Trace,
}

impl<'w> Simulator<'w> {
    /// A simulator at the world's start pose.
    pub fn new(world: &'w World, config: &SimConfig) -> Self {
        let range = config.sensor_range.unwrap_or(4.0 * world.robot().radius);
        let pose = world.start();
        let mut trace = Trace::default();
        trace.push_pose(0, pose);
        Self {
            world,
            pose,
            bumped: false,
            range,
            t: 0,
            trace,
        }
    }

    /// Executes one step (anything but `Done`).
    pub fn execute(&mut self, step: Step) {
        self.t += 1;
        match step {
            Step::Rotate(a) => self.rotate(a),
            Step::Translate(d) => self.translate(d),
            Step::MoveTo(p) => {
                let d = p.sub(self.pose.position());
                let dist = d.norm();
                if dist > 1e-12 {
                    self.rotate(wrap_angle(d.y.atan2(d.x) - self.pose.theta));
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
        self.bumped = false;
        self.trace.push_pose(self.t, self.pose);
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
        let b = Point::new(a.x + d.abs() * dir.cos(), a.y + d.abs() * dir.sin());
        match self.world.first_contact(a, b) {
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
    }

    /// Runs `planner` to completion (or the step cap).
    pub fn run(mut self, planner: &mut dyn Planner, config: &SimConfig) -> RunOutput {
        let started = std::time::Instant::now();
        let mut stop = StopReason::MaxSteps;
        for _ in 0..config.max_steps {
            let step = planner.next(&self);
            if step == Step::Done {
                stop = StopReason::Done;
                break;
            }
            self.execute(step);
        }
        let reason = match stop {
            StopReason::Done => "done",
            StopReason::MaxSteps => "max_steps",
        };
        self.trace.push_event(
            self.t,
            Event::Finished {
                reason: reason.to_string(),
            },
        );
        RunOutput {
            trace: self.trace,
            stop,
            tile_side: planner.tile_side(),
            planner: planner.name(),
            wall_time_s: started.elapsed().as_secs_f64(),
        }
    }
}

impl Sensor for Simulator<'_> {
    fn frame(&self) -> &MapFrame {
        self.world.frame()
    }
    fn robot(&self) -> Robot {
        self.world.robot()
    }
    fn pose(&self) -> Pose {
        self.pose
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

/// Convenience: simulate `planner` on `world` with `config`.
pub fn simulate(world: &World, planner: &mut dyn Planner, config: &SimConfig) -> RunOutput {
    Simulator::new(world, config).run(planner, config)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridMap;

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
}
