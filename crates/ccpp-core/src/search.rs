//! One deterministic graph search for every planner: breadth-first search, flood fill,
//! Dijkstra and A\* over nodes numbered `0..n`, with integer costs, a documented tie order and
//! reusable buffers.
//!
//! # Model
//!
//! A graph is given by the caller, never stored: nodes are dense `u32` indices (a tile or pixel
//! rectangle numbered row-major, a list of blocks, ...), and the neighbours of a node are
//! produced on demand, either by a closure ([`SearchSpace::bfs`], [`SearchSpace::flood_fill`],
//! [`SearchSpace::dijkstra`], [`SearchSpace::astar`]) or by the caller's own loop around the
//! *driver* calls ([`SearchSpace::pop`] / [`SearchSpace::relax`] for best-first search,
//! [`SearchSpace::pop_fifo`] / [`SearchSpace::discover`] for breadth-first search). The driver
//! form lets a planner test its goal, bound the search or skip expensive edge checks towards
//! settled nodes ([`SearchSpace::is_settled`]) in the middle of an expansion, with no closure
//! borrowing its state.
//!
//! # Determinism: the tie order
//!
//! * **Best-first** ([`SearchSpace::dijkstra`], [`SearchSpace::astar`], [`SearchSpace::pop`]):
//!   nodes are settled in increasing `(f, tie key, node index)`, where `f = g + h` (`h = 0` for
//!   Dijkstra) and the tie key is chosen by the space's [`TieBreak`] type: [`ByIndex`] (no key:
//!   equal `f` settles the smaller index first, so a row-major numbering means smaller row,
//!   then smaller column), [`DeeperFirst`] (smaller `h` first, i.e. the node nearer the goal;
//!   A\* then follows one path instead of widening a plateau) or [`ShallowerFirst`] (smaller `g`
//!   first). A node's parent is the neighbour that gave it its final cost *first*: later equal
//!   costs never replace it.
//! * **Breadth-first** ([`SearchSpace::bfs`], [`SearchSpace::flood_fill`],
//!   [`SearchSpace::pop_fifo`]): first in, first out; the sources in the order given, then each
//!   node's neighbours in the order the caller lists them. A node's parent is the node that
//!   discovered it first.
//!
//! No hashing anywhere: the same graph and the same calls give the same order and the same
//! paths on every run and platform.
//!
//! # Reuse
//!
//! A [`SearchSpace`] holds one record per node (cost, parent, generation stamp; 12 bytes for
//! `u32` costs, 16 for `u64`), the heap and the FIFO. [`SearchSpace::begin`] starts a new search
//! in O(1): it bumps the generation, which makes every record stale (the stamps are cleared,
//! O(n), once every 2^31 searches). The buffers keep their capacity, so a planner that searches
//! thousands of times allocates once.
//!
//! # Example
//!
//! ```text
//!   0 1 2 3          S = node 0 (row 0, column 0), G = node 11 (row 2, column 3)
//! 0 S . . .          4-neighbour moves of cost 1 between free cells ('#' blocks)
//! 1 . # # .
//! 2 . . . G          shortest cost 5: two ways (along row 0, or down column 0)
//! ```
//!
//! ```
//! use ccpp_core::search::{ByIndex, SearchSpace};
//! let rows = ["S...", ".##.", "...G"];
//! let (w, h) = (4u32, 3u32);
//! let free = |v: u32| rows[(v / w) as usize].as_bytes()[(v % w) as usize] != b'#';
//! let mut space: SearchSpace<u32, ByIndex> = SearchSpace::new((w * h) as usize);
//! let goal = space.dijkstra(
//!     [(0, 0)],
//!     |v, out| {
//!         let (c, r) = (v % w, v / w);
//!         // Neighbour order E, S, W, N: it decides nothing here (ties go by node index).
//!         if c + 1 < w && free(v + 1) { out.push((v + 1, 1)); }
//!         if r + 1 < h && free(v + w) { out.push((v + w, 1)); }
//!         if c > 0 && free(v - 1) { out.push((v - 1, 1)); }
//!         if r > 0 && free(v - w) { out.push((v - w, 1)); }
//!     },
//!     |v, _| v == 11,
//! );
//! assert_eq!(goal, Some(11));
//! assert_eq!(space.dist(11), Some(5));
//! // Node 3 (row 0) settles before node 8 (row 2) at cost 3, so it is G's parent.
//! assert_eq!(space.path_to(11), vec![0, 1, 2, 3, 7, 11]);
//! ```

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::fmt::Debug;
use std::marker::PhantomData;
use std::ops::Add;

