//! The planning pipeline (steps 1-5 of the module docs): lattices, decompositions, lanes,
//! cell tour, rim passes, repair, smoothing and turn pruning.

use std::collections::VecDeque;
use std::ops::{Add, Sub};
use std::sync::atomic::AtomicBool;

use rayon::prelude::*;

use super::angles::{dominant_angles, ANGLE_STEP_DEG, AXIS_TOL_DEG};
use super::cells::{decompose, split_ends, split_jumps, Cell};
use super::finish::{moves, repair, smooth, turns, Item};
use super::hops::WordHasher;
use super::lanes::{cell_paths, drop_covered, estimate, lanes_of, odd_runs, side_open};
use super::lattice::{Ctx, Lattice};
use super::rim::{rim_contours, rim_pass};
use super::transfer::Search;
use super::{hops, prune, tsp};
use super::{Bcd, BcdOptions};
use crate::geometry::{path_length, Point};
use crate::planner::Step;
use crate::planners::replay::Replay;
use crate::trace::Event;
use crate::world::World;

/// Which cell sets a lattice's plan tours (step 4 of the module docs).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Sets {
    /// The cells as decomposed.
    Whole,
    /// The cells with every even cell cut into two odd runs (no plan when there is none).
    Split,
    /// Both, the cheaper plan kept.
    Both,
}

/// A candidate plan and how it ranks: one that sweeps `min_coverage` of the floor first, then
/// fewer moves the repair had to skip, then the lower cost (length plus `turn_cost_m` per turn,
/// pixels). Every choice between candidates (cell sets, rim variants, lattices) uses
/// [`Plan::beats`]; of equal candidates the first is kept.
pub(super) struct Plan {
    /// Moves the repair could not make known-free and dropped.
    pub(super) skipped: usize,
    /// Whether the plan's estimated swept floor is below `min_coverage` (pruning never takes
    /// a plan below it, but a plan can reach pruning below it already).
    pub(super) short: bool,
    /// How far a short plan falls below `min_coverage`, in whole steps of `1 - rim_coverage`
    /// of the accessible floor (0 for a plan that is not short); ranks short plans among
    /// themselves.
    pub(super) shortfall: usize,
    /// Length plus `turn_cost_m` per turn, in pixels.
    pub(super) cost: f64,
    /// The plan's moves and marks.
    pub(super) items: Vec<Item>,
}

impl Plan {
    /// A plan with no moves that skips `skipped` moves (`usize::MAX`: one that never beats
    /// another) and is short of `min_coverage`.
    fn empty(skipped: usize) -> Self {
        Plan {
            skipped,
            short: true,
            shortfall: usize::MAX,
            cost: 0.0,
            items: Vec::new(),
        }
    }

    /// Does this plan rank before `best` (always, when there is none yet)? A plan that sweeps
    /// `min_coverage` of the floor before one that does not (a cheaper plan that sweeps less
    /// is not better), then fewer skipped moves, then the lower cost.
    ///
    /// Skipped moves ranked first before: a property test's map (0.01 m/px, r = 5.9 px, two
    /// thin walls and three blobs) got the peeled plan, which skipped none and swept 97.6 % of
    /// the floor, over lane plans that dropped 3 moves and swept 99.52 % (a skipped move is
    /// left out of the path, whose floor is then counted without it). On the 14 shared maps
    /// no plan chosen was short, so every plan there is the same.
    ///
    /// Of two short plans, the one that falls short by fewer steps of the floor ranks first,
    /// a step being the share `1 - rim_coverage` the user lets the rim passes leave (0.1 % by
    /// default): a salted map at r = 1.7 px had every plan short, and the peeled plan (no
    /// skipped move) swept 82 % where a lane plan swept 97.6 % (ba-star-extended: 97.8 %).
    /// Within a step the order is the usual one, so a plan that leaves low-yield rims as
    /// `rim_coverage` allows still wins on its shorter path.
    fn beats(&self, best: Option<&Plan>) -> bool {
        let key = |p: &Plan| (p.short, p.shortfall, p.skipped);
        best.is_none_or(|b| (key(self), self.cost) < (key(b), b.cost))
    }
}

/// A decomposition's cheapest lane phase (module docs, step 1): its estimate, the
/// decomposition, the phase and every cell's view.
type Pick = (f64, usize, f64, Vec<usize>);

/// Entry points a closed headland pass offers the tour (module docs, step 3).
const ROT: usize = 16;

/// Most offset-loop walks a peeled plan may have (module docs, step 3): beyond, it is not made.
const PEEL_WALKS: usize = 32;

/// The [`MARGIN_NOTE`](super::MARGIN_NOTE) of a finished plan (`None` without a margin, or
/// when every transfer keeps it): its transfers (the moves between a backtrack's marks) whose
/// moves come closer to obstacles than the margin asks, away from their ends.
fn margin_note(ctx: &Ctx<'_>, items: &[Item], margin_px: f64) -> Option<String> {
    ctx.keep_px?;
    let (mut hops, mut short) = (0usize, 0usize);
    // The point before the current transfer, and its moves so far.
    let mut at: Option<Point> = None;
    let mut hop: Option<(Point, Vec<Point>)> = None;
    for it in items {
        match it {
            Item::Move(p) => {
                if let Some((_, pts)) = hop.as_mut() {
                    pts.push(*p);
                }
                at = Some(*p);
            }
            Item::Mark(Event::BacktrackStart) => {
                hop = at.map(|a| (a, vec![a]));
            }
            Item::Mark(Event::BacktrackEnd) => {
                if let Some((a, pts)) = hop.take() {
                    let b = pts[pts.len() - 1];
                    if pts.len() > 1 {
                        hops += 1;
                        if !pts.windows(2).all(|m| ctx.keeps_margin(m[0], m[1], [a, b])) {
                            short += 1;
                        }
                    }
                }
            }
            Item::Mark(_) => {}
        }
    }
    // A margin no reachable point has: every point of a transfer near enough to its ends
    // counted as keeping it, so `margin_px: 1000` ran as 0 with no word (hostile pass).
    if hops > 0 && !ctx.safe.iter().any(|&s| s) {
        let robot =
            crate::collide::contact_radius_px(ctx.world.robot().radius / ctx.frame.resolution);
        let widest = (0..ctx.ok.len())
            .filter(|&i| ctx.ok[i])
            .map(|i| {
                let w = ctx.frame.width;
                ctx.world.pixel_clearance(i % w, i / w) / ctx.frame.resolution + 0.5 - robot
            })
            .fold(0.0_f64, f64::max);
        return Some(format!(
            "{} {} was kept on none of the plan's {hops} transfers: no reachable point is that far beyond the robot's clearance from obstacles (the widest spot allows {:.1}); they keep the robot's plain clearance",
            super::MARGIN_NOTE,
            crate::display::Compact(margin_px),
            widest.max(0.0)
        ));
    }
    (short > 0).then(|| {
        format!(
            "{} {} was not kept on {short} of the plan's {hops} transfers (no way keeps that clearance there, or smoothing cut it): they keep the robot's plain clearance",
            super::MARGIN_NOTE,
            crate::display::Compact(margin_px)
        )
    })
}

