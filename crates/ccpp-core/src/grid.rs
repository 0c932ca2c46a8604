//! Occupancy grids and the one place that converts between pixels and the world frame.
//!
//! Conventions (see `world-and-metrics.md`): world x east, y north, metres; the map `origin` is the
//! world pose of the **lower-left** pixel's lower-left corner; image row 0 is the **top** row.
//! Pixel `(col, row)` therefore has its centre at
//! `origin + R(yaw) * ((col + 0.5) * res, (height - row - 0.5) * res)`.
//!
//! Pixels outside the image are occupied.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::geometry::{Point, Pose};

/// Trinary occupancy of one map pixel (ROS `map_server` trinary mode).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[repr(u8)]
pub enum Cell {
    /// Known free floor: traversable and to be covered.
    Free = 0,
    /// Known obstacle.
    Occupied = 1,
    /// Unknown: never traversable, never counted as floor.
    Unknown = 2,
}

impl Cell {
    /// `true` only for [`Cell::Free`].
    #[inline]
    pub fn is_free(self) -> bool {
        self == Cell::Free
    }
}

/// The resolution of [`MapFrame::world_to_grid_snapped`], pixels: 2^-20, far above the
/// rounding of world coordinates (about 2e-7 px at 1e8 m from the origin at 0.05 m/px) and far
/// below anything a planner resolves.
pub const GRID_SNAP_PX: f64 = 1.0 / 1_048_576.0;

/// Geometry of a grid: size, resolution and placement in the world. Holds no cell data.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MapFrame {
    /// Number of columns (pixels along image x).
    pub width: usize,
    /// Number of rows (pixels along image y, row 0 at the top).
    pub height: usize,
    /// Side of one pixel in metres.
    pub resolution: f64,
    /// World pose of the lower-left corner of the lower-left pixel (`x`, `y`, `yaw`).
    pub origin: Pose,
}

impl MapFrame {
    /// A frame with zero origin.
    pub fn new(width: usize, height: usize, resolution: f64) -> Self {
        Self {
            width,
            height,
            resolution,
            origin: Pose::new(0.0, 0.0, 0.0),
        }
    }

    /// Number of pixels (saturating: a frame too large for memory, which [`GridMap::new`]
    /// refuses, counts as `usize::MAX` instead of overflowing).
    #[inline]
    pub fn len(&self) -> usize {
        self.width.saturating_mul(self.height)
    }

    /// `true` when the grid has no pixel.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Row-major index of `(col, row)`; the caller guarantees it is inside.
    #[inline]
    pub fn index(&self, col: usize, row: usize) -> usize {
        row * self.width + col
    }

    /// `(col, row)` of a row-major index.
    #[inline]
    pub fn col_row(&self, index: usize) -> (usize, usize) {
        (index % self.width, index / self.width)
    }

    /// World point -> continuous *grid* coordinates `(gx, gy)` in pixels, y up, with the
    /// lower-left map corner at (0, 0). Pixel `(col, row)` covers
    /// `[col, col+1] x [height-row-1, height-row]`.
    #[inline]
    pub fn world_to_grid(&self, p: Point) -> Point {
        let dx = p.x - self.origin.x;
        let dy = p.y - self.origin.y;
        if self.origin.theta == 0.0 {
            // The rotation is the identity (bit for bit: 1 * dx + 0 * dy == dx).
            return Point::new(dx / self.resolution, dy / self.resolution);
        }
        let (s, c) = self.origin.theta.sin_cos();
        Point::new(
            (c * dx + s * dy) / self.resolution,
            (-s * dx + c * dy) / self.resolution,
        )
    }

