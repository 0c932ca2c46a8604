//! Bench plots: coverage over travelled distance per map, summary bars, paths side by side,
//! effective coverage against path ratio per map and in summary. Every plot is written as SVG
//! and PNG from one chart description, each file atomically.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use ccpp_core::metrics::{coverage_curve, swept_pixels, Metrics};
use ccpp_core::trace::Trace;
use ccpp_core::world::{Robot, World};
use ccpp_core::Pose;
use ccpp_render::chart::{
    bar_panels, image_grid_captioned, line_chart, tradeoff_chart, Chart, Panel,
};
use ccpp_render::{
    coverage_png_swept, coverage_verdict_colour, legend_entries_union_of, CoverageStyle,
    LegendShown,
};
use rayon::prelude::*;

use crate::job::PreparedMap;
use crate::row::Row;
use crate::staging::write_file;

/// Reads a run's `trace.jsonl` back as `ccpp replay` does ([`ccpp_io::trace::read_run_trace`]:
/// every pose on the map of `frame`, for a robot of radius `radius`).
pub fn read_trace(path: &Path, frame: &ccpp_core::grid::MapFrame, radius: f64) -> Result<Trace> {
    Ok(ccpp_io::trace::read_run_trace(path, frame, radius)?)
}

fn write_chart(dir: &Path, stem: &str, chart: &Chart) -> Result<()> {
    // Through the command line's writer: its `.tmp` goes on interrupt, and the test hook of a
    // full disk reaches the plots.
    write_file(&dir.join(format!("{stem}.svg")), chart.to_svg().as_bytes())?;
    write_file(&dir.join(format!("{stem}.png")), &chart.to_png()?)?;
    Ok(())
}

