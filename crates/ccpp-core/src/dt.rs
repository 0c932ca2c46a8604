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
    is_feature: impl Fn(usize) -> bool + Sync,
    border_is_feature: bool,
) -> Vec<u32> {
    let n = width * height;
    if n == 0 {
        return Vec::new();
    }
    if height + 2 < usize::from(u16::MAX) {
        let g = column_pass::<u16>(width, height, &is_feature, border_is_feature);
        envelope_pass::<u16, u32>(&g, width, border_is_feature)
    } else {
        let g = column_pass::<u32>(width, height, &is_feature, border_is_feature);
        envelope_pass::<u32, u32>(&g, width, border_is_feature)
    }
}

/// A squared distance transform stored in the narrowest integer that holds every value
/// exactly: 2 bytes per pixel when no pixel can lie 256 pixels or more from its nearest
/// feature (known before the values are computed, from the distances along each column and
/// each row), else 4.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum CompactDt {
    /// Every value below `u16::MAX`; `u16::MAX` stands for [`INF`].
    U16(Vec<u16>),
    /// Any value.
    U32(Vec<u32>),
}

impl CompactDt {
    /// The squared distance of pixel `i` ([`INF`] when no feature exists).
    #[inline]
    pub fn get(&self, i: usize) -> u32 {
        match self {
            Self::U16(v) => {
                let d = v[i];
                if d == u16::MAX {
                    INF
                } else {
                    u32::from(d)
                }
            }
            Self::U32(v) => v[i],
        }
    }

    /// Number of pixels.
    pub fn len(&self) -> usize {
        match self {
            Self::U16(v) => v.len(),
            Self::U32(v) => v.len(),
        }
    }

    /// Whether it holds no pixel.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Bytes per pixel of the storage (2 or 4).
    pub fn bytes_per_pixel(&self) -> usize {
        match self {
            Self::U16(_) => 2,
            Self::U32(_) => 4,
        }
    }

    /// The largest value over the pixels of `range` (not empty) and the first pixel holding
    /// it.
    pub fn first_max(&self, range: std::ops::Range<usize>) -> (u32, usize) {
        let start = range.start;
        match self {
            // `u16::MAX` stands for INF, the largest value either way.
            Self::U16(v) => {
                let part = &v[range];
                let m = part.iter().copied().max().unwrap_or(0);
                let k = part.iter().position(|&d| d == m).unwrap_or(0);
                (if m == u16::MAX { INF } else { u32::from(m) }, start + k)
            }
            Self::U32(v) => {
                let part = &v[range];
                let m = part.iter().copied().max().unwrap_or(0);
                let k = part.iter().position(|&d| d == m).unwrap_or(0);
                (m, start + k)
            }
        }
    }

    /// Calls `f(i, d2)` for every pixel in index order.
    #[inline]
    pub fn for_each(&self, mut f: impl FnMut(usize, u32)) {
        match self {
            Self::U16(v) => {
                for (i, &d) in v.iter().enumerate() {
                    f(i, if d == u16::MAX { INF } else { u32::from(d) });
                }
            }
            Self::U32(v) => {
                for (i, &d) in v.iter().enumerate() {
                    f(i, d);
                }
            }
        }
    }
}

/// [`squared_edt`] stored as a [`CompactDt`] (same values). Peak memory: the column distances
/// (2 bytes per pixel for images under 65 533 rows) plus the result.
pub fn squared_edt_compact(
    width: usize,
    height: usize,
    is_feature: impl Fn(usize) -> bool + Sync,
    border_is_feature: bool,
) -> CompactDt {
    if width * height == 0 {
        return CompactDt::U16(Vec::new());
    }
    if height + 2 < usize::from(u16::MAX) {
        let g = column_pass::<u16>(width, height, &is_feature, border_is_feature);
        let bound = distance_bound(&g, width, border_is_feature);
        if bound.is_some_and(|b| b * b < u64::from(u16::MAX)) {
            CompactDt::U16(envelope_pass::<u16, u16>(&g, width, border_is_feature))
        } else {
            CompactDt::U32(envelope_pass::<u16, u32>(&g, width, border_is_feature))
        }
    } else {
        let g = column_pass::<u32>(width, height, &is_feature, border_is_feature);
        CompactDt::U32(envelope_pass::<u32, u32>(&g, width, border_is_feature))
    }
}

/// An unsigned integer the transform stores.
trait Store: Copy + Send + Sync + PartialOrd {
    /// "No feature in this column" (phase 1).
    const NONE: Self;
    /// "No feature anywhere" (results).
    const INF: Self;
    fn from_u32(v: u32) -> Self;
    fn to_u32(self) -> u32;
}

impl Store for u16 {
    const NONE: Self = u16::MAX;
    const INF: Self = u16::MAX;
    #[inline]
    fn from_u32(v: u32) -> Self {
        v as u16
    }
    #[inline]
    fn to_u32(self) -> u32 {
        u32::from(self)
    }
}

