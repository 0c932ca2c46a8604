//! Trace files: `trace.jsonl` (every pose and event, one JSON object a line) and `path.csv`
//! (the executed path at its segment ends), written and read back with checks, so that a
//! damaged or hand-edited trace is refused with the line at fault instead of hanging a
//! renderer.

use std::path::{Path, PathBuf};

use ccpp_core::grid::MapFrame;
use ccpp_core::route::{Route, DEFAULT_TOLERANCE_M};
use ccpp_core::trace::{Record, Trace};

/// Error reading a trace.
#[derive(Debug, thiserror::Error)]
pub enum TraceFileError {
    /// The file cannot be read.
    #[error("cannot read trace {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A line is not a trace record.
    #[error("trace {} line {line}: not a trace record ({message})", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// The parser's message.
        message: String,
    },
    /// A pose lies far outside the map (or is not finite).
    #[error("trace {} line {line}: pose ({x}, {y}) lies outside the map ({lo_x}, {lo_y} to {hi_x}, {hi_y})", path.display())]
    OutsideMap {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// Pose x.
        x: f64,
        /// Pose y.
        y: f64,
        /// Map lower corner x.
        lo_x: f64,
        /// Map lower corner y.
        lo_y: f64,
        /// Map upper corner x.
        hi_x: f64,
        /// Map upper corner y.
        hi_y: f64,
    },
}

/// The trace as JSON Lines.
///
/// # Errors
/// A record that cannot be serialized (non-finite numbers are written as `null` by
/// `serde_json`, so this does not happen for simulator traces).
pub fn trace_jsonl(trace: &Trace) -> Result<String, serde_json::Error> {
    let mut s = String::with_capacity(trace.records.len() * 48);
    for r in &trace.records {
        s.push_str(&serde_json::to_string(r)?);
        s.push('\n');
    }
    Ok(s)
}

/// The executed path as CSV, decimated to its segment ends: header `x,y,theta`, then one
/// line per waypoint of [`Route::from_trace`] with [`DEFAULT_TOLERANCE_M`] (`x`, `y`: map
/// frame, metres; `theta`: the heading the robot leaves the point with, radians). Collinear
/// poses (such as the control-step samples of PID execution) and rotations in place are
/// merged, so the size grows with the number of segments, not of control steps. Metrics are
/// computed from the full trace, never from this file. Same columns as `waypoints.csv`
/// ([`crate::export::waypoints_csv`]), readable with [`crate::export::parse_waypoints_csv`].
pub fn path_csv(trace: &Trace) -> String {
    crate::export::waypoints_csv(&Route::from_trace(trace, DEFAULT_TOLERANCE_M))
}

/// Parses `trace.jsonl` text (`path` names it in errors). When `frame` is given, every pose
/// must lie within the map's world bounds widened by `margin_m`.
///
/// # Errors
/// A line that is not a record, or a pose outside the map.
pub fn parse_trace(
    text: &str,
    path: &Path,
    frame: Option<(&MapFrame, f64)>,
) -> Result<Trace, TraceFileError> {
    let bounds = frame.map(|(f, m)| {
        let (lo, hi) = f.world_bounds();
        (lo.x - m, lo.y - m, hi.x + m, hi.y + m)
    });
    let mut records = Vec::new();
    for (k, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let r: Record = serde_json::from_str(line).map_err(|e| TraceFileError::Parse {
            path: path.to_path_buf(),
            line: k + 1,
            message: e.to_string(),
        })?;
        if let (Record::Pose { pose, .. }, Some((x0, y0, x1, y1))) = (&r, bounds) {
            let [x, y, th] = *pose;
            let inside = (x0..=x1).contains(&x) && (y0..=y1).contains(&y) && th.is_finite();
            if !inside {
                return Err(TraceFileError::OutsideMap {
                    path: path.to_path_buf(),
                    line: k + 1,
                    x,
                    y,
                    lo_x: x0,
                    lo_y: y0,
                    hi_x: x1,
                    hi_y: y1,
                });
            }
        }
        records.push(r);
    }
    Ok(Trace { records })
}

/// Reads a `trace.jsonl` (a regular file), checked as [`parse_trace`].
///
/// # Errors
/// See [`parse_trace`], plus an unreadable file.
pub fn read_trace(path: &Path, frame: Option<(&MapFrame, f64)>) -> Result<Trace, TraceFileError> {
    let text = crate::file::read_text(path).map_err(|source| TraceFileError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_trace(&text, path, frame)
}

#[cfg(test)]
mod tests {
    use super::*;
    use ccpp_core::Pose;

    #[test]
    fn round_trip_and_far_pose_refused() {
        let mut t = Trace::default();
        t.push_pose(0, Pose::new(1.0, 1.0, 0.5));
        t.push_pose(1, Pose::new(2.0, 1.5, -0.5));
        let text = trace_jsonl(&t).unwrap_or_default();
        let frame = MapFrame {
            width: 60,
            height: 60,
            resolution: 0.05,
            origin: Pose::new(0.0, 0.0, 0.0),
        };
        let back = parse_trace(&text, Path::new("t.jsonl"), Some((&frame, 0.1)));
        assert_eq!(back.ok().map(|b| b.records), Some(t.records.clone()));
        let far = text.replace("2.0,1.5", "1e300,1.5");
        let e = parse_trace(&far, Path::new("t.jsonl"), Some((&frame, 0.1)));
        let msg = e.err().map(|e| e.to_string()).unwrap_or_default();
        assert!(
            msg.contains("line 2") && msg.contains("outside the map"),
            "{msg}"
        );
        assert!(path_csv(&t).starts_with("x,y,theta\n1,1,0.5\n"));
    }
}
