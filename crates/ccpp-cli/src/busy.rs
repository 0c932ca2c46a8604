//! A spinner on standard error while a long step runs, so that a run on a large map does not
//! sit silent: `ccpp run` and `ccpp demo` while the planner plans and the simulator drives and
//! while the files are written, `ccpp plan` while it plans (bcd on the 4 M pixel `cluttered_2000` bench map takes about
//! 30 s). Drawn only when standard error is a terminal, and cleared before anything else is
//! printed: piped or redirected output, and every file, are the same as without it.

use std::io::IsTerminal;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// How often the spinner turns.
const TICK: Duration = Duration::from_millis(120);

/// The spinner of one step; cleared when dropped (or by [`Busy::done`]).
pub struct Busy(Option<ProgressBar>);

impl Busy {
    /// Starts the spinner with `what` (e.g. `bcd on office_1024: planning`), when standard
    /// error is a terminal; else does nothing.
    pub fn start(what: String) -> Self {
        if !std::io::stderr().is_terminal() {
            return Self(None);
        }
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        bar.set_message(what);
        // The first frame now, from this thread (the ticker thread's first may come after a
        // short step has ended).
        bar.tick();
        bar.enable_steady_tick(TICK);
        Self(Some(bar))
    }

    /// Clears the spinner (before the step's results are printed).
    pub fn done(self) {
        drop(self);
    }
}

impl Drop for Busy {
    fn drop(&mut self) {
        if let Some(bar) = self.0.take() {
            bar.finish_and_clear();
        }
    }
}