    /// [`Self::world_to_grid`] with each coordinate snapped to a multiple of [`GRID_SNAP_PX`],
    /// for tests that read exact ties. A robot's position is a pixel centre up to rounding that
    /// depends on where the frame is placed (`2000.275 - 2000` is `0.27500000000009095`): a
    /// sensor range that reaches a pixel centre exactly saw it or not with that rounding, and
    /// ba-star-extended on one room made 802 turns with the origin at (0, 0), 743 at
    /// (1000, 2000) and 796 at (1e6, 2e6) m. Snapped, what the sensor sees does not depend on
    /// where the map lies.
    #[inline]
    pub fn world_to_grid_snapped(&self, p: Point) -> Point {
        let g = self.world_to_grid(p);
        let snap = |v: f64| (v / GRID_SNAP_PX).round() * GRID_SNAP_PX;
        Point::new(snap(g.x), snap(g.y))
    }

    /// Continuous grid coordinates (pixels, y up) -> world point. Inverse of [`Self::world_to_grid`].
    #[inline]
    pub fn grid_to_world(&self, g: Point) -> Point {
        let gx = g.x * self.resolution;
        let gy = g.y * self.resolution;
        if self.origin.theta == 0.0 {
            // The rotation is the identity (bit for bit, as above).
            return Point::new(self.origin.x + gx, self.origin.y + gy);
        }
        let (s, c) = self.origin.theta.sin_cos();
        Point::new(
            self.origin.x + c * gx - s * gy,
            self.origin.y + s * gx + c * gy,
        )
    }

    /// Grid coordinates of the centre of pixel `(col, row)`.
    #[inline]
    pub fn pixel_center_grid(&self, col: usize, row: usize) -> Point {
        Point::new(col as f64 + 0.5, (self.height - row) as f64 - 0.5)
    }

    /// World coordinates of the centre of pixel `(col, row)`.
    #[inline]
    pub fn pixel_center(&self, col: usize, row: usize) -> Point {
        self.grid_to_world(self.pixel_center_grid(col, row))
    }

    /// The pixel `(col, row)` whose square contains grid point `g`, as signed integers (may lie
    /// outside the image).
    #[inline]
    pub fn grid_to_pixel_signed(&self, g: Point) -> (i64, i64) {
        // Far off the image (1e300 m) the integers saturate instead of overflowing, and a NaN
        // coordinate lies outside (it was pixel 0: `pixel_of` found a NaN point on the map).
        let floor = |v: f64| {
            if v.is_nan() {
                i64::MIN
            } else {
                v.floor() as i64
            }
        };
        let top = i64::try_from(self.height).unwrap_or(i64::MAX) - 1;
        (floor(g.x), top.saturating_sub(floor(g.y)))
    }

    /// The pixel containing world point `p`, or `None` outside the image.
    pub fn pixel_of(&self, p: Point) -> Option<(usize, usize)> {
        let (c, r) = self.grid_to_pixel_signed(self.world_to_grid(p));
        self.checked(c, r)
    }

    /// Converts signed pixel coordinates to unsigned ones when inside the image.
    #[inline]
    pub fn checked(&self, col: i64, row: i64) -> Option<(usize, usize)> {
        if col >= 0 && row >= 0 && (col as usize) < self.width && (row as usize) < self.height {
            Some((col as usize, row as usize))
        } else {
            None
        }
    }

    /// Axis-aligned world bounding box of the image, `(lower-left, upper-right)` corners
    /// (equal to the image extent when the origin has no yaw).
    pub fn world_bounds(&self) -> (Point, Point) {
        let (w, h) = (self.width as f64, self.height as f64);
        let mut lo = Point::new(f64::INFINITY, f64::INFINITY);
        let mut hi = Point::new(f64::NEG_INFINITY, f64::NEG_INFINITY);
        for g in [
            Point::new(0.0, 0.0),
            Point::new(w, 0.0),
            Point::new(0.0, h),
            Point::new(w, h),
        ] {
            let c = self.grid_to_world(g);
            lo = Point::new(lo.x.min(c.x), lo.y.min(c.y));
            hi = Point::new(hi.x.max(c.x), hi.y.max(c.y));
        }
        (lo, hi)
    }

