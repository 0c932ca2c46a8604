//! Judging standability and moves from the known map: [`Judgement`] and [`judge_motion`].

use crate::collide::contact_radius_px;
use crate::geometry::{ceil_i64, first_entry, floor_i64, point_segment_dist2, Point};
use crate::planner::{DiskState, KnownMap};

/// How much wider than the contact radius (pixels) [`judge_motion_px`] finds the part of a
/// segment near a row.
const YPAD: f64 = 1e-6;

/// Rows [`judge_motion_px`] first looks at together.
const ROW_BLOCK: i64 = 8;

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
    scan_motion_px(known, ga, gb, rc, None)
}

/// Is the straight move between world points `a` and `b` known free ([`judge_motion`] gives
/// [`Judgement::Free`]) for a robot of radius `r` metres? Stops at the first pixel that
/// decides "no", seen or not, and keeps it in `witness`: a later call whose move that pixel
/// touches too answers "no" at once (the caller keeps the known map unchanged while it reuses
/// `witness`; `None` to begin with).
pub(crate) fn motion_known_free(
    known: &KnownMap,
    a: Point,
    b: Point,
    r: f64,
    witness: &mut Option<(i64, i64)>,
) -> bool {
    let frame = known.frame();
    let ga = frame.world_to_grid(a);
    let gb = frame.world_to_grid(b);
    let rc = contact_radius_px(r / frame.resolution);
    free_px_with(known, ga, gb, rc, witness)
}

/// [`motion_known_free`] between grid points `ga` and `gb` for the contact radius `rc` pixels.
fn free_px_with(
    known: &KnownMap,
    ga: Point,
    gb: Point,
    rc: f64,
    witness: &mut Option<(i64, i64)>,
) -> bool {
    if ga == gb {
        return judge_point(known, ga, rc) == Judgement::Free;
    }
    if let Some((col, row)) = *witness {
        let q = Point::new(
            col as f64 + 0.5,
            known.frame().height as f64 - row as f64 - 0.5,
        );
        if point_segment_dist2(q, ga, gb) < rc * rc && first_entry(ga, gb, q, rc).is_some() {
            return false;
        }
    }
    scan_motion_px(known, ga, gb, rc, Some(witness)) == Judgement::Free
}

