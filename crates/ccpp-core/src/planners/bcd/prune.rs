//! Coverage-budgeted turn pruning of the finished plan (module docs of [`super`], step 5).
//!
//! The plan's polyline sweeps a set of accessible pixels; every pixel keeps the number of the
//! plan's segments whose tool capsule covers it (the metric's own capsule test). The vertices
//! strictly between `u` and a later vertex `w` (at most [`MAX_SPAN`] of them: a lone corner, a
//! short detour into a sliver cell and back) can be dropped when the straight move `u -> w` is
//! free on the true map; dropping them saves the turns they and `u`, `w` make and shortens the
//! path, and loses the accessible pixels that only the removed segments sweep and `u -> w`
//! does not. Spans are dropped greedily, fewest lost pixels per unit of saved cost first (the
//! path saved plus [`TURN_WEIGHT`] turn costs per turn saved), while the
//! pixels the plan still sweeps stay at least `floor` of the accessible floor. A span's loss is
//! recomputed when it is taken (lazy greedy), so the budget is kept exactly.
//!
//! Then a run of two to [`MERGE_RUN`] consecutive turns `v1 .. vk` becomes one where the move
//! into `v1` and the move out of `vk` meet, extended beyond the run or cut short before it
//! (corner completion: a transfer bending around an obstacle in two steps bends once, on the
//! side away from the obstacle; a step of three turns whose moves two at a time are parallel
//! does too; a bump out of a straight run, such as a join overshooting a lane end, is cut off),
//! within one turn cost per turn saved of the run's ends, when both new moves are free, the
//! path grows by at most one turn's cost per turn saved and the floor still holds (shorter
//! runs are tried first); the spans are dropped once more after that. On the 14 shared maps
//! (r = 0.15 m) bcd's mean turns went from 1162 (two turns, beyond only) to 1149 with runs of
//! up to four and to 1124 with bumps cut too (`stage_willow_full` 6950 to 6827 to 6652,
//! `rmf_office_scan` 1248 to 1232 to 1165), its mean path ratio from 1.1354 to 1.1359 to
//! 1.1344; no map dearer on length plus `turn_cost_m` per turn, no map with more turns. (Corners
//! up to twice as far gave 1118 turns, but `nav2_depot` 599 turns instead of 571 and a dearer
//! plan.)
//!
//! A U-turn of three or four turns between two antiparallel moves (the join of two lanes bent
//! round a speck or a bump of the wall, where no straight move across the turns is free) is a
//! candidate of the same ranking: the two moves cut short or extended along their lines to
//! the depth of one of the run's vertices each and joined by one straight move (two turns),
//! when the three moves are free and the path grows by at most one turn cost per turn saved
//! ([`Pruner::uturn_from`]). On the 14 shared maps (r = 0.15 m) bcd's mean turns went from
//! 1123.5 to 1114.6 and its mean path ratio from 1.1344 to 1.1349; 11 maps cheaper on length
//! plus `turn_cost_m` per turn, 3 dearer by less than a metre (`aws_bookstore`, `teb_maze`,
//! `teb_corridor`), for about 18 % more CPU time of the bcd bench.
//!
//! Cost: capsules are kept as row runs ([`crate::raster::capsule_runs`], the pixels the metric
//! stamps), once per move of the plan and per candidate move (with its free-move check); a
//! span's loss is counted over those runs; and a start's best span is evaluated again only when
//! its chain changed (its version) or a count under its moves changed (tracked per block of
//! [`BLOCK`] x [`BLOCK`] pixels), since otherwise the evaluation would give the same span.

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::ops::Sub;

use fixedbitset::FixedBitSet;

use super::finish::is_turn;
use super::finish::Item;
use super::lattice::Ctx;
use crate::geometry::{point_segment_dist2, Point};

/// Heading change at `b` between the moves `a -> b` and `b -> c` (as the simulator counts a
/// turn).
fn turn(a: Point, b: Point, c: Point) -> bool {
    let (d0, d1) = (b.sub(a), c.sub(b));
    is_turn(d0.y.atan2(d0.x), d1.y.atan2(d1.x))
}

/// Weight of a saved turn, in turn costs (`turn_px`), against the path a span saves when
/// spans are ranked. Measured on the 14 shared maps (r = 0.15 m): 1 (the plan's own cost)
/// lowers the mean path ratio less and raises the turns more than 3; 0 (turns only, the
/// ranking before) leaves the path a span saves out.
const TURN_WEIGHT: u64 = 3;

/// A length in pixels as a whole number of 1/16 pixels (rounded): ranking keys are integers
/// built from the plan's grid points, so a plan does not depend on where the map lies in the
/// world (a point converted from far-out world coordinates carries noise far below 1/16
/// pixel).
fn sixteenths(d: f64) -> u64 {
    (d * 16.0).round().clamp(0.0, 1e15) as u64
}

/// Most vertices one drop removes.
const MAX_SPAN: usize = 4;

/// Most turns in a row that corner completion replaces by one (module docs).
const MERGE_RUN: usize = 4;

/// Vertices of a pass over the whole plan between two looks at the stop flag.
const STOP_EVERY: usize = 256;
const NONE: usize = usize::MAX;

struct Pruner<'a, 'b> {
    ctx: &'a Ctx<'b>,
    pts: Vec<Point>,
    prev: Vec<usize>,
    next: Vec<usize>,
    alive: Vec<bool>,
    version: Vec<u32>,
    /// Segments of the plan covering each pixel, plus [`OFF_FLOOR`] for the pixels off the
    /// accessible floor once touched (so a count equals a span's count only on the floor).
    cnt: Vec<u32>,
    /// Scratch: segments of the span under evaluation covering each pixel (zero between
    /// evaluations).
    tmp: Vec<u32>,
    /// The pixels of the move from each vertex to the next as row runs, once computed (cleared
    /// when the move changes).
    seg: Vec<Vec<Run>>,
    /// The blocks ([`BLOCK`] pixels square) `[row0, row1, col0, col1]` (inclusive) holding
    /// each cached `seg`.
    seg_box: Vec<[u32; 4]>,
    /// Blocks per block row.
    blocks_w: usize,
    /// The drop during which each block's counts last changed (see `epoch`).
    changed: Vec<u32>,
    /// Drops so far in this round of [`Pruner::drop_spans`] (plus one per round).
    epoch: u32,
    /// Each vertex's last evaluated span: its `version`, the `epoch` it saw, the blocks it read
    /// and the result (valid while its version holds and no block of it changed).
    memo: Vec<Option<Memo>>,
    /// Each vertex's candidate moves evaluated so far (their points may have changed since).
    chords: Vec<Vec<Chord>>,
    acc: &'a FixedBitSet,
    covered: usize,
    rt: f64,
    /// Cost of one turn in 1/16 pixels of path ([`sixteenths`]): a span's saving is its
    /// length saved plus [`TURN_WEIGHT`] times this per turn saved.
    turn_16: u64,
}

