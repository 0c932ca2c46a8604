//! Unit tests of the BCD planner's private pieces.

use super::angles::dominant_angles;
use super::cells::{decompose, split_ends, split_jumps, Cell};
use super::finish::Item;
use super::finish::{moves, repair, smooth};
use super::lanes::{drop_covered, lanes_of, odd_runs};
use super::lattice::{Ctx, Lattice};
use super::transfer::Search;
use super::{on_pool, Bcd, BcdOptions};
use crate::geometry::Point;
use crate::planner::Step;
use crate::trace::Event;
use crate::world::World;

/// The geometry of `world` on its reachable C-free set, without a transfer margin, for a tool
/// of `rt` pixels.
fn reach_ctx(world: &World, rt: f64) -> Ctx<'_> {
    let n = world.frame().len();
    let reach = world.reachable();
    let ok: Vec<bool> = (0..n).map(|i| reach.contains(i)).collect();
    Ctx {
        world,
        frame: *world.frame(),
        safe: ok.clone(),
        keep_px: None,
        ok,
        rt,
        coarse: super::hops::CoarseCache::default(),
        stop: None,
    }
}

#[test]
fn decomposition_splits_and_merges_around_a_block() {
    let art = "........\n..##....\n..##....\n........";
    let g: crate::grid::GridMap = art.parse().unwrap();
    let d = decompose(8, 4, true, &|c, r| g.get(c, r).is_free());
    // Left part, above the block, below the block, right part.
    assert_eq!(d.len(), 4);
    assert_eq!((d[0].u0, d[0].runs.len()), (0, 2));
    assert_eq!((d[1].u0, d[1].runs.clone()), (2, vec![(0, 0), (0, 0)]));
    assert_eq!((d[2].u0, d[2].runs.clone()), (2, vec![(3, 3), (3, 3)]));
    assert_eq!((d[3].u0, d[3].runs.len()), (4, 4));
}

fn block_room() -> World {
    let art = "##########\n#........#\n#..##....#\n#..##....#\n#........#\n##########";
    let map = crate::grid::GridMap::from_ascii_scaled(art, 10, 0.02).unwrap();
    World::new(
        map,
        crate::world::Robot::new(0.08),
        Some(crate::geometry::Pose::new(0.3, 0.3, 0.0)),
    )
    .unwrap()
}

/// A 60 x 30 px room turned by `deg` degrees in a 90 x 90 px map (0.05 m/px).
fn turned_room(deg: f64) -> World {
    let (si, co) = deg.to_radians().sin_cos();
    let mut art = String::new();
    for r in 0..90 {
        for c in 0..90 {
            let (x, y) = (f64::from(c) - 44.5, f64::from(r) - 44.5);
            let (u, v) = (co * x + si * y, -si * x + co * y);
            art.push(if u.abs() < 30.0 && v.abs() < 15.0 {
                '.'
            } else {
                '#'
            });
        }
        art.push('\n');
    }
    let map = crate::grid::GridMap::from_ascii_scaled(art.trim_end(), 1, 0.05).unwrap();
    World::new(
        map,
        crate::world::Robot::new(0.15),
        Some(crate::geometry::Pose::new(2.25, 2.25, 0.0)),
    )
    .unwrap()
}

#[test]
fn walls_at_an_angle_get_a_turned_lattice() {
    for deg in [0.0, 30.0] {
        let world = turned_room(deg);
        let ctx = reach_ctx(&world, 3.0);
        let a = dominant_angles(&ctx)[0].to_degrees();
        // The image's rows run down: a room turned by +30 degrees there has walls at
        // 30 or 60 degrees (mod 90), whichever way the turn is read.
        let off = [deg, 90.0 - deg]
            .iter()
            .map(|d| (a - d).abs().min(90.0 - (a - d).abs()))
            .fold(f64::INFINITY, f64::min);
        assert!(off < 1.5, "{deg}: found {a}");
    }
    // The turned room's plan covers it without contact and with few turns (lanes along
    // its walls, not staircases across them).
    let world = turned_room(30.0);
    let m = run(&world, &BcdOptions::default());
    assert_eq!(m.collisions, 0);
    assert!(m.effective_coverage >= 0.99, "{}", m.effective_coverage);
    // Its plan on the lattice turned to its walls reaches every piece and costs about what
    // the pixel lattice's does (here the pixels' is kept: the room is small).
    let frame = *world.frame();
    let ctx = reach_ctx(&world, 3.0);
    let mut search = Search::new(frame.width, frame.height);
    // The lattices' plain plans (`plan_on` makes the plan of the options it is given: with a
    // headland, only the headland's).
    let opts = BcdOptions {
        headland_min_m: None,
        ..BcdOptions::default()
    };
    let a = dominant_angles(&ctx)[0];
    let turned = Bcd::plan_on(&ctx, &Lattice::turned(&ctx, a), &opts, &mut search);
    let pixels = Bcd::plan_on(&ctx, &Lattice::pixels(&ctx), &opts, &mut search);
    assert_eq!(turned.0.skipped, 0);
    assert!(
        turned.0.cost < 1.2 * pixels.0.cost,
        "{} vs {}",
        turned.0.cost,
        pixels.0.cost
    );
}

