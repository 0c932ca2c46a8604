//! Writing a run's files and printing its summary.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{bail, Context, Result};
use ccpp_core::metrics::Metrics;
use ccpp_core::trace::Trace;

use ccpp_core::world::World;
use ccpp_io::export::ExportFormat;
use ccpp_io::scenario::Scenario;

use crate::components::StartComponent;
use crate::job::{Job, JobResult};
use crate::staging::Staging;

/// Writes a run's files (plus `extra` ones) as one set: everything goes into a staging folder
/// beside `out`, which then replaces `out` whole (see [`crate::staging`]). A failure or an
/// interrupt leaves `out` as it was. The files are those of the library's
/// [`ccpp_render::run_files::render_run_files`] (the Python package's `save` writes the same
/// bytes), `trace.jsonl` streamed into its staging file as it is formed. `metrics.json` (which
/// marks a complete run where files are written one by one) is written first here: the staging
/// folder shows all files or none, and its sync then overlaps the drawing of the picture.
/// Returns the metrics JSON.
///
/// `manifest`: a file written last, `(name, head)`: `head` and then a line `NAME SIZE` for
/// every other file of the folder (a bench run's `bench-key.txt`, by which a resumed bench
/// tells a whole run folder from one cut short).
pub fn write_run_files(
    out: &Path,
    job: &Job,
    r: &JobResult,
    replay: bool,
    extra: &[(&'static str, Vec<u8>)],
    warnings: &[String],
    manifest: Option<(&str, &str)>,
) -> Result<String> {
    let metrics = ccpp_render::run_files::metrics_json(&r.metrics)?;
    let staging = Staging::new(out)?;
    // The folder appears whole or not at all, so the order inside it does not matter: the
    // small files known now go first, and their syncs run while the picture is drawn.
    staging.write("metrics.json", metrics.as_bytes())?;
    for (name, bytes) in extra {
        staging.write(name, bytes)?;
    }
    ccpp_render::run_files::stream_run_files::<anyhow::Error>(
        &job.scenario,
        &r.world,
        &r.run.trace,
        &r.metrics,
        &ccpp_render::run_files::KnownParts {
            swept: Some(&r.swept),
            formed: r.formed.as_ref(),
            warnings,
        },
        &mut |name, fill| staging.write_with(name, fill),
    )?;
    if replay {
        let title = format!("{} on {}", r.metrics.planner, r.metrics.map);
        let (html, gif) = render_replay(
            &r.world,
            &r.run.trace,
            r.run.tile_side,
            &metrics,
            &title,
            warnings,
        )?;
        staging.write("replay.html", html.as_bytes())?;
        staging.write("replay.gif", &gif)?;
    }
    if let Some((name, head)) = manifest {
        let mut text = head.to_string();
        for (file, len) in staging.sizes()? {
            text.push_str(&file);
            text.push(' ');
            text.push_str(&len.to_string());
            text.push('\n');
        }
        staging.write(name, text.as_bytes())?;
    }
    ccpp_io::phase::time("write files", || staging.commit())?;
    Ok(metrics)
}

/// Renders `replay.html` and `replay.gif` of a finished run.
pub fn render_replay(
    world: &World,
    trace: &Trace,
    tile_side: Option<f64>,
    metrics: &str,
    title: &str,
    warnings: &[String],
) -> Result<(String, Vec<u8>)> {
    let html = ccpp_render::replay::replay_html(world, trace, tile_side, metrics, title, warnings)?;
    let gif =
        ccpp_render::replay::replay_gif(world, trace, &ccpp_render::replay::GifOptions::default())?;
    Ok((html, gif))
}

/// `ccpp replay DIR`: rebuilds the world of a finished run and writes its replay files.
pub fn replay_dir(dir: &Path) -> Result<()> {
    // The folder read, to write into that one only: a `ccpp run` into the same folder swaps a
    // new folder in under the same name, and a replay that read the old run wrote its page and
    // GIF beside the new run's files (a folder mixing two runs).
    // A missing folder is said as such (it was "not a ccpp run folder (no readable run.json):
    // No such file or directory": hostile pass).
    if !dir.is_dir() {
        if dir.exists() {
            anyhow::bail!(
                "{} is not a folder: replay reads a run folder",
                dir.display()
            );
        }
        anyhow::bail!("{}: no such folder", dir.display());
    }
    // As `ccpp run` refuses such a folder: the write permission is the user's word, also
    // where the process could write anyway (as root the replay wrote into a `chmod 555`
    // folder that `ccpp run --out` refused: hostile pass, stop 69).
    if std::fs::metadata(dir).is_ok_and(|m| m.permissions().readonly()) {
        anyhow::bail!(
            "run folder {} is read-only: replay writes replay.html and replay.gif into it; make it writable",
            dir.display()
        );
    }
    let identity = folder_identity(dir);
    let rec_path = dir.join("run.json");
    // A `ccpp plan` folder holds exports only (it said "no readable run.json: No such file or
    // directory": docs review).
    let plan_files = [
        "nav_path.yaml",
        "waypoints.csv",
        "waypoints.json",
        "path.geojson",
    ];
    if !rec_path.exists() && plan_files.iter().any(|f| dir.join(f).is_file()) {
        anyhow::bail!(
            "{} holds a plan (ccpp plan), not a run: a plan is not simulated, so there is nothing to replay; `ccpp run` with the same map and planner writes a run folder",
            dir.display()
        );
    }
    let text = ccpp_io::file::read_text(&rec_path).with_context(|| {
        format!(
            "{} is not a ccpp run folder (no readable run.json)",
            dir.display()
        )
    })?;
    let scenario: Scenario = serde_json::from_str(&text).map_err(|e| {
        // (serde's message quotes the folder's values raw: a line break there cut it)
        anyhow::anyhow!(
            "{}: {}",
            rec_path.display(),
            ccpp_io::message::visible(&e.to_string())
        )
    })?;
    let map = crate::job::load_recipe(&scenario.map, scenario.max_memory_mb)?;
    let world = scenario.world(&map)?;
    // Poses must lie on the map: a damaged trace is refused instead of hanging the renderer.
    let trace = ccpp_io::trace::read_run_trace(
        &dir.join("trace.jsonl"),
        world.frame(),
        scenario.robot.radius,
    )?;
    // Through `read_text`: a FIFO named metrics.json hung the replay (a regular file only).
    let metrics_path = dir.join("metrics.json");
    let metrics = ccpp_io::file::read_text(&metrics_path).with_context(|| {
        format!(
            "{} is not a complete ccpp run folder (no readable metrics.json)",
            dir.display()
        )
    })?;
    let reported = check_same_run(dir, &scenario, &map.name, &world, &trace, &metrics)?;
    let trace = check_metrics_of_run(dir, &scenario, &map.name, &world, trace, &reported)?;
    crate::staging::pause_for(crate::staging::REPLAY_PAUSE_ENV);
    let title = format!("{} on {}", scenario.planner.name(), map.name);
    // The run's warnings, found again as `ccpp run` found them (the folder holds none).
    let warnings: Vec<String> = match serde_json::from_str::<ccpp_core::metrics::Metrics>(&metrics)
    {
        Ok(m) => {
            let swept = ccpp_core::metrics::swept_pixels(&world, &trace);
            ccpp_io::warnings::warnings_with_start(None, &scenario, &world, &trace, &m, &swept)
        }
        // Metrics of another shape (checked above for the figures the replay reads).
        Err(_) => Vec::new(),
    };
    let (html, gif) = render_replay(
        &world,
        &trace,
        scenario.tile_side(),
        &metrics,
        &title,
        &warnings,
    )?;
    let replaced = || {
        anyhow::anyhow!(
            "{} was replaced by another run while its replay was made: nothing written; run ccpp replay again",
            dir.display()
        )
    };
    if folder_identity(dir) != identity {
        bail!(replaced());
    }
    // Only a folder ccpp wrote (its stamp, and no file of the user's): the replay's files go
    // into it. (Checked last: what is wrong with the run itself is said first.)
    match ccpp_io::write::check_run_folder_entries(dir) {
        Err(ccpp_io::write::FolderError::Foreign { name, .. }) => anyhow::bail!(
            "run folder {} holds {name}, which ccpp did not write; replay writes replay.html and replay.gif into it, so it must hold ccpp's files only",
            dir.display()
        ),
        Err(ccpp_io::write::FolderError::Unstamped { .. }) => anyhow::bail!(
            "{} has no {} stamp, so ccpp did not write it as a run folder (or an older ccpp did); replay writes replay.html and replay.gif only into a run folder ccpp wrote",
            dir.display(),
            ccpp_io::write::STAMP_FILE
        ),
        other => other?,
    }
    let files: [(&str, &[u8]); 2] = [("replay.html", html.as_bytes()), ("replay.gif", &gif)];
    // Both or neither: one by one, a failure or an interrupt between them left the page
    // without its GIF (or beside the GIF of an earlier replay).
    crate::staging::write_files_together(dir, &files)?;
    if folder_identity(dir) != identity {
        // Swapped while the files were renamed in (a few milliseconds): take back whatever of
        // this replay landed in the new run's folder.
        for (name, bytes) in files {
            let p = dir.join(name);
            if std::fs::read(&p).is_ok_and(|b| b == bytes) {
                // Best effort: the error below tells the user to replay again.
                let _ = std::fs::remove_file(&p);
            }
        }
        bail!(replaced());
    }
    crate::print_stdout(&format!(
        "wrote {}/{{replay.html, replay.gif}}\n",
        folder_shown(dir)
    ))
}

/// The identity of the folder at `dir` (device and inode): a folder swapped in under the same
/// name has another. `None` where it cannot be read (or off Unix, where the check is skipped).
fn folder_identity(dir: &Path) -> Option<(u64, u64)> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        std::fs::metadata(dir).ok().map(|m| (m.dev(), m.ino()))
    }
    #[cfg(not(unix))]
    {
        let _ = dir;
        None
    }
}

