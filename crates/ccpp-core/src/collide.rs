//! Exact disk and swept-disk collision tests against a pixel grid.
//!
//! **Obstacle model** (one definition for the simulator and for every planner's own checks): a
//! non-free pixel is the disk inscribed in its square, i.e. a disk of radius half a pixel at the
//! pixel centre. A robot disk of radius `r` centred at `p` touches it when
//! `|p - centre| < r + res/2`. Adjacent blocked pixels therefore form a closed wall (no gap), and
//! a 1-pixel diagonal wall leaves gaps of `(sqrt 2 - 1)` px, too narrow for any robot of radius at
//! least half a pixel. The squares' corners stick out of their inscribed disks by at most
//! (sqrt 2 - 1)/2 px; that is the stated tolerance of the model.
//!
//! Computations here are in *grid coordinates* (pixels, y up, see
//! [`crate::grid::MapFrame::world_to_grid`]).

use crate::geometry::{first_entry, Point};
use crate::grid::{GridMap, MapFrame};

/// Contact tolerance in pixels: a disk at exactly `r + res/2` from a blocked centre is not in
/// contact (touching is allowed, overlapping is not).
pub const CONTACT_EPS_PX: f64 = 1e-6;

/// Anything that can say whether a pixel blocks the robot.
pub trait Occupancy {
    /// The grid's geometry.
    fn frame(&self) -> &MapFrame;
    /// `true` when pixel `(col, row)` (signed; outside the image) blocks the robot.
    fn blocked(&self, col: i64, row: i64) -> bool;
    /// Calls `f(col)` for each blocked pixel of image row `row`, columns `lo..=hi` (inside the
    /// image), left to right, until `f` returns `false`. The default asks [`Self::blocked`]
    /// pixel by pixel; bitset-backed grids skip free runs a word at a time.
    fn for_each_blocked_in_row(
        &self,
        row: usize,
        lo: usize,
        hi: usize,
        f: &mut dyn FnMut(usize) -> bool,
    ) {
        for col in lo..=hi {
            if self.blocked(col as i64, row as i64) && !f(col) {
                return;
            }
        }
    }
}

impl Occupancy for GridMap {
    fn frame(&self) -> &MapFrame {
        GridMap::frame(self)
    }
    #[inline]
    fn blocked(&self, col: i64, row: i64) -> bool {
        !self.get_signed(col, row).is_free()
    }
}

/// Contact radius in pixels for a robot of radius `r_px` pixels.
#[inline]
pub fn contact_radius_px(r_px: f64) -> f64 {
    r_px + 0.5 - CONTACT_EPS_PX
}

/// Centre (grid coordinates) of signed pixel `(col, row)`.
#[inline]
fn center(frame: &MapFrame, col: i64, row: i64) -> Point {
    Point::new(col as f64 + 0.5, (frame.height as i64 - row) as f64 - 0.5)
}

/// Signed pixel range (inclusive) whose centres may lie within `reach` of the box `lo..hi`
/// (grid coordinates).
#[inline]
fn pixel_window(frame: &MapFrame, lo: Point, hi: Point, reach: f64) -> (i64, i64, i64, i64) {
    let c0 = (lo.x - reach - 0.5).floor() as i64;
    let c1 = (hi.x + reach - 0.5).ceil() as i64;
    // gy = height - row - 0.5  =>  row = height - gy - 0.5
    let h = frame.height as f64;
    let r0 = (h - (hi.y + reach) - 0.5).floor() as i64;
    let r1 = (h - (lo.y - reach) - 0.5).ceil() as i64;
    (c0, c1, r0, r1)
}

/// The pixels examined around the image. Outside the image every pixel blocks, so only a band
/// of `ceil(rc) + 2` outside pixels matters (`rc` = [`contact_radius_px`]): a disk centred
/// farther out overlaps its own (outside) pixel, and a motion leaving the band from inside
/// meets a nearer outside pixel first. Both statements are exact for `rc > sqrt(1/2)` (a disk
/// that covers its own pixel's centre from anywhere in the pixel, i.e. `r_px > 0.21`); for
/// thinner disks, which can slip between pixel centres, they are a conservative bound. The work
/// of a test is thus bounded by the image size however far the robot is sent.
struct Band {
    /// Outside pixels examined on each side.
    width: i64,
    /// Lower-left corner of the covered box (grid coordinates).
    lo: Point,
    /// Upper-right corner.
    hi: Point,
}

