//! Rasterising shapes onto pixel bitsets, shared by the metrics (swept pixels) and the planners
//! that track what their tool has swept (so planners never depend on the metrics).

use std::ops::Sub;

use fixedbitset::FixedBitSet;

use crate::geometry::{ceil_i64, floor_i64, point_segment_dist2, Point};

/// Tolerance in pixels when deciding whether a pixel centre is within `r_tool` of the path
/// (the metrics and the planners that track their swept pixels use the same).
pub const SWEEP_EPS_PX: f64 = 1e-6;

/// Marks pixel centres within `rt` (pixels) of segment `a`-`b` (grid coordinates), row by row,
/// calling `on_new(index)` for each pixel not marked before.
///
/// The distance to a segment is convex along a row, so each row's pixels form one run of
/// columns. The run's ends are estimated in closed form (union of the two end disks and the
/// band around the segment, cut by the row), then settled with the exact predicate
/// `point_segment_dist2(centre, a, b) <= rt^2`, and the run is marked a bitset block at a time.
pub fn stamp_capsule(
    bits: &mut FixedBitSet,
    frame: &crate::grid::MapFrame,
    a: Point,
    b: Point,
    rt: f64,
    on_new: &mut impl FnMut(usize),
) {
    let rt2 = rt * rt;
    let h = frame.height as f64;
    let w = frame.width as i64;
    let ylo = a.y.min(b.y) - rt;
    let yhi = a.y.max(b.y) + rt;
    // Rows whose centre gy = h - row - 0.5 lies in [ylo, yhi].
    let r0 = (h - yhi - 0.5).ceil().max(0.0) as i64;
    let r1 = ((h - ylo - 0.5).floor() as i64).min(frame.height as i64 - 1);
    let d = b.sub(a);
    let l2 = d.dot(d);
    let len = l2.sqrt();
    for row in r0..=r1 {
        let gy = h - row as f64 - 0.5;
        let inside = |c: i64| point_segment_dist2(Point::new(c as f64 + 0.5, gy), a, b) <= rt2;
        // Closed-form x-extent of the capsule on this row (slightly generous is fine: the
        // ends are settled with the predicate below).
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for e in [a, b] {
            let dy = gy - e.y;
            let rem = rt2 - dy * dy;
            if rem >= 0.0 {
                let hw = rem.sqrt();
                lo = lo.min(e.x - hw);
                hi = hi.max(e.x + hw);
            }
        }
        let dya = gy - a.y;
        if d.y != 0.0 {
            // Perpendicular distance <= rt ...
            let (p, q) = (
                a.x + (d.x * dya - rt * len) / d.y,
                a.x + (d.x * dya + rt * len) / d.y,
            );
            let (mut blo, mut bhi) = (p.min(q), p.max(q));
            // ... and the projection on the segment within [0, 1].
            if d.x != 0.0 {
                let (p, q) = (a.x - dya * d.y / d.x, a.x + (l2 - dya * d.y) / d.x);
                blo = blo.max(p.min(q));
                bhi = bhi.min(p.max(q));
            } else if !(0.0..=l2).contains(&(dya * d.y)) {
                blo = f64::INFINITY;
            }
            if blo <= bhi {
                lo = lo.min(blo);
                hi = hi.max(bhi);
            }
        } else if dya.abs() <= rt {
            lo = lo.min(a.x.min(b.x));
            hi = hi.max(a.x.max(b.x));
        }
        if lo > hi {
            continue;
        }
        let mut c_lo = ceil_i64(lo - 0.5).clamp(-1, w);
        let mut c_hi = floor_i64(hi - 0.5).clamp(-1, w);
        // Settle the ends with the exact predicate (a step or two at most).
        let first = c_lo;
        while c_lo <= c_hi && !inside(c_lo) {
            c_lo += 1;
        }
        if c_lo > c_hi {
            // The estimate holds no pixel of the run (rounding at a tangent row): the run, if
            // any, is a pixel just outside it.
            match [first - 1, c_hi + 1].into_iter().find(|&c| inside(c)) {
                Some(c) => (c_lo, c_hi) = (c, c),
                None => continue,
            }
        }
        while c_lo > 0 && inside(c_lo - 1) {
            c_lo -= 1;
        }
        if inside(c_hi) {
            while c_hi < w - 1 && inside(c_hi + 1) {
                c_hi += 1;
            }
        } else {
            while c_hi > c_lo && !inside(c_hi) {
                c_hi -= 1;
            }
        }
        let (c_lo, c_hi) = (c_lo.max(0), c_hi.min(w - 1));
        if c_lo > c_hi {
            continue;
        }
        let base = row as usize * frame.width;
        crate::bits::insert_range(
            bits.as_mut_slice(),
            base + c_lo as usize,
            base + c_hi as usize + 1,
            &mut *on_new,
        );
    }
}
