//! `ccpp replay DIR`: `run.json` read as the [`Scenario`] it is (robot, start pose, tile side;
//! the map it names is replaced by a small fixed map) and `trace.jsonl` read by the checked codec
//! (`ccpp_io::trace::parse_trace`, poses bounded by the map as `replay` does), then the replay
//! page, the GIF and the bench plots' coverage curve drawn from them.
//! Input: the `run.json` text, a NUL byte, then the `trace.jsonl` text.
#![no_main]

use std::path::Path;

use ccpp_core::world::World;
use ccpp_core::Pose;
use ccpp_io::scenario::Scenario;
use ccpp_render::replay::{replay_gif, replay_html, GifOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((run, rest)) = ccpp_fuzz::split_text(data) else {
        return;
    };
    let Ok(trace_text) = std::str::from_utf8(rest) else {
        return;
    };
    let rec = serde_json::from_str::<Scenario>(run).ok();
    let own;
    let world = match &rec {
        Some(r) => {
            let start = r.start.map(|s| Pose::new(s[0], s[1], s[2]));
            match World::new(ccpp_fuzz::tiny_grid(), r.robot, start) {
                Ok(w) => {
                    own = w;
                    &own
                }
                Err(_) => return,
            }
        }
        None => ccpp_fuzz::tiny_world(),
    };
    let margin = world.robot().radius + 2.0 * world.frame().resolution;
    let Ok(trace) = ccpp_io::trace::parse_trace(
        trace_text,
        Path::new("trace.jsonl"),
        Some((world.frame(), margin)),
    ) else {
        return;
    };
    let tile_side = rec.as_ref().and_then(Scenario::tile_side);
    let _ = replay_html(world, &trace, tile_side, "{}", "fuzz", &[]);
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
