//! What a host planner plus the extension keep while they drive.

use std::collections::VecDeque;

use super::{Chunk, Extension, ExtensionOptions};
use crate::geometry::{polyline_length, Point};
use crate::planner::{Sensor, Step};
use crate::trace::Event;

/// Who decides the next step of a host planner plus the extension (`ba-star-extended`,
/// `bsa-extended`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Mode {
    /// The host planner decides.
    Host,
    /// Cleaning passes at the end of a host region (`false`) or of the host (`true`).
    Clean { last: bool },
    /// Everything done.
    Done,
}

/// What a host planner plus the extension keep while they drive (shared by `ba-star-extended`
/// and `bsa-extended`): the steps queued, the waypoints driven since the cleaning began (to
/// retreat by), whether a wall pass is open, and the last position seen (to record each move
/// into the extension).
#[derive(Debug, Default)]
pub(crate) struct Drive {
    /// Steps to return before asking anyone.
    pub queue: VecDeque<Step>,
    /// Waypoints driven since the cleaning began (its start first).
    pub trail: Vec<Point>,
    /// Inside a `wall_follow_start` / `wall_follow_end` pair.
    in_pass: bool,
    last_pos: Option<Point>,
    /// Bumper contacts in a row with the robot's position unchanged between them.
    stuck: u32,
}

/// Bumper contacts in a row, the robot's position unchanged between them, after which the
/// queued moves are dropped and the cleaning in progress is given up ([`Drive::stuck`]).
pub(crate) const STUCK_BUMPS: u32 = 3;

impl Drive {
    /// Records the move since the last step into `ext` (made at the first step, when the
    /// sensor tells the robot's size, and handed to the host's `configure` once then); returns
    /// the robot's position.
    pub fn observe(
        &mut self,
        ext: &mut Option<Extension>,
        opts: &ExtensionOptions,
        sensor: &dyn Sensor,
        configure: impl FnOnce(&mut Extension),
    ) -> Point {
        let pos = sensor.pose().position();
        if sensor.bumped() {
            self.stuck = if self.last_pos == Some(pos) {
                self.stuck.saturating_add(1)
            } else {
                1
            };
        } else {
            self.stuck = 0;
        }
        if let (Some(ext), Some(prev)) = (ext.as_mut(), self.last_pos) {
            if prev != pos {
                ext.record(prev, pos);
            }
        } else {
            let robot = sensor.robot();
            let mut made = Extension::new(
                opts.clone(),
                *sensor.frame(),
                robot.radius,
                robot.tool_radius,
            );
            configure(&mut made);
            made.record(pos, pos);
            *ext = Some(made);
        }
        self.last_pos = Some(pos);
        pos
    }

    /// Queues a chunk from `pos`: its trip (a backtracking transfer, drawn dashed and counted in
    /// `backtrack_length`, when it is a robot diameter (`2 radius`) or longer; else part of the
    /// pass) and its wall pass, with their events. `false` when the chunk is empty.
    pub fn queue_chunk(&mut self, pos: Point, chunk: &Chunk, radius: f64) -> bool {
        if chunk.transfer.is_empty() && chunk.sweep.is_empty() {
            return false;
        }
        // (a lead-in move is driven as the transfer's last: [`Chunk::lead_in`])
        let head = usize::from(chunk.lead_in).min(chunk.sweep.len());
        let (lead, sweep) = chunk.sweep.split_at(head);
        let way: Vec<Point> = chunk.transfer.iter().chain(lead).copied().collect();
        // A micrometre's slack: a one-tile trip is 2 r long, and its length in world
        // coordinates carries their rounding (0.30000000000000004 near the origin,
        // 0.2999999996 at 5.4e6 m), so a translated map labelled the same move otherwise
        // (hostile pass: 10 backtracks instead of 9, same path).
        let transfer = polyline_length(pos, &way) >= 2.0 * radius - 1e-6;
        if transfer {
            self.end_pass();
            self.queue.push_back(Step::Mark(Event::BacktrackStart));
        }
        for &p in &way {
            self.queue.push_back(Step::MoveTo(p));
            self.trail.push(p);
        }
        if transfer {
            self.queue.push_back(Step::Mark(Event::BacktrackEnd));
        }
        if !self.in_pass && !sweep.is_empty() {
            self.in_pass = true;
            self.queue.push_back(Step::Mark(Event::WallFollowStart));
        }
        for &p in sweep {
            self.queue.push_back(Step::MoveTo(p));
            self.trail.push(p);
        }
        true
    }

