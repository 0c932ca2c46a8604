//! `ba-star-extended` (BA* + the coverage extension) through the simulator and the metrics:
//! complete, collision-free, deterministic, terminating, online-honest, and its options.

#![allow(clippy::unwrap_used)] // helpers of a test file

use std::f64::consts::FRAC_PI_2;

use ccpp_core::grid::{Cell, GridMap};
use ccpp_core::metrics::{compute, Metrics};
use ccpp_core::planner::{Planner, Sensor, Step};
use ccpp_core::planners::ba_star::{BaStar, BaStarOptions};
use ccpp_core::planners::ba_star_extended::{BaStarExtended, BaStarExtendedOptions};
use ccpp_core::planners::extension::ExtensionOptions;
use ccpp_core::planners::{build, PlannerOptions};
use ccpp_core::sim::{simulate, RunOutput, SimConfig, StopReason};
use ccpp_core::trace::{Entry, Event, Trace};
use ccpp_core::world::{Robot, World};
use ccpp_core::Pose;

/// One character = 7 px at 0.02 m = 0.14 m; robot radius 0.1 m (tiles of 0.2 m), so tiles do
/// not line up with the characters and BA* leaves rims.
const R: f64 = 0.1;
const SCALE: usize = 7;
const RES: f64 = 0.02;

/// The world of a drawing with the start at the centre of character `(col, row)`; where the
/// robot's disk does not fit there (a free character between obstacles is narrower than the
/// robot), the library's default start (the widest free spot), so the case still runs; `None`
/// only when the robot fits nowhere.
fn world(art: &str, col: usize, row: usize, theta: f64) -> Option<World> {
    let m = GridMap::from_ascii_scaled(art, SCALE, RES).unwrap();
    let rows = m.frame().height / SCALE;
    let ch = SCALE as f64 * RES;
    let x = (col as f64 + 0.5) * ch;
    let y = ((rows - 1 - row) as f64 + 0.5) * ch;
    World::new(m.clone(), Robot::new(R), Some(Pose::new(x, y, theta)))
        .or_else(|_| World::new(m, Robot::new(R), None))
        .ok()
}

fn run_ext(w: &World, opts: BaStarExtendedOptions) -> (RunOutput, Metrics, BaStarExtended) {
    let mut p = BaStarExtended::new(opts);
    let out = simulate(w, &mut p, &SimConfig::default());
    let m = compute(w, &out, "test");
    (out, m, p)
}

fn run_ba(w: &World) -> Metrics {
    let mut p = BaStar::new(BaStarOptions::default());
    let out = simulate(w, &mut p, &SimConfig::default());
    compute(w, &out, "test")
}

fn count(trace: &Trace, f: impl Fn(&Event) -> bool) -> usize {
    trace.events().filter(|(_, e)| f(e)).count()
}

/// Checks that every commanded move is known free when it is commanded.
struct Checked {
    p: BaStarExtended,
    errors: Vec<String>,
}

impl Planner for Checked {
    fn name(&self) -> &'static str {
        self.p.name()
    }
    fn tile_side(&self) -> Option<f64> {
        self.p.tile_side()
    }
    fn next(&mut self, sensor: &dyn Sensor) -> Step {
        let step = self.p.next(sensor);
        if let Step::MoveTo(q) = &step {
            let known = self.p.backbone().known_map().unwrap();
            let a = sensor.pose().position();
            if !known.segment_free(a, *q, sensor.robot().radius) && self.errors.len() < 5 {
                self.errors
                    .push(format!("move {a:?} -> {q:?} not known free"));
            }
        }
        step
    }
}

fn random_art(w: usize, h: usize, density: f64, seed: u64) -> Option<(String, usize, usize)> {
    let mut rng = ccpp_core::rng::SplitMix64::new(seed);
    let mut rows = Vec::new();
    let mut free = Vec::new();
    for r in 0..h {
        let mut line = String::new();
        for c in 0..w {
            if rng.next_f64() < density {
                line.push('#');
            } else {
                line.push('.');
                free.push((c, r));
            }
        }
        rows.push(line);
    }
    if free.is_empty() {
        return None;
    }
    let (c, r) = free[(rng.next_u64() % free.len() as u64) as usize];
    Some((rows.join("\n"), c, r))
}

