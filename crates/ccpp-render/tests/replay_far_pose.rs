//! `ccpp replay` reads `trace.jsonl` from disk; a pose far outside the map (a hand-edited or
//! corrupted trace, found by fuzzing) must still render, quickly.
#![allow(clippy::unwrap_used)]

use ccpp_core::grid::GridMap;
use ccpp_core::trace::Trace;
use ccpp_core::world::{Robot, World};
use ccpp_core::Pose;
use ccpp_render::replay::{replay_gif, replay_html, GifOptions};

#[test]
fn far_pose_renders_in_bounded_time() {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let map = GridMap::from_ascii_scaled("#####\n#...#\n#####", 5, 0.1).unwrap();
        let world = World::new(map, Robot::new(0.1), Some(Pose::new(0.75, 0.75, 0.0))).unwrap();
        let mut trace = Trace::default();
        trace.push_pose(0, Pose::new(0.75, 0.75, 0.0));
        trace.push_pose(1, Pose::new(1.55e17, 0.7, 0.0));
        trace.push_pose(2, Pose::new(-3e300, 4e300, 0.0));
        trace.push_pose(3, Pose::new(1.5, 0.75, 0.0));
        let gif = replay_gif(&world, &trace, &GifOptions::default()).unwrap();
        let html = replay_html(&world, &trace, None, "{}", "far", &[]).unwrap();
        let _ = tx.send((gif.len(), html.len()));
    });
    let (gif, html) = rx
        .recv_timeout(std::time::Duration::from_mins(1))
        .expect("replay of a far pose did not finish");
    assert!(gif > 0 && html > 0);
}