#[test]
fn smoothing_straightens_wiggles_but_keeps_corners_and_marks() {
    let world = block_room();
    let frame = *world.frame();
    let n = frame.width * frame.height;
    let ctx = Ctx {
        world: &world,
        frame,
        ok: vec![true; n],
        safe: vec![true; n],
        keep_px: None,
        rt: 4.0,
        coarse: super::hops::CoarseCache::default(),
        stop: None,
    };
    // A wiggle of 0.3 px along a free row, then a corner, then a mark.
    let mut items: Vec<Item> = (0..36)
        .map(|i| {
            Item::Move(Point::new(
                14.0 + 2.0 * f64::from(i),
                15.0 + 0.3 * f64::from(i % 2),
            ))
        })
        .collect();
    items.push(Item::Move(Point::new(84.0, 25.0)));
    items.push(Item::Mark(Event::BacktrackStart));
    items.push(Item::Move(Point::new(84.0, 35.0)));
    let out = smooth(&ctx, items);
    let pts: Vec<Point> = moves(&out).into_iter().map(|m| m.0).collect();
    assert_eq!(pts.len(), 4, "{pts:?}");
    assert_eq!(pts[0], Point::new(14.0, 15.0));
    assert_eq!(pts[1], Point::new(84.0, 15.3));
    assert_eq!(pts[2], Point::new(84.0, 25.0));
    assert!(matches!(out[3], Item::Mark(Event::BacktrackStart)));
    // A chord within the tolerance that would hit the block (robot radius 4 px) is not taken.
    let around = vec![
        Item::Move(Point::new(20.0, 43.8)),
        Item::Move(Point::new(40.0, 44.25)),
        Item::Move(Point::new(60.0, 43.8)),
    ];
    assert_eq!(moves(&smooth(&ctx, around)).len(), 3);
}

#[test]
fn repair_counts_the_moves_it_cannot_route() {
    let world = block_room();
    let frame = *world.frame();
    let n = frame.width * frame.height;
    let ctx = Ctx {
        world: &world,
        frame,
        ok: vec![true; n],
        safe: vec![true; n],
        keep_px: None,
        rt: 4.0,
        coarse: super::hops::CoarseCache::default(),
        stop: None,
    };
    let mut search = Search::new(frame.width, frame.height);
    // A move into the middle of the block has no route: it is dropped and counted, and
    // the plan goes on from where it was.
    let items = vec![
        Item::Move(Point::new(14.0, 15.0)),
        Item::Move(Point::new(40.0, 30.0)),
        Item::Move(Point::new(84.0, 15.0)),
    ];
    let mut skipped = 0;
    let out = repair(&ctx, &mut search, items, &mut skipped);
    let pts: Vec<Point> = moves(&out).into_iter().map(|m| m.0).collect();
    assert_eq!(skipped, 1);
    assert_eq!(pts, vec![Point::new(14.0, 15.0), Point::new(84.0, 15.0)]);
    // A plan whose moves are all reachable counts nothing.
    let mut none = 0;
    let ok = vec![
        Item::Move(Point::new(14.0, 15.0)),
        Item::Move(Point::new(84.0, 45.0)),
    ];
    let routed = moves(&repair(&ctx, &mut search, ok, &mut none));
    assert_eq!(routed.last().map(|m| m.0), Some(Point::new(84.0, 45.0)));
    assert_eq!(none, 0);
}

fn run(world: &World, opts: &BcdOptions) -> crate::metrics::Metrics {
    let mut p = Bcd::try_new(world, opts).unwrap();
    let out = crate::sim::simulate(world, &mut p, &crate::sim::SimConfig::default());
    crate::metrics::compute(world, &out, "block_room")
}

#[test]
fn lanes_sit_on_closed_edges_and_on_the_lattice_between() {
    let cell = Cell {
        cols: true,
        u0: 3,
        runs: vec![(0, 9); 20],
    };
    // Both sides closed: lanes on both edges, as few as keep the gaps within 6 lines,
    // evenly spread (the lattice would take 5: 3, 6, 12, 18, 22).
    let l = lanes_of(&cell, 6.0, 0.0, false, false);
    assert_eq!(l, vec![3.0, 7.75, 12.5, 17.25, 22.0]);
    assert!(l.windows(2).all(|w| w[1] - w[0] <= 6.0));
    let l = lanes_of(&cell, 6.0, 2.0, false, false);
    assert_eq!(l, vec![3.0, 7.75, 12.5, 17.25, 22.0]);
    // One closed side: its edge lane, then the lattice.
    assert_eq!(
        lanes_of(&cell, 6.0, 0.0, false, true),
        vec![3.0, 6.0, 12.0, 18.0]
    );
    // Open sides: only the lattice, shared with the neighbours beyond.
    assert_eq!(lanes_of(&cell, 6.0, 0.0, true, true), vec![6.0, 12.0, 18.0]);
    // A lattice line within half a pixel of the edge belongs to this cell.
    assert_eq!(
        lanes_of(&cell, 6.0, 2.6, true, true),
        vec![3.0, 8.6, 14.6, 20.6]
    );
}

