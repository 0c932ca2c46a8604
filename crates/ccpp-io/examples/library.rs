//! The README's Rust library example: one scenario built, validated and run through the
//! library entry point, then re-run from its JSON (what `run.json` holds).
//!
//! `cargo run --release -p ccpp-io --example library -- ../shared/maps/teb_maze.yaml`

use ccpp_core::planners::PlannerKind;
use ccpp_io::scenario::Scenario;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let map = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "../shared/maps/teb_maze.yaml".to_string());
    let scenario = Scenario::builder(&map, PlannerKind::BaStarExtended)
        .radius(0.15)
        .build()?; // validated once, here
    let run = scenario.run()?; // load, check the memory estimate, plan and simulate, measure
    let m = &run.metrics;
    println!(
        "{}: effective coverage {:.4}, path {:.1} m (ratio {:.3}), {} collisions",
        m.planner, m.effective_coverage, m.path_length_m, m.path_ratio, m.collisions
    );
    // The scenario is data: its JSON reproduces the run exactly.
    let again: Scenario = serde_json::from_str(&scenario.to_json()?)?;
    assert_eq!(again.run()?.output.trace, run.output.trace);
    Ok(())
}
