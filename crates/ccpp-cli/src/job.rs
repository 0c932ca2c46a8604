//! From command-line flags to a [`Scenario`] (the library's run description, validated in one
//! place), and its execution. This module only maps flags to scenario fields and says which
//! flags apply to which planner; every value check lives in `ccpp_io::scenario` and the
//! planners' `PlannerSettings`.

use std::fmt::Display;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use ccpp_core::exec::{Execution, PidOptions};
use ccpp_core::metrics::Metrics;
use ccpp_core::planners::bsa::Side;
use ccpp_core::planners::random_bounce::RandomBounceOptions;
use ccpp_core::planners::{PlannerConfig, PlannerKind, PlannerOptions};
use ccpp_core::sim::{RunOutput, SimConfig};
use ccpp_core::world::{Robot, World};
use ccpp_core::Pose;
use ccpp_io::execution::{exec_choice, execution, ExecAsk, Names};
use ccpp_io::map::{load_map_bytes, LoadOptions};
use ccpp_io::scenario::{Scenario, ScenarioError};

pub use ccpp_io::scenario::{MapRecipe, PreparedMap};

use crate::args::{DemoArgs, MapArgs, RobotArgs, RunArgs};

/// The planner `ccpp demo` runs.
pub const FLAGSHIP: PlannerKind = PlannerKind::BaStarExtended;

const DEMO_YAML: &str = include_str!("../assets/aws_small_house.yaml");
const DEMO_IMAGE: &[u8] = include_bytes!("../assets/aws_small_house.pgm");
const DEMO_NAME: &str = "aws_small_house";

/// The bundled demo map, prepared by `recipe` (which has no path).
pub fn demo_map_with(recipe: &MapRecipe) -> Result<PreparedMap> {
    let name = Path::new("aws_small_house.yaml");
    let loaded = load_map_bytes(name, Some(DEMO_YAML), DEMO_IMAGE, &LoadOptions::default())
        .context("bundled demo map")?;
    Ok(recipe.prepare(loaded)?)
}

/// The recipe of the bundled demo map.
pub fn demo_recipe() -> MapRecipe {
    MapRecipe {
        name: Some(DEMO_NAME.to_string()),
        ..MapRecipe::default()
    }
}

/// Loads the map of `recipe`: its file (refused from its header when its pixels alone would
/// need more than `max_memory_mb`), or the bundled demo map when it names none.
pub fn load_recipe(recipe: &MapRecipe, max_memory_mb: u64) -> Result<PreparedMap> {
    if recipe.path.is_none() {
        return demo_map_with(recipe);
    }
    Ok(recipe.load_within(max_memory_mb)?)
}

/// Everything a run needs, validated.
pub struct Job {
    /// What to run (`run.json` is this, serialized).
    pub scenario: Scenario,
    /// The map, loaded and prepared; [`Job::execute`] moves it into the world (`None` after).
    pub map: Option<PreparedMap>,
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
    /// The pixels the tool swept (computed with the metrics, reused by the picture).
    pub swept: fixedbitset::FixedBitSet,
    /// The free area holding the start, when [`Job::execute_with`] was asked for it (found
    /// while the planner worked).
    pub start_area: Option<crate::components::StartComponent>,
    /// `path.csv`, formed while the run went on (`None`: form it from the trace).
    pub formed: Option<ccpp_io::trace::FormedFiles>,
}

impl JobResult {
    /// The note telling the user that the start lies outside the area and how far the robot
    /// drives to reach it first (`None` when it starts inside).
    pub fn approach_note(&self) -> Option<String> {
        approach_note(&self.world)
    }
}

/// The note telling the user that the start lies outside the area of `world` and how far the
/// robot drives to reach it first (`None` when it starts inside): `run` and `plan` print it.
pub fn approach_note(world: &World) -> Option<String> {
    ccpp_io::warnings::approach_note(world).map(|n| format!("note: {n}"))
}

