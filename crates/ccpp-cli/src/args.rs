//! Command-line arguments.

use std::path::PathBuf;

use ccpp_io::export::ExportFormat;
use ccpp_io::zones::ZoneSpec;
use clap::{Args, Parser, Subcommand};

/// Complete coverage path planning for mobile robots on 2-D occupancy-grid maps.
#[derive(Parser, Debug)]
#[command(name = "ccpp", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Simulate one planner on one map and write metrics, path, trace and a picture.
    Run(RunArgs),
    /// Run the flagship planner on the bundled demo map (writes ./ccpp-demo/).
    Demo(DemoArgs),
    /// List the planners, or print their default options as a `--config` file.
    Planners(PlannersArgs),
    /// Describe a map: size, resolution, pixel classes, components, accessible area.
    Info(InfoArgs),
    /// Run every planner on every map in parallel; write results.csv, results.md and plots.
    Bench(BenchArgs),
    /// Write the interactive replay.html (self-contained) and replay.gif of a finished run.
    Replay(ReplayArgs),
    /// Print the lane waypoints of a rectangular robot (seed 001) for a map, as CSV or JSON:
    /// its stops every robot length along each lane and the points of the detours between
    /// lanes (and from the start to the first lane; the start itself is not listed), without
    /// headings (without `--area`,
    /// `ccpp plan --planner rect-boustrophedon` gives the same lanes as a drivable route with
    /// headings; `--area` here is the rectangle the robot's centre lanes cover, there the area
    /// the whole robot stays inside).
    Waypoints(WaypointsArgs),
    /// Plan a path for a robot on a known map (bcd, rect-boustrophedon) and write only the path
    /// exports (default: `nav_path.yaml` and `waypoints.csv`); no simulation metrics.
    Plan(PlanArgs),
}

/// Map loading options shared by commands.
#[derive(Args, Debug, Clone, Default)]
pub struct MapArgs {
    /// Map file: a ROS `map_server` YAML (with its PGM/PNG) or a bare PGM/PNG image.
    #[arg(long, value_name = "FILE")]
    pub map: PathBuf,
    /// Override the resolution (m/px); bare images default to 0.05.
    #[arg(long, value_parser = parse_number, value_name = "M")]
    pub resolution: Option<f64>,
    /// Override the origin `X,Y[,YAW]` (world pose of the lower-left pixel; YAW left out is 0, not the map's yaw).
    #[arg(long, value_name = "X,Y[,YAW]", value_parser = parse_origin, allow_hyphen_values = true)]
    pub origin: Option<[f64; 3]>,
    /// Override `occupied_thresh`.
    #[arg(long, value_parser = parse_number, value_name = "P")]
    pub occupied_thresh: Option<f64>,
    /// Override `free_thresh`.
    #[arg(long, value_parser = parse_number, value_name = "P")]
    pub free_thresh: Option<f64>,
    /// Place the image by the rotation + uniform scale that fits surveyed point pairs best
    /// (least squares): a CSV of `px,py,wx,wy` lines (pixel coordinates from the image's
    /// top-left corner, y down; world metres). Overrides resolution and origin (a map YAML may
    /// leave them out). Refused when a pair misses the placement by more than 5 px or 0.5 m,
    /// whichever is more (a typo, or survey axes scaled apart).
    #[arg(long, value_name = "FILE")]
    pub georef: Option<PathBuf>,
    /// Grow obstacles by this many metres (exact distance transform) before anything else, as a
    /// costmap's inflation: the grown map is what the command works on (a run's planner, sensor,
    /// collisions and coverage figures, a plan's path, `info`'s figures), so the floor within M
    /// of an obstacle is no floor to cover and touching it is a collision.
    #[arg(long, value_parser = parse_number, value_name = "M")]
    pub inflate: Option<f64>,
}

