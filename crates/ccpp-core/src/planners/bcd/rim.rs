//! Rim passes (step 3 of the module docs): contour passes over what the lanes miss, placed
//! in the tour or inserted as detours.

use std::ops::{Add, Sub};

use fixedbitset::FixedBitSet;

use super::finish::moves;
use super::finish::Item;
use super::lattice::Ctx;
use super::transfer::Search;
use crate::geometry::{path_length, Point};

/// Step 3 of the module docs: the contour passes (grid polylines) that sweep the accessible
/// pixels the polylines `lines` miss, one per 8-connected group of missed pixels, with the
/// number of pixels each is meant to sweep; groups below `min_yield` are left out, and so are
/// the lowest-yield groups that fit in the budget `1 - target` of the accessible pixels.
pub(super) fn rim_contours(
    ctx: &Ctx<'_>,
    search: &mut Search,
    lines: &[&[Point]],
    min_yield: f64,
    target: f64,
) -> Vec<(Vec<Point>, usize)> {
    let frame = ctx.frame;
    let (w, h) = (frame.width, frame.height);
    let rt = ctx.rt + crate::raster::SWEEP_EPS_PX;
    let mut swept = FixedBitSet::with_capacity(frame.len());
    for line in lines {
        if let Some(&p) = line.first() {
            crate::raster::stamp_capsule(&mut swept, &frame, p, p, rt, &mut |_| {});
        }
        for s in line.windows(2) {
            if s[0] != s[1] {
                crate::raster::stamp_capsule(&mut swept, &frame, s[0], s[1], rt, &mut |_| {});
            }
        }
    }
    let acc = ctx.world.accessible();
    let mut missed = acc.clone();
    missed.difference_with(&swept);
    if missed.is_clear() {
        return Vec::new();
    }
    let witness = witnesses(ctx, &missed, rt);
    // Groups: 8-connected components of missed pixels.
    let mut group_of = vec![u32::MAX; frame.len()];
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for i in missed.ones() {
        if group_of[i] != u32::MAX || witness[i] == u32::MAX {
            continue;
        }
        let g = groups.len() as u32;
        let mut members = vec![i];
        group_of[i] = g;
        let mut q = 0;
        while q < members.len() {
            let j = members[q];
            q += 1;
            let (c, r) = ((j % w) as i64, (j / w) as i64);
            for dr in -1..=1 {
                for dc in -1..=1 {
                    let (nc, nr) = (c + dc, r + dr);
                    if nc < 0 || nr < 0 || nc >= w as i64 || nr >= h as i64 {
                        continue;
                    }
                    let n = nr as usize * w + nc as usize;
                    if missed.contains(n) && group_of[n] == u32::MAX && witness[n] != u32::MAX {
                        group_of[n] = g;
                        members.push(n);
                    }
                }
            }
        }
        groups.push(members);
    }
    let mut out = Vec::with_capacity(groups.len());
    for members in &groups {
        // (a plan given up is dropped whole: leave the rest)
        if ctx.stopped() {
            break;
        }
        let mut ws: Vec<usize> = members.iter().map(|&i| witness[i] as usize).collect();
        ws.sort_unstable();
        ws.dedup();
        let pts: Vec<Point> = ws.iter().map(|&i| ctx.centre(i % w, i / w)).collect();
        // Chain: from the witness farthest from the first one, nearest neighbour onwards.
        let far = (0..pts.len())
            .max_by(|&a, &b| {
                pts[a]
                    .dist2(pts[0])
                    .total_cmp(&pts[b].dist2(pts[0]))
                    .then(b.cmp(&a))
            })
            .unwrap_or(0);
        let chain = nearest_neighbour_chain(&pts, far);
        let Some(tail) = ctx.follow(search, &chain) else {
            continue;
        };
        let mut contour = vec![chain[0]];
        contour.extend(tail);
        let clen = path_length(&contour);
        if (members.len() as f64) < min_yield * clen.max(1.0) * 2.0 * ctx.rt {
            continue;
        }
        out.push((contour, members.len()));
    }

    // The budget: missed pixels allowed by `target`, less those no group holds.
    let grouped: usize = out.iter().map(|c| c.1).sum();
    let allowed = ((1.0 - target) * acc.count_ones(..) as f64).floor() as usize;
    let mut budget = allowed.saturating_sub(missed.count_ones(..) - grouped);
    if budget > 0 {
        // Lowest yield (pixels per pixel of contour) first; ties by group order.
        let mut order: Vec<usize> = (0..out.len()).collect();
        let yield_of = |c: &(Vec<Point>, usize)| c.1 as f64 / path_length(&c.0).max(1.0);
        order.sort_by(|&a, &b| {
            yield_of(&out[a])
                .total_cmp(&yield_of(&out[b]))
                .then(a.cmp(&b))
        });
        let mut drop = vec![false; out.len()];
        for i in order {
            if out[i].1 <= budget {
                budget -= out[i].1;
                drop[i] = true;
            }
        }
        let mut k = 0;
        out.retain(|_| {
            k += 1;
            !drop[k - 1]
        });
    }
    out
}

