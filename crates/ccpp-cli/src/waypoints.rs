//! `ccpp waypoints`: the seed-001 lane plan as a plain list, for users who only want the plan.

use std::fmt::Write as _;

use anyhow::{bail, Result};
use ccpp_core::planners::rect_boustrophedon::{plan, RectOptions};
use ccpp_core::planners::PlannerConfig;
use ccpp_io::export::round_m;
use ccpp_io::scenario::{Scenario, ScenarioError};

use crate::args::WaypointsArgs;
use crate::job::{recipe_from, robot_from};
use crate::staging::write_file;

/// Runs `ccpp waypoints`.
pub fn run(a: &WaypointsArgs) -> Result<()> {
    let format = a.format.to_ascii_lowercase();
    if format != "csv" && format != "json" {
        bail!("--format must be csv or json, got {:?}", a.format);
    }
    // A file named for the other format got this one (`--out w.json` wrote CSV, the default,
    // and replaced a JSON waypoints file with CSV: hostile pass, stop 70).
    if let Some(ext) = a
        .out
        .as_deref()
        .and_then(|p| p.extension())
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
    {
        if (ext == "json" || ext == "csv") && ext != format {
            bail!(
                "--out {} ends in .{ext} but the format is {format}: give --format {ext}, or name the file .{format}",
                a.out.as_deref().map_or_else(String::new, |p| p.display().to_string())
            );
        }
    }
    if a.robot.tool_radius.is_some() {
        // The lanes follow --width: the value would be validated and then change nothing.
        bail!("--tool-radius does not apply to `ccpp waypoints` (its lanes follow --width)");
    }
    if a.robot.start.is_some_and(|s| s.heading_given) {
        // Nothing a plan writes depends on the start heading: it would be dropped.
        bail!("--start THETA does not apply to `ccpp waypoints` (waypoints have no heading); give X,Y");
    }
    let (robot, start) = robot_from(&a.robot)?;
    let opts = RectOptions {
        length_m: a.length,
        width_m: a.width,
        area: a.area,
        // Waypoints are planned, never driven: no PID trace to hold (its records were counted
        // in the memory estimate: `cluttered_2000` at 0.05 m was refused for 1.4e8 of them).
        exec: ccpp_core::exec::Execution::Ideal,
        ..RectOptions::default()
    };
    if let Some(why) = ccpp_io::plan::radius_under_the_rectangle("--radius", a.robot.radius, &opts)
    {
        bail!("{why}");
    }
    // The same validation, checks and memory estimate as `ccpp run --planner
    // rect-boustrophedon`.
    let flag = |e: ScenarioError| {
        let e = crate::job::name_flag(e, &["--length", "--width"]);
        // `--area` here is the lanes' rectangle (`rect_boustrophedon.area`), not a zone.
        anyhow::anyhow!(e
            .to_string()
            .replacen("rect_boustrophedon.area: ", "--area: ", 1))
    };
    let scenario = Scenario::configure(
        recipe_from(&a.map),
        PlannerConfig::RectBoustrophedon(opts.clone()),
    )
    .robot(robot)
    .start_pose(start.map(|p| [p.x, p.y, p.theta]))
    .memory_limit(a.limits.max_memory)
    .zones(None, a.keepout.clone())
    .build()
    .map_err(flag)?;
    let map = recipe_from(&a.map).load_within(scenario.max_memory_mb)?;
    let world = scenario.world(&map).map_err(flag)?;
    let p = plan(&world, &opts);
    // Rounded as the exports round (`0.425`, not the `0.42500000000000004` of the
    // pixel-to-map arithmetic).
    let pts: Vec<[f64; 2]> = p
        .waypoints
        .iter()
        .map(|w| [round_m(w.x), round_m(w.y)])
        .collect();
    let text = if format == "csv" {
        let mut s = String::from("x,y\n");
        for [x, y] in &pts {
            let _ = writeln!(s, "{x},{y}");
        }
        s
    } else {
        let v = serde_json::json!({
            "map": map.name,
            // The values used (the robot's diameter when not given: `null` hid them).
            "length_m": opts.length_for(&scenario.robot),
            "width_m": opts.width_for(&scenario.robot),
            "area": p.area.map(round_m),
            "waypoints": pts,
        });
        let mut s = serde_json::to_string_pretty(&v)?;
        s.push('\n');
        s
    };
    match &a.out {
        Some(path) => {
            check_target(path)?;
            // Not into a folder a bench or sweep is writing (a file dropped among its runs
            // made every later bench there refuse the folder; hostile pass).
            ccpp_io::write::check_not_in_busy_folder(path)?;
            write_file(path, text.as_bytes())?;
        }
        None => crate::print_stdout(&text)?,
    }
    Ok(())
}

/// Refuses to replace a file at `path` that `ccpp waypoints` did not write (a map, its image,
/// an options file...): `--out room.yaml` replaced the map itself. A waypoints file of either
/// format (CSV: header `x,y`; JSON: the object it writes, which begins with `"area"`) is replaced.
fn check_target(path: &std::path::Path) -> Result<()> {
    use std::io::Read as _;
    let Ok(meta) = std::fs::metadata(path) else {
        return Ok(());
    };
    if !meta.is_file() {
        bail!(
            "--out {}: not a regular file (give the path of the file to write)",
            path.display()
        );
    }
    let mut head = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(16).read_to_end(&mut head))
        .map_err(|e| {
            anyhow::anyhow!("--out {}: cannot read the file there: {e}", path.display())
        })?;
    let ours =
        head.is_empty() || head.starts_with(b"x,y\n") || head.starts_with(b"{\n  \"area\": [");
    if !ours {
        bail!(
            "--out {}: the file exists and was not written by `ccpp waypoints`; remove it or choose another path",
            path.display()
        );
    }
    Ok(())
}