    /// Width of the mapped area in metres.
    pub fn width_m(&self) -> f64 {
        self.width as f64 * self.resolution
    }

    /// Height of the mapped area in metres.
    pub fn height_m(&self) -> f64 {
        self.height as f64 * self.resolution
    }
}

/// Finest map resolution ccpp computes precisely, metres per pixel (10 micrometres): below
/// about 1e-6 the fixed tolerances of the geometry (contact, free-move and sweep tests) are no
/// longer small against a pixel, and a map scaled down gave other results than the same map at
/// its scale (rect-boustrophedon swept 0.841 instead of 0.860 of a room at 5e-7 m/px; bsa-bfs
/// drove nothing at 5e-8; bcd reported collisions at 5e-14). Down to 5e-6 every planner whose
/// options scale with the map gives the same coverage as at 0.05.
pub const MIN_RESOLUTION_M: f64 = 1e-5;

/// Largest world coordinate of a map's corners ccpp computes precisely, metres (100 000 km,
/// beyond any UTM or Earth-centred coordinate): farther out, `f64` keeps too few digits for
/// the pixel arithmetic (at 1e9 m the same run covered 0.893 instead of 0.900 of the floor, at
/// 1e300 m every start looked like a wall), so the results would change without a word.
pub const MAX_COORD_M: f64 = 1e8;

/// Largest map side ccpp handles, metres (1000 km): larger frames come from a wrong
/// resolution, and their tile and distance arithmetic would lose all precision.
pub const MAX_MAP_SIDE_M: f64 = 1e6;

/// Why a [`MapFrame`] lies where `f64` does not keep the precision ccpp's geometry needs
/// ([`MapFrame::precision_problem`]).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FrameProblem {
    /// The resolution (m/px) is finer than [`MIN_RESOLUTION_M`].
    #[error(
        "the resolution {0:e} m/px is finer than the {MIN_RESOLUTION_M:e} m/px ccpp computes \
         precisely"
    )]
    TooFine(f64),
    /// A side is longer than [`MAX_MAP_SIDE_M`].
    #[error(
        "the map is {width_m:e} x {height_m:e} m ({width} x {height} px at {resolution:e} \
         m/px), larger than the {MAX_MAP_SIDE_M:e} m side ccpp handles"
    )]
    TooLarge {
        /// Width, metres.
        width_m: f64,
        /// Height, metres.
        height_m: f64,
        /// Width, pixels.
        width: usize,
        /// Height, pixels.
        height: usize,
        /// Resolution, m/px.
        resolution: f64,
    },
    /// A corner lies farther than [`MAX_COORD_M`] from the world's origin along an axis.
    #[error(
        "the map reaches {} m from the world's origin along an axis (origin {}, {}), \
         farther than the {MAX_COORD_M:e} m ccpp handles precisely",
        beyond_limit(*.far), crate::display::Compact(*.x), crate::display::Compact(*.y)
    )]
    TooFar {
        /// Largest corner coordinate magnitude, metres.
        far: f64,
        /// Origin x, metres.
        x: f64,
        /// Origin y, metres.
        y: f64,
    },
}

/// Whether a map origin's `yaw` turns the image's axes off the world's (not a multiple of a
/// quarter turn, beyond 1e-9 rad): planners that lay tiles or lanes along the world axes then
/// cross the map's walls, and the map's world bounds are a turned rectangle's box.
pub fn off_the_axes(yaw: f64) -> bool {
    let quarter = std::f64::consts::FRAC_PI_2;
    (yaw / quarter - (yaw / quarter).round()).abs() * quarter > 1e-9
}

/// A reach beyond [`MAX_COORD_M`] in three significant digits, or in as many more as show it
/// beyond: 1.005e8 m read "1.00e8 m ... farther than the 1e8 m", as if equal to the limit.
fn beyond_limit(far: f64) -> String {
    (2..=15)
        .map(|d| format!("{far:.d$e}"))
        .find(|t| t.parse::<f64>().is_ok_and(|v| v > MAX_COORD_M))
        .unwrap_or_else(|| format!("{far:e}"))
}