/// The figures of `metrics.json` that [`check_metrics_of_run`] computes again from the trace
/// (all but the planner's wall time, which no trace records and which must only be a time; the
/// stop reason is the one the trace's `finished` record gives).
const RECOMPUTED: [&str; 19] = [
    "robot_radius_m",
    "tool_radius_m",
    "coverage_rate",
    "effective_coverage",
    "path_length_m",
    "path_ratio",
    "redundancy",
    "revisit_rate",
    "regions",
    "backtracks",
    "backtrack_length_m",
    "turns",
    "rotation_rad",
    "collisions",
    "keepout_violations",
    "tracking_error_mean_m",
    "tracking_error_max_m",
    "rect_guarantee",
    "stop_reason",
];

/// Refuses a run folder whose `metrics.json` is not what the run of `run.json` (its robot,
/// map, zones and planner options such as the tile side) makes of `trace.jsonl`: the metrics are
/// computed again from the trace and compared figure by figure ([`RECOMPUTED`]). A `run.json`
/// copied in from another run on the same path (another tool radius, another tile side) passed
/// [`check_same_run`], and the page drew that run's swept floor beside this run's metrics (a
/// coverage curve ending at 0.771 beside an effective coverage of 0.907). `reported`: the
/// parsed `metrics.json` ([`check_same_run`]'s). Returns the trace.
fn check_metrics_of_run(
    dir: &Path,
    scenario: &Scenario,
    map_name: &str,
    world: &World,
    trace: Trace,
    reported: &serde_json::Map<String, serde_json::Value>,
) -> Result<Trace> {
    // The reason the trace's `finished` record gives (`check_same_run` made sure there is one).
    let stop = trace
        .events()
        .last()
        .and_then(|(_, e)| match e {
            ccpp_core::trace::Event::Finished { reason } => {
                ccpp_core::sim::StopReason::from_name(reason)
            }
            _ => None,
        })
        .with_context(|| {
            format!(
                "{}: trace.jsonl's `finished` record gives no stop reason the simulator writes",
                dir.display()
            )
        })?;
    let out = ccpp_core::sim::RunOutput {
        trace,
        stop,
        tile_side: scenario.tile_side(),
        planner: scenario.planner.name(),
        wall_time_s: 0.0,
    };
    let again = serde_json::to_value(ccpp_core::metrics::compute(world, &out, map_name))
        .context("metrics computed again from trace.jsonl")?;
    for key in RECOMPUTED {
        let (want, got) = (again.get(key), reported.get(key));
        let same = match (
            want.and_then(serde_json::Value::as_f64),
            got.and_then(serde_json::Value::as_f64),
        ) {
            // A word (the stop reason): the same word.
            _ if want.is_some_and(serde_json::Value::is_string)
                || got.is_some_and(serde_json::Value::is_string) =>
            {
                want == got
            }
            // Computed the same way from the same poses; the tolerance only allows for the
            // decimal round trip of the JSON numbers.
            (Some(a), Some(b)) => (a - b).abs() <= 1e-9 * (1.0 + a.abs()),
            (None, None) => {
                want.is_none_or(serde_json::Value::is_null)
                    && got.is_none_or(serde_json::Value::is_null)
            }
            _ => false,
        };
        if !same {
            bail!(
                "{}: metrics.json reports {key} {} but the run of run.json makes {} of \
                 trace.jsonl: the folder mixes files of two runs, a file was edited, or an \
                 older ccpp measured it otherwise (run it again)",
                dir.display(),
                got.map_or_else(|| "(none)".to_string(), ToString::to_string),
                want.map_or_else(|| "(none)".to_string(), ToString::to_string),
            );
        }
    }
    // The one figure no trace records: at least a time a run can have taken (a string there
    // was shown in the page's panel and pushed every other value out of view).
    let wall = reported.get("wall_time_s");
    if !wall
        .and_then(serde_json::Value::as_f64)
        .is_some_and(|t| t.is_finite() && t >= 0.0)
    {
        bail!(
            "{}: metrics.json reports wall_time_s {}, not a run's time (seconds, a finite \
             number >= 0): a file was edited",
            dir.display(),
            wall.map_or_else(|| "(none)".to_string(), ToString::to_string),
        );
    }
    Ok(out.trace)
}

