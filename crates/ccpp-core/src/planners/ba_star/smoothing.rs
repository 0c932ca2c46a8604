//! A*SPT path smoothing and its line-of-sight geometry (the tiles a moving disk sweeps).

use crate::geometry::{ceil_i32, floor_i32, point_segment_dist2, round_i32, Point};
use crate::tiles::Tile;

/// Squared distance between segment `a`-`b` and the axis-aligned box `lo`-`hi` (0 when they
/// meet).
pub(super) fn segment_box_dist2(a: Point, b: Point, lo: Point, hi: Point) -> f64 {
    // Liang-Barsky clip: does the segment meet the box?
    let d = Point::new(b.x - a.x, b.y - a.y);
    let mut t0: f64 = 0.0;
    let mut t1: f64 = 1.0;
    let mut meets = true;
    for (p, q) in [
        (-d.x, a.x - lo.x),
        (d.x, hi.x - a.x),
        (-d.y, a.y - lo.y),
        (d.y, hi.y - a.y),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                meets = false;
                break;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
            if t0 > t1 {
                meets = false;
                break;
            }
        }
    }
    if meets {
        return 0.0;
    }
    let pb = |p: Point| {
        let dx = (lo.x - p.x).max(0.0).max(p.x - hi.x);
        let dy = (lo.y - p.y).max(0.0).max(p.y - hi.y);
        dx * dx + dy * dy
    };
    let mut best = pb(a).min(pb(b));
    for c in [lo, Point::new(hi.x, lo.y), hi, Point::new(lo.x, hi.y)] {
        best = best.min(point_segment_dist2(c, a, b));
    }
    best
}

/// Calls `f` for every tile whose square the open disk of radius `rho` (in tile units) touches
/// while its centre moves from tile `a`'s centre to tile `b`'s; stops early when `f` returns
/// `false` (and then returns `false`). Tiles merely touching the swept disk's boundary (distance
/// exactly `rho`, as for the side neighbours of a straight move between centres at `rho = 1/2`)
/// are not touched.
pub fn for_each_swept_tile(a: Tile, b: Tile, rho: f64, f: impl FnMut(Tile) -> bool) -> bool {
    sweep(a, b, rho, |_| false, f)
}

/// Does `ok` hold for every tile [`for_each_swept_tile`] touches from `a` to `b`? The same
/// answer as `for_each_swept_tile(a, b, rho, ok)` for a pure `ok`, reading `ok` first: the
/// touching test (the geometry) is done only for the tiles near the swept disk where `ok`
/// fails, not for all of them.
pub fn all_swept_tiles(a: Tile, b: Tile, rho: f64, ok: impl Fn(Tile) -> bool) -> bool {
    sweep(a, b, rho, ok, |_| false)
}

