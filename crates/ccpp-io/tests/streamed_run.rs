//! A run that sweeps, tallies and merges its trace while it goes on
//! ([`Scenario::run_owned_with`] forming the files) gives the same metrics, swept pixels and
//! `path.csv` as the same run computed from the whole trace afterwards, for planners that move
//! tile by tile (lattice runs, many chunks), in free directions and with collisions.

#![allow(clippy::unwrap_used)] // tests may panic on broken fixtures

use ccpp_core::grid::GridMap;
use ccpp_core::planners::{PlannerConfig, PlannerKind};
use ccpp_core::world::Robot;
use ccpp_io::scenario::{MapRecipe, PreparedMap, Scenario};

/// A 24 m x 16 m room at 0.05 m/px with a wall stub and two pillars.
fn room() -> PreparedMap {
    let art = "\
        ########################\n\
        #......................#\n\
        #......##..............#\n\
        #......##.......#......#\n\
        #...............#......#\n\
        #..........#....#......#\n\
        #..........#...........#\n\
        #......................#\n\
        #.....#######..........#\n\
        #......................#\n\
        #......................#\n\
        #...............###....#\n\
        #......................#\n\
        #......................#\n\
        #......................#\n\
        ########################";
    PreparedMap {
        grid: GridMap::from_ascii_scaled(art, 20, 0.05).unwrap(),
        name: "room".to_string(),
        source: "room.yaml".into(),
        recipe: MapRecipe::file("room.yaml"),
        thresholds: ccpp_io::map::Thresholds::default(),
        alpha_differs: 0,
    }
}

#[test]
fn streamed_metrics_and_path_equal_those_of_the_whole_trace() {
    for (kind, radius) in [
        (PlannerKind::BaStar, 0.05),
        (PlannerKind::Bsa, 0.1),
        (PlannerKind::RandomBounce, 0.15),
    ] {
        let scenario = Scenario::configure(MapRecipe::file("room.yaml"), PlannerConfig::new(kind))
            .robot(Robot::new(radius))
            .build()
            .unwrap();
        let (streamed, (), files) = scenario.run_owned_with(room(), |_| (), true).unwrap();
        let whole = scenario.run_owned(room()).unwrap();
        let trace = &whole.output.trace;
        assert!(
            trace.piece_count() > 2 * 512,
            "{kind}: the trace must span several chunks ({} pieces)",
            trace.piece_count()
        );
        assert_eq!(streamed.output.trace, *trace, "{kind}: the run itself");
        let mut a = streamed.metrics.clone();
        let mut b = whole.metrics.clone();
        a.wall_time_s = 0.0;
        b.wall_time_s = 0.0;
        assert_eq!(a, b, "{kind}: metrics");
        assert_eq!(streamed.swept, whole.swept, "{kind}: swept pixels");
        assert_eq!(
            files.unwrap().path_csv,
            ccpp_io::trace::path_csv(trace),
            "{kind}: path.csv"
        );
    }
}
