//! Numbers in messages: short whatever their size. Rust prints an `f64` in full positional
//! notation (`1e300` as 301 digits), which turns a one-line error into a wall of zeros;
//! [`Compact`] switches to scientific notation outside `[1e-4, 1e9)`.

use std::fmt;

/// An `f64` shown compactly: as Rust shows it (shortest round-trip digits, or the precision
/// asked for, as in `{:.3}`) when `1e-4 <= |v| < 1e9` or `v` is 0, else in scientific
/// notation (`1e300`, `{:.3}` -> `1.000e300`). Non-finite values print as `NaN`, `inf`,
/// `-inf`.
///
/// ```
/// use ccpp_core::display::Compact;
/// assert_eq!(Compact(0.25).to_string(), "0.25");
/// assert_eq!(Compact(1e300).to_string(), "1e300");
/// assert_eq!(format!("{:.3}", Compact(-2.5e-7)), "-2.500e-7");
/// assert_eq!(format!("{:.3}", Compact(1.0)), "1.000");
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Compact(pub f64);

impl fmt::Display for Compact {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.0;
        let a = v.abs();
        let plain = !v.is_finite() || v == 0.0 || (1e-4..1e9).contains(&a);
        match (plain, f.precision()) {
            (true, Some(p)) => write!(f, "{v:.p$}"),
            (true, None) => write!(f, "{v}"),
            (false, Some(p)) => write!(f, "{v:.p$e}"),
            (false, None) => write!(f, "{v:e}"),
        }
    }
}

/// Comma-separated compact numbers (`0,0,1e300,1e300`), as zones and areas are written.
pub fn join(values: &[f64]) -> String {
    values
        .iter()
        .map(|v| Compact(*v).to_string())
        .collect::<Vec<_>>()
        .join(",")
}

/// `v` with `decimals` decimals, as a table shows it, but never a non-zero value as 0: one that
/// would show as zeros is written to three significant digits (`--resolution 1e-5` printed a
/// 200 px map as "0.00 x 0.00 m" and its widest spot as "clearance 0.000 m").
///
/// ```
/// use ccpp_core::display::fixed;
/// assert_eq!(fixed(10.0, 2), "10.00");
/// assert_eq!(fixed(0.002, 2), "2.00e-3");
/// assert_eq!(fixed(0.0, 2), "0.00");
/// assert_eq!(fixed(-0.0004, 3), "-4.00e-4");
/// ```
pub fn fixed(v: f64, decimals: usize) -> String {
    let shown = format!("{v:.decimals$}");
    let all_zero = shown
        .trim_start_matches('-')
        .bytes()
        .all(|b| b == b'0' || b == b'.');
    if v != 0.0 && v.is_finite() && all_zero {
        format!("{v:.2e}")
    } else {
        shown
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stays_short() {
        for v in [
            1e300,
            -1e300,
            1e-300,
            f64::MAX,
            f64::MIN_POSITIVE,
            123_456_789_012.5,
        ] {
            assert!(Compact(v).to_string().len() <= 24, "{}", Compact(v));
            assert!(
                format!("{:.3}", Compact(v)).len() <= 12,
                "{:.3}",
                Compact(v)
            );
        }
        assert_eq!(join(&[0.0, -1.5, 1e300]), "0,-1.5,1e300");
        assert_eq!(Compact(f64::NAN).to_string(), "NaN");
        assert_eq!(format!("{:.3}", Compact(f64::INFINITY)), "inf");
    }
}