impl FrameProblem {
    /// The map setting to check: `resolution` (too fine, too large) or `origin` (too far).
    #[must_use]
    pub fn setting(&self) -> &'static str {
        match self {
            Self::TooFine(_) | Self::TooLarge { .. } => "resolution",
            Self::TooFar { .. } => "origin",
        }
    }
}

impl MapFrame {
    /// Why the frame lies beyond the precision bounds ([`MIN_RESOLUTION_M`],
    /// [`MAX_MAP_SIDE_M`], [`MAX_COORD_M`]), if it does. [`crate::world::World`] refuses such
    /// a frame, and `ccpp_io`'s scenario names the map file that gave it.
    #[must_use]
    pub fn precision_problem(&self) -> Option<FrameProblem> {
        if self.resolution < MIN_RESOLUTION_M {
            return Some(FrameProblem::TooFine(self.resolution));
        }
        let fits = |v: f64| v.is_finite() && v <= MAX_MAP_SIDE_M;
        if !(fits(self.width_m()) && fits(self.height_m())) {
            return Some(FrameProblem::TooLarge {
                width_m: self.width_m(),
                height_m: self.height_m(),
                width: self.width,
                height: self.height,
                resolution: self.resolution,
            });
        }
        let (lo, hi) = self.world_bounds();
        let far = [lo.x, lo.y, hi.x, hi.y]
            .into_iter()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        // (a NaN corner is not within bounds either)
        let within = far
            .partial_cmp(&MAX_COORD_M)
            .is_some_and(std::cmp::Ordering::is_le);
        (!within).then_some(FrameProblem::TooFar {
            far,
            x: self.origin.x,
            y: self.origin.y,
        })
    }
}

/// A 2-D occupancy grid: a [`MapFrame`] plus one [`Cell`] per pixel, row-major, row 0 on top.
///
/// Grids read like drawings in tests (`#` occupied, `.` free, `?` unknown; the first line is the
/// top row):
///
/// ```
/// use ccpp_core::grid::{Cell, GridMap};
/// let g: GridMap = "####\n#..#\n#.?#\n####".parse().unwrap();
/// assert_eq!(g.frame().width, 4);
/// assert_eq!(g.get(1, 1), Cell::Free);
/// assert_eq!(g.get(2, 2), Cell::Unknown);
/// assert_eq!(g.get_signed(-1, 0), Cell::Occupied); // outside is occupied
/// ```
#[derive(Clone, PartialEq)]
pub struct GridMap {
    frame: MapFrame,
    cells: Vec<Cell>,
}

/// Error building a grid from parts or from ASCII art.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum GridError {
    /// The cell vector does not match `width * height`.
    #[error("grid has {got} cells but {width}x{height} needs {expected}")]
    SizeMismatch {
        /// Width given.
        width: usize,
        /// Height given.
        height: usize,
        /// `width * height`.
        expected: usize,
        /// Cells given.
        got: usize,
    },
    /// Resolution is not a finite positive number.
    #[error("resolution must be a finite number > 0, got {0}")]
    BadResolution(f64),
    /// Origin has a non-finite component.
    #[error("origin must be finite, got ({0}, {1}, {2})")]
    BadOrigin(f64, f64, f64),
    /// The grid has no pixel.
    #[error("the map is empty (0 pixels)")]
    Empty,
    /// ASCII rows of different lengths.
    #[error("ASCII map row {row} has {got} characters, expected {expected}")]
    RaggedRow {
        /// Row index (0 = first line).
        row: usize,
        /// Expected length.
        expected: usize,
        /// Actual length.
        got: usize,
    },
    /// Unknown ASCII character.
    #[error("ASCII map has unknown character {0:?} (use '#', '.', '?')")]
    BadChar(char),
    /// A side longer than [`MAX_SIDE_PX`].
    #[error("a {width}x{height} px grid is too large: each side may have at most {max} pixels", max = MAX_SIDE_PX)]
    TooLarge {
        /// Width given.
        width: usize,
        /// Height given.
        height: usize,
    },
}