/// The recipe of `args`: paths made absolute so that `run.json` works from any folder.
/// Symbolic links are kept, not resolved: a map YAML's image is looked up beside the path
/// given, as `map_server` does (a linked `la/m.yaml -> ../lb/m.yaml` reads `la/`'s image; it
/// read `lb/`'s).
pub fn recipe_from(args: &MapArgs) -> MapRecipe {
    let abs = |p: &PathBuf| std::path::absolute(p).unwrap_or_else(|_| p.clone());
    MapRecipe {
        path: Some(abs(&args.map)),
        name: Some(
            args.map
                .file_stem()
                .map_or_else(|| "map".to_string(), |s| s.to_string_lossy().into_owned()),
        ),
        resolution: args.resolution,
        origin: args.origin,
        occupied_thresh: args.occupied_thresh,
        free_thresh: args.free_thresh,
        inflate: args.inflate,
        georef: args.georef.as_ref().map(abs),
    }
}

/// Loads and prepares the map of `args` (validating overrides and inflation; an image whose
/// pixels alone would need more than `max_memory_mb` is refused from its header).
pub fn prepare_map(args: &MapArgs, max_memory_mb: u64) -> Result<PreparedMap> {
    Ok(recipe_from(args).load_within(max_memory_mb)?)
}

/// The robot radius when `--radius` is not given, metres.
pub const DEFAULT_RADIUS_M: f64 = 0.15;

/// The robot and start of `args`, validated by the library.
pub fn robot_from(args: &RobotArgs) -> Result<(Robot, Option<Pose>)> {
    let radius = args.radius.unwrap_or(DEFAULT_RADIUS_M);
    let robot = Robot {
        radius,
        tool_radius: args.tool_radius.unwrap_or(radius),
    };
    robot.validate()?;
    // Before `Pose::new` wraps it: a heading beyond two turns is a typo or degrees.
    if let Some(why) = args
        .start
        .and_then(|s| ccpp_io::map::heading_problem(s.pose[2]))
    {
        anyhow::bail!("--start THETA {why}");
    }
    let start = args
        .start
        .map(|s| Pose::new(s.pose[0], s.pose[1], s.pose[2]));
    Ok((robot, start))
}

/// Planner options from an optional YAML/JSON file (every section validated), with `--seed`
/// applied to the planners that use one.
pub fn planner_options(config: Option<&Path>, seed: Option<u64>) -> Result<PlannerOptions> {
    let mut options = match config {
        Some(p) => read_options(p)?,
        None => PlannerOptions::default(),
    };
    if let Some(seed) = seed {
        set_seed(&mut options.random_bounce, seed, config)?;
    }
    Ok(options)
}

/// The default options of every planner, or of the planners `names` (none or empty names:
/// all), as a `--config` YAML file: one section per planner, every field at its default.
///
/// # Errors
/// An unknown planner name.
pub fn default_options_yaml(names: &[String]) -> Result<String> {
    let all = names.len() == 1 && names[0].trim() == "all";
    // An empty name (`--defaults ''`, `--defaults bcd,`) names no planner: it printed every
    // one (hostile pass).
    if !all && names.iter().any(|n| n.trim().is_empty()) {
        bail!(
            "--defaults: an empty planner name in {:?}; name the planners (A,B,...), or give --defaults alone (or all) for every planner",
            names.join(",")
        );
    }
    // `all` means every planner only alone: beside names it is no planner (and the message
    // said just that: hostile pass).
    if !all && names.iter().any(|n| n.trim() == "all") {
        bail!(
            "--defaults: \"all\" stands alone (every planner); beside planner names in {:?} it names none: give the names, or all",
            names.join(",")
        );
    }
    let wanted = names
        .iter()
        .filter(|_| !all)
        .map(|n| parse_planner(n.trim()).map(|k| k.info().section))
        .collect::<Result<Vec<_>>>()?;
    // The typed options keep their fields in declaration order (documented order); a section
    // is a top-level key and the lines indented under it.
    let yaml = serde_saphyr::to_string(&PlannerOptions::default())?;
    // Every option is written out, so a flag that sets one of them (`--exec`, `--seed`,
    // `--odometry-noise`, `--tile-side`...) meets it in the file and is refused as setting it
    // twice: the header says so (a user took the file as a base for flags: hostile pass).
    let mut out = format!(
        "# ccpp {} planner options at their defaults: edit and pass with --config FILE\n\
         # (every option is set here: delete the lines of those you set by a flag instead)\n",
        env!("CARGO_PKG_VERSION")
    );
    let mut keep = wanted.is_empty();
    for line in yaml.lines() {
        if !line.starts_with(' ') {
            let key = line.split(':').next().unwrap_or_default();
            keep = wanted.is_empty() || wanted.contains(&key);
        }
        if keep {
            out.push_str(line);
            out.push('\n');
        }
    }
    Ok(out)
}