/// An integer path cost: non-negative, totally ordered, added along a path.
pub trait Cost: Copy + Ord + Add<Output = Self> + Debug {
    /// The cost of an empty path.
    const ZERO: Self;
    /// One breadth-first step (the depth unit of [`SearchSpace::bfs`]).
    const ONE: Self;
}

impl Cost for u32 {
    const ZERO: Self = 0;
    const ONE: Self = 1;
}

impl Cost for u64 {
    const ZERO: Self = 0;
    const ONE: Self = 1;
}

/// The tie key between heap entries of equal `f = g + h` (the node index decides last).
pub trait TieBreak<C: Cost> {
    /// The key compared after `f` (smaller first).
    type Key: Copy + Ord + Debug;
    /// The key of a node reached with cost `g` and heuristic `h`.
    fn key(g: C, h: C) -> Self::Key;
}

/// Ties of equal `f` go to the smaller node index (no extra key).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ByIndex;

/// Ties of equal `f` go to the smaller `h` (the node nearer the goal), then the smaller index.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DeeperFirst;

/// Ties of equal `f` go to the smaller `g` (the node nearer the source), then the smaller index.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ShallowerFirst;

impl<C: Cost> TieBreak<C> for ByIndex {
    type Key = ();
    #[inline]
    fn key(_: C, _: C) {}
}

impl<C: Cost> TieBreak<C> for DeeperFirst {
    type Key = C;
    #[inline]
    fn key(_: C, h: C) -> C {
        h
    }
}

impl<C: Cost> TieBreak<C> for ShallowerFirst {
    type Key = C;
    #[inline]
    fn key(g: C, _: C) -> C {
        g
    }
}

/// Parent of a source node.
const NONE: u32 = u32::MAX;

/// Per-node record: valid when `stamp` is the current generation (reached) or the generation
/// plus one (settled).
#[derive(Clone, Copy, Debug)]
struct Node<C> {
    dist: C,
    parent: u32,
    stamp: u32,
}

/// A node taken off the heap by [`SearchSpace::pop`]: now settled with its final cost.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Settled<C> {
    /// The node.
    pub node: u32,
    /// Its cost from the nearest source.
    pub g: C,
    /// Its heap priority `g + h`.
    pub f: C,
}

/// Reusable buffers for searches over nodes `0..len` with costs `C` and tie order `T` (see the
/// [module documentation](self) for the order and the reuse).
#[derive(Clone, Debug)]
pub struct SearchSpace<C: Cost = u64, T: TieBreak<C> = ByIndex> {
    nodes: Vec<Node<C>>,
    /// Even, >= 2: reached nodes carry `gen`, settled ones `gen + 1`.
    gen: u32,
    heap: BinaryHeap<Reverse<(C, T::Key, u32)>>,
    /// Breadth-first queue; after the search it lists every reached node in discovery order.
    fifo: Vec<u32>,
    head: usize,
    /// Neighbour buffers handed to the closures.
    edges: Vec<(u32, C)>,
    nbrs: Vec<u32>,
    _tie: PhantomData<T>,
}

impl<C: Cost, T: TieBreak<C>> Default for SearchSpace<C, T> {
    fn default() -> Self {
        Self::new(0)
    }
}

