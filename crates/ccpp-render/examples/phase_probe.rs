//! Times the parts of a run outside planning, each on its own: `cargo run --release -p ccpp-render
//! --example phase_probe -- MAP.yaml RADIUS [PLANNER [REPEATS]]` (default `ba-star`, 1 repeat).
//! Prints one line per part (milliseconds, the fastest of the repeats); for profiling only.

use std::time::Instant;

use ccpp_core::planners::PlannerKind;
use ccpp_io::scenario::Scenario;

/// Runs `f` `reps` times; prints the fastest time and returns the last result.
fn timed<T>(name: &str, reps: usize, mut f: impl FnMut() -> T) -> T {
    let mut best = f64::INFINITY;
    let mut out = None;
    for _ in 0..reps.max(1) {
        let t = Instant::now();
        let v = f();
        best = best.min(t.elapsed().as_secs_f64() * 1e3);
        out = Some(v);
    }
    println!("{name:<18}{best:9.1}");
    out.expect("at least one repeat")
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(map), Some(r)) = (args.first(), args.get(1)) else {
        eprintln!("usage: phase_probe MAP.yaml RADIUS [PLANNER [REPEATS]]");
        std::process::exit(2);
    };
    let kind: PlannerKind = args.get(2).map_or("ba-star", String::as_str).parse()?;
    let reps: usize = args.get(3).map_or(Ok(1), |s| s.parse())?;
    let scenario = Scenario::builder(map, kind).radius(r.parse()?).build()?;
    let prepared = timed("load map", reps, || scenario.map.load())?;
    let world = timed("world", reps, || scenario.world(&prepared))?;
    let run = scenario.run_on(&prepared)?;
    println!("plan + simulate   {:9.1}", run.output.wall_time_s * 1e3);
    let trace = &run.output.trace;
    println!(
        "trace: {} poses, {} events, {} pieces",
        trace.pose_count(),
        trace.event_count(),
        trace.piece_count()
    );
    timed("poses() count", reps, || trace.poses().count());
    timed("metrics", reps, || {
        ccpp_core::metrics::compute(&world, &run.output, "probe")
    });
    let part = ccpp_core::metrics::WorldPart::of(&world, run.output.tile_side);
    timed("metrics prepared", reps, || {
        ccpp_core::metrics::compute_prepared(&world, &run.output, "probe", part.clone())
    });
    let swept = timed("  swept_pixels", reps, || {
        ccpp_core::metrics::swept_pixels(&world, trace)
    });
    if let Some(side) = run.output.tile_side {
        let grid = ccpp_core::tiles::TileGrid::new(world.start().position(), side);
        timed("  reach tiles", reps, || {
            ccpp_core::tiles::reachable_tiles(&world, &grid)
        });
    }
    timed("crop box", reps, || ccpp_render::crop_box(&world, trace));
    let style = ccpp_render::CoverageStyle {
        title: ccpp_render::run_files::title_lines(&run.metrics),
        ..ccpp_render::CoverageStyle::default()
    };
    let pm = timed("coverage pixmap", reps, || {
        ccpp_render::coverage_pixmap_swept(&world, trace, &style, &swept)
    })?;
    let png = timed("png encode", reps, || ccpp_render::encode_png(&pm))?;
    println!("  ({}x{}, {} bytes)", pm.width(), pm.height(), png.len());
    let text = timed("trace.jsonl", reps, || ccpp_io::trace::trace_jsonl(trace))?;
    timed("route", reps, || {
        ccpp_core::route::Route::from_trace(trace, ccpp_core::route::DEFAULT_TOLERANCE_M)
    });
    let csv = timed("path.csv", reps, || ccpp_io::trace::path_csv(trace));
    println!("  (trace {} bytes, path {} bytes)", text.len(), csv.len());
    let t = Instant::now();
    drop(run);
    println!("drop run          {:9.1}", t.elapsed().as_secs_f64() * 1e3);
    Ok(())
}
