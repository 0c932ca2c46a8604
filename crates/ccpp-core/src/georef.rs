//! An affine world <-> pixel transform fitted by least squares from point pairs (seed 003).
//!
//! Seed 003 (a vacuum-robot BSA with BFS return) reads its map as an image and relates image
//! pixels to world coordinates by an affine transform fitted with `numpy.linalg.lstsq` on
//! measured point pairs, and inverts it (as a 3x3 matrix) for the other direction. Here the fit
//! is from **pixel to world** (`world = A * pixel + b`, six parameters), solved by the normal
//! equations on centred coordinates, with the residuals reported; [`Affine::inverse`] gives the
//! world-to-pixel map.
//!
//! For maps that come with a `map_server` YAML, [`crate::grid::MapFrame`] already is the one
//! pixel <-> world helper; this fit is for images whose placement is known only through
//! surveyed points (`--georef FILE`, parsed by `ccpp_io::georef`).
//!
//! ```
//! use ccpp_core::georef::fit_affine;
//! use ccpp_core::Point;
//! // 0.05 m/px, image row 0 on top of a 100-row image, origin (-1, 2).
//! let to_world = |c: f64, r: f64| Point::new(-1.0 + 0.05 * c, 2.0 + 0.05 * (100.0 - r));
//! let pairs: Vec<(Point, Point)> = [(0.0, 0.0), (50.0, 10.0), (20.0, 90.0), (99.0, 99.0)]
//!     .iter()
//!     .map(|&(c, r)| (Point::new(c, r), to_world(c, r)))
//!     .collect();
//! let fit = fit_affine(&pairs).unwrap();
//! assert!(fit.rms_residual < 1e-9);
//! let w = fit.affine.apply(Point::new(10.0, 40.0));
//! assert!(w.dist(to_world(10.0, 40.0)) < 1e-9);
//! let px = fit.affine.inverse().unwrap().apply(w);
//! assert!(px.dist(Point::new(10.0, 40.0)) < 1e-9);
//! ```

use serde::{Deserialize, Serialize};

use crate::geometry::Point;

/// An affine map `q = [[a, b], [c, d]] p + [tx, ty]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Affine {
    /// Row-major 2x2 linear part `[a, b, c, d]`.
    pub m: [f64; 4],
    /// Translation `[tx, ty]`.
    pub t: [f64; 2],
}

impl Affine {
    /// The identity.
    pub const IDENTITY: Affine = Affine {
        m: [1.0, 0.0, 0.0, 1.0],
        t: [0.0, 0.0],
    };

    /// Applies the map.
    pub fn apply(&self, p: Point) -> Point {
        let [a, b, c, d] = self.m;
        Point::new(a * p.x + b * p.y + self.t[0], c * p.x + d * p.y + self.t[1])
    }

    /// Determinant of the linear part.
    pub fn det(&self) -> f64 {
        self.m[0] * self.m[3] - self.m[1] * self.m[2]
    }

    /// The inverse map.
    ///
    /// # Errors
    /// [`GeorefError::Singular`] when the linear part is (numerically) singular.
    pub fn inverse(&self) -> Result<Affine, GeorefError> {
        let det = self.det();
        let scale = self.m.iter().map(|v| v.abs()).fold(0.0, f64::max);
        if !det.is_finite() || det.abs() <= 1e-12 * scale * scale {
            return Err(GeorefError::Singular);
        }
        let [a, b, c, d] = self.m;
        let m = [d / det, -b / det, -c / det, a / det];
        let t = [
            -(m[0] * self.t[0] + m[1] * self.t[1]),
            -(m[2] * self.t[0] + m[3] * self.t[1]),
        ];
        Ok(Affine { m, t })
    }
}

/// A least-squares fit and its residuals.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AffineFit {
    /// Pixel -> world map.
    pub affine: Affine,
    /// `|affine(pixel_i) - world_i|` for each pair, in world units.
    pub residuals: Vec<f64>,
    /// Root mean square of the residuals.
    pub rms_residual: f64,
    /// Largest residual.
    pub max_residual: f64,
    /// The pairs fitted, `(pixel, world)`, in the order of [`residuals`](Self::residuals).
    pub pairs: Vec<(Point, Point)>,
}

