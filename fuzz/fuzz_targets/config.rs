//! `--config FILE`: planner options parsed as the CLI does (`serde_json` for `.json`,
//! `serde_saphyr` otherwise; both parsers get every input), then every planner of the catalogue
//! built with them and simulated for a few hundred steps on a small fixed map, so that values
//! nobody would type (negative sides, NaN, huge counts) reach the planners.
#![no_main]

use ccpp_core::planners::{self, PlannerOptions};
use ccpp_core::sim::{simulate, SimConfig};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let json = serde_json::from_str::<PlannerOptions>(text);
    let yaml = serde_saphyr::from_str::<PlannerOptions>(text);
    for opts in [json.ok(), yaml.ok()].into_iter().flatten() {
        let world = ccpp_fuzz::tiny_world();
        let sim = SimConfig {
            max_steps: 300,
            ..SimConfig::default()
        };
        for p in planners::CATALOG {
            if let Ok(mut planner) = planners::build(p.name, &opts, world) {
                let _ = simulate(world, planner.as_mut(), &sim);
            }
        }
    }
});