/// The witness of each pixel of `missed`: the index of the nearest C-free pixel centre within
/// `rt` pixels (ties: lower row offset, then lower column offset), `u32::MAX` for none and for
/// pixels not missed.
pub(super) fn witnesses(ctx: &Ctx<'_>, missed: &FixedBitSet, rt: f64) -> Vec<u32> {
    let (w, h) = (ctx.frame.width, ctx.frame.height);
    let k = rt.floor() as i64;
    let rt2 = rt * rt;
    let mut offsets: Vec<(i64, i64, i64)> = Vec::new();
    for dr in -k..=k {
        for dc in -k..=k {
            let d2 = dc * dc + dr * dr;
            if (d2 as f64) <= rt2 {
                offsets.push((d2, dr, dc));
            }
        }
    }
    offsets.sort_unstable();
    // The first C-free pixel in that order lies at the squared distance the exact distance
    // transform of the C-free set gives (none is nearer), so only the offsets at that distance
    // are tried: scanning them all from the nearest took O(missed x r^2), 45 s of a 300 px
    // robot's plan in an empty room (its corners' missed pixels lie far from C-free). The
    // transform's buffer becomes the witnesses.
    let mut witness = crate::dt::squared_edt(w, h, |i| ctx.ok[i], false);
    for i in 0..ctx.frame.len() {
        let d2 = witness[i];
        witness[i] = u32::MAX;
        if !missed.contains(i) || d2 == crate::dt::INF || f64::from(d2) > rt2 {
            continue;
        }
        let (c, r) = ((i % w) as i64, (i / w) as i64);
        let from = offsets.partition_point(|o| o.0 < i64::from(d2));
        for &(_, dr, dc) in &offsets[from..] {
            if ctx.ok_at(c + dc, r + dr) {
                witness[i] = ((r + dr) as usize * w + (c + dc) as usize) as u32;
                break;
            }
        }
    }
    witness
}

/// Calls `f(x, y)` for the cells of a `w` x `h` grid on the square ring `ring` cells around
/// cell `(cx, cy)` (Chebyshev distance `ring`), row by row from the top, each row left to right.
/// Rows and ends outside the grid are skipped without a look, so the rings around a cell of a
/// grid a few cells wide cost a few cells each, not the ring's whole perimeter (a ring search
/// over a corridor 10 000 px long went over millions of cells outside it).
fn for_ring_cells(
    (cx, cy): (usize, usize),
    ring: usize,
    (w, h): (usize, usize),
    mut f: impl FnMut(usize, usize),
) {
    let (cx, cy, r) = (cx as i64, cy as i64, ring as i64);
    let (w, h) = (w as i64, h as i64);
    let (x0, x1) = ((cx - r).max(0), (cx + r).min(w - 1));
    let mut row = |y: i64, whole: bool| {
        if y < 0 || y >= h {
            return;
        }
        if whole {
            for x in x0..=x1 {
                f(x as usize, y as usize);
            }
        } else {
            for x in [cx - r, cx + r] {
                if x >= 0 && x < w {
                    f(x as usize, y as usize);
                }
            }
        }
    };
    if r == 0 {
        row(cy, true);
        return;
    }
    row(cy - r, true);
    // The ring's sides: only when one of them lies in the grid.
    if cx - r >= 0 || cx + r < w {
        for y in (cy - r + 1).max(0)..=(cy + r - 1).min(h - 1) {
            row(y, false);
        }
    }
    row(cy + r, true);
}

