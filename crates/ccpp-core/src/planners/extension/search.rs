//! The position search: Dijkstra (A* for transfers) over the positions from a grid point, on
//! a bucket queue with one-word, generation-stamped node states; and the transfers
//! (`Extension::route`) built on it.

use super::graph::{BLOCKED, FREE, NB};
use super::{Extension, Px};
use crate::geometry::{floor_i64, Point};
use crate::planner::KnownMap;

/// log2 of the key range one [`BucketQueue`] bucket holds (a sixteenth of an orthogonal step).
const BUCKET_SHIFT: u32 = 6;
/// The last [`BucketQueue`] bucket holds every larger key too (bounds its memory; the order
/// stays exact, only slower, for keys beyond about 65 000 pixel steps).
const BUCKET_MAX: usize = 1 << 20;

/// The position search's priority queue: pops the smallest `(key, index)` first, exactly the
/// order of a binary min-heap on that pair (so plans are unchanged), but cheaper. Keys are
/// search costs (plus a heuristic), integers in steps of about [`COST_ORTHO`]: entries go to
/// the bucket `key >> BUCKET_SHIFT` by a plain push, and a bucket is sorted once, when the
/// queue first pops from it (later pushes into a sorted bucket are inserted in order). The
/// weighted-A* heuristic is not consistent, so a key may fall below the bucket being popped:
/// the cursor then moves back to it.
///
/// Within a bucket below [`BUCKET_MAX`] every key has the same high bits, so an entry is one
/// word, [`pack`]ed: the key's low [`BUCKET_SHIFT`] bits above the 32-bit index. Comparing
/// two words compares `(key, index)`; half the memory of a pair and a plain integer sort. The
/// last bucket, which holds every larger key, keeps whole pairs.
///
/// A search's keys sweep upwards through tens of thousands of buckets on a large map, while
/// only the few buckets within a step's cost of the cursor hold entries at a time. So a bucket
/// the cursor leaves empty gives its storage to a pool, and a bucket that receives its first
/// entry takes storage from there: a handful of buffers, warm in the cache, serve the whole
/// search instead of one allocation (grown, and faulted in, step by step) per bucket.
#[derive(Default)]
pub(super) struct BucketQueue {
    /// Packed entries per bucket below [`BUCKET_MAX`]; a sorted bucket is in descending order
    /// (smallest last).
    buckets: Vec<Vec<u64>>,
    /// The entries of bucket [`BUCKET_MAX`], whole; descending when sorted.
    last: Vec<(u64, u32)>,
    /// Empty buffers for buckets that receive entries (see the type's docs).
    pool: Vec<Vec<u64>>,
    /// Whether each bucket is sorted (index [`BUCKET_MAX`]: `last`).
    sorted: Vec<bool>,
    /// No non-empty bucket lies below this one.
    cur: usize,
    /// One past the highest bucket used since the last clear.
    top: usize,
    /// Entries queued.
    len: usize,
}

/// A bucket entry below [`BUCKET_MAX`]: key bits below [`BUCKET_SHIFT`] over index `i`.
#[inline]
fn pack(key: u64, i: u32) -> u64 {
    (key & ((1 << BUCKET_SHIFT) - 1)) << 32 | u64::from(i)
}

impl BucketQueue {
    /// Empties the queue (keeps the buckets' storage).
    fn clear(&mut self) {
        let top = self.top.min(self.buckets.len());
        for b in self.cur.min(top)..top {
            self.recycle(b);
            self.sorted[b] = false;
        }
        if self.sorted.len() > BUCKET_MAX {
            self.sorted[BUCKET_MAX] = false;
        }
        self.last.clear();
        self.cur = usize::MAX;
        self.top = 0;
        self.len = 0;
    }

