//! Unit tests of the BA* internals.

use super::backtrack_list::Block3;
use super::smoothing::{all_swept_tiles, segment_box_dist2};
use super::*;

/// `Block3::in_l` (the early-stopping test the incremental L uses) is `mu >= 1`, over
/// random blocks of tile states and move judgements.
#[test]
fn block_in_l_is_mu_at_least_one() {
    let mut seed: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    let mut fired = [0usize; 2];
    for _ in 0..200_000 {
        let mut b = Block3 {
            state: [0; 25],
            moves: [0; 25],
            c: 12,
        };
        for k in 0..25 {
            let r = next();
            // Standability 0..=2, covered about half the time; each move slot 0..=2.
            b.state[k] = (r % 3) as u8 | if r >> 8 & 1 == 1 { ST_COVERED } else { 0 };
            b.moves[k] = (0..4).fold(0u8, |m, s| {
                m | ((((r >> (16 + 2 * s)) % 3) as u8) << (2 * s))
            });
        }
        for lane in [false, true] {
            let want = b.mu(lane) >= 1;
            assert_eq!(
                b.in_l(lane),
                want,
                "{:?} {:?} lane {lane}",
                b.state,
                b.moves
            );
            fired[usize::from(lane)] += usize::from(want);
        }
    }
    assert!(fired[0] > 10_000 && fired[1] > fired[0], "{fired:?}");
}

#[test]
fn corner_score_pairs() {
    let mut free = [false; 8];
    let mut blocked = [false; 8];
    assert_eq!(corner_score(free, blocked), 0);
    free[4] = true;
    blocked[3] = true;
    assert_eq!(corner_score(free, blocked), 1);
    blocked[5] = true;
    assert_eq!(corner_score(free, blocked), 2);
    // s3 (north) never starts a pair.
    free[2] = true;
    blocked[1] = true;
    blocked[3] = true;
    assert_eq!(corner_score(free, blocked), 2);
}

#[test]
fn swept_tiles_of_straight_and_diagonal_moves() {
    let collect = |a, b| {
        let mut v = Vec::new();
        for_each_swept_tile(a, b, 0.5, |t| {
            v.push(t);
            true
        });
        v.sort_unstable();
        v
    };
    assert_eq!(collect((0, 0), (1, 0)), vec![(0, 0), (1, 0)]);
    assert_eq!(collect((0, 0), (0, -2)), vec![(0, -2), (0, -1), (0, 0)]);
    assert_eq!(
        collect((0, 0), (1, 1)),
        vec![(0, 0), (0, 1), (1, 0), (1, 1)]
    );
    let v = collect((0, 0), (2, 1));
    assert!(v.contains(&(1, 0)) && v.contains(&(1, 1)) && v.len() >= 4);
}

#[test]
fn segment_box_distance() {
    let lo = Point::new(0.0, 0.0);
    let hi = Point::new(1.0, 1.0);
    let d = segment_box_dist2(Point::new(-1.0, 0.5), Point::new(2.0, 0.5), lo, hi);
    assert_eq!(d, 0.0);
    let d = segment_box_dist2(Point::new(-1.0, 2.0), Point::new(2.0, 2.0), lo, hi);
    assert!((d - 1.0).abs() < 1e-12);
    let d = segment_box_dist2(Point::new(2.0, 3.0), Point::new(3.0, 2.0), lo, hi);
    // Nearest: corner (1,1) to the line x + y = 5: distance 3/sqrt2.
    assert!((d - 4.5).abs() < 1e-12);
}

#[test]
fn heuristic_is_the_floored_euclidean_distance() {
    for di in -60..=60 {
        for dj in -60..=60 {
            let e = (f64::from(di).hypot(f64::from(dj)) * COST_ORTHO as f64).floor() as u64;
            assert_eq!(heuristic((di, dj), (0, 0)), e, "({di}, {dj})");
        }
    }
}

/// The shortcuts of [`for_each_swept_tile`] change nothing: the same tiles as the box
/// distance alone, for segments in every direction and several radii.
#[test]
fn swept_tiles_match_the_box_distance() {
    for rho in [0.0, 1e-12, 0.25, 0.5, 0.5 + 1e-12, 0.7, 1.0, 1.5, 2.3] {
        let lim = (rho * rho) * (1.0 - 1e-9) - 1e-12;
        for bx in -7..=7 {
            for by in -7..=7 {
                let (a, b) = ((0, 0), (bx, by));
                let mut got = Vec::new();
                for_each_swept_tile(a, b, rho, |t| {
                    got.push(t);
                    true
                });
                got.sort_unstable();
                let (pa, pb) = (
                    Point::new(0.0, 0.0),
                    Point::new(f64::from(bx), f64::from(by)),
                );
                let mut want = Vec::new();
                for j in -12..=12 {
                    for i in -12..=12 {
                        let (x, y) = (f64::from(i), f64::from(j));
                        let lo = Point::new(x - 0.5, y - 0.5);
                        let hi = Point::new(x + 0.5, y + 0.5);
                        if segment_box_dist2(pa, pb, lo, hi) < lim {
                            want.push((i, j));
                        }
                    }
                }
                want.sort_unstable();
                assert_eq!(got, want, "rho {rho}, to ({bx}, {by})");
            }
        }
    }
}

