//! `ccpp bench`: every planner on every map, in parallel, with tables and plots.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use anyhow::{bail, Context, Result};
use ccpp_core::metrics::Metrics;
use ccpp_core::planners::{self, PlannerOptions};
use ccpp_core::sim::SimConfig;
use ccpp_io::names::{expand_maps_noting, name_maps};
use ccpp_io::scenario::Scenario;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

use crate::args::{BenchArgs, MapArgs};
use crate::budget::MemoryBudget;
use crate::job::{parse_planner, planner_options, prepare_map, robot_from, Job, PreparedMap};
use crate::output::write_run_files;
use crate::row::Row;
use crate::staging::write_file;

/// Test hook: a planner named by this environment variable panics in a `ccpp bench` run, to
/// check that one failing run becomes an error row and the others finish.
pub const PANIC_ENV: &str = "CCPP_TEST_PANIC_PLANNER";

/// What defines a bench run, as written to its `bench-key.txt`: a finished run is reused only
/// when this matches exactly. Covers the map's content (after inflation) and its recipe as
/// `run.json` records it (path, bench name, inflation), the planner, its own
/// options (random-bounce's seed included; another planner's options or a `--seed` for
/// random-bounce redid every run), the robot, the simulator settings and the ccpp version.
/// The key's own version goes up when a planner's runs change under the same options (v4:
/// random-bounce finds its way out of a gap; a resumed bench reused its old runs, which
/// stopped at 13.4 of 31.7 km on `stage_willow_full`; v5: a run folder holds its
/// `warnings.txt`, so runs of v4, which have none, run again rather than report none; v6:
/// the warnings gained the floor never approached, and BA*'s traces bound their backtracking
/// lists, so a resumed bench reported v5 runs without the new warning; v7: the revisit
/// walk's tile boundaries moved by 1e-6 tile, which changed `revisit_rate` in 58 of the 112
/// runs of the 14 shared maps).
pub fn run_key(
    grid_hash: u64,
    recipe: &ccpp_io::scenario::MapRecipe,
    planner: &str,
    options: &PlannerOptions,
    robot: ccpp_core::world::Robot,
    sim: &SimConfig,
) -> Result<String> {
    let kind: ccpp_core::planners::PlannerKind = planner.parse()?;
    let mut h = ccpp_core::hash::Fnv::new();
    h.bytes(&grid_hash.to_le_bytes());
    // The map's recipe (path, name, inflation) as run.json records it: a run of the same map
    // read from another place was reused with its run.json naming the old path, which
    // `ccpp replay` then could not find.
    h.bytes(serde_json::to_string(recipe)?.as_bytes());
    h.bytes(planner.as_bytes());
    h.bytes(serde_json::to_string(&options.config(kind))?.as_bytes());
    h.bytes(serde_json::to_string(&robot)?.as_bytes());
    h.bytes(serde_json::to_string(sim)?.as_bytes());
    h.bytes(env!("CARGO_PKG_VERSION").as_bytes());
    Ok(format!("ccpp-bench-key v8 {:016x}\n", h.finish()))
}