    /// Queues position `i` at `key`.
    #[inline]
    fn push(&mut self, key: u64, i: usize) {
        let b = usize::try_from(key >> BUCKET_SHIFT).map_or(BUCKET_MAX, |b| b.min(BUCKET_MAX));
        if b >= self.sorted.len() {
            self.buckets.resize_with((b + 1).min(BUCKET_MAX), Vec::new);
            self.sorted.resize(b + 1, false);
        }
        if b == BUCKET_MAX {
            let e = (key, i as u32);
            if self.sorted[b] {
                let at = self.last.partition_point(|x| *x > e);
                self.last.insert(at, e);
            } else {
                self.last.push(e);
            }
        } else {
            let e = pack(key, i as u32);
            if self.buckets[b].capacity() == 0 {
                if let Some(v) = self.pool.pop() {
                    self.buckets[b] = v;
                }
            }
            let v = &mut self.buckets[b];
            if self.sorted[b] {
                let at = v.partition_point(|x| *x > e);
                v.insert(at, e);
            } else {
                v.push(e);
            }
        }
        if self.len == 0 || b < self.cur {
            self.cur = b;
        }
        self.top = self.top.max(b + 1);
        self.len += 1;
    }

    /// Empties bucket `b` (below [`BUCKET_MAX`]) and gives its storage (if any) to the pool.
    #[inline]
    fn recycle(&mut self, b: usize) {
        if self.buckets[b].capacity() > 0 {
            let mut v = std::mem::take(&mut self.buckets[b]);
            v.clear();
            self.pool.push(v);
        }
    }

    /// The position [`Self::pop`] would return next, when that is known without work (the
    /// current bucket is sorted and holds it); else `None`.
    #[inline]
    fn peek(&self) -> Option<usize> {
        let b = self.cur;
        if b >= BUCKET_MAX || !self.sorted.get(b).copied().unwrap_or(false) {
            return None;
        }
        self.buckets[b]
            .last()
            .map(|&e| (e & u64::from(u32::MAX)) as usize)
    }

    /// Removes and returns the position with the smallest `(key, index)`.
    fn pop(&mut self) -> Option<usize> {
        if self.len == 0 {
            return None;
        }
        while self.cur < BUCKET_MAX && self.buckets[self.cur].is_empty() {
            self.recycle(self.cur);
            self.sorted[self.cur] = false;
            self.cur += 1;
        }
        let b = self.cur;
        self.len -= 1;
        if b == BUCKET_MAX {
            if !self.sorted[b] {
                self.last.sort_unstable_by(|x, y| y.cmp(x));
                self.sorted[b] = true;
            }
            return self.last.pop().map(|(_, i)| i as usize);
        }
        if !self.sorted[b] {
            self.buckets[b].sort_unstable_by(|x, y| y.cmp(x));
            self.sorted[b] = true;
        }
        self.buckets[b]
            .pop()
            .map(|e| (e & u64::from(u32::MAX)) as usize)
    }
}

/// One pixel's search state ([`Extension::search`]; generation-stamped), one word: the
/// search cost in bits 20..63 ([`CLOSED`] set once settled), the move from the parent in bits
/// 16..20 (`k + 1` for a step `NB[k]`, 0: a first step from the start) and the generation in
/// bits 0..16. All zero is "never reached", so the table starts as zeroed memory the system
/// maps only where a search goes. (Eight bytes a pixel: the search is bound by memory traffic.)
pub(super) type Node = u64;

/// Bits of [`Node`] below the search cost.
const NODE_COST_SHIFT: u32 = 20;

/// Generations a [`Node`] tells apart (the table is cleared when they wrap).
const NODE_GENS: u32 = 1 << 16;

/// The [`Node`] of a position reached at cost `dist` by the move `NB[k]` (`None`: from the
/// start) in generation `gen`.
fn node(dist: u64, k: Option<usize>, gen: u32) -> Node {
    // 43 bits of cost: over 8e9 pixel steps, far beyond any map that fits in memory.
    debug_assert!(
        dist < 1 << (63 - NODE_COST_SHIFT),
        "search cost overflows a node"
    );
    debug_assert!(gen < NODE_GENS);
    let m = k.map_or(0, |k| k as u64 + 1);
    dist << NODE_COST_SHIFT | m << 16 | u64::from(gen)
}

/// The search cost recorded in `n`.
fn node_cost(n: Node) -> u64 {
    (n & !CLOSED) >> NODE_COST_SHIFT
}

/// The generation that wrote `n`.
fn node_gen(n: Node) -> u32 {
    (n & 0xFFFF) as u32
}

