//! BSA and extended BSA on ASCII maps: coverage, rules RS1-RS4, sides, determinism.

use ccpp_core::metrics::{compute, Metrics};
use ccpp_core::planners::bsa::{Bsa, BsaOptions, Side};
use ccpp_core::planners::bsa_extended::{BsaExtended, BsaExtendedOptions};
use ccpp_core::sim::{simulate, RunOutput, SimConfig};
use ccpp_core::trace::Event;
use ccpp_core::world::{Robot, World};
use ccpp_core::{GridMap, Pose};

/// Pixels per ASCII character and metres per pixel: one character = one cell of side 0.2 m
/// for a robot of radius 0.1 m.
const SCALE: usize = 5;
const RES: f64 = 0.04;
const R: f64 = 0.1;

/// World of an ASCII map, start at the centre of character (col, row) (row 0 = top line).
fn world(art: &str, col: usize, row: usize, theta: f64) -> World {
    let map = GridMap::from_ascii_scaled(art, SCALE, RES).expect("valid art");
    let h = map.frame().height as f64 * RES;
    let c = SCALE as f64 * RES;
    let start = Pose::new((col as f64 + 0.5) * c, h - (row as f64 + 0.5) * c, theta);
    World::new(map, Robot::new(R), Some(start)).expect("robot fits at the start")
}

fn run(w: &World, side: Side) -> (RunOutput, Metrics) {
    let mut p = Bsa::new(BsaOptions { side });
    let out = simulate(w, &mut p, &SimConfig::default());
    let m = compute(w, &out, "t");
    (out, m)
}

fn run_ext(w: &World, side: Side) -> (RunOutput, Metrics) {
    let mut p = BsaExtended::new(BsaExtendedOptions {
        side,
        ..Default::default()
    });
    let out = simulate(w, &mut p, &SimConfig::default());
    let m = compute(w, &out, "t");
    (out, m)
}

fn room(w: usize, h: usize) -> String {
    let mut s = String::new();
    for r in 0..h {
        for c in 0..w {
            s.push(if r == 0 || c == 0 || r == h - 1 || c == w - 1 {
                '#'
            } else {
                '.'
            });
        }
        s.push('\n');
    }
    s
}

/// The paper starts a spiral "nearby an obstacle, which is situated in the RLS": from a corner
/// an empty room is one spiral, no cell entered twice, ending near the centre.
#[test]
fn empty_room_is_one_spiral_ending_near_the_centre() {
    let art = room(12, 9);
    for (col, side) in [(1, Side::Left), (10, Side::Right)] {
        let w = world(&art, col, 7, 0.0);
        let (out, m) = run(&w, side);
        assert_eq!(m.coverage_rate, Some(1.0), "{side:?}");
        assert_eq!(m.collisions, 0);
        assert_eq!(m.regions, 1, "{side:?}");
        assert_eq!(m.backtracks, 0, "{side:?}");
        assert_eq!(m.revisit_rate, 0.0, "{side:?}");
        let last = out.trace.poses().last().unwrap();
        // Interior: 10 x 7 cells of 0.2 m from (0.2, 0.2): centre (1.2, 0.9); the innermost ring
        // is the 4 x 1 strip x in [0.9, 1.5], y = 0.9.
        assert!(
            (last.x - 1.2).abs() <= 0.31 && (last.y - 0.9).abs() <= 0.01,
            "{side:?} ends at {last:?}"
        );
    }
}

/// From the middle of the room the robot first drives to the wall; that spoke can leave a
/// one-cell pocket at its tip (one short backtrack), coverage stays complete.
#[test]
fn empty_room_from_the_middle_is_complete() {
    let art = room(12, 9);
    for side in [Side::Left, Side::Right] {
        let w = world(&art, 5, 4, 0.0);
        let (_, m) = run(&w, side);
        assert_eq!(m.coverage_rate, Some(1.0), "{side:?}");
        assert_eq!(m.collisions, 0);
        assert!(m.regions <= 2, "{side:?}: {m:?}");
        assert!(m.revisit_rate < 0.1, "{side:?}: {m:?}");
    }
}

