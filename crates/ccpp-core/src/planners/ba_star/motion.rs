//! Boustrophedon motion: initialisation, one BM step (or the critical point and the choice
//! of the backtracking path) and the arrival at the start point of the next region.

use crate::collide::contact_radius_px;
use crate::geometry::{wrap_angle, Point, Pose};
use crate::planner::{KnownMap, Sensor, Step};
use crate::tiles::{Tile, TileGrid, N8};
use crate::trace::Event;

use super::judge::Judgement;
use super::search::TileSearch;
use super::sensing::{centres_round_home, pixel_to_tiles, touch_box_of, DiskCache, Mind};
use super::smoothing::smooth_path;
use super::tile_model::TileModel;
use super::{BaStar, Phase};

/// The rotation and translation of seed 000's path following from `pose` to `target`:
/// `(beta, alpha, d)` with `beta = atan2(dy, dx)`, `alpha = wrap(beta - theta)`, `d = |delta|`.
pub fn motion_to(pose: Pose, target: Point) -> (f64, f64, f64) {
    let dx = target.x - pose.x;
    let dy = target.y - pose.y;
    let beta = dy.atan2(dx);
    (beta, wrap_angle(beta - pose.theta), dx.hypot(dy))
}

impl BaStar {
    pub(super) fn init(&mut self, sensor: &dyn Sensor) {
        let r = sensor.robot().radius;
        let side = self.opts.tile_side_m.unwrap_or(2.0 * r);
        self.side = Some(side);
        let frame = *sensor.frame();
        let grid = TileGrid::new(sensor.pose().position(), side);
        let mut tiles = TileModel::new(grid, &frame);
        tiles.lane_end_corners = self.opts.lane_end_corners;
        let known = KnownMap::new(&frame);
        tiles.judge_frame_edges(&known, r);
        let search = TileSearch::new(tiles.bounds());
        let n_tiles = tiles.state.len();
        let rc_px = contact_radius_px(r / frame.resolution);
        let (gx, gy) = if frame.origin.theta == 0.0 {
            let (i0, i1, j0, j1) = tiles.bounds();
            (
                (i0..=i1)
                    .map(|i| frame.world_to_grid(grid.center((i, j0))).x)
                    .collect(),
                (j0..=j1)
                    .map(|j| frame.world_to_grid(grid.center((i0, j))).y)
                    .collect(),
            )
        } else {
            (Vec::new(), Vec::new())
        };
        let touch_cols: Vec<(i64, i64)> = gx
            .iter()
            .map(|&x| touch_box_of(Point::new(x, 0.0), rc_px, 0.0).1)
            .collect();
        let touch_rows: Vec<(i64, i64)> = gy
            .iter()
            .map(|&y| touch_box_of(Point::new(0.0, y), rc_px, frame.height as f64).0)
            .collect();
        let (i0, _, j0, _) = tiles.bounds();
        let range = sensor.sensor_range();
        let sight = crate::planners::settings::neighbour_sight_m(side, r, frame.resolution);
        if range < sight {
            self.pending.push_back(Step::Mark(Event::Note {
                text: format!(
                    "ba-star: sensor range {range} m < tile side + r + res / 2 = {sight} m; some \
                     moves may stay undecided"
                ),
            }));
        }
        self.mind = Some(Box::new(Mind {
            list_room: Some(
                n_tiles
                    .saturating_mul(self.list_points_per_tile)
                    .min(super::LIST_POINTS_MAX),
            ),
            known,
            tiles,
            search,
            r,
            rc_px,
            last_scan: None,
            last_disk: None,
            new_spans: Vec::new(),
            candidate_rows: Vec::new(),
            band_rows: ((side / frame.resolution).floor() as usize).clamp(1, 64),
            disk: DiskCache::new(n_tiles, rc_px),
            col_tiles: if gx.is_empty() {
                Vec::new()
            } else {
                pixel_to_tiles(&touch_cols, frame.width, i0, false)
            },
            row_tiles: if gy.is_empty() {
                Vec::new()
            } else {
                pixel_to_tiles(&touch_rows, frame.height, j0, true)
            },
            touch_cols,
            touch_rows,
            gx,
            gy,
            sent_to: None,
            sent_move: None,
            held: None,
            centres_home: centres_round_home(&grid),
        }));
    }

