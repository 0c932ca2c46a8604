//! Loading occupancy grid maps: ROS `map_server` YAML + PGM/PNG, or a bare image.
//!
//! # Pixel rule
//!
//! Each pixel becomes a [`Cell`](ccpp_core::grid::Cell) by `map_server`'s rule for the YAML's
//! `mode` ([`MapMode`]; **trinary** when there is none or the map is a bare image):
//!
//! 1. Grey level `v` on the 0..=255 scale:
//!    * grey images (8-bit): the value itself;
//!    * colour images (RGB, RGBA, palette): the **exact** mean `(R + G + B) / 3` as an `f64`, no
//!      integer rounding (this is what `map_server` computes too);
//!    * **alpha is ignored** in trinary and raw modes. The real ROS loaders average alpha in as
//!      a fourth channel in trinary mode, which turns the grey 205 "unknown" of an opaque RGBA
//!      map into free; we follow the documented rule instead, so 205 stays unknown whatever
//!      the alpha. In **scale** mode a transparent pixel (alpha below its maximum) is unknown,
//!      as documented for `map_server`;
//!    * 16-bit images: `v = v16 / 257` as an `f64` (65535 -> 255.0, 205 * 257 -> 205.0), not
//!      truncated to 8 bits first; PGMs whose maxval is not 255 or 65535 are rescaled to the
//!      full range by the decoder (rounded to the nearest integer).
//! 2. `p = (255 - v) / 255`, or `p = v / 255` with `negate`. In **raw** mode the level is the
//!    occupancy in percent: `p = round(v) / 100` for `round(v) <= 100`, unknown above (255 is
//!    the usual unknown); `negate` with raw is refused (ROS 1 inverts a raw value, Nav2 does
//!    not).
//! 3. `p > occupied_thresh` -> occupied, `p < free_thresh` -> free, else unknown, compared in
//!    `f64` without rounding (grey 205 stays unknown under `free_thresh: 0.196`). Scale mode's
//!    graded occupancies between the thresholds stay unknown: ccpp's cells have no grades, and
//!    a robot should not count uncertain floor as floor to clean.
//!
//! A `mode` other than these three is refused ([`MapError::UnsupportedMode`]).
//!
//! # Frame
//!
//! The image's first row is the grid's row 0 (the top, largest y); `origin` is the world pose
//! of the lower-left pixel, with its yaw kept in [`MapFrame::origin`]`.theta`.

mod classify;
mod error;
pub(crate) mod pixels;
mod yaml;

use std::io::{BufReader, Cursor};
use std::path::{Path, PathBuf};

use ccpp_core::display::Compact;
use ccpp_core::geometry::Pose;
use ccpp_core::grid::{GridMap, MapFrame};
use image::ImageReader;

pub use classify::{classify, MapMode, Thresholds, DEFAULT_FREE_THRESH, DEFAULT_OCCUPIED_THRESH};
pub(crate) use error::one_line;
pub use error::MapError;
pub use yaml::{heading_problem, validate_placement, MapYaml, MAX_HEADING_RAD};

/// Resolution (m/px) of a bare image when no override is given.
pub const DEFAULT_BARE_RESOLUTION: f64 = 0.05;

/// Overrides applied on top of the YAML (or of the bare-image defaults: 0.05 m/px, origin
/// `(0, 0, 0)`, thresholds 0.65 / 0.196, not negated). `None` keeps the file's value.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LoadOptions {
    /// Metres per pixel.
    pub resolution: Option<f64>,
    /// World pose `(x, y, yaw)` of the lower-left pixel.
    pub origin: Option<[f64; 3]>,
    /// `occupied_thresh`.
    pub occupied_thresh: Option<f64>,
    /// `free_thresh`.
    pub free_thresh: Option<f64>,
    /// `negate`.
    pub negate: Option<bool>,
    /// Most pixels the image may have: a larger one is refused from its header, before it is
    /// decoded ([`MapError::TooLarge`]). `None`: only the decoder's own allocation limit.
    pub max_pixels: Option<u64>,
}

/// A loaded map.
#[derive(Clone, Debug)]
pub struct LoadedMap {
    /// The classified grid with its frame.
    pub grid: GridMap,
    /// The file the map was loaded from: the YAML, or the image for a bare image.
    pub source: PathBuf,
    /// The image file (resolved against the YAML's folder).
    pub image_path: PathBuf,
    /// The thresholds used, after overrides.
    pub thresholds: Thresholds,
    /// Pixels ROS `map_server` would classify otherwise: it averages the alpha channel of an
    /// 8-bit RGBA or grey+alpha image in with the colour in trinary mode, which ccpp does
    /// not (README, Maps); 0 for other images and modes. `ccpp info` notes it.
    pub alpha_differs: usize,
}