    /// Is the robot stuck: [`STUCK_BUMPS`] bumper contacts in a row without moving?
    ///
    /// Why: under odometry noise the pose estimate drifts from the truth, and the robot can
    /// face a wall it believes is elsewhere; every move it is sent then stops at once on the
    /// same contact (`ba-star-extended` on `nobleo_basement` at `--odometry-noise 0.02`: the
    /// same nine-move way to one rim piece, planned again and bumped 1492 times, then the
    /// simulator's stall stop). The host then gives the cleaning in progress up
    /// ([`Drive::abandon_if_stuck`]). Under ideal execution a correct plan never bumps.
    pub fn stuck(&self) -> bool {
        self.stuck >= STUCK_BUMPS
    }

    /// When the robot is [`stuck`](Drive::stuck): drops the queued moves (their marks stay,
    /// so every start mark keeps its end), closes an open wall pass, starts counting contacts
    /// anew and gives up the cleaning in progress in `mode` (the host goes on; at the end,
    /// the run ends).
    pub fn abandon_if_stuck(&mut self, mode: &mut Mode) {
        if !self.stuck() {
            return;
        }
        self.queue.retain(|s| matches!(s, Step::Mark(_)));
        self.end_pass();
        self.stuck = 0;
        match *mode {
            Mode::Clean { last: true } => *mode = Mode::Done,
            Mode::Clean { last: false } => *mode = Mode::Host,
            Mode::Host | Mode::Done => {}
        }
    }

    /// Closes an open wall pass (`wall_follow_end`).
    pub fn end_pass(&mut self) {
        if self.in_pass {
            self.in_pass = false;
            self.queue.push_back(Step::Mark(Event::WallFollowEnd));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(x: f64, y: f64) -> Point {
        Point::new(x, y)
    }

    /// The queued steps as letters: `B`/`b` backtrack start/end, `W`/`w` wall pass start/end,
    /// `m` a move.
    fn shape(d: &Drive) -> String {
        d.queue
            .iter()
            .map(|s| match s {
                Step::Mark(Event::BacktrackStart) => 'B',
                Step::Mark(Event::BacktrackEnd) => 'b',
                Step::Mark(Event::WallFollowStart) => 'W',
                Step::Mark(Event::WallFollowEnd) => 'w',
                Step::MoveTo(_) => 'm',
                _ => '?',
            })
            .collect()
    }

    fn chunk(transfer: Vec<Point>, sweep: Vec<Point>, lead_in: bool) -> Chunk {
        Chunk {
            transfer,
            sweep,
            lead_in,
            ..Chunk::default()
        }
    }

    #[test]
    fn a_lead_in_move_is_driven_as_the_transfers_last() {
        // Way 0 -> 1 m, then one merged move 1 -> 3 m (mostly way) and rim 3 -> 3.2 m.
        let c = chunk(vec![p(1.0, 0.0)], vec![p(3.0, 0.0), p(3.0, 0.2)], true);
        let mut d = Drive::default();
        assert!(d.queue_chunk(p(0.0, 0.0), &c, 0.15));
        assert_eq!(shape(&d), "BmmbWm");
        // Without the lead-in the merged move is the pass's first.
        let mut d = Drive::default();
        assert!(d.queue_chunk(
            p(0.0, 0.0),
            &chunk(c.transfer.clone(), c.sweep.clone(), false),
            0.15
        ));
        assert_eq!(shape(&d), "BmbWmm");
        assert_eq!(d.trail, vec![p(1.0, 0.0), p(3.0, 0.0), p(3.0, 0.2)]);
    }

    #[test]
    fn a_way_shorter_than_the_robot_is_part_of_the_pass() {
        // A way of 0.25 m < 2 r = 0.3 m, lead-in included: no transfer marks.
        let c = chunk(vec![p(0.1, 0.0)], vec![p(0.25, 0.0), p(0.25, 1.0)], true);
        let mut d = Drive::default();
        assert!(d.queue_chunk(p(0.0, 0.0), &c, 0.15));
        assert_eq!(shape(&d), "mmWm");
        // Of a diameter or more, it is a transfer, and it closes the pass that was open.
        let c = chunk(vec![p(0.25, 1.0), p(0.25, 1.4)], vec![p(0.3, 1.4)], false);
        assert!(d.queue_chunk(p(0.25, 1.0), &c, 0.15));
        assert_eq!(shape(&d), "mmWmwBmmbWm");
        // An empty chunk queues nothing.
        assert!(!d.queue_chunk(p(0.3, 1.4), &Chunk::default(), 0.15));
        assert_eq!(d.queue.len(), 11);
    }
}