impl Band {
    fn new(frame: &MapFrame, rc: f64) -> Self {
        // A NaN radius gives a NaN `rc`, which casts to 0.
        let band = rc.clamp(0.0, 1e9).ceil() as i64 + 2;
        Self {
            width: band,
            lo: Point::new(-band as f64, -band as f64),
            hi: Point::new(
                (frame.width as i64 + band) as f64,
                (frame.height as i64 + band) as f64,
            ),
        }
    }

    /// Is `p` inside the covered box (`false` for NaN)?
    fn contains(&self, p: Point) -> bool {
        p.x >= self.lo.x && p.x <= self.hi.x && p.y >= self.lo.y && p.y <= self.hi.y
    }

    /// `window` (from [`pixel_window`]) cut to the band.
    fn clip(&self, frame: &MapFrame, window: (i64, i64, i64, i64)) -> (i64, i64, i64, i64) {
        let (c0, c1, r0, r1) = window;
        let (w, h, b) = (frame.width as i64, frame.height as i64, self.width);
        (c0.max(-b - 1), c1.min(w + b), r0.max(-b - 1), r1.min(h + b))
    }

    /// Parameter `t` in `[0, 1]` at which the motion from `a` (inside the box) to `b` (outside
    /// it) leaves the box.
    fn exit_param(&self, a: Point, b: Point) -> f64 {
        let (dx, dy) = (b.x - a.x, b.y - a.y);
        let mut t = 1.0f64;
        for (d, room) in [
            (-dx, a.x - self.lo.x),
            (dx, self.hi.x - a.x),
            (-dy, a.y - self.lo.y),
            (dy, self.hi.y - a.y),
        ] {
            if d > 0.0 {
                t = t.min(room / d);
            }
        }
        t.clamp(0.0, 1.0)
    }
}

/// Does a robot disk of radius `r_px` (pixels) centred at grid point `p` overlap a blocked pixel?
/// Outside the image every pixel blocks; only a band of `ceil(rc) + 2` outside pixels is
/// examined (`rc` = [`contact_radius_px`]), and a disk centred beyond it hits.
pub fn disk_hits(occ: &impl Occupancy, p: Point, r_px: f64) -> bool {
    let rc = contact_radius_px(r_px);
    let rc2 = rc * rc;
    let frame = *occ.frame();
    let band = Band::new(&frame, rc);
    if !band.contains(p) {
        return true;
    }
    let (c0, c1, r0, r1) = band.clip(&frame, pixel_window(&frame, p, p, rc));
    for row in r0..=r1 {
        for col in c0..=c1 {
            if occ.blocked(col, row) && center(&frame, col, row).dist2(p) < rc2 {
                return true;
            }
        }
    }
    false
}

/// First parameter `t` in `[0, 1]` at which a disk of radius `r_px` moving from `a` to `b`
/// (grid coordinates) comes into contact with a blocked pixel; `None` when the whole motion is
/// free. Brute force over the swept capsule's bounding box: use for short motions, or call
/// through a distance-transform accelerated caller ([`crate::world::World::first_contact`]).
/// Only a band of `ceil(rc) + 2` outside pixels is examined (as in [`disk_hits`]): a motion
/// starting beyond it is in contact at `t = 0`.
pub fn segment_first_contact(occ: &impl Occupancy, a: Point, b: Point, r_px: f64) -> Option<f64> {
    let rc = contact_radius_px(r_px);
    let rc2 = rc * rc;
    let frame = *occ.frame();
    let band = Band::new(&frame, rc);
    if !band.contains(a) {
        return Some(0.0);
    }
    let lo = Point::new(a.x.min(b.x), a.y.min(b.y));
    let hi = Point::new(a.x.max(b.x), a.y.max(b.y));
    let window = band.clip(&frame, pixel_window(&frame, lo, hi, rc));
    let mut best: Option<f64> = None;
    // Earliest contact with the blocked pixel `(col, row)`; `false` once contact is at t = 0
    // (nothing can come earlier).
    let consider = |col: i64, row: i64| -> bool {
        let q = center(&frame, col, row);
        // Quick reject by distance to the segment.
        if crate::geometry::point_segment_dist2(q, a, b) >= rc2 {
            return true;
        }
        if let Some(t) = first_entry(a, b, q, rc) {
            if best.is_none_or(|bt| t < bt) {
                best = Some(t);
                if t == 0.0 {
                    return false;
                }
            }
        }
        true
    };
    // Outside the image every pixel blocks.
    if !for_each_blocked(occ, window, true, consider) {
        return best;
    }
    // Leaving the band without contact (only possible for disks thinner than a pixel's
    // diagonal): contact where the motion leaves the box.
    best.or_else(|| (!band.contains(b)).then(|| band.exit_param(a, b)))
}