/// Runs the benchmark.
pub fn run(a: &BenchArgs) -> Result<()> {
    let planners: Vec<String> = if a.planners.is_empty() {
        planners::CATALOG
            .iter()
            .map(|p| p.name.to_string())
            .collect()
    } else {
        // Each by its own name: `--planners "bsa, bcd"` names ` bcd` (and its run folder).
        a.planners
            .iter()
            .map(|p| Ok(parse_planner(p)?.name().to_string()))
            .collect::<Result<_>>()?
    };
    // A planner named twice runs once, as a map named twice does: two runs of it would
    // write the same run folder at the same time.
    let mut planners = planners;
    let mut seen = Vec::new();
    planners.retain(|p| {
        let first = !seen.contains(p);
        seen.push(p.clone());
        first
    });
    if a.seed.is_some()
        && !planners
            .iter()
            .any(|p| p == planners::PlannerKind::RandomBounce.name())
    {
        bail!("--seed does not apply to the planners of this bench (it applies to random-bounce)");
    }
    if a.jobs == Some(0) {
        bail!("--jobs must be at least 1, got 0");
    }
    // Refused here, before the folder is touched (every run would fail on it).
    ccpp_io::scenario::check_memory_limit(a.limits.max_memory_mb())?;
    // (`--inflate -1` was found map by map inside the bench: every run failed and the
    // summary of the last good bench in the folder was replaced by error rows)
    ccpp_io::scenario::MapRecipe {
        inflate: a.inflate,
        ..ccpp_io::scenario::MapRecipe::default()
    }
    .validate()?;
    let (robot, _) = robot_from(&(&a.robot).into())?;
    let options = planner_options(a.options.config.as_deref(), a.seed)?;
    let kinds: Vec<planners::PlannerKind> = planners
        .iter()
        .filter_map(|p| parse_planner(p).ok())
        .collect();
    crate::job::warn_unused_config(a.options.config.as_deref(), &kinds);
    // The planners' checks that need no map, before the folder is touched: every run would
    // meet them (`bcd: { bumper_reaction: false }`, a lane spacing wider than the tool: the
    // last good bench in the folder was replaced by error rows, which blamed the map and not
    // the options file: hostile pass, stop 69).
    for &kind in &kinds {
        Scenario::configure(
            ccpp_io::scenario::MapRecipe::default(),
            options.config(kind),
        )
        .robot(robot)
        .sim(SimConfig::default())
        .build()
        .and_then(|s| s.check_unplaced())
        .map_err(|e| {
            crate::job::naming_config(
                anyhow::Error::from(e),
                a.options.config.as_deref(),
                kind.info().section,
            )
        })?;
    }
    let (found, skipped) = expand_maps_noting(&a.maps)?;
    if !skipped.is_empty() {
        let names: Vec<String> = skipped
            .iter()
            .map(|p| ccpp_io::message::visible(&p.display().to_string()))
            .collect();
        say!(
            "note: left out {} YAML file{} that name{} no image (not map_server maps): {}",
            names.len(),
            if names.len() == 1 { "" } else { "s" },
            if names.len() == 1 { "s" } else { "" },
            names.join(", ")
        );
    }
    let maps = name_maps(found);
    check_map_names(&maps)?;
    // The maps whose plots a bench in this folder writes: this bench's and those of the run
    // folders an earlier one left (`runs/MAP`).
    let mut plotted: Vec<String> = maps.iter().map(|(_, n)| n.clone()).collect();
    if let Ok(entries) = std::fs::read_dir(a.out.join("runs")) {
        plotted.extend(
            entries
                .flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned()),
        );
    }
    check_bench_target(&a.out, &plotted)?;
    // (a bench into `runs/` of a bench or sweep at work above it wrote among its runs)
    ccpp_io::write::check_not_in_busy_folder(&a.out)?;
    ccpp_io::write::create_folder(&a.out, &a.out)?;
    // Held until the bench ends: a second bench on the folder is refused instead of writing
    // its runs and summary among this one's.
    let _lock = crate::lock::FolderLock::take(&a.out)?;
    // (the folder is ccpp's from now on: a later bench into it is not refused as a user's)
    crate::staging::write_file(
        &a.out.join(ccpp_io::write::STAMP_FILE),
        ccpp_io::write::STAMP_TEXT.as_bytes(),
    )?;
    // The summary of an earlier bench in this folder goes before any run starts: an
    // interrupted bench then leaves complete run folders and no summary, never a summary of
    // the earlier bench (another radius, other planners) beside run folders of this one.
    let had_summary = ["results.csv", "results.md"]
        .iter()
        .any(|f| a.out.join(f).is_file());
    clear_summary(&a.out, &plotted)?;
    crate::staging::set_interrupt_note(format!(
        "{}: the run folders finished so far are kept whole (a bench with the same --out reuses them) and no summary (results.csv, results.md, plots/) is written{}",
        a.out.display(),
        if had_summary {
            "; the earlier bench's summary there was removed when this one started"
        } else {
            ""
        }
    ));
    if let Some(j) = a.jobs {
        // A thread beyond one per run would only idle: `--jobs 100000` started 100000
        // threads, which took minutes on two cores before the first run.
        let runs = (maps.len() * planners.len()).max(1);
        // Ignore the error when a global pool already exists (tests).
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(j.min(runs))
            .build_global();
    }

    // Load every map once (in parallel); a map that fails to load fails all its runs.
    let prepared: Vec<(PathBuf, Result<PreparedMap, String>)> = maps
        .par_iter()
        .map(|(m, name)| {
            // A file of a maps folder named with a newline: the row's error said `map maps/new`
            // (the message cut at the newline), where `ccpp run` names the character.
            if let Some(problem) = ccpp_io::names::path_text_problem(m, "map") {
                return (m.clone(), Err(problem));
            }
            let args = MapArgs {
                map: m.clone(),
                inflate: a.inflate,
                ..MapArgs::default()
            };
            let map = prepare_map(&args, a.limits.max_memory_mb())
                .map(|mut p| {
                    // The bench's name when it is not the map's own (`FOLDER-NAME` for two
                    // maps of one file name): in the recipe too, so that run.json names the
                    // map as metrics.json does (`ccpp replay` refused such runs as mixed).
                    if p.name != *name {
                        p.name.clone_from(name);
                        p.recipe.name = Some(name.clone());
                    }
                    p
                })
                .map_err(|e| crate::errors::one_line(&e));
            (m.clone(), map)
        })
        .collect();
    let hashes: Vec<Option<u64>> = prepared
        .par_iter()
        .map(|(_, m)| m.as_ref().ok().map(|m| m.grid.content_hash()))
        .collect();

    let mut tasks = Vec::new();
    for (mi, (_, name)) in maps.iter().enumerate() {
        for p in &planners {
            tasks.push((mi, name.clone(), p.clone()));
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
    let budget = MemoryBudget::new(a.limits.max_memory_mb());
    let rows: Vec<Row> = tasks
        .par_iter()
        .map(|(mi, name, planner)| {
            let dir = a.out.join("runs").join(name).join(planner);
            let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                run_one(
                    a,
                    &prepared[*mi].1,
                    hashes[*mi],
                    &dir,
                    planner,
                    robot,
                    &options,
                    &budget,
                )
            }))
            .unwrap_or_else(|payload| Err(panic_message(payload.as_ref())));
            let (outcome, warnings) = match result {
                Ok((m, w)) => (Ok(m), w),
                Err(e) => (Err(e), Vec::new()),
            };
            let _guard = done.lock();
            bar.inc(1);
            bar.set_message(format!("{name} / {planner}"));
            Row {
                map: name.clone(),
                planner: planner.clone(),
                outcome,
                warnings,
                dir,
            }
        })
        .collect();
    bar.finish_and_clear();

    // The summary is one whole: a stop or an error (a full disk) while it is written removes
    // what it wrote (the plots folder only when this bench creates it, so that no file of the
    // user's goes with it), and `results.csv`, written last, marks it complete.
    let plots = a.out.join("plots");
    let mut summary = vec![a.out.join("results.csv"), a.out.join("results.md")];
    if !plots.exists() {
        summary.push(plots);
    }
    let summary = crate::staging::PendingSet::new(summary);
    let left_out = crate::plots::write_all(&a.out, &rows, &prepared, robot, &budget)?;
    let outside = starts_maybe_outside(&maps, &rows, &prepared);
    write_file(
        &a.out.join("results.md"),
        results_md(&rows, &outside).as_bytes(),
    )?;
    write_file(&a.out.join("results.csv"), results_csv(&rows).as_bytes())?;
    summary.done();
    for line in &left_out {
        say!("{line}");
    }
    let failed = rows.iter().filter(|r| r.outcome.is_err()).count();
    crate::print_stdout(&format!(
        "{}; wrote {}/results.csv, results.md, plots/\n",
        done_line(rows.len(), failed, prepared.len(), planners.len()),
        crate::output::folder_shown(&a.out)
    ))?;
    // Runs the simulator stopped before the planner finished (`stalled`, `max_steps`) are
    // results, not failures, but incomplete ones: named here as well as in `results.csv`.
    let stopped: Vec<String> = rows
        .iter()
        .filter_map(|r| {
            let reason = r.outcome.as_ref().ok()?.stop_reason.as_ref()?;
            Some(format!("{} / {} ({reason})", r.map, r.planner))
        })
        .collect();
    if !stopped.is_empty() {
        crate::print_stdout(&format!(
            "warning: stopped before the planner finished, with incomplete coverage (status in results.csv): {}\n",
            stopped.join(", ")
        ))?;
    }
    // The warnings `ccpp run` prints for a run (wide tiles, stranded tiles, boxed in, ...),
    // named here and written out in results.md and results.csv: a row of tile coverage 1.0
    // beside an effective coverage of 0.69 was shown without a word.
    let warned: Vec<String> = rows
        .iter()
        .filter(|r| !r.warnings.is_empty())
        .map(|r| format!("{} / {}", r.map, r.planner))
        .collect();
    if !warned.is_empty() {
        crate::print_stdout(&format!(
            "warning: {} with warnings (in results.md and the warnings column of results.csv): {}\n",
            crate::output::count(warned.len(), "run", "runs"),
            warned.join(", ")
        ))?;
    }
    if !outside.is_empty() {
        say!("{}", outside_warning(&outside));
    }
    if let Some(note) = earlier_runs_note(&a.out, &rows) {
        say!("{note}");
    }
    if failed > 0 {
        bail!(
            "{failed} of {} runs failed; see the error column of {}",
            rows.len(),
            a.out.join("results.csv").display()
        );
    }
    Ok(())
}

