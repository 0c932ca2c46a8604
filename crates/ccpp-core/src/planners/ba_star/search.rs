//! The backtracking searches over covered tiles: the nearest tile of `L` (Dijkstra, or A* to
//! the nearest of a target set with [`TargetBlocks`]) and the bounded A* path.

use crate::search::MonotoneQueue;
use crate::tiles::{Tile, N8};

/// Fixed-point cost of an orthogonal tile step (one tile = 1 000 000).
pub const COST_ORTHO: u64 = 1_000_000;
/// Fixed-point cost of a diagonal tile step (`sqrt 2` rounded up, which keeps the Euclidean
/// heuristic consistent).
pub const COST_DIAG: u64 = 1_414_214;

/// The graph BA* searches: covered tiles, joined when the straight move is free.
pub trait TileGraph {
    /// Inclusive tile bounds `(i0, i1, j0, j1)`; tiles outside are never covered.
    fn bounds(&self) -> (i32, i32, i32, i32);
    /// Is tile `t` covered?
    fn covered(&self, t: Tile) -> bool;
    /// Is the straight move from `t` to its neighbour `t + N8[k]` known to be free?
    fn move_free(&self, t: Tile, k: usize) -> bool;
    /// The edges of `t` as a mask: bit `k` set when [`graph_edge`]`(self, t, k)` holds.
    /// Implementors may override it with a faster equivalent (the searches call it once per
    /// settled tile).
    fn edge_mask(&self, t: Tile) -> u8
    where
        Self: Sized,
    {
        (0..8).fold(0, |m, k| {
            if graph_edge(self, t, k) {
                m | 1 << k
            } else {
                m
            }
        })
    }
}

/// Is the step `t -> t + N8[k]` an edge of the backtracking graph: both tiles covered, a
/// diagonal only when both orthogonal tiles are covered (no corner cutting), the move free.
pub fn graph_edge(g: &impl TileGraph, t: Tile, k: usize) -> bool {
    let (di, dj) = N8[k];
    let v = (t.0 + di, t.1 + dj);
    if !g.covered(v) {
        return false;
    }
    if k % 2 == 1 && !(g.covered((t.0 + di, t.1)) && g.covered((t.0, t.1 + dj))) {
        return false;
    }
    g.move_free(t, k)
}

/// Reusable dense scratch for Dijkstra and A* over a tile rectangle (no hashing, nothing
/// cleared per search). One 8-byte word per tile (`NodeWord`: cost, settled flag, direction
/// from the parent), stored in blocks of 8 x 8 tiles (`NODE_BLOCK`, 512 bytes) so a
/// search over a compact area touches few cache lines and pages; a block is reset the first
/// time a search touches it (a generation stamp per block). Heap entries carry the row-major
/// tile index, whose order is the `(j, i)` tie-break.
#[derive(Clone, Debug)]
pub struct TileSearch {
    i0: i32,
    j0: i32,
    w: usize,
    h: usize,
    /// Storage blocks per row.
    bw: usize,
    /// The node words, block after block (row-major inside a block).
    nodes: Vec<u64>,
    /// Per storage block: the generation its words belong to (older: all unlabelled).
    bstamp: Vec<u32>,
    generation: u32,
    heap: MonotoneQueue,
    /// Scratch of [`Self::nearest_of`]: the targets' candidate lists per block.
    blocks: TargetBlocks,
    /// The last answer of [`Self::nearest_of`] while its labels are intact: start and target
    /// indices, cost, generation (see [`Self::astar_bounded`]).
    last_nearest: Option<(usize, usize, u64, u32)>,
    /// Scratch of [`Self::mark_optimal`].
    stack: Vec<u32>,
    /// The tiles marked by [`Self::mark_optimal`]: a bit per row-major index, and the list of
    /// the set bits (to clear them).
    marks: Vec<u64>,
    marked: Vec<u32>,
}

/// Side, in tiles, of the storage blocks of [`TileSearch`].
const NODE_BLOCK: usize = 8;

