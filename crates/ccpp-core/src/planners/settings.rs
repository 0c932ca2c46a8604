//! Each planner's options behind one interface, [`PlannerSettings`]: validation of the values
//! (the one place both the command line and option files go through), the checks that need the
//! map frame and the robot (a tile larger than the map, a sensor that cannot see a neighbour
//! tile), the resource estimate made before anything is allocated, and the constructor.
//!
//! Resource estimates are deliberately generous upper bounds of the dominant allocations
//! (per-pixel arrays, per-tile / per-cell state, trace records and their text): the point is to
//! refuse runs that would take gigabytes or hours *before* allocating, not to predict the peak.

use std::sync::atomic::AtomicBool;

use crate::exec::{Execution, PidGains, PidOptions};
use crate::grid::MapFrame;
use crate::options::{present, OptionsError};
use crate::planner::Planner;
use crate::world::{Robot, World};

use super::ba_star::{BaStar, BaStarOptions};
use super::ba_star_extended::{BaStarExtended, BaStarExtendedOptions};
use super::bcd::{Bcd, BcdOptions};
use super::bsa::{Bsa, BsaOptions};
use super::bsa_bfs::{BsaBfs, BsaBfsOptions};
use super::bsa_extended::{BsaExtended, BsaExtendedOptions};
use super::extension::ExtensionOptions;
use super::random_bounce::{RandomBounce, RandomBounceOptions};
use super::rect_boustrophedon::{RectBoustrophedon, RectOptions};

/// Bytes per map pixel of a run: the grid, the distance transform, C-free / reachable /
/// accessible / swept bitsets, the known map of online planners, the rendered picture.
pub const PIXEL_BYTES: f64 = 64.0;
/// Bytes per tile (or cell) of a tile planner: tile state, search record, cached disk spans, and
/// the trace records of visiting it (in memory and as text).
pub const TILE_BYTES: f64 = 600.0;
/// Bytes per trace record: the record in memory and its `trace.jsonl` / `path.csv` lines.
pub const RECORD_BYTES: f64 = 200.0;
/// Bytes per map pixel that `bcd` holds beyond [`PIXEL_BYTES`] whatever its parallelism (the
/// planning context's masks, the coarse grids' labels, the headland's distance transform;
/// under `ccpp run` also the metrics' world part, made while it plans).
pub const BCD_PIXEL_BYTES: f64 = 64.0;
/// Bytes per map pixel of each `bcd` plan made at the same time (its transfer search, sweep
/// counts and rim masks), for up to [`BCD_MAX_JOBS`] plans: `bcd` makes its plans in
/// parallel, one per thread or [`super::bcd::BcdOptions::plans_at_a_time`]. Fitted to peak
/// resident memory (`/usr/bin/time -v ccpp plan --planner bcd`, `RAYON_NUM_THREADS` 1, 2,
/// 4, 8): `office_1024` at `--radius 0.1` 137, 202, 246, 272 MB, `cluttered_2000` 377, 477,
/// 547, 660 MB, `office_4096` at `--radius 0.1` 1700 MB (1 thread), 2312 MB (2), 2486 MB
/// (4); `ccpp run --planner bcd` on `office_1024` 153, 195, 270, 275 MB. Every figure is
/// within this estimate (`office_4096`: 3.5 GB at two threads, 4.6 GB from four).
pub const BCD_JOB_PIXEL_BYTES: f64 = 32.0;
/// Most `bcd` plans counted as made at the same time ([`BCD_JOB_PIXEL_BYTES`]): beyond four
/// threads the measured peaks grow little (the plans of one round are few).
pub const BCD_MAX_JOBS: usize = 4;

/// What a planner's checks and estimate may use: what an operator knows before the run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setup {
    /// The map frame (extent, resolution, origin).
    pub frame: MapFrame,
    /// The robot.
    pub robot: Robot,
    /// The sensor range in force, metres.
    pub sensor_range: f64,
    /// The run's step cap ([`crate::sim::SimConfig::max_steps`]): no run takes more steps, so
    /// no estimate counts more (random-bounce's budget may be far beyond it).
    pub max_steps: u64,
    /// The run's execution carries odometry noise (from the planner's options or the run's
    /// own, e.g. `--odometry-noise`): the true pose then leaves the map axes, so no PID step
    /// is dropped from the trace as part of a straight glide (see [`crate::sim`]).
    pub noisy: bool,
}

impl Setup {
    /// Number of tiles of side `side` whose centre can lie on the map (with a border tile).
    pub fn tiles(&self, side: f64) -> f64 {
        let (w, h) = (self.frame.width_m(), self.frame.height_m());
        // A rotated frame spans at most its diagonal in each axis.
        let d = w.hypot(h);
        let (w, h) = if self.frame.origin.theta == 0.0 {
            (w, h)
        } else {
            (d, d)
        };
        (w / side + 3.0) * (h / side + 3.0)
    }

    /// Number of map pixels.
    pub fn pixels(&self) -> f64 {
        self.frame.width as f64 * self.frame.height as f64
    }

    /// Area of the map frame, m² (what an operator knows without the map's contents).
    pub fn frame_area_m2(&self) -> f64 {
        self.frame.width_m() * self.frame.height_m()
    }
}

/// A resource estimate: bytes and what they are for.
#[derive(Clone, Debug, PartialEq)]
pub struct ResourceEstimate {
    /// Estimated bytes (may be huge or infinite: kept as `f64`).
    pub bytes: f64,
    /// The dominant quantity, for messages (`"9.0e6 tiles of 0.001 m"`).
    pub detail: String,
    /// What would shrink the dominant quantity, for messages (`"a larger robot or tile
    /// side"`): the advice of a refusal.
    pub remedy: String,
}

/// The remedy of an estimate that does not name its own.
pub const GENERIC_REMEDY: &str = "a larger robot, tile or spacing";

/// The remedy when the map's pixels dominate: a robot or tile changes nothing.
const PIXELS_REMEDY: &str = "a smaller map (crop the image or downsample it)";

impl ResourceEstimate {
    /// `count` units of `bytes_each`, described as `count what`.
    pub fn units(count: f64, bytes_each: f64, what: &str) -> Self {
        Self {
            bytes: count * bytes_each,
            detail: format!("{} {what}", fmt_count(count)),
            remedy: GENERIC_REMEDY.to_string(),
        }
    }

    /// The same estimate with `remedy` as its advice.
    #[must_use]
    pub fn remedy(mut self, remedy: &str) -> Self {
        self.remedy = remedy.to_string();
        self
    }
}

/// A count as `123456` or `1.2e18`; `over 1e308` when it overflowed (an infinite count of a
/// degenerate input, never `inf`).
pub fn fmt_count(n: f64) -> String {
    if !n.is_finite() {
        "over 1e308".to_string()
    } else if n < 1e7 {
        format!("{n:.0}")
    } else {
        format!("{n:.1e}")
    }
}

/// An `extension` section as written in an options file: the fields it gives. A host planner
/// ([`BaStarExtendedOptions`], [`BsaExtendedOptions`]) fills the others from **its own**
/// defaults (`reach_r` 0), not from [`ExtensionOptions::default`] (`reach_r` 4), so a partial
/// section such as `extension: { merge_segments: false }` changes that one field only.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct ExtensionSection {
    #[serde(default, deserialize_with = "present")]
    reach_r: Option<f64>,
    #[serde(default, deserialize_with = "present")]
    lane_ends: Option<bool>,
    #[serde(default, deserialize_with = "present")]
    merge_segments: Option<bool>,
    #[serde(default, deserialize_with = "present")]
    min_yield: Option<f64>,
    #[serde(default, deserialize_with = "present")]
    leave_fraction: Option<f64>,
    #[serde(default, deserialize_with = "present")]
    leave_group: Option<usize>,
    #[serde(default, deserialize_with = "present")]
    simplify_fraction: Option<f64>,
    #[serde(default, deserialize_with = "present")]
    simplify_loss: Option<f64>,
    #[serde(default, deserialize_with = "present")]
    corner_slack: Option<f64>,
}

impl ExtensionSection {
    /// The given fields over `base`. Every field is listed (no `..base`), so a field added to
    /// [`ExtensionOptions`] fails to compile here until it is read from files too.
    fn over(self, base: &ExtensionOptions) -> ExtensionOptions {
        ExtensionOptions {
            reach_r: self.reach_r.unwrap_or(base.reach_r),
            lane_ends: self.lane_ends.unwrap_or(base.lane_ends),
            merge_segments: self.merge_segments.unwrap_or(base.merge_segments),
            min_yield: self.min_yield.unwrap_or(base.min_yield),
            leave_fraction: self.leave_fraction.unwrap_or(base.leave_fraction),
            leave_group: self.leave_group.unwrap_or(base.leave_group),
            simplify_fraction: self.simplify_fraction.unwrap_or(base.simplify_fraction),
            simplify_loss: self.simplify_loss.unwrap_or(base.simplify_loss),
            corner_slack: self.corner_slack.unwrap_or(base.corner_slack),
        }
    }
}

/// Reads `ba_star_extended.extension` over `ba-star-extended`'s own extension defaults.
///
/// # Errors
/// A malformed section or an unknown field.
pub(crate) fn ba_star_extended_extension<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<ExtensionOptions, D::Error> {
    let section = <ExtensionSection as serde::Deserialize>::deserialize(d)?;
    Ok(section.over(&BaStarExtendedOptions::default().extension))
}