/// Checks that `out` is absent or a folder holding only what a bench writes (`results.csv`,
/// `results.md`, `plots/` with the plots of `maps`, `runs/`): a bench rewrites those, so
/// another file there (a user's own `results.csv` in a folder of theirs) would be overwritten.
///
/// # Errors
/// When `out` is a file, or a folder holding anything else.
fn check_bench_target(out: &Path, maps: &[String]) -> Result<()> {
    let Ok(meta) = std::fs::symlink_metadata(out) else {
        return Ok(());
    };
    if !meta.is_dir() {
        bail!(
            "output folder {} exists and is not a plain folder",
            out.display()
        );
    }
    let entries = std::fs::read_dir(out)
        .with_context(|| format!("cannot read output folder {}", out.display()))?;
    // (the first entry of what a bench writes, for a folder without ccpp's stamp: a user's
    // own `results.csv` there was overwritten; hostile pass, stop 70)
    let mut unstamped: Option<String> = None;
    let mut stamped = false;
    for e in entries {
        let e = e.with_context(|| format!("cannot read output folder {}", out.display()))?;
        let name = e.file_name();
        let name = name.to_string_lossy();
        let Ok(t) = e.file_type() else { continue };
        if name == ccpp_io::write::STAMP_FILE && t.is_file() {
            stamped = true;
            continue;
        }
        if name != crate::lock::LOCK_FILE && unstamped.as_deref().is_none_or(|u| *name < *u) {
            unstamped = Some(name.to_string());
        }
        let known = match name.as_ref() {
            // A write cut short leaves `<file>.tmp` (see `staging::write_file`; any other
            // `.tmp` is a user's), and a bench its lock file while it runs (a later bench is
            // then refused, see `crate::lock`) or when it was killed (taken over).
            "results.csv"
            | "results.md"
            | "results.csv.tmp"
            | "results.md.tmp"
            | crate::lock::LOCK_FILE => t.is_file(),
            "runs" => t.is_dir(),
            "plots" => {
                if t.is_dir() {
                    check_plots(out, &e.path(), maps)?;
                }
                t.is_dir()
            }
            _ => false,
        };
        if !known {
            bail!(
                "output folder {} holds {name}, which ccpp bench did not write; a bench rewrites \
                 its results there, so choose a new or bench-only folder",
                out.display()
            );
        }
    }
    if let (Some(name), false) = (unstamped, stamped) {
        bail!(
            "output folder {} holds {name} but no {} stamp, so ccpp did not write it (or an \
             older ccpp did); a bench rewrites its results there, so choose a new folder, or \
             remove that one first",
            out.display(),
            ccpp_io::write::STAMP_FILE
        );
    }
    Ok(())
}

/// Checks that the `plots/` folder of the bench folder `out` holds only plots a bench writes
/// ([`is_bench_plot`]): a bench removes the old ones, and removed a user's own figure there
/// with them.
///
/// # Errors
/// When it holds anything else (named), or cannot be read.
fn check_plots(out: &Path, dir: &Path, maps: &[String]) -> Result<()> {
    let entries =
        std::fs::read_dir(dir).with_context(|| format!("cannot read {}", dir.display()))?;
    for e in entries {
        let e = e.with_context(|| format!("cannot read {}", dir.display()))?;
        let name = e.file_name();
        let name = name.to_string_lossy();
        if !(is_bench_plot(&name, maps) && e.file_type().is_ok_and(|t| t.is_file())) {
            bail!(
                "output folder {} holds plots/{name}, which ccpp bench did not write; a bench \
                 rewrites its plots there, so choose a new or bench-only folder",
                out.display()
            );
        }
    }
    Ok(())
}

/// Whether `name` is a plot a bench writes in `plots/` ([`crate::plots::write_all`]):
/// `summary`, `tradeoff_summary`, or `coverage_MAP`, `paths_MAP`, `tradeoff_MAP` of one of
/// `maps` (a user's `coverage_mydiagram.png` was taken for a bench's and deleted), as `.svg`
/// or `.png`, or the `.tmp` of one that a write cut short left.
fn is_bench_plot(name: &str, maps: &[String]) -> bool {
    let name = name.strip_suffix(".tmp").unwrap_or(name);
    let Some(stem) = name
        .strip_suffix(".svg")
        .or_else(|| name.strip_suffix(".png"))
    else {
        return false;
    };
    stem == "summary"
        || stem == "tradeoff_summary"
        || ["coverage_", "paths_", "tradeoff_"]
            .iter()
            .filter_map(|p| stem.strip_prefix(p))
            .any(|m| maps.iter().any(|k| k == m))
}

