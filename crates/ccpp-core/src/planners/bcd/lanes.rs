//! Lanes fitted to each cell (step 2 of the module docs): lane placement, lane ends pushed to
//! the walls, the per-cell direction and the cell paths.

use std::ops::{Add, Sub};

use super::cells::Cell;
use super::lattice::{Ctx, Lattice};
use super::transfer::Search;
use crate::geometry::Point;

/// Gap kept between a pushed lane end and the exact contact (pixels).
const BACKOFF_PX: f64 = 0.05;

impl Ctx<'_> {
    /// Grid point of continuous line coordinate `t` (lattice points at integers) and lattice
    /// position `v` (may be fractional or outside the lattice) of `cell`'s orientation.
    fn at(lat: &Lattice, cols: bool, t: f64, v: f64) -> Point {
        if cols {
            lat.grid(t, v)
        } else {
            lat.grid(v, t)
        }
    }

    /// The end on side `hi` of the lane at line coordinate `t` of `cell` (between the lines
    /// `floor t` and `ceil t`): from the end of the two runs' common part, pushed along the
    /// lane to the exact contact (minus [`BACKOFF_PX`]) or, where nothing is hit, to the end
    /// of the longer run.
    fn lane_end(&self, lat: &Lattice, cell: &Cell, t: f64, hi: bool) -> Point {
        let (u0, u1) = (cell.u0, cell.u1());
        let a = (t.floor().max(u0 as f64) as usize).min(u1);
        let b = (t.ceil().max(u0 as f64) as usize).min(u1);
        let (ra, rb) = (cell.runs[a - u0], cell.runs[b - u0]);
        let (mut i0, mut i1) = (ra.0.max(rb.0), ra.1.min(rb.1));
        let (n0, n1) = (ra.0.min(rb.0), ra.1.max(rb.1));
        if i0 > i1 {
            // The runs do not overlap (cannot happen inside a cell): use the nearer line's.
            let r = if t - a as f64 <= 0.5 { ra } else { rb };
            (i0, i1) = r;
        }
        let (v_in, v_out, v_end) = if hi {
            (i1 as f64, n1 as f64 + 1.0, n1 as f64)
        } else {
            (i0 as f64, n0 as f64 - 1.0, n0 as f64)
        };
        let p = Self::at(lat, cell.cols, t, v_in);
        let q = Self::at(lat, cell.cols, t, v_out);
        let len = (v_out - v_in).abs();
        match self.world.first_contact_grid(p, q) {
            Some(s) if s * len > BACKOFF_PX => p.add(q.sub(p).scale(s - BACKOFF_PX / len)),
            Some(_) => p,
            None => Self::at(lat, cell.cols, t, v_end),
        }
    }
}

/// Share of the pixels of `cell`'s line `u` whose outer neighbour (towards `out` = -1 or +1
/// along the lines) passes `other`, at least one half?
pub(super) fn side_open(
    lat: &Lattice,
    cell: &Cell,
    u: usize,
    out: i64,
    other: &dyn Fn(usize) -> bool,
) -> bool {
    let (a, b) = cell.runs[u - cell.u0];
    let w = lat.w;
    let n = (a..=b)
        .filter(|&v| {
            let (c, r) = cell.px(u, v);
            let (c, r) = if cell.cols {
                (c as i64 + out, r as i64)
            } else {
                (c as i64, r as i64 + out)
            };
            lat.ok_at(c, r) && other(r as usize * w + c as usize)
        })
        .count();
    2 * n > b - a
}