/// The longest side a grid may have, in pixels (2^31 - 1): pixel coordinates are signed
/// 64-bit integers in the geometry, whose arithmetic stays far from overflow below this, and a
/// grid's pixel count then fits in memory's addresses. (A frame of 2^32 x 2^32 px overflowed
/// `width * height` and gave a grid of no cells.)
pub const MAX_SIDE_PX: usize = i32::MAX as usize;

/// Refuses a frame with a side beyond [`MAX_SIDE_PX`].
fn check_sides(width: usize, height: usize) -> Result<(), GridError> {
    if width > MAX_SIDE_PX || height > MAX_SIDE_PX {
        return Err(GridError::TooLarge { width, height });
    }
    Ok(())
}

impl GridMap {
    /// Builds a grid from a frame and row-major cells (row 0 on top).
    ///
    /// # Errors
    /// When sizes mismatch, the grid is empty, or resolution/origin are not finite and positive.
    pub fn new(frame: MapFrame, cells: Vec<Cell>) -> Result<Self, GridError> {
        if !(frame.resolution.is_finite() && frame.resolution > 0.0) {
            return Err(GridError::BadResolution(frame.resolution));
        }
        let o = frame.origin;
        if !(o.x.is_finite() && o.y.is_finite() && o.theta.is_finite()) {
            return Err(GridError::BadOrigin(o.x, o.y, o.theta));
        }
        if frame.width == 0 || frame.height == 0 {
            return Err(GridError::Empty);
        }
        check_sides(frame.width, frame.height)?;
        if cells.len() != frame.len() {
            return Err(GridError::SizeMismatch {
                width: frame.width,
                height: frame.height,
                expected: frame.len(),
                got: cells.len(),
            });
        }
        Ok(Self { frame, cells })
    }

    /// A grid filled with one value.
    ///
    /// # Errors
    /// As [`GridMap::new`].
    pub fn filled(frame: MapFrame, value: Cell) -> Result<Self, GridError> {
        // (before the allocation, which a huge frame would abort)
        check_sides(frame.width, frame.height)?;
        Self::new(frame, vec![value; frame.len()])
    }

    /// Parses ASCII art where each character stands for a `scale x scale` block of pixels of
    /// `resolution` metres. `#` occupied, `.` free, `?` unknown; other whitespace-only lines are
    /// ignored, leading/trailing spaces of each line are trimmed.
    ///
    /// # Errors
    /// Ragged rows, unknown characters, empty art or a bad resolution.
    pub fn from_ascii_scaled(art: &str, scale: usize, resolution: f64) -> Result<Self, GridError> {
        let rows: Vec<&str> = art
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect();
        let w = rows.first().map_or(0, |r| r.chars().count());
        let mut small = Vec::with_capacity(w * rows.len());
        for (i, r) in rows.iter().enumerate() {
            let n = r.chars().count();
            if n != w {
                return Err(GridError::RaggedRow {
                    row: i,
                    expected: w,
                    got: n,
                });
            }
            for ch in r.chars() {
                small.push(match ch {
                    '#' => Cell::Occupied,
                    '.' => Cell::Free,
                    '?' => Cell::Unknown,
                    other => return Err(GridError::BadChar(other)),
                });
            }
        }
        let scale = scale.max(1);
        let (Some(width), Some(height)) = (w.checked_mul(scale), rows.len().checked_mul(scale))
        else {
            return Err(GridError::TooLarge {
                width: usize::MAX,
                height: usize::MAX,
            });
        };
        check_sides(width, height)?;
        let frame = MapFrame::new(width, height, resolution);
        let mut cells = Vec::with_capacity(frame.len());
        for r in 0..frame.height {
            for c in 0..frame.width {
                cells.push(small[(r / scale) * w + c / scale]);
            }
        }
        Self::new(frame, cells)
    }

