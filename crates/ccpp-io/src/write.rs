//! Atomic file writers and a `map_saver`-style map writer.
//!
//! Every writer here writes to `<name>.tmp` in the destination's folder, flushes it to disk and
//! then renames it over the destination, so a failure never leaves a half-written output file
//! (at worst a stale `<name>.tmp`, which is removed when possible).

use std::ffi::OsString;
use std::fmt::Write as _;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use ccpp_core::grid::{Cell, GridMap, MapFrame};

/// Grey value `map_saver` writes for free cells.
pub const PGM_FREE: u8 = 254;
/// Grey value `map_saver` writes for occupied cells.
pub const PGM_OCCUPIED: u8 = 0;
/// Grey value `map_saver` writes for unknown cells.
pub const PGM_UNKNOWN: u8 = 205;

/// Error while writing an output file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WriteError {
    /// Creating, writing, syncing or renaming failed.
    #[error("cannot write {}: {source}", path.display())]
    Io {
        /// The destination file.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: io::Error,
    },
    /// The destination path has no file name (e.g. it ends in `..` or is a root).
    #[error("cannot write {}: the path has no file name", path.display())]
    NoFileName {
        /// The destination path.
        path: PathBuf,
    },
    /// The image file name derived from the YAML path is not UTF-8, so a YAML cannot name it.
    #[error("cannot save a map as {}: the file name is not UTF-8", path.display())]
    NonUtf8Name {
        /// The destination YAML path.
        path: PathBuf,
    },
}

/// The temporary path `<name>.tmp` beside `path`; for a name within 4 bytes of the 255-byte
/// limit, `<start>~<hash>.tmp` with the name cut at a character boundary (a legal 252-byte
/// `waypoints --out` failed with "File name too long").
fn tmp_path(path: &Path) -> Result<PathBuf, WriteError> {
    let name = path.file_name().ok_or_else(|| WriteError::NoFileName {
        path: path.to_path_buf(),
    })?;
    if name.len() + ".tmp".len() > NAME_MAX {
        let text = name.to_string_lossy();
        let mut h = ccpp_core::hash::Fnv::new();
        h.bytes(name.as_encoded_bytes());
        let hash = format!("~{:016x}.tmp", h.finish());
        let mut cut = (NAME_MAX - hash.len()).min(text.len());
        while !text.is_char_boundary(cut) {
            cut -= 1;
        }
        return Ok(path.with_file_name(format!("{}{hash}", &text[..cut])));
    }
    let mut tmp = OsString::from(name);
    tmp.push(".tmp");
    Ok(path.with_file_name(tmp))
}

/// Writes the output of `fill` to `path` atomically: `fill` writes into a buffered
/// `<name>.tmp` in the same folder, which is synced and renamed over `path` only if `fill`
/// succeeded. On any failure the temporary file is removed and `path` is left untouched.
///
/// # Errors
/// [`WriteError::Io`] naming `path` (including errors returned by `fill`), or
/// [`WriteError::NoFileName`].
pub fn write_atomic_with<F>(path: &Path, fill: F) -> Result<(), WriteError>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    write_via_tmp(path, fill, true).map(drop)
}

/// [`write_atomic_with`] without waiting for the disk: the file is renamed into place unsynced
/// and returned, for the caller to [`File::sync_all`] later (on another thread, or several
/// files at once, before anything depends on the data being durable). For a file inside a
/// folder that is itself moved into place only after that sync (the command line's staging
/// folders), nothing is visible earlier than with [`write_atomic_with`].
///
/// # Errors
/// As [`write_atomic_with`].
pub fn write_atomic_unsynced_with<F>(path: &Path, fill: F) -> Result<File, WriteError>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    write_via_tmp(path, fill, false)
}

/// `fill` into a buffered `<name>.tmp` beside `path`, synced first when `sync`, then renamed
/// over `path` (still open: std opens files with delete sharing, so this holds on Windows too)
/// and returned. On any failure the temporary is removed and `path` is left untouched.
fn write_via_tmp<F>(path: &Path, fill: F, sync: bool) -> Result<File, WriteError>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let tmp = tmp_path(path)?;
    let result = (|| {
        let file = File::create(&tmp)?;
        let mut w = BufWriter::new(file);
        fill(&mut w)?;
        let file = w.into_inner().map_err(io::IntoInnerError::into_error)?;
        if sync {
            file.sync_all()?;
        }
        std::fs::rename(&tmp, path)?;
        Ok(file)
    })();
    result.map_err(|source| {
        // Best effort: the temporary may not even exist.
        let _ = std::fs::remove_file(&tmp);
        WriteError::Io {
            path: path.to_path_buf(),
            source,
        }
    })
}

/// Writes `bytes` to `path` atomically (see [`write_atomic_with`]).
///
/// # Errors
/// As [`write_atomic_with`].
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// The files a run or plan folder may hold (`ccpp run`, `ccpp plan`, a bench's run folders,
/// the Python package's `save`). Such a folder is replaced whole by the next run into it, so a
/// folder holding anything else is refused rather than replaced.
pub const RUN_FILES: [&str; 13] = [
    "run.json",
    "path.csv",
    "trace.jsonl",
    "coverage.png",
    "metrics.json",
    "replay.html",
    "replay.gif",
    "bench-key.txt",
    BENCH_WARNINGS_FILE,
    // The path exports (`crate::export::ExportFormat::file_name`), also `ccpp plan`'s.
    "waypoints.csv",
    "waypoints.json",
    "nav_path.yaml",
    "path.geojson",
];

/// The stamp file ccpp writes into every run or plan folder it writes ([`STAMP_TEXT`]): a
/// folder that holds files is replaced by a run into it only when it holds the stamp too.
/// Before, the files' names alone decided, and a user's own `path.csv` or `metrics.json` in a
/// folder given to `--out` was deleted with the folder (hostile pass, stop 70).
pub const STAMP_FILE: &str = ".ccpp";

/// What the [`STAMP_FILE`] says.
pub const STAMP_TEXT: &str =
    "This folder was written by ccpp: the next ccpp run, plan or save into it replaces it whole.\n";

