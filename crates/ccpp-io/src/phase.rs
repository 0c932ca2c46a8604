//! Optional phase timing for the whole process: with the environment variable `CCPP_PHASES`
//! set (to anything), [`time`] prints `phase NAME: MS ms, rss MB (peak MB)` to standard error
//! after each phase (resident memory read from `/proc/self/status` where it exists). Unset,
//! it only calls the closure. Used by `ccpp run` around loading, the world, planning,
//! metrics, rendering and writing; the figures are for profiling, never part of the outputs.

use std::sync::OnceLock;
use std::time::Instant;

fn enabled() -> bool {
    static ON: OnceLock<bool> = OnceLock::new();
    *ON.get_or_init(|| std::env::var_os("CCPP_PHASES").is_some())
}

/// `(VmRSS, VmHWM)` in MB, if the system reports them.
fn rss_mb() -> Option<(f64, f64)> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    let field = |key: &str| -> Option<f64> {
        let line = text.lines().find(|l| l.starts_with(key))?;
        let kb: f64 = line[key.len()..]
            .trim()
            .trim_end_matches("kB")
            .trim()
            .parse()
            .ok()?;
        Some(kb / 1024.0)
    };
    Some((field("VmRSS:")?, field("VmHWM:")?))
}

/// Runs `f`, reporting its time and the memory after it when `CCPP_PHASES` is set.
pub fn time<T>(name: &str, f: impl FnOnce() -> T) -> T {
    if !enabled() {
        return f();
    }
    let t0 = Instant::now();
    let out = f();
    let ms = t0.elapsed().as_secs_f64() * 1e3;
    match rss_mb() {
        Some((rss, peak)) => {
            say(&format!(
                "phase {name}: {ms:.1} ms, rss {rss:.0} MB (peak {peak:.0} MB)"
            ));
        }
        None => say(&format!("phase {name}: {ms:.1} ms")),
    }
    out
}

/// Writes `line` to stderr; a stderr that cannot be written has no reader to tell
/// (`eprintln!` panicked there).
fn say(line: &str) {
    use std::io::Write as _;
    // (see the doc)
    let _ = writeln!(std::io::stderr(), "{line}");
}
