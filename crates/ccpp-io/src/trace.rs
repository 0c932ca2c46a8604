//! Trace files: `trace.jsonl` (every pose and event, one JSON object a line) and `path.csv`
//! (the executed path at its segment ends), written and read back with checks, so that a
//! damaged or hand-edited trace is refused with the line at fault instead of hanging a
//! renderer.
//!
//! # `trace.jsonl`
//!
//! One JSON object a line, in step order (`t` is the simulator's step counter):
//!
//! - `{"t":3,"pose":[x,y,theta]}`: one pose (metres, radians);
//! - `{"t":3,"event":"region_start","region":1}`: an event (the fields of
//!   [`ccpp_core::trace::Event`]);
//! - `{"t":3,"poses":n,"from":[x,y],"to":[x,y],"theta":th}`: a straight run of `n` poses with
//!   heading `th` at steps `t, t+1, ..., t+n-1`, from `from` to `to` through evenly spaced
//!   points of the lattice declared by the line `{"lattice":[x,y,side]}` before it: a lattice
//!   point `(i, j)` is at `(x + i * side, y + j * side)` (each coordinate one multiplication
//!   and one addition in `f64`, exactly as the tile planners compute tile centres);
//! - `{"t":3,"poses":n,"from":[x,y],"step":[dx,dy],"theta":th}`: a straight run of `n` poses
//!   whose positions follow by adding `[dx,dy]` (`f64` addition) to the previous one.
//!
//! - `{"t":9,"event":"backtrack_list","delta":[{"prev":0,"n":12},[x,y],{"prev":14,"n":3}]}`:
//!   a backtracking list written against the previous one (here: its points 0 to 11, then
//!   the point `[x,y]`, then its points 14 to 16), used when shorter than the list itself
//!   (consecutive lists share most of their points).
//!
//! Expanding the runs gives back every executed pose bit for bit (runs are formed only where
//! that holds, see [`ccpp_core::trace`]). A tile planner's trace is mostly runs, so the file
//! holds about one line per straight move instead of one per tile. Numbers are written in the
//! shortest form that reads back to the same `f64`. Files of the earlier one-line-per-pose form
//! (no `poses` lines) read the same; [`trace_jsonl_per_pose`] still writes that form.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use ccpp_core::display::Compact;
use ccpp_core::grid::MapFrame;
use ccpp_core::route::{Route, RouteBuilder, DEFAULT_TOLERANCE_M};
use ccpp_core::trace::{Advance, Chunk, Event, Lattice, Piece, Record, Run, Trace};
use ccpp_core::Pose;
use serde::{Deserialize, Serialize};

/// At most this many poses per byte of a `trace.jsonl` (a bound on what a short file may
/// expand to; real traces hold well under one pose per byte).
pub const MAX_POSES_PER_BYTE: usize = 64;

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
    #[error(
        "trace {} line {line}: pose ({}, {}) lies outside the map ({}, {} to {}, {})",
        path.display(),
        Compact(*.x),
        Compact(*.y),
        Compact(*.lo_x),
        Compact(*.lo_y),
        Compact(*.hi_x),
        Compact(*.hi_y)
    )]
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

/// Appends `v` as JSON: the shortest decimal that reads back to `v` (as `serde_json` writes
/// it), `null` when not finite.
fn push_f64(s: &mut String, v: f64) {
    use serde_json::ser::Formatter as _;
    if !v.is_finite() {
        s.push_str("null");
        return;
    }
    let mut buf = [0u8; 40];
    let mut w: &mut [u8] = &mut buf;
    let ok = serde_json::ser::CompactFormatter
        .write_f64(&mut w, v)
        .is_ok();
    let n = 40 - w.len();
    match std::str::from_utf8(&buf[..n]) {
        Ok(text) if ok => s.push_str(text),
        _ => {
            let _ = write!(s, "{v:?}");
        }
    }
}

fn push_pair(s: &mut String, p: [f64; 2]) {
    s.push('[');
    push_f64(s, p[0]);
    s.push(',');
    push_f64(s, p[1]);
    s.push(']');
}

fn push_pose_line(s: &mut String, t: u64, p: Pose) {
    let _ = write!(s, "{{\"t\":{t},\"pose\":[");
    push_f64(s, p.x);
    s.push(',');
    push_f64(s, p.y);
    s.push(',');
    push_f64(s, p.theta);
    s.push_str("]}\n");
}

/// An event line, borrowed (same text as [`Record::Event`]).
#[derive(Serialize)]
struct EventLine<'a> {
    t: u64,
    #[serde(flatten)]
    event: &'a Event,
}

fn push_event_line(s: &mut String, t: u64, event: &Event) -> Result<(), serde_json::Error> {
    s.push_str(&serde_json::to_string(&EventLine { t, event })?);
    s.push('\n');
    Ok(())
}

