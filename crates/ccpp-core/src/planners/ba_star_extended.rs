//! `ba-star-extended`: BA* ([`super::ba_star`], seed 000) plus the generic coverage extension
//! of seed 002 ([`super::extension`]), so that the rims BA*'s 2r tiles leave along walls and
//! furniture are swept too.
//!
//! BA* runs unchanged as the backbone. The extension steps in at two moments:
//!
//! * **End of a boustrophedon region** (a critical point, when BA* would start backtracking;
//!   off by default, [`ExtensionOptions::reach_r`] `= 0`): cleaning passes over the rims within [`ExtensionOptions::reach_r`] robot radii of the
//!   robot — pixels BA* will still sweep (those of tiles that are neither covered nor
//!   obstacles) are left to BA*. Then, instead of returning to the critical point, the robot
//!   drives a known-free transfer ([`super::extension`]'s A* over positions, merged into
//!   straight segments) straight to BA*'s chosen start point `s_sp`, and BA* resumes there.
//!   When nothing was cleaned (the default, `reach_r` 0), the extension's known-free
//!   transfer is driven too wherever it is shorter than BA*'s A*SPT-smoothed path over
//!   covered tiles ([`BaStarExtendedOptions::shorter_backtrack`]; BA*'s own path otherwise):
//!   the positions may cut across known-free floor BA* has not covered and corners its tile
//!   line of sight cannot. Before that transfer, rims next to the robot (each found within
//!   [`ON_WAY_REACH_R`] robot radii) may be swept whole on the way
//!   ([`BaStarExtendedOptions::backtrack_sweep`]): while the pass along the next one and
//!   the way on from its end to `s_sp` make the way back longer by less than the rim swept
//!   divided by `backtrack_sweep`, the robot drives that pass first. On `teb_corridor` BA*'s first
//!   region ends at the far end of the corridor; the way back along the wall sweeps the
//!   rim the final clean-up would have walked.
//! * **End of BA*** (`L` empty): passes over every rim left, wherever it is, nearest first;
//!   a trip that does not pay for itself ([`ExtensionOptions::min_yield`]) is left, within
//!   [`ExtensionOptions::leave_fraction`] of the known floor.
//!
//! The passes are marked `wall_follow_start` / `wall_follow_end` in the trace, the transfer
//! keeps BA*'s `backtrack_start` / `backtrack_end` marks, and every trip of a robot diameter or
//! more from one rim to the next (the first part of a chunk, [`super::extension`]'s
//! `plan_pass`) is marked `backtrack_start` / `backtrack_end` too: it sweeps nothing on purpose,
//! so it draws dashed and counts in `backtrack_length`. Everything is planned from what the
//! sensor has shown (BA*'s [`KnownMap`](crate::planner::KnownMap)), never from the world.
//!
//! ```
//! use ccpp_core::{GridMap, Pose};
//! use ccpp_core::world::{Robot, World};
//! use ccpp_core::planners::ba_star_extended::{BaStarExtended, BaStarExtendedOptions};
//! use ccpp_core::sim::{simulate, SimConfig};
//! let art = concat!(
//!     "#########\n",
//!     "#.......#\n",
//!     "#..##...#\n",
//!     "#.......#\n",
//!     "#########",
//! );
//! let map = GridMap::from_ascii_scaled(art, 7, 0.02).unwrap();
//! let world = World::new(map, Robot::new(0.1), Some(Pose::new(0.28, 0.27, 0.0))).unwrap();
//! let mut planner = BaStarExtended::new(BaStarExtendedOptions::default());
//! let out = simulate(&world, &mut planner, &SimConfig::default());
//! let m = ccpp_core::metrics::compute(&world, &out, "room");
//! assert_eq!(m.collisions, 0);
//! assert_eq!(m.coverage_rate, Some(1.0));
//! ```

use serde::{Deserialize, Serialize};

use super::ba_star::{BaStar, BaStarOptions};
use super::extension::{Chunk, Drive, Extension, ExtensionOptions, Mode};
use crate::geometry::{polyline_length, Point};
use crate::planner::{Planner, Sensor, Step};
use crate::trace::Event;

