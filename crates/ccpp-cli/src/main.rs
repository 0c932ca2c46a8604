//! `ccpp`: complete coverage path planning for mobile robots on occupancy-grid maps.
//!
//! A thin binary: clap arguments -> a validated [`job::Job`] -> dispatch. All the work lives in
//! the `ccpp-core`, `ccpp-io` and `ccpp-render` crates.

/// `eprintln!` that never panics: stderr that cannot be written (`2>/dev/full`, a closed
/// pipe) has no reader to tell, and `eprintln!` panicked there (exit 101) after the run's
/// folder was written (hostile pass). Warnings and errors go through this, one line each:
/// characters a terminal would act on (escape sequences, line breaks, bidirectional
/// overrides), which names and values from the user's files can hold, are written as `\u{..}`
/// ([`ccpp_io::message::visible`]).
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let line = ccpp_io::message::visible(&format!($($arg)*));
        // (nothing to tell when stderr itself fails: see the macro's doc)
        let _ = writeln!(std::io::stderr(), "{line}");
    }};
}

mod args;
mod bench;
mod budget;
mod busy;
use ccpp_io::components;
mod errors;
mod info;
mod job;
mod lock;
mod output;
mod plan;
mod plots;
mod row;
mod staging;
mod waypoints;

use std::fmt::Write as _;
use std::io::Write as _;
use std::process::ExitCode;

use clap::error::ErrorKind;
use clap::{CommandFactory, FromArgMatches};

use crate::args::{Cli, Command};

fn main() -> ExitCode {
    if std::env::args_os()
        .nth(1)
        .is_some_and(|a| a == bench::CHILD_ARG)
    {
        return bench::child_main();
    }
    let matches = match Cli::command().try_get_matches() {
        Ok(m) => m,
        Err(e) => return clap_exit(&e),
    };
    if let Err(msg) = utf8_values(&Cli::command(), &matches) {
        say!("error: {msg}");
        return ExitCode::FAILURE;
    }
    let cli = match Cli::from_arg_matches(&matches) {
        Ok(cli) => cli,
        Err(e) => return clap_exit(&e),
    };
    // Before any parallel work (a bench loads its maps on the process's pool before its first
    // scenario is built; the scenario checks this too, for the library and Python).
    if let Some(why) =
        ccpp_io::scenario::threads_env_problem(std::env::var("RAYON_NUM_THREADS").ok().as_deref())
    {
        say!("error: {why}");
        return ExitCode::FAILURE;
    }
    staging::install_signal_handler();
    let result = dispatch(cli);
    let code = if result.is_ok() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    };
    let code = staging::finish(code);
    if let Err(e) = result {
        say!("error: {}", errors::one_line(&e));
    }
    code
}

/// Refuses an argument that is not valid UTF-8 or holds a control character (of `cmd`, whose
/// parse gave `m`, and of its subcommands), naming the flag and the value. Paths are recorded as text (`run.json`,
/// `bench-key.txt`, exports), so a non-UTF-8 path failed late with a message naming neither
/// ("cannot serialize the run: path contains invalid UTF-8 characters"), or with a false one
/// ("must end in a folder name").
fn utf8_values(cmd: &clap::Command, m: &clap::ArgMatches) -> Result<(), String> {
    for arg in cmd.get_arguments() {
        let id = arg.get_id().as_str();
        let Ok(Some(values)) = m.try_get_raw(id) else {
            continue;
        };
        for v in values {
            let name = || {
                arg.get_long()
                    .map_or_else(|| id.to_uppercase(), |l| format!("--{l}"))
            };
            // Printed raw, a newline cut every message naming the value short and an escape
            // sequence reached the terminal (the check the bench makes of the map files a
            // folder holds, and Python of its paths).
            if let Some(problem) =
                ccpp_io::names::path_text_problem(std::path::Path::new(v), &name())
            {
                return Err(problem);
            }
        }
    }
    if let Some((name, sub)) = m.subcommand() {
        if let Some(c) = cmd.find_subcommand(name) {
            return utf8_values(c, sub);
        }
    }
    Ok(())
}

/// Help and version go to stdout with status 0; argument errors are one line and a hint on
/// stderr with status 1, like every other user error.
fn clap_exit(e: &clap::Error) -> ExitCode {
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
            let _ = e.print();
            ExitCode::SUCCESS
        }
        ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            say!("error: no command given");
            say!("hint: see `ccpp --help`");
            ExitCode::FAILURE
        }
        _ => {
            let (line, hint) = errors::clap_lines(e);
            say!("error: {line}");
            say!("{hint}");
            ExitCode::FAILURE
        }
    }
}

/// Prints `text` on stdout. A closed stdout (`ccpp waypoints ... | head`) is not an error: the
/// reader has what it wanted, so the text is dropped and the command still succeeds.
///
/// # Errors
/// Any other write error.
pub fn print_stdout(text: &str) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(anyhow::Error::new(e).context("cannot write to standard output"))
        }
        _ => Ok(()),
    }
}

/// Runs the job of `ccpp run` or `ccpp demo` with a spinner on a terminal ([`busy`]), then
/// tells whether the robot first drove to a start outside the area.
fn execute(job: &mut job::Job) -> anyhow::Result<job::JobResult> {
    let busy = busy::Busy::start(format!(
        "{} on {}: planning and simulating",
        job.scenario.planner.kind().name(),
        job.map.as_ref().map_or("the map", |m| m.name.as_str())
    ));
    let result = job.execute_with(true);
    busy.done();
    let result = result?;
    if let Some(note) = result.approach_note() {
        say!("{note}");
    }
    Ok(result)
}

fn dispatch(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Run(a) => {
            let mut job = job::Job::from_run_args(&a)?;
            staging::check_user_target(&job.out)?;
            staging::check_inputs(
                &job.out,
                &job.scenario,
                &[a.options.config.as_ref(), a.landmarks.as_ref()],
            )?;
            let result = execute(&mut job)?;
            output::emit(&job, &result, a.json, a.replay, &a.export)
        }
        Command::Demo(a) => {
            let mut job = job::Job::demo(&a)?;
            staging::check_user_target(&job.out)?;
            let result = execute(&mut job)?;
            output::emit(&job, &result, false, true, &[])
        }
        Command::Planners(a) => {
            if let Some(names) = &a.defaults {
                return print_stdout(&job::default_options_yaml(names)?);
            }
            let mut s = String::new();
            for p in ccpp_core::planners::CATALOG {
                let kind = if p.offline { "offline" } else { "online" };
                let _ = writeln!(s, "{:<19} {:<8} {}", p.name, kind, p.description);
            }
            print_stdout(&s)
        }
        Command::Info(a) => info::run(&a),
        Command::Bench(a) => bench::run(&a),
        Command::Replay(a) => output::replay_dir(&a.dir),
        Command::Waypoints(a) => waypoints::run(&a),
        Command::Plan(a) => plan::run(&a),
    }
}
