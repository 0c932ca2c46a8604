//! A validated run: map + robot + planner + settings, and its execution.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use ccpp_core::exec::{Execution, OdometryNoise, PidOptions};
use ccpp_core::metrics::{self, Metrics};
use ccpp_core::planners::bsa::Side;
use ccpp_core::planners::{self, PlannerOptions};
use ccpp_core::sim::{simulate, RunOutput, SimConfig};
use ccpp_core::world::{Robot, World};
use ccpp_core::{GridMap, Pose};
use ccpp_io::map::{load_map, load_map_bytes, LoadOptions};

use crate::args::{DemoArgs, MapArgs, RobotArgs, RunArgs};

/// The planner `ccpp demo` runs.
pub const FLAGSHIP: &str = "ba-star";

const DEMO_YAML: &str = include_str!("../assets/aws_small_house.yaml");
const DEMO_IMAGE: &[u8] = include_bytes!("../assets/aws_small_house.pgm");

/// A map ready for planning, with the name used in reports.
#[derive(Clone)]
pub struct PreparedMap {
    /// The (possibly inflated) grid.
    pub grid: GridMap,
    /// Short name (file stem).
    pub name: String,
    /// Where it came from, for messages.
    pub source: PathBuf,
    /// How to load it again (for `ccpp replay`).
    pub recipe: MapRecipe,
}

/// How a prepared map was made: enough to rebuild it exactly.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct MapRecipe {
    /// Map file (absolute when it could be resolved); `None` for the bundled demo map.
    pub path: Option<PathBuf>,
    /// Resolution override.
    pub resolution: Option<f64>,
    /// Origin override.
    pub origin: Option<[f64; 3]>,
    /// `occupied_thresh` override.
    pub occupied_thresh: Option<f64>,
    /// `free_thresh` override.
    pub free_thresh: Option<f64>,
    /// Obstacle inflation in metres.
    pub inflate: Option<f64>,
    /// Georeference point-pair file.
    pub georef: Option<PathBuf>,
}

impl MapRecipe {
    /// Loads and prepares the map again.
    pub fn prepare(&self) -> Result<PreparedMap> {
        match &self.path {
            None => demo_map(),
            Some(p) => prepare_map(&MapArgs {
                map: p.clone(),
                resolution: self.resolution,
                origin: self.origin,
                occupied_thresh: self.occupied_thresh,
                free_thresh: self.free_thresh,
                inflate: self.inflate,
                georef: self.georef.clone(),
            }),
        }
    }
}

/// Places `grid` by the affine fit of the point pairs in `path` (pixel coordinates from the
/// image's top-left corner, y down). ccpp frames are similarities (rotation + uniform scale),
/// so a fit with more than 1 % shear or anisotropy is refused.
pub fn apply_georef(grid: GridMap, path: &Path) -> Result<GridMap> {
    let fit = ccpp_io::georef::load_georef(path)
        .map_err(|e| anyhow::anyhow!("georef {}: {e}", path.display()))?;
    let [a, b, c, d] = fit.affine.m;
    let res = (a * d - b * c).abs().sqrt();
    if !(res.is_finite() && res > 0.0) {
        bail!("georef {}: degenerate transform", path.display());
    }
    let yaw = c.atan2(a);
    // Pixel y grows downwards, so the second column is res * (sin yaw, -cos yaw).
    let (sy, cy) = yaw.sin_cos();
    let dev = ((a - res * cy).powi(2)
        + (c - res * sy).powi(2)
        + (b - res * sy).powi(2)
        + (d + res * cy).powi(2))
    .sqrt()
        / res;
    if dev > 0.01 {
        bail!(
            "georef {}: the fitted transform has {:.1} % shear or anisotropy; ccpp needs rotation + uniform scale",
            path.display(),
            100.0 * dev
        );
    }
    let h = grid.frame().height as f64;
    let o = fit.affine.apply(ccpp_core::Point::new(0.0, h));
    Ok(grid.with_placement(res, Pose::new(o.x, o.y, yaw))?)
}

/// The bundled demo map.
pub fn demo_map() -> Result<PreparedMap> {
    let name = Path::new("aws_small_house.yaml");
    let loaded = load_map_bytes(name, Some(DEMO_YAML), DEMO_IMAGE, &LoadOptions::default())
        .context("bundled demo map")?;
    finish_map(
        loaded.grid,
        "aws_small_house".into(),
        name.into(),
        None,
        MapRecipe::default(),
    )
}