#[test]
fn heuristic_is_consistent() {
    assert_eq!(heuristic((0, 0), (1, 0)), COST_ORTHO);
    assert!(heuristic((0, 0), (1, 1)) <= COST_DIAG);
    assert!(heuristic((0, 0), (3, 4)) == 5 * COST_ORTHO);
}

/// The column-and-row pass of `judge_frame_edges` (unrotated frames) judges exactly the
/// tiles the tile-by-tile pass judges, the same way: frames of odd sizes, resolutions that
/// are not binary fractions, start points anywhere in a pixel and tile sides from below a
/// pixel to many pixels.
#[test]
fn frame_edges_by_lines_match_tile_by_tile() {
    use super::tile_model::TileModel;
    use crate::grid::MapFrame;
    use crate::tiles::TileGrid;
    let mut seed: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut judged = 0;
    for _ in 0..60 {
        let w = 3 + (next() * 60.0) as usize;
        let h = 3 + (next() * 60.0) as usize;
        let res = [0.05, 0.03, 0.1, 0.07][(next() * 4.0) as usize];
        let mut frame = MapFrame::new(w, h, res);
        frame.origin = crate::geometry::Pose::new(next() * 7.0 - 3.0, next() * 7.0 - 3.0, 0.0);
        let r = res * (0.3 + next() * 4.0);
        let start = Point::new(
            frame.origin.x + next() * w as f64 * res,
            frame.origin.y + next() * h as f64 * res,
        );
        let side = [2.0 * r, res, r * 1.3][(next() * 3.0) as usize];
        let grid = TileGrid::new(start, side);
        let known = KnownMap::new(&frame);
        let mut a = TileModel::new(grid, &frame);
        let mut b = TileModel::new(grid, &frame);
        a.judge_frame_edges_with(&known, r, true);
        b.judge_frame_edges_with(&known, r, false);
        assert_eq!(a.state, b.state, "frame {frame:?} r {r} side {side}");
        judged += a.state.iter().filter(|&&s| s != 0).count();
    }
    assert!(judged > 100, "{judged}");
}

/// Every tile of the centre line (`for_each_centre_tile`) is a tile the swept disk touches
/// (`for_each_swept_tile`), for any direction, length and radius above 1e-3 tiles; so an
/// uncovered centre tile refuses line of sight exactly when the full test would.
#[test]
fn centre_line_tiles_are_swept_tiles() {
    use super::smoothing::for_each_centre_tile;
    let mut seed: u64 = 0xd1b5_4a32_d192_ed03;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    let mut seen = 0usize;
    for k in 0..4000 {
        let r = next();
        let a = ((r % 41) as i32 - 20, ((r >> 8) % 41) as i32 - 20);
        let b = if k % 4 == 0 {
            // Axis and diagonal moves, as most backtracking segments.
            let d = ((r >> 16) % 30) as i32;
            [
                (a.0 + d, a.1),
                (a.0, a.1 - d),
                (a.0 - d, a.1 + d),
                (a.0 + d, a.1 + d),
            ][(r >> 24) as usize % 4]
        } else {
            (((r >> 16) % 81) as i32 - 40, ((r >> 24) % 81) as i32 - 40)
        };
        let rho = [0.5, 1e-3 * 1.01, 0.2, 0.7, 1.3, 2.9][(r >> 40) as usize % 6];
        let mut swept = Vec::new();
        for_each_swept_tile(a, b, rho, |t| {
            swept.push(t);
            true
        });
        for_each_centre_tile(a, b, |t| {
            assert!(
                swept.contains(&t),
                "{a:?} -> {b:?} rho {rho}: centre tile {t:?} not swept"
            );
            seen += 1;
            true
        });
    }
    assert!(seen > 40_000, "{seen}");
}