#[test]
fn block_room_is_covered_without_contact() {
    let world = block_room();
    let m = run(&world, &BcdOptions::default());
    assert_eq!(m.collisions, 0);
    assert!(m.effective_coverage >= 0.995, "{}", m.effective_coverage);
}

#[test]
fn rim_option_sweeps_what_lanes_miss() {
    // Every missed group swept (the default leaves the least useful 0.3 % of the floor,
    // which in this small room can be all the lanes miss).
    let all = BcdOptions {
        rim_coverage: 1.0,
        ..BcdOptions::default()
    };
    let world = block_room();
    let with = run(&world, &all);
    let without = run(
        &world,
        &BcdOptions {
            rim: false,
            ..all.clone()
        },
    );
    let picky = run(
        &world,
        &BcdOptions {
            rim_min_yield: 1.0,
            ..all
        },
    );
    assert_eq!(with.collisions + without.collisions + picky.collisions, 0);
    assert!(without.effective_coverage < with.effective_coverage);
    assert!(without.path_length_m < with.path_length_m);
    // A yield of a whole lane per metre is never met by a rim contour.
    assert!(picky.effective_coverage < with.effective_coverage);
}

#[test]
fn rim_coverage_trades_rim_passes_for_floor() {
    let world = block_room();
    let full = run(
        &world,
        &BcdOptions {
            rim_coverage: 1.0,
            min_coverage: 1.0,
            ..BcdOptions::default()
        },
    );
    let part = run(
        &world,
        &BcdOptions {
            rim_coverage: 0.98,
            min_coverage: 1.0,
            ..BcdOptions::default()
        },
    );
    assert_eq!(full.collisions + part.collisions, 0);
    assert!(
        full.effective_coverage >= 0.999,
        "{}",
        full.effective_coverage
    );
    // Leaving up to 2 % of the floor saves rim passes, and no more than that is left.
    assert!(part.path_length_m < full.path_length_m);
    assert!(part.effective_coverage < full.effective_coverage);
    assert!(
        part.effective_coverage >= 0.98,
        "{}",
        part.effective_coverage
    );
}

#[test]
fn a_plan_given_up_has_no_steps_and_one_not_given_up_is_the_plan() {
    use std::sync::atomic::AtomicBool;
    let world = block_room();
    let opts = BcdOptions::default();
    let given_up = Bcd::new_until(&world, &opts, &AtomicBool::new(true));
    assert!(given_up.replay.steps().is_empty());
    assert_eq!(given_up.cells(), 0);
    let kept = Bcd::new_until(&world, &opts, &AtomicBool::new(false));
    let plain = Bcd::new(&world, &opts);
    assert!(!kept.replay.steps().is_empty());
    assert_eq!(kept.replay.steps(), plain.replay.steps());
    assert_eq!(kept.cells(), plain.cells());
}

#[test]
fn same_plan_twice() {
    let world = block_room();
    let a = Bcd::new(&world, &BcdOptions::default());
    let b = Bcd::new(&world, &BcdOptions::default());
    assert_eq!(a.replay.steps(), b.replay.steps());
    assert_eq!(a.cells(), b.cells());
}

#[test]
fn min_coverage_trades_floor_for_turns_and_holds_it() {
    let world = block_room();
    let keep = run(
        &world,
        &BcdOptions {
            min_coverage: 1.0,
            ..BcdOptions::default()
        },
    );
    let mut last = keep.clone();
    for floor in [0.995, 0.98, 0.95] {
        let m = run(
            &world,
            &BcdOptions {
                min_coverage: floor,
                ..BcdOptions::default()
            },
        );
        assert_eq!(m.collisions, 0);
        // The estimate is the metric's own sweep: the floor holds as measured.
        assert!(
            m.effective_coverage >= floor,
            "{floor}: {}",
            m.effective_coverage
        );
        assert!(m.turns <= last.turns && m.path_length_m <= last.path_length_m + 1e-9);
        last = m;
    }
    assert!(last.turns < keep.turns, "{} vs {}", last.turns, keep.turns);
    assert!(last.effective_coverage < keep.effective_coverage);
}

