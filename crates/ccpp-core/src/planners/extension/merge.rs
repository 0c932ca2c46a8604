//! Merging a pixel walk into known-free straight segments that keep its gained pixels within
//! the tool radius, and squaring the rounded corners of the merged chunk.

use super::Extension;
#[cfg(doc)]
use super::ExtensionOptions;
use crate::geometry::{point_segment_dist2, Point};
use crate::planner::KnownMap;

/// Longest merged segment, in walk points (bounds the quadratic merge check).
pub(super) const MAX_MERGE: usize = 256;

/// How many points past the first one a merged segment cannot reach the merge still tries
/// (a wiggle of the wall may block one point while a farther one is in sight).
const MERGE_LOOK: usize = 8;

/// Earlier transfers of a pass whose cuts [`Extension::merge_transfer`] keeps.
const MERGE_MEMO_WAYS: usize = 32;

/// The cuts of one transfer merged in the running pass ([`Extension::merge_transfer`]): its
/// points and, per cut, the kept index, the highest point index the cut read and the last
/// point its segment reached before the look past a blocked point.
pub(super) struct MergeMemo {
    pts: Vec<Point>,
    cuts: Vec<(usize, usize, usize)>,
}

/// Most vertices [`Extension::square_corners`] replaces by one.
const CORNER_RUN: usize = 4;

impl Extension {
    /// Greedy cut of the polyline `pts` into straight segments, each known free and keeping
    /// every pixel in `gains` of the points it replaces within the tool radius. Returns the kept
    /// point indices (the first point, the robot, excluded).
    pub(super) fn merge(
        &self,
        known: &KnownMap,
        pts: &[Point],
        gains: &[Vec<usize>],
    ) -> Vec<usize> {
        self.merge_from(known, pts, gains, Vec::new(), 0, &mut Vec::new())
    }

    /// [`Self::merge`] of a transfer (`gains` empty but at the last point) in the final
    /// clean-up's chunks: the chunks of one pass are found by one search from the same point,
    /// so their ways share the first part (the search tree's) and the greedy cut of that part
    /// is the same. The cuts of the earlier transfers of the pass (`merge_memo`, dropped when
    /// a search starts afresh) are taken over as far as they read only shared points that are
    /// not the last of either way (the cut then asked the same questions of the same known
    /// map), and the rest is merged as usual.
    pub(super) fn merge_transfer(
        &mut self,
        known: &KnownMap,
        pts: &[Point],
        gains: &[Vec<usize>],
    ) -> Vec<usize> {
        let n = pts.len();
        // The memo that gives most: (cuts taken over, where the next cut's first segment
        // may start, memo).
        let mut best: (usize, usize, Option<usize>) = (0, 0, None);
        for (e, memo) in self.merge_memo.iter().enumerate() {
            let m = memo.pts.iter().zip(pts).take_while(|(x, y)| x == y).count();
            // Cuts whose every read lies in the shared points, before the last of either way.
            let lim = m.min(n - 1).min(memo.pts.len() - 1);
            let k = memo.cuts.iter().take_while(|c| c.1 < lim).count();
            // The next cut's segment reached every shared point up to its `bw` (each one
            // kept the gains, empty there, and was known free): start there.
            let skip = memo
                .cuts
                .get(k)
                .map_or(0, |c| c.2.min(lim.saturating_sub(1)));
            if (k, skip) > (best.0, best.1) {
                best = (k, skip, Some(e));
            }
        }
        let (out, mut cuts, skip) = match best {
            (k, skip, Some(e)) => {
                let cuts: Vec<(usize, usize, usize)> = self.merge_memo[e].cuts[..k].to_vec();
                (cuts.iter().map(|c| c.0).collect(), cuts, skip)
            }
            _ => (Vec::new(), Vec::new(), 0),
        };
        let mut his: Vec<(usize, usize)> = Vec::new();
        let out = self.merge_from(known, pts, gains, out, skip, &mut his);
        cuts.extend(
            out[cuts.len()..]
                .iter()
                .zip(his)
                .map(|(&b, (hi, bw))| (b, hi, bw)),
        );
        if self.merge_memo.len() >= MERGE_MEMO_WAYS {
            self.merge_memo.remove(0);
        }
        self.merge_memo.push(MergeMemo {
            pts: pts.to_vec(),
            cuts,
        });
        out
    }

