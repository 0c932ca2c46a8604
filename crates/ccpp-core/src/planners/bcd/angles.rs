//! Wall-angle estimation (step 1 of the module docs, turned lattice): the dominant wall
//! directions that decide which turned lattices are tried.

use std::cmp::Reverse;

use super::lattice::Ctx;

/// The dominant direction of the map's walls, in radians in `[0, pi/2)` (image frame): the
/// angle whose projections of the C-free boundary (reachable C-free pixels beside a blocked
/// one) onto it and onto its normal are most concentrated (the largest sum of squared counts
/// of one-pixel bins: walls along the angle pile up in few bins), searched in whole degrees
/// and then in tenths around the best; the same for the best local maximum at least
/// [`SECOND_PEAK_DEG`] away (walls of a wing turned against the rest). Empty when the C-free
/// set has no boundary.
pub(super) fn dominant_angles(ctx: &Ctx<'_>) -> Vec<f64> {
    let (w, h) = (ctx.frame.width, ctx.frame.height);
    let mut pts: Vec<(f64, f64)> = Vec::new();
    for r in 0..h {
        for c in 0..w {
            if !ctx.ok[r * w + c] {
                continue;
            }
            let (ci, ri) = (c as i64, r as i64);
            if [(1, 0), (-1, 0), (0, 1), (0, -1)]
                .iter()
                .any(|&(dc, dr)| !ctx.ok_at(ci + dc, ri + dr))
            {
                pts.push((c as f64 + 0.5, r as f64 + 0.5));
            }
        }
    }
    if pts.is_empty() {
        return Vec::new();
    }
    let span = (w + h) as f64 * std::f64::consts::SQRT_2;
    let nb = span.ceil() as usize + 2;
    let mut bins = vec![0u32; 2 * nb];
    let mut score = |deg: f64| -> u64 {
        let (si, co) = deg.to_radians().sin_cos();
        bins.fill(0);
        for &(x, y) in &pts {
            let p = x * co + y * si + span / 2.0;
            let q = -x * si + y * co + span / 2.0;
            bins[(p.max(0.0) as usize).min(nb - 1)] += 1;
            bins[nb + (q.max(0.0) as usize).min(nb - 1)] += 1;
        }
        bins.iter().map(|&b| u64::from(b) * u64::from(b)).sum()
    };
    let coarse: Vec<u64> = (0..90).map(|k| score(f64::from(k))).collect();
    let first = (0..90)
        .max_by_key(|&k| (coarse[k], Reverse(k)))
        .unwrap_or(0);
    let away = |k: usize| {
        let d = k.abs_diff(first);
        d.min(90 - d) >= SECOND_PEAK_DEG
    };
    let peak = |k: usize| coarse[k] >= coarse[(k + 1) % 90] && coarse[k] >= coarse[(k + 89) % 90];
    let second = (0..90)
        .filter(|&k| away(k) && peak(k))
        .max_by_key(|&k| (coarse[k], Reverse(k)));
    let mut out = Vec::new();
    for k in std::iter::once(first).chain(second) {
        let mut best = (coarse[k], k as f64);
        for j in -9..=9 {
            let d = k as f64 + f64::from(j) / 10.0;
            let v = score(d);
            if v > best.0 {
                best = (v, d);
            }
        }
        out.push(best.1.to_radians().rem_euclid(std::f64::consts::FRAC_PI_2));
    }
    out
}

/// Degrees between the turned lattices tried around a wall angle (`angle_tries`).
pub(super) const ANGLE_STEP_DEG: f64 = 0.5;

/// Degrees (at least) between the two wall directions [`dominant_angles`] returns.
const SECOND_PEAK_DEG: usize = 10;

/// A dominant wall direction within this many degrees of the pixel axes is taken as the axes:
/// no turned lattice is tried.
pub(super) const AXIS_TOL_DEG: f64 = 4.0;
