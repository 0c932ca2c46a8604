//! How a run executes its motions when the caller asks beside the planner's options: ideal or
//! PID execution, odometry noise and its seed. The command line (`--exec`, `--odometry-noise`,
//! `--seed`) and Python (`exec=`, `odometry_noise=`, `seed=`) ask the same things and get the
//! same [`Execution`] and the same refusals from [`execution`]; only the names differ
//! ([`Names`]).
//!
//! ```
//! use ccpp_core::exec::Execution;
//! use ccpp_core::planners::PlannerKind;
//! use ccpp_io::execution::{execution, ExecAsk, Names};
//! let ask = ExecAsk { noise: Some(vec![0.02]), seed: Some(7), ..ExecAsk::default() };
//! let run = execution(PlannerKind::BaStar, None, &ask, &Names::FLAGS).unwrap();
//! let Some(Execution::Pid(p)) = run else { panic!("{run:?}") };
//! let n = p.noise.unwrap();
//! assert_eq!((n.linear_rel_std, n.angular_rel_std, n.heading_drift_std), (0.02, 0.02, 0.0));
//! assert_eq!(n.seed, 7);
//! // No noise at all is refused: it would run as `--exec pid`.
//! let zero = ExecAsk { noise: Some(vec![0.0]), ..ExecAsk::default() };
//! let e = execution(PlannerKind::BaStar, None, &zero, &Names::FLAGS).unwrap_err();
//! assert!(e.contains("draws no noise"), "{e}");
//! ```

use ccpp_core::display::{join, Compact};
use ccpp_core::exec::{Execution, OdometryNoise, PidOptions};
use ccpp_core::planners::settings::{noise_too_small, MIN_NOISE_STD};
use ccpp_core::planners::PlannerKind;

/// What the caller asks of the execution.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExecAsk {
    /// `Some(true)`: PID execution; `Some(false)`: ideal; `None`: the planner's own.
    pub pid: Option<bool>,
    /// Odometry noise `[LIN, ANG, DRIFT]`, one to three numbers (ANG defaults to LIN, DRIFT
    /// to 0); it switches an ideal run to PID execution.
    pub noise: Option<Vec<f64>>,
    /// The seed asked for (of the noise, when there is some).
    pub seed: Option<u64>,
    /// Where the planner's options give its odometry noise, even as `null` (`noise` would
    /// replace it, so the two are refused together; so is a noise in `preferred`), e.g.
    /// `n.yaml (bsa_bfs.exec.pid.noise)`.
    pub noise_given_in: Option<String>,
    /// Where the planner's options give its PID execution, when they do (an ideal execution
    /// asked for would drop it), e.g. `n.yaml (bsa_bfs.exec)`.
    pub pid_given_in: Option<String>,
}

/// The names the caller's user typed, for the messages.
#[derive(Clone, Copy, Debug)]
pub struct Names {
    /// The execution choice (`--exec`).
    pub exec: &'static str,
    /// The odometry noise (`--odometry-noise`).
    pub noise: &'static str,
    /// The seed (`--seed`).
    pub seed: &'static str,
}

impl Names {
    /// The command line's flags.
    pub const FLAGS: Names = Names {
        exec: "--exec",
        noise: "--odometry-noise",
        seed: "--seed",
    };
    /// Python's keywords.
    pub const KEYWORDS: Names = Names {
        exec: "exec",
        noise: "odometry_noise",
        seed: "seed",
    };
}

/// The execution choice as typed (`ideal` or `pid`, without regard to case): `Some(true)` for
/// PID, `Some(false)` for ideal, `None` when none is given ([`ExecAsk::pid`]).
///
/// # Errors
/// Any other text, named by `names.exec`.
pub fn exec_choice(text: Option<&str>, names: &Names) -> Result<Option<bool>, String> {
    match text.map(str::to_ascii_lowercase).as_deref() {
        None => Ok(None),
        Some("ideal") => Ok(Some(false)),
        Some("pid") => Ok(Some(true)),
        Some(other) => Err(format!(
            "{} must be ideal or pid, got {other:?}",
            names.exec
        )),
    }
}