/// Robot options shared by commands.
#[derive(Args, Debug, Clone)]
pub struct RobotArgs {
    /// Robot (footprint) radius in metres [default: 0.15].
    // An `Option` (its default applied in `job::robot_from`): `plan` and `waypoints` refuse a
    // radius given beside a rectangle whose disk it cannot change.
    #[arg(long, value_parser = parse_number, value_name = "M")]
    pub radius: Option<f64>,
    /// Cleaning tool radius in metres, at most the robot radius (default: the robot radius).
    /// `plan` refuses it for rect-boustrophedon, whose lanes follow its lane width.
    #[arg(long, value_parser = parse_number, value_name = "M")]
    pub tool_radius: Option<f64>,
    /// Start pose `X,Y[,THETA]` in metres/radians (default: the widest free spot, heading
    /// east). THETA is for `run`: `info`, `plan` and `waypoints` use no heading and refuse
    /// one.
    #[arg(long, value_name = "X,Y[,THETA]", value_parser = parse_start, allow_hyphen_values = true)]
    pub start: Option<StartArg>,
}

/// A `--start` value: the pose (THETA left out is 0) and whether THETA was given, so that a
/// command that uses no heading refuses any, 0 included (`--start 2,2,0` was taken by `plan`
/// and dropped while `--start 2,2,1` was refused).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StartArg {
    /// `[x, y, theta]`.
    pub pose: [f64; 3],
    /// Whether THETA was given.
    pub heading_given: bool,
}

/// Parses `X,Y[,THETA]` into a [`StartArg`].
fn parse_start(s: &str) -> Result<StartArg, String> {
    let parts = parse_finite_list(s)?;
    let pose = parse_triple(s)?;
    Ok(StartArg {
        pose,
        heading_given: parts.len() == 3,
    })
}

/// Work area and keep-out zones, shared by `run`, `plan` and `info` (every planner honours them).
#[derive(Args, Debug, Clone, Default)]
pub struct ZoneArgs {
    /// Work area: a polygon file (`GeoJSON`, or YAML list of x,y points; map coordinates) or a
    /// rectangle `X0,Y0,X1,Y1`. The robot stays inside it (virtual walls: its pixels are
    /// those wholly inside); `run` measures coverage on the floor inside it. Default: the
    /// whole map.
    #[arg(long, value_name = "FILE|X0,Y0,X1,Y1", value_parser = parse_zone, allow_hyphen_values = true)]
    pub area: Option<ZoneSpec>,
    /// Keep-out zone (repeatable): a Nav2 keepout filter mask (`map_server` YAML + image in the
    /// map's frame, occupied = forbidden), a polygon file (`GeoJSON` or YAML) or a rectangle
    /// `X0,Y0,X1,Y1`. Never entered (`run` counts entries as `keepout_violations`).
    #[arg(long, value_name = "FILE|X0,Y0,X1,Y1", value_parser = parse_zone, allow_hyphen_values = true)]
    pub keepout: Vec<ZoneSpec>,
}

/// The planner options file, shared by `run`, `plan` and `bench`.
#[derive(Args, Debug, Clone, Default)]
pub struct OptionsArgs {
    /// Planner options file (YAML or JSON), sections named after the planners, e.g.
    /// `random_bounce: { budget_m: 200 }`.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
}

/// The memory budget, shared by every command that plans (`run`, `plan`, `waypoints`, `bench`).
#[derive(Args, Debug, Clone, Default)]
pub struct LimitArgs {
    /// Refuse work whose estimated memory exceeds this many MB (default 4096). MB in the limit and in
    /// every memory figure ccpp prints is 2^20 bytes (a MiB).
    #[arg(long, value_parser = parse_whole::<u64>, value_name = "MB")]
    pub max_memory: Option<u64>,
}

impl LimitArgs {
    /// The limit in MB: `--max-memory`, else the library's default.
    pub fn max_memory_mb(&self) -> u64 {
        self.max_memory
            .unwrap_or(ccpp_io::scenario::DEFAULT_MAX_MEMORY_MB)
    }
}