/// Options of [`BaStarExtended`] (`--planner ba-star-extended`, config section
/// `ba_star_extended`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BaStarExtendedOptions {
    /// The BA* backbone.
    pub ba_star: BaStarOptions,
    /// The extension. Its `reach_r` defaults to 0 here (one clean-up after BA*): cleaning
    /// around each region's end left the robot far from BA*'s next start, and the transfers
    /// made the mean path ratio on the 14 shared maps 1.461 instead of 1.421. Its final
    /// clean-up leaves trips below a yield of 0.03 within 0.3 % of the floor (`min_yield`
    /// 0.03, `leave_fraction` 0.003; the component's are 0.05 and 0.002): with
    /// `leave_group` judging clusters of specks as one and squared corners, the mean path
    /// ratio on the shared maps went from 1.366 to 1.337 and every map stayed at or above
    /// 99.5 % swept (the lowest, `stage_willow_full`, at 99.53 %). Clusters are judged up
    /// to 12 chunks together here (`leave_group` 12; the component's is 8): on the shared
    /// maps the mean path ratio went from 1.3235 to 1.3218 and the mean turns from 2013 to
    /// 2004 (`aws_small_warehouse_002` 1.326 -> 1.303), no map's path ratio grew and the
    /// lowest floor swept stayed 99.52 % (16 pushed `nav2_depot` from 1.185 to 1.210). An
    /// `extension` section that omits a field gets this planner's default for it, not the
    /// component's.
    #[serde(deserialize_with = "super::settings::ba_star_extended_extension")]
    pub extension: ExtensionOptions,
    /// Drive BA*'s backtracking transfers on the extension's known-free straight segments
    /// (A* over positions, merged by lines of sight) wherever that way is shorter than BA*'s
    /// A*SPT-smoothed path over covered tiles (`false`: BA*'s path, as `ba-star`).
    pub shorter_backtrack: bool,
    /// Rims swept on the way back: when BA* starts backtracking, the robot may first sweep
    /// the rim next to it (one pass of the extension, its start found within
    /// [`ON_WAY_REACH_R`] robot radii; pixels BA* will still sweep are left to BA*), then the
    /// next one from there, and so on, and transfer to BA*'s start point from the last pass's
    /// end. A pass of `s` metres that makes the way to the start point `e` metres longer than
    /// the transfer from where the robot is would be is driven when `s > backtrack_sweep * e`
    /// (the way on judged on the known-free transfer); the first pass that does not pay ends
    /// the sweeping. `0` never sweeps on the way back. The pass is driven whole or not at all (a rim cut short would
    /// leave a piece the final clean-up walks past anyway; cutting it at the best point made
    /// the mean path ratio on the shared maps 1.328 instead of 1.320).
    pub backtrack_sweep: f64,
}

/// How far (robot radii, path distance) [`BaStarExtendedOptions::backtrack_sweep`] looks for
/// the rim it may sweep on the way back.
pub const ON_WAY_REACH_R: f64 = 4.0;

impl Default for BaStarExtendedOptions {
    fn default() -> Self {
        Self {
            ba_star: BaStarOptions::default(),
            extension: ExtensionOptions {
                reach_r: 0.0,
                min_yield: 0.03,
                leave_fraction: 0.003,
                leave_group: 12,
                ..ExtensionOptions::default()
            },
            shorter_backtrack: true,
            backtrack_sweep: 2.0,
        }
    }
}

/// BA* plus the coverage extension (see the module docs).
pub struct BaStarExtended {
    ba: BaStar,
    opts: ExtensionOptions,
    ext: Option<Extension>,
    mode: Mode,
    /// Queued steps, trail and open wall pass.
    drive: Drive,
    /// Heading of the host's last lane move, while the host is in a lane.
    lane: Option<f64>,
    /// [`BaStarExtendedOptions::shorter_backtrack`].
    shorter_backtrack: bool,
    /// [`BaStarExtendedOptions::backtrack_sweep`].
    backtrack_sweep: f64,
    /// Whether the robot may still sweep a rim on its way back to BA*'s start point.
    on_way: bool,
    /// The last transfer planned during the current [`Self::clean`] call ([`RouteMemo`]).
    route_memo: RouteMemo,
}

/// The transfer last planned (`from`, `to`, the route) while the known map stays as it was:
/// one [`BaStarExtended::clean`] call, in which nothing is sensed. The extension's `route`
/// depends on the known map and its two ends only, so the way back that the rim on the way
/// was judged against is not searched again when that rim is not driven.
type RouteMemo = Option<(Point, Point, Option<Vec<Point>>)>;

