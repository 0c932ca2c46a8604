//! Ordering of coverage pieces as an open travelling-salesman path with orientations.
//!
//! Each piece (a BCD cell) can be driven in a few variants: variant `v` enters at `entry(v)`,
//! leaves at `exit(v)` and costs `inner(v)` inside the piece; variants come in pairs, `v ^ 1`
//! being `v` driven backwards (its entry is `v`'s exit and the other way round, same inner
//! cost). The path starts at a fixed point and visits every piece once; the cost of a hop is
//! given ([`Dist`]), never below the straight-line distance. Construction: nearest neighbour
//! from the start. Improvement, repeated
//! until a round changes nothing (or `rounds` is spent): 2-opt (a reversed stretch drives each of
//! its pieces backwards), Or-opt (stretches of 1 to 3 pieces moved elsewhere, either way round;
//! a single piece in any of its variants),
//! both tried only where a new hop joins one of a piece's 12 nearest pieces, and an exact dynamic
//! programme that picks every piece's variant for the current order.
//! The moves read the tour's current hops from a per-position cache and skip a move whose new
//! hops, costed in a straight line (a lower bound), already cannot win; neither changes which
//! move is taken (most candidate moves were costed on the hop table only to be refused: on
//! `stage_willow_full`, r = 0.15 m, the whole run's CPU time falls from 6.9 s to 4.6 s).
//! Everything is deterministic: fixed scan orders, strict improvements only, ties to the lower
//! index.

use crate::geometry::Point;

/// One piece to visit.
#[derive(Clone, Debug)]
pub(crate) struct Piece {
    /// Entry point of each variant.
    pub entry: Vec<Point>,
    /// Exit point of each variant.
    pub exit: Vec<Point>,
    /// Cost inside the piece of each variant.
    pub inner: Vec<f64>,
}

/// Improvement smaller than this is ignored (keeps the loops finite under rounding).
const EPS: f64 = 1e-7;

/// A visiting order: `(piece, variant)` pairs.
pub(crate) type Tour = Vec<(usize, usize)>;

/// Hop cost between two points; never below the straight-line distance (the improvement
/// moves skip a move whose straight-line cost already shows that it cannot win).
pub(crate) type Dist<'a> = &'a dyn Fn(Point, Point) -> f64;

/// Has the caller given the planning up? The improvement then ends within [`STOP_EVERY`]
/// positions of a pass, leaving a valid tour (`Ctx::stopped`).
pub(crate) type Stop<'a> = &'a dyn Fn() -> bool;

/// Positions of a pass between two looks at [`Stop`] (a pass over thousands of pieces took
/// seconds on the bench map `office_4096`).
const STOP_EVERY: usize = 64;

/// A lower bound of every hop cost from `a` to `b`: the straight-line distance, a little less
/// (so that it stays below a distance rounded another way, as by `hypot`).
fn low(a: Point, b: Point) -> f64 {
    let (dx, dy) = (a.x - b.x, a.y - b.y);
    (dx * dx + dy * dy).sqrt() * (1.0 - 1e-12)
}

/// Total cost of `tour` from `start`.
pub(crate) fn cost(pieces: &[Piece], start: Point, tour: &Tour, d: Dist<'_>) -> f64 {
    let mut at = start;
    let mut total = 0.0;
    for &(p, v) in tour {
        total += d(at, pieces[p].entry[v]) + pieces[p].inner[v];
        at = pieces[p].exit[v];
    }
    total
}

/// Plans the visiting order (see the module docs); `first`, when given, replaces the
/// nearest-neighbour construction.
pub(crate) fn solve(
    pieces: &[Piece],
    start: Point,
    rounds: u32,
    d: Dist<'_>,
    first: Option<Tour>,
    stop: Stop<'_>,
) -> Tour {
    let mut tour = first.unwrap_or_else(|| nearest_neighbour(pieces, start, d));
    if rounds == 0 {
        return tour;
    }
    let nb = neighbour_lists(pieces, d);
    improve(pieces, start, rounds, d, &nb, &mut tour, stop);
    tour
}

/// The candidate neighbours of every piece that [`improve`] needs.
pub(crate) fn neighbours(pieces: &[Piece], d: Dist<'_>) -> Vec<Vec<usize>> {
    neighbour_lists(pieces, d)
}