/// A candidate move from a vertex to a later one `w`: its points, its pixels, and whether it is
/// free on the map once asked.
struct Chord {
    w: usize,
    p0: Point,
    p1: Point,
    runs: Vec<Run>,
    free: Option<bool>,
}

/// The pixels `base..base + len` (one row's run of a capsule).
#[derive(Clone, Copy)]
struct Run {
    base: u32,
    len: u32,
}

impl Run {
    fn pixels(self) -> std::ops::Range<usize> {
        let b = self.base as usize;
        b..b + self.len as usize
    }
}

/// Added to the count of a pixel off the accessible floor (more than any count of segments).
const OFF_FLOOR: u32 = 1 << 31;

/// Side of the square blocks of pixels whose count changes are tracked.
const BLOCK: usize = 16;

/// A remembered [`Pruner::best_from`] result (see `Pruner::memo`).
#[derive(Clone, Copy)]
struct Memo {
    version: u32,
    epoch: u32,
    bbox: [u32; 4],
    best: Option<Span>,
}

/// A span to drop: the vertices strictly between `u` and `w`.
#[derive(Clone, Copy)]
struct Span {
    key: u64,
    w: usize,
    lost: usize,
    /// A U-turn completion instead of a straight move: the new points of the first two
    /// vertices after `u` (the others up to `w` dropped).
    to: Option<(Point, Point)>,
}

impl Pruner<'_, '_> {
    /// Pixels of the capsule `a`-`b` as row runs (each pixel once), appended to `out`.
    fn capsule(&self, a: Point, b: Point, out: &mut Vec<Run>) {
        let w = self.ctx.frame.width;
        crate::raster::capsule_runs(&self.ctx.frame, a, b, self.rt, |row, c0, c1| {
            out.push(Run {
                base: (row * w + c0) as u32,
                len: (c1 - c0 + 1) as u32,
            });
        });
    }

    /// The index in `chords[u]` of the move from `u` to `w` at their current points (added
    /// when new).
    fn chord(&mut self, u: usize, w: usize) -> usize {
        let (p0, p1) = (self.pts[u], self.pts[w]);
        if let Some(j) = self.chords[u]
            .iter()
            .position(|c| c.w == w && c.p0 == p0 && c.p1 == p1)
        {
            return j;
        }
        // Forget the moves to dropped vertices or from or to moved points.
        let (alive, pts) = (&self.alive, &self.pts);
        self.chords[u].retain(|c| alive[c.w] && c.p0 == p0 && c.p1 == pts[c.w]);
        let mut runs = Vec::new();
        self.capsule(p0, p1, &mut runs);
        self.chords[u].push(Chord {
            w,
            p0,
            p1,
            runs,
            free: None,
        });
        self.chords[u].len() - 1
    }

    /// Is the move `chords[u][j]` free on the true map (asked once)?
    fn chord_free(&mut self, u: usize, j: usize) -> bool {
        let c = &self.chords[u][j];
        if let Some(f) = c.free {
            return f;
        }
        let f = self.ctx.free(c.p0, c.p1);
        self.chords[u][j].free = Some(f);
        f
    }

    fn turn_at(&self, a: usize, b: usize, c: usize) -> i32 {
        if a == NONE || c == NONE {
            return 0;
        }
        i32::from(turn(self.pts[a], self.pts[b], self.pts[c]))
    }

    fn centre(&self, i: usize) -> Point {
        let w = self.ctx.frame.width;
        let h = self.ctx.frame.height as f64;
        Point::new((i % w) as f64 + 0.5, h - (i / w) as f64 - 0.5)
    }

    /// The cheapest span starting at `u` (lost pixels per pixel of saved cost: path plus
    /// [`TURN_WEIGHT`] `turn_px` per turn), if any saves a turn.
    ///
    /// The result depends on the chain around `u` (its `version` changes with it) and on the
    /// counts of the pixels of its segments: it is evaluated again only when one of those
    /// changed since the last evaluation.
    fn best_from(&mut self, u: usize) -> Option<Span> {
        if !self.alive[u] {
            return None;
        }
        if let Some(m) = self.memo[u] {
            if m.version == self.version[u] && !self.changed_since(m.bbox, m.epoch) {
                return m.best;
            }
        }
        let (best, bbox) = self.eval_from(u);
        self.memo[u] = Some(Memo {
            version: self.version[u],
            epoch: self.epoch,
            bbox,
            best,
        });
        best
    }

    /// Has any block of `bbox` changed after `epoch`?
    fn changed_since(&self, bbox: [u32; 4], epoch: u32) -> bool {
        let [r0, r1, c0, c1] = bbox.map(|x| x as usize);
        (r0..=r1).any(|r| {
            self.changed[r * self.blocks_w + c0..=r * self.blocks_w + c1]
                .iter()
                .any(|&e| e > epoch)
        })
    }

