//! `--landmarks FILE`: landmarks for the simulator's pose correction
//! ([`ccpp_core::landmarks`], seed 001's non-unique `AprilTags`).
//!
//! Two formats, chosen by content: a JSON array of `{"id": 1, "x": 2.0, "y": 3.0}` objects
//! (optional `"theta"`, radians), or CSV lines `id,x,y[,theta]` (commas, semicolons or
//! whitespace; blank lines and `#` comments skipped; a first line without any number is a header).
//!
//! ```
//! let l = ccpp_io::landmarks::parse_landmarks("id,x,y\n1,0.5,2\n1,4.5,2,1.57\n").unwrap();
//! assert_eq!(l.len(), 2);
//! assert_eq!(l[1].theta, 1.57);
//! let j = ccpp_io::landmarks::parse_landmarks(r#"[{"id": 3, "x": 1, "y": 2}]"#).unwrap();
//! assert_eq!(j[0].id, 3);
//! ```

use std::path::{Path, PathBuf};

use ccpp_core::landmarks::Landmark;

use crate::georef::{content_lines, fields};

/// Errors reading a landmark file.
#[derive(Debug, thiserror::Error)]
pub enum LandmarkFileError {
    /// The file could not be read (the message leaves the path to the caller, which names the
    /// file once, as `landmarks FILE: cannot read it: ...`).
    #[error("cannot read it: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// Invalid JSON.
    #[error("landmark JSON: {0}")]
    Json(String),
    /// A CSV line is not `id,x,y[,theta]`.
    #[error("landmark line {line}: expected `id,x,y[,theta]` (integer id, finite numbers), got {text:?}")]
    BadLine {
        /// 1-based line number.
        line: usize,
        /// The line.
        text: String,
    },
    /// A landmark has a non-finite coordinate.
    #[error("landmark {index} has a non-finite coordinate")]
    NonFinite {
        /// 0-based index.
        index: usize,
    },
    /// More landmarks than [`MAX_LANDMARKS`].
    #[error("more than {MAX_LANDMARKS} landmarks: every control step looks at each of them (2.8 million rows ran for hours); give the landmarks of the site")]
    TooMany,
    /// A file that holds no landmark (blank, or comments only): read and then nothing to
    /// correct with, the run would be the run without it.
    #[error("the file holds no landmark")]
    Empty,
}

/// Most landmarks a file may hold: every PID control step checks each landmark in sensor range
/// of the robot, so the run's time grows with their number (1 000 rows added 3 s to a run on
/// a 51 m map, 10 000 rows 20 s); a site has tens to hundreds of tags.
pub const MAX_LANDMARKS: usize = 4096;

fn parse_csv_line(line: &str) -> Option<Landmark> {
    let f: Vec<&str> = fields(line).collect();
    if !(3..=4).contains(&f.len()) {
        return None;
    }
    let id = f[0].parse::<u32>().ok()?;
    let num = |s: &str| s.parse::<f64>().ok().filter(|v| v.is_finite());
    Some(Landmark {
        id,
        x: num(f[1])?,
        y: num(f[2])?,
        theta: match f.get(3) {
            Some(s) => num(s)?,
            None => 0.0,
        },
    })
}

/// Parses landmarks from JSON or CSV text.
///
/// # Errors
/// Invalid JSON, a bad CSV line, or a non-finite coordinate.
pub fn parse_landmarks(text: &str) -> Result<Vec<Landmark>, LandmarkFileError> {
    // (A file's byte-order mark is skipped where it is read, `read_text`: here a second one,
    // or one in text given directly, is content, refused as such.)
    let trimmed = text.trim_start();
    let list: Vec<Landmark> = if trimmed.starts_with('[') {
        // Counted before they are built: the array's items are skipped, whatever their form
        // (objects, or arrays, which serde also takes for a landmark; braces of extra fields
        // inside an object are not items). A zero-sized item allocates nothing.
        let items: Vec<serde::de::IgnoredAny> =
            serde_json::from_str(trimmed).map_err(|e| LandmarkFileError::Json(e.to_string()))?;
        if items.len() > MAX_LANDMARKS {
            return Err(LandmarkFileError::TooMany);
        }
        serde_json::from_str(trimmed).map_err(|e| {
            // serde's words for an item of the wrong length name the struct's four fields
            // (`expected struct Landmark with 4 elements`); the theta is optional.
            let text = e.to_string();
            let text = if text.contains("struct Landmark") || text.contains("trailing characters") {
                format!("each landmark is [id, x, y] or [id, x, y, theta], or an object with those fields ({text})")
            } else {
                text
            };
            LandmarkFileError::Json(text)
        })?
    } else {
        let mut out = Vec::new();
        // Lines and headers as in a georef file: a byte-order mark, trailing comments and
        // blank lines (a file saved as Excel's "CSV UTF-8" lost its first landmark as a
        // "header"); a header has no number at all (`id,x,y`: a first line `-1,1.5,1.5`, a bad
        // id, was taken for a header and dropped without a word).
        for (n, line, header) in content_lines(text) {
            match parse_csv_line(line) {
                Some(_) if out.len() == MAX_LANDMARKS => return Err(LandmarkFileError::TooMany),
                Some(l) => out.push(l),
                None if header => {}
                None => {
                    return Err(LandmarkFileError::BadLine {
                        line: n + 1,
                        text: line.to_string(),
                    })
                }
            }
        }
        out
    };
    if let Some(index) = list
        .iter()
        .position(|l| !(l.x.is_finite() && l.y.is_finite() && l.theta.is_finite()))
    {
        return Err(LandmarkFileError::NonFinite { index });
    }
    Ok(list)
}

