//! Pixel classification: ROS `map_server`'s `trinary`, `scale` and `raw` modes ([`Thresholds`],
//! [`MapMode`], [`classify`]).

use ccpp_core::display::Compact;
use std::path::Path;

use ccpp_core::grid::Cell;

use super::error::MapError;

/// Default `occupied_thresh` of ROS `map_server` when the YAML has none.
pub const DEFAULT_OCCUPIED_THRESH: f64 = 0.65;
/// Default `free_thresh` of ROS `map_server` when the YAML has none.
pub const DEFAULT_FREE_THRESH: f64 = 0.196;

/// How a `map_server` YAML's `mode` reads a pixel (module docs of [`crate::map`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MapMode {
    /// `p` from the grey level, three classes by the thresholds (the default).
    #[default]
    Trinary,
    /// As trinary, and a transparent pixel (alpha below its maximum) is unknown. `map_server`
    /// grades the occupancies between the thresholds (1..99); ccpp has no graded cells and
    /// keeps them unknown, as trinary does.
    Scale,
    /// The grey level is the occupancy in percent: 0..=100 gives `p = v / 100` (rounded to
    /// a whole level first), classified by the thresholds; 101 and above is unknown.
    Raw,
}

impl MapMode {
    /// The mode named by a YAML `mode` value (`trinary`, `scale`, `raw`; any case, spaces
    /// around ignored), or `None`.
    pub fn parse(name: &str) -> Option<Self> {
        let n = name.trim();
        [
            ("trinary", Self::Trinary),
            ("scale", Self::Scale),
            ("raw", Self::Raw),
        ]
        .into_iter()
        .find(|(k, _)| n.eq_ignore_ascii_case(k))
        .map(|(_, m)| m)
    }

    /// The YAML name of the mode.
    pub fn name(self) -> &'static str {
        match self {
            Self::Trinary => "trinary",
            Self::Scale => "scale",
            Self::Raw => "raw",
        }
    }
}

/// Classification thresholds and mode of `map_server`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thresholds {
    /// A pixel whose occupancy probability `p` is strictly above this is occupied.
    pub occupied: f64,
    /// A pixel whose occupancy probability `p` is strictly below this is free.
    pub free: f64,
    /// When `true`, `p = v / 255` (light is occupied) instead of `p = (255 - v) / 255`.
    pub negate: bool,
    /// The YAML's `mode`.
    pub mode: MapMode,
}

impl Default for Thresholds {
    /// The `map_server` defaults: occupied 0.65, free 0.196, not negated.
    fn default() -> Self {
        Self {
            occupied: DEFAULT_OCCUPIED_THRESH,
            free: DEFAULT_FREE_THRESH,
            negate: false,
            mode: MapMode::Trinary,
        }
    }
}

