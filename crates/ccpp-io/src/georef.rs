//! `--georef FILE`: point pairs for the affine pixel -> world fit of seed 003
//! ([`ccpp_core::georef::fit_affine`]).
//!
//! Format: one pair per line, `px,py,wx,wy` (pixel column, pixel row, world x, world y; commas
//! or whitespace between the numbers). Blank lines are skipped and `#` starts a comment to the
//! end of its line; a first line none of whose fields is a number is taken as a header and
//! skipped (a data line with one bad field is an error, never a header).
//!
//! ```
//! let text = "px,py,wx,wy\n0,0,0,5\n100,0,5,5\n0,100,0,0\n";
//! let pairs = ccpp_io::georef::parse_georef(text).unwrap();
//! let fit = ccpp_core::georef::fit_affine(&pairs).unwrap();
//! let w = fit.affine.apply(ccpp_core::Point::new(50.0, 50.0));
//! assert!((w.x - 2.5).abs() < 1e-9 && (w.y - 2.5).abs() < 1e-9);
//! ```

use std::path::{Path, PathBuf};

use ccpp_core::georef::{fit_affine, AffineFit, GeorefError};
use ccpp_core::Point;

/// What is wrong with a georef file, without the file's name (a message that names the file
/// already shows this alone; [`GeorefFileError`] adds the name).
#[derive(Debug, thiserror::Error)]
pub enum GeorefProblem {
    /// The file could not be read.
    #[error("cannot read it: {0}")]
    Io(std::io::Error),
    /// A line is not four numbers.
    #[error("line {line}: expected `px,py,wx,wy` (four numbers), got {text:?}")]
    BadLine {
        /// 1-based line number.
        line: usize,
        /// The line.
        text: String,
    },
    /// The fit failed.
    #[error("{0}")]
    Fit(GeorefError),
    /// More point pairs than [`MAX_GEOREF_PAIRS`].
    #[error("more than {MAX_GEOREF_PAIRS} point pairs: a survey has a few dozen (2 million pairs held 146 MB in a run admitted under 20 MB)")]
    TooMany,
}

/// Most `(pixel, world)` pairs a georef file may hold: a least-squares affine fit needs 3 and
/// a survey gives tens; the bound keeps a file from holding memory no estimate counts.
pub const MAX_GEOREF_PAIRS: usize = 4096;

/// Errors reading a georef file: the [`GeorefProblem`] and the file.
#[derive(Debug, thiserror::Error)]
#[error("georef file {}: {problem}", path.display())]
pub struct GeorefFileError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong with it.
    pub problem: GeorefProblem,
}

/// Splits a line into fields on commas, semicolons or whitespace.
pub(crate) fn fields(line: &str) -> impl Iterator<Item = &str> {
    line.split(|c: char| c == ',' || c == ';' || c.is_whitespace())
        .filter(|s| !s.is_empty())
}

/// The content lines of a small CSV-like file (georef pairs, landmarks), numbered from 0, each
/// without its comment (from `#` to the end of the line) and surrounding white space; lines
/// left empty are skipped (a file's byte-order mark, Excel's "CSV UTF-8", is skipped where
/// the file is read, `read_text`). A trailing comment is a comment too: `0,0,0,10 # corner` was taken for a header and
/// its pair dropped without a word. The flag says whether the line is a header: the first
/// content line, with no number at all (`px,py,wx,wy`; a first line `-1,1.5,1.5` with a bad
/// field is a data line, to be refused, not a header to skip).
pub(crate) fn content_lines(text: &str) -> impl Iterator<Item = (usize, &str, bool)> {
    text.lines()
        .enumerate()
        .map(|(n, raw)| (n, raw.split('#').next().unwrap_or_default().trim()))
        .filter(|(_, line)| !line.is_empty())
        .enumerate()
        .map(|(k, (n, line))| {
            let header = k == 0 && fields(line).all(|f| f.parse::<f64>().is_err());
            (n, line, header)
        })
}

