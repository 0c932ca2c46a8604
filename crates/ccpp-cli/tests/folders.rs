//! End-to-end tests of what the output folders hold and who writes them: one bench at a time
//! on a folder, a user's files never taken for ccpp's (`plots/`, `*.tmp`), the replay's two
//! files written together, a failed bench summary removed whole, and `--out` names up to the
//! file system's 255 bytes.
#![allow(clippy::unwrap_used)]

use std::path::{Path, PathBuf};
use std::process::Stdio;

use assert_cmd::Command;

use crate::common::{ccpp, data, wait_for_pause};

/// Entry names of a folder, sorted.
fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        // (ccpp's stamp, in every folder it writes: `folders.rs` tests it)
        .filter(|n| n != ".ccpp")
        .collect();
    v.sort();
    v
}

/// `ccpp run --planner PLANNER` on the bundled `teb_empty_box` into `out`, which must succeed.
fn run_box(planner: &str, out: &Path) {
    ccpp()
        .args(["run", "--planner", planner, "--map"])
        .arg(data("teb_empty_box.yaml"))
        .arg("--out")
        .arg(out)
        .assert()
        .success();
}

/// Every file of a folder with its bytes, by name.
fn contents(dir: &Path) -> Vec<(String, Vec<u8>)> {
    entries(dir)
        .into_iter()
        .map(|n| {
            let bytes = std::fs::read(dir.join(&n)).unwrap();
            (n, bytes)
        })
        .collect()
}

fn stderr_of(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

const BASE_SET: [&str; 5] = [
    "coverage.png",
    "metrics.json",
    "path.csv",
    "run.json",
    "trace.jsonl",
];

const LOCK_FILE: &str = ".ccpp-bench.lock";

fn bench(out: &Path, planners: &str) -> Command {
    let mut c = ccpp();
    c.args(["bench", "--quiet", "--jobs", "1", "--planners", planners])
        .arg("--maps")
        .arg(data("teb_empty_box.yaml"))
        .arg("--out")
        .arg(out);
    c
}

/// A 600 x 600 px (30 x 30 m) room with pillars: a bench on it takes long enough to be caught
/// running.
fn slow_map(dir: &Path) -> PathBuf {
    crate::common::pillared_room(dir, "slow_room.png", 600)
}

/// Two benches on one `--out` at once wrote over each other and left a mixed folder, both
/// exiting 0. The second is now refused while the first runs, naming the first's process; the
/// lock goes with the first, on an interrupt too, and one left by a killed bench is taken over.
#[cfg(unix)]
#[test]
fn a_second_bench_on_a_folder_in_use_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let map = slow_map(dir.path());
    let out = dir.path().join("bb");
    let mut first = std::process::Command::new(assert_cmd::cargo::cargo_bin("ccpp"))
        .args(["bench", "--quiet", "--jobs", "1"])
        .args(["--planners", "ba-star,bsa,bcd,random-bounce", "--maps"])
        .arg(&map)
        .arg("--out")
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let lock = out.join(LOCK_FILE);
    let t0 = std::time::Instant::now();
    while !std::fs::read_to_string(&lock).is_ok_and(|t| t.ends_with('\n'))
        && t0.elapsed() < std::time::Duration::from_secs(30)
    {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    assert!(lock.is_file(), "the running bench holds no lock file");
    let still_running = first.try_wait().unwrap().is_none();
    let o = bench(&out, "bsa")
        .arg("--radius")
        .arg("0.2")
        .assert()
        .code(1)
        .get_output()
        .clone();
    assert!(
        still_running,
        "the first bench ended before the second started"
    );
    assert_eq!(
        stderr_of(&o),
        format!(
            "error: {} is in use by another ccpp bench or sweep (pid {})\n",
            out.display(),
            first.id()
        )
    );
    // Stopped, the first removes its lock file with its partial summary.
    let _ = std::process::Command::new("kill")
        .arg("-TERM")
        .arg(first.id().to_string())
        .status();
    let status = first.wait().unwrap();
    assert!(status.code() == Some(130) || status.success(), "{status:?}");
    assert!(!lock.exists(), "lock file left by an interrupted bench");
    // A lock file left by a killed bench (no process holds it) is taken over.
    std::fs::write(&lock, "4294967295\n").unwrap();
    bench(&out, "bsa").assert().success();
    let names = entries(&out);
    assert_eq!(names, ["plots", "results.csv", "results.md", "runs"]);
}

/// `bench` removed every PNG and SVG in `OUT/plots/`, a user's own figure too. Only the plots a
/// bench writes are its own; anything else there is refused, as at the top of the folder.
#[test]
fn bench_keeps_a_users_files_in_plots_and_refuses_the_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bf6");
    std::fs::create_dir_all(out.join("plots")).unwrap();
    std::fs::write(out.join("plots/my_figure.png"), "fig").unwrap();
    let o = bench(&out, "bsa").assert().code(1).get_output().clone();
    let err = stderr_of(&o);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("error: ") && err.contains("plots/my_figure.png"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("plots/my_figure.png")).unwrap(),
        "fig"
    );
    assert_eq!(
        entries(&out),
        ["plots"],
        "the refused bench wrote something"
    );
    // A bench's own old plots (of a map this bench does not have, whose run folders an
    // earlier bench left in `runs/`) still go; one of no such map is a user's, refused; a
    // stray `.tmp` at the top that a bench does not write is refused like any other file.
    std::fs::remove_file(out.join("plots/my_figure.png")).unwrap();
    // (an empty `plots/` of no bench: taken as a bench's once the folder holds ccpp's stamp)
    std::fs::write(out.join(".ccpp"), "stamp").unwrap();
    bench(&out, "bsa").assert().success();
    std::fs::write(out.join("plots/coverage_gone.png"), "old").unwrap();
    let o = bench(&out, "bsa").assert().code(1).get_output().clone();
    assert!(
        stderr_of(&o).contains("plots/coverage_gone.png"),
        "{}",
        stderr_of(&o)
    );
    std::fs::create_dir_all(out.join("runs/gone/bsa")).unwrap();
    bench(&out, "bsa").assert().success();
    assert!(!out.join("plots/coverage_gone.png").exists());
    std::fs::write(out.join("thesis.tmp"), "precious").unwrap();
    let o = bench(&out, "bsa").assert().code(1).get_output().clone();
    assert!(stderr_of(&o).contains("thesis.tmp"), "{}", stderr_of(&o));
    assert_eq!(
        std::fs::read_to_string(out.join("thesis.tmp")).unwrap(),
        "precious"
    );
}

