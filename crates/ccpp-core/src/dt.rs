//! Exact Euclidean distance transform (Felzenszwalb & Huttenlocher, "Distance Transforms of
//! Sampled Functions", Theory of Computing 8, 2012), in O(pixels).
//!
//! Distances are between pixel **centres**, in pixels, returned squared as integers.

/// Squared distance used for "no feature anywhere".
pub const INF: u32 = u32::MAX;

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
    let mut out = vec![INF; n];
    if n == 0 {
        return out;
    }
    let big = (width.max(height) as f64 + 2.0).powi(2) * 4.0;
    // Pass 1: columns, 1-D distance to the nearest feature in the same column.
    let mut f = vec![0f64; height.max(width)];
    let mut d = vec![0f64; height.max(width)];
    let mut v = vec![0usize; height.max(width)];
    let mut z = vec![0f64; height.max(width) + 1];
    let mut col_d = vec![f64::INFINITY; n];
    for c in 0..width {
        for r in 0..height {
            f[r] = if is_feature(r * width + c) { 0.0 } else { big };
        }
        dt1d(&f[..height], &mut d[..height], &mut v, &mut z);
        for r in 0..height {
            col_d[r * width + c] = d[r];
        }
    }
    // Pass 2: rows.
    for r in 0..height {
        f[..width].copy_from_slice(&col_d[r * width..(r + 1) * width]);
        dt1d(&f[..width], &mut d[..width], &mut v, &mut z);
        for c in 0..width {
            let mut best = d[c];
            if border_is_feature {
                let b = [(c + 1), (width - c), (r + 1), (height - r)]
                    .into_iter()
                    .min()
                    .unwrap_or(1) as f64;
                best = best.min(b * b);
            }
            out[r * width + c] = if best >= big { INF } else { best as u32 };
        }
    }
    out
}

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
