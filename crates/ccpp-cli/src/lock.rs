//! A bench's hold on its output folder.
//!
//! Two `ccpp bench` writing to the same `--out` at once each wrote their run folders and
//! summary over the other's, leaving a folder mixed from both (`results.csv` of one, run
//! folders of the other) while both exited 0. A bench now holds [`LOCK_FILE`] in the folder
//! for its whole life: created if absent, locked with the operating system's advisory lock
//! (`File::try_lock`, released by the system when the process ends in any way), with the
//! holder's process id written in it for the message of a bench refused. The file is removed
//! when the bench ends, on an error or an interrupt too; one left by a killed bench (SIGKILL) is
//! unlocked and taken over by the next.

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read as _, Seek as _, Write as _};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

/// The lock file a bench holds in its output folder.
pub const LOCK_FILE: &str = ".ccpp-bench.lock";

/// The lock on an output folder, released (and its file removed) when dropped.
pub struct FolderLock {
    path: PathBuf,
    /// Open while the lock is held: closing it releases the lock.
    _file: File,
}

impl FolderLock {
    /// Takes the lock of the existing folder `folder`.
    ///
    /// # Errors
    /// When another process holds it (`OUT is in use by another ccpp bench (pid N)`), or the
    /// lock file cannot be created or locked.
    pub fn take(folder: &Path) -> Result<Self> {
        let path = folder.join(LOCK_FILE);
        let cannot = || format!("cannot lock output folder {}", folder.display());
        let file = crate::staging::register_lock(|| {
            // A holder that ends removes the file: one opened just before that is locked by
            // nobody else and linked nowhere, so it is opened again.
            for _ in 0..100 {
                let mut file = OpenOptions::new()
                    .read(true)
                    .write(true)
                    .create(true)
                    .truncate(false)
                    .open(&path)
                    .with_context(cannot)?;
                match file.try_lock() {
                    Ok(()) => {}
                    Err(TryLockError::WouldBlock) => bail!(
                        "{} is in use by another ccpp bench ({})",
                        folder.display(),
                        holder(&path)
                    ),
                    Err(TryLockError::Error(e)) => return Err(e).with_context(cannot),
                }
                if !still_linked(&file, &path) {
                    continue;
                }
                let pid = format!("{}\n", std::process::id());
                file.set_len(0)
                    .and_then(|()| file.rewind())
                    .and_then(|()| file.write_all(pid.as_bytes()))
                    .with_context(cannot)?;
                return Ok((path.clone(), file));
            }
            bail!("{}: the lock file keeps being replaced", cannot());
        })?;
        Ok(Self { path, _file: file })
    }
}

impl Drop for FolderLock {
    /// Removes the lock file while still holding the lock, then releases it (the file closes).
    fn drop(&mut self) {
        crate::staging::unregister_lock(&self.path);
        // Best effort: a lock file left behind is unlocked and taken over by the next bench.
        let _ = std::fs::remove_file(&self.path);
    }
}

/// `pid N` of the process holding the lock file `path`, as it wrote there (it writes its id
/// just after it takes the lock: a moment is allowed for that).
fn holder(path: &Path) -> String {
    for _ in 0..50 {
        let mut text = String::new();
        let read = File::open(path).and_then(|mut f| f.read_to_string(&mut text));
        if let (Ok(_), Ok(pid)) = (read, text.trim().parse::<u32>()) {
            return format!("pid {pid}");
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    "pid unknown".into()
}

/// Whether the open `file` is still the one at `path` (not removed or replaced by the holder
/// before it).
#[cfg(unix)]
fn still_linked(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt as _;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// Whether the open `file` is still the one at `path` (assumed elsewhere: Windows does not
/// remove an open file's name).
#[cfg(not(unix))]
fn still_linked(_file: &File, path: &Path) -> bool {
    path.exists()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn a_second_lock_is_refused_and_a_stale_one_taken_over() {
        let d = tempfile::tempdir().unwrap();
        // A file left by a killed bench: unlocked, so taken over.
        std::fs::write(d.path().join(LOCK_FILE), "4294967295\n").unwrap();
        let held = FolderLock::take(d.path()).unwrap();
        let text = std::fs::read_to_string(d.path().join(LOCK_FILE)).unwrap();
        assert_eq!(text.trim(), std::process::id().to_string());
        // Another open file description of the same file cannot lock it, even in this process.
        let e = FolderLock::take(d.path()).err().unwrap().to_string();
        let want = format!(
            "{} is in use by another ccpp bench (pid {})",
            d.path().display(),
            std::process::id()
        );
        assert_eq!(e, want);
        drop(held);
        assert!(!d.path().join(LOCK_FILE).exists(), "lock file left");
        drop(FolderLock::take(d.path()).unwrap());
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 0);
    }
}
