//! The sweep estimate and its targets: recording executed motions, the pixels a polyline
//! would gain, owed pixels, counting the targets around a position (a per-search window of
//! prefix sums or whole words at a time), claiming them, and the final clean-up's
//! "gains nothing here" memo.

use super::{Extension, Px, Wanted};
use crate::geometry::{point_segment_dist2, Point};
use crate::planner::KnownMap;

/// Blocks of the known-free map [`Extension::refresh_no_gain`] compares at a time.
const STRETCH: usize = 64;

/// Target counts of the pixels around a bounded search's start, per window row as prefix sums
/// (`pre[row * (w + 1) + c]` = targets in columns `c0..c0 + c`). Built once per search, it
/// answers each settled position's gain with one subtraction per disk row.
#[derive(Default)]
pub(super) struct Window {
    c0: i64,
    r0: i64,
    w: i64,
    h: i64,
    pre: Vec<u32>,
}

impl Extension {
    /// Records an executed straight motion (world points) as swept.
    pub(crate) fn record(&mut self, a: Point, b: Point) {
        let f = self.frame;
        crate::raster::stamp_capsule(
            &mut self.swept,
            &f,
            f.world_to_grid_snapped(a),
            f.world_to_grid_snapped(b),
            self.rt,
            &mut |_| {},
        );
    }

    /// The targets (known free, not swept) that driving the grid polyline `pts` would sweep,
    /// per point: entry `m` holds those first swept by the segment ending at `pts[m]` (entry 0
    /// is empty).
    pub(super) fn polyline_gains(&mut self, known: &KnownMap, pts: &[Point]) -> Vec<Vec<usize>> {
        let f = self.frame;
        let free = known.known_free();
        let mut stamped = Vec::new();
        let mut gains = vec![Vec::new()];
        for s in pts.windows(2) {
            let start = stamped.len();
            crate::raster::stamp_capsule(&mut self.scratch, &f, s[0], s[1], self.rt, &mut |i| {
                stamped.push(i);
            });
            gains.push(
                stamped[start..]
                    .iter()
                    .copied()
                    .filter(|&i| free.contains(i) && !self.swept.contains(i))
                    .collect(),
            );
        }
        for &i in &stamped {
            self.scratch.set(i, false);
        }
        gains
    }

    /// Driving `alt` instead of the host's transfer `host` (both from world point `from`):
    /// the targets the host's way would sweep and `alt` does not become *owed* — the final
    /// clean-up fetches them even where they are specks below its thresholds, so that a
    /// shorter transfer never sweeps less than the host would. Returns how many were added.
    pub(crate) fn owe_skipped(
        &mut self,
        known: &KnownMap,
        from: Point,
        host: &[Point],
        alt: &[Point],
    ) -> usize {
        let f = self.frame;
        let grid = |pts: &[Point]| -> Vec<Point> {
            std::iter::once(from)
                .chain(pts.iter().copied())
                .map(|p| f.world_to_grid_snapped(p))
                .collect()
        };
        let gains = self.polyline_gains(known, &grid(host));
        let alt = grid(alt);
        let rt2 = self.rt * self.rt;
        let mut n = 0;
        for &i in gains.iter().flatten() {
            let c = self.center(self.px_of(i));
            if !alt
                .windows(2)
                .any(|s| point_segment_dist2(c, s[0], s[1]) <= rt2)
            {
                self.owed.insert(i);
                n += 1;
            }
        }
        self.any_owed |= n > 0;
        n
    }

    /// Does position `p` sweep an owed pixel that is still unswept?
    pub(super) fn sweeps_owed(&self, p: Px) -> bool {
        self.any_owed
            && self.tool.iter().any(|&(dc, dr)| {
                self.idx((p.0 + dc, p.1 + dr))
                    .is_some_and(|i| self.owed.contains(i) && !self.swept.contains(i))
            })
    }

    /// Is pixel `q` a target?
    fn is_target(&self, known: &KnownMap, q: Px, wanted: Wanted) -> bool {
        let Some(i) = self.idx(q) else { return false };
        known.known_free().contains(i)
            && !self.swept.contains(i)
            && wanted.is_none_or(|w| w(self.world(self.center(q))))
    }

    /// Number of targets within the tool radius of position `p` (stops at `cap`).
    pub(super) fn gain(&self, known: &KnownMap, p: Px, wanted: Wanted, cap: usize) -> usize {
        if self.win_on {
            if let Some(n) = self.window_count(p, cap) {
                return n;
            }
        }
        self.count_targets(known, p, wanted, cap, &self.tool_rows)
    }