/// A search node in one word: the cost in the bits from [`DIST_SHIFT`] up, [`SETTLED`], and in
/// the low bits the index `n` of [`N8`] with `tile = parent + N8[n]` ([`NO_PARENT`] at the
/// source). Costs stay far below `2^59` (a path visits a tile at most once, each step costs at
/// most [`COST_DIAG`]).
type NodeWord = u64;
const DIR_MASK: NodeWord = 0xF;
const NO_PARENT: NodeWord = 8;
const SETTLED: NodeWord = 1 << 4;
const DIST_SHIFT: u32 = 5;
/// A node not labelled in the current search: the largest cost, not settled, no parent.
const UNLABELLED: NodeWord = (NodeWord::MAX << DIST_SHIFT) | NO_PARENT;

#[inline]
fn word_dist(n: NodeWord) -> u64 {
    n >> DIST_SHIFT
}

#[inline]
fn word(dist: u64, dir: NodeWord) -> NodeWord {
    (dist << DIST_SHIFT) | dir
}

/// Side, in tiles, of the blocks of [`TargetBlocks`].
const TARGET_BLOCK: usize = 16;

/// The heuristic of [`TileSearch::nearest_of`]: the least [`octile`] cost from a tile to any
/// of a set of targets, computed from a per-block candidate list (built when the search first
/// reaches the block, reused by every tile of it).
///
/// Block `X` keeps the targets `l` whose octile cost from the nearest tile of `X` is at most
/// `U = min over l' of` the cost from the farthest tile of `X` (a corner: the octile cost is a
/// norm, hence convex). Any other target is farther from every tile of `X` than the target
/// achieving `U`, so the minimum over the list is the minimum over all targets: exact.
///
/// A block's list is taken from the list of its super-block (4 x 4 blocks, built from all
/// targets the same way), which holds it: for `X` inside `Y`, the cost from the nearest tile
/// of `Y` is at most that from the nearest of `X`, and `U` of `X` at most `U` of `Y`. So each
/// target is looked at once per super-block, not once per block.
#[derive(Clone, Debug, Default)]
struct TargetBlocks {
    /// Blocks per row and per column of the search rectangle.
    bw: usize,
    bh: usize,
    /// Per block: the generation its list was built in (0: never).
    stamp: Vec<u32>,
    /// Per block: its list, `arena[range.0..range.1]`.
    range: Vec<(u32, u32)>,
    arena: Vec<Tile>,
    generation: u32,
    targets: Vec<Tile>,
    /// The same per super-block (`SUPER_BLOCKS` blocks a side).
    sbw: usize,
    sstamp: Vec<u32>,
    srange: Vec<(u32, u32)>,
    sarena: Vec<Tile>,
}

/// Blocks a side of a super-block of [`TargetBlocks`].
const SUPER_BLOCKS: usize = 4;

/// The cost of the cheapest 8-neighbour path from `a` to `b` on an unobstructed grid
/// ([`COST_ORTHO`] / [`COST_DIAG`] steps): a lower bound of the search cost, and consistent
/// (it is the path metric of a supergraph with the same edge costs).
#[inline]
pub fn octile(a: Tile, b: Tile) -> u64 {
    octile_gap(u64::from(a.0.abs_diff(b.0)), u64::from(a.1.abs_diff(b.1)))
}

#[inline]
fn octile_gap(dx: u64, dy: u64) -> u64 {
    let (lo, hi) = if dx < dy { (dx, dy) } else { (dy, dx) };
    COST_ORTHO * (hi - lo) + COST_DIAG * lo
}

impl TileSearch {
    /// Scratch for tiles `i0..=i1`, `j0..=j1`.
    pub fn new((i0, i1, j0, j1): (i32, i32, i32, i32)) -> Self {
        let w = (i1 - i0 + 1).max(0) as usize;
        let h = (j1 - j0 + 1).max(0) as usize;
        let bw = w.div_ceil(NODE_BLOCK);
        let nb = bw * h.div_ceil(NODE_BLOCK);
        Self {
            i0,
            j0,
            w,
            h,
            bw,
            // Zeros (pages the system maps on first touch): every block is reset before its
            // first use, as no block stamp matches a search's generation (from 1) yet.
            nodes: vec![0; nb * NODE_BLOCK * NODE_BLOCK],
            bstamp: vec![0; nb],
            generation: 0,
            heap: MonotoneQueue::new(),
            blocks: TargetBlocks {
                bw: w.div_ceil(TARGET_BLOCK),
                bh: h.div_ceil(TARGET_BLOCK),
                ..TargetBlocks::default()
            },
            last_nearest: None,
            stack: Vec::new(),
            marks: vec![0; (w * h).div_ceil(64)],
            marked: Vec::new(),
        }
    }

