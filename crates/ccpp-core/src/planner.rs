//! The online step protocol: what a planner may know ([`Sensor`]) and what it may do ([`Step`]).
//!
//! An online planner learns the world only through [`Sensor::scan`] (the occupancy of the map
//! pixels within `sensor_range` of the robot centre) and [`Sensor::bumped`]. It may keep what it
//! saw in a [`KnownMap`]. It may know the map *frame* (extent, resolution, origin): the area the
//! robot is asked to work in, never its contents.

use fixedbitset::FixedBitSet;

use crate::bits::BLOCK_BITS;
use crate::collide::{self, Occupancy};
use crate::geometry::{ceil_i64, floor_i64, Point, Pose};
use crate::grid::{Cell, GridMap, MapFrame};
use crate::trace::Event;
use crate::world::Robot;

/// Rotations smaller than this (radians) are not executed by the simulator (planners skip
/// them too), nor counted as turns. 1e-6 rad, as PID's `heading_tolerance_rad`: at 1e-9, the
/// rounding of headings between collinear moves of a map placed far from the origin with a
/// yaw (about 1e-8 rad at (512345.6, 5098765.4)) was executed and counted as turns (bcd: 35
/// waypoints against 33 at the origin). The 112 runs of the shared bench are byte-identical
/// at either value.
pub const MIN_ROTATION: f64 = 1e-6;

/// One decision of a planner.
#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    /// Rotate in place by this angle (radians, counter-clockwise positive).
    Rotate(f64),
    /// Translate along the current heading by this distance (metres; negative = reverse).
    Translate(f64),
    /// Rotate to face the point, then translate to it (`beta`, `alpha`, `d` of seed 000).
    MoveTo(Point),
    /// Record an event in the trace.
    Mark(Event),
    /// Coverage is complete.
    Done,
}

/// The pixels within sensor range of the robot, read from the true map.
///
/// The planner can read only the pixels whose centre lies within `range` of the robot centre
/// (pixels outside the image read as occupied).
pub struct Scan<'a> {
    map: &'a GridMap,
    center: Point,
    range_px: f64,
}

impl<'a> Scan<'a> {
    /// A scan of `map` around world point `center` with radius `range` metres. Only the simulator
    /// should build these.
    pub fn new(map: &'a GridMap, center: Point, range: f64) -> Self {
        let g = map.frame().world_to_grid_snapped(center);
        Self {
            map,
            center: g,
            range_px: range / map.frame().resolution,
        }
    }

    /// Calls `f(row, lo, hi)` for every image row holding in-range pixels, top to bottom: the
    /// in-range pixels of the row are exactly columns `lo..=hi` (the same pixels, in the same
    /// order, as [`Self::for_each`]).
    pub fn for_each_row_span(&self, f: impl FnMut(usize, usize, usize)) {
        self.row_spans_beyond(None, f);
    }

    /// Where the scan was taken (continuous grid coordinates) and its range in pixels.
    pub(crate) fn disk_px(&self) -> (Point, f64) {
        (self.center, self.range_px)
    }