/// Reads `bsa_extended.extension` over `bsa-extended`'s own extension defaults.
///
/// # Errors
/// A malformed section or an unknown field.
pub(crate) fn bsa_extended_extension<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<ExtensionOptions, D::Error> {
    let section = <ExtensionSection as serde::Deserialize>::deserialize(d)?;
    Ok(section.over(&BsaExtendedOptions::default().extension))
}

/// A planner's options: validation, checks against the setup, resource estimate, constructor.
/// Implemented by every options type of the registry.
pub trait PlannerSettings {
    /// Checks each value on its own (finite, positive, ordered...). Errors name the field.
    ///
    /// # Errors
    /// The first invalid value.
    fn validate(&self) -> Result<(), OptionsError>;

    /// Checks the options against the map frame, the robot and the sensor: runs that are legal
    /// but cannot do anything (a tile larger than the map, a sensor that cannot see a neighbour
    /// tile, an area outside the map) are refused with what is wrong.
    ///
    /// # Errors
    /// What makes the run degenerate.
    fn check(&self, setup: &Setup) -> Result<(), OptionsError>;

    /// The part of [`Self::check`] that needs no map: the options against the robot and
    /// whether the run has odometry noise. `check` makes it too; a bench makes it for every
    /// planner before it touches its folder (a refusal that every run of it meets replaced
    /// the last good bench there with error rows: hostile pass, stop 69).
    ///
    /// # Errors
    /// What makes every run of these options degenerate.
    fn check_unplaced(&self, _robot: &Robot, _noisy: bool) -> Result<(), OptionsError> {
        Ok(())
    }

    /// Checks the options against the world itself, once it is built (what [`Self::check`]
    /// cannot tell from the frame: a user area that holds nothing the planner can reach).
    ///
    /// # Errors
    /// What makes the run degenerate.
    fn check_world(&self, _world: &World) -> Result<(), OptionsError> {
        Ok(())
    }

    /// The planner's share of the memory a run needs (tiles, cells, waypoints, trace).
    fn estimate(&self, setup: &Setup) -> ResourceEstimate;

    /// The path a run drives at most, metres, and the length of its typical straight move:
    /// what the memory estimate counts the PID trace of when the simulator runs the planner
    /// under PID execution (`--exec pid`) without the planner asking for it. By default twice
    /// the frame's area over the tool width (a path ratio of 2 over the whole frame) in moves
    /// of one tool width.
    fn path_estimate(&self, setup: &Setup) -> (f64, f64) {
        let w = 2.0 * setup.robot.tool_radius;
        (2.0 * setup.frame_area_m2() / w, w)
    }

    /// Bytes a PID trace record of this planner's runs takes at the peak of the process, for
    /// [`add_sim_pid_records`]: [`PID_RECORD_BYTES`] by default (ba-star under `--exec pid`
    /// on `apartment_400x300` at r = 0.05 m: 876 k records, 66 MiB peak).
    fn sim_pid_record_bytes(&self) -> f64 {
        PID_RECORD_BYTES
    }

    /// For a planner that decides from its neighbour tiles (cells) alone, the sensor range that
    /// sees a neighbour's whole contact disk (tile side + r + half a pixel, metres): a longer
    /// range changes nothing in its run, so a run of it senses at least this far whatever the
    /// default ([`PlannerInfo::range_matters`](super::PlannerInfo::range_matters) is `false`).
    /// `None` for the others.
    fn sensor_need(&self, _setup: &Setup) -> Option<f64> {
        None
    }

    /// The shortest sensor range the planner runs with on `setup`, if it needs more than
    /// nothing: a run that asks for no range senses at least this far (the default `4 r` is
    /// raised to it: a robot of a pixel or two, or a tile wider than `3 r`, needs more), and
    /// a range asked for below it is refused by [`check`](Self::check). Default:
    /// [`sensor_need`](Self::sensor_need), which for the planners it is given for is also
    /// all they ever use.
    fn least_sensor_range(&self, setup: &Setup) -> Option<f64> {
        self.sensor_need(setup)
    }

    /// The tile (cell) side the planner works on, if it is tile-based.
    fn tile_side(&self, robot: &Robot) -> Option<f64>;

    /// The execution the planner asks for when the simulator settings do not fix one.
    fn preferred_execution(&self) -> Option<Execution> {
        None
    }

    /// The radius of the disk the planner needs room for where its coverage starts: the
    /// robot's radius, or more for a planner that plans a larger body (rect-boustrophedon's
    /// clearance disk). A start outside the work area gets an approach that ends where this
    /// disk fits inside the area ([`World::with_zones_fitting`]).
    fn start_radius(&self, robot: &Robot) -> f64 {
        robot.radius
    }

    /// Builds the planner for `world` (offline planners plan here), unchecked: an option out
    /// of its range runs as its default. [`PlannerConfig::build`](super::PlannerConfig::build)
    /// checks the options first ([`validate`](Self::validate),
    /// [`check_world`](Self::check_world)) and is the one to call.
    fn build(&self, world: &World) -> Box<dyn Planner>;

    /// [`build`](Self::build) that another thread can give up by setting `stop`: a planner
    /// whose building takes long (bcd's and rect-boustrophedon's planning) then ends it early, with a planner that
    /// must not be driven (the caller is giving the run up). The others build as usual.
    fn build_until(&self, world: &World, _stop: &AtomicBool) -> Box<dyn Planner> {
        self.build(world)
    }
}

fn finite_pos(field: &str, v: f64) -> Result<(), OptionsError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(OptionsError::new(
            field,
            format!(
                "must be a finite number > 0, got {}",
                crate::display::Compact(v)
            ),
        ))
    }
}

fn finite_nonneg(field: &str, v: f64) -> Result<(), OptionsError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(OptionsError::new(
            field,
            format!(
                "must be a finite number >= 0, got {}",
                crate::display::Compact(v)
            ),
        ))
    }
}

/// Largest relative standard deviation of odometry speed noise ([`OdometryNoise`]'s
/// `linear_rel_std`, `angular_rel_std`) accepted.
///
/// [`OdometryNoise`]: crate::exec::OdometryNoise
pub const MAX_REL_STD: f64 = 1.0;

/// Largest heading drift standard deviation of odometry noise accepted, rad per metre.
pub const MAX_DRIFT_STD: f64 = 6.0;

/// Smallest non-zero standard deviation of odometry noise accepted (each of the three).
/// Below it the noise changes nothing a robot could measure: a relative speed error of 1e-9
/// is a nanometre per metre driven, and from about 1e-16 down it vanishes in the rounding of
/// the poses altogether (`--odometry-noise 1e-17` gave the trace of noiseless PID execution
/// for every seed, where `--odometry-noise 0` is refused for that very reason).
pub const MIN_NOISE_STD: f64 = 1e-9;

/// Why a noise standard deviation `v` is refused as too small to draw anything (0 is not: it
/// turns that part of the noise off), or `None`.
pub fn noise_too_small(v: f64) -> Option<String> {
    (v > 0.0 && v < MIN_NOISE_STD).then(|| {
        format!(
            "{} is too small to change the motion: give 0 (none) or at least {}",
            crate::display::Compact(v),
            crate::display::Compact(MIN_NOISE_STD)
        )
    })
}

/// `v` finite and in `[0, max]`; `unit` follows the bound in the message.
fn finite_at_most(field: &str, v: f64, max: f64, unit: &str) -> Result<(), OptionsError> {
    finite_nonneg(field, v)?;
    if v <= max {
        Ok(())
    } else {
        Err(OptionsError::new(
            field,
            format!(
                "must be at most {} {unit}, got {}",
                crate::display::Compact(max),
                crate::display::Compact(v)
            ),
        ))
    }
}

fn opt_finite_pos(field: &str, v: Option<f64>) -> Result<(), OptionsError> {
    v.map_or(Ok(()), |v| finite_pos(field, v))
}

/// Checks one controller's gains `g`; `default` is that controller's default (for the
/// options that only act together).
fn gains(field: &str, g: &PidGains, default: &PidGains) -> Result<(), OptionsError> {
    for (name, v) in [("kp", g.kp), ("ki", g.ki), ("kd", g.kd)] {
        // (a negative gain was taken and its sign dropped: the controller drives towards the
        // goal whatever the output's sign, so kp -2 ran byte-identical to kp 2; hostile pass)
        if !(v.is_finite() && v >= 0.0) {
            return Err(OptionsError::new(
                &format!("{field}.{name}"),
                format!("must be a finite number >= 0, got {v}"),
            ));
        }
    }
    finite_pos(&format!("{field}.output_limit"), g.output_limit)?;
    finite_nonneg(&format!("{field}.integral_limit"), g.integral_limit)?;
    // Options that switch each other off: the one switched off would be read, validated and
    // then change nothing.
    if g.ki == 0.0 && g.integral_limit != default.integral_limit {
        return Err(OptionsError::new(
            &format!("{field}.integral_limit"),
            format!(
                "bounds the integral term, which ki = 0 switches off; give ki too, or leave integral_limit at its default ({})",
                crate::display::Compact(default.integral_limit)
            ),
        ));
    }
    if g.ki != 0.0 && g.integral_limit == 0.0 {
        return Err(OptionsError::new(
            &format!("{field}.ki"),
            "has no effect: integral_limit 0 holds the integral at 0; give integral_limit > 0, or leave ki at 0",
        ));
    }
    Ok(())
}