/// Error of [`check_run_folder`] and [`write_folder`].
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FolderError {
    /// The path names no folder (`.`, `..`, a root).
    #[error("output folder {} must end in a folder name (not ., .. or a root)", path.display())]
    NoName {
        /// The output folder.
        path: PathBuf,
    },
    /// The path exists and is not a folder (a file, a symbolic link).
    #[error("output folder {} exists and is not a plain folder", path.display())]
    NotAFolder {
        /// The output folder.
        path: PathBuf,
    },
    /// The folder is write-protected: its owner said not to change it.
    #[error(
        "output folder {} is read-only: make it writable or give another --out",
        path.display()
    )]
    ReadOnly {
        /// The output folder.
        path: PathBuf,
    },
    /// A folder above the output folder exists as a file (`--out notes.txt/run`).
    #[error(
        "cannot create output folder {}: {} is a file, not a folder",
        path.display(), blocker.display()
    )]
    UnderAFile {
        /// The output folder.
        path: PathBuf,
        /// The part of its path that exists and is not a folder.
        blocker: PathBuf,
    },
    /// A folder above the output folder is a symbolic link that leads nowhere or to itself
    /// (it was called a file).
    #[error(
        "cannot create output folder {}: {} is a symbolic link to nothing or to itself",
        path.display(), blocker.display()
    )]
    UnderABrokenLink {
        /// The output folder.
        path: PathBuf,
        /// The link.
        blocker: PathBuf,
    },
    /// The folder is a run of a `ccpp bench` (it holds its `bench-key.txt`): a user's run,
    /// plan or demo written there replaced it with another map's or planner's run under the
    /// bench's `results.csv`, which then no longer told what the folder held (hostile pass).
    #[error(
        "output folder {} is a run of a ccpp bench (it holds bench-key.txt): written there, it \
         would no longer match the bench's results; choose another folder, or remove that one \
         first",
        path.display()
    )]
    BenchRun {
        /// The output folder.
        path: PathBuf,
    },
    /// The folder holds something ccpp did not write.
    #[error(
        "output folder {} holds {name}, which ccpp did not write; a run replaces the whole \
         folder, so choose a new or ccpp-only folder",
        path.display()
    )]
    Foreign {
        /// The output folder.
        path: PathBuf,
        /// The entry ccpp did not write.
        name: String,
    },
    /// The folder holds only files named as ccpp's, but no [`STAMP_FILE`]: ccpp did not
    /// write it (or a ccpp from before the stamp did), and the files may be a user's.
    #[error(
        "output folder {} holds {name} but no {STAMP_FILE} stamp, so ccpp did not write it (or \
         an older ccpp did); a run replaces the whole folder, so choose a new folder, or remove \
         that one first",
        path.display()
    )]
    Unstamped {
        /// The output folder.
        path: PathBuf,
        /// One of its files.
        name: String,
    },
    /// The folder holds one of the run's own input files (a map named `coverage.png`): the
    /// run would replace or delete it.
    #[error(
        "output folder {} holds {}, an input of this run, which writing the folder would \
         replace or delete; choose another folder",
        path.display(), input.display()
    )]
    HoldsInput {
        /// The output folder.
        path: PathBuf,
        /// The input file inside it (links resolved).
        input: PathBuf,
    },
    /// The folder is the working directory or holds it (`--out ../here` run from `here`): the
    /// swap would remove the folder the process and its shell or notebook are in, and every
    /// relative path used there afterwards fails.
    #[error(
        "output folder {} is the working directory or holds it, which writing the folder would \
         remove; choose another folder",
        path.display()
    )]
    HoldsWorkingDirectory {
        /// The output folder.
        path: PathBuf,
    },
    /// The output folder would lie inside a run folder (`--out ccpp-demo/x`): writing it made
    /// the run folder hold a folder ccpp does not write there, and the next run into the run
    /// folder replaced both.
    #[error(
        "output folder {} lies inside the run folder {}, which a run into it replaces whole; \
         choose a folder outside it",
        path.display(), run.display()
    )]
    InsideRunFolder {
        /// The output folder.
        path: PathBuf,
        /// The run folder above it.
        run: PathBuf,
    },
    /// A folder above the output folder is held by a `ccpp bench` or a Python sweep, which
    /// writes run folders below it and may replace this one.
    #[error(
        "output folder {} lies inside {}, which a ccpp bench or sweep ({holder}) is writing; \
         choose a folder outside it or wait for it to end",
        path.display(), held.display()
    )]
    InsideBusyFolder {
        /// The output folder.
        path: PathBuf,
        /// The held folder above it.
        held: PathBuf,
        /// `pid N` of the holder, as its lock file gives it.
        holder: String,
    },
    /// The folder's name is longer than a file system takes: found before the work, not at
    /// the final rename.
    #[error(
        "output folder {}: its name is {len} bytes, longer than the {NAME_MAX} a file \
         system takes",
        path.display()
    )]
    NameTooLong {
        /// The output folder.
        path: PathBuf,
        /// The name's length in bytes.
        len: usize,
    },
    /// Reading, creating, writing or renaming failed.
    #[error("cannot write output folder {}: {source}", path.display())]
    Io {
        /// The output folder.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: io::Error,
    },
}

/// Whether `name` is one ccpp writes in a run folder: one of [`RUN_FILES`], or the `<file>.tmp`
/// of one of them that an interrupted atomic write left (`ccpp replay` writes its files into
/// the run folder that way). Any other `.tmp` is a user's file.
pub fn is_run_file_name(name: &str) -> bool {
    name == STAMP_FILE
        || RUN_FILES.contains(&name)
        || name
            .strip_suffix(".tmp")
            .is_some_and(|f| RUN_FILES.contains(&f))
}

/// Longest file name the usual file systems take (ext4, XFS, Btrfs, APFS, NTFS), in bytes.
pub const NAME_MAX: usize = 255;