    pub(super) fn bm_step(&mut self, sensor: &dyn Sensor) -> Step {
        let Some(m) = self.mind.as_deref_mut() else {
            return Step::Done;
        };
        let mut c = match m.held.take() {
            Some(t) => t,
            None => m.robot_tile(sensor.pose().position()),
        };
        if let Some((from, k)) = m.sent_move.take() {
            if sensor.bumped() {
                // The move did not arrive: the robot stays on the tile it left (its estimate
                // may lie inside the target's square, which it has not reached).
                m.block_bumped_move(from, k);
                c = from;
            }
        }
        m.cover(c);
        for k in [2, 6, 0, 4] {
            let n = (c.0 + N8[k].0, c.1 + N8[k].1);
            if !m.tiles.covered(n) && m.judge_move(c, k) == Judgement::Free {
                m.sent_to = Some(n);
                m.sent_move = Some((c, k));
                return Step::MoveTo(m.center(n));
            }
        }
        // Critical point.
        let cp = m.center(c);
        self.pending
            .push_back(Step::Mark(Event::CriticalPoint { x: cp.x, y: cp.y }));
        self.pending.push_back(Step::Mark(Event::RegionEnd {
            region: self.region,
        }));
        if self.opts.record_backtrack_list {
            let n = m.tiles.l.len();
            match m.list_room {
                Some(room) if n <= room => {
                    m.list_room = Some(room - n);
                    let pts = m
                        .tiles
                        .l_tiles()
                        .into_iter()
                        .map(|t| {
                            let p = m.center(t);
                            [p.x, p.y]
                        })
                        .collect();
                    self.pending
                        .push_back(Step::Mark(Event::BacktrackList { points: pts }));
                }
                Some(_) => {
                    // The trace holds each list whole: on a 2000 x 2000 px map of salt noise
                    // at r = 0.05 m, 51 071 lists took 5 GB, six times the run's estimate.
                    m.list_room = None;
                    self.pending.push_back(Step::Mark(Event::Note {
                        text: format!(
                            "ba-star: backtracking lists are not recorded from here on: those recorded reached the trace's bound of {} points per tile of the map, at most {} (record_backtrack_list)",
                            self.list_points_per_tile,
                            super::LIST_POINTS_MAX
                        ),
                    }));
                }
                None => {}
            }
        }
        if m.tiles.l.len() == 0 {
            self.phase = Phase::Finished;
            return self.pending.pop_front().unwrap_or(Step::Done);
        }
        let tiles = &m.tiles;
        let targets = tiles.l_tiles();
        let found = m.search.nearest_of(tiles, c, &targets, |t| tiles.in_l(t));
        let Some((sp, sp_cost)) = found else {
            // Covered tiles form one connected graph, but for moves the bumper stopped
            // (`Mind::bumped_leg`): under odometry noise the tiles left in `L` may lie beyond
            // them.
            self.pending.push_back(Step::Mark(Event::Note {
                text: format!(
                    "{}: the {} tile(s) left in its backtracking list lie beyond moves the bumper stopped, so the floor there was not covered",
                    super::UNREACHABLE_NOTE,
                    m.tiles.l.len()
                ),
            }));
            self.phase = Phase::Finished;
            return self.pending.pop_front().unwrap_or(Step::Done);
        };
        let raw = m
            .search
            .astar_nearest(&m.tiles, c, sp, sp_cost)
            .map_or_else(|| vec![c, sp], |(p, _)| p);
        let smoothed = if self.opts.smoothing {
            let mm = &*m;
            smooth_path(&raw, |a, b| !mm.tiles.rough(a) && mm.visible(a, b))
        } else {
            raw.clone()
        };
        let to_pts = |p: &[Tile]| {
            p.iter()
                .map(|&t| {
                    let q = m.center(t);
                    [q.x, q.y]
                })
                .collect::<Vec<_>>()
        };
        let spc = m.center(sp);
        self.pending
            .push_back(Step::Mark(Event::StartPoint { x: spc.x, y: spc.y }));
        self.pending.push_back(Step::Mark(Event::PathRaw {
            points: to_pts(&raw),
        }));
        self.pending.push_back(Step::Mark(Event::PathSmoothed {
            points: to_pts(&smoothed),
        }));
        self.pending.push_back(Step::Mark(Event::BacktrackStart));
        self.phase = Phase::Backtrack {
            path: smoothed,
            next: 1,
        };
        self.pending.pop_front().unwrap_or(Step::Done)
    }

    pub(super) fn arrive(&mut self, sensor: &dyn Sensor) -> Step {
        self.region += 1;
        self.pending.push_back(Step::Mark(Event::BacktrackEnd));
        self.pending.push_back(Step::Mark(Event::RegionStart {
            region: self.region,
        }));
        if let Some(m) = self.mind.as_deref_mut() {
            let c = m
                .held
                .unwrap_or_else(|| m.tiles.grid.tile_of(sensor.pose().position()));
            // The direction of the first BM move (N, S, E, W order).
            let first = [2, 6, 0, 4].into_iter().find(|&k| {
                let n = (c.0 + N8[k].0, c.1 + N8[k].1);
                !m.tiles.covered(n) && m.judge_move(c, k) == Judgement::Free
            });
            if let Some(k) = first {
                let gamma = f64::from(N8[k].1).atan2(f64::from(N8[k].0));
                let alpha = wrap_angle(gamma - sensor.pose().theta);
                if alpha.abs() > crate::planner::MIN_ROTATION {
                    self.pending.push_back(Step::Rotate(alpha));
                }
            }
        }
        self.phase = Phase::Bm;
        self.pending.pop_front().unwrap_or(Step::Done)
    }
}