/// Everything a run needs, validated.
pub struct Job {
    /// The map.
    pub map: PreparedMap,
    /// The robot.
    pub robot: Robot,
    /// Start pose (None = default start).
    pub start: Option<Pose>,
    /// Planner name.
    pub planner: String,
    /// Planner options.
    pub options: PlannerOptions,
    /// Simulator settings.
    pub sim: SimConfig,
    /// Output folder.
    pub out: PathBuf,
}

/// A finished run.
pub struct JobResult {
    /// The truth it ran on.
    pub world: World,
    /// Trace and timing.
    pub run: RunOutput,
    /// The metrics.
    pub metrics: Metrics,
}

fn check_metres(name: &str, v: f64) -> Result<()> {
    if !v.is_finite() || v <= 0.0 {
        bail!("{name} must be a finite number > 0 m, got {v}");
    }
    Ok(())
}

/// Loads and prepares the map of `args` (validating overrides and inflation).
pub fn prepare_map(args: &MapArgs) -> Result<PreparedMap> {
    let opts = LoadOptions {
        resolution: args.resolution,
        origin: args.origin,
        occupied_thresh: args.occupied_thresh,
        free_thresh: args.free_thresh,
        negate: None,
    };
    let mut loaded = load_map(&args.map, &opts)?;
    if let Some(g) = &args.georef {
        loaded.grid = apply_georef(loaded.grid, g)?;
    }
    let name = args
        .map
        .file_stem()
        .map_or_else(|| "map".to_string(), |s| s.to_string_lossy().into_owned());
    let recipe = MapRecipe {
        path: Some(std::fs::canonicalize(&args.map).unwrap_or_else(|_| args.map.clone())),
        resolution: args.resolution,
        origin: args.origin,
        occupied_thresh: args.occupied_thresh,
        free_thresh: args.free_thresh,
        inflate: args.inflate,
        georef: args
            .georef
            .as_ref()
            .map(|g| std::fs::canonicalize(g).unwrap_or_else(|_| g.clone())),
    };
    finish_map(loaded.grid, name, loaded.source, args.inflate, recipe)
}

fn finish_map(
    grid: GridMap,
    name: String,
    source: PathBuf,
    inflate: Option<f64>,
    recipe: MapRecipe,
) -> Result<PreparedMap> {
    let grid = match inflate {
        None | Some(0.0) => grid,
        Some(m) => {
            check_metres("--inflate", m).with_context(|| format!("map {}", source.display()))?;
            ccpp_core::inflate::inflate(&grid, m)
        }
    };
    Ok(PreparedMap {
        grid,
        name,
        source,
        recipe,
    })
}

/// Validates the robot arguments.
pub fn robot_from(args: &RobotArgs) -> Result<(Robot, Option<Pose>)> {
    check_metres("--radius", args.radius)?;
    if let Some(t) = args.tool_radius {
        check_metres("--tool-radius", t)?;
    }
    let robot = Robot {
        radius: args.radius,
        tool_radius: args.tool_radius.unwrap_or(args.radius),
    };
    robot.validate()?;
    let start = args.start.map(|s| Pose::new(s[0], s[1], s[2]));
    Ok((robot, start))
}

/// Planner options from an optional YAML/JSON file, with `--seed` applied.
pub fn planner_options(config: Option<&Path>, seed: Option<u64>) -> Result<PlannerOptions> {
    let mut options = match config {
        Some(p) => read_options(p)?,
        None => PlannerOptions::default(),
    };
    if let Some(seed) = seed {
        options.random_bounce.seed = seed;
    }
    Ok(options)
}

/// Reads planner options from a YAML or JSON file.
pub fn read_options(path: &Path) -> Result<PlannerOptions> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read planner options {}", path.display()))?;
    let is_json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let opts: PlannerOptions = if is_json {
        serde_json::from_str(&text)
            .map_err(|e| anyhow::anyhow!("planner options {}: {e}", path.display()))?
    } else {
        serde_saphyr::from_str(&text)
            .map_err(|e| anyhow::anyhow!("planner options {}: {e}", path.display()))?
    };
    Ok(opts)
}

