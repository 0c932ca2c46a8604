//! A complete, serializable description of one coverage run — map recipe, robot, start, planner
//! with its options, simulator settings, memory limit — with **one** validation and one way to
//! run it.
//!
//! The command line builds a [`Scenario`] from its flags and `--config` file and writes it as
//! `run.json`; reading `run.json` back and calling [`Scenario::run`] reproduces the run exactly
//! (same trace). Rust users build one with [`Scenario::builder`]; a scenario file (YAML or JSON)
//! is [`Scenario::from_file`].
//!
//! Validation happens in two stages, both in this module:
//! * [`Scenario::validate`]: every value on its own (robot, start, sensor range, execution,
//!   landmarks, map overrides, the planner's options through
//!   [`PlannerSettings::validate`](ccpp_core::planners::PlannerSettings::validate));
//! * [`Scenario::check_map`], once the map is loaded: the planner's checks against the frame
//!   (a tile larger than the map, a sensor that cannot see a neighbour tile, an area outside the
//!   map) and the **memory estimate** against [`Scenario::max_memory_mb`], before anything
//!   large is allocated.
//!
//! ```no_run
//! use ccpp_core::planners::PlannerKind;
//! use ccpp_io::scenario::Scenario;
//! let run = Scenario::builder("map.yaml", PlannerKind::BaStar)
//!     .radius(0.2)
//!     .build()?
//!     .run()?;
//! println!("{}", run.metrics.effective_coverage);
//! # Ok::<(), ccpp_io::scenario::ScenarioError>(())
//! ```

use std::path::{Path, PathBuf};

use ccpp_core::display::Compact;
use ccpp_core::exec::{Execution, PidOptions};
use ccpp_core::grid::{GridError, GridMap, MapFrame};
pub use ccpp_core::grid::{MAX_COORD_M, MAX_MAP_SIDE_M, MIN_RESOLUTION_M};
use ccpp_core::metrics::{self, Metrics};
use ccpp_core::planners::settings::{
    add_sim_pid_records, estimate_run, estimate_zones, fmt_m, validate_execution, ZoneLoad,
    PROCESS_BYTES,
};
use ccpp_core::planners::{OptionsError, PlannerConfig, PlannerKind, ResourceEstimate, Setup};
use ccpp_core::sim::{simulate_tapped, simulate_until, RunOutput, SimConfig};
use ccpp_core::trace::Chunk;
use ccpp_core::world::{Robot, World, WorldError};
use ccpp_core::Pose;
use fixedbitset::FixedBitSet;
use serde::{Deserialize, Serialize};
use std::sync::atomic::AtomicBool;

use crate::map::{load_map, LoadOptions, LoadedMap, MapError, Thresholds};
use crate::trace::{FileFormer, FormedFiles};
use crate::zones::{ZoneData, ZoneSpec};
use ccpp_core::zones::ZoneMasks;

/// Default memory limit of a run, MB: room for the shared maps and the benchmark maps
/// (`cluttered_2000` at r = 0.025 m, `office_4096` at r = 0.1 m) with a wide margin.
pub const DEFAULT_MAX_MEMORY_MB: u64 = 4096;

/// The largest memory limit a scenario takes, MB (2^40 MB, an exbibyte). Limits are compared in
/// bytes, and a larger one (up to `u64::MAX` MB) overflowed them: the byte count was capped at
/// 2^64 while messages named the limit given, so a map was refused as needing "1.1e15 MB, more
/// than the memory limit of 18446744073709551615 MB".
pub const MAX_MEMORY_LIMIT_MB: u64 = 1 << 40;

/// Largest need, MB, for which a memory refusal suggests raising `--max-memory` (a
/// petabyte): beyond it only a larger robot, tile, spacing or smaller budget helps.
const MAX_SENSIBLE_MB: f64 = 1e9;

fn default_max_memory_mb() -> u64 {
    DEFAULT_MAX_MEMORY_MB
}

/// Error of a scenario: invalid values, a map that cannot be loaded, a run that would be
/// degenerate or too big. Every message names the value or the file at fault.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The run was stopped by its caller ([`Scenario::run_on_until`]).
    #[error("the run was interrupted")]
    Interrupted,
    /// The map cannot be loaded.
    #[error(transparent)]
    Map(#[from] MapError),
    /// The map image is too large for the memory limit (told by its header, before decoding).
    #[error(
        "map image {} is {width} x {height} px: its pixels alone would need {needed} in a run ({per_pixel} bytes a pixel), more than the memory limit of {limit_mb} MB (raise it with --max-memory MB / max_memory_mb{})",
        path.display(),
        if *limit_mb as f64 * 1024.0 * 1024.0 <= PROCESS_BYTES {
            format!(": the process alone needs {}", about_mb(PROCESS_BYTES))
        } else {
            ", or use a smaller map: crop the image or downsample it".to_string()
        }
    )]
    MapTooLarge {
        /// The image file.
        path: PathBuf,
        /// Its width, px.
        width: u32,
        /// Its height, px.
        height: u32,
        /// Memory its pixels need in a run: `about 1234 MB` (rounded up) or `about 1.2e15 MB`.
        needed: String,
        /// Bytes a pixel every run holds.
        per_pixel: u64,
        /// The limit, MB.
        limit_mb: u64,
    },
    /// The georeference file cannot be used.
    #[error("georef {}: {message}", path.display())]
    Georef {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The map and robot do not make a world (start in a wall, robot too big...).
    #[error("map {}: {source}", path.display())]
    World {
        /// The map file.
        path: PathBuf,
        /// The cause.
        source: WorldError,
    },
    /// The map grid cannot be placed.
    #[error("map {}: {source}", path.display())]
    Grid {
        /// The map file.
        path: PathBuf,
        /// The cause.
        source: GridError,
    },
    /// A value is invalid on its own.
    #[error("{0}")]
    Invalid(String),
    /// A planner option is invalid.
    #[error("planner option {0}")]
    Options(OptionsError),
    /// The run would be degenerate on this map (it could not do anything useful).
    #[error("map {}: {planner}: {message}", path.display())]
    Degenerate {
        /// The map file.
        path: PathBuf,
        /// The planner.
        planner: &'static str,
        /// What is wrong.
        message: String,
    },
    /// The run would need more memory than allowed.
    #[error(
        "map {}: {planner} would need {needed} ({detail}), more than the memory limit of {limit_mb} MB ({advice})",
        path.display()
    )]
    Memory {
        /// The map file.
        path: PathBuf,
        /// The planner.
        planner: &'static str,
        /// Estimated need: `about 1234 MB` (rounded up), `about 1.0e297 MB`, or `unbounded
        /// memory` when the estimate overflowed.
        needed: String,
        /// The dominant quantity.
        detail: String,
        /// The limit, MB.
        limit_mb: u64,
        /// What to do: raise the limit (when a machine could have that much) and what would
        /// shrink the dominant quantity.
        advice: String,
    },
    /// A scenario file cannot be read or parsed.
    #[error("scenario {}: {message}", path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A zone (`--area`, `--keepout`) cannot be used.
    #[error("{kind} {label}: {message}")]
    Zone {
        /// `area` or `keepout`.
        kind: &'static str,
        /// The file (or `rectangle ...` / `inline polygons`).
        label: String,
        /// What is wrong.
        message: String,
    },
    /// The scenario names no map file (the map must be given by the caller).
    #[error("the scenario names no map file")]
    NoMapPath,
}

impl ScenarioError {
    /// This error with the landmarks file named when it is about a landmark (one the map never
    /// sees, a bad heading): the scenario holds its landmarks as read, so its own message
    /// names the landmark only, and the command line and Python name the file `file` they read
    /// them from (Python named none where the command line did).
    #[must_use]
    pub fn naming_landmarks(self, file: Option<&Path>) -> Self {
        match (self, file) {
            (Self::Invalid(m), Some(p)) if m.starts_with("landmark ") => {
                Self::Invalid(format!("landmarks {}: {m}", p.display()))
            }
            (e, _) => e,
        }
    }
}

impl From<OptionsError> for ScenarioError {
    fn from(e: OptionsError) -> Self {
        Self::Options(e)
    }
}

/// How to load and prepare the map: enough to rebuild it exactly.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MapRecipe {
    /// Map file (a ROS `map_server` YAML or a bare PGM/PNG); `None` when the caller supplies the
    /// map (the CLI's bundled demo map).
    pub path: Option<PathBuf>,
    /// Name used in reports; `None` = the file stem.
    pub name: Option<String>,
    /// Resolution override, m/px.
    pub resolution: Option<f64>,
    /// Origin override `[x, y, yaw]`.
    pub origin: Option<[f64; 3]>,
    /// `occupied_thresh` override.
    pub occupied_thresh: Option<f64>,
    /// `free_thresh` override.
    pub free_thresh: Option<f64>,
    /// Grow obstacles by this many metres (exact distance transform). 0 grows nothing and is
    /// written as no inflation (`null`), so a run's `run.json` says what was done (it said
    /// `0.0` beside the same work as a run without `--inflate`).
    #[serde(serialize_with = "inflate_as_done")]
    pub inflate: Option<f64>,
    /// Georeference point-pair file (`px,py,wx,wy` lines); overrides resolution and origin.
    pub georef: Option<PathBuf>,
}

/// A map ready for planning.
#[derive(Clone, Debug)]
pub struct PreparedMap {
    /// The (placed, inflated) grid.
    pub grid: GridMap,
    /// Short name for reports.
    pub name: String,
    /// The file it came from, for messages.
    pub source: PathBuf,
    /// How it was made.
    pub recipe: MapRecipe,
    /// How its pixels were classified (the YAML's or the overridden thresholds, negate and
    /// mode; the defaults for a grid made in memory).
    pub thresholds: Thresholds,
    /// Pixels ROS `map_server` would classify otherwise ([`LoadedMap::alpha_differs`]; 0
    /// for a grid made in memory).
    ///
    /// [`LoadedMap::alpha_differs`]: crate::map::LoadedMap::alpha_differs
    pub alpha_differs: usize,
}

/// Serializes [`MapRecipe::inflate`]: 0 (or -0) as `null`.
#[allow(clippy::ref_option)] // serde's `serialize_with` passes the field by reference
fn inflate_as_done<S: serde::Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
    match v {
        Some(m) if *m != 0.0 => s.serialize_some(m),
        _ => s.serialize_none(),
    }
}

impl MapRecipe {
    /// The inflation in metres when it grows the obstacles (`inflate` above 0), else `None`:
    /// every figure of a run, plan or `info` is then on the grown map, which their reports say.
    pub fn inflation(&self) -> Option<f64> {
        self.inflate.filter(|m| *m > 0.0)
    }

    /// A recipe for the map file `path`, no overrides.
    pub fn file(path: impl Into<PathBuf>) -> Self {
        Self {
            path: Some(path.into()),
            ..Self::default()
        }
    }