    /// [`Self::for_each_row_span`], leaving out rows all of whose in-range pixels are in range
    /// of an earlier scan `prev` (`(centre, range)` from [`Self::disk_px`]) of the same map:
    /// the leading edge of a moving sensor. A row is left out only with a margin of
    /// [`LEADING_EDGE_MARGIN_PX`] on each side, far above the rounding of either in-range test,
    /// so every pixel it holds passed the earlier scan's test.
    pub(crate) fn row_spans_beyond(
        &self,
        prev: Option<(Point, f64)>,
        mut f: impl FnMut(usize, usize, usize),
    ) {
        // Only for the same range, and ranges small enough for the margin to dominate the
        // rounding of the squared distances (`r^2` up to 1e8 px^2).
        let prev = prev
            .filter(|&(_, r)| r.to_bits() == self.range_px.to_bits() && r <= 1e4)
            .map(|(c, _)| c);
        let frame = self.map.frame();
        let r = self.range_px;
        let r2 = r * r;
        let h = frame.height as f64;
        let (c0, c1, r0, r1) = self.pixel_box();
        if c0 > c1 {
            return;
        }
        let inside = |col: i64, dy2: f64| {
            let dx = col as f64 + 0.5 - self.center.x;
            dx * dx + dy2 <= r2
        };
        let (c0, c1) = (c0 as i64, c1 as i64);
        for row in r0..=r1 {
            let gy = h - row as f64 - 0.5;
            let dy2 = (gy - self.center.y).powi(2);
            if dy2 > r2 {
                continue;
            }
            // `dx * dx + dy2` is monotone on each side of the centre (rounding is monotone), so
            // the in-range columns of a row are one interval. Guess its ends from the square
            // root, then settle them with the exact test.
            let half = (r2 - dy2).sqrt();
            if let Some(a) = prev {
                // The row's in-range pixel centres lie within `half` (plus rounding) of the
                // centre's x; they were all in range of `a` when that interval, grown by the
                // margin, lies within `a`'s chord of this row shrunk by the margin:
                // `|dx| + half + 2 m <= sqrt(r^2 - dy_a^2)`.
                let dya = gy - a.y;
                let s = (self.center.x - a.x).abs() + half + 2.0 * LEADING_EDGE_MARGIN_PX;
                if s * s + dya * dya < r2 {
                    continue;
                }
            }
            let mut lo = ceil_i64(self.center.x - 0.5 - half).clamp(c0, c1 + 1);
            while lo > c0 && inside(lo - 1, dy2) {
                lo -= 1;
            }
            while lo <= c1 && !inside(lo, dy2) {
                lo += 1;
            }
            if lo > c1 {
                // Empty, or the guess overshot the whole interval: settle it from the left.
                lo = c0;
                while lo <= c1 && !inside(lo, dy2) {
                    lo += 1;
                }
                if lo > c1 {
                    continue;
                }
            }
            let mut hi = floor_i64(self.center.x - 0.5 + half).clamp(lo, c1);
            while hi < c1 && inside(hi + 1, dy2) {
                hi += 1;
            }
            while !inside(hi, dy2) {
                hi -= 1;
            }
            let (lo, hi) = (lo as usize, hi as usize);
            f(row, lo, hi);
        }
    }

    /// [`Self::for_each_row_span`] for scans whose pixel box is at most [`SMALL_SCAN_COLS`]
    /// columns wide (`false`, and no call, otherwise): the squared column offsets are computed
    /// once for the box and each row's interval is read off them by the same in-range test,
    /// without a square root per row.
    pub(crate) fn small_row_spans(&self, mut f: impl FnMut(usize, usize, usize)) -> bool {
        let r2 = self.range_px * self.range_px;
        let h = self.map.frame().height as f64;
        let (c0, c1, r0, r1) = self.pixel_box();
        if c0 > c1 {
            return true;
        }
        let n = c1 - c0 + 1;
        if n > SMALL_SCAN_COLS {
            return false;
        }
        let mut dx2 = [0.0f64; SMALL_SCAN_COLS];
        for (k, v) in dx2[..n].iter_mut().enumerate() {
            let dx = (c0 + k) as f64 + 0.5 - self.center.x;
            *v = dx * dx;
        }
        let dx2 = &dx2[..n];
        for row in r0..=r1 {
            let gy = h - row as f64 - 0.5;
            let dy2 = (gy - self.center.y).powi(2);
            if dy2 > r2 {
                continue;
            }
            // The in-range columns of a row are one interval (see `row_spans_beyond`).
            let Some(lo) = dx2.iter().position(|&v| v + dy2 <= r2) else {
                continue;
            };
            let hi = dx2.iter().rposition(|&v| v + dy2 <= r2).unwrap_or(lo);
            f(row, c0 + lo, c0 + hi);
        }
        true
    }