/// `ccpp run`.
#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct RunArgs {
    /// The map.
    #[command(flatten)]
    pub map: MapArgs,
    /// The robot.
    #[command(flatten)]
    pub robot: RobotArgs,
    /// Planner name (see `ccpp planners`).
    #[arg(long, value_name = "NAME")]
    pub planner: String,
    /// Seed of random-bounce's turns and of --odometry-noise (default 0; refused for other
    /// runs).
    #[arg(long, value_parser = parse_whole::<u64>, value_name = "N")]
    pub seed: Option<u64>,
    /// Planner options.
    #[command(flatten)]
    pub options: OptionsArgs,
    /// Sensor range in metres of random-bounce, ba-star-extended and bsa-extended (default
    /// 4 r, or the least the planner runs with where that is more: a robot of a pixel or two,
    /// a tile wider than 3 r); ba-star, bsa and bsa-bfs decide from their neighbour tiles alone and sense
    /// as far as that needs (refused for them and for the offline planners)
    #[arg(long, value_parser = parse_number, value_name = "M")]
    pub sensor_range: Option<f64>,
    /// Tile side in metres: ba-star and ba-star-extended tiles, bsa-bfs cells (default 2 r).
    #[arg(long, value_parser = parse_number, value_name = "M")]
    pub tile_side: Option<f64>,
    /// BA* backtracking path smoothing (A*SPT): `on` (default) or `off` to compare (also
    /// `true`/`false`, `yes`/`no`, `1`/`0`). For
    /// ba-star-extended it changes only the backtracks where BA*'s own path is driven: by
    /// default (`shorter_backtrack: true`) the extension's known-free way replaces it wherever
    /// that is shorter, which is almost everywhere.
    #[arg(long, value_name = "on|off", value_parser = parse_on_off)]
    pub smoothing: Option<bool>,
    /// BSA reference lateral side: `left` (default) or `right`.
    #[arg(long, value_name = "left|right")]
    pub side: Option<String>,
    /// Rectangular robot length in metres (rect-boustrophedon: waypoint spacing; default: the
    /// tool's width 2 x tool radius).
    #[arg(long, value_parser = parse_number, value_name = "M")]
    pub length: Option<f64>,
    /// Rectangular robot width in metres (rect-boustrophedon: lane spacing; default and at
    /// most, in a run: the tool's width 2 x tool radius).
    #[arg(long, value_parser = parse_number, value_name = "M")]
    pub width: Option<f64>,
    /// Work area and keep-out zones.
    #[command(flatten)]
    pub zones: ZoneArgs,
    /// Motion execution: `ideal` (exact rotate/translate) or `pid` (unicycle with PID
    /// tracking). Default: the planner's choice (bsa-bfs and rect-boustrophedon: pid).
    #[arg(long, value_name = "ideal|pid")]
    pub exec: Option<String>,
    /// Odometry noise under PID execution: relative std of linear and angular speed and the
    /// heading drift while driving (rad/s per m/s), standard deviations per control step of
    /// 0.05 s (the default `dt_s`; another period scales them by `sqrt(0.05 / dt_s)`, so the
    /// drift over a run does not depend on it), `LIN[,ANG[,DRIFT]]` (ANG defaults to LIN,
    /// DRIFT to 0; LIN and ANG at most 1, DRIFT at most 6; each 0 or at least 1e-9, not all 0; seeded by --seed, default 0). Without --exec it switches the run to PID execution;
    /// refused with --exec ideal.
    #[arg(long, value_name = "LIN[,ANG[,DRIFT]]")]
    pub odometry_noise: Option<String>,
    /// Landmarks for pose correction under PID (CSV `id,x,y[,theta]` or a JSON array).
    #[arg(long, value_name = "FILE")]
    pub landmarks: Option<PathBuf>,
    /// Memory budget.
    #[command(flatten)]
    pub limits: LimitArgs,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "ccpp-out")]
    pub out: PathBuf,
    /// Print the metrics JSON alone on stdout.
    #[arg(long)]
    pub json: bool,
    /// Also write replay.html and replay.gif.
    #[arg(long)]
    pub replay: bool,
    /// Also write the executed path as FORMAT (repeatable): `csv` (waypoints.csv), `json`
    /// (waypoints.json), `nav-path` (`nav_path.yaml`, a ROS `nav_msgs/Path`) or `geojson`
    /// (path.geojson).
    #[arg(long, value_name = "FORMAT", value_parser = parse_export)]
    pub export: Vec<ExportFormat>,
}

