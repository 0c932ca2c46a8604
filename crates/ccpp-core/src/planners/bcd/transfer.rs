//! Transfers between points: straight moves where free, else A* over the C-free pixel centres
//! ([`Search`]), shortened by line-of-sight checks on the true map.

use super::lattice::Ctx;
use crate::geometry::{cross, point_segment_dist2, Point};
use crate::search::MonotoneQueue;

/// How far a merged boundary segment may stray from the boundary points it replaces (pixels).
const CONTOUR_TOL_PX: f64 = 1.0;

impl Ctx<'_> {
    /// A C-free pixel centre joined to `p` by a free straight move (nearest first).
    fn anchor(&self, p: Point) -> Option<(usize, usize)> {
        let (c0, r0) = self.frame.grid_to_pixel_signed(p);
        let mut best: Option<(f64, (usize, usize))> = None;
        for dr in -2..=2 {
            for dc in -2..=2 {
                let (c, r) = (c0 + dc, r0 + dr);
                if !self.ok_at(c, r) {
                    continue;
                }
                let (c, r) = (c as usize, r as usize);
                let q = self.centre(c, r);
                let d = q.dist(p);
                if best.is_none_or(|b| d < b.0) && self.free(p, q) {
                    best = Some((d, (c, r)));
                }
            }
        }
        best.map(|b| b.1)
    }

    /// Is the straight move between the centres of pixels `i` and `j` (row-major indices)
    /// free on the true map? (the test of a diagonal step of [`Search::path`] whose side
    /// pixels are not both admitted)
    pub(super) fn pixel_move_free(&self, i: usize, j: usize) -> bool {
        let w = self.frame.width;
        self.free(self.centre(i % w, i / w), self.centre(j % w, j / w))
    }

    /// Moves from `a` to `b` (excluding `a`): straight when free, else an A* pixel path
    /// shortened by line of sight; `None` when no verified path exists.
    pub(super) fn route(&self, search: &mut Search, a: Point, b: Point) -> Option<Vec<Point>> {
        if self.free(a, b) && self.keeps_margin(a, b, [a, b]) {
            return Some(vec![b]);
        }
        let pa = self.anchor(a)?;
        let pb = self.anchor(b)?;
        let diag = |i: usize, j: usize| self.pixel_move_free(i, j);
        // Through the margin where a path keeps it (then shortened without giving it up),
        // else through the plain C-free set.
        let w = self.frame.width;
        let plain = |j: usize| self.ok[j];
        let (path, kept) = if let Some(keep) = self.keep_px {
            // The ends may sit closer to a wall (a lane end): the pixels within the kept
            // clearance of either end are open too, as in `keeps_margin`.
            let near = |j: usize, p: (usize, usize)| {
                let (dc, dr) = ((j % w) as f64 - p.0 as f64, (j / w) as f64 - p.1 as f64);
                dc * dc + dr * dr <= keep * keep
            };
            let kept = |j: usize| self.safe[j] || (self.ok[j] && (near(j, pa) || near(j, pb)));
            match search.path(&kept, pa, pb, &diag) {
                Some(p) => (p, true),
                None => (search.path(&plain, pa, pb, &diag)?, false),
            }
        } else {
            (search.path(&plain, pa, pb, &diag)?, false)
        };
        let mut pts = Vec::with_capacity(path.len() + 2);
        pts.push(a);
        pts.extend(path.iter().map(|&(c, r)| self.centre(c, r)));
        pts.push(b);
        pts.dedup();
        self.shorten(&pts, kept)
    }

    /// Line-of-sight shortening of a chain whose consecutive points are joined by free moves
    /// (not checked: a failing link gives `None`); with `margin`, a shortcut over more than one
    /// link must also keep the transfer margin ([`Ctx::keeps_margin`]). Returns the points
    /// after the first.
    fn shorten(&self, pts: &[Point], margin: bool) -> Option<Vec<Point>> {
        let ends = [pts[0], pts[pts.len() - 1]];
        let link = |i: usize, j: usize| {
            self.free(pts[i], pts[j])
                && (!margin || j == i + 1 || self.keeps_margin(pts[i], pts[j], ends))
        };
        let mut out = Vec::new();
        let mut i = 0;
        while i + 1 < pts.len() {
            let mut lo = i + 1;
            let mut step = 1;
            let mut hi = None;
            loop {
                let j = (i + step).min(pts.len() - 1);
                if link(i, j) {
                    lo = j;
                    if j == pts.len() - 1 {
                        break;
                    }
                    step *= 2;
                } else {
                    hi = Some(j);
                    break;
                }
            }
            if let Some(mut hi) = hi {
                if hi == i + 1 {
                    return None;
                }
                while hi - lo > 1 {
                    let mid = usize::midpoint(lo, hi);
                    if link(i, mid) {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
            }
            out.push(pts[lo]);
            i = lo;
        }
        Some(out)
    }

    /// Follows the chain `pts` (from `pts[0]`, excluded) with straight free moves that stay
    /// within [`CONTOUR_TOL_PX`] of every point they replace; links that are not free are
    /// routed. Returns the points after the first (`None`: some link has no route).
    pub(super) fn follow(&self, search: &mut Search, pts: &[Point]) -> Option<Vec<Point>> {
        let mut out = Vec::new();
        let mut i = 0;
        let tol2 = CONTOUR_TOL_PX * CONTOUR_TOL_PX;
        let mut hull = Hull::default();
        while i + 1 < pts.len() {
            // Farthest j whose chord keeps every point in between within the tolerance. The
            // points in between are judged by their convex hull where that decides (a
            // straight chain of n points cost n^2 / 2 distances: a 10 000 px corridor's rim
            // took seconds), else one by one.
            let mut jmax = i + 1;
            hull.clear();
            for j in i + 2..pts.len() {
                hull.add(pts[j - 1]);
                let within = hull.chord_within(pts[i], pts[j], tol2).unwrap_or_else(|| {
                    (i + 1..j).all(|m| point_segment_dist2(pts[m], pts[i], pts[j]) <= tol2)
                });
                if within {
                    jmax = j;
                } else {
                    break;
                }
            }
            let mut j = jmax;
            while j > i + 1 && !self.free(pts[i], pts[j]) {
                j -= 1;
            }
            if j == i + 1 && !self.free(pts[i], pts[j]) {
                out.extend(self.route(search, pts[i], pts[j])?);
            } else {
                out.push(pts[j]);
            }
            i = j;
        }
        Some(out)
    }
}

/// The convex hull of a growing set of points (counter-clockwise, collinear points left
/// out), for [`Ctx::follow`]'s chord test: a linear function of the points (the distance
/// across a chord, the position along it) is largest and smallest at hull vertices. The
/// points of a chain within a pixel of a chord have few hull vertices.
#[derive(Default)]
struct Hull {
    pts: Vec<Point>,
    scratch: Vec<Point>,
}

/// Margin (squared pixels, and chord fractions) within which [`Hull::chord_within`] leaves the
/// decision to the exact test: far above the rounding of its products, far below any distance
/// that matters.
const HULL_MARGIN: f64 = 1e-7;

/// Pushes `q` onto a monotone chain's half hull, first popping the points that would not
/// turn left while the chain holds at least `min_len` of them.
fn push_turning(hull: &mut Vec<Point>, q: Point, min_len: usize) {
    while hull.len() >= min_len && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0 {
        hull.pop();
    }
    hull.push(q);
}

impl Hull {
    fn clear(&mut self) {
        self.pts.clear();
    }

    /// Adds `p` (nothing changes when it lies inside).
    fn add(&mut self, p: Point) {
        let n = self.pts.len();
        if n >= 3 && (0..n).all(|k| cross(self.pts[k], self.pts[(k + 1) % n], p) >= 0.0) {
            return;
        }
        // Andrew's monotone chain over the old vertices and `p`.
        let mut v = std::mem::take(&mut self.scratch);
        v.clear();
        v.extend_from_slice(&self.pts);
        v.push(p);
        v.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
        v.dedup();
        self.pts.clear();
        if v.len() < 3 {
            self.pts.extend_from_slice(&v);
        } else {
            // Lower hull left to right, then upper right to left; the last point of each
            // half is the first of the other.
            for &q in &v {
                push_turning(&mut self.pts, q, 2);
            }
            let upper = self.pts.len() + 1;
            for &q in v.iter().rev().skip(1) {
                push_turning(&mut self.pts, q, upper);
            }
            self.pts.pop();
        }
        self.scratch = v;
    }

    /// Whether every point added lies within `sqrt(tol2)` of the segment `a b`, when the hull
    /// decides it clearly: `Some(true)` when every vertex lies within it across the chord and
    /// strictly between its ends along it (so the distance to the segment is the distance
    /// to its line), `Some(false)` when a vertex lies farther than that across it (no nearer
    /// to the segment than to its line); `None` otherwise, and near either bound.
    fn chord_within(&self, a: Point, b: Point, tol2: f64) -> Option<bool> {
        let d = b - a;
        let l2 = d.dot(d);
        if l2 == 0.0 || self.pts.is_empty() {
            return None;
        }
        let mut inside = true;
        for &v in &self.pts {
            let c = cross(a, b, v);
            let across2 = c * c / l2;
            if across2 > tol2 + HULL_MARGIN {
                return Some(false);
            }
            let t = (v - a).dot(d) / l2;
            inside &= across2 < tol2 - HULL_MARGIN && t > HULL_MARGIN && t < 1.0 - HULL_MARGIN;
        }
        inside.then_some(true)
    }
}

/// Pixel path search (A*, 8-connected, octile integer costs, no corner cutting).
pub(super) struct Search {
    width: usize,
    height: usize,
    stamp: Vec<u32>,
    gen: u32,
    g: Vec<u32>,
    parent: Vec<u32>,
    heap: MonotoneQueue,
}

impl Search {
    pub(super) fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            stamp: vec![0; width * height],
            gen: 0,
            g: vec![0; width * height],
            parent: vec![u32::MAX; width * height],
            heap: MonotoneQueue::new(),
        }
    }

    fn octile(a: (usize, usize), b: (usize, usize)) -> u32 {
        let dx = a.0.abs_diff(b.0) as u32;
        let dy = a.1.abs_diff(b.1) as u32;
        10 * dx.max(dy) + 4 * dx.min(dy)
    }

    /// A* from `s` to `t` over the pixels `ok` admits (the end pixels need not be in it). A
    /// diagonal step whose two side pixels are not both admitted is taken only when
    /// `diag(from, to)` allows it. Settles in `(f, g, pixel index)` order (a
    /// [`MonotoneQueue`] keyed `f << 32 | g`: the octile heuristic is consistent, so keys
    /// never go below the last popped one).
    pub(super) fn path<O: Fn(usize) -> bool, D: Fn(usize, usize) -> bool>(
        &mut self,
        ok: &O,
        s: (usize, usize),
        t: (usize, usize),
        diag_ok: &D,
    ) -> Option<Vec<(usize, usize)>> {
        self.gen = self.gen.wrapping_add(1);
        if self.gen == 0 {
            self.stamp.iter_mut().for_each(|x| *x = 0);
            self.gen = 1;
        }
        let (w, h) = (self.width, self.height);
        let ti = t.1 * w + t.0;
        let passable = |j: usize| ok(j) || j == ti;
        let mut heap = std::mem::replace(&mut self.heap, MonotoneQueue::new());
        heap.clear();
        let si = s.1 * w + s.0;
        self.stamp[si] = self.gen;
        self.g[si] = 0;
        self.parent[si] = u32::MAX;
        heap.push(u64::from(Self::octile(s, t)) << 32, si as u32);
        let mut found = false;
        while let Some((key, i)) = heap.pop() {
            let g = key as u32;
            let i = i as usize;
            if g > self.g[i] {
                continue;
            }
            if i == ti {
                found = true;
                break;
            }
            let (c, r) = (i % w, i / w);
            // The four side neighbours' passability, read once: the diagonal steps need
            // them too. (The order of the steps decides nothing: the queue's order is total,
            // and a neighbour's parent is the first settled position giving its cost.)
            let (east, north) = (c + 1 < w, r > 0);
            let (west, south) = (c > 0, r + 1 < h);
            let pe = east && passable(i + 1);
            let pn = north && passable(i - w);
            let pw = west && passable(i - 1);
            let ps = south && passable(i + w);
            let steps = [
                (pe, i.wrapping_add(1), false, false),
                (pn, i.wrapping_sub(w), false, false),
                (pw, i.wrapping_sub(1), false, false),
                (ps, i.wrapping_add(w), false, false),
                (
                    east && north,
                    i.wrapping_sub(w).wrapping_add(1),
                    true,
                    pe && pn,
                ),
                (
                    west && north,
                    i.wrapping_sub(w).wrapping_sub(1),
                    true,
                    pw && pn,
                ),
                (
                    west && south,
                    i.wrapping_add(w).wrapping_sub(1),
                    true,
                    pw && ps,
                ),
                (
                    east && south,
                    i.wrapping_add(w).wrapping_add(1),
                    true,
                    pe && ps,
                ),
            ];
            for (inside, j, diag, sides) in steps {
                // (a side step's `inside` is its passability, checked once above)
                if !inside || (diag && !passable(j)) {
                    continue;
                }
                if diag && !sides && !diag_ok(i, j) {
                    continue;
                }
                let ng = g + if diag { 14 } else { 10 };
                if self.stamp[j] != self.gen || ng < self.g[j] {
                    self.stamp[j] = self.gen;
                    self.g[j] = ng;
                    self.parent[j] = i as u32;
                    heap.push(
                        u64::from(ng + Self::octile((j % w, j / w), t)) << 32 | u64::from(ng),
                        j as u32,
                    );
                }
            }
        }
        self.heap = heap;
        if !found {
            return None;
        }
        let mut out = vec![t];
        let mut k = ti;
        while self.parent[k] != u32::MAX {
            k = self.parent[k] as usize;
            out.push((k % w, k / w));
        }
        out.reverse();
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;

    use proptest::prelude::*;

    use super::{Hull, Search, CONTOUR_TOL_PX};
    use crate::geometry::{point_segment_dist2, Point};

    proptest! {
        /// Where the hull decides the chord test it decides as the test of every point does:
        /// chains of pixel centres along a line (distances of exactly the tolerance are
        /// common there), wiggling, doubling back, and at sub-pixel offsets.
        #[test]
        fn the_hull_decides_the_chord_test_as_every_point_does(
            steps in prop::collection::vec((-1i32..=2, -1i32..=1), 2..60),
            off in (0u32..4, 0u32..4),
            slope in 0u32..4,
        ) {
            let tol2 = CONTOUR_TOL_PX * CONTOUR_TOL_PX;
            let (mut x, mut y) = (
                0.5 + f64::from(off.0) * 0.25,
                0.5 + f64::from(off.1) * 0.25,
            );
            let mut pts = vec![Point::new(x, y)];
            for (k, &(dx, dy)) in steps.iter().enumerate() {
                x += f64::from(dx);
                y += f64::from(dy) + if slope > 0 && (k as u32).is_multiple_of(slope + 1) { 1.0 } else { 0.0 };
                pts.push(Point::new(x, y));
            }
            let mut hull = Hull::default();
            for j in 2..pts.len() {
                hull.add(pts[j - 1]);
                let every = (1..j).all(|m| point_segment_dist2(pts[m], pts[0], pts[j]) <= tol2);
                if let Some(decided) = hull.chord_within(pts[0], pts[j], tol2) {
                    prop_assert_eq!(decided, every, "chord 0..{} of {:?}", j, &pts[..=j]);
                }
            }
        }
    }

    /// On a straight chain the hull decides every chord (so the test is not the scan of every
    /// point, which made a long straight rim cost its length squared).
    #[test]
    fn the_hull_decides_a_straight_chain() {
        let pts: Vec<Point> = (0..500)
            .map(|k| Point::new(f64::from(k) + 0.5, f64::from(k / 7) + 0.5))
            .collect();
        let mut hull = Hull::default();
        let mut decided = 0;
        for j in 2..pts.len() {
            hull.add(pts[j - 1]);
            decided += usize::from(hull.chord_within(pts[0], pts[j], 1.0).is_some());
        }
        assert!(hull.pts.len() < 40, "{} hull vertices", hull.pts.len());
        assert!(decided > 490, "{decided} of 498 chords decided by the hull");
    }

    /// The A* of [`Search::path`] with a binary heap of `(f, g, index)` triples: the order the
    /// planner's transfers were planned in before the monotone queue.
    fn reference(
        w: usize,
        h: usize,
        ok: &dyn Fn(usize) -> bool,
        s: (usize, usize),
        t: (usize, usize),
        diag_ok: &dyn Fn(usize, usize) -> bool,
    ) -> Option<Vec<(usize, usize)>> {
        let ti = t.1 * w + t.0;
        let passable = |j: usize| ok(j) || j == ti;
        let mut g = vec![u32::MAX; w * h];
        let mut parent = vec![u32::MAX; w * h];
        let mut heap = BinaryHeap::new();
        let si = s.1 * w + s.0;
        g[si] = 0;
        heap.push(Reverse((Search::octile(s, t), 0u32, si as u32)));
        while let Some(Reverse((_, gi, i))) = heap.pop() {
            let i = i as usize;
            if gi > g[i] {
                continue;
            }
            if i == ti {
                let mut out = vec![t];
                let mut k = ti;
                while parent[k] != u32::MAX {
                    k = parent[k] as usize;
                    out.push((k % w, k / w));
                }
                out.reverse();
                return Some(out);
            }
            let (c, r) = ((i % w) as i64, (i / w) as i64);
            for (dc, dr) in [
                (1, 0),
                (0, -1),
                (-1, 0),
                (0, 1),
                (1, -1),
                (-1, -1),
                (-1, 1),
                (1, 1),
            ] {
                let (nc, nr) = (c + dc, r + dr);
                if nc < 0 || nr < 0 || nc >= w as i64 || nr >= h as i64 {
                    continue;
                }
                let j = nr as usize * w + nc as usize;
                if !passable(j) {
                    continue;
                }
                let diag = dc != 0 && dr != 0;
                if diag
                    && !(passable(r as usize * w + nc as usize)
                        && passable(nr as usize * w + c as usize))
                    && !diag_ok(i, j)
                {
                    continue;
                }
                let ng = gi + if diag { 14 } else { 10 };
                if ng < g[j] {
                    g[j] = ng;
                    parent[j] = i as u32;
                    let h = Search::octile((nc as usize, nr as usize), t);
                    heap.push(Reverse((ng + h, ng, j as u32)));
                }
            }
        }
        None
    }

    /// Paths (with their ties) are those of the binary-heap A*, on grids like real maps:
    /// walls at any offset with gaps, salt noise, open rooms with many equal-cost paths, and
    /// diagonal squeezes allowed by a predicate; one `Search` reused for every query.
    #[test]
    fn paths_are_those_of_the_binary_heap_astar() {
        let mut seed: u64 = 0x2545_f491_4f6c_dd1d;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let (w, h) = (61, 47);
        let mut search = Search::new(w, h);
        let mut compared = 0;
        let mut detours = 0;
        for map in 0..40 {
            let mut free = vec![true; w * h];
            // Walls, vertical and horizontal, each with a gap.
            for _ in 0..(next() % 5) {
                let vertical = next() % 2 == 0;
                let (len, at) = if vertical {
                    (h, next() as usize % w)
                } else {
                    (w, next() as usize % h)
                };
                let gap = next() as usize % len;
                for k in 0..len {
                    if k.abs_diff(gap) > 1 {
                        let j = if vertical { k * w + at } else { at * w + k };
                        free[j] = false;
                    }
                }
            }
            // Salt noise, denser on some maps.
            let salt = [0, 2, 8, 20][map % 4];
            for j in 0..w * h {
                if next() % 100 < salt {
                    free[j] = false;
                }
            }
            let ok = |j: usize| free[j];
            let diag_ok = |i: usize, j: usize| (i * 31 + j * 17).is_multiple_of(3);
            for _ in 0..25 {
                let s = (next() as usize % w, next() as usize % h);
                let t = (next() as usize % w, next() as usize % h);
                if !free[s.1 * w + s.0] {
                    continue;
                }
                let want = reference(w, h, &ok, s, t, &diag_ok);
                let got = search.path(&ok, s, t, &diag_ok);
                assert_eq!(got, want, "map {map}, {s:?} -> {t:?}");
                compared += 1;
                if let Some(p) = &want {
                    let straight = s.0.abs_diff(t.0).max(s.1.abs_diff(t.1)) + 1;
                    detours += usize::from(p.len() > straight + 4);
                }
            }
        }
        // The comparison saw real searches: many queries, some of them long detours.
        assert!(
            compared > 500 && detours > 20,
            "{compared} queries, {detours} detours"
        );
    }
}