/// `run` and `plan` of bcd on the bundled `teb_empty_box` into `out` both refuse it in one
/// `error:` line holding `needle`, leaving exactly the entries `left`.
fn run_and_plan_refuse(out: &Path, needle: &str, left: &[&str]) {
    for sub in ["run", "plan"] {
        let o = ccpp()
            .args([sub, "--planner", "bcd", "--map"])
            .arg(data("teb_empty_box.yaml"))
            .arg("--out")
            .arg(out)
            .assert()
            .code(1)
            .get_output()
            .clone();
        let err = stderr_of(&o);
        assert!(
            err.starts_with("error: ")
                && err.contains(needle)
                && err.trim_end().lines().count() == 1,
            "{sub}: {err}"
        );
        assert_eq!(entries(out), left, "{sub}");
    }
}

/// `run` and `plan` took any `*.tmp` in `--out` for their own and deleted it with the old
/// folder. Only the `.tmp` of a file ccpp writes is its own.
#[test]
fn run_and_plan_refuse_a_users_tmp_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("u");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("thesis.tmp"), "precious").unwrap();
    run_and_plan_refuse(&out, "holds thesis.tmp", &["thesis.tmp"]);
    // The `.tmp` of a file ccpp writes (left by an interrupted `ccpp replay` in a run folder,
    // which holds ccpp's stamp) is its own.
    std::fs::remove_file(out.join("thesis.tmp")).unwrap();
    std::fs::write(out.join(".ccpp"), "stamp").unwrap();
    std::fs::write(out.join("replay.html.tmp"), "cut short").unwrap();
    run_box("bcd", &out);
    assert_eq!(entries(&out), BASE_SET);
}

/// A folder was taken for ccpp's by its files' names alone: a user's own `path.csv` and
/// `metrics.json` in a folder given to `--out` were deleted with it (hostile pass, stop 70).
/// Only a folder holding ccpp's `.ccpp` stamp is replaced; every folder ccpp writes holds it.
#[test]
fn a_folder_of_files_named_as_ccpps_without_its_stamp_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("mine");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("path.csv"), "my precious data").unwrap();
    std::fs::write(out.join("metrics.json"), "not json").unwrap();
    run_and_plan_refuse(
        &out,
        "holds metrics.json but no .ccpp stamp",
        &["metrics.json", "path.csv"],
    );
    assert_eq!(
        std::fs::read_to_string(out.join("path.csv")).unwrap(),
        "my precious data"
    );
    // What ccpp writes it may replace: a run's folder, then a plan into it, then a run again.
    let ours = dir.path().join("ours");
    run_box("bcd", &ours);
    assert!(ours.join(".ccpp").is_file());
    ccpp()
        .args(["plan", "--planner", "bcd", "--map"])
        .arg(data("teb_empty_box.yaml"))
        .arg("--out")
        .arg(&ours)
        .assert()
        .success();
    assert_eq!(entries(&ours), ["nav_path.yaml", "waypoints.csv"]);
    assert!(ours.join(".ccpp").is_file());
    run_box("bcd", &ours);
}

/// `ccpp bench` overwrote a user's own `results.csv` and `results.md` in a folder of theirs,
/// and `ccpp replay` a user's own `replay.html` in a run folder without the stamp, or wrote
/// beside a file of theirs (hostile pass, stop 70). Both now want ccpp's stamp; a bench's
/// folder holds it, so a second bench there resumes.
#[test]
fn bench_and_replay_refuse_a_folder_ccpp_did_not_write() {
    let dir = tempfile::tempdir().unwrap();
    let mine = dir.path().join("mine");
    std::fs::create_dir(&mine).unwrap();
    std::fs::write(mine.join("results.csv"), "my table").unwrap();
    let o = bench(&mine, "bsa").assert().code(1).get_output().clone();
    let err = stderr_of(&o);
    assert!(
        err.starts_with("error: ")
            && err.contains("holds results.csv but no .ccpp stamp")
            && err.trim_end().lines().count() == 1,
        "{err}"
    );
    assert_eq!(entries(&mine), ["results.csv"]);
    assert_eq!(
        std::fs::read_to_string(mine.join("results.csv")).unwrap(),
        "my table"
    );
    // A bench's own folder: stamped, and a second bench there resumes its run.
    let b = dir.path().join("b");
    bench(&b, "bsa").assert().success();
    assert!(b.join(".ccpp").is_file());
    let run_file = b.join("runs/teb_empty_box/bsa/trace.jsonl");
    let before = std::fs::metadata(&run_file).unwrap().modified().unwrap();
    bench(&b, "bsa").assert().success();
    // (the finished run kept, not redone)
    assert_eq!(
        std::fs::metadata(&run_file).unwrap().modified().unwrap(),
        before
    );
    assert!(b.join("results.csv").is_file());
    // Replay: a run folder whose stamp is gone, or that holds a file of the user's.
    let run = dir.path().join("r");
    run_box("bsa", &run);
    let replay = |want: &str| {
        let o = ccpp()
            .arg("replay")
            .arg(&run)
            .assert()
            .code(1)
            .get_output()
            .clone();
        let err = stderr_of(&o);
        assert!(
            err.starts_with("error: ") && err.contains(want) && err.trim_end().lines().count() == 1,
            "{err}"
        );
        assert!(!run.join("replay.html").exists());
    };
    std::fs::write(run.join("notes.txt"), "mine").unwrap();
    replay("holds notes.txt, which ccpp did not write");
    std::fs::remove_file(run.join("notes.txt")).unwrap();
    std::fs::remove_file(run.join(".ccpp")).unwrap();
    replay("has no .ccpp stamp");
}