/// `ccpp plan`.
#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct PlanArgs {
    /// The map.
    #[command(flatten)]
    pub map: MapArgs,
    /// The robot.
    #[command(flatten)]
    pub robot: RobotArgs,
    /// A known-map planner: `bcd` or `rect-boustrophedon` (online planners are refused).
    #[arg(long, value_name = "NAME")]
    pub planner: String,
    /// Planner options.
    #[command(flatten)]
    pub options: OptionsArgs,
    /// Rectangular robot length in metres (rect-boustrophedon: waypoint spacing; default: the
    /// robot's diameter).
    #[arg(long, value_parser = parse_number, value_name = "M")]
    pub length: Option<f64>,
    /// Rectangular robot width in metres (rect-boustrophedon: lane spacing; default: the
    /// robot's diameter; any width: a plan has no tool, the rectangle is the robot).
    #[arg(long, value_parser = parse_number, value_name = "M")]
    pub width: Option<f64>,
    /// Work area and keep-out zones (the path stays inside the area, outside the keep-outs).
    #[command(flatten)]
    pub zones: ZoneArgs,
    /// Memory budget.
    #[command(flatten)]
    pub limits: LimitArgs,
    /// Write the path as FORMAT (repeatable; default `nav-path` and `csv`): `csv`
    /// (waypoints.csv), `json` (waypoints.json), `nav-path` (`nav_path.yaml`) or `geojson`
    /// (path.geojson).
    #[arg(long, value_name = "FORMAT", value_parser = parse_export)]
    pub export: Vec<ExportFormat>,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "ccpp-plan")]
    pub out: PathBuf,
}

/// `ccpp waypoints`.
#[derive(Args, Debug)]
// `--tool-radius` is refused here (the lanes follow `--width`), so the help does not list it.
#[command(allow_negative_numbers = true, mut_arg("tool_radius", |a| a.hide(true)))]
pub struct WaypointsArgs {
    /// The map.
    #[command(flatten)]
    pub map: MapArgs,
    /// The robot (its radius is the smallest clearance kept).
    #[command(flatten)]
    pub robot: RobotArgs,
    /// Robot length in metres (waypoint spacing along a lane; default: the robot's diameter).
    #[arg(long, value_parser = parse_number, value_name = "M")]
    pub length: Option<f64>,
    /// Robot width in metres (lane spacing; default: the robot's diameter).
    #[arg(long, value_parser = parse_number, value_name = "M")]
    pub width: Option<f64>,
    /// Area to cover `X0,Y0,X1,Y1`: the seed's lane rectangle for the robot's centre
    /// (default: the start's free component).
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = parse_quad, allow_hyphen_values = true)]
    pub area: Option<[f64; 4]>,
    /// Keep-out zone (repeatable): a Nav2 keepout mask, a polygon file or `X0,Y0,X1,Y1`; no
    /// waypoint or connection enters it.
    #[arg(long, value_name = "FILE|X0,Y0,X1,Y1", value_parser = parse_zone, allow_hyphen_values = true)]
    pub keepout: Vec<ZoneSpec>,
    /// Memory budget.
    #[command(flatten)]
    pub limits: LimitArgs,
    /// Output format.
    #[arg(long, value_name = "csv|json", default_value = "csv")]
    pub format: String,
    /// Write to this file instead of stdout; a name ending in `.csv` or `.json` must match
    /// `--format`. An existing file is replaced only when it reads as
    /// a waypoints file (a CSV whose first line is `x,y`, or the JSON this command writes);
    /// any other is refused.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
}

/// `ccpp replay`.
#[derive(Args, Debug)]
pub struct ReplayArgs {
    /// A run's output folder (with run.json, trace.jsonl, metrics.json).
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
}

/// `ccpp demo`.
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "ccpp-demo")]
    pub out: PathBuf,
    /// Planner to run (default: the flagship).
    #[arg(long, value_name = "NAME")]
    pub planner: Option<String>,
}