/// The start `.<name>.ccpp-<kind>-` of the names of the staging (`kind` `new`) and set-aside
/// (`old`) folders of the output folder `name`, which go on with `<pid>-<n>`
/// ([`staging_name`]). Kept short enough that the whole name stays within 255 bytes with any
/// process id and counter: a longer `name` is cut at a character boundary and followed by `~`
/// and a hash of the whole name, so that two long names with the same start keep their
/// staging folders apart. Without the cut, a legal 250-byte `--out` failed with "File name too
/// long".
pub fn staging_prefix(name: &str, kind: &str) -> String {
    // `.`, name, `.ccpp-`, kind, `-`, a u32 process id, `-`, a u64 counter.
    let fixed = 1 + ".ccpp-".len() + kind.len() + 1 + 10 + 1 + 20;
    let room = NAME_MAX.saturating_sub(fixed);
    if name.len() <= room {
        return format!(".{name}.ccpp-{kind}-");
    }
    let mut h = ccpp_core::hash::Fnv::new();
    h.bytes(name.as_bytes());
    let hash = format!("~{:016x}", h.finish());
    let mut cut = room.saturating_sub(hash.len());
    while !name.is_char_boundary(cut) {
        cut -= 1;
    }
    format!(".{}{hash}.ccpp-{kind}-", &name[..cut])
}

/// The name of a staging (`kind` `new`) or set-aside (`old`) folder of the output folder
/// `name`, made by process `pid` as its `n`-th: `.<name>.ccpp-<kind>-<pid>-<n>`, within 255
/// bytes (see [`staging_prefix`]).
pub fn staging_name(name: &str, kind: &str, pid: u32, n: u64) -> String {
    format!("{}{pid}-{n}", staging_prefix(name, kind))
}

/// A staging (`kind` `new`) or set-aside (`old`) folder for the output folder `name` in
/// `parent`: [`staging_name`] with this process's id and the next number of one counter that
/// every writer of the process shares (the command line's staging and [`write_folder`] kept a
/// counter each, and could name two folders alike).
pub fn staging_path(parent: &Path, name: &str, kind: &str) -> PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    parent.join(staging_name(name, kind, std::process::id(), n))
}

/// Checks that `target` is absent, or a folder holding only run files ([`is_run_file_name`]:
/// [`RUN_FILES`] and the `.tmp` of one of them left by an interrupted atomic write) that is
/// not the working directory nor above it (`../here` from `here` was taken, and the swap
/// removed the folder the process was in).
///
/// # Errors
/// [`FolderError::NotAFolder`], [`FolderError::HoldsWorkingDirectory`],
/// [`FolderError::Foreign`], or [`FolderError::Io`] when the folder cannot be read.
pub fn check_run_folder(target: &Path) -> Result<(), FolderError> {
    let Ok(meta) = std::fs::symlink_metadata(target) else {
        return Ok(());
    };
    if !meta.is_dir() {
        return Err(FolderError::NotAFolder {
            path: target.to_path_buf(),
        });
    }
    // A write-protected folder is replaced by renames in its parent all the same, and its
    // old content, which cannot be removed, stayed beside it as a hidden copy per run
    // (`chmod 555 out`, then `ccpp run --out out`: exit 0: hostile pass).
    if meta.permissions().readonly() {
        return Err(FolderError::ReadOnly {
            path: target.to_path_buf(),
        });
    }
    // (the working directory as the system resolves it, against the folder resolved likewise;
    // either unknown, e.g. a working directory removed meanwhile: nothing to keep)
    if let (Ok(cwd), Ok(folder)) = (std::env::current_dir(), std::fs::canonicalize(target)) {
        if cwd.starts_with(&folder) {
            return Err(FolderError::HoldsWorkingDirectory {
                path: target.to_path_buf(),
            });
        }
    }
    check_run_folder_entries(target)
}

/// The part of [`check_run_folder`] about what the folder holds: only run files
/// ([`is_run_file_name`]) and, when it holds any, ccpp's [`STAMP_FILE`]. For `ccpp replay`,
/// which writes into a run folder (it wrote over a user's own `replay.html` in a folder
/// without the stamp: hostile pass, stop 70), and which may be run from inside it.
///
/// # Errors
/// [`FolderError::Foreign`], [`FolderError::Unstamped`], or [`FolderError::Io`] when the
/// folder cannot be read.
pub fn check_run_folder_entries(target: &Path) -> Result<(), FolderError> {
    let io_err = |source| FolderError::Io {
        path: target.to_path_buf(),
        source,
    };
    let entries = match std::fs::read_dir(target) {
        Ok(entries) => entries,
        // Renamed away since it was looked at (another thread's swap): absent.
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(io_err(e)),
    };
    // A bench run's `warnings.txt` is ccpp's only beside another file of a run, its
    // `bench-key.txt` or `metrics.json` (`ccpp run` writes none): a user's notes of that name
    // in a folder given to `ccpp run --out` were deleted with the folder. (Beside
    // `bench-key.txt` alone, a bench run folder whose key was removed to force a rerun was
    // refused as holding a file ccpp did not write.)
    let mut bench_only = None;
    let mut beside_run_file = false;
    let mut stamped = false;
    let mut first = None;
    for e in entries {
        let e = e.map_err(io_err)?;
        let name = e.file_name().to_string_lossy().into_owned();
        let known = is_run_file_name(&name);
        if !known || !e.file_type().is_ok_and(|t| t.is_file()) {
            return Err(FolderError::Foreign {
                path: target.to_path_buf(),
                name,
            });
        }
        if name == STAMP_FILE {
            stamped = true;
            continue;
        }
        if first.as_ref().is_none_or(|f: &String| name < *f) {
            first = Some(name.clone());
        }
        if name == "bench-key.txt" || name == "metrics.json" {
            beside_run_file = true;
        } else if name.trim_end_matches(".tmp") == BENCH_WARNINGS_FILE {
            bench_only = Some(name);
        }
    }
    match (bench_only, first) {
        (Some(name), _) if !beside_run_file => Err(FolderError::Foreign {
            path: target.to_path_buf(),
            name,
        }),
        (_, Some(name)) if !stamped => Err(FolderError::Unstamped {
            path: target.to_path_buf(),
            name,
        }),
        _ => Ok(()),
    }
}