/// Removes the summary of an earlier bench in `out`: `results.csv`, `results.md` and the plots
/// in `out/plots/` (maps it had and this one has not would stay beside this bench's results
/// otherwise), then the emptied `plots/`. Only names a bench writes ([`is_bench_plot`]; a
/// user's figure there is refused by [`check_bench_target`] before this). The run folders stay:
/// each is complete and keyed, so a bench reuses the ones that match it.
fn clear_summary(out: &Path, maps: &[String]) -> Result<()> {
    for name in ["results.csv", "results.md"] {
        let p = out.join(name);
        if std::fs::symlink_metadata(&p).is_ok_and(|m| m.is_file()) {
            std::fs::remove_file(&p)
                .with_context(|| format!("cannot remove the old {}", p.display()))?;
        }
    }
    let dir = out.join("plots");
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return Ok(());
    };
    for e in entries.flatten() {
        let p = e.path();
        let plot = is_bench_plot(&e.file_name().to_string_lossy(), maps);
        if plot && e.file_type().is_ok_and(|t| t.is_file()) {
            std::fs::remove_file(&p)
                .with_context(|| format!("cannot remove the old plot {}", p.display()))?;
        }
    }
    // Not removed when something else appeared there since the check: it stays as it is (and
    // the summary then leaves the folder in place on a stop or an error).
    if let Err(e) = std::fs::remove_dir(&dir) {
        if e.kind() != std::io::ErrorKind::DirectoryNotEmpty {
            return Err(e).with_context(|| format!("cannot remove the old {}", dir.display()));
        }
    }
    Ok(())
}

/// The message of a caught panic.
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    let msg = payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown cause".to_string());
    format!("the run panicked: {msg}")
}

/// The files every finished bench run folder holds (a bench writes no replay or exports).
const BENCH_RUN_FILES: [&str; 7] = [
    "run.json",
    "path.csv",
    "trace.jsonl",
    "coverage.png",
    "metrics.json",
    KEY_FILE,
    WARNINGS_FILE,
];

/// The warnings of a bench run, one per line (empty when none), beside its other files: a
/// resumed bench reports a reused run's warnings from it.
const WARNINGS_FILE: &str = ccpp_io::write::BENCH_WARNINGS_FILE;

/// The warnings in a bench run folder's [`WARNINGS_FILE`].
fn read_warnings(dir: &Path) -> Result<Vec<String>, String> {
    let text = ccpp_io::file::read_text(&dir.join(WARNINGS_FILE))
        .map_err(|e| crate::errors::one_line(&e.into()))?;
    Ok(text.lines().map(str::to_string).collect())
}

#[allow(clippy::too_many_arguments)] // the run, its map and the bench's shared state
fn run_one(
    a: &BenchArgs,
    map: &Result<PreparedMap, String>,
    grid_hash: Option<u64>,
    dir: &Path,
    planner: &str,
    robot: ccpp_core::world::Robot,
    options: &PlannerOptions,
    budget: &MemoryBudget,
) -> Result<(Metrics, Vec<String>), String> {
    let map = map.as_ref().map_err(Clone::clone)?;
    let sim = SimConfig::default();
    let key = grid_hash
        .map(|h| run_key(h, &map.recipe, planner, options, robot, &sim))
        .transpose()
        .map_err(|e| crate::errors::one_line(&e))?
        .unwrap_or_default();
    let metrics_path = dir.join("metrics.json");
    if let (Some(parent), Some(name)) = (dir.parent(), dir.file_name().and_then(|n| n.to_str())) {
        // Staging folders of a killed run beside this one (they stayed for good: the folder
        // was reused, and only a run into it cleans beside it; hostile pass).
        ccpp_io::write::clean_stale(parent, name);
    }
    if !a.force && dir.join("trace.jsonl").is_file() {
        // Regular files only (a FIFO would block the bench forever).
        let listed = ccpp_io::file::read_text(&dir.join(KEY_FILE))
            .ok()
            .and_then(|k| k.strip_prefix(key.as_str()).map(str::to_string));
        if let Some(listed) = listed {
            if let Ok(text) = ccpp_io::file::read_text(&metrics_path) {
                if let Ok(m) = serde_json::from_str::<Metrics>(&text) {
                    // Reused only when its trace reads back whole: a damaged trace was reused
                    // and then left out of the plots in silence.
                    // And only when the folder holds every file of a run: one missing
                    // (removed by hand, or a copy cut short) was reused, "0 failed".
                    let missing = BENCH_RUN_FILES
                        .iter()
                        .find(|f| ccpp_io::file::open_regular(&dir.join(f)).is_err());
                    let whole = match missing {
                        Some(f) => Err(format!("{f} is missing")),
                        None => same_run(&m, &map.name, planner)
                            .and_then(|()| sizes_match(dir, &listed))
                            .and_then(|()| {
                                whole_trace(dir, map.grid.frame(), robot.radius, budget, &m)
                            })
                            .and_then(|()| read_warnings(dir)),
                    };
                    match whole {
                        Ok(w) => return Ok((m, w)),
                        Err(why) => {
                            say!("warning: {}: {why}; running it again", dir.display());
                        }
                    }
                }
            }
        }
    }
    let kind = parse_planner(planner).map_err(|e| crate::errors::one_line(&e))?;
    let spec = JobSpec {
        scenario: Scenario::configure(map.recipe.clone(), options.config(kind))
            .robot(robot)
            .sim(sim)
            .memory_limit(a.limits.max_memory)
            .build()
            .map_err(|e| crate::errors::one_line(&e.into()))?,
        map_name: map.name.clone(),
        out: dir.to_path_buf(),
        key,
    };
    // The run's estimate against what the runs in progress hold (a run its own check refuses
    // holds nothing: the child says why).
    let bytes = spec.scenario.check_map(map).map_or(0.0, |e| e.bytes);
    let _grant = budget.take(bytes);
    let m = run_isolated(&spec).inspect_err(|_| {
        // A job that died (killed, crashed) may have left its staging folder beside the run
        // folder: removed now that its process is gone, not at the next bench (a finished
        // bench held a hidden copy of a dead job's files: hostile pass).
        if let (Some(parent), Some(name)) = (dir.parent(), dir.file_name().and_then(|n| n.to_str()))
        {
            ccpp_io::write::clean_stale(parent, name);
        }
        // An earlier bench's run in this slot (another radius, other options: not reused)
        // goes too: it stayed beside this bench's runs while `results.csv` listed this run
        // as failed, and `ccpp replay` showed it as this bench's (hostile pass).
        // Not when the bench is being interrupted (the child died of that, not of its run:
        // the earlier run is whole and keyed, and stays), and never file by file: an
        // interrupt cut such removals short and left folders holding a `path.csv` alone
        // (hostile pass).
        if !crate::staging::stopping() && dir.join(KEY_FILE).is_file() {
            if let Err(e) = ccpp_io::write::remove_folder(dir) {
                say!(
                    "warning: {}: cannot remove an earlier bench's run here ({e}); it is not this bench's",
                    dir.display()
                );
            }
        }
    })?;
    Ok((m, read_warnings(dir)?))
}