/// Validates execution settings (PID gains, periods, tolerances, odometry noise).
///
/// # Errors
/// The first invalid value, named `field.subfield`.
pub fn validate_execution(field: &str, e: &Execution) -> Result<(), OptionsError> {
    let Execution::Pid(p) = e else {
        return Ok(());
    };
    // Named as written in an options file: `exec: { pid: { ... } }`.
    validate_pid(&format!("{field}.pid"), p)
}

fn validate_pid(field: &str, p: &PidOptions) -> Result<(), OptionsError> {
    let f = |s: &str| format!("{field}.{s}");
    finite_pos(&f("dt_s"), p.dt_s)?;
    let base = PidOptions::default();
    gains(&f("linear"), &p.linear, &base.linear)?;
    gains(&f("angular"), &p.angular, &base.angular)?;
    finite_nonneg(&f("tolerance_m"), p.tolerance_m)?;
    finite_nonneg(&f("heading_tolerance_rad"), p.heading_tolerance_rad)?;
    finite_nonneg(&f("align_rad"), p.align_rad)?;
    // A heading error is at most pi: a tolerance of pi reaches every heading goal at once (no
    // turn in place at all), and an alignment bound above pi is never exceeded, so larger
    // values were taken and changed nothing.
    if p.heading_tolerance_rad >= std::f64::consts::PI {
        return Err(OptionsError::new(
            &f("heading_tolerance_rad"),
            format!(
                "must be below pi (a heading error is at most pi: every heading goal would be reached at once), got {}",
                crate::display::Compact(p.heading_tolerance_rad)
            ),
        ));
    }
    if p.align_rad > std::f64::consts::PI {
        return Err(OptionsError::new(
            &f("align_rad"),
            format!(
                "must be at most pi (a heading error is at most pi; pi already never turns in place again), got {}",
                crate::display::Compact(p.align_rad)
            ),
        ));
    }
    finite_pos(&f("min_speed_mps"), p.min_speed_mps)?;
    finite_pos(&f("min_turn_rate"), p.min_turn_rate)?;
    finite_nonneg(&f("lookahead_m"), p.lookahead_m)?;
    if p.record_every == 0 {
        return Err(OptionsError::new(&f("record_every"), "must be >= 1"));
    }
    if p.max_steps_per_motion == 0 {
        return Err(OptionsError::new(
            &f("max_steps_per_motion"),
            "must be >= 1",
        ));
    }
    if let Some(n) = &p.noise {
        // A relative speed error of one standard deviation = 100 % already reverses the motion
        // at about one control step in six; beyond it the "odometry" no longer measures motion.
        // A heading drift std of about a full turn per metre is likewise past any odometry.
        finite_at_most(
            &f("noise.linear_rel_std"),
            n.linear_rel_std,
            MAX_REL_STD,
            "(a relative std of 1 = 100 % of the speed)",
        )?;
        finite_at_most(
            &f("noise.angular_rel_std"),
            n.angular_rel_std,
            MAX_REL_STD,
            "(a relative std of 1 = 100 % of the turn rate)",
        )?;
        finite_at_most(
            &f("noise.heading_drift_std"),
            n.heading_drift_std,
            MAX_DRIFT_STD,
            "rad per metre (about a full turn per metre)",
        )?;
        for (name, v) in [
            ("noise.linear_rel_std", n.linear_rel_std),
            ("noise.angular_rel_std", n.angular_rel_std),
            ("noise.heading_drift_std", n.heading_drift_std),
        ] {
            if let Some(why) = noise_too_small(v) {
                return Err(OptionsError::new(&f(name), why));
            }
        }
        if n.seed != 0
            && n.linear_rel_std == 0.0
            && n.angular_rel_std == 0.0
            && n.heading_drift_std == 0.0
        {
            // Zero noise draws nothing: the seed would be read and change nothing.
            return Err(OptionsError::new(
                &f("noise.seed"),
                format!(
                    "has no effect: every noise std is 0 (give a noise of at least {}, or leave the seed out)",
                    crate::display::Compact(MIN_NOISE_STD)
                ),
            ));
        }
    }
    Ok(())
}

