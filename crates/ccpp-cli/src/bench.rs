//! `ccpp bench`: every planner on every map, in parallel, with tables and plots.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use anyhow::{bail, Context, Result};
use ccpp_core::metrics::Metrics;
use ccpp_core::planners::{self, PlannerOptions};
use ccpp_core::sim::SimConfig;
use ccpp_io::scenario::{Scenario, DEFAULT_MAX_MEMORY_MB};
use ccpp_io::write_atomic;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

use crate::args::{BenchArgs, MapArgs};
use crate::job::{parse_planner, planner_options, prepare_map, robot_from, Job, PreparedMap};
use crate::output::write_run_files;

/// One row of the results: a run, or its failure.
pub struct Row {
    /// Map name.
    pub map: String,
    /// Planner name.
    pub planner: String,
    /// The metrics, or the error.
    pub outcome: Result<Metrics, String>,
    /// Where the run's files are.
    pub dir: PathBuf,
}

/// Expands `--maps` arguments: a folder gives its `*.yaml` maps (or, when it has none, its
/// PNG/PGM images), sorted; a file is taken as it is.
pub fn expand_maps(items: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for item in items {
        if item.is_dir() {
            let mut files: Vec<PathBuf> = std::fs::read_dir(item)
                .with_context(|| format!("cannot read map folder {}", item.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .collect();
            files.sort();
            let has_ext = |p: &Path, exts: &[&str]| {
                p.extension()
                    .and_then(|e| e.to_str())
                    .is_some_and(|e| exts.iter().any(|x| e.eq_ignore_ascii_case(x)))
            };
            let yamls: Vec<PathBuf> = files
                .iter()
                .filter(|p| has_ext(p, &["yaml", "yml"]))
                .cloned()
                .collect();
            if yamls.is_empty() {
                out.extend(
                    files
                        .into_iter()
                        .filter(|p| has_ext(p, &["png", "pgm", "pnm"])),
                );
            } else {
                out.extend(yamls);
            }
        } else {
            out.push(item.clone());
        }
    }
    if out.is_empty() {
        bail!(
            "no map found in {}",
            items
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    Ok(out)
}

fn map_name(p: &Path) -> String {
    p.file_stem()
        .map_or_else(|| "map".into(), |s| s.to_string_lossy().into_owned())
}

/// Runs the benchmark.
pub fn run(a: &BenchArgs) -> Result<()> {
    let planners: Vec<String> = if a.planners.is_empty() {
        planners::CATALOG
            .iter()
            .map(|p| p.name.to_string())
            .collect()
    } else {
        a.planners.clone()
    };
    for p in &planners {
        if !planners::CATALOG.iter().any(|c| c.name == p) {
            bail!("unknown planner {p:?}; run `ccpp planners` for the list");
        }
    }
    let (robot, _) = robot_from(&(&a.robot).into())?;
    let options = planner_options(a.config.as_deref(), a.seed)?;
    let maps = expand_maps(&a.maps)?;
    std::fs::create_dir_all(&a.out)
        .with_context(|| format!("cannot create output folder {}", a.out.display()))?;
    if let Some(j) = a.jobs {
        // Ignore the error when a global pool already exists (tests).
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(j.max(1))
            .build_global();
    }

    // Load every map once (in parallel); a map that fails to load fails all its runs.
    let prepared: Vec<(PathBuf, Result<PreparedMap, String>)> = maps
        .par_iter()
        .map(|m| {
            let args = MapArgs {
                map: m.clone(),
                inflate: a.inflate,
                ..MapArgs::default()
            };
            (m.clone(), prepare_map(&args).map_err(|e| format!("{e:#}")))
        })
        .collect();

    let mut tasks = Vec::new();
    for (mi, (path, _)) in prepared.iter().enumerate() {
        for p in &planners {
            tasks.push((mi, map_name(path), p.clone()));
        }
    }
    let bar = ProgressBar::new(tasks.len() as u64);
    if a.quiet {
        bar.set_draw_target(ProgressDrawTarget::hidden());
    }
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} runs  {elapsed}  {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let done = Mutex::new(());
    let rows: Vec<Row> = tasks
        .par_iter()
        .map(|(mi, name, planner)| {
            let dir = a.out.join("runs").join(name).join(planner);
            let outcome = run_one(a, &prepared[*mi].1, &dir, planner, robot, &options);
            let _guard = done.lock();
            bar.inc(1);
            bar.set_message(format!("{name} / {planner}"));
            Row {
                map: name.clone(),
                planner: planner.clone(),
                outcome,
                dir,
            }
        })
        .collect();
    bar.finish_and_clear();

    write_atomic(&a.out.join("results.csv"), results_csv(&rows).as_bytes())?;
    write_atomic(&a.out.join("results.md"), results_md(&rows).as_bytes())?;
    crate::plots::write_all(&a.out, &rows, &prepared, robot)?;
    let failed = rows.iter().filter(|r| r.outcome.is_err()).count();
    println!(
        "{} runs ({} failed) on {} maps x {} planners; wrote {}/results.csv, results.md, plots/",
        rows.len(),
        failed,
        prepared.len(),
        planners.len(),
        a.out.display()
    );
    Ok(())
}

fn run_one(
    a: &BenchArgs,
    map: &Result<PreparedMap, String>,
    dir: &Path,
    planner: &str,
    robot: ccpp_core::world::Robot,
    options: &PlannerOptions,
) -> Result<Metrics, String> {
    let metrics_path = dir.join("metrics.json");
    if !a.force && metrics_path.is_file() && dir.join("trace.jsonl").is_file() {
        if let Ok(text) = std::fs::read_to_string(&metrics_path) {
            if let Ok(m) = serde_json::from_str::<Metrics>(&text) {
                return Ok(m);
            }
        }
    }
    let map = map.as_ref().map_err(Clone::clone)?;
    let kind = parse_planner(planner).map_err(|e| format!("{e:#}"))?;
    let mut job = Job {
        scenario: Scenario {
            map: map.recipe.clone(),
            robot,
            start: None,
            planner: options.config(kind),
            sim: SimConfig::default(),
            max_memory_mb: a.max_memory.unwrap_or(DEFAULT_MAX_MEMORY_MB),
        },
        map: map.clone(),
        out: dir.to_path_buf(),
    };
    let result = job.execute().map_err(|e| format!("{e:#}"))?;
    write_run_files(dir, &job, &result).map_err(|e| format!("{e:#}"))?;
    Ok(result.metrics)
}

/// Quotes a CSV field when needed.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Column names of `results.csv`.
pub const CSV_COLUMNS: [&str; 20] = [
    "map",
    "planner",
    "status",
    "error",
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
    "wall_time_s",
    "dir",
];

/// `results.csv`: one row per run, failures included.
pub fn results_csv(rows: &[Row]) -> String {
    let mut s = CSV_COLUMNS.join(",");
    s.push('\n');
    for r in rows {
        let mut f: Vec<String> = vec![csv_field(&r.map), csv_field(&r.planner)];
        match &r.outcome {
            Ok(m) => {
                f.push("ok".into());
                f.push(String::new());
                f.push(m.robot_radius_m.to_string());
                f.push(m.tool_radius_m.to_string());
                f.push(m.coverage_rate.map_or_else(String::new, |c| c.to_string()));
                for v in [
                    m.effective_coverage,
                    m.path_length_m,
                    m.path_ratio,
                    m.redundancy,
                    m.revisit_rate,
                ] {
                    f.push(v.to_string());
                }
                f.push(m.regions.to_string());
                f.push(m.backtracks.to_string());
                f.push(m.backtrack_length_m.to_string());
                f.push(m.turns.to_string());
                f.push(m.rotation_rad.to_string());
                f.push(m.collisions.to_string());
                f.push(m.wall_time_s.to_string());
            }
            Err(e) => {
                f.push("error".into());
                f.push(csv_field(e));
                f.extend(std::iter::repeat_n(String::new(), 15));
            }
        }
        f.push(csv_field(&r.dir.display().to_string()));
        s.push_str(&f.join(","));
        s.push('\n');
    }
    s
}

/// `results.md`: a table per map and a summary across maps.
pub fn results_md(rows: &[Row]) -> String {
    let mut s = String::from("# ccpp bench results\n\n");
    let mut maps: Vec<&str> = Vec::new();
    let mut planners: Vec<&str> = Vec::new();
    for r in rows {
        if !maps.contains(&r.map.as_str()) {
            maps.push(&r.map);
        }
        if !planners.contains(&r.planner.as_str()) {
            planners.push(&r.planner);
        }
    }
    let header = "| planner | eff. coverage | tile coverage | path_ratio | regions | revisit_rate | turns | collisions | wall time (s) |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    let _ = writeln!(s, "## Summary across {} maps\n", maps.len());
    let _ = writeln!(
        s,
        "Means over the maps where the planner ran; `fails` counts runs that returned an error.\n"
    );
    s.push_str("| planner | runs | fails | eff. coverage | path_ratio | regions | revisit_rate | turns | collisions (total) | wall time (s, total) |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for p in &planners {
        let ok: Vec<&Metrics> = rows
            .iter()
            .filter(|r| r.planner == *p)
            .filter_map(|r| r.outcome.as_ref().ok())
            .collect();
        let fails = rows
            .iter()
            .filter(|r| r.planner == *p && r.outcome.is_err())
            .count();
        let n = ok.len().max(1) as f64;
        let mean = |f: fn(&Metrics) -> f64| ok.iter().map(|m| f(m)).sum::<f64>() / n;
        let _ = writeln!(
            s,
            "| {p} | {} | {fails} | {:.4} | {:.3} | {:.1} | {:.3} | {:.0} | {} | {:.2} |",
            ok.len(),
            mean(|m| m.effective_coverage),
            mean(|m| m.path_ratio),
            mean(|m| f64::from(m.regions)),
            mean(|m| m.revisit_rate),
            mean(|m| f64::from(m.turns)),
            ok.iter().map(|m| m.collisions).sum::<u32>(),
            ok.iter().map(|m| m.wall_time_s).sum::<f64>(),
        );
    }
    s.push('\n');
    for map in &maps {
        let _ = writeln!(s, "## {map}\n");
        s.push_str(header);
        for r in rows.iter().filter(|r| r.map == *map) {
            match &r.outcome {
                Ok(m) => {
                    let _ = writeln!(
                        s,
                        "| {} | {:.4} | {} | {:.3} | {} | {:.3} | {} | {} | {:.3} |",
                        r.planner,
                        m.effective_coverage,
                        m.coverage_rate
                            .map_or_else(|| "–".to_string(), |c| format!("{c:.4}")),
                        m.path_ratio,
                        m.regions,
                        m.revisit_rate,
                        m.turns,
                        m.collisions,
                        m.wall_time_s
                    );
                }
                Err(e) => {
                    let _ = writeln!(
                        s,
                        "| {} | error: {} | | | | | | | |",
                        r.planner,
                        e.replace('|', "/")
                    );
                }
            }
        }
        s.push('\n');
    }
    s
}