    /// [`Pruner::best_from`] evaluated, with the blocks of the pixels it read.
    fn eval_from(&mut self, u: usize) -> (Option<Span>, [u32; 4]) {
        let mut bbox = [u32::MAX, 0, u32::MAX, 0];
        let pu = self.prev[u];
        let mut only = 0usize;
        let mut best: Option<Span> = None;
        // Turns of the chain from u: at u (with pu), and inside.
        let mut before = 0;
        // Length of the chain from u to the span's end, in 1/16 pixels (each move rounded).
        let mut span_len = 0u64;
        let mut v = u;
        let mut a = self.next[u];
        if a == NONE {
            return (None, [0, 0, 0, 0]);
        }
        for k in 0..=MAX_SPAN {
            // Add segment v -> a.
            let seg = self.segment(v);
            for r in &seg {
                let px = r.pixels();
                for (t, &c) in self.tmp[px.clone()].iter_mut().zip(&self.cnt[px]) {
                    *t += 1;
                    only += usize::from(*t == c);
                }
            }

            self.seg[v] = seg;
            let sb = self.seg_box[v];
            bbox = [
                bbox[0].min(sb[0]),
                bbox[1].max(sb[1]),
                bbox[2].min(sb[2]),
                bbox[3].max(sb[3]),
            ];
            before += self.turn_at(self.prev[v], v, a);
            span_len += sixteenths(self.pts[v].dist(self.pts[a]));
            let w = a;
            if k >= 1 {
                let nw = self.next[w];
                let b = before + self.turn_at(v, w, nw);
                let after = self.turn_at(pu, u, w) + self.turn_at(u, w, nw);
                let saved = b - after;
                if saved > 0 {
                    // The pixels only the span sweeps, less those the new move sweeps.
                    let j = self.chord(u, w);
                    let mut kept = 0;
                    for r in &self.chords[u][j].runs {
                        let px = r.pixels();
                        for (&t, &c) in self.tmp[px.clone()].iter().zip(&self.cnt[px]) {
                            kept += usize::from(t == c) & usize::from(t != 0);
                        }
                    }
                    let lost = only - kept;
                    // Lost pixels per pixel of cost saved (path, and TURN_WEIGHT turn costs a
                    // turn), all integers (1/16 pixels; 2^20 = 65536 per pixel).
                    let gain = saved as u64 * TURN_WEIGHT * self.turn_16
                        + span_len.saturating_sub(sixteenths(self.pts[u].dist(self.pts[w])));
                    let key = (lost as u64).saturating_mul(1 << 20) / gain.max(1);
                    // The shorter span on ties.
                    if best.is_none_or(|s| key < s.key) && self.chord_free(u, j) {
                        best = Some(Span {
                            key,
                            w,
                            lost,
                            to: None,
                        });
                    }
                }
            }
            v = a;
            a = self.next[a];
            // No longer span beats a span that loses nothing (ties go to the shorter).
            if a == NONE || best.is_some_and(|s| s.key == 0) {
                break;
            }
        }
        // Clear the scratch counts over the segments just added (u up to v, exclusive).
        let mut x = u;
        while x != v {
            for r in &self.seg[x] {
                self.tmp[r.pixels()].fill(0);
            }
            x = self.next[x];
        }
        if bbox[0] > bbox[1] {
            // No pixel read.
            bbox = [0, 0, 0, 0];
        }
        // A U-turn completion where no span loses nothing (its pixels are those of the
        // spans' moves, in `bbox` already).
        if best.is_none_or(|s| s.key > 0) {
            if let Some(c) = self.uturn_from(u, best.map(|s| s.key)) {
                best = Some(Span {
                    key: c.key,
                    w: c.w,
                    lost: c.lost,
                    to: Some((c.x, c.y)),
                });
            }
        }
        (best, bbox)
    }

    /// The pixels of the move from `v` to the next vertex (taken out of the cache: put back
    /// into `self.seg[v]`).
    fn segment(&mut self, v: usize) -> Vec<Run> {
        let mut seg = std::mem::take(&mut self.seg[v]);
        if seg.is_empty() {
            let (p, q) = (self.pts[v], self.pts[self.next[v]]);
            self.capsule(p, q, &mut seg);
            self.seg_box[v] = self.blocks_of(&seg);
        }
        seg
    }

    /// The blocks `[row0, row1, col0, col1]` holding the pixels of `runs` (all zero when
    /// there are none).
    fn blocks_of(&self, runs: &[Run]) -> [u32; 4] {
        let w = self.ctx.frame.width;
        let mut b = [u32::MAX, 0, u32::MAX, 0];
        for r in runs {
            let i = r.base as usize;
            let (row, c0) = (i / w, i % w);
            let c1 = c0 + r.len as usize - 1;
            let (br, b0, b1) = (
                (row / BLOCK) as u32,
                (c0 / BLOCK) as u32,
                (c1 / BLOCK) as u32,
            );
            b = [b[0].min(br), b[1].max(br), b[2].min(b0), b[3].max(b1)];
        }
        if b[0] > b[1] {
            [0, 0, 0, 0]
        } else {
            b
        }
    }

    /// Adds (`up`) or removes the move `a -> b` from the counts.
    fn add(&mut self, a: Point, b: Point, up: bool, buf: &mut Vec<Run>) {
        buf.clear();
        self.capsule(a, b, buf);
        self.apply(buf, up);
    }

    /// Adds (`up`) or removes a move with the pixels `runs` from the counts.
    fn apply(&mut self, runs: &[Run], up: bool) {
        let w = self.ctx.frame.width;
        for r in runs {
            let i = r.base as usize;
            let (row, c0) = (i / w, i % w);
            let c1 = c0 + r.len as usize - 1;
            let at = row / BLOCK * self.blocks_w;
            self.changed[at + c0 / BLOCK..=at + c1 / BLOCK].fill(self.epoch);
        }
        for i in runs.iter().flat_map(|r| r.pixels()) {
            if up {
                if self.cnt[i] == 0 {
                    if self.acc.contains(i) {
                        self.covered += 1;
                    } else {
                        self.cnt[i] = OFF_FLOOR;
                    }
                }
                self.cnt[i] += 1;
            } else {
                // Off the floor the count stays at least OFF_FLOOR.
                self.cnt[i] -= 1;
                if self.cnt[i] == 0 {
                    self.covered -= 1;
                }
            }
        }
    }
}

/// Corner completion: the point where the rays from `u` through `v1` and from `w` through `v2`
/// meet (within `reach` of both `v1` and `v2`), if any: beyond the turns (a bend completed on
/// its outer side) or before them (a bump cut off).
fn corner(u: Point, v1: Point, v2: Point, w: Point, reach: f64) -> Option<Point> {
    let d1 = v1.sub(u);
    let d2 = v2.sub(w);
    let den = d1.x * d2.y - d1.y * d2.x;
    if den.abs() < 1e-9 * (d1.dot(d1) * d2.dot(d2)).sqrt().max(1e-12) {
        return None;
    }
    // u + s d1 = w + t d2
    let e = w.sub(u);
    let s = (e.x * d2.y - e.y * d2.x) / den;
    let t = (e.x * d1.y - e.y * d1.x) / den;
    if !(s > 0.0 && t > 0.0 && s.is_finite() && t.is_finite()) {
        return None;
    }
    let x = Point::new(u.x + s * d1.x, u.y + s * d1.y);
    (x.dist(v1) <= reach && x.dist(v2) <= reach).then_some(x)
}