    /// Checks the overrides on their own (the loader checks them again with the file's values).
    ///
    /// # Errors
    /// A non-finite or non-positive value.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        let map = self
            .path
            .as_ref()
            .map_or_else(String::new, |p| format!("map {}: ", p.display()));
        if let Some(r) = self.resolution {
            if !(r.is_finite() && r > 0.0) {
                return Err(ScenarioError::Invalid(format!(
                    "{map}--resolution / map.resolution must be a finite number > 0, got {}",
                    Compact(r)
                )));
            }
        }
        if let Some(why) = self.origin.and_then(|o| crate::map::heading_problem(o[2])) {
            return Err(ScenarioError::Invalid(format!(
                "{map}--origin / map.origin yaw {why}"
            )));
        }
        // The name goes into folder names, pictures, pages, SVG plots and messages, as a file
        // stem would (whose control characters are refused with the path): Python's
        // `name=` took an escape sequence and a line break into every file and the terminal.
        // An empty (or blank) name left the map nameless in metrics, titles and results
        // (Python's `name=""`: kwargs pass).
        if self.name.as_deref().is_some_and(|n| n.trim().is_empty()) {
            return Err(ScenarioError::Invalid(format!(
                "{map}map.name is empty; give a name, or leave it out for the file's stem"
            )));
        }
        if let Some(c) = self
            .name
            .as_deref()
            .and_then(|n| n.chars().find(|&c| crate::message::hidden(c)))
        {
            // (the name is the file's stem unless given: a user who gave none is told to
            // rename the file, the only way the command line has to change it)
            return Err(ScenarioError::Invalid(format!(
                "{map}map.name holds a control or invisible character (U+{:04X}); give a plain name (it is the map file's name without its extension unless map.name / Python's name= gives one: rename the file)",
                u32::from(c)
            )));
        }
        if let Some(g) = &self.georef {
            // The fit places the image: a resolution or origin given beside it would be
            // validated and then replaced.
            let given: Vec<&str> = [
                self.resolution.map(|_| "--resolution / map.resolution"),
                self.origin.map(|_| "--origin / map.origin"),
            ]
            .into_iter()
            .flatten()
            .collect();
            if !given.is_empty() {
                return Err(ScenarioError::Invalid(format!(
                    "{} cannot be used with --georef {}, whose fit sets the resolution and origin; remove one of them",
                    given.join(" and "),
                    g.display()
                )));
            }
        }
        if let Some(m) = self.inflate {
            if !(m.is_finite() && m >= 0.0) {
                return Err(ScenarioError::Invalid(format!(
                    "--inflate / map.inflate must be a finite number >= 0 m, got {}",
                    Compact(m)
                )));
            }
        }
        Ok(())
    }

    /// Loads the map file and prepares it (georef, inflation), within the default memory limit
    /// ([`DEFAULT_MAX_MEMORY_MB`]; see [`Self::load_within`]).
    ///
    /// # Errors
    /// As [`Self::load_within`].
    pub fn load(&self) -> Result<PreparedMap, ScenarioError> {
        self.load_within(DEFAULT_MAX_MEMORY_MB)
    }

    /// Loads the map file and prepares it (georef, inflation). An image whose pixels alone
    /// would need more than `max_memory_mb` in a run (every run holds
    /// [`PIXEL_BYTES`](ccpp_core::planners::settings::PIXEL_BYTES) bytes a pixel: grid,
    /// distance transform, bitsets, known map, picture) is refused from its header, before it
    /// is decoded; [`Scenario::check_map`] later checks the whole run's estimate.
    ///
    /// # Errors
    /// [`ScenarioError::NoMapPath`] without a path, [`ScenarioError::MapTooLarge`], else
    /// loading errors.
    pub fn load_within(&self, max_memory_mb: u64) -> Result<PreparedMap, ScenarioError> {
        self.validate()?;
        check_memory_limit(max_memory_mb)?;
        let path = self.path.as_ref().ok_or(ScenarioError::NoMapPath)?;
        let per_pixel = ccpp_core::planners::settings::PIXEL_BYTES as u64;
        // With a georef file the fit places the map: the YAML's resolution and origin, which
        // it replaces, may be left out (they were required, though any value was taken).
        let placed = self.georef.is_some();
        let opts = LoadOptions {
            resolution: self.resolution.or(placed.then_some(1.0)),
            origin: self.origin.or(placed.then_some([0.0; 3])),
            occupied_thresh: self.occupied_thresh,
            free_thresh: self.free_thresh,
            negate: None,
            max_pixels: Some(max_memory_mb.saturating_mul(1024 * 1024) / per_pixel),
        };
        let loaded =
            crate::phase::time("load map", || load_map(path, &opts)).map_err(|e| match e {
                MapError::TooLarge {
                    path,
                    width,
                    height,
                    ..
                } => ScenarioError::MapTooLarge {
                    path,
                    width,
                    height,
                    // In floating point: 4e9 x 4e9 px (a PGM header may say so) times 64 bytes
                    // is beyond u64.
                    needed: about_mb(f64::from(width) * f64::from(height) * per_pixel as f64),
                    per_pixel,
                    limit_mb: max_memory_mb,
                },
                e => ScenarioError::Map(e),
            })?;
        crate::phase::time("prepare map", || self.prepare(loaded))
    }

    /// Prepares a map the caller loaded (e.g. from bytes): georef, inflation, name.
    ///
    /// # Errors
    /// A georef file that cannot be used, an invalid inflation.
    pub fn prepare(&self, loaded: LoadedMap) -> Result<PreparedMap, ScenarioError> {
        self.validate()?;
        let mut grid = loaded.grid;
        match &self.georef {
            // (its placement checked there, against the georef file)
            Some(g) => grid = apply_georef(grid, g)?,
            None => check_extent(&grid, &loaded.source)?,
        }
        if let Some(m) = self.inflate {
            if m > 0.0 {
                // Inflation turns pixels whose centre is within `m` of an obstacle's centre:
                // below one pixel it would be validated and then grow nothing.
                let res = grid.frame().resolution;
                if (m / res).powi(2) + 1e-9 < 1.0 {
                    return Err(ScenarioError::Invalid(format!(
                        "--inflate / map.inflate {} m grows nothing on the map {}: it is less than one pixel ({} m)",
                        Compact(m),
                        loaded.source.display(),
                        Compact(res)
                    )));
                }
                grid = ccpp_core::inflate::inflate(&grid, m);
            }
        }
        let name = self.name.clone().unwrap_or_else(|| {
            loaded
                .source
                .file_stem()
                .map_or_else(|| "map".to_string(), |s| s.to_string_lossy().into_owned())
        });
        Ok(PreparedMap {
            grid,
            name,
            source: loaded.source,
            recipe: self.clone(),
            thresholds: loaded.thresholds,
            alpha_differs: loaded.alpha_differs,
        })
    }
}

/// The width `2 r` of a robot of radius `r`, as [`Compact`] shows it, also where `2 r` is
/// beyond `f64` (`--radius 1e308` printed `inf m across`): then the mantissa of `r` doubled
/// (`2e308`).
fn across(r: f64) -> String {
    let d = 2.0 * r;
    if d.is_finite() || !r.is_finite() {
        return Compact(d).to_string();
    }
    let text = format!("{r:e}");
    let parts = text
        .split_once('e')
        .and_then(|(m, e)| Some((m.parse::<f64>().ok()?, e.parse::<i32>().ok()?)));
    match parts {
        Some((m, e)) if (2.0 * m).abs() >= 10.0 => format!("{}e{}", 2.0 * m / 10.0, e + 1),
        Some((m, e)) => format!("{}e{e}", 2.0 * m),
        None => Compact(d).to_string(),
    }
}

/// A memory need of `bytes` as the refusals print it: `about 1234 MB` (rounded up), `about
/// 1.0e297 MB` from 1e9 MB up, or `unbounded memory` when the estimate overflowed.
fn about_mb(bytes: f64) -> String {
    let mb = bytes / (1024.0 * 1024.0);
    if !mb.is_finite() {
        "unbounded memory".to_string()
    } else if mb < 1e9 {
        format!("about {:.0} MB", mb.ceil())
    } else {
        format!("about {mb:.1e} MB")
    }
}

/// What a world error on a map whose obstacles `--inflate` grew by `inflation` m says, naming
/// the inflation (the likely cause), or `None` for an error the inflation has no part in (or
/// no inflation). `inflation` is [`MapRecipe::inflation`]: `Some` only for an inflation that
/// grew the obstacles (a `Some(0.0)` would be named as one). A robot that fits nowhere: the widest
/// free spot left; a start in an obstacle: the start may be free on the map as drawn. `run`'s
/// refusal and `info`'s report both say it this way.
pub fn inflated_world_error(e: &WorldError, inflation: Option<f64>) -> Option<String> {
    let m = inflation?;
    match e {
        WorldError::RobotTooBig {
            radius,
            max_clearance,
        } => Some(format!(
            "robot of radius {} m does not fit anywhere once --inflate / map.inflate {} m has \
             grown the obstacles (the widest free spot then has clearance {} m); \
             lower the inflation",
            Compact(*radius),
            Compact(m),
            ccpp_core::display::fixed(*max_clearance, 3),
        )),
        WorldError::StartInObstacle { .. } => Some(format!(
            "{e} once --inflate / map.inflate {} m has grown the obstacles",
            Compact(m)
        )),
        _ => None,
    }
}

/// Refuses a map frame finer than [`MIN_RESOLUTION_M`], wider or taller than
/// [`MAX_MAP_SIDE_M`], or placed with a corner farther
/// than [`MAX_COORD_M`] from the world's origin along either axis (every subcommand prepares its
/// map through [`MapRecipe::prepare`], so `info`, `waypoints` and `plan` refuse what `run`
/// refuses).
///
/// # Errors
/// [`ScenarioError::Invalid`] naming the file.
pub fn check_extent(grid: &GridMap, source: &Path) -> Result<(), ScenarioError> {
    match extent_problem(grid) {
        None => Ok(()),
        Some((problem, what)) => Err(ScenarioError::Invalid(format!(
            "map {}: {problem}; check the {what}",
            source.display()
        ))),
    }
}

/// What [`check_extent`] refuses in `grid`'s frame ([`MapFrame::precision_problem`]), and
/// which of the map's settings to check (`resolution` or `origin`); `None` when the frame is
/// within bounds.
fn extent_problem(grid: &GridMap) -> Option<(String, &'static str)> {
    let p = grid.frame().precision_problem()?;
    Some((p.to_string(), p.setting()))
}