/// Reads planner options from a YAML or JSON file and validates every section.
pub fn read_options(path: &Path) -> Result<PlannerOptions> {
    let text = ccpp_io::file::read_text(path)
        .with_context(|| format!("cannot read planner options {}", path.display()))?;
    let is_json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    // A file with nothing in it — empty, comments only, `---`, `null` or `~` — gives no
    // option, as an empty file always did (`null` was refused as "expected mapping start", an
    // empty JSON file as "EOF while parsing").
    let blank = text
        .lines()
        .map(|l| l.split('#').next().unwrap_or("").trim())
        .all(|l| l.is_empty() || matches!(l, "---" | "..." | "null" | "~" | "Null" | "NULL"));
    if blank {
        return Ok(PlannerOptions::default());
    }
    let opts: PlannerOptions = ccpp_io::file::parse_yaml_or_json(&text, is_json)
        .map_err(|e| anyhow::anyhow!("planner options {}: {e}", path.display()))?;
    opts.validate()
        .map_err(|e| anyhow::anyhow!("planner options {}: {e}", path.display()))?;
    Ok(opts)
}

/// Warns (on stderr) when the options file `config` has no section for any of the planners
/// `kinds`: they run at their defaults, which a section for another planner (`ba_star:` for
/// `ba-star-extended`, whose BA* options are `ba_star_extended.ba_star`) suggests the user did
/// not mean. The file's sections for other planners are allowed (one file can serve a bench).
pub fn warn_unused_config(config: Option<&Path>, kinds: &[PlannerKind]) {
    let Some(f) = config else { return };
    // Read and parsed once for every planner.
    let value = file_value(f);
    if value
        .as_ref()
        .is_some_and(|v| kinds.iter().any(|k| value_sets(v, k.info().section)))
    {
        return;
    }
    let sections = value
        .and_then(|v| v.as_object().map(|o| o.keys().cloned().collect::<Vec<_>>()))
        .unwrap_or_default();
    let names: Vec<&str> = kinds.iter().map(|k| k.name()).collect();
    let wanted: Vec<&str> = kinds.iter().map(|k| k.info().section).collect();
    say!(
        "warning: {} has no section for {} ({}{}): {} at the planner defaults",
        f.display(),
        names.join(", "),
        wanted.join(", "),
        if sections.is_empty() {
            "; it has none".to_string()
        } else {
            format!("; it has {}", sections.join(", "))
        },
        if kinds.len() == 1 {
            "it runs"
        } else {
            "they run"
        }
    );
}

/// Parses a planner name.
pub fn parse_planner(name: &str) -> Result<PlannerKind> {
    Ok(name.parse::<PlannerKind>()?)
}

/// "`flag` does not apply to `planner`" with the planners it applies to.
fn not_applicable(flag: &str, kind: PlannerKind, applies_to: &str) -> anyhow::Error {
    anyhow::anyhow!("{flag} does not apply to {kind} (it applies to {applies_to})")
}

/// Which option each planner flag sets, for naming the flag in validation errors.
const FLAG_FIELDS: [(&str, &[&str]); 4] = [
    (
        "--tile-side",
        &[
            "ba_star.tile_side_m",
            "ba_star_extended.ba_star.tile_side_m",
            "bsa_bfs.cell_side_m",
        ],
    ),
    ("--length", &["rect_boustrophedon.length_m"]),
    ("--width", &["rect_boustrophedon.width_m"]),
    ("--sensor-range", &["sim.sensor_range"]),
];