/// One item of a backtracking list written as a delta: a point, or `n` points of the previous
/// list from index `prev` on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
enum DeltaItem {
    Point([f64; 2]),
    Copy { prev: usize, n: usize },
}

/// `points` as copies of stretches of `prev` and literal points (greedy, deterministic): a
/// point that does not continue the current copy starts a copy at its first occurrence in
/// `prev` at or after where the copy stood, else at its first occurrence.
fn list_delta(prev: &[[f64; 2]], points: &[[f64; 2]]) -> Vec<DeltaItem> {
    let key = |p: &[f64; 2]| (p[0].to_bits(), p[1].to_bits());
    // `prev`'s points sorted by (point, index): the occurrences of a point are one stretch, in
    // index order (one sort instead of a map of lists). A list mostly repeats the previous
    // one, so it needs few look-ups: they scan `prev` until the scans have read a few times
    // its length, and only then is it sorted.
    let mut index: Option<Vec<((u64, u64), usize)>> = None;
    let mut scan_budget = DELTA_SCANS * prev.len() + 64;
    let mut out: Vec<DeltaItem> = Vec::new();
    // The index in `prev` that the current copy continues with.
    let mut next = usize::MAX;
    for p in points {
        if next < prev.len() && key(&prev[next]) == key(p) {
            if let Some(DeltaItem::Copy { n, .. }) = out.last_mut() {
                *n += 1;
                next += 1;
                continue;
            }
        }
        let at = next.min(prev.len());
        let kp = key(p);
        // The first occurrence at or after `at`, else the first one.
        let found = if index.is_none() && scan_budget >= prev.len() {
            scan_budget -= prev.len();
            let is_p = |q: &[f64; 2]| key(q) == kp;
            match prev[at..].iter().position(is_p) {
                Some(j) => Some(at + j),
                None => prev[..at].iter().position(is_p),
            }
        } else {
            let index = index.get_or_insert_with(|| {
                let mut v: Vec<((u64, u64), usize)> =
                    prev.iter().enumerate().map(|(k, p)| (key(p), k)).collect();
                v.sort_unstable();
                v
            });
            let first = index.partition_point(|&(q, _)| q < kp);
            if index.get(first).is_some_and(|&(q, _)| q == kp) {
                let from = index.partition_point(|&e| e < (kp, at));
                match index.get(from) {
                    Some(&(q, k)) if q == kp => Some(k),
                    _ => Some(index[first].1),
                }
            } else {
                None
            }
        };
        if let Some(k) = found {
            out.push(DeltaItem::Copy { prev: k, n: 1 });
            next = k + 1;
        } else {
            out.push(DeltaItem::Point(*p));
            next = usize::MAX;
        }
    }
    out
}

/// How many times the length of the previous list [`list_delta`] scans it, looking points up,
/// before it sorts that list instead.
const DELTA_SCANS: usize = 8;

/// Resolves a delta against the previous list.
fn apply_delta(
    prev: Option<&Vec<[f64; 2]>>,
    delta: &[DeltaItem],
    budget: usize,
) -> Result<Vec<[f64; 2]>, String> {
    let mut out = Vec::new();
    for item in delta {
        let n = match *item {
            DeltaItem::Point(_) => 1,
            DeltaItem::Copy { n, .. } => n,
        };
        if out.len().saturating_add(n) > budget {
            return Err(format!(
                "backtrack_list points exceed {MAX_POSES_PER_BYTE} per byte of trace"
            ));
        }
        match *item {
            DeltaItem::Point(p) => out.push(p),
            DeltaItem::Copy { prev: k, n } => {
                let prev = prev.ok_or("a backtrack_list delta needs a backtrack_list before it")?;
                let part = k
                    .checked_add(n)
                    .and_then(|end| prev.get(k..end))
                    .ok_or_else(|| {
                        format!(
                            "a backtrack_list delta copies points {k}..{} of a list of {}",
                            k.saturating_add(n),
                            prev.len()
                        )
                    })?;
                out.extend_from_slice(part);
            }
        }
    }
    Ok(out)
}

/// A backtracking list written as a delta (`event` is `backtrack_list`, checked before).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DeltaLine {
    t: u64,
    #[serde(rename = "event")]
    _event: String,
    delta: Vec<DeltaItem>,
}

/// The trace as JSON Lines, straight runs of poses merged into one line each (the format in
/// the module documentation).
///
/// # Errors
/// An event that cannot be serialized (non-finite numbers are written as `null`, so this does
/// not happen for simulator traces).
pub fn trace_jsonl(trace: &Trace) -> Result<String, serde_json::Error> {
    let mut s = String::with_capacity(trace.piece_count() * 64 + 64);
    trace_jsonl_into(trace, &mut s, &mut |_| Ok(()))?;
    Ok(s)
}

