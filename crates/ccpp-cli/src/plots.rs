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

/// Reads a `trace.jsonl` back (the checked codec of `ccpp_io::trace`).
pub fn read_trace(path: &Path) -> Result<Trace> {
    Ok(ccpp_io::trace::read_trace(path, None)?)
}

fn write_chart(dir: &Path, stem: &str, chart: &Chart) -> Result<()> {
    // Through the command line's writer: its `.tmp` goes on interrupt, and the test hook of a
    // full disk reaches the plots.
    write_file(&dir.join(format!("{stem}.svg")), chart.to_svg().as_bytes())?;
    write_file(&dir.join(format!("{stem}.png")), &chart.to_png()?)?;
    Ok(())
}

/// Writes every plot into `out/plots/`.
pub fn write_all(
    out: &Path,
    rows: &[Row],
    maps: &[(PathBuf, Result<PreparedMap, String>)],
    robot: Robot,
    budget: &crate::bench::MemoryBudget,
) -> Result<()> {
    let dir = out.join("plots");
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let mut planners: Vec<String> = Vec::new();
    for r in rows {
        if !planners.contains(&r.planner) {
            planners.push(r.planner.clone());
        }
    }
    maps.par_iter().try_for_each(|(_, m)| -> Result<()> {
        let Ok(m) = m else { return Ok(()) };
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
        let _grant = budget
            .take(2.0 * largest_trace as f64 + pixels * ccpp_core::planners::settings::PIXEL_BYTES);
        let Ok(world) = World::new(m.grid.clone(), robot, None) else {
            return Ok(());
        };
        let mut series = Vec::new();
        let mut panels = Vec::new();
        // What each drawn run's picture shows, for the shared legend (its trace and world are
        // dropped once drawn: a map holds one trace at a time).
        let mut shown: Vec<LegendShown> = Vec::new();
        for r in rows.iter().filter(|r| r.map == m.name) {
            let Ok(metrics) = &r.outcome else { continue };
            let Ok(trace) = read_trace(&r.dir.join("trace.jsonl")) else {
                continue;
            };
            series.push((r.planner.clone(), coverage_curve(&world, &trace, 200)));
            // The panel: the run's picture without header or legend (one shared legend and
            // legible captions instead), drawn from the run's own start pose.
            // A run from the default start (as bench runs are) is drawn on the map's world.
            let start = trace.poses().next().map(|p| Pose::new(p.x, p.y, p.theta));
            let own = if start == Some(world.start()) {
                None
            } else {
                let Ok(w) = World::new(m.grid.clone(), robot, start) else {
                    continue;
                };
                Some(w)
            };
            let run_world = own.as_ref().unwrap_or(&world);
            let swept = swept_pixels(run_world, &trace);
            let style = CoverageStyle {
                min_width: 500,
                max_side: 1000,
                title: Vec::new(),
                legend: false,
            };
            let Ok(png) = coverage_png_swept(run_world, &trace, &style, &swept) else {
                continue;
            };
            panels.push(Panel {
                label: r.planner.clone(),
                badge: Some((
                    format!(
                        "effective coverage {:.1}%",
                        100.0 * metrics.effective_coverage
                    ),
                    coverage_verdict_colour(metrics.effective_coverage),
                )),
                caption: vec![
                    format!(
                        "path {:.1} m, ratio {:.2}, revisits {:.2}",
                        metrics.path_length_m, metrics.path_ratio, metrics.revisit_rate
                    ),
                    format!(
                        "regions {}, turns {}, collisions {}",
                        metrics.regions, metrics.turns, metrics.collisions
                    ),
                ],
                png,
            });
            shown.push(LegendShown::of(run_world, &trace, &swept));
        }
        let points = tradeoff_points(rows, &planners, &m.name);
        if points.iter().any(Option::is_some) {
            let c = tradeoff_chart(
                &format!("Coverage against path ratio - {}", m.name),
                &planners,
                &points,
                &[],
            );
            write_chart(&dir, &format!("tradeoff_{}", m.name), &c)?;
        }
        if !series.is_empty() {
            let c = line_chart(
                &format!("Effective coverage over travelled distance - {}", m.name),
                "travelled distance (m)",
                "effective coverage",
                &series,
                Some(1.0),
            );
            write_chart(&dir, &format!("coverage_{}", m.name), &c)?;
        }
        if !panels.is_empty() {
            let legend = legend_entries_union_of(&shown);
            let c = image_grid_captioned(
                &format!("Paths - {}", m.name),
                &panels,
                &legend,
                3,
                520,
                420,
            );
            write_chart(&dir, &format!("paths_{}", m.name), &c)?;
        }
        Ok(())
    })?;
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
            "wall time (s)".into(),
            planners
                .iter()
                .map(|p| mean(p, |m| m.wall_time_s))
                .collect(),
        ),
    ];
    let c = bar_panels("Summary (mean over maps)", &planners, &metrics);
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
            &planners,
            &means,
            &per_map,
        );
        write_chart(&dir, "tradeoff_summary", &c)?;
    }
    Ok(())
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