/// The times a disk of radius `r_px` (pixels) moving from `a` to `b` (grid coordinates)
/// overlaps the blocked pixels whose centres lie within reach of the part `part` of that motion
/// (two points of it, in order): for each such pixel, the open interval of `t` in `[0, 1]`
/// during which the disk overlaps it (clipped to `[0, 1]`; a pixel the disk only touches adds
/// none), appended to `out`. The pixels [`Occupancy::blocked`] says are blocked, in the image
/// and in the band around it (as [`disk_hits`] asks; [`segment_first_contact`] counts every
/// pixel outside the image); calls over consecutive parts
/// cover the whole motion (a pixel near two parts is given twice). Exact per pixel, so the
/// union of the intervals does not depend on how the motion is cut into parts.
pub fn contact_intervals(
    occ: &impl Occupancy,
    a: Point,
    b: Point,
    part: (Point, Point),
    r_px: f64,
    out: &mut Vec<(f64, f64)>,
) {
    let rc = contact_radius_px(r_px);
    let rc2 = rc * rc;
    let frame = *occ.frame();
    let band = Band::new(&frame, rc);
    let (p, q) = part;
    let lo = Point::new(p.x.min(q.x), p.y.min(q.y));
    let hi = Point::new(p.x.max(q.x), p.y.max(q.y));
    let window = band.clip(&frame, pixel_window(&frame, lo, hi, rc));
    let d = b - a;
    let aa = d.dot(d);
    if aa.is_nan() || aa <= 0.0 {
        return;
    }
    let mut add = |col: i64, row: i64| {
        let c = center(&frame, col, row);
        let f = a - c;
        let bb = 2.0 * f.dot(d);
        let cc = f.dot(f) - rc2;
        let disc = bb * bb - 4.0 * aa * cc;
        if disc.is_nan() || disc <= 0.0 {
            return;
        }
        let sq = disc.sqrt();
        let t0 = ((-bb - sq) / (2.0 * aa)).max(0.0);
        let t1 = ((-bb + sq) / (2.0 * aa)).min(1.0);
        if t0 < t1 {
            out.push((t0, t1));
        }
    };
    // Outside the image as `occ` says (as `disk_hits` asks it, so that an overlap the
    // intervals begin at 0 is one `disk_hits` sees at the start).
    for_each_blocked(occ, window, false, |col, row| {
        add(col, row);
        true
    });
}