    /// The columns `c0..=c1` and rows `r0..=r1` of the image that can hold in-range pixels
    /// (`c0 > c1` when none can).
    fn pixel_box(&self) -> (usize, usize, usize, usize) {
        let frame = self.map.frame();
        let r = self.range_px;
        let h = frame.height as f64;
        let c0 = floor_i64(self.center.x - r - 0.5).max(0) as usize;
        let c1 = (ceil_i64(self.center.x + r - 0.5).max(0) as usize).min(frame.width - 1);
        let r0 = floor_i64(h - (self.center.y + r) - 0.5).max(0) as usize;
        let r1 = (ceil_i64(h - (self.center.y - r) - 0.5).max(0) as usize).min(frame.height - 1);
        (c0, c1, r0, r1)
    }

    /// Calls `f(col, row, cell)` for every in-range pixel that lies inside the image, in
    /// row-major order. (Out-of-image pixels are occupied by convention and never change.)
    pub fn for_each(&self, mut f: impl FnMut(usize, usize, Cell)) {
        let frame = self.map.frame();
        let r = self.range_px;
        let r2 = r * r;
        let h = frame.height as f64;
        let (c0, c1, r0, r1) = self.pixel_box();
        for row in r0..=r1 {
            let gy = h - row as f64 - 0.5;
            let dy2 = (gy - self.center.y).powi(2);
            if dy2 > r2 {
                continue;
            }
            for col in c0..=c1 {
                let dx = col as f64 + 0.5 - self.center.x;
                if dx * dx + dy2 <= r2 {
                    f(col, row, self.map.get(col, row));
                }
            }
        }
    }
}

/// The widest pixel box (columns) [`Scan::small_row_spans`] takes.
const SMALL_SCAN_COLS: usize = 16;

/// Margin (pixels) by which a row of a scan must lie inside an earlier scan's disk to be left
/// out of [`Scan::row_spans_beyond`]: far above the rounding of the in-range tests.
const LEADING_EDGE_MARGIN_PX: f64 = 1e-3;

/// What a real robot can know.
pub trait Sensor {
    /// The working area's frame (extent, resolution, origin) — not its contents.
    fn frame(&self) -> &MapFrame;
    /// The robot model.
    fn robot(&self) -> Robot;
    /// The robot's pose (odometry/localization).
    fn pose(&self) -> Pose;
    /// Sensor range in metres.
    fn sensor_range(&self) -> f64;
    /// The occupancy of the pixels within sensor range.
    fn scan(&self) -> Scan<'_>;
    /// `true` when the last motion stopped on a bumper contact.
    fn bumped(&self) -> bool;
}

/// A coverage planner driven step by step by the simulator.
pub trait Planner {
    /// Short machine name (`ba-star`, `random-bounce`, ...).
    fn name(&self) -> &'static str;
    /// Tile side in metres for tile-based planners (enables the `coverage_rate` metric).
    fn tile_side(&self) -> Option<f64> {
        None
    }
    /// `true` for planners that read the whole map up front (offline).
    fn is_offline(&self) -> bool {
        false
    }
    /// The execution mode this planner is meant to run under, used by the simulator when
    /// [`SimConfig::exec`](crate::sim::SimConfig::exec) is `None`; `None` = ideal execution.
    fn preferred_execution(&self) -> Option<crate::exec::Execution> {
        None
    }
    /// The next decision.
    fn next(&mut self, sensor: &dyn Sensor) -> Step;
}

/// Image rows (signed, one row of margin each side) that the disk of radius `rc` pixels at grid
/// point `g` can reach.
pub(crate) fn disk_rows(frame: &MapFrame, g: Point, rc: f64) -> std::ops::RangeInclusive<i64> {
    let h = frame.height as f64;
    floor_i64(h - (g.y + rc) - 0.5) - 1..=ceil_i64(h - (g.y - rc) - 0.5) + 1
}