/// Places `grid` by the point pairs in `path` (pixel coordinates from the image's top-left
/// corner, y down). ccpp frames are similarities (rotation + uniform scale):
/// the map is placed by the similarity that fits the pairs best, and a pair it misses by more
/// than [`GEOREF_MISS_PX`] pixels or [`GEOREF_MISS_M`] metres, whichever is more, is refused
/// (a typo in one pair is named from the affine fit first; axes scaled apart or sheared are
/// said as such).
///
/// # Errors
/// An unreadable or degenerate georef file, a fit that is not a similarity, or a placement
/// out of the bounds of [`check_extent`].
pub fn apply_georef(grid: GridMap, path: &Path) -> Result<GridMap, ScenarioError> {
    let err = |message: String| ScenarioError::Georef {
        path: path.to_path_buf(),
        message,
    };
    // The problem alone: the message names the file once (`georef FILE: ...`).
    let fit = crate::georef::load_georef(path).map_err(|e| err(e.problem.to_string()))?;
    let [a, b, c, d] = fit.affine.m;
    let res = (a * d - b * c).abs().sqrt();
    if !(res.is_finite() && res > 0.0) {
        return Err(err(format!(
            "degenerate transform (its scale is {} m/px); check the world coordinates",
            Compact(res)
        )));
    }
    // Pixel rows grow downwards and world y upwards: a map's transform flips orientation.
    // One that does not mirrors the image, as pixel coordinates given y up do (it read as
    // "200 % shear or anisotropy").
    if a * d - b * c > 0.0 {
        return Err(err(
            "the fit mirrors the image: pixel coordinates are counted from the top-left corner with py growing downwards, and these look counted y up (use py = image height - py)"
                .to_string(),
        ));
    }
    // A pair far off the fit of all (a typo in a coordinate): the placement it pulls off is
    // used silently otherwise (one wrong digit of seven pairs moved the map 1.43 m).
    let limit = (GEOREF_MISS_PX * res).max(GEOREF_MISS_M);
    if fit.max_residual > limit {
        let worst = (0..fit.residuals.len())
            .max_by(|&i, &j| fit.residuals[i].total_cmp(&fit.residuals[j]))
            .unwrap_or(0);
        let (p, w) = fit.pairs[worst];
        let others = (0..fit.residuals.len())
            .filter(|&i| i != worst)
            .map(|i| fit.residuals[i])
            .fold(0.0, f64::max);
        return Err(err(format!(
            "the pair {},{} -> {},{} (pair {} of {}) is {} m ({:.1} px) off the transform fitted to all the pairs, the others at most {} m: a typo in it, or in another pair? (a pair may miss the fit by at most {GEOREF_MISS_PX} px or {GEOREF_MISS_M} m, whichever is more)",
            Compact(p.x),
            Compact(p.y),
            Compact(w.x),
            Compact(w.y),
            worst + 1,
            fit.residuals.len(),
            Compact(round_sig(fit.residuals[worst])),
            fit.residuals[worst] / res,
            Compact(round_sig(others)),
        )));
    }
    // The map is placed by the rotation + uniform scale that fits the pairs best (every map
    // frame is one), and each pair is held to that placement: placed by parts of the affine
    // fit (its scale, its first column's angle, its corner), a survey with axes 1.4 % apart
    // put a 2000 px map's pairs 14-20 px off, with nothing said (hostile pass).
    let sim = fit.image_similarity().map_err(|e| err(e.to_string()))?;
    let res = sim.res;
    if let Some(worst) = (0..sim.residuals.len())
        .filter(|&i| sim.residuals[i] > limit)
        .max_by(|&i, &j| sim.residuals[i].total_cmp(&sim.residuals[j]))
    {
        let (p, w) = fit.pairs[worst];
        return Err(err(format!(
            "placed by rotation and uniform scale (as every map is), the pair {},{} -> {},{} (pair {} of {}) is {} m ({:.1} px) off: the pairs need {:.1} % more scale along one axis than across it (anisotropy or shear), which a map frame cannot hold; check the survey (a pair may miss the placement by at most {GEOREF_MISS_PX} px or {GEOREF_MISS_M} m, whichever is more)",
            Compact(p.x),
            Compact(p.y),
            Compact(w.x),
            Compact(w.y),
            worst + 1,
            sim.residuals.len(),
            Compact(round_sig(sim.residuals[worst])),
            sim.residuals[worst] / res,
            100.0 * ccpp_core::georef::anisotropy(fit.affine.m),
        )));
    }
    let h = grid.frame().height as f64;
    let o = sim.apply(ccpp_core::Point::new(0.0, h));
    let yaw = sim.yaw;
    // A placement the grid refuses, or one out of the bounds every map is held to
    // ([`check_extent`]), is the georef file's fault: named as such (not `map FILE`, whose
    // origin and resolution the fit replaced).
    let placed = grid
        .with_placement(res, Pose::new(o.x, o.y, yaw))
        .map_err(|e| err(e.to_string()))?;
    if let Some((problem, _)) = extent_problem(&placed) {
        return Err(err(format!(
            "the fitted placement: {problem}; check the world coordinates"
        )));
    }
    Ok(placed)
}

/// Most pixels a georef pair may miss the fitted transform by (or [`GEOREF_MISS_M`], whichever
/// is more): a picked pixel is a pixel or two off, a surveyed point a few centimetres, while a
/// typo in a coordinate misses by metres.
pub const GEOREF_MISS_PX: f64 = 5.0;

/// Most metres a georef pair may miss the fitted transform by, on maps whose pixels are small
/// ([`GEOREF_MISS_PX`]): room for a GPS-surveyed point on a 1 cm map.
pub const GEOREF_MISS_M: f64 = 0.5;

/// `v` to three significant digits (for messages).
fn round_sig(v: f64) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let k = 10f64.powi(2 - v.abs().log10().floor() as i32);
    (v * k).round() / k
}

/// One coverage run, fully described. `run.json` is this, serialized.
///
/// The planner and its options are flattened: `"planner": "ba-star", "options": {...}` (only
/// that planner's options, see [`PlannerConfig`]).
///
/// Other crates assemble one with [`Scenario::builder`] or [`Scenario::configure`] (whose
/// [`build`](ScenarioBuilder::build) validates it) or read one with serde; a struct literal is
/// not possible outside this crate (`non_exhaustive`), so no caller skips the validation:
///
/// ```compile_fail
/// # use ccpp_core::planners::{PlannerConfig, PlannerKind};
/// # use ccpp_io::scenario::{MapRecipe, Scenario};
/// let s = Scenario {
///     map: MapRecipe::file("m.yaml"),
///     robot: ccpp_core::world::Robot::new(-1.0),
///     start: None,
///     planner: PlannerConfig::new(PlannerKind::BaStar),
///     sim: ccpp_core::sim::SimConfig::default(),
///     max_memory_mb: 1,
///     area: None,
///     keepout: Vec::new(),
/// };
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Scenario {
    /// The map.
    pub map: MapRecipe,
    /// The robot (radius and tool radius, metres).
    pub robot: Robot,
    /// Start pose `[x, y, theta]`; `None` = the widest free spot of the largest free area,
    /// heading east.
    #[serde(default)]
    pub start: Option<[f64; 3]>,
    /// The planner and its options (seeds included: `random_bounce.seed`, and the odometry
    /// noise seed in [`SimConfig::exec`]).
    #[serde(flatten)]
    pub planner: PlannerConfig,
    /// Simulator settings: sensor range, execution (ideal or PID with its options and odometry
    /// noise), landmarks.
    #[serde(default)]
    pub sim: SimConfig,
    /// Refuse runs whose estimated memory exceeds this many MB (2^20 bytes).
    #[serde(default = "default_max_memory_mb")]
    pub max_memory_mb: u64,
    /// Work area: the robot stays inside it (virtual walls for every planner) and metrics
    /// measure coverage of the floor inside it; `None` = the whole map.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub area: Option<ZoneSpec>,
    /// Keep-out zones: never entered (virtual walls; entries are counted as
    /// `keepout_violations`), not counted as floor to cover.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub keepout: Vec<ZoneSpec>,
    /// The digest ([`World::digest`], 16 hex digits) the world built from the map and zones
    /// must have; `None` = any. A run writes its world's digest into `run.json`, so a replay
    /// (or a rerun of that file) refuses a map or zone file edited since the run instead of
    /// drawing the run's path over other walls. Remove it to run the scenario on the new map.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub map_digest: Option<String>,
}

/// [`Scenario`] as read: its fields, and any other key of the file, which is refused
/// ([`Scenario`]'s `Deserialize`). `#[serde(deny_unknown_fields)]` does not work beside the
/// flattened planner, and without it a misspelt `keepouts:` ran with no keep-out at all.
#[derive(Deserialize)]
struct ScenarioIn {
    map: MapRecipe,
    robot: Robot,
    #[serde(default)]
    start: Option<[f64; 3]>,
    #[serde(flatten)]
    planner: PlannerConfig,
    #[serde(default)]
    sim: SimConfig,
    #[serde(default = "default_max_memory_mb")]
    max_memory_mb: u64,
    #[serde(default)]
    area: Option<ZoneSpec>,
    #[serde(default)]
    keepout: Vec<ZoneSpec>,
    #[serde(default)]
    map_digest: Option<String>,
    /// Every key not taken above (the planner takes `planner` and `options`); the values are
    /// skipped, only the first key is named.
    #[serde(flatten)]
    #[allow(clippy::zero_sized_map_values)] // (a set cannot take a map's entries)
    other: std::collections::BTreeMap<String, serde::de::IgnoredAny>,
}

/// The keys of a scenario file, as an unknown key's error lists them.
const SCENARIO_KEYS: &[&str] = &[
    "map",
    "robot",
    "start",
    "planner",
    "options",
    "sim",
    "max_memory_mb",
    "area",
    "keepout",
    "map_digest",
];

impl<'de> Deserialize<'de> for Scenario {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = ScenarioIn::deserialize(d)?;
        if let Some(key) = s.other.keys().next() {
            return Err(serde::de::Error::unknown_field(key, SCENARIO_KEYS));
        }
        Ok(Self {
            map: s.map,
            robot: s.robot,
            start: s.start,
            planner: s.planner,
            sim: s.sim,
            max_memory_mb: s.max_memory_mb,
            area: s.area,
            keepout: s.keepout,
            map_digest: s.map_digest,
        })
    }
}

/// A finished run.
pub struct Run {
    /// The truth it ran on.
    pub world: World,
    /// Trace, stop reason and timing.
    pub output: RunOutput,
    /// The metrics.
    pub metrics: Metrics,
    /// The pixels the tool swept ([`metrics::swept_pixels`], computed with the metrics; the
    /// coverage picture reuses them).
    pub swept: FixedBitSet,
}

/// Sealed trace pieces copied out at a time while a run forms its files
/// ([`Scenario::run_owned_with`]).
const FORM_CHUNK: usize = 512;

/// The result of a scoped thread (its panic passed on).
fn join_scoped<T>(h: std::thread::ScopedJoinHandle<'_, T>) -> T {
    match h.join() {
        Ok(v) => v,
        Err(panic) => std::panic::resume_unwind(panic),
    }
}