/// Lanes closer than the tool's width overlap as asked: the plan sweeps the floor even with a
/// tool of half the spacing (the pruning once dropped every other lane as already swept, which
/// left gaps of twice the spacing).
#[test]
fn a_spacing_below_the_tool_width_keeps_its_lanes() {
    let world = block_room();
    let narrow = |spacing: f64| {
        let robot = crate::world::Robot {
            radius: 0.08,
            tool_radius: spacing / 2.0,
        };
        World::new(world.map().clone(), robot, Some(world.start())).unwrap()
    };
    let swept = |opts: &BcdOptions, spacing: f64| {
        let mut p = Bcd::try_new(&world, opts).unwrap();
        let out = crate::sim::simulate(&world, &mut p, &crate::sim::SimConfig::default());
        crate::metrics::compute(&narrow(spacing), &out, "block_room").effective_coverage
    };
    for spacing in [0.08, 0.04] {
        let opts = BcdOptions {
            lane_spacing_m: Some(spacing),
            ..BcdOptions::default()
        };
        let asked = swept(&opts, spacing);
        let plain = swept(&BcdOptions::default(), spacing);
        assert!(asked >= 0.99, "spacing {spacing}: {asked}");
        assert!(
            plain < 0.9,
            "spacing {spacing}: the default plan sweeps {plain}"
        );
    }
}

#[test]
fn invalid_options_are_refused() {
    let world = block_room();
    for bad in [
        BcdOptions {
            lane_spacing_m: Some(0.0),
            ..BcdOptions::default()
        },
        // Wider than the tool (2 r_tool = 0.16 m here), and far wider than any map: the fuzz
        // input that once overflowed the lane arithmetic.
        BcdOptions {
            lane_spacing_m: Some(0.5),
            ..BcdOptions::default()
        },
        BcdOptions {
            lane_spacing_m: Some(8.888_888_888_888_889e24),
            ..BcdOptions::default()
        },
        // Finer than a pixel (0.02 m): lanes lie on pixel lines.
        BcdOptions {
            lane_spacing_m: Some(0.01),
            ..BcdOptions::default()
        },
        BcdOptions {
            margin_px: -1.0,
            ..BcdOptions::default()
        },
        BcdOptions {
            turn_cost_m: f64::NAN,
            ..BcdOptions::default()
        },
        // Finite, but an infinite cost per pixel (every comparison tied).
        BcdOptions {
            turn_cost_m: 1e308,
            ..BcdOptions::default()
        },
        BcdOptions {
            rim_min_yield: 1.5,
            ..BcdOptions::default()
        },
        BcdOptions {
            rim_coverage: -0.1,
            ..BcdOptions::default()
        },
        BcdOptions {
            min_coverage: 1.5,
            ..BcdOptions::default()
        },
        BcdOptions {
            plans_at_a_time: Some(0),
            ..BcdOptions::default()
        },
        BcdOptions {
            plans_at_a_time: Some(65),
            ..BcdOptions::default()
        },
    ] {
        let e = Bcd::try_new(&world, &bad).err().unwrap();
        assert!(e.to_string().starts_with("bcd option "), "{e}");
        // The infallible constructor falls back to the defaults and still plans.
        assert!(!Bcd::new(&world, &bad).replay.steps().is_empty());
    }
}

#[test]
fn elongated_cells_lose_their_rounded_ends() {
    // A strip of 20 columns whose first and last two columns reach further down (the
    // rounded C-free corners beside an obstacle): rows 4 and 5 meet it at both ends only,
    // so it is not monotone across as a whole, but its middle is.
    let mut runs = vec![(0, 3); 20];
    runs[0] = (0, 5);
    runs[1] = (0, 4);
    runs[18] = (0, 4);
    runs[19] = (0, 5);
    let strip = Cell {
        cols: true,
        u0: 5,
        runs,
    };
    assert!(strip.transposed().is_none());
    let parts = split_ends(vec![strip.clone()], 4);
    assert_eq!(parts.len(), 3);
    assert_eq!(parts[1].u0, 7);
    assert_eq!(parts[1].runs.len(), 16);
    assert!(parts[1].transposed().is_some());
    // Every line is kept, once.
    let lines: usize = parts.iter().map(|c| c.runs.len()).sum();
    assert_eq!(lines, 20);
    // Ends longer than the limit: the cell stays whole.
    assert_eq!(split_ends(vec![strip], 1).len(), 1);
}

#[test]
fn cells_that_neighbours_lanes_sweep_are_dropped() {
    // A wide cell (columns 0..=19, rows 0..=9) with lanes up to column 19, and a sliver of
    // columns 20..=21 beside it: its pixels are within rt = 3 of the lane at column 19.
    let wide = Cell {
        cols: true,
        u0: 0,
        runs: vec![(0, 9); 20],
    };
    let sliver = Cell {
        cols: true,
        u0: 20,
        runs: vec![(0, 9); 2],
    };
    let far = Cell {
        cols: true,
        u0: 25,
        runs: vec![(0, 9); 2],
    };
    let cells = vec![
        (wide.clone(), vec![0.0, 6.0, 12.0, 19.0]),
        (sliver, vec![21.0]),
        (far, vec![25.0]),
    ];
    let kept = drop_covered(cells, 30, 10, 3.0);
    assert_eq!(kept.len(), 2);
    assert_eq!(kept[0].0.u0, 0);
    assert_eq!(kept[1].0.u0, 25);
    // When the wide cell's lanes end at column 12 (sweeping up to 15), neither cell's
    // lanes sweep all of the other's pixels: both stay.
    let cells = vec![
        (wide, vec![0.0, 6.0, 12.0]),
        (
            Cell {
                cols: true,
                u0: 20,
                runs: vec![(0, 9); 2],
            },
            vec![21.0],
        ),
    ];
    assert_eq!(drop_covered(cells, 30, 10, 3.0).len(), 2);
}