/// Loads a map from a YAML (`.yaml` / `.yml`, case-insensitive) or a bare image (any other
/// extension; PNG or PGM/PNM detected from the content).
///
/// The YAML's `image` is resolved against the YAML's folder unless absolute. `opts` override
/// the file's values; the result is validated after the overrides.
///
/// # Errors
/// See [`MapError`]: missing files, malformed YAML, missing or bad fields, unsupported mode,
/// undecodable image. Never panics on user data.
pub fn load_map(path: &Path, opts: &LoadOptions) -> Result<LoadedMap, MapError> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => {}
        Ok(m) => {
            // (a folder given as the map said "not a regular file" only: docs review)
            let what = if m.is_dir() {
                "a folder, not a map: give a map_server YAML or an image"
            } else {
                "not a regular file"
            };
            return Err(MapError::Io {
                path: path.to_path_buf(),
                source: std::io::Error::other(what),
            });
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(MapError::NotFound {
                path: path.to_path_buf(),
            })
        }
        Err(e) => {
            return Err(MapError::Io {
                path: path.to_path_buf(),
                source: e,
            })
        }
    }
    if is_yaml_path(path) {
        let bytes = crate::file::read_bytes(path).map_err(|e| MapError::Io {
            path: path.to_path_buf(),
            source: e,
        })?;
        let text = std::str::from_utf8(&bytes).map_err(|e| MapError::Yaml {
            path: path.to_path_buf(),
            message: format!("not UTF-8 text ({e})"),
        })?;
        // The thresholds are checked with the overrides applied (`finish`).
        let yaml = MapYaml::parse_fields(text, path, opts.resolution, opts.origin)?;
        let image_path = image_beside(path, &yaml.image);
        let file = match crate::file::open_regular(&image_path) {
            Ok(f) => f,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(MapError::ImageNotFound {
                    yaml: path.to_path_buf(),
                    image: image_path,
                })
            }
            Err(e) => {
                return Err(MapError::ImageUnreadable {
                    yaml: path.to_path_buf(),
                    image: image_path,
                    source: e,
                })
            }
        };
        let reader = ImageReader::new(BufReader::new(file));
        finish(Some(&yaml), path, image_path, reader, opts)
    } else {
        let file = crate::file::open_regular(path).map_err(|e| MapError::Io {
            path: path.to_path_buf(),
            source: e,
        })?;
        let reader = ImageReader::new(BufReader::new(file));
        finish(None, path, path.to_path_buf(), reader, opts)
    }
}

/// Loads a map held in memory, e.g. embedded in a binary with `include_str!` /
/// `include_bytes!`.
///
/// * `name`: a name for the map (such as `demo/map.yaml`), used as [`LoadedMap::source`] and in
///   error messages; nothing is read from disk.
/// * `yaml`: the YAML text, or `None` for a bare image (bare-image defaults apply). The YAML's
///   `image` field is not opened; it is only joined to `name`'s folder for
///   [`LoadedMap::image_path`].
/// * `image`: the PNG or PGM bytes.
///
/// ```
/// use std::path::Path;
/// use ccpp_core::grid::Cell;
/// use ccpp_io::map::{load_map_bytes, LoadOptions};
/// let pgm = b"P5 2 1 255\n\x00\xfe";
/// let yaml = "image: tiny.pgm\nresolution: 0.1\norigin: [1.0, 2.0, 0.0]\n";
/// let m = load_map_bytes(Path::new("tiny.yaml"), Some(yaml), pgm, &LoadOptions::default())?;
/// assert_eq!(m.grid.get(0, 0), Cell::Occupied);
/// assert_eq!(m.grid.get(1, 0), Cell::Free);
/// # Ok::<(), ccpp_io::map::MapError>(())
/// ```
///
/// # Errors
/// As [`load_map`], except the file-system ones.
pub fn load_map_bytes(
    name: &Path,
    yaml: Option<&str>,
    image: &[u8],
    opts: &LoadOptions,
) -> Result<LoadedMap, MapError> {
    let reader = ImageReader::new(Cursor::new(image));
    match yaml {
        Some(text) => {
            let y = MapYaml::parse_fields(text, name, opts.resolution, opts.origin)?;
            let image_path = image_beside(name, &y.image);
            finish(Some(&y), name, image_path, reader, opts)
        }
        None => finish(None, name, name.to_path_buf(), reader, opts),
    }
}

/// `true` for `.yaml` / `.yml` (any case).
fn is_yaml_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("yaml") || e.eq_ignore_ascii_case("yml"))
}