impl Thresholds {
    /// Checks that both thresholds lie in `[0, 1]`, that `free < occupied`, and that `negate`
    /// is not asked of `raw` mode (ROS 1's `map_server` inverts a raw value, Nav2's does not:
    /// such a map means two different things).
    ///
    /// # Errors
    /// [`MapError::BadValue`] naming `path` and the offending field.
    pub fn validate(&self, path: &Path) -> Result<(), MapError> {
        let bad = |field, reason| MapError::BadValue {
            path: path.to_path_buf(),
            field,
            reason,
        };
        for (field, v) in [
            ("occupied_thresh", self.occupied),
            ("free_thresh", self.free),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(bad(field, format!("{} is not in [0, 1]", Compact(v))));
            }
        }
        if self.free >= self.occupied {
            return Err(bad(
                "free_thresh",
                format!(
                    "free_thresh {} must be below occupied_thresh {}",
                    Compact(self.free),
                    Compact(self.occupied)
                ),
            ));
        }
        if self.negate && self.mode == MapMode::Raw {
            return Err(bad(
                "negate",
                "negate: 1 with mode: raw is ambiguous (ROS 1 map_server inverts raw values, \
                 Nav2 does not); invert the image and set negate: 0"
                    .to_owned(),
            ));
        }
        Ok(())
    }

    /// Classifies an occupancy probability `p`: `p > occupied` is occupied, `p < free` is free,
    /// anything else (including NaN) unknown.
    #[inline]
    pub fn classify_probability(&self, p: f64) -> Cell {
        if p > self.occupied {
            Cell::Occupied
        } else if p < self.free {
            Cell::Free
        } else {
            Cell::Unknown
        }
    }

    /// Classifies a grey level on the 0..=255 scale, possibly fractional (the mean of R, G, B
    /// or a rescaled 16-bit value). `p = (255 - level) / 255`, or `level / 255` when negated,
    /// computed in `f64` exactly as `map_server` does; in `raw` mode the level rounded is the
    /// occupancy in percent (above 100: unknown).
    #[inline]
    pub fn classify_level(&self, level: f64) -> Cell {
        if self.mode == MapMode::Raw {
            let v = level.round();
            return if v <= 100.0 {
                self.classify_probability(v / 100.0)
            } else {
                Cell::Unknown
            };
        }
        let p = if self.negate {
            level / 255.0
        } else {
            (255.0 - level) / 255.0
        };
        self.classify_probability(p)
    }

    /// A lookup table of [`classify`] for every 8-bit grey value.
    pub fn lut(&self) -> [Cell; 256] {
        let mut t = [Cell::Unknown; 256];
        for (v, c) in (0u8..=255).zip(t.iter_mut()) {
            *c = classify(v, self);
        }
        t
    }
}