/// `ext.route(known, from, to)`, from `memo` when it holds these ends (the caller keeps the
/// known map unchanged while `memo` lives).
fn route_memoised(
    memo: &mut RouteMemo,
    ext: &mut Extension,
    known: &crate::planner::KnownMap,
    from: Point,
    to: Point,
) -> Option<Vec<Point>> {
    if let Some((f, t, route)) = memo {
        if *f == from && *t == to {
            return route.clone();
        }
    }
    let route = ext.route(known, from, to);
    *memo = Some((from, to, route.clone()));
    route
}

impl BaStarExtended {
    /// A planner with these options.
    pub fn new(opts: BaStarExtendedOptions) -> Self {
        Self {
            ba: BaStar::new(opts.ba_star),
            opts: opts.extension,
            ext: None,
            mode: Mode::Host,
            drive: Drive::default(),
            lane: None,
            shorter_backtrack: opts.shorter_backtrack,
            backtrack_sweep: opts.backtrack_sweep,
            on_way: false,
            route_memo: None,
        }
    }

    /// The BA* backbone (its known map, tiles and backtracking list).
    pub fn backbone(&self) -> &BaStar {
        &self.ba
    }

    /// One cleaning chunk, or the end of the cleaning.
    fn clean(&mut self, pos: Point, last: bool) {
        // The known map changed since the last call (the robot drove and sensed).
        self.route_memo = None;
        // At a region's end, and after each pass swept on the way back: the next rim swept on
        // the way, while one pays.
        let on_way =
            (!last && self.opts.reach_r <= 0.0 && self.backtrack_sweep > 0.0 && self.on_way).then(
                || {
                    let chunk = self.on_way_chunk(pos);
                    self.on_way = !chunk.sweep.is_empty();
                    chunk
                },
            );
        let Some(ext) = self.ext.as_mut() else {
            self.mode = Mode::Host;
            return;
        };
        let Some(known) = self.ba.known_map() else {
            self.mode = Mode::Host;
            return;
        };
        let bounded = !last;
        let chunk = if bounded && ext.options().reach_r <= 0.0 {
            on_way.unwrap_or_default()
        } else {
            let ba = &self.ba;
            let wanted = |p: Point| !ba.will_cover(p);
            ext.plan_pass(
                known,
                pos,
                bounded,
                (!last).then_some(&wanted as &dyn Fn(Point) -> bool),
            )
        };
        if self.drive.queue_chunk(pos, &chunk, ext.radius()) {
            return;
        }
        self.drive.end_pass();
        if last {
            self.mode = Mode::Done;
            return;
        }
        // Transfer to BA*'s start point: direct when the robot moved, else BA*'s own path.
        self.drive
            .queue
            .push_back(Step::Mark(Event::BacktrackStart));
        self.mode = Mode::Host;
        let Some(goal) = self.ba.backtrack_goal() else {
            return;
        };
        if self.drive.trail.len() <= 1 {
            // The robot is where BA* backtracks from: the extension's straight known-free way
            // when it is shorter than BA*'s smoothed tile path.
            if !self.shorter_backtrack {
                return;
            }
            let own = self.ba.backtrack_rest().unwrap_or_default();
            if let Some(route) = route_memoised(&mut self.route_memo, ext, known, pos, goal) {
                if route.last() == Some(&goal)
                    && polyline_length(pos, &route) < polyline_length(pos, &own) - 1e-9
                {
                    self.drive.queue.extend(route.into_iter().map(Step::MoveTo));
                    self.ba.skip_backtrack();
                }
            }
            return;
        }
        let route =
            route_memoised(&mut self.route_memo, ext, known, pos, goal).unwrap_or_else(|| {
                // Retreat the way the passes came (every segment known free); BA* goes on from there.
                self.drive.trail.iter().rev().skip(1).copied().collect()
            });
        let direct = route.last() == Some(&goal);
        for p in route {
            self.drive.queue.push_back(Step::MoveTo(p));
        }
        if direct {
            self.ba.skip_backtrack();
        }
    }
}

