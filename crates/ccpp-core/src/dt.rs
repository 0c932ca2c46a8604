//! Exact Euclidean distance transform (Felzenszwalb & Huttenlocher, "Distance Transforms of
//! Sampled Functions", Theory of Computing 8, 2012), in O(pixels).
//!
//! Distances are between pixel **centres**, in pixels, returned squared as integers.

/// Squared distance used for "no feature anywhere".
pub const INF: u32 = u32::MAX;

/// Column distance meaning "no feature in this column" (phase 1).
const NONE: u32 = u32::MAX / 4;

/// Squared Euclidean distance from every pixel centre to the nearest feature pixel centre.
///
/// `is_feature(index)` is called once per row-major index. With `border_is_feature`, the ring of
/// pixels just outside the image also counts as features (so the result never exceeds the
/// squared distance to the image border plus one pixel). Pixels with no feature anywhere get
/// [`INF`].
pub fn squared_edt(
    width: usize,
    height: usize,
    is_feature: impl Fn(usize) -> bool,
    border_is_feature: bool,
) -> Vec<u32> {
    let n = width * height;
    if n == 0 {
        return Vec::new();
    }
    // Phase 1 (Meijster et al.): distance to the nearest feature in the same column, in two
    // row-order sweeps (cache friendly). `NONE` = no feature in the column.
    let mut g = vec![NONE; n];
    let edge = if border_is_feature { 0 } else { NONE };
    for r in 0..height {
        for c in 0..width {
            let i = r * width + c;
            g[i] = if is_feature(i) {
                0
            } else if r == 0 {
                edge.saturating_add(1).min(NONE)
            } else {
                (g[i - width] + 1).min(NONE)
            };
        }
    }
    for r in (0..height).rev() {
        for c in 0..width {
            let i = r * width + c;
            let below = if r + 1 == height {
                edge.saturating_add(1).min(NONE)
            } else {
                (g[i + width] + 1).min(NONE)
            };
            if below < g[i] {
                g[i] = below;
            }
        }
    }
    // Phase 2 (Felzenszwalb-Huttenlocher lower envelope) along each row; rows are independent,
    // so large images split them between two threads.
    let big = (width.max(height) as f64 + 2.0).powi(2) * 4.0;
    let mut out = vec![INF; n];
    let rows_pass = |g_rows: &[u32], out_rows: &mut [u32]| {
        let mut f = vec![0f64; width];
        let mut d = vec![0f64; width];
        let mut v = vec![0usize; width];
        let mut z = vec![0f64; width + 1];
        for (row, o) in g_rows
            .chunks_exact(width)
            .zip(out_rows.chunks_exact_mut(width))
        {
            for (fc, &gc) in f.iter_mut().zip(row) {
                *fc = if gc >= NONE {
                    big
                } else {
                    f64::from(gc) * f64::from(gc)
                };
            }
            dt1d(&f, &mut d, &mut v, &mut z);
            for c in 0..width {
                let mut best = d[c];
                if border_is_feature {
                    let b = (c + 1).min(width - c) as f64;
                    best = best.min(b * b);
                }
                o[c] = if best >= big { INF } else { best as u32 };
            }
        }
    };
    if n >= PARALLEL_MIN_PIXELS && height >= 2 {
        let split = height / 2 * width;
        let (g0, g1) = g.split_at(split);
        let (o0, o1) = out.split_at_mut(split);
        std::thread::scope(|s| {
            s.spawn(|| rows_pass(g1, o1));
            rows_pass(g0, o0);
        });
    } else {
        rows_pass(&g, &mut out);
    }
    out
}

/// Images at least this large (pixels) run phase 2 on two threads.
const PARALLEL_MIN_PIXELS: usize = 1 << 20;

/// Lower envelope of parabolas: `d[q] = min_p (q - p)^2 + f[p]`.
fn dt1d(f: &[f64], d: &mut [f64], v: &mut [usize], z: &mut [f64]) {
    let n = f.len();
    if n == 0 {
        return;
    }
    let mut k = 0usize;
    v[0] = 0;
    z[0] = f64::NEG_INFINITY;
    z[1] = f64::INFINITY;
    for q in 1..n {
        let fq = f[q] + (q * q) as f64;
        loop {
            let p = v[k];
            let s = (fq - (f[p] + (p * p) as f64)) / (2.0 * (q as f64 - p as f64));
            if s <= z[k] && k > 0 {
                k -= 1;
            } else if s <= z[k] {
                // k == 0 and z[0] = -inf: cannot happen, kept for clarity.
                break;
            } else {
                k += 1;
                v[k] = q;
                z[k] = s;
                z[k + 1] = f64::INFINITY;
                break;
            }
        }
    }
    k = 0;
    for (q, dq) in d.iter_mut().enumerate().take(n) {
        while z[k + 1] < q as f64 {
            k += 1;
        }
        let p = v[k];
        let diff = q as f64 - p as f64;
        *dq = diff * diff + f[p];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(w: usize, h: usize, feat: &[bool], border: bool) -> Vec<u32> {
        let mut out = vec![INF; w * h];
        for r in 0..h as i64 {
            for c in 0..w as i64 {
                let mut best = i64::from(INF);
                for rr in -1..=h as i64 {
                    for cc in -1..=w as i64 {
                        let inside = rr >= 0 && cc >= 0 && rr < h as i64 && cc < w as i64;
                        let is_f = if inside {
                            feat[(rr as usize) * w + cc as usize]
                        } else {
                            border
                        };
                        if is_f {
                            best = best.min((rr - r).pow(2) + (cc - c).pow(2));
                        }
                    }
                }
                out[r as usize * w + c as usize] = best.min(i64::from(INF)) as u32;
            }
        }
        out
    }

    #[test]
    fn matches_brute_force() {
        let mut seed = 12345u64;
        for trial in 0..30 {
            let w = 1 + trial % 9;
            let h = 1 + (trial * 7) % 11;
            let feat: Vec<bool> = (0..w * h)
                .map(|_| {
                    seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
                    (seed >> 33).is_multiple_of(7)
                })
                .collect();
            for border in [false, true] {
                let got = squared_edt(w, h, |i| feat[i], border);
                assert_eq!(
                    got,
                    brute(w, h, &feat, border),
                    "w={w} h={h} border={border}"
                );
            }
        }
    }
}
