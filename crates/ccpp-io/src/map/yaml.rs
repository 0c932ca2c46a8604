//! The ROS `map_server` YAML file ([`MapYaml`]).

use std::fmt;
use std::path::Path;

use serde::de::{self, Deserializer, Visitor};
use serde::Deserialize;

use super::classify::Thresholds;
use super::error::{one_line, MapError};

/// Default `occupied_thresh` of ROS `map_server` when the YAML has none.
pub const DEFAULT_OCCUPIED_THRESH: f64 = 0.65;
/// Default `free_thresh` of ROS `map_server` when the YAML has none.
pub const DEFAULT_FREE_THRESH: f64 = 0.196;

/// A parsed and validated ROS `map_server` YAML.
///
/// ```yaml
/// image: map.pgm            # required; relative to the YAML's folder, or absolute
/// resolution: 0.05          # required; metres per pixel, finite and > 0
/// origin: [-10, -10, 0.0]   # required; world pose (x, y, yaw) of the lower-left pixel
/// negate: 0                 # optional, 0/1 or false/true (default 0)
/// occupied_thresh: 0.65     # optional (default 0.65)
/// free_thresh: 0.196        # optional (default 0.196)
/// mode: trinary             # optional; only trinary is supported by the loader
/// ```
///
/// Unknown keys are ignored, as `map_server` does.
#[derive(Clone, Debug, PartialEq)]
pub struct MapYaml {
    /// The image file as written in the YAML (not yet resolved against the YAML's folder).
    pub image: String,
    /// Metres per pixel.
    pub resolution: f64,
    /// World pose `(x, y, yaw)` of the lower-left corner of the lower-left pixel.
    pub origin: [f64; 3],
    /// `true` when the image is negated (`p = v / 255`).
    pub negate: bool,
    /// Occupancy probability above which a pixel is occupied.
    pub occupied_thresh: f64,
    /// Occupancy probability below which a pixel is free.
    pub free_thresh: f64,
    /// The `mode` field when present (`trinary`, `scale` or `raw` in `map_server`).
    pub mode: Option<String>,
}

/// What the YAML holds before the required fields are checked.
#[derive(Deserialize)]
struct RawYaml {
    image: Option<String>,
    resolution: Option<f64>,
    origin: Option<Vec<f64>>,
    negate: Option<Negate>,
    occupied_thresh: Option<f64>,
    free_thresh: Option<f64>,
    mode: Option<String>,
}

/// `negate` as written: an integer or a boolean.
enum Negate {
    Int(i64),
    Bool(bool),
    Other(String),
}

impl<'de> Deserialize<'de> for Negate {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Negate;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("0, 1, false or true")
            }
            fn visit_bool<E: de::Error>(self, v: bool) -> Result<Negate, E> {
                Ok(Negate::Bool(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Negate, E> {
                Ok(Negate::Int(v))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Negate, E> {
                Ok(i64::try_from(v).map_or_else(|_| Negate::Other(v.to_string()), Negate::Int))
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Negate, E> {
                Ok(Negate::Other(v.to_string()))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Negate, E> {
                Ok(Negate::Other(format!("{v:?}")))
            }
        }
        deserializer.deserialize_any(V)
    }
}

impl MapYaml {
    /// Parses and validates the text of a map YAML. `path` is only used in error messages.
    ///
    /// # Errors
    /// [`MapError::Yaml`] for malformed YAML or wrongly typed fields,
    /// [`MapError::MissingField`] when `image`, `resolution` or `origin` is absent, and
    /// [`MapError::BadValue`] for out-of-domain values (see [`validate_placement`] and
    /// [`Thresholds::validate`]). The mode is not checked here.
    pub fn parse(text: &str, path: &Path) -> Result<Self, MapError> {
        let raw: RawYaml = serde_saphyr::from_str(text).map_err(|e| MapError::Yaml {
            path: path.to_path_buf(),
            message: one_line(&e.to_string()),
        })?;
        let missing = |field| MapError::MissingField {
            path: path.to_path_buf(),
            field,
        };
        let bad = |field, reason| MapError::BadValue {
            path: path.to_path_buf(),
            field,
            reason,
        };

        let image = raw.image.ok_or_else(|| missing("image"))?;
        if image.trim().is_empty() {
            return Err(bad("image", "the image file name is empty".to_owned()));
        }
        let resolution = raw.resolution.ok_or_else(|| missing("resolution"))?;
        let origin_v = raw.origin.ok_or_else(|| missing("origin"))?;
        let origin: [f64; 3] = origin_v.as_slice().try_into().map_err(|_| {
            bad(
                "origin",
                format!(
                    "expected 3 numbers [x, y, yaw], got {} ({origin_v:?})",
                    origin_v.len()
                ),
            )
        })?;
        let negate = match raw.negate {
            None | Some(Negate::Int(0) | Negate::Bool(false)) => false,
            Some(Negate::Int(1) | Negate::Bool(true)) => true,
            Some(Negate::Int(v)) => return Err(bad("negate", format!("{v} is not 0 or 1"))),
            Some(Negate::Other(v)) => {
                return Err(bad("negate", format!("{v} is not 0, 1, false or true")))
            }
        };
        let yaml = Self {
            image,
            resolution,
            origin,
            negate,
            occupied_thresh: raw.occupied_thresh.unwrap_or(DEFAULT_OCCUPIED_THRESH),
            free_thresh: raw.free_thresh.unwrap_or(DEFAULT_FREE_THRESH),
            mode: raw.mode,
        };
        validate_placement(yaml.resolution, yaml.origin, path)?;
        yaml.thresholds().validate(path)?;
        Ok(yaml)
    }

    /// The classification thresholds of this YAML.
    pub fn thresholds(&self) -> Thresholds {
        Thresholds {
            occupied: self.occupied_thresh,
            free: self.free_thresh,
            negate: self.negate,
        }
    }
}

/// Checks that `resolution` is finite and > 0 and that `origin` is finite.
///
/// # Errors
/// [`MapError::BadValue`] naming `path` and the field.
pub fn validate_placement(resolution: f64, origin: [f64; 3], path: &Path) -> Result<(), MapError> {
    if !(resolution.is_finite() && resolution > 0.0) {
        return Err(MapError::BadValue {
            path: path.to_path_buf(),
            field: "resolution",
            reason: format!("{resolution} is not a finite number > 0"),
        });
    }
    if !origin.iter().all(|v| v.is_finite()) {
        return Err(MapError::BadValue {
            path: path.to_path_buf(),
            field: "origin",
            reason: format!("{origin:?} has a non-finite component"),
        });
    }
    Ok(())
}