/// A room speckled with single-pixel obstacles at scattered offsets (as scanned maps are):
/// many small cells, some of whose moves the smoothing and pruning merge into their
/// neighbours'. Every region the plan reports has a move, and regions count 1, 2, ...
#[test]
fn every_reported_region_has_moves_and_regions_count_up() {
    let (w, h) = (90usize, 60usize);
    let mut art = String::new();
    let mut seed = 0x5eed_u64;
    for r in 0..h {
        for c in 0..w {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let border = r == 0 || c == 0 || r + 1 == h || c + 1 == w;
            art.push(if border || (seed >> 33).is_multiple_of(97) {
                '#'
            } else {
                '.'
            });
        }
        art.push('\n');
    }
    let map = crate::grid::GridMap::from_ascii_scaled(&art, 1, 0.05).unwrap();
    let world = World::new(
        map,
        crate::world::Robot::new(0.1),
        Some(crate::geometry::Pose::new(0.5, 0.5, 0.0)),
    )
    .unwrap();
    let plan = Bcd::new(&world, &BcdOptions::default());
    let (mut open, mut moved, mut ended) = (None, false, 0u32);
    for s in plan.replay.steps() {
        match s {
            Step::Mark(Event::RegionStart { region }) => {
                assert_eq!(open, None, "region {region} starts inside another");
                assert_eq!(*region, ended + 1, "regions count up");
                open = Some(*region);
                moved = false;
            }
            Step::MoveTo(_) => moved = true,
            Step::Mark(Event::RegionEnd { region }) => {
                assert_eq!(open.take(), Some(*region));
                assert!(moved, "region {region} has no move");
                ended += 1;
            }
            _ => {}
        }
    }
    assert!(
        ended > 5,
        "{ended} regions: the specks should split the room"
    );
}

#[test]
fn abrupt_cells_are_cut_where_the_parts_are_cheaper() {
    // An L: ten long lines (a room), then ninety short ones (a corridor along the lines).
    let mut runs = vec![(0, 99); 10];
    runs.extend(std::iter::repeat_n((90, 99), 90));
    let l = Cell {
        cols: true,
        u0: 5,
        runs,
    };
    // Price: the fewer lines of the two views (lanes), plus one per cell.
    let cost = |c: &Cell| {
        let t = c.transposed().map_or(usize::MAX, |t| t.runs.len());
        c.runs.len().min(t) as f64 + 1.0
    };
    let parts = split_jumps(vec![l.clone()], 3, &cost);
    assert_eq!(parts.len(), 2);
    assert_eq!((parts[0].u0, parts[0].runs.len()), (5, 10));
    assert_eq!((parts[1].u0, parts[1].runs.len()), (15, 90));
    // No cut where the jump is within the tolerance, nor where it does not pay.
    assert_eq!(split_jumps(vec![l.clone()], 90, &cost).len(), 1);
    assert_eq!(
        split_jumps(vec![l], 3, &|c: &Cell| c.runs.len() as f64 + 1.0).len(),
        1
    );
}

#[test]
fn transposed_cell_needs_one_run_per_line() {
    // An L: rows 0-1 span columns 0-3, rows 2-3 only column 0.
    let l = Cell {
        cols: true,
        u0: 0,
        runs: vec![(0, 3), (0, 1), (0, 1), (0, 1)],
    };
    let t = l.transposed().unwrap();
    assert!(!t.cols);
    assert_eq!(t.runs, vec![(0, 3), (0, 3), (0, 0), (0, 0)]);
    // A U (row 1 meets the cell in columns 0 and 2 only) is not monotone across.
    let u = Cell {
        cols: true,
        u0: 0,
        runs: vec![(0, 2), (0, 0), (0, 2)],
    };
    assert!(u.transposed().is_none());
}

