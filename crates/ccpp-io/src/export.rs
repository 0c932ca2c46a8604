//! Path exports a robot stack reads: a [`Route`] (waypoints with headings at segment ends) as
//! CSV, JSON, a ROS 2 `nav_msgs/Path` in YAML and a `GeoJSON` `FeatureCollection`, plus readers
//! for the CSV and JSON forms.
//!
//! | format ([`ExportFormat`]) | file | content |
//! |---|---|---|
//! | `csv` | `waypoints.csv` | header `x,y,theta`, one waypoint a line (metres, radians) |
//! | `json` | `waypoints.json` | `{"frame_id":"map", "planner", "map", "tolerance_m", "length_m", "waypoints":[{"x","y","theta"}, ..]}` |
//! | `nav-path` | `nav_path.yaml` | a `nav_msgs/Path` as `ros2 topic echo` prints it (without the trailing `---`) |
//! | `geojson` | `path.geojson` | a `FeatureCollection`: the route as a `LineString`, then any zone polygons |
//!
//! All coordinates are in the map frame (metres; `x` east, `y` north): the `GeoJSON` is not
//! WGS 84, so GIS tools should read it in a local/unknown coordinate system. `theta` is the
//! heading the robot leaves the waypoint with (radians, 0 = +x, counter-clockwise); the
//! `nav_msgs/Path` carries it as the quaternion `(0, 0, sin(theta/2), cos(theta/2))`.
//!
//! The exported route is [`tidy`]: positions rounded to a nanometre ([`round_m`]) and headings in
//! `(-pi, pi]`, a heading within a nanoradian of a multiple of 45 degrees set to it exactly,
//! so the pixel-to-map arithmetic's last bits do not reach the files (`0.675`, not
//! `0.6750000000000005`; `0` and `3.141592653589793`, not `4.4e-15` and
//! `-3.141592653589793`); quaternion components below 1e-15 are written as 0. Every
//! number is written so that it reads back to the same `f64` (shortest round-trip form); YAML
//! floats always have a decimal point and no exponent, so YAML 1.1 parsers read them as floats
//! too. Output is a pure function of the inputs (byte-identical for the same route).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use ccpp_core::geometry::Point;
use ccpp_core::metrics::Metrics;
use ccpp_core::route::Route;
use ccpp_core::world::Robot;
use ccpp_core::Pose;
use serde::{Deserialize, Serialize};

/// The frame every export is expressed in (`header.frame_id` of the `nav_msgs/Path`).
pub const FRAME_ID: &str = "map";

/// `v` metres rounded to a nanometre (no `-0`): far below what a robot resolves and below
/// the metrics' tolerance (1e-6 pixel), far above the noise of the pixel-to-map arithmetic.
/// Far from the origin, where a nanometre is within a few steps of an `f64` (above about
/// 5e5 m), to the decimal place at least eight steps wide (1e-8 m up to about 5e6 m, a
/// micrometre at the 1e8 m placement limit), so that the result is the `f64` nearest to a
/// short decimal and rounding it again changes nothing.
#[must_use]
pub fn round_m(v: f64) -> f64 {
    if !v.is_finite() {
        return v;
    }
    let places = decimal_places(v);
    // Rounded in decimal (the exact value, half to even), then read back: the nearest f64 to
    // that decimal. (Scaling by 1e9 and `round` pushed clean values a step off above 2e6 m
    // and left the noise above 4.5e6 m.)
    let r: f64 = format!("{v:.places$}").parse().unwrap_or(v);
    if r == 0.0 {
        0.0
    } else {
        r
    }
}

/// The decimal places [`round_m`] keeps of `v`: 9, fewer where eight steps of an `f64`
/// (2.2e-16 relative each) exceed a unit of the last place.
fn decimal_places(v: f64) -> usize {
    let mut places = 9usize;
    while places > 0 && v.abs() * 1.8e-15 > 10f64.powi(-(places as i32)) {
        places -= 1;
    }
    places
}

/// Whether the exported positions `a` and `b` ([`round_m`]ed) are one position: at most a unit
/// of the last place [`round_m`] keeps apart. Far from the origin a unit is above the route's
/// [`ccpp_core::route::SAME_POSITION_M`], and two poses of one rotation in place under
/// odometry noise, a few `f64` steps apart, were exported as two waypoints at one position
/// (or 1e-8 m apart, with a heading that is no direction of travel).
fn same_exported_position(a: &Pose, b: &Pose) -> bool {
    let unit = |v: f64| 10f64.powi(-(decimal_places(v) as i32));
    // (Adjacent values of the last place differ by a unit give or take the f64 steps of
    // their difference: half a unit more covers them, and no two units.)
    let close = |u: f64, v: f64| (u - v).abs() <= 1.5 * unit(u.abs().max(v.abs()));
    close(a.x, b.x) && close(a.y, b.y)
}

/// `theta` wrapped into `(-pi, pi]`, and set to the multiple of 45 degrees it lies within a
/// nanoradian of (no `-0`, and `pi` rather than `-pi`).
#[must_use]
pub fn tidy_heading(theta: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_4, PI, TAU};
    if !theta.is_finite() {
        return theta;
    }
    let mut t = theta % TAU;
    if t <= -PI {
        t += TAU;
    } else if t > PI {
        t -= TAU;
    }
    let k = (t / FRAC_PI_4).round();
    if (t - k * FRAC_PI_4).abs() <= 1e-9 {
        t = if k == 0.0 { 0.0 } else { k * FRAC_PI_4 };
    }
    if t <= -PI {
        PI
    } else {
        t
    }
}