/// [`trace_jsonl`]'s text written to `out` as it is formed (the whole file is never held in
/// memory: a few tens of kilobytes at a time). Same bytes.
///
/// # Errors
/// As [`trace_jsonl`], and write failures of `out` (as [`serde_json::Error::io`]).
pub fn write_trace_jsonl(
    trace: &Trace,
    out: &mut dyn std::io::Write,
) -> Result<(), serde_json::Error> {
    const CHUNK: usize = 1 << 16;
    let mut s = String::with_capacity(CHUNK + 4096);
    let mut flush = |s: &mut String| -> Result<(), serde_json::Error> {
        out.write_all(s.as_bytes()).map_err(serde_json::Error::io)?;
        s.clear();
        Ok(())
    };
    trace_jsonl_into(trace, &mut s, &mut |s| {
        if s.len() >= CHUNK {
            flush(s)?;
        }
        Ok(())
    })?;
    flush(&mut s)
}

/// Appends the lines of [`trace_jsonl`] to `s`, calling `after_line(s)` after each piece (to
/// drain `s` into a file).
fn trace_jsonl_into(
    trace: &Trace,
    s: &mut String,
    after_line: &mut dyn FnMut(&mut String) -> Result<(), serde_json::Error>,
) -> Result<(), serde_json::Error> {
    let lattice = trace.lattice();
    let mut lines = JsonlLines::default();
    for piece in trace.pieces() {
        if !s.is_empty() {
            after_line(s)?;
        }
        lines.piece(s, piece, lattice)?;
    }
    Ok(())
}

/// What the lines of [`trace_jsonl`] depend on beyond their own piece: whether the lattice was
/// declared, and the last backtracking list (the next one may be written as a delta of it).
#[derive(Default)]
struct JsonlLines<'a> {
    declared: bool,
    prev_list: Option<&'a [[f64; 2]]>,
}

impl<'a> JsonlLines<'a> {
    /// Appends the lines of `piece` to `s` (`lattice`: the trace's).
    fn piece(
        &mut self,
        s: &mut String,
        piece: Piece<'a>,
        lattice: Option<Lattice>,
    ) -> Result<(), serde_json::Error> {
        match piece {
            Piece::Pose { t, pose } => push_pose_line(s, t, pose),
            Piece::Event {
                t,
                event: event @ Event::BacktrackList { points },
            } => {
                if let Some(prev) = &self.prev_list {
                    let delta = list_delta(prev, points);
                    // Written as a delta when that takes fewer items than the list.
                    if delta.len() < points.len() {
                        let _ = write!(s, "{{\"t\":{t},\"event\":\"backtrack_list\",\"delta\":");
                        s.push_str(&serde_json::to_string(&delta)?);
                        s.push_str("}\n");
                        self.prev_list = Some(points);
                        return Ok(());
                    }
                }
                self.prev_list = Some(points);
                push_event_line(s, t, event)?;
            }
            Piece::Event { t, event } => push_event_line(s, t, event)?,
            Piece::Run(run) if run.n < 3 => {
                for (t, p) in run.poses(lattice) {
                    push_pose_line(s, t, p);
                }
            }
            Piece::Run(run) => {
                if let (Advance::Lattice { .. }, Some(l), false) =
                    (run.advance, lattice, self.declared)
                {
                    self.declared = true;
                    s.push_str("{\"lattice\":[");
                    push_f64(s, l.anchor[0]);
                    s.push(',');
                    push_f64(s, l.anchor[1]);
                    s.push(',');
                    push_f64(s, l.side);
                    s.push_str("]}\n");
                }
                let _ = write!(s, "{{\"t\":{},\"poses\":{},\"from\":", run.t, run.n);
                push_pair(s, run.from);
                match run.advance {
                    Advance::Lattice { .. } => {
                        s.push_str(",\"to\":");
                        push_pair(s, run.to(lattice));
                    }
                    Advance::Step { d } => {
                        s.push_str(",\"step\":");
                        push_pair(s, d);
                    }
                }
                s.push_str(",\"theta\":");
                push_f64(s, run.theta);
                s.push_str("}\n");
            }
        }
        Ok(())
    }
}

/// `path.csv` formed while a run goes on, from the [`Chunk`]s of its trace in order (see
/// [`Trace::chunk`]): the same text as [`path_csv`] of the whole trace, ready when the run
/// ends. (`trace.jsonl`, the size of the trace's lists, is streamed into its file after the
/// run instead of being held in memory.)
pub struct FileFormer {
    route: RouteBuilder,
}

impl Default for FileFormer {
    fn default() -> Self {
        Self {
            route: RouteBuilder::new(DEFAULT_TOLERANCE_M),
        }
    }
}