/// Checks a memory limit, MB (a scenario's, or the one a map is loaded within): from 1 to
/// [`MAX_MEMORY_LIMIT_MB`].
///
/// # Errors
/// [`ScenarioError::Invalid`] naming the option and the range.
pub fn check_memory_limit(mb: u64) -> Result<(), ScenarioError> {
    if !(1..=MAX_MEMORY_LIMIT_MB).contains(&mb) {
        return Err(invalid(format!(
            "--max-memory / max_memory_mb must be from 1 to {MAX_MEMORY_LIMIT_MB} MB (1 EiB), got {mb}"
        )));
    }
    Ok(())
}

fn invalid(msg: String) -> ScenarioError {
    ScenarioError::Invalid(msg)
}

impl Scenario {
    /// A scenario with default robot (r = 0.15 m), options and settings.
    pub fn new(map: MapRecipe, planner: PlannerKind) -> Self {
        Self {
            map,
            robot: Robot::new(0.15),
            start: None,
            planner: PlannerConfig::new(planner),
            sim: SimConfig::default(),
            max_memory_mb: DEFAULT_MAX_MEMORY_MB,
            area: None,
            keepout: Vec::new(),
            map_digest: None,
        }
    }

    /// The files the scenario reads: the map (and the image its YAML names), the georeference
    /// file and the zone files (a Nav2 mask's image too). For
    /// [`crate::write::check_inputs_outside`]: an output folder must not hold them.
    pub fn input_files(&self) -> Vec<PathBuf> {
        let mut out = Vec::new();
        let mut add = |p: &Path| {
            out.push(p.to_path_buf());
            if let Some(image) = crate::map::yaml_image_path(p) {
                out.push(image);
            }
        };
        if let Some(p) = &self.map.path {
            add(p);
        }
        if let Some(p) = &self.map.georef {
            add(p);
        }
        for z in self.area.iter().chain(&self.keepout) {
            if let ZoneSpec::File(p) = z {
                add(p);
            }
        }
        out
    }

    /// A builder for the map file `map` and `planner`.
    pub fn builder(map: impl Into<PathBuf>, planner: PlannerKind) -> ScenarioBuilder {
        ScenarioBuilder(Self::new(MapRecipe::file(map), planner))
    }

    /// A builder for a map recipe and a planner with its options (the command line's `run`,
    /// `plan`, `waypoints` and `bench`, and Python's runs go through here).
    pub fn configure(map: MapRecipe, planner: PlannerConfig) -> ScenarioBuilder {
        let mut s = Self::new(map, planner.kind());
        s.planner = planner;
        ScenarioBuilder(s)
    }

    /// Reads a scenario file: JSON (`.json`, such as a run's `run.json`) or YAML.
    ///
    /// # Errors
    /// An unreadable or malformed file.
    pub fn from_file(path: &Path) -> Result<Self, ScenarioError> {
        let err = |message: String| ScenarioError::File {
            path: path.to_path_buf(),
            message,
        };
        let text = crate::file::read_text(path).map_err(|e| err(e.to_string()))?;
        let is_json = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"));
        crate::file::parse_yaml_or_json(&text, is_json).map_err(err)
    }

    /// The scenario as pretty JSON (the `run.json` format).
    ///
    /// # Errors
    /// Serialization failure (does not happen for valid scenarios).
    pub fn to_json(&self) -> Result<String, serde_json::Error> {
        let mut s = serde_json::to_string_pretty(self)?;
        s.push('\n');
        Ok(s)
    }

    /// The execution in force: the simulator's, else the planner's preferred one, else ideal.
    pub fn execution(&self) -> Execution {
        self.sim
            .exec
            .or_else(|| self.planner.settings().preferred_execution())
            .unwrap_or_default()
    }

    /// The planner's tile side for this robot, if tile-based.
    pub fn tile_side(&self) -> Option<f64> {
        self.planner.settings().tile_side(&self.robot)
    }