    /// [`Self::merge`] going on after the cuts `out` (the last one the start of the next
    /// segment), whose first segment is known to reach every point up to `skip` (`0`: not
    /// known); pushes, per new cut, the highest point index it read and how far its
    /// segment reached before the look past a blocked point.
    fn merge_from(
        &self,
        known: &KnownMap,
        pts: &[Point],
        gains: &[Vec<usize>],
        mut out: Vec<usize>,
        mut skip: usize,
        his: &mut Vec<(usize, usize)>,
    ) -> Vec<usize> {
        let rt2 = self.rt * self.rt;
        // The gained pixels' centres, once (each is checked against many segments), flat
        // with `at[m]..at[m + 1]` those of point `m`.
        let mut at = Vec::with_capacity(gains.len() + 1);
        let mut centres = Vec::with_capacity(gains.iter().map(Vec::len).sum());
        for g in gains {
            at.push(centres.len());
            centres.extend(g.iter().map(|&i| self.center(self.px_of(i))));
        }
        at.push(centres.len());
        // The last pixel that made a segment not free: asked first (a wiggle of the wall
        // often blocks the next segments tried too).
        let mut witness = None;
        let mut keeps = |a: usize, b: usize| -> bool {
            centres[at[a + 1]..at[b + 1]]
                .iter()
                .all(|&c| point_segment_dist2(c, pts[a], pts[b]) <= rt2)
                && self.seg_free_with(known, pts[a], pts[b], &mut witness)
        };
        let mut a = out.last().copied().unwrap_or(0);
        while a + 1 < pts.len() {
            let mut b = (a + 1).max(skip);
            skip = 0;
            while b + 1 < pts.len() && b + 1 - a <= MAX_MERGE && keeps(a, b + 1) {
                b += 1;
            }
            let far = (b + MERGE_LOOK).min(pts.len() - 1).min(a + MAX_MERGE);
            // Every point this cut read (or weighed the end of the way against).
            his.push(((b + 1).max(far), b));
            if let Some(c) = (b + 2..=far).rev().find(|&c| keeps(a, c)) {
                b = c;
            }
            out.push(b);
            a = b;
        }
        out
    }