impl Store for u32 {
    const NONE: Self = NONE;
    const INF: Self = INF;
    #[inline]
    fn from_u32(v: u32) -> Self {
        v
    }
    #[inline]
    fn to_u32(self) -> u32 {
        self
    }
}

/// Phase 1 (Meijster et al.): distance to the nearest feature in the same column, in two
/// row-order sweeps (cache friendly); `T::NONE` = no feature in the column. `T` must hold
/// `height + 1`. Columns are independent: large images split them (left and right halves of
/// every row) between two threads.
fn column_pass<T: Store>(
    width: usize,
    height: usize,
    is_feature: &(impl Fn(usize) -> bool + Sync),
    border_is_feature: bool,
) -> Vec<T> {
    let n = width * height;
    let mut g = vec![T::NONE; n];
    if n >= PARALLEL_MIN_PIXELS && width >= 2 {
        let half = width / 2;
        let (mut left, mut right): (Vec<&mut [T]>, Vec<&mut [T]>) = g
            .chunks_exact_mut(width)
            .map(|row| row.split_at_mut(half))
            .unzip();
        std::thread::scope(|s| {
            s.spawn(|| column_strip(&mut right, half, width, is_feature, border_is_feature));
            column_strip(&mut left, 0, width, is_feature, border_is_feature);
        });
    } else {
        let mut rows: Vec<&mut [T]> = g.chunks_exact_mut(width).collect();
        column_strip(&mut rows, 0, width, is_feature, border_is_feature);
    }
    g
}

/// [`column_pass`] on a strip of columns: `rows[r]` holds row `r` from column `c0` on.
fn column_strip<T: Store>(
    rows: &mut [&mut [T]],
    c0: usize,
    width: usize,
    is_feature: &impl Fn(usize) -> bool,
    border_is_feature: bool,
) {
    let none = T::NONE.to_u32();
    let edge = if border_is_feature { 0 } else { none };
    let step = |v: u32| v.saturating_add(1).min(none);
    for r in 0..rows.len() {
        let (above, rest) = rows.split_at_mut(r);
        let row = &mut *rest[0];
        let base = r * width + c0;
        match above.last() {
            None => {
                for (c, v) in row.iter_mut().enumerate() {
                    *v = T::from_u32(if is_feature(base + c) { 0 } else { step(edge) });
                }
            }
            Some(prev) => {
                for (c, (v, p)) in row.iter_mut().zip(prev.iter()).enumerate() {
                    *v = T::from_u32(if is_feature(base + c) {
                        0
                    } else {
                        step(p.to_u32())
                    });
                }
            }
        }
    }
    for r in (0..rows.len()).rev() {
        let (upto, below) = rows.split_at_mut(r + 1);
        let row = &mut *upto[r];
        match below.first() {
            None => {
                let b = T::from_u32(step(edge));
                for v in row.iter_mut() {
                    if b < *v {
                        *v = b;
                    }
                }
            }
            Some(next) => {
                for (v, nx) in row.iter_mut().zip(next.iter()) {
                    let b = T::from_u32(step(nx.to_u32()));
                    if b < *v {
                        *v = b;
                    }
                }
            }
        }
    }
}

/// An upper bound on every pixel's distance to its nearest feature, from the column distances
/// `g` of [`column_pass`]: the largest over pixels of the smaller of the column distance and
/// the distance to the nearest feature (or, with `border_is_feature`, border) in the same row.
/// `None` when some pixel may have no feature at all.
fn distance_bound<T: Store>(g: &[T], width: usize, border_is_feature: bool) -> Option<u64> {
    let height = g.len() / width;
    if g.len() >= PARALLEL_MIN_PIXELS && height >= 2 {
        // Rows are independent: two halves on two threads.
        let (g0, g1) = g.split_at(height / 2 * width);
        let (b0, b1) = std::thread::scope(|s| {
            let b1 = s.spawn(|| rows_bound(g1, width, border_is_feature));
            let b0 = rows_bound(g0, width, border_is_feature);
            match b1.join() {
                Ok(b1) => (b0, b1),
                Err(panic) => std::panic::resume_unwind(panic),
            }
        });
        return Some(b0?.max(b1?));
    }
    rows_bound(g, width, border_is_feature)
}

/// [`distance_bound`] over the rows of `g`.
fn rows_bound<T: Store>(g: &[T], width: usize, border_is_feature: bool) -> Option<u64> {
    let none = T::NONE.to_u32();
    let far = u32::MAX;
    let start = if border_is_feature { 0 } else { far };
    let mut left = vec![0u32; width];
    let mut bound = 0u32;
    for row in g.chunks_exact(width) {
        let mut run = start;
        for (l, &gc) in left.iter_mut().zip(row) {
            run = if gc.to_u32() == 0 {
                0
            } else {
                run.saturating_add(1)
            };
            *l = run;
        }
        let mut run = start;
        for (l, &gc) in left.iter().zip(row).rev() {
            let gc = gc.to_u32();
            run = if gc == 0 { 0 } else { run.saturating_add(1) };
            let column = if gc >= none { far } else { gc };
            let d = column.min(run).min(*l);
            if d == far {
                return None;
            }
            bound = bound.max(d);
        }
    }
    Some(u64::from(bound))
}