    /// The grid's geometry.
    #[inline]
    pub fn frame(&self) -> &MapFrame {
        &self.frame
    }

    /// Replaces the world placement (resolution and origin) keeping the cells.
    ///
    /// # Errors
    /// When the resolution or origin are invalid.
    pub fn with_placement(mut self, resolution: f64, origin: Pose) -> Result<Self, GridError> {
        self.frame.resolution = resolution;
        self.frame.origin = origin;
        Self::new(self.frame, self.cells)
    }

    /// A hash of the grid's content: size, placement and every cell ([`crate::hash::Fnv`]).
    #[must_use]
    pub fn content_hash(&self) -> u64 {
        self.content_hash_mapped(|_, c| c)
    }

    /// [`Self::content_hash`] of the grid whose pixel `i` is `cell(i, c)` where this grid has
    /// `c` (a map with virtual walls), without building that grid.
    #[must_use]
    pub fn content_hash_mapped(&self, cell: impl Fn(usize, Cell) -> Cell) -> u64 {
        let f = self.frame();
        let mut h = crate::hash::Fnv::new();
        h.bytes(&(f.width as u64).to_le_bytes());
        h.bytes(&(f.height as u64).to_le_bytes());
        for v in [f.resolution, f.origin.x, f.origin.y, f.origin.theta] {
            h.bytes(&v.to_bits().to_le_bytes());
        }
        h.field(
            self.cells()
                .iter()
                .enumerate()
                .map(|(i, &c)| match cell(i, c) {
                    Cell::Free => 0,
                    Cell::Occupied => 1,
                    Cell::Unknown => 2,
                }),
        );
        h.finish()
    }

    /// Row-major cells, row 0 on top.
    #[inline]
    pub fn cells(&self) -> &[Cell] {
        &self.cells
    }

    /// Mutable row-major cells.
    #[inline]
    pub fn cells_mut(&mut self) -> &mut [Cell] {
        &mut self.cells
    }

    /// Cell at `(col, row)`; panics if outside (use [`Self::get_signed`] for unchecked input).
    #[inline]
    pub fn get(&self, col: usize, row: usize) -> Cell {
        self.cells[self.frame.index(col, row)]
    }

    /// Cell at signed `(col, row)`; outside the image is [`Cell::Occupied`].
    #[inline]
    pub fn get_signed(&self, col: i64, row: i64) -> Cell {
        match self.frame.checked(col, row) {
            Some((c, r)) => self.get(c, r),
            None => Cell::Occupied,
        }
    }

    /// Sets the cell at `(col, row)`.
    #[inline]
    pub fn set(&mut self, col: usize, row: usize, value: Cell) {
        let i = self.frame.index(col, row);
        self.cells[i] = value;
    }

    /// Counts of (free, occupied, unknown) pixels.
    pub fn counts(&self) -> (usize, usize, usize) {
        let mut n = [0usize; 3];
        for &c in &self.cells {
            n[c as usize] += 1;
        }
        (n[0], n[1], n[2])
    }
}

impl FromStr for GridMap {
    type Err = GridError;
    /// One pixel per character at 1 m/px; see [`GridMap::from_ascii_scaled`].
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::from_ascii_scaled(s, 1, 1.0)
    }
}

