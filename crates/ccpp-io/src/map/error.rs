//! [`MapError`]: everything that can go wrong while loading a map.

use std::io;
use std::path::PathBuf;

use ccpp_core::grid::GridError;

/// Error while loading a map. Every variant names the file it is about, and every message is a
/// single line that says what is wrong and where.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MapError {
    /// The map file (YAML or image) given by the user does not exist.
    #[error("map file not found: {}", path.display())]
    NotFound {
        /// The missing file.
        path: PathBuf,
    },
    /// Reading a file failed for another reason than "not found".
    #[error("cannot read {}: {source}", path.display())]
    Io {
        /// The file being read.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: io::Error,
    },
    /// The YAML is malformed or a field has the wrong type.
    #[error("invalid map YAML {}: {message}", path.display())]
    Yaml {
        /// The YAML file.
        path: PathBuf,
        /// What the YAML parser reported (flattened to one line).
        message: String,
    },
    /// A required YAML field (`image`, `resolution` or `origin`) is absent.
    #[error("map YAML {} lacks the required field `{field}`", path.display())]
    MissingField {
        /// The YAML file.
        path: PathBuf,
        /// The missing field.
        field: &'static str,
    },
    /// A field has a value outside its domain (resolution <= 0 or NaN, thresholds outside
    /// `[0, 1]` or `free_thresh >= occupied_thresh`, non-finite origin, bad `negate`, ...).
    #[error("map {}: bad `{field}`: {reason}", path.display())]
    BadValue {
        /// The YAML (or bare image) whose value, possibly overridden, is bad.
        path: PathBuf,
        /// The field.
        field: &'static str,
        /// The value and why it is refused.
        reason: String,
    },
    /// The image named by the YAML's `image` field does not exist.
    #[error("map YAML {} names image {}, which does not exist", yaml.display(), image.display())]
    ImageNotFound {
        /// The YAML file.
        yaml: PathBuf,
        /// The image path, resolved against the YAML's folder.
        image: PathBuf,
    },
    /// The image named by the YAML's `image` field exists but cannot be read (a folder, a
    /// device, no permission): said with the YAML that names it (`image: /dev/zero` read
    /// "cannot read /dev/zero: not a regular file", naming neither the YAML nor the field).
    #[error(
        "map YAML {} names image {}, which cannot be read: {source}",
        yaml.display(),
        image.display()
    )]
    ImageUnreadable {
        /// The YAML file.
        yaml: PathBuf,
        /// The image path, resolved against the YAML's folder.
        image: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: io::Error,
    },
    /// The image could not be decoded (corrupt, truncated, unsupported format, too large).
    #[error("cannot decode map image {}: {message}", path.display())]
    Decode {
        /// The image file.
        path: PathBuf,
        /// What the decoder reported (flattened to one line).
        message: String,
    },
    /// The image has more pixels than [`super::LoadOptions::max_pixels`] allows (told by its
    /// header; nothing was decoded).
    #[error(
        "map image {} is {width} x {height} px, more than the {max_pixels} pixels allowed",
        path.display()
    )]
    TooLarge {
        /// The image file.
        path: PathBuf,
        /// Its width, px.
        width: u32,
        /// Its height, px.
        height: u32,
        /// The most pixels allowed.
        max_pixels: u64,
    },
    /// The YAML asks for a `mode` other than `trinary`, `scale` or `raw`.
    #[error(
        "map YAML {}: unsupported mode `{}` (map_server's modes are trinary, scale and raw)",
        path.display(),
        crate::message::visible(mode)
    )]
    UnsupportedMode {
        /// The YAML file.
        path: PathBuf,
        /// The mode asked for.
        mode: String,
    },
    /// A key that is not one of `map_server`'s but so near one the file leaves out, with a
    /// value that field could take, that it is taken for a misspelling (`negat: 1`,
    /// `occupied_threshold: 0.5`, `Resolution: 0.05`). `map_server` ignores unknown keys, so a
    /// misspelt optional field silently falls back to its default (an un-negated map, other
    /// thresholds); other unknown keys are ignored here too.
    #[error(
        "map YAML {}: unknown key `{key}`; did you mean `{field}`? (map_server would ignore it {})",
        path.display(),
        if matches!(*field, "image" | "resolution" | "origin") {
            format!("and refuse the map without `{field}`")
        } else {
            format!("and use the default of `{field}`")
        }
    )]
    MisspeltField {
        /// The YAML file.
        path: PathBuf,
        /// The key as written.
        key: String,
        /// The field it is near.
        field: &'static str,
    },
    /// The decoded image does not make a valid grid (e.g. it has no pixel).
    #[error("map {}: {source}", path.display())]
    Grid {
        /// The image or YAML file.
        path: PathBuf,
        /// The grid error.
        #[source]
        source: GridError,
    },
}

/// Collapses a possibly multi-line message (YAML snippets, decoder chains) to one line.
pub(crate) fn one_line(message: &str) -> String {
    let parts: Vec<&str> = message
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    parts.join(" | ")
}