/// The move from the parent recorded in `n` (an index into [`NB`]).
fn node_move(n: Node) -> Option<usize> {
    let m = (n >> 16) & 0xF;
    (m != 0).then(|| (m - 1) as usize)
}

/// Fixed-point step costs (one pixel = 1000).
pub(super) const COST_ORTHO: u64 = 1000;
const COST_DIAG: u64 = 1414;

/// The cost of the step `NB[k]` (odd `k`: diagonal).
const STEP_COST: [u64; 8] = [
    COST_ORTHO, COST_DIAG, COST_ORTHO, COST_DIAG, COST_ORTHO, COST_DIAG, COST_ORTHO, COST_DIAG,
];

/// Settled positions carry this bit in their search cost.
const CLOSED: u64 = 1 << 63;

/// Settled positions after which a final clean-up's search checks whether any position is
/// left that could stop it ([`Extension::nothing_gains`]).
const EXHAUST_CHECK: usize = 4096;

/// Most positions [`Extension::cut_off`] walks back over before it gives up.
const CUT_OFF_MAX: usize = 1024;

/// Heuristic weight of transfer searches.
const ROUTE_WEIGHT: f64 = 1.5;

/// The transfer search's heuristic at grid point `c` for the goal `g`:
/// `floor(|c - g| * ROUTE_WEIGHT * COST_ORTHO)` with the distance by `hypot`. A square root
/// is within a few units in the last place of `hypot` (far cheaper than the libm call), so
/// its floor is the same wherever the product lies more than a rounding margin from an
/// integer; next to one, `hypot` decides.
#[inline]
fn route_heuristic(c: Point, g: Point) -> u64 {
    let (dx, dy) = (c.x - g.x, c.y - g.y);
    let v = (dx * dx + dy * dy).sqrt() * ROUTE_WEIGHT * COST_ORTHO as f64;
    let f = floor_i64(v);
    let frac = v - f as f64;
    let margin = 1e-6 + v * 1e-12;
    if f >= 0 && frac > margin && frac < 1.0 - margin {
        return f as u64;
    }
    (c.dist(g) * ROUTE_WEIGHT * COST_ORTHO as f64).floor() as u64
}

/// `c.dist(g) < 1.5` (the transfer search's goal test, at every position it settles) without
/// the `hypot` call where the squared distance decides: it lies within a few units in the last
/// place of the exact square, so only a square within a relative `1e-12` of `2.25` asks `hypot`.
#[inline]
fn within_1_5(c: Point, g: Point) -> bool {
    let (dx, dy) = (c.x - g.x, c.y - g.y);
    let s = dx * dx + dy * dy;
    if s < 2.25 * (1.0 - 1e-12) {
        return true;
    }
    if s > 2.25 * (1.0 + 1e-12) {
        return false;
    }
    c.dist(g) < 1.5
}

impl Extension {
    fn begin(&mut self) {
        self.generation = (self.generation + 1) % NODE_GENS;
        if self.generation == 0 {
            self.nodes.fill(0);
            self.generation = 1;
        }
    }

    /// Dijkstra (A* with `goal`) over positions from grid point `from`. Stops at the first
    /// settled position for which `done` holds, or when the cost exceeds `limit`. Returns the
    /// position path (pixel indices), starting next to `from`. With `resume`, goes on from
    /// where the last search (same `from`, `limit` and no `goal`, nothing changed since but
    /// the targets) stopped, when it found a position.
    pub(super) fn search(
        &mut self,
        known: &KnownMap,
        from: Point,
        limit: Option<u64>,
        goal: Option<Point>,
        resume: bool,
        done: &mut dyn FnMut(&mut Self, Px) -> bool,
    ) -> Option<Vec<usize>> {
        let mut heap = std::mem::take(&mut self.heap);
        if !resume || self.resume_at.is_none() {
            self.begin();
            for j in self.unreach_marked.drain(..) {
                self.unreach.set(j, false);
            }
            self.resume_at = None;
            heap.clear();
        }
        // Transfers need a short known-free way, not the shortest: an inflated heuristic
        // (weighted A*) settles far fewer positions; the way is straightened afterwards.
        // Without a goal the heuristic is 0 and compiled away (a search settles up to millions
        // of positions, each queuing up to 8 neighbours).
        let found = match goal {
            None => self.search_with(known, from, limit, &|_: &Self, _: Px| 0, &mut heap, done),
            Some(g) => {
                let h = move |s: &Self, p: Px| route_heuristic(s.center(p), g);
                self.search_with(known, from, limit, &h, &mut heap, done)
            }
        };
        self.heap = heap;
        found
    }