/// Longest map name a bench takes, in bytes: a map's plots are `tradeoff_NAME.svg` and
/// `coverage_NAME.png`, written through `NAME.svg.tmp`, and a file name holds at most 255
/// bytes. A longer name (a legal file name of 239 bytes or more) ran every run and then lost
/// the whole summary to "File name too long" (hostile pass).
const MAX_MAP_NAME_BYTES: usize = 255 - "tradeoff_".len() - ".svg.tmp".len();

/// Refuses, before any run, a map whose name is too long for the bench's file names
/// ([`MAX_MAP_NAME_BYTES`]).
fn check_map_names(maps: &[(PathBuf, String)]) -> Result<()> {
    for (path, name) in maps {
        if name.len() > MAX_MAP_NAME_BYTES {
            anyhow::bail!(
                "map {}: its name is {} bytes, more than the {MAX_MAP_NAME_BYTES} a bench takes (its plots are named tradeoff_NAME.svg, and a file name holds at most 255 bytes); link or copy the map under a shorter name",
                path.display(),
                name.len()
            );
        }
    }
    Ok(())
}

/// The file of a bench run folder that holds the run's key ([`run_key`]) and then a line
/// `NAME SIZE` for each of its other files.
const KEY_FILE: &str = "bench-key.txt";

/// Checks that a reused run folder's metrics are of this run: a `metrics.json` copied from
/// another run (`bcd`'s into `ba-star`'s folder) was reused and its numbers reported in the
/// other planner's row (hostile pass).
fn same_run(m: &Metrics, map: &str, planner: &str) -> Result<(), String> {
    if m.planner == planner && m.map == map {
        Ok(())
    } else {
        Err(format!(
            "metrics.json is of {} on {}, not of this run",
            m.planner, m.map
        ))
    }
}

/// Checks the sizes `listed` in a run folder's [`KEY_FILE`] (after its key) against the files
/// of `dir`: a copy cut short (a truncated `coverage.png` or `path.csv`) was reused, and a
/// `run.json` emptied by hand too (hostile pass).
fn sizes_match(dir: &Path, listed: &str) -> Result<(), String> {
    let mut seen = 0;
    for line in listed.lines() {
        let parsed = line
            .rsplit_once(' ')
            .and_then(|(f, n)| Some((f, n.parse::<u64>().ok()?)));
        let Some((file, len)) = parsed else {
            return Err(format!("{KEY_FILE} is damaged"));
        };
        let actual = std::fs::metadata(dir.join(file)).ok().map(|m| m.len());
        if actual != Some(len) {
            return Err(format!(
                "{file} is not the file the run wrote ({len} bytes were written)"
            ));
        }
        seen += 1;
    }
    // Every file but the key file itself is listed.
    if seen + 1 < BENCH_RUN_FILES.len() {
        return Err(format!("{KEY_FILE} lists too few files"));
    }
    Ok(())
}

/// Checks that the `trace.jsonl` of the run folder `dir` reads back (as the plots read it,
/// every pose on the map of `frame`, within the robot's `radius` and two pixels),
/// ends with the simulator's `finished` record (a trace cut at a line's end reads back) and
/// drives the path length `metrics` reports. The
/// parsed trace is held against `budget` while it is checked (streamed, about twice the
/// file's size).
fn whole_trace(
    dir: &Path,
    frame: &ccpp_core::grid::MapFrame,
    radius: f64,
    budget: &MemoryBudget,
    metrics: &Metrics,
) -> Result<(), String> {
    let path = dir.join("trace.jsonl");
    let len = std::fs::metadata(&path).map_or(0, |m| m.len());
    let _grant = budget.take(2.0 * len as f64);
    let trace =
        crate::plots::read_trace(&path, frame, radius).map_err(|e| crate::errors::one_line(&e))?;
    if !matches!(
        trace.events().last(),
        Some((_, ccpp_core::trace::Event::Finished { .. }))
    ) {
        return Err(
            "trace.jsonl does not end with the simulator's `finished` record (cut short)".into(),
        );
    }
    // The path the trace drives is the one metrics.json reports, as `ccpp replay` checks: a
    // metrics.json edited to another length of the same size was reused (hostile pass).
    crate::output::length_mismatch(&trace, metrics.path_length_m).map_or(Ok(()), Err)
}

/// Hidden first argument that makes `ccpp` run one bench job (a [`JobSpec`] as JSON on stdin)
/// and print its metrics JSON.
pub const CHILD_ARG: &str = "__bench-job";

/// The bench's process id, given to each job: a job whose bench has gone stops as if
/// interrupted ([`crate::staging::stop_with_parent`]).
const PARENT_ENV: &str = "CCPP_BENCH_PARENT";

/// Test hook: a planner named by this environment variable aborts the process running it.
pub const ABORT_ENV: &str = "CCPP_TEST_ABORT_PLANNER";

/// One bench run, as handed to the child process.
#[derive(serde::Serialize, serde::Deserialize)]
pub struct JobSpec {
    /// What to run.
    pub scenario: Scenario,
    /// The map's name in the bench.
    pub map_name: String,
    /// The run folder.
    pub out: PathBuf,
    /// The run's key, written as `bench-key.txt`.
    pub key: String,
}

/// Runs one job in a child process of this binary, so that a panic, an abort or a crash (stack
/// overflow, out of memory) ends that run only, and its memory goes back when it ends.
fn run_isolated(spec: &JobSpec) -> Result<Metrics, String> {
    use std::io::Write as _;
    use std::process::{Command, Stdio};
    let input = serde_json::to_vec(spec).map_err(|e| e.to_string())?;
    let exe = std::env::current_exe().map_err(|e| format!("cannot find the ccpp binary: {e}"))?;
    let mut child = crate::staging::spawn_child(
        Command::new(exe)
            .arg(CHILD_ARG)
            .env(PARENT_ENV, std::process::id().to_string())
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped()),
    )
    .map_err(|e| format!("cannot start a run: {e}"))?;
    let pid = child.id();
    if let Some(mut stdin) = child.stdin.take() {
        // A child that died at once shows in its status below.
        let _ = stdin.write_all(&input);
    }
    let out = child.wait_with_output();
    crate::staging::unregister_child(pid);
    let out = out.map_err(|e| format!("lost the run: {e}"))?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    if out.status.success() {
        return serde_json::from_slice::<Metrics>(&out.stdout)
            .map_err(|e| format!("the run's metrics are unreadable: {e}"));
    }
    Err(child_failure(out.status, &stderr))
}