    #[inline]
    fn idx(&self, t: Tile) -> Option<usize> {
        let di = t.0 - self.i0;
        let dj = t.1 - self.j0;
        if di < 0 || dj < 0 || di as usize >= self.w || dj as usize >= self.h {
            None
        } else {
            Some(dj as usize * self.w + di as usize)
        }
    }

    #[inline]
    fn tile(&self, k: usize) -> Tile {
        (self.i0 + (k % self.w) as i32, self.j0 + (k / self.w) as i32)
    }

    /// The storage block of the tile at offset `(x, y)` and the word's place in it.
    #[inline]
    fn block_of(&self, x: usize, y: usize) -> (usize, usize) {
        (
            (y / NODE_BLOCK) * self.bw + x / NODE_BLOCK,
            (y % NODE_BLOCK) * NODE_BLOCK + x % NODE_BLOCK,
        )
    }

    /// The word index of the tile at offset `(x, y)` (in the rectangle), resetting its block
    /// to unlabelled words when the current search touches it first.
    // Measured: left to the compiler, this hot accessor stays an out-of-line call.
    #[allow(clippy::inline_always)]
    #[inline(always)]
    fn slot(&mut self, x: usize, y: usize) -> usize {
        let (b, o) = self.block_of(x, y);
        if self.bstamp[b] != self.generation {
            self.reset_block(b);
        }
        b * NODE_BLOCK * NODE_BLOCK + o
    }

    /// Makes the words of storage block `b` unlabelled in the current search.
    #[cold]
    #[inline(never)]
    fn reset_block(&mut self, b: usize) {
        self.bstamp[b] = self.generation;
        let base = b * NODE_BLOCK * NODE_BLOCK;
        self.nodes[base..base + NODE_BLOCK * NODE_BLOCK].fill(UNLABELLED);
    }

    /// The word of the tile at offset `(x, y)` in the current search (read only).
    #[inline]
    fn peek(&self, x: usize, y: usize) -> NodeWord {
        let (b, o) = self.block_of(x, y);
        if self.bstamp[b] == self.generation {
            self.nodes[b * NODE_BLOCK * NODE_BLOCK + o]
        } else {
            UNLABELLED
        }
    }

    #[inline]
    fn is_marked(&self, k: usize) -> bool {
        self.marks[k / 64] & (1 << (k % 64)) != 0
    }

    fn clear_marks(&mut self) {
        for &k in &self.marked {
            self.marks[k as usize / 64] = 0;
        }
        self.marked.clear();
    }