/// "`flag` and `field` in the options file set the same option": the flag would replace the
/// file's value, read and validated, without a word.
fn clash(
    file: Option<&Path>,
    flag: &str,
    v: impl Display,
    field: &str,
    w: impl Display,
) -> anyhow::Error {
    anyhow::anyhow!(
        "{flag} {v} and {field}: {w} in {} set the same option; remove one of them",
        options_file(file)
    )
}

/// Whether the options file `file` gives the option at `path` (`ba_star.smoothing`), whatever
/// its value: a flag beside it replaces the file's value even where that value is the default
/// (the file `planners --defaults` prints gives every option). `false` without a file.
fn file_sets(file: Option<&Path>, path: &str) -> bool {
    file.and_then(file_value)
        .is_some_and(|v| value_sets(&v, path))
}

/// The options file `f` as a JSON value (`None` when it cannot be read or parsed: it was read
/// and validated already, so that means it was not given).
fn file_value(f: &Path) -> Option<serde_json::Value> {
    let text = ccpp_io::file::read_text(f).ok()?;
    let json = f
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    ccpp_io::file::parse_yaml_or_json::<serde_json::Value>(&text, json).ok()
}

/// Whether the parsed options file `v` gives the option at `path`, whatever its value.
fn value_sets(v: &serde_json::Value, path: &str) -> bool {
    path.split('.').try_fold(v, |v, k| v.get(k)).is_some()
}

/// `--seed` into random-bounce's options, refused beside a `random_bounce.seed` of another
/// value from the options file `file` (`run` and `bench` alike).
fn set_seed(o: &mut RandomBounceOptions, seed: u64, file: Option<&Path>) -> Result<()> {
    let file_seed = o.seed;
    if (file_seed != RandomBounceOptions::default().seed || file_sets(file, "random_bounce.seed"))
        && file_seed != seed
    {
        return Err(clash(file, "--seed", seed, "random_bounce.seed", file_seed));
    }
    o.seed = seed;
    // With the seed in place (one turn angle makes it change nothing): refused before any
    // run (in a bench it failed every random-bounce run after the others had run).
    ccpp_core::planners::PlannerSettings::validate(o)
        .map_err(|e| anyhow::anyhow!("--seed {seed}: random_bounce.{e}"))?;
    Ok(())
}

/// `--length` / `--width` into rect-boustrophedon's options (`run` and `plan` alike), refused
/// for other planners and beside a different value for the same option in `file`. Returns the
/// flags given.
pub(crate) fn apply_rect_flags(
    length: Option<f64>,
    width: Option<f64>,
    config: &mut PlannerConfig,
    file: Option<&Path>,
) -> Result<Vec<&'static str>> {
    let kind = config.kind();
    let mut given = Vec::new();
    for (flag, v) in [("--length", length), ("--width", width)] {
        let Some(v) = v else { continue };
        given.push(flag);
        let (slot, field) = match config {
            PlannerConfig::RectBoustrophedon(o) if flag == "--length" => {
                (&mut o.length_m, "rect_boustrophedon.length_m")
            }
            PlannerConfig::RectBoustrophedon(o) => (&mut o.width_m, "rect_boustrophedon.width_m"),
            _ => return Err(not_applicable(flag, kind, "rect-boustrophedon")),
        };
        // A value from the file (`null` too: the file `planners --defaults` prints gives it)
        // that the flag would replace.
        if slot.is_none_or(|w| w.to_bits() != v.to_bits())
            && (slot.is_some() || file_sets(file, field))
        {
            let w = slot.map_or_else(|| "null".to_string(), |w| w.to_string());
            return Err(clash(file, flag, v, field, w));
        }
        *slot = Some(v);
    }
    Ok(given)
}