    /// Validates every value on its own: the one place for it (the CLI and option files go
    /// through here).
    ///
    /// # Errors
    /// The first invalid value, named.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        threads_env_problem(std::env::var("RAYON_NUM_THREADS").ok().as_deref())
            .map_or(Ok(()), |why| Err(invalid(why)))?;
        self.map.validate()?;
        self.robot
            .validate()
            .map_err(|e| invalid(format!("robot: {e}")))?;
        if let Some(s) = self.start {
            if s.iter().any(|v| !v.is_finite()) {
                return Err(invalid(format!("start must be finite, got {s:?}")));
            }
            if let Some(why) = crate::map::heading_problem(s[2]) {
                return Err(invalid(format!("--start / start THETA {why}")));
            }
        }
        if let Some(r) = self.sim.sensor_range {
            if !(r.is_finite() && r > 0.0) {
                return Err(invalid(format!(
                    "--sensor-range / sim.sensor_range must be a finite number > 0 m, got {}",
                    Compact(r)
                )));
            }
        }
        if self.sim.max_steps == 0 {
            // Python's `max_steps=` names it so; a scenario file's field is `sim.max_steps`.
            return Err(invalid(
                "max_steps / sim.max_steps must be >= 1, got 0".into(),
            ));
        }
        if let Some(e) = &self.sim.exec {
            validate_execution("sim.exec", e).map_err(|e| {
                // The CLI's --odometry-noise lands in sim.exec's noise: name the flag too.
                if e.field.contains(".noise.") {
                    invalid(format!("--odometry-noise / {e}"))
                } else {
                    invalid(e.to_string())
                }
            })?;
        }
        self.check_exec_override()?;
        // A goal counted reached from a robot radius away or more skips the moves between:
        // bsa-bfs with `tolerance_m: 0.3` (r = 0.15) drove 2.8 m of a room and swept 2 %,
        // ending "done" in silence.
        if let Execution::Pid(p) = self.execution() {
            // The default (1 micrometre) is no choice of the user's, whatever the robot.
            if p.tolerance_m > PidOptions::default().tolerance_m
                && p.tolerance_m >= self.robot.radius
            {
                return Err(invalid(format!(
                    "exec.pid.tolerance_m {} m is not below the robot radius {} m: a goal counted reached from that far skips the moves between (give a tolerance of a few millimetres)",
                    Compact(p.tolerance_m),
                    Compact(self.robot.radius)
                )));
            }
        }
        let lm = &self.sim.landmarks;
        for (f, v) in [("range_m", lm.range_m), ("period_s", lm.period_s)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(format!(
                    "sim.landmarks.{f} must be a finite number > 0, got {}",
                    Compact(v)
                )));
            }
        }
        if let Some(i) = lm
            .landmarks
            .iter()
            .position(|l| !(l.x.is_finite() && l.y.is_finite() && l.theta.is_finite()))
        {
            return Err(invalid(format!("landmark {i} has a non-finite pose")));
        }
        if lm.landmarks.len() > crate::landmarks::MAX_LANDMARKS {
            return Err(invalid(
                crate::landmarks::LandmarkFileError::TooMany.to_string(),
            ));
        }
        // A heading of 100 "rad" is a typo or degrees, as for a start pose or a map's yaw.
        for (i, l) in lm.landmarks.iter().enumerate() {
            if let Some(p) = crate::map::heading_problem(l.theta) {
                return Err(invalid(format!("landmark {i} (id {}) heading: {p}", l.id)));
            }
        }
        if !lm.landmarks.is_empty() && !matches!(self.execution(), Execution::Pid(_)) {
            return Err(invalid(format!(
                "landmarks correct the pose estimate of PID execution only, and {} runs with ideal execution, where the estimate is the true pose (add --odometry-noise / odometry_noise=, which runs PID; PID alone has no drift to correct either)",
                self.planner.name()
            )));
        }
        if let Execution::Pid(p) = self.execution() {
            // Without odometry noise the estimate is the true pose: a fix corrects nothing
            // (the run differed from one without landmarks in the 12th digit only).
            if !lm.landmarks.is_empty() && p.noise.is_none() {
                return Err(invalid(
                    "landmarks correct odometry drift, and this run has none: without odometry noise the pose estimate is the true pose (add --odometry-noise / odometry_noise=, or leave the landmarks out)".to_string(),
                ));
            }
        }
        check_memory_limit(self.max_memory_mb)?;
        self.planner.validate()?;
        self.validate_zones()?;
        Ok(())
    }

    /// Whether the planner's options set an execution of their own (`bsa_bfs.exec`,
    /// `rect_boustrophedon.exec`) other than the planner's default one.
    pub(crate) fn planner_sets_execution(&self) -> bool {
        let default = PlannerConfig::new(self.planner.kind());
        self.planner.settings().preferred_execution() != default.settings().preferred_execution()
    }

    /// `sim.exec` replaces the planner's own execution (`bsa_bfs.exec`,
    /// `rect_boustrophedon.exec`): when the planner's was set to something other than its
    /// default, a different `sim.exec` would read, validate and then drop it, so the pair is
    /// refused. A PID execution that only adds odometry noise to the planner's PID settings
    /// (`--odometry-noise`) keeps them and is accepted.
    fn check_exec_override(&self) -> Result<(), ScenarioError> {
        let settings = self.planner.settings();
        let (Some(sim), Some(own)) = (self.sim.exec, settings.preferred_execution()) else {
            return Ok(());
        };
        let kind = self.planner.kind();
        let keeps = match (sim, own) {
            _ if !self.planner_sets_execution() || sim == own => true,
            (Execution::Pid(s), Execution::Pid(o)) => {
                o.noise.is_none() && PidOptions { noise: None, ..s } == o
            }
            _ => false,
        };
        if keeps {
            return Ok(());
        }
        let what = match (sim, own) {
            (Execution::Ideal, _) => "ideal",
            (Execution::Pid(_), Execution::Ideal) => "pid",
            (Execution::Pid(_), Execution::Pid(_)) => "pid with other PID settings",
        };
        // Odometry noise is what made the run's execution PID when it carries noise: the user
        // gave `--odometry-noise`, not `--exec` (the message named a flag they never typed).
        let by = match sim {
            Execution::Pid(s) if s.noise.is_some() => "PID execution (--exec pid / exec=, or odometry noise: --odometry-noise / odometry_noise=, which runs PID)".to_string(),
            _ => format!("sim.exec {what} (--exec / exec=)"),
        };
        Err(invalid(format!(
            "{by} would drop the execution given for {kind} in {}.exec; remove one of them",
            kind.info().section
        )))
    }

    /// The zone values that can be checked without the map (rectangles, inline polygons).
    fn validate_zones(&self) -> Result<(), ScenarioError> {
        let specs = self
            .area
            .iter()
            .map(|a| ("area", a))
            .chain(self.keepout.iter().map(|k| ("keepout", k)));
        for (kind, spec) in specs {
            let res = match spec {
                ZoneSpec::Rect(r) => crate::zones::check_rect(*r).map_err(|e| e.to_string()),
                ZoneSpec::Polygons(p) => {
                    ccpp_core::zones::validate_polygons(p).map_err(|e| e.to_string())
                }
                ZoneSpec::File(_) => Ok(()),
            };
            res.map_err(|message| ScenarioError::Zone {
                kind,
                label: spec.label(),
                message,
            })?;
        }
        Ok(())
    }

    /// Loads and rasterises the zones onto `map`'s grid (`None` without zones).
    ///
    /// # Errors
    /// [`ScenarioError::Zone`] naming the file: unreadable or malformed, an invalid polygon, a
    /// keepout mask in another frame.
    pub fn zone_masks(&self, map: &PreparedMap) -> Result<Option<ZoneMasks>, ScenarioError> {
        if self.area.is_none() && self.keepout.is_empty() {
            return Ok(None);
        }
        let frame = *map.grid.frame();
        let load = |kind: &'static str, spec: &ZoneSpec, mask_ok: bool| {
            spec.load(&frame, mask_ok).map_err(|e| ScenarioError::Zone {
                kind,
                label: spec.label(),
                message: e.to_string(),
            })
        };
        let area = match &self.area {
            Some(spec) => match load("area", spec, false)? {
                ZoneData::Polygons(p) => Some(p),
                ZoneData::Mask(_) => None,
            },
            None => None,
        };
        let mut polys = Vec::new();
        // The keep-out pixels, each file's rasterised once: checked on its own, then united
        // (a pixel is kept out when any polygon or mask holds it, so the union of the files'
        // rasters is the raster of all their polygons).
        let mut keepout = FixedBitSet::with_capacity(frame.len());
        for spec in &self.keepout {
            let bits = match load("keepout", spec, true)? {
                ZoneData::Polygons(p) => {
                    let bits = ccpp_core::zones::rasterize_keepout(&frame, &p);
                    polys.extend(p);
                    bits
                }
                ZoneData::Mask(m) => m,
            };
            // A keep-out that marks no pixel would be read, validated and then keep nothing
            // out: refused, as an area holding no pixel is.
            if bits.is_clear() {
                return Err(ScenarioError::Zone {
                    kind: "keepout",
                    label: spec.label(),
                    message: format!(
                        "keeps out no pixel of the map {} (it lies outside the map or, for a mask, has no occupied pixel)",
                        map.source.display()
                    ),
                });
            }
            keepout.union_with(&bits);
        }
        let z = ZoneMasks::with_keepout_pixels(&frame, area.as_deref(), keepout, polys);
        if let (Some(spec), Some(a)) = (&self.area, &z.area) {
            if a.is_clear() {
                return Err(ScenarioError::Zone {
                    kind: "area",
                    label: spec.label(),
                    message: format!(
                        "holds no pixel centre of the map {} (it lies outside the map or is thinner than a pixel)",
                        map.source.display()
                    ),
                });
            }
        }
        Ok(Some(z))
    }

    /// The zone a world error is about, for messages: the area for a start outside it, the
    /// first keep-out for a start inside one, else the area (or the first keep-out).
    fn zone_of(&self, e: &WorldError) -> Option<(&'static str, String)> {
        let area = self.area.as_ref().map(|a| ("area", a.label()));
        let keep = || {
            let labels: Vec<String> = self.keepout.iter().map(ZoneSpec::label).collect();
            (!labels.is_empty()).then(|| ("keepout", labels.join(", ")))
        };
        match e {
            WorldError::StartOutsideArea { .. } | WorldError::AreaUnreachable { .. } => area,
            WorldError::StartInKeepout { .. } => keep(),
            WorldError::NoRoomInZones { .. } => area.or_else(keep),
            _ => None,
        }
    }

    /// `e` as the error of the zone it is about (`keepout FILE: ...`, as [`ScenarioError::Zone`]
    /// words it), when it is about one (see `zone_of`); for `ccpp info`, which builds its
    /// world itself.
    pub fn zone_error(&self, e: &WorldError, map: &Path) -> Option<ScenarioError> {
        self.zone_of(e).map(|(kind, label)| ScenarioError::Zone {
            kind,
            label,
            message: format!("{e} (map {})", map.display()),
        })
    }

    /// What the zones will hold, for the memory estimate (before any zone file is read).
    pub fn zone_load(&self) -> ZoneLoad {
        ZoneLoad {
            any: self.area.is_some() || !self.keepout.is_empty(),
            approach: self.area.is_some() && self.start.is_some(),
            mask_files: self
                .keepout
                .iter()
                .filter(|k| matches!(k, ZoneSpec::File(_)))
                .count(),
        }
    }

    /// What the planner's checks and estimate see for `map`.
    pub fn setup(&self, map: &PreparedMap) -> Setup {
        self.setup_on(map.grid.frame())
    }

    /// [`Self::setup`] for a map of `frame`: the sensor range in force is the one asked for,
    /// or with no range asked for 4 r raised to the least the planner runs with
    /// ([`least_sensor_range`](ccpp_core::planners::PlannerSettings::least_sensor_range): a
    /// robot of a pixel or two, or a tile wider than 3 r, needs more than 4 r; for a planner
    /// that decides from its neighbour tiles alone more changes nothing).
    fn setup_on(&self, frame: &MapFrame) -> Setup {
        let mut setup = Setup {
            frame: *frame,
            robot: self.robot,
            sensor_range: self.sim.sensor_range_on(&self.robot, frame),
            max_steps: self.sim.max_steps,
            noisy: self.noisy(),
        };
        if self.sim.sensor_range.is_none() {
            if let Some(need) = self.planner.settings().least_sensor_range(&setup) {
                setup.sensor_range = setup.sensor_range.max(need);
            }
        }
        setup
    }

    /// The simulator settings of a run on a map of `frame`: [`Self::sim`]'s, with the sensor
    /// range [`Self::setup`] resolves.
    fn sim_on(&self, frame: &MapFrame) -> SimConfig {
        let range = self.setup_on(frame).sensor_range;
        let mut sim = self.sim.clone();
        if self.sim.sensor_range.is_none() && range > self.sim.sensor_range_on(&self.robot, frame) {
            sim.sensor_range = Some(range);
        }
        sim
    }

    /// Checks the run against the loaded map: the map's extent, the planner's checks
    /// (degenerate runs), then the memory estimate (before anything large is allocated).
    /// Returns the estimate.
    ///
    /// # Errors
    /// [`ScenarioError::Memory`] or [`ScenarioError::Degenerate`].
    pub fn check_map(&self, map: &PreparedMap) -> Result<ResourceEstimate, ScenarioError> {
        self.check_map_as(map, true)
    }

    /// Whether the run's execution carries odometry noise ([`Setup::noisy`]).
    fn noisy(&self) -> bool {
        matches!(self.execution(), Execution::Pid(p) if p.noise.is_some())
    }

    /// The planner's checks that need no map
    /// ([`check_unplaced`](ccpp_core::planners::PlannerSettings::check_unplaced)): its options
    /// against the robot and the run's odometry noise. [`Self::check_map`] makes them too; a
    /// bench makes them before it touches its folder.
    ///
    /// # Errors
    /// [`ScenarioError::Invalid`]: `PLANNER: SECTION.FIELD: message`.
    pub fn check_unplaced(&self) -> Result<(), ScenarioError> {
        self.planner
            .settings()
            .check_unplaced(&self.robot, self.noisy())
            .map_err(|e| {
                let e = e.in_section(self.planner.kind().info().section);
                ScenarioError::Invalid(format!("{}: {e}", self.planner.name()))
            })
    }

    /// [`Self::check_map`] for a robot its caller drives (Python's step API): the planner's
    /// checks and its memory are left out (an `Env` holds the world, the sweep and the known
    /// map, and no planner; a tiny robot was refused for the tiles of a planner it never ran).
    ///
    /// # Errors
    /// As [`Self::check_map`], but for the planner's own.
    pub fn check_driven_map(&self, map: &PreparedMap) -> Result<ResourceEstimate, ScenarioError> {
        self.check_map_as(map, false)
    }

    /// [`Self::check_map`], with the planner's checks and memory (`with_planner`) or without.
    fn check_map_as(
        &self,
        map: &PreparedMap,
        with_planner: bool,
    ) -> Result<ResourceEstimate, ScenarioError> {
        let setup = self.setup(map);
        let planner = if with_planner {
            self.planner.name()
        } else {
            "the step API"
        };
        // Also checked when the map is prepared; again here for a map the caller built.
        check_extent(&map.grid, &map.source)?;
        // A robot wider than the map fits nowhere, whatever the planner: said before the
        // planner's own checks, which would blame its tile (`ba_star.tile_side_m: tile side
        // 10 m is larger than the map` for a robot of radius 5 m).
        let f = map.grid.frame();
        let (w, h) = (f.width_m(), f.height_m());
        if 2.0 * self.robot.radius > w.max(h) {
            return Err(ScenarioError::Invalid(format!(
                "map {}: a robot of radius {} m ({} m across) is larger than the map ({} x {} m): it fits nowhere",
                map.source.display(),
                Compact(self.robot.radius),
                across(self.robot.radius),
                fmt_m(w),
                fmt_m(h)
            )));
        }
        if with_planner {
            self.planner
                .settings()
                .check(&setup)
                .map_err(|e| self.degenerate(&map.source, e))?;
        }
        // A landmark farther off the map than the landmark range is never seen from it: it
        // would be read, checked and then change nothing.
        let (lo, hi) = f.world_bounds();
        let reach = self.sim.landmarks.range_m;
        if let Some((i, l)) = self
            .sim
            .landmarks
            .landmarks
            .iter()
            .enumerate()
            .find(|(_, l)| {
                // Distance from the map's bounding box (a box widened by the range let a
                // landmark off a corner, 4.1 m away with a 3 m range, through).
                let dx = (lo.x - l.x).max(l.x - hi.x).max(0.0);
                let dy = (lo.y - l.y).max(l.y - hi.y).max(0.0);
                dx.hypot(dy) > reach
            })
        {
            return Err(ScenarioError::Invalid(format!(
                "landmark {i} (id {}) at ({}, {}) lies more than the landmark range ({} m) outside map {} ({}, {} to {}, {}): no robot on the map sees it",
                l.id,
                Compact(l.x),
                Compact(l.y),
                Compact(reach),
                map.source.display(),
                Compact(lo.x),
                Compact(lo.y),
                Compact(hi.x),
                Compact(hi.y)
            )));
        }
        // The PID trace of the planner's path; a driven robot's trace grows with its
        // caller's steps, which nothing estimates beforehand.
        let mut est = if with_planner {
            let mut est = estimate_run(&setup, self.planner.settings());
            add_sim_pid_records(&mut est, &setup, self.planner.settings(), &self.execution());
            est
        } else {
            ccpp_core::planners::settings::estimate_driven(&setup)
        };
        let zones = estimate_zones(&setup, self.zone_load());
        if zones.bytes > 0.0 {
            est.bytes += zones.bytes;
            est.detail = format!("{}; {}", est.detail, zones.detail);
        }
        let limit = self.max_memory_mb as f64 * 1024.0 * 1024.0;
        if est.bytes.is_nan() || est.bytes > limit {
            let mb = est.bytes / (1024.0 * 1024.0);
            let needed = about_mb(est.bytes);
            // Beyond a petabyte no limit is the answer: only the cause can be changed.
            let advice = if limit <= PROCESS_BYTES {
                // Below the process's own share no smaller map or larger robot helps.
                format!(
                    "raise it with --max-memory MB / max_memory_mb: the process alone needs {}",
                    about_mb(PROCESS_BYTES)
                )
            } else if mb <= MAX_SENSIBLE_MB {
                format!(
                    "raise it with --max-memory MB / max_memory_mb, or use {}",
                    est.remedy
                )
            } else {
                format!("no machine has that much; use {}", est.remedy)
            };
            return Err(ScenarioError::Memory {
                path: map.source.clone(),
                planner,
                needed,
                detail: est.detail,
                limit_mb: self.max_memory_mb,
                advice,
            });
        }
        // A bound on time, as the memory estimate above is one on space (checked after it:
        // a tiny robot or gains that crawl are refused there with their own advice): a
        // control period far below any robot's ran for half an hour in a few MB.
        if with_planner {
            let exec = self.execution();
            if let Execution::Pid(p) = &exec {
                let steps = ccpp_core::planners::settings::pid_control_steps(
                    &setup,
                    self.planner.settings(),
                    &exec,
                );
                if steps > ccpp_core::planners::settings::MAX_PID_STEPS {
                    return Err(ScenarioError::Invalid(format!(
                        "map {}: {} under PID execution would simulate about {:.1e} control steps (dt_s {} s, max_steps_per_motion {}), more than {:.0e}: raise exec.pid.dt_s (a robot's control loop runs at 10 to 1000 Hz: dt_s 0.001 to 0.1), or the speed limits and gains that set how many steps a move takes (linear/angular output_limit and kp, min_speed_mps, min_turn_rate)",
                        map.source.display(),
                        self.planner.name(),
                        steps,
                        Compact(p.dt_s),
                        p.max_steps_per_motion,
                        ccpp_core::planners::settings::MAX_PID_STEPS
                    )));
                }
                // Every move stopped at its cap: the run ends "done" having driven nothing.
                if let Some((move_m, cap)) = ccpp_core::planners::settings::pid_moves_cut_short(
                    &setup,
                    self.planner.settings(),
                    &exec,
                ) {
                    return Err(ScenarioError::Invalid(format!(
                        "map {}: {} under PID execution: a quarter turn and a move of {} m take max_steps_per_motion ({cap}) control steps or more at dt_s {} s, so every move would stop short of its goal: raise exec.pid.dt_s (a robot's control loop runs at 10 to 1000 Hz: dt_s 0.001 to 0.1) or max_steps_per_motion, or the speed limits and gains that set how many steps a move takes (linear/angular output_limit and kp, min_speed_mps, min_turn_rate)",
                        map.source.display(),
                        self.planner.name(),
                        Compact(move_m),
                        Compact(p.dt_s),
                    )));
                }
            }
        }
        Ok(est)
    }

    /// Validates, checks against `map` and builds the world.
    ///
    /// # Errors
    /// As [`validate`](Self::validate) and [`check_map`](Self::check_map), plus a start in a
    /// wall or a robot that fits nowhere.
    pub fn world(&self, map: &PreparedMap) -> Result<World, ScenarioError> {
        let zones = self.world_checks(map)?;
        self.world_on(map.grid.clone(), &map.source, map.recipe.inflation(), zones)
    }

    /// The checks before a world is built; returns the zone masks.
    fn world_checks(&self, map: &PreparedMap) -> Result<Option<ZoneMasks>, ScenarioError> {
        self.validate()?;
        self.check_map(map)?;
        self.zone_masks(map)
    }

    /// The world of this scenario's robot and start on `map` with `zones` (from
    /// [`zone_masks`](Self::zone_masks), loaded once by a caller that builds many worlds), without
    /// the planner's checks: for callers that drive the robot themselves (Python's `Env`).
    /// Errors about a zone name it, as [`world`](Self::world)'s do.
    ///
    /// # Errors
    /// A start in a wall, outside the map or in a keep-out, an area the start cannot reach, a
    /// robot that fits nowhere.
    pub fn world_with_zones(
        &self,
        map: &PreparedMap,
        zones: Option<ZoneMasks>,
    ) -> Result<World, ScenarioError> {
        self.world_on(map.grid.clone(), &map.source, map.recipe.inflation(), zones)
    }

    /// A planner's check failure as [`ScenarioError::Degenerate`] on the map `source`.
    fn degenerate(&self, source: &Path, e: OptionsError) -> ScenarioError {
        let e = e.in_section(self.planner.kind().info().section);
        ScenarioError::Degenerate {
            path: source.to_path_buf(),
            planner: self.planner.name(),
            message: if e.field.contains('.') {
                e.to_string()
            } else {
                e.message
            },
        }
    }

    /// Refuses a map (with its zones) whose digest is not the scenario's `map_digest`, before
    /// the world is built: a start now in a wall is the edit's consequence, not the news.
    fn check_digest(
        &self,
        grid: &GridMap,
        zones: Option<&ZoneMasks>,
        source: &Path,
    ) -> Result<(), ScenarioError> {
        let Some(want) = &self.map_digest else {
            return Ok(());
        };
        let well_formed = want.len() == 16
            && want
                .bytes()
                .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b));
        if !well_formed {
            let shown: String = want.chars().take(24).collect();
            let more = if want.chars().count() > 24 { "..." } else { "" };
            return Err(ScenarioError::Invalid(format!(
                "map_digest {shown:?}{more} is not a digest (16 lowercase hex digits, as a run \
                 writes it into run.json); remove it to run on the map as it is"
            )));
        }
        let got = format!("{:016x}", ccpp_core::world::map_digest(grid, zones));
        if *want != got {
            return Err(ScenarioError::Invalid(format!(
                "map {}: its content (with the zones) differs from the one this scenario was \
                 recorded on (map_digest {want}, now {got}): the map or a zone file was edited \
                 since; remove map_digest to run on it as it is now",
                source.display()
            )));
        }
        Ok(())
    }

    /// Builds the world on `grid` (the prepared map's, loaded from `source` and grown by
    /// `inflation` metres when that is `Some`) after [`Self::check_digest`], and runs the
    /// planner's checks against it; a world error the inflation likely caused names it
    /// ([`inflated_world_error`]).
    fn world_on(
        &self,
        grid: GridMap,
        source: &Path,
        inflation: Option<f64>,
        zones: Option<ZoneMasks>,
    ) -> Result<World, ScenarioError> {
        self.check_digest(&grid, zones.as_ref(), source)?;
        let start = self.start.map(|s| Pose::new(s[0], s[1], s[2]));
        let settings = self.planner.settings();
        let fit = settings.start_radius(&self.robot);
        // A tile planner's approach ends where its tiles around the start fit too (a disk one
        // tile side wider), when the part of the area it reaches has such a spot.
        let room = fit + settings.tile_side(&self.robot).unwrap_or(0.0);
        let world = World::with_zones_room(grid, self.robot, start, zones, fit, room).map_err(
            |source_err| {
                match self.zone_error(&source_err, source) {
                    Some(zone) => zone,
                    // An error the inflation likely caused names it.
                    None => match inflated_world_error(&source_err, inflation) {
                        Some(m) => ScenarioError::Invalid(format!("map {}: {m}", source.display())),
                        None => ScenarioError::World {
                            path: source.to_path_buf(),
                            source: source_err,
                        },
                    },
                }
            },
        )?;
        self.planner
            .settings()
            .check_world(&world)
            .map_err(|e| self.degenerate(source, e))?;
        Ok(world)
    }

    /// What a simulated run refuses and a plan does not (checked by every run entry point
    /// before the map is read): `rect-boustrophedon` lanes farther apart than the tool sweeps
    /// ([`RectOptions::check_tool`](ccpp_core::planners::rect_boustrophedon::RectOptions)).
    ///
    /// # Errors
    /// The option at fault.
    pub fn check_run(&self) -> Result<(), ScenarioError> {
        if let PlannerConfig::RectBoustrophedon(o) = &self.planner {
            o.check_tool(&self.robot)
                .map_err(|e| ScenarioError::Options(e.in_section("rect_boustrophedon")))?;
        }
        Ok(())
    }

    /// Runs the scenario on a map the caller prepared (bench runs share one map).
    ///
    /// # Errors
    /// As [`world`](Self::world).
    pub fn run_on(&self, map: &PreparedMap) -> Result<Run, ScenarioError> {
        self.check_run()?;
        let world = crate::phase::time("world", || self.world(map))?;
        // (a flag nobody sets: the same run as one that cannot be stopped)
        self.run_in(world, &map.name, |_| (), &AtomicBool::new(false))
            .map(|(run, ())| run)
    }

    /// [`run_on`](Self::run_on) that another thread can stop by setting `stop`: the
    /// simulation ends within [`STOP_CHECK_STEPS`](ccpp_core::sim::STOP_CHECK_STEPS) steps of
    /// it and no metrics are computed (Python's Ctrl-C gives up a run this way, instead of
    /// leaving it to finish unseen). bcd's planning before the first step stops too
    /// ([`PlannerConfig::build_until`]).
    ///
    /// # Errors
    /// As [`world`](Self::world); [`ScenarioError::Interrupted`] when `stop` ended the run.
    pub fn run_on_until(&self, map: &PreparedMap, stop: &AtomicBool) -> Result<Run, ScenarioError> {
        self.check_run()?;
        let world = crate::phase::time("world", || self.world(map))?;
        self.run_in(world, &map.name, |_| (), stop)
            .map(|(run, ())| run)
    }

    /// [`run_on`](Self::run_on) taking the prepared map, whose grid becomes the world's
    /// instead of being copied (one byte per pixel less at the peak): same run, same results.
    ///
    /// # Errors
    /// As [`world`](Self::world).
    pub fn run_owned(&self, map: PreparedMap) -> Result<Run, ScenarioError> {
        Ok(self.run_owned_beside(map, |_| ())?.0)
    }

    /// [`run_owned`](Self::run_owned), also calling `beside` on the world on a second thread
    /// while the planner works (the planner reads the world, never writes it), for work of the
    /// caller's that needs the world but not the run: same run, same results.
    ///
    /// # Errors
    /// As [`world`](Self::world).
    pub fn run_owned_beside<T: Send>(
        &self,
        map: PreparedMap,
        beside: impl FnOnce(&World) -> T + Send,
    ) -> Result<(Run, T), ScenarioError> {
        let (run, extra, _) = self.run_owned_with(map, beside, false)?;
        Ok((run, extra))
    }

    /// [`run_owned_beside`](Self::run_owned_beside), also forming `path.csv` while the run
    /// goes on when `form_files` (on another thread, from the trace as it grows; the swept
    /// pixels and the motion figures of the metrics are found the same way): the same run,
    /// metrics and file bytes, with less left to do when the run ends. The files are `None`
    /// when not asked for.
    ///
    /// # Errors
    /// As [`world`](Self::world).
    pub fn run_owned_with<T: Send>(
        &self,
        map: PreparedMap,
        beside: impl FnOnce(&World) -> T + Send,
        form_files: bool,
    ) -> Result<(Run, T, Option<FormedFiles>), ScenarioError> {
        self.check_run()?;
        let PreparedMap {
            grid,
            name,
            source,
            recipe,
            thresholds,
            alpha_differs,
        } = map;
        let world = crate::phase::time("world", || {
            // The checks read the map as prepared; the grid is moved back out afterwards.
            let prepared = PreparedMap {
                grid,
                name: String::new(),
                source,
                recipe,
                thresholds,
                alpha_differs,
            };
            let zones = self.world_checks(&prepared)?;
            self.world_on(
                prepared.grid,
                &prepared.source,
                prepared.recipe.inflation(),
                zones,
            )
        })?;
        if form_files {
            Ok(self.run_forming(world, &name, beside))
        } else {
            let (run, extra) = self.run_in(world, &name, beside, &AtomicBool::new(false))?;
            Ok((run, extra, None))
        }
    }

    /// Plans and simulates in `world`, then computes the metrics. What the metrics need of the
    /// world alone ([`metrics::WorldPart`]) and `beside` are computed on a second thread while
    /// the planner works. `stop` set by another thread ends the simulation early
    /// ([`ScenarioError::Interrupted`]).
    fn run_in<T: Send>(
        &self,
        world: World,
        map_name: &str,
        beside: impl FnOnce(&World) -> T + Send,
        stop: &AtomicBool,
    ) -> Result<(Run, T), ScenarioError> {
        let side = self.tile_side();
        let (output, part, extra) = crate::phase::time("plan + simulate", || {
            std::thread::scope(|s| {
                // A planner that reads the accessible surface first waits for it.
                let other = s.spawn(|| (metrics::WorldPart::of(&world, side), beside(&world)));
                // Wall time covers planning (offline planners plan in `build`) and simulation.
                let started = std::time::Instant::now();
                // (bcd's and rect-boustrophedon's planning end early too when `stop` is set;
                // the options were checked when the world was built, `Scenario::world`)
                let mut planner = self.planner.settings().build_until(&world, stop);
                let sim = self.sim_on(world.frame());
                let output = simulate_until(&world, planner.as_mut(), &sim, &mut |_| {}, stop);
                let wall_time_s = started.elapsed().as_secs_f64();
                let (part, extra) = join_scoped(other);
                output.map(|mut output| {
                    output.wall_time_s = wall_time_s;
                    (output, part, extra)
                })
            })
        })
        .ok_or(ScenarioError::Interrupted)?;
        let (metrics, swept) = crate::phase::time("metrics", || {
            metrics::compute_prepared(&world, &output, map_name, part)
        });
        let run = Run {
            world,
            output,
            metrics,
            swept,
        };
        Ok((run, extra))
    }

    /// [`run_in`](Self::run_in), a third thread reading the trace as it grows (copied out in
    /// chunks of [`FORM_CHUNK`] sealed pieces) to sweep the tool's pixels, tally the motion
    /// metrics ([`metrics::MotionTally`]) and form `path.csv` and `trace.jsonl`.
    fn run_forming<T: Send>(
        &self,
        world: World,
        map_name: &str,
        beside: impl FnOnce(&World) -> T + Send,
    ) -> (Run, T, Option<FormedFiles>) {
        let side = self.tile_side();
        let (output, part, extra, (swept, tally), files) =
            crate::phase::time("plan + simulate", || {
                std::thread::scope(|s| {
                    let world = &world;
                    // A planner that reads the accessible surface first waits for it.
                    let other = s.spawn(|| (metrics::WorldPart::of(world, side), beside(world)));
                    let (tx, rx) = std::sync::mpsc::channel::<Chunk>();
                    let former = s.spawn(move || {
                        let mut sweep = metrics::TraceSweep::new(world);
                        let mut tally = metrics::MotionTally::new(world);
                        let mut files = FileFormer::default();
                        for chunk in rx {
                            sweep.chunk(&chunk);
                            tally.chunk(&chunk);
                            files.chunk(&chunk);
                        }
                        ((sweep.finish(), tally), Some(files.finish()))
                    });
                    // Wall time covers planning (offline planners plan in `build`) and simulation.
                    let started = std::time::Instant::now();
                    // (options checked when the world was built, `Scenario::world`)
                    let mut planner = self.planner.settings().build(world);
                    let sim = self.sim_on(world.frame());
                    let mut sent = 0usize;
                    let mut output = simulate_tapped(world, planner.as_mut(), &sim, &mut |t| {
                        let n = t.sealed_count();
                        if n >= sent + FORM_CHUNK {
                            // A closed channel (the former panicked) shows when it is joined.
                            let _ = tx.send(t.chunk(sent..n));
                            sent = n;
                        }
                    });
                    output.wall_time_s = started.elapsed().as_secs_f64();
                    let _ = tx.send(output.trace.chunk(sent..output.trace.piece_count()));
                    drop(tx);
                    let (part, extra) = join_scoped(other);
                    let (swept, files) =
                        crate::phase::time("wait for the streamed files", || join_scoped(former));
                    (output, part, extra, swept, files)
                })
            });
        let (metrics, swept) = crate::phase::time("metrics", || {
            metrics::compute_prepared_with(
                &world,
                &output,
                map_name,
                part,
                Some(swept),
                Some(tally),
            )
        });
        let run = Run {
            world,
            output,
            metrics,
            swept,
        };
        (run, extra, files)
    }

    /// Loads the map and runs the scenario.
    ///
    /// # Errors
    /// As [`MapRecipe::load`] and [`run_on`](Self::run_on).
    pub fn run(&self) -> Result<Run, ScenarioError> {
        self.validate()?;
        let map = self.map.load_within(self.max_memory_mb)?;
        self.run_on(&map)
    }
}

