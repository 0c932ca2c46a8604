//! Hop costs for the cell tour, computed once per tour.
//!
//! A hop between two points costs the straight-line distance, or the length of a shortest path
//! over a coarse grid of the C-free set when that is longer (walls between the points). The
//! grid's blocks of `b` pixels are split into the connected parts of their C-free pixels, with
//! the steps of the transfers' pixel search ([`Coarse`]); each part is a node, and two nodes
//! are joined when a pixel step crosses from one into the other (a diagonal block step also by
//! way of a side block). So two points in one block but on either side of a thin wall, or of a
//! squeeze the robot cannot pass, are two nodes, and their hop is costed by the way round; on
//! the bench map `cluttered_2000` a grid of whole blocks costed hops of 3 to 50 pixels that
//! are 160 to 3100 pixels when routed. Costs are integers (10 per side step, 14 per diagonal
//! step), so every search has a fixed order and ties break on the node index.
//!
//! Instead of searching each queried pair (the tour's improvement moves ask for the same hops
//! many times), [`HopTable`] runs one Dijkstra per node that holds an end point of some piece,
//! bounded to [`RADIUS_BLOCKS`] blocks of path, and keeps the costs to the other end-point
//! nodes in a sorted row. A pair beyond the radius (or not joined by the coarse grid within
//! it) is costed on a second grid of blocks [`FAR_FACTOR`] times larger, searched whole from
//! each of its end-point nodes: the path there less two far-block diagonals (the points can
//! sit anywhere in their blocks), at least the radius and the straight line. A table of
//! every pair grows with the square of the end-point nodes, so beyond [`FAR_EXACT_MAX`] of
//! them the far grid gives landmark lower bounds instead (searches from [`LANDMARKS`] nodes;
//! `Far`). Both grids depend on the C-free set alone and are made once per plan
//! ([`CoarseCache`]).

use std::sync::{Arc, Mutex};

use super::tsp;
use crate::geometry::Point;

/// Search radius of each end point's Dijkstra, in blocks of path.
const RADIUS_BLOCKS: u32 = 24;
const _: () = assert!(RADIUS_BLOCKS * 10 < u8::MAX as u32);
/// Side of a far block, in blocks.
pub(super) const FAR_FACTOR: u32 = 4;
/// Largest hop matrix kept dense (bytes).
const DENSE_MAX: usize = 16 << 20;

/// Rows of a [`HopTable`] searched between two looks at the stop flag (a table of a large
/// map holds tens of thousands of rows and took seconds).
const STOP_EVERY_ROWS: usize = 16;

/// The coarse grid of the C-free set: blocks of `b` x `b` pixels, each split into the connected
/// parts of its C-free pixels (the *nodes*), joined where a pixel step crosses from one block's
/// part into the next block's.
///
/// Pixel steps are those of the transfers' pixel search ([`super::transfer`]'s `Search`): a
/// side step between C-free pixels, a diagonal one when both side pixels are C-free or the
/// straight move is free on the map. So two points whose nodes are not joined are not joined
/// by any transfer either, and a block holding C-free pixels on both sides of a thin wall (or
/// of a squeeze the robot cannot pass, a line of C-free pixels no step joins) is two nodes,
/// not one: such a hop is costed by the way round, not by the straight line.
pub(super) struct Coarse {
    b: usize,
    bw: usize,
    width: usize,
    height: usize,
    /// Per pixel: the number of its part within its block ([`NOT_FREE`]: not C-free). A block
    /// of more than 254 parts counts the rest as its part 254 (costs stay estimates).
    label: Vec<u8>,
    /// Per block: its first node (a block's nodes are consecutive); one more entry at the end.
    first: Vec<u32>,
    /// Per node: its first neighbour in `adj`; one more entry at the end.
    adj_start: Vec<u32>,
    /// Neighbours of the nodes: the node, with [`DIAG`] set when its block is a diagonal
    /// neighbour (a step of cost 14; 10 to a side block).
    adj: Vec<u32>,
}

/// The coarse grids of one plan's C-free set, made once per block size and shared by the
/// plan's parallel jobs (a grid depends on the C-free set and the block size alone, so which
/// job makes it changes nothing).
#[derive(Default)]
pub(super) struct CoarseCache(Mutex<Vec<(usize, Arc<Coarse>)>>);

impl CoarseCache {
    /// The grid in blocks of about `sp` pixels ([`Coarse::side`]), made by `make(sp)` when no
    /// grid of that block side is cached.
    pub(super) fn get(&self, sp: f64, make: impl FnOnce(f64) -> Coarse) -> Arc<Coarse> {
        let b = Coarse::side(sp);
        // (a job that panicked while holding the lock left no half-made grid in it)
        let mut grids = self
            .0
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some((_, g)) = grids.iter().find(|g| g.0 == b) {
            return Arc::clone(g);
        }
        let g = Arc::new(make(sp));
        grids.push((b, Arc::clone(&g)));
        g
    }
}

/// Marks a link to a diagonal block in [`Coarse::adj`] (node numbers stay below it: there are
/// fewer nodes than pixels).
const DIAG: u32 = 1 << 31;

/// [`Coarse::label`] of a pixel that is not C-free.
const NOT_FREE: u8 = u8::MAX;
/// Most parts a block keeps apart ([`Coarse::label`]).
const MAX_PARTS: u8 = NOT_FREE - 1;

/// Buckets of the circular bucket queue: more than the largest step cost.
const BUCKETS: usize = 16;