#[test]
fn a_jagged_wall_band_may_be_left_out_of_the_view_across() {
    // Rows 0-7 from a jagged wall on the left (columns 0-2, its bumps 1-2 pixels deep) to a
    // straight wall on the right (column 9):
    //
    //   ..........      row 0
    //   #.........      row 1
    //   ..........      row 2
    //   ##........      row 3
    //   ..........      row 4
    //   #.........      row 5
    //   ..........      row 6
    //   ###.......      row 7 (the deepest bump)
    //
    // Columns 0 and 1 meet the cell in several runs, so it is not monotone across.
    let runs = vec![
        (0, 9),
        (1, 9),
        (0, 9),
        (2, 9),
        (0, 9),
        (1, 9),
        (0, 9),
        (3, 9),
    ];
    let cell = Cell {
        cols: false,
        u0: 0,
        runs,
    };
    assert!(cell.transposed().is_none());
    // A band of one column is not enough, of two it is: columns 2-9 (column 2 holds rows
    // 0-6, one run) become the lines of the view across.
    assert!(cell.transposed_trim(0).is_none());
    assert!(cell.transposed_trim(1).is_none());
    let t = cell.transposed_trim(2).unwrap();
    assert!(t.cols);
    assert_eq!(t.u0, 2);
    assert_eq!(t.runs[0], (0, 6));
    assert_eq!(t.runs[1..], [(0, 7); 7]);
    // A deeper band takes no more than it needs.
    assert_eq!(cell.transposed_trim(5).unwrap().u0, 2);
    // A monotone cell is transposed whole, whatever the band.
    let whole = Cell {
        cols: false,
        u0: 0,
        runs: vec![(0, 9); 4],
    };
    assert_eq!(whole.transposed_trim(3).unwrap().runs, vec![(0, 3); 10]);
    // Bumps in the middle are no wall band: no view across.
    let mid = Cell {
        cols: false,
        u0: 0,
        runs: vec![(0, 9), (0, 3), (0, 9)],
    };
    assert!(mid.transposed_trim(3).is_none());
}

/// `margin_px`: a transfer around the block keeps the extra clearance along its whole length
/// (apart from the stretches next to its ends), where without it the shortened path grazes
/// the block's corners.
#[test]
fn transfers_keep_the_margin_they_are_given() {
    // A 100 x 80 px room (0.02 m/px) with a 20 x 20 px block in the middle, 30 px from the walls.
    let art = "##########\n#........#\n#........#\n#...##...#\n#...##...#\n#........#\n#........#\n##########";
    let map = crate::grid::GridMap::from_ascii_scaled(art, 10, 0.02).unwrap();
    let world = World::new(
        map,
        crate::world::Robot::new(0.08),
        Some(crate::geometry::Pose::new(0.3, 0.3, 0.0)),
    )
    .unwrap();
    let frame = *world.frame();
    let (w, h) = (frame.width, frame.height);
    let res = frame.resolution;
    let reach = world.reachable();
    let ok: Vec<bool> = (0..w * h).map(|i| reach.contains(i)).collect();
    let clear = |p: Point| {
        let (c, r) = frame.grid_to_pixel_signed(p);
        let (c, r) = frame.checked(c, r).unwrap();
        world.pixel_clearance(c, r) / res
    };
    // Least clearance (pixels) along the route, away from its ends.
    let least = |margin: f64| {
        let need = crate::collide::contact_radius_px(world.robot().radius / res) + margin;
        let ctx = Ctx {
            world: &world,
            frame,
            ok: ok.clone(),
            safe: (0..w * h)
                .map(|i| ok[i] && world.pixel_clearance(i % w, i / w) / res + 0.5 >= need)
                .collect(),
            keep_px: (margin > 0.0).then_some(need),
            rt: 4.0,
            coarse: super::hops::CoarseCache::default(),
            stop: None,
        };
        let (a, b) = (Point::new(30.0, 20.0), Point::new(70.0, 60.0));
        let mut pts = vec![a];
        pts.extend(ctx.route(&mut Search::new(w, h), a, b).unwrap());
        assert_eq!(pts.last(), Some(&b));
        let mut low = f64::INFINITY;
        for s in pts.windows(2) {
            for k in 0..=20 {
                let t = f64::from(k) / 20.0;
                let p = Point::new(
                    s[0].x + (s[1].x - s[0].x) * t,
                    s[0].y + (s[1].y - s[0].y) * t,
                );
                if p.dist(a) > need && p.dist(b) > need {
                    low = low.min(clear(p));
                }
            }
        }
        (low, need)
    };
    let (bare, contact) = least(0.0);
    let (kept, need) = least(3.0);
    assert!(
        bare < contact + 1.0,
        "without a margin the route grazes the block: {bare}"
    );
    assert!(kept >= need - 1.0, "with 3 px it keeps {kept} px of {need}");
}

