//! Work zones: an **area** the robot must stay inside and **keep-out** regions it must never
//! enter, as polygons in map (world) coordinates and as pixel masks on the map grid.
//!
//! Semantics (one definition for every planner, the simulator and the metrics):
//!
//! * Zones are **virtual walls** the robot knows from the start. A [`crate::world::World`] built
//!   with zones plans on the true map with every pixel outside the area and every keep-out
//!   pixel marked occupied ([`crate::world::World::map`]); collisions are still checked against
//!   the true map ([`crate::world::World::true_map`]): a virtual wall does not stop a robot, it
//!   is only a rule, and entering a keep-out is counted by the metrics
//!   (`keepout_violations`), not prevented by the simulator.
//! * **Rasterisation** (the pixel-centre rule): a pixel belongs to a polygon when its centre
//!   lies inside the polygon by the even-odd rule, evaluated on each image row at the row's
//!   centre line; a centre exactly on a left edge is inside, exactly on a right edge outside
//!   (half-open spans), so two polygons sharing an edge never both claim a pixel column of it
//!   and the result depends on nothing but the coordinates. Several polygons are united.
//! * The **area** holds the pixel-centre pixels less those its border cuts whose square
//!   reaches out of it ([`rasterize_area`]): a robot that keeps off the pixels outside keeps
//!   its disk inside the area (to within a pixel only at a reflex vertex inside a square).
//! * A **keep-out polygon** holds every pixel whose square its inside overlaps: the pixel-centre
//!   pixels and every pixel an edge passes through ([`rasterize_keepout`]), so the pixels cover
//!   the polygon and a robot that keeps off them keeps off the polygon, however thin or
//!   slanted it is drawn.
//! * A **keep-out mask** (a Nav2 keepout filter mask, loaded by `ccpp-io`) is given directly as
//!   pixels; it is united with the keep-out polygons.

use crate::display::Compact;
use fixedbitset::FixedBitSet;
use serde::{Deserialize, Serialize};

use crate::geometry::{cross, Point};
use crate::grid::{Cell, MapFrame};

/// A simple polygon in map coordinates (metres): its vertices in order, either orientation;
/// closing the ring (repeating the first vertex at the end) is optional.
///
/// Serialized as its vertex list alone: the name is what a zone file called it (a `GeoJSON`
/// feature's `properties.name`), carried to the exports; a run's record names the file, which
/// gives the names again.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Polygon {
    /// Vertices `[x, y]`.
    pub points: Vec<[f64; 2]>,
    /// The zone's name in its file, if it has one (not serialized).
    #[serde(skip)]
    pub name: Option<String>,
}

/// Errors of zone polygons and masks.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ZoneError {
    /// No polygon at all.
    #[error("holds no polygon")]
    NoPolygon,
    /// A polygon with fewer than three distinct vertices.
    #[error("polygon {index} has {distinct} distinct points; a polygon needs at least 3")]
    TooFewPoints {
        /// Polygon index (0-based).
        index: usize,
        /// Distinct vertices found.
        distinct: usize,
    },
    /// A coordinate that is NaN or infinite.
    #[error("polygon {index} has a non-finite coordinate at point {point}")]
    NonFinite {
        /// Polygon index (0-based).
        index: usize,
        /// Vertex index (0-based).
        point: usize,
    },
    /// Two edges that cross or touch away from their shared vertex.
    #[error(
        "polygon {index} intersects itself: edge {a} ({:.3},{:.3})-({:.3},{:.3}) meets edge {b}",
        Compact(*.ax),
        Compact(*.ay),
        Compact(*.bx),
        Compact(*.by)
    )]
    SelfIntersecting {
        /// Polygon index (0-based).
        index: usize,
        /// First edge (0-based; edge `k` runs from vertex `k` to `k + 1`).
        a: usize,
        /// Second edge.
        b: usize,
        /// Start of edge `a`.
        ax: f64,
        /// Start of edge `a`.
        ay: f64,
        /// End of edge `a`.
        bx: f64,
        /// End of edge `a`.
        by: f64,
    },
    /// All vertices on one line.
    #[error("polygon {index} has zero area (all its points lie on one line)")]
    ZeroArea {
        /// Polygon index (0-based).
        index: usize,
    },
    /// Coordinates so large that the polygon's area is not a finite number.
    #[error("polygon {index} has coordinates too large to compute with (its area overflows)")]
    Overflow {
        /// Polygon index (0-based).
        index: usize,
    },
    /// More vertices than the self-intersection check accepts.
    #[error("polygon {index} has {points} vertices; at most {max} are accepted")]
    TooManyPoints {
        /// Polygon index (0-based).
        index: usize,
        /// Vertices given.
        points: usize,
        /// The limit.
        max: usize,
    },
}

/// Most vertices one polygon may have (the self-intersection check is quadratic).
pub const MAX_POLYGON_POINTS: usize = 4096;

impl Polygon {
    /// The axis-aligned rectangle `[x0, y0, x1, y1]`.
    pub fn rect(r: [f64; 4]) -> Self {
        let [x0, y0, x1, y1] = r;
        Self {
            points: vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]],
            name: None,
        }
    }

    /// The vertices without consecutive duplicates and without the closing repeat.
    pub fn ring(&self) -> Vec<Point> {
        let mut out: Vec<Point> = Vec::with_capacity(self.points.len());
        for p in &self.points {
            let q = Point::new(p[0], p[1]);
            if out.last() != Some(&q) {
                out.push(q);
            }
        }
        while out.len() > 1 && out.first() == out.last() {
            out.pop();
        }
        out
    }

    /// How many vertices the polygon is given with: its points, less a closing repeat of the
    /// first (`GeoJSON` requires one; it is not a vertex of its own). What
    /// [`MAX_POLYGON_POINTS`] bounds, and what a zone file's total counts.
    pub fn vertex_count(&self) -> usize {
        let n = self.points.len();
        n - usize::from(n > 1 && self.points.first() == self.points.last())
    }

    /// Signed area (positive counter-clockwise), square metres. The shoelace sum is taken
    /// about the first vertex: about the frame's origin, a 5 cm square at a survey northing
    /// (5.5e6 m) lost its area to rounding and was refused as "zero area", and the ring
    /// orientation exported to `GeoJSON` came out at random (hostile pass).
    pub fn signed_area(&self) -> f64 {
        let r = self.ring();
        shoelace(&r, r.first().copied().unwrap_or(Point::new(0.0, 0.0)))
    }

    /// Checks the polygon (`index` names it in errors): finite coordinates, at least three
    /// distinct vertices, non-zero area, no two edges meeting except consecutive ones at their
    /// shared vertex.
    ///
    /// # Errors
    /// The first problem found.
    pub fn validate(&self, index: usize) -> Result<(), ZoneError> {
        if let Some(k) = self
            .points
            .iter()
            .position(|p| !(p[0].is_finite() && p[1].is_finite()))
        {
            return Err(ZoneError::NonFinite { index, point: k });
        }
        // The closing repeat of a ring (GeoJSON requires it) is not a vertex of its own: a
        // closed ring of 4096 vertices was refused as 4097 points.
        let vertices = self.vertex_count();
        if vertices > MAX_POLYGON_POINTS {
            return Err(ZoneError::TooManyPoints {
                index,
                points: vertices,
                max: MAX_POLYGON_POINTS,
            });
        }
        let r = self.ring();
        let about_first = r.first().copied().unwrap_or(Point::new(0.0, 0.0));
        if !(shoelace(&r, Point::new(0.0, 0.0)).is_finite()
            && shoelace(&r, about_first).is_finite())
        {
            // Products of coordinates overflow: every geometric test below would be noise.
            return Err(ZoneError::Overflow { index });
        }
        let area = shoelace(&r, about_first);
        let mut distinct: Vec<(u64, u64)> =
            r.iter().map(|p| (p.x.to_bits(), p.y.to_bits())).collect();
        distinct.sort_unstable();
        distinct.dedup();
        if distinct.len() < 3 {
            return Err(ZoneError::TooFewPoints {
                index,
                distinct: distinct.len(),
            });
        }
        // All on one line: that is the problem to name (its edges fold back onto each other,
        // which the test below called "intersects itself").
        if area.abs() <= f64::EPSILON * bbox_scale(&r) && on_one_line(&r) {
            return Err(ZoneError::ZeroArea { index });
        }
        let n = r.len();
        for i in 0..n {
            let (a, b) = (r[i], r[(i + 1) % n]);
            for j in i + 1..n {
                let adjacent = j == i + 1 || (i == 0 && j == n - 1);
                let (c, d) = (r[j], r[(j + 1) % n]);
                let meet = if adjacent {
                    // Consecutive edges share one vertex; they may not fold back onto each
                    // other (overlap beyond the shared vertex).
                    let shared = if j == i + 1 { b } else { a };
                    let (p, q) = if j == i + 1 { (a, d) } else { (b, c) };
                    folds_back(shared, p, q)
                } else {
                    segments_meet(a, b, c, d)
                };
                if meet {
                    return Err(ZoneError::SelfIntersecting {
                        index,
                        a: i,
                        b: j,
                        ax: a.x,
                        ay: a.y,
                        bx: b.x,
                        by: b.y,
                    });
                }
            }
        }
        if area.abs() <= f64::EPSILON * bbox_scale(&r) {
            return Err(ZoneError::ZeroArea { index });
        }
        Ok(())
    }
}