impl fmt::Debug for GridMap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "GridMap {}x{} @ {} m/px, origin ({}, {}, {})",
            self.frame.width,
            self.frame.height,
            self.frame.resolution,
            self.frame.origin.x,
            self.frame.origin.y,
            self.frame.origin.theta
        )?;
        for r in 0..self.frame.height {
            for c in 0..self.frame.width {
                let ch = match self.get(c, r) {
                    Cell::Free => '.',
                    Cell::Occupied => '#',
                    Cell::Unknown => '?',
                };
                write!(f, "{ch}")?;
            }
            writeln!(f)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    /// A reach just beyond the limit shows as beyond it (1.005e8 m read "1.00e8 m").
    #[test]
    fn a_reach_beyond_the_limit_reads_beyond_it() {
        assert_eq!(super::beyond_limit(1.005e8), "1.005e8");
        assert_eq!(super::beyond_limit(1.000_000_012e9), "1.00e9");
        assert_eq!(super::beyond_limit(2.5e8), "2.50e8");
    }

    use super::*;

    /// A NaN point is off the map (it was pixel (0, 0)), and a point 1e300 m away is off it
    /// without an overflow; a frame with a side beyond `MAX_SIDE_PX` is refused before any
    /// allocation (2^32 x 2^32 px overflowed `width * height` and gave a grid of no cells).
    #[test]
    fn far_points_and_huge_frames_are_refused_not_overflowed() {
        let f = MapFrame::new(4, 3, 1.0);
        assert_eq!(f.pixel_of(Point::new(f64::NAN, 0.5)), None);
        assert_eq!(f.pixel_of(Point::new(0.5, f64::NAN)), None);
        assert_eq!(f.pixel_of(Point::new(1e300, -1e300)), None);
        assert_eq!(f.pixel_of(Point::new(-1e300, 1e300)), None);
        assert_eq!(f.pixel_of(Point::new(0.5, 0.5)), Some((0, 2)));
        for (w, h) in [(1 << 32, 1 << 32), ((1 << 63) + 1, 2), (MAX_SIDE_PX + 1, 1)] {
            let frame = MapFrame::new(w, h, 1.0);
            assert!(matches!(
                GridMap::new(frame, vec![Cell::Free; 2]),
                Err(GridError::TooLarge { .. })
            ));
            assert!(matches!(
                GridMap::filled(frame, Cell::Free),
                Err(GridError::TooLarge { .. })
            ));
        }
        assert!(matches!(
            GridMap::from_ascii_scaled("..", usize::MAX, 1.0),
            Err(GridError::TooLarge { .. })
        ));
    }

    #[test]
    fn ascii_roundtrip_and_frames() {
        let g: GridMap = "#..\n.?#".parse().unwrap();
        assert_eq!(g.counts(), (3, 2, 1));
        let dbg = format!("{g:?}");
        assert!(dbg.ends_with("#..\n.?#\n"));
        // Pixel (0, 1) is the lower-left pixel: centre (0.5, 0.5) at 1 m/px.
        assert_eq!(g.frame().pixel_center(0, 1), Point::new(0.5, 0.5));
        assert_eq!(g.frame().pixel_center(2, 0), Point::new(2.5, 1.5));
        assert_eq!(g.frame().pixel_of(Point::new(2.9, 1.1)), Some((2, 0)));
        assert_eq!(g.frame().pixel_of(Point::new(3.1, 1.1)), None);
    }

    #[test]
    fn rotated_origin_roundtrip() {
        let mut f = MapFrame::new(10, 10, 0.05);
        f.origin = Pose::new(1.0, -2.0, 0.7);
        let p = Point::new(0.3, -1.7);
        let back = f.grid_to_world(f.world_to_grid(p));
        assert!((back.x - p.x).abs() < 1e-12 && (back.y - p.y).abs() < 1e-12);
    }

    #[test]
    fn scaled_ascii() {
        let g = GridMap::from_ascii_scaled("#.\n..", 3, 0.1).unwrap();
        assert_eq!(g.frame().width, 6);
        assert_eq!(g.get(2, 2), Cell::Occupied);
        assert_eq!(g.get(3, 2), Cell::Free);
        assert!(matches!(
            "#x".parse::<GridMap>(),
            Err(GridError::BadChar('x'))
        ));
        assert!(matches!(
            "#.\n#".parse::<GridMap>(),
            Err(GridError::RaggedRow { .. })
        ));
    }
}