    /// [`Self::search`]'s body, on the queue `heap`.
    fn search_with<H: Fn(&Self, Px) -> u64>(
        &mut self,
        known: &KnownMap,
        from: Point,
        limit: Option<u64>,
        h: &H,
        heap: &mut BucketQueue,
        done: &mut dyn FnMut(&mut Self, Px) -> bool,
    ) -> Option<Vec<usize>> {
        let p0 = self.frame.grid_to_pixel_signed(from);
        if let Some(i) = self.resume_at.take() {
            // Go on where the last search from `from` stopped: its settled positions and queue
            // are still valid (the graph has not changed); expand the position it stopped at.
            let p = self.px_of(i);
            self.relax(known, i, p, h, heap);
        } else {
            self.seed(known, from, p0, h, heap);
        }
        let mut settled = 0usize;
        while let Some(i) = heap.pop() {
            if let Some(j) = heap.peek() {
                self.warm(j);
            }
            if self.nodes[i] & CLOSED != 0 {
                continue;
            }
            let d = node_cost(self.nodes[i]);
            if limit.is_some_and(|l| d > l) {
                return None;
            }
            self.nodes[i] |= CLOSED;
            settled += 1;
            if settled == EXHAUST_CHECK && self.exhaust_check && self.nothing_gains(known, done) {
                return None;
            }
            let p = self.px_of(i);
            // A final clean-up's `done` is false wherever `no_gain` holds: most positions it
            // settles (asked here without the call).
            if !(self.exhaust_check && self.no_gain.contains(i)) && done(self, p) {
                self.resume_at = Some(i);
                let mut path = vec![i];
                let mut c = i;
                while let Some(k) = node_move(self.nodes[c]) {
                    let (col, row) = self.px_of(c);
                    c = self
                        .idx((col - NB[k].0, row - NB[k].1))
                        .expect("parents are in the image");
                    path.push(c);
                }
                path.reverse();
                return Some(path);
            }
            self.relax(known, i, p, h, heap);
        }
        None
    }

    /// Loads the state of position `j` and of the rows above and below it (what settling it
    /// reads) without using it: the next position popped is known one step ahead, and its
    /// loads, mostly cache misses, then overlap with the work on the current one.
    #[inline]
    fn warm(&self, j: usize) {
        let w = self.frame.width;
        let n = |k: usize| self.nodes.get(k).copied().unwrap_or(0);
        std::hint::black_box((
            n(j),
            n(j.wrapping_sub(w)),
            n(j.wrapping_add(w)),
            self.edges.get(j).copied(),
        ));
    }

    /// Can the running search (a final clean-up's, whose `done` is false wherever `no_gain`
    /// holds) find nothing more? Judges every pixel outside `no_gain` where the robot may fit:
    /// when each is not done, or cannot be reached ([`Self::cut_off`]), the search would
    /// settle the rest of its component and find nothing, so it may stop. Stops at the first
    /// one done and reachable.
    fn nothing_gains(
        &mut self,
        known: &KnownMap,
        done: &mut dyn FnMut(&mut Self, Px) -> bool,
    ) -> bool {
        let n = self.nodes.len();
        let bits = crate::bits::BLOCK_BITS;
        for b in 0..self.no_gain.as_slice().len() {
            let mut todo = !self.no_gain.as_slice()[b] & !self.unreach.as_slice()[b];
            while todo != 0 {
                let i = b * bits + todo.trailing_zeros() as usize;
                todo &= todo - 1;
                if i >= n {
                    break;
                }
                if self.s0[i] != 2
                    && !self.unreach.contains(i)
                    && done(self, self.px_of(i))
                    && !self.cut_off(known, i)
                {
                    return false;
                }
            }
        }
        true
    }

