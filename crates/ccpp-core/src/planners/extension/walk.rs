//! One chunk of a cleaning pass: the search for a rim, the greedy contour walk along it (the
//! strip rules included), then merging, simplifying and squaring its corners; and the lane
//! ends driven to the wall.

use super::graph::NB;
use super::search::COST_ORTHO;
use super::{Chunk, Extension, Wanted};
use crate::geometry::{path_length, Point};
use crate::planner::KnownMap;
use crate::planners::ba_star::{judge_motion, Judgement};

/// A strip of rim: at least [`STRIP_N`] targets within the tool radius plus [`STRIP_PX`]
/// pixels (see `plan_pass`).
pub(super) const STRIP_PX: f64 = 3.0;
const STRIP_N: usize = 4;

/// Longest walk of one chunk, in pixel steps.
const MAX_WALK: usize = 20_000;

impl Extension {
    /// One chunk of [`Self::plan_pass`]; `resume` goes on with the last search from `pos`
    /// (the last chunk was left).
    pub(super) fn plan_chunk(
        &mut self,
        known: &KnownMap,
        pos: Point,
        bounded: bool,
        wanted: Wanted,
        resume: bool,
    ) -> Chunk {
        let from = self.frame.world_to_grid_snapped(pos);
        let limit = bounded.then(|| {
            (self.opts.reach_r * self.r / self.frame.resolution * COST_ORTHO as f64) as u64
        });
        // Thresholds, in pixels a position must sweep: a trip to a rim must gain a tool radius
        // of pixels (at least 2; after the host's coverage one on a strip of rim: only specks
        // stay), a step off the contour as much, a step along the contour one.
        let tool = self.rt.ceil().max(1.0) as usize;
        let g_start = if bounded { tool } else { tool.max(2) };
        let g_int = tool;
        let g_con = 1;
        // A resumed search follows a chunk left in the same pass: the known map is the same.
        if !bounded && !resume {
            self.refresh_no_gain(known);
            // No chunk planned before gives its claims back selectively now (see `unclaim`).
            self.no_gain_log_base += self.no_gain_log.len();
            self.no_gain_log.clear();
        }
        if !resume {
            // A new search (from elsewhere, or the known map changed): other ways.
            self.merge_memo.clear();
            self.charged_segs.clear();
        }
        if let Some(l) = limit {
            // Every position the bounded search settles lies within `l` of `from`.
            let rad = (l / COST_ORTHO) as i64 + self.tool_rows.len() as i64 + 2;
            let p0 = self.frame.grid_to_pixel_signed(from);
            self.build_window(known, p0, rad, wanted);
        }
        self.exhaust_check = !bounded;
        let transit = self.search(known, from, limit, None, resume, &mut |s, p| {
            let i = s.idx(p).expect("positions are in the image");
            if !bounded && s.no_gain.contains(i) {
                return false;
            }
            let g = s.gain(known, p, wanted, g_start);
            // After the host: a position that sweeps a single pixel starts a pass too when it
            // lies on a strip of rim (enough targets in the wider disk), not on a lone speck.
            let gains = g >= g_start
                || (!bounded
                    && g >= 1
                    && (s.count_targets(known, p, wanted, STRIP_N, &s.strip_rows) >= STRIP_N
                        || s.sweeps_owed(p)));
            if !gains && !bounded {
                s.no_gain.insert(i);
                s.no_gain_log.push(i);
            }
            gains
        });
        self.win_on = false;
        self.exhaust_check = false;
        let Some(transit) = transit else {
            return Chunk::default();
        };
        let log_at = self.no_gain_log_base + self.no_gain_log.len();
        let mut pts: Vec<Point> = vec![from];
        let mut gains: Vec<Vec<usize>> = vec![Vec::new()];
        for &i in &transit[..transit.len() - 1] {
            pts.push(self.center(self.px_of(i)));
            gains.push(Vec::new());
        }
        // The walk.
        // Gains beyond a tool radius of pixels do not outrank a straighter step (fewer turns
        // once merged; on the shared maps 3 % fewer turns for either host).
        let walk_cap = g_int;
        let mut cur = self.px_of(*transit.last().expect("non-empty path"));
        let mut dir: Option<usize> = None;
        pts.push(self.center(cur));
        gains.push(self.claim(known, cur, wanted));
        for _ in 0..MAX_WALK {
            let mut best: Option<(bool, usize, i64, usize)> = None;
            for k in 0..8 {
                if !self.edge(known, cur, k) {
                    continue;
                }
                let q = (cur.0 + NB[k].0, cur.1 + NB[k].1);
                // Counted up to `walk_cap` (>= `g_int` >= `g_con`): every test below reads no more.
                let g = self.gain(known, q, wanted, walk_cap);
                if g < g_con {
                    continue;
                }
                let contour = self.on_contour(known, q);
                // Off the contour a step must gain a tool radius of pixels; with `strip_walk`
                // (final clean-up only) also a step onto a strip of rim, as a pass may start.
                if !contour
                    && g < g_int
                    && !(self.strip_walk
                        && !bounded
                        && self.count_targets(known, q, wanted, STRIP_N, &self.strip_rows)
                            >= STRIP_N)
                {
                    continue;
                }
                let turn = dir.map_or(0, |d| {
                    let t = (k + 8 - d) % 8;
                    t.min(8 - t) as i64
                });
                let key = (contour, g.min(walk_cap), -turn, k);
                let better = best.is_none_or(|b| {
                    (key.0, key.1, key.2) > (b.0, b.1, b.2)
                        || ((key.0, key.1, key.2) == (b.0, b.1, b.2) && key.3 < b.3)
                });
                if better {
                    best = Some(key);
                }
            }
            let Some((_, _, _, k)) = best else { break };
            cur = (cur.0 + NB[k].0, cur.1 + NB[k].1);
            dir = Some(k);
            pts.push(self.center(cur));
            gains.push(self.claim(known, cur, wanted));
        }
        // The transfer (up to the walk's first position, index `nt`) and the walk are merged
        // apart: no segment cuts across from the way there to the rim.
        let nt = transit.len();
        let mut simplified = 0;
        let kept: Vec<usize> = if self.opts.merge_segments {
            let mut kept = if bounded {
                self.merge(known, &pts[..=nt], &gains[..=nt])
            } else {
                self.merge_transfer(known, &pts[..=nt], &gains[..=nt])
            };
            kept.extend(
                self.merge(known, &pts[nt..], &gains[nt..])
                    .into_iter()
                    .map(|k| k + nt),
            );
            let (kept, lost) = self.simplify(known, &pts, &gains, kept);
            simplified = lost;
            kept
        } else {
            (1..pts.len()).collect()
        };
        let verts: Vec<(usize, Point)> = std::iter::once(0)
            .chain(kept)
            .map(|k| (k, pts[k]))
            .collect();
        let verts = if self.opts.merge_segments && self.opts.corner_slack > 0.0 {
            self.square_corners(known, &gains, verts)
        } else {
            verts
        };
        let split = verts.partition_point(|v| v.0 <= nt);
        // A move from before the walk's first position to after it: more way or more walk?
        let lead_in = split >= 1 && split < verts.len() && verts[split - 1].0 < nt && {
            let (j, k) = (verts[split - 1].0, verts[split].0);
            path_length(&pts[j..=nt]) > path_length(&pts[nt..=k])
        };
        Chunk {
            transfer: verts[1..split].iter().map(|v| self.world(v.1)).collect(),
            sweep: verts[split..].iter().map(|v| self.world(v.1)).collect(),
            lead_in,
            gained: gains.iter().map(Vec::len).sum(),
            claimed: gains.iter().flatten().copied().collect(),
            owed: self.any_owed && gains.iter().flatten().any(|&i| self.owed.contains(i)),
            simplified,
            log_at,
        }
    }

