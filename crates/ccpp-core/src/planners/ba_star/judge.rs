//! Judging standability and moves from the known map: [`Judgement`] and [`judge_motion`].

use crate::collide::contact_radius_px;
use crate::geometry::{ceil_i64, first_entry, floor_i64, point_segment_dist2, Point};
use crate::planner::{DiskState, KnownMap};

/// A three-valued verdict from partial knowledge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Judgement {
    /// Not all pixels that matter have been seen and none of the seen ones blocks.
    Undetermined = 0,
    /// Every pixel that matters has been seen and none blocks.
    Free = 1,
    /// A seen blocked pixel (or the outside of the map) blocks.
    Blocked = 2,
}

impl Judgement {
    #[inline]
    pub(super) fn from_bits(b: u8) -> Self {
        match b & 3 {
            1 => Judgement::Free,
            2 => Judgement::Blocked,
            _ => Judgement::Undetermined,
        }
    }
}

/// Judges the straight motion of the robot disk (radius `r` metres) from world point `a` to `b`
/// (`a == b`: standing at `a`) on the known map. `Free` is exactly [`KnownMap::segment_free`]
/// (resp. [`KnownMap::disk_free`]); `Blocked` means blocked whatever the unseen pixels hold.
///
/// Visits only the pixels near the segment (row spans of the swept capsule), so long segments
/// cost `O(length * r)`, not the area of their bounding box.
pub fn judge_motion(known: &KnownMap, a: Point, b: Point, r: f64) -> Judgement {
    let frame = known.frame();
    let ga = frame.world_to_grid(a);
    let gb = frame.world_to_grid(b);
    let rc = contact_radius_px(r / frame.resolution);
    judge_motion_px(known, ga, gb, rc)
}

/// [`judge_motion`] between grid points `ga` and `gb` (continuous grid coordinates of the two
/// world points) for the contact radius `rc` pixels of the robot.
pub(super) fn judge_motion_px(known: &KnownMap, ga: Point, gb: Point, rc: f64) -> Judgement {
    let frame = *known.frame();
    let rc2 = rc * rc;
    let h = frame.height as f64;
    if ga == gb {
        return judge_point(known, ga, rc);
    }
    let (dx, dy) = (gb.x - ga.x, gb.y - ga.y);
    let ylo = ga.y.min(gb.y) - rc;
    let yhi = ga.y.max(gb.y) + rc;
    // Pixel centre of row `row` is at gy = h - row - 0.5.
    let row0 = floor_i64(h - yhi - 0.5) - 1;
    let row1 = ceil_i64(h - ylo - 0.5) + 1;
    let (w, hh) = (frame.width as i64, frame.height as i64);
    // Fast path: every pixel that can touch has its centre within `rc` of the segment, so in
    // the capsule's bounding box grown by `rc` (with a margin for rounding far below the
    // contact epsilon, so the pixels at exactly `r + 1/2` from a tile centre, which never
    // touch, stay out: for one-pixel tiles the box of a move is then just its two pixels).
    // That box inside the image and entirely known free: free.
    let eps = 1e-7;
    let cmin = ceil_i64(ga.x.min(gb.x) - rc - 0.5 - eps);
    let cmax = floor_i64(ga.x.max(gb.x) + rc - 0.5 + eps);
    let rmin = ceil_i64(h - yhi - 0.5 - eps);
    let rmax = floor_i64(h - ylo - 0.5 + eps);
    if 0 <= rmin
        && rmin <= rmax
        && rmax < hh
        && cmin <= cmax
        && cmin >= 0
        && cmax < w
        && (rmax - rmin + 1) * (cmax - cmin + 1) <= 1024
        && known.rect_known_free(rmin as usize, rmax as usize, cmin as usize, cmax as usize)
    {
        return Judgement::Free;
    }
    let mut undetermined = false;
    for row in row0..=row1 {
        let gy = h - row as f64 - 0.5;
        // Parameter range of the segment whose y lies within rc of this row.
        let (tl, th) = if dy == 0.0 {
            if (ga.y - gy).abs() > rc + 1e-9 {
                continue;
            }
            (0.0, 1.0)
        } else {
            let t1 = (gy - rc - ga.y) / dy;
            let t2 = (gy + rc - ga.y) / dy;
            (t1.min(t2).max(0.0), t1.max(t2).min(1.0))
        };
        if tl > th + 1e-12 {
            continue;
        }
        let xa = ga.x + tl * dx;
        let xb = ga.x + th * dx;
        let c0 = floor_i64(xa.min(xb) - rc - 0.5) - 1;
        let c1 = ceil_i64(xa.max(xb) + rc - 0.5) + 1;
        let touches = |col: i64| {
            let q = Point::new(col as f64 + 0.5, gy);
            point_segment_dist2(q, ga, gb) < rc2 && first_entry(ga, gb, q, rc).is_some()
        };
        // Outside the image every pixel is occupied (and seen).
        if row < 0 || row >= hh {
            if (c0..=c1).any(touches) {
                return Judgement::Blocked;
            }
            continue;
        }
        if (c0..=c1.min(-1)).any(touches) || (c0.max(w)..=c1).any(touches) {
            return Judgement::Blocked;
        }
        let (lo, hi) = (c0.max(0), c1.min(w - 1));
        if lo > hi {
            continue;
        }
        // Inside: seen free pixels never matter, whatever their distance; visit the others.
        let mut blocked = false;
        known.for_each_not_known_free(row as usize, lo as usize, hi as usize, |col, seen| {
            if !touches(col as i64) {
                return true;
            }
            if seen {
                blocked = true;
                return false;
            }
            undetermined = true;
            true
        });
        if blocked {
            return Judgement::Blocked;
        }
    }
    if undetermined {
        Judgement::Undetermined
    } else {
        Judgement::Free
    }
}

/// [`judge_motion`] for a motionless disk at grid point `g` (contact radius `rc` pixels): the
/// same predicate (`|q - g|^2 < rc^2` for a pixel centre `q`), by [`KnownMap::disk_state`].
pub(super) fn judge_point(known: &KnownMap, g: Point, rc: f64) -> Judgement {
    known.disk_state(g, rc).into()
}

impl From<DiskState> for Judgement {
    fn from(s: DiskState) -> Self {
        match s {
            DiskState::Free => Judgement::Free,
            DiskState::Blocked => Judgement::Blocked,
            DiskState::Unseen => Judgement::Undetermined,
        }
    }
}