/// Factors of the user's `turn_cost_m` every plan is also made with (module docs, step 6).
const TURN_FACTORS: [f64; 3] = [1.0, 0.5, 0.0];

/// The index of the plan of `plans` that [`Plan::beats`] the others (the first of equal
/// ones).
fn best_index(plans: &[(Plan, usize)]) -> Option<usize> {
    (0..plans.len()).fold(None, |b: Option<usize>, j| {
        if plans[j].0.beats(b.map(|i| &plans[i].0)) {
            Some(j)
        } else {
            b
        }
    })
}

/// A kind of plan of the first round (module docs, steps 1 and 3).
#[derive(Clone, Copy)]
struct Kind {
    /// Its lattice: 0 the pixels, else the turned lattice of that index.
    lattice: usize,
    /// With a headland.
    head: bool,
    /// Peeled (offset loops instead of lanes; with a headland, on the pixels only).
    peel: bool,
    /// On the sweep the estimate did not pick (on the pixels, without a headland).
    other: bool,
}

/// A job of the planning round.
#[derive(Clone, Copy)]
struct Job {
    /// Its kind (an index into the round's kinds; job `i` of the first round is kind `i`).
    kind: usize,
    /// The index of its options in the turn-cost variants (step 6; 0: the user's).
    factor: usize,
    /// Its cells take the jagged-wall views (step 2).
    trim: bool,
}

/// How a plan is made beyond its lattice and options.
#[derive(Clone, Copy, Default)]
struct How {
    /// Offset loops from the outer walls instead of lanes (module docs, step 3).
    peel: bool,
    /// The cells of the sweep (west-to-east or north-to-south, step 1) whose estimate is
    /// the higher.
    other: bool,
    /// A cell's view across its lines may leave out a band along a jagged wall (step 2,
    /// [`TRIM_LANES`]).
    trim: bool,
}

/// Deepest band along a jagged wall that a cell's view across its lines may leave out, in
/// lane spacings (module docs, step 2).
const TRIM_LANES: f64 = 2.0;

/// The turn-cost variants (step 6, the first of [`TURN_FACTORS`]) made with the jagged-wall
/// views (step 2).
const TRIM_VARIANTS: usize = 2;

/// The steps without the transfers that have no move between their marks: a hop the smoothing
/// and pruning merged into the moves around it, or one between cells that meet where the one
/// ends and the next starts, is no transfer between regions (`teb_maze` counted 18 backtracks
/// between 16 cells, 5 of them without a move). The marks of a transfer with moves are kept.
fn drop_empty_transfers(steps: VecDeque<Step>) -> VecDeque<Step> {
    let mut out = VecDeque::with_capacity(steps.len());
    // An open transfer's start mark and the marks after it, held while no move has followed.
    let mut held: Option<Vec<Step>> = None;
    for step in steps {
        match step {
            Step::Mark(Event::BacktrackStart) => {
                out.extend(held.take().into_iter().flatten());
                held = Some(vec![step]);
            }
            Step::Mark(Event::BacktrackEnd) => match held.take() {
                // No move: the start mark goes, the marks after it stay.
                Some(marks) => out.extend(marks.into_iter().skip(1)),
                None => out.push_back(step),
            },
            Step::MoveTo(_) | Step::Rotate(_) | Step::Translate(_) => {
                out.extend(held.take().into_iter().flatten());
                out.push_back(step);
            }
            Step::Mark(_) | Step::Done => match held.as_mut() {
                Some(marks) => marks.push(step),
                None => out.push_back(step),
            },
        }
    }
    out.extend(held.into_iter().flatten());
    out
}

/// Improvement rounds of the first tour (which only picks each cell's path for the rim step).
const FIRST_ROUNDS: u32 = 1;