/// The columns (signed) of image row `row` whose pixel centre `q` has `|q - g|^2 < rc^2`, or
/// `None`. The predicate is convex in the column, so they are the interval between the first
/// and the last column satisfying it: guessed from the square root, settled with the predicate.
#[inline]
pub(crate) fn disk_row_span(frame: &MapFrame, g: Point, rc: f64, row: i64) -> Option<(i64, i64)> {
    let rc2 = rc * rc;
    let gy = frame.height as f64 - row as f64 - 0.5;
    let dy = gy - g.y;
    let rem = rc2 - dy * dy;
    if rem <= 0.0 {
        // dx^2 + dy^2 >= dy^2 >= rc^2: no pixel of this row touches.
        return None;
    }
    let touches = |col: i64| Point::new(col as f64 + 0.5, gy).dist2(g) < rc2;
    let half = rem.sqrt();
    let mut lo = ceil_i64(g.x - half - 0.5) - 1;
    let mut hi = floor_i64(g.x + half - 0.5) + 1;
    while lo <= hi && !touches(lo) {
        lo += 1;
    }
    while hi >= lo && !touches(hi) {
        hi -= 1;
    }
    (lo <= hi).then_some((lo, hi))
}

/// The disk of contact radius `rc` pixels around a pixel centre, as row half-widths: entry
/// `dy` is the largest `dx >= 0` with `dx^2 + dy^2 < rc^2`, or -1 when the row holds no pixel.
pub(crate) fn pixel_disk_spans(rc: f64) -> Vec<i64> {
    let rc2 = rc * rc;
    let reach = rc.ceil().max(0.0) as i64;
    (0..=reach)
        .map(|dy| {
            let mut hw = -1;
            while (((hw + 1) * (hw + 1) + dy * dy) as f64) < rc2 {
                hw += 1;
            }
            hw
        })
        .collect()
}

/// What a [`KnownMap`] says about a disk ([`KnownMap::disk_state`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum DiskState {
    /// Every pixel seen free.
    Free,
    /// A pixel seen blocked or outside the image.
    Blocked,
    /// Nothing blocked, but some pixel not seen yet.
    Unseen,
}

/// A planner's memory of what its sensor has shown: each pixel is unseen, or seen with its
/// occupancy. Unseen pixels block motion in every check.
#[derive(Clone)]
pub struct KnownMap {
    grid: GridMap,
    seen: FixedBitSet,
    /// Seen and free (the pixels that never block).
    free: FixedBitSet,
}

impl KnownMap {
    /// Nothing seen yet.
    ///
    /// # Panics
    /// Never for a frame that came from a valid map.
    pub fn new(frame: &MapFrame) -> Self {
        let grid = GridMap::filled(*frame, Cell::Unknown).expect("frame of a valid map");
        Self {
            grid,
            seen: FixedBitSet::with_capacity(frame.len()),
            free: FixedBitSet::with_capacity(frame.len()),
        }
    }

    /// Stores every pixel of a scan.
    pub fn integrate(&mut self, scan: &Scan<'_>) {
        self.integrate_with(scan, |_, _, _| {});
    }

    /// Stores every pixel of a scan and calls `first_seen(col, row, cell)` for each pixel seen
    /// for the first time (in the scan's row-major order).
    ///
    /// Works a block of the seen bitset at a time: pixels already seen cost nothing (their
    /// value never changes: the map is static).
    pub fn integrate_with(
        &mut self,
        scan: &Scan<'_>,
        mut first_seen: impl FnMut(usize, usize, Cell),
    ) {
        let w = self.grid.frame().width;
        let truth = scan.map.cells();
        let cells = self.grid.cells_mut();
        let seen = self.seen.as_mut_slice();
        let free = self.free.as_mut_slice();
        scan.for_each_row_span(|row, lo, hi| {
            let base = row * w;
            crate::bits::insert_range(seen, base + lo, base + hi + 1, |i| {
                let cell = truth[i];
                cells[i] = cell;
                if cell.is_free() {
                    free[i / BLOCK_BITS] |= 1 << (i % BLOCK_BITS);
                }
                first_seen(i - base, row, cell);
            });
        });
    }

