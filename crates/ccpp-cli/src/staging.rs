//! All-or-nothing output folders and cleanup on interrupt.
//!
//! A run's files are written into a staging folder `.<name>.ccpp-new-<pid>-<n>` beside the
//! target folder `<name>`. Only when every file is written is the set moved into place: the old
//! folder (if any) is renamed to `.<name>.ccpp-old-<pid>-<n>`, the staging folder is renamed to
//! `<name>`, and the old folder is removed. A reader therefore sees the old complete set or the
//! new complete set (for an instant, between the two renames, no folder), never a mix and never
//! a half-written file. Inside the staging folder, which no reader looks into, files are written
//! under their own names (no `.tmp` and rename each). Each staged file is synced to disk on a
//! thread of its own as soon as it is written (the disk's latency overlaps the work on the next
//! file; small files known early, such as `metrics.json`, go first); the swap waits for all of
//! them, so the folder that appears is on disk whole. For a long `<name>` the staging names
//! keep a cut of it and a hash, to stay within the file system's 255 bytes
//! ([`ccpp_io::write::staging_name`]).
//!
//! What a crash (power loss) can leave: the file contents are durable before the swap, the two
//! renames of the swap are not synced themselves (that would add a wait for the disk after the
//! last file). After a crash the target therefore holds the old complete set or the new
//! complete set, never a mix or a half-written file; when the crash fell between the two
//! renames, the target is missing and the next run into it puts the old folder back (see
//! below). A run that exited may, after a crash, show the old set again until it is repeated.
//!
//! On SIGINT/SIGTERM the handler waits for a swap in progress to finish, removes every staging
//! folder and temporary file still registered, and exits with status 130. Folders left by a
//! process that could not clean up (SIGKILL, power loss) carry its process id; the next run into
//! the same target removes them, or puts an old folder back when the target is missing.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};

use anyhow::{bail, Context, Result};
use ccpp_io::write::SwapError;

/// Paths to remove if the process is interrupted.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
/// Child processes (bench runs) to stop if this process is interrupted.
static CHILDREN: Mutex<Vec<u32>> = Mutex::new(Vec::new());
/// Set by the signal handler: no child process may start any more.
static STOPPING: AtomicBool = AtomicBool::new(false);
/// Lock files of output folders this process holds (a bench's, see [`crate::lock`]): removed on
/// interrupt after the child processes have ended, so that no other bench starts on the folder
/// while they may still write into it.
static LOCKS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// The output folders this process has moved into place, whole (as the user named them): an
/// interrupt after that says they were written, where it said only "interrupted" and a user
/// took the new complete set for the old one or for a broken one (hostile pass).
static WRITTEN: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// What an interrupt leaves, for its message when no output was moved into place whole (a
/// bench: which run folders stay and what became of the summary); `None`: nothing to add.
static INTERRUPT_NOTE: Mutex<Option<String>> = Mutex::new(None);

/// Sets what an interrupt says it leaves ([`INTERRUPT_NOTE`]): the interrupted bench said only
/// "interrupted" after it had removed an earlier summary and rewritten some run folders
/// (hostile pass).
pub fn set_interrupt_note(note: String) {
    *lock(&INTERRUPT_NOTE) = Some(note);
}

/// Test hook: when this environment variable names a file, writing that file fails as on a full
/// disk (`ENOSPC`). Used by the end-to-end tests to check that a failed run leaves no output.
pub const FAIL_WRITE_ENV: &str = "CCPP_TEST_FAIL_WRITE";

/// Test hook: `ccpp replay` waits this many milliseconds after reading the run folder, before
/// it renders (a test swaps the folder meanwhile, as a `ccpp run` into it would).
pub const REPLAY_PAUSE_ENV: &str = "CCPP_TEST_REPLAY_PAUSE_MS";

/// Test hook: a staging folder waits this many milliseconds before it is moved into place (a
/// test puts a file into the target meanwhile, as a user might while a large run writes), and
/// so do a replay's page and GIF before they are renamed in (a test starts a second replay).
pub const COMMIT_PAUSE_ENV: &str = "CCPP_TEST_COMMIT_PAUSE_MS";