    /// Is position `i` out of the running search's reach? Walks back from it over the moves
    /// the search would make (from positions where the robot fits, known free); when that
    /// walk ends (within [`CUT_OFF_MAX`] positions) without meeting a position the search
    /// has reached or queued, no way leads from the search's start to `i`, and every position
    /// met is marked in `unreach` (valid for this search and its resumptions: the known map
    /// does not change meanwhile).
    fn cut_off(&mut self, known: &KnownMap, i: usize) -> bool {
        let gen = self.generation;
        let mut stack = vec![i];
        let mut met = vec![i];
        self.met.insert(i);
        let mut cut = true;
        while let Some(v) = stack.pop() {
            if node_gen(self.nodes[v]) == gen || met.len() > CUT_OFF_MAX {
                cut = false;
                break;
            }
            let pv = self.px_of(v);
            for (k, d) in NB.iter().enumerate() {
                // From `u` the move `NB[k]` leads to `v`.
                let u = (pv.0 - d.0, pv.1 - d.1);
                let Some(j) = self.idx(u) else { continue };
                if self.met.contains(j)
                    || self.in_s0(known, u) != Some(true)
                    || !self.edge(known, u, k)
                {
                    continue;
                }
                self.met.insert(j);
                met.push(j);
                stack.push(j);
            }
        }
        for &j in &met {
            self.met.set(j, false);
            if cut {
                self.unreach.insert(j);
                self.unreach_marked.push(j);
            }
        }
        cut
    }

    /// The positions next to grid point `from` that it reaches by a known-free move, queued.
    fn seed<H: Fn(&Self, Px) -> u64>(
        &mut self,
        known: &KnownMap,
        from: Point,
        p0: Px,
        h: &H,
        heap: &mut BucketQueue,
    ) {
        let gen = self.generation;
        for dr in -1..=1 {
            for dc in -1..=1 {
                let p = (p0.0 + dc, p0.1 + dr);
                let Some(i) = self.idx(p) else { continue };
                if self.in_s0(known, p) != Some(true) || !self.seg_free(known, from, self.center(p))
                {
                    continue;
                }
                let d = (from.dist(self.center(p)) * COST_ORTHO as f64).round() as u64;
                let n = self.nodes[i];
                if node_gen(n) != gen || d < node_cost(n) {
                    self.nodes[i] = node(d, None, gen);
                    heap.push(d + h(self, p), i);
                }
            }
        }
    }

    /// Queues the neighbours of settled position `i` (pixel `p`; search cost in `dist`).
    fn relax<H: Fn(&Self, Px) -> u64>(
        &mut self,
        known: &KnownMap,
        i: usize,
        p: Px,
        h: &H,
        heap: &mut BucketQueue,
    ) {
        let gen = self.generation;
        let d = node_cost(self.nodes[i]);
        let (w, h_img) = (self.frame.width as i64, self.frame.height as i64);
        let memo = self.edges[i];
        let (edges, blocked) = (memo[FREE], memo[BLOCKED]);
        // The moves to try: those not known blocked (walls, positions where the robot does
        // not fit) that stay in the image, one bit each, in the order of `NB`.
        let mut todo = !blocked;
        // The neighbours' states are read first, all at once (independent loads, mostly
        // cache misses, overlap); the loop below writes only neighbours, each once.
        let mut ns = [0 as Node; 8];
        if p.0 > 0 && p.1 > 0 && p.0 < w - 1 && p.1 < h_img - 1 {
            // Inside the image's rim every neighbour is in it: the three rows around `i`, read
            // whole (a move known blocked leads onto the same cache lines) as three runs of
            // three from the first one (`i - width - 1`; fixed-size: no check per neighbour).
            let wu = self.frame.width;
            let first = i - wu - 1;
            let row = |o: usize| -> [Node; 3] {
                self.nodes[first + o..first + o + 3]
                    .try_into()
                    .expect("three nodes")
            };
            let (up, mid, down) = (row(0), row(wu), row(2 * wu));
            ns = [
                mid[2], up[2], up[1], up[0], mid[0], down[0], down[1], down[2],
            ];
        } else {
            for k in 0..8 {
                let q = (p.0 + NB[k].0, p.1 + NB[k].1);
                if q.0 >= 0 && q.1 >= 0 && q.0 < w && q.1 < h_img {
                    ns[k] = self.nodes[(q.1 * w + q.0) as usize];
                } else {
                    todo &= !(1 << k);
                }
            }
        }
        // Settled or no better: skip before judging the move (judging only fills memos).
        // Judged for all eight at once, without branches (the states were read above and
        // the loop below writes each neighbour once, so the order does not matter).
        let mut better = 0u8;
        for k in 0..8 {
            let n = ns[k];
            let nd = d + STEP_COST[k];
            let skip = node_gen(n) == gen && (n & CLOSED != 0 || nd >= node_cost(n));
            better |= u8::from(!skip) << k;
        }
        todo &= better;
        while todo != 0 {
            let k = todo.trailing_zeros() as usize;
            todo &= todo - 1;
            let nd = d + STEP_COST[k];
            // The memo first (most moves were judged by an earlier search).
            if edges & (1 << k) == 0 && !self.edge(known, p, k) {
                continue;
            }
            // In the image (checked above): the neighbour's index.
            let j = (i as i64 + NB[k].1 * w + NB[k].0) as usize;
            self.nodes[j] = node(nd, Some(k), gen);
            heap.push(nd + h(self, (p.0 + NB[k].0, p.1 + NB[k].1)), j);
        }
    }