    fn begin(&mut self) {
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.bstamp.fill(0);
            self.generation = 1;
        }
        self.heap.clear();
    }

    /// Labels the source (row-major index `s`) with cost 0.
    fn start(&mut self, s: usize, key: u64) {
        let ss = self.slot(s % self.w, s / self.w);
        self.nodes[ss] = word(0, NO_PARENT);
        self.heap.push(key, s as u32);
    }

    /// Settles the node of a popped pair (row-major `k`): its word index and cost, or `None`
    /// when it was settled already or (with `check_dist`) the pair's key is above its cost.
    #[inline]
    fn settle(&mut self, k: usize, key: u64, check_dist: bool) -> Option<(usize, u64)> {
        let sk = self.slot(k % self.w, k / self.w);
        let n = self.nodes[sk];
        if n & SETTLED != 0 || (check_dist && key > word_dist(n)) {
            return None;
        }
        self.nodes[sk] = n | SETTLED;
        Some((sk, word_dist(n)))
    }

    fn path_to(&self, k: usize) -> Vec<Tile> {
        let mut path = vec![self.tile(k)];
        let (mut x, mut y) = (k % self.w, k / self.w);
        loop {
            let dir = self.peek(x, y) & DIR_MASK;
            if dir == NO_PARENT {
                break;
            }
            let (di, dj) = N8[dir as usize];
            x = x.wrapping_add_signed(-di as isize);
            y = y.wrapping_add_signed(-dj as isize);
            path.push(self.tile(y * self.w + x));
        }
        path.reverse();
        path
    }

    /// Dijkstra from `from` over the graph of [`graph_edge`]; returns the first settled tile
    /// with `is_target` (smallest cost, then smaller `j`, then smaller `i`) and its cost.
    pub fn nearest(
        &mut self,
        g: &impl TileGraph,
        from: Tile,
        is_target: impl Fn(Tile) -> bool,
    ) -> Option<(Tile, u64)> {
        let s = self.idx(from)?;
        self.begin();
        self.start(s, 0);
        while let Some((d, k)) = self.heap.pop() {
            let k = k as usize;
            if self.settle(k, d, true).is_none() {
                continue;
            }
            let t = self.tile(k);
            if is_target(t) {
                return Some((t, d));
            }
            self.expand_within(g, t, k, d, None, u64::MAX, false);
        }
        None
    }

    /// [`Self::nearest`] when the targets are listed (`targets`: exactly the tiles with
    /// `is_target`): the same tile and cost, found by A* towards the set.
    ///
    /// The heuristic is the least [`octile`] cost to a target (bounded per block of tiles):
    /// consistent, and zero at the targets, whose key is then their cost. Popping in `(key, index)` order,
    /// every tile on a cheapest path to a target of the least cost `d*` is popped, with its
    /// exact cost, before any key above `d*`; so once a target is popped the search goes on
    /// through the key `d*` and answers with the smallest-index target popped at that key:
    /// the first target of the Dijkstra order `(cost, index)`. Targets are not expanded, as
    /// in [`Self::nearest`] (a cheapest path to a target of cost `d*` passes through no other
    /// target: costs are positive). Far targets cost a search of the region between, not of
    /// the disc of radius `d*`.
    pub fn nearest_of(
        &mut self,
        g: &impl TileGraph,
        from: Tile,
        targets: &[Tile],
        is_target: impl Fn(Tile) -> bool,
    ) -> Option<(Tile, u64)> {
        let s = self.idx(from)?;
        self.begin();
        self.last_nearest = None;
        self.blocks.begin(targets);
        let h0 = self.target_h(from);
        self.start(s, h0);
        let mut best: Option<(usize, u64)> = None;
        while let Some((key, k)) = self.heap.pop() {
            if best.is_some_and(|(_, d)| key > d) {
                break;
            }
            let k = k as usize;
            let Some((_, d)) = self.settle(k, key, false) else {
                continue;
            };
            let t = self.tile(k);
            if is_target(t) {
                if best.is_none_or(|(b, _)| k < b) {
                    best = Some((k, d));
                }
                continue;
            }
            // Once a target is found at `d*`, labels with keys above it are never popped
            // (nor read by `mark_optimal`, which reads settled tiles only): not pushed.
            let bound = best.map_or(u64::MAX, |(_, bd)| bd);
            self.expand_to_targets(g, t, k, d, bound);
        }
        if let Some((k, d)) = best {
            self.last_nearest = Some((s, k, d, self.generation));
        }
        best.map(|(k, d)| (self.tile(k), d))
    }

    /// The heuristic of [`Self::nearest_of`] at tile `t` (in the search rectangle).
    #[inline]
    fn target_h(&mut self, t: Tile) -> u64 {
        let bi = (t.0 - self.i0) as usize / TARGET_BLOCK;
        let bj = (t.1 - self.j0) as usize / TARGET_BLOCK;
        let (lo, hi) = self.blocks.list(bi, bj, (self.i0, self.j0));
        self.blocks.arena[lo..hi]
            .iter()
            .map(|&l| octile(t, l))
            .min()
            .unwrap_or(u64::MAX / 4)
    }

    /// The neighbour `N8[n]` of the tile at row-major `k`: its row-major index and word index
    /// (`None` outside the rectangle).
    #[inline]
    fn neighbour(&mut self, k: usize, n: usize) -> Option<(usize, usize)> {
        let (di, dj) = N8[n];
        let x = (k % self.w).wrapping_add_signed(di as isize);
        let y = (k / self.w).wrapping_add_signed(dj as isize);
        if x >= self.w || y >= self.h {
            return None;
        }
        Some((y * self.w + x, self.slot(x, y)))
    }

    /// [`Self::expand_within`] for [`Self::nearest_of`]: keys `cost + target_h`, none above
    /// `bound`.
    fn expand_to_targets(&mut self, g: &impl TileGraph, t: Tile, k: usize, d: u64, bound: u64) {
        let mut mask = g.edge_mask(t);
        while mask != 0 {
            let n = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let Some((kv, sv)) = self.neighbour(k, n) else {
                continue;
            };
            let nd = d + if n % 2 == 1 { COST_DIAG } else { COST_ORTHO };
            let node = self.nodes[sv];
            if node & SETTLED != 0 || nd >= word_dist(node) {
                continue;
            }
            let (di, dj) = N8[n];
            let f = nd + self.target_h((t.0 + di, t.1 + dj));
            if f > bound {
                continue;
            }
            self.nodes[sv] = word(nd, n as NodeWord);
            self.heap.push(f, kv as u32);
        }
    }

    /// Relaxes the edges of the settled tile `t` (index `k`, cost `d`), pushing each improved
    /// neighbour with key `cost + heuristic`; a neighbour whose key would exceed `bound` is left
    /// unlabelled (see [`Self::astar_within`]); with `only_marked`, so is a neighbour neither
    /// labelled in this search nor marked by [`Self::mark_optimal`].
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn expand_within(
        &mut self,
        g: &impl TileGraph,
        t: Tile,
        k: usize,
        d: u64,
        goal: Option<Tile>,
        bound: u64,
        only_marked: bool,
    ) {
        let mut mask = g.edge_mask(t);
        while mask != 0 {
            let n = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let Some((kv, sv)) = self.neighbour(k, n) else {
                continue;
            };
            let nd = d + if n % 2 == 1 { COST_DIAG } else { COST_ORTHO };
            let node = self.nodes[sv];
            // Settled, or labelled at least as well: nothing to do.
            if node & SETTLED != 0 || nd >= word_dist(node) {
                continue;
            }
            if only_marked && node == UNLABELLED && !self.is_marked(kv) {
                continue;
            }
            let (di, dj) = N8[n];
            let v = (t.0 + di, t.1 + dj);
            let f = match goal {
                Some(gl) => {
                    // The octile cost to the goal bounds the remaining cost from below and
                    // is at least the Euclidean heuristic: a label beyond `bound` by it lies
                    // on no path of cost `<= bound` (see [`Self::astar_bounded`]).
                    if bound != u64::MAX && nd + octile(v, gl) > bound {
                        continue;
                    }
                    nd + heuristic(v, gl)
                }
                None => nd,
            };
            if f > bound {
                continue;
            }
            self.nodes[sv] = word(nd, n as NodeWord);
            self.heap.push(f, kv as u32);
        }
    }

    /// A* from `from` to `to` over the graph of [`graph_edge`] (costs [`COST_ORTHO`] /
    /// [`COST_DIAG`], Euclidean heuristic); the tile path (both ends included) and its cost.
    pub fn astar(&mut self, g: &impl TileGraph, from: Tile, to: Tile) -> Option<(Vec<Tile>, u64)> {
        self.astar_within(g, from, to, u64::MAX, false)
    }

    /// [`Self::astar`] when the cost of the best path is known to be `cost` (say from
    /// [`Self::nearest`] on the same graph): the same answer, without labelling a tile whose
    /// label plus the [`octile`] cost to the goal exceeds `cost` (the keys stay `cost +`
    /// Euclidean heuristic; the octile cost is at least that heuristic).
    ///
    /// Why it is the same: the octile cost is a lower bound of the remaining cost, so a
    /// left-out label is either worse than its tile's best cost or belongs to a tile on no
    /// cheapest path to the goal. Call the tiles on cheapest paths *optimal*. With a consistent
    /// heuristic every tile is settled through the label of its best cost, and an optimal
    /// tile's best label is pushed when the first of its optimal predecessors (in settling
    /// order) is expanded, with that predecessor as parent; no left-out or other label of
    /// another tile can set or block it (they are worse, or from tiles that are not optimal
    /// predecessors). So the best labels of optimal tiles are pushed at the same points of the
    /// sequence of optimal settlings in both searches, and as the queue pops pairs in
    /// `(key, index)` order, both settle the optimal tiles in the same order, with the same
    /// parents, up to the goal: the same path and cost. Should the bound be too low (or the
    /// heuristic inconsistent), this search runs dry before the goal and the full search is
    /// run instead.
    pub fn astar_bounded(
        &mut self,
        g: &impl TileGraph,
        from: Tile,
        to: Tile,
        cost: u64,
    ) -> Option<(Vec<Tile>, u64)> {
        self.astar_within(g, from, to, cost, false)
            .or_else(|| self.astar_within(g, from, to, u64::MAX, false))
    }

    /// [`Self::astar_bounded`] right after [`Self::nearest_of`] on the same graph answered
    /// `(to, cost)` from `from`: the same answer, settling only the tiles on cheapest paths
    /// from `from` to `to` (otherwise, or should that search run dry, it is
    /// [`Self::astar_bounded`]).
    ///
    /// Why it is the same: the proof of [`Self::astar_bounded`] holds for leaving out any
    /// label of a tile on no cheapest path to the goal (a non-optimal tile never gives an
    /// optimal one its best label: it would then be optimal). Every optimal tile `v` was
    /// settled by [`Self::nearest_of`] with its exact cost (its key there is at most the cost,
    /// and that search went through every key up to it), and its optimal predecessors are
    /// exactly the settled neighbours `u` with an edge `u -> v` and `cost(u) + step = cost(v)`:
    /// `mark_optimal` (a private helper) finds them all walking back from the goal, before
    /// the labels are overwritten.
    pub fn astar_nearest(
        &mut self,
        g: &impl TileGraph,
        from: Tile,
        to: Tile,
        cost: u64,
    ) -> Option<(Vec<Tile>, u64)> {
        if self.mark_optimal(g, from, to, cost) {
            let r = self.astar_within(g, from, to, cost, true);
            self.clear_marks();
            if r.is_some() {
                return r;
            }
        }
        self.astar_bounded(g, from, to, cost)
    }

    /// Marks the tiles on cheapest paths from `from` to `to` (in `marks`), read off the labels
    /// of the last [`Self::nearest_of`] if it answered `(to, cost)` from `from` and no search
    /// ran since; false (nothing marked) otherwise.
    fn mark_optimal(&mut self, g: &impl TileGraph, from: Tile, to: Tile, cost: u64) -> bool {
        let (Some(s), Some(t)) = (self.idx(from), self.idx(to)) else {
            return false;
        };
        if self.last_nearest.take() != Some((s, t, cost, self.generation)) {
            return false;
        }
        let mut stack = std::mem::take(&mut self.stack);
        stack.clear();
        self.mark(t);
        stack.push(t as u32);
        while let Some(kv) = stack.pop() {
            let kv = kv as usize;
            let v = self.tile(kv);
            let (x, y) = (kv % self.w, kv / self.w);
            let dv = word_dist(self.peek(x, y));
            for (n, &(di, dj)) in N8.iter().enumerate() {
                let ux = x.wrapping_add_signed(di as isize);
                let uy = y.wrapping_add_signed(dj as isize);
                if ux >= self.w || uy >= self.h {
                    continue;
                }
                let ku = uy * self.w + ux;
                let step = if n % 2 == 1 { COST_DIAG } else { COST_ORTHO };
                let node = self.peek(ux, uy);
                if node & SETTLED == 0 || word_dist(node) + step != dv || self.is_marked(ku) {
                    continue;
                }
                // The edge `u -> v` goes the opposite way of `N8[n]`.
                let u = (v.0 + di, v.1 + dj);
                if g.edge_mask(u) & (1 << ((n + 4) % 8)) == 0 {
                    continue;
                }
                self.mark(ku);
                stack.push(ku as u32);
            }
        }
        self.stack = stack;
        true
    }

    #[inline]
    fn mark(&mut self, k: usize) {
        self.marks[k / 64] |= 1 << (k % 64);
        self.marked.push(k as u32);
    }

    fn astar_within(
        &mut self,
        g: &impl TileGraph,
        from: Tile,
        to: Tile,
        bound: u64,
        only_marked: bool,
    ) -> Option<(Vec<Tile>, u64)> {
        let s = self.idx(from)?;
        self.idx(to)?;
        self.begin();
        self.start(s, heuristic(from, to));
        while let Some((key, k)) = self.heap.pop() {
            let k = k as usize;
            let Some((_, d)) = self.settle(k, key, false) else {
                continue;
            };
            let t = self.tile(k);
            if t == to {
                return Some((self.path_to(k), d));
            }
            self.expand_within(g, t, k, d, Some(to), bound, only_marked);
        }
        None
    }
}
impl TargetBlocks {
    /// A new search towards `targets`: every block's list is stale.
    fn begin(&mut self, targets: &[Tile]) {
        if self.stamp.len() != self.bw * self.bh {
            self.stamp = vec![0; self.bw * self.bh];
            self.range = vec![(0, 0); self.bw * self.bh];
            self.sbw = self.bw.div_ceil(SUPER_BLOCKS);
            let n = self.sbw * self.bh.div_ceil(SUPER_BLOCKS);
            self.sstamp = vec![0; n];
            self.srange = vec![(0, 0); n];
        }
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.stamp.fill(0);
            self.sstamp.fill(0);
            self.generation = 1;
        }
        self.arena.clear();
        self.sarena.clear();
        self.targets.clear();
        self.targets.extend_from_slice(targets);
    }

    /// The arena range of block `(bi, bj)` of a search rectangle whose first tile is
    /// `origin`, built on first use.
    #[inline]
    fn list(&mut self, bi: usize, bj: usize, origin: Tile) -> (usize, usize) {
        let b = bj * self.bw + bi;
        if self.stamp[b] != self.generation {
            self.build(bi, bj, origin);
        }
        let (lo, hi) = self.range[b];
        (lo as usize, hi as usize)
    }

    fn build(&mut self, bi: usize, bj: usize, origin: Tile) {
        let (si, sj) = (bi / SUPER_BLOCKS, bj / SUPER_BLOCKS);
        let sb = sj * self.sbw + si;
        if self.sstamp[sb] != self.generation {
            let side = TARGET_BLOCK * SUPER_BLOCKS;
            let lo = self.sarena.len();
            candidates(
                &self.targets,
                block_rect(origin, si, sj, side),
                &mut self.sarena,
            );
            self.srange[sb] = (lo as u32, self.sarena.len() as u32);
            self.sstamp[sb] = self.generation;
        }
        let (slo, shi) = self.srange[sb];
        let lo = self.arena.len();
        candidates(
            &self.sarena[slo as usize..shi as usize],
            block_rect(origin, bi, bj, TARGET_BLOCK),
            &mut self.arena,
        );
        let b = bj * self.bw + bi;
        self.range[b] = (lo as u32, self.arena.len() as u32);
        self.stamp[b] = self.generation;
    }
}