/// Where `centres_round_home` holds, a tile centre lies in its own tile (`tile_of`) for
/// anchors and sides of every magnitude it admits and tiles up to its index bound; the
/// shortcut of `Mind::robot_tile` returns exactly what `tile_of` does.
#[test]
fn tile_centres_round_home() {
    use super::sensing::centres_round_home;
    use crate::tiles::TileGrid;
    let mut seed: u64 = 0x6a09_e667_f3bc_c909;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    let mut checked = 0;
    for _ in 0..200_000 {
        let r = next();
        let mag = [1.0, 1e-3, 1e3, 1e6, 1e9, 1e14, 9e14][(r % 7) as usize];
        let anchor = Point::new(
            ((r >> 8) % 100_003) as f64 * 1.7e-5 * mag - 0.8 * mag,
            ((r >> 28) % 100_003) as f64 * -1.3e-5 * mag,
        );
        let scale = anchor.x.abs().max(anchor.y.abs()).max(1.0);
        let side = [
            0.05,
            0.1,
            0.025,
            0.3,
            1.7e-3,
            2e-9 * scale,
            1.01e-9 * scale,
            9e14,
        ][(r >> 48) as usize % 8];
        let grid = TileGrid::new(anchor, side);
        if !centres_round_home(&grid) {
            continue;
        }
        let lim = [1_000i64, 1 << 20, (1 << 30) - 1][(next() % 3) as usize];
        let v = next();
        let t = (
            ((v % (2 * lim as u64 + 1)) as i64 - lim) as i32,
            (((v >> 32) % (2 * lim as u64 + 1)) as i64 - lim) as i32,
        );
        assert_eq!(grid.tile_of(grid.center(t)), t, "{grid:?} {t:?}");
        checked += 1;
    }
    assert!(checked > 100_000, "{checked}");
}

/// [`all_swept_tiles`] (the predicate read first, the geometry only where it fails) answers
/// as [`for_each_swept_tile`] with the same predicate: over pseudo-random sets of good tiles
/// (dense, as the covered tiles around a backtracking path, and sparse), segments in every
/// direction and several radii; both answers occur.
#[test]
fn all_swept_tiles_answers_as_the_full_sweep() {
    let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
    let (mut yes, mut no) = (0, 0);
    for rho in [0.0, 0.25, 0.5, 0.7, 1.0, 2.3] {
        for density in [70, 97, 100] {
            let good: Vec<bool> = (0..31 * 31)
                .map(|_| {
                    x ^= x << 13;
                    x ^= x >> 7;
                    x ^= x << 17;
                    x % 100 < density
                })
                .collect();
            let ok = |t: Tile| {
                (-15..=15).contains(&t.0)
                    && (-15..=15).contains(&t.1)
                    && good[((t.1 + 15) * 31 + t.0 + 15) as usize]
            };
            for bx in -9..=9 {
                for by in -9..=9 {
                    let a = (bx / 3, -by / 2);
                    let b = (bx, by);
                    let want = for_each_swept_tile(a, b, rho, ok);
                    assert_eq!(
                        all_swept_tiles(a, b, rho, ok),
                        want,
                        "rho {rho} {a:?} {b:?}"
                    );
                    if want {
                        yes += 1;
                    } else {
                        no += 1;
                    }
                }
            }
        }
    }
    assert!(yes > 100 && no > 100, "{yes} {no}");
}

/// The trace holds the backtracking lists while they fit in their bound
/// ([`LIST_POINTS_PER_TILE`] points a tile): past it a note says that recording stopped, and
/// nothing else of the run changes (on a 2000 x 2000 px map of salt noise at r = 0.05 m the
/// lists, held whole, took 5 GB, six times the run's estimate).
#[test]
fn backtracking_lists_stop_at_their_bound_with_a_note() {
    use crate::sim::{simulate, SimConfig};
    use crate::trace::Event;
    use crate::world::{Robot, World};
    let art = "\
        ..........\n\
        ..##...#..\n\
        ..##......\n\
        ......##..\n\
        .#....##..\n\
        ..........";
    let map = crate::GridMap::from_ascii_scaled(art, 11, 0.01).unwrap();
    let start = crate::Pose::new(0.055, 0.055, std::f64::consts::FRAC_PI_2);
    let world = World::new(map, Robot::new(0.055), Some(start)).unwrap();
    let run = |k: Option<usize>| {
        let mut p = BaStar::new(BaStarOptions::default());
        if let Some(k) = k {
            p = p.with_list_points_per_tile(k);
        }
        simulate(&world, &mut p, &SimConfig::default()).trace
    };
    let lists = |t: &crate::trace::Trace| {
        t.events()
            .filter_map(|(_, e)| match e {
                Event::BacktrackList { points } => Some(points.len()),
                _ => None,
            })
            .collect::<Vec<_>>()
    };
    let notes = |t: &crate::trace::Trace| {
        t.events()
            .filter(|(_, e)| {
                matches!(e, Event::Note { text } if text.contains("backtracking lists are not recorded"))
            })
            .count()
    };
    let whole = run(None);
    let all = lists(&whole);
    assert!(all.iter().filter(|&&n| n > 0).count() >= 2, "{all:?}");
    assert_eq!(notes(&whole), 0);
    let cut = run(Some(0));
    assert!(lists(&cut).iter().all(|&n| n == 0), "{:?}", lists(&cut));
    assert_eq!(notes(&cut), 1);
    assert!(
        whole.poses().eq(cut.poses()),
        "the bound changed the motion"
    );
}