/// Runs ba-star-extended on the drawn map and checks its invariants; a map where the robot
/// fits nowhere is rejected (proptest draws another: a case without a run is no pass).
fn check_run(
    art: &str,
    col: usize,
    row: usize,
    theta: f64,
) -> Result<(), proptest::test_runner::TestCaseError> {
    let Some(wd) = world(art, col, row, theta) else {
        return Err(proptest::test_runner::TestCaseError::reject(
            "the robot fits nowhere on the map",
        ));
    };
    let mut c = Checked {
        p: BaStarExtended::new(BaStarExtendedOptions::default()),
        errors: Vec::new(),
    };
    let out = simulate(&wd, &mut c, &SimConfig::default());
    assert!(c.errors.is_empty(), "{:?}\n{art}", c.errors);
    // Terminates by itself.
    assert_eq!(out.stop, StopReason::Done, "{art}");
    let m = compute(&wd, &out, "random");
    assert_eq!(m.coverage_rate, Some(1.0), "{m:?}\n{art}");
    assert_eq!(m.collisions, 0, "{art}");
    // At least what BA* sweeps.
    let mb = run_ba(&wd);
    assert!(
        m.effective_coverage >= mb.effective_coverage - 1e-9,
        "extended {} < ba-star {}\n{art}",
        m.effective_coverage,
        mb.effective_coverage
    );
    // Identical input, identical trace.
    let (again, _, _) = run_ext(&wd, BaStarExtendedOptions::default());
    assert_eq!(out.trace, again.trace);
    Ok(())
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 24, rng_seed: proptest::test_runner::RngSeed::Fixed(0x5eed_0107), ..Default::default() })]
    #[test]
    fn random_maps_are_covered(
        w in 4usize..=24,
        h in 4usize..=24,
        density in 0.0f64..0.3,
        seed in proptest::prelude::any::<u64>(),
        heading in 0usize..4,
    ) {
        let Some((art, c, r)) = random_art(w, h, density, seed) else {
            return Err(proptest::test_runner::TestCaseError::reject("no free character"));
        };
        check_run(&art, c, r, heading as f64 * FRAC_PI_2)?;
    }
}

const ROOM: &str = "\
    ##############\n\
    #............#\n\
    #..##........#\n\
    #..##....#...#\n\
    #........#...#\n\
    #............#\n\
    ##############";

#[test]
fn room_rims_are_swept() {
    let wd = world(ROOM, 2, 4, 0.0).unwrap();
    check_run(ROOM, 2, 4, 0.0).unwrap();
    let (out, m, _) = run_ext(&wd, BaStarExtendedOptions::default());
    let mb = run_ba(&wd);
    assert!(mb.effective_coverage < 0.95, "{}", mb.effective_coverage);
    assert!(m.effective_coverage > 0.99, "{}", m.effective_coverage);
    let starts = count(&out.trace, |e| matches!(e, Event::WallFollowStart));
    assert!(starts >= 1);
    assert_eq!(
        starts,
        count(&out.trace, |e| matches!(e, Event::WallFollowEnd))
    );
    // BA*'s region changes, plus the marked transfers between rims.
    assert!(m.backtracks + 1 >= m.regions);
    assert_eq!(
        count(&out.trace, |e| matches!(e, Event::BacktrackStart)),
        count(&out.trace, |e| matches!(e, Event::BacktrackEnd))
    );
}

/// Length of the moves after trace record `from` from the first wall pass on (the final
/// clean-up when `from` is BA*'s last region end).
fn length_after(trace: &Trace, from: usize) -> f64 {
    let (mut on, mut last, mut len) = (false, None::<[f64; 2]>, 0.0);
    for r in trace.entries().skip(from) {
        match r {
            Entry::Event {
                event: Event::WallFollowStart,
                ..
            } => on = true,
            Entry::Pose { pose, .. } => {
                if let (true, Some(l)) = (on, last) {
                    len += (pose.x - l[0]).hypot(pose.y - l[1]);
                }
                last = Some([pose.x, pose.y]);
            }
            Entry::Event { .. } => {}
        }
    }
    len
}