impl Bcd {
    pub(super) fn plan(world: &World, opts: &BcdOptions, stop: Option<&AtomicBool>) -> Self {
        let frame = *world.frame();
        let (w, h) = (frame.width, frame.height);
        let robot = world.robot();
        let res = frame.resolution;
        let reach = world.reachable();
        let ok: Vec<bool> = (0..w * h).map(|i| reach.contains(i)).collect();
        let need = crate::collide::contact_radius_px(robot.radius / res) + opts.margin_px;
        let safe: Vec<bool> = (0..w * h)
            .map(|i| ok[i] && world.pixel_clearance(i % w, i / w) / res + 0.5 >= need)
            .collect();
        let ctx = Ctx {
            world,
            frame,
            ok,
            safe,
            keep_px: (opts.margin_px > 0.0).then_some(need),
            // Lanes set closer than the tool's width overlap on purpose (mowing, disinfection):
            // every choice that counts swept floor (cells left to their neighbours' lanes, rim
            // passes, turn pruning) counts it with half the spacing, else the pruning drops
            // the lanes the overlap doubles (`lane_spacing_m: 0.1` gave gaps of 0.2 m).
            rt: robot
                .tool_radius
                .min(opts.lane_spacing_m.map_or(f64::INFINITY, |s| s / 2.0))
                / res,
            coarse: hops::CoarseCache::default(),
            stop,
        };
        // The plan on the pixel lattice and, when the walls run at an angle to the pixel
        // axes, on the lattices turned to them; the cheapest is kept (module docs, step 1).
        // The lattices are planned in parallel (each with its own search state) and compared
        // in their fixed order, the first of equal plans kept: the same choice as one by one.
        let off_axis = |a: &f64| {
            let deg = a.to_degrees();
            deg.min(90.0 - deg) > AXIS_TOL_DEG
        };
        let angles = dominant_angles(&ctx);
        // A map whose dominant walls run along the axes is planned on the pixels only.
        let angles: &[f64] = if angles.first().is_some_and(off_axis) {
            &angles
        } else {
            &[]
        };
        // `None`: the pixel lattice; `Some(t)`: the lattice turned by `t`.
        let mut turns_by: Vec<Option<f64>> = vec![None];
        for a in angles.iter().copied() {
            if !off_axis(&a) {
                continue;
            }
            for j in 0..opts.angle_tries {
                // 0, +1/2, -1/2, +1, -1, ... degrees around the wall angle.
                let step = f64::from(j.div_ceil(2)) * ANGLE_STEP_DEG;
                let d = if j % 2 == 1 { step } else { -step };
                turns_by.push(Some(a + d.to_radians()));
            }
        }
        let lattice = |t: &Option<f64>| match t {
            None => Lattice::pixels(&ctx),
            Some(t) => Lattice::turned(&ctx, *t),
        };
        // Every job tours its cells whole; the cell sets with even cells cut (step 4) are then
        // toured on the best job only (and on the best of the user's turn cost, step 6, when
        // that is another one, below): the split changes a plan's cost by a few
        // percent, the lattice or the decomposition by more, and a second tour per job doubled
        // the time. With a headland (module docs, step 3), every lattice is planned with and
        // without it, the cheaper plan kept.
        let cost_turn_px = opts.turn_cost_m / res;
        // The options with the user's turn cost and with the lower ones of step 6 (module
        // docs), each as given and without a headland; every plan is judged by the user's
        // cost (`cost_turn_px`) whatever turn cost made its choices.
        let factors: &[f64] = if opts.turn_cost_m > 0.0 {
            &TURN_FACTORS
        } else {
            &TURN_FACTORS[..1]
        };
        let variants: Vec<(BcdOptions, BcdOptions)> = factors
            .iter()
            .map(|f| {
                let o = BcdOptions {
                    turn_cost_m: opts.turn_cost_m * f,
                    ..opts.clone()
                };
                let plain = BcdOptions {
                    headland_min_m: None,
                    ..o.clone()
                };
                (plain, o)
            })
            .collect();
        // On the pixel lattice alone (walls along the axes), the plain plan is also made on
        // the sweep the estimate did not pick (module docs, step 1): the estimate misses the
        // transfers, and the other sweep's plan is often the cheaper one. With a headland, the
        // peeled plan (offset loops from the outer walls in) too, on the pixel lattice only
        // (offset loops follow the walls on any lattice). Jobs: lattice, options, peeled,
        // other sweep.
        let many = turns_by.len() > 1;
        let kind = |lattice, head, peel, other| Kind {
            lattice,
            head,
            peel,
            other,
        };
        let mut kinds: Vec<Kind> = Vec::new();
        for k in 0..turns_by.len() {
            kinds.push(kind(k, false, false, false));
            if !many {
                kinds.push(kind(k, false, false, true));
            }
            if opts.headland_min_m.is_some() {
                kinds.push(kind(k, true, false, false));
                if k == 0 {
                    kinds.push(kind(k, true, true, false));
                }
            }
        }
        // A job's lattice, options and how its plan is made.
        let options = |job: Job| {
            let Kind {
                lattice,
                head,
                peel,
                other,
            } = kinds[job.kind];
            let (plain, o) = &variants[job.factor];
            let how = How {
                peel,
                other,
                trim: job.trim,
            };
            (lattice, if head { o } else { plain }, how)
        };
        let run = |jobs: &[Job], sets: Sets| -> Vec<(Plan, usize)> {
            jobs.par_iter()
                .map(|&job| {
                    if ctx.stopped() {
                        return (Plan::empty(usize::MAX), 0);
                    }
                    let (k, o, how) = options(job);
                    let mut search = Search::new(w, h);
                    let lat = lattice(&turns_by[k]);
                    Self::plan_sets(&ctx, &lat, o, cost_turn_px, &mut search, sets, how)
                })
                .collect()
        };
        let job = |kind, factor, trim| Job { kind, factor, trim };
        let mut jobs: Vec<Job> = (0..kinds.len()).map(|i| job(i, 0, false)).collect();
        let mut plans = run(&jobs, Sets::Whole);
        // The lower turn costs (step 6) on the best job's kind only: on the 14 shared maps
        // every plan they improved came from it (made on every kind within 1 % of the best
        // too, they won nowhere else and the bcd bench took about a tenth more time; on
        // every kind, the same plans in about 1.6 times the time).
        let lead = best_index(&plans);
        // The jagged-wall views (step 2) likewise, on the best job's kind with the user's
        // turn cost and with half of it (module docs, step 6: where they won on the 14
        // shared maps; with no turn cost at all they won nowhere).
        let more: Vec<Job> = lead
            .into_iter()
            .flat_map(|i| {
                (1..variants.len())
                    .map(move |f| job(i, f, false))
                    .chain((0..variants.len().min(TRIM_VARIANTS)).map(move |f| job(i, f, true)))
            })
            .collect();
        plans.extend(run(&more, Sets::Whole));
        jobs.extend(more);
        // The cell sets with even cells cut are toured on the best job's cells and, when a
        // lower turn cost made another job the best, on the best job of the user's turn
        // cost too (so no plan is dearer than without step 6).
        let mut cut: Vec<usize> = lead.into_iter().chain(best_index(&plans)).collect();
        cut.dedup();
        let cut_jobs: Vec<Job> = cut.into_iter().map(|j| jobs[j]).collect();
        plans.extend(run(&cut_jobs, Sets::Split));
        if ctx.stopped() {
            return Self {
                replay: Replay::new(world, VecDeque::new()),
                cells: 0,
            };
        }
        let best = best_index(&plans).map(|i| plans.swap_remove(i));
        let (items, ncells) = best.map_or((Vec::new(), 0), |(p, n)| (p.items, n));
        let start = frame.world_to_grid_snapped(world.start().position());
        let note = margin_note(&ctx, &items, opts.margin_px);

        // A region whose moves the smoothing and pruning merged into the moves around it (or
        // a cell whose lane is a single point) has nothing left between its start and end: it
        // is not reported (marks inside it are kept), and the regions left are numbered 1, 2,
        // ... in order.
        let mut steps = VecDeque::with_capacity(items.len() + 1);
        steps.extend(note.map(|text| Step::Mark(Event::Note { text })));
        let mut at = start;
        // Marks since a region's start while it has no move yet (`None`: no region pending).
        let mut pending: Option<Vec<Event>> = None;
        let mut region = 0u32;
        for it in items {
            match it {
                Item::Move(p) => {
                    if p != at {
                        if let Some(marks) = pending.take() {
                            region += 1;
                            steps.push_back(Step::Mark(Event::RegionStart { region }));
                            steps.extend(marks.into_iter().map(Step::Mark));
                        }
                        steps.push_back(Step::MoveTo(frame.grid_to_world(p)));
                        at = p;
                    }
                }
                Item::Mark(Event::RegionStart { .. }) => {
                    if let Some(marks) = pending.replace(Vec::new()) {
                        steps.extend(marks.into_iter().map(Step::Mark));
                    }
                }
                Item::Mark(Event::RegionEnd { .. }) => match pending.take() {
                    Some(marks) => steps.extend(marks.into_iter().map(Step::Mark)),
                    None => steps.push_back(Step::Mark(Event::RegionEnd { region })),
                },
                Item::Mark(e) => match pending.as_mut() {
                    Some(marks) => marks.push(e),
                    None => steps.push_back(Step::Mark(e)),
                },
            }
        }
        if let Some(marks) = pending {
            steps.extend(marks.into_iter().map(Step::Mark));
        }
        Self {
            replay: Replay::new(world, drop_empty_transfers(steps)).reacting(opts.bumper_reaction),
            cells: ncells,
        }
    }