    /// Square corners: where the merged chunk rounds a corner (the contour at clearance 0 is an
    /// arc there, several short segments), a run of up to [`CORNER_RUN`] vertices is replaced
    /// by the one point where the segment entering it and the segment leaving it meet, when
    /// both new segments are known free, every pixel the walk gained along the run that the
    /// chunk still sweeps stays within the tool radius, and the way grows by at most
    /// [`ExtensionOptions::corner_slack`] robot radii per turn saved. Takes and returns the
    /// vertices (index of the walk point each replaces last, grid point), the robot's position
    /// first.
    pub(super) fn square_corners(
        &self,
        known: &KnownMap,
        gains: &[Vec<usize>],
        mut out: Vec<(usize, Point)>,
    ) -> Vec<(usize, Point)> {
        let rt2 = self.rt * self.rt;
        let slack = self.opts.corner_slack * self.r / self.frame.resolution;
        let near = |c: Point, poly: &[Point]| {
            poly.windows(2)
                .any(|s| point_segment_dist2(c, s[0], s[1]) <= rt2)
        };
        let mut i = 1;
        while i + 2 < out.len() {
            let mut replaced = false;
            for j in (i + 1..=(i + CORNER_RUN - 1).min(out.len() - 2)).rev() {
                let (a, p, q, b) = (out[i - 1].1, out[i].1, out[j].1, out[j + 1].1);
                let (d1, d2) = (p - a, b - q);
                let cross = d1.x * d2.y - d1.y * d2.x;
                if cross.abs() < 1e-9 {
                    continue;
                }
                // a + t d1 = q + s d2.
                let w = q - a;
                let t = (w.x * d2.y - w.y * d2.x) / cross;
                let s = (w.x * d1.y - w.y * d1.x) / cross;
                if t < 1.0 - 1e-9 || s > 1e-9 {
                    continue;
                }
                let x = Point::new(a.x + t * d1.x, a.y + t * d1.y);
                let old: Vec<Point> = out[i - 1..=j + 1].iter().map(|v| v.1).collect();
                let old_len: f64 = old.windows(2).map(|s| s[0].dist(s[1])).sum();
                let new = [a, x, b];
                if a.dist(x) + x.dist(b) - old_len > slack * (j - i) as f64 {
                    continue;
                }
                let keeps = gains[out[i - 1].0 + 1..=out[j + 1].0].iter().all(|g| {
                    g.iter().all(|&k| {
                        let c = self.center(self.px_of(k));
                        !near(c, &old) || near(c, &new)
                    })
                });
                if keeps && self.seg_free(known, a, x) && self.seg_free(known, x, b) {
                    let last = out[j].0;
                    out.splice(i..=j, [(last, x)]);
                    replaced = true;
                    break;
                }
            }
            if !replaced {
                i += 1;
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Extension, ExtensionOptions};
    use crate::geometry::Point;
    use crate::grid::GridMap;
    use crate::planner::{KnownMap, Scan};

    /// The transfers of a pass (ways that share first parts, as a search tree's do, each
    /// with gains at its last point only) merge to the same cuts with the memo as without,
    /// on a partly seen map with walls; the memo is dropped now and then, as a new search
    /// drops it.
    #[test]
    fn merge_transfer_is_merge() {
        let art = "\
################
#..............#
#.#..#..#..#...#
#..............#
#...#..#..#..#.#
#..............#
#.#..#..#..#...#
#..............#
#...#..#..#..#.#
#..............#
################";
        let map = GridMap::from_ascii_scaled(art, 4, 0.05).unwrap();
        let frame = *map.frame();
        let mut known = KnownMap::new(&frame);
        known.integrate(&Scan::new(&map, Point::new(0.3, 0.3), 1.6));
        let mut ext = Extension::new(ExtensionOptions::default(), frame, 0.06, 0.06);
        let mut rng = crate::rng::SplitMix64::new(0x6d65_7267);
        let (w, h) = (frame.width as i64, frame.height as i64);
        let centre = |p: (i64, i64)| Point::new(p.0 as f64 + 0.5, (h - p.1) as f64 - 0.5);
        let mut ways: Vec<Vec<(i64, i64)>> = Vec::new();
        let mut taken = 0;
        for round in 0..3000 {
            if round % 50 == 0 {
                ext.merge_memo.clear();
                ways.clear();
            }
            // A prefix of an earlier way (the shared part), then a random walk.
            let mut way: Vec<(i64, i64)> = match ways.len() {
                0 => vec![(6, 6)],
                n => {
                    let base = &ways[(rng.range(0.0, n as f64) as usize).min(n - 1)];
                    let keep = 1 + (rng.range(0.0, base.len() as f64) as usize).min(base.len() - 1);
                    base[..keep].to_vec()
                }
            };
            let steps = rng.range(1.0, 300.0) as usize;
            // Away from the earlier way at once (most often), or straight on.
            let mut dir = (
                rng.range(-1.0, 2.0).floor() as i64,
                rng.range(-1.0, 2.0).floor() as i64,
            );
            for _ in 0..steps {
                if rng.range(0.0, 1.0) < 0.15 {
                    dir = (
                        rng.range(-1.0, 2.0).floor() as i64,
                        rng.range(-1.0, 2.0).floor() as i64,
                    );
                }
                let last = *way.last().unwrap();
                let next = (last.0 + dir.0, last.1 + dir.1);
                if next != last && next.0 >= 0 && next.1 >= 0 && next.0 < w && next.1 < h {
                    way.push(next);
                }
            }
            if way.len() < 2 {
                continue;
            }
            let pts: Vec<Point> = way.iter().map(|&p| centre(p)).collect();
            let mut gains = vec![Vec::new(); pts.len()];
            let last = *way.last().unwrap();
            for (dc, dr) in [(0, 0), (1, 0), (0, 1), (-1, -1)] {
                let q = (last.0 + dc, last.1 + dr);
                if let Some(i) = ext.idx(q) {
                    gains[pts.len() - 1].push(i);
                }
            }
            let want = ext.merge(&known, &pts, &gains);
            let got = ext.merge_transfer(&known, &pts, &gains);
            assert_eq!(got, want, "round {round}");
            taken += usize::from(ext.merge_memo.len() > 1);
            ways.push(way);
        }
        assert!(taken > 1000, "the memo was hardly there: {taken}");
    }
}