/// `ccpp replay` wrote `replay.html` and then `replay.gif`: a failure between them left the page
/// without its GIF, or a new page beside the GIF of an earlier replay. Both or neither now.
#[test]
fn replay_writes_its_page_and_gif_together() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    run_box("bcd", &out);
    let replay = |fail: &str| {
        let mut c = ccpp();
        c.arg("replay").arg(&out);
        if !fail.is_empty() {
            c.env("CCPP_TEST_FAIL_WRITE", fail);
        }
        c
    };
    for fail in ["replay.html", "replay.gif"] {
        let o = replay(fail).assert().code(1).get_output().clone();
        let err = stderr_of(&o);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(fail) && err.contains("os error 28"), "{err}");
        assert_eq!(entries(&out), BASE_SET, "{fail}: no replay at all");
    }
    // An earlier replay stays whole when the new one fails.
    std::fs::write(out.join("replay.html"), "old page").unwrap();
    std::fs::write(out.join("replay.gif"), "old gif").unwrap();
    for fail in ["replay.html", "replay.gif"] {
        replay(fail).assert().code(1);
        assert_eq!(
            std::fs::read_to_string(out.join("replay.html")).unwrap(),
            "old page",
            "{fail}"
        );
        assert_eq!(
            std::fs::read_to_string(out.join("replay.gif")).unwrap(),
            "old gif",
            "{fail}"
        );
        assert_eq!(
            entries(&out).len(),
            BASE_SET.len() + 2,
            "{fail}: stray file"
        );
    }
    replay("").assert().success();
    assert!(std::fs::read(out.join("replay.gif"))
        .unwrap()
        .starts_with(b"GIF8"));
    assert!(std::fs::read_to_string(out.join("replay.html"))
        .unwrap()
        .contains("<html"));
    assert_eq!(entries(&out).len(), BASE_SET.len() + 2);
}

/// A bench that failed while writing its summary (a full disk) left some of its plots; the
/// error path now removes what the summary wrote, as the interrupt path does, and keeps the
/// complete run folders.
#[test]
fn a_failed_bench_summary_leaves_no_part_of_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bench");
    bench(&out, "bsa,bcd").assert().success();
    for fail in ["summary.png", "results.md", "results.csv"] {
        let o = bench(&out, "bsa,bcd")
            .env("CCPP_TEST_FAIL_WRITE", fail)
            .assert()
            .code(1)
            .get_output()
            .clone();
        let err = stderr_of(&o);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(fail) && err.contains("os error 28"), "{err}");
        assert_eq!(entries(&out), ["runs"], "{fail}: a partial summary");
        for p in ["bsa", "bcd"] {
            let run = out.join("runs/teb_empty_box").join(p);
            assert!(run.join("metrics.json").is_file(), "{fail}: run {p} lost");
        }
    }
    bench(&out, "bsa,bcd").assert().success();
    assert_eq!(
        entries(&out),
        ["plots", "results.csv", "results.md", "runs"]
    );
}

/// A legal long `--out` name failed with "File name too long": the staging folder's name added
/// 20-odd bytes to it. Any name the file system takes works now, and is replaced on a rerun.
#[test]
fn run_and_plan_take_the_longest_folder_name() {
    let dir = tempfile::tempdir().unwrap();
    for (sub, c) in [("run", "a"), ("plan", "\u{e9}")] {
        let name = c.repeat(255 / c.len());
        let out = dir.path().join(&name);
        for _ in 0..2 {
            ccpp()
                .args([sub, "--planner", "bcd", "--map"])
                .arg(data("teb_empty_box.yaml"))
                .arg("--out")
                .arg(&out)
                .assert()
                .success();
        }
        assert!(out.is_dir(), "{sub}");
        assert!(!entries(&out).is_empty(), "{sub}");
    }
    assert_eq!(entries(dir.path()).len(), 2, "stray staging folder");
}

