//! Writing a run's files and printing its summary.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result};
use ccpp_core::metrics::Metrics;
use ccpp_core::trace::Trace;
use ccpp_io::write_atomic;

use ccpp_core::world::World;
use ccpp_io::scenario::Scenario;

use crate::job::{Job, JobResult};

/// Writes the run's files into `out` (see [`ccpp_render::run_files::write_run_files`]) and
/// returns the metrics JSON.
pub fn write_run_files(out: &Path, job: &Job, r: &JobResult) -> Result<String> {
    Ok(ccpp_render::run_files::write_run_files(
        out,
        &job.scenario,
        &r.world,
        &r.run.trace,
        &r.metrics,
    )?)
}

/// Writes `replay.html` and `replay.gif` of a finished run into `out`.
pub fn write_replay(
    out: &Path,
    world: &World,
    trace: &Trace,
    tile_side: Option<f64>,
    metrics: &str,
    title: &str,
) -> Result<()> {
    let html = ccpp_render::replay::replay_html(world, trace, tile_side, metrics, title)?;
    let gif =
        ccpp_render::replay::replay_gif(world, trace, &ccpp_render::replay::GifOptions::default())?;
    write_atomic(&out.join("replay.html"), html.as_bytes())?;
    write_atomic(&out.join("replay.gif"), &gif)?;
    Ok(())
}

/// `ccpp replay DIR`: rebuilds the world of a finished run and writes its replay files.
pub fn replay_dir(dir: &Path) -> Result<()> {
    let rec_path = dir.join("run.json");
    let text = ccpp_io::file::read_text(&rec_path).with_context(|| {
        format!(
            "{} is not a ccpp run folder (no readable run.json)",
            dir.display()
        )
    })?;
    let scenario: Scenario =
        serde_json::from_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", rec_path.display()))?;
    let map = crate::job::load_recipe(&scenario.map)?;
    let world = scenario.world(&map)?;
    // Poses must lie on the map (a robot cannot leave it): a damaged trace is refused here
    // instead of hanging the renderer.
    let margin = scenario.robot.radius + 2.0 * world.frame().resolution;
    let trace =
        ccpp_io::trace::read_trace(&dir.join("trace.jsonl"), Some((world.frame(), margin)))?;
    let metrics = std::fs::read_to_string(dir.join("metrics.json")).unwrap_or_default();
    let title = format!("{} on {}", scenario.planner.name(), map.name);
    write_replay(dir, &world, &trace, scenario.tile_side(), &metrics, &title)?;
    println!("wrote {}/replay.html and replay.gif", dir.display());
    Ok(())
}

/// Writes the run's files, then prints the summary (or the metrics JSON alone).
pub fn emit(job: &Job, r: &JobResult, json_only: bool, replay: bool) -> Result<()> {
    let metrics = write_run_files(&job.out, job, r)?;
    if replay {
        let title = format!("{} on {}", r.metrics.planner, r.metrics.map);
        write_replay(
            &job.out,
            &r.world,
            &r.run.trace,
            r.run.tile_side,
            &metrics,
            &title,
        )?;
    }
    if json_only {
        print!("{metrics}");
    } else {
        print!("{}", summary(&r.metrics));
        let extra = if replay {
            ", replay.html, replay.gif"
        } else {
            ""
        };
        println!(
            "wrote {}/{{metrics.json, path.csv, trace.jsonl, coverage.png, run.json{extra}}}",
            job.out.display()
        );
    }
    Ok(())
}

/// A short human table of the metrics.
pub fn summary(m: &Metrics) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{} on {} (r = {} m, tool r = {} m)",
        m.planner, m.map, m.robot_radius_m, m.tool_radius_m
    );
    let cov = m
        .coverage_rate
        .map_or_else(|| "n/a".to_string(), |c| format!("{c:.4}"));
    let rows: [(&str, String); 13] = [
        ("coverage_rate", cov),
        ("effective_coverage", format!("{:.4}", m.effective_coverage)),
        ("path_length_m", format!("{:.2}", m.path_length_m)),
        ("path_ratio", format!("{:.3}", m.path_ratio)),
        ("redundancy", format!("{:.3}", m.redundancy)),
        ("revisit_rate", format!("{:.3}", m.revisit_rate)),
        ("regions", m.regions.to_string()),
        ("backtracks", m.backtracks.to_string()),
        ("backtrack_length_m", format!("{:.2}", m.backtrack_length_m)),
        ("turns", m.turns.to_string()),
        ("rotation_rad", format!("{:.1}", m.rotation_rad)),
        ("collisions", m.collisions.to_string()),
        ("wall_time_s", format!("{:.3}", m.wall_time_s)),
    ];
    for (k, v) in rows {
        let _ = writeln!(s, "  {k:<20} {v:>12}");
    }
    s
}