/// Whether every point of `r` lies on the line through its first point and the first point
/// distinct from it (to rounding: the cross products within a few ulps of the ring's scale).
fn on_one_line(r: &[Point]) -> bool {
    let Some(&a) = r.first() else { return true };
    let Some(&b) = r.iter().find(|p| p.x != a.x || p.y != a.y) else {
        return true;
    };
    let tol = 8.0 * f64::EPSILON * bbox_scale(r);
    r.iter()
        .all(|p| ((b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x)).abs() <= tol)
}

/// The signed area of the ring `r` by the shoelace formula about `o`.
fn shoelace(r: &[Point], o: Point) -> f64 {
    let n = r.len();
    (0..n)
        .map(|i| {
            let (a, b) = (r[i] - o, r[(i + 1) % n] - o);
            a.x * b.y - b.x * a.y
        })
        .sum::<f64>()
        / 2.0
}

fn bbox_scale(r: &[Point]) -> f64 {
    let (mut lo, mut hi) = (
        Point::new(f64::MAX, f64::MAX),
        Point::new(f64::MIN, f64::MIN),
    );
    for p in r {
        lo = Point::new(lo.x.min(p.x), lo.y.min(p.y));
        hi = Point::new(hi.x.max(p.x), hi.y.max(p.y));
    }
    (hi.x - lo.x) * (hi.y - lo.y)
}

fn on_segment(p: Point, a: Point, b: Point) -> bool {
    p.x >= a.x.min(b.x) && p.x <= a.x.max(b.x) && p.y >= a.y.min(b.y) && p.y <= a.y.max(b.y)
}

/// Do the closed segments `a-b` and `c-d` share a point?
fn segments_meet(a: Point, b: Point, c: Point, d: Point) -> bool {
    let d1 = cross(c, d, a);
    let d2 = cross(c, d, b);
    let d3 = cross(a, b, c);
    let d4 = cross(a, b, d);
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && on_segment(a, c, d))
        || (d2 == 0.0 && on_segment(b, c, d))
        || (d3 == 0.0 && on_segment(c, a, b))
        || (d4 == 0.0 && on_segment(d, a, b))
}

/// Two edges `shared-p` and `shared-q` meeting at `shared`: do they overlap (collinear and
/// pointing the same way)?
fn folds_back(shared: Point, p: Point, q: Point) -> bool {
    let u = Point::new(p.x - shared.x, p.y - shared.y);
    let v = Point::new(q.x - shared.x, q.y - shared.y);
    u.x * v.y - u.y * v.x == 0.0 && u.x * v.x + u.y * v.y > 0.0
}

/// Validates a list of polygons (at least one).
///
/// # Errors
/// [`ZoneError::NoPolygon`] for an empty list, else the first invalid polygon.
pub fn validate_polygons(polys: &[Polygon]) -> Result<(), ZoneError> {
    if polys.is_empty() {
        return Err(ZoneError::NoPolygon);
    }
    for (i, p) in polys.iter().enumerate() {
        p.validate(i)?;
    }
    Ok(())
}

/// Marks in `mask` (a `frame`-sized bitset) every pixel whose centre lies inside one of
/// `polys` (the pixel-centre rule of the module docs). Polygons should be validated first;
/// non-finite vertices are skipped.
pub fn rasterize_into(mask: &mut FixedBitSet, frame: &MapFrame, polys: &[Polygon]) {
    let (w, h) = (frame.width, frame.height);
    let mut xs: Vec<f64> = Vec::new();
    for poly in polys {
        let ring: Vec<Point> = poly
            .ring()
            .into_iter()
            .filter(|p| p.x.is_finite() && p.y.is_finite())
            .map(|p| frame.world_to_grid(p))
            .collect();
        let n = ring.len();
        if n < 3 {
            continue;
        }
        let (ymin, ymax) = ring.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
            (lo.min(p.y), hi.max(p.y))
        });
        // Rows whose centre line gy = h - row - 0.5 lies in [ymin, ymax].
        let row_lo = (h as f64 - ymax - 0.5).ceil().max(0.0);
        let row_hi = (h as f64 - ymin - 0.5).floor().min(h as f64 - 1.0);
        if row_lo > row_hi {
            continue;
        }
        for row in row_lo as usize..=row_hi as usize {
            let gy = h as f64 - row as f64 - 0.5;
            xs.clear();
            for i in 0..n {
                let (a, b) = (ring[i], ring[(i + 1) % n]);
                if (a.y <= gy) != (b.y <= gy) {
                    // The crossing from the lower end, whichever way the ring runs: an edge two
                    // polygons share (run one way by one, the other way by the other) then
                    // crosses at the same float for both, so a centre on it falls inside
                    // exactly one of them (each rounded it its own way: on a 45-degree edge
                    // through pixel centres, neither took them, a one-pixel wall across an
                    // area given as two polygons).
                    let (a, b) = if a.y < b.y { (a, b) } else { (b, a) };
                    let x = a.x + (gy - a.y) * (b.x - a.x) / (b.y - a.y);
                    // A crossing within a billionth of a pixel of a centre is at the centre:
                    // an edge one polygon splits with a vertex on it (a T-junction, as GIS
                    // snapping writes) is crossed from other ends by the two polygons, and
                    // their last bits differ.
                    let c = (x - 0.5).round() + 0.5;
                    xs.push(if (x - c).abs() <= 1e-9 { c } else { x });
                }
            }
            xs.sort_by(f64::total_cmp);
            for pair in xs.chunks_exact(2) {
                // Columns whose centre col + 0.5 lies in [x0, x1).
                let c0 = (pair[0] - 0.5).ceil().max(0.0);
                let c1 = ((pair[1] - 0.5).ceil() - 1.0).min(w as f64 - 1.0);
                if c0 > c1 {
                    continue;
                }
                let base = row * w;
                mask.insert_range(base + c0 as usize..base + c1 as usize + 1);
            }
        }
    }
}