impl Coarse {
    /// The grid of the C-free set `ok` (row-major, `w` x `h` pixels) in blocks of about `sp`
    /// pixels (at least 4); `move_free(i, j)` tells whether the straight move between the
    /// centres of pixels `i` and `j` is free on the map (asked of a diagonal step whose side
    /// pixels are not both C-free).
    ///
    /// `stop` is asked once per row of blocks: when it says so, the grid of an empty C-free
    /// set is returned instead (the plan is being given up; the grid of a 4000 x 4000 px
    /// map took a second, during which a Python Ctrl-C held the next run: hostile pass).
    pub(super) fn new(
        w: usize,
        h: usize,
        ok: &[bool],
        move_free: impl Fn(usize, usize) -> bool,
        sp: f64,
        stop: &dyn Fn() -> bool,
    ) -> Self {
        let b = Self::side(sp);
        let (bw, bh) = (w.div_ceil(b), h.div_ceil(b));
        let given_up = || Self {
            b,
            bw,
            width: w,
            height: h,
            label: vec![NOT_FREE; w * h],
            first: vec![0; bw * bh + 1],
            adj_start: vec![0],
            adj: Vec::new(),
        };
        // A diagonal pixel step from `i` to `j` (both C-free): as the transfers' search.
        let diag = |i: usize, j: usize| {
            let (ci, ri, cj, rj) = (i % w, i / w, j % w, j / w);
            (ok[ri * w + cj] && ok[rj * w + ci]) || move_free(i, j)
        };
        // Parts of each block: first joined by side steps and by the diagonal steps whose side
        // pixels are both C-free (no map test), then by the other diagonal steps, each tested
        // only when it would join two parts not joined yet (union-find over the block).
        let mut label = vec![NOT_FREE; w * h];
        let mut first = Vec::with_capacity(bw * bh + 1);
        let mut nodes = 0u32;
        let mut stack: Vec<usize> = Vec::new();
        let mut parent: Vec<u32> = Vec::new();
        let mut pix: Vec<(usize, u32)> = Vec::new();
        for br in 0..bh {
            if stop() {
                return given_up();
            }
            for bc in 0..bw {
                first.push(nodes);
                let (r0, r1) = (br * b, ((br + 1) * b).min(h));
                let (c0, c1) = (bc * b, ((bc + 1) * b).min(w));
                let inside = |c: i64, r: i64| {
                    c >= c0 as i64 && c < c1 as i64 && r >= r0 as i64 && r < r1 as i64
                };
                parent.clear();
                pix.clear();
                for r in r0..r1 {
                    for c in c0..c1 {
                        let i = r * w + c;
                        if !ok[i] || label[i] != NOT_FREE {
                            continue;
                        }
                        // (provisional labels count up from 0 in `parent`; at most b * b)
                        let part = parent.len() as u32;
                        parent.push(part);
                        label[i] = 0;
                        pix.push((i, part));
                        stack.push(i);
                        while let Some(k) = stack.pop() {
                            let (c, r) = ((k % w) as i64, (k / w) as i64);
                            for (dc, dr) in DIRS {
                                let (nc, nr) = (c + dc, r + dr);
                                if !inside(nc, nr) {
                                    continue;
                                }
                                let j = nr as usize * w + nc as usize;
                                if !ok[j] || label[j] != NOT_FREE {
                                    continue;
                                }
                                if dc != 0 && dr != 0 {
                                    let (sa, sb) = (
                                        r as usize * w + nc as usize,
                                        nr as usize * w + c as usize,
                                    );
                                    if !(ok[sa] && ok[sb]) {
                                        continue;
                                    }
                                }
                                label[j] = 0;
                                pix.push((j, part));
                                stack.push(j);
                            }
                        }
                    }
                }
                let find = |parent: &mut Vec<u32>, mut x: u32| {
                    while parent[x as usize] != x {
                        let up = parent[parent[x as usize] as usize];
                        parent[x as usize] = up;
                        x = up;
                    }
                    x
                };
                // By pixel: to find a pixel's part, and to number parts by their smallest pixel.
                pix.sort_unstable();
                if parent.len() > 1 {
                    // The diagonal steps between parts.
                    let part_of =
                        |i: usize| pix.binary_search_by_key(&i, |e| e.0).map(|k| pix[k].1);
                    for k in 0..pix.len() {
                        let (i, pa) = pix[k];
                        let (c, r) = ((i % w) as i64, (i / w) as i64);
                        for (dc, dr) in [(1i64, 1i64), (-1, 1)] {
                            let (nc, nr) = (c + dc, r + dr);
                            if !inside(nc, nr) {
                                continue;
                            }
                            let j = nr as usize * w + nc as usize;
                            if !ok[j] {
                                continue;
                            }
                            let Ok(pb) = part_of(j) else { continue };
                            let (ra, rb) = (find(&mut parent, pa), find(&mut parent, pb));
                            if ra != rb && diag(i, j) {
                                parent[ra.max(rb) as usize] = ra.min(rb);
                            }
                        }
                    }
                }
                // Compact part numbers, in the order of their smallest pixel.
                let mut number: Vec<u32> = vec![u32::MAX; parent.len()];
                let mut parts = 0u32;
                for &(i, part) in &pix {
                    let root = find(&mut parent, part) as usize;
                    if number[root] == u32::MAX {
                        number[root] = parts;
                        parts += 1;
                    }
                    label[i] = number[root].min(u32::from(MAX_PARTS)) as u8;
                }
                nodes += parts.min(u32::from(MAX_PARTS) + 1);
            }
        }
        first.push(nodes);
        let node = |i: usize| {
            let (c, r) = (i % w, i / w);
            first[(r / b) * bw + c / b] + u32::from(label[i])
        };
        // Links: every pixel step that crosses into another block joins the two parts. Only
        // the pixels on a block's last column or row step out of it east, south, south-east or
        // south-west (the other four steps are these reversed); a block's links are made
        // unique before they are kept (a border of `b` pixels mostly repeats one link).
        let mut links: Vec<(u32, u32)> = Vec::new();
        let mut local: Vec<(u32, u32)> = Vec::new();
        for br in 0..bh {
            for bc in 0..bw {
                let (r0, r1) = (br * b, ((br + 1) * b).min(h));
                let (c0, c1) = (bc * b, ((bc + 1) * b).min(w));
                local.clear();
                let border = (r0..r1)
                    .map(|r| (c1 - 1, r))
                    .chain((c0..c1 - 1).map(|c| (c, r1 - 1)))
                    .chain((r0..r1 - 1).map(|r| (c0, r)));
                for (c, r) in border {
                    let i = r * w + c;
                    if !ok[i] {
                        continue;
                    }
                    for (dc, dr) in [(1i64, 0i64), (0, 1), (1, 1), (-1, 1)] {
                        let (nc, nr) = (c as i64 + dc, r as i64 + dr);
                        if nc < 0 || nc >= w as i64 || nr >= h as i64 {
                            continue;
                        }
                        let (nc, nr) = (nc as usize, nr as usize);
                        let (sc, sr) = (nc / b != bc, nr / b != br);
                        if !sc && !sr {
                            continue;
                        }
                        let j = nr * w + nc;
                        if !ok[j] {
                            continue;
                        }
                        let link = (node(i), node(j) | if sc && sr { DIAG } else { 0 });
                        if dc != 0 && dr != 0 && !local.contains(&link) && !diag(i, j) {
                            continue;
                        }
                        local.push(link);
                    }
                }
                local.sort_unstable();
                local.dedup();
                links.extend_from_slice(&local);
            }
        }
        // Both ways of every link, per node (counting sort).
        let n = nodes as usize;
        let mut start = vec![0u32; n + 1];
        for &(a, e) in &links {
            start[a as usize + 1] += 1;
            start[(e & !DIAG) as usize + 1] += 1;
        }
        for k in 0..n {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let mut direct = vec![0u32; start[n] as usize];
        for &(a, e) in &links {
            let (bn, d) = (e & !DIAG, e & DIAG);
            direct[fill[a as usize] as usize] = e;
            fill[a as usize] += 1;
            direct[fill[bn as usize] as usize] = a | d;
            fill[bn as usize] += 1;
        }
        drop(links);
        drop(fill);
        // A diagonal block step also goes round by a side block: part `a` to part `c` of a
        // diagonal block when a part `m` of a side block joins both by side links. Each node's
        // neighbours, made unique (a neighbour by one link only, the side or the diagonal one
        // its blocks make it).
        let slice = |k: u32| &direct[start[k as usize] as usize..start[k as usize + 1] as usize];
        let mut adj_start = Vec::with_capacity(n + 1);
        let mut adj: Vec<u32> = Vec::with_capacity(direct.len());
        let mut mine: Vec<u32> = Vec::new();
        for a in 0..nodes {
            adj_start.push(adj.len() as u32);
            mine.clear();
            mine.extend_from_slice(slice(a));
            let ba = block_of(&first, a);
            for &m in slice(a) {
                if m & DIAG != 0 {
                    continue;
                }
                for &c in slice(m) {
                    if c & DIAG != 0 || c == a {
                        continue;
                    }
                    let bc = block_of(&first, c);
                    if (ba % bw).abs_diff(bc % bw) == 1 && (ba / bw).abs_diff(bc / bw) == 1 {
                        mine.push(c | DIAG);
                    }
                }
            }
            mine.sort_unstable_by_key(|&e| e & !DIAG);
            mine.dedup_by_key(|e| *e & !DIAG);
            adj.extend(mine.iter().filter(|&&e| e & !DIAG != a));
        }
        adj_start.push(adj.len() as u32);
        adj.shrink_to_fit();
        Self {
            b,
            bw,
            width: w,
            height: h,
            label,
            first,
            adj_start,
            adj,
        }
    }

    /// The block side for about `sp` pixels (at least 4).
    fn side(sp: f64) -> usize {
        (sp.round() as usize).max(4)
    }

    /// Nodes of the grid.
    fn nodes(&self) -> usize {
        self.adj_start.len() - 1
    }

    /// The block of node `n`.
    fn block_of(&self, n: u32) -> usize {
        block_of(&self.first, n)
    }

    /// The node of grid point `p` (grid y up): that of its pixel when C-free, else of the
    /// nearest C-free pixel centre within two pixels (ties: the first in row-major order);
    /// `None` when there is none.
    fn node(&self, p: Point) -> Option<u32> {
        let (w, h) = (self.width as i64, self.height as i64);
        let col = p.x.floor();
        let row = h as f64 - 1.0 - p.y.floor();
        if !(col.is_finite() && row.is_finite()) {
            return None;
        }
        let (c0, r0) = (col as i64, row as i64);
        let at = |c: i64, r: i64| -> Option<u32> {
            if c < 0 || r < 0 || c >= w || r >= h {
                return None;
            }
            let (c, r) = (c as usize, r as usize);
            let l = self.label[r * self.width + c];
            (l != NOT_FREE).then(|| self.first[(r / self.b) * self.bw + c / self.b] + u32::from(l))
        };
        if let Some(n) = at(c0, r0) {
            return Some(n);
        }
        let mut best: Option<(f64, u32)> = None;
        for r in r0 - 2..=r0 + 2 {
            for c in c0 - 2..=c0 + 2 {
                if let Some(n) = at(c, r) {
                    let (x, y) = (c as f64 + 0.5, (h - r) as f64 - 0.5);
                    let d = (x - p.x).powi(2) + (y - p.y).powi(2);
                    if best.is_none_or(|b| d < b.0) {
                        best = Some((d, n));
                    }
                }
            }
        }
        best.map(|b| b.1)
    }

    /// Shortest path costs (tenths of a block) from node `s` over the links, up to `cap`:
    /// `visit(n, g)` is called once for every node reached, in non-decreasing `g`, until it
    /// returns `false`. `g` must
    /// hold `u32::MAX` everywhere and is left so; `touched` and `buckets` are scratch. (Costs
    /// are small integers, so a circular bucket queue gives the exact Dijkstra costs.)
    fn search(
        &self,
        s: u32,
        cap: u32,
        g: &mut [u32],
        touched: &mut Vec<u32>,
        buckets: &mut [Vec<u32>; BUCKETS],
        mut visit: impl FnMut(u32, u32) -> bool,
    ) {
        g[s as usize] = 0;
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
            if g[k as usize] != d {
                continue;
            }
            if !visit(k, d) {
                break;
            }
            let (a, z) = (
                self.adj_start[k as usize] as usize,
                self.adj_start[k as usize + 1] as usize,
            );
            for &e in &self.adj[a..z] {
                let (j, ng) = (e & !DIAG, d + if e & DIAG != 0 { 14 } else { 10 });
                if ng <= cap && ng < g[j as usize] {
                    if g[j as usize] == u32::MAX {
                        touched.push(j);
                    }
                    g[j as usize] = ng;
                    buckets[ng as usize % BUCKETS].push(j);
                    queued += 1;
                }
            }
        }
        for &k in touched.iter() {
            g[k as usize] = u32::MAX;
        }
        touched.clear();
        // (left over when `visit` stopped the search)
        buckets.iter_mut().for_each(Vec::clear);
    }
}