/// Errors of [`fit_affine`].
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum GeorefError {
    /// Fewer than three pairs.
    #[error("an affine fit needs at least 3 point pairs, got {0}")]
    TooFewPairs(usize),
    /// A coordinate is NaN or infinite.
    #[error("point pair {0} has a non-finite coordinate")]
    NonFinite(usize),
    /// The pixel points are (nearly) collinear: the fit is not determined.
    #[error("the pixel points are collinear: an affine fit needs 3 points not on one line")]
    Collinear,
    /// One pair's pixel point lies so far from the others (well spread on their own) that the
    /// spread of all looks like a line (0-based index): the fit would rest on that point.
    #[error(
        "point pair {} (pixel {}, {}) lies so far from the others that they look collinear beside it: the fit is ill-conditioned; check that pair",
        .index + 1, crate::display::Compact(*.x), crate::display::Compact(*.y)
    )]
    Outlier {
        /// Index of the pair.
        index: usize,
        /// Its pixel x.
        x: f64,
        /// Its pixel y.
        y: f64,
    },
    /// The fitted linear part is singular (cannot invert).
    #[error("the affine transform is singular and has no inverse")]
    Singular,
    /// The coordinates are so large that the fit overflows (found by fuzzing: a pixel
    /// coordinate of 1e177 squared is infinite and the fit came out NaN).
    #[error("the point coordinates are too large for a fit (the sums overflow)")]
    Overflow,
}

/// Whether the pixel points of `pairs` are well spread in both directions: the determinant of
/// their centred scatter matrix is not negligible against its spread squared.
fn well_spread(pixels: impl Iterator<Item = Point> + Clone) -> bool {
    let n = pixels.clone().count() as f64;
    let c = pixels
        .clone()
        .fold(Point::default(), |a, p| a + p)
        .scale(1.0 / n);
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for p in pixels {
        let d = p - c;
        sxx += d.x * d.x;
        sxy += d.x * d.y;
        syy += d.y * d.y;
    }
    conditioned(sxx, sxy, syy)
}

/// Whether a centred scatter matrix `[[sxx, sxy], [sxy, syy]]` of pixel points determines an
/// affine fit: its determinant is not negligible against its spread squared.
fn conditioned(sxx: f64, sxy: f64, syy: f64) -> bool {
    let spread = (sxx + syy).max(f64::MIN_POSITIVE);
    sxx * syy - sxy * sxy > 1e-12 * spread * spread
}

/// For a fit [`fit_affine`] found ill-conditioned: the one pair whose pixel point lies far
/// from the others when the others alone are well spread (an outlier swamps the spread, so
/// the points looked collinear); `None` when no single point explains it.
fn far_point(pairs: &[(Point, Point)]) -> Option<GeorefError> {
    if pairs.len() < 4 {
        return None;
    }
    let n = pairs.len() as f64;
    let c = pairs
        .iter()
        .fold(Point::default(), |a, (p, _)| a + *p)
        .scale(1.0 / n);
    let (index, _) = pairs
        .iter()
        .enumerate()
        .map(|(i, (p, _))| (i, p.dist(c)))
        .fold((0, f64::NEG_INFINITY), |b, x| if x.1 > b.1 { x } else { b });
    let others = pairs
        .iter()
        .enumerate()
        .filter(move |(i, _)| *i != index)
        .map(|(_, (p, _))| *p);
    well_spread(others).then(|| GeorefError::Outlier {
        index,
        x: pairs[index].0.x,
        y: pairs[index].0.y,
    })
}