/// Builds a [`Scenario`] step by step; [`build`](Self::build) validates it.
#[derive(Clone, Debug)]
pub struct ScenarioBuilder(Scenario);

impl ScenarioBuilder {
    /// Robot radius (the tool radius follows unless set).
    #[must_use]
    pub fn radius(mut self, r: f64) -> Self {
        let same = self.0.robot.tool_radius == self.0.robot.radius;
        self.0.robot.radius = r;
        if same {
            self.0.robot.tool_radius = r;
        }
        self
    }

    /// Tool radius.
    #[must_use]
    pub fn tool_radius(mut self, r: f64) -> Self {
        self.0.robot.tool_radius = r;
        self
    }

    /// Start pose.
    #[must_use]
    pub fn start(mut self, x: f64, y: f64, theta: f64) -> Self {
        self.0.start = Some([x + 0.0, y + 0.0, theta + 0.0]);
        self
    }

    /// The robot (radius and tool radius).
    #[must_use]
    pub fn robot(mut self, robot: Robot) -> Self {
        self.0.robot = robot;
        self
    }

    /// Start pose `[x, y, theta]`, or `None` for the default start. A zero given as `-0` is stored as 0 (its sign reached `run.json` and the trace).
    #[must_use]
    pub fn start_pose(mut self, start: Option<[f64; 3]>) -> Self {
        self.0.start = start.map(|s| s.map(|v| v + 0.0));
        self
    }

