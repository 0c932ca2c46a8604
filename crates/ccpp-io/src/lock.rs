//! The hold of a `ccpp bench` or a Python sweep on its output folder.
//!
//! Two benches (or a bench and a sweep) writing to the same folder at once each wrote their run
//! folders and summary over the other's, leaving a folder mixed from both while both reported
//! success. A writer holds [`LOCK_FILE`] in the folder for its whole life: created if absent,
//! locked with the operating system's advisory lock (`File::try_lock`, released by the system
//! when the process ends in any way), with the holder's process id written in it for the
//! message of a writer refused. The file is removed when the lock is dropped; one left by a
//! killed process (SIGKILL) is unlocked and taken over by the next writer.
//!
//! One implementation for the command line (which also registers the file with its interrupt
//! cleanup) and the Python sweeps (`ccpp.sweeps`, through the native module).

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read as _, Seek as _, Write as _};
use std::path::{Path, PathBuf};

/// The lock file a bench or a sweep holds in its output folder.
pub const LOCK_FILE: &str = ".ccpp-bench.lock";

/// Why an output folder could not be locked.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    /// Another process holds the lock.
    #[error("{} is in use by another ccpp bench or sweep ({holder})", folder.display())]
    InUse {
        /// The folder.
        folder: PathBuf,
        /// `pid N` of the holder as it wrote in the file, or `pid unknown`.
        holder: String,
    },
    /// The lock file could not be created, locked or written.
    #[error("cannot lock output folder {}: {source}", folder.display())]
    Io {
        /// The folder.
        folder: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The lock file was removed or replaced every time it was opened (holders coming and
    /// going faster than it could be taken).
    #[error("cannot lock output folder {}: the lock file keeps being replaced", folder.display())]
    Replaced {
        /// The folder.
        folder: PathBuf,
    },
}

/// The lock on an output folder, released (and its file removed) when dropped.
#[derive(Debug)]
pub struct FolderLock {
    path: PathBuf,
    /// Open while the lock is held: closing it releases the lock.
    _file: File,
}

impl FolderLock {
    /// Takes the lock of the existing folder `folder`.
    ///
    /// # Errors
    /// [`LockError::InUse`] when another process (or another open file description in this
    /// one) holds it; [`LockError::Io`] when the lock file cannot be created or locked.
    pub fn take(folder: &Path) -> Result<Self, LockError> {
        let path = folder.join(LOCK_FILE);
        let io = |source| LockError::Io {
            folder: folder.to_path_buf(),
            source,
        };
        // A holder that ends removes the file: one opened just before that is locked by
        // nobody else and linked nowhere, so it is opened again.
        for _ in 0..100 {
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .map_err(io)?;
            match file.try_lock() {
                Ok(()) => {}
                Err(TryLockError::WouldBlock) => {
                    return Err(LockError::InUse {
                        folder: folder.to_path_buf(),
                        holder: holder(&path),
                    })
                }
                Err(TryLockError::Error(e)) => return Err(io(e)),
            }
            if !still_linked(&file, &path) {
                continue;
            }
            let pid = format!("{}\n", std::process::id());
            file.set_len(0)
                .and_then(|()| file.rewind())
                .and_then(|()| file.write_all(pid.as_bytes()))
                .map_err(io)?;
            return Ok(Self { path, _file: file });
        }
        Err(LockError::Replaced {
            folder: folder.to_path_buf(),
        })
    }

    /// The lock file.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for FolderLock {
    /// Removes the lock file while still holding the lock, then releases it (the file closes).
    fn drop(&mut self) {
        // Best effort: a lock file left behind is unlocked and taken over by the next writer.
        let _ = std::fs::remove_file(&self.path);
    }
}

/// `pid N` of the process that holds the lock of `folder` now, `None` when nobody does (no
/// lock file, or one left unlocked by a killed holder). Nothing is created or removed: the
/// existing lock file is opened for reading and locked shared for a moment, which fails only
/// while a holder has it.
#[must_use]
pub fn holder_of(folder: &Path) -> Option<String> {
    let path = folder.join(LOCK_FILE);
    let file = File::open(&path).ok()?;
    match file.try_lock_shared() {
        Err(TryLockError::WouldBlock) => Some(holder(&path)),
        // Taken (and released when the file closes), or not lockable: not held as a bench
        // holds it.
        Ok(()) | Err(TryLockError::Error(_)) => None,
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
        assert_eq!(held.path(), d.path().join(LOCK_FILE));
        let text = std::fs::read_to_string(d.path().join(LOCK_FILE)).unwrap();
        assert_eq!(text.trim(), std::process::id().to_string());
        // Another open file description of the same file cannot lock it, even in this process.
        let e = FolderLock::take(d.path()).err().unwrap();
        assert!(matches!(e, LockError::InUse { .. }), "{e:?}");
        let want = format!(
            "{} is in use by another ccpp bench or sweep (pid {})",
            d.path().display(),
            std::process::id()
        );
        assert_eq!(e.to_string(), want);
        drop(held);
        assert!(!d.path().join(LOCK_FILE).exists(), "lock file left");
        drop(FolderLock::take(d.path()).unwrap());
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 0);
    }

    #[test]
    fn a_folder_that_is_not_there_is_an_io_error_naming_it() {
        let d = tempfile::tempdir().unwrap();
        let gone = d.path().join("gone");
        let e = FolderLock::take(&gone).err().unwrap();
        assert!(matches!(e, LockError::Io { .. }), "{e:?}");
        let msg = e.to_string();
        assert!(
            msg.starts_with(&format!("cannot lock output folder {}: ", gone.display())),
            "{msg}"
        );
    }
}