/// Fits `world = A pixel + b` to `pairs` of `(pixel, world)` points by least squares.
///
/// # Errors
/// Fewer than 3 pairs, non-finite input, or collinear pixel points.
pub fn fit_affine(pairs: &[(Point, Point)]) -> Result<AffineFit, GeorefError> {
    if pairs.len() < 3 {
        return Err(GeorefError::TooFewPairs(pairs.len()));
    }
    if let Some(i) = pairs
        .iter()
        .position(|(p, w)| !(p.is_finite() && w.is_finite()))
    {
        return Err(GeorefError::NonFinite(i));
    }
    let n = pairs.len() as f64;
    let (mut pc, mut wc) = (Point::default(), Point::default());
    for (p, w) in pairs {
        pc = pc + *p;
        wc = wc + *w;
    }
    pc = pc.scale(1.0 / n);
    wc = wc.scale(1.0 / n);
    // Normal equations on centred coordinates: S = sum dp dp^T, R = sum dw dp^T, A = R S^-1.
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    let (mut rxx, mut rxy, mut ryx, mut ryy) = (0.0, 0.0, 0.0, 0.0);
    for (p, w) in pairs {
        let dp = *p - pc;
        let dw = *w - wc;
        sxx += dp.x * dp.x;
        sxy += dp.x * dp.y;
        syy += dp.y * dp.y;
        rxx += dw.x * dp.x;
        rxy += dw.x * dp.y;
        ryx += dw.y * dp.x;
        ryy += dw.y * dp.y;
    }
    let det = sxx * syy - sxy * sxy;
    if ![det, sxx, syy, rxx, rxy, ryx, ryy]
        .iter()
        .all(|v| v.is_finite())
    {
        return Err(GeorefError::Overflow);
    }
    if !conditioned(sxx, sxy, syy) {
        return Err(far_point(pairs).unwrap_or(GeorefError::Collinear));
    }
    let (i00, i01, i11) = (syy / det, -sxy / det, sxx / det);
    let m = [
        rxx * i00 + rxy * i01,
        rxx * i01 + rxy * i11,
        ryx * i00 + ryy * i01,
        ryx * i01 + ryy * i11,
    ];
    let t = [
        wc.x - (m[0] * pc.x + m[1] * pc.y),
        wc.y - (m[2] * pc.x + m[3] * pc.y),
    ];
    if !m.iter().chain(&t).all(|v| v.is_finite()) {
        return Err(GeorefError::Overflow);
    }
    let affine = Affine { m, t };
    let residuals: Vec<f64> = pairs
        .iter()
        .map(|(p, w)| affine.apply(*p).dist(*w))
        .collect();
    let rms_residual = (residuals.iter().map(|r| r * r).sum::<f64>() / n).sqrt();
    let max_residual = residuals.iter().copied().fold(0.0, f64::max);
    Ok(AffineFit {
        affine,
        residuals,
        rms_residual,
        max_residual,
        pairs: pairs.to_vec(),
    })
}

/// The map frame that best fits point pairs of an image (pixel coordinates from the image's
/// top-left corner, y down): `world = res * R(yaw) * (px, -py) + t`, a rotation and a uniform
/// scale as every ccpp map frame is (the y flip is the image's), fitted by least squares
/// (the orthogonal Procrustes solution on centred coordinates).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SimilarityFit {
    /// Metres per pixel.
    pub res: f64,
    /// Rotation of the image's x axis from the world's, radians.
    pub yaw: f64,
    /// World position of pixel coordinates `(0, 0)` (the image's top-left corner).
    pub t: Point,
    /// `|fit(pixel_i) - world_i|` for each pair, in world units.
    pub residuals: Vec<f64>,
}

impl SimilarityFit {
    /// The world position of pixel coordinates `p` (y down).
    pub fn apply(&self, p: Point) -> Point {
        let (s, c) = self.yaw.sin_cos();
        let (x, y) = (p.x, -p.y);
        Point::new(
            self.res * (c * x - s * y) + self.t.x,
            self.res * (s * x + c * y) + self.t.y,
        )
    }
}

impl AffineFit {
    /// The [`SimilarityFit`] of the same pairs (image pixel coordinates, y down): checked
    /// already (count, finite, spread) by the affine fit that made `self`.
    ///
    /// # Errors
    /// [`GeorefError::Singular`] for a degenerate fit (all world points at one place).
    pub fn image_similarity(&self) -> Result<SimilarityFit, GeorefError> {
        similarity_of(&self.pairs)
    }
}