/// Up to `rounds` improvement rounds of `tour` (module docs); true when a round left the cost
/// unchanged (further rounds would change nothing), so that `k` rounds followed by `m` more
/// (when this returned false) are the same as `k + m` rounds at once.
pub(crate) fn improve(
    pieces: &[Piece],
    start: Point,
    rounds: u32,
    d: Dist<'_>,
    nb: &[Vec<usize>],
    tour: &mut Tour,
    stop: Stop<'_>,
) -> bool {
    for _ in 0..rounds {
        if stop() {
            return true;
        }
        let before = cost(pieces, start, tour, d);
        two_opt(pieces, start, tour, nb, d, stop);
        or_opt(pieces, start, tour, nb, d, stop);
        choose_variants(pieces, start, tour, d);
        if cost(pieces, start, tour, d) >= before - EPS {
            return true;
        }
    }
    false
}

fn nearest_neighbour(pieces: &[Piece], start: Point, d: Dist<'_>) -> Tour {
    let n = pieces.len();
    let mut done = vec![false; n];
    let mut tour = Vec::with_capacity(n);
    let mut at = start;
    let mut cands: Vec<(f64, usize, usize)> = Vec::new();
    for _ in 0..n {
        // Candidates by straight-line cost (a lower bound of the hop cost), then exact costs
        // until the bound passes the best found.
        cands.clear();
        for (p, piece) in pieces.iter().enumerate() {
            if done[p] {
                continue;
            }
            for v in 0..piece.entry.len() {
                cands.push((at.dist(piece.entry[v]) + piece.inner[v], p, v));
            }
        }
        cands.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        let mut best: Option<(f64, usize, usize)> = None;
        for &(lb, p, v) in &cands {
            if best.is_some_and(|b| lb >= b.0) {
                break;
            }
            let c = d(at, pieces[p].entry[v]) + pieces[p].inner[v];
            if best.is_none_or(|b| c < b.0) {
                best = Some((c, p, v));
            }
        }
        let Some((_, p, v)) = best else { break };
        done[p] = true;
        tour.push((p, v));
        at = pieces[p].exit[v];
    }
    tour
}

/// Exit of the element before position `i` (the start for `i == 0`).
fn prev_exit(pieces: &[Piece], start: Point, tour: &Tour, i: usize) -> Point {
    if i == 0 {
        start
    } else {
        let (p, v) = tour[i - 1];
        pieces[p].exit[v]
    }
}

/// Number of candidate neighbours per piece in the improvement moves.
const NEIGHBOURS: usize = 12;

/// The `NEIGHBOURS` pieces nearest to each piece (by the closest pair of end points), nearest
/// first, ties by index.
fn neighbour_lists(pieces: &[Piece], d: Dist<'_>) -> Vec<Vec<usize>> {
    let ends: Vec<Vec<Point>> = pieces
        .iter()
        .map(|p| {
            let mut v: Vec<Point> = p.entry.iter().chain(&p.exit).copied().collect();
            v.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
            v.dedup();
            v
        })
        .collect();
    let gap = |a: usize, b: usize| -> f64 {
        let mut m = f64::INFINITY;
        for p in &ends[a] {
            for q in &ends[b] {
                m = m.min(p.dist2(*q));
            }
        }
        m
    };
    // Bounding box of each piece's end points: its squared gap to another box is a lower
    // bound of `gap` (rounding is monotone, so also in floating point), which skips most pieces
    // once a piece's candidate list is full ([`BoxGrid`]).
    let boxes: Vec<[f64; 4]> = ends
        .iter()
        .map(|v| {
            v.iter().fold(
                [
                    f64::INFINITY,
                    f64::NEG_INFINITY,
                    f64::INFINITY,
                    f64::NEG_INFINITY,
                ],
                |b, p| [b[0].min(p.x), b[1].max(p.x), b[2].min(p.y), b[3].max(p.y)],
            )
        })
        .collect();
    let grid = BoxGrid::new(&boxes);
    let mut seen = vec![usize::MAX; pieces.len()];
    (0..pieces.len())
        .map(|a| {
            // The 3 * NEIGHBOURS nearest in a straight line (the smallest `(gap, index)`), then
            // re-ranked by hop cost.
            let keep = 3 * NEIGHBOURS;
            let mut best: Vec<(f64, usize)> = Vec::with_capacity(keep + 1);
            grid.near(a, &mut seen, &mut |b, box_gap| {
                if best.len() == keep {
                    // (no candidate at or beyond this gap can enter the list any more)
                    let w = best[keep - 1];
                    if (box_gap, b) > w {
                        return Some(w.0);
                    }
                }
                let g = gap(a, b);
                if best.len() < keep || (g, b) < best[keep - 1] {
                    let at = best.partition_point(|e| *e < (g, b));
                    best.insert(at, (g, b));
                    best.truncate(keep);
                }
                (best.len() == keep).then(|| best[keep - 1].0)
            });
            // (one hop cost per candidate: between its end points nearest in a straight line)
            let mut ranked: Vec<(f64, usize)> = best
                .into_iter()
                .map(|(_, b)| {
                    let mut pair = (f64::INFINITY, ends[a][0], ends[b][0]);
                    for p in &ends[a] {
                        for q in &ends[b] {
                            if p.dist2(*q) < pair.0 {
                                pair = (p.dist2(*q), *p, *q);
                            }
                        }
                    }
                    (d(pair.1, pair.2), b)
                })
                .collect();
            ranked.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            ranked.truncate(NEIGHBOURS);
            ranked.into_iter().map(|e| e.1).collect()
        })
        .collect()
}

