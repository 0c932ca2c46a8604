//! `ccpp plan`: a known-map planner's path for a robot, written only as path exports (no
//! simulation metrics, picture or trace). See [`ccpp_io::plan`].

use std::fmt::Write as _;

use anyhow::{bail, Result};
use ccpp_core::planners::{PlannerConfig, PlannerKind};
use ccpp_core::route::DEFAULT_TOLERANCE_M;
use ccpp_core::sim::StopReason;
use ccpp_io::export::{render_exports, zone_features, ExportFormat, ExportMeta};
use ccpp_io::plan::{offline_planners, plan_route, PlanError};
use ccpp_io::scenario::{Scenario, ScenarioError};

use crate::args::PlanArgs;
use crate::components::StartComponent;
use crate::job::{load_recipe, parse_planner, planner_options, recipe_from, robot_from};
use crate::staging::{check_user_target, Staging};

/// The exports written when `--export` is not given.
pub const DEFAULT_EXPORTS: [ExportFormat; 2] = [ExportFormat::Csv, ExportFormat::NavPath];

/// Runs `ccpp plan`.
pub fn run(a: &PlanArgs) -> Result<()> {
    let kind = parse_planner(&a.planner)?;
    if !kind.info().offline {
        // Refused before the map is read.
        return Err(PlanError::Online(kind.name(), offline_planners()).into());
    }
    if a.robot.tool_radius.is_some() && kind == PlannerKind::RectBoustrophedon {
        // Its lanes follow --width and a plan has no coverage metrics: the value would be
        // validated and then change nothing.
        bail!("--tool-radius does not apply to {kind} in `ccpp plan` (its lanes follow --width)");
    }
    if a.robot.start.is_some_and(|s| s.heading_given) {
        // Nothing a plan writes depends on the start heading: it would be dropped.
        bail!("--start THETA does not apply to `ccpp plan` (the path heads from the start to its first waypoint); give X,Y");
    }
    let (robot, start) = robot_from(&a.robot)?;
    let mut planner = planner_options(a.options.config.as_deref(), None)?.config(kind);
    crate::job::warn_unused_config(a.options.config.as_deref(), &[kind]);
    let given =
        crate::job::apply_rect_flags(a.length, a.width, &mut planner, a.options.config.as_deref())?;
    // A plan is not simulated: beside a rectangle the radius is only a floor under its disk
    // (`ccpp run` keeps it: the simulator's collisions use it).
    if let PlannerConfig::RectBoustrophedon(o) = &planner {
        if let Some(why) = ccpp_io::plan::radius_under_the_rectangle("--radius", a.robot.radius, o)
        {
            bail!("{why}");
        }
    }
    let flag = |e: ScenarioError| crate::job::name_flag(e, &given);
    let scenario = Scenario::configure(recipe_from(&a.map), planner)
        .robot(robot)
        .start_pose(start.map(|p| [p.x, p.y, p.theta]))
        .memory_limit(a.limits.max_memory)
        .zones(a.zones.area.clone(), a.zones.keepout.clone())
        .build()
        .map_err(flag)?;
    check_user_target(&a.out)?;
    crate::staging::check_inputs(&a.out, &scenario, &[a.options.config.as_ref()])?;
    let map = load_recipe(&scenario.map, scenario.max_memory_mb)?;
    let busy = crate::busy::Busy::start(format!("{kind} on {}: planning", map.name));
    let plan = plan_route(&scenario, &map, DEFAULT_TOLERANCE_M);
    busy.done();
    let plan = plan.map_err(|e| match (e, a.options.config.as_deref()) {
        // The planner's execution given in the options file: name the file (`ccpp run` names
        // it for the same clash).
        (PlanError::Scenario(ScenarioError::Invalid(m)), Some(cfg))
            if m.starts_with("the execution given for") =>
        {
            anyhow::anyhow!("{}: {m}", cfg.display())
        }
        (PlanError::Scenario(s), cfg) => {
            crate::job::naming_config(flag(s), cfg, kind.info().section)
        }
        (other @ PlanError::Online(..), _) => other.into(),
    })?;
    let formats: &[ExportFormat] = if a.export.is_empty() {
        &DEFAULT_EXPORTS
    } else {
        &a.export
    };
    let meta = ExportMeta {
        planner: kind.name(),
        map: &map.name,
        robot,
        footprint: ccpp_io::export::Footprint::of(&scenario.planner, &robot),
        tolerance_m: DEFAULT_TOLERANCE_M,
        metrics: None,
    };
    let files = render_exports(
        &plan.route,
        &meta,
        formats,
        &zone_features(plan.world.zones(), plan.world.frame()),
    )?;
    let staging = Staging::new(&a.out)?;
    for (name, bytes) in &files {
        staging.write(name, bytes)?;
    }
    staging.commit()?;
    if let Some(note) = crate::job::approach_note(&plan.world) {
        say!("{note}");
    }
    let comp = StartComponent::of_world(&plan.world);
    for w in &plan.warnings {
        say!("warning: {w}");
    }
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{} on {} ({}): {} waypoints, {:.2} m, planned in {:.3} s",
        kind,
        map.name,
        robot_used(&scenario),
        plan.route.waypoints.len(),
        plan.route.length_m(),
        plan.wall_time_s
    );
    if plan.stop != StopReason::Done {
        let _ = writeln!(
            s,
            "  warning: {}",
            ccpp_io::warnings::stop_warning(plan.stop.as_str(), "path")
        );
    }
    // As `run` prints it: an area of two rooms the start's room does not join was planned in
    // the start's room only, and nothing said so.
    let _ = writeln!(s, "  start area: {}", comp.line());
    let names: Vec<&str> = files.iter().map(|(n, _)| *n).collect();
    let _ = writeln!(
        s,
        "wrote {}/{{{}}}",
        crate::output::folder_shown(&a.out),
        names.join(", ")
    );
    crate::print_stdout(&s)
}

/// The robot a plan was made for, as the summary prints it: `r = 0.15 m, tool r = 0.15 m`,
/// and for rect-boustrophedon the rectangle (whose width is its lanes' spacing: a plan has no
/// tool of its own) and the disk it plans for (`rectangle 0.4 x 0.4 m, clearance disk
/// r = 0.283 m`).
pub fn robot_used(scenario: &Scenario) -> String {
    use crate::output::num;
    let robot = scenario.robot;
    match &scenario.planner {
        PlannerConfig::RectBoustrophedon(o) => format!(
            "rectangle {} x {} m, clearance disk r = {:.3} m",
            num(o.length_for(&robot)),
            num(o.width_for(&robot)),
            o.clearance_radius(&robot),
        ),
        _ => format!(
            "r = {} m, tool r = {} m",
            num(robot.radius),
            num(robot.tool_radius)
        ),
    }
}