    /// A transfer from world point `from` to world point `to` over positions (A*), merged into
    /// known-free straight segments; `None` when no known-free way exists.
    pub(crate) fn route(&mut self, known: &KnownMap, from: Point, to: Point) -> Option<Vec<Point>> {
        let (gf, gt) = (
            self.frame.world_to_grid_snapped(from),
            self.frame.world_to_grid_snapped(to),
        );
        if self.seg_free(known, gf, gt) {
            return Some(vec![to]);
        }
        let path = self.search(known, gf, None, Some(gt), false, &mut |s, p| {
            within_1_5(s.center(p), gt) && s.seg_free(known, s.center(p), gt)
        })?;
        let mut pts = vec![gf];
        pts.extend(path.iter().map(|&i| self.center(self.px_of(i))));
        pts.push(gt);
        // Long known-free lines of sight: gallop forward, then bisect back to a free one.
        let mut out = Vec::new();
        let mut a = 0;
        let n = pts.len();
        while a + 1 < n {
            let (mut good, mut step) = (a + 1, 1);
            let mut bad = n;
            while good + step < n && self.seg_free(known, pts[a], pts[good + step]) {
                good += step;
                step *= 2;
            }
            if good + step < n {
                bad = good + step;
            }
            while bad - good > 1 {
                let mid = good + (bad - good) / 2;
                if self.seg_free(known, pts[a], pts[mid]) {
                    good = mid;
                } else {
                    bad = mid;
                }
            }
            out.push(self.world(pts[good]));
            a = good;
        }
        if let Some(last) = out.last_mut() {
            *last = to;
        }
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::{
        node, node_cost, node_gen, node_move, route_heuristic, within_1_5, BucketQueue, BUCKET_MAX,
        BUCKET_SHIFT, CLOSED, COST_ORTHO, NODE_COST_SHIFT, NODE_GENS, ROUTE_WEIGHT,
    };
    use crate::geometry::Point;
    use proptest::prelude::*;
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;

    /// A key: mostly a few pixel steps of search cost, sometimes past the last bucket.
    fn key() -> impl Strategy<Value = u64> {
        prop_oneof![
            8 => 0u64..20_000,
            1 => Just((BUCKET_MAX as u64) << BUCKET_SHIFT).prop_flat_map(|b| b..b + 5_000),
        ]
    }

    /// The heuristic's fast square root gives `hypot`'s floor: random points, points on the
    /// same row or column as the goal, distances that are whole numbers of steps.
    #[test]
    fn route_heuristic_is_hypot_floor() {
        let mut rng = crate::rng::SplitMix64::new(0x4079_0715);
        let want =
            |c: Point, g: Point| (c.dist(g) * ROUTE_WEIGHT * COST_ORTHO as f64).floor() as u64;
        for k in 0..200_000 {
            let g = Point::new(rng.range(-10.0, 3000.0), rng.range(-10.0, 3000.0));
            let c = match k % 4 {
                0 => Point::new(
                    rng.range(0.0, 3000.0).floor() + 0.5,
                    rng.range(0.0, 3000.0).floor() + 0.5,
                ),
                1 => Point::new(g.x, g.y + rng.range(-500.0, 500.0).round() / 3.0),
                2 => Point::new(
                    g.x + 3.0 * rng.range(0.0, 100.0).round(),
                    g.y + 4.0 * rng.range(0.0, 100.0).round(),
                ),
                _ => Point::new(rng.range(-1e5, 1e5), rng.range(-1e5, 1e5)),
            };
            assert_eq!(route_heuristic(c, g), want(c, g), "{c:?} {g:?}");
        }
    }

    /// The goal test's squared fast path agrees with `hypot`: random points, points on the
    /// circle of radius 1.5 (up to rounding) and at whole-pixel offsets.
    #[test]
    fn within_1_5_is_hypot_test() {
        let mut rng = crate::rng::SplitMix64::new(0x0715_1500);
        for k in 0..200_000 {
            let g = Point::new(rng.range(-10.0, 3000.0), rng.range(-10.0, 3000.0));
            let c = match k % 4 {
                0 => Point::new(g.x + rng.range(-3.0, 3.0), g.y + rng.range(-3.0, 3.0)),
                1 => {
                    let a = rng.range(0.0, std::f64::consts::TAU);
                    Point::new(g.x + 1.5 * a.cos(), g.y + 1.5 * a.sin())
                }
                2 => Point::new(
                    g.x + rng.range(-3.0, 3.0).round(),
                    g.y + rng.range(-3.0, 3.0).round(),
                ),
                _ => Point::new(g.x + 1.5, g.y + rng.range(-1e-6, 1e-6)),
            };
            assert_eq!(within_1_5(c, g), c.dist(g) < 1.5, "{c:?} {g:?}");
        }
    }

    /// A node gives back the cost, move and generation it was made of, with or without the
    /// settled bit, at the extremes of every field.
    #[test]
    fn node_fields_round_trip() {
        let max_cost = (1u64 << (63 - NODE_COST_SHIFT)) - 1;
        for dist in [0, 1, 1414, 123_456_789, max_cost] {
            for k in [None, Some(0), Some(3), Some(7)] {
                for gen in [1, 2, NODE_GENS - 1] {
                    for closed in [0, CLOSED] {
                        let n = node(dist, k, gen) | closed;
                        assert_eq!(node_cost(n), dist);
                        assert_eq!(node_move(n), k);
                        assert_eq!(node_gen(n), gen);
                        assert_eq!(n & CLOSED, closed);
                    }
                }
            }
        }
    }

    proptest! {
        /// The bucket queue pops exactly what a binary min-heap on `(key, index)` pops, for any
        /// mix of pushes (keys below already popped ones included), pops and clears.
        #[test]
        fn bucket_queue_pops_in_heap_order(
            ops in proptest::collection::vec((0u8..10, key(), 0usize..64), 0..400)
        ) {
            let mut q = BucketQueue::default();
            let mut h: BinaryHeap<Reverse<(u64, usize)>> = BinaryHeap::new();
            for (op, k, i) in ops {
                match op {
                    0..=5 => {
                        q.push(k, i);
                        h.push(Reverse((k, i)));
                    }
                    6..=8 => {
                        if let Some(j) = q.peek() {
                            prop_assert_eq!(Some(j), h.peek().map(|Reverse((_, i))| *i));
                        }
                        prop_assert_eq!(q.pop(), h.pop().map(|Reverse((_, i))| i));
                    }
                    _ => {
                        q.clear();
                        h.clear();
                    }
                }
            }
            while let Some(Reverse((_, i))) = h.pop() {
                prop_assert_eq!(q.pop(), Some(i));
            }
            prop_assert_eq!(q.pop(), None);
        }
    }
}