/// The pixels whose centre lies inside one of `polys` (see [`rasterize_into`]).
pub fn rasterize(frame: &MapFrame, polys: &[Polygon]) -> FixedBitSet {
    let mut m = FixedBitSet::with_capacity(frame.len());
    rasterize_into(&mut m, frame, polys);
    m
}

/// The keep-out pixels of `polys`: every pixel whose square the inside of a polygon overlaps
/// (the module docs' keep-out rule), [`rasterize`]'s pixels and those that an edge passes
/// through. By the pixel-centre rule alone a thin keep-out (a virtual wall drawn as a strip a
/// fraction of a pixel wide, slanted) marked scattered pixels with gaps wider than the robot,
/// which then drove through the drawn polygon while its `keepout_violations`, counted on the
/// same pixels, stayed 0 (hostile pass).
pub fn rasterize_keepout(frame: &MapFrame, polys: &[Polygon]) -> FixedBitSet {
    let mut m = rasterize(frame, polys);
    for poly in polys {
        let ring = snapped_ring(frame, poly);
        if ring.len() < 3 {
            continue;
        }
        for i in 0..ring.len() {
            mark_edge_pixels(&mut m, frame, ring[i], ring[(i + 1) % ring.len()]);
        }
    }
    m
}

/// The ring of `poly` in grid coordinates, its finite vertices only, each snapped onto a grid
/// line it lies within rounding of (see [`rasterize_keepout`]).
fn snapped_ring(frame: &MapFrame, poly: &Polygon) -> Vec<Point> {
    poly.ring()
        .into_iter()
        .filter(|p| p.x.is_finite() && p.y.is_finite())
        .map(|p| {
            let g = frame.world_to_grid(p);
            // A vertex within a millionth of a pixel of a grid line (more where the
            // coordinates' own rounding is larger: far from the origin, on a fine grid)
            // is on it: an edge along a pixel border (a rectangle given in whole pixels, a
            // keep-out exported by ccpp and read back) passes through no pixel, instead of
            // through a whole row of them by rounding. (At a billionth, a mask exported to
            // `path.geojson`, whose coordinates have nine decimals, and read back on a map
            // at a UTM origin or with a yaw took in a strip of pixels more: 5.00 m2 became
            // 5.32; hostile pass.)
            let mag = [p.x, p.y, frame.origin.x, frame.origin.y]
                .into_iter()
                .fold(1.0f64, |m, v| m.max(v.abs()));
            let tol = 1e-6 + 8.0 * f64::EPSILON * mag / frame.resolution;
            let snap = |v: f64| {
                if (v - v.round()).abs() <= tol {
                    v.round()
                } else {
                    v
                }
            };
            Point::new(snap(g.x), snap(g.y))
        })
        .collect()
}

/// The area pixels of `polys`: [`rasterize`]'s (the pixel-centre rule) less those an edge
/// passes through whose square reaches out of the polygons' union (a corner outside every
/// polygon), so that a robot keeping off the pixels outside keeps inside the area also where
/// its border runs between pixel borders. By the pixel-centre rule alone a pixel half out of
/// the area was in it, and the robot's disk reached up to half a pixel past the border
/// (hostile pass, stop 70). An edge two abutting polygons share passes through squares
/// wholly inside their union, which stay. At a reflex vertex of the area that lies inside a
/// square whose corners are all inside, the disk may still reach past the border by less
/// than a pixel.
pub fn rasterize_area(frame: &MapFrame, polys: &[Polygon]) -> FixedBitSet {
    let mut m = rasterize(frame, polys);
    let rings: Vec<Vec<Point>> = polys
        .iter()
        .map(|p| snapped_ring(frame, p))
        .filter(|r| r.len() >= 3)
        .collect();
    let mut edge = FixedBitSet::with_capacity(frame.len());
    for ring in &rings {
        for i in 0..ring.len() {
            mark_edge_pixels(&mut edge, frame, ring[i], ring[(i + 1) % ring.len()]);
        }
    }
    let h = frame.height as f64;
    for i in edge.ones() {
        if !m.contains(i) {
            continue;
        }
        let (col, row) = (i % frame.width, i / frame.width);
        // The square in grid coordinates (y up): x in [col, col + 1], y in [h - 1 - row, h - row].
        let (x0, y0) = (col as f64, h - 1.0 - row as f64);
        let corners = [
            Point::new(x0, y0),
            Point::new(x0 + 1.0, y0),
            Point::new(x0, y0 + 1.0),
            Point::new(x0 + 1.0, y0 + 1.0),
        ];
        if !corners
            .iter()
            .all(|&c| rings.iter().any(|r| inside_or_on(r, c)))
        {
            m.set(i, false);
        }
    }
    m
}

/// Is `p` inside the ring `r` (even-odd) or on one of its edges (within a millionth of a
/// pixel)?
fn inside_or_on(r: &[Point], p: Point) -> bool {
    let n = r.len();
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (r[i], r[(i + 1) % n]);
        let (dx, dy) = (b.x - a.x, b.y - a.y);
        let len2 = dx * dx + dy * dy;
        if len2 > 0.0 {
            let t = (((p.x - a.x) * dx + (p.y - a.y) * dy) / len2).clamp(0.0, 1.0);
            let (qx, qy) = (a.x + t * dx - p.x, a.y + t * dy - p.y);
            if qx * qx + qy * qy <= 1e-12 {
                return true;
            }
        }
        if (a.y <= p.y) != (b.y <= p.y) {
            let x = a.x + (p.y - a.y) * dx / dy;
            if x > p.x {
                inside = !inside;
            }
        }
    }
    inside
}

/// Marks every pixel of `frame` whose open square the segment `a`-`b` (grid coordinates, y up)
/// passes through; a segment along pixel borders or through a corner only marks none there.
fn mark_edge_pixels(mask: &mut FixedBitSet, frame: &MapFrame, a: Point, b: Point) {
    let (w, h) = (frame.width as i64, frame.height as i64);
    // Marks the pixels of column `c` whose open y-range meets the open interval `(y0, y1)`,
    // or, for `y0 == y1`, holds `y0`.
    let mut mark_column = |c: i64, y0: f64, y1: f64| {
        if c < 0 || c >= w {
            return;
        }
        let (j0, j1) = if y0 < y1 {
            (y0.floor() as i64, y1.ceil() as i64 - 1)
        } else if y0.fract() != 0.0 {
            (y0.floor() as i64, y0.floor() as i64)
        } else {
            return;
        };
        for j in j0.max(0)..=j1.min(h - 1) {
            // Grid row j (y up) is image row h - 1 - j.
            mask.insert(((h - 1 - j) * w + c) as usize);
        }
    };
    let (lo, hi) = if a.x <= b.x { (a, b) } else { (b, a) };
    if lo.x == hi.x {
        if lo.x.fract() != 0.0 {
            mark_column(lo.x.floor() as i64, lo.y.min(hi.y), lo.y.max(hi.y));
        }
        return;
    }
    let y_at = |x: f64| lo.y + (x - lo.x) * (hi.y - lo.y) / (hi.x - lo.x);
    let c_first = (lo.x.floor() as i64).max(-1);
    let c_last = ((hi.x.ceil() as i64) - 1).min(w);
    for c in c_first..=c_last {
        let x0 = lo.x.max(c as f64);
        let x1 = hi.x.min(c as f64 + 1.0);
        if x0 >= x1 {
            continue;
        }
        let (ya, yb) = (y_at(x0), y_at(x1));
        mark_column(c, ya.min(yb), ya.max(yb));
    }
}

