//! Zones in the core: the metrics count keep-out entries from the trace, online planners treat
//! zones as walls (and never learn them as free), and coverage is measured on the allowed floor.
#![allow(clippy::unwrap_used)]

use ccpp_core::grid::GridMap;
use ccpp_core::metrics;
use ccpp_core::planners::{PlannerConfig, PlannerKind};
use ccpp_core::sim::{simulate, RunOutput, SimConfig, StopReason};
use ccpp_core::trace::Trace;
use ccpp_core::world::{Robot, World, WorldError};
use ccpp_core::zones::{Polygon, ZoneMasks};
use ccpp_core::Pose;

/// A 4 x 2 m walled room at 0.05 m/px.
fn room() -> GridMap {
    let (w, h) = (80, 40);
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
    GridMap::from_ascii_scaled(&s, 1, 0.05).unwrap()
}

fn zones(map: &GridMap, area: Option<[f64; 4]>, keepout: &[[f64; 4]]) -> ZoneMasks {
    let a: Option<Vec<Polygon>> = area.map(|r| vec![Polygon::rect(r)]);
    let k: Vec<Polygon> = keepout.iter().map(|r| Polygon::rect(*r)).collect();
    ZoneMasks::new(map.frame(), a.as_deref(), &k, &[])
}

#[test]
fn a_trace_through_a_keepout_counts_each_entry() {
    let map = room();
    let z = zones(&map, None, &[[1.8, 0.0, 2.2, 2.0]]);
    let world = World::with_zones(
        map,
        Robot::new(0.1),
        Some(Pose::new(0.5, 1.0, 0.0)),
        Some(z),
    )
    .unwrap();
    let mut trace = Trace::default();
    for (k, x) in [0.5, 3.5, 0.5, 1.0].iter().enumerate() {
        trace.push_pose(k as u64, Pose::new(*x, 1.0, 0.0));
    }
    let run = RunOutput {
        trace,
        stop: StopReason::Done,
        tile_side: None,
        planner: "hand",
        wall_time_s: 0.0,
    };
    let m = metrics::compute(&world, &run, "room");
    assert_eq!(m.keepout_violations, 2);
    // The physical map has no wall there: no collision.
    assert_eq!(m.collisions, 0);
    // The same trace without zones: no violation.
    let plain = World::new(room(), Robot::new(0.1), Some(Pose::new(0.5, 1.0, 0.0))).unwrap();
    assert_eq!(metrics::compute(&plain, &run, "room").keepout_violations, 0);
}

#[test]
fn online_and_offline_planners_respect_the_zones() {
    let map = room();
    // Work in the west 3 m, minus a keep-out block in the middle of it.
    let area = [0.0, 0.0, 3.0, 2.0];
    let keep = [1.2, 0.6, 1.8, 1.4];
    let plain = World::new(map.clone(), Robot::new(0.1), None).unwrap();
    let world = World::with_zones(
        map.clone(),
        Robot::new(0.1),
        None,
        Some(zones(&map, Some(area), &[keep])),
    )
    .unwrap();
    assert!(world.accessible_count() < plain.accessible_count() * 3 / 4);
    // The default start is inside the area and outside the keep-out.
    let s = world.start();
    assert!(s.x < 3.0 - 0.1 && !(1.1..=1.9).contains(&s.x) || !(0.5..=1.5).contains(&s.y));
    for kind in PlannerKind::ALL {
        let cfg = PlannerConfig::new(*kind);
        let mut p = cfg.build(&world).unwrap();
        let out = simulate(&world, p.as_mut(), &SimConfig::default());
        let m = metrics::compute(&world, &out, "room");
        assert_eq!(m.keepout_violations, 0, "{kind}");
        assert_eq!(m.collisions, 0, "{kind}");
        for pose in out.trace.poses() {
            assert!(
                pose.x <= 3.0 - 0.1 + 0.03,
                "{kind} leaves the area at {pose:?}"
            );
        }
        if matches!(kind, PlannerKind::Bcd | PlannerKind::BsaExtended) {
            assert!(
                m.effective_coverage > 0.95,
                "{kind}: {}",
                m.effective_coverage
            );
        }
    }
}

