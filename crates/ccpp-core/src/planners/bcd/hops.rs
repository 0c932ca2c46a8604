//! Hop costs for the cell tour, computed once per tour.
//!
//! A hop between two points costs the straight-line distance, or the length of a shortest path
//! over a coarse grid of the C-free set when that is longer (walls between the points). Blocks
//! of `b` pixels are open when they hold a C-free pixel and joined to a side neighbour when
//! C-free pixels touch across their common edge; a diagonal block step needs one of its two
//! side paths. Costs are integers (10 per side step, 14 per diagonal step), so every search
//! has a fixed order and ties break on the block index.
//!
//! Instead of searching each queried pair (the tour's improvement moves ask for the same hops
//! many times), [`HopTable`] runs one Dijkstra per block that holds an end point of some piece,
//! bounded to [`RADIUS_BLOCKS`] blocks of path, and keeps the costs to the other end-point
//! blocks in a sorted row. A pair beyond the radius (or not joined by the coarse grid within
//! it) is costed on a second grid of blocks [`FAR_FACTOR`] times larger, searched whole from
//! each of its end-point blocks: the path there less two far-block diagonals (the points can
//! sit anywhere in their blocks), at least the radius and the straight line.

use super::lattice::Ctx;
use super::tsp;
use crate::geometry::Point;

/// Search radius of each end point's Dijkstra, in blocks of path.
const RADIUS_BLOCKS: u32 = 24;
const _: () = assert!(RADIUS_BLOCKS * 10 < u8::MAX as u32);
/// Side of a far block, in blocks.
pub(super) const FAR_FACTOR: u32 = 4;
/// Largest hop matrix kept dense (bytes).
const DENSE_MAX: usize = 16 << 20;

/// The coarse grid of the C-free set.
pub(super) struct Coarse {
    b: usize,
    bw: usize,
    bh: usize,
    open: Vec<bool>,
    /// Per block: bit `i` set when the step [`DIRS`]`[i]` is allowed (see [`Coarse::step_mask`]).
    mask: Vec<u8>,
}

/// The eight block steps (column, row): four side steps (cost 10), then four diagonals (14).
const DIRS: [(i64, i64); 8] = [
    (1, 0),
    (0, 1),
    (-1, 0),
    (0, -1),
    (1, 1),
    (1, -1),
    (-1, 1),
    (-1, -1),
];

/// Buckets of the circular bucket queue: more than the largest step cost.
const BUCKETS: usize = 16;

impl Coarse {
    /// The grid of `ctx`'s C-free set in blocks of about `sp` pixels (at least 4).
    pub(super) fn new(ctx: &Ctx<'_>, sp: f64) -> Self {
        let (w, h) = (ctx.frame.width, ctx.frame.height);
        let b = (sp.round() as usize).max(4);
        let (bw, bh) = (w.div_ceil(b), h.div_ceil(b));
        let mut open = vec![false; bw * bh];
        let mut east = vec![false; bw * bh];
        let mut south = vec![false; bw * bh];
        for r in 0..h {
            for c in 0..w {
                if !ctx.ok[r * w + c] {
                    continue;
                }
                let k = (r / b) * bw + c / b;
                open[k] = true;
                if c + 1 < w && (c + 1) % b == 0 && ctx.ok[r * w + c + 1] {
                    east[k] = true;
                }
                if r + 1 < h && (r + 1) % b == 0 && ctx.ok[(r + 1) * w + c] {
                    south[k] = true;
                }
            }
        }
        let mut grid = Self {
            b,
            bw,
            bh,
            open,
            mask: Vec::new(),
        };
        grid.mask = (0..bw * bh)
            .map(|k| {
                if grid.open[k] {
                    grid.step_mask(k, &east, &south)
                } else {
                    0
                }
            })
            .collect();
        grid
    }

    /// The block of grid point `p` (grid y up; blocks count rows from the top).
    fn block(&self, p: Point) -> usize {
        let bf = self.b as f64;
        // (`as usize` truncates: the floor of a non-negative value)
        let c = ((p.x / bf).max(0.0) as usize).min(self.bw - 1);
        let rows = self.bh * self.b;
        let r_px = (rows as f64 - p.y).max(0.0) as usize;
        let r = (r_px / self.b).min(self.bh - 1);
        r * self.bw + c
    }

    fn linked(&self, east: &[bool], south: &[bool], k: usize, dc: i64, dr: i64) -> bool {
        match (dc, dr) {
            (1, 0) => east[k],
            (-1, 0) => east[k - 1],
            (0, 1) => south[k],
            (0, -1) => south[k - self.bw],
            _ => false,
        }
    }

