//! The trace: every executed pose and every event of a run, in order. Metrics, pictures and the
//! replay are pure functions of (world, trace).
//!
//! Serialized as JSON Lines: `{"t":3,"pose":[x,y,theta]}` for poses and
//! `{"t":3,"event":"region_start","region":1}` for events.

use serde::{Deserialize, Serialize};

use crate::geometry::Pose;

/// Something that happened during a run (a mark in the trace). Planners emit most of these;
/// the simulator emits [`Event::Collision`] and [`Event::Finished`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum Event {
    /// A coverage segment starts (boustrophedon region, spiral, BCD cell...). Counted by the
    /// `regions` metric.
    RegionStart {
        /// 1-based region number.
        region: u32,
    },
    /// A coverage segment ends.
    RegionEnd {
        /// 1-based region number.
        region: u32,
    },
    /// BA*: the robot is at a critical point (all four neighbours blocked).
    CriticalPoint {
        /// World x of the tile centre.
        x: f64,
        /// World y.
        y: f64,
    },
    /// A planner picked the next starting point (BA* `s_sp`, BSA backtracking point).
    StartPoint {
        /// World x.
        x: f64,
        /// World y.
        y: f64,
    },
    /// A transfer between regions starts: motion until [`Event::BacktrackEnd`] is backtracking.
    BacktrackStart,
    /// The transfer ends.
    BacktrackEnd,
    /// A planned path before smoothing (world points).
    PathRaw {
        /// Waypoints.
        points: Vec<[f64; 2]>,
    },
    /// A planned path after smoothing (world points).
    PathSmoothed {
        /// Waypoints.
        points: Vec<[f64; 2]>,
    },
    /// The current backtracking list (candidate start points), world tile centres.
    BacktrackList {
        /// Candidates.
        points: Vec<[f64; 2]>,
    },
    /// A candidate backtracking point was recorded (BSA).
    BacktrackPoint {
        /// World x.
        x: f64,
        /// World y.
        y: f64,
    },
    /// Wall following starts (extended BSA).
    WallFollowStart,
    /// Wall following ends.
    WallFollowEnd,
    /// The bumper touched an obstacle: the motion stopped at contact.
    Collision {
        /// World x of the robot centre at contact.
        x: f64,
        /// World y.
        y: f64,
    },
    /// The run ended.
    Finished {
        /// Why: `done`, `budget`, `max_steps`, ...
        reason: String,
    },
    /// Free-form note from a planner.
    Note {
        /// Text.
        text: String,
    },
    /// The simulator executes motions by PID tracking on a unicycle model (see
    /// [`crate::exec`]); written once at the start of such a run. Absent for ideal execution.
    Execution {
        /// `pid`.
        mode: String,
        /// Control period, seconds.
        dt_s: f64,
        /// Waypoint tolerance, metres: a waypoint counts as reached within this distance (the
        /// `coverage_rate` metric uses it as the tile-centre visit tolerance).
        tolerance_m: f64,
    },
    /// The straight segment the robot is asked to follow next (PID execution only). The pose
    /// records up to the next such event are measured against it (`tracking_error_*`).
    PlannedSegment {
        /// Start (planned position before the motion), world.
        from: [f64; 2],
        /// Goal, world.
        to: [f64; 2],
    },
    /// Rectangular-robot lane sweep (seed 001): lane spacing and robot length, for the
    /// `rect_guarantee` metric.
    RectLanes {
        /// Robot length `l` (waypoint spacing along a lane), metres.
        length_m: f64,
        /// Robot width `b` (lane spacing), metres.
        width_m: f64,
    },
    /// The pose estimate was reset from a landmark observation (see [`crate::landmarks`]).
    LandmarkFix {
        /// Observed (shared) landmark id.
        id: u32,
        /// Corrected estimate x.
        x: f64,
        /// Corrected estimate y.
        y: f64,
        /// Corrected estimate heading.
        theta: f64,
    },
}

/// One trace line.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Record {
    /// The robot's pose after a motion (or the start pose at `t = 0`).
    Pose {
        /// Step counter.
        t: u64,
        /// `[x, y, theta]`.
        pose: [f64; 3],
    },
    /// An event.
    Event {
        /// Step counter.
        t: u64,
        /// The event.
        #[serde(flatten)]
        event: Event,
    },
}

/// A whole run's record.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Trace {
    /// The lines, in order.
    pub records: Vec<Record>,
}

impl Trace {
    /// Appends a pose.
    pub fn push_pose(&mut self, t: u64, p: Pose) {
        self.records.push(Record::Pose {
            t,
            pose: [p.x, p.y, p.theta],
        });
    }

    /// Appends an event.
    pub fn push_event(&mut self, t: u64, event: Event) {
        self.records.push(Record::Event { t, event });
    }

    /// The executed poses, in order.
    pub fn poses(&self) -> impl Iterator<Item = Pose> + '_ {
        self.records.iter().filter_map(|r| match r {
            Record::Pose { pose, .. } => Some(Pose {
                x: pose[0],
                y: pose[1],
                theta: pose[2],
            }),
            Record::Event { .. } => None,
        })
    }

    /// The events, in order, with their step.
    pub fn events(&self) -> impl Iterator<Item = (u64, &Event)> + '_ {
        self.records.iter().filter_map(|r| match r {
            Record::Event { t, event } => Some((*t, event)),
            Record::Pose { .. } => None,
        })
    }
}
