//! `ccpp`: complete coverage path planning for mobile robots on occupancy-grid maps.
//!
//! A thin binary: clap arguments -> a validated [`job::Job`] -> dispatch. All the work lives in
//! the `ccpp-core`, `ccpp-io` and `ccpp-render` crates.

mod args;
mod bench;
mod info;
mod job;
mod output;
mod plots;
mod waypoints;

use std::process::ExitCode;

use clap::Parser;

use crate::args::{Cli, Command};

fn main() -> ExitCode {
    let cli = Cli::parse();
    match dispatch(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // One line: the problem and its causes.
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn dispatch(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Run(a) => {
            let mut job = job::Job::from_run_args(&a)?;
            let result = job.execute()?;
            output::emit(&job, &result, a.json, a.replay)
        }
        Command::Demo(a) => {
            let mut job = job::Job::demo(&a)?;
            let result = job.execute()?;
            output::emit(&job, &result, false, true)
        }
        Command::Planners => {
            for p in ccpp_core::planners::CATALOG {
                let kind = if p.offline { "offline" } else { "online" };
                println!("{:<19} {:<8} {}", p.name, kind, p.description);
            }
            Ok(())
        }
        Command::Info(a) => info::run(&a),
        Command::Bench(a) => bench::run(&a),
        Command::Replay(a) => output::replay_dir(&a.dir),
        Command::Waypoints(a) => waypoints::run(&a),
    }
}
