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

use std::sync::atomic::AtomicBool;

use ccpp_core::exec::Execution;
use ccpp_core::planners::PlannerConfig;
use ccpp_core::route::Route;
use ccpp_core::sim::{simulate_until, StopReason};
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
    /// What the planner said of the plan that its user should hear
    /// ([`plan_warnings`](crate::warnings::plan_warnings), without `warning: `).
    pub warnings: Vec<String>,
}

/// Why a robot radius given beside the rectangle of rect-boustrophedon's `o` changes nothing in
/// a plan (`None` when it does): with both `length_m` and `width_m` the lanes keep clear the
/// rectangle's circumscribed disk (or `clearance_radius_m`), and the radius is only a floor
/// under it (`ccpp plan --radius 0.1` beside a 0.3 x 0.3 m rectangle wrote the same waypoints as
/// 0.2 or none). `name` is the radius as the caller's user wrote it (`--radius`, `radius=`). A
/// simulated run keeps the radius: its collisions use it.
pub fn radius_under_the_rectangle(
    name: &str,
    given: Option<f64>,
    o: &ccpp_core::planners::rect_boustrophedon::RectOptions,
) -> Option<String> {
    let r = given?;
    // Without both sides the rectangle follows the tool, and so the radius.
    o.length_m.zip(o.width_m)?;
    let disk = o.rectangle_disk(&ccpp_core::world::Robot::new(r));
    (r <= disk).then(|| {
        format!(
            "{name} {} m changes nothing here: the lanes keep clear the rectangle's disk of radius {disk:.4} m (from its length and width), which is larger; leave the radius out, or give more than that",
            ccpp_core::display::Compact(r)
        )
    })
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

/// Refuses the simulator settings a plan would read and then drop: it executes the planner's
/// steps ideally, so an execution (the simulator's or the planner's own, when not its default)
/// and landmarks (which correct PID execution) would change nothing.
fn check_dropped(scenario: &Scenario) -> Result<(), ScenarioError> {
    let dropped = |what: String| {
        ScenarioError::Invalid(format!(
            "{what} does not apply to a plan: it executes the planner's steps ideally (use a run to simulate an execution)"
        ))
    };
    if scenario.sim.exec.is_some() {
        return Err(dropped(
            "sim.exec (--exec, --odometry-noise; exec=, odometry_noise=)".into(),
        ));
    }
    if scenario.planner_sets_execution() {
        let kind = scenario.planner.kind();
        return Err(dropped(format!(
            "the execution given for {kind} in {}.exec",
            kind.info().section
        )));
    }
    if !scenario.sim.landmarks.landmarks.is_empty() {
        return Err(dropped("sim.landmarks".into()));
    }
    Ok(())
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
    // (a flag nobody sets: the same plan as one that cannot be given up)
    plan_route_until(scenario, map, tolerance_m, &AtomicBool::new(false))
}

/// [`plan_route`] that another thread can give up by setting `stop`: bcd's planning ends at
/// its next step, rect-boustrophedon's within a lane point or a search
/// ([`PlannerConfig::build_until`]), and the execution within a few steps
/// (Python's Ctrl-C gives a plan up this way).
///
/// # Errors
/// As [`plan_route`]; [`ScenarioError::Interrupted`] when `stop` ended the plan.
pub fn plan_route_until(
    scenario: &Scenario,
    map: &PreparedMap,
    tolerance_m: f64,
    stop: &AtomicBool,
) -> Result<Plan, PlanError> {
    let kind = scenario.planner.kind();
    if !kind.info().offline {
        return Err(PlanError::Online(kind.name(), offline_planners()));
    }
    check_dropped(scenario)?;
    // A plan executes its steps ideally, so its memory is that of an ideal run: the estimate
    // of a planner that asks for PID (rect-boustrophedon) counted PID trace records a plan
    // never makes (209 MB estimated for an 85 MB plan; `waypoints` on `cluttered_2000` refused
    // at the default 4096 MB for a 473 MB job).
    let mut ideal = scenario.clone();
    if let PlannerConfig::RectBoustrophedon(o) = &mut ideal.planner {
        o.exec = Execution::Ideal;
    }
    ideal.sim.exec = Some(Execution::Ideal);
    let world = ideal.world(map)?;
    let started = std::time::Instant::now();
    let mut sim = scenario.sim.clone();
    sim.exec = Some(Execution::Ideal);
    // (options checked when the world was built, `Scenario::world`)
    let mut planner = scenario.planner.settings().build_until(&world, stop);
    let output = simulate_until(&world, planner.as_mut(), &sim, &mut |_| {}, stop)
        .ok_or(ScenarioError::Interrupted)?;
    let route = Route::from_trace(&output.trace, tolerance_m);
    let warnings = crate::warnings::plan_warnings(scenario, &world, &output.trace, &route);
    Ok(Plan {
        world,
        route,
        stop: output.stop,
        wall_time_s: started.elapsed().as_secs_f64(),
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use ccpp_core::exec::PidOptions;
    use ccpp_core::planners::rect_boustrophedon::RectOptions;
    use ccpp_core::planners::PlannerKind;

    use crate::scenario::MapRecipe;

    #[test]
    fn a_plan_refuses_the_execution_it_would_drop() {
        let mut s = Scenario::builder("m.yaml", PlannerKind::RectBoustrophedon)
            .build()
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(check_dropped(&s).is_ok());
        s.planner = PlannerConfig::RectBoustrophedon(RectOptions {
            exec: Execution::Pid(PidOptions {
                dt_s: 0.1,
                ..PidOptions::default()
            }),
            ..RectOptions::default()
        });
        let e = check_dropped(&s)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("rect_boustrophedon.exec"), "{e}");
        let mut s = Scenario::new(MapRecipe::file("m.yaml"), PlannerKind::Bcd);
        s.sim.exec = Some(Execution::Ideal);
        let e = check_dropped(&s)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("sim.exec"), "{e}");
    }
}
