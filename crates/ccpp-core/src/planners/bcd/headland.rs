//! Headland (step 3 of the module docs): contour passes along the C-free boundary of the long
//! obstacles, and the interior of a lattice's free points (at least `2 r_tool` inside those
//! passes) that the cells and lanes are made on.

use super::lattice::{Ctx, Lattice};
use super::transfer::Search;
use crate::geometry::Point;

/// The headland: the interior lattice (see [`interior`]) and the contour passes along the
/// long obstacles' C-free boundary (grid polylines, merged into straight collision-free
/// segments), pieces shorter than `min_piece` points left to the rim step. The passes walk the
/// boundary points from the first one in scan order, to the first unvisited 8-neighbour of
/// the same pass (the 4-neighbours first, in a fixed order); a walk that ends beside its start
/// is closed.
///
/// With `peel` (lattice steps), the passes go on inwards from the outer walls (the obstacles
/// that reach the lattice's border) every `peel` steps until the floor is used up, and the
/// interior is empty (see [`interior`]). More than `max_walks` walks: `None` (a floor that
/// falls apart into that many offset pieces is left to the lanes).
#[allow(clippy::too_many_arguments)] // the headland's inputs, all distinct
pub(super) fn headland(
    ctx: &Ctx<'_>,
    lat: &Lattice,
    search: &mut Search,
    dist: f64,
    min_px: f64,
    min_piece: usize,
    peel: Option<f64>,
    max_walks: usize,
) -> Option<(Vec<bool>, Vec<Vec<Point>>)> {
    let (inner, on_b) = interior(lat, dist, min_px, peel);
    let (w, h) = (lat.w, lat.h);
    let mut seen = vec![false; w * h];
    let mut walks = Vec::new();
    for s in 0..w * h {
        if on_b[s] == 0 || seen[s] {
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
                if on_b[n] == on_b[s] && !seen[n] {
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
        if walks.len() == max_walks {
            return None;
        }
        walks.push((s, at, chain));
    }
    let mut out = Vec::new();
    for (s, at, mut chain) in walks {
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
    Some((inner, out))
}

/// The free points of `lat` whose distance (lattice steps) to every non-free point of an
/// obstacle whose C-free boundary has at least `min_px` edges is at least `dist`, and the
/// passes' points: 1 on the free points beside (8-neighbours of) such obstacles, 0 elsewhere.
///
/// With `peel` (lattice steps), no interior, and the passes go on inwards: pass `k + 1`
/// (`k >= 1`) runs through the free points whose distance to the outer walls (the
/// obstacles that reach the lattice's border, and the outside) is at least `1 + k peel` and
/// which have a free 8-neighbour nearer than that (the front of that distance), except on
/// pass 1. On a ring around a block the offset loops are laid from the outer wall in, the
/// last one beside the block's pass, so the overlap the ring's width leaves falls on the
/// shortest loops (`d` = distance to the outer wall, `r_tool` = 2 steps):
///
/// ```text
/// outer wall   d:  1   5   9  11 12  block
/// ||||||||||||     o   o   o   o  b  ######     o = offset loops 2 r_tool apart,
///                                               b = the block's pass
/// ```
pub(super) fn interior(
    lat: &Lattice,
    dist: f64,
    min_px: f64,
    peel: Option<f64>,
) -> (Vec<bool>, Vec<u32>) {
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
    let mut on_b: Vec<u32> = (0..w * h)
        .map(|i| u32::from(ok[i] && at(i) <= 2.0))
        .collect();
    let Some(step) = peel else {
        let inner = (0..w * h).map(|i| ok[i] && at(i) >= d2).collect();
        return (inner, on_b);
    };
    let step = step.max(1.0);
    let e = crate::dt::squared_edt(w, h, |i| !ok[i] && outer[comp[i] as usize], true);
    // The last pass at most a point's distance: k with (1 + k step)^2 <= e (0: none).
    let level = |i: usize| -> u32 {
        let d = f64::from(e[i]).sqrt();
        if d < 1.0 + step {
            0
        } else {
            // (a distance is at most the lattice's diagonal: far below u32::MAX steps)
            let mut k = ((d - 1.0) / step).floor() as u32;
            while k > 0 && (1.0 + f64::from(k) * step).powi(2) > f64::from(e[i]) {
                k -= 1;
            }
            k
        }
    };
    let lv: Vec<u32> = (0..w * h)
        .map(|i| if ok[i] { level(i) } else { 0 })
        .collect();
    for i in 0..w * h {
        if !ok[i] || on_b[i] != 0 || lv[i] == 0 {
            continue;
        }
        let (c, r) = ((i % w) as i64, (i / w) as i64);
        let front = (-1..=1i64).any(|dr| {
            (-1..=1i64).any(|dc| {
                let (nc, nr) = (c + dc, r + dr);
                if nc < 0 || nr < 0 || nc >= w as i64 || nr >= h as i64 {
                    return false;
                }
                let n = nr as usize * w + nc as usize;
                ok[n] && lv[n] < lv[i]
            })
        });
        if front {
            on_b[i] = lv[i] + 1;
        }
    }
    (vec![false; w * h], on_b)
}