/// The cells whose centres the robot reached, in order (no consecutive repeats), as ASCII
/// (col, row) of the map drawing.
fn cells(w: &World, out: &RunOutput) -> Vec<(usize, usize)> {
    let c = SCALE as f64 * RES;
    let h = w.frame().height as f64 * RES;
    let mut v: Vec<(usize, usize)> = Vec::new();
    for p in out.trace.poses() {
        let fx = p.x / c - 0.5;
        let fy = (h - p.y) / c - 0.5;
        if (fx - fx.round()).abs() > 1e-6 || (fy - fy.round()).abs() > 1e-6 {
            continue;
        }
        let t = (fx.round() as usize, fy.round() as usize);
        if v.last() != Some(&t) {
            v.push(t);
        }
    }
    v
}

fn count(out: &RunOutput, f: impl Fn(&Event) -> bool) -> usize {
    out.trace.events().filter(|(_, e)| f(e)).count()
}

/// RS4: obstacle on the RLS, front free: straight on, never turning.
#[test]
fn rs4_moves_forward() {
    let art = "#######\n#.....#\n#######";
    for side in [Side::Left, Side::Right] {
        let w = world(art, 1, 1, 0.0);
        let (out, m) = run(&w, side);
        assert_eq!(
            cells(&w, &out),
            vec![(1, 1), (2, 1), (3, 1), (4, 1), (5, 1)]
        );
        assert_eq!(m.turns, 0, "{side:?}");
        assert_eq!(m.coverage_rate, Some(1.0));
    }
}

/// RS1: all around blocked ends the spiral; with no BP left the run ends (one region, no
/// backtrack). A single free cell ends at once.
#[test]
fn rs1_ends_the_spiral() {
    let w = world("#######\n#.....#\n#######", 1, 1, 0.0);
    let (out, m) = run(&w, Side::Left);
    assert_eq!(m.regions, 1);
    assert_eq!(count(&out, |e| matches!(e, Event::RegionEnd { .. })), 1);
    assert_eq!(m.backtracks, 0);
    let w = world("###\n#.#\n###", 1, 1, 0.0);
    let (out, m) = run(&w, Side::Left);
    assert_eq!(m.path_length_m, 0.0);
    assert_eq!(m.regions, 1);
    assert_eq!(cells(&w, &out), vec![(1, 1)]);
}

/// RS2: the RLS neighbour is free: turn to it even though the front is free too; the front
/// cell is recorded as a BP and covered after backtracking.
#[test]
fn rs2_turns_to_the_free_rls() {
    for (art, side, turn) in [
        ("#######\n###.###\n#.....#\n#######", Side::Left, (3, 1)),
        ("#######\n#.....#\n###.###\n#######", Side::Right, (3, 2)),
    ] {
        let row = if side == Side::Left { 2 } else { 1 };
        let w = world(art, 1, row, 0.0);
        let (out, m) = run(&w, side);
        let v = cells(&w, &out);
        assert_eq!(&v[..4], &[(1, row), (2, row), (3, row), turn], "{side:?}");
        assert_eq!(m.coverage_rate, Some(1.0));
        assert_eq!(m.regions, 2);
        assert!(count(&out, |e| matches!(e, Event::BacktrackPoint { .. })) >= 1);
    }
}

/// RS3: front blocked, RLS blocked: turn to the OLS.
#[test]
fn rs3_turns_to_the_ols() {
    for (art, side, row, turn) in [
        ("#####\n#...#\n###.#\n#####", Side::Left, 1, (3, 2)),
        ("#####\n###.#\n#...#\n#####", Side::Right, 2, (3, 1)),
    ] {
        let w = world(art, 1, row, 0.0);
        let (out, m) = run(&w, side);
        assert_eq!(
            cells(&w, &out),
            vec![(1, row), (2, row), (3, row), turn],
            "{side:?}"
        );
        assert_eq!(m.regions, 1);
    }
}

const BLOCKS: &str = "\
##############
#............#
#..##....#...#
#..##....#...#
#........#...#
#....###.....#
#....###..#..#
#............#
##############";

const COMB: &str = "\
#############
#...........#
#.#.#.#.#.#.#
#.#.#.#.#.#.#
#.#.#.#.#.#.#
#.#.#.#.#.#.#
#############";

const TWO_ROOMS: &str = "\
#############
#.....#.....#
#.....#.....#
#...........#
#.....#.....#
#.....#.....#
#############";

