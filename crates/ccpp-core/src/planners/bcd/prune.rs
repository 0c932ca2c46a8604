//! Coverage-budgeted turn pruning of the finished plan (module docs of [`super`], step 5).
//!
//! The plan's polyline sweeps a set of accessible pixels; every pixel keeps the number of the
//! plan's segments whose tool capsule covers it (the metric's own capsule test). The vertices
//! strictly between `u` and a later vertex `w` (at most [`MAX_SPAN`] of them: a lone corner, a
//! short detour into a sliver cell and back) can be dropped when the straight move `u -> w` is
//! free on the true map; dropping them saves the turns they and `u`, `w` make and shortens the
//! path, and loses the accessible pixels that only the removed segments sweep and `u -> w`
//! does not. Spans are dropped greedily, fewest lost pixels per saved turn first, while the
//! pixels the plan still sweeps stay at least `floor` of the accessible floor. A span's loss is
//! recomputed when it is taken (lazy greedy), so the budget is kept exactly.

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::ops::Sub;

use fixedbitset::FixedBitSet;

use super::{Ctx, Item};
use crate::geometry::{point_segment_dist2, Point};

/// Heading change at `b` between the moves `a -> b` and `b -> c` (as the simulator counts a
/// turn).
fn turn(a: Point, b: Point, c: Point) -> bool {
    let (d0, d1) = (b.sub(a), c.sub(b));
    let h0 = d0.y.atan2(d0.x);
    let h1 = d1.y.atan2(d1.x);
    crate::geometry::wrap_angle(h1 - h0).abs() > crate::planner::MIN_ROTATION
}

/// Most vertices one drop removes.
const MAX_SPAN: usize = 6;
const NONE: usize = usize::MAX;

struct Pruner<'a, 'b> {
    ctx: &'a Ctx<'b>,
    pts: Vec<Point>,
    prev: Vec<usize>,
    next: Vec<usize>,
    alive: Vec<bool>,
    version: Vec<u32>,
    /// Segments of the plan covering each pixel.
    cnt: Vec<u32>,
    /// Scratch: segments of the span under evaluation covering each pixel.
    tmp: Vec<u32>,
    acc: &'a FixedBitSet,
    covered: usize,
    scratch: FixedBitSet,
    rt: f64,
}

/// A span to drop: the vertices strictly between `u` and `w`.
#[derive(Clone, Copy)]
struct Span {
    key: u64,
    w: usize,
    lost: usize,
}