    /// Steps 1-5 of the module docs on the lattice `lat`: the plan's items with the moves it
    /// had to skip, its cost (length plus `turn_cost_m` per turn, pixels) and its cells.
    #[cfg(test)]
    pub(super) fn plan_on(
        ctx: &Ctx<'_>,
        lat: &Lattice,
        opts: &BcdOptions,
        search: &mut Search,
    ) -> (Plan, usize) {
        let cost_turn_px = opts.turn_cost_m / ctx.frame.resolution;
        Self::plan_sets(
            ctx,
            lat,
            opts,
            cost_turn_px,
            search,
            Sets::Both,
            How::default(),
        )
    }

    /// Steps 1-5 of the module docs on the lattice `lat`, touring only the cell sets `sets`
    /// (step 4): the best plan and the number of cells. With [`Sets::Split`] and no even cell,
    /// an empty plan that never beats another (skips `usize::MAX`).
    fn plan_sets(
        ctx: &Ctx<'_>,
        lat: &Lattice,
        opts: &BcdOptions,
        cost_turn_px: f64,
        search: &mut Search,
        sets: Sets,
        how: How,
    ) -> (Plan, usize) {
        let How { peel, other, .. } = how;
        let world = ctx.world;
        let frame = ctx.frame;
        let robot = world.robot();
        let res = frame.resolution;
        let spacing = opts.lane_spacing_m.unwrap_or(2.0 * robot.tool_radius);
        // With a headland: the interior lattice and the passes (module docs, step 3).
        let (inner, heads) = match opts.headland_min_m {
            Some(m) => {
                // Interior points lie at least 2 r_tool from the passes, which run through the
                // free points beside the obstacles, one lattice step from them.
                let Some((ok, passes)) = super::headland::headland(
                    ctx,
                    lat,
                    search,
                    2.0 * ctx.rt + 1.0,
                    m / res,
                    (2.0 * (spacing / res)).ceil() as usize,
                    peel.then_some((spacing / res).max(1.0)),
                    if peel { PEEL_WALKS } else { usize::MAX },
                ) else {
                    return (Plan::empty(usize::MAX), 0);
                };
                (Some(lat.with_ok(ok)), passes)
            }
            None => (None, Vec::new()),
        };
        let lat = inner.as_ref().unwrap_or(lat);
        let (w, h) = (lat.w, lat.h);
        let sp = (spacing / res).max(1.0);
        let turn_px = opts.turn_cost_m / res;
        let start = frame.world_to_grid_snapped(world.start().position());

        // 1-2. Both decompositions, each cell's cheaper lane direction, the cheaper total.
        // Lines across a cell that a jagged wall's bumps split may be left out of its view
        // across, up to a band this deep (step 2).
        let trim_band = if how.trim {
            (TRIM_LANES * sp).floor() as usize
        } else {
            0
        };
        let ok = &lat.ok;
        let by_cols = decompose(w, h, true, &|c, r| ok[r * w + c]);
        let by_rows = decompose(h, w, false, &|r, c| ok[r * w + c]);
        // Each cell's views (along its lines; across them when monotone) with their sides'
        // openness where C-free continues; per decomposition and lattice phase, the cheaper
        // view of every cell and the estimated total.
        let views = |cells: Vec<Cell>| -> Vec<Vec<(Cell, bool, bool)>> {
            cells
                .into_iter()
                .map(|c| {
                    let t = c.transposed_trim(trim_band);
                    let mut v = Vec::with_capacity(2);
                    for c in std::iter::once(c).chain(t) {
                        let lo = side_open(lat, &c, c.u0, -1, &|_| true);
                        let hi = side_open(lat, &c, c.u1(), 1, &|_| true);
                        v.push((c, lo, hi));
                    }
                    v
                })
                .collect()
        };
        // A cell's estimated cost: its cheaper view plus reaching it.
        let cell_cost = |c: &Cell| -> f64 {
            let view = |c: &Cell| {
                let lo = side_open(lat, c, c.u0, -1, &|_| true);
                let hi = side_open(lat, c, c.u1(), 1, &|_| true);
                let lanes = lanes_of(c, sp, 0.0, lo, hi);
                estimate(c, &lanes, turn_px) + 2.0 * turn_px + sp
            };
            let along = view(c);
            c.transposed_trim(trim_band)
                .map_or(along, |t| along.min(view(&t)))
        };
        let trim_max = (2.0 * sp).ceil() as usize;
        let jump = (sp / 2.0).ceil() as usize;
        let part_cost = |c: &Cell| -> f64 {
            split_ends(vec![c.clone()], trim_max)
                .iter()
                .map(cell_cost)
                .sum()
        };
        let decs = [
            views(split_ends(split_jumps(by_cols, jump, &part_cost), trim_max)),
            views(split_ends(split_jumps(by_rows, jump, &part_cost), trim_max)),
        ];
        // Per decomposition, the cheapest phase: estimate, decomposition, phase, views.
        let mut best: [Option<Pick>; 2] = [None, None];
        for (d, cells) in decs.iter().enumerate() {
            for k in 0..6 {
                let phase = sp * f64::from(k) / 6.0;
                let mut total = 0.0;
                let mut pick = Vec::with_capacity(cells.len());
                for vs in cells {
                    let mut b: Option<(f64, usize)> = None;
                    for (j, (c, lo, hi)) in vs.iter().enumerate() {
                        let lanes = lanes_of(c, sp, phase, *lo, *hi);
                        let mut e = estimate(c, &lanes, turn_px);
                        if !lanes.is_empty() {
                            e += 2.0 * turn_px + sp;
                        }
                        if b.is_none_or(|b| e < b.0) {
                            b = Some((e, j));
                        }
                    }
                    let (e, j) = b.unwrap_or((0.0, 0));
                    total += e;
                    pick.push(j);
                }
                if best[d].as_ref().is_none_or(|b| total < b.0) {
                    best[d] = Some((total, d, phase, pick));
                }
            }
        }
        // The estimate's pick (of equal estimates the column sweep), or the other one.
        let [by_c, by_r] = best;
        let pick_c = match (&by_c, &by_r) {
            (Some(c), Some(r)) => c.0 <= r.0,
            (c, _) => c.is_some(),
        };
        let chosen = if pick_c == other { by_r } else { by_c };
        let Some((_, d, phase, pick)) = chosen else {
            return (Plan::empty(usize::MAX), 0);
        };
        let chosen: Vec<Cell> = decs[d]
            .iter()
            .zip(&pick)
            .map(|(vs, &j)| vs[j].0.clone())
            .collect();
        // Lanes: a side is open where the neighbouring pixels belong to cells with lanes the
        // same way (their lattice lines continue this cell's).
        let mut cols_at = vec![0u8; w * h];
        for c in &chosen {
            for (k, &(a, b)) in c.runs.iter().enumerate() {
                for v in a..=b {
                    let (cc, rr) = c.px(c.u0 + k, v);
                    cols_at[rr * w + cc] = if c.cols { 1 } else { 2 };
                }
            }
        }
        let cells: Vec<(Cell, Vec<f64>)> = chosen
            .into_iter()
            .map(|c| {
                let mine = if c.cols { 1 } else { 2 };
                let same = |i: usize| cols_at[i] == mine;
                let lo = side_open(lat, &c, c.u0, -1, &same);
                let hi = side_open(lat, &c, c.u1(), 1, &same);
                let lanes = lanes_of(&c, sp, phase, lo, hi);
                (c, lanes)
            })
            .filter(|(_, l)| !l.is_empty())
            .collect();
        let cells = drop_covered(cells, w, h, ctx.rt);

        // A cell with an even number of lanes leaves on the side it entered. The same cells
        // with each such cell cut into two runs of an odd number of lanes (`k` and `n - k`,
        // as even as parity allows), which the tour may drive at different times, each
        // leaving on the side opposite its entry; when the halves are best driven one after
        // the other the tour joins them back. Both cell sets are toured and the cheaper plan
        // is kept (module docs, step 4).
        let split = odd_runs(&cells);
        // (no even cell: the second set is the first) With both, the sets are toured in
        // parallel (the second with its own search state) and compared in order, the first of
        // equal plans kept: the same choice as one after the other.
        let even = split.len() > cells.len();
        let (first, second) = if sets == Sets::Split {
            let b = if even {
                Self::tour_cells(
                    ctx,
                    lat,
                    opts,
                    cost_turn_px,
                    search,
                    &split,
                    &heads,
                    sp,
                    start,
                )
            } else {
                None
            };
            (b, None)
        } else if even && sets == Sets::Both {
            rayon::join(
                || {
                    Self::tour_cells(
                        ctx,
                        lat,
                        opts,
                        cost_turn_px,
                        search,
                        &cells,
                        &heads,
                        sp,
                        start,
                    )
                },
                || {
                    let mut own = Search::new(ctx.frame.width, ctx.frame.height);
                    Self::tour_cells(
                        ctx,
                        lat,
                        opts,
                        cost_turn_px,
                        &mut own,
                        &split,
                        &heads,
                        sp,
                        start,
                    )
                },
            )
        } else {
            (
                Self::tour_cells(
                    ctx,
                    lat,
                    opts,
                    cost_turn_px,
                    search,
                    &cells,
                    &heads,
                    sp,
                    start,
                ),
                None,
            )
        };
        let mut best: Option<Plan> = None;
        for b in [first, second].into_iter().flatten() {
            if b.beats(best.as_ref()) {
                best = Some(b);
            }
        }
        let ncells = cells.len();
        let none = if sets == Sets::Split { usize::MAX } else { 0 };
        let best = best.unwrap_or_else(|| Plan::empty(none));
        (best, ncells)
    }