/// The lane positions (line coordinates) of `cell` (module docs, step 2): a lane on each
/// closed side and the lines `phase + k sp` in between, shared with the neighbours across open
/// sides. A cell closed on both sides shares no lane with a neighbour: its lanes are spread
/// evenly between its two edge lines, as few as keep every gap at most `sp`.
pub(super) fn lanes_of(cell: &Cell, sp: f64, phase: f64, open_lo: bool, open_hi: bool) -> Vec<f64> {
    let (u0, u1) = (cell.u0 as f64, cell.u1() as f64);
    if !open_lo && !open_hi {
        let gaps = ((u1 - u0) / sp - 1e-9).ceil();
        if gaps < 1.0 {
            return vec![u0];
        }
        return (0..=gaps as usize)
            .map(|k| u0 + (u1 - u0) * k as f64 / gaps)
            .collect();
    }
    let mut lanes: Vec<f64> = Vec::new();
    if !open_lo {
        lanes.push(u0);
    }
    // Lattice lines in [u0 - 1/2, u1 + 1/2): every line belongs to exactly one of the cells
    // that meet along the lines, whatever the rounding.
    let mut k = ((u0 - 0.5 - phase) / sp).floor();
    loop {
        let t = phase + k * sp;
        if t >= u1 + 0.5 {
            break;
        }
        if t >= u0 - 0.5 && lanes.last().is_none_or(|&l| t.max(u0) - l > 1e-6) {
            lanes.push(t.clamp(u0, u1));
        }
        k += 1.0;
    }
    if !open_hi && lanes.last().is_none_or(|&l| u1 - l > 1e-6) {
        lanes.push(u1);
    }
    lanes
}

/// The pixel positions `v` that the lane at line coordinate `t` of `cell` surely spans: the
/// common part of the runs of the lines on either side of it.
fn lane_span(cell: &Cell, t: f64) -> Option<(usize, usize)> {
    let (u0, u1) = (cell.u0, cell.u1());
    let a = (t.floor().max(u0 as f64) as usize).min(u1);
    let b = (t.ceil().max(u0 as f64) as usize).min(u1);
    let (ra, rb) = (cell.runs[a - u0], cell.runs[b - u0]);
    let (v0, v1) = (ra.0.max(rb.0), ra.1.min(rb.1));
    (v0 <= v1).then_some((v0, v1))
}

/// Calls `f` with every pixel index (image `w` x `h`) that the lanes of `cell` surely sweep:
/// the pixel centres within `rt` of a lane, across it, along its sure span.
fn for_lane_pixels(
    cell: &Cell,
    lanes: &[f64],
    w: usize,
    h: usize,
    rt: f64,
    f: &mut dyn FnMut(usize),
) {
    let nu = if cell.cols { w } else { h };
    for &t in lanes {
        let Some((v0, v1)) = lane_span(cell, t) else {
            continue;
        };
        let ua = (t - rt).ceil().max(0.0) as usize;
        let ub = ((t + rt).floor().max(0.0) as usize).min(nu - 1);
        for u in ua..=ub {
            for v in v0..=v1 {
                let (c, r) = cell.px(u, v);
                f(r * w + c);
            }
        }
    }
}

/// Drops the cells whose every pixel the lanes of other cells already sweep (module docs,
/// step 2), the cells with the least lane length first.
pub(super) fn drop_covered(
    cells: Vec<(Cell, Vec<f64>)>,
    w: usize,
    h: usize,
    rt: f64,
) -> Vec<(Cell, Vec<f64>)> {
    // How many cells' lanes sweep each pixel.
    let mut count = vec![0u16; w * h];
    let mut last = vec![u32::MAX; w * h];
    for (k, (c, l)) in cells.iter().enumerate() {
        for_lane_pixels(c, l, w, h, rt, &mut |i| {
            if last[i] != k as u32 {
                last[i] = k as u32;
                count[i] = count[i].saturating_add(1);
            }
        });
    }
    let lane_len = |c: &Cell, l: &[f64]| -> usize {
        l.iter()
            .filter_map(|&t| lane_span(c, t))
            .map(|(a, b)| b - a + 1)
            .sum()
    };
    let mut order: Vec<usize> = (0..cells.len()).collect();
    order.sort_by_key(|&k| (lane_len(&cells[k].0, &cells[k].1), k));
    let mut keep = vec![true; cells.len()];
    let mut mine = vec![false; w * h];
    let mut touched: Vec<usize> = Vec::new();
    for k in order {
        let (c, l) = &cells[k];
        touched.clear();
        for_lane_pixels(c, l, w, h, rt, &mut |i| {
            if !mine[i] {
                mine[i] = true;
                touched.push(i);
            }
        });
        let covered = c.runs.iter().enumerate().all(|(j, &(a, b))| {
            (a..=b).all(|v| {
                let (cc, rr) = c.px(c.u0 + j, v);
                let i = rr * w + cc;
                count[i] > u16::from(mine[i])
            })
        });
        if covered {
            keep[k] = false;
            for &i in &touched {
                count[i] -= 1;
            }
        }
        for &i in &touched {
            mine[i] = false;
        }
    }
    cells
        .into_iter()
        .zip(keep)
        .filter_map(|(c, k)| k.then_some(c))
        .collect()
}