/// Phase 2 (Felzenszwalb-Huttenlocher lower envelope) along each row of the column distances
/// `g`; rows are independent, so large images split them between two threads. `O` must hold
/// every finite result (checked by the caller); no feature gives `O::INF`.
fn envelope_pass<G: Store, O: Store>(g: &[G], width: usize, border_is_feature: bool) -> Vec<O> {
    let n = g.len();
    let height = n / width;
    let none = G::NONE.to_u32();
    let big = (width.max(height) as f64 + 2.0).powi(2) * 4.0;
    let inf = O::INF;
    let mut out = vec![inf; n];
    let rows_pass = |g_rows: &[G], out_rows: &mut [O]| {
        let mut f = vec![0f64; width];
        let mut d = vec![0f64; width];
        let mut v = vec![0usize; width];
        let mut z = vec![0f64; width + 1];
        for (row, o) in g_rows
            .chunks_exact(width)
            .zip(out_rows.chunks_exact_mut(width))
        {
            for (fc, &gc) in f.iter_mut().zip(row) {
                let gc = gc.to_u32();
                *fc = if gc >= none {
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
                o[c] = if best >= big {
                    inf
                } else {
                    O::from_u32(best as u32)
                };
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
        rows_pass(g, &mut out);
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

    /// Large images split the column pass and the distance bound between two threads: the
    /// same values as one pass over the whole image (featureless columns included).
    #[test]
    fn split_passes_match_one_pass() {
        let (w, h) = (1031, 1025);
        assert!(w * h >= PARALLEL_MIN_PIXELS);
        let mut seed = 99u64;
        let feat: Vec<bool> = (0..w * h)
            .map(|i| {
                seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
                i % w != 700 && (seed >> 33).is_multiple_of(997)
            })
            .collect();
        for border in [false, true] {
            let split = column_pass::<u16>(w, h, &|i: usize| feat[i], border);
            let mut one = vec![u16::NONE; w * h];
            let mut rows: Vec<&mut [u16]> = one.chunks_exact_mut(w).collect();
            column_strip(&mut rows, 0, w, &|i: usize| feat[i], border);
            assert!(split == one, "border {border}");
            assert_eq!(
                distance_bound(&split, w, border),
                rows_bound(&one, w, border)
            );
        }
    }

    fn compact_values(dt: &CompactDt) -> Vec<u32> {
        let mut v = Vec::with_capacity(dt.len());
        dt.for_each(|i, d| {
            assert_eq!(i, v.len());
            assert_eq!(d, dt.get(i));
            v.push(d);
        });
        v
    }

    #[test]
    fn compact_matches_plain_and_picks_its_width() {
        let mut seed = 777u64;
        for trial in 0..30 {
            let w = 1 + trial % 13;
            let h = 1 + (trial * 5) % 17;
            let feat: Vec<bool> = (0..w * h)
                .map(|_| {
                    seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
                    (seed >> 33).is_multiple_of(5)
                })
                .collect();
            for border in [false, true] {
                let dt = squared_edt_compact(w, h, |i| feat[i], border);
                let values = compact_values(&dt);
                assert_eq!(values, brute(w, h, &feat, border));
                for a in 0..values.len() {
                    for b in a + 1..=values.len() {
                        let m = *values[a..b].iter().max().unwrap();
                        let k = a + values[a..b].iter().position(|&d| d == m).unwrap();
                        assert_eq!(dt.first_max(a..b), (m, k));
                    }
                }
                // Without the border a featureless column may leave pixels at INF: those
                // need the wide form unless some feature bounds every pixel.
                if border {
                    assert_eq!(dt.bytes_per_pixel(), 2, "w={w} h={h}");
                }
            }
        }
        // An empty room 600 px wide: the middle is 300 px from the border, 300^2 > u16.
        let (w, h) = (600, 601);
        let dt = squared_edt_compact(w, h, |_| false, true);
        assert_eq!(dt.bytes_per_pixel(), 4);
        assert_eq!(compact_values(&dt), squared_edt(w, h, |_| false, true));
        assert_eq!(dt.get(300 * w + 299), 300 * 300);
        // 250 px from the border at most: fits.
        let (w, h) = (499, 499);
        let dt = squared_edt_compact(w, h, |_| false, true);
        assert_eq!(dt.bytes_per_pixel(), 2);
        assert_eq!(compact_values(&dt), squared_edt(w, h, |_| false, true));
        // No feature at all: INF everywhere, kept exactly.
        let dt = squared_edt_compact(7, 3, |_| false, false);
        assert!(compact_values(&dt).iter().all(|&d| d == INF));
        // Taller than u16 column distances allow: the wide column pass.
        let (w, h) = (2, 70_000);
        let dt = squared_edt_compact(w, h, |i| i == 2 * 35_000, false);
        assert_eq!(dt.get(0), 35_000 * 35_000);
        assert_eq!(
            compact_values(&dt),
            squared_edt(w, h, |i| i == 2 * 35_000, false)
        );
    }
}