    /// Steps 3-5 of the module docs for the cells `cells` with their lanes: cell paths, the
    /// tour, rim passes, repair, smoothing and pruning; the plan's skipped moves, its cost
    /// (length plus `turn_cost_m` per turn, pixels) and items.
    #[allow(clippy::too_many_arguments)] // the pipeline's state, passed down unchanged
    fn tour_cells(
        ctx: &Ctx<'_>,
        lat: &Lattice,
        opts: &BcdOptions,
        cost_turn_px: f64,
        search: &mut Search,
        cells: &[(Cell, Vec<f64>)],
        heads: &[Vec<Point>],
        sp: f64,
        start: Point,
    ) -> Option<Plan> {
        let turn_px = opts.turn_cost_m / ctx.frame.resolution;
        // Cell paths; a first tour over the cells picks each cell's path (corner), the rim
        // contours of what those paths miss join the cells in the final tour, where each cell
        // keeps its path (driven either way).
        let mut paths: Vec<[Vec<Point>; 2]> = Vec::with_capacity(cells.len());
        let mut pieces = Vec::with_capacity(cells.len());
        for (cell, lanes) in cells {
            let ps = cell_paths(ctx, lat, search, cell, lanes);
            let mut piece = tsp::Piece {
                entry: Vec::new(),
                exit: Vec::new(),
                inner: Vec::new(),
            };
            for p in &ps {
                let (f, l) = (p[0], p[p.len() - 1]);
                let len = path_length(p);
                piece.entry.extend([f, l]);
                piece.exit.extend([l, f]);
                piece.inner.extend([len, len]);
            }
            pieces.push(piece);
            paths.push(ps);
        }
        // Headland passes: pieces driven either way; a closed loop from any of up to
        // `ROT` points along it.
        let ncell0 = paths.len();
        let mut rots: Vec<Vec<Vec<Point>>> = Vec::with_capacity(heads.len());
        for p in heads {
            let len = path_length(p);
            let mut rs = vec![p.clone()];
            if p.len() > 3 && p[0] == p[p.len() - 1] {
                // Entry points about evenly along the loop: segments cut every `step`.
                let step = (len / ROT as f64).max(sp);
                let mut q = vec![p[0]];
                for s in p.windows(2) {
                    let k = (s[0].dist(s[1]) / step).floor() as usize;
                    for j in 1..=k {
                        let t = j as f64 / (k + 1) as f64;
                        q.push(s[0].add(s[1].sub(s[0]).scale(t)));
                    }
                    q.push(s[1]);
                }
                let n = q.len();
                let k = (n - 1).min(ROT);
                for j in 1..k {
                    let i = j * (n - 1) / k;
                    let mut r = q[i..].to_vec();
                    r.extend_from_slice(&q[1..=i]);
                    rs.push(r);
                }
            }
            let mut piece = tsp::Piece {
                entry: Vec::new(),
                exit: Vec::new(),
                inner: Vec::new(),
            };
            for r in &rs {
                let (f, l) = (r[0], r[r.len() - 1]);
                piece.entry.extend([f, l]);
                piece.exit.extend([l, f]);
                piece.inner.extend([len, len]);
            }
            pieces.push(piece);
            paths.push([p.clone(), p.clone()]);
            rots.push(rs);
        }
        let coarse = ctx.coarse.get(sp, |s| ctx.coarse_grid(s));
        let far = ctx
            .coarse
            .get(sp * f64::from(hops::FAR_FACTOR), |s| ctx.coarse_grid(s));
        let ncells = paths.len();
        // Two ways to sweep the rim (module docs, step 3): its passes as pieces of the tour,
        // or inserted into the finished tour where they cost least; the cheaper plan is kept.
        let cell_pieces = pieces;
        let cell_paths_all = paths;
        let mut best: Option<Plan> = None;
        // The hop table and nearest-neighbour tour of the cells alone serve both plans.
        let stop: tsp::Stop<'_> = &|| ctx.stopped();
        let cell_table = hops::HopTable::new(&coarse, &far, &cell_pieces, start, stop);
        // (a table given up has empty rows: no tour over it)
        if ctx.stopped() {
            return None;
        }
        let cell_nn = cell_table.nearest_tour(&cell_pieces, start);
        // The cells' tour after the first rounds, whether those settled it, and its neighbours.
        let mut cell_tour: Option<(tsp::Tour, bool, Vec<Vec<usize>>)> = None;
        for in_tour in [true, false] {
            if !opts.rim && !in_tour || ctx.stopped() {
                break;
            }
            // (with a headland, whose passes sweep most of the rim, the rest is only
            // inserted as detours)
            if !heads.is_empty() && opts.rim && in_tour {
                continue;
            }
            let mut pieces = cell_pieces.clone();
            let mut paths = cell_paths_all.clone();
            let contours: Vec<Vec<Point>> = if opts.rim && in_tour {
                // The first rounds of the cells' tour, kept: the other plan goes on from there.
                let dist = |a: Point, b: Point| cell_table.dist(a, b);
                let nb = tsp::neighbours(&pieces, &dist);
                let mut first = cell_nn.clone();
                let rounds = opts.tour_rounds.min(FIRST_ROUNDS);
                let settled = rounds > 0
                    && tsp::improve(&pieces, start, rounds, &dist, &nb, &mut first, stop);
                cell_tour = Some((first.clone(), settled, nb));
                let mut keep = vec![0usize; ncells];
                for &(c, v) in &first {
                    keep[c] = v / 2;
                }
                for (c, k) in keep.iter().enumerate().take(ncell0) {
                    if *k == 1 {
                        paths[c].swap(0, 1);
                    }
                    let p = &paths[c][0];
                    let (f, l) = (p[0], p[p.len() - 1]);
                    let len = path_length(p);
                    pieces[c] = tsp::Piece {
                        entry: vec![f, l],
                        exit: vec![l, f],
                        inner: vec![len, len],
                    };
                }
                let lines: Vec<&[Point]> = paths.iter().map(|p| p[0].as_slice()).collect();
                rim_contours(ctx, search, &lines, opts.rim_min_yield, opts.rim_coverage)
                    .into_iter()
                    .map(|c| c.0)
                    .collect()
            } else {
                Vec::new()
            };
            for c in &contours {
                let (f, l) = (c[0], c[c.len() - 1]);
                let len = path_length(c);
                pieces.push(tsp::Piece {
                    entry: vec![f, l],
                    exit: vec![l, f],
                    inner: vec![len, len],
                });
            }
            // Only the rim-in-tour plan changes the pieces (one variant per cell, rim passes
            // added); the other plan tours the cells alone.
            let own = (opts.rim && in_tour)
                .then(|| hops::HopTable::new(&coarse, &far, &pieces, start, stop));
            if ctx.stopped() {
                return None;
            }
            let table = own.as_ref().unwrap_or(&cell_table);
            let dist = |a: Point, b: Point| table.dist(a, b);
            let cont = if own.is_none() {
                cell_tour.take()
            } else {
                None
            };
            let tour = match (&own, cont) {
                (Some(t), _) => {
                    let nn = t.nearest_tour(&pieces, start);
                    tsp::solve(&pieces, start, opts.tour_rounds, &dist, Some(nn), stop)
                }
                // (the rounds left after the first ones; none when they settled the tour)
                (None, Some((mut tour, settled, nb))) => {
                    let done = opts.tour_rounds.min(FIRST_ROUNDS);
                    if !settled && opts.tour_rounds > done {
                        tsp::improve(
                            &pieces,
                            start,
                            opts.tour_rounds - done,
                            &dist,
                            &nb,
                            &mut tour,
                            stop,
                        );
                    }
                    tour
                }
                (None, None) => tsp::solve(
                    &pieces,
                    start,
                    opts.tour_rounds,
                    &dist,
                    Some(cell_nn.clone()),
                    stop,
                ),
            };

            if ctx.stopped() {
                return None;
            }
            // Hop corrections (module docs, step 4) in the tour of the cells (and headland
            // passes); the tour with the rim passes keeps its estimates (corrected, it wins
            // on cost with fewer turns but longer paths: `rmf_office_scan` 1.52 -> 1.57).
            let mut routes = Routes::default();
            let tour = if in_tour {
                tour
            } else {
                correct_hops(
                    ctx,
                    search,
                    &pieces,
                    start,
                    opts.tour_rounds,
                    &dist,
                    tour,
                    &mut routes,
                )
            };

            let mut items: Vec<Item> = vec![Item::Move(start)];
            let mut here = start;
            let mut region = 0u32;
            // Pieces and moves this plan had to skip because no route reached them: a plan
            // that skips less is kept before a shorter one (a skip loses floor silently).
            let mut skipped = 0usize;
            for &(cid, v) in &tour {
                if cid >= ncells {
                    let c = &contours[cid - ncells];
                    let pts: Vec<Point> = if v == 0 {
                        c.clone()
                    } else {
                        c.iter().rev().copied().collect()
                    };
                    if pts[0] != here {
                        let Some(hop) = routes.get(ctx, search, here, pts[0]) else {
                            skipped += 1;
                            continue;
                        };
                        items.push(Item::Mark(Event::BacktrackStart));
                        items.extend(hop.into_iter().map(Item::Move));
                        items.push(Item::Mark(Event::BacktrackEnd));
                    }
                    items.extend(pts[1..].iter().copied().map(Item::Move));
                    here = pts[pts.len() - 1];
                    continue;
                }
                let path = if cid >= ncell0 {
                    &rots[cid - ncell0][v / 2]
                } else {
                    &paths[cid][v / 2]
                };
                let pts: Vec<Point> = if v % 2 == 0 {
                    path.clone()
                } else {
                    path.iter().rev().copied().collect()
                };
                let entry = pts[0];
                if entry != here {
                    let Some(hop) = routes.get(ctx, search, here, entry) else {
                        skipped += 1;
                        continue;
                    };
                    items.push(Item::Mark(Event::BacktrackStart));
                    items.extend(hop.into_iter().map(Item::Move));
                    items.push(Item::Mark(Event::BacktrackEnd));
                }
                region += 1;
                items.push(Item::Mark(Event::RegionStart { region }));
                items.extend(pts[1..].iter().copied().map(Item::Move));
                items.push(Item::Mark(Event::RegionEnd { region }));
                here = pts[pts.len() - 1];
            }

            if ctx.stopped() {
                return None;
            }
            if opts.rim {
                rim_pass(
                    ctx,
                    search,
                    &mut items,
                    opts.rim_min_yield,
                    opts.rim_coverage,
                );
            }
            if ctx.stopped() {
                return None;
            }
            let mut items = smooth(ctx, repair(ctx, search, items, &mut skipped));
            if opts.rim && !in_tour {
                // A second mop-up of what the inserted passes and the smoothing left.
                rim_pass(
                    ctx,
                    search,
                    &mut items,
                    opts.rim_min_yield,
                    opts.rim_coverage,
                );
                items = smooth(ctx, repair(ctx, search, items, &mut skipped));
            }
            if ctx.stopped() {
                return None;
            }
            let (items, short, missing) = prune::prune(ctx, items, opts.min_coverage, turn_px);
            let shortfall = if short {
                let acc = ctx.world.accessible_count();
                let step = ((1.0 - opts.rim_coverage) * acc as f64).floor() as usize;
                missing.div_ceil(step.max(1))
            } else {
                0
            };
            let pts: Vec<Point> = moves(&items).into_iter().map(|m| m.0).collect();
            let cost = path_length(&pts) + cost_turn_px * turns(&pts) as f64;
            let plan = Plan {
                skipped,
                short,
                shortfall,
                cost,
                items,
            };
            if plan.beats(best.as_ref()) {
                best = Some(plan);
            }
        }
        best
    }
}

