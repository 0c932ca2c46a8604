//! Pixel classification: ROS `map_server` trinary mode ([`Thresholds`], [`classify`]).

use std::path::Path;

use ccpp_core::grid::Cell;

use super::error::MapError;

/// Default `occupied_thresh` of ROS `map_server` when the YAML has none.
pub const DEFAULT_OCCUPIED_THRESH: f64 = 0.65;
/// Default `free_thresh` of ROS `map_server` when the YAML has none.
pub const DEFAULT_FREE_THRESH: f64 = 0.196;

/// Trinary classification thresholds of `map_server`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thresholds {
    /// A pixel whose occupancy probability `p` is strictly above this is occupied.
    pub occupied: f64,
    /// A pixel whose occupancy probability `p` is strictly below this is free.
    pub free: f64,
    /// When `true`, `p = v / 255` (light is occupied) instead of `p = (255 - v) / 255`.
    pub negate: bool,
}

impl Default for Thresholds {
    /// The `map_server` defaults: occupied 0.65, free 0.196, not negated.
    fn default() -> Self {
        Self {
            occupied: DEFAULT_OCCUPIED_THRESH,
            free: DEFAULT_FREE_THRESH,
            negate: false,
        }
    }
}

impl Thresholds {
    /// Checks that both thresholds lie in `[0, 1]` and that `free < occupied`.
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
                return Err(bad(field, format!("{v} is not in [0, 1]")));
            }
        }
        if self.free >= self.occupied {
            return Err(bad(
                "free_thresh",
                format!(
                    "free_thresh {} must be below occupied_thresh {}",
                    self.free, self.occupied
                ),
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
    /// computed in `f64` exactly as `map_server` does.
    #[inline]
    pub fn classify_level(&self, level: f64) -> Cell {
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
        };
        assert_eq!(classify(204, &t), Cell::Unknown);
        assert_eq!(classify(203, &t), Cell::Occupied);
        let t = Thresholds {
            occupied: 0.9,
            free: 0.2,
            negate: false,
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
            negate: false
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
            };
            assert!(
                matches!(t.validate(p), Err(MapError::BadValue { .. })),
                "{o} {f}"
            );
        }
    }
}