/// The execution of a run of `kind` for `ask`, given the planner's own (`preferred`, from its
/// options): `None` leaves the planner's own. The seed is used for the noise here
/// (random-bounce also takes it as its option, which the caller sets).
///
/// # Errors
/// A message naming what was asked: noise of other than one to three finite numbers >= 0,
/// noise that draws nothing (it would run as PID execution without noise), noise beside an
/// ideal execution or beside the planner's own noise, an ideal execution that would drop the
/// planner's PID settings, a seed with nothing to seed.
pub fn execution(
    kind: PlannerKind,
    preferred: Option<Execution>,
    ask: &ExecAsk,
    names: &Names,
) -> Result<Option<Execution>, String> {
    let Names { exec, noise, seed } = *names;
    let mut pid = match preferred {
        Some(Execution::Pid(p)) => p,
        _ => PidOptions::default(),
    };
    if ask.pid == Some(false) {
        if let Some(place) = &ask.pid_given_in {
            return Err(format!(
                "{exec} ideal drops the PID settings given for {kind} in {place}; remove one of them"
            ));
        }
    }
    let mut noise_given = false;
    if let Some(v) = &ask.noise {
        let shown = join(v);
        if v.is_empty() || v.len() > 3 || v.iter().any(|x| !x.is_finite() || *x < 0.0) {
            return Err(format!(
                "{noise} expects one to three finite numbers >= 0 (LIN[,ANG[,DRIFT]]), got {shown}"
            ));
        }
        if ask.pid == Some(false) {
            return Err(format!("{noise} needs PID execution, not {exec} ideal"));
        }
        if v.iter().all(|x| *x == 0.0) {
            // It would run exactly as PID execution without noise (and change nothing for a
            // planner that executes by PID already): a value read and dropped.
            return Err(format!(
                "{noise} {shown} draws no noise: give a noise of at least {}, or use {exec} pid for PID execution without noise",
                Compact(MIN_NOISE_STD)
            ));
        }
        if let Some(why) = v.iter().find_map(|x| noise_too_small(*x)) {
            return Err(format!("{noise} {shown}: {why}"));
        }
        if pid.noise.is_some() || ask.noise_given_in.is_some() {
            let place = ask.noise_given_in.as_deref().unwrap_or("its options");
            // `noise: null` (as `planners --defaults` prints it) sets the option too: the
            // message names the setting, not a noise that may not be there (hostile pass).
            return Err(format!(
                "{noise} and the odometry noise setting of {kind} in {place} set the same option; remove one of them"
            ));
        }
        // Exactly the noise asked for: a heading drift left out is 0, not the library's
        // default (`--odometry-noise 0` used to drift 0.2 rad per metre).
        pid.noise = Some(OdometryNoise {
            seed: ask.seed.unwrap_or(0),
            linear_rel_std: v[0],
            angular_rel_std: v.get(1).copied().unwrap_or(v[0]),
            heading_drift_std: v.get(2).copied().unwrap_or(0.0),
        });
        noise_given = true;
    }
    if ask.seed.is_some() && !noise_given && kind != PlannerKind::RandomBounce {
        // A noise from the planner's options has its own seed there (the refusal said the
        // seed did not apply to a run that was noisy and seeded; hostile pass).
        if pid.noise.is_some() {
            let place = ask.noise_given_in.as_deref().unwrap_or("its options");
            return Err(format!(
                "{seed} seeds {noise}; the odometry noise of {kind} given in {place} takes its seed from there (noise.seed, 0 when left out): set noise.seed there instead"
            ));
        }
        return Err(format!(
            "{seed} does not apply to {kind} (it applies to random-bounce and {noise})"
        ));
    }
    Ok(match ask.pid {
        Some(false) => Some(Execution::Ideal),
        Some(true) => Some(Execution::Pid(pid)),
        None if noise_given => Some(Execution::Pid(pid)),
        None => None,
    })
}