/// The approach of a planner that needs room for a larger disk than the robot's own
/// (rect-boustrophedon's clearance disk) is planned for that disk all the way: it ended where
/// that disk fitted but drove corners where only the robot's did (a rectangle turning there
/// hits the wall), and through doors too narrow for it.
#[test]
fn an_approach_for_a_larger_disk_keeps_that_disk_clear() {
    let map = room();
    // Keep-outs leave a door 0.4 m wide (y 0.8 to 1.2) between the start and the area.
    let z = || {
        zones(
            &map,
            Some([0.0, 0.0, 1.5, 2.0]),
            &[[1.8, 0.0, 2.2, 0.8], [1.8, 1.2, 2.2, 2.0]],
        )
    };
    let start = Some(Pose::new(3.0, 0.3, 0.0));
    let robot = Robot::new(0.1);
    assert!(World::with_zones(map.clone(), robot, start, Some(z())).is_ok());
    // A disk 0.5 m across does not pass the door.
    let e = World::with_zones_fitting(map.clone(), robot, start, Some(z()), 0.25);
    assert!(
        matches!(e, Err(WorldError::AreaUnreachable { radius, .. }) if radius == 0.25),
        "{e:?}"
    );
    // A disk 0.3 m across does, and keeps clear of the door's posts at every corner and along
    // every segment (sampled), not only where it ends.
    let w = World::with_zones_fitting(map.clone(), robot, start, Some(z()), 0.15).unwrap();
    let posts = [[1.8, 0.0, 2.2, 0.8], [1.8, 1.2, 2.2, 2.0]];
    let clear = |x: f64, y: f64| {
        posts.iter().all(|r| {
            let dx = (r[0] - x).max(x - r[2]).max(0.0);
            let dy = (r[1] - y).max(y - r[3]).max(0.0);
            dx.hypot(dy) >= 0.15 - 0.025
        })
    };
    let mut prev = w.initial_pose().position();
    for p in w.approach() {
        for k in 0..=50 {
            let t = f64::from(k) / 50.0;
            let (x, y) = (prev.x + t * (p.x - prev.x), prev.y + t * (p.y - prev.y));
            assert!(clear(x, y), "({x}, {y}) on the approach {:?}", w.approach());
        }
        prev = *p;
    }
    assert!(w.start().x <= 1.5 - 0.15 + 0.025 + 1e-9, "{:?}", w.start());
    // An area narrower than the larger disk has no spot for it at all: said so, not "no path
    // leads into it" (the robot's own disk gets in).
    let narrow = || zones(&map, Some([0.0, 0.0, 0.4, 2.0]), &[]);
    let start = Some(Pose::new(3.0, 1.0, 0.0));
    assert!(World::with_zones(map.clone(), robot, start, Some(narrow())).is_ok());
    let e = World::with_zones_fitting(map.clone(), robot, start, Some(narrow()), 0.25);
    assert!(
        matches!(e, Err(WorldError::NoRoomInZones { radius, .. }) if radius == 0.25),
        "{e:?}"
    );
}