/// Length of the moves inside backtrack sections after trace record `from`.
fn backtrack_length_after(trace: &Trace, from: usize) -> f64 {
    let (mut inside, mut last, mut len) = (false, None::<[f64; 2]>, 0.0);
    for r in trace.entries().skip(from) {
        match r {
            Entry::Event {
                event: Event::BacktrackStart,
                ..
            } => inside = true,
            Entry::Event {
                event: Event::BacktrackEnd,
                ..
            } => inside = false,
            Entry::Pose { pose, .. } => {
                if let (true, Some(l)) = (inside, last) {
                    len += (pose.x - l[0]).hypot(pose.y - l[1]);
                }
                last = Some([pose.x, pose.y]);
            }
            Entry::Event { .. } => {}
        }
    }
    len
}

#[test]
fn final_transfers_are_backtracking_transfers() {
    // Cleaning only after BA*: the robot must travel between the rims of the rooms, and those
    // trips are marked as backtracking transfers (drawn dashed, counted in the backtrack length).
    // BA*'s own backtracking (with the shorter straight transfers the tour here ends beside
    // the last rims and no trip between rims reaches a robot diameter).
    let wd = world(HALLS, 2, 9, 0.0).unwrap();
    let opts = BaStarExtendedOptions {
        extension: ExtensionOptions {
            reach_r: 0.0,
            ..ExtensionOptions::default()
        },
        shorter_backtrack: false,
        ..BaStarExtendedOptions::default()
    };
    let (out, m, _) = run_ext(&wd, opts);
    assert_eq!(m.collisions, 0);
    assert!(m.effective_coverage > 0.99);
    let (_, last_region_end) = first_pass_last_region_end(&out.trace);
    let after = backtrack_length_after(&out.trace, last_region_end);
    assert!(after >= 2.0 * R, "{after}");
    assert!(m.backtrack_length_m >= after);
    assert!(m.backtracks + 1 > m.regions);
}

#[test]
fn merging_saves_turns_and_keeps_coverage() {
    let wd = world(ROOM, 2, 4, 0.0).unwrap();
    let merge = |merge_segments| BaStarExtendedOptions {
        extension: ExtensionOptions {
            merge_segments,
            ..ExtensionOptions::default()
        },
        ..BaStarExtendedOptions::default()
    };
    let (mo, merged, _) = run_ext(&wd, merge(true));
    let (po, pixel, _) = run_ext(&wd, merge(false));
    assert_eq!(pixel.collisions, 0);
    assert_eq!(merged.collisions, 0);
    // Far fewer waypoints in the passes; the whole run may turn a little more or less (the
    // merged walk leaves other one-pixel strips for later passes), never much more.
    let (a, b) = (pass_poses(&mo.trace), pass_poses(&po.trace));
    assert!(2 * a < b, "merged {a} pixel {b}");
    assert!(
        merged.turns * 10 < pixel.turns * 11,
        "{} {}",
        merged.turns,
        pixel.turns
    );
    assert!(merged.effective_coverage >= pixel.effective_coverage - 0.002);
}

const BLOCKS: &str = "\
    ####################\n\
    #..................#\n\
    #..................#\n\
    #..................#\n\
    #.....######.......#\n\
    #.....######.......#\n\
    #.....######.......#\n\
    #..................#\n\
    #..................#\n\
    #..................#\n\
    ####################";

const HALLS: &str = "\
    ##############################\n\
    #............................#\n\
    #..####......####......####..#\n\
    #..####......####......####..#\n\
    #............................#\n\
    #............................#\n\
    #..####......####......####..#\n\
    #..####......####......####..#\n\
    #............................#\n\
    #............................#\n\
    ##############################";

/// Index of the first wall pass and of the last region end in a trace.
fn first_pass_last_region_end(trace: &Trace) -> (usize, usize) {
    let mut last_region_end = 0;
    let mut first_pass = usize::MAX;
    for (k, r) in trace.entries().enumerate() {
        if let Entry::Event { event, .. } = r {
            match event {
                Event::RegionEnd { .. } => last_region_end = k,
                Event::WallFollowStart => first_pass = first_pass.min(k),
                _ => {}
            }
        }
    }
    (first_pass, last_region_end)
}