/// A `ccpp run` into a folder while `ccpp replay` of its old run was rendering: the replay wrote
/// the old run's page and GIF beside the new run's files, a folder mixing two runs. Now it
/// writes into the folder it read or not at all. (The swap is made here as a run makes it:
/// the old folder renamed away, the new one renamed in under the same name.)
#[test]
fn a_replay_never_writes_into_a_folder_swapped_in_meanwhile() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    let new = dir.path().join("new");
    for (d, planner) in [(&out, "bcd"), (&new, "ba-star")] {
        ccpp()
            .args(["run", "--planner", planner, "--map"])
            .arg(data("teb_empty_box.yaml"))
            .arg("--out")
            .arg(d)
            .assert()
            .success();
    }
    let child = std::process::Command::new(assert_cmd::cargo::cargo_bin("ccpp"))
        .arg("replay")
        .arg(&out)
        .env("CCPP_TEST_REPLAY_PAUSE_MS", "3000")
        .env("CCPP_TEST_PAUSED_FILE", dir.path().join("paused"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The replay has read the run and waits three seconds.
    wait_for_pause(&dir.path().join("paused"));
    std::fs::rename(&out, dir.path().join("old")).unwrap();
    std::fs::rename(&new, &out).unwrap();
    let o = child.wait_with_output().unwrap();
    let err = stderr_of(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("was replaced by another run while its replay was made"),
        "{err}"
    );
    assert_eq!(entries(&out), BASE_SET, "the new run's folder is untouched");
    assert_eq!(entries(&dir.path().join("old")), BASE_SET);
    // Replayed again, the folder's own run is drawn.
    ccpp().arg("replay").arg(&out).assert().success();
    let page = std::fs::read_to_string(out.join("replay.html")).unwrap();
    assert!(page.contains("ba-star on teb_empty_box"));
}

/// Two `ccpp replay` of one run at once: both wrote `replay.html.tmp`, and the second's rename
/// found the file already renamed by the first ("No such file"), so one failed. The second now
/// waits for the first's files to be renamed in, and both succeed.
#[test]
fn two_replays_of_one_run_at_once_both_succeed() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    run_box("ba-star", &out);
    let first = std::process::Command::new(assert_cmd::cargo::cargo_bin("ccpp"))
        .arg("replay")
        .arg(&out)
        .env("CCPP_TEST_COMMIT_PAUSE_MS", "3000")
        .env("CCPP_TEST_PAUSED_FILE", dir.path().join("paused"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The first waits three seconds with its files written beside their names.
    wait_for_pause(&dir.path().join("paused"));
    let second = ccpp().arg("replay").arg(&out).output().unwrap();
    let first = first.wait_with_output().unwrap();
    assert!(first.status.success(), "{}", stderr_of(&first));
    assert!(second.status.success(), "{}", stderr_of(&second));
    let mut want: Vec<String> = BASE_SET.iter().map(|s| (*s).to_string()).collect();
    want.extend(["replay.gif".into(), "replay.html".into()]);
    want.sort();
    assert_eq!(entries(&out), want);
    let page = std::fs::read_to_string(out.join("replay.html")).unwrap();
    assert!(page.contains("ba-star on teb_empty_box"));
}

/// A replay whose run folder another process holds (a replay stopped with Ctrl-Z) waits for it,
/// says so, and after the wait (a minute; shortened here by the test hook) gives up with one
/// error line, writing nothing; once the folder is free, the replay is written.
#[test]
fn a_replay_gives_up_on_a_folder_held_too_long_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    run_box("ba-star", &out);
    let before = contents(&out);
    // This process holds the folder as a writing replay would.
    let held = std::fs::File::open(&out).unwrap();
    held.lock().unwrap();
    let t0 = std::time::Instant::now();
    let o = ccpp()
        .arg("replay")
        .arg(&out)
        .env("CCPP_TEST_WRITER_WAIT_MS", "1500")
        .output()
        .unwrap();
    let waited = t0.elapsed();
    let err = stderr_of(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("note: waiting for another process writing"),
        "{err}"
    );
    let last: Vec<&str> = err.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(last.len(), 1, "{err}");
    assert!(
        last[0].contains("held by another process writing it for over a minute")
            && last[0].contains("nothing was written"),
        "{err}"
    );
    assert!(
        waited >= std::time::Duration::from_millis(1500),
        "{waited:?}"
    );
    assert_eq!(contents(&out), before, "the folder changed");
    held.unlock().unwrap();
    ccpp().arg("replay").arg(&out).assert().success();
    assert!(out.join("replay.html").is_file() && out.join("replay.gif").is_file());
}

/// A user's run, plan or demo into a bench's run folder (`runs/MAP/PLANNER`, holding its
/// `bench-key.txt`) is refused: `ccpp demo --out b/runs/teb_empty_box/ba-star` put another
/// map's run there under the bench's `results.csv` (hostile pass). `ccpp replay` of it, which
/// adds to the bench's run, still works, and so does a bench's rerun into it.
#[test]
fn a_users_run_into_a_bench_run_folder_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b");
    let bench = || {
        ccpp()
            .args(["bench", "--quiet", "--planners", "ba-star", "--maps"])
            .arg(data("teb_empty_box.yaml"))
            .arg("--out")
            .arg(&out)
            .assert()
            .success();
    };
    bench();
    let run_dir = out.join("runs/teb_empty_box/ba-star");
    let before = std::fs::read(run_dir.join("path.csv")).unwrap();
    for (cmd, planner) in [("run", "bsa"), ("plan", "bcd")] {
        let o = ccpp()
            .args([cmd, "--planner", planner, "--map"])
            .arg(data("teb_empty_box.yaml"))
            .arg("--out")
            .arg(&run_dir)
            .output()
            .unwrap();
        let err = stderr_of(&o);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert!(
            err.starts_with("error: output folder ")
                && err.contains("is a run of a ccpp bench (it holds bench-key.txt)"),
            "{err}"
        );
        assert_eq!(err.lines().count(), 1, "{err}");
    }
    let demo = ccpp()
        .args(["demo", "--out"])
        .arg(&run_dir)
        .output()
        .unwrap();
    assert_eq!(demo.status.code(), Some(1), "{}", stderr_of(&demo));
    assert_eq!(std::fs::read(run_dir.join("path.csv")).unwrap(), before);
    ccpp().arg("replay").arg(&run_dir).assert().success();
    std::fs::remove_file(run_dir.join("bench-key.txt")).unwrap();
    bench();
    assert!(run_dir.join("bench-key.txt").is_file());
}

