//! `--config FILE`: planner options parsed as the CLI does (`serde_json` for `.json`,
//! `serde_saphyr` otherwise; both parsers get every input), validated as a `Scenario` validates
//! them (values, then each planner's checks against the map and its memory estimate), then every
//! planner that passes built and simulated for a few hundred steps on a small fixed map, so that
//! values nobody would type (negative sides, NaN, huge counts) reach the planners.
#![no_main]

use ccpp_core::planners::settings::Setup;
use ccpp_core::planners::{PlannerKind, PlannerOptions};
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
        if opts.validate().is_err() {
            continue;
        }
        let setup = Setup {
            frame: *world.frame(),
            robot: world.robot(),
            sensor_range: sim.sensor_range_for(&world.robot()),
            max_steps: sim.max_steps,
            noisy: false,
        };
        for &kind in PlannerKind::ALL {
            let config = opts.config(kind);
            let settings = config.settings();
            // The default 4096 MB limit of a run, as `Scenario::check_map` applies it.
            if settings.check(&setup).is_err()
                || !(settings.estimate(&setup).bytes <= 4096.0 * 1024.0 * 1024.0)
            {
                continue;
            }
            let mut planner = settings.build(world);
            let _ = simulate(world, planner.as_mut(), &sim);
        }
    }
});