/// The route as the exports write it: positions [`round_m`], headings [`tidy_heading`], and
/// waypoints that come out at one position (within a unit of the last place kept) merged into
/// the first of them with the heading of the last, as the route merges a rotation in place.
/// Applying it twice changes nothing.
#[must_use]
pub fn tidy(route: &Route) -> Route {
    let mut waypoints: Vec<Pose> = Vec::with_capacity(route.waypoints.len());
    for p in &route.waypoints {
        let p = Pose::new(round_m(p.x), round_m(p.y), tidy_heading(p.theta));
        match waypoints.last_mut() {
            Some(w) if same_exported_position(w, &p) => w.theta = p.theta,
            _ => waypoints.push(p),
        }
    }
    Route { waypoints }
}

/// An export format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ExportFormat {
    /// `waypoints.csv`.
    Csv,
    /// `waypoints.json`.
    Json,
    /// `nav_path.yaml`: a ROS 2 `nav_msgs/Path`.
    NavPath,
    /// `path.geojson`.
    GeoJson,
}

impl ExportFormat {
    /// Every format, in writing order.
    pub const ALL: [ExportFormat; 4] = [
        ExportFormat::Csv,
        ExportFormat::Json,
        ExportFormat::NavPath,
        ExportFormat::GeoJson,
    ];

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ExportFormat::Csv => "csv",
            ExportFormat::Json => "json",
            ExportFormat::NavPath => "nav-path",
            ExportFormat::GeoJson => "geojson",
        }
    }

    /// The file the format is written to.
    pub fn file_name(self) -> &'static str {
        match self {
            ExportFormat::Csv => "waypoints.csv",
            ExportFormat::Json => "waypoints.json",
            ExportFormat::NavPath => "nav_path.yaml",
            ExportFormat::GeoJson => "path.geojson",
        }
    }
}

impl std::fmt::Display for ExportFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// An unknown export format name.
#[derive(Debug, thiserror::Error)]
#[error("unknown export format {0:?} (expected csv, json, nav-path or geojson)")]
pub struct UnknownFormat(pub String);

impl FromStr for ExportFormat {
    type Err = UnknownFormat;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let l = s.trim().to_ascii_lowercase();
        Self::ALL
            .into_iter()
            .find(|f| f.name() == l)
            .ok_or_else(|| UnknownFormat(s.to_string()))
    }
}

/// What a route's exports say about where it came from.
#[derive(Clone, Debug)]
pub struct ExportMeta<'a> {
    /// Planner name.
    pub planner: &'a str,
    /// Map name.
    pub map: &'a str,
    /// The robot.
    pub robot: Robot,
    /// The rectangle a rect-boustrophedon route was planned for ([`Footprint::of`]), written
    /// beside the robot's disk; `None` for the disk planners.
    pub footprint: Option<Footprint>,
    /// The merging tolerance the route was built with, metres.
    pub tolerance_m: f64,
    /// The run's metrics (`GeoJSON` properties), when the path was simulated and measured.
    pub metrics: Option<&'a Metrics>,
}

/// The rectangular robot a route was planned for (seed 001's `l x b` robot, planned as its
/// clearance disk), as the exports name it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    /// Length `l` along the direction of travel, metres.
    pub length_m: f64,
    /// Width `b` (the lane spacing), metres.
    pub width_m: f64,
    /// Radius of the disk the route keeps clear, metres.
    pub clearance_radius_m: f64,
}

impl Footprint {
    /// The rectangle of a rect-boustrophedon `planner` for `robot` (its options' length and
    /// width, defaults resolved); `None` for the other planners, which plan for the robot's
    /// disk.
    #[must_use]
    pub fn of(planner: &ccpp_core::planners::PlannerConfig, robot: &Robot) -> Option<Self> {
        match planner {
            ccpp_core::planners::PlannerConfig::RectBoustrophedon(o) => Some(Self {
                length_m: o.length_for(robot),
                width_m: o.width_for(robot),
                clearance_radius_m: o.clearance_radius(robot),
            }),
            _ => None,
        }
    }
}

/// An extra polygon for the `GeoJSON` export (a keep-out zone, a work area...): rings of map
/// coordinates, the first the outer boundary and any others holes. Rings are written closed
/// (the first point repeated at the end when it is not already).
#[derive(Clone, Debug, PartialEq)]
pub struct PolygonFeature {
    /// What it is (`keepout`, `area`, ...): the `kind` property.
    pub kind: String,
    /// Optional `name` property.
    pub name: Option<String>,
    /// Rings of `(x, y)` map coordinates: outer boundary first, then holes.
    pub rings: Vec<Vec<[f64; 2]>>,
}