/// The block of node `n`, from the blocks' first nodes.
fn block_of(first: &[u32], n: u32) -> usize {
    first.partition_point(|&f| f <= n) - 1
}

/// The eight pixel steps (column, row): four side steps, then four diagonals.
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

/// One row of a [`HopTable`]: end-point nodes sorted by index, and the path cost to each in
/// tenths of a block (at most `10 * RADIUS_BLOCKS`, so a byte). Two exact-size slices, 5
/// bytes an entry: the rows grow with the square of the end points where the radius spans
/// the map, and as `Vec<(u32, u32)>` (8 bytes an entry, up to twice that in spare capacity)
/// they were most of bcd's memory on cluttered maps (a 500 x 500 px map of 1 % salt noise at
/// r = 0.05 m peaked at 404 MB against an estimate of 81 MB: hostile pass).
#[derive(Default)]
struct HopRow {
    node: Box<[u32]>,
    cost: Box<[u8]>,
}

// Every cost a row holds fits a byte.
const _: () = assert!(RADIUS_BLOCKS * 10 < u8::MAX as u32);

impl HopRow {
    #[cfg(test)]
    fn is_empty(&self) -> bool {
        self.node.is_empty()
    }

    /// The (node, cost) entries, by node.
    fn iter(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.node
            .iter()
            .zip(self.cost.iter())
            .map(|(&k, &g)| (k, u32::from(g)))
    }
}

/// Hop costs between the end points of a set of pieces (module docs).
pub(super) struct HopTable<'a> {
    coarse: &'a Coarse,
    far: Far<'a>,
    /// Per node: its row in `rows`, or `u32::MAX` when no end point lies in it.
    row_of: Vec<u32>,
    /// Per end-point node: the other end-point nodes within the radius and their path costs.
    rows: Vec<HopRow>,
    /// The node of each row.
    nodes: Vec<u32>,
    /// `rows` as a square matrix (`u8::MAX`: beyond the radius), when it has at most
    /// [`DENSE_MAX`] entries; empty otherwise.
    dense: Vec<u8>,
    /// The rows of every end point and of `start`, by the bits of its coordinates
    /// ([`EndRows`]).
    ends: PointMap<EndRows>,
}

