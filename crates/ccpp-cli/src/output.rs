//! Writing a run's files and printing its summary.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result};
use ccpp_core::metrics::Metrics;
use ccpp_core::trace::Trace;

use ccpp_core::world::World;
use ccpp_io::export::ExportFormat;
use ccpp_io::scenario::Scenario;

use crate::info::StartComponent;
use crate::job::{Job, JobResult};
use crate::staging::{write_file, Staging};

/// A run's files, rendered in memory: `(file name, bytes)`.
pub struct RunFiles {
    /// The files, `metrics.json` last.
    pub files: Vec<(&'static str, Vec<u8>)>,
    /// The metrics JSON (also among `files`).
    pub metrics: String,
}

/// Renders every file of a run (and the replay files when `replay`) without writing anything.
pub fn render_run_files(job: &Job, r: &JobResult, replay: bool) -> Result<RunFiles> {
    // The library renders the standard set (the Python package's `save` writes the same
    // bytes); the replay files go before `metrics.json`, which marks a complete run.
    let mut files = ccpp_render::run_files::render_run_files_swept(
        &job.scenario,
        &r.world,
        &r.run.trace,
        &r.metrics,
        Some(&r.swept),
    )?;
    let (_, metrics_bytes) = files.pop().context("no metrics.json rendered")?;
    let metrics = String::from_utf8(metrics_bytes).context("metrics.json is not UTF-8")?;
    if replay {
        let title = format!("{} on {}", r.metrics.planner, r.metrics.map);
        let (html, gif) = render_replay(&r.world, &r.run.trace, r.run.tile_side, &metrics, &title)?;
        files.push(("replay.html", html.into_bytes()));
        files.push(("replay.gif", gif));
    }
    files.push(("metrics.json", metrics.clone().into_bytes()));
    Ok(RunFiles { files, metrics })
}

/// Writes a run's files (plus `extra` ones) as one set: everything goes into a staging folder
/// beside `out`, which then replaces `out` whole (see [`crate::staging`]). A failure or an
/// interrupt leaves `out` as it was. Returns the metrics JSON.
pub fn write_run_files(
    out: &Path,
    job: &Job,
    r: &JobResult,
    replay: bool,
    extra: &[(&'static str, Vec<u8>)],
) -> Result<String> {
    let rendered = render_run_files(job, r, replay)?;
    ccpp_io::phase::time("write files", || -> Result<()> {
        let staging = Staging::new(out)?;
        for (name, bytes) in extra.iter().chain(&rendered.files) {
            staging.write(name, bytes)?;
        }
        staging.commit()
    })?;
    Ok(rendered.metrics)
}

/// Renders `replay.html` and `replay.gif` of a finished run.
pub fn render_replay(
    world: &World,
    trace: &Trace,
    tile_side: Option<f64>,
    metrics: &str,
    title: &str,
) -> Result<(String, Vec<u8>)> {
    let html = ccpp_render::replay::replay_html(world, trace, tile_side, metrics, title)?;
    let gif =
        ccpp_render::replay::replay_gif(world, trace, &ccpp_render::replay::GifOptions::default())?;
    Ok((html, gif))
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
    let (html, gif) = render_replay(&world, &trace, scenario.tile_side(), &metrics, &title)?;
    write_file(&dir.join("replay.html"), html.as_bytes())?;
    write_file(&dir.join("replay.gif"), &gif)?;
    crate::print_stdout(&format!(
        "wrote {}/replay.html and replay.gif\n",
        dir.display()
    ))
}

/// Writes the run's files (with the replay when `replay`, and the path in each of `exports`)
/// as one set, then prints the summary (or the metrics JSON alone). A start whose free area
/// reaches the map's border is warned about on stderr.
pub fn emit(
    job: &Job,
    r: &JobResult,
    json_only: bool,
    replay: bool,
    exports: &[ExportFormat],
) -> Result<()> {
    let export_files = ccpp_render::run_files::render_export_files(
        &job.scenario,
        &r.run.trace,
        &r.metrics,
        exports,
        &ccpp_io::export::zone_features(r.world.zones()),
    )?;
    let metrics = write_run_files(&job.out, job, r, replay, &export_files)?;
    let comp = StartComponent::of(r.world.map(), r.world.start().position());
    if let Some(w) = comp.warning() {
        eprintln!("{w}");
    }
    if json_only {
        return crate::print_stdout(&metrics);
    }
    let mut s = summary(&r.metrics);
    let _ = writeln!(s, "  start area: {}", comp.line());
    let mut extra = String::new();
    if replay {
        extra.push_str(", replay.html, replay.gif");
    }
    for (name, _) in &export_files {
        extra.push_str(", ");
        extra.push_str(name);
    }
    let _ = writeln!(
        s,
        "wrote {}/{{metrics.json, path.csv, trace.jsonl, coverage.png, run.json{extra}}}",
        job.out.display()
    );
    crate::print_stdout(&s)
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
    let redundancy = m
        .redundancy
        .map_or_else(|| "n/a".to_string(), |v| format!("{v:.3}"));
    // The floor actually swept leads; the tile figure (1.0 for every complete tile planner)
    // follows.
    let rows: [(&str, String); 14] = [
        ("effective_coverage", format!("{:.4}", m.effective_coverage)),
        ("coverage_rate", cov),
        ("path_length_m", format!("{:.2}", m.path_length_m)),
        ("path_ratio", format!("{:.3}", m.path_ratio)),
        ("redundancy", redundancy),
        ("revisit_rate", format!("{:.3}", m.revisit_rate)),
        ("regions", m.regions.to_string()),
        ("backtracks", m.backtracks.to_string()),
        ("backtrack_length_m", format!("{:.2}", m.backtrack_length_m)),
        ("turns", m.turns.to_string()),
        ("rotation_rad", format!("{:.1}", m.rotation_rad)),
        ("collisions", m.collisions.to_string()),
        ("keepout_violations", m.keepout_violations.to_string()),
        ("wall_time_s", format!("{:.3}", m.wall_time_s)),
    ];
    for (k, v) in rows {
        let _ = writeln!(s, "  {k:<20} {v:>12}");
    }
    s
}