/// Writes every plot into `out/plots/`. Returns one `warning:` line per run (or map) left
/// out of its map's plots, saying why, in the maps' order (the caller prints them: nothing
/// vanishes from the plots in silence).
pub fn write_all(
    out: &Path,
    rows: &[Row],
    maps: &[(PathBuf, Result<PreparedMap, String>)],
    robot: Robot,
    budget: &crate::budget::MemoryBudget,
) -> Result<Vec<String>> {
    let dir = out.join("plots");
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let mut planners: Vec<String> = Vec::new();
    for r in rows {
        if !planners.contains(&r.planner) {
            planners.push(r.planner.clone());
        }
    }
    // What was left out of the plots, and why: printed after them, in the maps' order.
    let skipped: Vec<Vec<String>> = maps
        .par_iter()
        .map(|(_, m)| -> Result<Vec<String>> {
            let mut skipped = Vec::new();
            let Ok(m) = m else { return Ok(skipped) };
            // A map's pictures hold its world and one run's trace at a time: under the bench's
            // memory limit with the other maps' (drawn all at once, four PID traces of
            // `office_1024` peaked at 840 MB under `--max-memory 341`). A parsed trace takes about
            // twice its file's size.
            let largest_trace = rows
                .iter()
                .filter(|r| r.map == m.name)
                .filter_map(|r| std::fs::metadata(r.dir.join("trace.jsonl")).ok())
                .map(|md| md.len())
                .max()
                .unwrap_or(0);
            let pixels = (m.grid.frame().width * m.grid.frame().height) as f64;
            let _grant = budget.take(
                2.0 * largest_trace as f64 + pixels * ccpp_core::planners::settings::PIXEL_BYTES,
            );
            let world = match World::new(m.grid.clone(), robot, None) {
                Ok(w) => w,
                Err(e) => {
                    skipped.push(format!(
                        "warning: no plots of map {}: its world cannot be built ({e})",
                        m.name
                    ));
                    return Ok(skipped);
                }
            };
            // Planners whose run on this map failed: named in the map's titles (their panel,
            // curve and point are missing, and the pictures said nothing of it).
            let failed: Vec<&str> = rows
                .iter()
                .filter(|r| r.map == m.name && r.outcome.is_err())
                .map(|r| r.planner.as_str())
                .collect();
            let title = |what: &str| {
                if failed.is_empty() {
                    format!("{what} - {}", m.name)
                } else {
                    format!(
                        "{what} - {} (failed: {}; see results.md)",
                        m.name,
                        failed.join(", ")
                    )
                }
            };
            let mut series = Vec::new();
            let mut panels = Vec::new();
            // What each drawn run's picture shows, for the shared legend (its trace and world are
            // dropped once drawn: a map holds one trace at a time).
            let mut shown: Vec<LegendShown> = Vec::new();
            for r in rows.iter().filter(|r| r.map == m.name) {
                let Ok(metrics) = &r.outcome else { continue };
                let trace =
                    match read_trace(&r.dir.join("trace.jsonl"), m.grid.frame(), robot.radius) {
                        Ok(t) => t,
                        Err(e) => {
                            skipped.push(left_out(r, &crate::errors::one_line(&e)));
                            continue;
                        }
                    };
                series.push((r.planner.clone(), coverage_curve(&world, &trace, 200)));
                // The panel: the run's picture without header or legend (one shared legend and
                // legible captions instead), drawn from the run's own start pose.
                // A run from the default start (as bench runs are) is drawn on the map's world.
                let start = trace.poses().next().map(|p| Pose::new(p.x, p.y, p.theta));
                let own = if start == Some(world.start()) {
                    None
                } else {
                    match World::new(m.grid.clone(), robot, start) {
                        Ok(w) => Some(w),
                        Err(e) => {
                            skipped
                                .push(left_out(r, &format!("its start pose gives no world ({e})")));
                            continue;
                        }
                    }
                };
                let run_world = own.as_ref().unwrap_or(&world);
                let swept = swept_pixels(run_world, &trace);
                let style = CoverageStyle {
                    min_width: 500,
                    max_side: 1000,
                    title: Vec::new(),
                    legend: false,
                    warnings: Vec::new(),
                };
                let png = match coverage_png_swept(run_world, &trace, &style, &swept) {
                    Ok(png) => png,
                    Err(e) => {
                        // Its coverage curve is drawn; its panel is not.
                        skipped.push(format!(
                            "warning: {}: left out of paths_{}: its picture cannot be drawn ({e})",
                            r.dir.display(),
                            m.name
                        ));
                        continue;
                    }
                };
                panels.push(Panel {
                    label: r.planner.clone(),
                    badge: Some((
                        format!(
                            "effective coverage {}",
                            ccpp_render::percent(metrics.effective_coverage)
                        ),
                        coverage_verdict_colour(metrics.effective_coverage),
                    )),
                    caption: [
                        format!(
                            "path {:.1} m, ratio {:.2}, revisits {:.2}",
                            metrics.path_length_m, metrics.path_ratio, metrics.revisit_rate
                        ),
                        format!(
                            "regions {}, turns {}, collisions {}",
                            metrics.regions, metrics.turns, metrics.collisions
                        ),
                    ]
                    .into_iter()
                    .chain(warning_caption(&r.warnings))
                    .collect(),
                    png,
                });
                shown.push(LegendShown::of(run_world, &trace, &swept));
            }
            let points = tradeoff_points(rows, &planners, &m.name);
            if points.iter().any(Option::is_some) {
                // A run with warnings is named so beside its point (its figures may be of
                // less than the user meant: a start outside the building, a robot boxed in).
                let labels: Vec<String> = planners
                    .iter()
                    .map(|p| {
                        let warned = rows
                            .iter()
                            .any(|r| r.map == m.name && &r.planner == p && !r.warnings.is_empty());
                        if warned {
                            format!("{p} (warned)")
                        } else {
                            p.clone()
                        }
                    })
                    .collect();
                let c =
                    tradeoff_chart(&title("Coverage against path ratio"), &labels, &points, &[]);
                write_chart(&dir, &format!("tradeoff_{}", m.name), &c)?;
            }
            if !series.is_empty() {
                let c = line_chart(
                    &title("Effective coverage over travelled distance"),
                    "travelled distance (m)",
                    "effective coverage",
                    &series,
                    Some(1.0),
                );
                write_chart(&dir, &format!("coverage_{}", m.name), &c)?;
            }
            if !panels.is_empty() {
                let legend = legend_entries_union_of(&shown);
                let c = image_grid_captioned(&title("Paths"), &panels, &legend, 3, 520, 420);
                write_chart(&dir, &format!("paths_{}", m.name), &c)?;
            }
            Ok(skipped)
        })
        .collect::<Result<_>>()?;

    // Summary bars: means over maps.
    let mean = |p: &str, f: fn(&Metrics) -> f64| {
        let v: Vec<f64> = rows
            .iter()
            .filter(|r| r.planner == p)
            .filter_map(|r| r.outcome.as_ref().ok())
            .map(f)
            .collect();
        if v.is_empty() {
            f64::NAN
        } else {
            v.iter().sum::<f64>() / v.len() as f64
        }
    };
    let metrics: Vec<(String, Vec<f64>)> = vec![
        (
            "effective coverage".into(),
            planners
                .iter()
                .map(|p| mean(p, |m| m.effective_coverage))
                .collect(),
        ),
        (
            "path ratio".into(),
            planners.iter().map(|p| mean(p, |m| m.path_ratio)).collect(),
        ),
        (
            "revisit rate".into(),
            planners
                .iter()
                .map(|p| mean(p, |m| m.revisit_rate))
                .collect(),
        ),
        (
            "regions".into(),
            planners
                .iter()
                .map(|p| mean(p, |m| f64::from(m.regions)))
                .collect(),
        ),
        (
            "turns".into(),
            planners
                .iter()
                .map(|p| mean(p, |m| f64::from(m.turns)))
                .collect(),
        ),
        (
            "wall time (s, mean a map)".into(),
            planners
                .iter()
                .map(|p| mean(p, |m| m.wall_time_s))
                .collect(),
        ),
    ];
    // A planner whose runs failed on maps where others ran is averaged over fewer maps than
    // they are: its label says over how many (its bar and point stood beside means over more
    // maps, unmarked). A map no planner ran on counts for none.
    let mut ran_maps: Vec<&str> = rows
        .iter()
        .filter(|r| r.outcome.is_ok())
        .map(|r| r.map.as_str())
        .collect();
    ran_maps.sort_unstable();
    ran_maps.dedup();
    let labels: Vec<String> = planners
        .iter()
        .map(|p| {
            let ok = rows
                .iter()
                .filter(|r| &r.planner == p && r.outcome.is_ok())
                .count();
            let warned = rows
                .iter()
                .filter(|r| &r.planner == p && r.outcome.is_ok() && !r.warnings.is_empty())
                .count();
            let mut notes = Vec::new();
            if ok < ran_maps.len() {
                notes.push(format!("{ok} of {} maps", ran_maps.len()));
            }
            if warned > 0 {
                notes.push(format!(
                    "warned on {warned} map{}",
                    if warned == 1 { "" } else { "s" }
                ));
            }
            if notes.is_empty() {
                p.clone()
            } else {
                format!("{p} ({})", notes.join(", "))
            }
        })
        .collect();
    let c = bar_panels("Summary (mean over maps)", &labels, &metrics);
    write_chart(&dir, "summary", &c)?;
    // Trade-off summary: each planner at its means, its per-map points faint behind.
    let means: Vec<Option<[f64; 2]>> = planners
        .iter()
        .map(|p| {
            let pt = [mean(p, |m| m.path_ratio), mean(p, |m| m.effective_coverage)];
            pt.iter().all(|v| v.is_finite()).then_some(pt)
        })
        .collect();
    let per_map: Vec<Vec<[f64; 2]>> = planners
        .iter()
        .map(|p| {
            rows.iter()
                .filter(|r| &r.planner == p)
                .filter_map(|r| r.outcome.as_ref().ok())
                .map(|m| [m.path_ratio, m.effective_coverage])
                .collect()
        })
        .collect();
    if means.iter().any(Option::is_some) {
        let c = tradeoff_chart(
            "Coverage against path ratio (mean over maps)",
            &labels,
            &means,
            &per_map,
        );
        write_chart(&dir, "tradeoff_summary", &c)?;
    }
    Ok(skipped.into_iter().flatten().collect())
}