/// Corrections of [`correct_hops`]: each improves the tour with the corrected hop costs and
/// routes the new tour's hops. (More corrections with more improvement rounds each lower the
/// mean path ratio further, 1.1747 with 3 corrections of 3 rounds, but cost about twice the
/// planning time, and with 6 corrections `rmf_office_scan` finds a plan that trades path for
/// turns: 1.46 -> 1.58.)
const CORRECT_ROUNDS: usize = 2;

/// Improvement rounds after each correction (at most `tour_rounds`).
const CORRECT_IMPROVE: u32 = 1;

/// A routed hop longer than its cost in the tour by more than this (pixels) is corrected.
const HOP_TOL_PX: f64 = 1e-6;

/// Key of a hop: its end points in 1/16 pixels (grid coordinates, so the key does not depend
/// on where the map lies in the world).
#[derive(Clone, Copy, PartialEq, Eq)]
struct HopKey([i64; 4]);

impl std::hash::Hash for HopKey {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        // One word per coordinate (mixed by [`WordHasher`]).
        for v in self.0 {
            state.write_u64(v as u64);
        }
    }
}

fn hop_key(a: Point, b: Point) -> HopKey {
    let q = |v: f64| (v * 16.0).round() as i64;
    HopKey([q(a.x), q(a.y), q(b.x), q(b.y)])
}