/// Classifies one 8-bit grey value `v` with `map_server`'s trinary rule: `p = (255 - v) / 255`
/// (`v / 255` when negated), occupied when `p > t.occupied`, free when `p < t.free`, otherwise
/// unknown. The comparison is done in `f64` without rounding, so grey 205 (`p = 0.19608`) stays
/// unknown under the usual `free_thresh` of 0.196.
///
/// ```
/// use ccpp_core::grid::Cell;
/// use ccpp_io::map::{classify, Thresholds};
/// let t = Thresholds::default();
/// assert_eq!(classify(254, &t), Cell::Free);
/// assert_eq!(classify(205, &t), Cell::Unknown);
/// assert_eq!(classify(0, &t), Cell::Occupied);
/// ```
#[inline]
pub fn classify(v: u8, t: &Thresholds) -> Cell {
    t.classify_level(f64::from(v))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn map_saver_values_under_ros_defaults() {
        let t = Thresholds::default();
        assert_eq!(classify(254, &t), Cell::Free);
        assert_eq!(classify(255, &t), Cell::Free);
        assert_eq!(classify(206, &t), Cell::Free);
        assert_eq!(classify(205, &t), Cell::Unknown);
        assert_eq!(classify(90, &t), Cell::Unknown);
        assert_eq!(classify(89, &t), Cell::Occupied);
        assert_eq!(classify(0, &t), Cell::Occupied);
    }

    #[test]
    fn other_thresholds_and_negate() {
        let willow = Thresholds {
            free: 0.1,
            ..Thresholds::default()
        };
        assert_eq!(classify(206, &willow), Cell::Unknown);
        assert_eq!(classify(230, &willow), Cell::Free);
        let depot = Thresholds {
            free: 0.25,
            ..Thresholds::default()
        };
        assert_eq!(classify(205, &depot), Cell::Free);
        let neg = Thresholds {
            negate: true,
            ..Thresholds::default()
        };
        assert_eq!(classify(0, &neg), Cell::Free);
        assert_eq!(classify(255, &neg), Cell::Occupied);
        assert_eq!(classify(50, &neg), Cell::Unknown); // p = 0.19608
    }

    #[test]
    fn strict_comparisons_at_exact_ties() {
        // p = 51 / 255 = 0.2 exactly: neither > 0.2 nor < 0.2.
        let t = Thresholds {
            occupied: 0.2,
            free: 0.1,
            negate: false,
            mode: MapMode::Trinary,
        };
        assert_eq!(classify(204, &t), Cell::Unknown);
        assert_eq!(classify(203, &t), Cell::Occupied);
        let t = Thresholds {
            occupied: 0.9,
            free: 0.2,
            negate: false,
            mode: MapMode::Trinary,
        };
        assert_eq!(classify(204, &t), Cell::Unknown);
        assert_eq!(classify(205, &t), Cell::Free);
        assert_eq!(t.classify_probability(f64::NAN), Cell::Unknown);
    }

    #[test]
    fn lut_matches_classify() {
        let t = Thresholds {
            occupied: 0.5,
            free: 0.3,
            negate: true,
            mode: MapMode::Trinary,
        };
        let lut = t.lut();
        for v in 0..=255u8 {
            assert_eq!(lut[usize::from(v)], classify(v, &t));
        }
    }

    #[test]
    fn validate() {
        let p = Path::new("x.yaml");
        assert!(Thresholds::default().validate(p).is_ok());
        assert!(Thresholds {
            occupied: 1.0,
            free: 0.0,
            negate: false,
            mode: MapMode::Trinary,
        }
        .validate(p)
        .is_ok());
        for (o, f) in [
            (0.5, 0.5),
            (0.5, 0.6),
            (1.1, 0.1),
            (0.5, -0.1),
            (f64::NAN, 0.1),
        ] {
            let t = Thresholds {
                occupied: o,
                free: f,
                negate: false,
                mode: MapMode::Trinary,
            };
            assert!(
                matches!(t.validate(p), Err(MapError::BadValue { .. })),
                "{o} {f}"
            );
        }
    }

    #[test]
    fn modes_by_name_and_raw_levels() {
        assert_eq!(MapMode::parse(" Scale "), Some(MapMode::Scale));
        assert_eq!(MapMode::parse("RAW"), Some(MapMode::Raw));
        assert_eq!(MapMode::parse("trinary"), Some(MapMode::Trinary));
        assert_eq!(MapMode::parse("tri"), None);
        for m in [MapMode::Trinary, MapMode::Scale, MapMode::Raw] {
            assert_eq!(MapMode::parse(m.name()), Some(m));
        }
        // Scale reads grey levels as trinary does.
        let scale = Thresholds {
            mode: MapMode::Scale,
            ..Thresholds::default()
        };
        for v in 0..=255u8 {
            assert_eq!(
                classify(v, &scale),
                classify(v, &Thresholds::default()),
                "{v}"
            );
        }
        // Raw: the value is the occupancy in percent.
        let raw = Thresholds {
            mode: MapMode::Raw,
            ..Thresholds::default()
        };
        assert_eq!(classify(0, &raw), Cell::Free);
        assert_eq!(classify(19, &raw), Cell::Free); // p = 0.19 < 0.196
        assert_eq!(classify(20, &raw), Cell::Unknown);
        assert_eq!(classify(65, &raw), Cell::Unknown); // not above 0.65
        assert_eq!(classify(66, &raw), Cell::Occupied);
        assert_eq!(classify(100, &raw), Cell::Occupied);
        assert_eq!(classify(101, &raw), Cell::Unknown);
        assert_eq!(classify(255, &raw), Cell::Unknown);
        // A colour mean rounds to a whole level first.
        assert_eq!(raw.classify_level(65.6), Cell::Occupied);
        assert_eq!(raw.classify_level(100.4), Cell::Occupied);
        assert_eq!(raw.classify_level(100.5), Cell::Unknown);
        // Raw and negate: refused.
        let p = Path::new("r.yaml");
        assert!(raw.validate(p).is_ok());
        let e = Thresholds {
            negate: true,
            ..raw
        }
        .validate(p)
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("negate") && e.contains("raw") && e.contains("r.yaml"),
            "{e}"
        );
    }
}