/// Words for a child run that did not succeed.
fn child_failure(status: std::process::ExitStatus, stderr: &str) -> String {
    let lines: Vec<&str> = stderr
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    if let Some(i) = lines.iter().position(|l| l.contains("panicked at")) {
        let msg = lines.get(i + 1).copied().unwrap_or("unknown cause");
        return format!("the run panicked: {msg}");
    }
    if let Some(e) = lines.iter().rev().find_map(|l| l.strip_prefix("error: ")) {
        return e.to_string();
    }
    #[cfg(unix)]
    {
        use std::os::unix::process::ExitStatusExt as _;
        if let Some(sig) = status.signal() {
            let what = match sig {
                6 => " (abort)",
                9 => " (killed, e.g. out of memory)",
                11 => " (segmentation fault or stack overflow)",
                _ => "",
            };
            return format!("the run crashed: signal {sig}{what}");
        }
    }
    format!("the run failed ({status})")
}

/// `ccpp __bench-job`: runs the [`JobSpec`] read from stdin, writes its run folder and prints
/// its metrics JSON. Errors are one `error:` line on stderr and exit status 1.
pub fn child_main() -> std::process::ExitCode {
    crate::staging::install_signal_handler();
    let parent = std::env::var(PARENT_ENV).ok().and_then(|p| p.parse().ok());
    crate::staging::stop_with_parent(parent);
    let code = match child_job() {
        Ok(metrics) => match crate::print_stdout(&metrics) {
            Ok(()) => std::process::ExitCode::SUCCESS,
            Err(_) => std::process::ExitCode::FAILURE,
        },
        Err(e) => {
            say!("error: {}", crate::errors::one_line(&e));
            std::process::ExitCode::FAILURE
        }
    };
    crate::staging::finish(code)
}

fn child_job() -> Result<String> {
    use std::io::Read as _;
    let mut text = String::new();
    std::io::stdin()
        .read_to_string(&mut text)
        .context("cannot read the job")?;
    let spec: JobSpec = serde_json::from_str(&text).context("cannot read the job")?;
    let planner = spec.scenario.planner.name();
    if let Some(hook) = std::env::var_os(PANIC_ENV) {
        assert!(hook != planner, "{PANIC_ENV} asked {planner} to panic");
    }
    if std::env::var_os(ABORT_ENV).is_some_and(|h| h == planner) {
        std::process::abort();
    }
    let mut map = crate::job::load_recipe(&spec.scenario.map, spec.scenario.max_memory_mb)?;
    map.name.clone_from(&spec.map_name);
    let mut job = Job {
        scenario: spec.scenario,
        map: Some(map),
        out: spec.out,
    };
    let result = job.execute()?;
    if let Some(note) = result.approach_note() {
        say!("{note}");
    }
    // One a line (a line break inside one, as from a map's name, made a space).
    let list = ccpp_io::warnings::run_warnings(
        &job.scenario,
        &result.world,
        &result.run.trace,
        &result.metrics,
        &result.swept,
    );
    let mut warnings = String::new();
    for w in &list {
        warnings.push_str(&w.replace(['\n', '\r'], " "));
        warnings.push('\n');
    }
    let extra = [(WARNINGS_FILE, warnings.into_bytes())];
    write_run_files(
        &job.out,
        &job,
        &result,
        false,
        &extra,
        &list,
        Some((KEY_FILE, &spec.key)),
    )
}

/// Quotes a CSV field when needed (a carriage return too: a map file named with one split
/// its row in two for Python's `csv` and pandas).
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Column names of `results.csv`.
pub const CSV_COLUMNS: [&str; 21] = [
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
    "warnings",
];