    /// Stores every pixel of a scan and calls `new_in_row(row, lo, hi)` once for each image
    /// row holding pixels seen for the first time, top to bottom: `lo` and `hi` are the first
    /// and last such column of the row (the pixels between them may include ones seen before).
    /// The same pixels are stored as by [`Self::integrate_with`], without a call per pixel.
    ///
    /// `prev`: the [`Scan::disk_px`] of the scan integrated last into this map (of the same
    /// true map), if any; the rows already in its range are skipped (the leading edge). Small
    /// scans ([`Scan::small_row_spans`]) visit every row instead: a row with nothing new costs
    /// a word of the seen bitset, less than deciding to skip it.
    pub(crate) fn integrate_rows(
        &mut self,
        scan: &Scan<'_>,
        prev: Option<(Point, f64)>,
        mut new_in_row: impl FnMut(usize, usize, usize),
    ) {
        let w = self.grid.frame().width;
        let truth = scan.map.cells();
        let cells = self.grid.cells_mut();
        let seen = self.seen.as_mut_slice();
        let free = self.free.as_mut_slice();
        let mut row_span = |row: usize, lo: usize, hi: usize| {
            let base = row * w;
            let (mut first, mut last) = (usize::MAX, 0);
            crate::bits::insert_range(seen, base + lo, base + hi + 1, |i| {
                let cell = truth[i];
                cells[i] = cell;
                if cell.is_free() {
                    free[i / BLOCK_BITS] |= 1 << (i % BLOCK_BITS);
                }
                first = first.min(i);
                last = i;
            });
            if first <= last {
                new_in_row(row, first - base, last - base);
            }
        };
        if !scan.small_row_spans(&mut row_span) {
            scan.row_spans_beyond(prev, row_span);
        }
    }

    /// The frame.
    pub fn frame(&self) -> &MapFrame {
        self.grid.frame()
    }

    /// Has pixel `(col, row)` been seen?
    pub fn is_seen(&self, col: usize, row: usize) -> bool {
        self.seen.contains(self.grid.frame().index(col, row))
    }

    /// The known value of a seen pixel (`Unknown` when unseen).
    pub fn get(&self, col: usize, row: usize) -> Cell {
        self.grid.get(col, row)
    }

    /// The pixels seen so far.
    pub fn seen(&self) -> &FixedBitSet {
        &self.seen
    }

    /// The pixels seen and free so far (those that never block the robot).
    pub fn known_free(&self) -> &FixedBitSet {
        &self.free
    }

    /// Calls `f(col, seen)` for each pixel of image row `row`, columns `col0..=col1` (inside
    /// the image), that is not known free (unseen, or seen and not free), in column order,
    /// until `f` returns `false`. Known-free pixels cost a bit each, a block at a time.
    #[inline]
    pub(crate) fn for_each_not_known_free(
        &self,
        row: usize,
        col0: usize,
        col1: usize,
        mut f: impl FnMut(usize, bool) -> bool,
    ) {
        let base = row * self.grid.frame().width;
        let free = self.free.as_slice();
        let seen = self.seen.as_slice();
        crate::bits::for_each_set(
            base + col0,
            base + col1 + 1,
            |k| !free[k],
            |i| f(i - base, seen[i / BLOCK_BITS] >> (i % BLOCK_BITS) & 1 == 1),
        );
    }

    /// Is every pixel of image rows `row0..=row1`, columns `col0..=col1` (inside the image)
    /// known free? A block of the bitset at a time.
    pub(crate) fn rect_known_free(
        &self,
        row0: usize,
        row1: usize,
        col0: usize,
        col1: usize,
    ) -> bool {
        if col0 > col1 {
            return true;
        }
        let w = self.grid.frame().width;
        let free = self.free.as_slice();
        for row in row0..=row1 {
            // Bits `a..=b` of the image: the first and last blocks masked, whole blocks between.
            let (a, b) = (row * w + col0, row * w + col1);
            let (ka, kb) = (a / BLOCK_BITS, b / BLOCK_BITS);
            let lo = usize::MAX << (a % BLOCK_BITS);
            let hi = usize::MAX >> (BLOCK_BITS - 1 - b % BLOCK_BITS);
            if ka == kb {
                if !free[ka] & lo & hi != 0 {
                    return false;
                }
                continue;
            }
            if !free[ka] & lo != 0
                || !free[kb] & hi != 0
                || free[ka + 1..kb].iter().any(|&v| v != usize::MAX)
            {
                return false;
            }
        }
        true
    }