/// `ccpp bench`.
#[derive(Args, Debug)]
#[command(
    allow_negative_numbers = true,
    mut_arg("max_memory", |a| a.help("Refuse work whose estimated memory exceeds this many MB (2^20 bytes, as in every memory figure ccpp prints; default 4096): each run is checked, and the runs in progress and the summary pictures share the limit (a run starts when its estimate fits beside theirs)"))
)]
pub struct BenchArgs {
    /// Map files and/or folders (a folder contributes its `*.yaml` maps, or its images; a
    /// YAML naming no image, such as an options file, is left out with a note).
    #[arg(long, value_name = "DIR|FILES", num_args = 1.., required = true)]
    pub maps: Vec<PathBuf>,
    /// Planners, comma-separated (default: all).
    #[arg(long, value_name = "A,B,...", value_delimiter = ',')]
    pub planners: Vec<String>,
    /// Robot radius and tool radius (the start is each map's default start).
    #[command(flatten)]
    pub robot: BenchRobotArgs,
    /// Grow obstacles by this many metres before planning (the grown map is each run's world,
    /// its figures included: see `ccpp run --help`).
    #[arg(long, value_parser = parse_number, value_name = "M")]
    pub inflate: Option<f64>,
    /// Seed of random-bounce's turns (default 0).
    #[arg(long, value_parser = parse_whole::<u64>, value_name = "N")]
    pub seed: Option<u64>,
    /// Planner options.
    #[command(flatten)]
    pub options: OptionsArgs,
    /// Memory budget.
    #[command(flatten)]
    pub limits: LimitArgs,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "ccpp-bench")]
    pub out: PathBuf,
    /// Redo runs whose results already exist in the output folder.
    #[arg(long)]
    pub force: bool,
    /// Worker threads (default: all cores; at most one per run).
    #[arg(long, value_parser = parse_whole::<usize>, value_name = "N")]
    pub jobs: Option<usize>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// Robot options of `ccpp bench` (no start: each map uses its default start).
#[derive(Args, Debug, Clone)]
pub struct BenchRobotArgs {
    /// Robot (footprint) radius in metres.
    #[arg(long, value_parser = parse_number, value_name = "M", default_value_t = 0.15)]
    pub radius: f64,
    /// Cleaning tool radius in metres, at most the robot radius (default: the robot radius).
    #[arg(long, value_parser = parse_number, value_name = "M")]
    pub tool_radius: Option<f64>,
}

impl From<&BenchRobotArgs> for RobotArgs {
    fn from(b: &BenchRobotArgs) -> Self {
        Self {
            radius: Some(b.radius),
            tool_radius: b.tool_radius,
            start: None,
        }
    }
}

/// `ccpp planners`.
#[derive(Args, Debug)]
pub struct PlannersArgs {
    /// Print the default options of every planner (`--defaults` alone, or `all`) or of the
    /// planners named as a `--config` file: YAML, one section per planner, every field at its
    /// default
    #[arg(long, value_name = "A,B,...", num_args = 0..=1, value_delimiter = ',', require_equals = false, default_missing_value = "all")]
    pub defaults: Option<Vec<String>>,
}

/// `ccpp info`.
#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct InfoArgs {
    /// The map.
    #[command(flatten)]
    pub map: MapArgs,
    /// The robot.
    #[command(flatten)]
    pub robot: RobotArgs,
    /// Work area and keep-out zones (shown with their size and the accessible floor inside).
    #[command(flatten)]
    pub zones: ZoneArgs,
    /// Memory budget (a map image whose pixels alone would need more is refused from its
    /// header).
    #[command(flatten)]
    pub limits: LimitArgs,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

/// Parses a comma-separated list of finite numbers.
fn parse_finite_list(s: &str) -> Result<Vec<f64>, String> {
    s.split(',')
        .map(str::trim)
        .map(|p| match p.parse::<f64>() {
            // `-0` is 0: the sign of a zero reached run.json, the map digest and, as a start
            // heading, the trace (bsa-bfs recorded a turn of no angle first).
            Ok(x) if x.is_finite() => Ok(x + 0.0),
            Ok(_) => Err(format!("{p:?} is not a finite number")),
            Err(_) => Err(format!("{p:?} is not a number")),
        })
        .collect()
}