/// A run, a plan or a demo into a folder below one that a bench or sweep of another process is
/// writing (its `runs/MAP/PLANNER`) is refused before any work: the bench replaced it, or it
/// replaced the bench's run. A lock file left unlocked by a killed bench does not count.
#[test]
fn runs_below_a_busy_bench_folder_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let bench_out = dir.path().join("b");
    std::fs::create_dir(&bench_out).unwrap();
    let target = bench_out.join("runs/teb_empty_box/ba-star");
    let held = ccpp_io::lock::FolderLock::take(&bench_out).unwrap();
    let run = |cmd: &str, planner: &str| {
        ccpp()
            .args([cmd, "--planner", planner, "--map"])
            .arg(data("teb_empty_box.yaml"))
            .arg("--out")
            .arg(&target)
            .output()
            .unwrap()
    };
    for (cmd, planner) in [("run", "ba-star"), ("plan", "bcd")] {
        let o = run(cmd, planner);
        let err = stderr_of(&o);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert!(
            err.contains("which a ccpp bench or sweep (pid ")
                && err.contains(&format!("pid {}", std::process::id())),
            "{err}"
        );
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(!target.exists());
    }
    let demo = ccpp()
        .current_dir(&bench_out)
        .args(["demo", "--out", "d"])
        .output()
        .unwrap();
    assert_eq!(demo.status.code(), Some(1), "{}", stderr_of(&demo));
    // A waypoints file too (dropped among the bench's files, it made every later bench there
    // refuse the folder: hostile pass).
    let w = ccpp()
        .args(["waypoints", "--map"])
        .arg(data("teb_empty_box.yaml"))
        .arg("--out")
        .arg(bench_out.join("w.csv"))
        .output()
        .unwrap();
    let err = stderr_of(&w);
    assert_eq!(w.status.code(), Some(1), "{err}");
    assert!(err.contains("which a ccpp bench or sweep (pid "), "{err}");
    assert!(!bench_out.join("w.csv").exists());
    // A bench into the held folder's `runs/` too (it wrote among the other bench's runs).
    let nested = ccpp()
        .args(["bench", "--quiet", "--planners", "bcd", "--maps"])
        .arg(data("teb_empty_box.yaml"))
        .arg("--out")
        .arg(bench_out.join("runs"))
        .output()
        .unwrap();
    let err = stderr_of(&nested);
    assert_eq!(nested.status.code(), Some(1), "{err}");
    assert!(err.contains("which a ccpp bench or sweep (pid "), "{err}");
    assert!(!bench_out.join("runs").exists());
    // Released, the lock file is gone; a file left behind unlocked (a killed bench) is no
    // hold either.
    drop(held);
    std::fs::write(bench_out.join(LOCK_FILE), "12345\n").unwrap();
    let o = run("run", "ba-star");
    assert!(o.status.success(), "{}", stderr_of(&o));
    assert_eq!(entries(&target), BASE_SET);
}

/// A bare-image map named as one of ccpp's outputs (`coverage.png`) inside the output folder:
/// `run` replaced it with the coverage picture (and `replay` then refused the run), `plan`
/// deleted it, both exiting 0. Both now refuse the folder in one line naming the map, which
/// stays as it was; so do a map YAML's image and an options file there, and so does Python
/// (`test_save_refuses_a_folder_holding_an_input`).
#[test]
fn an_output_folder_holding_the_runs_own_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let png = std::fs::read(data("teb_empty_box.png")).unwrap();
    let out = dir.path().join("m");
    std::fs::create_dir(&out).unwrap();
    // (a folder ccpp wrote, with its stamp: a folder without it is refused for that)
    std::fs::write(out.join(".ccpp"), "stamp").unwrap();
    let map = out.join("coverage.png");
    std::fs::write(&map, &png).unwrap();
    for (sub, planner) in [("run", "bsa"), ("plan", "bcd")] {
        let o = ccpp()
            .args([sub, "--planner", planner, "--map"])
            .arg(&map)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1), "{sub}");
        let e = stderr_of(&o);
        assert!(e.starts_with("error: output folder "), "{sub}: {e}");
        assert!(
            e.contains("coverage.png, an input of this run"),
            "{sub}: {e}"
        );
        assert_eq!(e.lines().count(), 1, "{e}");
        assert_eq!(std::fs::read(&map).unwrap(), png, "{sub}");
        assert_eq!(entries(&out), ["coverage.png"]);
    }
    // The image a map YAML (outside) names, inside the folder.
    let yaml = dir.path().join("box.yaml");
    std::fs::write(
        &yaml,
        "image: m/coverage.png\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
    )
    .unwrap();
    let o = ccpp()
        .args(["run", "--planner", "bsa", "--map"])
        .arg(&yaml)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr_of(&o).contains("an input of this run"),
        "{}",
        stderr_of(&o)
    );
    assert_eq!(std::fs::read(&map).unwrap(), png);
    // An options file named `metrics.json` in the folder of an earlier run.
    let run = dir.path().join("r");
    let o = ccpp()
        .args(["run", "--planner", "bsa", "--map"])
        .arg(data("teb_empty_box.yaml"))
        .arg("--out")
        .arg(&run)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr_of(&o));
    let config = run.join("metrics.json");
    std::fs::write(&config, "{\"bsa\": {}}").unwrap();
    let o = ccpp()
        .args(["run", "--planner", "bsa", "--map"])
        .arg(data("teb_empty_box.yaml"))
        .arg("--config")
        .arg(&config)
        .arg("--out")
        .arg(&run)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr_of(&o).contains("metrics.json, an input of this run"),
        "{}",
        stderr_of(&o)
    );
    assert_eq!(std::fs::read_to_string(&config).unwrap(), "{\"bsa\": {}}");
}

/// `bench --inflate -1` was checked map by map inside the bench: every run failed and the
/// summary of the earlier bench in the folder was replaced by error rows. It is refused
/// before the folder is touched, as `--radius nan` is.
#[test]
fn a_bench_with_a_bad_inflation_leaves_the_folder_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b");
    bench(&out, "ba-star").assert().success();
    let before = std::fs::read(out.join("results.csv")).unwrap();
    for v in ["-1", "nan", "inf"] {
        let o = bench(&out, "ba-star")
            .arg(format!("--inflate={v}"))
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1), "{v}");
        let e = stderr_of(&o);
        assert!(
            e.starts_with("error: --inflate / map.inflate must be a finite number >= 0 m"),
            "{v}: {e}"
        );
        assert_eq!(e.lines().count(), 1, "{e}");
        assert_eq!(
            std::fs::read(out.join("results.csv")).unwrap(),
            before,
            "{v}"
        );
    }
}