    /// Fills [`Self::win`] with the targets within `rad` pixels (square) of `c`.
    pub(super) fn build_window(&mut self, known: &KnownMap, c: Px, rad: i64, wanted: Wanted) {
        let f = self.frame;
        let (w_img, h_img) = (f.width as i64, f.height as i64);
        let (c0, c1) = ((c.0 - rad).max(0), (c.0 + rad).min(w_img - 1));
        let (r0, r1) = ((c.1 - rad).max(0), (c.1 + rad).min(h_img - 1));
        if c0 > c1 || r0 > r1 {
            self.win_on = false;
            return;
        }
        let (w, h) = (c1 - c0 + 1, r1 - r0 + 1);
        let mut pre = std::mem::take(&mut self.win.pre);
        pre.clear();
        pre.resize((h * (w + 1)) as usize, 0);
        let free = known.known_free().as_slice();
        let swept = self.swept.as_slice();
        for r in 0..h {
            let row = r0 + r;
            let base = row as usize * f.width;
            let line = &mut pre[(r * (w + 1)) as usize..((r + 1) * (w + 1)) as usize];
            crate::bits::for_each_set(
                base + c0 as usize,
                base + c1 as usize + 1,
                |k| free[k] & !swept[k],
                |i| {
                    let col = (i - base) as i64;
                    if wanted.is_none_or(|wf| wf(self.world(self.center((col, row))))) {
                        line[(col - c0 + 1) as usize] = 1;
                    }
                    true
                },
            );
            for k in 1..line.len() {
                line[k] += line[k - 1];
            }
        }
        self.win = Window { c0, r0, w, h, pre };
        self.win_on = true;
    }

    /// [`Self::count_targets`] over the tool disk from the window; `None` when the disk leaves it.
    fn window_count(&self, p: Px, cap: usize) -> Option<usize> {
        let f = self.frame;
        let (w_img, h_img) = (f.width as i64, f.height as i64);
        let win = &self.win;
        let cap = cap.max(1);
        let rows = &self.tool_rows;
        let reach = rows.len() as i64 - 1;
        let mut n = 0;
        for dr in -reach..=reach {
            let row = p.1 + dr;
            let hw = rows[dr.unsigned_abs() as usize];
            if hw < 0 || row < 0 || row >= h_img {
                continue;
            }
            let (lo, hi) = ((p.0 - hw).max(0), (p.0 + hw).min(w_img - 1));
            if lo > hi {
                continue;
            }
            if row < win.r0 || row >= win.r0 + win.h || lo < win.c0 || hi >= win.c0 + win.w {
                return None;
            }
            let base = ((row - win.r0) * (win.w + 1)) as usize;
            n += (win.pre[base + (hi - win.c0 + 1) as usize]
                - win.pre[base + (lo - win.c0) as usize]) as usize;
            if n >= cap {
                return Some(cap);
            }
        }
        Some(n)
    }

    /// Number of targets in the disk `rows` (row half-widths) around `p` (stops at `cap`).
    pub(super) fn count_targets(
        &self,
        known: &KnownMap,
        p: Px,
        wanted: Wanted,
        cap: usize,
        rows: &[i64],
    ) -> usize {
        let f = self.frame;
        let (w, h) = (f.width as i64, f.height as i64);
        let free = known.known_free().as_slice();
        let swept = self.swept.as_slice();
        let reach = rows.len() as i64 - 1;
        let mut n = 0;
        for dr in -reach..=reach {
            let row = p.1 + dr;
            let hw = rows[dr.unsigned_abs() as usize];
            if hw < 0 || row < 0 || row >= h {
                continue;
            }
            let (lo, hi) = ((p.0 - hw).max(0), (p.0 + hw).min(w - 1));
            if lo > hi {
                continue;
            }
            let base = row as usize * f.width;
            let Some(wanted) = wanted else {
                // Every target counts: whole words at a time.
                n += count_range(free, swept, base + lo as usize, base + hi as usize + 1);
                if n >= cap.max(1) {
                    return cap.max(1);
                }
                continue;
            };
            let go_on = crate::bits::for_each_set(
                base + lo as usize,
                base + hi as usize + 1,
                |k| free[k] & !swept[k],
                |i| {
                    if wanted(self.world(self.center(((i - base) as i64, row)))) {
                        n += 1;
                    }
                    n < cap
                },
            );
            if !go_on {
                break;
            }
        }
        n
    }