/// The rows of a point in a [`HopTable`] and in its [`Far`] costs (`u32::MAX`: none), as
/// [`HopTable::row`] and [`Far::row`] give them. The tour asks for the hops between the same
/// end points millions of times; each look-up of a row from the point reads two large arrays
/// per grid (the pixel's part and its block's first node), and on `office_4096` at `--radius
/// 0.1` those reads were about a sixth of the planning time.
#[derive(Clone, Copy)]
struct EndRows {
    row: u32,
    far: u32,
}

/// A hasher for keys written as whole words (the bits of a point's coordinates here, a hop's
/// end points in `plan`): mixed per word, then finished with the `MurmurHash3` finaliser
/// (pixel-centre coordinates have all-zero low mantissa bits, which a plain multiply would
/// leave in the low bits the table indexes by). bcd's maps are only looked up, never
/// iterated, so the hash does not affect any plan; the standard library's default hasher is
/// seeded per process and several times slower on these small keys.
#[derive(Default, Clone, Copy)]
pub(super) struct WordHasher(u64);

impl std::hash::Hasher for WordHasher {
    fn finish(&self) -> u64 {
        let mut h = self.0;
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        h ^ (h >> 33)
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(29) ^ v).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    }
}

/// A map keyed by the bits of a point's coordinates ([`WordHasher`]).
type PointMap<V> =
    std::collections::HashMap<(u64, u64), V, std::hash::BuildHasherDefault<WordHasher>>;

/// The row (of `row_of`, per node of `coarse`) of the node holding `p`; `u32::MAX` when `p` is
/// in no node or its node holds no end point. One function for the near table and the far
/// costs, whose rows are looked up alike.
fn end_row(coarse: &Coarse, row_of: &[u32], p: Point) -> u32 {
    coarse.node(p).map_or(u32::MAX, |k| row_of[k as usize])
}

/// The key of point `p` in a [`PointMap`]: its exact coordinates, so that a value cached for
/// a point is the value computed from that very point.
fn point_key(p: Point) -> (u64, u64) {
    (p.x.to_bits(), p.y.to_bits())
}

/// The nodes of `coarse` holding the entries and exits of `pieces` and `start` (once each, in
/// no particular order) and a row index per node (`u32::MAX` for the others, 0 for these).
fn end_nodes(coarse: &Coarse, pieces: &[tsp::Piece], start: Point) -> (Vec<u32>, Vec<u32>) {
    let mut row_of = vec![u32::MAX; coarse.nodes()];
    let mut nodes: Vec<u32> = Vec::new();
    let mut add = |p: Point| {
        if let Some(k) = coarse.node(p) {
            if row_of[k as usize] == u32::MAX {
                row_of[k as usize] = 0;
                nodes.push(k);
            }
        }
    };
    add(start);
    for piece in pieces {
        piece.entry.iter().chain(&piece.exit).for_each(|&p| add(p));
    }
    (nodes, row_of)
}

impl<'a> HopTable<'a> {
    /// The table for the entries and exits of `pieces` and the point `start`. Once `stop`
    /// says the plan is given up, the rows not searched yet stay empty (every hop from them
    /// is then priced on the far grid): a table for a plan nobody will use, made quickly.
    pub(super) fn new(
        coarse: &'a Coarse,
        far: &'a Coarse,
        pieces: &[tsp::Piece],
        start: Point,
        stop: tsp::Stop<'_>,
    ) -> Self {
        let (mut nodes, mut row_of) = end_nodes(coarse, pieces, start);
        // Z-order of their blocks, so that the rows and columns of nearby nodes (the hops
        // asked for most) lie close together in the table.
        nodes.sort_unstable_by_key(|&k| {
            let blk = coarse.block_of(k);
            (morton(blk % coarse.bw, blk / coarse.bw), k)
        });
        for (i, &k) in nodes.iter().enumerate() {
            row_of[k as usize] = i as u32;
        }
        let cap = RADIUS_BLOCKS * 10;
        let mut g = vec![u32::MAX; coarse.nodes()];
        let mut touched: Vec<u32> = Vec::new();
        let mut buckets: [Vec<u32>; BUCKETS] = std::array::from_fn(|_| Vec::new());
        let mut rows: Vec<HopRow> = Vec::with_capacity(nodes.len());
        let mut row: Vec<(u32, u32)> = Vec::new();
        for (i, &s) in nodes.iter().enumerate() {
            if i.is_multiple_of(STOP_EVERY_ROWS) && stop() {
                rows.resize_with(nodes.len(), HopRow::default);
                break;
            }
            row.clear();
            coarse.search(s, cap, &mut g, &mut touched, &mut buckets, |k, gk| {
                if row_of[k as usize] != u32::MAX {
                    row.push((k, gk));
                }
                true
            });
            row.sort_unstable();
            rows.push(HopRow {
                node: row.iter().map(|e| e.0).collect(),
                // (searched within `cap` = 10 * RADIUS_BLOCKS <= 255)
                cost: row
                    .iter()
                    .map(|e| e.1.min(u32::from(u8::MAX - 1)) as u8)
                    .collect(),
            });
        }
        // Dense copy when small enough: one byte per pair (costs are at most 10 * radius).
        let m = nodes.len();
        let dense = if m * m <= DENSE_MAX {
            let mut d = vec![u8::MAX; m * m];
            for (i, row) in rows.iter().enumerate() {
                for (k, g) in row.iter() {
                    d[i * m + row_of[k as usize] as usize] = g as u8;
                }
            }
            d
        } else {
            Vec::new()
        };
        let mut table = Self {
            coarse,
            far: Far::new(far, pieces, start),
            row_of,
            rows,
            nodes,
            dense,
            ends: PointMap::default(),
        };
        let mut ends = PointMap::default();
        for p in
            std::iter::once(&start).chain(pieces.iter().flat_map(|c| c.entry.iter().chain(&c.exit)))
        {
            ends.entry(point_key(*p))
                .or_insert_with(|| table.rows_of_uncached(*p));
        }
        table.ends = ends;
        table
    }

    /// The rows of `p` ([`EndRows`]), found from the point itself.
    fn rows_of_uncached(&self, p: Point) -> EndRows {
        EndRows {
            row: end_row(self.coarse, &self.row_of, p),
            far: end_row(self.far.coarse, &self.far.row_of, p),
        }
    }

    /// The rows of `p` ([`EndRows`]): cached for the end points and the start, found from
    /// the point for any other.
    fn rows_of(&self, p: Point) -> EndRows {
        match self.ends.get(&point_key(p)) {
            Some(&r) => r,
            None => self.rows_of_uncached(p),
        }
    }

    /// The row of the node of `p`, if it holds an end point.
    fn row(&self, p: Point) -> Option<u32> {
        let r = self.rows_of(p).row;
        (r != u32::MAX).then_some(r)
    }