/// A bench into the folder of an earlier one with more planners left that one's run folders
/// under `runs/` beside a summary that does not list them, in silence: the folder looked like
/// one bench. The run folders are kept (benches may add planners one at a time) and named.
#[test]
fn a_bench_names_the_earlier_runs_its_summary_leaves_out() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b");
    let first = bench(&out, "ba-star,bsa").output().unwrap();
    assert!(first.status.success());
    assert!(
        !stderr_of(&first).contains("note:"),
        "{}",
        stderr_of(&first)
    );
    let o = bench(&out, "ba-star").output().unwrap();
    assert!(o.status.success(), "{}", stderr_of(&o));
    let e = stderr_of(&o);
    assert!(
        e.contains("also holds 1 run folder of an earlier bench that this summary leaves out (teb_empty_box/bsa); remove it"),
        "{e}"
    );
    assert!(out.join("runs/teb_empty_box/bsa/metrics.json").is_file());
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    assert!(!csv.contains(",bsa,"), "{csv}");
    // The same bench again lists both: nothing left out, no note.
    let o = bench(&out, "ba-star,bsa").output().unwrap();
    assert!(!stderr_of(&o).contains("note:"), "{}", stderr_of(&o));
}

/// An output folder that is the working directory, or holds it, was taken under any name but
/// `.`: `ccpp run --out ../out` from inside `out` swapped the folder away, the shell was left
/// in a deleted folder, and every relative path failed there.
#[test]
fn the_working_directory_is_no_output_folder_by_any_name() {
    let dir = tempfile::tempdir().unwrap();
    let map = data("teb_empty_box.png");
    let out = dir.path().join("up").join("out");
    let first = ccpp()
        .args(["run", "--planner", "bsa", "--map"])
        .arg(&map)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(first.status.success(), "{}", stderr_of(&first));
    let before: Vec<(String, Vec<u8>)> = entries(&out)
        .into_iter()
        .map(|n| (n.clone(), std::fs::read(out.join(&n)).unwrap()))
        .collect();
    let up = dir.path().join("up");
    for (sub, planner) in [("run", "bsa"), ("plan", "bcd")] {
        for target in [PathBuf::from("../out"), out.clone(), up.clone()] {
            let o = ccpp()
                .current_dir(&out)
                .args([sub, "--planner", planner, "--map"])
                .arg(&map)
                .arg("--out")
                .arg(&target)
                .output()
                .unwrap();
            assert_eq!(o.status.code(), Some(1), "{sub} {}", target.display());
            let e = stderr_of(&o);
            assert_eq!(
                e,
                format!(
                    "error: output folder {} is the working directory or holds it, which \
                     writing the folder would remove; choose another folder\n",
                    target.display()
                )
            );
        }
    }
    let after: Vec<(String, Vec<u8>)> = entries(&out)
        .into_iter()
        .map(|n| (n.clone(), std::fs::read(out.join(&n)).unwrap()))
        .collect();
    assert_eq!(after, before);
}

/// Copies the test map `teb_empty_box` (YAML and image) into `folder`, made if missing, under
/// the file stem `stem`; returns the YAML.
fn map_copy(folder: &Path, stem: &str) -> PathBuf {
    std::fs::create_dir_all(folder).unwrap();
    std::fs::copy(
        data("teb_empty_box.png"),
        folder.join(format!("{stem}.png")),
    )
    .unwrap();
    let yaml = std::fs::read_to_string(data("teb_empty_box.yaml"))
        .unwrap()
        .replace("teb_empty_box.png", &format!("{stem}.png"));
    let p = folder.join(format!("{stem}.yaml"));
    std::fs::write(&p, yaml).unwrap();
    p
}

fn bench_maps(out: &Path, maps: &[&Path]) -> std::process::Output {
    let mut c = ccpp();
    c.args([
        "bench",
        "--quiet",
        "--jobs",
        "1",
        "--planners",
        "ba-star",
        "--maps",
    ]);
    for m in maps {
        c.arg(m);
    }
    c.arg("--out").arg(out).output().unwrap()
}

/// Three ways a bench's run folders could not be replayed or misled (a hostile pass): maps of
/// one file name in two folders (`site1-box`) were named so in metrics.json but not in run.json,
/// and `ccpp replay` refused them as mixed; a run reused after the maps folder moved kept a
/// run.json naming the old path, which replay could not find; and a run that failed on its
/// second bench left the first bench's folder in place beside an error row (unnamed, then
/// named; now removed).
#[test]
fn bench_run_folders_replay_and_a_failed_rerun_removes_the_old_folder() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (
        map_copy(&dir.path().join("site1"), "box"),
        map_copy(&dir.path().join("site2"), "box"),
    );
    let out = dir.path().join("b");
    let o = bench_maps(&out, &[&a, &b]);
    assert!(o.status.success(), "{}", stderr_of(&o));
    for site in ["site1-box", "site2-box"] {
        let run = out.join("runs").join(site).join("ba-star");
        let o = ccpp().arg("replay").arg(&run).output().unwrap();
        assert!(o.status.success(), "{site}: {}", stderr_of(&o));
    }
    // The maps folder moved: the run is made again, its run.json naming the new path.
    let out3 = dir.path().join("b3");
    assert!(bench_maps(&out3, &[&b]).status.success());
    let moved = dir.path().join("site2-moved");
    std::fs::rename(dir.path().join("site2"), &moved).unwrap();
    let o = bench_maps(&out3, &[&moved.join("box.yaml")]);
    assert!(o.status.success(), "{}", stderr_of(&o));
    let run = out3.join("runs/box/ba-star");
    let json = std::fs::read_to_string(run.join("run.json")).unwrap();
    assert!(json.contains("site2-moved"), "{json}");
    let o = ccpp().arg("replay").arg(&run).output().unwrap();
    assert!(o.status.success(), "{}", stderr_of(&o));
    // A rerun that fails (the map's scale changed: the robot no longer fits on it) removes
    // the earlier bench's folder from the failed run's slot (it was left and named: "also
    // holds 1 run folder of an earlier bench that this summary leaves out (box/ba-star)").
    let c = a;
    let yaml = std::fs::read_to_string(&c).unwrap();
    let o = bench_maps(&dir.path().join("b4"), &[&c]);
    assert!(o.status.success(), "{}", stderr_of(&o));
    assert!(yaml.contains("resolution: 0.050000"), "{yaml}");
    std::fs::write(
        &c,
        yaml.replace("resolution: 0.050000", "resolution: 0.0001"),
    )
    .unwrap();
    assert!(dir.path().join("b4/runs/box/ba-star/run.json").is_file());
    let o = bench_maps(&dir.path().join("b4"), &[&c]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr_of(&o);
    assert!(!e.contains("earlier bench"), "{e}");
    assert!(!dir.path().join("b4/runs/box/ba-star").exists());
    let csv = std::fs::read_to_string(dir.path().join("b4/results.csv")).unwrap();
    assert!(csv.contains("box,ba-star,error"), "{csv}");
}