/// The pieces' end-point boxes (`[x0, x1, y0, y1]`) in a uniform grid of squares, for
/// [`neighbour_lists`]: the pieces near a piece are visited ring by ring of squares around
/// its box, and the rings stop once no piece beyond them can come closer than the list's
/// worst entry. Before, every pair of pieces was tried (with a box check): on
/// `stage_willow_full` (r = 0.15 m, up to 2980 pieces) about 0.8 s of the run's 7 s CPU.
struct BoxGrid<'a> {
    boxes: &'a [[f64; 4]],
    /// Lower-left corner of the grid and the side of its squares.
    x0: f64,
    y0: f64,
    side: f64,
    /// Squares per row and per column.
    nx: usize,
    ny: usize,
    /// The pieces whose box meets each square (row-major), in index order.
    squares: Vec<Vec<u32>>,
}

/// The most squares a [`BoxGrid`] side is cut into, less one (a side `w` long in squares of
/// `w / MAX_SQUARES` takes `MAX_SQUARES + 1` of them, at most 4096).
const MAX_SQUARES: f64 = 4095.0;

impl<'a> BoxGrid<'a> {
    fn new(boxes: &'a [[f64; 4]]) -> Self {
        let low = |k: usize| boxes.iter().map(|b| b[k]).fold(f64::INFINITY, f64::min);
        let high = |k: usize| boxes.iter().map(|b| b[k]).fold(f64::NEG_INFINITY, f64::max);
        let (x0, x1, y0, y1) = (low(0), high(1), low(2), high(3));
        let (wx, wy) = ((x1 - x0).max(0.0), (y1 - y0).max(0.0));
        // About one piece per square; at least a unit side (grid points are pixels), and at
        // most 4096 squares a side: the side grows to span the pieces in that many (it was
        // kept while the count was capped, so on a long thin map, a corridor 30 000 px long,
        // the last square held two thirds of the 7321 pieces and the search went quadratic:
        // bcd on one 100 000 px long took 13 s to plan).
        let n = boxes.len().max(1) as f64;
        let side = ((wx * wy) / n)
            .sqrt()
            .max(1.0)
            .max(wx / MAX_SQUARES)
            .max(wy / MAX_SQUARES);
        let count = |w: f64| ((w / side).floor() as usize + 1).min(4096);
        let (nx, ny) = if boxes.is_empty() {
            (0, 0)
        } else {
            (count(wx), count(wy))
        };
        let mut grid = Self {
            boxes,
            x0,
            y0,
            side,
            nx,
            ny,
            squares: vec![Vec::new(); nx * ny],
        };
        for (i, b) in boxes.iter().enumerate() {
            let [cx0, cx1, cy0, cy1] = grid.span(b);
            for cy in cy0..=cy1 {
                for cx in cx0..=cx1 {
                    grid.squares[cy * nx + cx].push(i as u32);
                }
            }
        }
        grid
    }

    /// The squares a box meets: `[cx0, cx1, cy0, cy1]`, inclusive.
    fn span(&self, b: &[f64; 4]) -> [usize; 4] {
        let at =
            |v: f64, o: f64, n: usize| (((v - o) / self.side).floor().max(0.0) as usize).min(n - 1);
        [
            at(b[0], self.x0, self.nx),
            at(b[1], self.x0, self.nx),
            at(b[2], self.y0, self.ny),
            at(b[3], self.y0, self.ny),
        ]
    }