impl Pruner<'_, '_> {
    /// The greedy span drops of the module docs while the plan sweeps at least `need` pixels.
    fn drop_spans(&mut self, need: usize, starts: impl Iterator<Item = usize>) {
        // A new round: forget the evaluations of the last one (points may have moved).
        self.memo.fill(None);
        self.epoch += 1;
        // (key, start vertex, its version)
        let mut heap: BinaryHeap<Reverse<(u64, usize, u32)>> = BinaryHeap::new();
        for (i, u) in starts.enumerate() {
            if i.is_multiple_of(STOP_EVERY) && self.ctx.stopped() {
                return;
            }
            if let Some(s) = self.best_from(u) {
                heap.push(Reverse((s.key, u, self.version[u])));
            }
        }
        while let Some(Reverse((k, u, ver))) = heap.pop() {
            // (a plan given up is dropped whole: leave the rest)
            if self.ctx.stopped() {
                return;
            }
            if !self.alive[u] || ver != self.version[u] {
                continue;
            }
            let Some(s) = self.best_from(u) else {
                continue;
            };
            if s.key > k {
                heap.push(Reverse((s.key, u, ver)));
                continue;
            }
            if s.lost > 0 && self.covered - s.lost < need {
                continue;
            }
            self.epoch += 1;
            let v1 = self.next[u];
            let v2 = if v1 == NONE { NONE } else { self.next[v1] };
            // Drop the vertices strictly between u and w.
            let mut v = u;
            while v != s.w {
                let a = self.next[v];
                let seg = self.segment(v);
                self.apply(&seg, false);
                if v != u {
                    self.alive[v] = false;
                    self.chords[v] = Vec::new();
                }
                v = a;
            }
            if let Some((x, y)) = s.to {
                // U-turn completion: the first two vertices after u move to x and y.
                self.alive[v1] = true;
                self.alive[v2] = true;
                self.pts[v1] = x;
                self.pts[v2] = y;
                self.chords[v1] = Vec::new();
                self.chords[v2] = Vec::new();
                self.next[u] = v1;
                self.prev[v1] = u;
                self.next[v1] = v2;
                self.prev[v2] = v1;
                self.next[v2] = s.w;
                self.prev[s.w] = v2;
                // (their versions move with the starts re-evaluated below)
                for v in [u, v1, v2] {
                    self.seg[v].clear();
                    let seg = self.segment(v);
                    self.apply(&seg, true);
                    self.seg[v] = seg;
                }
            } else {
                let j = self.chord(u, s.w);
                let runs = self.chords[u][j].runs.clone();
                self.apply(&runs, true);
                self.next[u] = s.w;
                self.prev[s.w] = u;
                self.seg_box[u] = self.blocks_of(&runs);
                self.seg[u] = runs;
            }
            // Re-evaluate the spans whose turns or segments changed: those starting up to
            // MAX_SPAN + 1 vertices before u, at u, and at w.
            let mut starts = vec![s.w];
            if s.to.is_some() {
                starts.extend([v1, v2]);
            }
            let mut x = u;
            for _ in 0..=MAX_SPAN + 1 {
                if x == NONE {
                    break;
                }
                starts.push(x);
                x = self.prev[x];
            }
            for x in starts {
                self.version[x] = self.version[x].wrapping_add(1);
                if let Some(s) = self.best_from(x) {
                    heap.push(Reverse((s.key, x, self.version[x])));
                }
            }
        }
    }

    /// Corner completion: a run of two to [`MERGE_RUN`] consecutive turns `v1 .. vk` becomes
    /// one at the point where the moves into `v1` and out of `vk` meet ([`corner`]; within
    /// `k - 1` times `max_extra` of `v1` and of `vk`), when both new moves are free, the path grows by at most
    /// `max_extra` per turn saved and the plan keeps sweeping at least `need` pixels; the
    /// shortest such run from each vertex is taken. Returns the merged vertices.
    fn merge_corners(
        &mut self,
        need: usize,
        max_extra: f64,
        touched: &mut Vec<usize>,
        buf: &mut Vec<Run>,
    ) -> Vec<usize> {
        let rt2 = self.rt * self.rt;
        let mut merged = Vec::new();
        let mut v1 = 0;
        let mut looks = 0usize;
        while v1 != NONE {
            looks += 1;
            if looks.is_multiple_of(STOP_EVERY) && self.ctx.stopped() {
                return merged;
            }
            let u = self.prev[v1];
            if u == NONE || self.next[v1] == NONE {
                v1 = self.next[v1];
                continue;
            }
            // The runs v1..vk of 2 to MERGE_RUN turns, shortest first.
            let mut done = false;
            let mut chain = vec![v1];
            while chain.len() < MERGE_RUN && !done {
                let vk = self.next[chain[chain.len() - 1]];
                if vk == NONE || self.next[vk] == NONE {
                    break;
                }
                chain.push(vk);
                let w = self.next[vk];
                let pts: Vec<Point> = std::iter::once(u)
                    .chain(chain.iter().copied())
                    .chain(std::iter::once(w))
                    .map(|i| self.pts[i])
                    .collect();
                let (pu, p1, pk, pw) = (pts[0], pts[1], pts[pts.len() - 2], pts[pts.len() - 1]);
                let before: i32 = (1..pts.len() - 1)
                    .map(|j| i32::from(turn(pts[j - 1], pts[j], pts[j + 1])))
                    .sum();
                let saves = (chain.len() - 1) as f64;
                let Some(x) = corner(pu, p1, pk, pw, max_extra * saves) else {
                    continue;
                };
                let inner: f64 = pts[1..pts.len() - 1]
                    .windows(2)
                    .map(|w| w[0].dist(w[1]))
                    .sum();
                let extra = p1.dist(x) + x.dist(pk) - inner;
                if before < 2
                    || !turn(pu, x, pw)
                    || extra > max_extra * f64::from(before - 1)
                    || !(self.ctx.free(pu, x) && self.ctx.free(x, pw))
                {
                    continue;
                }
                // Pixels only the old moves sweep and the two new ones do not.
                touched.clear();
                for m in pts.windows(2) {
                    buf.clear();
                    self.capsule(m[0], m[1], buf);
                    for i in buf.iter().flat_map(|r| r.pixels()) {
                        if self.tmp[i] == 0 {
                            touched.push(i);
                        }
                        self.tmp[i] += 1;
                    }
                }
                let lost = touched
                    .iter()
                    .filter(|&&i| {
                        let c = self.centre(i);
                        self.cnt[i] == self.tmp[i]
                            && point_segment_dist2(c, pu, x) > rt2
                            && point_segment_dist2(c, x, pw) > rt2
                    })
                    .count();
                for &i in touched.iter() {
                    self.tmp[i] = 0;
                }
                if lost > 0 && self.covered - lost < need {
                    continue;
                }
                for m in pts.windows(2) {
                    self.add(m[0], m[1], false, buf);
                }
                self.add(pu, x, true, buf);
                self.add(x, pw, true, buf);
                self.pts[v1] = x;
                for &v in &chain[1..] {
                    self.alive[v] = false;
                }
                self.next[v1] = w;
                self.prev[w] = v1;
                self.seg[u].clear();
                self.seg[v1].clear();
                merged.push(v1);
                done = true;
            }
            // Look again from the vertex before (its pair changed), else go on.
            v1 = if done { u } else { self.next[v1] };
        }
        merged
    }
}

