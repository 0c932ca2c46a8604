//! The files of a finished run — `run.json`, `path.csv`, `trace.jsonl`, `coverage.png`,
//! `metrics.json` — written the same way by the command line (`ccpp run`, `ccpp bench`) and the
//! Python package (`Result.save`).

use std::io::Write;
use std::path::Path;

use ccpp_core::metrics::Metrics;
use ccpp_core::route::{Route, DEFAULT_TOLERANCE_M};
use ccpp_core::trace::Trace;
use ccpp_core::world::World;
use ccpp_io::export::{render_exports, ExportFormat, ExportMeta, PolygonFeature};
use ccpp_io::phase;
use ccpp_io::scenario::Scenario;
use ccpp_io::trace::FormedFiles;
use ccpp_io::write::WriteError;

use crate::{coverage_png, coverage_png_swept, CoverageStyle, RenderError};

/// Failure writing a run's files.
#[derive(Debug, thiserror::Error)]
pub enum RunFilesError {
    /// Serializing the metrics, scenario or trace failed.
    #[error("cannot serialize the run: {0}")]
    Json(#[from] serde_json::Error),
    /// The coverage picture failed.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The output folder cannot be created.
    #[error("cannot create output folder {}: {source}", path.display())]
    Folder {
        /// The folder.
        path: std::path::PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A file cannot be written.
    #[error(transparent)]
    Write(#[from] WriteError),
    /// The output folder cannot be replaced (see [`ccpp_io::write::write_folder`]).
    #[error(transparent)]
    Output(#[from] ccpp_io::write::FolderError),
}

/// The metrics as pretty JSON (`metrics.json`).
///
/// # Errors
/// Serialization failure.
pub fn metrics_json(m: &Metrics) -> Result<String, serde_json::Error> {
    let mut s = serde_json::to_string_pretty(m)?;
    s.push('\n');
    Ok(s)
}

/// Title lines of the coverage picture.
pub fn title_lines(m: &Metrics) -> Vec<String> {
    let cov = m
        .coverage_rate
        .map_or_else(|| "-".to_string(), crate::percent);
    vec![
        format!(
            "{} on {}  r={} m  tool={} m",
            m.planner, m.map, m.robot_radius_m, m.tool_radius_m
        ),
        format!(
            "effective coverage {}  tiles {}  path {:.1} m  ratio {:.2}",
            crate::percent(m.effective_coverage),
            cov,
            m.path_length_m,
            m.path_ratio,
        ),
        format!(
            "regions {}  revisits {:.2}  turns {}  collisions {}",
            m.regions, m.revisit_rate, m.turns, m.collisions
        ),
    ]
}

/// `run.json`: `scenario` with the start actually used (the world's initial pose, before any
/// approach into the work area) and the digest of the map and zones it ran on.
///
/// # Errors
/// A scenario that does not serialise (a non-finite number).
pub fn run_json(scenario: &Scenario, world: &World) -> Result<String, serde_json::Error> {
    let mut scenario = scenario.clone();
    let start = world.initial_pose();
    scenario.start = Some([start.x, start.y, start.theta]);
    scenario.map_digest = Some(format!("{:016x}", world.digest()));
    scenario.to_json()
}

/// The style of a run's `coverage.png`.
fn coverage_style(metrics: &Metrics, warnings: &[String]) -> CoverageStyle {
    CoverageStyle {
        title: title_lines(metrics),
        warnings: warnings.to_vec(),
        ..CoverageStyle::default()
    }
}

/// Renders a run's standard files in memory, in writing order: `run.json`, `path.csv`,
/// `trace.jsonl`, `coverage.png`, `metrics.json` (last: its presence marks a complete run).
/// `warnings` are the run's warnings (as `ccpp run` prints them), shown in `coverage.png`.
/// `run.json` is `scenario` with the start actually used (the world's), so that
/// [`Scenario::run`] on it reproduces the run. The command line adds its replay files before
/// `metrics.json` and writes the set through its own staging folder; [`write_run_files`]
/// through [`ccpp_io::write::write_folder`].
///
/// # Errors
/// Serialization or rendering failures.
pub fn render_run_files(
    scenario: &Scenario,
    world: &World,
    trace: &Trace,
    metrics: &Metrics,
    warnings: &[String],
) -> Result<Vec<(&'static str, Vec<u8>)>, RunFilesError> {
    render_run_files_swept(scenario, world, trace, metrics, None, warnings)
}

/// [`render_run_files`] reusing the swept pixels when given (they must be
/// [`ccpp_core::metrics::swept_pixels`]`(world, trace)`, as [`ccpp_io::scenario::Run::swept`]
/// holds them): the same bytes, without sweeping the trace a second time for the picture.
///
/// # Errors
/// Serialization or rendering failures.
pub fn render_run_files_swept(
    scenario: &Scenario,
    world: &World,
    trace: &Trace,
    metrics: &Metrics,
    swept: Option<&fixedbitset::FixedBitSet>,
    warnings: &[String],
) -> Result<Vec<(&'static str, Vec<u8>)>, RunFilesError> {
    let metrics_text = metrics_json(metrics)?;
    let run_json = run_json(scenario, world)?;
    let style = coverage_style(metrics, warnings);
    // The picture and the text files are independent pure functions of (world, trace): draw
    // the picture on a second thread while this one writes the text (same bytes either way).
    let (png, text) = std::thread::scope(|s| {
        let png = s.spawn(|| coverage_picture(world, trace, &style, swept));
        let text = phase::time("trace.jsonl", || ccpp_io::trace::trace_jsonl(trace)).map(|t| {
            let path = phase::time("path.csv", || ccpp_io::trace::path_csv(trace));
            (t, path)
        });
        let png = match png.join() {
            Ok(png) => png,
            Err(panic) => std::panic::resume_unwind(panic),
        };
        (png, text)
    });
    let (trace_text, path) = text?;
    let png = png?;
    Ok(vec![
        ("run.json", run_json.into_bytes()),
        ("path.csv", path.into_bytes()),
        ("trace.jsonl", trace_text.into_bytes()),
        ("coverage.png", png),
        ("metrics.json", metrics_text.into_bytes()),
    ])
}

/// `coverage.png` (timed as its phase), from `swept` when the caller has the swept pixels.
fn coverage_picture(
    world: &World,
    trace: &Trace,
    style: &CoverageStyle,
    swept: Option<&fixedbitset::FixedBitSet>,
) -> Result<Vec<u8>, RenderError> {
    phase::time("coverage.png", || match swept {
        Some(swept) => coverage_png_swept(world, trace, style, swept),
        None => coverage_png(world, trace, style),
    })
}

/// What the caller of [`stream_run_files`] already has of a run's files.
#[derive(Clone, Copy, Debug, Default)]
pub struct KnownParts<'a> {
    /// The swept pixels ([`ccpp_core::metrics::swept_pixels`] of the run), when computed.
    pub swept: Option<&'a fixedbitset::FixedBitSet>,
    /// The `path.csv` formed while the run went on, when formed.
    pub formed: Option<&'a FormedFiles>,
    /// The run's warnings, shown in `coverage.png`.
    pub warnings: &'a [String],
}

/// What [`stream_run_files`] writes each file with: `put(name, fill)` creates the file `name`
/// and calls `fill` with a writer into it (the command line puts the files in its staging
/// folder).
pub type PutFile<'a, E> = dyn FnMut(&'static str, &mut dyn FnMut(&mut dyn Write) -> std::io::Result<()>) -> Result<(), E>
    + 'a;

/// The files of [`render_run_files`] but `metrics.json` — `run.json`, `path.csv`,
/// `trace.jsonl`, `coverage.png`, in that order — handed to `put` one by one, with
/// `trace.jsonl` streamed as it is formed instead of built whole in memory (the largest file;
/// `coverage.png` is drawn on a second thread meanwhile). Same bytes as
/// [`render_run_files`]. `known.swept`, when given, must be
/// [`ccpp_core::metrics::swept_pixels`]`(world, trace)`; `known.formed`, when given, the `path.csv` of
/// the trace formed while it ran ([`ccpp_io::scenario::Scenario::run_owned_with`]), written as
/// it is.
///
/// # Errors
/// Serialization or rendering failures (converted into `E`), or what `put` returns.
pub fn stream_run_files<E: From<RunFilesError>>(
    scenario: &Scenario,
    world: &World,
    trace: &Trace,
    metrics: &Metrics,
    known: &KnownParts<'_>,
    put: &mut PutFile<'_, E>,
) -> Result<(), E> {
    let KnownParts {
        swept,
        formed,
        warnings,
    } = *known;
    let run_json = run_json(scenario, world).map_err(RunFilesError::from)?;
    let style = coverage_style(metrics, warnings);
    std::thread::scope(|s| {
        let png = s.spawn(|| coverage_picture(world, trace, &style, swept));
        let text = (|| -> Result<(), E> {
            put("run.json", &mut |w| w.write_all(run_json.as_bytes()))?;
            if let Some(f) = formed {
                put("path.csv", &mut |w| w.write_all(f.path_csv.as_bytes()))?;
            } else {
                let path = phase::time("path.csv", || ccpp_io::trace::path_csv(trace));
                put("path.csv", &mut |w| w.write_all(path.as_bytes()))?;
            }
            phase::time("trace.jsonl", || {
                put("trace.jsonl", &mut |w| {
                    ccpp_io::trace::write_trace_jsonl(trace, w).map_err(std::io::Error::other)
                })
            })
        })();
        let png = match png.join() {
            Ok(png) => png,
            Err(panic) => std::panic::resume_unwind(panic),
        };
        text?;
        let png = png.map_err(RunFilesError::from)?;
        put("coverage.png", &mut |w| w.write_all(&png))
    })
}

/// Renders the path exports of a finished run in memory ([`ccpp_io::export`]): the route of the
/// executed trace (merged with [`DEFAULT_TOLERANCE_M`]) in each of `formats`, `(file name,
/// bytes)` in [`ExportFormat::ALL`] order; the `GeoJSON` carries the metrics and `polygons`
/// (zones, in map coordinates). Nothing is written; the command line stages these files with
/// the others.
///
/// # Errors
/// Serialization failure.
pub fn render_export_files(
    scenario: &Scenario,
    trace: &Trace,
    metrics: &Metrics,
    formats: &[ExportFormat],
    polygons: &[PolygonFeature],
) -> Result<Vec<(&'static str, Vec<u8>)>, RunFilesError> {
    if formats.is_empty() {
        return Ok(Vec::new());
    }
    let route = Route::from_trace(trace, DEFAULT_TOLERANCE_M);
    let meta = ExportMeta {
        planner: &metrics.planner,
        map: &metrics.map,
        robot: scenario.robot,
        footprint: ccpp_io::export::Footprint::of(&scenario.planner, &scenario.robot),
        tolerance_m: DEFAULT_TOLERANCE_M,
        metrics: Some(metrics),
    };
    Ok(render_exports(&route, &meta, formats, polygons)?)
}

/// Renders everything first ([`render_run_files`]), then writes the files and `extra` (path
/// exports) as the whole content of the folder `out`, all or nothing
/// ([`ccpp_io::write::write_folder`]): `out` must be absent or hold only run files, and the
/// older set in it is replaced whole, never mixed with the new one. Returns the metrics JSON.
///
/// # Errors
/// Serialization, rendering or writing failures; an `out` holding other files.
pub fn write_run_files(
    out: &Path,
    scenario: &Scenario,
    world: &World,
    trace: &Trace,
    metrics: &Metrics,
    warnings: &[String],
    extra: &[(&'static str, Vec<u8>)],
) -> Result<String, RunFilesError> {
    let mut files = render_run_files(scenario, world, trace, metrics, warnings)?;
    files.extend(extra.iter().cloned());
    let metrics_text = files
        .iter()
        .find(|(n, _)| *n == "metrics.json")
        .map(|(_, b)| String::from_utf8_lossy(b).into_owned())
        .unwrap_or_default();
    ccpp_io::write::write_folder(out, &files)?;
    Ok(metrics_text)
}