impl Job {
    /// A job from `ccpp run` arguments.
    pub fn from_run_args(a: &RunArgs) -> Result<Self> {
        if !planners::CATALOG.iter().any(|p| p.name == a.planner) {
            bail!(
                "unknown planner {:?}; run `ccpp planners` for the list",
                a.planner
            );
        }
        let (robot, start) = robot_from(&a.robot)?;
        if let Some(r) = a.sensor_range {
            check_metres("--sensor-range", r)?;
        }
        let mut options = planner_options(a.config.as_deref(), a.seed)?;
        if let Some(t) = a.tile_side {
            check_metres("--tile-side", t)?;
            options.ba_star.tile_side_m = Some(t);
        }
        if let Some(s) = a.smoothing {
            options.ba_star.smoothing = s;
        }
        if let Some(side) = &a.side {
            let side = match side.to_ascii_lowercase().as_str() {
                "left" => Side::Left,
                "right" => Side::Right,
                other => bail!("--side must be left or right, got {other:?}"),
            };
            options.bsa.side = side;
            options.bsa_extended.side = side;
        }
        if let Some(l) = a.length {
            check_metres("--length", l)?;
            options.rect_boustrophedon.length_m = l;
        }
        if let Some(w) = a.width {
            check_metres("--width", w)?;
            options.rect_boustrophedon.width_m = w;
        }
        if a.area.is_some() {
            options.rect_boustrophedon.area = a.area;
        }
        let mut sim = SimConfig {
            sensor_range: a.sensor_range,
            ..SimConfig::default()
        };
        let mut pid = PidOptions::default();
        if let Some(n) = &a.odometry_noise {
            let v: Vec<f64> = n
                .split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| anyhow::anyhow!("--odometry-noise expects LIN[,ANG], got {n:?}"))?;
            if v.is_empty() || v.len() > 2 || v.iter().any(|x| !x.is_finite() || *x < 0.0) {
                bail!("--odometry-noise expects one or two finite numbers >= 0, got {n:?}");
            }
            pid.noise = Some(OdometryNoise {
                seed: a.seed.unwrap_or(0),
                linear_rel_std: v[0],
                angular_rel_std: v.get(1).copied().unwrap_or(v[0]),
                ..OdometryNoise::default()
            });
        }
        sim.exec = match a.exec.as_deref().map(str::to_ascii_lowercase).as_deref() {
            None if pid.noise.is_some() => Some(Execution::Pid(pid)),
            None => None,
            Some("ideal") => {
                if pid.noise.is_some() {
                    bail!("--odometry-noise needs --exec pid");
                }
                Some(Execution::Ideal)
            }
            Some("pid") => Some(Execution::Pid(pid)),
            Some(other) => bail!("--exec must be ideal or pid, got {other:?}"),
        };
        if let Some(p) = &a.landmarks {
            sim.landmarks.landmarks = ccpp_io::landmarks::load_landmarks(p)
                .map_err(|e| anyhow::anyhow!("landmarks {}: {e}", p.display()))?;
        }
        let map = prepare_map(&a.map)?;
        Ok(Self {
            map,
            robot,
            start,
            planner: a.planner.clone(),
            options,
            sim: SimConfig {
                sensor_range: a.sensor_range,
                ..SimConfig::default()
            },
            out: a.out.clone(),
        })
    }

    /// The demo job: the flagship planner on the bundled map.
    pub fn demo(a: &DemoArgs) -> Result<Self> {
        let map = demo_map()?;
        let planner = a.planner.clone().unwrap_or_else(|| FLAGSHIP.to_string());
        if !planners::CATALOG.iter().any(|p| p.name == planner) {
            bail!("unknown planner {planner:?}; run `ccpp planners` for the list");
        }
        Ok(Self {
            map,
            robot: Robot::new(0.15),
            start: None,
            planner,
            options: PlannerOptions::default(),
            sim: SimConfig::default(),
            out: a.out.clone(),
        })
    }

    /// Builds the world, runs the planner in the simulator and computes the metrics.
    pub fn execute(&self) -> Result<JobResult> {
        let world = World::new(self.map.grid.clone(), self.robot, self.start)
            .with_context(|| format!("map {}", self.map.source.display()))?;
        // Wall time covers planning (offline planners plan in `build`) and simulation.
        let started = std::time::Instant::now();
        let mut planner = planners::build(&self.planner, &self.options, &world)?;
        let mut run = simulate(&world, planner.as_mut(), &self.sim);
        run.wall_time_s = started.elapsed().as_secs_f64();
        let metrics = metrics::compute(&world, &run, &self.map.name);
        Ok(JobResult {
            world,
            run,
            metrics,
        })
    }
}
