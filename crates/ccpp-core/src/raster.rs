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
    capsule_runs(frame, a, b, rt, |row, c_lo, c_hi| {
        let base = row * frame.width;
        crate::bits::insert_range(
            bits.as_mut_slice(),
            base + c_lo,
            base + c_hi + 1,
            &mut *on_new,
        );
    });
}

/// The pixels of [`stamp_capsule`]'s capsule as row runs: `on_run(row, c_lo, c_hi)` for every
/// image row holding pixels of the capsule (in increasing row order, each row once), the run
/// being the columns `c_lo..=c_hi`. [`stamp_capsule`] marks exactly these runs.
pub fn capsule_runs(
    frame: &crate::grid::MapFrame,
    a: Point,
    b: Point,
    rt: f64,
    mut on_run: impl FnMut(usize, usize, usize),
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
    // The run of one row, `None` when the row holds no pixel of the capsule.
    let row_run = |row: i64| -> Option<(usize, usize)> {
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
            return None;
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
            let c = [first - 1, c_hi + 1].into_iter().find(|&c| inside(c))?;
            (c_lo, c_hi) = (c, c);
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
        (c_lo <= c_hi).then_some((c_lo as usize, c_hi as usize))
    };
    // A vertical segment's rows between its end disks all have the same run: there the
    // nearest point of the segment is the pixel centre's projection, at the segment's x
    // exactly, and the rounding of its y (a few ulps of the map's extent, squared) lies below
    // half an ulp of `rt2` (guaranteed by `extent < 1e6 rt`), so the exact predicate is
    // `(c + 0.5 - a.x)^2 <= rt2` on every such row, and the closed-form estimate does not
    // depend on the row either. Those rows reuse the first one's run (same runs as row by row).
    let extent = h.max(a.y.abs()).max(b.y.abs());
    let vertical = d.x == 0.0 && d.y.abs() >= 1e-6 && extent < 1e6 * rt && rt2 > 0.0;
    let mut shared: Option<Option<(usize, usize)>> = None;
    for row in r0..=r1 {
        if vertical {
            let gy = h - row as f64 - 0.5;
            let (dya, dyb) = (gy - a.y, gy - b.y);
            if rt2 - dya * dya < 0.0 && rt2 - dyb * dyb < 0.0 && (0.0..=l2).contains(&(dya * d.y)) {
                if let Some((c_lo, c_hi)) = *shared.get_or_insert_with(|| row_run(row)) {
                    on_run(row as usize, c_lo, c_hi);
                }
                continue;
            }
        }
        if let Some((c_lo, c_hi)) = row_run(row) {
            on_run(row as usize, c_lo, c_hi);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Pose;
    use proptest::prelude::*;

    fn frame() -> crate::grid::MapFrame {
        crate::grid::MapFrame {
            width: 37,
            height: 29,
            resolution: 0.05,
            origin: Pose::new(0.0, 0.0, 0.0),
        }
    }

    /// A segment of kind `kind`: a point, horizontal, vertical, 45-degree diagonal or any.
    fn segment(kind: u8, a: (f64, f64), b: (f64, f64)) -> (Point, Point) {
        let a = Point::new(a.0, a.1);
        let b = match kind {
            0 => a,
            1 => Point::new(b.0, a.y),
            2 => Point::new(a.x, b.1),
            3 => Point::new(b.0, a.y + (b.0 - a.x)),
            _ => Point::new(b.0, b.1),
        };
        (a, b)
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 512, rng_seed: proptest::test_runner::RngSeed::Fixed(0x5eed_0131), ..ProptestConfig::default() })]

        /// The runs of `capsule_runs` are the pixels `stamp_capsule` marks and the pixel centres
        /// within `rt` of the segment, one run per row in increasing row order.
        #[test]
        fn capsule_runs_are_the_stamped_pixels(
            kind in 0u8..5,
            a in (-4.0f64..41.0, -4.0f64..33.0),
            b in (-4.0f64..41.0, -4.0f64..33.0),
            rt in 0.3f64..7.0,
        ) {
            let f = frame();
            let (a, b) = segment(kind, a, b);
            let mut stamped = FixedBitSet::with_capacity(f.len());
            stamp_capsule(&mut stamped, &f, a, b, rt, &mut |_| {});
            let mut runs = FixedBitSet::with_capacity(f.len());
            let mut last_row = None;
            capsule_runs(&f, a, b, rt, |row, c0, c1| {
                assert!(last_row.is_none_or(|r| r < row), "rows out of order");
                assert!(c0 <= c1 && c1 < f.width && row < f.height);
                last_row = Some(row);
                runs.insert_range(row * f.width + c0..row * f.width + c1 + 1);
            });
            prop_assert_eq!(&runs, &stamped);
            for row in 0..f.height {
                for col in 0..f.width {
                    let q = f.pixel_center_grid(col, row);
                    let inside = point_segment_dist2(q, a, b) <= rt * rt;
                    prop_assert_eq!(runs.contains(f.index(col, row)), inside, "pixel {} {}", col, row);
                }
            }
        }
    }
}