    /// The block steps from block `k` that the grid allows, as a bit set over [`DIRS`]: a
    /// side step needs the two blocks joined, a diagonal step one of its two side paths.
    fn step_mask(&self, k: usize, east: &[bool], south: &[bool]) -> u8 {
        let bw = self.bw;
        let (c, r) = ((k % bw) as i64, (k / bw) as i64);
        let at = |c: i64, r: i64| r as usize * bw + c as usize;
        let mut mask = 0u8;
        for (i, &(dc, dr)) in DIRS.iter().enumerate() {
            let (nc, nr) = (c + dc, r + dr);
            if nc < 0 || nr < 0 || nc >= bw as i64 || nr >= self.bh as i64 {
                continue;
            }
            let j = at(nc, nr);
            if !self.open[j] {
                continue;
            }
            let ok = if dc != 0 && dr != 0 {
                let (vh, vv) = (at(nc, r), at(c, nr));
                let a = self.open[vh]
                    && self.linked(east, south, k, dc, 0)
                    && self.linked(east, south, vh, 0, dr);
                let b = self.open[vv]
                    && self.linked(east, south, k, 0, dr)
                    && self.linked(east, south, vv, dc, 0);
                a || b
            } else {
                self.linked(east, south, k, dc, dr)
            };
            if ok {
                mask |= 1 << i;
            }
        }
        mask
    }

    /// Shortest path costs (tenths of a block) from block `s` over the allowed block steps, up
    /// to `cap`: `visit(k, g)` is called once for every block reached, in non-decreasing `g`.
    /// `g` must hold `u32::MAX` everywhere and is left so; `touched` and `buckets` are scratch.
    /// (Costs are small integers, so a circular bucket queue gives the exact Dijkstra costs.)
    fn search(
        &self,
        s: usize,
        cap: u32,
        g: &mut [u32],
        touched: &mut Vec<usize>,
        buckets: &mut [Vec<usize>; BUCKETS],
        mut visit: impl FnMut(usize, u32),
    ) {
        let bw = self.bw as isize;
        let offs: [isize; 8] = DIRS.map(|(dc, dr)| dr as isize * bw + dc as isize);
        g[s] = 0;
        touched.push(s);
        buckets[0].push(s);
        let mut queued = 1usize;
        let mut d = 0u32;
        while queued > 0 {
            // Pushes go to `d + 10` or `d + 14`, never to the bucket of `d` itself.
            let Some(k) = buckets[d as usize % BUCKETS].pop() else {
                d += 1;
                continue;
            };
            queued -= 1;
            if g[k] != d {
                continue;
            }
            visit(k, d);
            let mut m = self.mask[k];
            while m != 0 {
                let i = m.trailing_zeros() as usize;
                m &= m - 1;
                let ng = d + if i < 4 { 10 } else { 14 };
                let j = k.wrapping_add_signed(offs[i]);
                if ng <= cap && ng < g[j] {
                    if g[j] == u32::MAX {
                        touched.push(j);
                    }
                    g[j] = ng;
                    buckets[ng as usize % BUCKETS].push(j);
                    queued += 1;
                }
            }
        }
        for &k in touched.iter() {
            g[k] = u32::MAX;
        }
        touched.clear();
    }
}

/// Hop costs between the end points of a set of pieces (module docs).
pub(super) struct HopTable<'a> {
    coarse: &'a Coarse,
    far: Far<'a>,
    /// Per block: its row in `rows`, or `u32::MAX` when no end point lies in it.
    row_of: Vec<u32>,
    /// Per end-point block: (other end-point block, path cost in tenths of a block), sorted by
    /// block.
    rows: Vec<Vec<(u32, u32)>>,
    /// The block of each row.
    blocks: Vec<usize>,
    /// `rows` as a square matrix (`u8::MAX`: beyond the radius), when it has at most
    /// [`DENSE_MAX`] entries; empty otherwise.
    dense: Vec<u8>,
}