    /// Calls `visit(b, box_gap)` for every other piece `b` (each once; `seen` is scratch,
    /// stamped with `a`), nearest rings of squares first, with the squared gap between the
    /// two boxes. `visit` returns the squared gap beyond which it wants no more pieces
    /// (`None`: all of them); the rings stop when every piece not yet visited lies farther.
    fn near(&self, a: usize, seen: &mut [usize], visit: &mut dyn FnMut(usize, f64) -> Option<f64>) {
        if self.nx == 0 {
            return;
        }
        let p = &self.boxes[a];
        let [cx0, cx1, cy0, cy1] = self.span(p);
        let box_gap = |q: &[f64; 4]| {
            let dx = (p[0] - q[1]).max(q[0] - p[1]).max(0.0);
            let dy = (p[2] - q[3]).max(q[2] - p[3]).max(0.0);
            dx * dx + dy * dy
        };
        seen[a] = a;
        let mut limit: Option<f64> = None;
        let mut r = 0usize;
        loop {
            // A piece not met in rings 0..r lies more than `r - 1` squares from the squares of
            // `a`'s box, which hold that box: its box gap exceeds `((r - 1) side)^2`.
            if r > 0 {
                let d = (r - 1) as f64 * self.side;
                if limit.is_some_and(|l| d * d > l) {
                    return;
                }
            }
            let (lx, hx) = (cx0 as i64 - r as i64, (cx1 + r) as i64);
            let (ly, hy) = (cy0 as i64 - r as i64, (cy1 + r) as i64);
            if lx < 0 && ly < 0 && hx >= self.nx as i64 && hy >= self.ny as i64 && r > 0 {
                return;
            }
            for cy in ly.max(0)..=hy.min(self.ny as i64 - 1) {
                let edge_row = cy == ly || cy == hy;
                let mut cx = lx.max(0);
                while cx <= hx.min(self.nx as i64 - 1) {
                    // Inside the ring only its first and last columns are new squares.
                    if !edge_row && r > 0 && cx != lx && cx != hx {
                        cx = if hx < self.nx as i64 {
                            hx
                        } else {
                            self.nx as i64
                        };
                        continue;
                    }
                    for &b in &self.squares[cy as usize * self.nx + cx as usize] {
                        let b = b as usize;
                        if seen[b] == a {
                            continue;
                        }
                        seen[b] = a;
                        limit = visit(b, box_gap(&self.boxes[b])).or(limit);
                    }
                    cx += 1;
                }
            }
            r += 1;
        }
    }
}

fn positions(tour: &Tour, n: usize) -> Vec<usize> {
    let mut pos = vec![usize::MAX; n];
    for (i, e) in tour.iter().enumerate() {
        pos[e.0] = i;
    }
    pos
}

/// The hop into every position of `tour`: `into[i]` is the cost from the exit before `i` (the
/// start for `i == 0`) to the entry of `tour[i]`. The improvement moves read the tour's current
/// hops from here instead of asking `d` again (the same calls give the same costs).
fn hops_into(pieces: &[Piece], start: Point, tour: &Tour, d: Dist<'_>) -> Vec<f64> {
    (0..tour.len())
        .map(|i| {
            let (p, v) = tour[i];
            d(prev_exit(pieces, start, tour, i), pieces[p].entry[v])
        })
        .collect()
}

/// Recomputes `into[i]` (see [`hops_into`]) for the positions `range` of `tour` that exist.
fn rehop(
    pieces: &[Piece],
    start: Point,
    tour: &Tour,
    d: Dist<'_>,
    into: &mut [f64],
    range: std::ops::RangeInclusive<usize>,
) {
    let (lo, hi) = (
        *range.start(),
        (*range.end()).min(tour.len().saturating_sub(1)),
    );
    for i in lo..=hi {
        let (p, v) = tour[i];
        into[i] = d(prev_exit(pieces, start, tour, i), pieces[p].entry[v]);
    }
}