/// Parses a single-number flag, with whitespace around it taken as the list flags take it
/// (`--start " 1, 2"` ran while `--radius " 0.15"` was refused). A number out of its range
/// (infinite, negative, ...) is left to the scenario's checks, which name the setting.
fn parse_number(s: &str) -> Result<f64, String> {
    let t = s.trim();
    // `-0` is 0, as in `parse_finite_list`.
    t.parse::<f64>()
        .map(|x| x + 0.0)
        .map_err(|_| format!("{t:?} is not a number"))
}

/// Parses a whole-number flag (`--seed`, `--jobs`, `--max-memory`), whitespace around it
/// taken as [`parse_number`] takes it.
fn parse_whole<T: std::str::FromStr>(s: &str) -> Result<T, String>
where
    T::Err: std::fmt::Display,
{
    let t = s.trim();
    t.parse::<T>().map_err(|e| {
        // (`-5` "is not a whole number (invalid digit found in string)": docs review)
        let digits = |d: &str| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit());
        if digits(t.strip_prefix('+').unwrap_or(t)) {
            format!("{t:?} is too large ({e})")
        } else if t.strip_prefix('-').is_some_and(digits) {
            format!("{t:?} is negative: give a whole number")
        } else if t.parse::<f64>().is_ok_and(f64::is_finite) {
            format!("{t:?} is not a whole number: give one without a fraction or exponent")
        } else {
            format!("{t:?} is not a whole number ({e})")
        }
    })
}

/// Parses `A,B,C,D` into four finite numbers.
fn parse_quad(s: &str) -> Result<[f64; 4], String> {
    let v: [f64; 4] = parse_finite_list(s)?
        .try_into()
        .map_err(|_| format!("expected X0,Y0,X1,Y1, got {s:?}"))?;
    if v[2] <= v[0] || v[3] <= v[1] {
        return Err(format!("rectangle {s:?} must have X1 > X0 and Y1 > Y0"));
    }
    Ok(v)
}

/// Parses a zone ([`ZoneSpec`]'s `FromStr`: `X0,Y0,X1,Y1` is a rectangle, anything else a file
/// name); a rectangle's numbers are checked here already, so clap names the flag.
fn parse_zone(s: &str) -> Result<ZoneSpec, String> {
    match s.parse::<ZoneSpec>().map_err(|e| e.to_string())? {
        ZoneSpec::Rect(_) => parse_quad(s).map(ZoneSpec::Rect),
        other => Ok(other),
    }
}

/// Parses `--origin`'s `X,Y[,YAW]` (as [`parse_triple`], the message naming YAW).
fn parse_origin(s: &str) -> Result<[f64; 3], String> {
    parse_triple_named(s, "YAW")
}

/// Parses `A,B` or `A,B,C` into three numbers (C defaults to 0).
fn parse_triple(s: &str) -> Result<[f64; 3], String> {
    parse_triple_named(s, "THETA")
}

/// [`parse_triple`], the third number called `third` in the message (as the flag's help
/// calls it: `--origin 1,2,3,4` said "X,Y,THETA" of `X,Y[,YAW]`).
fn parse_triple_named(s: &str, third: &str) -> Result<[f64; 3], String> {
    let parts = parse_finite_list(s)?;
    if !(2..=3).contains(&parts.len()) {
        return Err(format!("expected X,Y or X,Y,{third}, got {s:?}"));
    }
    let mut v = [0.0; 3];
    v[..parts.len()].copy_from_slice(&parts);
    Ok(v)
}

/// Parses an export format name.
fn parse_export(s: &str) -> Result<ExportFormat, String> {
    s.parse::<ExportFormat>().map_err(|e| e.to_string())
}

/// Parses `on`/`off` (also `true`/`false`, `1`/`0`).
fn parse_on_off(s: &str) -> Result<bool, String> {
    match s.to_ascii_lowercase().as_str() {
        "on" | "true" | "1" | "yes" => Ok(true),
        "off" | "false" | "0" | "no" => Ok(false),
        _ => Err(format!(
            "expected on or off (or true/false, yes/no, 1/0), got {s:?}"
        )),
    }
}