/// Most characters of a run's first warning in its panel's caption.
const CAPTION_WARNING_CHARS: usize = 64;

/// The caption line of a run's warnings in its map's `paths_` panel: their count and the
/// first, cut to [`CAPTION_WARNING_CHARS`] (the whole text is in `results.md` and the run's
/// `warnings.txt`); none without warnings. The panels showed a warned run as any other.
fn warning_caption(warnings: &[String]) -> Option<String> {
    let first = warnings.first()?;
    let mut text: String = first.chars().take(CAPTION_WARNING_CHARS).collect();
    if first.chars().count() > CAPTION_WARNING_CHARS {
        text.push_str("...");
    }
    let n = warnings.len();
    Some(format!(
        "{n} warning{}: {text}",
        if n == 1 { "" } else { "s" }
    ))
}

/// The warning for a run left out of its map's plots (`why` says why).
fn left_out(r: &Row, why: &str) -> String {
    format!(
        "warning: {}: left out of the plots of map {}: {why}",
        r.dir.display(),
        r.map
    )
}

/// Each planner's `[path_ratio, effective_coverage]` on `map` (`None`: no successful run).
fn tradeoff_points(rows: &[Row], planners: &[String], map: &str) -> Vec<Option<[f64; 2]>> {
    planners
        .iter()
        .map(|p| {
            rows.iter()
                .find(|r| r.map == map && &r.planner == p)
                .and_then(|r| r.outcome.as_ref().ok())
                .map(|m| [m.path_ratio, m.effective_coverage])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// A run whose trace does not read back (or whose picture cannot be drawn) is left out of
    /// its map's plots with a `warning:` line naming its folder and why; it was left out in
    /// silence.
    #[test]
    fn a_run_left_out_of_the_plots_is_named() {
        let out = tempfile::tempdir().unwrap();
        let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/teb_empty_box.yaml");
        let args = crate::args::MapArgs {
            map: data.clone(),
            ..crate::args::MapArgs::default()
        };
        let mut map = crate::job::prepare_map(&args, 1024).unwrap();
        map.name = "box".into();
        let metrics: Metrics = serde_json::from_str(
            r#"{"planner": "bsa", "map": "box", "robot_radius_m": 0.15, "tool_radius_m": 0.15,
            "coverage_rate": 1.0, "effective_coverage": 0.8, "path_length_m": 2.0,
            "path_ratio": 0.9, "redundancy": 0.1, "revisit_rate": 0.1, "regions": 1,
            "backtracks": 0, "backtrack_length_m": 0.0, "turns": 1, "rotation_rad": 1.0,
            "collisions": 0, "keepout_violations": 0, "wall_time_s": 0.001}"#,
        )
        .unwrap();
        let dir = out.path().join("runs/box/bsa");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("trace.jsonl"), "{\"t\":0,\"pose\":[1.0,").unwrap();
        let rows = [Row {
            map: "box".into(),
            planner: "bsa".into(),
            outcome: Ok(metrics),
            warnings: Vec::new(),
            dir: dir.clone(),
        }];
        let maps = [(data, Ok(map))];
        let budget = crate::budget::MemoryBudget::new(1024);
        let warnings = write_all(out.path(), &rows, &maps, Robot::new(0.15), &budget).unwrap();
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        let w = &warnings[0];
        assert!(w.starts_with("warning: "), "{w}");
        assert!(w.contains(&dir.display().to_string()), "{w}");
        assert!(w.contains("left out of the plots of map box"), "{w}");
        assert!(w.contains("not a trace record"), "{w}");
        assert!(!w.contains('\n'), "{w}");
    }
}