#[test]
fn zero_reach_cleans_only_after_ba_star() {
    let wd = world(BLOCKS, 2, 8, 0.0).unwrap();
    let opts = BaStarExtendedOptions {
        extension: ExtensionOptions {
            reach_r: 0.0,
            ..ExtensionOptions::default()
        },
        ..BaStarExtendedOptions::default()
    };
    let (out, m, _) = run_ext(&wd, opts);
    assert_eq!(m.collisions, 0);
    assert!(m.effective_coverage > 0.99);
    assert!(m.regions >= 2, "{}", m.regions);
    // Every pass starts after BA*'s last region ended.
    let (first_pass, last_region_end) = first_pass_last_region_end(&out.trace);
    assert!(first_pass > last_region_end && first_pass != usize::MAX);
    // The default cleans only after BA* too.
    let (out_d, _, _) = run_ext(&wd, BaStarExtendedOptions::default());
    assert_eq!(out_d.trace, out.trace);
    // With a reach, passes also run between regions.
    let opts = BaStarExtendedOptions {
        extension: ExtensionOptions {
            reach_r: 4.0,
            ..ExtensionOptions::default()
        },
        ..BaStarExtendedOptions::default()
    };
    let (out, m, _) = run_ext(&wd, opts);
    assert_eq!(m.collisions, 0);
    let (first_pass, last_region_end) = first_pass_last_region_end(&out.trace);
    assert!(first_pass < last_region_end);
}

#[test]
fn lane_ends_drive_to_the_wall() {
    let wd = world(BLOCKS, 2, 8, 0.0).unwrap();
    let opts = BaStarExtendedOptions {
        extension: ExtensionOptions {
            lane_ends: true,
            ..ExtensionOptions::default()
        },
        ..BaStarExtendedOptions::default()
    };
    let (out, m, _) = run_ext(&wd, opts);
    let (plain, mp, _) = run_ext(&wd, BaStarExtendedOptions::default());
    assert_eq!(m.collisions, 0);
    assert!(m.effective_coverage > 0.99);
    assert_ne!(out.trace, plain.trace);
    // The first lane (north from the start) goes on past its last tile centre to the wall:
    // the robot gets nearer the north wall than any tile centre with the option off.
    let top = |t: &Trace| t.poses().map(|p| p.y).fold(f64::MIN, f64::max);
    let bm_top = |t: &Trace| {
        let mut y = f64::MIN;
        for r in t.entries() {
            match r {
                Entry::Event {
                    event: Event::WallFollowStart,
                    ..
                } => break,
                Entry::Pose { pose, .. } => y = y.max(pose.y),
                Entry::Event { .. } => {}
            }
        }
        y
    };
    assert!(bm_top(&out.trace) > bm_top(&plain.trace) + 0.01);
    assert!(top(&out.trace) >= bm_top(&out.trace));
    assert!(mp.effective_coverage > 0.99);
}

#[test]
fn options_parse_and_refuse_unknown_fields() {
    let o: PlannerOptions = serde_json::from_str(
        r#"{"ba_star_extended": {"extension": {"reach_r": 2.5, "merge_segments": false},
            "ba_star": {"smoothing": false}}}"#,
    )
    .unwrap();
    assert!((o.ba_star_extended.extension.reach_r - 2.5).abs() < 1e-12);
    assert!(!o.ba_star_extended.extension.merge_segments);
    assert!(!o.ba_star_extended.ba_star.smoothing);
    assert!(serde_json::from_str::<PlannerOptions>(
        r#"{"ba_star_extended": {"extension": {"reach": 2.5}}}"#
    )
    .is_err());
    let wd = world(ROOM, 2, 4, 0.0).unwrap();
    let p = build("ba-star-extended", &PlannerOptions::default(), &wd).unwrap();
    assert_eq!(p.name(), "ba-star-extended");
    assert!(!p.is_offline());
}

// ---------------------------------------------------------------------------------------------
// Online honesty.

