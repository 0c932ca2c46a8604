//! Planning without measuring: a known-map (offline) planner's path as a [`Route`], for a
//! robot that has its map before it starts.
//!
//! [`plan_route`] builds the world and the planner exactly as [`Scenario::run_on`] does, then
//! executes the planner's steps **ideally** (exact rotations and straight moves; every motion is
//! still checked against the map, so the route never passes through a wall), whatever the
//! scenario's execution setting: the route is the commanded geometry, not a PID rendition of
//! it. No metrics, picture or trace file are produced, which is where a simulated run spends
//! most of its time. Online planners are refused: their path exists only once a simulated robot
//! has discovered the map ([`Scenario::run_on`] and the route of its trace).

use ccpp_core::exec::Execution;
use ccpp_core::route::Route;
use ccpp_core::sim::{simulate, StopReason};
use ccpp_core::world::World;

use crate::scenario::{PreparedMap, Scenario, ScenarioError};

/// Why a plan cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// The planner is online.
    #[error("{0} is an online planner: it discovers the map while driving, so its path exists only after a simulated run (use `ccpp run --export`); plan needs a known-map planner ({1})")]
    Online(&'static str, String),
    /// The scenario is invalid or does not fit the map.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
}

/// A planned path.
pub struct Plan {
    /// The world it was planned on.
    pub world: World,
    /// The waypoints ([`Route::from_trace`] of the ideal execution with `tolerance_m`).
    pub route: Route,
    /// Whether the planner finished (`Done`) or hit the step cap.
    pub stop: StopReason,
    /// Wall time of planning and execution, seconds.
    pub wall_time_s: f64,
}

/// The names of the known-map planners, comma-separated.
pub fn offline_planners() -> String {
    ccpp_core::planners::CATALOG
        .iter()
        .filter(|p| p.offline)
        .map(|p| p.name)
        .collect::<Vec<_>>()
        .join(", ")
}

/// Plans `scenario` on `map` with a known-map planner and returns its route (waypoints merged
/// with `tolerance_m`, see [`ccpp_core::route`]).
///
/// # Errors
/// An online planner, or what [`Scenario::world`] refuses.
pub fn plan_route(
    scenario: &Scenario,
    map: &PreparedMap,
    tolerance_m: f64,
) -> Result<Plan, PlanError> {
    let kind = scenario.planner.kind();
    if !kind.info().offline {
        return Err(PlanError::Online(kind.name(), offline_planners()));
    }
    let world = scenario.world(map)?;
    let started = std::time::Instant::now();
    let mut planner = scenario.planner.build(&world);
    let mut sim = scenario.sim.clone();
    sim.exec = Some(Execution::Ideal);
    let output = simulate(&world, planner.as_mut(), &sim);
    let route = Route::from_trace(&output.trace, tolerance_m);
    Ok(Plan {
        world,
        route,
        stop: output.stop,
        wall_time_s: started.elapsed().as_secs_f64(),
    })
}