/// The least-squares [`SimilarityFit`] of checked `pairs`.
fn similarity_of(pairs: &[(Point, Point)]) -> Result<SimilarityFit, GeorefError> {
    let n = pairs.len() as f64;
    let flip = |p: Point| Point::new(p.x, -p.y);
    let (mut qc, mut wc) = (Point::default(), Point::default());
    for (p, w) in pairs {
        qc = qc + flip(*p);
        wc = wc + *w;
    }
    qc = qc.scale(1.0 / n);
    wc = wc.scale(1.0 / n);
    // Centred: maximise sum <R dq, dw> over rotations; scale = that sum over sum |dq|^2.
    let (mut dot, mut cross, mut qq) = (0.0, 0.0, 0.0);
    for (p, w) in pairs {
        let dq = flip(*p) - qc;
        let dw = *w - wc;
        dot += dq.x * dw.x + dq.y * dw.y;
        cross += dq.x * dw.y - dq.y * dw.x;
        qq += dq.x * dq.x + dq.y * dq.y;
    }
    let yaw = cross.atan2(dot);
    let res = dot.hypot(cross) / qq;
    if !(res.is_finite() && res > 0.0 && yaw.is_finite()) {
        return Err(GeorefError::Singular);
    }
    let (s, c) = yaw.sin_cos();
    let t = Point::new(
        wc.x - res * (c * qc.x - s * qc.y),
        wc.y - res * (s * qc.x + c * qc.y),
    );
    let mut fit = SimilarityFit {
        res,
        yaw,
        t,
        residuals: Vec::new(),
    };
    fit.residuals = pairs.iter().map(|(p, w)| fit.apply(*p).dist(*w)).collect();
    Ok(fit)
}

