//! Times the parts of a run outside planning, each on its own: `cargo run --release -p ccpp-render
//! --example phase_probe -- MAP.yaml RADIUS [PLANNER]` (default `ba-star`). Prints one line per
//! part (milliseconds); for profiling only.

use std::time::Instant;

use ccpp_core::planners::PlannerKind;
use ccpp_io::scenario::Scenario;

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(map), Some(r)) = (args.first(), args.get(1)) else {
        eprintln!("usage: phase_probe MAP.yaml RADIUS [PLANNER]");
        std::process::exit(2);
    };
    let kind: PlannerKind = args.get(2).map_or("ba-star", String::as_str).parse()?;
    let scenario = Scenario::builder(map, kind).radius(r.parse()?).build()?;
    let t = Instant::now();
    let prepared = scenario.map.load()?;
    println!("load map        {:9.1}", ms(t));
    let t = Instant::now();
    let world = scenario.world(&prepared)?;
    println!("world           {:9.1}", ms(t));
    let run = scenario.run_on(&prepared)?;
    println!("plan + simulate {:9.1}", run.output.wall_time_s * 1e3);
    let trace = &run.output.trace;
    println!(
        "trace: {} poses, {} events, {} pieces",
        trace.pose_count(),
        trace.event_count(),
        trace.piece_count()
    );
    let t = Instant::now();
    let n = trace.poses().count();
    println!("poses() x1      {:9.1}  ({n})", ms(t));
    let t = Instant::now();
    let _ = ccpp_core::metrics::compute(&world, &run.output, "probe");
    println!("metrics         {:9.1}", ms(t));
    let t = Instant::now();
    let swept = ccpp_core::metrics::swept_pixels(&world, trace);
    println!(
        "  swept_pixels  {:9.1}  ({} px)",
        ms(t),
        swept.count_ones(..)
    );
    if let Some(side) = run.output.tile_side {
        let grid = ccpp_core::tiles::TileGrid::new(world.start().position(), side);
        let t = Instant::now();
        let reach = ccpp_core::tiles::reachable_tiles(&world, &grid);
        println!("  reach tiles   {:9.1}  ({})", ms(t), reach.len());
    }
    let t = Instant::now();
    let _ = ccpp_render::crop_box(&world, trace);
    println!("crop box        {:9.1}", ms(t));
    let style = ccpp_render::CoverageStyle::default();
    let t = Instant::now();
    let pm = ccpp_render::coverage_pixmap(&world, trace, &style)?;
    println!(
        "coverage pixmap {:9.1}  ({}x{})",
        ms(t),
        pm.width(),
        pm.height()
    );
    let t = Instant::now();
    let png = pm.encode_png()?;
    println!("png encode      {:9.1}  ({} bytes)", ms(t), png.len());
    let t = Instant::now();
    let text = ccpp_io::trace::trace_jsonl(trace)?;
    println!("trace.jsonl     {:9.1}  ({} bytes)", ms(t), text.len());
    let t = Instant::now();
    let csv = ccpp_io::trace::path_csv(trace);
    println!("path.csv        {:9.1}  ({} bytes)", ms(t), csv.len());
    let t = Instant::now();
    let back = ccpp_io::trace::parse_trace(&text, std::path::Path::new("t"), None)?;
    println!(
        "parse trace     {:9.1}  ({} poses)",
        ms(t),
        back.pose_count()
    );
    Ok(())
}