/// Applies overrides, validates, decodes and builds the grid.
fn finish<R: std::io::BufRead + std::io::Seek>(
    yaml: Option<&MapYaml>,
    source: &Path,
    image_path: PathBuf,
    reader: ImageReader<R>,
    opts: &LoadOptions,
) -> Result<LoadedMap, MapError> {
    if let Some(mode) = yaml.and_then(|y| y.mode.as_deref()) {
        if MapMode::parse(mode).is_none() {
            return Err(MapError::UnsupportedMode {
                path: source.to_path_buf(),
                mode: mode.to_owned(),
            });
        }
    }
    let bare = yaml.is_none();
    let (res, origin, base) = yaml.map_or(
        (DEFAULT_BARE_RESOLUTION, [0.0; 3], Thresholds::default()),
        |y| (y.resolution, y.origin, y.thresholds()),
    );
    let resolution = opts.resolution.unwrap_or(res);
    let origin = opts.origin.unwrap_or(origin);
    let thresholds = Thresholds {
        occupied: opts.occupied_thresh.unwrap_or(base.occupied),
        free: opts.free_thresh.unwrap_or(base.free),
        negate: opts.negate.unwrap_or(base.negate),
        mode: base.mode,
    };
    validate_placement(resolution, origin, source)?;
    thresholds.validate(source).map_err(|e| {
        // Thresholds that cross because of an override: say which value was given and which
        // is the map's (`--occupied-thresh 0.1` was reported as a bad `free_thresh`).
        let theirs = if bare {
            "the default for a bare image"
        } else {
            "the map's"
        };
        let (t, given) = (
            &thresholds,
            |o: Option<f64>| if o.is_some() { "given" } else { theirs },
        );
        // Only the order of two thresholds in [0, 1] is reworded (`--free-thresh 1.1` said
        // "must be below occupied_thresh", not "not in [0, 1]").
        let in_range = (0.0..=1.0).contains(&t.free) && (0.0..=1.0).contains(&t.occupied);
        match e {
            MapError::BadValue {
                path,
                field: "free_thresh",
                ..
            } if in_range && t.free >= t.occupied && opts.occupied_thresh.is_some() => {
                MapError::BadValue {
                    path,
                    field: "occupied_thresh",
                    reason: format!(
                        "occupied_thresh {} (given) must be above free_thresh {} ({})",
                        Compact(t.occupied),
                        Compact(t.free),
                        given(opts.free_thresh)
                    ),
                }
            }
            MapError::BadValue {
                path,
                field: "free_thresh",
                ..
            } if in_range && t.free >= t.occupied && opts.free_thresh.is_some() => {
                MapError::BadValue {
                    path,
                    field: "free_thresh",
                    reason: format!(
                        "free_thresh {} (given) must be below occupied_thresh {} ({theirs})",
                        Compact(t.free),
                        Compact(t.occupied)
                    ),
                }
            }
            e => e,
        }
    })?;

    // A PNM header with a comment right after a token (`50#c`, which Netpbm allows) is
    // rewritten without its comments first: the decoder refused it ("Non-ASCII-digit character
    // when parsing number in preamble": hostile pass).
    let mut inner = reader.into_inner();
    let c = match pixels::tight_pnm_header(&mut inner).map_err(|e| MapError::Io {
        path: image_path.clone(),
        source: e,
    })? {
        Some(plain) => pixels::decode_and_classify(
            ImageReader::new(Cursor::new(plain)),
            &image_path,
            &thresholds,
            opts.max_pixels,
        )?,
        None => pixels::decode_and_classify(
            ImageReader::new(inner),
            &image_path,
            &thresholds,
            opts.max_pixels,
        )?,
    };
    let frame = MapFrame {
        width: c.width,
        height: c.height,
        resolution,
        origin: Pose::new(origin[0], origin[1], origin[2]),
    };
    let grid = GridMap::new(frame, c.cells).map_err(|e| MapError::Grid {
        path: image_path.clone(),
        source: e,
    })?;
    Ok(LoadedMap {
        grid,
        source: source.to_path_buf(),
        image_path,
        thresholds,
        alpha_differs: c.alpha_differs,
    })
}

/// The image a map YAML names, resolved beside it (`None`: not a YAML path, or a file that
/// does not read as a map YAML). For the output-folder check of the files a run reads.
pub fn yaml_image_path(path: &Path) -> Option<PathBuf> {
    if !is_yaml_path(path) {
        return None;
    }
    let bytes = crate::file::read_bytes(path).ok()?;
    let text = std::str::from_utf8(&bytes).ok()?;
    // Any placement stands in for the file's: only the image is read here.
    let yaml = MapYaml::parse_fields(text, path, Some(1.0), Some([0.0; 3])).ok()?;
    Some(image_beside(path, &yaml.image))
}

/// The image a map YAML at `yaml` names, `image` resolved beside it (as `map_server` does).
fn image_beside(yaml: &Path, image: &str) -> PathBuf {
    yaml.parent().unwrap_or(Path::new("")).join(image)
}