#[test]
fn even_cells_are_cut_into_two_odd_runs_of_their_lanes() {
    let cell = |u0| Cell {
        cols: true,
        u0,
        runs: vec![(0, 9); 30],
    };
    let lanes = |n: usize| (0..n).map(|i| 3.0 * i as f64).collect::<Vec<f64>>();
    let cells: Vec<(Cell, Vec<f64>)> = [1, 2, 4, 5, 6, 8]
        .iter()
        .enumerate()
        .map(|(i, &n)| (cell(i), lanes(n)))
        .collect();
    let out = odd_runs(&cells);
    let got: Vec<(usize, Vec<f64>)> = out.iter().map(|(c, l)| (c.u0, l.clone())).collect();
    // 1 and 5 stay; 2 -> 1 + 1, 4 -> 1 + 3, 6 -> 3 + 3, 8 -> 3 + 5; same cell, lanes in order.
    let want: Vec<(usize, Vec<f64>)> = vec![
        (0, lanes(1)),
        (1, vec![0.0]),
        (1, vec![3.0]),
        (2, vec![0.0]),
        (2, vec![3.0, 6.0, 9.0]),
        (3, lanes(5)),
        (4, vec![0.0, 3.0, 6.0]),
        (4, vec![9.0, 12.0, 15.0]),
        (5, vec![0.0, 3.0, 6.0]),
        (5, vec![9.0, 12.0, 15.0, 18.0, 21.0]),
    ];
    assert_eq!(got, want);
    assert!(out.iter().all(|(_, l)| l.len() % 2 == 1));
}

/// A 100 x 100 px map (0.05 m/px) free up to its border around a 60 x 60 px block: a ring
/// 1 m wide, robot radius 0.15 m.
fn ring() -> World {
    let mut art = String::new();
    for r in 0..100 {
        for c in 0..100 {
            let block = (20..80).contains(&r) && (20..80).contains(&c);
            art.push(if block { '#' } else { '.' });
        }
        art.push('\n');
    }
    let map = crate::grid::GridMap::from_ascii_scaled(art.trim_end(), 1, 0.05).unwrap();
    World::new(
        map,
        crate::world::Robot::new(0.15),
        Some(crate::geometry::Pose::new(0.5, 0.5, 0.0)),
    )
    .unwrap()
}

#[test]
fn a_ring_is_peeled_into_offset_loops_from_the_outer_wall() {
    let world = ring();
    let ctx = reach_ctx(&world, 3.0);
    let lat = Lattice::pixels(&ctx);
    // Row 50 (through the block) from the left border: C-free from column 3 to 16 (the
    // block starts at 20). Pass 1 beside the outer wall and beside the block, then the
    // offset loops 6 columns apart from the outer wall in; no interior.
    let (inner, pass) = super::headland::interior(&lat, 7.0, 120.0, Some(6.0));
    assert!(inner.iter().all(|&i| !i));
    let row: Vec<u32> = (0..20).map(|c| pass[50 * 100 + c]).collect();
    assert_eq!(
        row,
        [0, 0, 0, 1, 0, 0, 0, 0, 0, 2, 0, 0, 0, 0, 0, 3, 1, 0, 0, 0]
    );
    // Without `peel`, the plain headland: the two passes, lanes inside.
    let (inner, pass) = super::headland::interior(&lat, 7.0, 120.0, None);
    let row: Vec<u32> = (0..20).map(|c| pass[50 * 100 + c]).collect();
    assert_eq!(
        row,
        [0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0]
    );
    // (the interior: 7 columns from both walls' non-free points, columns 2 and 17)
    let inner_row: Vec<bool> = (0..20).map(|c| inner[50 * 100 + c]).collect();
    let at: Vec<usize> = (0..20).filter(|&c| inner_row[c]).collect();
    assert_eq!(at, [9, 10]);
    // The planner keeps the loops: shorter than the plain plan's lanes, the floor swept.
    let m = run(&world, &BcdOptions::default());
    let plain = run(
        &world,
        &BcdOptions {
            headland_min_m: None,
            ..BcdOptions::default()
        },
    );
    assert_eq!(m.collisions, 0);
    assert!(m.effective_coverage >= 0.995, "{}", m.effective_coverage);
    assert!(
        m.path_length_m < 0.97 * plain.path_length_m,
        "{} vs {}",
        m.path_length_m,
        plain.path_length_m
    );
    // Four loops (outer pass, two offset loops, the block's pass), one region each; the
    // plan made with a lower turn cost in its choices (module docs, step 6) wins here
    // (49.7 m and 24 turns against 62.8 m and 19), and its pruning drops the loop whose
    // floor the loops beside it sweep.
    assert!(matches!(m.regions, 3 | 4), "{m:?}");
    // (without step 6 the plan costs 62.8 m + 19 turns x 0.3 m = 68.5 m)
    let cost = m.path_length_m + 0.3 * f64::from(m.turns);
    assert!(cost < 60.0, "{m:?}");
}

/// `plans_at_a_time` runs the planning on a pool of exactly that many threads (what bounds the
/// plans made at once); `None` stays on the caller's pool.
#[test]
fn plans_run_on_a_pool_of_plans_at_a_time_threads() {
    for n in [1, 3, 5] {
        assert_eq!(on_pool(Some(n), rayon::current_num_threads), n as usize);
    }
    let outer = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    assert_eq!(
        outer.install(|| on_pool(None, rayon::current_num_threads)),
        2
    );
    // The plan is the same whatever the count.
    let world = block_room();
    let pool = Bcd::new(&world, &BcdOptions::default());
    for n in [1, 2, 4] {
        let b = Bcd::new(
            &world,
            &BcdOptions {
                plans_at_a_time: Some(n),
                ..BcdOptions::default()
            },
        );
        assert_eq!(b.replay.steps(), pool.replay.steps(), "{n}");
    }
}

