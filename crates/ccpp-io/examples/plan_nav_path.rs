//! The README's "plan a path for my robot" example: a known-map planner's route on a map,
//! written as a ROS 2 `nav_msgs/Path` (YAML) without simulating or measuring anything.
//!
//! `cargo run --release -p ccpp-io --example plan_nav_path -- ../shared/maps/nav2_depot.yaml nav_path.yaml`
//!
//! The body of [`run`] is the README's code block line for line (`tests/readme_examples.rs`
//! checks that and runs it on the shared map).

use ccpp_core::planners::PlannerKind;
use ccpp_core::route::DEFAULT_TOLERANCE_M;
use ccpp_io::{export, plan, scenario::Scenario};

/// The README's example: the route of `bcd` on `map`, written to `out` as a `nav_msgs/Path`.
///
/// # Errors
/// The map cannot be loaded, the plan is refused or the file cannot be written.
pub fn run(map: &str, out: &str) -> Result<(), Box<dyn std::error::Error>> {
    let scenario = Scenario::builder(map, PlannerKind::Bcd)
        .radius(0.2)
        .build()?;
    let plan = plan::plan_route(&scenario, &scenario.map.load()?, DEFAULT_TOLERANCE_M)?;
    std::fs::write(out, export::nav_path_yaml(&plan.route))?;
    println!(
        "{} waypoints, {:.1} m",
        plan.route.waypoints.len(),
        plan.route.length_m()
    );
    Ok(())
}

#[allow(dead_code)] // `tests/readme_examples.rs` includes this file for `run` alone
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let map = args
        .next()
        .unwrap_or_else(|| "../shared/maps/nav2_depot.yaml".into());
    let out = args.next().unwrap_or_else(|| "nav_path.yaml".into());
    run(&map, &out)?;
    println!("-> {out}");
    Ok(())
}