/// A map file named with a newline in a maps folder: its error row said `map maps/new` (the
/// message cut at the newline) where `ccpp run` names the character.
#[test]
fn a_bench_row_names_a_map_file_with_a_control_character() {
    let dir = tempfile::tempdir().unwrap();
    let maps = dir.path().join("maps");
    map_copy(&maps, "new\nline");
    map_copy(&maps, "plain");
    let out = dir.path().join("b");
    let o = bench_maps(&out, &[&maps]);
    assert_eq!(o.status.code(), Some(1));
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    assert!(
        csv.contains("new\\nline.yaml\"\": holds a control character (U+000A); rename it"),
        "{csv}"
    );
}

/// A file the user put into the output folder while the run wrote its files was deleted with
/// the old folder at the swap, and the run said it succeeded (hostile pass): the folder is
/// checked again under the swap lock, and the run fails leaving the folder as it was.
#[test]
fn a_file_put_into_the_folder_during_the_run_is_kept() {
    let dir = tempfile::tempdir().unwrap();
    // (apart: the test checks that `dir` holds the output folder only)
    let marks = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    let run = |pause: Option<&str>| {
        let mut c = std::process::Command::new(assert_cmd::cargo::cargo_bin("ccpp"));
        c.args(["run", "--planner", "ba-star", "--map"])
            .arg(data("teb_empty_box.yaml"))
            .arg("--out")
            .arg(&out)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        if let Some(ms) = pause {
            c.env("CCPP_TEST_COMMIT_PAUSE_MS", ms)
                .env("CCPP_TEST_PAUSED_FILE", marks.path().join("paused"));
        }
        c.spawn().unwrap()
    };
    assert!(run(None).wait().unwrap().success());
    let before = std::fs::read(out.join("path.csv")).unwrap();
    let child = run(Some("3000"));
    // The run waits three seconds before its swap.
    wait_for_pause(&marks.path().join("paused"));
    std::fs::write(out.join("notes.txt"), b"thesis").unwrap();
    let o = child.wait_with_output().unwrap();
    let err = stderr_of(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains("changed while the run wrote its files (it now holds notes.txt"),
        "{err}"
    );
    assert_eq!(std::fs::read(out.join("notes.txt")).unwrap(), b"thesis");
    assert_eq!(std::fs::read(out.join("path.csv")).unwrap(), before);
    // No staging folder is left beside it.
    assert_eq!(entries(dir.path()), ["o"]);
}

/// `--out` inside a run folder made the run folder hold a folder, which the next run into it
/// deleted (and `ccpp demo --out ccpp-demo/x` made `ccpp-demo` a folder runs refuse): refused
/// before the work, and so is a name longer than a file system takes (it failed only at the
/// final rename, after the whole run).
#[test]
fn an_output_folder_inside_a_run_folder_or_with_a_too_long_name_is_refused_first() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    let run = |target: &Path| {
        ccpp()
            .args(["run", "--planner", "ba-star", "--map"])
            .arg(data("teb_empty_box.yaml"))
            .arg("--out")
            .arg(target)
            .assert()
    };
    run(&out).success();
    for inner in [out.join("x"), out.join("x/y")] {
        let a = run(&inner).code(1);
        let err = stderr_of(a.get_output());
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(
            err.contains("lies inside the run folder") && err.contains("choose a folder outside"),
            "{err}"
        );
    }
    assert_eq!(entries(&out), BASE_SET);
    let long = dir.path().join("a".repeat(256));
    let started = std::time::Instant::now();
    let a = run(&long).code(1);
    let err = stderr_of(a.get_output());
    assert!(
        err.contains("its name is 256 bytes, longer than the 255"),
        "{err}"
    );
    assert!(started.elapsed() < std::time::Duration::from_secs(5));
    assert_eq!(entries(dir.path()), ["o"]);
}

/// A run replacing a folder kept its files but not its access: a private folder (mode 2770)
/// became world-readable 755 (hostile pass). The new folder takes the old one's mode.
#[cfg(unix)]
#[test]
fn a_replaced_folder_keeps_its_permissions() {
    use std::os::unix::fs::PermissionsExt as _;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    std::fs::create_dir(&out).unwrap();
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o2770)).unwrap();
    for planner in ["ba-star", "bsa"] {
        ccpp()
            .args(["run", "--planner", planner, "--map"])
            .arg(data("teb_empty_box.yaml"))
            .arg("--out")
            .arg(&out)
            .assert()
            .success();
        let mode = std::fs::metadata(&out).unwrap().permissions().mode() & 0o7777;
        assert_eq!(mode, 0o2770, "{planner}: {mode:o}");
    }
}

/// With stderr unwritable (`2>/dev/full`) a failing run, and a run with a warning after its
/// folder was written, panicked (exit 101) in `eprintln!` (hostile pass): exit 1 and 0.
#[cfg(target_os = "linux")]
#[test]
fn an_unwritable_stderr_is_no_panic() {
    let dir = tempfile::tempdir().unwrap();
    let full = || {
        std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap()
    };
    let run = |map: &Path, out: &str, extra: &[&str]| {
        std::process::Command::new(assert_cmd::cargo::cargo_bin("ccpp"))
            .args(["run", "--planner", "bsa-bfs", "--map"])
            .arg(map)
            .arg("--out")
            .arg(dir.path().join(out))
            .args(extra)
            .stdout(Stdio::null())
            .stderr(full())
            .status()
            .unwrap()
    };
    assert_eq!(run(&dir.path().join("none.yaml"), "a", &[]).code(), Some(1));
    // Heavy odometry noise without landmarks: the run warns of bumper contacts and of floor
    // far from the path, after its folder is written.
    let status = run(
        &data("teb_empty_box.yaml"),
        "b",
        &["--odometry-noise", "0.5", "--seed", "1"],
    );
    assert_eq!(status.code(), Some(0));
    assert!(dir.path().join("b/metrics.json").is_file());
}