/// Refuses a run folder whose files come from different runs (a trace or metrics copied in
/// from another run), which the replay would draw as one, or that is not a whole run: the
/// trace must hold a pose, end with the simulator's `finished` record, hold a `tracking`
/// record only where a run writes one ([`ccpp_core::metrics::tracking_record_problem`]: the
/// tracking error is read from it) and begin at the start pose of the run that `run.json`
/// describes; `metrics.json` must be a run's metrics, name
/// its planner and map, and report the path length the trace drives (the metrics are computed
/// from the same poses, so only another run's trace differs). Returns `metrics.json` parsed.
fn check_same_run(
    dir: &Path,
    scenario: &Scenario,
    map_name: &str,
    world: &World,
    trace: &Trace,
    metrics: &str,
) -> Result<serde_json::Map<String, serde_json::Value>> {
    // Where the robot was placed: the start, or the pose outside the area it drove in from.
    let start = world.initial_pose();
    let Some(first) = trace.poses().next() else {
        bail!(
            "{}: trace.jsonl holds no pose: not a finished run's trace",
            dir.display()
        );
    };
    if !matches!(
        trace.events().last(),
        Some((_, ccpp_core::trace::Event::Finished { .. }))
    ) {
        bail!(
            "{}: trace.jsonl does not end with the simulator's `finished` record: the trace is cut short",
            dir.display()
        );
    }
    // The tracking error is read from the trace's record: it must be one the simulator can
    // have written (a doctored record passed with a matching metrics.json).
    if let Some(problem) = ccpp_core::metrics::tracking_record_problem(trace) {
        bail!(
            "{}: trace.jsonl's tracking record is not a run's: {problem}",
            dir.display()
        );
    }
    // The trace records the start exactly; a thousandth of a pixel allows for nothing but
    // another run.
    let tol = world.frame().resolution * 1e-3;
    if (first.x - start.x).abs() > tol || (first.y - start.y).abs() > tol {
        bail!(
            "{}: trace.jsonl starts at ({:.3}, {:.3}) but the run of run.json starts at \
             ({:.3}, {:.3}): the folder mixes files of two runs",
            dir.display(),
            first.x,
            first.y,
            start.x,
            start.y
        );
    }
    let Ok(serde_json::Value::Object(m)) = serde_json::from_str::<serde_json::Value>(metrics)
    else {
        bail!(
            "{}: metrics.json is not a run's metrics (not a JSON object)",
            dir.display()
        );
    };
    let planner = scenario.planner.name();
    for (key, want) in [("planner", planner), ("map", map_name)] {
        let got = m.get(key).and_then(serde_json::Value::as_str);
        if got != Some(want) {
            bail!(
                "{}: metrics.json is of {key} {} but run.json of {key} {want}: the \
                 folder mixes files of two runs",
                dir.display(),
                got.unwrap_or("(none)")
            );
        }
    }
    let Some(reported) = m.get("path_length_m").and_then(serde_json::Value::as_f64) else {
        bail!(
            "{}: metrics.json is not a run's metrics (no path_length_m)",
            dir.display()
        );
    };
    if let Some(why) = length_mismatch(trace, reported) {
        bail!(
            "{}: {why}: the folder mixes files of two runs",
            dir.display()
        );
    }
    Ok(m)
}