/// A pixel only a U-turn's old moves sweep, placed against the two lanes' lines (see
/// [`Pruner::uturn_from`]): its centre, its depth along each line from the lane's far end
/// and its squared distance to the line's part up to that depth.
struct OnlyPx {
    c: Point,
    t1: f64,
    d1: f64,
    t2: f64,
    d2: f64,
}

/// A U-turn completion from a vertex `u` (see [`Pruner::uturn_from`]): the vertex after the
/// run, the new points of the run's first two vertices, the pixels lost, the ranking key (as
/// a span's) and the path added (1/16 pixels, negative when shorter).
struct UTurn {
    w: usize,
    x: Point,
    y: Point,
    lost: usize,
    key: u64,
    extra_16: i64,
}

impl Pruner<'_, '_> {
    /// The best U-turn completion of the run of three or four turns after `u` (between the
    /// move out of `u` and an antiparallel move into the vertex after the run, `w`): the two
    /// moves cut short or extended along their lines to the depth of one of the run's vertices
    /// each and joined by one straight move, all three free, the path longer by at most one
    /// turn cost (`turn_16`) per turn saved; fewest pixels lost per cost saved (the key of
    /// a span, whose saved path may be negative here), then the shortest; only one whose key
    /// is below `bound` (the best span's).
    fn uturn_from(&mut self, u: usize, bound: Option<u64>) -> Option<UTurn> {
        let rt2 = self.rt * self.rt;
        let max_extra = self.turn_16 as f64 / 16.0;
        let v1 = self.next[u];
        if v1 == NONE {
            return None;
        }
        let mut chain = vec![v1];
        // (the completion, and whether it extends the first / the last move)
        let mut cands: Vec<(UTurn, bool, bool)> = Vec::new();
        let mut touched = Vec::new();
        let mut only: Vec<OnlyPx> = Vec::new();
        while chain.len() < MERGE_RUN {
            let vk = self.next[chain[chain.len() - 1]];
            if vk == NONE || self.next[vk] == NONE {
                break;
            }
            chain.push(vk);
            if chain.len() < 3 {
                continue;
            }
            let w = self.next[vk];
            let pts: Vec<Point> = std::iter::once(u)
                .chain(chain.iter().copied())
                .chain(std::iter::once(w))
                .map(|i| self.pts[i])
                .collect();
            let (pu, p1, pk, pw) = (pts[0], pts[1], pts[pts.len() - 2], pts[pts.len() - 1]);
            let (d1, d2) = (p1.sub(pu), pw.sub(pk));
            let (l1, l2) = (d1.dot(d1).sqrt(), d2.dot(d2).sqrt());
            if l1 < 1e-9 || l2 < 1e-9 || d1.dot(d2) > -0.999 * l1 * l2 {
                continue;
            }
            let e = d1.scale(1.0 / l1);
            let f = d2.scale(-1.0 / l2);
            let fe = f.dot(e);
            let depth = |p: Point| p.sub(pu).dot(e);
            let sw = depth(pw);
            let before: i32 = (1..pts.len() - 1)
                .map(|j| i32::from(turn(pts[j - 1], pts[j], pts[j + 1])))
                .sum();
            let old_len: f64 = pts.windows(2).map(|m| m[0].dist(m[1])).sum();
            let depths: Vec<f64> = pts[1..pts.len() - 1].iter().map(|&p| depth(p)).collect();
            let mut counted = false;
            for &sx in &depths {
                for &sy in &depths {
                    let ty = (sy - sw) / fe;
                    if sx < 0.5 || ty < 0.5 {
                        continue;
                    }
                    let x = Point::new(pu.x + sx * e.x, pu.y + sx * e.y);
                    let y = Point::new(pw.x + ty * f.x, pw.y + ty * f.y);
                    if x.dist(y) < 1e-6 {
                        continue;
                    }
                    let after = i32::from(turn(pu, x, y)) + i32::from(turn(x, y, pw));
                    let saved = before - after;
                    if saved < 1 {
                        continue;
                    }
                    let extra = pu.dist(x) + x.dist(y) + y.dist(pw) - old_len;
                    if extra > max_extra * f64::from(saved) {
                        continue;
                    }
                    let gain = (saved as u64 * TURN_WEIGHT * self.turn_16)
                        .saturating_sub(sixteenths(extra.max(0.0)))
                        + sixteenths((-extra).max(0.0));
                    if gain == 0 {
                        continue;
                    }
                    if !counted {
                        // The pixels only the run's moves sweep (tmp: their counts),
                        // of the run's moves (from the cache of `segment`) at
                        // depth `dmin` or more: a pixel shallower than every candidate point
                        // by more than the tool's radius (and a margin) lies within it of
                        // the kept part of a lane, so it is never lost and the lanes' bodies
                        // are left out. Along a row the depth is linear in the column.
                        let dmin =
                            depths.iter().copied().fold(f64::INFINITY, f64::min) - self.rt - 2.0;
                        let w_px = self.ctx.frame.width;
                        let h_px = self.ctx.frame.height as f64;
                        touched.clear();
                        let mut v = u;
                        while v != w {
                            let seg = self.segment(v);
                            for r in &seg {
                                let (b, len) = (r.base as usize, r.len as usize);
                                let (row, c0) = (b / w_px, b % w_px);
                                let yc = h_px - row as f64 - 0.5;
                                let at =
                                    |c: usize| (c as f64 + 0.5 - pu.x) * e.x + (yc - pu.y) * e.y;
                                let (mut lo, mut hi) = (c0, c0 + len - 1);
                                if at(lo) < dmin && at(hi) < dmin {
                                    // Both ends shallow: the whole run is (depth is linear).
                                    continue;
                                }
                                if e.x > 0.0 {
                                    let k = ((dmin - (yc - pu.y) * e.y) / e.x + pu.x - 0.5).ceil();
                                    lo = lo.max(k.max(0.0) as usize);
                                } else if e.x < 0.0 {
                                    let k = ((dmin - (yc - pu.y) * e.y) / e.x + pu.x - 0.5).floor();
                                    hi = hi.min(if k < 0.0 { 0 } else { k as usize });
                                }
                                for c in lo..=hi {
                                    if at(c) < dmin {
                                        continue;
                                    }
                                    let i = row * w_px + c;
                                    if self.tmp[i] == 0 {
                                        touched.push(i);
                                    }
                                    self.tmp[i] += 1;
                                }
                            }
                            self.seg[v] = seg;
                            v = self.next[v];
                        }
                        let (cnt, tmp) = (&self.cnt, &mut self.tmp);
                        touched.retain(|&i| {
                            let only = cnt[i] == tmp[i];
                            tmp[i] = 0;
                            only
                        });
                        only.clear();
                        for &i in &touched {
                            let c = self.centre(i);
                            let (t1, t2) = (c.sub(pu).dot(e), c.sub(pw).dot(f));
                            let (q1, q2) = (c.dist2(pu), c.dist2(pw));
                            only.push(OnlyPx {
                                c,
                                t1,
                                d1: if t1 < 0.0 { q1 } else { q1 - t1 * t1 },
                                t2,
                                d2: if t2 < 0.0 { q2 } else { q2 - t2 * t2 },
                            });
                        }
                        counted = true;
                    }
                    // Per pixel: beside either kept lane part (its depth on the lane's
                    // line and its distance across it, computed once), else near the join.
                    let lost = only
                        .iter()
                        .filter(|o| {
                            let near1 = if o.t1 <= sx { o.d1 } else { o.c.dist2(x) };
                            let near2 = if o.t2 <= ty { o.d2 } else { o.c.dist2(y) };
                            near1 > rt2 && near2 > rt2 && point_segment_dist2(o.c, x, y) > rt2
                        })
                        .count();
                    let key = (lost as u64).saturating_mul(1 << 20) / gain;
                    if bound.is_some_and(|b| key >= b) {
                        continue;
                    }
                    cands.push((
                        UTurn {
                            w,
                            x,
                            y,
                            lost,
                            key,
                            extra_16: (extra * 16.0).round() as i64,
                        },
                        sx > l1 + 1e-9,
                        ty > l2 + 1e-9,
                    ));
                }
            }
        }
        // Cheapest first; the free-move checks (the dear part) only until one passes. A move
        // cut short lies on a move of the plan, free already.
        // (a stable sort: equal keys and lengths keep the order of the depths tried)
        cands.sort_by_key(|c| (c.0.key, c.0.extra_16));
        cands.into_iter().find_map(|(c, ext_x, ext_y)| {
            let pu = self.pts[u];
            let pw = self.pts[c.w];
            ((!ext_x || self.ctx.free(pu, c.x))
                && self.ctx.free(c.x, c.y)
                && (!ext_y || self.ctx.free(c.y, pw)))
            .then_some(c)
        })
    }
}