/// 2-opt over candidate neighbours: reversing `tour[i..=j]` makes the hops
/// `prev(i) -> exit(j)` and `entry(i) -> entry(j + 1)`; `j` is taken where either new hop
/// joins neighbours.
fn two_opt(
    pieces: &[Piece],
    start: Point,
    tour: &mut Tour,
    nb: &[Vec<usize>],
    d: Dist<'_>,
    stop: Stop<'_>,
) {
    let n = tour.len();
    let entry = |t: &Tour, i: usize| pieces[t[i].0].entry[t[i].1];
    let exit = |t: &Tour, i: usize| pieces[t[i].0].exit[t[i].1];
    let mut pos = positions(tour, pieces.len());
    let mut into = hops_into(pieces, start, tour, d);
    let mut improved = true;
    let mut passes = 0;
    let mut cand: Vec<usize> = Vec::new();
    while improved && passes < 50 && !stop() {
        improved = false;
        passes += 1;
        for i in 0..n {
            if i % STOP_EVERY == 0 && stop() {
                return;
            }
            cand.clear();
            if i > 0 {
                cand.extend(nb[tour[i - 1].0].iter().map(|&q| pos[q]));
            } else {
                cand.extend(0..n.min(NEIGHBOURS));
            }
            cand.extend(nb[tour[i].0].iter().filter_map(|&q| pos[q].checked_sub(1)));
            cand.push(n - 1);
            cand.sort_unstable();
            cand.dedup();
            let a = prev_exit(pieces, start, tour, i);
            let bi = entry(tour, i);
            for &j in cand.iter().filter(|&&j| j >= i && j < n) {
                let ej = exit(tour, j);
                // (`into[i]` is the hop a -> bi, `into[j + 1]` the hop ej -> bn; a move whose
                // new hops cost too much in a straight line is not costed: floating-point
                // sums are monotone, so the bound is below the cost)
                let bn = (j + 1 < n).then(|| entry(tour, j + 1));
                let before = match bn {
                    Some(_) => into[i] + into[j + 1],
                    None => into[i],
                };
                let bound = match bn {
                    Some(bn) => low(a, ej) + low(bi, bn),
                    None => low(a, ej),
                };
                if bound >= before - EPS {
                    continue;
                }
                let after = match bn {
                    Some(bn) => d(a, ej) + d(bi, bn),
                    None => d(a, ej),
                };
                if after < before - EPS {
                    tour[i..=j].reverse();
                    for e in &mut tour[i..=j] {
                        e.1 ^= 1;
                    }
                    for k in i..=j {
                        pos[tour[k].0] = k;
                    }
                    rehop(pieces, start, tour, d, &mut into, i..=j + 1);
                    improved = true;
                    break;
                }
            }
        }
    }
}

/// How an Or-opt move drives the stretch it moves.
#[derive(Clone, Copy)]
enum Alt {
    /// As before.
    Forward,
    /// Backwards (every piece in its reversed variant).
    Backward,
    /// A single piece in this variant.
    Variant(usize),
}

/// Or-opt over candidate neighbours: stretches of 1 to 3 pieces moved next to a neighbour of
/// their first or last piece, either way round; a single piece moved may also change its
/// variant (be started at another corner) where that costs less at its new place.
fn or_opt(
    pieces: &[Piece],
    start: Point,
    tour: &mut Tour,
    nb: &[Vec<usize>],
    d: Dist<'_>,
    stop: Stop<'_>,
) {
    let entry = |t: &Tour, i: usize| pieces[t[i].0].entry[t[i].1];
    let exit = |t: &Tour, i: usize| pieces[t[i].0].exit[t[i].1];
    let mut pos = positions(tour, pieces.len());
    let mut into = hops_into(pieces, start, tour, d);
    let mut improved = true;
    let mut passes = 0;
    let mut cand: Vec<usize> = Vec::new();
    let mut alts: Vec<(Point, Point, f64, Alt)> = Vec::new();
    while improved && passes < 50 && !stop() {
        improved = false;
        passes += 1;
        let n = tour.len();
        for k in 1..=3usize {
            if k >= n {
                break;
            }
            for i in 0..=n - k {
                if i % STOP_EVERY == 0 && stop() {
                    return;
                }
                let j = i + k - 1;
                let a = prev_exit(pieces, start, tour, i);
                let (si, ej) = (entry(tour, i), exit(tour, j));
                // (`into[i]` is the hop a -> si, `into[j + 1]` the hop ej -> bn)
                let removed = if j + 1 < n {
                    let bn = entry(tour, j + 1);
                    into[i] + into[j + 1] - d(a, bn)
                } else {
                    into[i]
                };
                // Insertion between p-1 and p: next to a neighbour on either side.
                cand.clear();
                for &q in nb[tour[i].0].iter().chain(&nb[tour[j].0]) {
                    cand.push(pos[q]);
                    cand.push(pos[q] + 1);
                }
                cand.push(0);
                cand.push(n);
                cand.sort_unstable();
                cand.dedup();
                // The ways the stretch can be driven at its new place: a stretch of several
                // pieces forwards or backwards; a single piece in any of its variants (its
                // other corners too, the change of its inner cost counted).
                alts.clear();
                if k == 1 {
                    let (p, v) = tour[i];
                    let pc = &pieces[p];
                    alts.extend((0..pc.entry.len()).map(|w| {
                        (
                            pc.entry[w],
                            pc.exit[w],
                            pc.inner[w] - pc.inner[v],
                            Alt::Variant(w),
                        )
                    }));
                } else {
                    alts.push((si, ej, 0.0, Alt::Forward));
                    alts.push((ej, si, 0.0, Alt::Backward));
                }
                let mut best: Option<(f64, usize, Alt)> = None;
                for &p in &cand {
                    if p > n || (p >= i && p <= j + 1) {
                        continue;
                    }
                    let before_pt = prev_exit(pieces, start, tour, p);
                    // (the hop before_pt -> nx now is `into[p]`)
                    let next = if p < n {
                        Some((entry(tour, p), into[p]))
                    } else {
                        None
                    };
                    for &(s_in, s_out, extra, alt) in &alts {
                        // (a bound below `add`, as in `two_opt`: skipped when it cannot win)
                        let bound = extra
                            + match next {
                                Some((nx, now)) => low(before_pt, s_in) + low(s_out, nx) - now,
                                None => low(before_pt, s_in),
                            };
                        if bound >= removed - EPS || best.is_some_and(|b| bound >= b.0) {
                            continue;
                        }
                        let add = extra
                            + match next {
                                Some((nx, now)) => d(before_pt, s_in) + d(s_out, nx) - now,
                                None => d(before_pt, s_in),
                            };
                        if add < removed - EPS && best.is_none_or(|b| add < b.0) {
                            best = Some((add, p, alt));
                        }
                    }
                }
                if let Some((_, p, alt)) = best {
                    let mut seg: Vec<(usize, usize)> = tour.drain(i..=j).collect();
                    match alt {
                        Alt::Forward => {}
                        Alt::Backward => {
                            seg.reverse();
                            for e in &mut seg {
                                e.1 ^= 1;
                            }
                        }
                        Alt::Variant(w) => seg[0].1 = w,
                    }
                    let at = if p > j { p - k } else { p };
                    tour.splice(at..at, seg);
                    pos = positions(tour, pieces.len());
                    // The hops that changed: into the piece that followed the stretch (at `i`,
                    // or `i + k` when the stretch went before it), into the stretch and into
                    // the piece after it.
                    into.drain(i..=j);
                    into.splice(at..at, std::iter::repeat_n(0.0, k));
                    let after = if at < i { i + k } else { i };
                    rehop(pieces, start, tour, d, &mut into, after..=after);
                    rehop(pieces, start, tour, d, &mut into, at..=at + k);
                    improved = true;
                }
            }
        }
    }
}