    /// Work area (`None`: the whole map) and keep-out zones, replacing any set before; zone
    /// files are recorded by their absolute paths.
    #[must_use]
    pub fn zones(mut self, area: Option<ZoneSpec>, keepout: Vec<ZoneSpec>) -> Self {
        // Zone files are recorded absolute, as the map is, so that `run.json` replays from any
        // folder (a relative `area.geojson` was looked up beside the replay's working folder).
        self.0.area = area.map(ZoneSpec::absolute);
        self.0.keepout = keepout.into_iter().map(ZoneSpec::absolute).collect();
        self
    }

    /// The planner with its options.
    #[must_use]
    pub fn planner(mut self, p: PlannerConfig) -> Self {
        self.0.planner = p;
        self
    }

    /// Simulator settings.
    #[must_use]
    pub fn sim(mut self, s: SimConfig) -> Self {
        self.0.sim = s;
        self
    }

    /// Work area (see [`Scenario::area`]).
    #[must_use]
    pub fn area(mut self, a: ZoneSpec) -> Self {
        self.0.area = Some(a);
        self
    }

    /// Adds a keep-out zone (see [`Scenario::keepout`]).
    #[must_use]
    pub fn keepout(mut self, k: ZoneSpec) -> Self {
        self.0.keepout.push(k);
        self
    }

    /// Memory limit, MB.
    #[must_use]
    pub fn max_memory_mb(mut self, mb: u64) -> Self {
        self.0.max_memory_mb = mb;
        self
    }

    /// Memory limit, MB, or `None` for [`DEFAULT_MAX_MEMORY_MB`].
    #[must_use]
    pub fn memory_limit(self, mb: Option<u64>) -> Self {
        self.max_memory_mb(mb.unwrap_or(DEFAULT_MAX_MEMORY_MB))
    }

    /// The validated scenario.
    ///
    /// # Errors
    /// As [`Scenario::validate`].
    pub fn build(self) -> Result<Scenario, ScenarioError> {
        self.0.validate()?;
        Ok(self.0)
    }
}

/// Most threads `RAYON_NUM_THREADS` may ask for. A process's pool starts that many threads,
/// and bcd's plans run one a thread: `RAYON_NUM_THREADS=99999999` started thousands of
/// threads and had not finished after five minutes (a run of one second); 1000 still runs.
pub const MAX_THREADS: usize = 1024;