/// Calls `f` on the blocked pixels `(col, row)` of the signed pixel window `(c0, c1, r0, r1)`
/// (inclusive, already cut to the band around the image), row by row: those of the image as
/// [`Occupancy::for_each_blocked_in_row`] gives them, and outside the image every pixel when
/// `outside_blocks`, else those [`Occupancy::blocked`] says. Stops as soon as `f` returns
/// `false`; returns whether it went through the whole window.
#[inline]
fn for_each_blocked(
    occ: &impl Occupancy,
    window: (i64, i64, i64, i64),
    outside_blocks: bool,
    mut f: impl FnMut(i64, i64) -> bool,
) -> bool {
    let (c0, c1, r0, r1) = window;
    let frame = occ.frame();
    let (w, h) = (frame.width as i64, frame.height as i64);
    for row in r0..=r1 {
        let in_image = (0..h).contains(&row);
        // The window's pixels outside the image: the whole row, or its ends.
        let (left, right) = if in_image {
            (c0..=c1.min(-1), c0.max(w)..=c1)
        } else {
            (c0..=c1, c1 + 1..=c1)
        };
        for col in left.chain(right) {
            if (outside_blocks || occ.blocked(col, row)) && !f(col, row) {
                return false;
            }
        }
        if !in_image {
            continue;
        }
        let (lo, hi) = (c0.max(0), c1.min(w - 1));
        if lo <= hi {
            let mut go = true;
            occ.for_each_blocked_in_row(row as usize, lo as usize, hi as usize, &mut |col| {
                go = f(col as i64, row);
                go
            });
            if !go {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs `f` on a helper thread and fails if it takes longer than `secs` seconds.
    fn within<T: Send + 'static>(secs: u64, f: impl FnOnce() -> T + Send + 'static) -> T {
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let _ = tx.send(f());
        });
        rx.recv_timeout(std::time::Duration::from_secs(secs))
            .expect("did not finish in time")
    }

    #[test]
    fn astronomically_long_motions_are_bounded_by_the_image() {
        // Found by fuzzing `--config` (bsa-bfs `cell_side_m: 1.1e49`): the brute force walked
        // every outside pixel of the motion's bounding box and never returned.
        let g: GridMap = "..........\n".repeat(10).trim_end().parse().unwrap();
        let a = Point::new(5.0, 5.0);
        let short = segment_first_contact(&g, a, Point::new(25.0, 5.0), 1.0).unwrap();
        let (long, diag, back) = within(20, move || {
            (
                segment_first_contact(&g, a, Point::new(5.0 + 1e12, 5.0), 1.0),
                segment_first_contact(&g, a, Point::new(-1e49, 1e49), 1.0),
                segment_first_contact(&g, Point::new(1e12, 5.0), a, 1.0),
            )
        });
        // The same contact point (against the outside column) however far the target is.
        let x_short = 5.0 + 20.0 * short;
        let x_long = 5.0 + 1e12 * long.unwrap();
        assert!((x_short - x_long).abs() < 1e-3, "{x_short} vs {x_long}");
        assert!(x_short > 9.0 && x_short < 10.0, "{x_short}");
        assert!(diag.is_some_and(|t| t > 0.0 && t < 1e-47), "{diag:?}");
        // Starting far outside the image is contact at once; so is standing there (the pixel
        // window overflowed `i64` in `center` for such points).
        assert_eq!(back, Some(0.0));
        let g: GridMap = "...\n...".parse().unwrap();
        assert!(disk_hits(&g, Point::new(1e30, -1e49), 1.0));
        assert!(disk_hits(&g, Point::new(f64::NAN, 1.0), 1.0));
        assert!(!disk_hits(&g, Point::new(1.5, 1.0), 0.4));
    }

    #[test]
    fn disk_against_wall() {
        // Wall pixel centre at gx = 0.5 (col 0); robot r = 1 px: contact when x < 2.0.
        let g: GridMap = "#.....\n#.....\n#.....".parse().unwrap();
        assert!(!disk_hits(&g, Point::new(2.0, 1.5), 1.0));
        assert!(disk_hits(&g, Point::new(1.99, 1.5), 1.0));
        // The border (outside) is occupied: top edge at gy = 3, outside centres at 3.5.
        assert!(disk_hits(&g, Point::new(3.0, 2.2), 1.0));
        assert!(!disk_hits(&g, Point::new(3.0, 1.5), 1.0));
    }

    #[test]
    fn sweep_stops_at_contact() {
        let g: GridMap = "..........#".parse().unwrap();
        // Moving right at gy = 0.5 with r = 0 px: contact radius ~0.5 around centre 10.5.
        let t =
            segment_first_contact(&g, Point::new(0.5, 0.5), Point::new(10.5, 0.5), 0.0).unwrap();
        assert!((0.5 + 10.0 * t - 10.0).abs() < 1e-5);
        assert_eq!(
            segment_first_contact(&g, Point::new(0.5, 0.5), Point::new(9.0, 0.5), 0.0),
            None
        );
    }
}