    /// Path cost (pixels) between the nodes of rows `ra` and `rb` when within the radius.
    fn path_px(&self, ra: u32, rb: u32) -> Option<f64> {
        if !self.dense.is_empty() {
            let m = self.nodes.len();
            let g = self.dense[ra as usize * m + rb as usize];
            return (g != u8::MAX).then(|| f64::from(g) / 10.0 * self.coarse.b as f64);
        }
        let kb = self.nodes[rb as usize];
        let row = &self.rows[ra as usize];
        let i = row.node.binary_search(&kb).ok()?;
        Some(f64::from(row.cost[i]) / 10.0 * self.coarse.b as f64)
    }

    /// The hop cost from `a` to `b` (pixels; module docs): the straight line within one
    /// node (or where a point lies in none), else the longer of the straight line and the way
    /// over the coarse grid.
    pub(super) fn dist(&self, a: Point, b: Point) -> f64 {
        let e = euclid(a, b);
        let (ea, eb) = (self.rows_of(a), self.rows_of(b));
        let (ra, rb) = (ea.row, eb.row);
        if ra == u32::MAX || rb == u32::MAX || ra == rb {
            return e;
        }
        match self.path_px(ra, rb) {
            Some(g) => e.max(g),
            None => e
                .max(f64::from(RADIUS_BLOCKS) * self.coarse.b as f64)
                .max(self.far.rows_px(ea.far, eb.far)),
        }
    }

