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

/// The temporary path `<name>.tmp` beside `path`.
fn tmp_path(path: &Path) -> Result<PathBuf, WriteError> {
    let name = path.file_name().ok_or_else(|| WriteError::NoFileName {
        path: path.to_path_buf(),
    })?;
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
