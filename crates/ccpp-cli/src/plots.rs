//! Bench plots: coverage over travelled distance per map, summary bars, paths side by side.
//! Every plot is written as SVG and PNG from one chart description.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use ccpp_core::metrics::{coverage_curve, Metrics};
use ccpp_core::trace::Trace;
use ccpp_core::world::{Robot, World};
use ccpp_io::write_atomic;
use ccpp_render::chart::{bar_panels, image_grid, line_chart, Chart};
use rayon::prelude::*;

use crate::bench::Row;
use crate::job::PreparedMap;

/// Reads a `trace.jsonl` back.
pub fn read_trace(path: &Path) -> Result<Trace> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    ccpp_io::trace::parse_trace_jsonl(&text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

fn write_chart(dir: &Path, stem: &str, chart: &Chart) -> Result<()> {
    write_atomic(&dir.join(format!("{stem}.svg")), chart.to_svg().as_bytes())?;
    write_atomic(&dir.join(format!("{stem}.png")), &chart.to_png()?)?;
    Ok(())
}

/// Writes every plot into `out/plots/`.
pub fn write_all(
    out: &Path,
    rows: &[Row],
    maps: &[(PathBuf, Result<PreparedMap, String>)],
    robot: Robot,
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
        let Ok(world) = World::new(m.grid.clone(), robot, None) else {
            return Ok(());
        };
        let mut series = Vec::new();
        let mut pictures = Vec::new();
        for r in rows.iter().filter(|r| r.map == m.name && r.outcome.is_ok()) {
            if let Ok(trace) = read_trace(&r.dir.join("trace.jsonl")) {
                series.push((r.planner.clone(), coverage_curve(&world, &trace, 200)));
            }
            if let Ok(png) = std::fs::read(r.dir.join("coverage.png")) {
                pictures.push((r.planner.clone(), png));
            }
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
        if !pictures.is_empty() {
            let c = image_grid(&format!("Paths - {}", m.name), &pictures, 3, 520, 420);
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
    Ok(())
}