/// Reads and parses a landmark file.
///
/// # Errors
/// As [`parse_landmarks`], plus an unreadable file and one that holds no landmark
/// ([`LandmarkFileError::Empty`]: the CLI and Python both refuse it).
pub fn load_landmarks(path: &Path) -> Result<Vec<Landmark>, LandmarkFileError> {
    let text = crate::file::read_text(path).map_err(|source| LandmarkFileError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let list = parse_landmarks(&text)?;
    if list.is_empty() {
        return Err(LandmarkFileError::Empty);
    }
    Ok(list)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_and_json() {
        let l = parse_landmarks("# tags\n1 0 0\n2;1.5;-2;0.5\n").unwrap();
        assert_eq!(
            l,
            vec![
                Landmark::new(1, 0.0, 0.0),
                Landmark {
                    id: 2,
                    x: 1.5,
                    y: -2.0,
                    theta: 0.5
                }
            ]
        );
        let e = parse_landmarks("1,0,0\n-1,0,0\n").unwrap_err();
        assert!(
            matches!(e, LandmarkFileError::BadLine { line: 2, .. }),
            "{e}"
        );
        // The same bad line first is an error too, not a header; a header has no number.
        let e = parse_landmarks("-1,1.5,1.5\n2,-1.5,-1.5\n").unwrap_err();
        assert!(
            matches!(e, LandmarkFileError::BadLine { line: 1, .. }),
            "{e}"
        );
        assert_eq!(parse_landmarks("id x y\n2 0 0\n").unwrap().len(), 1);
        // Excel's "CSV UTF-8" starts with a byte-order mark (the first landmark was taken for
        // a header, then refused as a bad line): the file reader skips it, once (a second one
        // is content, as in every text input); a comment may end a line, as in georef files.
        let d = tempfile::tempdir().unwrap();
        let file = |name: &str, text: &str| {
            let p = d.path().join(name);
            std::fs::write(&p, text).unwrap();
            load_landmarks(&p)
        };
        let l = file("l.csv", "\u{feff}1,1.0,1.0\n2,4.0,4.0 # dock\n").unwrap();
        assert_eq!(
            l,
            vec![Landmark::new(1, 1.0, 1.0), Landmark::new(2, 4.0, 4.0)]
        );
        let l = file("l.json", "\u{feff}[{\"id\":1,\"x\":0,\"y\":0}]").unwrap();
        assert_eq!(l, vec![Landmark::new(1, 0.0, 0.0)]);
        assert!(file("l2.csv", "\u{feff}\u{feff}1,1.0,1.0\n").is_err());
        // (text that does not start with `[` is CSV: this is one header line, no landmark,
        // which the loader refuses as a file holding none)
        let l2 = file("l2.json", "\u{feff}\u{feff}[{\"id\":1,\"x\":0,\"y\":0}]");
        assert!(matches!(l2, Err(LandmarkFileError::Empty)), "{l2:?}");
        assert!(matches!(
            file("c.csv", "# id,x,y\n"),
            Err(LandmarkFileError::Empty)
        ));
        assert!(matches!(
            parse_landmarks("[{\"id\":1}]"),
            Err(LandmarkFileError::Json(_))
        ));
        assert!(parse_landmarks("").unwrap().is_empty());
        // An item of the wrong length says what an item is.
        for bad in ["[[1, 0]]", "[[1, 0, 0, 0, 0]]"] {
            let e = parse_landmarks(bad).unwrap_err().to_string();
            assert!(
                e.contains("each landmark is [id, x, y] or [id, x, y, theta]"),
                "{bad}: {e}"
            );
        }
        // A misspelt field is refused (it was dropped: the tag faced east).
        let e = parse_landmarks(r#"[{"id":1,"x":0,"y":0,"thta":1.0}]"#).unwrap_err();
        assert!(e.to_string().contains("unknown field `thta`"), "{e}");
    }

    #[test]
    fn file() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("l.json");
        std::fs::write(&f, r#"[{"id":1,"x":1,"y":2,"theta":0.1}]"#).unwrap();
        assert_eq!(load_landmarks(&f).unwrap()[0].theta, 0.1);
        assert!(matches!(
            load_landmarks(&dir.path().join("none")),
            Err(LandmarkFileError::Io { .. })
        ));
    }
}