/// The zones as `GeoJSON` polygon features: the work area's polygons (`kind` `area`), the
/// keep-out polygons (`kind` `keepout`), each closed, and the keep-out pixels that no polygon
/// gave (a Nav2 mask) as rectangles of whole pixels on `frame` (`kind` `keepout`, `name`
/// `mask`): runs of pixels along a row, merged with the same run in the rows below. A mask
/// keep-out was left out of the exports before.
#[must_use]
pub fn zone_features(
    zones: Option<&ccpp_core::zones::ZoneMasks>,
    frame: &ccpp_core::grid::MapFrame,
) -> Vec<PolygonFeature> {
    let Some(z) = zones else {
        return Vec::new();
    };
    let feature = |kind: &str, p: &ccpp_core::zones::Polygon| PolygonFeature {
        kind: kind.to_string(),
        name: p.name.clone(),
        rings: vec![p.points.clone()],
    };
    let mut out: Vec<PolygonFeature> = z
        .area_polygons
        .iter()
        .map(|p| feature("area", p))
        .chain(z.keepout_polygons.iter().map(|p| feature("keepout", p)))
        .collect();
    let mut mask_only = z.keepout.clone();
    if mask_only.len() == frame.len() {
        mask_only.difference_with(&ccpp_core::zones::rasterize_keepout(
            frame,
            &z.keepout_polygons,
        ));
        out.extend(
            pixel_rectangles(&mask_only, frame)
                .into_iter()
                .map(|ring| PolygonFeature {
                    kind: "keepout".to_string(),
                    name: Some("mask".to_string()),
                    rings: vec![ring],
                }),
        );
    }
    out
}

/// The pixels of `bits` (on `frame`) as closed rectangle rings in map coordinates: each run
/// of set pixels along a row, extended down while the next row has the same run.
fn pixel_rectangles(
    bits: &fixedbitset::FixedBitSet,
    frame: &ccpp_core::grid::MapFrame,
) -> Vec<Vec<[f64; 2]>> {
    let (w, h) = (frame.width, frame.height);
    // Open rectangles: (first column, end column, first row), by first column.
    let mut open: Vec<(usize, usize, usize)> = Vec::new();
    let mut done: Vec<(usize, usize, usize, usize)> = Vec::new();
    for row in 0..=h {
        let mut runs: Vec<(usize, usize)> = Vec::new();
        if row < h {
            let mut c = 0;
            while c < w {
                if bits.contains(row * w + c) {
                    let c0 = c;
                    while c < w && bits.contains(row * w + c) {
                        c += 1;
                    }
                    runs.push((c0, c));
                } else {
                    c += 1;
                }
            }
        }
        let mut next = Vec::with_capacity(runs.len());
        for &(c0, c1, r0) in &open {
            if runs.contains(&(c0, c1)) {
                next.push((c0, c1, r0));
            } else {
                done.push((c0, c1, r0, row));
            }
        }
        for &(c0, c1) in &runs {
            if !open.iter().any(|&(a, b, _)| (a, b) == (c0, c1)) {
                next.push((c0, c1, row));
            }
        }
        next.sort_unstable();
        open = next;
    }
    done.sort_unstable_by_key(|&(c0, c1, r0, r1)| (r0, c0, c1, r1));
    done.into_iter()
        .map(|(c0, c1, r0, r1)| {
            // Grid y is up: rows r0..r1 (down) span grid y from h - r1 to h - r0.
            let corner = |c: usize, r: usize| {
                let p = frame.grid_to_world(Point::new(c as f64, (h - r) as f64));
                [round_m(p.x), round_m(p.y)]
            };
            vec![
                corner(c0, r1),
                corner(c1, r1),
                corner(c1, r0),
                corner(c0, r0),
                corner(c0, r1),
            ]
        })
        .collect()
}

/// Error reading a waypoint file.
#[derive(Debug, thiserror::Error)]
pub enum WaypointFileError {
    /// The file cannot be read.
    #[error("cannot read waypoints {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The content is not a waypoint list.
    #[error("waypoints {} line {line}: {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line (1 for JSON errors without a line).
        line: usize,
        /// What is wrong.
        message: String,
    },
}

/// The route as CSV: header `x,y,theta`, one waypoint a line. A waypoint that is not finite
/// is written as `NaN` or `inf`, which [`parse_waypoints_csv`] refuses: [`render_exports`]
/// refuses such a route instead.
pub fn waypoints_csv(route: &Route) -> String {
    csv_of(&tidy(route))
}

/// [`waypoints_csv`] of a route already [`tidy`].
fn csv_of(route: &Route) -> String {
    let mut s = String::with_capacity(16 + route.waypoints.len() * 48);
    s.push_str("x,y,theta\n");
    for p in &route.waypoints {
        let _ = writeln!(s, "{},{},{}", p.x, p.y, p.theta);
    }
    s
}