/// How much more the linear part `m` (row-major) stretches one direction than another, as a
/// fraction (`sigma_max / sigma_min - 1`: 0.014 for axes scaled 1.4 % apart; shear counts
/// too); infinite for a singular `m`.
pub fn anisotropy(m: [f64; 4]) -> f64 {
    let [a, b, c, d] = m;
    let f2 = a * a + b * b + c * c + d * d;
    let det = (a * d - b * c).abs();
    let root = (f2 * f2 - 4.0 * det * det).max(0.0).sqrt();
    let (s1, s2) = (f64::midpoint(f2, root).sqrt(), ((f2 - root) / 2.0).sqrt());
    if s2 > 0.0 {
        s1 / s2 - 1.0
    } else {
        f64::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    #[test]
    fn the_similarity_fit_recovers_a_map_frame() {
        // 0.05 m/px, turned 0.3 rad, top-left corner at (4, -2).
        let truth = SimilarityFit {
            res: 0.05,
            yaw: 0.3,
            t: Point::new(4.0, -2.0),
            residuals: Vec::new(),
        };
        let pairs: Vec<(Point, Point)> = [(0.0, 0.0), (300.0, 10.0), (20.0, 200.0), (150.0, 90.0)]
            .iter()
            .map(|&(c, r)| (Point::new(c, r), truth.apply(Point::new(c, r))))
            .collect();
        let fit = fit_affine(&pairs)
            .and_then(|a| a.image_similarity())
            .unwrap_or_else(|e| panic!("{e}"));
        assert!((fit.res - 0.05).abs() < 1e-12);
        assert!((fit.yaw - 0.3).abs() < 1e-12);
        assert!(fit.t.dist(Point::new(4.0, -2.0)) < 1e-9);
        assert!(fit.residuals.iter().all(|r| *r < 1e-9));
        // y grows downwards: pixel (0, 100) lies 5 m "below" the corner before turning
        let p = truth.apply(Point::new(0.0, 100.0));
        assert!(
            p.dist(Point::new(
                4.0 + 5.0 * 0.3f64.sin(),
                -2.0 - 5.0 * 0.3f64.cos()
            )) < 1e-9
        );
    }

    #[test]
    fn anisotropy_is_the_axis_ratio() {
        assert!((anisotropy([0.05, 0.0, 0.0, -0.0507]) - 0.014).abs() < 1e-12);
        assert!(anisotropy([2.0, 0.0, 0.0, 2.0]).abs() < 1e-12);
        // a rotation changes nothing
        let (s, c) = 0.7f64.sin_cos();
        let m = [c * 1.0, -s * 1.02, s * 1.0, c * 1.02];
        assert!((anisotropy(m) - 0.02).abs() < 1e-12);
        assert!(anisotropy([1.0, 1.0, 1.0, 1.0]).is_infinite());
    }

    #[test]
    fn huge_coordinates_are_refused_not_fitted_to_nan() {
        let pairs = [
            (Point::new(0.0, 1.1e177), Point::new(1.0, 0.0)),
            (Point::new(0.0, 0.0), Point::new(1.0, 0.0)),
            (Point::new(10.0, 0.0), Point::new(-1.7, 0.0)),
        ];
        assert_eq!(fit_affine(&pairs).err(), Some(GeorefError::Overflow));
    }

    #[test]
    fn exact_fit_and_inverse() {
        let truth = Affine {
            m: [0.05 * 0.8, -0.05 * 0.6, -0.05 * 0.6, -0.05 * 0.8],
            t: [3.0, -7.0],
        };
        let pairs: Vec<_> = [(0.0, 0.0), (100.0, 0.0), (0.0, 50.0), (70.0, 30.0)]
            .iter()
            .map(|&(x, y)| {
                let p = Point::new(x, y);
                (p, truth.apply(p))
            })
            .collect();
        let fit = fit_affine(&pairs).unwrap();
        for k in 0..4 {
            assert!((fit.affine.m[k] - truth.m[k]).abs() < 1e-12);
        }
        assert!(fit.max_residual < 1e-9);
        let inv = fit.affine.inverse().unwrap();
        let p = Point::new(12.5, -3.0);
        assert!(inv.apply(fit.affine.apply(p)).dist(p) < 1e-9);
    }

    #[test]
    fn noisy_fit_reports_residuals() {
        let truth = Affine {
            m: [0.05, 0.0, 0.0, -0.05],
            t: [1.0, 10.0],
        };
        let mut rng = SplitMix64::new(3);
        let pairs: Vec<_> = (0..40)
            .map(|_| {
                let p = Point::new(rng.range(0.0, 200.0), rng.range(0.0, 200.0));
                let w = truth.apply(p);
                (
                    p,
                    Point::new(w.x + 0.01 * rng.gaussian(), w.y + 0.01 * rng.gaussian()),
                )
            })
            .collect();
        let fit = fit_affine(&pairs).unwrap();
        assert!(
            fit.rms_residual > 0.003 && fit.rms_residual < 0.03,
            "{}",
            fit.rms_residual
        );
        assert!((fit.affine.m[0] - 0.05).abs() < 1e-3);
        assert_eq!(fit.residuals.len(), 40);
    }

    #[test]
    fn degenerate_inputs() {
        let p = |x, y| (Point::new(x, y), Point::new(x, y));
        assert_eq!(
            fit_affine(&[p(0.0, 0.0), p(1.0, 1.0)]),
            Err(GeorefError::TooFewPairs(2))
        );
        assert_eq!(
            fit_affine(&[p(0.0, 0.0), p(1.0, 1.0), p(2.0, 2.0), p(5.0, 5.0)]),
            Err(GeorefError::Collinear)
        );
        assert_eq!(
            fit_affine(&[p(0.0, 0.0), p(1.0, f64::NAN), p(2.0, 2.0)]),
            Err(GeorefError::NonFinite(1))
        );
        // Three good points and one a billion pixels out: the others are well spread, so the
        // far one is named (it was reported as "the pixel points are collinear").
        let far = fit_affine(&[p(0.0, 0.0), p(60.0, 0.0), p(0.0, 40.0), p(1e9, 1e9)]);
        assert_eq!(
            far,
            Err(GeorefError::Outlier {
                index: 3,
                x: 1e9,
                y: 1e9
            })
        );
        assert!(far
            .unwrap_err()
            .to_string()
            .contains("point pair 4 (pixel 1e9, 1e9)"));
        // Collinear points with a far one on the same line stay collinear.
        assert_eq!(
            fit_affine(&[p(0.0, 0.0), p(1.0, 1.0), p(2.0, 2.0), p(1e9, 1e9)]),
            Err(GeorefError::Collinear)
        );
        let flat = Affine {
            m: [1.0, 2.0, 2.0, 4.0],
            t: [0.0, 0.0],
        };
        assert_eq!(flat.inverse(), Err(GeorefError::Singular));
    }
}