/// `results.csv`: one row per run, failures included.
pub fn results_csv(rows: &[Row]) -> String {
    let mut s = CSV_COLUMNS.join(",");
    s.push('\n');
    for r in rows {
        let mut f: Vec<String> = vec![csv_field(&r.map), csv_field(&r.planner)];
        match &r.outcome {
            Ok(m) => {
                // A run stopped early (`stalled`, `max_steps`) says so instead of `ok`.
                f.push(m.stop_reason.clone().unwrap_or_else(|| "ok".into()));
                f.push(String::new());
                f.push(m.robot_radius_m.to_string());
                f.push(m.tool_radius_m.to_string());
                f.push(m.coverage_rate.map_or_else(String::new, |c| c.to_string()));
                for v in [m.effective_coverage, m.path_length_m, m.path_ratio] {
                    f.push(v.to_string());
                }
                f.push(m.redundancy.map_or_else(String::new, |v| v.to_string()));
                f.push(m.revisit_rate.to_string());
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
        // A failed run leaves no folder: its `dir` is empty rather than a path that does not
        // exist.
        let dir = if r.outcome.is_ok() {
            r.dir.display().to_string()
        } else {
            String::new()
        };
        f.push(csv_field(&dir));
        f.push(csv_field(&r.warnings.join(ccpp_io::warnings::SEPARATOR)));
        s.push_str(&f.join(","));
        s.push('\n');
    }
    s
}

/// The head of bench's last line: `3 runs (0 failed) on 1 map x 3 planners`, each count with
/// its noun in the singular or plural it takes.
fn done_line(runs: usize, failed: usize, maps: usize, planners: usize) -> String {
    use crate::output::count;
    format!(
        "{} ({failed} failed) on {} x {}",
        count(runs, "run", "runs"),
        count(maps, "map", "maps"),
        count(planners, "planner", "planners")
    )
}

/// A name as Markdown text on one line: control characters escaped (`\n`; a map file named
/// with a newline split its heading in two), `|` escaped so it does not end a table cell, and
/// `<`, `>`, `&` as HTML entities so that they show as written (a map `<script>.yaml` gave the
/// heading `## <script>`, which a Markdown renderer drops as HTML), and the characters of
/// Markdown's own syntax backslash-escaped (a map `![i](http:__x.png).yaml` became an image in
/// its heading, `**b**.yaml` bold, `#.yaml` an empty heading: hostile pass).
fn md_text(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    let chars: Vec<char> = name.chars().collect();
    for (i, &c) in chars.iter().enumerate() {
        // (an `_` between letters or digits opens no emphasis: `aws_small_house` stays as
        // it is written)
        let inside_word = |k: Option<usize>| {
            k.and_then(|k| chars.get(k))
                .is_some_and(|c| c.is_alphanumeric())
        };
        match c {
            '_' if inside_word(i.checked_sub(1)) && inside_word(Some(i + 1)) => out.push(c),
            '|' => out.push_str("\\|"),
            '\\' | '`' | '*' | '_' | '[' | ']' | '#' | '!' | '~' => {
                out.push('\\');
                out.push(c);
            }
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' => out.push_str("&amp;"),
            c if ccpp_io::message::hidden(c) => out.extend(c.escape_default()),
            c => out.push(c),
        }
    }
    out
}

/// The maps (names, in bench order) whose runs started in a free area that reaches the map's
/// border, so probably outside the building, as `ccpp run` and `ccpp info` warn: the start
/// each run used is in its `run.json` (the first run of the map that has one; every planner
/// of a bench starts at the same place).
fn starts_maybe_outside(
    maps: &[(PathBuf, String)],
    rows: &[Row],
    prepared: &[(PathBuf, Result<PreparedMap, String>)],
) -> Vec<String> {
    maps.iter()
        .zip(prepared)
        .filter_map(|((_, name), (_, map))| {
            let map = map.as_ref().ok()?;
            let scenario = rows
                .iter()
                .filter(|r| r.map == *name && r.outcome.is_ok())
                .find_map(|r| Scenario::from_file(&r.dir.join("run.json")).ok())?;
            let [x, y, _] = scenario.start?;
            let start = ccpp_core::geometry::Point::new(x, y);
            // The pixel flood first (cheap); where it reaches the border, the floor the
            // robot reaches decides, as `ccpp run` says it.
            if !crate::components::StartComponent::of(&map.grid, start).touches_border {
                return None;
            }
            let world = scenario.world(map).ok()?;
            crate::components::StartComponent::of_world(&world)
                .touches_border
                .then(|| name.clone())
        })
        .collect()
}

/// The warning a bench prints for [`starts_maybe_outside`]'s maps.
fn outside_warning(maps: &[String]) -> String {
    format!(
        "warning: on {} the floor open to the robot from the start reaches the map's border, so the start \
         may be outside the building (only that area is covered; `ccpp info` shows it); a \
         start inside needs `ccpp run --start X,Y`",
        maps.join(", ")
    )
}

/// The run folders under `out/runs/MAP/PLANNER` that `rows` (this bench's runs) leave out:
/// an earlier bench's, with other maps, planners or settings, which the summary does not
/// describe. Named on stderr so that a folder holding two benches is not taken for one.
fn earlier_runs_note(out: &Path, rows: &[Row]) -> Option<String> {
    let mut left: Vec<String> = Vec::new();
    let runs = out.join("runs");
    let mut maps: Vec<_> = std::fs::read_dir(&runs).ok()?.flatten().collect();
    maps.sort_by_key(std::fs::DirEntry::file_name);
    for m in maps {
        let map = m.file_name().to_string_lossy().into_owned();
        let Ok(planners) = std::fs::read_dir(m.path()) else {
            continue;
        };
        let mut planners: Vec<_> = planners.flatten().collect();
        planners.sort_by_key(std::fs::DirEntry::file_name);
        for p in planners {
            let planner = p.file_name().to_string_lossy().into_owned();
            // (a staging folder of a killed run, `.bcd.ccpp-new-PID-N`, is no run folder;
            // it was named as one of an earlier bench)
            if planner.starts_with('.') {
                continue;
            }
            // (a run of this bench that failed leaves the earlier bench's folder, which its
            // error row does not describe, in place)
            let ours = rows
                .iter()
                .any(|r| r.map == map && r.planner == planner && r.outcome.is_ok());
            if !ours && p.path().join("metrics.json").is_file() {
                left.push(format!("{map}/{planner}"));
            }
        }
    }
    if left.is_empty() {
        return None;
    }
    let n = left.len();
    let shown: Vec<&str> = left.iter().take(8).map(String::as_str).collect();
    let more = if n > shown.len() { ", ..." } else { "" };
    Some(format!(
        "note: {} also holds {n} run folder{} of an earlier bench that this summary leaves out ({}{more}); remove {} or bench into a new folder to keep one bench per folder",
        runs.display(),
        if n == 1 { "" } else { "s" },
        shown.join(", "),
        if n == 1 { "it" } else { "them" }
    ))
}

/// `results.md`: a table per map and a summary across maps; `outside` names the maps whose
/// start may lie outside the building ([`starts_maybe_outside`]), said under their tables and
/// under the summary.
pub fn results_md(rows: &[Row], outside: &[String]) -> String {
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
    let _ = writeln!(
        s,
        "## Summary across {} map{}\n",
        maps.len(),
        if maps.len() == 1 { "" } else { "s" }
    );
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
        if ok.is_empty() {
            // No run to average: dashes, not means of nothing (`-0.0000` was printed).
            let _ = writeln!(
                s,
                "| {} | 0 | {fails} | - | - | - | - | - | - | - |",
                md_text(p)
            );
            continue;
        }
        let n = ok.len() as f64;
        let mean = |f: fn(&Metrics) -> f64| ok.iter().map(|m| f(m)).sum::<f64>() / n;
        let _ = writeln!(
            s,
            "| {} | {} | {fails} | {:.4} | {:.3} | {:.1} | {:.3} | {:.0} | {} | {:.2} |",
            md_text(p),
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
    if !outside.is_empty() {
        let names: Vec<String> = outside.iter().map(|m| md_text(m)).collect();
        let _ = writeln!(
            s,
            "\nOn {} the floor open to the robot from the start reaches the map's border: the start may be \
             outside the building, and only that area is covered and measured.",
            names.join(", ")
        );
    }
    s.push('\n');
    for map in &maps {
        let _ = writeln!(s, "## {}\n", md_text(map));
        if outside.iter().any(|m| m == map) {
            s.push_str(
                "The floor open to the robot from the start reaches the map's border: the start may be \
                 outside the building.\n\n",
            );
        }
        s.push_str(header);
        for r in rows.iter().filter(|r| r.map == *map) {
            match &r.outcome {
                Ok(m) => {
                    let _ = writeln!(
                        s,
                        "| {} | {:.4} | {} | {:.3} | {} | {:.3} | {} | {} | {:.3} |",
                        md_text(&r.planner),
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
                        md_text(&r.planner),
                        md_text(&e.replace('|', "/"))
                    );
                }
            }
        }
        let warned: Vec<&Row> = rows
            .iter()
            .filter(|r| r.map == *map && !r.warnings.is_empty())
            .collect();
        if !warned.is_empty() {
            s.push_str("\nWarnings:\n\n");
            for r in warned {
                for w in &r.warnings {
                    // (random-bounce's boxed-in warning names the planner itself)
                    if w.starts_with(&format!("{}:", r.planner)) {
                        let _ = writeln!(s, "- {}", md_text(w));
                    } else {
                        let _ = writeln!(s, "- {}: {}", md_text(&r.planner), md_text(w));
                    }
                }
            }
        }
        s.push('\n');
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Names show in results.md as written: Markdown's syntax escaped, an `_` inside a word
    /// left alone, hidden characters written as escapes.
    #[test]
    fn markdown_names_are_written_as_they_are() {
        assert_eq!(md_text("aws_small_house"), "aws_small_house");
        assert_eq!(
            md_text("![img](http:__x.png)"),
            "\\!\\[img\\](http:\\_\\_x.png)"
        );
        assert_eq!(md_text("**b**"), "\\*\\*b\\*\\*");
        assert_eq!(md_text("#"), "\\#");
        assert_eq!(md_text("a\\|b`c`"), "a\\\\\\|b\\`c\\`");
        assert_eq!(md_text("_x_ <s>"), "\\_x\\_ &lt;s&gt;");
        assert_eq!(md_text("r\u{202e}t\n"), "r\\u{202e}t\\n");
    }

    #[test]
    fn bench_plots_are_known_by_name() {
        let maps = ["teb_maze".to_string(), "a-b".to_string(), "x".to_string()];
        for ok in [
            "summary.png",
            "summary.svg",
            "tradeoff_summary.png",
            "coverage_teb_maze.svg",
            "paths_a-b.png",
            "tradeoff_x.svg.tmp",
        ] {
            assert!(is_bench_plot(ok, &maps), "{ok}");
        }
        for foreign in [
            "my_figure.png",
            "coverage_.png",
            "summary.pdf",
            "notes.txt",
            "paths_x.png.bak",
            // Named like a bench's plot, but of no map of this bench or its run folders.
            "coverage_mydiagram.png",
            "tradeoff_notes.svg",
        ] {
            assert!(!is_bench_plot(foreign, &maps), "{foreign}");
        }
    }

    /// A planner whose every run failed had "means" of nothing (`-0.0000`) in the summary, and
    /// its rows named run folders that were never written.
    #[test]
    fn a_planner_without_a_run_has_no_means_and_no_folders() {
        let row = |map: &str| Row {
            map: map.into(),
            planner: "bsa".into(),
            outcome: Err("robot too big".into()),
            warnings: Vec::new(),
            dir: PathBuf::from(format!("out/runs/{map}/bsa")),
        };
        let rows = [row("a"), row("b")];
        let md = results_md(&rows, &[]);
        assert!(
            md.contains("| bsa | 0 | 2 | - | - | - | - | - | - | - |"),
            "{md}"
        );
        assert!(!md.contains("-0.0"), "{md}");
        let csv = results_csv(&rows);
        for l in csv.lines().skip(1) {
            // 15 metric columns, the folder and the warnings: empty.
            assert!(l.ends_with(",error,robot too big,,,,,,,,,,,,,,,,,"), "{l}");
        }
    }

    /// A map file named with a carriage return split its `results.csv` row in two (Python's
    /// `csv` read three rows, pandas two): the field is quoted.
    #[test]
    fn a_carriage_return_in_a_name_is_quoted() {
        let rows = [Row {
            map: "a\rb".into(),
            planner: "bsa".into(),
            outcome: Err("robot too big".into()),
            warnings: Vec::new(),
            dir: PathBuf::from("out/runs/x/bsa"),
        }];
        let csv = results_csv(&rows);
        let row = csv.split('\n').nth(1).unwrap();
        assert!(row.starts_with("\"a\rb\",bsa,error,"), "{row:?}");
    }

    /// Warnings are listed under their map, each after its planner's name, once (the
    /// boxed-in warning names random-bounce itself: it read `random-bounce: random-bounce:`).
    #[test]
    fn warnings_are_listed_under_their_map() {
        let row = |planner: &str, w: &str| Row {
            map: "hall".into(),
            planner: planner.into(),
            outcome: Err("x".into()),
            warnings: vec![w.into()],
            dir: PathBuf::from("out/runs/hall/x"),
        };
        let rows = [
            row("random-bounce", "random-bounce: boxed in: no heading"),
            row("ba-star", "the tile side 0.3 m is wider"),
        ];
        let md = results_md(&rows, &[]);
        assert!(
            md.contains("Warnings:\n\n- random-bounce: boxed in: no heading\n- ba-star: the tile side 0.3 m is wider\n"),
            "{md}"
        );
        let csv = results_csv(&rows);
        assert!(
            csv.contains(",random-bounce: boxed in: no heading\n"),
            "{csv}"
        );
    }

    /// A map named with a newline (from its file name) split its heading in two.
    #[test]
    fn a_map_name_is_one_heading_line() {
        let rows = [Row {
            map: "lab\nb|c".into(),
            planner: "bsa".into(),
            outcome: Err("robot too big".into()),
            warnings: Vec::new(),
            dir: PathBuf::from("out/runs/x/bsa"),
        }];
        let md = results_md(&rows, &[]);
        assert!(md.contains("\n## lab\\nb\\|c\n"), "{md}");
    }
}
