//! Headless Chromium for the page tests of `ccpp-render` and `ccpp-cli` (the CLI's tests include
//! this file by path): where the browser is, and a call of it that cannot hang the suite.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::Duration;

/// The headless browser the page tests drive, where one is installed.
pub fn chromium() -> Option<PathBuf> {
    [
        "/usr/bin/chromium",
        "/usr/bin/chromium-browser",
        "/usr/bin/google-chrome",
    ]
    .iter()
    .map(PathBuf::from)
    .find(|p| p.is_file())
}

/// [`chromium`], or `None` after saying that the browser part is skipped; under CI (`CI` set)
/// a missing browser fails the test instead (CI installs it, see `.ci/run`).
///
/// # Panics
/// Under CI without a browser.
pub fn require_chromium() -> Option<PathBuf> {
    let c = chromium();
    if c.is_none() {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI must install chromium (see .ci/run)"
        );
        eprintln!("chromium not found; skipping the browser part");
    }
    c
}

/// A headless Chromium command for `chrome` with its own profile folder `profile`: no GPU, no
/// network side traffic, console messages on stderr (the page tests look there for errors).
/// Callers add their own window size, virtual time and action.
pub fn headless(chrome: &Path, profile: &Path) -> Command {
    let mut c = Command::new(chrome);
    c.args([
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--enable-logging=stderr",
        "--v=0",
    ])
    .arg(format!("--user-data-dir={}", profile.display()));
    c
}

/// How long one browser call of a page test may take: a page that never loads, or a browser
/// that waits on something, fails its test instead of hanging the suite.
pub const BROWSER_LIMIT: Duration = Duration::from_mins(2);

/// [`output_within`] at [`BROWSER_LIMIT`].
pub fn output_within_limit(c: &mut Command) -> Output {
    output_within(c, BROWSER_LIMIT)
}

/// Runs `c` in a process group of its own and returns its output, or kills the whole group (a
/// browser's helper processes too) and panics once it has run `limit`.
///
/// # Panics
/// When the command cannot start, or runs out of time.
pub fn output_within(c: &mut Command, limit: Duration) -> Output {
    use std::os::unix::process::CommandExt;
    let child = c
        .process_group(0)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the command starts");
    let pid = child.id();
    let (tx, rx) = std::sync::mpsc::channel();
    let waiter = std::thread::spawn(move || {
        // (the receiver is gone only when this test has already failed)
        let _ = tx.send(child.wait_with_output());
    });
    if let Ok(out) = rx.recv_timeout(limit) {
        return out.expect("the command runs");
    }
    // Out of time: the group's id is the command's pid (`process_group(0)`).
    let killed = Command::new("kill")
        .args(["-KILL", "--", &format!("-{pid}")])
        .status();
    // (its output, if any, is not wanted any more; the join only reaps the waiter)
    let _ = waiter.join();
    panic!(
        "{} did not finish within {limit:?} (killed: {killed:?})",
        std::path::Path::new(c.get_program()).display()
    );
}

/// A command that outlives its limit fails its test, and its whole process group is gone
/// (a browser's helpers would otherwise live on after the test).
#[test]
fn a_command_past_its_limit_is_killed_with_its_group() {
    let pid_file = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("group-kill-{}.pid", std::process::id()));
    let mut c = Command::new("sh");
    c.arg("-c")
        .arg(format!("sleep 60 & echo $! > {}; wait", pid_file.display()));
    let t0 = std::time::Instant::now();
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        output_within(&mut c, Duration::from_secs(1))
    }));
    assert!(r.is_err(), "a minute's sleep finished within a second");
    assert!(t0.elapsed() < Duration::from_secs(30));
    let pid = std::fs::read_to_string(&pid_file).expect("the pid file");
    // (a leftover file changes nothing: the next run writes its own)
    let _ = std::fs::remove_file(&pid_file);
    let stat = std::path::Path::new("/proc").join(pid.trim()).join("stat");
    // The group's `sleep` is gone, or a zombie waiting for whoever adopted it.
    let t1 = std::time::Instant::now();
    while let Ok(s) = std::fs::read_to_string(&stat) {
        if s.rsplit(')')
            .next()
            .is_some_and(|r| r.trim_start().starts_with('Z'))
        {
            break;
        }
        assert!(
            t1.elapsed() < Duration::from_secs(10),
            "the group's sleep lives on: {s}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}