/// The zones of one run as pixel masks on the map grid.
#[derive(Clone, Debug, PartialEq)]
pub struct ZoneMasks {
    /// Pixels inside the work area; `None` = the whole map.
    pub area: Option<FixedBitSet>,
    /// Keep-out pixels (polygons and masks united).
    pub keepout: FixedBitSet,
    /// The area's polygons (for drawing its border), map coordinates.
    pub area_polygons: Vec<Polygon>,
    /// The keep-out polygons (for drawing), map coordinates; mask pixels are only in
    /// [`Self::keepout`].
    pub keepout_polygons: Vec<Polygon>,
}

impl ZoneMasks {
    /// Rasterises `area` polygons (`None` = no area restriction) and `keepout` polygons onto
    /// `frame`, plus the keep-out pixel `masks` (each `frame`-sized).
    pub fn new(
        frame: &MapFrame,
        area: Option<&[Polygon]>,
        keepout: &[Polygon],
        masks: &[FixedBitSet],
    ) -> Self {
        let mut k = rasterize_keepout(frame, keepout);
        for m in masks {
            k.union_with(m);
        }
        Self::with_keepout_pixels(frame, area, k, keepout.to_vec())
    }

    /// Rasterises `area` polygons (`None` = no area restriction) onto `frame`, with the
    /// keep-out pixels `keepout` already rasterised (`frame`-sized: the union of every keep-out
    /// polygon's and mask's pixels) and the keep-out polygons they came from (for pictures and
    /// exports).
    pub fn with_keepout_pixels(
        frame: &MapFrame,
        area: Option<&[Polygon]>,
        keepout: FixedBitSet,
        keepout_polygons: Vec<Polygon>,
    ) -> Self {
        Self {
            area: area.map(|a| rasterize_area(frame, a)),
            keepout,
            area_polygons: area.map(<[Polygon]>::to_vec).unwrap_or_default(),
            keepout_polygons,
        }
    }

    /// Is pixel `i` forbidden (outside the area or in a keep-out)?
    pub fn forbidden(&self, i: usize) -> bool {
        self.keepout.contains(i) || self.area.as_ref().is_some_and(|a| !a.contains(i))
    }

    /// Pixel `i`, `c` on the true map, as the planning map has it: a free pixel the zones
    /// forbid is a (virtual) wall.
    pub fn plan_cell(&self, i: usize, c: Cell) -> Cell {
        if c.is_free() && self.forbidden(i) {
            Cell::Occupied
        } else {
            c
        }
    }

    /// No area restriction and no keep-out pixel.
    pub fn is_empty(&self) -> bool {
        self.area.is_none() && self.keepout.is_clear()
    }
}

/// A pixel mask as an obstacle set for the exact disk tests of [`crate::collide`]: a pixel
/// blocks when its bit is set (or clear, with `invert`); pixels outside the image never block.
pub struct MaskOccupancy<'a> {
    frame: &'a MapFrame,
    bits: &'a FixedBitSet,
    invert: bool,
}

impl<'a> MaskOccupancy<'a> {
    /// The mask `bits` (`frame`-sized) as obstacles; `invert` makes the clear bits block.
    pub fn new(frame: &'a MapFrame, bits: &'a FixedBitSet, invert: bool) -> Self {
        Self {
            frame,
            bits,
            invert,
        }
    }
}

impl crate::collide::Occupancy for MaskOccupancy<'_> {
    fn frame(&self) -> &MapFrame {
        self.frame
    }
    #[inline]
    fn blocked(&self, col: i64, row: i64) -> bool {
        self.frame
            .checked(col, row)
            .is_some_and(|(c, r)| self.bits.contains(self.frame.index(c, r)) != self.invert)
    }
    fn for_each_blocked_in_row(
        &self,
        row: usize,
        lo: usize,
        hi: usize,
        f: &mut dyn FnMut(usize) -> bool,
    ) {
        let base = row * self.frame.width;
        let blocks = self.bits.as_slice();
        let inv = if self.invert { usize::MAX } else { 0 };
        crate::bits::for_each_set(
            base + lo,
            base + hi + 1,
            |k| blocks[k] ^ inv,
            |i| f(i - base),
        );
    }
}

/// Keep-out entries along a centre polyline (grid coordinates): a robot of radius `r_px`
/// pixels enters a keep-out when its disk, not overlapping any keep-out pixel (the obstacle
/// model of [`crate::collide`]: a pixel is the disk inscribed in its square), starts to overlap
/// one. Counted exactly along each segment (the times the disk overlaps each pixel,
/// [`crate::collide::contact_intervals`], joined: each stretch of overlap that begins after
/// the disk was clear is one entry), so a path counts the same entries driven in one long move
/// or in many short ones, whatever the size of the keep-outs and the gaps between them. A
/// start inside a keep-out counts as one entry.
pub fn keepout_entries(
    frame: &MapFrame,
    keepout: &FixedBitSet,
    points: &[Point],
    r_px: f64,
) -> u32 {
    if keepout.is_clear() {
        return 0;
    }
    entries(
        &MaskOccupancy::new(frame, keepout, false),
        points,
        r_px,
        true,
    )
}

/// Exits from the work area `area` along a centre polyline (grid coordinates), counted as
/// [`keepout_entries`] counts entries into the pixels outside the area (the area's border is
/// a virtual wall as a keep-out's is): a robot that drives out of the area, as a user of the
/// step API can, enters forbidden floor. A start outside the area is no exit (the approach
/// to the area begins there; give the points from the approach's end).
pub fn area_exits(frame: &MapFrame, area: &FixedBitSet, points: &[Point], r_px: f64) -> u32 {
    entries(&MaskOccupancy::new(frame, area, true), points, r_px, false)
}

/// Entries of the disk into `occ`'s blocked pixels along `points` (see [`keepout_entries`]);
/// a start overlapping one counts when `count_start`.
///
/// A segment whose capsule's bounding box meets no block of [`SUMMARY_BLOCK`] pixels holding
/// a blocked pixel is clear without the exact tests (a PID run's millions of small steps
/// inside an area are nearly all such: bsa-bfs on `tuw_freihaus_eg` with
/// `--area=-80,-30,50,60`, 2.4 M poses, spent 483 ms in its metrics without the summary and
/// 240 ms with it).
fn entries(occ: &MaskOccupancy<'_>, points: &[Point], r_px: f64, count_start: bool) -> u32 {
    if points.is_empty() {
        return 0;
    }
    let summary = BlockSummary::of(occ);
    let mut inside = crate::collide::disk_hits(occ, points[0], r_px);
    let mut n = u32::from(inside && count_start);
    let mut spans: Vec<(f64, f64)> = Vec::new();
    for w in points.windows(2) {
        if w[0] == w[1] {
            continue;
        }
        if !inside && summary.clear(occ.frame, w[0], w[1], r_px) {
            continue;
        }
        // The pixels near the move are found in stretches of at most a pixel (each search's
        // window stays small on a long diagonal move); each one's overlap is timed on the
        // whole move, so the stretches do not change what is counted.
        let len = w[0].dist(w[1]);
        let pieces = if len.is_finite() {
            (len.ceil() as usize).clamp(1, MAX_PIECES)
        } else {
            1
        };
        spans.clear();
        let mut from = w[0];
        for k in 1..=pieces {
            let to = if k == pieces {
                w[1]
            } else {
                let t = k as f64 / pieces as f64;
                Point::new(
                    w[0].x + (w[1].x - w[0].x) * t,
                    w[0].y + (w[1].y - w[0].y) * t,
                )
            };
            if !summary.clear(occ.frame, from, to, r_px) {
                crate::collide::contact_intervals(occ, w[0], w[1], (from, to), r_px, &mut spans);
            }
            from = to;
        }
        n += overlap_starts(&mut spans, inside);
        inside = crate::collide::disk_hits(occ, w[1], r_px);
    }
    n
}