/// Side of [`nearest_neighbour_chain`]'s grid cells, pixels.
const CHAIN_CELL: f64 = 8.0;

/// The points `pts` chained from `pts[first]`, each next one the nearest of those not chained
/// yet (ties: the lowest index). Unchained points are found on a grid of [`CHAIN_CELL`] px
/// cells, ring by ring around the last point, until no farther ring can hold a nearer one: a
/// scan of every point per step took seconds on the rim of a corridor 10 000 px long.
fn nearest_neighbour_chain(pts: &[Point], first: usize) -> Vec<Point> {
    let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for p in pts {
        (x0, y0, x1, y1) = (x0.min(p.x), y0.min(p.y), x1.max(p.x), y1.max(p.y));
    }
    let cell_of = |v: f64, v0: f64| ((v - v0) / CHAIN_CELL).floor().max(0.0) as usize;
    let (gw, gh) = (cell_of(x1, x0) + 1, cell_of(y1, y0) + 1);
    let mut cells: Vec<Vec<u32>> = vec![Vec::new(); gw * gh];
    let at = |p: Point| (cell_of(p.x, x0), cell_of(p.y, y0));
    for (j, &p) in pts.iter().enumerate() {
        let (cx, cy) = at(p);
        cells[cy * gw + cx].push(j as u32);
    }
    let take = |cells: &mut Vec<Vec<u32>>, j: usize| {
        let (cx, cy) = at(pts[j]);
        let c = &mut cells[cy * gw + cx];
        if let Some(k) = c.iter().position(|&x| x as usize == j) {
            c.swap_remove(k);
        }
    };
    let mut chain = Vec::with_capacity(pts.len());
    chain.push(pts[first]);
    take(&mut cells, first);
    for _ in 1..pts.len() {
        let last = chain[chain.len() - 1];
        let (lx, ly) = at(last);
        let mut best: Option<(f64, usize)> = None;
        for ring in 0..gw.max(gh) {
            for_ring_cells((lx, ly), ring, (gw, gh), |x, y| {
                for &j in &cells[y * gw + x] {
                    let (j, d) = (j as usize, pts[j as usize].dist2(last));
                    if best.is_none_or(|b| d < b.0 || (d == b.0 && j < b.1)) {
                        best = Some((d, j));
                    }
                }
            });
            // Beyond this ring every point lies more than `ring` cells away on an axis.
            if let Some((d, _)) = best {
                let reach = ring as f64 * CHAIN_CELL;
                if reach * reach > d {
                    break;
                }
            }
        }
        let Some((_, j)) = best else { break };
        take(&mut cells, j);
        chain.push(pts[j]);
    }
    chain
}

