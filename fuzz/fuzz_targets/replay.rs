//! `ccpp replay DIR`: what it reads from `run.json` (robot, start pose, tile side) and
//! `trace.jsonl` (`ccpp_io::trace::parse_trace_jsonl`), then the replay page, the GIF and the
//! bench plots' coverage curve drawn from them on a small fixed map.
//! Input: the `run.json` text, a NUL byte, then the `trace.jsonl` text.
#![no_main]

use ccpp_core::world::{Robot, World};
use ccpp_core::Pose;
use ccpp_render::replay::{replay_gif, replay_html, GifOptions};
use libfuzzer_sys::fuzz_target;

/// The fields of the CLI's `RunRecord` that `replay` uses besides the map recipe (which names
/// files on disk); unknown fields are ignored as the CLI's record does.
#[derive(serde::Deserialize)]
struct Record {
    robot: Robot,
    start: [f64; 3],
    tile_side: Option<f64>,
}

fuzz_target!(|data: &[u8]| {
    let Some((run, rest)) = ccpp_fuzz::split_text(data) else {
        return;
    };
    let Ok(trace_text) = std::str::from_utf8(rest) else {
        return;
    };
    let rec = serde_json::from_str::<Record>(run).ok();
    let Ok(trace) = ccpp_io::trace::parse_trace_jsonl(trace_text) else {
        return;
    };
    let own;
    let world = match &rec {
        Some(r) => {
            let start = Pose::new(r.start[0], r.start[1], r.start[2]);
            match World::new(ccpp_fuzz::tiny_grid(), r.robot, Some(start)) {
                Ok(w) => {
                    own = w;
                    &own
                }
                Err(_) => return,
            }
        }
        None => ccpp_fuzz::tiny_world(),
    };
    let tile_side = rec.as_ref().and_then(|r| r.tile_side);
    let _ = replay_html(world, &trace, tile_side, "{}", "fuzz");
    // Few small frames: the same drawing code as the CLI's 60 frames of 400 px, at a cost that
    // allows millions of runs.
    let gif = GifOptions {
        max_side: 48,
        frames: 3,
        ..GifOptions::default()
    };
    let _ = replay_gif(world, &trace, &gif);
    let _ = ccpp_core::metrics::coverage_curve(world, &trace, 200);
});
