//! The plan's steps and finishing its path: repair of moves that are not free, smoothing, turn
//! counting.

use std::ops::Sub;

use super::lattice::Ctx;
use super::transfer::Search;
use crate::geometry::{point_segment_dist2, Point};
use crate::trace::Event;

/// One step of the plan.
#[derive(Clone, Debug)]
pub(super) enum Item {
    Move(Point),
    Mark(Event),
}

/// Re-checks every move of the plan on the true map and routes the ones that are not free
/// (dropping a move that has no route, and skipping to the next reachable point; `skipped`
/// counts the dropped moves).
pub(super) fn repair(
    ctx: &Ctx<'_>,
    search: &mut Search,
    items: Vec<Item>,
    skipped: &mut usize,
) -> Vec<Item> {
    let mut out = Vec::with_capacity(items.len());
    let mut at: Option<Point> = None;
    for it in items {
        match it {
            Item::Move(p) => match at {
                None => {
                    out.push(Item::Move(p));
                    at = Some(p);
                }
                Some(a) => {
                    if a == p || ctx.free(a, p) {
                        out.push(Item::Move(p));
                        at = Some(p);
                    } else if let Some(v) = ctx.route(search, a, p) {
                        out.extend(v.into_iter().map(Item::Move));
                        at = Some(p);
                    } else {
                        *skipped += 1;
                    }
                }
            },
            Item::Mark(e) => out.push(Item::Mark(e)),
        }
    }
    out
}

/// Largest distance (pixels) a smoothed move may stray from a point of the plan it replaces.
const SMOOTH_TOL_PX: f64 = 0.5;
/// Points a smoothed move may replace at most (bounds the work per point).
const SMOOTH_REACH: usize = 48;

/// Straightens the plan: within each run of consecutive moves (the marks stay where they
/// are), a point is dropped when the straight move that replaces it and its neighbours is
/// free on the true map and stays within [`SMOOTH_TOL_PX`] of every dropped point, so a
/// jagged boundary pass becomes a few straight moves (fewer turns) sweeping almost the same
/// floor.
pub(super) fn smooth(ctx: &Ctx<'_>, items: Vec<Item>) -> Vec<Item> {
    let tol2 = SMOOTH_TOL_PX * SMOOTH_TOL_PX;
    let mut out = Vec::with_capacity(items.len());
    let mut run: Vec<Point> = Vec::new();
    let flush = |run: &mut Vec<Point>, out: &mut Vec<Item>| {
        let n = run.len();
        if n > 0 {
            out.push(Item::Move(run[0]));
        }
        let mut i = 0;
        while i + 1 < n {
            let mut j = i + 1;
            for k in i + 2..n.min(i + 2 + SMOOTH_REACH) {
                if (i + 1..k).all(|m| point_segment_dist2(run[m], run[i], run[k]) <= tol2)
                    && ctx.free(run[i], run[k])
                {
                    j = k;
                } else {
                    break;
                }
            }
            out.push(Item::Move(run[j]));
            i = j;
        }
        run.clear();
    };
    for it in items {
        match it {
            Item::Move(p) => {
                if run.last() != Some(&p) {
                    run.push(p);
                }
            }
            Item::Mark(e) => {
                flush(&mut run, &mut out);
                out.push(Item::Mark(e));
            }
        }
    }
    flush(&mut run, &mut out);
    out
}

/// Number of heading changes along the polyline `pts` (as the simulator counts turns).
/// Whether turning from heading `from` to heading `to` is a rotation the simulator counts.
pub(super) fn is_turn(from: f64, to: f64) -> bool {
    crate::geometry::wrap_angle(to - from).abs() > crate::planner::MIN_ROTATION
}

pub(super) fn turns(pts: &[Point]) -> usize {
    let mut n = 0;
    let mut heading: Option<f64> = None;
    for w in pts.windows(2) {
        let d = w[1].sub(w[0]);
        if d.x == 0.0 && d.y == 0.0 {
            continue;
        }
        let h = d.y.atan2(d.x);
        if heading.is_some_and(|g| is_turn(g, h)) {
            n += 1;
        }
        heading = Some(h);
    }
    n
}

/// The moves of `items` as a polyline with, for each point, its index in `items`.
pub(super) fn moves(items: &[Item]) -> Vec<(Point, usize)> {
    items
        .iter()
        .enumerate()
        .filter_map(|(i, it)| match it {
            Item::Move(p) => Some((*p, i)),
            Item::Mark(_) => None,
        })
        .collect()
}