impl<C: Cost, T: TieBreak<C>> SearchSpace<C, T> {
    /// Buffers for nodes `0..len`.
    pub fn new(len: usize) -> Self {
        Self {
            nodes: vec![
                Node {
                    dist: C::ZERO,
                    parent: NONE,
                    stamp: 0,
                };
                len
            ],
            gen: 2,
            heap: BinaryHeap::new(),
            fifo: Vec::new(),
            head: 0,
            edges: Vec::new(),
            nbrs: Vec::new(),
            _tie: PhantomData,
        }
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// `true` when there are no nodes.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Grows the space to at least `len` nodes (new nodes unreached); never shrinks.
    pub fn ensure_len(&mut self, len: usize) {
        if len > self.nodes.len() {
            self.nodes.resize(
                len,
                Node {
                    dist: C::ZERO,
                    parent: NONE,
                    stamp: 0,
                },
            );
        }
    }

    /// Starts a new search: every node unreached, heap and queue empty. O(1) (amortised).
    pub fn begin(&mut self) {
        self.gen = self.gen.wrapping_add(2);
        if self.gen < 2 {
            for n in &mut self.nodes {
                n.stamp = 0;
            }
            self.gen = 2;
        }
        self.heap.clear();
        self.fifo.clear();
        self.head = 0;
    }

    /// Has `v` been reached in the current search (it has a cost and a parent)?
    #[inline]
    pub fn is_reached(&self, v: u32) -> bool {
        self.nodes[v as usize].stamp & !1 == self.gen
    }

    /// Has `v` been settled (taken off the heap) in the current search?
    #[inline]
    pub fn is_settled(&self, v: u32) -> bool {
        self.nodes[v as usize].stamp == self.gen + 1
    }

    /// The cost of `v` in the current search (final once settled); `None` when unreached.
    #[inline]
    pub fn dist(&self, v: u32) -> Option<C> {
        let n = &self.nodes[v as usize];
        (n.stamp & !1 == self.gen).then_some(n.dist)
    }

    /// The parent of `v` in the current search; `None` for a source or an unreached node.
    #[inline]
    pub fn parent(&self, v: u32) -> Option<u32> {
        let n = &self.nodes[v as usize];
        (n.stamp & !1 == self.gen && n.parent != NONE).then_some(n.parent)
    }

    /// The path from a source to the reached node `v`, both included, source first.
    pub fn path_to(&self, v: u32) -> Vec<u32> {
        let mut out = Vec::new();
        self.path_into(v, &mut out);
        out
    }

    /// Like [`Self::path_to`], into `out` (cleared first); empty when `v` is unreached.
    pub fn path_into(&self, v: u32, out: &mut Vec<u32>) {
        out.clear();
        if !self.is_reached(v) {
            return;
        }
        let mut c = v;
        out.push(c);
        while self.nodes[c as usize].parent != NONE {
            c = self.nodes[c as usize].parent;
            out.push(c);
        }
        out.reverse();
    }

    #[inline]
    fn set(&mut self, v: u32, dist: C, parent: u32) {
        let gen = self.gen;
        let n = &mut self.nodes[v as usize];
        n.stamp = gen;
        n.dist = dist;
        n.parent = parent;
    }

    /// Records cost `dist` and parent `from` (`None`: a source) for `v` without queueing it,
    /// for callers that run their own queue (a bucket queue over small integer costs).
    #[inline]
    pub fn assign(&mut self, v: u32, dist: C, from: Option<u32>) {
        self.set(v, dist, from.unwrap_or(NONE));
    }

    // ---- best-first driver -------------------------------------------------------------

    /// Adds source `v` with start cost `g` and heuristic `h` (kept only if it improves `v`).
    pub fn push_source(&mut self, v: u32, g: C, h: C) {
        if !self.is_settled(v) && self.improves(v, g) {
            self.update(NONE, v, g, h);
        }
    }

    /// Would cost `g` improve the unsettled node `v` (unreached, or strictly cheaper)?
    #[inline]
    pub fn improves(&self, v: u32, g: C) -> bool {
        let n = &self.nodes[v as usize];
        n.stamp & !1 != self.gen || g < n.dist
    }

    /// Gives `v` cost `g` and parent `from` and queues it with priority `g + h`; use after
    /// [`Self::improves`] (the split lets `h` be computed only for improving edges, by code
    /// that borrows the caller's state).
    #[inline]
    pub fn update(&mut self, from: u32, v: u32, g: C, h: C) {
        self.set(v, g, from);
        self.heap.push(Reverse((g + h, T::key(g, h), v)));
    }

    /// Relaxes the edge `from -> v` reaching `v` with cost `g`: unless `v` is settled or already
    /// as cheap, records it and queues it with priority `g + h()`. Returns whether it did.
    #[inline]
    pub fn relax(&mut self, from: u32, v: u32, g: C, h: impl FnOnce() -> C) -> bool {
        if self.is_settled(v) || !self.improves(v, g) {
            return false;
        }
        self.update(from, v, g, h());
        true
    }

    /// Settles the next node in `(f, tie key, index)` order (stale heap entries are skipped);
    /// `None` when the heap is empty.
    #[inline]
    pub fn pop(&mut self) -> Option<Settled<C>> {
        while let Some(Reverse((f, _, v))) = self.heap.pop() {
            let gen = self.gen;
            let n = &mut self.nodes[v as usize];
            if n.stamp == gen + 1 {
                continue;
            }
            n.stamp = gen + 1;
            return Some(Settled {
                node: v,
                g: n.dist,
                f,
            });
        }
        None
    }

    // ---- breadth-first driver ----------------------------------------------------------

    /// Adds source `v` (depth 0) to the queue unless already reached.
    pub fn push_fifo_source(&mut self, v: u32) {
        if !self.is_reached(v) {
            self.set(v, C::ZERO, NONE);
            self.fifo.push(v);
        }
    }

    /// Takes the next node off the queue, with its depth.
    #[inline]
    pub fn pop_fifo(&mut self) -> Option<(u32, C)> {
        let v = *self.fifo.get(self.head)?;
        self.head += 1;
        Some((v, self.nodes[v as usize].dist))
    }

    /// Discovers `v` from the reached node `from` (depth + 1, parent `from`) unless `v` is
    /// already reached; returns whether it was new.
    #[inline]
    pub fn discover(&mut self, from: u32, v: u32) -> bool {
        if self.is_reached(v) {
            return false;
        }
        let d = self.nodes[from as usize].dist + C::ONE;
        self.set(v, d, from);
        self.fifo.push(v);
        true
    }

    /// Every node reached by the current breadth-first search, in discovery order.
    pub fn fifo_order(&self) -> &[u32] {
        &self.fifo
    }

    // ---- closure forms -----------------------------------------------------------------

    /// Breadth-first search from `sources`: `neighbours(v, out)` pushes the nodes reachable
    /// from `v` in one step (in the order that decides ties); returns the first dequeued node
    /// for which `goal` holds (sources included). Starts a new search.
    pub fn bfs(
        &mut self,
        sources: impl IntoIterator<Item = u32>,
        mut neighbours: impl FnMut(u32, &mut Vec<u32>),
        mut goal: impl FnMut(u32) -> bool,
    ) -> Option<u32> {
        self.begin();
        for s in sources {
            self.push_fifo_source(s);
        }
        let mut buf = std::mem::take(&mut self.nbrs);
        let mut found = None;
        while let Some((v, _)) = self.pop_fifo() {
            if goal(v) {
                found = Some(v);
                break;
            }
            buf.clear();
            neighbours(v, &mut buf);
            for &n in &buf {
                self.discover(v, n);
            }
        }
        self.nbrs = buf;
        found
    }

    /// Every node reachable from `sources`, in breadth-first order (see [`Self::bfs`]); depths
    /// and parents stay queryable until the next search.
    pub fn flood_fill(
        &mut self,
        sources: impl IntoIterator<Item = u32>,
        neighbours: impl FnMut(u32, &mut Vec<u32>),
    ) -> &[u32] {
        self.bfs(sources, neighbours, |_| false);
        &self.fifo
    }

    /// Dijkstra from `sources` (node, start cost): `neighbours(v, out)` pushes `(node, step
    /// cost)`; returns the first settled node for which `goal(node, cost)` holds (in the tie
    /// order of `T`). Without a goal (`|_, _| false`) it settles the whole component, whose
    /// costs [`Self::dist`] then gives. Starts a new search.
    pub fn dijkstra(
        &mut self,
        sources: impl IntoIterator<Item = (u32, C)>,
        neighbours: impl FnMut(u32, &mut Vec<(u32, C)>),
        goal: impl FnMut(u32, C) -> bool,
    ) -> Option<u32> {
        self.astar(sources, neighbours, |_| C::ZERO, goal)
    }

    /// A\* from `sources` with heuristic `h` (admissible and consistent for shortest paths;
    /// an inflated `h` gives a bounded-suboptimal search: settled nodes are never reopened).
    /// Otherwise as [`Self::dijkstra`].
    pub fn astar(
        &mut self,
        sources: impl IntoIterator<Item = (u32, C)>,
        mut neighbours: impl FnMut(u32, &mut Vec<(u32, C)>),
        mut h: impl FnMut(u32) -> C,
        mut goal: impl FnMut(u32, C) -> bool,
    ) -> Option<u32> {
        self.begin();
        for (s, g) in sources {
            let hs = h(s);
            self.push_source(s, g, hs);
        }
        let mut buf = std::mem::take(&mut self.edges);
        let mut found = None;
        while let Some(s) = self.pop() {
            if goal(s.node, s.g) {
                found = Some(s.node);
                break;
            }
            buf.clear();
            neighbours(s.node, &mut buf);
            for &(v, step) in &buf {
                self.relax(s.node, v, s.g + step, || h(v));
            }
        }
        self.edges = buf;
        found
    }

    /// Test hook: the generation just before it wraps.
    #[cfg(test)]
    fn force_generation(&mut self, gen: u32) {
        self.gen = gen;
    }
}

/// Which neighbours a pixel has in a grid flood fill ([`fill_runs`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Connectivity {
    /// Left, right, up, down.
    Four,
    /// The four and the diagonals.
    Eight,
}