/// The trace's path length against the `reported` one of a `metrics.json`, `None` when they
/// agree (to 1e-9, relative): replay and a bench's reuse of a run folder both check it.
pub fn length_mismatch(trace: &Trace, reported: f64) -> Option<String> {
    // Summed in the trace's order, as the metrics sum it.
    let positions: Vec<ccpp_core::geometry::Point> = trace.poses().map(|p| p.position()).collect();
    let driven = ccpp_core::geometry::path_length(&positions);
    ((driven - reported).abs() > 1e-9 + 1e-9 * reported.abs()).then(|| {
        format!("trace.jsonl drives {driven:.3} m but metrics.json reports {reported:.3} m")
    })
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
    let busy = crate::busy::Busy::start(format!(
        "{} on {}: writing files",
        r.metrics.planner, r.metrics.map
    ));
    let export_files = ccpp_render::run_files::render_export_files(
        &job.scenario,
        &r.run.trace,
        &r.metrics,
        exports,
        &ccpp_io::export::zone_features(r.world.zones(), r.world.frame()),
    )?;
    // The start's free area (a flood fill over the map; `run` finds it while the planner
    // works) and the run's warnings, before the files: `coverage.png` shows them.
    let comp = r
        .start_area
        .unwrap_or_else(|| StartComponent::of_world(&r.world));
    let warnings = ccpp_io::warnings::warnings_with_start(
        Some(comp),
        &job.scenario,
        &r.world,
        &r.run.trace,
        &r.metrics,
        &r.swept,
    );
    let metrics = write_run_files(&job.out, job, r, replay, &export_files, &warnings, None);
    busy.done();
    let metrics = metrics?;
    // Every warning on stderr, with or without --json (the early stop's was a line of the
    // table on stdout without it), as Python's `RunResult.warnings` lists them.
    for w in &warnings {
        say!("warning: {w}");
    }
    if json_only {
        return crate::print_stdout(&metrics);
    }
    let mut s = summary(&r.metrics);
    let _ = writeln!(s, "  start area: {}", comp.line());
    if let Some(m) = job.scenario.map.inflation() {
        // The figures above are on the grown map, not the map as drawn: said where they are
        // read (with 0.3 m, teb_empty_box's coverage rose from 0.907 to 0.973 while the floor
        // swept of the drawn map fell by a tenth).
        let _ = writeln!(s, "{}", inflated_line(m));
    }
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
        folder_shown(&job.out)
    );
    crate::print_stdout(&s)
}

