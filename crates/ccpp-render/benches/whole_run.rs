//! The whole `ccpp run` on the generated benchmark maps of `../shared/bench`, in process: load
//! and prepare the map, build the world, plan and simulate, metrics, and render every output
//! file in memory (`render_run_files`: run.json, path.csv, trace.jsonl, coverage.png,
//! metrics.json); only the writing to disk is left out. BA* on `apartment_400x300` and
//! `cluttered_2000` at r = 0.025 m (one pixel per tile) and on `office_1024` / `office_4096` at
//! r = 0.1 m. Select one with e.g. `cargo bench -p ccpp-render --bench whole_run --
//! whole_run/ba-star/apartment`; the `world` group times the world alone. Skips with a note
//! when `../shared/bench` is absent.

use std::path::{Path, PathBuf};
use std::time::Duration;

use ccpp_core::planners::PlannerKind;
use ccpp_io::scenario::Scenario;
use criterion::{criterion_group, criterion_main, Criterion};

fn bench_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/bench")
}

/// One whole run; returns the bytes rendered (so nothing is optimised away).
fn whole_run(scenario: &Scenario) -> usize {
    let map = scenario.map.load().expect("map");
    let run = scenario.run_owned(map).expect("run");
    // As `ccpp run`: the warnings first (the picture shows them), and the picture reuses the
    // swept pixels of the metrics.
    let warnings = ccpp_io::warnings::run_warnings(
        scenario,
        &run.world,
        &run.output.trace,
        &run.metrics,
        &run.swept,
    );
    let files = ccpp_render::run_files::render_run_files_swept(
        scenario,
        &run.world,
        &run.output.trace,
        &run.metrics,
        Some(&run.swept),
        &warnings,
    )
    .expect("files");
    files.iter().map(|(_, b)| b.len()).sum()
}

fn benches(c: &mut Criterion) {
    let mut g = c.benchmark_group("whole_run");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(100))
        .measurement_time(Duration::from_secs(5));
    for (name, r) in [
        ("apartment_400x300", 0.025),
        ("office_1024", 0.1),
        ("cluttered_2000", 0.025),
        ("office_4096", 0.1),
    ] {
        let path = bench_dir().join(format!("{name}.yaml"));
        if !path.is_file() {
            eprintln!("{} not found; skipping", path.display());
            continue;
        }
        let scenario = Scenario::builder(&path, PlannerKind::BaStar)
            .radius(r)
            .build()
            .expect("scenario");
        g.bench_function(format!("ba-star/{name}/r{r}"), |b| {
            b.iter(|| whole_run(&scenario));
        });
    }
    g.finish();
    // The world alone (distance transform, C-free, reachable component, accessible surface):
    // the largest part of a run outside planning, metrics and files.
    let mut g = c.benchmark_group("world");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(100))
        .measurement_time(Duration::from_secs(3));
    for (name, r) in [("cluttered_2000", 0.025), ("office_4096", 0.1)] {
        let path = bench_dir().join(format!("{name}.yaml"));
        if !path.is_file() {
            continue;
        }
        let scenario = Scenario::builder(&path, PlannerKind::BaStar)
            .radius(r)
            .build()
            .expect("scenario");
        let map = scenario.map.load().expect("map");
        g.bench_function(format!("{name}/r{r}"), |b| {
            b.iter(|| scenario.world(&map).expect("world").accessible_count());
        });
    }
    g.finish();
}

criterion_group!(whole, benches);
criterion_main!(whole);