/// Applies the planner flags of `a` to `config`, refusing flags the planner does not use and
/// flags that would replace a different value the options file gives for the same option.
fn apply_planner_flags(a: &RunArgs, config: &mut PlannerConfig) -> Result<Vec<&'static str>> {
    let kind = config.kind();
    let mut given = Vec::new();
    if let Some(t) = a.tile_side {
        given.push("--tile-side");
        let (slot, field) = match config {
            PlannerConfig::BaStar(o) => (&mut o.tile_side_m, "ba_star.tile_side_m"),
            PlannerConfig::BaStarExtended(o) => (
                &mut o.ba_star.tile_side_m,
                "ba_star_extended.ba_star.tile_side_m",
            ),
            PlannerConfig::BsaBfs(o) => (&mut o.cell_side_m, "bsa_bfs.cell_side_m"),
            _ => {
                return Err(not_applicable(
                    "--tile-side",
                    kind,
                    "ba-star, ba-star-extended, bsa-bfs",
                ))
            }
        };
        let file = a.options.config.as_deref();
        if slot.is_none_or(|w| w.to_bits() != t.to_bits()) && file_sets(file, field) {
            let w = slot.map_or_else(|| "null".to_string(), |w| w.to_string());
            return Err(clash(file, "--tile-side", t, field, w));
        }
        *slot = Some(t);
    }
    if let Some(s) = a.smoothing {
        let (slot, field) = match config {
            PlannerConfig::BaStar(o) => (&mut o.smoothing, "ba_star.smoothing"),
            PlannerConfig::BaStarExtended(o) => (
                &mut o.ba_star.smoothing,
                "ba_star_extended.ba_star.smoothing",
            ),
            _ => {
                return Err(not_applicable(
                    "--smoothing",
                    kind,
                    "ba-star, ba-star-extended",
                ))
            }
        };
        // The default is on: a file that turned it off and the flag that turns it on clash,
        // and so does a file that gives it at all beside a flag of the other value.
        let file = a.options.config.as_deref();
        if *slot != s && (!*slot || file_sets(file, field)) {
            return Err(clash(
                file,
                "--smoothing",
                if s { "on" } else { "off" },
                field,
                *slot,
            ));
        }
        *slot = s;
    }
    if let Some(side) = &a.side {
        let side = match side.to_ascii_lowercase().as_str() {
            "left" => Side::Left,
            "right" => Side::Right,
            other => bail!("--side must be left or right, got {other:?}"),
        };
        let (slot, field) = match config {
            PlannerConfig::Bsa(o) => (&mut o.side, "bsa.side"),
            PlannerConfig::BsaExtended(o) => (&mut o.side, "bsa_extended.side"),
            _ => return Err(not_applicable("--side", kind, "bsa, bsa-extended")),
        };
        if (*slot != Side::default() || file_sets(a.options.config.as_deref(), field))
            && *slot != side
        {
            return Err(clash(
                a.options.config.as_deref(),
                "--side",
                side.as_str(),
                field,
                slot.as_str(),
            ));
        }
        *slot = side;
    }
    given.extend(apply_rect_flags(
        a.length,
        a.width,
        config,
        a.options.config.as_deref(),
    )?);
    Ok(given)
}

/// The options file `file`, for messages.
fn options_file(file: Option<&Path>) -> String {
    file.map_or_else(
        || "the options file".to_string(),
        |p| p.display().to_string(),
    )
}