/// [`judge_motion_px`]'s body. With `witness` it answers only "free or not": it stops at the
/// first touching pixel that is not known free (seen or not; its verdict is then `Blocked` or
/// `Undetermined`, not necessarily the one [`judge_motion_px`] gives) and writes it there.
fn scan_motion_px(
    known: &KnownMap,
    ga: Point,
    gb: Point,
    rc: f64,
    mut witness: Option<&mut Option<(i64, i64)>>,
) -> Judgement {
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
    // Each row's window: the pixels whose centre is within `rc` (in x) of the part of the
    // segment within `rc` (in y) of the row. That part is found for a radius a hair wider
    // (`YPAD`, far above the rounding of the parameters), so it holds the exact part; the
    // columns then need a margin only for rounding (`eps`, as the box above).
    let (rlo, rhi) = (-rc - YPAD - ga.y, rc + YPAD - ga.y);
    let inv_dy = 1.0 / dy;
    // The columns of the pixels within `rc` (in x) of the part of the segment whose y lies
    // within `rc` of the rows with centres `gy_lo..=gy_hi`, or `None`.
    let window = |gy_lo: f64, gy_hi: f64| -> Option<(i64, i64)> {
        let (tl, th) = if dy == 0.0 {
            if ga.y < gy_lo - rc - 1e-9 || ga.y > gy_hi + rc + 1e-9 {
                return None;
            }
            (0.0, 1.0)
        } else {
            let t1 = (gy_lo + rlo) * inv_dy;
            let t2 = (gy_hi + rhi) * inv_dy;
            (t1.min(t2).max(0.0), t1.max(t2).min(1.0))
        };
        if tl > th + 1e-12 {
            return None;
        }
        let xa = ga.x + tl * dx;
        let xb = ga.x + th * dx;
        Some((
            ceil_i64(xa.min(xb) - rc - 0.5 - eps),
            floor_i64(xa.max(xb) + rc - 0.5 + eps),
        ))
    };
    let mut block_free_to = row0 - 1;
    for row in row0..=row1 {
        // A block of rows at a time first: the union of their windows inside the image and
        // known free, none of them can block (long moves through the open: one look per
        // block instead of one window per row).
        if row > block_free_to && (row - row0) % ROW_BLOCK == 0 {
            let last = (row + ROW_BLOCK - 1).min(row1);
            let (gy_lo, gy_hi) = (h - last as f64 - 0.5, h - row as f64 - 0.5);
            match window(gy_lo, gy_hi) {
                None => {
                    block_free_to = last;
                }
                Some((c0, c1)) => {
                    if row >= 0
                        && last < hh
                        && c0 >= 0
                        && c1 < w
                        && (c0 > c1
                            || known.rect_known_free(
                                row as usize,
                                last as usize,
                                c0 as usize,
                                c1 as usize,
                            ))
                    {
                        block_free_to = last;
                    }
                }
            }
        }
        if row <= block_free_to {
            continue;
        }
        let gy = h - row as f64 - 0.5;
        let Some((c0, c1)) = window(gy, gy) else {
            continue;
        };
        let touches = |col: i64| {
            let q = Point::new(col as f64 + 0.5, gy);
            point_segment_dist2(q, ga, gb) < rc2 && first_entry(ga, gb, q, rc).is_some()
        };
        // Outside the image every pixel is occupied (and seen).
        if row < 0 || row >= hh {
            if let Some(col) = (c0..=c1).find(|&c| touches(c)) {
                if let Some(wit) = witness.as_deref_mut() {
                    *wit = Some((col, row));
                }
                return Judgement::Blocked;
            }
            continue;
        }
        if let Some(col) = (c0..=c1.min(-1))
            .find(|&c| touches(c))
            .or_else(|| (c0.max(w)..=c1).find(|&c| touches(c)))
        {
            if let Some(wit) = witness.as_deref_mut() {
                *wit = Some((col, row));
            }
            return Judgement::Blocked;
        }
        let (lo, hi) = (c0.max(0), c1.min(w - 1));
        if lo > hi {
            continue;
        }
        // Inside: seen free pixels never matter, whatever their distance; visit the others.
        let mut blocked = false;
        let stop_unseen = witness.is_some();
        let mut hit = None;
        known.for_each_not_known_free(row as usize, lo as usize, hi as usize, |col, seen| {
            if !touches(col as i64) {
                return true;
            }
            if seen {
                blocked = true;
                hit = Some(col);
                return false;
            }
            undetermined = true;
            if stop_unseen {
                hit = Some(col);
                return false;
            }
            true
        });
        if let (Some(col), Some(wit)) = (hit, witness.as_deref_mut()) {
            *wit = Some((col as i64, row));
            return if blocked {
                Judgement::Blocked
            } else {
                Judgement::Undetermined
            };
        }
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

#[cfg(test)]
mod tests {
    use super::{free_px_with, judge_motion_px, Judgement};
    use crate::geometry::{ceil_i64, first_entry, floor_i64, point_segment_dist2, Point};
    use crate::grid::{Cell, GridMap, MapFrame};
    use crate::planner::{KnownMap, Scan};

    /// The verdict by brute force: every pixel of a box around the capsule, inside the image
    /// or not, tested with the contact predicate.
    fn brute(known: &KnownMap, ga: Point, gb: Point, rc: f64) -> Judgement {
        let f = *known.frame();
        let h = f.height as f64;
        let (w, hh) = (f.width as i64, f.height as i64);
        let rows = floor_i64(h - ga.y.max(gb.y) - rc - 0.5) - 2
            ..=ceil_i64(h - ga.y.min(gb.y) + rc - 0.5) + 2;
        let cols =
            floor_i64(ga.x.min(gb.x) - rc - 0.5) - 2..=ceil_i64(ga.x.max(gb.x) + rc - 0.5) + 2;
        let mut unseen = false;
        for row in rows {
            for col in cols.clone() {
                let q = Point::new(col as f64 + 0.5, h - row as f64 - 0.5);
                if point_segment_dist2(q, ga, gb) >= rc * rc || first_entry(ga, gb, q, rc).is_none()
                {
                    continue;
                }
                if row < 0 || row >= hh || col < 0 || col >= w {
                    return Judgement::Blocked;
                }
                let i = f.index(col as usize, row as usize);
                if known.known_free().contains(i) {
                    continue;
                }
                if known.seen().contains(i) {
                    return Judgement::Blocked;
                }
                unseen = true;
            }
        }
        if unseen {
            Judgement::Undetermined
        } else {
            Judgement::Free
        }
    }

    /// The row windows give the brute-force verdict: random maps with walls, clutter and
    /// unseen parts, moves between pixel centres (the extension's), along walls, axis-aligned
    /// and random, for contact radii of a few pixels, out of the image too.
    #[test]
    fn judge_motion_px_matches_brute_force() {
        let mut rng = crate::rng::SplitMix64::new(0x1d6e_5eed);
        let mut counts = [0usize; 3];
        let mut witnessed = 0usize;
        for round in 0..60 {
            let (w, h) = (40 + round % 7, 30 + round % 5);
            let mut cells = vec![Cell::Free; w * h];
            for (k, c) in cells.iter_mut().enumerate() {
                let (col, row) = (k % w, k / w);
                let u = rng.next_f64();
                if col == 5 + round % 3 || row == 25 || u < 0.004 {
                    *c = Cell::Occupied;
                } else if u < 0.008 {
                    *c = Cell::Unknown;
                }
            }
            let truth = GridMap::new(MapFrame::new(w, h, 0.05), cells).unwrap();
            let mut known = KnownMap::new(truth.frame());
            for _ in 0..3 {
                let c = Point::new(
                    rng.range(0.0, w as f64 * 0.05),
                    rng.range(0.0, h as f64 * 0.05),
                );
                known.integrate(&Scan::new(&truth, c, rng.range(0.5, 2.0)));
            }
            let rc = crate::collide::contact_radius_px(rng.range(0.5, 7.0));
            let mut witness = None;
            for k in 0..400 {
                let pick = |rng: &mut crate::rng::SplitMix64| {
                    let x = rng.range(-2.0, w as f64 + 2.0);
                    let y = rng.range(-2.0, h as f64 + 2.0);
                    if k % 2 == 0 {
                        Point::new(x.floor() + 0.5, y.floor() + 0.5)
                    } else {
                        Point::new(x, y)
                    }
                };
                let ga = pick(&mut rng);
                let mut gb = match k % 5 {
                    0 => Point::new(ga.x + rng.range(-12.0, 12.0).round(), ga.y),
                    1 => Point::new(ga.x, ga.y + rng.range(-12.0, 12.0).round()),
                    2 => {
                        let t = rng.range(-10.0, 10.0).round();
                        Point::new(ga.x + t, ga.y + t)
                    }
                    _ => pick(&mut rng),
                };
                if k % 11 == 3 {
                    // Axis-aligned up to a round trip through world coordinates.
                    gb = Point::new(gb.x, ga.y + 1e-12 * rng.range(-1.0, 1.0));
                } else if k % 11 == 4 {
                    gb = Point::new(ga.x + 1e-12 * rng.range(-1.0, 1.0), gb.y);
                }
                if k % 7 == 0 {
                    gb = Point::new(
                        ga.x + rng.range(-1.0, 1.0).round(),
                        ga.y + rng.range(-1.0, 1.0).round(),
                    );
                }
                let want = brute(&known, ga, gb, rc);
                assert_eq!(
                    judge_motion_px(&known, ga, gb, rc),
                    want,
                    "{ga:?} {gb:?} rc {rc}"
                );
                // The free-or-not answer, fresh and with the pixel that decided an earlier
                // move (same map) asked first.
                assert_eq!(
                    free_px_with(&known, ga, gb, rc, &mut None),
                    want == Judgement::Free,
                    "{ga:?} {gb:?} rc {rc}"
                );
                let before = witness;
                assert_eq!(
                    free_px_with(&known, ga, gb, rc, &mut witness),
                    want == Judgement::Free,
                    "{ga:?} {gb:?} rc {rc} witness {before:?}"
                );
                if before != witness {
                    witnessed += 1;
                }
                counts[want as usize] += 1;
            }
        }
        assert!(counts.iter().all(|&n| n > 100), "{counts:?}");
        assert!(witnessed > 100, "{witnessed}");
    }
}