    /// The known free pixels: the count [`Self::refresh_no_gain`] keeps once the final
    /// clean-up began, else counted now.
    pub(super) fn known_free_count(&self, known: &KnownMap) -> usize {
        if self.no_gain_free.len() == known.known_free().as_slice().len() {
            self.free_count
        } else {
            known.known_free().count_ones(..)
        }
    }

    /// Drops the [`Self::no_gain`] memo around every pixel that became known free since the
    /// last call (a new target there may make positions within the strip disk gain).
    pub(super) fn refresh_no_gain(&mut self, known: &KnownMap) {
        let free = known.known_free().as_slice();
        if self.no_gain_free.len() != free.len() {
            self.no_gain.clear();
            self.no_gain_free = free.to_vec();
            self.free_count = known.known_free().count_ones(..);
            self.fill_memos(known);
            return;
        }
        let f = self.frame;
        let (w, h) = (f.width as i64, f.height as i64);
        let reach = self.strip_rows.len() as i64 - 1;
        let bits = crate::bits::BLOCK_BITS;
        // The memo is dropped in the square of side `2 reach + 1` around every new pixel: per
        // image row, the new pixels' columns widened by `reach` and merged into runs, each run
        // then cleared in the rows within `reach` (one range per run and row, not per pixel).
        let mut runs: Vec<(i64, i64, i64)> = Vec::new();
        // Most of the map did not change since the last call: compare a stretch of blocks at
        // a time (one slice comparison) and look into the stretches that differ only.
        let changed: Vec<usize> = (0..free.len())
            .step_by(STRETCH)
            .filter(|&s| {
                let e = (s + STRETCH).min(free.len());
                free[s..e] != self.no_gain_free[s..e]
            })
            .collect();
        for b in changed
            .into_iter()
            .flat_map(|s| s..(s + STRETCH).min(free.len()))
        {
            let new = free[b] & !self.no_gain_free[b];
            self.no_gain_free[b] = free[b];
            if new == 0 {
                continue;
            }
            self.free_count += new.count_ones() as usize;
            let mut todo = new;
            while todo != 0 {
                let i = b * bits + todo.trailing_zeros() as usize;
                todo &= todo - 1;
                let (c, r) = f.col_row(i);
                let (c, r) = (c as i64, r as i64);
                let (c0, c1) = ((c - reach).max(0), (c + reach).min(w - 1));
                // Pixels come in index order: a run grows while it stays on its row and overlaps.
                match runs.last_mut() {
                    Some(last) if last.0 == r && c0 <= last.2 + 1 => last.2 = last.2.max(c1),
                    _ => runs.push((r, c0, c1)),
                }
            }
        }
        for (r, c0, c1) in runs {
            for row in (r - reach).max(0)..=(r + reach).min(h - 1) {
                let base = row as usize * f.width;
                self.no_gain
                    .remove_range(base + c0 as usize..base + c1 as usize + 1);
            }
        }
    }

    /// Marks the targets around `p` swept; returns their indices.
    pub(super) fn claim(&mut self, known: &KnownMap, p: Px, wanted: Wanted) -> Vec<usize> {
        let mut out = Vec::new();
        for k in 0..self.tool.len() {
            let (dc, dr) = self.tool[k];
            let q = (p.0 + dc, p.1 + dr);
            if self.is_target(known, q, wanted) {
                let i = self.idx(q).expect("targets are in the image");
                self.swept.insert(i);
                out.push(i);
            }
        }
        out
    }
}

/// Number of bits `a..b` set in `free` and clear in `swept`.
fn count_range(free: &[usize], swept: &[usize], a: usize, b: usize) -> usize {
    use crate::bits::{range_mask, BLOCK_BITS};
    let mut n = 0;
    let mut blk = a / BLOCK_BITS;
    while blk * BLOCK_BITS < b {
        let start = blk * BLOCK_BITS;
        let mask = range_mask(a.max(start) - start, b.min(start + BLOCK_BITS) - start);
        // Mostly none (the target is built without a popcount instruction): test first.
        let bits = free[blk] & !swept[blk] & mask;
        if bits != 0 {
            n += bits.count_ones() as usize;
        }
        blk += 1;
    }
    n
}