/// Estimated cost of sweeping `cell` with `lanes`: lane lengths, the span between the first
/// and last lane, and `turn_px` per turn (two per lane).
pub(super) fn estimate(cell: &Cell, lanes: &[f64], turn_px: f64) -> f64 {
    if lanes.is_empty() {
        return 0.0;
    }
    let len: f64 = lanes
        .iter()
        .map(|&t| {
            let u = (t.round() as usize).clamp(cell.u0, cell.u1());
            let (a, b) = cell.runs[u - cell.u0];
            (b - a) as f64
        })
        .sum();
    let span = lanes[lanes.len() - 1] - lanes[0];
    len + span + turn_px * (2 * lanes.len()) as f64
}

/// The cells with every cell of an even number `n` of lanes cut into two cells of the same
/// pixels holding its first `k` and its last `n - k` lanes, both odd (`k` = `n / 2` or the odd
/// number just below it), so each leaves on the side opposite its entry (module docs, step 4).
/// Other cells are kept as they are, and the order of cells and lanes is kept.
pub(super) fn odd_runs(cells: &[(Cell, Vec<f64>)]) -> Vec<(Cell, Vec<f64>)> {
    let mut out = Vec::with_capacity(2 * cells.len());
    for (c, l) in cells {
        let n = l.len();
        if n >= 2 && n % 2 == 0 {
            let k = if (n / 2) % 2 == 1 { n / 2 } else { n / 2 - 1 };
            out.push((c.clone(), l[..k].to_vec()));
            out.push((c.clone(), l[k..].to_vec()));
        } else {
            out.push((c.clone(), l.clone()));
        }
    }
    out
}

/// A cell's two boustrophedon paths (grid points), starting at the first lane's low end and at
/// its high end.
pub(super) fn cell_paths(
    ctx: &Ctx<'_>,
    lat: &Lattice,
    search: &mut Search,
    cell: &Cell,
    lanes: &[f64],
) -> [Vec<Point>; 2] {
    let mut out = [Vec::new(), Vec::new()];
    for (k, start_hi) in [false, true].into_iter().enumerate() {
        let mut pts: Vec<Point> = Vec::new();
        let mut hi = start_hi;
        for (i, &u) in lanes.iter().enumerate() {
            let a = ctx.lane_end(lat, cell, u, hi);
            let b = ctx.lane_end(lat, cell, u, !hi);
            if i == 0 {
                pts.push(a);
            } else {
                // Join along the boundary on side `hi` from the previous lane.
                let prev = lanes[i - 1];
                let mut chain = vec![*pts.last().unwrap_or(&a)];
                let mut w = prev.floor() + 1.0;
                while w < u - 1e-9 {
                    chain.push(ctx.lane_end(lat, cell, w, hi));
                    w += 1.0;
                }
                chain.push(a);
                if let Some(v) = ctx.follow(search, &chain) {
                    pts.extend(v);
                } else {
                    // Unreachable along the rim (should not happen inside a cell): route.
                    let from = *pts.last().unwrap_or(&a);
                    if let Some(v) = ctx.route(search, from, a) {
                        pts.extend(v);
                    }
                }
            }
            if ctx.free(a, b) {
                pts.push(b);
            } else if let Some(v) = ctx.route(search, a, b) {
                pts.extend(v);
            }
            hi = !hi;
        }
        pts.dedup();
        out[k] = pts;
    }
    out
}