impl<'a> HopTable<'a> {
    /// The table for the entries and exits of `pieces` and the point `start`.
    pub(super) fn new(
        coarse: &'a Coarse,
        far: &'a Coarse,
        pieces: &[tsp::Piece],
        start: Point,
    ) -> Self {
        let n = coarse.bw * coarse.bh;
        let mut row_of = vec![u32::MAX; n];
        let mut blocks: Vec<usize> = Vec::new();
        let mut add = |p: Point| {
            let k = coarse.block(p);
            if row_of[k] == u32::MAX {
                row_of[k] = 0;
                blocks.push(k);
            }
        };
        add(start);
        for piece in pieces {
            piece.entry.iter().chain(&piece.exit).for_each(|&p| add(p));
        }
        // Z-order, so that the rows and columns of nearby blocks (the hops asked for most)
        // lie close together in the table.
        blocks.sort_unstable_by_key(|&k| morton(k % coarse.bw, k / coarse.bw));
        for (i, &k) in blocks.iter().enumerate() {
            row_of[k] = i as u32;
        }
        let cap = RADIUS_BLOCKS * 10;
        let mut g = vec![u32::MAX; n];
        let mut touched: Vec<usize> = Vec::new();
        let mut buckets: [Vec<usize>; BUCKETS] = std::array::from_fn(|_| Vec::new());
        let mut rows = Vec::with_capacity(blocks.len());
        for &s in &blocks {
            let mut row: Vec<(u32, u32)> = Vec::new();
            coarse.search(s, cap, &mut g, &mut touched, &mut buckets, |k, gk| {
                if row_of[k] != u32::MAX {
                    row.push((k as u32, gk));
                }
            });
            row.sort_unstable();
            rows.push(row);
        }
        // Dense copy when small enough: one byte per pair (costs are at most 10 * radius).
        let m = blocks.len();
        let dense = if m * m <= DENSE_MAX {
            let mut d = vec![u8::MAX; m * m];
            for (i, row) in rows.iter().enumerate() {
                for &(k, g) in row {
                    d[i * m + row_of[k as usize] as usize] = g as u8;
                }
            }
            d
        } else {
            Vec::new()
        };
        Self {
            coarse,
            far: Far::new(far, pieces, start),
            row_of,
            rows,
            blocks,
            dense,
        }
    }

    /// Path cost (pixels) between the blocks of `a` and `b` when within the radius.
    fn path_px(&self, a: Point, b: Point) -> Option<f64> {
        let (ka, kb) = (self.coarse.block(a), self.coarse.block(b));
        let ra = self.row_of[ka];
        if ra == u32::MAX {
            return None;
        }
        if !self.dense.is_empty() {
            let rb = self.row_of[kb];
            if rb == u32::MAX {
                return None;
            }
            let m = self.blocks.len();
            let g = self.dense[ra as usize * m + rb as usize];
            return (g != u8::MAX).then(|| f64::from(g) / 10.0 * self.coarse.b as f64);
        }
        let row = &self.rows[ra as usize];
        let i = row.binary_search_by_key(&(kb as u32), |e| e.0).ok()?;
        Some(f64::from(row[i].1) / 10.0 * self.coarse.b as f64)
    }

    /// The hop cost from `a` to `b` (pixels; module docs).
    pub(super) fn dist(&self, a: Point, b: Point) -> f64 {
        let e = euclid(a, b);
        if e < self.coarse.b as f64 {
            return e;
        }
        match self.path_px(a, b) {
            Some(g) => e.max(g),
            None => e
                .max(f64::from(RADIUS_BLOCKS) * self.coarse.b as f64)
                .max(self.far.path_px(a, b)),
        }
    }

    /// Nearest-neighbour tour: from each exit, the piece entries within the radius are ranked
    /// by hop cost plus the variant's extra inner cost over the piece's cheapest variant (ties:
    /// piece, then variant); where none is left within it, every remaining entry the same way.
    pub(super) fn nearest_tour(&self, pieces: &[tsp::Piece], start: Point) -> tsp::Tour {
        let mut at_row: Vec<Vec<(usize, usize)>> = vec![Vec::new(); self.blocks.len()];
        for (p, piece) in pieces.iter().enumerate() {
            for (v, &e) in piece.entry.iter().enumerate() {
                at_row[self.row_of[self.coarse.block(e)] as usize].push((p, v));
            }
        }
        let mut done = vec![false; pieces.len()];
        // Undone entries per row, so exhausted blocks are skipped in O(1).
        let mut left: Vec<usize> = at_row.iter().map(Vec::len).collect();
        let mut tour = Vec::with_capacity(pieces.len());
        let mut here = start;
        let bpx = self.coarse.b as f64;
        let least: Vec<f64> = pieces
            .iter()
            .map(|p| p.inner.iter().copied().fold(f64::INFINITY, f64::min))
            .collect();
        let extra = |p: usize, v: usize| pieces[p].inner[v] - least[p];
        let better = |c: f64, p: usize, v: usize, b: Option<(f64, usize, usize)>| {
            b.is_none_or(|b| c < b.0 || (c == b.0 && (p, v) < (b.1, b.2)))
        };
        for _ in 0..pieces.len() {
            let mut best: Option<(f64, usize, usize)> = None;
            let r = self.row_of[self.coarse.block(here)];
            if r != u32::MAX {
                for &(k, g) in &self.rows[r as usize] {
                    let kr = self.row_of[k as usize] as usize;
                    if left[kr] == 0 {
                        continue;
                    }
                    let g_px = f64::from(g) / 10.0 * bpx;
                    for &(p, v) in &at_row[kr] {
                        if done[p] {
                            continue;
                        }
                        let e = euclid(here, pieces[p].entry[v]);
                        let hop = if e < bpx { e } else { e.max(g_px) };
                        let c = hop + extra(p, v);
                        if better(c, p, v, best) {
                            best = Some((c, p, v));
                        }
                    }
                }
            }
            if best.is_none() {
                for (p, piece) in pieces.iter().enumerate() {
                    if done[p] {
                        continue;
                    }
                    for (v, &e) in piece.entry.iter().enumerate() {
                        let c = self.dist(here, e) + extra(p, v);
                        if better(c, p, v, best) {
                            best = Some((c, p, v));
                        }
                    }
                }
            }
            let Some((_, p, v)) = best else { break };
            done[p] = true;
            for &e in &pieces[p].entry {
                left[self.row_of[self.coarse.block(e)] as usize] -= 1;
            }
            tour.push((p, v));
            here = pieces[p].exit[v];
        }
        tour
    }
}