/// The stretches of overlap that the intervals `spans` (of one move, in `[0, 1]`) join into
/// and that begin while the disk is clear: all of them but one that begins at 0 when the move
/// starts `inside` (intervals that meet or overlap are one stretch; sorts `spans`).
fn overlap_starts(spans: &mut [(f64, f64)], inside: bool) -> u32 {
    spans.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.total_cmp(&y.1)));
    let mut n = 0u32;
    let mut end: Option<f64> = None;
    for &(s, e) in spans.iter() {
        if end.is_none_or(|end| s > end) {
            if !(s <= 0.0 && inside) {
                n += 1;
            }
            end = Some(e);
        } else {
            end = end.map(|end| end.max(e));
        }
    }
    n
}

/// Most stretches one move is cut into by [`entries`] (a move across a 100 000-pixel map).
const MAX_PIECES: usize = 100_000;

/// Side of the blocks of [`BlockSummary`], pixels.
const SUMMARY_BLOCK: usize = 8;

/// Which blocks of [`SUMMARY_BLOCK`] x [`SUMMARY_BLOCK`] pixels hold a blocked pixel of a
/// mask.
struct BlockSummary {
    /// Blocks per block row.
    bw: usize,
    /// Block rows.
    bh: usize,
    /// Whether each block holds a blocked pixel.
    any: Vec<bool>,
}

impl BlockSummary {
    fn of(occ: &MaskOccupancy<'_>) -> Self {
        let f = occ.frame;
        if f.width == 0 || f.height == 0 {
            return Self {
                bw: 0,
                bh: 0,
                any: Vec::new(),
            };
        }
        let (bw, bh) = (
            f.width.div_ceil(SUMMARY_BLOCK),
            f.height.div_ceil(SUMMARY_BLOCK),
        );
        let mut any = vec![false; bw * bh];
        for row in 0..f.height {
            let base = (row / SUMMARY_BLOCK) * bw;
            crate::collide::Occupancy::for_each_blocked_in_row(
                occ,
                row,
                0,
                f.width - 1,
                &mut |c| {
                    any[base + c / SUMMARY_BLOCK] = true;
                    true
                },
            );
        }
        Self { bw, bh, any }
    }

    /// Whether the capsule of radius `r_px` around `a -> b` (grid coordinates) surely meets
    /// no blocked pixel: its bounding box, widened by a pixel, lies in the image and meets no
    /// block holding one. (A box reaching past the image is left to the exact tests, which
    /// take a disk far outside the image as in contact.)
    fn clear(&self, f: &MapFrame, a: Point, b: Point, r_px: f64) -> bool {
        if self.any.is_empty() {
            return true;
        }
        let m = r_px + 1.0;
        let lo = Point::new(a.x.min(b.x) - m, a.y.min(b.y) - m);
        let hi = Point::new(a.x.max(b.x) + m, a.y.max(b.y) + m);
        if !(lo.x.is_finite() && hi.x.is_finite() && lo.y.is_finite() && hi.y.is_finite()) {
            return false;
        }
        // Rows grow downwards: the box's top (`hi.y`) is its first row.
        let (c0, r0) = f.grid_to_pixel_signed(Point::new(lo.x, hi.y));
        let (c1, r1) = f.grid_to_pixel_signed(Point::new(hi.x, lo.y));
        if c0 < 0 || r0 < 0 || c1 >= f.width as i64 || r1 >= f.height as i64 {
            return false;
        }
        let block = |v: i64| v as usize / SUMMARY_BLOCK;
        let (bc0, bc1) = (block(c0), block(c1));
        let (br0, br1) = (block(r0), block(r1));
        debug_assert!(bc1 < self.bw && br1 < self.bh);
        (br0..=br1).all(|br| (bc0..=bc1).all(|bc| !self.any[br * self.bw + bc]))
    }
}

#[cfg(test)]
mod tests {

    /// A small polygon far from the origin keeps its area and orientation: the shoelace sum
    /// about the origin lost them to rounding (a 5 cm square at 5.5e6 m was refused as "zero
    /// area", a 0.3 m one at 8e7 m too, and exported rings came out clockwise: hostile pass).
    #[test]
    fn a_small_polygon_far_out_keeps_its_area_and_orientation() {
        for (o, side) in [
            (5.5e6, 0.05),
            (8e7, 0.3),
            (8e7, 0.8),
            (3e7, 0.1),
            (0.0, 0.05),
        ] {
            let p = Polygon {
                points: vec![
                    [o + 1.0, o + 1.0],
                    [o + 1.0 + side, o + 1.0],
                    [o + 1.0 + side, o + 1.0 + side],
                    [o + 1.0, o + 1.0 + side],
                ],
                name: None,
            };
            p.validate(0).unwrap();
            let a = p.signed_area();
            assert!(
                (a - side * side).abs() < 1e-6 * side * side + 1e-9,
                "{o} {side}: {a}"
            );
        }
    }

    use super::*;

    fn poly(p: &[[f64; 2]]) -> Polygon {
        Polygon {
            points: p.to_vec(),
            name: None,
        }
    }

    /// Points all on one line are named as that (zero area), not as edges that intersect
    /// (they fold back onto each other); a bow tie, whose signed area is zero too, still
    /// intersects itself.
    #[test]
    fn a_polygon_on_one_line_has_zero_area() {
        for line in [
            &[[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]][..],
            &[[0.0, 0.0], [2.0, 0.0], [1.0, 0.0], [3.0, 0.0]],
            &[[-1.0, -1.0], [0.0, -1.0], [1.0, -1.0]],
        ] {
            assert!(
                matches!(poly(line).validate(0), Err(ZoneError::ZeroArea { .. })),
                "{line:?}: {:?}",
                poly(line).validate(0)
            );
        }
        let bow = poly(&[[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]]);
        assert!(matches!(
            bow.validate(0),
            Err(ZoneError::SelfIntersecting { .. })
        ));
    }

    /// The vertex limit counts vertices: a closed ring repeats its first one at the end.
    #[test]
    fn the_vertex_limit_does_not_count_the_closing_repeat() {
        let circle = |n: usize, closed: bool| {
            let mut p: Vec<[f64; 2]> = (0..n)
                .map(|k| {
                    let a = std::f64::consts::TAU * k as f64 / n as f64;
                    [10.0 * a.cos(), 10.0 * a.sin()]
                })
                .collect();
            if closed {
                p.push(p[0]);
            }
            poly(&p)
        };
        assert!(circle(MAX_POLYGON_POINTS, true).validate(0).is_ok());
        assert!(circle(MAX_POLYGON_POINTS, false).validate(0).is_ok());
        let e = circle(MAX_POLYGON_POINTS + 1, true)
            .validate(0)
            .unwrap_err();
        assert!(e.to_string().contains("4097 vertices; at most 4096"), "{e}");
    }

