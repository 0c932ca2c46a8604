//! Opening user files safely: only regular files are read, so a FIFO, a device or a folder
//! named as a map, image, landmark, georef, options or trace file is an error instead of a
//! read that never ends.

use std::fs::File;
use std::io;
use std::path::Path;

/// Opens `path` for reading if it is a regular file (following symlinks).
///
/// # Errors
/// The file does not exist, is not a regular file, or cannot be opened.
pub fn open_regular(path: &Path) -> io::Result<File> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "not a regular file",
        ));
    }
    File::open(path)
}

/// Reads a regular file's bytes.
///
/// # Errors
/// As [`open_regular`], plus read errors.
pub fn read_bytes(path: &Path) -> io::Result<Vec<u8>> {
    let mut v = Vec::new();
    io::Read::read_to_end(&mut open_regular(path)?, &mut v)?;
    Ok(v)
}

/// Reads a regular file as UTF-8 text.
///
/// # Errors
/// As [`open_regular`], plus read errors and invalid UTF-8.
pub fn read_text(path: &Path) -> io::Result<String> {
    let mut s = String::new();
    io::Read::read_to_string(&mut open_regular(path)?, &mut s)?;
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folders_are_refused() {
        let d = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
        let e = read_text(d.path()).err().map(|e| e.to_string());
        assert_eq!(e.as_deref(), Some("not a regular file"));
    }
}