    /// What is known of the disk of radius `rc` pixels at grid point `g`: the pixels whose
    /// centre `q` has `|q - g|^2 < rc^2` ([`crate::collide`]'s contact test with `rc` the
    /// contact radius). Blocked when one of them is seen blocked or lies outside the image,
    /// else unseen when one of them is not seen yet, else free.
    ///
    /// The predicate is convex in the column, so each row's pixels are the interval between
    /// the first and the last column satisfying it; the interval is read off the bitsets.
    pub(crate) fn disk_state(&self, g: Point, rc: f64) -> DiskState {
        let frame = *self.grid.frame();
        self.runs_state(
            disk_rows(&frame, g, rc)
                .filter_map(|row| disk_row_span(&frame, g, rc, row).map(|(lo, hi)| (row, lo, hi))),
        )
    }

    /// [`Self::disk_state`] at the centre of pixel `(col, row)`, with the disk given as
    /// [`pixel_disk_spans`] (centres are whole pixels apart, so the disk is the same integer
    /// pattern around every pixel and the predicate is exact in integers).
    pub(crate) fn disk_state_px(&self, col: i64, row: i64, spans: &[i64]) -> DiskState {
        let reach = spans.len() as i64 - 1;
        self.runs_state((-reach..=reach).filter_map(|dy| {
            let hw = spans[dy.unsigned_abs() as usize];
            (hw >= 0).then_some((row + dy, col - hw, col + hw))
        }))
    }

    /// What is known of the pixels in the runs `(row, lo, hi)` (signed; columns `lo..=hi`):
    /// blocked when one is seen blocked or lies outside the image, else unseen when one is not
    /// seen yet, else free.
    pub(crate) fn runs_state(&self, runs: impl Iterator<Item = (i64, i64, i64)>) -> DiskState {
        let frame = *self.grid.frame();
        let (w, hh) = (frame.width as i64, frame.height as i64);
        let mut unseen = false;
        for (row, lo, hi) in runs {
            // Outside the image every pixel is occupied (and seen).
            if row < 0
                || row >= hh
                || lo < 0
                || hi >= w
                || self.row_blocked(row as usize, lo as usize, hi as usize, &mut unseen)
            {
                return DiskState::Blocked;
            }
        }
        if unseen {
            DiskState::Unseen
        } else {
            DiskState::Free
        }
    }

    /// Does a seen blocked pixel lie in image row `row`, columns `lo..=hi`? Sets `unseen` when
    /// an unseen pixel lies there (before the first blocked one).
    pub(crate) fn row_blocked(&self, row: usize, lo: usize, hi: usize, unseen: &mut bool) -> bool {
        let mut blocked = false;
        self.for_each_not_known_free(row, lo, hi, |_, seen| {
            if seen {
                blocked = true;
                return false;
            }
            *unseen = true;
            true
        });
        blocked
    }

    /// Can the robot (radius `r` metres) stand at world point `p`, as far as it knows?
    pub fn disk_free(&self, p: Point, r: f64) -> bool {
        let f = self.grid.frame();
        !collide::disk_hits(self, f.world_to_grid(p), r / f.resolution)
    }

    /// Is the straight move from `a` to `b` free, as far as it knows?
    pub fn segment_free(&self, a: Point, b: Point, r: f64) -> bool {
        let f = self.grid.frame();
        collide::segment_first_contact(
            self,
            f.world_to_grid(a),
            f.world_to_grid(b),
            r / f.resolution,
        )
        .is_none()
    }

    /// Farthest free distance (metres, up to `max`) along heading `theta` from `p`, as far as it
    /// knows.
    pub fn free_distance(&self, p: Point, theta: f64, max: f64, r: f64) -> f64 {
        let f = self.grid.frame();
        let a = f.world_to_grid(p);
        let b = f.world_to_grid(Point::new(p.x + max * theta.cos(), p.y + max * theta.sin()));
        match collide::segment_first_contact(self, a, b, r / f.resolution) {
            Some(t) => t * max,
            None => max,
        }
    }
}