/// Parses [`waypoints_csv`] text (`path` names it in errors): a header `x,y,theta` and three
/// finite numbers a line; blank lines are skipped.
///
/// # Errors
/// A missing or different header, or a line that is not three finite numbers.
pub fn parse_waypoints_csv(text: &str, path: &Path) -> Result<Route, WaypointFileError> {
    let err = |line: usize, message: String| WaypointFileError::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut lines = text.lines().enumerate();
    match lines.next() {
        Some((_, h)) if h.trim() == "x,y,theta" => {}
        Some((_, h)) => return Err(err(1, format!("expected the header x,y,theta, got {h:?}"))),
        None => return Err(err(1, "empty file (expected the header x,y,theta)".into())),
    }
    let mut waypoints = Vec::new();
    for (k, line) in lines {
        if line.trim().is_empty() {
            continue;
        }
        let v: Vec<f64> = line
            .split(',')
            .map(|x| x.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| err(k + 1, format!("{line:?}: {e}")))?;
        match v.as_slice() {
            &[x, y, theta] if x.is_finite() && y.is_finite() && theta.is_finite() => {
                waypoints.push(Pose::new(x, y, theta));
            }
            _ => {
                return Err(err(
                    k + 1,
                    format!("expected three finite numbers x,y,theta, got {line:?}"),
                ))
            }
        }
    }
    Ok(Route { waypoints })
}

/// One waypoint in `waypoints.json`.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonWaypoint {
    x: f64,
    y: f64,
    theta: f64,
}

/// `waypoints.json`.
#[derive(Serialize, Deserialize)]
struct WaypointsJson {
    frame_id: String,
    planner: String,
    map: String,
    tolerance_m: f64,
    length_m: f64,
    waypoints: Vec<JsonWaypoint>,
}

/// The route as pretty JSON: `frame_id`, `planner`, `map`, `tolerance_m`, `length_m` and
/// `waypoints` (objects `{"x","y","theta"}`).
///
/// # Errors
/// A waypoint that is not finite.
pub fn waypoints_json(route: &Route, meta: &ExportMeta<'_>) -> Result<String, serde_json::Error> {
    check_finite(route)?;
    json_of(&tidy(route), meta)
}

/// Refuses a route with a waypoint that is not finite (`Route`'s field is public: a library
/// user's route with a NaN was written as `null` coordinates, invalid `GeoJSON`, and as `NaN`
/// rows that `ccpp` itself cannot read back: hostile pass).
fn check_finite(route: &Route) -> Result<(), serde_json::Error> {
    match route
        .waypoints
        .iter()
        .position(|p| !(p.x.is_finite() && p.y.is_finite() && p.theta.is_finite()))
    {
        None => Ok(()),
        Some(k) => {
            let p = route.waypoints[k];
            Err(serde::ser::Error::custom(format!(
                "waypoint {} of the route is not finite: ({}, {}, {})",
                k + 1,
                p.x,
                p.y,
                p.theta
            )))
        }
    }
}

/// [`waypoints_json`] of a route already [`tidy`].
fn json_of(route: &Route, meta: &ExportMeta<'_>) -> Result<String, serde_json::Error> {
    let doc = WaypointsJson {
        frame_id: FRAME_ID.to_string(),
        planner: meta.planner.to_string(),
        map: meta.map.to_string(),
        tolerance_m: meta.tolerance_m,
        length_m: round_m(route.length_m()),
        waypoints: route
            .waypoints
            .iter()
            .map(|p| JsonWaypoint {
                x: p.x,
                y: p.y,
                theta: p.theta,
            })
            .collect(),
    };
    let mut s = serde_json::to_string_pretty(&doc)?;
    s.push('\n');
    Ok(s)
}

/// Parses [`waypoints_json`] text (`path` names it in errors).
///
/// # Errors
/// Not such a document, or a non-finite number.
pub fn parse_waypoints_json(text: &str, path: &Path) -> Result<Route, WaypointFileError> {
    let doc: WaypointsJson = serde_json::from_str(text).map_err(|e| WaypointFileError::Parse {
        path: path.to_path_buf(),
        line: e.line().max(1),
        message: e.to_string(),
    })?;
    let waypoints = doc
        .waypoints
        .into_iter()
        .map(|w| Pose::new(w.x, w.y, w.theta))
        .collect();
    Ok(Route { waypoints })
}