/// Checks that `target` is not a run folder of a `ccpp bench` ([`FolderError::BenchRun`]), for
/// the runs, plans and demos a user writes (the bench's own runs replace theirs).
///
/// # Errors
/// [`FolderError::BenchRun`].
pub fn check_not_bench_run(target: &Path) -> Result<(), FolderError> {
    if target.join("bench-key.txt").is_file() {
        return Err(FolderError::BenchRun {
            path: target.to_path_buf(),
        });
    }
    Ok(())
}

/// Checks what can be known of the output folder `target` before a run's work, beyond
/// [`check_run_folder`]: its name fits a file system ([`FolderError::NameTooLong`], found
/// after the whole run at the final rename; hostile pass), and no folder above it is a run
/// folder ([`FolderError::InsideRunFolder`]: `ccpp demo --out ccpp-demo/x` made `ccpp-demo`
/// hold a folder, and a run swapping `ccpp-demo` meanwhile deleted `x` with it).
///
/// # Errors
/// [`FolderError::NameTooLong`], [`FolderError::InsideRunFolder`].
pub fn check_output_place(target: &Path) -> Result<(), FolderError> {
    if let Some(name) = target.file_name() {
        let len = name.as_encoded_bytes().len();
        if len > NAME_MAX {
            return Err(FolderError::NameTooLong {
                path: target.to_path_buf(),
                len,
            });
        }
    }
    let Some(base) = resolved_parent(target) else {
        return Ok(());
    };
    for above in base.ancestors() {
        let marked = ["run.json", "metrics.json"]
            .iter()
            .any(|f| std::fs::symlink_metadata(above.join(f)).is_ok_and(|m| m.is_file()));
        if marked && check_run_folder(above).is_ok() {
            return Err(FolderError::InsideRunFolder {
                path: target.to_path_buf(),
                run: above.to_path_buf(),
            });
        }
    }
    Ok(())
}

/// The folder above `target`, resolved from the nearest one above it that exists (`out/../out`
/// is not inside `out`: a lexical walk took it for so); `None` when none resolves.
fn resolved_parent(target: &Path) -> Option<PathBuf> {
    target
        .ancestors()
        .skip(1)
        .map(|a| {
            if a.as_os_str().is_empty() {
                Path::new(".")
            } else {
                a
            }
        })
        .find_map(|a| std::fs::canonicalize(a).ok())
}

/// Checks that no folder above the output folder `target` is held by another process's
/// running bench or sweep ([`crate::lock::holder_of`]): a `ccpp run --out` into a bench's
/// `runs/MAP/PLANNER` while the bench ran replaced the bench's run folder or was replaced by
/// it. For a user's own run, plan, demo, bench or Python `save`; a bench's or sweep's runs (in
/// its own process or in worker processes) write below their own lock and do not call this.
///
/// # Errors
/// [`FolderError::InsideBusyFolder`].
pub fn check_not_in_busy_folder(target: &Path) -> Result<(), FolderError> {
    let Some(base) = resolved_parent(target) else {
        return Ok(());
    };
    for above in base.ancestors() {
        if let Some(holder) = crate::lock::holder_of(above) {
            return Err(FolderError::InsideBusyFolder {
                path: target.to_path_buf(),
                held: above.to_path_buf(),
                holder,
            });
        }
    }
    Ok(())
}

/// Gives the new folder `staging` the access of the folder `target` it replaces: its
/// permission bits (setgid too) and, where this process may, its owner and group. A private
/// folder (`chmod 2770`, group `lab`) became `drwxr-xr-x` of the process's user and group when
/// a run replaced it (hostile pass). Access control lists are not copied. Best effort: a
/// failure leaves the staging folder's own access.
fn copy_access(target: &Path, staging: &Path) {
    let Ok(meta) = std::fs::metadata(target) else {
        return;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt as _;
        // (best effort, see the doc: changing the owner needs the privilege to; the group
        // needs membership)
        let _ = std::os::unix::fs::chown(staging, Some(meta.uid()), Some(meta.gid()));
        let _ = std::os::unix::fs::chown(staging, None, Some(meta.gid()));
    }
    // (after the owner: a change of owner may clear the setgid bit)
    let _ = std::fs::set_permissions(staging, meta.permissions());
}

/// The warnings file of a bench run folder, one of [`RUN_FILES`] only beside its
/// `bench-key.txt` or `metrics.json` ([`check_run_folder`]).
pub const BENCH_WARNINGS_FILE: &str = "warnings.txt";

/// Checks that none of `inputs` (the files a run reads) lies in the output folder `target`.
/// A folder that [`check_run_folder`] accepts holds only files named as ccpp's outputs, so an
/// input there has such a name (a bare-image map `coverage.png`) and writing the folder would
/// replace or delete it. Paths that do not exist, and an absent `target`, pass.
///
/// # Errors
/// [`FolderError::HoldsInput`] naming the first such input.
pub fn check_inputs_outside(target: &Path, inputs: &[PathBuf]) -> Result<(), FolderError> {
    let Ok(folder) = std::fs::canonicalize(target) else {
        return Ok(());
    };
    for input in inputs {
        // (the file itself: a link outside the folder to a file in it names that file)
        let Ok(file) = std::fs::canonicalize(input) else {
            continue;
        };
        if file.parent() == Some(folder.as_path()) {
            return Err(FolderError::HoldsInput {
                path: target.to_path_buf(),
                input: file,
            });
        }
    }
    Ok(())
}