/// Flood-fills the component holding `seed` of the pixels for which `inside` holds, on a `w` x
/// `h` row-major grid, by horizontal runs: each run is found once, marked in `visited` whole and
/// reported once as `on_run(row, first column, last column)`. Pixels already in `visited` are
/// not entered, so one `visited` set serves to count every component of a grid. Memory: the
/// caller's bitset (an eighth of a byte a pixel) and a stack of run seeds.
///
/// ```
/// use ccpp_core::search::{fill_runs, Connectivity};
/// use fixedbitset::FixedBitSet;
/// // .#.
/// // #..   the top-left pixel touches the rest only diagonally
/// let free = [true, false, true, false, true, true];
/// let count = |c: Connectivity| {
///     let mut seen = FixedBitSet::with_capacity(6);
///     let mut n = 0;
///     fill_runs(3, 2, |i| free[i], 0, c, &mut seen, |_, lo, hi| n += hi - lo + 1);
///     n
/// };
/// assert_eq!(count(Connectivity::Four), 1);
/// assert_eq!(count(Connectivity::Eight), 4);
/// ```
pub fn fill_runs(
    w: usize,
    h: usize,
    inside: impl Fn(usize) -> bool,
    seed: usize,
    connectivity: Connectivity,
    visited: &mut fixedbitset::FixedBitSet,
    mut on_run: impl FnMut(usize, usize, usize),
) {
    if w == 0 || seed >= w * h || !inside(seed) {
        return;
    }
    let wider = usize::from(connectivity == Connectivity::Eight);
    let mut stack = vec![seed];
    while let Some(i) = stack.pop() {
        if visited.contains(i) {
            continue;
        }
        let (row, col) = (i / w, i % w);
        let base = row * w;
        // The whole run holding `i` is unvisited: runs are always filled whole.
        let mut lo = col;
        while lo > 0 && inside(base + lo - 1) {
            lo -= 1;
        }
        let mut hi = col;
        while hi + 1 < w && inside(base + hi + 1) {
            hi += 1;
        }
        visited.insert_range(base + lo..base + hi + 1);
        on_run(row, lo, hi);
        // The rows above and below: the run's columns, one wider on each side for 8-connected.
        let (c0, c1) = (lo.saturating_sub(wider), (hi + wider).min(w - 1));
        for nrow in [row.wrapping_sub(1), row + 1] {
            if nrow >= h {
                continue;
            }
            let nb = nrow * w;
            let mut c = c0;
            while c <= c1 {
                if inside(nb + c) && !visited.contains(nb + c) {
                    stack.push(nb + c);
                    // One seed per run: skip the rest of it.
                    while c <= c1 && inside(nb + c) {
                        c += 1;
                    }
                } else {
                    c += 1;
                }
            }
        }
    }
}

