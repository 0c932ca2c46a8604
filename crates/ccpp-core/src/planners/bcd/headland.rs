//! Headland (step 3 of the module docs): contour passes along the C-free boundary of the long
//! obstacles, and the interior of a lattice's free points (at least `2 r_tool` inside those
//! passes) that the cells and lanes are made on.

use super::lattice::{Ctx, Lattice};
use super::transfer::Search;
use crate::geometry::Point;

/// The headland: the interior lattice (see [`interior`]) and the contour passes along the
/// long obstacles' C-free boundary (grid polylines, merged into straight collision-free
/// segments), pieces shorter than `min_piece` points left to the rim step. The passes walk the
/// boundary points from the first one in scan order, to the first unvisited 8-neighbour (the
/// 4-neighbours first, in a fixed order); a walk that ends beside its start is closed.
pub(super) fn headland(
    ctx: &Ctx<'_>,
    lat: &Lattice,
    search: &mut Search,
    dist: f64,
    min_px: f64,
    min_piece: usize,
) -> (Vec<bool>, Vec<Vec<Point>>) {
    let (inner, on_b) = interior(lat, dist, min_px);
    let (w, h) = (lat.w, lat.h);
    let mut seen = vec![false; w * h];
    let mut out = Vec::new();
    for s in 0..w * h {
        if !on_b[s] || seen[s] {
            continue;
        }
        let mut chain = vec![s];
        seen[s] = true;
        let mut at = s;
        loop {
            let (c, r) = ((at % w) as i64, (at / w) as i64);
            let mut next = None;
            for (dc, dr) in [
                (1i64, 0i64),
                (0, 1),
                (-1, 0),
                (0, -1),
                (1, 1),
                (-1, 1),
                (-1, -1),
                (1, -1),
            ] {
                let (nc, nr) = (c + dc, r + dr);
                if nc < 0 || nr < 0 || nc >= w as i64 || nr >= h as i64 {
                    continue;
                }
                let n = nr as usize * w + nc as usize;
                if on_b[n] && !seen[n] {
                    next = Some(n);
                    break;
                }
            }
            let Some(n) = next else { break };
            seen[n] = true;
            chain.push(n);
            at = n;
        }
        if chain.len() < min_piece {
            continue;
        }
        // Close the loop when the walk ended beside its start.
        let (c0, r0) = ((s % w) as i64, (s / w) as i64);
        let (c1, r1) = ((at % w) as i64, (at / w) as i64);
        if (c0 - c1).abs() <= 1 && (r0 - r1).abs() <= 1 {
            chain.push(s);
        }
        let pts: Vec<Point> = chain
            .iter()
            .map(|&i| lat.grid((i % w) as f64, (i / w) as f64))
            .collect();
        if let Some(tail) = ctx.follow(search, &pts) {
            let mut p = vec![pts[0]];
            p.extend(tail);
            p.dedup();
            if p.len() >= 2 {
                out.push(p);
            }
        }
    }
    (inner, out)
}

/// The free points of `lat` whose distance (lattice steps) to every non-free point of an
/// obstacle whose C-free boundary has at least `min_px` edges is at least `dist`, and the
/// free points beside (8-neighbours of) such obstacles.
pub(super) fn interior(lat: &Lattice, dist: f64, min_px: f64) -> (Vec<bool>, Vec<bool>) {
    let (w, h) = (lat.w, lat.h);
    let ok = &lat.ok;
    // 8-connected components of non-free points; the lattice's outside is component 0.
    let mut comp = vec![u32::MAX; w * h];
    let mut perim: Vec<usize> = Vec::new();
    let mut outer: Vec<bool> = Vec::new();
    for s in 0..w * h {
        if ok[s] || comp[s] != u32::MAX {
            continue;
        }
        let id = perim.len() as u32;
        perim.push(0);
        outer.push(false);
        comp[s] = id;
        let mut stack = vec![s];
        while let Some(i) = stack.pop() {
            let (c, r) = ((i % w) as i64, (i / w) as i64);
            for dr in -1..=1i64 {
                for dc in -1..=1i64 {
                    let (nc, nr) = (c + dc, r + dr);
                    if nc < 0 || nr < 0 || nc >= w as i64 || nr >= h as i64 {
                        outer[id as usize] = true;
                        continue;
                    }
                    let n = nr as usize * w + nc as usize;
                    if !ok[n] && comp[n] == u32::MAX {
                        comp[n] = id;
                        stack.push(n);
                    }
                }
            }
        }
    }
    for i in 0..w * h {
        if !ok[i] {
            continue;
        }
        let (c, r) = (i % w, i / w);
        for (dc, dr) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
            let (nc, nr) = (c as i64 + dc, r as i64 + dr);
            if nc < 0 || nr < 0 || nc >= w as i64 || nr >= h as i64 {
                continue;
            }
            let n = nr as usize * w + nc as usize;
            if !ok[n] {
                perim[comp[n] as usize] += 1;
            }
        }
    }
    let big: Vec<bool> = perim
        .iter()
        .zip(&outer)
        .map(|(&p, &o)| o || p as f64 >= min_px)
        .collect();
    // Exact squared Euclidean distance (lattice steps) to the seeds: the big obstacles and the
    // lattice's outside (the ring just beyond its border).
    let d = crate::dt::squared_edt(w, h, |i| !ok[i] && big[comp[i] as usize], true);
    let d2 = dist * dist;
    let at = |i: usize| f64::from(d[i]);
    let inner = (0..w * h).map(|i| ok[i] && at(i) >= d2).collect();
    let on_b = (0..w * h).map(|i| ok[i] && at(i) <= 2.0).collect();
    (inner, on_b)
}