/// The text files of a run formed by a [`FileFormer`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FormedFiles {
    /// [`path_csv`] of the trace.
    pub path_csv: String,
}

impl FileFormer {
    /// Adds the pieces of `chunk` (the next ones of the trace).
    pub fn chunk(&mut self, chunk: &Chunk) {
        for pose in chunk.poses() {
            self.route.push(pose);
        }
    }

    /// The files.
    pub fn finish(self) -> FormedFiles {
        FormedFiles {
            path_csv: crate::export::waypoints_csv(&self.route.finish()),
        }
    }
}

/// The trace as JSON Lines of the earlier form: one line per pose (no runs).
///
/// # Errors
/// As [`trace_jsonl`].
pub fn trace_jsonl_per_pose(trace: &Trace) -> Result<String, serde_json::Error> {
    let mut s = String::with_capacity(trace.len() * 48);
    for e in trace.entries() {
        match e {
            ccpp_core::trace::Entry::Pose { t, pose } => push_pose_line(&mut s, t, pose),
            ccpp_core::trace::Entry::Event { t, event } => push_event_line(&mut s, t, event)?,
        }
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

/// A line that is not an event.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlainLine {
    t: Option<u64>,
    pose: Option<[f64; 3]>,
    poses: Option<u32>,
    from: Option<[f64; 2]>,
    to: Option<[f64; 2]>,
    step: Option<[f64; 2]>,
    theta: Option<f64>,
    lattice: Option<[f64; 3]>,
}

/// What a non-event line holds.
enum Line {
    Pose(u64, [f64; 3]),
    Run(Run),
    Lattice(Lattice),
}

/// Reads a non-event line; `lattice` is the one declared before it.
fn plain_line(text: &str, lattice: Option<Lattice>) -> Result<Line, String> {
    let l: PlainLine = serde_json::from_str(text).map_err(|e| e.to_string())?;
    let run_fields = l.poses.is_some()
        || l.from.is_some()
        || l.to.is_some()
        || l.step.is_some()
        || l.theta.is_some();
    match l {
        PlainLine {
            lattice: Some(a),
            t: None,
            pose: None,
            ..
        } if !run_fields => {
            if a.iter().all(|v| v.is_finite()) && a[2] > 0.0 {
                Ok(Line::Lattice(Lattice {
                    anchor: [a[0], a[1]],
                    side: a[2],
                }))
            } else {
                Err(format!(
                    "lattice [{}, {}, {}] needs finite numbers and a side > 0",
                    a[0], a[1], a[2]
                ))
            }
        }
        PlainLine {
            t: Some(t),
            pose: Some(p),
            lattice: None,
            ..
        } if !run_fields => Ok(Line::Pose(t, p)),
        PlainLine {
            t: Some(t),
            poses: Some(n),
            from: Some(from),
            to,
            step,
            theta: Some(theta),
            pose: None,
            lattice: None,
        } => {
            if n == 0 {
                return Err("a run needs poses >= 1".to_string());
            }
            if t.checked_add(u64::from(n)).is_none() {
                return Err("a run's steps overflow".to_string());
            }
            let advance = match (to, step) {
                (Some(to), None) => {
                    let lat =
                        lattice.ok_or("a run with \"to\" needs a \"lattice\" line before it")?;
                    let (Some((i0, j0)), Some((i1, j1))) = (lat.index(from), lat.index(to)) else {
                        return Err(
                            "a run's \"from\" and \"to\" must be lattice points".to_string()
                        );
                    };
                    let k = i64::from(n) - 1;
                    let (di, dj) = (i64::from(i1) - i64::from(i0), i64::from(j1) - i64::from(j0));
                    if k == 0 && (di, dj) != (0, 0) {
                        return Err("a run of one pose must end where it starts".to_string());
                    }
                    if k > 0 && (di % k != 0 || dj % k != 0) {
                        return Err(format!(
                            "a run of {n} poses cannot reach \"to\" in equal lattice steps"
                        ));
                    }
                    let (di, dj) = if k == 0 { (0, 0) } else { (di / k, dj / k) };
                    Advance::Lattice {
                        i: i0,
                        j: j0,
                        di: i32::try_from(di).map_err(|e| e.to_string())?,
                        dj: i32::try_from(dj).map_err(|e| e.to_string())?,
                    }
                }
                (None, Some(d)) => Advance::Step { d },
                _ => return Err("a run needs exactly one of \"to\" and \"step\"".to_string()),
            };
            Ok(Line::Run(Run {
                t,
                n,
                theta,
                from,
                advance,
            }))
        }
        _ => Err("expected a pose, a run, a lattice or an event".to_string()),
    }
}

/// Parses `trace.jsonl` text (`path` names it in errors), in either form (runs or one line per
/// pose). When `frame` is given, every pose must lie within the map's world bounds widened by
/// `margin_m`.
///
/// # Errors
/// A line that is not a record, or a pose outside the map, or more than
/// [`MAX_POSES_PER_BYTE`] poses per byte of text.
pub fn parse_trace(
    text: &str,
    path: &Path,
    frame: Option<(&MapFrame, f64)>,
) -> Result<Trace, TraceFileError> {
    let lines = text
        .lines()
        .map(|l| Ok::<_, std::io::Error>(std::borrow::Cow::Borrowed(l)));
    parse_trace_lines(lines, text.len(), path, frame)
}

/// [`parse_trace`] of the lines of a text of `byte_len` bytes, read one at a time (a read
/// failure is [`TraceFileError::Io`]).
fn parse_trace_lines<'a>(
    lines: impl Iterator<Item = std::io::Result<std::borrow::Cow<'a, str>>>,
    byte_len: usize,
    path: &Path,
    frame: Option<(&MapFrame, f64)>,
) -> Result<Trace, TraceFileError> {
    let bounds = frame.map(|(f, m)| {
        let (lo, hi) = f.world_bounds();
        (lo.x - m, lo.y - m, hi.x + m, hi.y + m)
    });
    let parse_error = |line: usize, message: String| TraceFileError::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    let max_poses = byte_len.saturating_mul(MAX_POSES_PER_BYTE);
    let mut trace = Trace::default();
    let mut lattice: Option<Lattice> = None;
    let mut last_list: Option<Vec<[f64; 2]>> = None;
    // Points of all backtracking lists together, bounded like the poses.
    let mut list_budget = max_poses;
    let check = |line: usize, t: u64, p: Pose, trace: &mut Trace| {
        if trace.pose_count() >= max_poses {
            return Err(parse_error(
                line,
                format!("more than {MAX_POSES_PER_BYTE} poses per byte of trace"),
            ));
        }
        if let Some((x0, y0, x1, y1)) = bounds {
            let inside =
                (x0..=x1).contains(&p.x) && (y0..=y1).contains(&p.y) && p.theta.is_finite();
            if !inside {
                return Err(TraceFileError::OutsideMap {
                    path: path.to_path_buf(),
                    line,
                    x: p.x,
                    y: p.y,
                    lo_x: x0,
                    lo_y: y0,
                    hi_x: x1,
                    hi_y: y1,
                });
            }
        }
        trace.push_pose(t, p);
        Ok(())
    };
    for (k, line) in lines.enumerate() {
        let line = line.map_err(|source| TraceFileError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let line: &str = &line;
        if line.trim().is_empty() {
            continue;
        }
        if line.contains("\"event\":\"backtrack_list\"") && line.contains("\"delta\"") {
            let d: DeltaLine =
                serde_json::from_str(line).map_err(|e| parse_error(k + 1, e.to_string()))?;
            let points = apply_delta(last_list.as_ref(), &d.delta, list_budget)
                .map_err(|m| parse_error(k + 1, m))?;
            list_budget -= points.len();
            last_list = Some(points.clone());
            trace.push_event(d.t, Event::BacktrackList { points });
            continue;
        }
        if line.contains("\"event\"") {
            let r: Record =
                serde_json::from_str(line).map_err(|e| parse_error(k + 1, e.to_string()))?;
            match r {
                Record::Event {
                    t,
                    event: Event::BacktrackList { points },
                } => {
                    list_budget = list_budget.saturating_sub(points.len());
                    last_list = Some(points.clone());
                    trace.push_event(t, Event::BacktrackList { points });
                }
                Record::Event { t, event } => trace.push_event(t, event),
                Record::Pose { t, pose } => {
                    check(k + 1, t, Pose::new(pose[0], pose[1], pose[2]), &mut trace)?;
                }
            }
            continue;
        }
        match plain_line(line, lattice).map_err(|m| parse_error(k + 1, m))? {
            Line::Pose(t, p) => check(k + 1, t, Pose::new(p[0], p[1], p[2]), &mut trace)?,
            Line::Lattice(l) => lattice = Some(l),
            Line::Run(run) => {
                for (t, p) in run.poses(lattice) {
                    check(k + 1, t, p, &mut trace)?;
                }
            }
        }
    }
    Ok(trace)
}

/// Reads the `trace.jsonl` of a finished run on a map of `frame` by a robot of radius
/// `radius`: [`read_trace`] with every pose on the map, widened by the radius and two pixels
/// (a robot cannot leave its map). A damaged trace is refused here instead of hanging a
/// renderer (a pose of 1.7e308 m hung the bench's pictures; one of 100 m on a 6 m map drew a
/// path off the picture). `ccpp replay` and `ccpp bench` read traces back through it.
///
/// # Errors
/// See [`read_trace`].
pub fn read_run_trace(path: &Path, frame: &MapFrame, radius: f64) -> Result<Trace, TraceFileError> {
    read_trace(path, Some((frame, radius + 2.0 * frame.resolution)))
}

/// Reads a `trace.jsonl` (a regular file), checked as [`parse_trace`].
///
/// # Errors
/// See [`parse_trace`], plus an unreadable file.
pub fn read_trace(path: &Path, frame: Option<(&MapFrame, f64)>) -> Result<Trace, TraceFileError> {
    use std::io::BufRead as _;
    let io_err = |source| TraceFileError::Io {
        path: path.to_path_buf(),
        source,
    };
    // Read line by line: the file is never held whole in memory, nor a line longer than
    // `MAX_TEXT_BYTES` (a 3 GB file without a newline was read into one 3 GB line).
    let file = crate::file::open_regular(path).map_err(io_err)?;
    let len = file.metadata().map_err(io_err)?.len();
    let mut reader = std::io::BufReader::new(file);
    let limit = crate::file::MAX_TEXT_BYTES;
    let lines = std::iter::from_fn(move || {
        let mut buf = Vec::new();
        match std::io::Read::take(&mut reader, limit + 1).read_until(b'\n', &mut buf) {
            Ok(0) => None,
            Ok(_) if buf.len() as u64 > limit => Some(Err(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!("a line is longer than {} MiB", limit >> 20),
            ))),
            Ok(_) => {
                // As `BufRead::lines`: without the `\n` or `\r\n`.
                if buf.last() == Some(&b'\n') {
                    buf.pop();
                    if buf.last() == Some(&b'\r') {
                        buf.pop();
                    }
                }
                Some(
                    String::from_utf8(buf)
                        .map(std::borrow::Cow::Owned)
                        .map_err(|_| {
                            std::io::Error::new(
                                std::io::ErrorKind::InvalidData,
                                "stream did not contain valid UTF-8",
                            )
                        }),
                )
            }
            Err(e) => Some(Err(e)),
        }
    });
    parse_trace_lines(
        lines,
        usize::try_from(len).unwrap_or(usize::MAX),
        path,
        frame,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use ccpp_core::trace::Entry;
    use ccpp_core::Pose;

    fn frame() -> MapFrame {
        MapFrame {
            width: 60,
            height: 60,
            resolution: 0.05,
            origin: Pose::new(0.0, 0.0, 0.0),
        }
    }

    #[test]
    fn round_trip_and_far_pose_refused() {
        let mut t = Trace::default();
        t.push_pose(0, Pose::new(1.0, 1.0, 0.5));
        t.push_pose(1, Pose::new(2.0, 1.5, -0.5));
        let text = trace_jsonl(&t).unwrap_or_default();
        let frame = frame();
        let back = parse_trace(&text, Path::new("t.jsonl"), Some((&frame, 0.1)));
        assert_eq!(back.ok(), Some(t.clone()));
        let far = text.replace("2.0,1.5", "1e300,1.5");
        let e = parse_trace(&far, Path::new("t.jsonl"), Some((&frame, 0.1)));
        let msg = e.err().map(|e| e.to_string()).unwrap_or_default();
        assert!(
            msg.contains("line 2") && msg.contains("outside the map"),
            "{msg}"
        );
        assert!(path_csv(&t).starts_with("x,y,theta\n1,1,0.5\n"));
    }

    /// A tile-like trace: lanes of 0.3 m steps from an anchor, turns, events, a drift.
    fn lanes() -> Trace {
        let mut tr = Trace::default();
        let (ax, ay, s) = (0.125, 0.375, 0.3);
        let mut t = 0;
        tr.push_pose(t, Pose::new(ax, ay, 0.0));
        tr.push_event(1, Event::RegionStart { region: 1 });
        for lane in 0..4 {
            let th = if lane % 2 == 0 { 1.5 } else { -1.5 };
            t += 1;
            let x = ax + f64::from(lane) * s;
            tr.push_pose(t, Pose::new(x, tr.poses().last().map_or(ay, |p| p.y), th));
            for k in 1..6 {
                let j = if lane % 2 == 0 { k } else { 6 - k };
                tr.push_pose(t, Pose::new(x, ay + f64::from(j) * s, th));
                t += 1;
            }
            tr.push_pose(t, Pose::new(x + s * 0.999, ay, 0.0));
        }
        // A step run (repeated addition) and a collision.
        let mut p = Pose::new(1.0, 1.0, 0.25);
        for _ in 0..5 {
            t += 1;
            p.x += 0.07;
            p.y += 0.011;
            tr.push_pose(t, p);
        }
        tr.push_event(t, Event::Collision { x: p.x, y: p.y });
        tr
    }

    #[test]
    fn runs_are_written_as_one_line_and_read_back_exactly() {
        let tr = lanes();
        assert!(tr.piece_count() < tr.len(), "{} pieces", tr.piece_count());
        let text = trace_jsonl(&tr).unwrap_or_default();
        assert!(text.contains("{\"lattice\":[0.125,0.375,0.3]}"), "{text}");
        assert!(
            text.contains("\"to\":") && text.contains("\"step\":"),
            "{text}"
        );
        let old = trace_jsonl_per_pose(&tr).unwrap_or_default();
        assert!(text.lines().count() < old.lines().count());
        let f = frame();
        let a = parse_trace(&text, Path::new("new"), Some((&f, 0.5))).ok();
        let b = parse_trace(&old, Path::new("old"), Some((&f, 0.5))).ok();
        let bits = |t: &Trace| -> Vec<(u64, [u64; 3])> {
            t.timed_poses()
                .map(|(k, p)| (k, [p.x.to_bits(), p.y.to_bits(), p.theta.to_bits()]))
                .collect()
        };
        let (Some(a), Some(b)) = (a, b) else {
            panic!("unreadable: {text}");
        };
        assert_eq!(bits(&a), bits(&tr));
        assert_eq!(bits(&b), bits(&tr));
        assert_eq!(
            a.records().collect::<Vec<_>>(),
            tr.records().collect::<Vec<_>>()
        );
        assert_eq!(
            b.records().collect::<Vec<_>>(),
            tr.records().collect::<Vec<_>>()
        );
        // Both forms rewrite to the same text.
        assert_eq!(trace_jsonl(&b).unwrap_or_default(), text);
        assert_eq!(trace_jsonl_per_pose(&a).unwrap_or_default(), old);
    }

    #[test]
    fn bad_runs_are_refused_with_their_line() {
        let f = frame();
        let cases = [
            ("{\"t\":0,\"poses\":3,\"from\":[0.1,0.1],\"to\":[0.7,0.1],\"theta\":0.0}", "lattice"),
            ("{\"lattice\":[0.1,0.1,0.3]}\n{\"t\":0,\"poses\":3,\"from\":[0.1,0.1],\"to\":[0.4,0.1],\"theta\":0.0}", "equal lattice steps"),
            ("{\"lattice\":[0.1,0.1,0.3]}\n{\"t\":0,\"poses\":3,\"from\":[0.1,0.1],\"to\":[0.45,0.1],\"theta\":0.0}", "lattice points"),
            ("{\"lattice\":[0.1,0.1,-1]}", "side > 0"),
            ("{\"t\":0,\"poses\":0,\"from\":[0.1,0.1],\"step\":[0.1,0],\"theta\":0.0}", "poses >= 1"),
            ("{\"t\":0,\"poses\":2,\"from\":[0.1,0.1],\"theta\":0.0}", "exactly one of"),
            ("{\"t\":0,\"poses\":9,\"from\":[0.1,0.1],\"step\":[1,0],\"theta\":0.0}", "outside the map"),
            ("{\"t\":0,\"poses\":4000000000,\"from\":[0.1,0.1],\"step\":[0,0],\"theta\":0.0}", "poses per byte"),
            ("{\"t\":0,\"pose\":[1,1,0],\"theta\":0.0}", "expected a pose"),
        ];
        for (text, want) in cases {
            let text = format!("{{\"t\":0,\"pose\":[0.1,0.1,0]}}\n{text}");
            let e = parse_trace(&text, Path::new("t.jsonl"), Some((&f, 0.0)));
            let msg = e.err().map(|e| e.to_string()).unwrap_or_default();
            assert!(msg.contains(want) && msg.contains("line"), "{text}: {msg}");
        }
    }

    /// The delta encoder's rule spelled out plainly: a map from point to its indices in order.
    fn reference_delta(prev: &[[f64; 2]], points: &[[f64; 2]]) -> Vec<DeltaItem> {
        let key = |p: &[f64; 2]| (p[0].to_bits(), p[1].to_bits());
        let mut index: std::collections::BTreeMap<(u64, u64), Vec<usize>> =
            std::collections::BTreeMap::new();
        for (k, p) in prev.iter().enumerate() {
            index.entry(key(p)).or_default().push(k);
        }
        let mut out: Vec<DeltaItem> = Vec::new();
        let mut next = usize::MAX;
        for p in points {
            if next < prev.len() && key(&prev[next]) == key(p) {
                if let Some(DeltaItem::Copy { n, .. }) = out.last_mut() {
                    *n += 1;
                    next += 1;
                    continue;
                }
            }
            let at = next.min(prev.len());
            let found = index.get(&key(p)).and_then(|ks| {
                ks.iter()
                    .copied()
                    .find(|&k| k >= at)
                    .or(ks.first().copied())
            });
            if let Some(k) = found {
                out.push(DeltaItem::Copy { prev: k, n: 1 });
                next = k + 1;
            } else {
                out.push(DeltaItem::Point(*p));
                next = usize::MAX;
            }
        }
        out
    }

    #[test]
    fn the_sorted_delta_index_picks_the_same_copies_as_a_map_of_occurrences() {
        // Lists over few distinct points (many repeats) and edits between them; the scans of
        // the previous list and its sorted index (once the scans used their budget) must pick
        // the same copies.
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut rnd = |m: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % m
        };
        let mut prev: Vec<[f64; 2]> = Vec::new();
        for round in 0..300 {
            // Short lists, and long ones (more look-ups than the scans' budget allows).
            let len = rnd(if round % 2 == 0 { 40 } else { 200 }) as usize;
            let mut points: Vec<[f64; 2]> = Vec::with_capacity(len);
            for _ in 0..len {
                if !prev.is_empty() && rnd(3) > 0 {
                    points.push(prev[rnd(prev.len() as u64) as usize]);
                } else {
                    points.push([rnd(6) as f64 * 0.5, rnd(4) as f64 - 1.0]);
                }
            }
            if rnd(4) == 0 {
                points.extend_from_slice(&prev);
            }
            let got = list_delta(&prev, &points);
            assert_eq!(got, reference_delta(&prev, &points));
            assert_eq!(apply_delta(Some(&prev), &got, usize::MAX).unwrap(), points);
            prev = points;
        }
    }

    #[test]
    fn backtrack_lists_are_written_as_deltas_and_read_back_exactly() {
        let mut tr = Trace::default();
        tr.push_pose(0, Pose::new(0.1, 0.1, 0.0));
        let base: Vec<[f64; 2]> = (0..20).map(|k| [0.1 + 0.3 * f64::from(k), 0.7]).collect();
        tr.push_event(
            1,
            Event::BacktrackList {
                points: base.clone(),
            },
        );
        // Two removed, one added in the middle, order changed at the end.
        let mut next: Vec<[f64; 2]> = base[..5].to_vec();
        next.push([0.25, 0.35]);
        next.extend_from_slice(&base[7..18]);
        next.push(base[19]);
        next.push(base[18]);
        tr.push_event(
            2,
            Event::BacktrackList {
                points: next.clone(),
            },
        );
        tr.push_event(3, Event::BacktrackList { points: Vec::new() });
        let text = trace_jsonl(&tr).unwrap_or_default();
        assert!(text.contains("\"delta\":[{\"prev\":0,\"n\":5},[0.25,0.35],{\"prev\":7,\"n\":11},{\"prev\":19,\"n\":1},{\"prev\":18,\"n\":1}]"), "{text}");
        let back = parse_trace(&text, Path::new("t"), None).ok();
        assert_eq!(back.as_ref(), Some(&tr));
        // A copy past the previous list, or before any list, is refused with its line.
        for bad in [
            "{\"t\":2,\"event\":\"backtrack_list\",\"delta\":[{\"prev\":15,\"n\":9}]}",
            "{\"t\":2,\"event\":\"backtrack_list\",\"delta\":[{\"prev\":0,\"n\":99999999}]}",
        ] {
            let text = format!(
                "{{\"t\":1,\"event\":\"backtrack_list\",\"points\":{}}}\n{bad}",
                serde_json::to_string(&base).unwrap_or_default()
            );
            let e = parse_trace(&text, Path::new("t"), None)
                .err()
                .map(|e| e.to_string());
            assert!(e.as_deref().is_some_and(|m| m.contains("line 2")), "{e:?}");
        }
        let lone = "{\"t\":2,\"event\":\"backtrack_list\",\"delta\":[{\"prev\":0,\"n\":1}]}";
        let e = parse_trace(lone, Path::new("t"), None)
            .err()
            .map(|e| e.to_string());
        assert!(
            e.as_deref()
                .is_some_and(|m| m.contains("needs a backtrack_list before")),
            "{e:?}"
        );
    }

    #[test]
    fn entries_from_a_cursor_see_what_came_after() {
        let tr = lanes();
        let all: Vec<Entry<'_>> = tr.entries().collect();
        // Rebuild step by step, reading what is new after each push.
        let mut part = Trace::default();
        let mut cursor = part.end();
        let mut seen: Vec<Record> = Vec::new();
        for r in tr.records() {
            part.push(r);
            seen.extend(part.entries_from(cursor).map(|e| match e {
                Entry::Pose { t, pose } => Record::Pose {
                    t,
                    pose: [pose.x, pose.y, pose.theta],
                },
                Entry::Event { t, event } => Record::Event {
                    t,
                    event: event.clone(),
                },
            }));
            cursor = part.end();
        }
        assert_eq!(seen.len(), all.len());
        assert_eq!(seen, tr.records().collect::<Vec<_>>());
    }
}