/// Creates `folder` (the output folder `target` or a folder above it) and its missing
/// ancestors. When a part of the path exists as something other than a folder, the error
/// names that part ([`FolderError::UnderAFile`]), not only the system's "File exists".
///
/// # Errors
/// [`FolderError::UnderAFile`], or [`FolderError::Io`] naming `target`.
pub fn create_folder(folder: &Path, target: &Path) -> Result<(), FolderError> {
    if let Some(blocker) = folder
        .ancestors()
        .filter(|a| !a.as_os_str().is_empty())
        .find(|a| std::fs::symlink_metadata(a).is_ok())
        .filter(|a| !a.is_dir())
    {
        let broken = std::fs::symlink_metadata(blocker).is_ok_and(|m| m.file_type().is_symlink())
            && std::fs::metadata(blocker).is_err();
        return Err(if broken {
            FolderError::UnderABrokenLink {
                path: target.to_path_buf(),
                blocker: blocker.to_path_buf(),
            }
        } else {
            FolderError::UnderAFile {
                path: target.to_path_buf(),
                blocker: blocker.to_path_buf(),
            }
        });
    }
    std::fs::create_dir_all(folder).map_err(|source| FolderError::Io {
        path: target.to_path_buf(),
        source,
    })
}

/// Held while a folder of this process is renamed away and its new content renamed in
/// ([`swap_lock`]): two threads saving into one folder (Python's `save()` from a thread pool)
/// interleaved their renames, failed with "Directory not empty" or "No such file" and left
/// `.NAME.ccpp-old-*` copies behind. The last swap wins.
static FOLDER_SWAP: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// The lock of every folder swap in this process ([`swap_folder`]; the command line's
/// interrupt cleanup holds it too, so that no swap is half done when it exits).
pub fn swap_lock() -> std::sync::MutexGuard<'static, ()> {
    FOLDER_SWAP
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Why [`swap_folder`] failed; each leaves the target as it was, but [`SwapError::Lost`].
#[derive(Debug)]
pub enum SwapError {
    /// The old folder could not be renamed away (nothing moved).
    MoveOld(io::Error),
    /// The new folder could not be renamed in (the old one is back in place).
    MoveNew(io::Error),
    /// The new folder could not be renamed in, nor the old one put back: it is at `old`.
    Lost {
        /// Why the new folder did not move in.
        error: io::Error,
        /// Why the old one did not move back.
        back: io::Error,
    },
}

/// Replaces the folder `target` by `staging`: `target` (when present) is renamed to `old`,
/// `staging` to `target`, and on failure the old folder is put back. The caller holds
/// [`swap_lock`] and removes `old` afterwards (after letting the lock go: removing a large old
/// run need not hold up the other swaps). `before_old` runs before the old folder moves (the
/// command line registers `old` for its interrupt cleanup there). Returns whether there was an
/// old folder.
///
/// # Errors
/// [`SwapError`].
pub fn swap_folder(
    staging: &Path,
    target: &Path,
    old: &Path,
    before_old: impl FnOnce(),
) -> Result<bool, SwapError> {
    let mut before_old = Some(before_old);
    let mut attempt = 0;
    loop {
        attempt += 1;
        // Another process swapping the same folder (two `ccpp run --out o` at once; the lock
        // is per process) can take the old folder away between a look and the rename, or put
        // its new one in: that is a race, not a failure, and the swap goes round again, the
        // last writer winning. It said "cannot replace output folder o: No such file or
        // directory" about once in a hundred such pairs.
        let again = attempt < SWAP_ATTEMPTS;
        let had_old = std::fs::symlink_metadata(target).is_ok();
        if had_old {
            copy_access(target, staging);
            if let Some(f) = before_old.take() {
                f();
            }
            match std::fs::rename(target, old) {
                Ok(()) => {}
                Err(e) if again && e.kind() == io::ErrorKind::NotFound => continue,
                Err(e) => return Err(SwapError::MoveOld(e)),
            }
        }
        let error = match std::fs::rename(staging, target) {
            Ok(()) => return Ok(had_old),
            Err(error) => error,
        };
        let taken = matches!(
            error.kind(),
            io::ErrorKind::AlreadyExists | io::ErrorKind::DirectoryNotEmpty
        );
        // Another writer's complete set is in place (the one moved away is older still), if
        // what is there now is a run folder: anything else is not ccpp's to replace.
        if again && taken && check_run_folder(target).is_ok() {
            if had_old {
                remove_all_quietly(old);
            }
            continue;
        }
        if had_old {
            if let Err(back) = std::fs::rename(old, target) {
                return Err(SwapError::Lost { error, back });
            }
        }
        return Err(SwapError::MoveNew(error));
    }
}

/// Whether the process `pid` still runs (Linux `/proc`; elsewhere assumed gone). A process
/// of another PID namespace (a container sharing the folder) is not seen: its staging
/// folders look stale.
fn pid_alive(pid: u32) -> bool {
    pid == std::process::id() || Path::new("/proc").join(pid.to_string()).exists()
}

/// The process id in a name `.<name>.ccpp-<kind>-<pid>-<n>`.
fn parse_pid(rest: &str) -> Option<u32> {
    rest.split('-').next()?.parse().ok()
}

/// Removes the staging folders of dead processes beside the output folder `parent/name`
/// ([`staging_name`]: a process killed while it wrote, or while it swapped), and puts back an
/// old folder that such a process had renamed away when `name` is missing. The command line
/// does this before each run into a folder, a bench before reusing a run folder, and
/// [`write_folder`] (Python's `save`) before each write: Python left them for good.
pub fn clean_stale(parent: &Path, name: &str) {
    let Ok(entries) = std::fs::read_dir(parent) else {
        return;
    };
    let new_prefix = staging_prefix(name, "new");
    let old_prefix = staging_prefix(name, "old");
    let gone_prefix = staging_prefix(name, GONE);
    let mut names: Vec<String> = entries
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .collect();
    names.sort();
    for n in names {
        // (a folder being removed, [`remove_folder`], is never put back: it may be cut short)
        let (is_old, rest) = if let Some(r) = n.strip_prefix(&new_prefix) {
            (false, r)
        } else if let Some(r) = n.strip_prefix(&old_prefix) {
            (true, r)
        } else if let Some(r) = n.strip_prefix(&gone_prefix) {
            (false, r)
        } else {
            continue;
        };
        let Some(pid) = parse_pid(rest) else { continue };
        if pid_alive(pid) {
            continue;
        }
        let p = parent.join(&n);
        let target = parent.join(name);
        if is_old && !target.exists() && std::fs::rename(&p, &target).is_ok() {
            continue;
        }
        remove_all_quietly(&p);
    }
}