/// Drops turn vertices of the plan's moves while its estimated effective coverage stays at
/// least `floor` (module docs); corners are completed where that saves a turn for at most
/// `max_extra` (pixels) of path. Returns the moves, whether the plan came short of `floor`
/// already before pruning, and how many accessible pixels the pruned plan sweeps fewer than
/// `floor` of them (0 when it reaches it).
pub(super) fn prune(
    ctx: &Ctx<'_>,
    items: Vec<Item>,
    floor: f64,
    max_extra: f64,
) -> (Vec<Item>, bool, usize) {
    // The distinct consecutive points of the plan with their item indices.
    let mut pts: Vec<Point> = Vec::new();
    let mut at: Vec<usize> = Vec::new();
    for (k, it) in items.iter().enumerate() {
        if let Item::Move(p) = it {
            if pts.last() != Some(p) {
                pts.push(*p);
                at.push(k);
            }
        }
    }
    let n = pts.len();
    let acc = ctx.world.accessible();
    let need = (floor * ctx.world.accessible_count() as f64).ceil() as usize;
    if n < 3 {
        // Nothing to prune, but whether the plan is short still counts: a plan of one or no
        // move was reported as sweeping the floor, and on a property test's map (0.087 m/px,
        // r = 2.9 px, salt) such a plan of a turned lattice beat every plan with moves; the
        // run swept 38 % of the floor.
        let mut swept = FixedBitSet::with_capacity(ctx.frame.len());
        let rt = ctx.rt + crate::raster::SWEEP_EPS_PX;
        for k in 0..n {
            let a = pts[k];
            let b = pts[(k + 1).min(n - 1)];
            crate::raster::stamp_capsule(&mut swept, &ctx.frame, a, b, rt, &mut |_| {});
        }
        let covered = swept.intersection(acc).count();
        return (
            items,
            n == 0 || covered < need,
            need.saturating_sub(covered),
        );
    }
    let frame = ctx.frame;
    let mut pr = Pruner {
        ctx,
        prev: (0..n).map(|i| if i == 0 { NONE } else { i - 1 }).collect(),
        next: (0..n)
            .map(|i| if i + 1 == n { NONE } else { i + 1 })
            .collect(),
        alive: vec![true; n],
        version: vec![0; n],
        cnt: vec![0; frame.len()],
        tmp: vec![0; frame.len()],
        seg: vec![Vec::new(); n],
        seg_box: vec![[0; 4]; n],
        blocks_w: frame.width.div_ceil(BLOCK),
        changed: vec![0; frame.width.div_ceil(BLOCK) * frame.height.div_ceil(BLOCK)],
        epoch: 0,
        memo: vec![None; n],
        chords: (0..n).map(|_| Vec::new()).collect(),
        acc,
        covered: 0,
        rt: ctx.rt + crate::raster::SWEEP_EPS_PX,
        turn_16: sixteenths(max_extra),
        pts,
    };
    let mut buf = Vec::new();
    let mut touched = Vec::new();
    let p0 = pr.pts[0];
    pr.add(p0, p0, true, &mut buf);
    for i in 0..n - 1 {
        // (a plan given up is dropped whole: return it as it came)
        if i.is_multiple_of(STOP_EVERY) && ctx.stopped() {
            return (items, false, 0);
        }
        let seg = pr.segment(i);
        pr.apply(&seg, true);
        pr.seg[i] = seg;
    }
    // Pruning never takes the plan below the floor, but a plan may come to it below already.
    let short = pr.covered < need;
    pr.drop_spans(need, 0..n);
    if max_extra > 0.0 {
        let merged = pr.merge_corners(need, max_extra, &mut touched, &mut buf);
        // Merged corners open new straight moves: the spans starting near them.
        let mut starts = Vec::new();
        for v in merged {
            if !pr.alive[v] {
                continue;
            }
            starts.push(pr.next[v]);
            let mut x = v;
            for _ in 0..=MAX_SPAN + 1 {
                if x == NONE {
                    break;
                }
                starts.push(x);
                x = pr.prev[x];
            }
        }
        starts.sort_unstable();
        starts.dedup();
        starts.retain(|&x| x != NONE);
        pr.drop_spans(need, starts.into_iter());
    }
    // The items again: each vertex's first move at its (possibly moved) point, its repeats
    // and the dropped vertices' moves left out, the marks kept.
    let mut vertex_at = vec![NONE; items.len()];
    for (v, &k) in at.iter().enumerate() {
        vertex_at[k] = v;
    }
    let items = items
        .into_iter()
        .enumerate()
        .filter_map(|(k, it)| match it {
            Item::Move(_) => {
                let v = vertex_at[k];
                (v != NONE && pr.alive[v]).then(|| Item::Move(pr.pts[v]))
            }
            Item::Mark(_) => Some(it),
        })
        .collect();
    (items, short, need.saturating_sub(pr.covered))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::{Robot, World};

    #[test]
    fn corners_meet_beyond_both_turns_or_not_at_all() {
        let p = Point::new;
        let x = corner(
            p(0.0, 0.0),
            p(10.0, 0.0),
            p(12.0, -2.0),
            p(12.0, -10.0),
            5.0,
        );
        assert!(x.is_some_and(|x| x.dist(p(12.0, 0.0)) < 1e-9), "{x:?}");
        // Too far from the turns.
        assert!(corner(
            p(0.0, 0.0),
            p(10.0, 0.0),
            p(12.0, -2.0),
            p(12.0, -10.0),
            1.0
        )
        .is_none());
        // A bump: the rays meet before the turns.
        let x = corner(p(0.0, 0.0), p(10.0, 0.0), p(8.0, -2.0), p(8.0, 10.0), 3.0);
        assert!(x.is_some_and(|x| x.dist(p(8.0, 0.0)) < 1e-9), "{x:?}");
        // Behind `u`: no corner.
        assert!(corner(
            p(0.0, 0.0),
            p(10.0, 0.0),
            p(-2.0, -2.0),
            p(-2.0, 10.0),
            50.0
        )
        .is_none());
        // A U-turn: parallel moves never meet.
        assert!(corner(p(0.0, 0.0), p(10.0, 0.0), p(10.0, -3.0), p(0.0, -3.0), 50.0).is_none());
        // An S-bend: the lines meet behind the turns.
        assert!(corner(
            p(0.0, 0.0),
            p(10.0, 0.0),
            p(12.0, -2.0),
            p(22.0, -2.0),
            50.0
        )
        .is_none());
    }

    fn room() -> World {
        let art =
            "############\n#..........#\n#..........#\n#..........#\n#..........#\n############";
        let map = crate::grid::GridMap::from_ascii_scaled(art, 10, 0.02).unwrap();
        World::new(
            map,
            Robot::new(0.05),
            Some(crate::geometry::Pose::new(0.3, 0.3, 0.0)),
        )
        .unwrap()
    }

    fn ctx(world: &World) -> Ctx<'_> {
        let frame = *world.frame();
        let reach = world.reachable();
        let ok: Vec<bool> = (0..frame.len()).map(|i| reach.contains(i)).collect();
        Ctx {
            world,
            frame,
            safe: ok.clone(),
            keep_px: None,
            ok,
            rt: world.robot().tool_radius / frame.resolution,
            coarse: super::super::hops::CoarseCache::default(),
            stop: None,
        }
    }

    /// The points of the moves of `items`.
    fn points(items: &[Item]) -> Vec<Point> {
        super::super::finish::moves(items)
            .into_iter()
            .map(|m| m.0)
            .collect()
    }

    fn swept(c: &Ctx<'_>, items: &[Item]) -> FixedBitSet {
        let pts = points(items);
        let rt = c.rt + crate::raster::SWEEP_EPS_PX;
        let mut s = FixedBitSet::with_capacity(c.frame.len());
        crate::raster::stamp_capsule(&mut s, &c.frame, pts[0], pts[0], rt, &mut |_| {});
        for w in pts.windows(2) {
            crate::raster::stamp_capsule(&mut s, &c.frame, w[0], w[1], rt, &mut |_| {});
        }
        s.intersect_with(c.world.accessible());
        s
    }

    fn turns(items: &[Item]) -> usize {
        super::super::finish::turns(&points(items))
    }

    #[test]
    fn pruning_keeps_its_floor_and_the_marks() {
        let world = room();
        let c = ctx(&world);
        let p = Point::new;
        // A wiggly pass with a two-step bend, a needless detour and a mark in between.
        let items = vec![
            Item::Move(p(20.0, 20.0)),
            Item::Move(p(40.0, 21.0)),
            Item::Move(p(60.0, 20.0)),
            Item::Mark(crate::trace::Event::BacktrackStart),
            Item::Move(p(80.0, 20.0)),
            Item::Move(p(84.0, 24.0)),
            Item::Move(p(84.0, 40.0)),
            Item::Move(p(60.0, 40.0)),
            Item::Move(p(58.0, 42.0)),
            Item::Move(p(56.0, 40.0)),
            Item::Move(p(20.0, 40.0)),
        ];
        let before = swept(&c, &items);
        // Floor 1: only drops and merges that lose no accessible pixel.
        let kept = prune(&c, items.clone(), 1.0, 6.0).0;
        let after = swept(&c, &kept);
        assert!(before.is_subset(&after));
        assert!(turns(&kept) < turns(&items), "{kept:?}");
        assert_eq!(
            kept.iter().filter(|i| matches!(i, Item::Mark(_))).count(),
            1
        );
        // A lower floor trades floor for turns, never below the floor.
        let acc = world.accessible().count_ones(..) as f64;
        let base = after.count_ones(..) as f64 / acc;
        let floor = base - 0.05;
        let less = prune(&c, items, floor, 6.0).0;
        let got = swept(&c, &less).count_ones(..) as f64 / acc;
        assert!(got >= floor - 1e-12, "{got} < {floor}");
        assert!(turns(&less) <= turns(&kept));
        for w in less.windows(2) {
            if let [Item::Move(a), Item::Move(b)] = w {
                assert!(c.free(*a, *b));
            }
        }
    }

    /// The room of `room()` (10 px a cell) at one pixel a cell, with obstacle pixels given by
    /// (column, row) of the image; a pixel's centre is (column + 0.5, 59.5 - row) in grid
    /// points.
    fn specked_room(specks: &[(usize, usize)]) -> World {
        let mut rows: Vec<String> = Vec::new();
        for r in 0..60usize {
            let line: String = (0..120usize)
                .map(|c| {
                    let wall = !(10..110).contains(&c) || !(10..50).contains(&r);
                    if wall || specks.contains(&(c, r)) {
                        '#'
                    } else {
                        '.'
                    }
                })
                .collect();
            rows.push(line);
        }
        let map = crate::grid::GridMap::from_ascii_scaled(&rows.join("\n"), 1, 0.02).unwrap();
        World::new(
            map,
            Robot::new(0.05),
            Some(crate::geometry::Pose::new(0.3, 0.3, 0.0)),
        )
        .unwrap()
    }

    /// A step of three turns among specks becomes one corner where the moves before and
    /// after it meet: every straight move across the step hits a speck and the turns taken
    /// two at a time never meet (their moves are parallel), so only a run of three turns
    /// ([`MERGE_RUN`]) completes it.
    #[test]
    fn a_step_of_three_turns_among_specks_becomes_one_corner() {
        let world = specked_room(&[(52, 34), (52, 28), (52, 18), (27, 34)]);
        let c = ctx(&world);
        let p = Point::new;
        let pts = [
            p(15.0, 15.0),
            p(40.0, 15.0),
            p(40.0, 35.0),
            p(65.0, 35.0),
            p(65.0, 47.0),
        ];
        for w in pts.windows(2) {
            assert!(c.free(w[0], w[1]));
        }
        for (a, b) in [(0, 2), (0, 3), (0, 4), (1, 3), (1, 4), (2, 4)] {
            assert!(!c.free(pts[a], pts[b]), "{a} -> {b} is free");
        }
        let items: Vec<Item> = pts.into_iter().map(Item::Move).collect();
        assert_eq!(turns(&items), 3);
        let kept = prune(&c, items, 0.0, 15.0).0;
        assert_eq!(points(&kept), vec![pts[0], p(65.0, 15.0), pts[4]]);
    }

    /// A U-turn of three turns (a join bent round a speck between two lanes' ends) becomes
    /// one of two: no straight move between the turns is free, but both lanes extended to the
    /// bend's depth are joined by a free straight move, for little floor.
    #[test]
    fn a_u_turn_bent_round_a_speck_becomes_two_turns() {
        let world = specked_room(&[(90, 42)]);
        let c = ctx(&world);
        let p = Point::new;
        // Lane out along y = 14, a join bent round the speck (x 90-91, y 17-18), lane back
        // along y = 21.
        let pts = [
            p(15.0, 14.0),
            p(90.0, 14.0),
            p(98.0, 17.5),
            p(90.0, 21.0),
            p(15.0, 21.0),
        ];
        for w in pts.windows(2) {
            assert!(c.free(w[0], w[1]));
        }
        assert!(!c.free(pts[1], pts[3]), "the straight join is free");
        let items: Vec<Item> = pts.into_iter().map(Item::Move).collect();
        assert_eq!(turns(&items), 3);
        // A floor a few pixels below the plan's: no lane can be given up for the turns.
        let acc = world.accessible().count_ones(..) as f64;
        let before = swept(&c, &items).count_ones(..) as f64;
        let floor = (before - 12.0) / acc;
        let kept = prune(&c, items, floor, 15.0).0;
        assert_eq!(
            points(&kept),
            vec![pts[0], p(98.0, 14.0), p(98.0, 21.0), pts[4]]
        );
        assert!(swept(&c, &kept).count_ones(..) as f64 >= floor * acc - 1e-9);
    }

    /// A plan given up while it is pruned comes back as it went in (the planner drops it
    /// whole): the stop is looked at before the first pass over its moves.
    #[test]
    fn pruning_a_plan_given_up_returns_it_unchanged() {
        let world = room();
        let flag = std::sync::atomic::AtomicBool::new(true);
        let c = Ctx {
            stop: Some(&flag),
            ..ctx(&world)
        };
        let p = Point::new;
        let items = vec![
            Item::Move(p(20.0, 20.0)),
            Item::Move(p(40.0, 21.0)),
            Item::Move(p(60.0, 20.0)),
            Item::Move(p(60.0, 40.0)),
            Item::Move(p(58.0, 42.0)),
            Item::Move(p(20.0, 40.0)),
        ];
        let (out, short, _) = prune(&c, items.clone(), 0.5, 6.0);
        assert_eq!(points(&out), points(&items));
        assert_eq!(out.len(), items.len());
        assert!(!short);
        // The same plan not given up loses turns.
        assert!(turns(&prune(&ctx(&world), items.clone(), 0.5, 6.0).0) < turns(&items));
    }
}