/// A margin no way can keep is said: three rooms in a row joined by corridors one robot wide
/// (0.2 m, robot radius 0.08 m), the start in the middle one, so one corridor is driven twice,
/// once as a transfer. With `margin_px: 3` (more clearance than the corridor has) the plan
/// starts with a [`super::MARGIN_NOTE`] naming the transfers; without a margin it says nothing.
/// (A margin wider than every corridor used to fall back to the plain clearance in silence.)
#[test]
fn a_margin_no_transfer_can_keep_is_said() {
    let rooms = |mid: char| {
        let mut s = String::from("#");
        for k in 0..3 {
            if k > 0 {
                s.extend(std::iter::repeat_n(mid, 5));
            }
            s.push_str("....");
        }
        s.push('#');
        s
    };
    let wall = "#".repeat(24);
    let art = [
        wall.clone(),
        rooms('#'),
        rooms('#'),
        rooms('.'),
        rooms('#'),
        rooms('#'),
        wall,
    ]
    .join("\n");
    let map = crate::grid::GridMap::from_ascii_scaled(&art, 10, 0.02).unwrap();
    let world = World::new(
        map,
        crate::world::Robot::new(0.08),
        Some(crate::geometry::Pose::new(2.4, 0.7, 0.0)),
    )
    .unwrap();
    let note = |margin_px: f64| {
        let opts = BcdOptions {
            margin_px,
            ..BcdOptions::default()
        };
        let plan = Bcd::new(&world, &opts);
        plan.replay.steps().iter().find_map(|s| match s {
            Step::Mark(Event::Note { text }) => Some(text.clone()),
            _ => None,
        })
    };
    let said = note(3.0).expect("a note");
    assert!(
        said.starts_with(super::MARGIN_NOTE) && said.contains("margin_px 3 was not kept on"),
        "{said}"
    );
    assert_eq!(note(0.0), None);
    // A margin beyond every point's clearance: every transfer point lay near enough to an
    // end to count as keeping it, so it ran as no margin with no word (hostile pass).
    for huge in [1000.0, 1e300] {
        let said = note(huge).expect("a note");
        assert!(
            said.starts_with(super::MARGIN_NOTE)
                && said.contains("was kept on none of the plan's")
                && said.contains("the widest spot allows"),
            "{said}"
        );
    }
}

/// The rim's witnesses (the nearest C-free pixel within the tool's reach of each missed pixel,
/// ties by row then column offset) found through the distance transform are those of the scan
/// of every offset from the nearest out, which they replaced for speed (45 s to 1.3 s for a
/// 300 px robot), on maps with specks, thin walls and rooms at several tool radii.
#[test]
fn rim_witnesses_are_the_nearest_c_free_pixels() {
    let art = "\
####################################
#..........#.......#.....#.........#
#...#......#...............##......#
#..........#.......#..#............#
#......#...####.####.......#.......#
#..................................#
#####.#######...##......#####..#####
#......#...........#...............#
#...#..#.....#.....#....#....#.....#
#......#...........#...............#
####################################";
    let map = crate::grid::GridMap::from_ascii_scaled(art, 3, 0.05).unwrap();
    let world = World::new(
        map,
        crate::world::Robot::new(0.1),
        Some(crate::geometry::Pose::new(0.4, 0.4, 0.0)),
    )
    .unwrap();
    let frame = *world.frame();
    let n = frame.len();
    let ctx = reach_ctx(&world, 3.0);
    // Every pixel but every seventh one is "missed".
    let mut missed = fixedbitset::FixedBitSet::with_capacity(n);
    for i in (0..n).filter(|i| i % 7 != 0) {
        missed.insert(i);
    }
    let w = frame.width as i64;
    for rt in [0.5, 1.0, 2.3, 4.0, 7.5] {
        let got = super::rim::witnesses(&ctx, &missed, rt);
        for i in 0..n {
            let want = if missed.contains(i) {
                let (c, r) = (i as i64 % w, i as i64 / w);
                let k = rt.floor() as i64;
                let mut best: Option<(i64, i64, i64)> = None;
                for dr in -k..=k {
                    for dc in -k..=k {
                        let d2 = dc * dc + dr * dr;
                        if (d2 as f64) <= rt * rt
                            && ctx.ok_at(c + dc, r + dr)
                            && best.is_none_or(|b| (d2, dr, dc) < b)
                        {
                            best = Some((d2, dr, dc));
                        }
                    }
                }
                best.map_or(u32::MAX, |(_, dr, dc)| ((r + dr) * w + c + dc) as u32)
            } else {
                u32::MAX
            };
            assert_eq!(got[i], want, "rt {rt}, pixel {i}");
        }
    }
}