/// `--out loop1/x` under a symbolic link loop (or a link to nothing) said "loop1 is a file,
/// not a folder" (hostile pass).
#[cfg(unix)]
#[test]
fn an_output_folder_under_a_broken_link_names_the_link() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::os::unix::fs::symlink(d.join("loop1"), d.join("loop2")).unwrap();
    std::os::unix::fs::symlink(d.join("loop2"), d.join("loop1")).unwrap();
    std::os::unix::fs::symlink(d.join("nowhere"), d.join("dangling")).unwrap();
    for link in ["loop1", "dangling"] {
        let a = ccpp()
            .args(["run", "--planner", "ba-star", "--map"])
            .arg(data("teb_empty_box.yaml"))
            .arg("--out")
            .arg(d.join(link).join("x"))
            .assert()
            .code(1);
        let err = stderr_of(a.get_output());
        assert!(
            err.contains(&format!(
                "{link} is a symbolic link to nothing or to itself"
            )),
            "{err}"
        );
    }
}

/// A write-protected output folder is refused, not replaced: the swap renames in the parent
/// went through, and the old run, which could not be removed, stayed beside it as a hidden
/// `.NAME.ccpp-old-*` copy per run (hostile pass).
#[cfg(unix)]
#[test]
fn a_read_only_output_folder_is_refused() {
    use std::os::unix::fs::PermissionsExt as _;
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("res");
    run_box("bcd", &out);
    let before = contents(&out);
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o555)).unwrap();
    let o = ccpp()
        .args(["run", "--planner", "bsa", "--map"])
        .arg(data("teb_empty_box.yaml"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o755)).unwrap();
    assert_eq!(o.status.code(), Some(1), "{o:?}");
    let err = stderr_of(&o);
    assert!(
        err.starts_with("error: ") && err.contains("is read-only") && err.contains("res"),
        "{err}"
    );
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert_eq!(contents(&out), before);
    assert_eq!(entries(d.path()), ["res"]);
    // `ccpp replay` refuses it the same way (it wrote its page and GIF into it when the
    // process could write anyway, as root: hostile pass, stop 69), and writes once writable.
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o555)).unwrap();
    let o = ccpp().arg("replay").arg(&out).output().unwrap();
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o755)).unwrap();
    assert_eq!(o.status.code(), Some(1), "{o:?}");
    let err = stderr_of(&o);
    assert!(
        err.starts_with("error: run folder ") && err.contains("res is read-only"),
        "{err}"
    );
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert_eq!(contents(&out), before);
    ccpp().arg("replay").arg(&out).assert().success();
    assert!(out.join("replay.html").is_file() && out.join("replay.gif").is_file());
}

/// Options that every run of a bench would be refused for, whatever the map, are refused
/// before the bench touches its folder, naming the options file: they were found run by run,
/// every run failed, and the last good bench in the folder was replaced by error rows that
/// blamed the map (hostile pass, stop 69). Options a planner of the bench can use (noise of
/// rect-boustrophedon's own) still run.
#[test]
fn a_bench_refuses_options_no_run_can_take_before_touching_its_folder() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("bench");
    let map = data("teb_empty_box.yaml");
    let bench = |config: Option<&Path>| {
        let mut c = ccpp();
        c.args([
            "bench",
            "--planners",
            "bcd,rect-boustrophedon",
            "--quiet",
            "--maps",
        ])
        .arg(&map)
        .arg("--out")
        .arg(&out);
        if let Some(f) = config {
            c.arg("--config").arg(f);
        }
        c.output().unwrap()
    };
    assert!(bench(None).status.success());
    let kept = [
        "results.csv",
        "results.md",
        "runs/teb_empty_box/bcd/metrics.json",
        "runs/teb_empty_box/rect-boustrophedon/path.csv",
    ];
    let snapshot = || -> Vec<Vec<u8>> {
        kept.iter()
            .map(|f| std::fs::read(out.join(f)).unwrap())
            .collect()
    };
    let before = snapshot();
    for (text, words) in [
        (
            "bcd: { bumper_reaction: false }",
            "bcd.bumper_reaction: false changes nothing without odometry noise",
        ),
        (
            "bcd: { lane_spacing_m: 1.0 }",
            "bcd.lane_spacing_m: lane spacing 1 m is wider than the tool",
        ),
        (
            "rect_boustrophedon: { clearance_radius_m: 0.01 }",
            "rect_boustrophedon.clearance_radius_m: 0.01 m is below the robot radius",
        ),
    ] {
        let f = d.path().join("opts.yaml");
        std::fs::write(&f, text).unwrap();
        let o = bench(Some(&f));
        let err = stderr_of(&o);
        assert_eq!(o.status.code(), Some(1), "{text}: {err}");
        assert!(
            err.starts_with("error: ")
                && err.contains(words)
                && err.contains("(set in planner options ")
                && err.contains("opts.yaml"),
            "{text}: {err}"
        );
        assert_eq!(err.trim_end().lines().count(), 1, "{text}: {err}");
        assert!(snapshot() == before, "{text}: the earlier bench changed");
    }
    let f = d.path().join("noisy.yaml");
    std::fs::write(
        &f,
        "rect_boustrophedon: { bumper_reaction: false, exec: { pid: { noise: { seed: 1, linear_rel_std: 0.01 } } } }",
    )
    .unwrap();
    let o = bench(Some(&f));
    assert!(o.status.success(), "{}", stderr_of(&o));
}