/// Exact choice of every piece's variant for the current order (dynamic programme).
fn choose_variants(pieces: &[Piece], start: Point, tour: &mut Tour, d: Dist<'_>) {
    let n = tour.len();
    if n == 0 {
        return;
    }
    // best[i][v]: cost up to and including piece i driven in variant v; from[i][v]: variant of
    // piece i-1.
    let mut best: Vec<Vec<f64>> = Vec::with_capacity(n);
    let mut from: Vec<Vec<usize>> = Vec::with_capacity(n);
    for i in 0..n {
        let pc = &pieces[tour[i].0];
        let mut row = vec![f64::INFINITY; pc.entry.len()];
        let mut frow = vec![0usize; pc.entry.len()];
        for v in 0..pc.entry.len() {
            if i == 0 {
                row[v] = d(start, pc.entry[v]) + pc.inner[v];
            } else {
                let pp = &pieces[tour[i - 1].0];
                for u in 0..pp.exit.len() {
                    let c = best[i - 1][u] + d(pp.exit[u], pc.entry[v]) + pc.inner[v];
                    if c < row[v] {
                        row[v] = c;
                        frow[v] = u;
                    }
                }
            }
        }
        best.push(row);
        from.push(frow);
    }
    let last = &best[n - 1];
    let mut v = 0;
    for (u, &c) in last.iter().enumerate() {
        if c < last[v] {
            v = u;
        }
    }
    let old = cost(pieces, start, tour, d);
    if last[v] >= old - EPS {
        return;
    }
    for i in (0..n).rev() {
        tour[i].1 = v;
        v = from[i][v];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn euclid(a: Point, b: Point) -> f64 {
        a.dist(b)
    }

    fn point_piece(x: f64, y: f64) -> Piece {
        let p = Point::new(x, y);
        Piece {
            entry: vec![p, p],
            exit: vec![p, p],
            inner: vec![0.0, 0.0],
        }
    }

    /// [`neighbour_lists`] as it was before [`BoxGrid`]: every pair of pieces tried.
    fn neighbour_lists_all_pairs(pieces: &[Piece], d: Dist<'_>) -> Vec<Vec<usize>> {
        let ends: Vec<Vec<Point>> = pieces
            .iter()
            .map(|p| {
                let mut v: Vec<Point> = p.entry.iter().chain(&p.exit).copied().collect();
                v.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
                v.dedup();
                v
            })
            .collect();
        let near = |a: usize, b: usize| -> (f64, Point, Point) {
            let mut m = (f64::INFINITY, ends[a][0], ends[b][0]);
            for p in &ends[a] {
                for q in &ends[b] {
                    if p.dist2(*q) < m.0 {
                        m = (p.dist2(*q), *p, *q);
                    }
                }
            }
            m
        };
        (0..pieces.len())
            .map(|a| {
                let mut all: Vec<(f64, usize)> = (0..pieces.len())
                    .filter(|&b| b != a)
                    .map(|b| (near(a, b).0, b))
                    .collect();
                all.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
                all.truncate(3 * NEIGHBOURS);
                let mut ranked: Vec<(f64, usize)> = all
                    .into_iter()
                    .map(|(_, b)| {
                        let (_, p, q) = near(a, b);
                        (d(p, q), b)
                    })
                    .collect();
                ranked.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
                ranked.truncate(NEIGHBOURS);
                ranked.into_iter().map(|e| e.1).collect()
            })
            .collect()
    }

    /// The grid gives every piece the neighbours that trying every pair gives: pieces of one
    /// point and long pieces (lanes of a whole cell, boxes over many squares), clusters,
    /// repeated points (ties broken by index), on a hop cost that is not the straight line.
    #[test]
    fn grid_neighbours_are_the_all_pairs_neighbours() {
        let mut rng = crate::rng::SplitMix64::new(7);
        // (a hop cost above the straight line that ranks some candidates differently)
        let bent = |a: Point, b: Point| a.dist(b) + 0.3 * (a.x - b.x).abs();
        for case in 0..40 {
            let n = [0, 1, 2, 5, 40, 300][case % 6];
            let spread = [1.0, 30.0, 400.0][case % 3];
            let mut pieces = Vec::with_capacity(n);
            for i in 0..n {
                let (cx, cy) = if rng.next_f64() < 0.5 {
                    (rng.range(0.0, spread), rng.range(0.0, spread))
                } else {
                    // clustered, on whole numbers (repeated points)
                    (
                        (rng.range(0.0, 4.0)).floor() + 10.0,
                        (rng.range(0.0, 4.0)).floor() + 10.0,
                    )
                };
                let p = Point::new(cx, cy);
                if i % 3 == 0 {
                    pieces.push(point_piece(cx, cy));
                } else {
                    let len = if i % 7 == 0 {
                        spread
                    } else {
                        rng.range(0.0, 5.0)
                    };
                    let q = Point::new(cx + len, cy + rng.range(-2.0, 2.0));
                    let r = Point::new(cx, cy + rng.range(0.0, len));
                    pieces.push(Piece {
                        entry: vec![p, q, r, q],
                        exit: vec![q, p, q, r],
                        inner: vec![len; 4],
                    });
                }
            }
            for d in [&euclid as Dist<'_>, &bent] {
                assert_eq!(
                    neighbour_lists(&pieces, d),
                    neighbour_lists_all_pairs(&pieces, d),
                    "case {case}, {n} pieces"
                );
            }
        }
        // Many exact ties: points of a small lattice, each several times, so that pieces at
        // the list's worst gap sit in squares met later than higher-index ones.
        for (k, m) in [(7, 5), (13, 11), (3, 29)] {
            let pieces: Vec<Piece> = (0..240)
                .map(|i: i32| point_piece(f64::from((i * 5) % k) * 1.5, f64::from((i * 3) % m)))
                .collect();
            // (a hop cost that ranks the diagonal candidates first, which the straight-line
            // list holds only the first few of: the cut at the list's end decides)
            let odd = |a: Point, b: Point| {
                let straight = (a.x - b.x).abs() < 1e-9 || (a.y - b.y).abs() < 1e-9;
                a.dist(b) + if straight { 10.0 } else { 0.0 }
            };
            assert_eq!(
                neighbour_lists(&pieces, &odd),
                neighbour_lists_all_pairs(&pieces, &odd),
                "lattice {k} x {m}"
            );
        }
    }

    /// On a long thin spread of pieces the grid's squares grow to span them all: with the
    /// side kept while the count of squares was capped at 4096, the last square held most of
    /// the pieces (a corridor 30 000 px long: 2/3 of 7321) and the search went quadratic.
    #[test]
    fn a_long_thin_spread_of_pieces_fills_the_squares_evenly() {
        let pieces: Vec<Piece> = (0..20_000)
            .map(|i| point_piece(f64::from(i) * 5.0, f64::from(i % 3)))
            .collect();
        let ends: Vec<[f64; 4]> = pieces
            .iter()
            .map(|p| [p.entry[0].x, p.entry[0].x, p.entry[0].y, p.entry[0].y])
            .collect();
        let grid = BoxGrid::new(&ends);
        let fullest = grid.squares.iter().map(Vec::len).max().unwrap();
        assert!(grid.nx <= 4096 && grid.ny <= 4096);
        assert!(fullest <= 8, "{fullest} pieces in one square");
    }

    #[test]
    fn points_on_a_line_are_visited_in_order() {
        let xs = [5.0, 1.0, 9.0, 3.0, 7.0, 2.0];
        let pieces: Vec<Piece> = xs.iter().map(|&x| point_piece(x, 0.0)).collect();
        let tour = solve(&pieces, Point::new(0.0, 0.0), 10, &euclid, None, &|| false);
        let order: Vec<f64> = tour.iter().map(|&(p, _)| xs[p]).collect();
        assert_eq!(order, vec![1.0, 2.0, 3.0, 5.0, 7.0, 9.0]);
        assert!((cost(&pieces, Point::new(0.0, 0.0), &tour, &euclid) - 9.0).abs() < 1e-9);
    }

    #[test]
    fn segments_are_driven_the_short_way_round() {
        // Two horizontal segments; variant 0 goes left to right, 1 right to left.
        let seg = |y: f64| Piece {
            entry: vec![Point::new(0.0, y), Point::new(10.0, y)],
            exit: vec![Point::new(10.0, y), Point::new(0.0, y)],
            inner: vec![10.0, 10.0],
        };
        let pieces = vec![seg(1.0), seg(0.0)];
        let tour = solve(&pieces, Point::new(0.0, 0.0), 10, &euclid, None, &|| false);
        assert_eq!(tour, vec![(1, 0), (0, 1)]);
        assert!((cost(&pieces, Point::new(0.0, 0.0), &tour, &euclid) - 21.0).abs() < 1e-9);
    }

    #[test]
    fn or_opt_moves_a_piece_into_another_variant() {
        // Points A (x = 1) and C (x = 3) on a line from the start; B is a piece whose variants
        // 0/1 lie far off the line (inner cost 0) and whose variants 2/3 lie between A and C
        // (inner cost 9.5). At the end of the tour B is cheaper in variant 0 (10.05 against
        // 10.5), so the variant choice alone keeps it there; only moving B between A and C in
        // variant 2 lowers the cost (13.05 to 12.5).
        let far = Point::new(2.0, 10.0);
        let near = Point::new(2.0, 0.0);
        let b = Piece {
            entry: vec![far, far, near, near],
            exit: vec![far, far, near, near],
            inner: vec![0.0, 0.0, 9.5, 9.5],
        };
        let pieces = vec![point_piece(1.0, 0.0), point_piece(3.0, 0.0), b];
        let start = Point::new(0.0, 0.0);
        let nb = neighbours(&pieces, &euclid);
        let mut tour = vec![(0, 0), (1, 0), (2, 0)];
        let before = cost(&pieces, start, &tour, &euclid);
        assert!((before - (3.0 + 101.0f64.sqrt())).abs() < 1e-9);
        improve(&pieces, start, 5, &euclid, &nb, &mut tour, &|| false);
        let order: Vec<usize> = tour.iter().map(|e| e.0).collect();
        assert_eq!(order, vec![0, 2, 1]);
        assert!(tour[1].1 >= 2, "{tour:?}");
        assert!((cost(&pieces, start, &tour, &euclid) - 12.5).abs() < 1e-9);
    }

    #[test]
    fn improvement_never_loses_to_construction() {
        // A scattered deterministic point set.
        let mut pieces = Vec::new();
        let mut s = 7u64;
        for _ in 0..40 {
            s = s.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            let x = (s >> 33) as f64 / 1e6;
            s = s.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            let y = (s >> 33) as f64 / 1e6;
            pieces.push(point_piece(x, y));
        }
        let start = Point::new(0.0, 0.0);
        let nn = nearest_neighbour(&pieces, start, &euclid);
        let best = solve(&pieces, start, 20, &euclid, None, &|| false);
        assert!(cost(&pieces, start, &best, &euclid) <= cost(&pieces, start, &nn, &euclid) + 1e-9);
        let mut seen: Vec<usize> = best.iter().map(|e| e.0).collect();
        seen.sort_unstable();
        assert_eq!(seen, (0..40).collect::<Vec<_>>());
    }
}