/// The simulator settings of `a` for `config` (execution, odometry noise, landmarks, sensor
/// range), refusing flags that do not apply.
fn sim_from(a: &RunArgs, config: &mut PlannerConfig) -> Result<SimConfig> {
    let kind = config.kind();
    let mut sim = SimConfig::default();
    if let Some(r) = a.sensor_range {
        if let Some(applies) = kind.sensor_range_refusal() {
            return Err(not_applicable("--sensor-range", kind, &applies));
        }
        sim.sensor_range = Some(r);
    }
    let exec = exec_choice(a.exec.as_deref(), &Names::FLAGS).map_err(anyhow::Error::msg)?;
    let preferred = config.settings().preferred_execution();
    let section = kind.info().section;
    let file = options_file(a.options.config.as_deref());
    // `--exec ideal` replaces the planner's execution: PID settings given for it in the
    // options file would be read, validated and then dropped, so the two are refused together.
    // A file that gives the planner's PID execution at all (its defaults too) clashes; one
    // that runs it ideally agrees.
    let own_pid = matches!(preferred, Some(Execution::Pid(p)) if p != PidOptions::default());
    let file_pid = matches!(preferred, Some(Execution::Pid(_)))
        && file_sets(a.options.config.as_deref(), &format!("{section}.exec"));
    let noise = match &a.odometry_noise {
        None => None,
        Some(n) => Some(
            n.split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<Result<Vec<_>, _>>()
                .map_err(|_| {
                    anyhow::anyhow!("--odometry-noise expects LIN[,ANG[,DRIFT]], got {n:?}")
                })?,
        ),
    };
    let ask = ExecAsk {
        pid: exec,
        noise,
        // random-bounce's seed, from the flag or its options file, also seeds the noise
        // (`--seed 7` and `random_bounce: { seed: 7 }` are the same option; hostile pass).
        seed: a.seed.or(config.seed()),
        // A file that gives the noise at all (`noise: null` too, as `planners --defaults`
        // prints it) clashes, as every other flag beside its option in the file does.
        noise_given_in: file_sets(
            a.options.config.as_deref(),
            &format!("{section}.exec.pid.noise"),
        )
        .then(|| format!("{file} ({section}.exec.pid.noise)")),
        pid_given_in: (own_pid || file_pid).then(|| format!("{file} ({section}.exec)")),
    };
    sim.exec = execution(kind, preferred, &ask, &Names::FLAGS).map_err(anyhow::Error::msg)?;
    if let (Some(seed), PlannerConfig::RandomBounce(o)) = (a.seed, &mut *config) {
        set_seed(o, seed, a.options.config.as_deref())?;
    }
    if let Some(p) = &a.landmarks {
        sim.landmarks.landmarks = ccpp_io::landmarks::load_landmarks(p)
            .map_err(|e| anyhow::anyhow!("landmarks {}: {e}", p.display()))?;
    }
    Ok(sim)
}

/// Names the flag that set an invalid option (one of `given`), or that makes the run
/// degenerate on the map (`map FILE: PLANNER: --width: ...` instead of the option's field
/// `rect_boustrophedon.width_m`, which the user did not type).
pub(crate) fn name_flag(e: ScenarioError, given: &[&str]) -> anyhow::Error {
    let flagged = FLAG_FIELDS.iter().filter(|(flag, _)| given.contains(flag));
    match e {
        ScenarioError::Options(o) => {
            for (flag, fields) in flagged {
                if fields.contains(&o.field.as_str()) {
                    return anyhow::anyhow!("{flag}: {}", ScenarioError::Options(o));
                }
            }
            ScenarioError::Options(o).into()
        }
        ScenarioError::Degenerate {
            path,
            planner,
            message,
        } => {
            let named = flagged
                .flat_map(|(flag, fields)| fields.iter().map(move |f| (flag, f)))
                .find_map(|(flag, f)| {
                    let rest = message.strip_prefix(f)?.strip_prefix(": ")?;
                    Some(format!("{flag}: {rest}"))
                });
            let message = named.unwrap_or(message);
            ScenarioError::Degenerate {
                path,
                planner,
                message,
            }
            .into()
        }
        e => e.into(),
    }
}

/// Names the options file `config` in an error about a planner option it sets (section
/// `section`): a value fine on its own but wrong on this map (a budget shorter than a move, a
/// lane spacing finer than the pixels, a control period that stops every move) was reported
/// against the map alone, and the user had to guess which file held it.
pub(crate) fn naming_config(
    e: anyhow::Error,
    config: Option<&Path>,
    section: &str,
) -> anyhow::Error {
    let Some(f) = config else { return e };
    let msg = e.to_string();
    let shown = f.display().to_string();
    let Some(v) = file_value(f) else { return e };
    let about = (msg.contains(&format!("{section}.")) && value_sets(&v, section))
        || (msg.contains("exec.pid") && value_sets(&v, &format!("{section}.exec")));
    if about && !msg.contains(&shown) {
        anyhow::anyhow!("{msg} (set in planner options {shown})")
    } else {
        e
    }
}