/// The tiles `(x0, x1, y0, y1)` of block `(bi, bj)` of side `side` from `origin` (not clipped
/// to the search rectangle: a larger block keeps every list exact).
fn block_rect(origin: Tile, bi: usize, bj: usize, side: usize) -> (i32, i32, i32, i32) {
    let x0 = origin.0 + (bi * side) as i32;
    let y0 = origin.1 + (bj * side) as i32;
    (x0, x0 + side as i32 - 1, y0, y0 + side as i32 - 1)
}

/// Appends to `out` the targets of `src` kept for the block `(x0, x1, y0, y1)` (see
/// [`TargetBlocks`]), in the order of `src`.
fn candidates(src: &[Tile], (x0, x1, y0, y1): (i32, i32, i32, i32), out: &mut Vec<Tile>) {
    let gap = |v: i32, lo: i32, hi: i32| {
        u64::from(
            lo.saturating_sub(v)
                .max(v.saturating_sub(hi))
                .max(0)
                .unsigned_abs(),
        )
    };
    let near = |l: Tile| octile_gap(gap(l.0, x0, x1), gap(l.1, y0, y1));
    let far = |l: Tile| {
        let dx = u64::from(l.0.abs_diff(x0).max(l.0.abs_diff(x1)));
        let dy = u64::from(l.1.abs_diff(y0).max(l.1.abs_diff(y1)));
        octile_gap(dx, dy)
    };
    let u = src.iter().map(|&l| far(l)).min().unwrap_or(0);
    out.extend(src.iter().copied().filter(|&l| near(l) <= u));
}

/// Euclidean distance between tiles in the fixed-point unit of [`COST_ORTHO`], rounded down
/// (admissible and consistent with the rounded-up diagonal cost).
#[inline]
pub fn heuristic(a: Tile, b: Tile) -> u64 {
    let di = f64::from(a.0 - b.0);
    let dj = f64::from(a.1 - b.1);
    // The product is finite and >= 0, where the truncating cast is the floor (without a call
    // into libm).
    (di.hypot(dj) * COST_ORTHO as f64) as u64
}