/// A folder as the `wrote DIR/{...}` lines print it: without the separators it was given
/// with at its end (`--out runs/` printed `wrote runs//{...}`; the root folder prints as
/// nothing before the `/`), and with the characters a terminal acts on or hides (a
/// right-to-left override reversed the rest of the line) written as `\u{..}`, as on stderr
/// ([`ccpp_io::message::visible`]).
pub fn folder_shown(dir: &Path) -> String {
    let s = dir.display().to_string();
    ccpp_io::message::visible(s.trim_end_matches(std::path::MAIN_SEPARATOR))
}

/// The summary's line of a run on a map grown by `--inflate` `m` metres.
pub fn inflated_line(m: f64) -> String {
    format!(
        "  inflated: obstacles grown by {} m (--inflate); every figure is on the grown map (the floor within {} m of an obstacle is not counted, and touching it is a collision)",
        num(m),
        num(m)
    )
}

/// A user-given number as `{}` prints it (`0.15`, `50000000`), but in exponent form (`1e-300`)
/// below 1e-4 and from 1e9 up, where `{}` would print a line of hundreds of digits.
pub fn num(v: f64) -> String {
    if v == 0.0 {
        // (a YAML's `origin: [-0.0, ...]` printed `-0`)
        return "0".to_string();
    }
    if v.abs() < 1e-4 || v.abs() >= 1e9 {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// A number a fit computed (a `--georef` map's resolution and origin), as [`num`] prints it
/// after rounding to 12 significant digits, and 0 within `zero` of it: the fit's rounding
/// showed as `0.049999999999999996 m/px` and an origin of `7.00e-17` (hostile pass).
pub fn fitted(v: f64, zero: f64) -> String {
    if v.abs() <= zero {
        return "0".to_string();
    }
    num(format!("{v:.11e}").parse().unwrap_or(v))
}

/// `n` and its noun: `1 map`, `2 maps`.
pub fn count(n: usize, one: &str, many: &str) -> String {
    if n == 1 {
        format!("{n} {one}")
    } else {
        format!("{n} {many}")
    }
}

/// A short human table of the metrics: every key of `metrics.json` but the header's (planner,
/// map, radii), the optional ones (`tracking_error_*`, `rect_guarantee`, `stop_reason`) when
/// the run has them.
pub fn summary(m: &Metrics) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{} on {} (r = {} m, tool r = {} m)",
        m.planner,
        m.map,
        num(m.robot_radius_m),
        num(m.tool_radius_m)
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
    // The optional metrics, when present (null keys are left out of metrics.json).
    let optional = [
        ("tracking_error_mean_m", m.tracking_error_mean_m, 4),
        ("tracking_error_max_m", m.tracking_error_max_m, 4),
        ("rect_guarantee", m.rect_guarantee, 4),
    ];
    let optional = optional
        .into_iter()
        .filter_map(|(k, v, digits)| v.map(|v| (k, format!("{v:.digits$}"))));
    for (k, v) in rows.into_iter().chain(optional) {
        let _ = writeln!(s, "  {k:<21} {v:>12}");
    }
    if let Some(why) = &m.stop_reason {
        let _ = writeln!(s, "  {:<21} {why:>12}", "stop_reason");
    }
    s
}