/// Why the `RAYON_NUM_THREADS` value `v` is refused: a count above [`MAX_THREADS`]. Values
/// rayon itself ignores (not a number, 0: one thread a core) are left to it.
pub fn threads_env_problem(v: Option<&str>) -> Option<String> {
    let v = v?.trim();
    let n: u128 = v.parse().ok()?;
    (n > MAX_THREADS as u128).then(|| {
        format!(
            "RAYON_NUM_THREADS={}: at most {MAX_THREADS} threads (this machine has {}); unset it or give a smaller count",
            v.chars().take(40).collect::<String>(),
            std::thread::available_parallelism().map_or_else(|_| "an unknown number of cores".to_string(), |n| format!("{n} cores"))
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use ccpp_core::planners::ba_star::BaStarOptions;

    #[test]
    fn an_absurd_thread_count_is_refused() {
        assert_eq!(threads_env_problem(None), None);
        for ok in ["1", "2", "1024", " 64 ", "0", "abc", "-1", ""] {
            assert_eq!(threads_env_problem(Some(ok)), None, "{ok}");
        }
        for bad in [
            "1025",
            "99999999",
            "340282366920938463463374607431768211455",
        ] {
            let e = threads_env_problem(Some(bad)).unwrap_or_default();
            assert!(e.contains("at most 1024 threads"), "{bad}: {e}");
        }
    }

    /// A robot's width in the "fits nowhere" refusal stays a number where `2 r` overflows
    /// (`--radius 1e308` printed `inf m across`).
    #[test]
    fn the_width_of_a_huge_robot_is_a_number() {
        assert_eq!(across(5.0), "10");
        assert_eq!(across(1e300), "2e300");
        assert_eq!(across(1e308), "2e308");
        assert_eq!(across(9e307), "1.8e308");
        assert_eq!(across(f64::MAX), "3.5953862697246315e308");
        assert_eq!(across(f64::INFINITY), "inf");
    }

    /// A misspelt key of a scenario file, of its robot or of its simulator settings is refused,
    /// named (a misspelt `keepouts:` ran with no keep-out at all, `tool_radus` with the tool
    /// as wide as the robot: hostile pass), in YAML and in JSON; the file's own keys still read.
    #[test]
    fn unknown_keys_of_a_scenario_file_are_refused() {
        let base = "map: {path: m.yaml}\nrobot: {radius: 0.1, tool_radius: 0.1}\nplanner: bcd\noptions: {turn_cost_m: 0.5}\n";
        let read = |text: &str, json: bool| {
            crate::file::parse_yaml_or_json::<Scenario>(text, json).map(|s| s.planner.kind())
        };
        assert_eq!(read(base, false), Ok(PlannerKind::Bcd));
        let with_keepout = format!("{base}keepout: [[0.5, 0.5, 2.5, 1.5]]\n");
        assert!(read(&with_keepout, false).is_ok());
        for (text, key) in [
            (
                format!("{base}keepouts: [[0.5, 0.5, 2.5, 1.5]]\n"),
                "keepouts",
            ),
            (format!("{base}colour: red\n"), "colour"),
            (base.replace("tool_radius", "tool_radus"), "tool_radus"),
            (format!("{base}sim: {{max_step: 1}}\n"), "max_step"),
        ] {
            let e = read(&text, false).expect_err(key);
            assert!(e.contains(&format!("unknown field `{key}`")), "{e}");
        }
        let mut s = Scenario::new(MapRecipe::file("m.yaml"), PlannerKind::Bcd);
        s.keepout = vec![ZoneSpec::Rect([0.0, 0.0, 1.0, 1.0])];
        let mut v: serde_json::Value =
            serde_json::from_str(&s.to_json().unwrap_or_default()).unwrap_or_default();
        assert_eq!(read(&v.to_string(), true), Ok(PlannerKind::Bcd));
        // The keys the refusal lists as expected are the file's own, every one: a field added
        // to `Scenario` and `ScenarioIn` but not to `SCENARIO_KEYS` would be left out of the
        // message (this keeps the three in step).
        let mut full = s.clone();
        full.start = Some([0.0, 0.0, 0.0]);
        full.area = Some(ZoneSpec::Rect([0.0, 0.0, 1.0, 1.0]));
        full.map_digest = Some("0123456789abcdef".into());
        let keys: Vec<String> = serde_json::from_str::<serde_json::Map<String, serde_json::Value>>(
            &full.to_json().unwrap_or_default(),
        )
        .unwrap_or_default()
        .keys()
        .cloned()
        .collect();
        let mut want: Vec<&str> = SCENARIO_KEYS.to_vec();
        want.sort_unstable();
        assert_eq!(keys, want);
        v["max_memory"] = serde_json::json!(1);
        let e = read(&v.to_string(), true).expect_err("max_memory");
        assert!(e.contains("unknown field `max_memory`"), "{e}");
    }

    #[test]
    fn json_round_trip_keeps_planner_and_options_flat() {
        let mut s = Scenario::new(MapRecipe::file("m.yaml"), PlannerKind::BaStar);
        s.planner = PlannerConfig::BaStar(BaStarOptions {
            smoothing: false,
            ..BaStarOptions::default()
        });
        let j = s.to_json().unwrap_or_default();
        let v: serde_json::Value = serde_json::from_str(&j).unwrap_or_default();
        assert_eq!(v["planner"], "ba-star");
        assert_eq!(v["options"]["smoothing"], false);
        let back: Scenario = serde_json::from_str(&j).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(back, s);
        // Another planner's options are refused.
        let bad = j.replace("\"smoothing\": false", "\"side\": \"left\"");
        assert!(serde_json::from_str::<Scenario>(&bad).is_err());
    }

    /// Every member path of `v` (keys, and indices into arrays of objects are not needed).
    fn paths(v: &serde_json::Value, prefix: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
        if let serde_json::Value::Object(m) = v {
            for (k, child) in m {
                prefix.push(k.clone());
                out.push(prefix.clone());
                paths(child, prefix, out);
                prefix.pop();
            }
        }
    }

    #[test]
    fn an_omitted_field_at_any_depth_reads_back_as_the_default() {
        for kind in PlannerKind::ALL {
            let mut s = Scenario::new(MapRecipe::file("m.yaml"), *kind);
            s.sim.exec = Some(Execution::Pid(ccpp_core::exec::PidOptions::default()));
            let full = serde_json::to_value(&s).unwrap_or_default();
            let mut all = Vec::new();
            paths(&full, &mut Vec::new(), &mut all);
            for path in all {
                // The map file and the PID execution are set, not defaults: omitting them
                // changes the scenario; everything inside them must not.
                let p = path.join(".");
                if ["map.path", "sim.exec"]
                    .iter()
                    .any(|set| *set == p || set.starts_with(&format!("{p}.")))
                {
                    continue;
                }
                let (last, parent) = path.split_last().unwrap_or_else(|| unreachable!());
                let mut v = full.clone();
                let mut cur = &mut v;
                for k in parent {
                    cur = &mut cur[k.as_str()];
                }
                if let Some(m) = cur.as_object_mut() {
                    m.remove(last);
                }
                if let Ok(back) = serde_json::from_value::<Scenario>(v) {
                    assert_eq!(back, s, "{kind}: omitting {}", path.join("."));
                }
            }
        }
    }

    #[test]
    fn configure_keeps_every_part_and_validates_once_built() {
        let planner = PlannerConfig::BaStar(BaStarOptions {
            smoothing: false,
            ..BaStarOptions::default()
        });
        let s = Scenario::configure(MapRecipe::file("m.yaml"), planner.clone())
            .robot(Robot::new(0.2))
            .start_pose(Some([1.0, 2.0, 0.5]))
            .memory_limit(Some(7))
            .zones(
                Some(ZoneSpec::Rect([0.0, 0.0, 1.0, 1.0])),
                vec![ZoneSpec::Rect([0.2, 0.2, 0.4, 0.4])],
            )
            .build()
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s.planner, planner);
        assert_eq!(s.robot, Robot::new(0.2));
        assert_eq!(s.start, Some([1.0, 2.0, 0.5]));
        assert_eq!(s.max_memory_mb, 7);
        assert!(s.area.is_some() && s.keepout.len() == 1);
        let d = Scenario::configure(MapRecipe::file("m.yaml"), planner.clone())
            .memory_limit(None)
            .build()
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(d.max_memory_mb, DEFAULT_MAX_MEMORY_MB);
        for bad in [
            Scenario::configure(MapRecipe::file("m.yaml"), planner.clone()).robot(Robot::new(-1.0)),
            Scenario::configure(MapRecipe::file("m.yaml"), planner.clone())
                .zones(Some(ZoneSpec::Rect([1.0, 1.0, 0.0, 0.0])), Vec::new()),
            Scenario::configure(MapRecipe::file("m.yaml"), planner.clone()).memory_limit(Some(0)),
        ] {
            assert!(bad.build().is_err());
        }
    }

    #[test]
    fn validate_refuses_bad_values() {
        let mut s = Scenario::new(MapRecipe::file("m.yaml"), PlannerKind::Bcd);
        s.planner = PlannerConfig::Bcd(ccpp_core::planners::bcd::BcdOptions {
            lane_spacing_m: Some(f64::NAN),
            ..Default::default()
        });
        let e = s
            .validate()
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("bcd.lane_spacing_m"), "{e}");
        let mut s = Scenario::new(MapRecipe::file("m.yaml"), PlannerKind::BaStar);
        s.sim.landmarks.landmarks = vec![ccpp_core::landmarks::Landmark::new(1, 0.0, 0.0)];
        let e = s
            .validate()
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("PID"), "{e}");
        // PID without odometry noise: the estimate is the truth, nothing to correct.
        s.sim.exec = Some(Execution::Pid(PidOptions::default()));
        let e = s
            .validate()
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("landmarks correct odometry drift"), "{e}");
        s.sim.exec = Some(Execution::Pid(PidOptions {
            noise: Some(ccpp_core::exec::OdometryNoise {
                linear_rel_std: 0.05,
                ..Default::default()
            }),
            ..PidOptions::default()
        }));
        assert!(s.validate().is_ok(), "{:?}", s.validate());
    }

    #[test]
    fn sim_exec_never_drops_the_planners_own_execution() {
        use ccpp_core::exec::OdometryNoise;
        use ccpp_core::planners::bsa_bfs::BsaBfsOptions;
        let own = PidOptions {
            dt_s: 0.1,
            ..PidOptions::default()
        };
        let with = |planner_exec: Option<Execution>, sim: Option<Execution>| {
            let mut s = Scenario::new(MapRecipe::file("m.yaml"), PlannerKind::BsaBfs);
            if let Some(e) = planner_exec {
                s.planner = PlannerConfig::BsaBfs(BsaBfsOptions {
                    exec: e,
                    ..BsaBfsOptions::default()
                });
            }
            s.sim.exec = sim;
            s.validate().err().map(|e| e.to_string())
        };
        let noisy = PidOptions {
            noise: Some(OdometryNoise::default()),
            ..own
        };
        // The planner's default execution may be replaced; its own settings only by the same
        // settings (or the same with odometry noise added).
        assert_eq!(with(None, Some(Execution::Ideal)), None);
        assert_eq!(with(None, Some(Execution::Pid(own))), None);
        assert_eq!(with(Some(Execution::Pid(own)), None), None);
        assert_eq!(
            with(Some(Execution::Pid(own)), Some(Execution::Pid(own))),
            None
        );
        assert_eq!(
            with(Some(Execution::Pid(own)), Some(Execution::Pid(noisy))),
            None
        );
        for (planner, sim) in [
            (Execution::Pid(own), Execution::Ideal),
            (Execution::Pid(own), Execution::Pid(PidOptions::default())),
            (Execution::Ideal, Execution::Pid(PidOptions::default())),
        ] {
            let e = with(Some(planner), Some(sim)).unwrap_or_default();
            assert!(e.contains("bsa_bfs.exec") && e.contains("drop"), "{e}");
        }
    }
}