/// Reads `waypoints.csv` or `waypoints.json` (by extension: `.json` is JSON, anything else CSV).
///
/// # Errors
/// An unreadable file or the parse errors of [`parse_waypoints_csv`] / [`parse_waypoints_json`];
/// a `.yaml`, `.yml` or `.geojson` file (ccpp's other exports, which it does not read back) is
/// refused as such (a `nav_path.yaml` was refused as a CSV without the header `x,y,theta`).
pub fn read_waypoints(path: &Path) -> Result<Route, WaypointFileError> {
    if let Some(ext) = path.extension().and_then(|e| e.to_str()).filter(|e| {
        ["yaml", "yml", "geojson"]
            .iter()
            .any(|k| e.eq_ignore_ascii_case(k))
    }) {
        return Err(WaypointFileError::Parse {
            path: path.to_path_buf(),
            line: 1,
            message: format!(
                "a .{ext} file: waypoints are read back from the CSV (x,y,theta) and JSON exports only"
            ),
        });
    }
    let text = crate::file::read_text(path).map_err(|source| WaypointFileError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
    {
        parse_waypoints_json(&text, path)
    } else {
        parse_waypoints_csv(&text, path)
    }
}

/// A YAML float: the shortest round-trip decimal, never with an exponent, always with a
/// decimal point (`1.0`, not `1`), so YAML 1.1 and 1.2 parsers both read a float.
fn yaml_float(v: f64) -> String {
    if !v.is_finite() {
        return if v.is_nan() {
            ".nan".to_string()
        } else if v > 0.0 {
            ".inf".to_string()
        } else {
            "-.inf".to_string()
        };
    }
    let s = format!("{v}");
    if s.contains('.') {
        s
    } else {
        format!("{s}.0")
    }
}

/// The quaternion `[x, y, z, w]` of a rotation by `theta` about the z axis.
pub fn heading_quaternion(theta: f64) -> [f64; 4] {
    let h = 0.5 * theta;
    // (cos(pi / 2) is 6e-17 in floating point; a component that small is written as 0)
    let clean = |v: f64| if v.abs() < 1e-15 { 0.0 } else { v };
    [0.0, 0.0, clean(h.sin()), clean(h.cos())]
}

/// The route as a ROS 2 `nav_msgs/Path` in the YAML shape `ros2 topic echo` prints:
/// `header` (stamp 0, `frame_id: map`) and `poses`, a list of `geometry_msgs/PoseStamped`
/// (same header; `pose.position` x, y, z = 0; `pose.orientation` the heading quaternion
/// [`heading_quaternion`]). The trailing `---` document separator is left out so that the file
/// is one YAML document. A waypoint that is not finite is written as `.nan` or `.inf`:
/// [`render_exports`] refuses such a route instead.
pub fn nav_path_yaml(route: &Route) -> String {
    nav_path_of(&tidy(route))
}

/// [`nav_path_yaml`] of a route already [`tidy`].
fn nav_path_of(route: &Route) -> String {
    let mut s = String::with_capacity(128 + route.waypoints.len() * 280);
    let header = |s: &mut String, indent: &str| {
        let _ = write!(
            s,
            "{indent}header:\n{indent}  stamp:\n{indent}    sec: 0\n{indent}    nanosec: 0\n{indent}  frame_id: {FRAME_ID}\n"
        );
    };
    header(&mut s, "");
    if route.waypoints.is_empty() {
        s.push_str("poses: []\n");
        return s;
    }
    s.push_str("poses:\n");
    for p in &route.waypoints {
        let q = heading_quaternion(p.theta);
        s.push_str("- ");
        // The first key shares the list item's line.
        let mut item = String::new();
        header(&mut item, "");
        let _ = write!(
            item,
            "pose:\n  position:\n    x: {}\n    y: {}\n    z: 0.0\n  orientation:\n    x: {}\n    y: {}\n    z: {}\n    w: {}\n",
            yaml_float(p.x),
            yaml_float(p.y),
            yaml_float(q[0]),
            yaml_float(q[1]),
            yaml_float(q[2]),
            yaml_float(q[3]),
        );
        for (k, line) in item.lines().enumerate() {
            if k > 0 {
                s.push_str("  ");
            }
            s.push_str(line);
            s.push('\n');
        }
    }
    s
}

/// A ring closed: the first point repeated at the end when it is not already.
fn closed_ring(ring: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut r = ring.to_vec();
    if let (Some(&first), Some(&last)) = (r.first(), r.last()) {
        if first != last {
            r.push(first);
        }
    }
    r
}

/// A ring closed ([`closed_ring`]) and turned as RFC 7946 (section 3.1.6) asks: an exterior
/// ring counter-clockwise, a hole clockwise. A zone given clockwise was written clockwise.
fn oriented_ring(ring: &[[f64; 2]], exterior: bool) -> Vec<[f64; 2]> {
    let p = ccpp_core::zones::Polygon {
        points: closed_ring(ring),
        name: None,
    };
    let clockwise = p.signed_area() < 0.0;
    let mut r = p.points;
    if clockwise == exterior {
        r.reverse();
    }
    r
}

/// The `robot` property of the exports: the disk (`radius_m`, `tool_radius_m`) and, for a
/// rectangular robot, its `footprint` (`shape: "rectangle"`, `length_m`, `width_m`,
/// `clearance_radius_m`). A rectangle's plan that was not simulated has the footprint only:
/// its route depends on the rectangle alone (`ccpp plan` refuses `--tool-radius` there, and a
/// `--radius` below the clearance disk changes nothing), so a disk beside it named values the
/// route was not planned for.
fn robot_json(meta: &ExportMeta<'_>) -> serde_json::Value {
    let mut robot = if meta.footprint.is_some() && meta.metrics.is_none() {
        serde_json::json!({})
    } else {
        serde_json::json!({
            "radius_m": meta.robot.radius,
            "tool_radius_m": meta.robot.tool_radius,
        })
    };
    if let (Some(f), serde_json::Value::Object(fields)) = (meta.footprint, &mut robot) {
        fields.insert(
            "footprint".into(),
            serde_json::json!({
                "shape": "rectangle",
                "length_m": f.length_m,
                "width_m": f.width_m,
                "clearance_radius_m": f.clearance_radius_m,
            }),
        );
    }
    robot
}

/// The route (and `polygons`) as a `GeoJSON` `FeatureCollection` in map coordinates
/// (`[x, y]` order, metres). The first feature is the route: a `LineString` of the waypoints
/// (a single waypoint is repeated so the line has the two positions `GeoJSON` requires; an empty
/// route has a `null` geometry) with properties `kind: "path"`, `frame_id`, `planner`, `map`,
/// `robot` (`radius_m`, `tool_radius_m`, and a rectangular robot's `footprint`; a rectangle's
/// plan that was not simulated has only the footprint), `route`
/// (`waypoints`, `length_m`, `tolerance_m`) and
/// `metrics` (the run's metrics but `wall_time_s`, which differs between identical runs, or
/// `null` for a plan that was not measured). Then one
/// `Polygon` feature per entry of `polygons` with properties `kind` and `name`, rings closed
/// and turned counter-clockwise (holes clockwise).
///
/// # Errors
/// A waypoint that is not finite.
pub fn geojson(
    route: &Route,
    meta: &ExportMeta<'_>,
    polygons: &[PolygonFeature],
) -> Result<String, serde_json::Error> {
    check_finite(route)?;
    geojson_of(&tidy(route), meta, polygons)
}

/// [`geojson`] of a route already [`tidy`].
fn geojson_of(
    route: &Route,
    meta: &ExportMeta<'_>,
    polygons: &[PolygonFeature],
) -> Result<String, serde_json::Error> {
    use serde_json::{json, Value};
    let mut coords: Vec<[f64; 2]> = route.waypoints.iter().map(|p| [p.x, p.y]).collect();
    if coords.len() == 1 {
        coords.push(coords[0]);
    }
    let geometry = if coords.is_empty() {
        Value::Null
    } else {
        json!({ "type": "LineString", "coordinates": coords })
    };
    let mut metrics = match meta.metrics {
        Some(m) => serde_json::to_value(m)?,
        None => Value::Null,
    };
    // The wall time is the one number that differs between identical runs; a path export
    // leaves it out, so that the same inputs give the same file.
    if let Value::Object(fields) = &mut metrics {
        fields.remove("wall_time_s");
    }
    let features = [json!({
        "type": "Feature",
        "geometry": geometry,
        "properties": {
            "kind": "path",
            "frame_id": FRAME_ID,
            "planner": meta.planner,
            "map": meta.map,
            "robot": robot_json(meta),
            "route": {
                "waypoints": route.waypoints.len(),
                "length_m": round_m(route.length_m()),
                "tolerance_m": meta.tolerance_m,
            },
            "metrics": metrics,
        },
    })];
    // The document is written feature by feature, as `to_string_pretty` would write it whole
    // (keys in order, two spaces an indent): a tree of every feature first took ten times the
    // file's size (a speckled Nav2 mask of 248 101 rectangles: 1.78 GB for a 167 MB file).
    let mut s = String::from("{\n  \"features\": [\n");
    let put = |s: &mut String, f: &Value, first: bool| -> Result<(), serde_json::Error> {
        if !first {
            s.push_str(",\n");
        }
        for (i, line) in serde_json::to_string_pretty(f)?.lines().enumerate() {
            if i > 0 {
                s.push('\n');
            }
            s.push_str("    ");
            s.push_str(line);
        }
        Ok(())
    };
    put(&mut s, &features[0], true)?;
    for p in polygons {
        let rings: Vec<Vec<[f64; 2]>> = p
            .rings
            .iter()
            .enumerate()
            .map(|(k, r)| oriented_ring(r, k == 0))
            .collect();
        let f = json!({
            "type": "Feature",
            "geometry": { "type": "Polygon", "coordinates": rings },
            "properties": { "kind": p.kind, "name": p.name },
        });
        put(&mut s, &f, false)?;
    }
    s.push_str("\n  ],\n  \"type\": \"FeatureCollection\"\n}\n");
    Ok(s)
}

/// Renders `route` in each of `formats` (duplicates written once, in [`ExportFormat::ALL`]
/// order): `(file name, bytes)`. `polygons` go into the `GeoJSON`.
///
/// # Errors
/// A waypoint that is not finite, in any format.
pub fn render_exports(
    route: &Route,
    meta: &ExportMeta<'_>,
    formats: &[ExportFormat],
    polygons: &[PolygonFeature],
) -> Result<Vec<(&'static str, Vec<u8>)>, serde_json::Error> {
    check_finite(route)?;
    // Tidied once for every format (each public writer tidies its own).
    let route = &tidy(route);
    let mut out = Vec::new();
    for f in ExportFormat::ALL {
        if !formats.contains(&f) {
            continue;
        }
        let text = match f {
            ExportFormat::Csv => csv_of(route),
            ExportFormat::Json => json_of(route, meta)?,
            ExportFormat::NavPath => nav_path_of(route),
            ExportFormat::GeoJson => geojson_of(route, meta, polygons)?,
        };
        out.push((f.file_name(), text.into_bytes()));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn route() -> Route {
        Route {
            waypoints: vec![
                Pose::new(1.0, 2.0, 0.0),
                Pose::new(3.5, 2.0, std::f64::consts::FRAC_PI_2),
                Pose::new(3.5, 4.25, -3.0),
            ],
        }
    }

    fn meta() -> ExportMeta<'static> {
        ExportMeta {
            planner: "bcd",
            map: "m",
            robot: Robot {
                radius: 0.15,
                tool_radius: 0.15,
            },
            footprint: None,
            tolerance_m: 0.001,
            metrics: None,
        }
    }

    /// A route with a waypoint that is not finite is refused, naming it, by every writer that
    /// can fail (it was written as `null` coordinates in the JSON and `GeoJSON`).
    #[test]
    fn a_route_that_is_not_finite_is_refused() {
        for bad in [f64::NAN, f64::INFINITY] {
            let mut r = route();
            r.waypoints[1].y = bad;
            let e = waypoints_json(&r, &meta()).expect_err("json");
            assert!(
                e.to_string()
                    .contains("waypoint 2 of the route is not finite"),
                "{e}"
            );
            assert!(geojson(&r, &meta(), &[]).is_err());
            assert!(render_exports(&r, &meta(), &[ExportFormat::Csv], &[]).is_err());
        }
        assert!(render_exports(&route(), &meta(), &ExportFormat::ALL, &[]).is_ok());
    }

    /// ccpp's other exports are refused as such, not as a CSV missing its header.
    #[test]
    fn the_yaml_and_geojson_exports_are_not_read_as_waypoints() {
        let d = tempfile::tempdir().unwrap();
        for name in ["nav_path.yaml", "p.YML", "path.geojson"] {
            let p = d.path().join(name);
            std::fs::write(&p, nav_path_yaml(&route())).unwrap();
            let e = read_waypoints(&p).expect_err(name).to_string();
            assert!(
                e.contains("read back from the CSV (x,y,theta) and JSON exports only"),
                "{e}"
            );
        }
    }

    #[test]
    fn csv_and_json_round_trip() {
        let r = route();
        let back = parse_waypoints_csv(&waypoints_csv(&r), Path::new("w.csv"));
        assert_eq!(back.ok(), Some(r.clone()));
        let text = waypoints_json(&r, &meta()).unwrap_or_default();
        let back = parse_waypoints_json(&text, Path::new("w.json"));
        assert_eq!(back.ok(), Some(r));
    }

    #[test]
    fn bad_waypoint_files_name_the_line() {
        let e = parse_waypoints_csv("x,y,theta\n1,2,3\n1,2\n", Path::new("w.csv"))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("w.csv line 3"), "{e}");
        let e = parse_waypoints_csv("a,b\n", Path::new("w.csv"))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("header"), "{e}");
        let e = parse_waypoints_csv("x,y,theta\n1,NaN,0\n", Path::new("w.csv"));
        assert!(e.is_err());
        assert!(parse_waypoints_json("{}", Path::new("w.json")).is_err());
    }

    /// Far from the origin, waypoints that round to one position (two poses of a rotation in
    /// place under odometry noise, a few `f64` steps apart, or a unit of the last place kept)
    /// are one waypoint with the later heading; the hostile pass found both exported as two
    /// rows at one position in every format (`bsa-bfs` with noise at 4.2e6 m).
    #[test]
    fn far_out_waypoints_at_one_exported_position_merge() {
        let x = 4_242_861.700_001_6;
        let y = 5_340_004.375_736_46;
        let step = |v: f64| f64::from_bits(v.to_bits() + 2);
        let r = Route {
            waypoints: vec![
                Pose::new(x - 3.0, y, 0.0),
                Pose::new(x, y, 1.365_933_260_428_760_4),
                Pose::new(step(x), step(y), 2.257_356_936_097_352),
                Pose::new(x + 1e-8, y, 2.3),
                Pose::new(x - 2.0, y + 2.0, 2.3),
            ],
        };
        let t = tidy(&r);
        assert_eq!(t.waypoints.len(), 3, "{t:?}");
        assert_eq!(t.waypoints[1].theta, 2.3);
        assert_eq!(t.waypoints[1].x, round_m(x));
        assert_eq!(tidy(&t), t);
        let csv = waypoints_csv(&r);
        assert_eq!(csv.lines().count(), 4, "{csv}");
        // Near the origin a nanometre apart is still two positions (nothing merged there
        // beyond what the route merges).
        let near = Route {
            waypoints: vec![
                Pose::new(0.0, 0.0, 0.0),
                Pose::new(0.5, 0.0, 1.0),
                Pose::new(0.5 + 2e-9, 0.0, 2.0),
            ],
        };
        assert_eq!(tidy(&near).waypoints.len(), 3);
    }

    #[test]
    fn exports_leave_the_float_noise_out() {
        use std::f64::consts::{FRAC_PI_2, PI};
        let r = Route {
            waypoints: vec![
                Pose::new(0.675_000_000_000_000_5, -1e-17, 4.4e-15),
                Pose::new(30.650_000_000_000_002, 2.0, -PI),
                Pose::new(1.234_567_890_4, 2.0, -1.570_796_326_794_825_5),
                Pose::new(3.0, 2.0, 2.5 + 2.0 * PI),
            ],
        };
        let csv = waypoints_csv(&r);
        assert_eq!(
            csv,
            format!("x,y,theta\n0.675,0,0\n30.65,2,{PI}\n1.23456789,2,-{FRAC_PI_2}\n3,2,2.5\n")
        );
        assert_eq!(tidy(&tidy(&r)), tidy(&r));
        let yaml = nav_path_yaml(&r);
        assert!(yaml.contains("x: 30.65\n"), "{yaml}");
        // heading pi: the quaternion (0, 0, 1, 0), not (0, 0, -1, 6e-17)
        assert!(yaml.contains("z: 1.0\n      w: 0.0\n"), "{yaml}");
        assert!(!yaml.contains("0000000"), "{yaml}");
        let json = waypoints_json(&r, &meta()).unwrap_or_default();
        assert!(json.contains("\"x\": 0.675,"), "{json}");
        // A heading a micro-radian off an axis is a real heading: kept.
        assert_eq!(tidy_heading(1e-6), 1e-6);
        assert_eq!(round_m(-1e-10), 0.0);
        assert!(round_m(-1e-10).is_sign_positive());
        // Far from the origin (UTM-like coordinates): clean values stay clean, noise goes, and
        // rounding twice changes nothing, up to the 1e8 m placement limit.
        assert_eq!(round_m(4_242_856.065), 4_242_856.065);
        assert_eq!(round_m(5_340_003.347_999_999), 5_340_003.348);
        assert_eq!(round_m(1e8 - 1e-8), 1e8);
        let mut v = 0.123_456_789_012_345;
        for _ in 0..2000 {
            let r = round_m(v);
            assert_eq!(round_m(r), r, "{v}");
            assert!((r - v).abs() <= 5e-9_f64.max(v.abs() * 1e-14), "{v} -> {r}");
            v = v * 1.013 + 0.37;
            if v > 1e8 {
                v = -v / 3e7;
            }
        }
    }

    #[test]
    fn yaml_floats_have_a_point_and_no_exponent() {
        assert_eq!(yaml_float(1.0), "1.0");
        assert_eq!(yaml_float(-0.5), "-0.5");
        assert_eq!(yaml_float(1e-17), "0.00000000000000001");
        assert_eq!(yaml_float(1e20), "100000000000000000000.0");
    }

    #[test]
    fn formats_parse_by_name() {
        for f in ExportFormat::ALL {
            assert_eq!(f.name().parse::<ExportFormat>().ok(), Some(f));
        }
        assert!("kml".parse::<ExportFormat>().is_err());
    }

    #[test]
    fn geojson_closes_rings_and_keeps_xy_order() {
        let poly = PolygonFeature {
            kind: "keepout".into(),
            name: Some("rug".into()),
            rings: vec![vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]],
        };
        let text = geojson(&route(), &meta(), &[poly]).unwrap_or_default();
        let v: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
        assert_eq!(v["type"], "FeatureCollection");
        assert_eq!(v["features"][0]["geometry"]["coordinates"][1][0], 3.5);
        assert_eq!(v["features"][0]["geometry"]["coordinates"][2][1], 4.25);
        let ring = &v["features"][1]["geometry"]["coordinates"][0];
        assert_eq!(ring.as_array().map(Vec::len), Some(4));
        assert_eq!(ring[0], ring[3]);
        assert_eq!(v["features"][1]["properties"]["kind"], "keepout");
    }

    /// RFC 7946 ring orientation: a zone given clockwise is written counter-clockwise, one
    /// given counter-clockwise as it is; a second ring (a hole) clockwise.
    #[test]
    fn geojson_rings_turn_counter_clockwise() {
        let ccw = vec![[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]];
        let cw: Vec<[f64; 2]> = ccw.iter().rev().copied().collect();
        let hole = vec![[0.5, 0.5], [1.0, 0.5], [1.0, 1.0]];
        let polys: Vec<PolygonFeature> = [vec![cw.clone()], vec![ccw.clone()], vec![cw, hole]]
            .into_iter()
            .map(|rings| PolygonFeature {
                kind: "keepout".into(),
                name: None,
                rings,
            })
            .collect();
        let text = geojson(&route(), &meta(), &polys).unwrap_or_default();
        let v: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
        let area2 = |r: &serde_json::Value| -> f64 {
            let p: Vec<[f64; 2]> = serde_json::from_value(r.clone()).unwrap_or_default();
            p.windows(2)
                .map(|w| w[0][0] * w[1][1] - w[1][0] * w[0][1])
                .sum()
        };
        for k in 1..=3 {
            let ring = &v["features"][k]["geometry"]["coordinates"][0];
            assert!((area2(ring) - 8.0).abs() < 1e-12, "feature {k}: {ring}");
            assert_eq!(ring[0], ring[4]);
        }
        let hole = &v["features"][3]["geometry"]["coordinates"][1];
        assert!(area2(hole) < 0.0, "{hole}");
        // The counter-clockwise ring is written as given.
        assert_eq!(
            v["features"][2]["geometry"]["coordinates"][0][1],
            serde_json::json!([2.0, 0.0])
        );
    }

    /// Written feature by feature, the document is what `to_string_pretty` writes whole.
    #[test]
    fn geojson_is_pretty_json_as_a_whole() {
        let polys: Vec<PolygonFeature> = (0..3)
            .map(|k| PolygonFeature {
                kind: "keepout".into(),
                name: (k == 1).then(|| "rug \"new\"\nline".to_string()),
                rings: vec![vec![[0.0, 0.0], [1.0 + f64::from(k), 0.0], [1.0, 1.0]]],
            })
            .collect();
        for polys in [&polys[..], &[]] {
            let text = geojson(&route(), &meta(), polys).unwrap_or_default();
            let v: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
            let whole = serde_json::to_string_pretty(&v).unwrap_or_default() + "\n";
            assert_eq!(text, whole);
            assert_eq!(
                v["features"].as_array().map(Vec::len),
                Some(1 + polys.len())
            );
        }
    }
}