/// Parses `(pixel, world)` pairs from the text of a georef file.
///
/// # Errors
/// [`GeorefProblem::BadLine`] for a line that is not four finite numbers (other than a
/// header on the first content line).
pub fn parse_georef(text: &str) -> Result<Vec<(Point, Point)>, GeorefProblem> {
    let mut pairs = Vec::new();
    for (n, line, header) in content_lines(text) {
        let nums: Option<Vec<f64>> = fields(line)
            .map(|f| f.parse::<f64>().ok().filter(|v| v.is_finite()))
            .collect();
        match nums {
            Some(v) if v.len() == 4 => {
                if pairs.len() == MAX_GEOREF_PAIRS {
                    return Err(GeorefProblem::TooMany);
                }
                pairs.push((Point::new(v[0], v[1]), Point::new(v[2], v[3])));
            }
            None if header => {}
            _ => {
                return Err(GeorefProblem::BadLine {
                    line: n + 1,
                    text: line.to_string(),
                })
            }
        }
    }
    Ok(pairs)
}

/// Reads a georef file and fits the affine pixel -> world transform.
///
/// # Errors
/// Unreadable file, bad line, or a fit that fails (fewer than 3 pairs, collinear points).
pub fn load_georef(path: &Path) -> Result<AffineFit, GeorefFileError> {
    let fit = crate::file::read_text(path)
        .map_err(GeorefProblem::Io)
        .and_then(|text| parse_georef(&text))
        .and_then(|pairs| fit_affine(&pairs).map_err(GeorefProblem::Fit));
    fit.map_err(|problem| GeorefFileError {
        path: path.to_path_buf(),
        problem,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_comments_header_and_separators() {
        let t = "# survey\nu v x y\n1 2 3 4\n5,6,7,8\n\n9;10;11;12\n";
        let p = parse_georef(t).unwrap();
        assert_eq!(p.len(), 3);
        assert_eq!(p[1], (Point::new(5.0, 6.0), Point::new(7.0, 8.0)));
    }

    /// A first line with a trailing comment is data, and a first line with a number among
    /// words is an error, not a header: either once dropped a pair without a word.
    #[test]
    fn trailing_comments_and_half_numeric_first_lines() {
        let p = parse_georef("0,0,0,10 # a\n200,0,10,10\n0,200,0,0 # c\n").unwrap();
        assert_eq!(p.len(), 3);
        // A file's byte-order mark is skipped once, where it is read; a second one is content.
        let d = tempfile::tempdir().unwrap();
        let g = d.path().join("g.csv");
        std::fs::write(&g, "\u{feff}0,0,0,10\n200,0,10,10\n0,200,0,0\n").unwrap();
        assert!(load_georef(&g).is_ok());
        std::fs::write(&g, "\u{feff}\u{feff}0,0,0,10\n200,0,10,10\n0,200,0,0\n").unwrap();
        assert!(load_georef(&g).is_err());
        assert_eq!(p[0], (Point::new(0.0, 0.0), Point::new(0.0, 10.0)));
        let e = parse_georef("0,0,x,10\n200,0,10,10\n").unwrap_err();
        assert!(matches!(e, GeorefProblem::BadLine { line: 1, .. }), "{e}");
    }

    #[test]
    fn bad_lines_are_named() {
        let e = parse_georef("1,2,3,4\n1,2,3\n").unwrap_err();
        assert!(e.to_string().contains("line 2"), "{e}");
        let e = parse_georef("1,2,3,4\n1,2,x,4\n").unwrap_err();
        assert!(matches!(e, GeorefProblem::BadLine { line: 2, .. }));
    }

    #[test]
    fn file_roundtrip_and_fit_errors() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("g.csv");
        std::fs::write(&f, "0,0,0,0\n1,1,1,1\n2,2,2,2\n").unwrap();
        let e = load_georef(&f).unwrap_err();
        assert!(matches!(
            e.problem,
            GeorefProblem::Fit(GeorefError::Collinear)
        ));
        assert_eq!(
            e.to_string(),
            format!("georef file {}: {}", f.display(), GeorefError::Collinear)
        );
        std::fs::write(&f, "0,0,0,0\n10,0,1,0\n0,10,0,-1\n").unwrap();
        let fit = load_georef(&f).unwrap();
        assert!(fit.max_residual < 1e-12);
        assert!(matches!(
            load_georef(&dir.path().join("missing.csv")),
            Err(GeorefFileError {
                problem: GeorefProblem::Io(_),
                ..
            })
        ));
    }
}