impl Job {
    /// A job from `ccpp run` arguments.
    pub fn from_run_args(a: &RunArgs) -> Result<Self> {
        let kind = parse_planner(&a.planner)?;
        let (robot, start) = robot_from(&a.robot)?;
        let mut planner = planner_options(a.options.config.as_deref(), None)?.config(kind);
        warn_unused_config(a.options.config.as_deref(), &[kind]);
        let mut given = apply_planner_flags(a, &mut planner)?;
        let sim = sim_from(a, &mut planner)?;
        if a.sensor_range.is_some() {
            given.push("--sensor-range");
        }
        let scenario = Scenario::configure(recipe_from(&a.map), planner)
            .robot(robot)
            .start_pose(start.map(|p| [p.x, p.y, p.theta]))
            .sim(sim)
            .memory_limit(a.limits.max_memory)
            .zones(a.zones.area.clone(), a.zones.keepout.clone())
            .build()
            .map_err(|e| name_flag(e.naming_landmarks(a.landmarks.as_deref()), &given))?;
        let map = load_recipe(&scenario.map, scenario.max_memory_mb)?;
        let config = a.options.config.as_deref();
        let section = kind.info().section;
        scenario
            .check_map(&map)
            // A landmark the map never sees: name the landmark file, not only the map.
            .map_err(|e| name_flag(e.naming_landmarks(a.landmarks.as_deref()), &given))
            .map_err(|e| naming_config(e, config, section))?;
        scenario
            .check_run()
            .map_err(|e| naming_config(name_flag(e, &given), config, section))?;
        Ok(Self {
            scenario,
            map: Some(map),
            out: a.out.clone(),
        })
    }

    /// The demo job: the flagship planner on the bundled map.
    pub fn demo(a: &DemoArgs) -> Result<Self> {
        let kind = match &a.planner {
            Some(p) => parse_planner(p)?,
            None => FLAGSHIP,
        };
        let scenario = Scenario::configure(demo_recipe(), PlannerConfig::new(kind)).build()?;
        let map = load_recipe(&scenario.map, scenario.max_memory_mb)?;
        Ok(Self {
            scenario,
            map: Some(map),
            out: a.out.clone(),
        })
    }

    /// Builds the world, runs the planner in the simulator and computes the metrics. The
    /// scenario's start becomes the start actually used, so that `run.json` replays exactly.
    /// The prepared map becomes the world's (no copy): a job runs once.
    ///
    /// This is a bench job's run: the files are formed from the trace after the run, not on a
    /// thread beside the planner (a bench already keeps every core busy with jobs, and such a
    /// thread would only compete with the planner and inflate its `wall_time_s`).
    pub fn execute(&mut self) -> Result<JobResult> {
        self.execute_as(false, false)
    }

    /// [`Job::execute`] for `ccpp run` and `ccpp demo`: `path.csv`, the swept pixels and the
    /// motion metrics are formed on another thread while the planner works (the same bytes),
    /// and the free area holding the start ([`JobResult::start_area`]) is found beside it when
    /// `start_area`.
    pub fn execute_with(&mut self, start_area: bool) -> Result<JobResult> {
        self.execute_as(start_area, true)
    }

    /// The run behind [`Job::execute`] and [`Job::execute_with`].
    fn execute_as(&mut self, start_area: bool, form_files: bool) -> Result<JobResult> {
        let map = self.map.take().context("the job has already run")?;
        let (run, start_area, formed) = self.scenario.run_owned_with(
            map,
            |w| start_area.then(|| crate::components::StartComponent::of_world(w)),
            form_files,
        )?;
        let s = run.world.initial_pose();
        self.scenario.start = Some([s.x, s.y, s.theta]);
        Ok(JobResult {
            world: run.world,
            run: run.output,
            metrics: run.metrics,
            swept: run.swept,
            start_area,
            formed,
        })
    }
}