    /// Nearest-neighbour tour: from each exit, the piece entries within the radius are ranked
    /// by hop cost plus the variant's extra inner cost over the piece's cheapest variant (ties:
    /// piece, then variant); where none is left within it, every remaining entry the same way.
    pub(super) fn nearest_tour(&self, pieces: &[tsp::Piece], start: Point) -> tsp::Tour {
        let mut at_row: Vec<Vec<(usize, usize)>> = vec![Vec::new(); self.nodes.len()];
        // Entries in no node are only reached by the fallback below.
        for (p, piece) in pieces.iter().enumerate() {
            for (v, &e) in piece.entry.iter().enumerate() {
                if let Some(r) = self.row(e) {
                    at_row[r as usize].push((p, v));
                }
            }
        }
        let mut done = vec![false; pieces.len()];
        // Undone entries per row, so exhausted rows are skipped in O(1).
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
        // Every entry with its piece and variant, for the fallback below.
        let entries: Vec<(Point, usize, usize)> = pieces
            .iter()
            .enumerate()
            .flat_map(|(p, piece)| piece.entry.iter().enumerate().map(move |(v, &e)| (e, p, v)))
            .collect();
        // Scratch of the fallback: (bound, piece, variant) of the remaining entries.
        let mut bounds: Vec<(f64, usize, usize)> = Vec::new();
        for _ in 0..pieces.len() {
            let mut best: Option<(f64, usize, usize)> = None;
            if let Some(r) = self.row(here) {
                for (k, g) in self.rows[r as usize].iter() {
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
                        // (as `dist`: the straight line within one node)
                        let hop = if kr == r as usize { e } else { e.max(g_px) };
                        let c = hop + extra(p, v);
                        if better(c, p, v, best) {
                            best = Some((c, p, v));
                        }
                    }
                }
            }
            if best.is_none() {
                // Every remaining entry, its cost `dist + extra` asked only where its bound,
                // the straight line plus the extra (`dist` is never below the straight line
                // `euclid` gives, and floating-point sums are monotone), is not above the best
                // cost found: an entry above it cannot win or tie, so the choice is that of
                // costing them all (which took a fifth of the planning time on
                // `office_4096` at `--radius 0.1`, thousands of times over every entry).
                bounds.clear();
                bounds.extend(
                    entries
                        .iter()
                        .filter(|e| !done[e.1])
                        .map(|&(e, p, v)| (euclid(here, e) + extra(p, v), p, v)),
                );
                // Least bound first (ties in any order: all entries up to the best cost are
                // costed, and `better` orders them whatever the order of asking). A NaN cost
                // (a NaN bound) is kept only when asked first, so then the entries are asked
                // in their order, every one, as before.
                let sorted = !bounds.iter().any(|b| b.0.is_nan());
                if sorted {
                    bounds.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
                }
                for &(lb, p, v) in &bounds {
                    if sorted && best.is_some_and(|b: (f64, usize, usize)| lb > b.0) {
                        break;
                    }
                    let c = self.dist(here, pieces[p].entry[v]) + extra(p, v);
                    if better(c, p, v, best) {
                        best = Some((c, p, v));
                    }
                }
            }
            let Some((_, p, v)) = best else { break };
            done[p] = true;
            for &e in &pieces[p].entry {
                if let Some(r) = self.row(e) {
                    left[r as usize] -= 1;
                }
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

/// Whole-map path costs between the far nodes holding end points (module docs).
struct Far<'a> {
    coarse: &'a Coarse,
    row_of: Vec<u32>,
    costs: FarCosts,
}

/// Most end-point nodes whose far costs are kept exact ([`FarCosts::Exact`]: a triangle of
/// `m (m + 1) / 2` two-byte costs, 16 MiB here, and one search per node). On the 14 shared
/// maps (r 0.15 m) `m` is at most 1140 (`stage_willow_full`) and on the bench map
/// `cluttered_2000` 2430; `office_4096` at `--radius 0.1` has 27 000, whose triangle (730 MB
/// per table, several tables alive at once) and searches (each over most of the grid) grew
/// with the map's square.
const FAR_EXACT_MAX: usize = 4096;
/// Landmarks of [`FarCosts::Landmarks`]. On `office_4096` at `--radius 0.1` (`ccpp plan
/// --planner bcd`, single runs): the exact table 412 s, 3.52 GB peak, path 199 918 m; 24
/// landmarks 103 s, 2.30 GB, 200 894 m; 64 landmarks 111 s, 2.31 GB, 200 495 m.
const LANDMARKS: usize = 64;

/// The far grid's path costs (tenths of a far block) between end-point nodes.
enum FarCosts {
    /// Exact costs between rows `i >= j` at [`tri`]`(i, j)` (`u16::MAX`: not joined; costs
    /// are the same both ways: links join both ways at one cost).
    Exact(Vec<u16>),
    /// Lower bounds from landmarks (ALT: Goldberg and Harrelson, "Computing the shortest path:
    /// A* search meets graph theory", SODA 2005): the path costs from each of `k` landmarks to
    /// every row (`d[row * k + l]`, `u32::MAX`: not joined), and the cost between two rows is at
    /// least `max_l |d(l, a) - d(l, b)|` by the triangle inequality. Memory and time grow with
    /// the number of rows, not its square.
    Landmarks { k: usize, d: Vec<u32> },
}

/// Index of the pair of rows `i >= j` in [`FarCosts::Exact`].
fn tri(i: usize, j: usize) -> usize {
    i * (i + 1) / 2 + j
}

impl<'a> Far<'a> {
    fn new(coarse: &'a Coarse, pieces: &[tsp::Piece], start: Point) -> Self {
        Self::with_limit(coarse, pieces, start, FAR_EXACT_MAX)
    }

    /// [`Self::new`] with exact costs only up to `exact_max` end-point nodes.
    fn with_limit(
        coarse: &'a Coarse,
        pieces: &[tsp::Piece],
        start: Point,
        exact_max: usize,
    ) -> Self {
        let (mut nodes, mut row_of) = end_nodes(coarse, pieces, start);
        nodes.sort_unstable();
        for (i, &k) in nodes.iter().enumerate() {
            row_of[k as usize] = i as u32;
        }
        let costs = if nodes.len() <= exact_max {
            Self::exact(coarse, &nodes, &row_of)
        } else {
            Self::landmarks(coarse, &nodes, &row_of)
        };
        Self {
            coarse,
            row_of,
            costs,
        }
    }

    /// One search per end-point node, each stopping once it has reached the rows up to its own.
    fn exact(coarse: &Coarse, nodes: &[u32], row_of: &[u32]) -> FarCosts {
        let m = nodes.len();
        let mut costs = vec![u16::MAX; tri(m, 0)];
        let mut g = vec![u32::MAX; coarse.nodes()];
        let mut touched: Vec<u32> = Vec::new();
        let mut buckets: [Vec<u32>; BUCKETS] = std::array::from_fn(|_| Vec::new());
        for (i, &s) in nodes.iter().enumerate() {
            // The rows up to `i` (itself included); the search stops once it has reached them.
            let out = &mut costs[tri(i, 0)..=tri(i, i)];
            let mut left = i + 1;
            coarse.search(
                s,
                u32::MAX - 14,
                &mut g,
                &mut touched,
                &mut buckets,
                |k, gk| {
                    let r = row_of[k as usize] as usize;
                    if r <= i {
                        out[r] = gk.min(u32::from(u16::MAX) - 1) as u16;
                        left -= 1;
                    }
                    left > 0
                },
            );
        }
        FarCosts::Exact(costs)
    }

    /// [`LANDMARKS`] whole searches from landmarks picked farthest first: the first row's
    /// node, then each time the row farthest from every landmark so far (a row no landmark
    /// reaches counts as farthest, so each part of the grid gets one while landmarks last;
    /// ties: the lower row).
    fn landmarks(coarse: &Coarse, nodes: &[u32], row_of: &[u32]) -> FarCosts {
        let m = nodes.len();
        let k = LANDMARKS.min(m);
        let mut d = vec![u32::MAX; m * k];
        // Per row: the least cost from the landmarks so far (u64::MAX: none reaches it).
        let mut least = vec![u64::MAX; m];
        let mut g = vec![u32::MAX; coarse.nodes()];
        let mut touched: Vec<u32> = Vec::new();
        let mut buckets: [Vec<u32>; BUCKETS] = std::array::from_fn(|_| Vec::new());
        let mut next = 0usize;
        for l in 0..k {
            coarse.search(
                nodes[next],
                u32::MAX - 14,
                &mut g,
                &mut touched,
                &mut buckets,
                |n, gn| {
                    let r = row_of[n as usize];
                    if r != u32::MAX {
                        let r = r as usize;
                        d[r * k + l] = gn;
                        least[r] = least[r].min(u64::from(gn));
                    }
                    true
                },
            );
            // (`max_by_key` keeps the last of equal keys: compare on the row reversed)
            next = (0..m)
                .max_by_key(|&r| (least[r], std::cmp::Reverse(r)))
                .unwrap_or(0);
            if least[next] == 0 {
                break;
            }
        }
        FarCosts::Landmarks { k, d }
    }

    /// Estimated path cost (pixels) between `a` and `b`; 0 when unknown.
    #[cfg(test)]
    fn path_px(&self, a: Point, b: Point) -> f64 {
        let row = |p: Point| end_row(self.coarse, &self.row_of, p);
        self.rows_px(row(a), row(b))
    }

    /// Estimated path cost (pixels) between the end-point nodes of rows `ra` and `rb`
    /// (`u32::MAX`: a point in no such node); 0 when unknown.
    fn rows_px(&self, ra: u32, rb: u32) -> f64 {
        if ra == u32::MAX || rb == u32::MAX {
            return 0.0;
        }
        let (ra, rb) = (ra as usize, rb as usize);
        let g = match &self.costs {
            FarCosts::Exact(tri_costs) => {
                let g = tri_costs[tri(ra.max(rb), ra.min(rb))];
                if g == u16::MAX {
                    return 0.0;
                }
                u32::from(g)
            }
            FarCosts::Landmarks { k, d } => {
                let (da, db) = (&d[ra * k..(ra + 1) * k], &d[rb * k..(rb + 1) * k]);
                let mut lb: Option<u32> = None;
                for (&x, &y) in da.iter().zip(db) {
                    match (x == u32::MAX, y == u32::MAX) {
                        (false, false) => lb = Some(lb.unwrap_or(0).max(x.abs_diff(y))),
                        // Reached from a landmark that does not reach the other: not joined.
                        (true, false) | (false, true) => return 0.0,
                        (true, true) => {}
                    }
                }
                // (no landmark reaches either: unknown)
                let Some(lb) = lb else { return 0.0 };
                lb
            }
        };
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

#[cfg(test)]
mod tests {
    use super::{Coarse, CoarseCache, Far, HopTable, BUCKETS};
    use crate::geometry::{Point, Pose};
    use crate::grid::{Cell, GridMap, MapFrame};
    use crate::planners::bcd::lattice::Ctx;
    use crate::planners::bcd::transfer::Search;
    use crate::planners::bcd::tsp;
    use crate::world::{Robot, World};

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
            coarse: CoarseCache::default(),
            stop: None,
        }
    }

    /// A grid whose planning is given up while it is made is the grid of an empty C-free set
    /// (the plan is dropped; the grid must not index past its arrays meanwhile).
    #[test]
    fn a_grid_given_up_is_empty() {
        let (w, h) = (40, 30);
        let ok = vec![true; w * h];
        let whole = Coarse::new(w, h, &ok, |_, _| true, 6.0, &|| false);
        assert!(whole.nodes() > 0);
        let asked = std::cell::Cell::new(0);
        let given_up = Coarse::new(w, h, &ok, |_, _| true, 6.0, &|| {
            asked.set(asked.get() + 1);
            asked.get() > 2
        });
        assert_eq!(given_up.nodes(), 0);
        assert_eq!(given_up.first.len(), whole.first.len());
        assert!(given_up.node(Point::new(10.5, 10.5)).is_none());
    }

    /// Are the nodes of pixels `a` and `b` joined by the grid's links (unbounded search)?
    fn joined(grid: &Coarse, ctx: &Ctx<'_>, a: usize, b: usize) -> bool {
        let w = ctx.frame.width;
        let node = |i: usize| grid.node(ctx.centre(i % w, i / w)).expect("a C-free pixel");
        let (na, nb) = (node(a), node(b));
        let mut g = vec![u32::MAX; grid.nodes()];
        let mut touched = Vec::new();
        let mut buckets: [Vec<u32>; BUCKETS] = std::array::from_fn(|_| Vec::new());
        let mut hit = false;
        grid.search(
            na,
            u32::MAX - 14,
            &mut g,
            &mut touched,
            &mut buckets,
            |k, _| {
                hit |= k == nb;
                !hit
            },
        );
        hit
    }

    /// A wall down the middle of a room with a gap at the bottom: two points either side of
    /// it at the top lie in one block of the coarse grid, and the hop between them is costed
    /// by the way round through the gap, not by the straight line across the wall.
    ///
    /// ```text
    ///   ##########
    ///   #...#....#    a: left of the wall, b: right of it, both in one block
    ///   #...#....#
    ///   #...#....#
    ///   #...#....#
    ///   #........#    the gap
    ///   ##########
    /// ```
    #[test]
    fn a_wall_inside_a_block_is_gone_round() {
        let art =
            "##########\n#...#....#\n#...#....#\n#...#....#\n#...#....#\n#........#\n##########";
        let map = GridMap::from_ascii_scaled(art, 6, 0.02).expect("map");
        let world =
            World::new(map, Robot::new(0.03), Some(Pose::new(0.2, 0.2, 0.0))).expect("world");
        let ctx = ctx(&world);
        // (6 pixels a character, robot radius 1.5 pixels: the wall covers columns 24-29 and
        // the robot's centre keeps clear of columns 23-30.) Blocks of 20 pixels: columns
        // 20-39 are one block, holding C-free pixels of both sides.
        let grid = ctx.coarse_grid(20.0);
        let h = world.frame().height as f64;
        let a = Point::new(22.5, h - 8.5);
        let b = Point::new(33.5, h - 8.5);
        assert_eq!(
            grid.block_of(grid.node(a).unwrap()),
            grid.block_of(grid.node(b).unwrap())
        );
        assert_ne!(grid.node(a), grid.node(b), "two parts of one block");
        let far = ctx.coarse_grid(80.0);
        let piece = |p: Point| tsp::Piece {
            entry: vec![p],
            exit: vec![p],
            inner: vec![0.0],
        };
        let table = HopTable::new(&grid, &far, &[piece(a), piece(b)], a, &|| false);
        let d = table.dist(a, b);
        // The way round: down the wall (about 4 rows of 6 pixels) and up again.
        assert!(d > 3.0 * a.dist(b), "hop {d} px, straight {} px", a.dist(b));
        let mut search = Search::new(ctx.frame.width, ctx.frame.height);
        let route = ctx.route(&mut search, a, b).expect("a way through the gap");
        let len = crate::geometry::polyline_length(a, &route);
        assert!(d <= 1.2 * len, "hop {d} px against the route's {len} px");
    }

    /// A table given up before its first row holds an empty row per node and still prices
    /// every hop (no index out of range): by the straight line or the far grid, never below
    /// the straight line. Not given up, the same hop is priced by the way round.
    #[test]
    fn a_table_given_up_has_empty_rows_and_still_prices_hops() {
        let art =
            "##########\n#...#....#\n#...#....#\n#...#....#\n#...#....#\n#........#\n##########";
        let map = GridMap::from_ascii_scaled(art, 6, 0.02).expect("map");
        let world =
            World::new(map, Robot::new(0.03), Some(Pose::new(0.2, 0.2, 0.0))).expect("world");
        let ctx = ctx(&world);
        let grid = ctx.coarse_grid(20.0);
        let far = ctx.coarse_grid(80.0);
        let h = world.frame().height as f64;
        let pts = [
            Point::new(10.5, h - 8.5),
            Point::new(22.5, h - 20.5),
            Point::new(40.5, h - 8.5),
        ];
        let pieces: Vec<tsp::Piece> = pts
            .iter()
            .map(|&p| tsp::Piece {
                entry: vec![p],
                exit: vec![p],
                inner: vec![0.0],
            })
            .collect();
        let given_up = HopTable::new(&grid, &far, &pieces, pts[0], &|| true);
        assert_eq!(given_up.rows.len(), given_up.nodes.len());
        assert!(given_up.rows.iter().all(super::HopRow::is_empty));
        let full = HopTable::new(&grid, &far, &pieces, pts[0], &|| false);
        assert!(full.rows.iter().all(|r| !r.is_empty()));
        for &a in &pts {
            for &b in &pts {
                let d = given_up.dist(a, b);
                assert!(d.is_finite() && d >= a.dist(b) - 1e-9, "{d}");
            }
        }
        assert!(full.dist(pts[0], pts[2]) > 1.5 * pts[0].dist(pts[2]));
    }

    /// The grid's nodes are joined exactly when the transfers' pixel search finds a way
    /// between their pixels, on maps like real ones (walls at any offset with gaps narrower
    /// than the robot at some places, salt noise, several block sizes).
    #[test]
    fn nodes_are_joined_exactly_when_pixels_are() {
        let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let (w, h) = (90, 70);
        let (mut pairs, mut apart, mut in_block_apart) = (0, 0, 0);
        for map in 0..24 {
            let mut cells = vec![Cell::Free; w * h];
            for r in 0..h {
                for c in 0..w {
                    if r == 0 || c == 0 || r == h - 1 || c == w - 1 {
                        cells[r * w + c] = Cell::Occupied;
                    }
                }
            }
            // Walls with a gap of 4 to 9 pixels (the robot needs about 6).
            for _ in 0..(2 + next() % 4) {
                let vertical = next() % 2 == 0;
                let (len, at) = if vertical {
                    (h, 5 + next() as usize % (w - 10))
                } else {
                    (w, 5 + next() as usize % (h - 10))
                };
                let thick = 1 + next() as usize % 2;
                let gap = next() as usize % len;
                let gw = 4 + next() as usize % 6;
                for k in 0..len {
                    if k < gap || k >= gap + gw {
                        for t in 0..thick {
                            let j = if vertical {
                                k * w + (at + t).min(w - 1)
                            } else {
                                (at + t).min(h - 1) * w + k
                            };
                            cells[j] = Cell::Occupied;
                        }
                    }
                }
            }
            // Walls at a slant (steps of one pixel and the next), with a gap: the robot's
            // centre squeezes along them at single pixels, diagonally.
            for _ in 0..=(next() % 3) {
                let (c0, r0) = (next() as usize % w, next() as usize % h);
                let (dc, dr) = (
                    [1i64, -1][next() as usize % 2],
                    [1i64, -1][next() as usize % 2],
                );
                let slope = 1 + next() as usize % 3;
                let gap = next() as usize % 60;
                let gw = 4 + next() as usize % 5;
                let (mut c, mut r) = (c0 as i64, r0 as i64);
                for k in 0..80 {
                    if c <= 0 || r <= 0 || c >= w as i64 - 1 || r >= h as i64 - 1 {
                        break;
                    }
                    if k < gap || k >= gap + gw {
                        cells[r as usize * w + c as usize] = Cell::Occupied;
                    }
                    c += dc;
                    if k % slope == 0 {
                        r += dr;
                    }
                }
            }
            // A slanted corridor about the robot's width (two parallel slanted walls): the
            // robot's centre fits at single pixels only, some joined diagonally, some not.
            for _ in 0..2 {
                let (c0, r0) = (next() as usize % w, next() as usize % h);
                let apart = 5 + (next() % 5) as i64;
                let slope = 1 + next() as usize % 3;
                let dr = [1i64, -1][next() as usize % 2];
                for side in [0, apart] {
                    let (mut c, mut r) = (c0 as i64, r0 as i64 + side);
                    for k in 0..70 {
                        if c <= 0 || r <= 0 || c >= w as i64 - 1 || r >= h as i64 - 1 {
                            break;
                        }
                        cells[r as usize * w + c as usize] = Cell::Occupied;
                        c += 1;
                        if k % slope == 0 {
                            r += dr;
                        }
                    }
                }
            }
            let salt = [0, 1, 3][map % 3];
            for j in 0..w * h {
                if next() % 100 < salt {
                    cells[j] = Cell::Occupied;
                }
            }
            let frame = MapFrame::new(w, h, 0.05);
            let Ok(grid_map) = GridMap::new(frame, cells) else {
                continue;
            };
            // Start at some free spot the robot fits in.
            let Ok(world) = World::new(grid_map, Robot::new(0.14), None) else {
                continue;
            };
            // Every C-free pixel, not only the start's part: pairs in rooms no gap joins, and
            // pairs a squeeze the robot's centre passes only at one pixel may separate.
            let mut ctx = ctx(&world);
            ctx.ok = (0..w * h).map(|i| world.cfree().contains(i)).collect();
            let ok: Vec<usize> = (0..w * h).filter(|&i| ctx.ok[i]).collect();
            if ok.len() < 50 {
                continue;
            }
            let grid = ctx.coarse_grid([4.0, 6.0, 9.0][map % 3]);
            let mut search = Search::new(w, h);
            let diag = |i: usize, j: usize| ctx.pixel_move_free(i, j);
            let plain = |j: usize| ctx.ok[j];
            for q in 0..60 {
                let a = ok[next() as usize % ok.len()];
                // Every other pair lies within one block: the pixels beside the other side
                // of a wall (or of a squeeze) share a block with `a`.
                let b = if q % 2 == 0 {
                    ok[next() as usize % ok.len()]
                } else {
                    let (bs, w_) = (grid.b, w);
                    let near: Vec<usize> = ok
                        .iter()
                        .copied()
                        .filter(|&j| j / w_ / bs == a / w_ / bs && j % w_ / bs == a % w_ / bs)
                        .collect();
                    near[next() as usize % near.len()]
                };
                let by_pixels = search
                    .path(&plain, (a % w, a / w), (b % w, b / w), &diag)
                    .is_some();
                assert_eq!(
                    joined(&grid, &ctx, a, b),
                    by_pixels,
                    "map {map}, {a} -> {b}"
                );
                pairs += 1;
                apart += usize::from(!by_pixels);
                in_block_apart += usize::from(!by_pixels && q % 2 == 1);
            }
        }
        // Real comparisons, some of them between pixels no transfer joins.
        assert!(
            pairs > 800 && apart > 10 && in_block_apart > 5,
            "{pairs} pairs, {apart} apart, {in_block_apart} of them in one block"
        );
    }

    /// Beyond [`super::FAR_EXACT_MAX`] end-point nodes the far costs are landmark lower
    /// bounds: never above the exact costs, exact from the first landmark (the first row),
    /// "not joined" exactly where the exact table says so (a closed room), and not trivially
    /// low (a wall with a door at its end costs the way round).
    ///
    /// ```text
    ///   ####################
    ///   #.....#......#.....#
    ///   #.....#......#.....#   three rooms joined by doors at the bottom and the top,
    ///   #.....#......#.....#   and a closed room (right) that no way reaches
    ///   #.....#......#######
    ///   #..................#
    ///   ####################
    /// ```
    #[test]
    fn landmark_far_costs_bound_the_exact_ones_from_below() {
        let art = "####################\n\
                   #.....#......#.....#\n\
                   #.....#......#.....#\n\
                   #.....#......#.....#\n\
                   #.............######\n\
                   #.............#....#\n\
                   #.............#....#\n\
                   ####################";
        let map = GridMap::from_ascii_scaled(art, 8, 0.02).expect("map");
        let world =
            World::new(map, Robot::new(0.03), Some(Pose::new(0.2, 0.2, 0.0))).expect("world");
        let mut ctx = ctx(&world);
        let (w, h) = (ctx.frame.width, ctx.frame.height);
        ctx.ok = (0..w * h).map(|i| world.cfree().contains(i)).collect();
        let far = ctx.coarse_grid(4.0);
        // An end point every 3 pixels: many more end-point nodes than landmarks.
        let mut pts = Vec::new();
        for r in (0..h).step_by(3) {
            for c in (0..w).step_by(3) {
                if ctx.ok[r * w + c] {
                    pts.push(ctx.centre(c, r));
                }
            }
        }
        let pieces: Vec<tsp::Piece> = pts
            .iter()
            .map(|&p| tsp::Piece {
                entry: vec![p],
                exit: vec![p],
                inner: vec![0.0],
            })
            .collect();
        let start = pts[0];
        let exact = Far::with_limit(&far, &pieces, start, usize::MAX);
        let bound = Far::with_limit(&far, &pieces, start, 0);
        assert!(matches!(exact.costs, super::FarCosts::Exact(_)));
        assert!(matches!(bound.costs, super::FarCosts::Landmarks { .. }));
        let rows = exact.row_of.iter().filter(|&&r| r != u32::MAX).count();
        assert!(rows > 4 * super::LANDMARKS, "{rows} end-point nodes");
        // The first landmark: the node of the first row.
        let first = (0..far.nodes())
            .find(|&k| exact.row_of[k] == 0)
            .expect("a first row") as u32;
        let (mut apart, mut tight, mut pairs, mut from_first) = (0, 0, 0, 0);
        for (i, &a) in pts.iter().enumerate() {
            for &b in pts.iter().skip(i + 1).step_by(7) {
                let (e, l) = (exact.path_px(a, b), bound.path_px(a, b));
                assert!(l <= e + 1e-9, "{a:?} -> {b:?}: bound {l} above exact {e}");
                if e == 0.0 {
                    assert_eq!(l, 0.0, "{a:?} -> {b:?}: joined by landmarks only");
                    apart += 1;
                    continue;
                }
                pairs += 1;
                tight += usize::from(l >= 0.8 * e);
                if far.node(a) == Some(first) {
                    assert!((l - e).abs() < 1e-9, "from the first landmark: {l} vs {e}");
                    from_first += 1;
                }
            }
        }
        assert!(
            apart > 10 && from_first > 0,
            "{apart} apart, {from_first} from the first"
        );
        assert!(
            tight * 2 > pairs,
            "only {tight} of {pairs} bounds within 80 % of the exact cost"
        );
    }
}