/// A priority queue of `(key, index)` pairs popping the smallest pair (key, then index) for
/// keys that never go below the last popped key (Dijkstra costs, A* `f` with a consistent
/// heuristic): a radix heap over the keys, plus a binary heap of the indices whose key equals
/// the current minimum. Every pair in a search is distinct, so the pop order is exactly that of
/// a binary heap of the pairs. A key below the minimum is still popped in order (slowly).
///
/// The planners' own hot searches use it where a binary heap of the pairs was the cost: BA*'s
/// backtracking searches, and BCD's pixel A* of transfers (key `f << 32 | g`: the order
/// `(f, g, index)`).
#[derive(Clone, Debug)]
pub(crate) struct MonotoneQueue {
    /// The key of the current group (the last popped minimum).
    last: u64,
    /// Indices whose key is `last`.
    current: BinaryHeap<Reverse<u32>>,
    /// Bucket `b` (1..=64) holds the pairs whose key's highest bit differing from `last` is
    /// bit `b - 1`; bucket 0 is unused.
    buckets: Vec<Vec<(u64, u32)>>,
    /// Bit `b` set when bucket `b` may be non-empty.
    nonempty: u128,
}

impl MonotoneQueue {
    pub(crate) fn new() -> Self {
        Self {
            last: 0,
            current: BinaryHeap::new(),
            buckets: vec![Vec::new(); 65],
            nonempty: 0,
        }
    }

    pub(crate) fn clear(&mut self) {
        self.last = 0;
        self.current.clear();
        while self.nonempty != 0 {
            let b = self.nonempty.trailing_zeros() as usize;
            self.nonempty &= self.nonempty - 1;
            self.buckets[b].clear();
        }
    }

    #[inline]
    fn bucket(last: u64, key: u64) -> usize {
        64 - (key ^ last).leading_zeros() as usize
    }

    #[inline]
    pub(crate) fn push(&mut self, key: u64, index: u32) {
        if key < self.last {
            self.lower(key);
        }
        if key == self.last {
            self.current.push(Reverse(index));
        } else {
            let b = Self::bucket(self.last, key);
            self.buckets[b].push((key, index));
            self.nonempty |= 1 << b;
        }
    }

    /// Makes `key` (below the current minimum) the current key, redistributing every pair:
    /// keeps the exact order should a key ever go below the minimum (a heuristic rounding).
    #[cold]
    fn lower(&mut self, key: u64) {
        let mut all: Vec<(u64, u32)> = self
            .current
            .drain()
            .map(|Reverse(i)| (self.last, i))
            .collect();
        for b in &mut self.buckets {
            all.append(b);
        }
        self.nonempty = 0;
        self.last = key;
        for (k, i) in all {
            self.push(k, i);
        }
    }