impl Pruner<'_, '_> {
    /// Pixels of the capsule `a`-`b` (each once).
    fn capsule(&mut self, a: Point, b: Point, out: &mut Vec<usize>) {
        let start = out.len();
        crate::raster::stamp_capsule(
            &mut self.scratch,
            &self.ctx.frame,
            a,
            b,
            self.rt,
            &mut |i| {
                out.push(i);
            },
        );
        for &i in &out[start..] {
            self.scratch.set(i, false);
        }
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

    /// The cheapest span starting at `u` (lost pixels per saved turn), if any saves a turn.
    fn best_from(
        &mut self,
        u: usize,
        touched: &mut Vec<usize>,
        buf: &mut Vec<usize>,
    ) -> Option<Span> {
        if !self.alive[u] {
            return None;
        }
        let pu = self.prev[u];
        let rt2 = self.rt * self.rt;
        touched.clear();
        let mut best: Option<Span> = None;
        // Turns of the chain from u: at u (with pu), and inside.
        let mut before = 0;
        let mut v = u;
        let mut a = self.next[u];
        if a == NONE {
            return None;
        }
        for k in 0..=MAX_SPAN {
            // Add segment v -> a.
            buf.clear();
            let (pv, pa) = (self.pts[v], self.pts[a]);
            self.capsule(pv, pa, buf);
            for &i in buf.iter() {
                if self.tmp[i] == 0 {
                    touched.push(i);
                }
                self.tmp[i] += 1;
            }
            before += self.turn_at(self.prev[v], v, a);
            let w = a;
            if k >= 1 {
                let nw = self.next[w];
                let b = before + self.turn_at(v, w, nw);
                let after = self.turn_at(pu, u, w) + self.turn_at(u, w, nw);
                let saved = b - after;
                if saved > 0 {
                    let (p0, p1) = (self.pts[u], self.pts[w]);
                    let lost = touched
                        .iter()
                        .filter(|&&i| {
                            self.acc.contains(i)
                                && self.cnt[i] == self.tmp[i]
                                && point_segment_dist2(self.centre(i), p0, p1) > rt2
                        })
                        .count();
                    let key = (lost as u64 * 1024) / saved as u64;
                    if best.is_none_or(|s| key < s.key) && self.ctx.free(p0, p1) {
                        best = Some(Span { key, w, lost });
                    }
                }
            }
            v = a;
            a = self.next[a];
            if a == NONE {
                break;
            }
        }
        for &i in touched.iter() {
            self.tmp[i] = 0;
        }
        best
    }

    fn add(&mut self, a: Point, b: Point, up: bool, buf: &mut Vec<usize>) {
        buf.clear();
        self.capsule(a, b, buf);
        for &i in buf.iter() {
            if up {
                if self.cnt[i] == 0 && self.acc.contains(i) {
                    self.covered += 1;
                }
                self.cnt[i] += 1;
            } else {
                self.cnt[i] -= 1;
                if self.cnt[i] == 0 && self.acc.contains(i) {
                    self.covered -= 1;
                }
            }
        }
    }
}

/// Drops turn vertices of the plan's moves while its estimated effective coverage stays at
/// least `floor` (module docs).
pub(super) fn prune(ctx: &Ctx<'_>, items: Vec<Item>, floor: f64) -> Vec<Item> {
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
    if n < 3 {
        return items;
    }
    let acc = ctx.world.accessible();
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
        acc,
        covered: 0,
        scratch: FixedBitSet::with_capacity(frame.len()),
        rt: ctx.rt + crate::raster::SWEEP_EPS_PX,
        pts,
    };
    let mut buf = Vec::new();
    let mut touched = Vec::new();
    let p0 = pr.pts[0];
    pr.add(p0, p0, true, &mut buf);
    for i in 0..n - 1 {
        let (a, b) = (pr.pts[i], pr.pts[i + 1]);
        pr.add(a, b, true, &mut buf);
    }
    let need = (floor * acc.count_ones(..) as f64).ceil() as usize;
    // (key, start vertex, its version)
    let mut heap: BinaryHeap<Reverse<(u64, usize, u32)>> = BinaryHeap::new();
    for u in 0..n - 2 {
        if let Some(s) = pr.best_from(u, &mut touched, &mut buf) {
            heap.push(Reverse((s.key, u, 0)));
        }
    }
    while let Some(Reverse((k, u, ver))) = heap.pop() {
        if !pr.alive[u] || ver != pr.version[u] {
            continue;
        }
        let Some(s) = pr.best_from(u, &mut touched, &mut buf) else {
            continue;
        };
        if s.key > k {
            heap.push(Reverse((s.key, u, ver)));
            continue;
        }
        if s.lost > 0 && pr.covered - s.lost < need {
            continue;
        }
        // Drop the vertices strictly between u and w.
        let (pu, pw) = (pr.pts[u], pr.pts[s.w]);
        let mut v = u;
        while v != s.w {
            let a = pr.next[v];
            let (p, q) = (pr.pts[v], pr.pts[a]);
            pr.add(p, q, false, &mut buf);
            if v != u {
                pr.alive[v] = false;
            }
            v = a;
        }
        pr.add(pu, pw, true, &mut buf);
        pr.next[u] = s.w;
        pr.prev[s.w] = u;
        // Re-evaluate the spans whose turns or segments changed: those starting up to
        // MAX_SPAN + 1 vertices before u, at u, and at w.
        let mut starts = vec![s.w];
        let mut x = u;
        for _ in 0..=MAX_SPAN + 1 {
            if x == NONE {
                break;
            }
            starts.push(x);
            x = pr.prev[x];
        }
        for x in starts {
            pr.version[x] = pr.version[x].wrapping_add(1);
            if let Some(s) = pr.best_from(x, &mut touched, &mut buf) {
                heap.push(Reverse((s.key, x, pr.version[x])));
            }
        }
    }
    // Drop the items of the dropped vertices.
    let mut drop = vec![false; items.len()];
    for (v, &k) in at.iter().enumerate() {
        if !pr.alive[v] {
            drop[k] = true;
        }
    }
    // Repeated points of a dropped vertex go with it.
    let mut last_dropped: Option<Point> = None;
    items
        .into_iter()
        .enumerate()
        .filter_map(|(k, it)| {
            if drop[k] {
                if let Item::Move(p) = it {
                    last_dropped = Some(p);
                }
                return None;
            }
            if let Item::Move(p) = it {
                if last_dropped == Some(p) {
                    return None;
                }
                last_dropped = None;
            }
            Some(it)
        })
        .collect()
}