/// Final mop-up of step 3: sweeps what the assembled plan still misses with contour detours
/// inserted at the cheapest point of the path (out and back).
pub(super) fn rim_pass(
    ctx: &Ctx<'_>,
    search: &mut Search,
    items: &mut Vec<Item>,
    min_yield: f64,
    target: f64,
) {
    const B: f64 = 16.0;
    let frame = ctx.frame;
    let (w, h) = (frame.width, frame.height);
    let path = moves(items);
    let line: Vec<Point> = path.iter().map(|m| m.0).collect();
    let contours = rim_contours(ctx, search, &[&line], min_yield, target);
    // Spatial index of the path's segments (buckets of 16 px).
    let (bw, bh) = (
        (w as f64 / B).ceil() as usize + 1,
        (h as f64 / B).ceil() as usize + 1,
    );
    let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); bw * bh];
    let bucket = |p: Point| -> (usize, usize) {
        (
            ((p.x / B).floor().max(0.0) as usize).min(bw - 1),
            ((p.y / B).floor().max(0.0) as usize).min(bh - 1),
        )
    };
    for (s, seg) in path.windows(2).enumerate() {
        let (a, b) = (bucket(seg[0].0), bucket(seg[1].0));
        for by in a.1.min(b.1)..=a.1.max(b.1) {
            for bx in a.0.min(b.0)..=a.0.max(b.0) {
                buckets[by * bw + bx].push(s as u32);
            }
        }
    }
    // (insert after path segment s, at parameter t along it, the detour points)
    let mut inserts: Vec<(usize, f64, Vec<Point>)> = Vec::new();
    for (contour, _) in contours {
        if ctx.stopped() {
            return;
        }
        let clen = path_length(&contour);
        let (cs, ce) = (contour[0], contour[contour.len() - 1]);
        // Cheapest insertion: segments near the contour's start, widening the search.
        let mut best: Option<(f64, usize, f64, bool)> = None;
        let (bx, by) = bucket(cs);
        for ring in 0..bw.max(bh) {
            for_ring_cells((bx, by), ring, (bw, bh), |x, y| {
                for &s in &buckets[y * bw + x] {
                    let s = s as usize;
                    let (a, b) = (path[s].0, path[s + 1].0);
                    for rev in [false, true] {
                        let (i0, i1) = if rev { (ce, cs) } else { (cs, ce) };
                        let t = proj(a, b, i0);
                        let q = a.add(b.sub(a).scale(t));
                        let c = q.dist(i0) + clen + i1.dist(q);
                        if best.is_none_or(|bb| c < bb.0) {
                            best = Some((c, s, t, rev));
                        }
                    }
                }
            });
            // Stop once the ring is farther than the best detour's approach.
            if let Some(bb) = best {
                if (ring as f64 - 1.0) * B > bb.0 - clen {
                    break;
                }
            }
        }
        let Some((_, s, t, rev)) = best else {
            continue;
        };
        let (a, b) = (path[s].0, path[s + 1].0);
        let q = a.add(b.sub(a).scale(t));
        let mut det: Vec<Point> = vec![q];
        if rev {
            det.extend(contour.iter().rev().copied());
        } else {
            det.extend(contour.iter().copied());
        }
        det.push(q);
        inserts.push((s, t, det));
    }
    let inserts = inserts
        .into_iter()
        .map(|(s, t, det)| (path[s + 1].1, t, det))
        .collect();
    insert_detours(items, inserts);
}

/// A detour to insert: before the item at this index, at this parameter along the segment
/// that item ends, these points.
type Detour = (usize, f64, Vec<Point>);

/// Inserts the detours `(at, t, points)` into `items`, each before the item at index `at` (the
/// move that ends the segment it leaves from): the detours at one index by their parameter `t`
/// along the segment, those at one parameter in the reverse of their order in `inserts`. One
/// pass over the plan (a splice per detour moved the rest of the plan each time: about a third
/// of the planning time of a large map).
fn insert_detours(items: &mut Vec<Item>, inserts: Vec<Detour>) {
    let extra: usize = inserts.iter().map(|d| d.2.len()).sum();
    let mut order: Vec<(usize, Detour)> = inserts.into_iter().enumerate().collect();
    order.sort_by(|(kx, x), (ky, y)| x.0.cmp(&y.0).then(x.1.total_cmp(&y.1)).then(ky.cmp(kx)));
    let old = std::mem::take(items);
    items.reserve(old.len() + extra);
    let mut next = order.into_iter().peekable();
    for (k, it) in old.into_iter().enumerate() {
        while let Some((_, (_, _, det))) = next.next_if(|(_, d)| d.0 == k) {
            items.extend(det.into_iter().map(Item::Move));
        }
        items.push(it);
    }
    debug_assert!(next.peek().is_none(), "a detour before no item");
}