    #[test]
    fn validation_catches_bad_polygons() {
        assert_eq!(validate_polygons(&[]), Err(ZoneError::NoPolygon));
        assert_eq!(
            validate_polygons(&[Polygon::rect([0.0, 0.0, 1e300, 1e300])]),
            Err(ZoneError::Overflow { index: 0 })
        );
        let e = poly(&[[0.0, 0.0], [1.0, 0.0], [0.0, 0.0]]).validate(0);
        assert!(matches!(
            e,
            Err(ZoneError::TooFewPoints { distinct: 2, .. })
        ));
        let e = poly(&[[0.0, 0.0], [1.0, f64::NAN], [0.0, 1.0]]).validate(3);
        assert_eq!(e, Err(ZoneError::NonFinite { index: 3, point: 1 }));
        // A bow tie.
        let e = poly(&[[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]]).validate(0);
        assert!(
            matches!(e, Err(ZoneError::SelfIntersecting { .. })),
            "{e:?}"
        );
        // A spike folding back on itself.
        let e = poly(&[[0.0, 0.0], [2.0, 0.0], [1.0, 0.0], [1.0, 1.0]]).validate(0);
        assert!(
            matches!(e, Err(ZoneError::SelfIntersecting { .. })),
            "{e:?}"
        );
        let e = poly(&[[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]).validate(0);
        assert!(e.is_err(), "{e:?}");
        // Closed ring and either orientation are fine.
        poly(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 0.0]])
            .validate(0)
            .unwrap();
        poly(&[[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]])
            .validate(0)
            .unwrap();
    }

    /// A keep-out drawn as a thin slanted strip (0.01 m wide at 0.05 m pixels, slope 1/10)
    /// holds every pixel it overlaps: a chain the robot cannot pass. By the pixel-centre rule
    /// it held a few scattered pixels, with gaps a robot drove through (hostile pass).
    /// A keep-out drawn along pixel borders holds exactly the pixels inside, also where the
    /// coordinates carry rounding: a rectangle in whole pixels at a UTM origin, and a block of
    /// pixels whose corners went out with nine decimals (as `path.geojson` writes them) on a
    /// yawed map. At a snap of a billionth of a pixel both took in a strip more (1.05 m2
    /// instead of 1.00; 5.32 instead of 5.00 on a round trip; hostile pass).
    #[test]
    fn a_keepout_along_pixel_borders_holds_the_pixels_inside_despite_rounding() {
        let mut utm = MapFrame::new(200, 200, 0.05);
        utm.origin = crate::Pose::new(600_000.0, 5_300_000.0, 0.0);
        let rect = poly(&[
            [600_001.05, 5_300_001.05],
            [600_002.05, 5_300_001.05],
            [600_002.05, 5_300_002.05],
            [600_001.05, 5_300_002.05],
        ]);
        assert_eq!(rasterize_keepout(&utm, &[rect]).count_ones(..), 400);
        let mut yawed = MapFrame::new(200, 200, 0.05);
        yawed.origin = crate::Pose::new(2.0, -1.0, 0.5);
        let nine = |v: f64| (v * 1e9).round() / 1e9;
        let corners: Vec<[f64; 2]> = [(30.0, 40.0), (90.0, 40.0), (90.0, 65.0), (30.0, 65.0)]
            .into_iter()
            .map(|(x, y)| {
                let w = yawed.grid_to_world(Point::new(x, y));
                [nine(w.x), nine(w.y)]
            })
            .collect();
        let block = poly(&corners);
        assert_eq!(rasterize_keepout(&yawed, &[block]).count_ones(..), 60 * 25);
    }

    #[test]
    fn a_thin_slanted_keepout_holds_every_pixel_it_overlaps() {
        let mut f = MapFrame::new(80, 160, 0.05);
        f.origin = crate::Pose::new(-1.0, -4.0, 0.0);
        let strip = poly(&[[1.0, -4.0], [1.01, -4.0], [1.61, 2.0], [1.6, 2.0]]);
        let centre = rasterize(&f, std::slice::from_ref(&strip));
        let k = rasterize_keepout(&f, std::slice::from_ref(&strip));
        // The strip crosses 120 rows of pixels; about one in five held a centre.
        assert!(centre.count_ones(..) <= 30, "{}", centre.count_ones(..));
        assert!(k.count_ones(..) >= 120, "{}", k.count_ones(..));
        assert!(k.is_superset(&centre));
        // Every point of the strip lies in a marked pixel (sampled densely, inside it).
        for i in 1..6000 {
            let t = f64::from(i) / 6000.0;
            for s in [0.001, 0.005, 0.009] {
                let p = Point::new(1.0 + s + 0.6 * t, -4.0 + 6.0 * t);
                let g = f.world_to_grid(p);
                let (c, r) = (g.x.floor() as usize, 159 - g.y.floor() as usize);
                if g.y < 160.0 {
                    assert!(k.contains(r * 80 + c), "{p:?} in pixel ({c}, {r})");
                }
            }
        }
        // Only those: each marked pixel's square meets the strip (no pixel away from it).
        for i in k.ones() {
            let (c, r) = ((i % 80) as f64, (i / 80) as f64);
            let y_lo = -4.0 + (159.0 - r) * 0.05;
            let x_at = |y: f64| 1.0 + 0.1 * (y + 4.0);
            let x_lo = -1.0 + c * 0.05;
            let near = (x_at(y_lo) - 0.01..x_at(y_lo + 0.05) + 0.02).contains(&x_lo)
                || (x_lo..x_lo + 0.05).contains(&x_at(y_lo));
            assert!(near, "pixel ({c}, {r}) away from the strip");
        }
    }

    /// A keep-out rectangle on pixel borders holds exactly the pixels inside it: its edges
    /// run along borders and pass through no pixel, whatever the rounding of its corners.
    #[test]
    fn a_keepout_on_pixel_borders_holds_only_its_inside() {
        let mut f = MapFrame::new(100, 100, 0.05);
        f.origin = crate::Pose::new(-2.5, -2.5, 0.0);
        for r in [
            [-1.0, -1.0, 1.0, 1.0],
            [-0.35, 0.1, 0.3, 1.95],
            [0.15, -2.05, 0.2, -0.7],
        ] {
            let rect = Polygon::rect(r);
            let k = rasterize_keepout(&f, std::slice::from_ref(&rect));
            assert_eq!(k, rasterize(&f, std::slice::from_ref(&rect)), "{r:?}");
            let px = ((r[2] - r[0]) / 0.05).round() * ((r[3] - r[1]) / 0.05).round();
            assert_eq!(k.count_ones(..) as f64, px, "{r:?}");
        }
    }

    /// An area given as two polygons that share a slanted edge is their union, whichever way
    /// each runs along the edge: a centre on it belongs to exactly one of them. (Each computed
    /// the crossing from its own first vertex: on the 45-degree edge (-1.8, -2.1)-(0.2, -0.1)
    /// of a `teb_empty_box` area neither took the centres on it, a wall across the area.)
    #[test]
    fn polygons_sharing_a_slanted_edge_tile_their_union() {
        let mut f = MapFrame::new(120, 120, 0.05);
        f.origin = crate::Pose::new(-3.0, -3.0, 0.0);
        let whole = rasterize(&f, &[Polygon::rect([-2.8, -2.1, 2.8, -0.1])]);
        let mut tried = 0;
        // Splits of the rectangle by the segment from (x0, -2.1) to (x1, -0.1), on the map's
        // 0.05 m grid (lines through pixel centres: 45 degrees and many others).
        for i0 in 0..40 {
            for i1 in (0..60).step_by(3) {
                let x0 = -1.8 + 0.05 * f64::from(i0);
                let x1 = -1.0 + 0.05 * f64::from(i1);
                let left = poly(&[[-2.8, -2.1], [x0, -2.1], [x1, -0.1], [-2.8, -0.1]]);
                // The right part runs the other way along the shared edge.
                let right = poly(&[[x0, -2.1], [2.8, -2.1], [2.8, -0.1], [x1, -0.1]]);
                let (a, b) = (
                    rasterize(&f, std::slice::from_ref(&left)),
                    rasterize(&f, std::slice::from_ref(&right)),
                );
                assert!(a.is_disjoint(&b), "split {x0} {x1}");
                assert_eq!(rasterize(&f, &[left, right]), whole, "split {x0} {x1}");
                tried += 1;
            }
        }
        assert_eq!(tried, 800);
        // The right part with a vertex in the middle of the shared edge (a T-junction): the
        // two cross the edge from different ends.
        for i0 in 0..40 {
            for i1 in (0..60).step_by(7) {
                let x0 = -1.8 + 0.05 * f64::from(i0);
                let x1 = -1.0 + 0.05 * f64::from(i1);
                let mid = [0.5 * (x0 + x1), -1.1];
                let left = poly(&[[-2.8, -2.1], [x0, -2.1], [x1, -0.1], [-2.8, -0.1]]);
                let right = poly(&[[x0, -2.1], [2.8, -2.1], [2.8, -0.1], [x1, -0.1], mid]);
                let (a, b) = (
                    rasterize(&f, std::slice::from_ref(&left)),
                    rasterize(&f, std::slice::from_ref(&right)),
                );
                assert!(a.is_disjoint(&b), "split {x0} {x1} at {mid:?}");
                assert_eq!(
                    rasterize(&f, &[left, right]),
                    whole,
                    "split {x0} {x1} at {mid:?}"
                );
            }
        }
    }

    #[test]
    fn rasterisation_follows_the_pixel_centre_rule() {
        // 10 x 10 pixels of 0.1 m, origin (0, 0).
        let f = MapFrame::new(10, 10, 0.1);
        // x in [0.2, 0.5) holds centres 0.25, 0.35, 0.45; y in [0.1, 0.3] holds 0.15, 0.25.
        let m = rasterize(&f, &[Polygon::rect([0.2, 0.1, 0.5, 0.3])]);
        assert_eq!(m.count_ones(..), 6);
        for c in 2..5 {
            for gy in [1usize, 2] {
                assert!(m.contains(f.index(c, 9 - gy)), "col {c} gy {gy}");
            }
        }
        // Two rectangles sharing an edge claim each centre once: the union is the big one.
        let a = rasterize(&f, &[Polygon::rect([0.0, 0.0, 0.5, 1.0])]);
        let b = rasterize(&f, &[Polygon::rect([0.5, 0.0, 1.0, 1.0])]);
        assert!(a.is_disjoint(&b));
        assert_eq!(a.count_ones(..) + b.count_ones(..), 100);
        // A triangle: the orientation does not matter.
        let t1 = rasterize(&f, &[poly(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])]);
        let t2 = rasterize(&f, &[poly(&[[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]])]);
        assert_eq!(t1, t2);
        // 45 centres lie strictly below the diagonal x + y = 1; the ten on it are decided by
        // the half-open span rule after rounding.
        let n = t1.count_ones(..);
        assert!((45..=55).contains(&n), "{n}");
        // Outside the map: nothing, no panic.
        assert!(rasterize(&f, &[Polygon::rect([5.0, 5.0, 9.0, 9.0])]).is_clear());
        assert_eq!(
            rasterize(&f, &[Polygon::rect([-5.0, -5.0, 9.0, 9.0])]).count_ones(..),
            100
        );
    }

    #[test]
    fn keepout_entries_are_counted_once_per_entry() {
        let f = MapFrame::new(20, 10, 0.1);
        // A keep-out block at x in [0.9, 1.1), all rows.
        let k = rasterize(&f, &[Polygon::rect([0.9, 0.0, 1.1, 1.0])]);
        let g = |x: f64, y: f64| f.world_to_grid(Point::new(x, y));
        let r = 1.0; // px
                     // Across and back: two entries; staying left of it: none.
        let across = [g(0.2, 0.5), g(1.8, 0.5), g(0.2, 0.5)];
        assert_eq!(keepout_entries(&f, &k, &across, r), 2);
        let left = [g(0.2, 0.5), g(0.7, 0.5), g(0.2, 0.3)];
        assert_eq!(keepout_entries(&f, &k, &left, r), 0);
        // Into it in small steps: one entry.
        let steps: Vec<Point> = (0..20).map(|i| g(0.5 + 0.05 * f64::from(i), 0.5)).collect();
        assert_eq!(keepout_entries(&f, &k, &steps, r), 1);
        assert_eq!(
            keepout_entries(&f, &FixedBitSet::with_capacity(200), &across, r),
            0
        );
    }

    /// The block summary only skips segments the exact tests would find clear: the counts
    /// equal the plain segment-by-segment ones on random masks and paths.
    #[test]
    fn the_block_summary_changes_no_count() {
        // Every move's pixels timed exactly, searched in stretches of at most a pixel, with no
        // block summary.
        let plain = |occ: &MaskOccupancy<'_>, points: &[Point], r_px: f64| {
            let mut inside = crate::collide::disk_hits(occ, points[0], r_px);
            let mut n = u32::from(inside);
            let mut spans = Vec::new();
            for w in points.windows(2) {
                if w[0] == w[1] {
                    continue;
                }
                let pieces = (w[0].dist(w[1]).ceil() as usize).max(1);
                spans.clear();
                let mut from = w[0];
                for k in 1..=pieces {
                    let to = if k == pieces {
                        w[1]
                    } else {
                        let t = k as f64 / pieces as f64;
                        Point::new(
                            w[0].x + (w[1].x - w[0].x) * t,
                            w[0].y + (w[1].y - w[0].y) * t,
                        )
                    };
                    crate::collide::contact_intervals(
                        occ,
                        w[0],
                        w[1],
                        (from, to),
                        r_px,
                        &mut spans,
                    );
                    from = to;
                }
                n += overlap_starts(&mut spans, inside);
                inside = crate::collide::disk_hits(occ, w[1], r_px);
            }
            n
        };
        let mut rng = crate::rng::SplitMix64::new(7);
        for case in 0..60 {
            let f = MapFrame::new(
                40 + (rng.next_u64() % 50) as usize,
                30 + (rng.next_u64() % 50) as usize,
                0.05,
            );
            let mut bits = FixedBitSet::with_capacity(f.len());
            // A few blobs and specks.
            for _ in 0..(rng.next_u64() % 6) {
                let (c, r) = (
                    (rng.next_u64() % f.width as u64) as usize,
                    (rng.next_u64() % f.height as u64) as usize,
                );
                let s = 1 + (rng.next_u64() % 7) as usize;
                for rr in r..(r + s).min(f.height) {
                    for cc in c..(c + s).min(f.width) {
                        bits.insert(f.index(cc, rr));
                    }
                }
            }
            let r_px = 0.5 + (rng.next_u64() % 60) as f64 / 10.0;
            let points: Vec<Point> = (0..200)
                .map(|_| {
                    Point::new(
                        rng.range(-3.0, f.width as f64 + 3.0),
                        rng.range(-3.0, f.height as f64 + 3.0),
                    )
                })
                .collect();
            // Small steps too, as PID execution makes them.
            let mut steps = vec![points[0]];
            for k in 1..400 {
                let p = steps[k - 1];
                steps.push(Point::new(
                    p.x + rng.range(-0.7, 0.7),
                    p.y + rng.range(-0.7, 0.7),
                ));
            }
            for invert in [false, true] {
                let occ = MaskOccupancy::new(&f, &bits, invert);
                for pts in [&points, &steps] {
                    assert_eq!(
                        entries(&occ, pts, r_px, true),
                        plain(&occ, pts, r_px),
                        "case {case}, invert {invert}"
                    );
                }
            }
        }
    }

    /// A straight move past keep-outs whose gaps are under a pixel counts each one it enters,
    /// as the same move in small steps does (a long move's stretches of a pixel missed an
    /// exit and entry inside one stretch: a PID glide recorded by its ends counted 1 where
    /// its control steps counted 6); and on random specks, one long move counts what the same
    /// moves cut into steps of a tenth of a pixel count.
    #[test]
    fn entries_do_not_depend_on_how_a_move_is_cut() {
        let f = MapFrame::new(60, 40, 0.05);
        let mut specks = FixedBitSet::with_capacity(f.len());
        // Six one-pixel keep-outs in a row, 3 px apart. The robot's centre passes 3 px beside
        // them: its disk (2.7 px, plus the pixel's inscribed disk, 0.5 px) overlaps each one
        // for 2.2 px of the way, with 0.8 px clear between two.
        for k in 0..6 {
            specks.insert(f.index(10 + 3 * k, 5));
        }
        let r = 2.7;
        let line = |x0: f64, x1: f64, n: usize| -> Vec<Point> {
            (0..=n)
                .map(|i| Point::new(x0 + (x1 - x0) * i as f64 / n as f64, 40.0 - 5.5 + 3.0))
                .collect()
        };
        let one = keepout_entries(&f, &specks, &line(2.0, 40.0, 1), r);
        let fine = keepout_entries(&f, &specks, &line(2.0, 40.0, 3800), r);
        assert_eq!(fine, 6, "small steps");
        assert_eq!(one, fine, "one move");
        let mut rng = crate::rng::SplitMix64::new(11);
        for case in 0..40 {
            let f = MapFrame::new(50, 40, 0.05);
            let mut bits = FixedBitSet::with_capacity(f.len());
            for _ in 0..(3 + rng.next_u64() % 30) {
                let (c, r) = (
                    (rng.next_u64() % f.width as u64) as usize,
                    (rng.next_u64() % f.height as u64) as usize,
                );
                bits.insert(f.index(c, r));
            }
            let r_px = 0.3 + (rng.next_u64() % 40) as f64 / 10.0;
            let points: Vec<Point> = (0..12)
                .map(|_| Point::new(rng.range(2.0, 48.0), rng.range(2.0, 38.0)))
                .collect();
            let mut cut = vec![points[0]];
            for w in points.windows(2) {
                let n = (w[0].dist(w[1]) * 10.0).ceil() as usize;
                for i in 1..=n {
                    let t = i as f64 / n as f64;
                    cut.push(Point::new(
                        w[0].x + (w[1].x - w[0].x) * t,
                        w[0].y + (w[1].y - w[0].y) * t,
                    ));
                }
            }
            for invert in [false, true] {
                let occ = MaskOccupancy::new(&f, &bits, invert);
                assert_eq!(
                    entries(&occ, &points, r_px, true),
                    entries(&occ, &cut, r_px, true),
                    "case {case}, invert {invert}"
                );
            }
        }
    }

    #[test]
    fn area_exits_are_entries_into_the_outside() {
        let f = MapFrame::new(20, 10, 0.1);
        // The area: x in [0, 1.2), all rows.
        let a = rasterize(&f, &[Polygon::rect([0.0, 0.0, 1.2, 1.0])]);
        let g = |x: f64, y: f64| f.world_to_grid(Point::new(x, y));
        let r = 1.0; // px
                     // Out and back in, twice: two exits; staying inside: none.
        let out = [g(0.5, 0.5), g(1.6, 0.5), g(0.5, 0.5), g(1.6, 0.5)];
        assert_eq!(area_exits(&f, &a, &out, r), 2);
        let inside = [g(0.2, 0.5), g(1.0, 0.5), g(0.2, 0.3)];
        assert_eq!(area_exits(&f, &a, &inside, r), 0);
        // A start outside (the approach) is no exit; leaving again after it is one.
        let approach = [g(1.8, 0.5), g(0.5, 0.5), g(1.8, 0.5)];
        assert_eq!(area_exits(&f, &a, &approach, r), 1);
        assert_eq!(area_exits(&f, &a, &approach[..2], r), 0);
        // Out, then back through the area and out on its other side in one long move: two
        // exits, as the same path in short steps (a hostile tester counted one).
        let area = rasterize(&f, &[Polygon::rect([0.6, 0.0, 1.2, 1.0])]);
        let long = [g(0.9, 0.5), g(1.8, 0.5), g(0.1, 0.5)];
        assert_eq!(area_exits(&f, &area, &long, r), 2);
        let short: Vec<Point> = (0..=18)
            .map(|i| g(0.9 + 0.05 * f64::from(i), 0.5))
            .chain((0..=34).map(|i| g(1.8 - 0.05 * f64::from(i), 0.5)))
            .collect();
        assert_eq!(area_exits(&f, &area, &short, r), 2);
        // Across two keep-outs in one move: two entries.
        let two = rasterize(
            &f,
            &[
                Polygon::rect([0.5, 0.0, 0.7, 1.0]),
                Polygon::rect([1.3, 0.0, 1.5, 1.0]),
            ],
        );
        assert_eq!(keepout_entries(&f, &two, &[g(0.1, 0.5), g(1.9, 0.5)], r), 2);
    }

    /// The area rule: a rectangle on pixel borders keeps every pixel of the centre rule; one
    /// with borders between them loses the pixels they cut (each kept pixel's square is inside
    /// the rectangle); two polygons sharing an edge through pixel squares give their union's
    /// pixels, not a seam.
    #[test]
    fn area_pixels_lie_wholly_inside_the_area() {
        let f = MapFrame::new(40, 30, 0.05);
        let on_grid = Polygon::rect([0.1, 0.1, 1.0, 1.4]);
        assert_eq!(
            rasterize_area(&f, std::slice::from_ref(&on_grid)),
            rasterize(&f, std::slice::from_ref(&on_grid))
        );
        let off = [0.12, 0.1, 1.0, 1.376];
        let a = rasterize_area(&f, &[Polygon::rect(off)]);
        let centre = rasterize(&f, &[Polygon::rect(off)]);
        assert!(a.is_subset(&centre) && a.count_ones(..) < centre.count_ones(..));
        for i in a.ones() {
            let (col, row) = (i % f.width, i / f.width);
            let (x0, y1) = (col as f64 * 0.05, (f.height - row) as f64 * 0.05);
            assert!(
                x0 >= off[0] - 1e-9 && x0 + 0.05 <= off[2] + 1e-9,
                "pixel ({col}, {row}) x"
            );
            assert!(
                y1 - 0.05 >= off[1] - 1e-9 && y1 <= off[3] + 1e-9,
                "pixel ({col}, {row}) y"
            );
        }
        // Split at x = 0.512 (inside a pixel column): the union's pixels, no seam.
        let left = Polygon::rect([0.1, 0.1, 0.512, 1.4]);
        let right = Polygon::rect([0.512, 0.1, 1.0, 1.4]);
        assert_eq!(
            rasterize_area(&f, &[left, right]),
            rasterize_area(&f, std::slice::from_ref(&on_grid))
        );
    }
}