/// The staging kind of a folder [`remove_folder`] renamed away to remove it.
const GONE: &str = "gone";

/// Removes the folder `target` all or nothing as a reader of `target` sees it: it is renamed
/// to a hidden `.NAME.ccpp-gone-PID-N` beside it (under [`swap_lock`], so an interrupt
/// cleanup holding that lock never sees it half moved), then removed. A process stopped
/// during the removal leaves only the hidden folder, which the next [`clean_stale`] beside
/// `target` removes. Removing a folder in place, file by file, left run folders holding a
/// `path.csv` alone when a bench was interrupted (hostile pass).
///
/// # Errors
/// The rename's error (nothing moved); the removal of the renamed folder is best effort.
pub fn remove_folder(target: &Path) -> io::Result<()> {
    let (Some(parent), Some(name)) = (target.parent(), target.file_name().and_then(|n| n.to_str()))
    else {
        return std::fs::remove_dir_all(target);
    };
    let aside = staging_path(parent, name, GONE);
    {
        let _swap = swap_lock();
        std::fs::rename(target, &aside)?;
    }
    remove_all_quietly(&aside);
    Ok(())
}

/// Rounds of [`swap_folder`] against other processes swapping the same folder.
const SWAP_ATTEMPTS: u32 = 16;

/// Removes a folder moved aside, best effort: what is left is a stale `.NAME.ccpp-old-*`
/// folder, which the next write beside it clears.
fn remove_all_quietly(path: &Path) {
    // (best effort by design: see the doc)
    let _ = std::fs::remove_dir_all(path);
}

/// Writes `files` as the whole content of the folder `target`, all or nothing, as the command
/// line writes a run folder: `target` must be absent or hold only [`RUN_FILES`]
/// ([`check_run_folder`]); the files are written and synced into a staging folder
/// `.NAME.ccpp-new-PID-N` beside it, the old folder (if any) is renamed away, the staging
/// folder renamed to `target` and the old one removed (one such swap at a time in a process,
/// so threads writing one folder leave the last set whole). A failure leaves the old folder as
/// it was and no staging folder; a reader sees the old complete set or the new one, never a
/// mix. Parent folders are created as needed.
///
/// # Errors
/// As [`check_run_folder`] and [`create_folder`], [`FolderError::NoName`], or
/// [`FolderError::Io`] naming `target`.
pub fn write_folder(target: &Path, files: &[(&str, Vec<u8>)]) -> Result<(), FolderError> {
    let name = match target.file_name().and_then(|n| n.to_str()) {
        Some(n) if n != "." && n != ".." => n.to_string(),
        _ => {
            return Err(FolderError::NoName {
                path: target.to_path_buf(),
            })
        }
    };
    check_run_folder(target)?;
    check_output_place(target)?;
    let io_err = |source| FolderError::Io {
        path: target.to_path_buf(),
        source,
    };
    let parent = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let existed = std::fs::symlink_metadata(target).is_ok();
    create_folder(&parent, target)?;
    // Renames go through the resolved parent: with `a/../a` the first rename would remove the
    // path the second goes through.
    let parent = parent.canonicalize().map_err(io_err)?;
    clean_stale(&parent, &name);
    let target_in = parent.join(&name);
    if !existed {
        // `create_dir_all("a/..")` created `a`, the target itself (empty): not a run folder.
        // Best effort: an empty folder left behind is harmless (the swap below replaces it).
        let _ = std::fs::remove_dir(&target_in);
    }
    let tag = |kind: &str| staging_path(&parent, &name, kind);
    let staging = tag("new");
    std::fs::create_dir(&staging).map_err(io_err)?;
    let stamp = (STAMP_FILE, STAMP_TEXT.as_bytes().to_vec());
    let written = std::iter::once(&stamp)
        .chain(files)
        .try_for_each(|(file, bytes)| {
            let mut f = File::create(staging.join(file))?;
            f.write_all(bytes)?;
            f.sync_all()
        });
    if let Err(e) = written {
        // Best effort: the write's error is the one to report; a staging folder left behind
        // carries the staging name, never the target's.
        let _ = std::fs::remove_dir_all(&staging);
        return Err(io_err(e));
    }
    // One swap at a time in this process ([`swap_lock`]); the folder is checked again under
    // it (another thread may have swapped it meanwhile).
    let old = tag("old");
    let swap = swap_lock();
    let swapped = check_run_folder(target).and_then(|()| {
        swap_folder(&staging, &target_in, &old, || {}).map_err(|e| match e {
            SwapError::MoveOld(e) | SwapError::MoveNew(e) => io_err(e),
            // The previous folder stays under its hidden name: say where, or the user's
            // earlier run looks lost.
            SwapError::Lost { error, back } => io_err(std::io::Error::new(
                error.kind(),
                format!(
                    "{error}; the previous folder could not be put back ({back}) and is at {}",
                    old.display()
                ),
            )),
        })
    });
    drop(swap);
    let had_old = match swapped {
        Ok(had_old) => had_old,
        Err(e) => {
            // Best effort: the new files are not in place, whatever happens to their staging
            // copy.
            let _ = std::fs::remove_dir_all(&staging);
            return Err(e);
        }
    };
    if had_old {
        // Best effort: the new folder is in place; an old copy left behind carries the
        // staging name (`ccpp run` clears such leftovers of dead processes).
        let _ = std::fs::remove_dir_all(&old);
    }
    Ok(())
}

/// Encodes a grid as a binary (`P5`) 8-bit PGM with `map_saver`'s values: 254 free,
/// 0 occupied, 205 unknown; row 0 of the grid is the first image row.
pub fn encode_pgm(grid: &GridMap) -> Vec<u8> {
    let f = grid.frame();
    let header = format!(
        "P5\n# CREATOR: ccpp-io {:.6} m/pix\n{} {}\n255\n",
        f.resolution, f.width, f.height
    );
    let mut out = Vec::with_capacity(header.len() + grid.cells().len());
    out.extend_from_slice(header.as_bytes());
    out.extend(grid.cells().iter().map(|&c| match c {
        Cell::Free => PGM_FREE,
        Cell::Occupied => PGM_OCCUPIED,
        Cell::Unknown => PGM_UNKNOWN,
    }));
    out
}