    /// Lane ends driven to the wall: the host's lane along heading `theta` ends at world point
    /// `c` and the host moves on to `next` (the start of its next lane, beside `c`). When a
    /// known obstacle lies within `reach` metres ahead of `c`, the robot drives on to it, along
    /// it to the point in front of `next`, and back to `next` (the next lane, started at the
    /// wall); the waypoints, or `None` when there is no wall ahead or nothing to gain there.
    pub(crate) fn lane_end(
        &mut self,
        known: &KnownMap,
        c: Point,
        theta: f64,
        next: Point,
        reach: f64,
        wanted: &dyn Fn(Point) -> bool,
    ) -> Option<Vec<Point>> {
        let res = self.frame.resolution;
        let ahead = |p: Point| -> Option<Point> {
            let d = known.free_distance(p, theta, reach, self.r);
            if d >= reach - 1e-9 {
                return None;
            }
            // Stop a hair short of contact, then make sure.
            let mut d = d - 1e-3 * res;
            for _ in 0..8 {
                let w = Point::new(p.x + d * theta.cos(), p.y + d * theta.sin());
                if d <= 0.0 {
                    return None;
                }
                if judge_motion(known, p, w, self.r) == Judgement::Free {
                    return Some(w);
                }
                d -= 0.05 * res;
            }
            None
        };
        let w = ahead(c)?;
        if w.dist(c) < 0.5 * res {
            return None;
        }
        let gw = self
            .frame
            .grid_to_pixel_signed(self.frame.world_to_grid_snapped(w));
        if self.gain(known, gw, Some(wanted), 2) < 2 {
            return None;
        }
        let free = |a: Point, b: Point| judge_motion(known, a, b, self.r) == Judgement::Free;
        let out = match ahead(next) {
            Some(w2) if free(w, w2) => vec![w, w2, next],
            _ if free(w, next) => vec![w, next],
            _ => vec![w, c, next],
        };
        for w2 in out.windows(2) {
            self.record(w2[0], w2[1]);
        }
        self.record(c, w);
        Some(out)
    }
}