/// Parameter in `[0, 1]` of the point of segment `a`-`b` nearest to `p`.
fn proj(a: Point, b: Point, p: Point) -> f64 {
    let d = b.sub(a);
    let l2 = d.dot(d);
    if l2 == 0.0 {
        0.0
    } else {
        (p.sub(a).dot(d) / l2).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::Event;
    use proptest::prelude::*;

    /// The chain by a scan of every point per step (the rim step's before the grid).
    fn chain_by_scan(pts: &[Point], first: usize) -> Vec<Point> {
        let mut used = vec![false; pts.len()];
        let mut chain = vec![pts[first]];
        used[first] = true;
        for _ in 1..pts.len() {
            let last = chain[chain.len() - 1];
            let mut best: Option<(f64, usize)> = None;
            for (j, p) in pts.iter().enumerate() {
                if !used[j] && best.is_none_or(|b| p.dist2(last) < b.0) {
                    best = Some((p.dist2(last), j));
                }
            }
            let Some((_, j)) = best else { break };
            used[j] = true;
            chain.push(pts[j]);
        }
        chain
    }

    proptest! {
        /// The grid's chain is the scan's, ties included: pixel centres (many equal
        /// distances) in clusters and strips, wide apart and close together.
        #[test]
        fn the_grid_chain_is_the_scans(
            cells in prop::collection::btree_set((0u32..90, 0u32..30), 1..160),
            stretch in 1u32..40,
            first in any::<prop::sample::Index>(),
        ) {
            let pts: Vec<Point> = cells
                .iter()
                .map(|&(x, y)| Point::new(f64::from(x * stretch) + 0.5, f64::from(y) + 0.5))
                .collect();
            let first = first.index(pts.len());
            prop_assert_eq!(nearest_neighbour_chain(&pts, first), chain_by_scan(&pts, first));
        }
    }

    /// The ring of a grid cell, as the scan of the whole square that skipped its inside visited
    /// it: the same cells in the same order, in grids wide, tall and of one cell.
    #[test]
    fn ring_cells_are_the_squares_border_in_order() {
        for (w, h) in [(1, 1), (3, 40), (40, 3), (7, 9)] {
            for cy in 0..h {
                for cx in 0..w {
                    for ring in 0..w.max(h) + 2 {
                        let mut got = Vec::new();
                        for_ring_cells((cx, cy), ring, (w, h), |x, y| got.push((x, y)));
                        let (c, r) = (cx as i64, cy as i64);
                        let k = ring as i64;
                        let mut want = Vec::new();
                        for y in r - k..=r + k {
                            for x in c - k..=c + k {
                                let on_ring = (y - r).abs() == k || (x - c).abs() == k;
                                let inside = x >= 0 && y >= 0 && x < w as i64 && y < h as i64;
                                if on_ring && inside {
                                    want.push((x as usize, y as usize));
                                }
                            }
                        }
                        assert_eq!(got, want, "{w} x {h}, cell ({cx}, {cy}), ring {ring}");
                    }
                }
            }
        }
    }

    /// The one-pass insertion puts every detour where a splice per detour put them (later
    /// segments first, along a segment from its far end): several detours at one index and at
    /// one parameter, at the first and the last index, beside a mark.
    #[test]
    fn detours_go_where_a_splice_each_put_them() {
        let p = |x: f64| Point::new(x, 0.0);
        let items: Vec<Item> = (0..8)
            .map(|i| {
                if i == 3 {
                    Item::Mark(Event::BacktrackStart)
                } else {
                    Item::Move(p(f64::from(i)))
                }
            })
            .collect();
        let inserts: Vec<(usize, f64, Vec<Point>)> = vec![
            (5, 0.5, vec![p(100.0), p(101.0)]),
            (1, 0.2, vec![p(102.0)]),
            (5, 0.1, vec![p(103.0)]),
            (5, 0.5, vec![p(104.0)]),
            (0, 0.0, vec![p(105.0)]),
            (7, 1.0, vec![p(106.0), p(107.0)]),
            (5, 0.5, vec![p(108.0)]),
            (4, 0.3, vec![p(109.0)]),
        ];
        // The splice per detour it replaces.
        let mut want = items.clone();
        let mut sorted = inserts.clone();
        sorted.sort_by(|x, y| y.0.cmp(&x.0).then(y.1.total_cmp(&x.1)));
        for (at, _, det) in sorted {
            want.splice(at..at, det.into_iter().map(Item::Move));
        }
        let mut got = items;
        insert_detours(&mut got, inserts);
        let show = |v: &[Item]| -> Vec<String> {
            v.iter()
                .map(|i| match i {
                    Item::Move(q) => format!("{q:?}"),
                    Item::Mark(e) => format!("{e:?}"),
                })
                .collect()
        };
        assert_eq!(show(&got), show(&want));
        assert_eq!(got.len(), 8 + 10);
    }
}