/// A `map_server` YAML for an image written by [`encode_pgm`]: `image` (as given, quoted),
/// `resolution`, `origin`, `negate: 0`, `occupied_thresh: 0.65`, `free_thresh: 0.196`,
/// `mode: trinary`. Those thresholds read 254 back as free, 0 as occupied and 205 as unknown.
/// Numbers are written in plain decimal with the shortest digits that round-trip, so they
/// reload exactly.
pub fn map_yaml(frame: &MapFrame, image: &str) -> String {
    let mut quoted = String::with_capacity(image.len() + 2);
    quoted.push('"');
    for ch in image.chars() {
        match ch {
            '"' => quoted.push_str("\\\""),
            '\\' => quoted.push_str("\\\\"),
            c if c.is_control() => {
                let _ = write!(quoted, "\\u{:04x}", u32::from(c));
            }
            c => quoted.push(c),
        }
    }
    quoted.push('"');
    let o = frame.origin;
    format!(
        "image: {quoted}\nresolution: {}\norigin: [{}, {}, {}]\nnegate: 0\n\
         occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n",
        frame.resolution, o.x, o.y, o.theta
    )
}

/// Saves a grid as a `map_server` map: `<stem>.pgm` beside `yaml_path` (see [`encode_pgm`]),
/// then the YAML (see [`map_yaml`]) naming it by its file name. Both files are written
/// atomically, the image first so the YAML never names a missing image. Returns the image path.
///
/// # Errors
/// [`WriteError`] naming the file that could not be written.
pub fn save_map(grid: &GridMap, yaml_path: &Path) -> Result<PathBuf, WriteError> {
    let stem = yaml_path
        .file_stem()
        .ok_or_else(|| WriteError::NoFileName {
            path: yaml_path.to_path_buf(),
        })?;
    let mut image_name = OsString::from(stem);
    image_name.push(".pgm");
    let name = image_name.to_str().ok_or_else(|| WriteError::NonUtf8Name {
        path: yaml_path.to_path_buf(),
    })?;
    let image_path = yaml_path.with_file_name(name);
    write_atomic(&image_path, &encode_pgm(grid))?;
    let yaml = map_yaml(grid.frame(), name);
    write_atomic(yaml_path, yaml.as_bytes())?;
    Ok(image_path)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// `remove_folder` takes the folder away whole, and a removal a dead process left (its
    /// hidden `gone` folder, maybe cut short) is removed beside the target, never put back
    /// in its place as a set-aside `old` folder is.
    #[test]
    fn a_folder_being_removed_is_never_put_back() {
        let d = tempfile::tempdir().unwrap();
        let run = d.path().join("run");
        std::fs::create_dir(&run).unwrap();
        std::fs::write(run.join("path.csv"), "x,y,theta\n").unwrap();
        remove_folder(&run).unwrap();
        assert!(!run.exists());
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 0);
        // A dead process's cut-short removal (no such process id: beyond pid_max).
        let cut = d.path().join(staging_name("run", GONE, 4_194_305, 0));
        std::fs::create_dir(&cut).unwrap();
        std::fs::write(cut.join("path.csv"), "x,y,theta\n").unwrap();
        clean_stale(d.path(), "run");
        assert!(!run.exists() && !cut.exists());
    }

    /// `warnings.txt` is a bench run's only beside its `bench-key.txt` or `metrics.json`: a
    /// user's notes of that name were deleted with a folder given to `ccpp run --out`, and a
    /// bench run folder whose key was removed was refused.
    #[test]
    fn a_warnings_file_is_ccpps_only_in_a_bench_run_folder() {
        let d = tempfile::tempdir().unwrap();
        let notes = d.path().join("notes");
        std::fs::create_dir(&notes).unwrap();
        std::fs::write(notes.join("warnings.txt"), "my notes").unwrap();
        assert!(matches!(
            check_run_folder(&notes),
            Err(FolderError::Foreign { ref name, .. }) if name == "warnings.txt"
        ));
        std::fs::write(notes.join("path.csv"), "x,y,theta\n").unwrap();
        assert!(check_run_folder(&notes).is_err());
        // (beside a run file, and with ccpp's stamp: without it, no folder is ccpp's)
        std::fs::write(notes.join(STAMP_FILE), STAMP_TEXT).unwrap();
        for beside in ["metrics.json", "bench-key.txt"] {
            std::fs::write(notes.join(beside), "{}").unwrap();
            check_run_folder(&notes).unwrap();
            std::fs::remove_file(notes.join(beside)).unwrap();
        }
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n != STAMP_FILE)
            .collect();
        v.sort();
        v
    }

    /// A folder of files named as ccpp's but without its stamp is not ccpp's (a user's own
    /// `path.csv` was deleted with it); every folder `write_folder` writes holds the stamp.
    #[test]
    fn only_a_stamped_folder_is_ccpps() {
        let d = tempfile::tempdir().unwrap();
        let mine = d.path().join("mine");
        std::fs::create_dir(&mine).unwrap();
        std::fs::write(mine.join("path.csv"), "my data").unwrap();
        assert!(matches!(
            check_run_folder(&mine),
            Err(FolderError::Unstamped { ref name, .. }) if name == "path.csv"
        ));
        assert!(write_folder(&mine, &[("path.csv", b"x".to_vec())]).is_err());
        assert_eq!(std::fs::read(mine.join("path.csv")).unwrap(), b"my data");
        let ours = d.path().join("ours");
        write_folder(&ours, &[("path.csv", b"x".to_vec())]).unwrap();
        assert_eq!(
            std::fs::read_to_string(ours.join(STAMP_FILE)).unwrap(),
            STAMP_TEXT
        );
        write_folder(&ours, &[("metrics.json", b"{}".to_vec())]).unwrap();
        assert_eq!(names(&ours), ["metrics.json"]);
    }

    #[test]
    fn write_folder_replaces_the_whole_folder() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("out");
        write_folder(
            &target,
            &[("run.json", b"1".to_vec()), ("path.geojson", b"g".to_vec())],
        )
        .unwrap();
        write_folder(&target, &[("run.json", b"2".to_vec())]).unwrap();
        assert_eq!(names(&target), ["run.json"], "no file of the older set");
        assert_eq!(std::fs::read(target.join("run.json")).unwrap(), b"2");
        assert_eq!(names(d.path()), ["out"], "no staging folder left");
        // Through `..`, new and then existing.
        let dotdot = d.path().join("new/../new");
        write_folder(&dotdot, &[("run.json", b"3".to_vec())]).unwrap();
        write_folder(&dotdot, &[("run.json", b"4".to_vec())]).unwrap();
        assert_eq!(std::fs::read(d.path().join("new/run.json")).unwrap(), b"4");
        assert_eq!(names(d.path()), ["new", "out"]);
    }

    #[test]
    fn only_ccpp_names_are_run_files() {
        for ok in [
            "run.json",
            "replay.gif",
            "replay.html.tmp",
            "metrics.json.tmp",
        ] {
            assert!(is_run_file_name(ok), "{ok}");
        }
        for foreign in ["thesis.tmp", ".tmp", "tmp", "run.json.tmp.tmp", "notes.txt"] {
            assert!(!is_run_file_name(foreign), "{foreign}");
        }
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("u");
        std::fs::create_dir(&target).unwrap();
        std::fs::write(target.join("thesis.tmp"), b"precious").unwrap();
        let e = write_folder(&target, &[("run.json", b"1".to_vec())]).unwrap_err();
        assert!(e.to_string().contains("holds thesis.tmp"), "{e}");
        assert_eq!(names(&target), ["thesis.tmp"]);
    }

    #[test]
    fn staging_names_stay_within_255_bytes() {
        let long = |c: &str, n: usize| c.repeat(n);
        for name in [
            "out".to_string(),
            long("a", 213),
            long("a", 214),
            long("a", 255),
            long("\u{e9}", 127),
            long("\u{1f600}", 63),
        ] {
            for kind in ["new", "old"] {
                let s = staging_name(&name, kind, u32::MAX, u64::MAX);
                assert!(s.len() <= 255, "{} bytes for {} bytes", s.len(), name.len());
                assert!(s.starts_with(&staging_prefix(&name, kind)));
            }
        }
        // Short names are kept whole; long ones that share a start stay apart.
        assert_eq!(staging_name("out", "new", 7, 1), ".out.ccpp-new-7-1");
        let (a, b) = (long("a", 250), format!("{}b", long("a", 249)));
        assert_ne!(staging_prefix(&a, "new"), staging_prefix(&b, "new"));
        // A folder of the longest legal name is written and replaced.
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join(long("a", 255));
        write_folder(&target, &[("run.json", b"1".to_vec())]).unwrap();
        write_folder(&target, &[("run.json", b"2".to_vec())]).unwrap();
        assert_eq!(std::fs::read(target.join("run.json")).unwrap(), b"2");
        assert_eq!(names(d.path()).len(), 1);
    }

    /// Another process's swap can take the old folder away between the look and the rename
    /// (two `ccpp run --out o` at once): the swap goes round again instead of failing with
    /// "No such file or directory".
    #[test]
    fn a_folder_taken_away_mid_swap_is_swapped_again() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("o");
        let staging = d.path().join(".o.new");
        let old = d.path().join(".o.old");
        std::fs::create_dir(&target).unwrap();
        std::fs::write(target.join("metrics.json"), "old").unwrap();
        std::fs::create_dir(&staging).unwrap();
        std::fs::write(staging.join("metrics.json"), "new").unwrap();
        // The other process: it moves the folder away just before this one's rename.
        let elsewhere = d.path().join("elsewhere");
        let had_old = swap_folder(&staging, &target, &old, || {
            std::fs::rename(&target, &elsewhere).unwrap();
        })
        .unwrap();
        assert!(!had_old);
        assert_eq!(
            std::fs::read_to_string(target.join("metrics.json")).unwrap(),
            "new"
        );
        assert!(!staging.exists() && !old.exists());
    }

    /// Threads saving into one folder (Python's `save()` from a thread pool) interleaved their
    /// renames: "Directory not empty", "No such file", and hidden `.out.ccpp-old-*` copies
    /// left beside the folder. The swaps now take turns: every save succeeds and the folder
    /// holds one whole set.
    #[test]
    fn threads_writing_one_folder_take_turns() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("out");
        for round in 0..10 {
            std::thread::scope(|s| {
                for t in 0..4 {
                    let target = &target;
                    s.spawn(move || {
                        let tag = format!("{round}-{t}");
                        write_folder(
                            target,
                            &[
                                ("metrics.json", tag.clone().into_bytes()),
                                ("path.csv", tag.into_bytes()),
                            ],
                        )
                        .unwrap();
                    });
                }
            });
            assert_eq!(names(d.path()), ["out"], "round {round}");
            let a = std::fs::read(target.join("metrics.json")).unwrap();
            assert_eq!(a, std::fs::read(target.join("path.csv")).unwrap());
        }
    }

    #[test]
    fn write_folder_refuses_what_it_would_destroy() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("out");
        std::fs::create_dir(&target).unwrap();
        std::fs::write(target.join("notes.txt"), b"mine").unwrap();
        let e = write_folder(&target, &[("run.json", b"1".to_vec())]).unwrap_err();
        assert!(e.to_string().contains("holds notes.txt"), "{e}");
        assert_eq!(names(&target), ["notes.txt"]);
        let file = d.path().join("file");
        std::fs::write(&file, b"x").unwrap();
        let e = write_folder(&file, &[]).unwrap_err();
        assert!(e.to_string().contains("not a plain folder"), "{e}");
        assert!(write_folder(Path::new("/"), &[]).is_err());
        assert_eq!(names(d.path()), ["file", "out"]);
    }
}