#[test]
fn rooms_with_blocks_comb_and_door_are_covered() {
    for (name, art, col, row) in [
        ("blocks", BLOCKS, 1, 7),
        ("comb", COMB, 1, 1),
        ("two rooms", TWO_ROOMS, 1, 5),
        ("two rooms, middle", TWO_ROOMS, 3, 3),
    ] {
        for side in [Side::Left, Side::Right] {
            let w = world(art, col, row, 0.0);
            let (out, m) = run(&w, side);
            assert_eq!(m.coverage_rate, Some(1.0), "{name} {side:?}");
            assert_eq!(m.collisions, 0, "{name} {side:?}");
            assert_eq!(
                m.regions as usize,
                count(&out, |e| matches!(e, Event::RegionStart { .. }))
            );
            assert_eq!(m.backtracks, m.regions - 1, "{name} {side:?}");
        }
    }
}

/// Extended BSA on maps whose cells do not line up with the obstacles (robot radius 0.08 m,
/// characters of 0.2 m): collision-free, deterministic, at least basic BSA's effective
/// coverage, and wall following happens.
#[test]
fn extended_beats_basic_near_obstacles() {
    for (name, art, col, row) in [
        ("blocks", BLOCKS, 1, 7),
        ("comb", COMB, 1, 1),
        ("two rooms", TWO_ROOMS, 3, 3),
    ] {
        let map = GridMap::from_ascii_scaled(art, 8, 0.025).unwrap();
        let h = map.frame().height as f64 * 0.025;
        let start = Pose::new(
            (f64::from(col) + 0.5) * 0.2,
            h - (f64::from(row) + 0.5) * 0.2,
            0.0,
        );
        let w = World::new(map, Robot::new(0.08), Some(start)).unwrap();
        for side in [Side::Left, Side::Right] {
            let (_, mb) = run(&w, side);
            let (out, me) = run_ext(&w, side);
            let (out2, _) = run_ext(&w, side);
            assert_eq!(out.trace, out2.trace, "{name} {side:?}: not deterministic");
            assert_eq!(me.collisions, 0, "{name} {side:?}");
            assert_eq!(mb.collisions, 0, "{name} {side:?}");
            assert!(
                me.effective_coverage > mb.effective_coverage,
                "{name} {side:?}: {} vs {}",
                me.effective_coverage,
                mb.effective_coverage
            );
            assert!(me.effective_coverage > 0.97, "{name} {side:?}: {me:?}");
            assert!(count(&out, |e| matches!(e, Event::WallFollowStart)) >= 1);
            assert_eq!(
                count(&out, |e| matches!(e, Event::WallFollowStart)),
                count(&out, |e| matches!(e, Event::WallFollowEnd))
            );
        }
    }
}

/// `strip_walk`: at fine pixels the corners of BSA's spiral rings leave small triangles whose
/// pixels the final clean-up reaches only from positions off the obstacle contour. With the
/// option the walk follows such a strip (one pass, merged into straight segments); without it
/// every position is a chunk of its own (one pixel step, often a turn). Fewer turns, the plans
/// differ, and the floor lost is within what simplifying the longer walks may leave
/// (`simplify_fraction`, 0.6 % of the floor for bsa-extended).
#[test]
fn strip_walk_follows_strips_off_the_contour() {
    // Cells of 0.2 m at 0.01 m pixels (a tool radius of 10 pixels): 10 x 8 cells in the room.
    let map = GridMap::from_ascii_scaled(&room(12, 10), 20, 0.01).unwrap();
    let start = Pose::new(0.3, 0.3, 0.0);
    let w = World::new(map, Robot::new(0.1), Some(start)).unwrap();
    let go = |strip_walk| {
        let mut p = BsaExtended::new(BsaExtendedOptions {
            strip_walk,
            ..Default::default()
        });
        let out = simulate(&w, &mut p, &SimConfig::default());
        let m = compute(&w, &out, "t");
        (out, m)
    };
    let (on, m_on) = go(true);
    let (off, m_off) = go(false);
    assert_ne!(on.trace, off.trace);
    for m in [&m_on, &m_off] {
        assert_eq!(m.collisions, 0);
        assert_eq!(m.coverage_rate, Some(1.0));
        assert!(m.effective_coverage > 0.99, "{m:?}");
    }
    assert!(m_on.turns < m_off.turns, "{} {}", m_on.turns, m_off.turns);
    assert!(
        m_on.effective_coverage >= m_off.effective_coverage - 0.006,
        "{m_on:?} {m_off:?}"
    );
}