impl Occupancy for KnownMap {
    fn frame(&self) -> &MapFrame {
        self.grid.frame()
    }
    #[inline]
    fn blocked(&self, col: i64, row: i64) -> bool {
        match self.grid.frame().checked(col, row) {
            Some((c, r)) => !self.free.contains(self.grid.frame().index(c, r)),
            None => true,
        }
    }
    fn for_each_blocked_in_row(
        &self,
        row: usize,
        lo: usize,
        hi: usize,
        f: &mut dyn FnMut(usize) -> bool,
    ) {
        self.for_each_not_known_free(row, lo, hi, |col, _| f(col));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn row_spans_match_for_each() {
        let map = GridMap::filled(MapFrame::new(37, 23, 0.05), Cell::Free).expect("map");
        let mut seed = 3u64;
        let mut next = || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut small = 0;
        for k in 0..3000 {
            let center = Point::new(next() * 2.4 - 0.3, next() * 1.6 - 0.3);
            // Ranges on and off pixel-centre distances, down to nothing.
            let range = if k % 3 == 0 {
                (next() * 8.0).round() * 0.025
            } else {
                next() * 0.6
            };
            let scan = Scan::new(&map, center, range);
            let mut a = Vec::new();
            scan.for_each(|c, r, _| a.push((c, r)));
            let mut b = Vec::new();
            scan.for_each_row_span(|r, lo, hi| b.extend((lo..=hi).map(|c| (c, r))));
            assert_eq!(a, b, "centre {center:?} range {range}");
            let mut c = Vec::new();
            if scan.small_row_spans(|r, lo, hi| c.extend((lo..=hi).map(|c| (c, r)))) {
                assert_eq!(a, c, "small: centre {center:?} range {range}");
                small += 1;
            }
        }
        // Ranges up to 0.6 m are at most 25 px wide: most scans take the small path too.
        assert!(small > 1000, "{small}");
    }

    /// The leading edge: the rows `row_spans_beyond` leaves out hold only pixels in range of
    /// the earlier scan, and the rows it keeps are the full rows.
    #[test]
    fn leading_edge_rows_are_in_range_of_the_earlier_scan() {
        let map = GridMap::filled(MapFrame::new(61, 47, 0.05), Cell::Free).expect("map");
        let mut seed = 11u64;
        let mut next = || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut skipped = 0;
        for k in 0..4000 {
            let a = Point::new(next() * 3.0, next() * 2.3);
            // Moves along an axis (by whole and fractional pixels) and in any direction.
            let step = if k % 2 == 0 {
                (next() * 8.0).round() * 0.05
            } else {
                next() * 0.5
            };
            let dir = if k % 4 < 2 {
                f64::from((k / 4 % 4) as u8) * std::f64::consts::FRAC_PI_2
            } else {
                next() * std::f64::consts::TAU
            };
            let b = Point::new(a.x + step * dir.cos(), a.y + step * dir.sin());
            let range = if k % 3 == 0 {
                (next() * 10.0).round() * 0.05
            } else {
                next() * 0.6
            };
            let (sa, sb) = (Scan::new(&map, a, range), Scan::new(&map, b, range));
            let mut seen_a = std::collections::BTreeSet::new();
            sa.for_each(|c, r, _| {
                seen_a.insert((c, r));
            });
            let mut full = Vec::new();
            sb.for_each_row_span(|r, lo, hi| full.push((r, lo, hi)));
            let mut kept = Vec::new();
            sb.row_spans_beyond(Some(sa.disk_px()), |r, lo, hi| kept.push((r, lo, hi)));
            for &(r, lo, hi) in &full {
                if kept.contains(&(r, lo, hi)) {
                    continue;
                }
                skipped += 1;
                for c in lo..=hi {
                    assert!(
                        seen_a.contains(&(c, r)),
                        "{a:?} -> {b:?}, range {range}: {c},{r}"
                    );
                }
            }
            assert!(kept.iter().all(|s| full.contains(s)));
            // A different range: nothing left out.
            let mut other = Vec::new();
            sb.row_spans_beyond(Some((sa.disk_px().0, sa.disk_px().1 + 1.0)), |r, lo, hi| {
                other.push((r, lo, hi));
            });
            assert_eq!(other, full);
        }
        assert!(skipped > 1000, "{skipped}");
    }
}