/// Refuses a planner's own PID `noise` section whose every std is 0: it draws nothing, so it
/// runs exactly as no section (`noise: {}` was taken as zero noise without a word, where it
/// meant the library's defaults before the section's fields followed `--odometry-noise`).
/// `--odometry-noise 0` is refused for the same reason (it ran exactly as `--exec pid`).
fn noise_that_draws(field: &str, e: &Execution) -> Result<(), OptionsError> {
    if let Execution::Pid(p) = e {
        if let Some(n) = p.noise {
            if !n.draws() {
                return Err(OptionsError::new(
                    &format!("{field}.pid.noise"),
                    format!(
                        "draws no noise: every std is 0 (leave the section out, or give linear_rel_std of at least {})",
                        crate::display::Compact(MIN_NOISE_STD)
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Bytes of one PID trace record in memory: a stored pose (56 bytes) in a vector that grows by
/// doubling (1.5 times that on average, twice at worst; the record count the estimates use
/// is itself above the measured ones). The trace's text is written as it is made, not held.
pub const PID_RECORD_BYTES: f64 = 84.0;

/// Trace records of a PID-executed path of `moves` straight moves of `move_m` metres each,
/// with a quarter turn in place before one move in [`PID_TURN_EVERY`]: the control steps of
/// such motions ([`crate::exec::PidOptions::motion_steps`], creep and arrival included), one
/// record every `record_every` steps. Measured with `ccpp run --planner bsa-bfs`: 32 steps a
/// 0.1 m move and 33 a quarter turn at the default gains; 906 424 records on
/// `apartment_400x300` at `--radius 0.05` (25 841 moves, 1198 turns), where the old count
/// (length over top speed) gave 120 000 and the estimate 37 MB against a peak of 81 MB.
///
/// `glides`: every move runs along a map axis and the run has no odometry noise, so the
/// simulator drops the steps of each drive as a straight glide ([`crate::sim`]) and only the
/// turns' steps are recorded (bsa-bfs on `office_1024` at r = 0.1 m wrote 356 688 poses where
/// every step counted was 3.1 million).
fn pid_records(e: &Execution, moves: f64, move_m: f64, glides: bool) -> f64 {
    match e {
        Execution::Pid(p) => {
            let turn = p.motion_steps(std::f64::consts::FRAC_PI_2, 0.0) as f64 / PID_TURN_EVERY;
            let per_move = p.motion_steps(0.0, move_m) as f64 + turn;
            let recorded = if glides && p.noise.is_none() {
                turn
            } else {
                per_move
            };
            // Kept whatever `record_every` is: the end of each motion and the pose where the
            // robot stops turning in place before it drives (bsa-bfs on `tuw_freihaus_eg` at
            // r = 0.05 m and `record_every: 1e6` was estimated at 62 records and wrote 848 862).
            let kept = 2.0 + 1.0 / PID_TURN_EVERY;
            moves * (recorded / f64::from(p.record_every.max(1)) + kept).min(per_move)
        }
        Execution::Ideal => 0.0,
    }
}

/// Most PID control steps a run may be estimated to take: each is a controller update, a
/// unicycle step and a collision test (about 0.3 us measured: bsa-bfs on `teb_maze` at
/// `dt_s: 1e-5` ran 22 s), so this is minutes of simulation, and the estimate is above the
/// steps run. `dt_s: 1e-7` with a large `max_steps_per_motion` ran for over half an hour on a
/// 10 m map with no refusal (its memory stayed small at a large `record_every`).
pub const MAX_PID_STEPS: f64 = 1.0e9;

/// Control steps of a PID-executed run (`exec`) of `planner` on `s`: its estimated path
/// ([`PlannerSettings::path_estimate`]) in moves, each turned and driven as
/// [`crate::exec::PidOptions::motion_steps`] counts them; 0 under ideal execution.
pub fn pid_control_steps(s: &Setup, planner: &dyn PlannerSettings, exec: &Execution) -> f64 {
    let Execution::Pid(p) = exec else {
        return 0.0;
    };
    let (path_m, move_m) = planner.path_estimate(s);
    if !(path_m.is_finite() && move_m > 0.0) {
        return 0.0;
    }
    let every_step = Execution::Pid(crate::exec::PidOptions {
        record_every: 1,
        ..*p
    });
    pid_records(&every_step, path_m / move_m, move_m, false)
}

/// A PID-executed run (`exec`) of `planner` on `s` whose every move would stop short: a quarter
/// turn and a move of the planner's typical length ([`PlannerSettings::path_estimate`]) take
/// `max_steps_per_motion` control steps or more. Returns the move's length and the cap; `None`
/// under ideal execution. `dt_s: 1e-7` at the default cap ran "done" in 0.08 s having driven
/// 1 mm (0.08 % swept), with only a warning of motions stopped at the cap.
pub fn pid_moves_cut_short(
    s: &Setup,
    planner: &dyn PlannerSettings,
    exec: &Execution,
) -> Option<(f64, u32)> {
    let Execution::Pid(p) = exec else {
        return None;
    };
    let (path_m, move_m) = planner.path_estimate(s);
    if !(path_m.is_finite() && path_m > 0.0 && move_m.is_finite() && move_m > 0.0) {
        return None;
    }
    let cap = u64::from(p.max_steps_per_motion);
    let pid = crate::exec::PidOptions { noise: None, ..*p };
    (pid.motion_steps(std::f64::consts::FRAC_PI_2, move_m) >= cap)
        .then_some((move_m, p.max_steps_per_motion))
}

/// Adds the PID trace records of `moves` moves of `move_m` metres ([`pid_records`]) to an
/// estimate, naming them in its detail (nothing under ideal execution).
fn add_pid_records(e: &mut ResourceEstimate, exec: &Execution, moves: f64, move_m: f64) {
    add_pid_records_at(e, exec, moves, move_m, PID_RECORD_BYTES, false);
}

/// [`add_pid_records`] at `record_bytes` a record.
fn add_pid_records_at(
    e: &mut ResourceEstimate,
    exec: &Execution,
    moves: f64,
    move_m: f64,
    record_bytes: f64,
    glides: bool,
) {
    let records = pid_records(exec, moves, move_m, glides);
    if records > 0.0 {
        e.bytes += records * record_bytes;
        e.detail = format!(
            "{}, about {} PID trace records",
            e.detail,
            fmt_count(records)
        );
    }
}

/// Adds to `est` the PID trace of a run that the simulator executes with `exec` although its
/// planner asks for no execution of its own (`--exec pid` for ba-star, bcd, ...): the records
/// of [`PlannerSettings::path_estimate`]'s path in its moves. A planner that runs PID itself
/// (bsa-bfs, rect-boustrophedon) counts its records in its own estimate. Under `--exec pid`
/// random-bounce on `apartment_400x300` at r = 0.05 m was admitted under a 54 MB limit and
/// peaked at 675 MiB.
pub fn add_sim_pid_records(
    est: &mut ResourceEstimate,
    s: &Setup,
    planner: &dyn PlannerSettings,
    exec: &Execution,
) {
    if matches!(planner.preferred_execution(), Some(Execution::Pid(_))) {
        return;
    }
    let (path_m, move_m) = planner.path_estimate(s);
    if path_m.is_finite() && move_m > 0.0 {
        add_pid_records_at(
            est,
            exec,
            path_m / move_m,
            move_m,
            planner.sim_pid_record_bytes(),
            false,
        );
    }
}

/// One move in this many is counted with a quarter turn in place before it
/// ([`pid_records`]): `bsa-bfs` turned before one move in 22 on `apartment_400x300`, one in 6.5
/// on `office_1024`.
const PID_TURN_EVERY: f64 = 4.0;

/// The sensor must see a neighbour tile's whole contact disk: the pixels whose centres lie
/// within `r + half a pixel` of the tile centre ([`crate::collide::contact_radius_px`]), so up
/// to `side + r + res / 2` from the robot. A shorter range leaves part of every neighbour's
/// disk unknown, the planner reads every neighbour as blocked and the run ends where it
/// started.
fn check_neighbour_sight(setup: &Setup, side: f64, what: &str) -> Result<(), OptionsError> {
    let need = neighbour_sight(setup, side);
    if setup.sensor_range < need * (1.0 - 1e-9) {
        return Err(OptionsError::new(
            "",
            format!(
                "the sensor range {} m cannot see a neighbour {what}'s disk (needs >= {what} side + r + half a pixel = {} m); raise the sensor range",
                fmt_m(setup.sensor_range), fmt_m(need)
            ),
        ));
    }
    Ok(())
}

/// The range that sees a neighbour tile's (cell's) whole contact disk ([`check_neighbour_sight`]).
fn neighbour_sight(setup: &Setup, side: f64) -> f64 {
    neighbour_sight_m(side, setup.robot.radius, setup.frame.resolution)
}

/// The sensor range that sees a neighbour tile's contact disk: tile side `side` + robot radius
/// `radius` + half a pixel of `resolution` (metres). BA*'s own check of its sensor at the start
/// uses this too (it asked a whole pixel, and noted in every trace at the default range that
/// "some moves may stay undecided").
pub(crate) fn neighbour_sight_m(side: f64, radius: f64, resolution: f64) -> f64 {
    side + radius + 0.5 * resolution
}

/// A tile larger than the map leaves no neighbour tile to move to.
fn check_side_fits(setup: &Setup, side: f64, field: &str, what: &str) -> Result<(), OptionsError> {
    let (w, h) = (setup.frame.width_m(), setup.frame.height_m());
    if side > w.max(h) {
        return Err(OptionsError::new(
            field,
            format!(
                "{what} side {} m is larger than the map ({} x {} m): no neighbour {what} fits",
                fmt_m(side),
                fmt_m(w),
                fmt_m(h)
            ),
        ));
    }
    Ok(())
}

/// The least random-bounce budget that makes a move on a map of `res` metres a pixel: half a
/// pixel (its shortest move), and 2e-4 px for the 1e-4 px a move stops short of what is left
/// and the rounding of the free distance.
pub fn least_budget(res: f64) -> f64 {
    (0.5 + 2e-4) * res
}

/// The least value at or above `min` that a refusal names: `min` rounded up to a micrometre,
/// so that the value printed passes the check it names.
fn least_shown(min: f64) -> f64 {
    let mut shown = (min * 1e6).ceil() / 1e6;
    if shown < min {
        shown += 1e-6;
    }
    shown
}

/// The shortest sensor range random-bounce runs with. It looks `range - r - 1.5 px` ahead
/// and drives only strides of half a pixel or more: a range below r + 2 px turned it in place
/// 65 times and ended the run "done" at 0 m (r = 0.03 m at a range of 4 r on a 0.05 m map).
/// A thousandth of a pixel above that: the strides stop 1e-4 px short of what is seen.
fn random_bounce_least_range(s: &Setup) -> f64 {
    let res = s.frame.resolution;
    s.robot.radius + 2.0 * res + 1e-3 * res
}

/// The largest turn random-bounce takes, either way (degrees): two whole turns, so that a
/// range across 360 degrees (`300` to `420`) can be written.
pub const MAX_TURN_DEG: f64 = 720.0;

impl PlannerSettings for RandomBounceOptions {
    fn validate(&self) -> Result<(), OptionsError> {
        opt_finite_pos("budget_m", self.budget_m)?;
        for (f, v) in [
            ("min_turn_deg", self.min_turn_deg),
            ("max_turn_deg", self.max_turn_deg),
        ] {
            if !v.is_finite() {
                return Err(OptionsError::new(f, format!("must be finite, got {v}")));
            }
            // (-9e307 to 9e307 was taken: its width overflowed to infinity and no turn was
            // ever drawn, a run of 6 m ending "done"; wider than two turns either way only
            // repeats angles)
            if v.abs() > MAX_TURN_DEG {
                return Err(OptionsError::new(
                    f,
                    format!(
                        "must be within [-{MAX_TURN_DEG}, {MAX_TURN_DEG}] degrees, got {}",
                        crate::display::Compact(v)
                    ),
                ));
            }
        }
        if self.min_turn_deg > self.max_turn_deg {
            return Err(OptionsError::new(
                "min_turn_deg",
                format!(
                    "must be <= max_turn_deg ({} > {})",
                    self.min_turn_deg, self.max_turn_deg
                ),
            ));
        }
        if self.min_turn_deg == self.max_turn_deg && self.min_turn_deg.rem_euclid(360.0) == 0.0 {
            return Err(OptionsError::new(
                "max_turn_deg",
                "the turn range holds no turn (only multiples of 360 degrees)",
            ));
        }
        // One turn angle draws nothing: a seed would be read, checked and then change nothing.
        if self.min_turn_deg == self.max_turn_deg
            && self.seed != RandomBounceOptions::default().seed
        {
            return Err(OptionsError::new(
                "seed",
                format!(
                    "changes nothing: every turn is {} degrees (min_turn_deg = max_turn_deg); leave the seed out or widen the turn range",
                    crate::display::Compact(self.min_turn_deg)
                ),
            ));
        }
        Ok(())
    }

    fn check(&self, s: &Setup) -> Result<(), OptionsError> {
        let res = s.frame.resolution;
        // Its shortest move is half a pixel, and a move stops 1e-4 px short of what is left
        // (2e-4 px asked, for the rounding of the free distance): a smaller budget ended the
        // run at 0 m with the "did not move" warning, which blames the floor (budgets from
        // half a pixel to 1e-4 px more passed and did so too).
        if let Some(b) = self.budget_m {
            let min = least_budget(res);
            if b < min {
                return Err(OptionsError::new(
                    "budget_m",
                    format!(
                        "{} m is shorter than random-bounce's shortest move, half a pixel ({} m on this map): {} m or more",
                        fmt_m(b),
                        fmt_m(0.5 * res),
                        fmt_m(least_shown(min))
                    ),
                ));
            }
        }
        let min = random_bounce_least_range(s);
        if s.sensor_range < min {
            // (the message named r + 2 px itself, which was refused)
            return Err(OptionsError::new(
                "",
                format!(
                    "the sensor range {} m sees too little beyond the robot's footprint: random-bounce moves in strides of at least half a pixel beyond the r + 1.5 px its disk can touch, so it needs a little over r + 2 px, {} m or more (raise --sensor-range; a larger robot needs a larger range)",
                    fmt_m(s.sensor_range), fmt_m(least_shown(min))
                ),
            ));
        }
        Ok(())
    }

    fn least_sensor_range(&self, s: &Setup) -> Option<f64> {
        Some(random_bounce_least_range(s))
    }

    fn estimate(&self, s: &Setup) -> ResourceEstimate {
        let (path, stride) = self.path_estimate(s);
        let budget = self.budget_m.unwrap_or_else(|| default_budget(s));
        // A stride and a turn per stride; the step cap named when it is what bounds them.
        let what = if path < budget {
            "strides, the run's step cap"
        } else {
            "strides"
        };
        let e = ResourceEstimate::units(path / stride, 2.0 * RECORD_BYTES, what);
        if path < budget {
            // Beyond the cap a smaller budget changes nothing until it falls below it.
            e.remedy(&format!(
                "a random_bounce.budget_m well below {} m, the way the run's step cap of {} steps allows (a larger budget changes nothing), or in Python a lower max_steps",
                fmt_count(path),
                fmt_count(s.max_steps as f64)
            ))
        } else if self.budget_m.is_some() {
            e.remedy("a smaller random_bounce.budget_m")
        } else {
            e.remedy("a larger tool radius or a random_bounce.budget_m (the default budget is 3 x the map frame's area over the tool width)")
        }
    }

    fn sim_pid_record_bytes(&self) -> f64 {
        // Measured: 3.84 million records, 657 MiB peak (179 bytes a record; its poses are
        // not lattice steps) on `apartment_400x300` at r = 0.05 m under `--exec pid`.
        2.0 * PID_RECORD_BYTES
    }

    fn path_estimate(&self, s: &Setup) -> (f64, f64) {
        let stride = bounce_stride(s);
        // A stride is a step: the run's step cap ends it before a budget beyond it (a
        // `budget_m` of 1e12 m with `max_steps` 1000 was refused as 1e9 MB).
        let budget = self.budget_m.unwrap_or_else(|| default_budget(s));
        (budget.min(s.max_steps as f64 * stride), stride)
    }

    fn tile_side(&self, _: &Robot) -> Option<f64> {
        None
    }

    fn build(&self, world: &World) -> Box<dyn Planner> {
        let mut o = self.clone();
        if o.budget_m.is_none() {
            o.budget_m = Some(default_budget_in(world));
        }
        Box::new(RandomBounce::new(o))
    }
}

/// The straight move random-bounce's estimates count: as far as the sensor sees ahead of the
/// robot's disk, at least half a pixel.
fn bounce_stride(s: &Setup) -> f64 {
    let res = s.frame.resolution;
    (s.sensor_range - s.robot.radius - 1.5 * res).max(0.5 * res)
}

/// The random-bounce default distance budget: 3x the lane-by-lane length of the map frame's
/// area (`3 * width_m * height_m / (2 r_tool)`) — what an operator knows, never the map's
/// contents, so the run stays online-honest.
pub fn default_budget(s: &Setup) -> f64 {
    3.0 * s.frame_area_m2() / (2.0 * s.robot.tool_radius)
}

/// [`default_budget`] for a run in `world`: with a work area, 3x the lane-by-lane length of
/// the area (its pixels' extent; the operator drew it, so the run stays online-honest), at
/// least [`least_budget`] (one move). The map frame's budget ignored the
/// area: a one-pixel area drove 360 m of jiggles, path ratio 1489. Never more than the
/// frame's, which the memory estimate counts before the area is read.
pub fn default_budget_in(world: &World) -> f64 {
    let frame = *world.frame();
    let robot = world.robot();
    let whole = default_budget(&Setup {
        frame,
        robot,
        sensor_range: 0.0,
        max_steps: u64::MAX,
        noisy: false,
    });
    match world.zones().and_then(|z| z.area.as_ref()) {
        Some(area) => {
            let res = frame.resolution;
            let m2 = area.count_ones(..) as f64 * res * res;
            (3.0 * m2 / (2.0 * robot.tool_radius))
                .max(least_budget(res))
                .min(whole)
        }
        None => whole,
    }
}

impl PlannerSettings for BaStarOptions {
    fn validate(&self) -> Result<(), OptionsError> {
        opt_finite_pos("tile_side_m", self.tile_side_m)
    }

    fn check(&self, s: &Setup) -> Result<(), OptionsError> {
        let t = self.tile_side_m.unwrap_or(2.0 * s.robot.radius);
        check_side_fits(s, t, "tile_side_m", "tile")?;
        check_neighbour_sight(s, t, "tile")
    }

    fn sensor_need(&self, s: &Setup) -> Option<f64> {
        Some(neighbour_sight(
            s,
            self.tile_side_m.unwrap_or(2.0 * s.robot.radius),
        ))
    }

    fn estimate(&self, s: &Setup) -> ResourceEstimate {
        let t = self.tile_side_m.unwrap_or(2.0 * s.robot.radius);
        // Cached disk spans: 2 bytes per row of the contact disk.
        let rows = 2.0 * (s.robot.radius / s.frame.resolution + 1.0) + 4.0;
        // The trace's backtracking lists: 16 bytes a point, at most `LIST_POINTS_PER_TILE`
        // points a tile and `LIST_POINTS_MAX` in all.
        let lists = if self.record_backtrack_list {
            use crate::planners::ba_star::{LIST_POINTS_MAX, LIST_POINTS_PER_TILE};
            16.0 * (LIST_POINTS_PER_TILE as f64 * s.tiles(t)).min(LIST_POINTS_MAX as f64)
        } else {
            0.0
        };
        let tiles_bytes = s.tiles(t) * (TILE_BYTES + 2.0 * rows);
        // (the lists named as a remedy only where they are most of the need: turning them
        // off could not rescue an estimate of 1.5e16 MB, whose lists were 123 MB; hostile
        // pass, stop 70)
        let mut e = ResourceEstimate::units(s.tiles(t), TILE_BYTES + 2.0 * rows, "tiles")
            .remedy(&if self.record_backtrack_list && lists >= tiles_bytes {
                format!(
                    "a larger robot or tile side, or ba_star.record_backtrack_list: false (its lists: up to {} MB)",
                    (lists / MIB).ceil()
                )
            } else {
                "a larger robot or tile side".to_string()
            });
        e.bytes += lists;
        e.detail = format!("{} of {} m", e.detail, fmt_m(t));
        e
    }

    fn tile_side(&self, robot: &Robot) -> Option<f64> {
        Some(self.tile_side_m.unwrap_or(2.0 * robot.radius))
    }

    fn build(&self, world: &World) -> Box<dyn Planner> {
        let mut o = self.clone();
        if o.tile_side_m.is_none() {
            o.tile_side_m = Some(2.0 * world.robot().radius);
        }
        Box::new(BaStar::new(o))
    }
}

/// Refuses option `field` set to `v`, not its default `d`, while `off` (described by
/// `because`) keeps it from doing anything: it would be validated and then change nothing.
fn unused_option<T: PartialEq + Copy + std::fmt::Display>(
    field: &str,
    v: T,
    d: T,
    off: bool,
    because: &str,
) -> Result<(), OptionsError> {
    if off && v != d {
        return Err(OptionsError::new(
            field,
            format!("{v} changes nothing while {because}; leave it out or change that"),
        ));
    }
    Ok(())
}

/// `bumper_reaction: false` (bcd, rect-boustrophedon) in a run without odometry noise, where
/// no motion meets an obstacle and the replay is the plan either way.
/// `how` says where the option applies for this planner.
fn bumper_reaction_applies(react: bool, noisy: bool, how: &str) -> Result<(), OptionsError> {
    if !react && !noisy {
        return Err(OptionsError::new(
            "bumper_reaction",
            format!("false changes nothing without odometry noise (no motion meets an obstacle), as in a plan; leave it out, or give it to {how}"),
        ));
    }
    Ok(())
}

/// The extension options that another one turns off, set anyway (`d`: the host's defaults).
fn extension_unused(e: &ExtensionOptions, d: &ExtensionOptions) -> Result<(), OptionsError> {
    let no_yield = e.min_yield <= 0.0;
    let why = "extension.min_yield is 0 (every chunk is driven)";
    unused_option(
        "extension.leave_fraction",
        e.leave_fraction,
        d.leave_fraction,
        no_yield,
        why,
    )?;
    unused_option(
        "extension.leave_group",
        e.leave_group,
        d.leave_group,
        no_yield,
        why,
    )?;
    // The other way round: nothing may be left, so no trip is judged.
    let no_leave = e.leave_fraction <= 0.0;
    let why = "extension.leave_fraction is 0 (no trip is left, so none is judged)";
    unused_option(
        "extension.min_yield",
        e.min_yield,
        d.min_yield,
        no_leave,
        why,
    )?;
    unused_option(
        "extension.leave_group",
        e.leave_group,
        d.leave_group,
        no_leave,
        why,
    )?;
    let unmerged = !e.merge_segments;
    let why = "extension.merge_segments is false (passes are neither simplified nor squared)";
    for (field, v, dv) in [
        (
            "extension.simplify_fraction",
            e.simplify_fraction,
            d.simplify_fraction,
        ),
        ("extension.simplify_loss", e.simplify_loss, d.simplify_loss),
        ("extension.corner_slack", e.corner_slack, d.corner_slack),
    ] {
        unused_option(field, v, dv, unmerged, why)?;
    }
    unused_option(
        "extension.simplify_loss",
        e.simplify_loss,
        d.simplify_loss,
        e.simplify_fraction <= 0.0,
        "extension.simplify_fraction is 0 (no vertex that loses a pixel is dropped)",
    )?;
    unused_option(
        "extension.simplify_fraction",
        e.simplify_fraction,
        d.simplify_fraction,
        e.simplify_loss <= 0.0,
        "extension.simplify_loss is 0 (no vertex that loses a pixel is dropped)",
    )
}

impl PlannerSettings for BaStarExtendedOptions {
    fn validate(&self) -> Result<(), OptionsError> {
        self.ba_star
            .validate()
            .map_err(|e| e.in_section("ba_star"))?;
        let k = self.backtrack_sweep;
        if !(k.is_finite() && k >= 0.0) {
            return Err(OptionsError::new(
                "backtrack_sweep",
                format!("must be a finite number >= 0, got {k}"),
            ));
        }
        self.extension.validate()?;
        let d = Self::default();
        unused_option(
            "backtrack_sweep",
            k,
            d.backtrack_sweep,
            self.extension.reach_r > 0.0,
            "extension.reach_r is above 0 (rims are swept around each region's end instead)",
        )?;
        extension_unused(&self.extension, &d.extension)
    }

    fn check(&self, s: &Setup) -> Result<(), OptionsError> {
        self.ba_star.check(s).map_err(|e| e.in_section("ba_star"))
    }

    fn least_sensor_range(&self, s: &Setup) -> Option<f64> {
        // BA*'s own need: its tiles' neighbours seen whole (a longer range also lets the
        // extension see farther, so unlike BA*'s it is a floor, not all it uses).
        self.ba_star.sensor_need(s)
    }

    fn estimate(&self, s: &Setup) -> ResourceEstimate {
        // BA*'s tiles plus the extension's per-pixel state (swept and target bitsets, the search
        // records of its position searches: about 16 bytes a pixel).
        let mut e = self.ba_star.estimate(s);
        e.bytes += 16.0 * s.pixels();
        e
    }

    fn tile_side(&self, robot: &Robot) -> Option<f64> {
        self.ba_star.tile_side(robot)
    }

    fn build(&self, world: &World) -> Box<dyn Planner> {
        let mut o = self.clone();
        if o.ba_star.tile_side_m.is_none() {
            o.ba_star.tile_side_m = Some(2.0 * world.robot().radius);
        }
        Box::new(BaStarExtended::new(o))
    }
}

fn bsa_cells(s: &Setup) -> ResourceEstimate {
    let c = 2.0 * s.robot.radius;
    let mut e = ResourceEstimate::units(s.tiles(c), TILE_BYTES, "cells")
        .remedy("a larger robot (the cells are 2 r wide)");
    e.detail = format!("{} of {} m", e.detail, fmt_m(c));
    e
}

impl PlannerSettings for BsaOptions {
    fn validate(&self) -> Result<(), OptionsError> {
        Ok(())
    }

    fn check(&self, s: &Setup) -> Result<(), OptionsError> {
        check_neighbour_sight(s, 2.0 * s.robot.radius, "cell")
    }

    fn sensor_need(&self, s: &Setup) -> Option<f64> {
        Some(neighbour_sight(s, 2.0 * s.robot.radius))
    }

    fn estimate(&self, s: &Setup) -> ResourceEstimate {
        bsa_cells(s)
    }

    fn tile_side(&self, robot: &Robot) -> Option<f64> {
        Some(2.0 * robot.radius)
    }

    fn build(&self, _: &World) -> Box<dyn Planner> {
        Box::new(Bsa::new(*self))
    }
}

impl PlannerSettings for BsaExtendedOptions {
    fn validate(&self) -> Result<(), OptionsError> {
        if self.extension.lane_ends {
            // BSA fills spirals, not lanes: nothing to drive on to the wall.
            return Err(OptionsError::new(
                "extension.lane_ends",
                "does not apply to bsa-extended (BSA has no lanes)",
            ));
        }
        self.extension.validate()?;
        extension_unused(&self.extension, &Self::default().extension)
    }

    fn check(&self, s: &Setup) -> Result<(), OptionsError> {
        check_neighbour_sight(s, 2.0 * s.robot.radius, "cell")
    }

    fn least_sensor_range(&self, s: &Setup) -> Option<f64> {
        Some(neighbour_sight(s, 2.0 * s.robot.radius))
    }

    fn estimate(&self, s: &Setup) -> ResourceEstimate {
        // BSA's cells plus the extension's per-pixel state (as for ba-star-extended).
        let mut e = bsa_cells(s);
        e.bytes += 16.0 * s.pixels();
        e
    }

    fn tile_side(&self, robot: &Robot) -> Option<f64> {
        Some(2.0 * robot.radius)
    }

    fn build(&self, _: &World) -> Box<dyn Planner> {
        Box::new(BsaExtended::new(self.clone()))
    }
}

impl PlannerSettings for BsaBfsOptions {
    fn validate(&self) -> Result<(), OptionsError> {
        opt_finite_pos("cell_side_m", self.cell_side_m)?;
        finite_nonneg("clearance_margin_m", self.clearance_margin_m)?;
        validate_execution("exec", &self.exec)?;
        noise_that_draws("exec", &self.exec)
    }

    fn check(&self, s: &Setup) -> Result<(), OptionsError> {
        let c = self.cell_side_m.unwrap_or(2.0 * s.robot.radius);
        check_side_fits(s, c, "cell_side_m", "cell")?;
        check_neighbour_sight(s, c, "cell")
    }

    fn sensor_need(&self, s: &Setup) -> Option<f64> {
        Some(neighbour_sight(
            s,
            self.cell_side_m.unwrap_or(2.0 * s.robot.radius),
        ))
    }

    fn estimate(&self, s: &Setup) -> ResourceEstimate {
        let c = self.cell_side_m.unwrap_or(2.0 * s.robot.radius);
        let cells = s.tiles(c);
        // Cell state and return stacks; the trace is counted by PID records below.
        let mut e = ResourceEstimate::units(cells, TILE_BYTES / 3.0, "cells")
            .remedy("a larger robot or cell side, or a larger bsa_bfs.exec.pid.record_every");
        e.detail = format!("{} of {} m", e.detail, fmt_m(c));
        // The lane-by-lane length of the whole frame, one cell a move; every move runs from
        // cell to cell along an axis, a straight glide unless the run is noisy.
        let moves = s.frame_area_m2() / (c * c);
        add_pid_records_at(&mut e, &self.exec, moves, c, PID_RECORD_BYTES, !s.noisy);
        e
    }

    fn tile_side(&self, robot: &Robot) -> Option<f64> {
        Some(self.cell_side_m.unwrap_or(2.0 * robot.radius))
    }

    fn preferred_execution(&self) -> Option<Execution> {
        Some(self.exec)
    }

    fn build(&self, _: &World) -> Box<dyn Planner> {
        Box::new(BsaBfs::new(self.clone()))
    }
}

impl PlannerSettings for BcdOptions {
    fn validate(&self) -> Result<(), OptionsError> {
        self.check_ranges().map_err(|e| match e {
            super::bcd::BcdOptionsError::OutOfRange { name, what, value } => {
                OptionsError::new(name, format!("must be {what}, got {value}"))
            }
        })?;
        let d = Self::default();
        let why = "rim is false (no rim pass)";
        unused_option(
            "rim_min_yield",
            self.rim_min_yield,
            d.rim_min_yield,
            !self.rim,
            why,
        )?;
        unused_option(
            "rim_coverage",
            self.rim_coverage,
            d.rim_coverage,
            !self.rim,
            why,
        )
    }

    fn check_unplaced(&self, robot: &Robot, noisy: bool) -> Result<(), OptionsError> {
        bumper_reaction_applies(
            self.bumper_reaction,
            noisy,
            "`ccpp run` with --odometry-noise (Python: `run` with odometry_noise=; a bench has no noise for bcd)",
        )?;
        // Lanes farther apart than the tool's width leave a strip between each pair that no
        // lane sweeps (the rim pass only mops up what is left at the walls), and a spacing far
        // beyond the map would only reach the lane arithmetic as a huge count.
        let tool = 2.0 * robot.tool_radius;
        if let Some(sp) = self.lane_spacing_m {
            if sp > tool * (1.0 + 1e-9) {
                return Err(OptionsError::new(
                    "lane_spacing_m",
                    format!(
                        "lane spacing {} m is wider than the tool (2 r_tool = {} m): the lanes would leave strips unswept",
                        fmt_m(sp),
                        fmt_m(tool)
                    ),
                ));
            }
        }
        Ok(())
    }

    fn check(&self, s: &Setup) -> Result<(), OptionsError> {
        self.check_unplaced(&s.robot, s.noisy)?;
        if let Some(sp) = self.lane_spacing_m {
            // Lanes lie on pixel lines: a finer spacing ran as one pixel (0.05 and 0.02 m on a
            // 0.05 m map gave the same plan).
            let res = s.frame.resolution;
            if sp < res * (1.0 - 1e-9) {
                return Err(OptionsError::new(
                    "lane_spacing_m",
                    format!(
                        "lane spacing {} m is finer than the map's pixel ({} m): the lanes lie on its pixel lines",
                        crate::display::Compact(sp),
                        fmt_m(res)
                    ),
                ));
            }
        }
        Ok(())
    }

    fn estimate(&self, s: &Setup) -> ResourceEstimate {
        let sp = self.lane_spacing_m.unwrap_or(2.0 * s.robot.tool_radius);
        // Lane pieces and their waypoints: at most one per lane-spacing square of the frame.
        let mut e = ResourceEstimate::units(s.tiles(sp), TILE_BYTES / 2.0, "lane squares")
            .remedy("a larger tool radius or bcd.lane_spacing_m");
        e.detail = format!("{} of {} m", e.detail, fmt_m(sp));
        // The plans' own pixel-sized state, part of it once per plan made at the same time.
        let jobs = self
            .plans_at_a_time
            .map_or_else(rayon::current_num_threads, |n| n as usize)
            .clamp(1, BCD_MAX_JOBS);
        let per_px = BCD_PIXEL_BYTES + BCD_JOB_PIXEL_BYTES * jobs as f64;
        // (one plan at a time is a remedy only where more run at once: at 1 it was offered
        // as the way out of a refusal that already counted 1: hostile pass)
        let remedy = if jobs > 1 {
            format!("{PIXELS_REMEDY}, or one plan at a time (bcd.plans_at_a_time: 1)")
        } else {
            PIXELS_REMEDY.to_string()
        };
        let mut px = ResourceEstimate::units(s.pixels(), per_px, "map pixels").remedy(&remedy);
        px.detail = format!(
            "{}, {jobs} plan{} at a time",
            px.detail,
            if jobs == 1 { "" } else { "s" }
        );
        if px.bytes > e.bytes {
            px.bytes += e.bytes;
            px
        } else {
            e.bytes += px.bytes;
            e
        }
    }

    fn tile_side(&self, _: &Robot) -> Option<f64> {
        None
    }

    fn build(&self, world: &World) -> Box<dyn Planner> {
        Box::new(Bcd::new(world, self))
    }

    fn build_until(&self, world: &World, stop: &AtomicBool) -> Box<dyn Planner> {
        Box::new(Bcd::new_until(world, self, stop))
    }
}

impl RectOptions {
    /// What a simulated run refuses and a plan does not: lanes farther apart than the tool
    /// of `robot` sweeps. A run measures coverage with the disk tool, so each lane would
    /// leave a strip unswept: a 0.6 m wide robot with the default 0.15 m tool swept 54 % of
    /// the floor while `rect_guarantee` promised all of it. (A plan has no tool: the
    /// rectangle is the robot, and its radius only the clearance kept.)
    ///
    /// # Errors
    /// `width_m` wider than `2 tool_radius`.
    pub fn check_tool(&self, robot: &Robot) -> Result<(), OptionsError> {
        if let Some(b) = self.width_m {
            let tool = 2.0 * robot.tool_radius;
            if b > tool * (1.0 + 1e-9) {
                return Err(OptionsError::new(
                    "width_m",
                    format!(
                        "{} m lanes are farther apart than the tool sweeps in a run ({} m, 2 x tool radius): every lane would leave a strip unswept; give a tool radius of half the width (and a robot radius at least that), or a width of at most {} m",
                        crate::display::Compact(b),
                        crate::display::Compact(tool),
                        crate::display::Compact(tool)
                    ),
                ));
            }
        }
        Ok(())
    }
}

impl PlannerSettings for RectOptions {
    fn validate(&self) -> Result<(), OptionsError> {
        opt_finite_pos("length_m", self.length_m)?;
        opt_finite_pos("width_m", self.width_m)?;
        opt_finite_pos("clearance_radius_m", self.clearance_radius_m)?;
        if let Some(a) = self.area {
            if a.iter().any(|v| !v.is_finite()) || a[2] <= a[0] || a[3] <= a[1] {
                return Err(OptionsError::new(
                    "area",
                    format!(
                        "must be finite X0,Y0,X1,Y1 with X1 > X0 and Y1 > Y0, got {}",
                        crate::display::join(&a)
                    ),
                ));
            }
        }
        validate_execution("exec", &self.exec)?;
        noise_that_draws("exec", &self.exec)
    }

    fn check_unplaced(&self, robot: &Robot, noisy: bool) -> Result<(), OptionsError> {
        bumper_reaction_applies(
            self.bumper_reaction,
            noisy,
            "`ccpp run` with --odometry-noise (Python: `run` with odometry_noise=), or with rect_boustrophedon.exec.pid.noise (also in `ccpp bench`)",
        )?;
        // The lanes are planned for at least the robot's own disk: a smaller clearance was
        // raised to the radius in silence (0.1 m, 0.01 m and 0.15 m gave the same run), while
        // run.json recorded the value given.
        if let Some(c) = self.clearance_radius_m {
            if c < robot.radius {
                return Err(OptionsError::new(
                    "clearance_radius_m",
                    format!(
                        "{} m is below the robot radius {} m: the lanes keep at least the robot's own clearance (leave it out, or give at least the radius)",
                        crate::display::Compact(c),
                        crate::display::Compact(robot.radius)
                    ),
                ));
            }
        }
        Ok(())
    }

    fn check(&self, s: &Setup) -> Result<(), OptionsError> {
        self.check_unplaced(&s.robot, s.noisy)?;
        let res = s.frame.resolution;
        let (w, h) = (s.frame.width_m(), s.frame.height_m());
        for (f, given, v) in [
            ("length_m", self.length_m, self.length_for(&s.robot)),
            ("width_m", self.width_m, self.width_for(&s.robot)),
        ] {
            // A default follows the tool: the message says so (the user gave no such field).
            let f = if given.is_some() {
                f.to_string()
            } else {
                format!("{f} (not given: the tool's width, 2 x tool radius)")
            };
            // A robot longer or wider than the map fits nowhere: its lanes would be empty (an
            // empty waypoint list) or its estimate absurd.
            if v > w.max(h) {
                return Err(OptionsError::new(
                    &f,
                    format!(
                        "{} m is larger than the map ({} x {} m): the robot fits nowhere",
                        crate::display::Compact(v),
                        fmt_m(w),
                        fmt_m(h)
                    ),
                ));
            }
            if v < res {
                return Err(OptionsError::new(
                    &f,
                    format!(
                        "{} m is finer than the map resolution ({} m/px)",
                        crate::display::Compact(v),
                        crate::display::Compact(res)
                    ),
                ));
            }
        }
        if let Some(a) = self.area {
            let (lo, hi) = s.frame.world_bounds();
            if a[2] <= lo.x || a[0] >= hi.x || a[3] <= lo.y || a[1] >= hi.y {
                return Err(OptionsError::new(
                    "area",
                    format!(
                        "{} lies outside the map ({} to {})",
                        crate::display::join(&a),
                        crate::display::join(&[lo.x, lo.y]),
                        crate::display::join(&[hi.x, hi.y])
                    ),
                ));
            }
            // A lane rectangle narrower than a pixel: its edges' lanes and stops lie within one
            // pixel of each other (`1,1,1.0000001,1.0000001` gave four waypoints 0.1 um apart:
            // hostile pass).
            let (aw, ah) = (a[2] - a[0], a[3] - a[1]);
            if aw.min(ah) < res {
                return Err(OptionsError::new(
                    "area",
                    format!(
                        "{} is {} x {} m, narrower than a map pixel ({} m): its lanes and stops would lie within one pixel of each other",
                        crate::display::join(&a),
                        fmt_m(aw),
                        fmt_m(ah),
                        crate::display::Compact(res)
                    ),
                ));
            }
        }
        Ok(())
    }

    fn check_world(&self, world: &World) -> Result<(), OptionsError> {
        super::rect_boustrophedon::check(world, self)
    }

    fn estimate(&self, s: &Setup) -> ResourceEstimate {
        let (lo, hi) = s.frame.world_bounds();
        let (mut w, mut h) = (hi.x - lo.x, hi.y - lo.y);
        if let Some(a) = self.area {
            w = w.min(a[2] - a[0]);
            h = h.min(a[3] - a[1]);
        }
        let (length, width) = (self.length_for(&s.robot), self.width_for(&s.robot));
        let n = (w / width + 2.0) * (h / length + 2.0);
        let mut e = ResourceEstimate::units(n, RECORD_BYTES, "waypoints")
            .remedy("a larger robot length and width, or a smaller area");
        // A move a waypoint, at most a lane's length each.
        add_pid_records(&mut e, &self.exec, n, length);
        e
    }

    fn tile_side(&self, _: &Robot) -> Option<f64> {
        None
    }

    fn start_radius(&self, robot: &Robot) -> f64 {
        self.clearance_radius(robot)
    }

    fn preferred_execution(&self) -> Option<Execution> {
        Some(self.exec)
    }

    fn build(&self, world: &World) -> Box<dyn Planner> {
        Box::new(RectBoustrophedon::new(world, self))
    }

    fn build_until(&self, world: &World, stop: &AtomicBool) -> Box<dyn Planner> {
        Box::new(RectBoustrophedon::new_until(world, self, Some(stop)))
    }
}

/// The memory a run needs: the per-pixel part, the metrics' tile sets and the planner's share;
/// the detail names the largest part.
pub fn estimate_run(s: &Setup, planner: &dyn PlannerSettings) -> ResourceEstimate {
    estimate_with(s, planner.estimate(s), planner.tile_side(&s.robot))
}

/// [`estimate_run`] of a robot its caller drives (Python's step API): the world, the sweep
/// and the metrics' tiles, no planner's own state.
pub fn estimate_driven(s: &Setup) -> ResourceEstimate {
    let none = ResourceEstimate {
        bytes: 0.0,
        detail: "no planner".into(),
        remedy: GENERIC_REMEDY.into(),
    };
    estimate_with(s, none, None)
}

/// A run's estimate from its planner's own part `own` and its tile side, if it has tiles: the
/// metrics hold the revisit tiles (side `2 r`) and, for a tile planner, its tiles for the tile
/// coverage.
fn estimate_with(s: &Setup, own: ResourceEstimate, tile_side: Option<f64>) -> ResourceEstimate {
    let revisit_side = 2.0 * s.robot.radius;
    let count = s.tiles(revisit_side) + tile_side.map_or(0.0, |side| s.tiles(side));
    let sides = match tile_side {
        Some(side) if side != revisit_side => {
            format!("{} and {}", fmt_m(revisit_side), fmt_m(side))
        }
        _ => fmt_m(revisit_side),
    };
    let mut metric_tiles =
        ResourceEstimate::units(count, 1.0 / 8.0, "tiles").remedy("a larger robot, tool or tile");
    metric_tiles.detail = format!("{} of {sides} m for the metrics", metric_tiles.detail);
    let pixels =
        ResourceEstimate::units(s.pixels(), PIXEL_BYTES, "map pixels").remedy(PIXELS_REMEDY);
    let bytes = own.bytes + metric_tiles.bytes + pixels.bytes + PROCESS_BYTES;
    let mut parts = [own, metric_tiles, pixels];
    parts.sort_by(|a, b| b.bytes.total_cmp(&a.bytes));
    let [largest, _, _] = parts;
    // The process's own part is named but never the advice: nothing shrinks it.
    ResourceEstimate {
        bytes,
        detail: format!(
            "{}; {} MB for the process itself",
            largest.detail,
            PROCESS_BYTES / MIB
        ),
        remedy: largest.remedy,
    }
}

/// Bytes a run's process holds whatever its map and planner: code, the thread pools, the
/// output writers' buffers and the PNG encoder. Measured with `/usr/bin/time -v` on
/// `ccpp run --planner ba-star` on `teb_empty_box` (a 3 k-pixel map): 14 MiB peak; `ccpp info`
/// alone peaks at 7 MiB. Counted in every run's estimate, so a limit below it is refused
/// instead of being beaten by the process itself.
pub const PROCESS_BYTES: f64 = 16.0 * MIB;

const MIB: f64 = 1024.0 * 1024.0;

/// Bytes per map pixel that zones add to any run with an area or keep-outs: the area and
/// keep-out bitsets, the planning map with its virtual walls (a second grid) and its blocked
/// bitset, and the distance transform of the true map when the zones leave no room.
pub const ZONE_PIXEL_BYTES: f64 = 8.0;
/// Bytes per map pixel of the approach to an area from a start outside it: the distance
/// transform with keep-outs, Dijkstra distances, parents and heap entries.
pub const APPROACH_PIXEL_BYTES: f64 = 64.0;
/// Bytes per map pixel of each keep-out file that may be a Nav2 mask (decoded image, its grid
/// and its bitset; a mask has the map's size).
pub const MASK_PIXEL_BYTES: f64 = 12.0;

/// What a run's zones will hold, as known before any zone file is read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ZoneLoad {
    /// An area or at least one keep-out is given.
    pub any: bool,
    /// An area and an explicit start: the start may be outside the area and need an approach.
    pub approach: bool,
    /// Keep-out files (each may be a map-sized Nav2 mask).
    pub mask_files: usize,
}

/// The memory zones add to a run (0 bytes without zones).
pub fn estimate_zones(s: &Setup, z: ZoneLoad) -> ResourceEstimate {
    if !z.any {
        return ResourceEstimate {
            bytes: 0.0,
            detail: String::new(),
            remedy: String::new(),
        };
    }
    let mut per_px = ZONE_PIXEL_BYTES + MASK_PIXEL_BYTES * z.mask_files as f64;
    if z.approach {
        per_px += APPROACH_PIXEL_BYTES;
    }
    let mut e = ResourceEstimate::units(s.pixels(), per_px, "map pixels").remedy(PIXELS_REMEDY);
    e.detail = format!("{} for the zones", e.detail);
    e
}

/// A length in metres, at most 6 significant digits (`0.45`, `2e-9`).
pub fn fmt_m(v: f64) -> String {
    if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e7) {
        format!("{v:.3e}")
    } else {
        let s = format!("{v:.6}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn apartment() -> Setup {
        // `apartment_400x300` at `--radius 0.05` (cells of 0.1 m).
        Setup {
            frame: MapFrame::new(400, 300, 0.05),
            robot: Robot::new(0.05),
            sensor_range: 1.0,
            max_steps: crate::sim::SimConfig::default().max_steps,
            noisy: false,
        }
    }

    /// The registry's `range_matters` and the settings' `sensor_need` say the same thing twice
    /// (the CLI and Python refuse a range by the first, the scenario sizes the sensor by the
    /// second): an online planner has a sensor need exactly when its range does not matter.
    #[test]
    fn range_matters_and_sensor_need_agree() {
        let s = apartment();
        let all = super::super::PlannerOptions::default();
        for &kind in super::super::PlannerKind::ALL {
            let info = kind.info();
            let need = all.config(kind).settings().sensor_need(&s);
            assert_eq!(
                need.is_some(),
                !info.offline && !info.range_matters,
                "{}",
                info.name
            );
            assert_eq!(kind.sensor_range_refusal().is_none(), info.range_matters);
        }
    }

    /// Random-bounce's strides are steps: a budget beyond the run's step cap is estimated at
    /// the cap (1e12 m with a cap of 1000 steps was refused as 1e9 MB).
    #[test]
    fn random_bounce_estimate_stops_at_the_step_cap() {
        let opts = RandomBounceOptions {
            budget_m: Some(1e12),
            ..RandomBounceOptions::default()
        };
        let wide = apartment();
        let capped = Setup {
            max_steps: 1000,
            ..apartment()
        };
        let stride = bounce_stride(&capped);
        assert_eq!(opts.path_estimate(&capped), (1000.0 * stride, stride));
        assert!(
            opts.estimate(&capped).bytes < 1e6,
            "{}",
            opts.estimate(&capped).bytes
        );
        // At the default cap (5e7 steps) still gigabytes: refused under the default limit.
        assert!(opts.estimate(&wide).bytes > 4096.0 * 1024.0 * 1024.0);
        // Below the cap the budget is what counts.
        let small = RandomBounceOptions {
            budget_m: Some(10.0),
            ..RandomBounceOptions::default()
        };
        assert_eq!(small.path_estimate(&capped).0, 10.0);
    }

    /// BA*'s recorded backtracking lists are counted up to their bound in all, not only per
    /// tile: with tiles of a pixel (`cluttered_2000` at r = 0.025 m, 4 million tiles) the
    /// per-tile bound alone was 2 GB of a 4570 MB estimate, for a run that peaks at 83 MiB.
    #[test]
    fn ba_star_lists_are_estimated_within_their_bound_in_all() {
        let s = Setup {
            frame: MapFrame::new(2000, 2000, 0.05),
            robot: Robot::new(0.025),
            sensor_range: 1.0,
            max_steps: crate::sim::SimConfig::default().max_steps,
            noisy: false,
        };
        let with = BaStarOptions::default();
        let without = BaStarOptions {
            record_backtrack_list: false,
            ..BaStarOptions::default()
        };
        let lists = with.estimate(&s).bytes - without.estimate(&s).bytes;
        let bound = 16.0 * crate::planners::ba_star::LIST_POINTS_MAX as f64;
        assert!(lists > 0.0 && lists <= bound, "{lists}");
        assert!(
            with.estimate(&s).bytes < 3000.0 * MIB,
            "{}",
            with.estimate(&s).bytes
        );
        // A small map's lists stay at the bound per tile.
        let small = apartment();
        let per_tile = 16.0 * crate::planners::ba_star::LIST_POINTS_PER_TILE as f64;
        let lists = with.estimate(&small).bytes - without.estimate(&small).bytes;
        assert!((lists - per_tile * small.tiles(0.1)).abs() < 1.0, "{lists}");
    }

    #[test]
    fn bsa_bfs_estimate_counts_the_pid_records_a_run_makes() {
        let s = apartment();
        let o = BsaBfsOptions::default();
        assert!(matches!(o.exec, Execution::Pid(_)));
        let e = o.estimate(&s);
        // Measured (`ccpp run --planner bsa-bfs --radius 0.05`): 906 424 trace records with
        // every step kept, peak resident memory 81 MB of which 8 MB are the map's pixels
        // ([`PIXEL_BYTES`]); 65 092 records and 25 MiB with the glides dropped.
        let moves = s.frame_area_m2() / 0.01;
        let every = pid_records(&o.exec, moves, 0.1, false);
        assert!(every >= 906_424.0, "{every}");
        let glides = pid_records(&o.exec, moves, 0.1, true);
        assert!((65_092.0..every / 3.0).contains(&glides), "{glides}");
        assert!(
            e.bytes + s.pixels() * PIXEL_BYTES >= 25.0 * 1024.0 * 1024.0,
            "{}",
            e.bytes
        );
        assert!(e.detail.contains("PID trace records"), "{}", e.detail);
        assert!(e.remedy.contains("record_every"), "{}", e.remedy);
        // Under odometry noise (the planner's own or the run's) every step is kept.
        let noisy = Setup {
            noisy: true,
            ..apartment()
        };
        assert!(o.estimate(&noisy).bytes - e.bytes >= (every - glides) * PID_RECORD_BYTES * 0.99);
        let own_noise = BsaBfsOptions {
            exec: Execution::Pid(PidOptions {
                noise: Some(crate::exec::OdometryNoise::default()),
                ..PidOptions::default()
            }),
            ..BsaBfsOptions::default()
        };
        assert_eq!(own_noise.estimate(&s).bytes, o.estimate(&noisy).bytes);
        // Fewer records kept, less memory; none under ideal execution.
        let sparse = BsaBfsOptions {
            exec: Execution::Pid(PidOptions {
                record_every: 10,
                ..PidOptions::default()
            }),
            ..BsaBfsOptions::default()
        };
        assert!(sparse.estimate(&s).bytes < e.bytes / 2.0);
        let ideal = BsaBfsOptions {
            exec: Execution::Ideal,
            ..BsaBfsOptions::default()
        };
        let i = ideal.estimate(&s);
        assert!(i.bytes < e.bytes / 3.0, "{} {}", i.bytes, e.bytes);
        assert!(!i.detail.contains("PID"), "{}", i.detail);
    }
}