/// [`for_each_swept_tile`], passing over the tiles with `skip` without testing whether the
/// disk touches them.
fn sweep(
    a: Tile,
    b: Tile,
    rho: f64,
    skip: impl Fn(Tile) -> bool,
    mut f: impl FnMut(Tile) -> bool,
) -> bool {
    let pa = Point::new(f64::from(a.0), f64::from(a.1));
    let pb = Point::new(f64::from(b.0), f64::from(b.1));
    let lim = (rho * rho) * (1.0 - 1e-9) - 1e-12;
    let (dx, dy) = (pb.x - pa.x, pb.y - pa.y);
    // Shortcuts from the squared distance of a tile's centre to the segment, exact with wide
    // margins (the unit square holds the disk of radius 1/2 around its centre and lies in the
    // disk of radius sqrt(1/2)): clearly below 1/4, the segment crosses the square (box
    // distance 0 < `lim`); clearly above `(rho + sqrt(1/2))^2`, the square is farther than
    // `rho`. Only the tiles between take the box distance.
    let accept2 = if lim > 1e-9 {
        0.25 * (1.0 - 1e-6)
    } else {
        -1.0
    };
    let reject2 = (rho + std::f64::consts::FRAC_1_SQRT_2 + 1e-6).powi(2);
    let touches = |i: i32, y: f64| {
        let dc2 = point_segment_dist2(Point::new(f64::from(i), y), pa, pb);
        if dc2 < accept2 {
            true
        } else if dc2 >= reject2 {
            false
        } else {
            let lo = Point::new(f64::from(i) - 0.5, y - 0.5);
            let hi = Point::new(f64::from(i) + 0.5, y + 0.5);
            segment_box_dist2(pa, pb, lo, hi) < lim
        }
    };
    let step: i32 = if b.1 >= a.1 { 1 } else { -1 };
    let reach = rho + 0.5;
    let j_first = if step > 0 {
        floor_i32(pa.y - reach)
    } else {
        ceil_i32(pa.y + reach)
    };
    let j_last = if step > 0 {
        ceil_i32(pb.y + reach)
    } else {
        floor_i32(pb.y - reach)
    };
    let mut j = j_first;
    loop {
        let y = f64::from(j);
        let (tl, th) = if dy == 0.0 {
            (0.0, 1.0)
        } else {
            let t1 = (y - reach - pa.y) / dy;
            let t2 = (y + reach - pa.y) / dy;
            (t1.min(t2).max(0.0), t1.max(t2).min(1.0))
        };
        if tl <= th && (dy != 0.0 || (pa.y - y).abs() <= reach) {
            let xa = pa.x + tl * dx;
            let xb = pa.x + th * dx;
            let i_lo = floor_i32(xa.min(xb) - reach);
            let i_hi = ceil_i32(xa.max(xb) + reach);
            let (mut i, i_end, istep) = if dx >= 0.0 {
                (i_lo, i_hi, 1)
            } else {
                (i_hi, i_lo, -1)
            };
            loop {
                if !skip((i, j)) && touches(i, y) && !f((i, j)) {
                    return false;
                }
                if i == i_end {
                    break;
                }
                i += istep;
            }
        }
        if j == j_last {
            break;
        }
        j += step;
    }
    true
}

/// Calls `f` for tiles that [`for_each_swept_tile`] with the same `a`, `b` and a radius
/// `rho > 1e-3` surely visits: the tiles holding the points `a + (k / n) (b - a)`, `k = 0..=n`,
/// `n` the larger of `|b - a|`'s coordinates (tile units), each point rounded to its tile. The
/// centre passes through each such (closed) square, so the square's distance to the segment is
/// zero (up to rounding far below `rho^2`) and the swept disk touches it. Stops early when `f`
/// returns `false` (and then returns `false`). A cheap first test of line of sight: one tile per
/// step along the longer axis, no distances.
pub(super) fn for_each_centre_tile(a: Tile, b: Tile, mut f: impl FnMut(Tile) -> bool) -> bool {
    let (dx, dy) = (
        i64::from(b.0) - i64::from(a.0),
        i64::from(b.1) - i64::from(a.1),
    );
    let n = dx.abs().max(dy.abs());
    if n == 0 {
        return f(a);
    }
    let (ax, ay) = (f64::from(a.0), f64::from(a.1));
    let (fx, fy) = (dx as f64, dy as f64);
    let nf = n as f64;
    for k in 0..=n {
        let t = k as f64 / nf;
        let t = (round_i32(ax + t * fx), round_i32(ay + t * fy));
        if !f(t) {
            return false;
        }
    }
    true
}

/// A*SPT: from the current waypoint jump to the farthest later tile of `path` for which
/// `visible(from, to)` holds; repeat. Consecutive tiles of the path must be visible (so the
/// result always reaches the last tile).
pub fn smooth_path(path: &[Tile], mut visible: impl FnMut(Tile, Tile) -> bool) -> Vec<Tile> {
    let Some(&first) = path.first() else {
        return Vec::new();
    };
    let mut out = vec![first];
    let mut k = 0;
    let n = path.len();
    while k + 1 < n {
        let mut m = n - 1;
        while m > k + 1 && !visible(path[k], path[m]) {
            m -= 1;
        }
        out.push(path[m]);
        k = m;
    }
    out
}