fn flip_unseen(wd: &World, p: &BaStarExtended) -> World {
    let known = p.backbone().known_map().unwrap();
    let mut m = wd.map().clone();
    let f = *m.frame();
    for row in 0..f.height {
        for col in 0..f.width {
            if !known.is_seen(col, row) {
                let v = if m.get(col, row).is_free() {
                    Cell::Occupied
                } else {
                    Cell::Free
                };
                m.set(col, row, v);
            }
        }
    }
    World::new(m, wd.robot(), Some(wd.start())).unwrap()
}

#[test]
fn trace_ignores_pixels_never_sensed() {
    for seed in 0..4u64 {
        let (art, c, r) = random_art(16, 12, 0.2, seed).unwrap();
        // A sealed-off part behind a wall thicker than the sensor range.
        let art: String = art
            .lines()
            .enumerate()
            .map(|(i, l)| format!("{l}#####{}", if i % 3 == 0 { "..#.." } else { "....." }))
            .collect::<Vec<_>>()
            .join("\n");
        let Some(wd) = world(&art, c, r, 0.0) else {
            continue;
        };
        let (out, _, p) = run_ext(&wd, BaStarExtendedOptions::default());
        let unseen = p.backbone().known_map().unwrap().seen().count_zeroes(..);
        assert!(unseen > 0);
        let flipped = flip_unseen(&wd, &p);
        let (out2, m2, _) = run_ext(&flipped, BaStarExtendedOptions::default());
        assert_eq!(out.trace, out2.trace, "seed {seed}");
        assert_eq!(m2.collisions, 0);
    }
}

/// Poses recorded inside wall passes.
fn pass_poses(trace: &Trace) -> usize {
    let mut inside = false;
    let mut n = 0;
    for r in trace.entries() {
        match r {
            Entry::Event {
                event: Event::WallFollowStart,
                ..
            } => inside = true,
            Entry::Event {
                event: Event::WallFollowEnd,
                ..
            } => inside = false,
            Entry::Pose { .. } if inside => n += 1,
            _ => {}
        }
    }
    n
}