mod props {
    use super::*;
    use proptest::prelude::*;

    /// A random map: `w x h` characters inside a border wall, obstacles with probability `p`;
    /// the start is the first free character in reading order.
    fn random_world(w: usize, h: usize, p: f64, seed: u64) -> Option<World> {
        let mut rng = ccpp_core::rng::SplitMix64::new(seed);
        let mut art = String::new();
        let mut start = None;
        for r in 0..h + 2 {
            for c in 0..w + 2 {
                let border = r == 0 || c == 0 || r == h + 1 || c == w + 1;
                let wall = border || rng.range(0.0, 1.0) < p;
                if !wall && start.is_none() {
                    start = Some((c, r));
                }
                art.push(if wall { '#' } else { '.' });
            }
            art.push('\n');
        }
        let (c, r) = start?;
        Some(world(&art, c, r, 0.0))
    }

    /// Fixed seeds: the same cases on every run (CI and local alike); the counterexamples
    /// proptest found earlier are named tests below.
    fn config(cases: u32, seed: u64) -> ProptestConfig {
        ProptestConfig {
            cases,
            rng_seed: proptest::test_runner::RngSeed::Fixed(seed),
            ..ProptestConfig::default()
        }
    }

    /// Extended BSA sweeps at least what basic BSA sweeps on `random_world(w, h, p, seed)`.
    fn assert_extended_no_worse(w: usize, h: usize, p: f64, seed: u64) {
        let world = random_world(w, h, p, seed).expect("a free character");
        let (_, mb) = run(&world, Side::Left);
        let (_, me) = run_ext(&world, Side::Left);
        assert_eq!(me.collisions, 0);
        assert!(
            me.effective_coverage >= mb.effective_coverage - 1e-12,
            "{} < {}",
            me.effective_coverage,
            mb.effective_coverage
        );
    }

    /// Found by proptest (CI, stop 17): the extension's straight transfer between spirals was
    /// shorter than BSA's cell path but skipped pixels at spiral corners that the cell path
    /// swept, and the final clean-up leaves such specks.
    #[test]
    fn extended_no_worse_counterexample_15x8() {
        assert_extended_no_worse(15, 8, 0.271_616_595_059_142_5, 4_444_818_232_748_928_553);
    }

    /// Found by proptest (CI, stop 17), same cause as the 15 x 8 case.
    #[test]
    fn extended_no_worse_counterexample_5x10() {
        assert_extended_no_worse(5, 10, 0.172_224_253_015_350_52, 1_275_306_396_875_129_893);
    }

    proptest! {
        #![proptest_config(config(48, 0x00b5_a001))]

        #[test]
        fn bsa_covers_every_reachable_cell(
            w in 5usize..=40, h in 5usize..=40, p in 0.0f64..0.35, seed: u64, left: bool
        ) {
            let Some(world) = random_world(w, h, p, seed) else { return Ok(()); };
            let side = if left { Side::Left } else { Side::Right };
            let (out, m) = run(&world, side);
            prop_assert_eq!(m.coverage_rate, Some(1.0));
            prop_assert_eq!(m.collisions, 0);
            let (out2, _) = run(&world, side);
            prop_assert_eq!(out.trace, out2.trace);
        }
    }

    proptest! {
        #![proptest_config(config(32, 0x00b5_a002))]

        #[test]
        fn bsa_extended_is_safe_and_no_worse(
            w in 5usize..=20, h in 5usize..=20, p in 0.0f64..0.35, seed: u64
        ) {
            let Some(world) = random_world(w, h, p, seed) else { return Ok(()); };
            let (_, mb) = run(&world, Side::Left);
            let (out, me) = run_ext(&world, Side::Left);
            prop_assert_eq!(me.collisions, 0);
            prop_assert!(me.effective_coverage >= mb.effective_coverage - 1e-12,
                "{} < {}: {:?} {:?}", me.effective_coverage, mb.effective_coverage, me, mb);
            let (out2, _) = run_ext(&world, Side::Left);
            prop_assert_eq!(out.trace, out2.trace);
        }
    }
}
