//! The README's Rust library example: one scenario built, validated and run through the
//! library entry point, then re-run from its JSON (what `run.json` holds).
//!
//! `cargo run --release -p ccpp-io --example library -- ../shared/maps/teb_maze.yaml`
//!
//! The body of [`run`] is the README's code block line for line (`tests/readme_examples.rs`
//! checks that and runs it on the shared map).

use ccpp_core::planners::PlannerKind;
use ccpp_io::scenario::Scenario;

/// The README's example on `map`.
///
/// # Errors
/// The map cannot be loaded or the run is refused.
pub fn run(map: &str) -> Result<(), Box<dyn std::error::Error>> {
    let scenario = Scenario::builder(map, PlannerKind::BaStarExtended)
        .radius(0.15)
        .build()?; // validated once, here
    let run = scenario.run()?; // load, memory check, plan + simulate, metrics
    println!("{:.4}", run.metrics.effective_coverage);
    let again: Scenario = serde_json::from_str(&scenario.to_json()?)?;
    assert_eq!(again.run()?.output.trace, run.output.trace); // the JSON reproduces the run
    Ok(())
}

#[allow(dead_code)] // `tests/readme_examples.rs` includes this file for `run` alone
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let arg = std::env::args().nth(1);
    run(arg.as_deref().unwrap_or("../shared/maps/teb_maze.yaml"))
}