impl BaStarExtended {
    /// [`BaStarExtendedOptions::backtrack_sweep`]: the rim next to the robot when sweeping
    /// it on the way to BA*'s start point `s_sp` pays; else no chunk.
    fn on_way_chunk(&mut self, pos: Point) -> Chunk {
        let (Some(ext), Some(known), Some(goal)) = (
            self.ext.as_mut(),
            self.ba.known_map(),
            self.ba.backtrack_goal(),
        ) else {
            return Chunk::default();
        };
        let ba = &self.ba;
        let wanted = |p: Point| !ba.will_cover(p);
        let chunk = ext.plan_near(known, pos, ON_WAY_REACH_R, Some(&wanted));
        // Judged and driven whole, or not at all: a rim cut short here would leave a piece
        // the final clean-up walks past anyway.
        let Some(&end) = chunk.sweep.last() else {
            ext.drop_chunk(&chunk);
            return Chunk::default();
        };
        // The transfer driven without the sweep: BA*'s backtracking (where it starts) or the
        // known-free way.
        let moved = self.drive.trail.len() > 1;
        let mut plain = if moved {
            f64::INFINITY
        } else {
            polyline_length(pos, &self.ba.backtrack_rest().unwrap_or_default())
        };
        if self.shorter_backtrack || moved {
            if let Some(route) = route_memoised(&mut self.route_memo, ext, known, pos, goal) {
                plain = plain.min(polyline_length(pos, &route));
            }
        }
        let (trip, swept) = (chunk.trip_len(pos), chunk.walk_len(pos));
        let pays = |on: f64| swept > self.backtrack_sweep * (trip + swept + on - plain).max(0.0);
        // The straight way on first (a lower bound), then the known-free one.
        if pays(end.dist(goal))
            && ext
                .route(known, end, goal)
                .is_some_and(|on| pays(polyline_length(end, &on)))
        {
            return chunk;
        }
        ext.drop_chunk(&chunk);
        Chunk::default()
    }
}

impl Planner for BaStarExtended {
    fn name(&self) -> &'static str {
        "ba-star-extended"
    }

    fn tile_side(&self) -> Option<f64> {
        self.ba.tile_side()
    }

    fn next(&mut self, sensor: &dyn Sensor) -> Step {
        let pos = self
            .drive
            .observe(&mut self.ext, &self.opts, sensor, |ext| {
                ext.set_speck_fields(true);
            });
        self.ba.observe(sensor);
        // Stuck against a wall under odometry noise: the moves queued from a position the
        // robot is not at are dropped and the cleaning in progress is given up.
        self.drive.abandon_if_stuck(&mut self.mode);
        loop {
            if let Some(s) = self.drive.queue.pop_front() {
                return s;
            }
            match self.mode {
                Mode::Done => return Step::Done,
                Mode::Clean { last } => self.clean(pos, last),
                Mode::Host => match self.ba.next(sensor) {
                    Step::Mark(Event::BacktrackStart) => {
                        self.lane = None;
                        self.on_way = true;
                        self.drive.trail = vec![pos];
                        self.mode = Mode::Clean { last: false };
                    }
                    Step::Done => {
                        self.drive.trail = vec![pos];
                        self.mode = Mode::Clean { last: true };
                    }
                    Step::MoveTo(target) if !self.ba.is_backtracking() => {
                        let theta = sensor.pose().theta;
                        let turn = crate::geometry::wrap_angle(
                            (target.y - pos.y).atan2(target.x - pos.x) - theta,
                        );
                        let in_lane = self
                            .lane
                            .is_some_and(|h| crate::geometry::wrap_angle(h - theta).abs() < 1e-6);
                        self.lane = Some((target.y - pos.y).atan2(target.x - pos.x));
                        let lane_end = if self.opts.lane_ends && in_lane && turn.abs() > 0.1 {
                            match (self.ext.as_mut(), self.ba.known_map(), self.ba.tile_grid()) {
                                (Some(ext), Some(known), Some(g)) => {
                                    let ba = &self.ba;
                                    let wanted = |p: Point| !ba.will_cover(p);
                                    ext.lane_end(known, pos, theta, target, g.side, &wanted)
                                }
                                _ => None,
                            }
                        } else {
                            None
                        };
                        match lane_end {
                            Some(pts) => {
                                for p in pts {
                                    self.drive.queue.push_back(Step::MoveTo(p));
                                }
                            }
                            None => return Step::MoveTo(target),
                        }
                    }
                    s => return s,
                },
            }
        }
    }
}