#[test]
fn zone_errors_are_specific() {
    let map = room();
    // A start outside the area gets an approach into it (avoiding the keep-out in between);
    // behind a keep-out wall the area cannot be reached.
    let z = zones(&map, Some([0.0, 0.0, 1.5, 2.0]), &[[1.8, 0.0, 2.2, 1.2]]);
    let w = World::with_zones(
        map.clone(),
        Robot::new(0.1),
        Some(Pose::new(3.0, 0.5, 0.0)),
        Some(z),
    )
    .unwrap();
    assert_eq!(w.initial_pose(), Pose::new(3.0, 0.5, 0.0));
    assert!(w.start().x <= 1.5 - 0.1 + 1e-9, "{:?}", w.start());
    assert!(w.approach_length_m() > 1.5 && !w.approach().is_empty());
    let mut sim = ccpp_core::sim::Simulator::new(&w, &SimConfig::default());
    sim.execute(ccpp_core::planner::Step::Rotate(0.0));
    assert_eq!(sim.true_pose().position(), w.start().position());
    let out = simulate(
        &w,
        PlannerConfig::new(PlannerKind::BaStar)
            .build(&w)
            .unwrap()
            .as_mut(),
        &SimConfig::default(),
    );
    let m = metrics::compute(&w, &out, "room");
    assert_eq!((m.keepout_violations, m.collisions), (0, 0));
    let z = zones(&map, Some([0.0, 0.0, 1.5, 2.0]), &[[1.8, 0.0, 2.2, 2.0]]);
    let e = World::with_zones(
        map.clone(),
        Robot::new(0.1),
        Some(Pose::new(3.0, 1.0, 0.0)),
        Some(z),
    );
    assert!(
        matches!(e, Err(WorldError::AreaUnreachable { .. })),
        "{e:?}"
    );
    let z = zones(&map, None, &[[2.5, 0.5, 3.5, 1.5]]);
    let e = World::with_zones(
        map.clone(),
        Robot::new(0.1),
        Some(Pose::new(3.0, 1.0, 0.0)),
        Some(z),
    );
    assert!(matches!(e, Err(WorldError::StartInKeepout { .. })), "{e:?}");
    // An area thinner than the robot: no room.
    let z = zones(&map, Some([1.0, 0.5, 1.1, 1.5]), &[]);
    let e = World::with_zones(map, Robot::new(0.1), None, Some(z));
    assert!(matches!(e, Err(WorldError::NoRoomInZones { .. })), "{e:?}");
}

/// A start outside an area of two parts drives to the larger part, not to the nearer one (an
/// area drawn loosely around a room took in a strip of the corridor beside it, and the robot
/// swept the strip alone, "effective coverage 1.0").
#[test]
fn an_approach_goes_to_the_largest_part_of_the_area() {
    let map = room();
    // A strip 0.4 m wide (x 1.6 to 2.0) next to the start, and a part 1.4 m wide beyond it.
    let parts = [
        Polygon::rect([0.0, 0.0, 1.4, 2.0]),
        Polygon::rect([1.6, 0.0, 2.0, 2.0]),
    ];
    let z = ZoneMasks::new(map.frame(), Some(&parts), &[], &[]);
    let w = World::with_zones(
        map.clone(),
        Robot::new(0.1),
        Some(Pose::new(3.0, 1.0, 0.0)),
        Some(z),
    )
    .unwrap();
    assert!(w.start().x < 1.4 - 0.1 + 1e-9, "{:?}", w.start());
    assert!(!w.approach().is_empty());
    // A start in the strip whose disk crosses its border moves into the strip (a few
    // centimetres), not to the larger part.
    let z = ZoneMasks::new(map.frame(), Some(&parts), &[], &[]);
    let w = World::with_zones(
        map.clone(),
        Robot::new(0.1),
        Some(Pose::new(1.65, 1.0, 0.0)),
        Some(z),
    )
    .unwrap();
    assert!(
        (1.7 - 1e-9..=1.9 + 1e-9).contains(&w.start().x),
        "{:?}",
        w.start()
    );
    // The strip alone: the approach ends in it, as before.
    let z = ZoneMasks::new(map.frame(), Some(&parts[1..]), &[], &[]);
    let w = World::with_zones(
        map,
        Robot::new(0.1),
        Some(Pose::new(3.0, 1.0, 0.0)),
        Some(z),
    )
    .unwrap();
    assert!(
        (1.7 - 1e-9..=1.9 + 1e-9).contains(&w.start().x),
        "{:?}",
        w.start()
    );
}