#[test]
fn a_diagonal_wall_is_followed_in_few_segments() {
    // A 1.2 m x 0.9 m room (0.01 m/px) crossed by a thick wall at about 27 degrees.
    let (w, h) = (120usize, 90usize);
    let mut cells = vec![Cell::Free; w * h];
    for row in 0..h {
        for col in 0..w {
            let border = col < 2 || row < 2 || col >= w - 2 || row >= h - 2;
            // Distance to the line through (20, 70) and (100, 30) (column, row).
            let (dx, dy) = (80.0f64, -40.0f64);
            let (px, py) = (col as f64 - 20.0, row as f64 - 70.0);
            let t = ((px * dx + py * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
            let d = (px - t * dx).hypot(py - t * dy);
            if border || d < 2.5 {
                cells[row * w + col] = Cell::Occupied;
            }
        }
    }
    let map = GridMap::new(ccpp_core::MapFrame::new(w, h, 0.01), cells).unwrap();
    let wd = World::new(map, Robot::new(0.07), Some(Pose::new(0.1, 0.1, 0.0))).unwrap();
    let (merged_out, merged, _) = run_ext(&wd, BaStarExtendedOptions::default());
    let opts = BaStarExtendedOptions {
        extension: ExtensionOptions {
            merge_segments: false,
            ..ExtensionOptions::default()
        },
        ..BaStarExtendedOptions::default()
    };
    let (pixel_out, pixel, _) = run_ext(&wd, opts);
    assert_eq!(merged.collisions, 0);
    assert_eq!(pixel.collisions, 0);
    let (a, b) = (pass_poses(&merged_out.trace), pass_poses(&pixel_out.trace));
    assert!(b > 0 && 4 * a < b, "merged {a} pixel {b}");
    assert!(
        merged.turns < pixel.turns,
        "{} {}",
        merged.turns,
        pixel.turns
    );
    assert!(merged.effective_coverage >= pixel.effective_coverage - 0.003);
    assert!(
        merged.effective_coverage > 0.99,
        "{}",
        merged.effective_coverage
    );
}

/// `min_yield` / `leave_fraction`: trips that do not pay for themselves are left, within the
/// budget; `min_yield: 0` or `leave_fraction: 0` drive every one.
#[test]
fn low_yield_trips_are_left_within_the_budget() {
    let opts = |min_yield, leave_fraction| BaStarExtendedOptions {
        extension: ExtensionOptions {
            reach_r: 0.0,
            min_yield,
            leave_fraction,
            ..ExtensionOptions::default()
        },
        ..BaStarExtendedOptions::default()
    };
    let d = ExtensionOptions::default();
    assert!(d.min_yield > 0.0 && d.leave_fraction > 0.0);
    let (mut differed, mut left_len, mut all_len) = (0, 0.0, 0.0);
    for (art, c, r) in [(HALLS, 2, 9), (BLOCKS, 1, 1), (ROOM, 2, 4)] {
        let wd = world(art, c, r, 0.0).unwrap();
        let (lo, lm, _) = run_ext(&wd, opts(d.min_yield, d.leave_fraction));
        let (ao, am, _) = run_ext(&wd, opts(0.0, d.leave_fraction));
        let (zo, _, _) = run_ext(&wd, opts(d.min_yield, 0.0));
        // No budget: every trip is driven, as with no threshold.
        assert_eq!(zo.trace, ao.trace);
        assert_eq!(lm.collisions, 0);
        assert!(lm.effective_coverage > 0.99, "{}", lm.effective_coverage);
        left_len += lm.path_length_m;
        all_len += am.path_length_m;
        if lo.trace != ao.trace {
            differed += 1;
            // What is left stays small (the changed order may also sweep a little more).
            assert!(
                lm.effective_coverage > am.effective_coverage - 0.005,
                "{} {}",
                lm.effective_coverage,
                am.effective_coverage
            );
        }
    }
    assert!(differed >= 1);
    // Shorter in all (one map alone may come out longer: the greedy order changes).
    assert!(left_len < all_len, "{left_len} {all_len}");
}

/// `simplify_fraction`: dropping wall-pass vertices that lose few pixels saves turns, stays
/// collision-free, and leaves at most that fraction of the floor; `0` loses no pixel.
#[test]
fn simplified_passes_save_turns_within_the_budget() {
    let opts = |simplify_fraction| BaStarExtendedOptions {
        extension: ExtensionOptions {
            reach_r: 0.0,
            simplify_fraction,
            ..ExtensionOptions::default()
        },
        ..BaStarExtendedOptions::default()
    };
    let d = BaStarExtendedOptions::default().extension.simplify_fraction;
    assert!(d > 0.0);
    let (mut turns_s, mut turns_z, mut differed) = (0, 0, 0);
    for (art, c, r) in [(HALLS, 2, 9), (BLOCKS, 1, 1), (ROOM, 2, 4)] {
        let wd = world(art, c, r, 0.0).unwrap();
        let (so, sm, _) = run_ext(&wd, opts(0.01));
        let (zo, zm, _) = run_ext(&wd, opts(0.0));
        assert_eq!(sm.collisions, 0);
        assert_eq!(sm.coverage_rate, Some(1.0));
        // The order of later passes may change too: a little slack beyond the budget.
        assert!(
            sm.effective_coverage > zm.effective_coverage - 0.01 - 0.003,
            "{} {}",
            sm.effective_coverage,
            zm.effective_coverage
        );
        turns_s += sm.turns;
        turns_z += zm.turns;
        differed += usize::from(so.trace != zo.trace);
    }
    assert!(differed >= 1);
    assert!(turns_s < turns_z, "{turns_s} {turns_z}");
}

/// `simplify_loss`: the most one dropped vertex may lose; `0` drops only vertices that lose
/// nothing, a larger cap drops more (fewer turns in all).
#[test]
fn simplify_loss_caps_each_dropped_vertex() {
    let opts = |simplify_loss| BaStarExtendedOptions {
        extension: ExtensionOptions {
            reach_r: 0.0,
            simplify_fraction: 0.05,
            simplify_loss,
            ..ExtensionOptions::default()
        },
        ..BaStarExtendedOptions::default()
    };
    let (mut turns_0, mut turns_3, mut differed) = (0, 0, 0);
    for (art, c, r) in [(HALLS, 2, 9), (BLOCKS, 1, 1), (ROOM, 2, 4)] {
        let wd = world(art, c, r, 0.0).unwrap();
        let (zo, zm, _) = run_ext(&wd, opts(0.0));
        let (bo, bm, _) = run_ext(&wd, opts(3.0));
        assert_eq!(bm.collisions, 0);
        assert_eq!(bm.coverage_rate, Some(1.0));
        turns_0 += zm.turns;
        turns_3 += bm.turns;
        differed += usize::from(zo.trace != bo.trace);
    }
    assert!(differed >= 1);
    assert!(turns_3 < turns_0, "{turns_3} {turns_0}");
}

#[test]
fn shorter_backtrack_changes_the_plan() {
    // Several halls: BA* backtracks between them; the extension's straight known-free way is
    // driven where it is shorter than BA*'s smoothed tile path, so the plans differ and the
    // backtracking is no longer.
    let wd = world(HALLS, 2, 9, 0.0).unwrap();
    let opts = |shorter_backtrack| BaStarExtendedOptions {
        shorter_backtrack,
        ..BaStarExtendedOptions::default()
    };
    let (on, m_on, _) = run_ext(&wd, opts(true));
    let (off, m_off, _) = run_ext(&wd, opts(false));
    assert_ne!(on.trace.entries().count(), 0);
    assert_ne!(
        format!("{:?}", on.trace.entries().collect::<Vec<_>>()),
        format!("{:?}", off.trace.entries().collect::<Vec<_>>())
    );
    assert!(
        m_on.path_length_m < m_off.path_length_m,
        "{m_on:?} {m_off:?}"
    );
    for m in [&m_on, &m_off] {
        assert_eq!(m.collisions, 0);
        assert!(m.effective_coverage > 0.99);
    }
}

/// A corridor entered near its west end: BA*'s first region sweeps everything east of the
/// start and ends at the far end, then BA* backtracks west.
const CORRIDOR: &str = "\
    ######################################################################\n\
    #....................................................................#\n\
    #....................................................................#\n\
    #....................................................................#\n\
    #....................................................................#\n\
    #....................................................................#\n\
    #....................................................................#\n\
    #....................................................................#\n\
    #....................................................................#\n\
    #....................................................................#\n\
    #....................................................................#\n\
    #....................................................................#\n\
    #....................................................................#\n\
    ######################################################################";

#[test]
fn backtrack_sweep_sweeps_rims_on_the_way_back() {
    // With the default, the robot sweeps the rim along the wall on its way back to BA*'s start
    // point (a wall pass before BA*'s last region); `0` cleans only after BA*. The rim swept
    // on the way is not swept again: the final clean-up is shorter. (Whether the whole path
    // is shorter depends on the map: on the 14 shared maps the mean path ratio fell from
    // 1.3218 to 1.3128; on this small corridor it grows by 2.5 %.)
    let wd = world(CORRIDOR, 8, 6, 0.0).unwrap();
    let opts = |backtrack_sweep| BaStarExtendedOptions {
        backtrack_sweep,
        ..BaStarExtendedOptions::default()
    };
    let (on, m_on, _) = run_ext(&wd, BaStarExtendedOptions::default());
    let (off, m_off, _) = run_ext(&wd, opts(0.0));
    let (first_on, last_on) = first_pass_last_region_end(&on.trace);
    let (first_off, last_off) = first_pass_last_region_end(&off.trace);
    assert!(first_on < last_on, "{first_on} {last_on}");
    assert!(first_off > last_off && first_off != usize::MAX);
    let (final_on, final_off) = (
        length_after(&on.trace, last_on),
        length_after(&off.trace, last_off),
    );
    assert!(final_on < final_off, "{final_on} {final_off}");
    for m in [&m_on, &m_off] {
        assert_eq!(m.collisions, 0);
        assert_eq!(m.coverage_rate, Some(1.0));
        assert!(m.effective_coverage > 0.99, "{m:?}");
    }
    // A sweep that must pay for itself many times over is not driven here.
    let (strict, _, _) = run_ext(&wd, opts(1e9));
    assert_eq!(strict.trace, off.trace);
}