/// Test hook: a staging folder, once moved into place, waits this many milliseconds (a test
/// interrupts the process then); so do a replay's page and GIF once renamed in.
pub const AFTER_COMMIT_PAUSE_ENV: &str = "CCPP_TEST_AFTER_COMMIT_PAUSE_MS";

/// Test hook: with a pause above, the file this environment variable names is created as the
/// pause begins (holding the pause's variable name), so that a test acts during the pause
/// whatever the machine's load, instead of guessing when it began.
pub const PAUSED_FILE_ENV: &str = "CCPP_TEST_PAUSED_FILE";

/// Test hook: [`write_files_together`] waits at most this many milliseconds (instead of a
/// minute) for another writer of the folder, so that a test sees the wait end in an error.
pub const WRITER_WAIT_ENV: &str = "CCPP_TEST_WRITER_WAIT_MS";

/// The milliseconds a test hook's environment variable `var` gives, at most a minute; `None`
/// when it is not set to a whole number.
fn hook_duration(var: &str) -> Option<std::time::Duration> {
    let ms = std::env::var(var).ok()?.parse::<u64>().ok()?;
    Some(std::time::Duration::from_millis(ms.min(60_000)))
}

/// Sleeps for the milliseconds the environment variable `var` gives, if any, at most a
/// minute (the test hooks above), first creating [`PAUSED_FILE_ENV`]'s file if one is named.
pub fn pause_for(var: &str) {
    if let Some(pause) = hook_duration(var) {
        if let Some(mark) = std::env::var_os(PAUSED_FILE_ENV) {
            // A test hook: a test that finds no file fails on its own, saying so.
            let _ = std::fs::write(mark, var);
        }
        std::thread::sleep(pause);
    }
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

fn register(p: &Path) {
    lock(&PENDING).push(p.to_path_buf());
}

/// Paths written one by one that make one whole (a bench's summary: `results.csv`,
/// `results.md`, `plots/`): registered for removal on interrupt from creation until
/// [`PendingSet::done`], and removed when the guard is dropped before that (an error on the
/// way), so a stop or a failure in the middle leaves none of them instead of some.
pub struct PendingSet {
    paths: Vec<PathBuf>,
    done: bool,
}

impl PendingSet {
    /// Registers `paths` (they need not exist yet).
    pub fn new(paths: Vec<PathBuf>) -> Self {
        for p in &paths {
            register(p);
        }
        Self { paths, done: false }
    }

    /// The whole is written: its paths stay, and are no longer removed on interrupt.
    pub fn done(mut self) {
        self.done = true;
    }
}

impl Drop for PendingSet {
    /// Removes the paths unless the whole was written ([`PendingSet::done`]).
    fn drop(&mut self) {
        for p in &self.paths {
            if !self.done {
                remove_all(p);
            }
            unregister(p);
        }
    }
}

fn unregister(p: &Path) {
    let mut v = lock(&PENDING);
    if let Some(i) = v.iter().position(|q| q == p) {
        v.swap_remove(i);
    }
}

/// Removes a file or folder, retrying a few times (a worker thread may still be adding files).
fn remove_all(p: &Path) {
    for _ in 0..10 {
        let r = if p.is_dir() {
            std::fs::remove_dir_all(p)
        } else {
            std::fs::remove_file(p)
        };
        if r.is_ok() || !p.exists() {
            return;
        }
    }
}

/// Starts a child process that is stopped (SIGTERM) if this process is interrupted. Spawning
/// and recording happen under one lock, so the signal handler never misses a child.
///
/// # Errors
/// When the process cannot be started.
pub fn spawn_child(cmd: &mut std::process::Command) -> std::io::Result<std::process::Child> {
    let mut children = lock(&CHILDREN);
    if STOPPING.load(Ordering::SeqCst) {
        return Err(std::io::Error::new(
            std::io::ErrorKind::Interrupted,
            "interrupted",
        ));
    }
    let child = cmd.spawn()?;
    children.push(child.id());
    Ok(child)
}

/// Forgets a child process that has ended.
pub fn unregister_child(pid: u32) {
    lock(&CHILDREN).retain(|&p| p != pid);
}

/// Whether an interrupt is being handled (no new child may start, and what a stopped child
/// leaves is not its run's failure).
pub fn stopping() -> bool {
    STOPPING.load(Ordering::SeqCst)
}

/// Installs the SIGINT/SIGTERM handler (once, at start-up).
pub fn install_signal_handler() {
    // Failure to install (a handler already set) only loses the cleanup.
    let _ = ctrlc::set_handler(|| interrupted());
}

/// Called once the command is done, just before the process exits with `code`: takes the
/// lock the interrupt cleanup ([`install_signal_handler`]) takes first and keeps it until
/// exit, so that the process ends one way only. An interrupt whose cleanup began first ends
/// it (status 130, its message); one that comes later finds the lock taken and the process
/// ends with `code`. Before, a cleanup waiting on a folder swap ran on while `main` returned:
/// its "interrupted" line came out with status 0.
pub fn finish(code: std::process::ExitCode) -> std::process::ExitCode {
    // Never released: the process ends with this function's caller.
    std::mem::forget(ccpp_io::write::swap_lock());
    code
}

/// The interrupt cleanup (module docs), then exit with status 130.
fn interrupted() -> ! {
    use std::io::Write as _;
    // Hold both locks until exit: no swap can be half done and no new staging folder can
    // appear after the cleanup.
    let _swap = ccpp_io::write::swap_lock();
    let pending = lock(&PENDING);
    for p in pending.iter() {
        remove_all(p);
    }
    // Running children clean up their own staging folders when told to stop; no new one
    // starts once STOPPING is set. Wait (a few seconds at most) until they have ended.
    {
        let children = lock(&CHILDREN);
        STOPPING.store(true, Ordering::SeqCst);
        for pid in children.iter() {
            let _ = std::process::Command::new("kill")
                .arg("-TERM")
                .arg(pid.to_string())
                .stderr(std::process::Stdio::null())
                .status();
        }
    }
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(5);
    while !lock(&CHILDREN).is_empty() && std::time::Instant::now() < deadline {
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    // Held until exit: no lock can be taken after this cleanup. The process's own lock on
    // each file goes with it.
    let locks = lock(&LOCKS);
    for p in locks.iter() {
        // Best effort: a lock file left behind is taken over by the next bench.
        let _ = std::fs::remove_file(p);
    }
    // Stderr may be a pipe whose reader is gone (a bench job whose bench died): no panic.
    let written = lock(&WRITTEN);
    let note = lock(&INTERRUPT_NOTE);
    if !written.is_empty() {
        let names: Vec<String> = written
            .iter()
            .map(|p| ccpp_io::message::visible(&p.display().to_string()))
            .collect();
        let _ = writeln!(
            std::io::stderr(),
            "error: interrupted after the new output was written whole to {}",
            names.join(", ")
        );
    } else if let Some(note) = note.as_deref() {
        let _ = writeln!(
            std::io::stderr(),
            "error: interrupted; {}",
            ccpp_io::message::visible(note)
        );
    } else {
        let _ = writeln!(std::io::stderr(), "error: interrupted");
    }
    std::process::exit(130);
}

/// Ends this process as an interrupt does ([`install_signal_handler`]) once its parent has
/// gone: a bench's job would otherwise run on as an orphan after the bench was killed
/// (SIGKILL, which no handler sees), outside the bench's lock and memory budget, and still
/// write its run folder. `parent`: the process id the parent gave (it may have died before
/// this process looked), else this process's parent now. Looks at once, then every 50 ms.
/// Elsewhere than on Unix it does nothing (no portable way to read the parent's id).
#[cfg(unix)]
pub fn stop_with_parent(parent: Option<u32>) {
    let parent = parent.unwrap_or_else(std::os::unix::process::parent_id);
    std::thread::spawn(move || loop {
        if std::os::unix::process::parent_id() != parent {
            interrupted();
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    });
}

/// See the Unix version: nothing to watch here.
#[cfg(not(unix))]
pub fn stop_with_parent(_parent: Option<u32>) {}

/// Runs `take` (which creates and locks a lock file, returning its path when it took the lock)
/// under the lock of the interrupt cleanup, and registers the path it returns: an interrupt
/// removes the file unless it came before `take` started.
///
/// # Errors
/// What `take` returns.
pub fn register_lock<T>(take: impl FnOnce() -> Result<(PathBuf, T)>) -> Result<T> {
    let mut locks = lock(&LOCKS);
    let (path, held) = take()?;
    locks.push(path);
    Ok(held)
}

/// Forgets a lock file (before removing it on a normal exit).
pub fn unregister_lock(p: &Path) {
    lock(&LOCKS).retain(|q| q != p);
}

/// Longest wait of [`write_files_together`] for another writer of the folder.
const WRITER_WAIT: std::time::Duration = std::time::Duration::from_mins(1);

/// Writes `files` (name, bytes) into the existing folder `dir` as one set, both or neither:
/// each is written and synced as `<name>.tmp` first (a failure there removes them all and
/// leaves the old files as they were); then, under the swap lock (an interrupt waits for it),
/// each is renamed over its name in order. When a rename fails, the files renamed before it
/// are put back as they were (the old content, kept in memory, or no file). Used by
/// `ccpp replay`, whose page and GIF went one by one: a failure or interrupt between them left
/// the page without its GIF. Honours the [`FAIL_WRITE_ENV`] test hook.
///
/// # Errors
/// When a file cannot be written (named as in `dir`) or renamed into place.
pub fn write_files_together(dir: &Path, files: &[(&str, &[u8])]) -> Result<()> {
    // One writer at a time per folder: two `ccpp replay` of one run wrote the same
    // `<name>.tmp` files, and the second's rename found its file already renamed by the first
    // ("No such file"). The operating system's advisory lock on the folder itself (no file is
    // added to it) makes the second wait until the first has renamed its files in; it is
    // released when the process ends in any way. Where the folder cannot be locked, the
    // files are written without it. The wait is said, and bounded: a holder stopped with
    // Ctrl-Z (or any other process holding the lock) made the next replay hang without a word.
    let writer = std::fs::File::open(dir).ok();
    if let Some(f) = &writer {
        let wait = hook_duration(WRITER_WAIT_ENV).map_or(WRITER_WAIT, |d| d.min(WRITER_WAIT));
        let t0 = std::time::Instant::now();
        let mut told = false;
        loop {
            match f.try_lock() {
                Ok(()) | Err(std::fs::TryLockError::Error(_)) => break,
                Err(std::fs::TryLockError::WouldBlock) => {
                    if !told {
                        say!(
                            "note: waiting for another process writing {} to finish",
                            dir.display()
                        );
                        told = true;
                    }
                    if t0.elapsed() > wait {
                        bail!(
                            "{} has been held by another process writing it for over a minute (a ccpp replay stopped with Ctrl-Z?); nothing was written",
                            dir.display()
                        );
                    }
                    std::thread::sleep(std::time::Duration::from_millis(50));
                }
            }
        }
    }
    let tmp_of = |name: &str| dir.join(format!("{name}.tmp"));
    let clear = |upto: usize| {
        for (name, _) in &files[..upto] {
            let t = tmp_of(name);
            // Best effort: it may not exist (already renamed, or never created).
            let _ = std::fs::remove_file(&t);
            unregister(&t);
        }
    };
    for (i, (name, bytes)) in files.iter().enumerate() {
        let tmp = tmp_of(name);
        register(&tmp);
        let failing = std::env::var_os(FAIL_WRITE_ENV).is_some_and(|v| v == *name);
        let written = (|| {
            if failing {
                return Err(std::io::Error::from_raw_os_error(28));
            }
            let mut f = std::fs::File::create(&tmp)?;
            std::io::Write::write_all(&mut f, bytes)?;
            f.sync_all()
        })();
        if let Err(e) = written {
            clear(i + 1);
            bail!("cannot write {}: {e}", dir.join(name).display());
        }
    }
    pause_for(COMMIT_PAUSE_ENV);
    let swap = ccpp_io::write::swap_lock();
    // The old content of each file before it is replaced, to put back if a later one fails.
    let mut before: Vec<Option<Vec<u8>>> = Vec::new();
    for (i, (name, _)) in files.iter().enumerate() {
        let path = dir.join(name);
        let old = if i + 1 < files.len() {
            std::fs::read(&path).ok()
        } else {
            None
        };
        if let Err(e) = std::fs::rename(tmp_of(name), &path) {
            for ((done, _), old) in files[..i].iter().zip(&before).rev() {
                let p = dir.join(done);
                // Best effort: the error below is what the user learns.
                let _ = match old {
                    Some(bytes) => std::fs::write(&p, bytes),
                    None => std::fs::remove_file(&p),
                };
            }
            clear(files.len());
            bail!("cannot write {}: {e}", path.display());
        }
        unregister(&tmp_of(name));
        before.push(old);
    }
    // An interrupt from here on says the files were written whole, as after a folder's swap
    // (a replay interrupted after its renames said only "interrupted": hostile pass).
    lock(&WRITTEN).push(dir.to_path_buf());
    // Released before the pause: the interrupt cleanup takes this lock, and it waited out the
    // rest of the command here, then raced the command's own exit (status 0 after its
    // "interrupted" line: CI).
    drop(swap);
    pause_for(AFTER_COMMIT_PAUSE_ENV);
    Ok(())
}

/// [`check_target`] for a user's own run, plan or demo, which also may not replace a bench's
/// run folder ([`ccpp_io::write::check_not_bench_run`]) nor write below a
/// folder another process's bench or sweep is writing
/// ([`ccpp_io::write::check_not_in_busy_folder`]; a bench's runs write below their own).
///
/// # Errors
/// As [`check_target`], or when a folder above `target` is held.
pub fn check_user_target(target: &Path) -> Result<()> {
    check_target(target)?;
    ccpp_io::write::check_not_bench_run(target)?;
    Ok(ccpp_io::write::check_not_in_busy_folder(target)?)
}

/// Checks that `target` is absent, or a folder holding only run files
/// ([`ccpp_io::write::check_run_folder`]).
///
/// # Errors
/// When it is a file, or a folder holding anything else.
pub fn check_target(target: &Path) -> Result<()> {
    Ok(ccpp_io::write::check_run_folder(target)?)
}

/// Checks that the output folder `target` holds none of the files the run reads: the
/// scenario's ([`ccpp_io::scenario::Scenario::input_files`]) and `extra` (the options and
/// landmark files).
///
/// # Errors
/// An input inside `target` ([`ccpp_io::write::FolderError::HoldsInput`]).
pub fn check_inputs(
    target: &Path,
    scenario: &ccpp_io::scenario::Scenario,
    extra: &[Option<&std::path::PathBuf>],
) -> Result<()> {
    let mut inputs = scenario.input_files();
    inputs.extend(extra.iter().flatten().map(|p| (*p).clone()));
    Ok(ccpp_io::write::check_inputs_outside(target, &inputs)?)
}

/// A staging folder that becomes `target` on [`Staging::commit`] and is removed otherwise.
pub struct Staging {
    /// The target as the user named it (for messages).
    shown: PathBuf,
    /// The target under its resolved parent folder (for the renames).
    target: PathBuf,
    dir: PathBuf,
    parent: PathBuf,
    name: String,
    done: bool,
    /// The files written, each being synced to disk on its own thread (so the disk's latency
    /// overlaps the next file's work); [`Staging::commit`] waits for all before the swap.
    syncs: Mutex<Vec<(String, std::thread::JoinHandle<std::io::Result<()>>)>>,
}

impl Staging {
    /// Creates the staging folder beside `target` (creating `target`'s parent if needed).
    ///
    /// # Errors
    /// When `target` names no folder (`.`, `..`, a root), exists as a file or as a folder with
    /// files ccpp did not write, or the staging folder cannot be created.
    pub fn new(target: &Path) -> Result<Self> {
        let name = match target.file_name().and_then(|n| n.to_str()) {
            Some(n) if n != "." && n != ".." => n.to_string(),
            _ => bail!(
                "output folder {} must end in a folder name (not ., .. or a root)",
                target.display()
            ),
        };
        check_target(target)?;
        ccpp_io::write::check_output_place(target)?;
        let parent = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let existed = std::fs::symlink_metadata(target).is_ok();
        ccpp_io::write::create_folder(&parent, target)?;
        // The swap renames `parent/name` away and then renames the staging folder to it: with
        // a `..` in `parent` (`--out a/../a`) the old folder's rename would remove the path the
        // second rename goes through, and the run, finished, would fail and leave both staging
        // folders behind. The resolved parent is the same folder and stays reachable.
        let parent = parent
            .canonicalize()
            .with_context(|| format!("cannot create output folder {}", parent.display()))?;
        let resolved = parent.join(&name);
        if !existed {
            // `create_dir_all("a/..")` creates `a`, the target itself: not a run folder.
            let _ = std::fs::remove_dir(&resolved);
        }
        ccpp_io::write::clean_stale(&parent, &name);
        let dir = ccpp_io::write::staging_path(&parent, &name, "new");
        {
            // Registered and created under the lock: the signal handler sees both or neither.
            let mut pending = lock(&PENDING);
            std::fs::create_dir(&dir)
                .with_context(|| format!("cannot create output folder {}", target.display()))?;
            pending.push(dir.clone());
        }
        let staged = Self {
            shown: target.to_path_buf(),
            target: resolved,
            dir,
            parent,
            name,
            done: false,
            syncs: Mutex::new(Vec::new()),
        };
        // (a folder holding files is replaced only when it holds this stamp)
        staged.write(
            ccpp_io::write::STAMP_FILE,
            ccpp_io::write::STAMP_TEXT.as_bytes(),
        )?;
        Ok(staged)
    }

    /// Writes `bytes` as `name` into the staging folder.
    ///
    /// # Errors
    /// When the file cannot be written (named by its place in the target folder).
    pub fn write(&self, name: &str, bytes: &[u8]) -> Result<()> {
        self.write_with(name, &mut |w| w.write_all(bytes))
    }

    /// Writes the file `name` of the set with what `fill` writes (streamed: the file need not
    /// be held in memory).
    ///
    /// # Errors
    /// When the file cannot be written (named as in the target folder).
    pub fn write_with(
        &self,
        name: &str,
        fill: &mut dyn FnMut(&mut dyn std::io::Write) -> std::io::Result<()>,
    ) -> Result<()> {
        let file = write_file_with(&self.dir.join(name), fill, true).map_err(|e| {
            // Name the file where it would have gone, not its staging copy.
            let shown = self.shown.join(name);
            match e {
                ccpp_io::WriteError::Io { source, .. } => {
                    anyhow::anyhow!("cannot write {}: {source}", shown.display())
                }
                other => anyhow::anyhow!("cannot write {}: {other}", shown.display()),
            }
        })?;
        if let Some(file) = file {
            let sync = std::thread::spawn(move || file.sync_all());
            lock(&self.syncs).push((name.to_string(), sync));
        }
        Ok(())
    }

    /// The files staged so far and their sizes in bytes, by name (a bench run's
    /// `bench-key.txt` lists them, so a resumed bench can tell a copy cut short).
    ///
    /// # Errors
    /// When the staging folder cannot be read.
    pub fn sizes(&self) -> Result<Vec<(String, u64)>> {
        let mut v = Vec::new();
        for e in std::fs::read_dir(&self.dir)
            .with_context(|| format!("cannot read {}", self.dir.display()))?
        {
            let e = e.with_context(|| format!("cannot read {}", self.dir.display()))?;
            if e.file_name() == ccpp_io::write::STAMP_FILE {
                continue;
            }
            let len = e
                .metadata()
                .with_context(|| format!("cannot read {}", self.dir.display()))?
                .len();
            v.push((e.file_name().to_string_lossy().into_owned(), len));
        }
        v.sort();
        Ok(v)
    }

    /// Waits until every file written is on disk.
    fn wait_synced(&self) -> Result<()> {
        let syncs = std::mem::take(&mut *lock(&self.syncs));
        let mut first_error = None;
        for (name, sync) in syncs {
            let r = sync
                .join()
                .unwrap_or_else(|_| Err(std::io::Error::other("sync thread panicked")));
            if let (Err(e), None) = (r, &first_error) {
                let shown = self.shown.join(name);
                first_error = Some(anyhow::anyhow!("cannot write {}: {e}", shown.display()));
            }
        }
        first_error.map_or(Ok(()), Err)
    }

    /// Moves the staging folder into place, replacing the old target folder.
    ///
    /// # Errors
    /// When a rename fails; the old folder is then put back where possible.
    pub fn commit(mut self) -> Result<()> {
        self.wait_synced()?;
        pause_for(COMMIT_PAUSE_ENV);
        let old = ccpp_io::write::staging_path(&self.parent, &self.name, "old");
        let swap = ccpp_io::write::swap_lock();
        // Checked again under the lock: a file the user put into the folder while the run
        // wrote its files was deleted with the old folder (hostile pass; `write_folder` did
        // this already).
        if let Err(e) = ccpp_io::write::check_run_folder(&self.target) {
            let what = match &e {
                ccpp_io::write::FolderError::Foreign { name, .. } => {
                    format!("it now holds {name}, which ccpp did not write")
                }
                other => other.to_string(),
            };
            bail!(
                "output folder {} changed while the run wrote its files ({what}); nothing was replaced",
                self.shown.display()
            );
        }
        let had_old = match ccpp_io::write::swap_folder(&self.dir, &self.target, &old, || {
            register(&old);
        }) {
            Ok(had_old) => had_old,
            Err(e) => {
                unregister(&old);
                return Err(match e {
                    SwapError::MoveOld(e) => anyhow::Error::new(e).context(format!(
                        "cannot replace output folder {}",
                        self.shown.display()
                    )),
                    SwapError::MoveNew(e) => anyhow::Error::new(e).context(format!(
                        "cannot move the new output into {}",
                        self.shown.display()
                    )),
                    // The previous output stays under its hidden name (the next `ccpp run`
                    // into this folder puts it back): say where.
                    SwapError::Lost { error, back } => anyhow::Error::new(error).context(format!(
                        "cannot move the new output into {}, nor put the previous one back ({back}): it is at {}",
                        self.shown.display(),
                        old.display()
                    )),
                });
            }
        };
        unregister(&self.dir);
        self.done = true;
        lock(&WRITTEN).push(self.shown.clone());
        drop(swap);
        if had_old {
            remove_all(&old);
            unregister(&old);
            if std::fs::symlink_metadata(&old).is_ok() {
                // (an undeletable file in it: the previous output stayed hidden without a
                // word; hostile pass)
                say!(
                    "warning: the previous output of {} could not be removed whole; what is left of it is at {}",
                    self.shown.display(),
                    old.display()
                );
            }
        }
        pause_for(AFTER_COMMIT_PAUSE_ENV);
        Ok(())
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if !self.done {
            remove_all(&self.dir);
            unregister(&self.dir);
        }
    }
}

/// Writes `bytes` to `path` atomically (see [`ccpp_io::write_atomic`]); its `.tmp` is removed
/// if the process is interrupted meanwhile. Honours the [`FAIL_WRITE_ENV`] test hook.
///
/// # Errors
/// When the file cannot be written.
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<(), ccpp_io::WriteError> {
    write_file_with(path, &mut |w| w.write_all(bytes), false).map(drop)
}

/// Writes the file at `path` atomically with what `fill` writes, synced before it is renamed
/// into place; or, `deferred` (a file of a staging folder, which becomes visible only with the
/// folder), written under its name unsynced and returned for the caller to sync.
fn write_file_with(
    path: &Path,
    fill: &mut dyn FnMut(&mut dyn std::io::Write) -> std::io::Result<()>,
    deferred: bool,
) -> Result<Option<std::fs::File>, ccpp_io::WriteError> {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    let write = |fill: &mut dyn FnMut(&mut dyn std::io::Write) -> std::io::Result<()>| {
        if deferred {
            write_staged(path, fill).map(Some)
        } else {
            ccpp_io::write::write_atomic_with(path, fill).map(|()| None)
        }
    };
    if std::env::var_os(FAIL_WRITE_ENV).is_some_and(|v| v == name) {
        return write(&mut |_| Err(std::io::Error::from_raw_os_error(28)));
    }
    if deferred {
        // A file of a staging folder: written under its own name (the folder is private until
        // it is moved into place, so no reader can see the file half written; the folder is
        // registered, and removed whole on failure or interrupt).
        return write(fill);
    }
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    register(&tmp);
    let r = write(fill);
    unregister(&tmp);
    r
}

/// Writes what `fill` writes into a new file `path` of a staging folder, unsynced, and returns
/// it for the caller to sync; on failure the file is removed.
fn write_staged(
    path: &Path,
    fill: &mut dyn FnMut(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> Result<std::fs::File, ccpp_io::WriteError> {
    let result = (|| {
        let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
        fill(&mut w)?;
        w.into_inner().map_err(std::io::IntoInnerError::into_error)
    })();
    result.map_err(|source| {
        // Best effort: the file may not even exist.
        let _ = std::fs::remove_file(path);
        ccpp_io::WriteError::Io {
            path: path.to_path_buf(),
            source,
        }
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn export_files_are_run_files() {
        // A folder holding exports can be replaced by the next run or plan.
        for f in ccpp_io::export::ExportFormat::ALL {
            assert!(ccpp_io::write::RUN_FILES.contains(&f.file_name()), "{f}");
        }
    }

    #[test]
    fn commit_replaces_the_whole_folder() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("out");
        let s = Staging::new(&target).unwrap();
        s.write("run.json", b"1").unwrap();
        s.write("replay.gif", b"g").unwrap();
        s.commit().unwrap();
        let s = Staging::new(&target).unwrap();
        s.write("run.json", b"2").unwrap();
        s.commit().unwrap();
        assert_eq!(std::fs::read(target.join("run.json")).unwrap(), b"2");
        assert!(!target.join("replay.gif").exists(), "old files must go");
        let names: Vec<_> = std::fs::read_dir(d.path()).unwrap().collect();
        assert_eq!(names.len(), 1, "no staging folder left");
    }

    #[test]
    fn dropped_staging_leaves_the_old_folder() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("out");
        let s = Staging::new(&target).unwrap();
        s.write("run.json", b"1").unwrap();
        s.commit().unwrap();
        let s = Staging::new(&target).unwrap();
        s.write("run.json", b"2").unwrap();
        drop(s);
        assert_eq!(std::fs::read(target.join("run.json")).unwrap(), b"1");
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 1);
    }

    #[test]
    fn refuses_folders_with_foreign_files_and_bad_names() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("out");
        std::fs::create_dir(&target).unwrap();
        std::fs::write(target.join("notes.txt"), b"mine").unwrap();
        let e = Staging::new(&target).err().unwrap().to_string();
        assert!(e.contains("notes.txt"), "{e}");
        assert!(Staging::new(Path::new(".")).is_err());
        assert!(Staging::new(Path::new("/")).is_err());
    }

    #[test]
    fn stale_folders_of_dead_processes_are_cleaned() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("out");
        // A pid that cannot be alive (above Linux's pid_max).
        let dead = d.path().join(".out.ccpp-new-4294967295-0");
        std::fs::create_dir(&dead).unwrap();
        let old = d.path().join(".out.ccpp-old-4294967295-1");
        std::fs::create_dir(&old).unwrap();
        std::fs::write(old.join("run.json"), b"old").unwrap();
        let s = Staging::new(&target).unwrap();
        assert!(!dead.exists());
        // The target was missing, so the old folder came back.
        assert_eq!(std::fs::read(target.join("run.json")).unwrap(), b"old");
        drop(s);
    }
}