/// A map keyed by hops (looked up only, never iterated: [`WordHasher`]).
type HopMap<V> = std::collections::HashMap<HopKey, V, std::hash::BuildHasherDefault<WordHasher>>;

/// Transfers already routed, by hop (looked up only, never iterated).
#[derive(Default)]
struct Routes(HopMap<Option<Vec<Point>>>);

impl Routes {
    /// The route from `a` to `b` ([`Ctx::route`]), computed once per hop.
    fn get(
        &mut self,
        ctx: &Ctx<'_>,
        search: &mut Search,
        a: Point,
        b: Point,
    ) -> Option<Vec<Point>> {
        self.0
            .entry(hop_key(a, b))
            .or_insert_with(|| ctx.route(search, a, b))
            .clone()
    }
}

/// Hop corrections of a finished tour (module docs, step 4). The hop costs of the tour
/// ([`hops::HopTable`]) come from a coarse grid and miss walls inside a block or between
/// blocks joined elsewhere, so some hops of the tour are much longer when routed. Every hop of
/// `tour` is routed on the true map ([`Ctx::route`], kept in `routes` for the plan); a hop
/// whose route is longer than its cost in the tour gets the route's length as its cost (both
/// ways), and the tour is improved again with the corrected costs ([`CORRECT_IMPROVE`] rounds
/// of [`tsp::improve`], at most `rounds`; nothing is corrected when `rounds` is 0); up to
/// [`CORRECT_ROUNDS`] times, until no hop of the tour is corrected. Of the tours seen, the one
/// with the lowest routed cost (inner costs plus routed hops; a hop with no route at its
/// estimate) is returned, so a correction never lengthens the tour.
#[allow(clippy::too_many_arguments)]
fn correct_hops(
    ctx: &Ctx<'_>,
    search: &mut Search,
    pieces: &[tsp::Piece],
    start: Point,
    rounds: u32,
    est: tsp::Dist<'_>,
    mut tour: tsp::Tour,
    routes: &mut Routes,
) -> tsp::Tour {
    if rounds == 0 {
        return tour;
    }
    let mut fixed: HopMap<f64> = HopMap::default();
    let mut nb: Option<Vec<Vec<usize>>> = None;
    // The best tour by its routed cost (hops as routed, unroutable hops at their estimate).
    let mut best: Option<(f64, tsp::Tour)> = None;
    for r in 0..=CORRECT_ROUNDS {
        if ctx.stopped() {
            break;
        }
        let mut changed = false;
        let mut here = start;
        let mut real = 0.0;
        for &(p, v) in &tour {
            let entry = pieces[p].entry[v];
            real += pieces[p].inner[v];
            if entry != here {
                let k = hop_key(here, entry);
                let now = fixed.get(&k).copied().unwrap_or_else(|| est(here, entry));
                if let Some(route) = routes.get(ctx, search, here, entry) {
                    let len = here.dist(route[0]) + path_length(&route);
                    real += len;
                    if len > now + HOP_TOL_PX {
                        fixed.insert(k, len);
                        fixed.insert(hop_key(entry, here), len);
                        changed = true;
                    }
                } else {
                    real += now;
                }
            }
            here = pieces[p].exit[v];
        }
        if best.as_ref().is_none_or(|b| real < b.0) {
            best = Some((real, tour.clone()));
        }
        if !changed || r == CORRECT_ROUNDS {
            break;
        }
        let d = |a: Point, b: Point| {
            fixed
                .get(&hop_key(a, b))
                .copied()
                .unwrap_or_else(|| est(a, b))
        };
        let nb = nb.get_or_insert_with(|| tsp::neighbours(pieces, &d));
        tsp::improve(
            pieces,
            start,
            rounds.min(CORRECT_IMPROVE),
            &d,
            nb,
            &mut tour,
            &|| ctx.stopped(),
        );
    }
    best.map_or(tour, |b| b.1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Transfer marks with no move between them go (marks between them stay); a transfer with
    /// a move, a turn or a drive keeps both; an unclosed start is kept as it is.
    #[test]
    fn empty_transfers_are_dropped() {
        let p = Point::new(1.0, 2.0);
        let note = || Event::Note { text: "n".into() };
        let bt = |e: Event| Step::Mark(e);
        let steps: VecDeque<Step> = vec![
            Step::MoveTo(p),
            bt(Event::BacktrackStart),
            bt(note()),
            bt(Event::BacktrackEnd),
            bt(Event::BacktrackStart),
            Step::MoveTo(p),
            bt(Event::BacktrackEnd),
            bt(Event::BacktrackStart),
            Step::Rotate(0.5),
            bt(Event::BacktrackEnd),
            bt(Event::BacktrackStart),
            bt(Event::BacktrackEnd),
            bt(Event::BacktrackStart),
            bt(note()),
        ]
        .into();
        let want: Vec<Step> = vec![
            Step::MoveTo(p),
            bt(note()),
            bt(Event::BacktrackStart),
            Step::MoveTo(p),
            bt(Event::BacktrackEnd),
            bt(Event::BacktrackStart),
            Step::Rotate(0.5),
            bt(Event::BacktrackEnd),
            bt(Event::BacktrackStart),
            bt(note()),
        ];
        assert_eq!(Vec::from(drop_empty_transfers(steps)), want);
    }
}