    #[inline]
    pub(crate) fn pop(&mut self) -> Option<(u64, u32)> {
        if let Some(Reverse(i)) = self.current.pop() {
            return Some((self.last, i));
        }
        if self.nonempty == 0 {
            return None;
        }
        // The lowest non-empty bucket holds the smallest keys: its minimum becomes the new
        // current key and the rest spread into lower buckets.
        let b = self.nonempty.trailing_zeros() as usize;
        self.nonempty &= !(1u128 << b);
        let mut items = std::mem::take(&mut self.buckets[b]);
        let min = items.iter().map(|&(k, _)| k).min().unwrap_or(self.last);
        self.last = min;
        for &(k, i) in &items {
            if k == min {
                self.current.push(Reverse(i));
            } else {
                let nb = Self::bucket(min, k);
                self.buckets[nb].push((k, i));
                self.nonempty |= 1 << nb;
            }
        }
        items.clear();
        self.buckets[b] = items;
        self.current.pop().map(|Reverse(i)| (self.last, i))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An ASCII grid: `#` blocked, anything else free; nodes row-major.
    struct Grid {
        w: u32,
        h: u32,
        cells: Vec<u8>,
    }

    impl Grid {
        fn parse(rows: &[&str]) -> Self {
            let w = rows[0].len() as u32;
            let cells: Vec<u8> = rows.iter().flat_map(|r| r.bytes()).collect();
            Self {
                w,
                h: rows.len() as u32,
                cells,
            }
        }

        fn find(&self, ch: u8) -> Vec<u32> {
            (0..self.cells.len() as u32)
                .filter(|&v| self.cells[v as usize] == ch)
                .collect()
        }

        fn len(&self) -> usize {
            self.cells.len()
        }

        /// Free 4-neighbours in the order E, S, W, N.
        fn n4(&self, v: u32, out: &mut Vec<u32>) {
            let (c, r) = (v % self.w, v / self.w);
            let mut cand = Vec::new();
            if c + 1 < self.w {
                cand.push(v + 1);
            }
            if r + 1 < self.h {
                cand.push(v + self.w);
            }
            if c > 0 {
                cand.push(v - 1);
            }
            if r > 0 {
                cand.push(v - self.w);
            }
            out.extend(cand.into_iter().filter(|&n| self.cells[n as usize] != b'#'));
        }

        fn n4_cost(&self, v: u32, out: &mut Vec<(u32, u32)>) {
            let mut b = Vec::new();
            self.n4(v, &mut b);
            out.extend(b.into_iter().map(|n| (n, 10)));
        }

        fn manhattan(&self, a: u32, b: u32) -> u32 {
            let (ca, ra) = (a % self.w, a / self.w);
            let (cb, rb) = (b % self.w, b / self.w);
            10 * (ca.abs_diff(cb) + ra.abs_diff(rb))
        }

        /// The grid with the path drawn as `*` (rows joined by `|`).
        fn draw(&self, path: &[u32]) -> String {
            let mut cells = self.cells.clone();
            for &v in path {
                cells[v as usize] = b'*';
            }
            cells
                .chunks(self.w as usize)
                .map(|r| String::from_utf8_lossy(r).into_owned())
                .collect::<Vec<_>>()
                .join("|")
        }
    }

    const OPEN: [&str; 4] = ["S....", ".....", ".....", "....G"];

    #[test]
    fn dijkstra_ties_go_to_the_smaller_index() {
        let g = Grid::parse(&OPEN);
        let (s, t) = (g.find(b'S')[0], g.find(b'G')[0]);
        let mut sp: SearchSpace<u32> = SearchSpace::new(g.len());
        let found = sp.dijkstra([(s, 0)], |v, o| g.n4_cost(v, o), |v, _| v == t);
        assert_eq!(found, Some(t));
        assert_eq!(sp.dist(t), Some(70));
        // Every cell's parent is the neighbour with the smaller index among the cheapest: the
        // one above (row - 1) before the one to the left, so the path runs along row 0 first.
        assert_eq!(
            g.draw(&sp.path_to(t)),
            "*****|....*|....*|....*",
            "{}",
            g.draw(&sp.path_to(t))
        );
    }

    #[test]
    fn bfs_ties_follow_the_neighbour_order() {
        let g = Grid::parse(&OPEN);
        let (s, t) = (g.find(b'S')[0], g.find(b'G')[0]);
        let mut sp: SearchSpace<u32> = SearchSpace::new(g.len());
        assert_eq!(sp.bfs([s], |v, o| g.n4(v, o), |v| v == t), Some(t));
        assert_eq!(sp.dist(t), Some(7));
        // E is listed before S, so each level is queued with its row-0 end first, and the
        // goal is discovered from its upper neighbour: the path runs along row 0 first.
        assert_eq!(g.draw(&sp.path_to(t)), "*****|....*|....*|....*");
        // Listing S before E flips it.
        let sn = |v: u32, o: &mut Vec<u32>| {
            let mut b = Vec::new();
            g.n4(v, &mut b);
            b.sort_by_key(|&n| std::cmp::Reverse(n));
            o.extend(b);
        };
        assert_eq!(sp.bfs([s], sn, |v| v == t), Some(t));
        assert_eq!(g.draw(&sp.path_to(t)), "*....|*....|*....|*****");
    }

    #[test]
    fn astar_tie_keys_choose_between_equal_paths() {
        let g = Grid::parse(&OPEN);
        let (s, t) = (g.find(b'S')[0], g.find(b'G')[0]);
        let h = |v: u32| g.manhattan(v, t);
        let mut by_index: SearchSpace<u32, ByIndex> = SearchSpace::new(g.len());
        by_index.astar([(s, 0)], |v, o| g.n4_cost(v, o), h, |v, _| v == t);
        let mut deeper: SearchSpace<u32, DeeperFirst> = SearchSpace::new(g.len());
        deeper.astar([(s, 0)], |v, o| g.n4_cost(v, o), h, |v, _| v == t);
        assert_eq!(by_index.dist(t), Some(70));
        assert_eq!(deeper.dist(t), Some(70));
        assert_eq!(g.draw(&by_index.path_to(t)), "*****|....*|....*|....*");
        assert_eq!(g.draw(&deeper.path_to(t)), "*****|....*|....*|....*");
        // Deeper-first settles only the cells of one path (plus none off it) on an open grid:
        // every f equals 70 and the smallest h is always the last discovered cell.
        let settled = |n: usize, f: &dyn Fn(u32) -> bool| (0..n as u32).filter(|&v| f(v)).count();
        let d = settled(g.len(), &|v| deeper.is_settled(v));
        let b = settled(g.len(), &|v| by_index.is_settled(v));
        assert_eq!(d, 8);
        assert!(b > d, "by index settles the plateau: {b}");
        // Shallower-first widens it completely before reaching the goal.
        let mut shallow: SearchSpace<u32, ShallowerFirst> = SearchSpace::new(g.len());
        shallow.astar([(s, 0)], |v, o| g.n4_cost(v, o), h, |v, _| v == t);
        assert_eq!(settled(g.len(), &|v| shallow.is_settled(v)), g.len());
    }

    #[test]
    fn equal_cost_goals_settle_by_index() {
        // Two goals at cost 40 from S: the one in the upper row wins.
        let g = Grid::parse(&["G....", ".....", "..S..", ".....", "....G"]);
        let s = g.find(b'S')[0];
        let goals = g.find(b'G');
        let mut sp: SearchSpace<u32> = SearchSpace::new(g.len());
        let a = sp.dijkstra([(s, 0)], |v, o| g.n4_cost(v, o), |v, _| goals.contains(&v));
        assert_eq!(a, Some(goals[0]));
        // Multi-source, listed in the other order: S's path still starts at the upper goal
        // (its cost-30 neighbour above settles first).
        let b = sp.dijkstra(
            [(goals[1], 0), (goals[0], 0)],
            |v, o| g.n4_cost(v, o),
            |v, _| v == s,
        );
        assert_eq!(b, Some(s));
        assert_eq!(sp.path_to(s).first(), Some(&goals[0]));
    }

    #[test]
    fn unreachable_goal_gives_none_and_the_component() {
        let g = Grid::parse(&["S.#..", "..#.G", "###.."]);
        let (s, t) = (g.find(b'S')[0], g.find(b'G')[0]);
        let mut sp: SearchSpace<u64> = SearchSpace::new(g.len());
        let mut sp32: SearchSpace<u32> = SearchSpace::new(g.len());
        assert_eq!(
            sp32.dijkstra([(s, 0)], |v, o| g.n4_cost(v, o), |v, _| v == t),
            None
        );
        assert_eq!(sp32.dist(t), None);
        assert!(sp32.path_to(t).is_empty());
        assert_eq!(sp.bfs([s], |v, o| g.n4(v, o), |v| v == t), None);
        let mut comp = sp.flood_fill([s], |v, o| g.n4(v, o)).to_vec();
        comp.sort_unstable();
        assert_eq!(comp, vec![0, 1, 5, 6]);
        assert_eq!(sp.dist(6), Some(2));
        assert_eq!(sp.parent(6), Some(1));
        assert_eq!(sp.parent(0), None);
    }

    #[test]
    fn a_reused_space_answers_like_a_fresh_one() {
        let g = Grid::parse(&["S..#....", ".#.#.##.", ".#...#..", ".####.#.", "......#G"]);
        let (s, t) = (g.find(b'S')[0], g.find(b'G')[0]);
        let run = |sp: &mut SearchSpace<u32>, a: u32, b: u32| {
            let f = sp.astar(
                [(a, 0)],
                |v, o| g.n4_cost(v, o),
                |v| g.manhattan(v, b),
                |v, _| v == b,
            );
            (f, sp.path_to(b), sp.dist(b))
        };
        let mut reused: SearchSpace<u32> = SearchSpace::new(g.len());
        let pairs = [(s, t), (t, s), (s, 12), (12, 3), (s, t)];
        for &(a, b) in &pairs {
            let mut fresh: SearchSpace<u32> = SearchSpace::new(g.len());
            assert_eq!(run(&mut reused, a, b), run(&mut fresh, a, b), "{a} -> {b}");
        }
        // Interleaved BFS searches on the same buffers.
        let mut fresh: SearchSpace<u32> = SearchSpace::new(g.len());
        fresh.bfs([t], |v, o| g.n4(v, o), |_| false);
        reused.bfs([t], |v, o| g.n4(v, o), |_| false);
        assert_eq!(fresh.fifo_order(), reused.fifo_order());
        // A wrapping generation clears the stamps instead of reviving old records.
        reused.force_generation(u32::MAX - 1);
        reused.bfs([s], |v, o| g.n4(v, o), |_| false);
        assert!(reused.is_reached(t));
        reused.begin();
        assert!((0..g.len() as u32).all(|v| !reused.is_reached(v)));
        assert_eq!(run(&mut reused, s, t), {
            let mut f: SearchSpace<u32> = SearchSpace::new(g.len());
            run(&mut f, s, t)
        });
    }

    #[test]
    fn driver_form_matches_the_closure_form() {
        let g = Grid::parse(&["S..#....", ".#.#.##.", ".#...#..", ".####.#.", "......#G"]);
        let (s, t) = (g.find(b'S')[0], g.find(b'G')[0]);
        let mut a: SearchSpace<u32> = SearchSpace::new(g.len());
        a.dijkstra([(s, 0)], |v, o| g.n4_cost(v, o), |v, _| v == t);
        let mut b: SearchSpace<u32> = SearchSpace::new(g.len());
        b.begin();
        b.push_source(s, 0, 0);
        let mut buf = Vec::new();
        let mut order = Vec::new();
        while let Some(x) = b.pop() {
            order.push(x.node);
            if x.node == t {
                break;
            }
            buf.clear();
            g.n4(x.node, &mut buf);
            for &n in &buf {
                b.relax(x.node, n, x.g + 10, || 0);
            }
        }
        assert_eq!(a.path_to(t), b.path_to(t));
        // Costs never decrease along the settle order.
        let costs: Vec<u32> = order.iter().map(|&v| b.dist(v).unwrap_or(0)).collect();
        assert!(costs.windows(2).all(|w| w[0] <= w[1]));
        assert!(b.is_settled(t));
        assert_eq!(a.dist(t), b.dist(t));
    }

    /// The monotone queue pops exactly what a binary heap of the pairs pops, over a
    /// Dijkstra-like run (pushes at or above the last popped key, ties on the key, keys below
    /// the minimum, reuse after `clear`).
    #[test]
    fn monotone_queue_matches_binary_heap() {
        let mut q = MonotoneQueue::new();
        let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        for round in 0..4 {
            q.clear();
            let mut heap = BinaryHeap::new();
            let mut last = 0u64;
            let mut id = 0u32;
            for step in 0..5000 {
                for _ in 0..(next() % 4) {
                    let r = next();
                    let key = match r % 5 {
                        0 => last,
                        1 if round == 3 && last > 0 => last - 1 - r % last.min(7),
                        _ => last + (r >> 8) % [3, 1_000, 1_414_214, 1 << 40][round],
                    };
                    id = id.wrapping_add(1 + (r >> 40) as u32 % 3) % 100_000;
                    // Every pair distinct, as in a search.
                    let pair = (key, id ^ step);
                    q.push(pair.0, pair.1);
                    heap.push(Reverse(pair));
                }
                if next() % 3 != 0 {
                    let got = q.pop();
                    assert_eq!(got, heap.pop().map(|Reverse(p)| p));
                    if let Some((k, _)) = got {
                        last = k;
                    }
                }
            }
            while let Some(Reverse(p)) = heap.pop() {
                assert_eq!(q.pop(), Some(p));
            }
            assert_eq!(q.pop(), None);
        }
    }
}