/// Straight-line distance (plain square root: hop costs are asked for millions of times).
fn euclid(a: Point, b: Point) -> f64 {
    let (dx, dy) = (a.x - b.x, a.y - b.y);
    (dx * dx + dy * dy).sqrt()
}

/// Whole-map path costs between the far blocks holding end points (module docs).
struct Far<'a> {
    coarse: &'a Coarse,
    row_of: Vec<u32>,
    /// Square matrix of path costs in tenths of a far block (`u16::MAX`: not joined).
    dense: Vec<u16>,
    m: usize,
}

impl<'a> Far<'a> {
    fn new(coarse: &'a Coarse, pieces: &[tsp::Piece], start: Point) -> Self {
        let n = coarse.bw * coarse.bh;
        let mut row_of = vec![u32::MAX; n];
        let mut blocks: Vec<usize> = Vec::new();
        let mut add = |p: Point| {
            let k = coarse.block(p);
            if row_of[k] == u32::MAX {
                row_of[k] = 0;
                blocks.push(k);
            }
        };
        add(start);
        for piece in pieces {
            piece.entry.iter().chain(&piece.exit).for_each(|&p| add(p));
        }
        blocks.sort_unstable();
        for (i, &k) in blocks.iter().enumerate() {
            row_of[k] = i as u32;
        }
        let m = blocks.len();
        let mut dense = vec![u16::MAX; m * m];
        let mut g = vec![u32::MAX; n];
        let mut touched: Vec<usize> = Vec::new();
        let mut buckets: [Vec<usize>; BUCKETS] = std::array::from_fn(|_| Vec::new());
        for (i, &s) in blocks.iter().enumerate() {
            let out = &mut dense[i * m..(i + 1) * m];
            coarse.search(
                s,
                u32::MAX - 14,
                &mut g,
                &mut touched,
                &mut buckets,
                |k, gk| {
                    if row_of[k] != u32::MAX {
                        out[row_of[k] as usize] = gk.min(u32::from(u16::MAX) - 1) as u16;
                    }
                },
            );
        }
        Self {
            coarse,
            row_of,
            dense,
            m,
        }
    }

    /// Estimated path cost (pixels) between `a` and `b`; 0 when unknown.
    fn path_px(&self, a: Point, b: Point) -> f64 {
        let (ra, rb) = (
            self.row_of[self.coarse.block(a)],
            self.row_of[self.coarse.block(b)],
        );
        if ra == u32::MAX || rb == u32::MAX {
            return 0.0;
        }
        let g = self.dense[ra as usize * self.m + rb as usize];
        if g == u16::MAX {
            return 0.0;
        }
        let bpx = self.coarse.b as f64;
        (f64::from(g) / 10.0 - 2.0 * std::f64::consts::SQRT_2) * bpx
    }
}

/// Z-order key of block `(c, r)`: the bits of the two coordinates interleaved.
fn morton(c: usize, r: usize) -> u64 {
    let spread = |v: usize| {
        let mut x = v as u64 & 0xffff_ffff;
        x = (x | (x << 16)) & 0x0000_ffff_0000_ffff;
        x = (x | (x << 8)) & 0x00ff_00ff_00ff_00ff;
        x = (x | (x << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
        x = (x | (x << 2)) & 0x3333_3333_3333_3333;
        (x | (x << 1)) & 0x5555_5555_5555_5555
    };
    spread(c) | (spread(r) << 1)
}
