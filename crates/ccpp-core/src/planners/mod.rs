//! The coverage planners, one module each, behind the [`Planner`] trait, and the **registry**:
//! one row per planner (its [`PlannerKind`], command-line name, description, online/offline,
//! options type and options section), from which [`PlannerKind`], [`PlannerConfig`] (one
//! planner's options, tagged with its name), [`PlannerOptions`] (every planner's options, one
//! section each, the `--config` file) and [`CATALOG`] are generated.
//!
//! Adding a planner: write its module, implement [`PlannerSettings`] for its options type (the
//! validation, the resource estimate and the constructor, in [`settings`]), and add one row to
//! the `registry!` invocation below.

pub mod ba_star;
pub mod ba_star_extended;
pub mod bcd;
pub mod bsa;
pub mod bsa_bfs;
pub mod bsa_extended;
pub mod extension;
pub mod random_bounce;
pub mod rect_boustrophedon;
pub mod replay;
pub mod settings;

use serde::{Deserialize, Serialize};

use crate::planner::Planner;
use crate::world::World;

pub use crate::options::OptionsError;
pub use settings::{PlannerSettings, ResourceEstimate, Setup};

/// One catalogue entry.
#[derive(Clone, Copy, Debug)]
pub struct PlannerInfo {
    /// Which planner.
    pub kind: PlannerKind,
    /// Name used on the command line and in files (kebab-case).
    pub name: &'static str,
    /// Name of its section in [`PlannerOptions`] (`snake_case`).
    pub section: &'static str,
    /// One-line description.
    pub description: &'static str,
    /// `true` when the planner reads the whole map up front.
    pub offline: bool,
    /// `true` when the sensor range changes the planner's run beyond seeing its neighbour
    /// tiles (`false` for offline planners, and for those that decide from their neighbour
    /// tiles or cells alone: their range is set to what sees them, and `--sensor-range` /
    /// `sensor_range` is refused for them).
    pub range_matters: bool,
}

/// Generates the planner registry from one row per planner.
macro_rules! registry {
    ($(
        $(#[$doc:meta])*
        $variant:ident {
            name: $name:literal,
            section: $section:ident,
            options: $opts:ty,
            offline: $offline:literal,
            range_matters: $range:literal,
            description: $desc:literal $(,)?
        }
    )*) => {
        /// Every planner ccpp knows (serialized by its kebab-case command-line name).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
        pub enum PlannerKind {
            $(
                $(#[$doc])*
                #[serde(rename = $name)]
                $variant,
            )*
        }

        impl PlannerKind {
            /// All planners, in catalogue order.
            pub const ALL: &'static [PlannerKind] = &[$(PlannerKind::$variant),*];

            /// The catalogue entry.
            pub fn info(self) -> &'static PlannerInfo {
                match self {
                    $(PlannerKind::$variant => &CATALOG[PlannerKind::$variant as usize],)*
                }
            }
        }

        /// Every planner ccpp knows, in [`PlannerKind`] order.
        pub const CATALOG: &[PlannerInfo] = &[$(
            PlannerInfo {
                kind: PlannerKind::$variant,
                name: $name,
                section: stringify!($section),
                description: $desc,
                offline: $offline,
                range_matters: $range,
            },
        )*];

        /// Options of every planner, one section each (the `--config` file format).
        #[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
        #[serde(default, deny_unknown_fields)]
        pub struct PlannerOptions {
            $(
                #[doc = concat!("`", $name, "`.")]
                pub $section: $opts,
            )*
        }

        impl PlannerOptions {
            /// Validates every section (errors name the section and the field).
            ///
            /// # Errors
            /// The first invalid option.
            pub fn validate(&self) -> Result<(), OptionsError> {
                $(
                    self.$section
                        .validate()
                        .map_err(|e| e.in_section(stringify!($section)))?;
                )*
                Ok(())
            }

            /// The options of planner `kind` (its section).
            pub fn config(&self, kind: PlannerKind) -> PlannerConfig {
                match kind {
                    $(PlannerKind::$variant => PlannerConfig::$variant(self.$section.clone()),)*
                }
            }
        }

        /// One planner with its options: a planner's options cannot be given to another.
        /// Serialized as `"planner": NAME, "options": {..}`.
        #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
        #[serde(tag = "planner", content = "options")]
        pub enum PlannerConfig {
            $(
                #[doc = concat!("`", $name, "`.")]
                #[serde(rename = $name)]
                $variant($opts),
            )*
        }

        impl PlannerConfig {
            /// Which planner.
            pub fn kind(&self) -> PlannerKind {
                match self {
                    $(PlannerConfig::$variant(_) => PlannerKind::$variant,)*
                }
            }

            /// The options as the common settings interface.
            pub fn settings(&self) -> &dyn PlannerSettings {
                match self {
                    $(PlannerConfig::$variant(o) => o,)*
                }
            }

            /// The options as the common settings interface, mutable.
            pub fn settings_mut(&mut self) -> &mut dyn PlannerSettings {
                match self {
                    $(PlannerConfig::$variant(o) => o,)*
                }
            }
        }
    };
}

registry! {
    /// Roomba-like baseline.
    RandomBounce {
        name: "random-bounce",
        section: random_bounce,
        options: random_bounce::RandomBounceOptions,
        offline: false,
        range_matters: true,
        description: "Roomba-like baseline: straight until the sensed obstacle, seeded random turn, distance budget",
    }
    /// BA* (Viet et al. 2013).
    BaStar {
        name: "ba-star",
        section: ba_star,
        options: ba_star::BaStarOptions,
        offline: false,
        range_matters: false,
        description: "BA* (Viet et al. 2013): boustrophedon regions on 2r tiles, A* + smoothed backtracking to the nearest corner tile",
    }
    /// BA* plus the seed-002 extension.
    BaStarExtended {
        name: "ba-star-extended",
        section: ba_star_extended,
        options: ba_star_extended::BaStarExtendedOptions,
        offline: false,
        range_matters: true,
        description: "BA* plus the seed-002 extension: online wall following of the rims its tiles leave, merged into straight known-free segments",
    }
    /// Backtracking Spiral Algorithm.
    Bsa {
        name: "bsa",
        section: bsa,
        options: bsa::BsaOptions,
        offline: false,
        range_matters: false,
        description: "Backtracking Spiral Algorithm: spirals on robot-sized cells, BFS backtracking over visited cells",
    }
    /// BSA hosting the coverage extension (wall following of the rims, gap crossing).
    BsaExtended {
        name: "bsa-extended",
        section: bsa_extended,
        options: bsa_extended::BsaExtendedOptions,
        offline: false,
        range_matters: true,
        description: "BSA plus the coverage extension (as ba-star-extended): wall passes over the rims its cells leave, straight known-free transfers",
    }
    /// The vacuum-robot BSA of seed 003.
    BsaBfs {
        name: "bsa-bfs",
        section: bsa_bfs,
        options: bsa_bfs::BsaBfsOptions,
        offline: false,
        range_matters: false,
        description: "Vacuum-robot BSA (seed 003): cells +x,+y,-x,-y, return-cell stack, BFS return over visited cells, PID execution",
    }
    /// Boustrophedon cellular decomposition.
    Bcd {
        name: "bcd",
        section: bcd,
        options: bcd::BcdOptions,
        offline: true,
        range_matters: false,
        description: "Boustrophedon cellular decomposition of the known map, lanes 2 r_tool apart (the known-map baseline)",
    }
    /// Lane waypoints for a rectangular robot (seed 001).
    RectBoustrophedon {
        name: "rect-boustrophedon",
        section: rect_boustrophedon,
        options: rect_boustrophedon::RectOptions,
        offline: true,
        range_matters: false,
        description: "Known-map lane waypoints for a rectangular robot (seed 001): lanes b apart, waypoints every l, blocked edges joined by clearance A*",
    }
}

impl PlannerKind {
    /// Command-line name (kebab-case).
    pub fn name(self) -> &'static str {
        self.info().name
    }

    /// `None` when a sensor range asked for changes this planner's runs; else what the range
    /// applies to instead, for the refusal (`--sensor-range does not apply to bcd (it applies
    /// to ...)`): offline planners read the whole map; ba-star, bsa and bsa-bfs decide from
    /// their neighbour tiles alone, which their sensor is set to see.
    pub fn sensor_range_refusal(self) -> Option<String> {
        let info = self.info();
        if info.range_matters {
            return None;
        }
        let names: Vec<&str> = CATALOG
            .iter()
            .filter(|i| i.range_matters)
            .map(|i| i.name)
            .collect();
        let list = match names.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
            _ => names.join(""),
        };
        Some(if info.offline {
            format!("{list}; offline planners read the whole map")
        } else {
            format!(
                "{list}; {} decides from its neighbour tiles alone, which its sensor is set to see: a longer range changes nothing",
                info.name
            )
        })
    }
}

impl std::fmt::Display for PlannerKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for PlannerKind {
    type Err = BuildError;

    /// A planner's name, with any whitespace around it (`"bsa, bcd"` split at the comma).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let name = s.trim();
        CATALOG
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.kind)
            .ok_or_else(|| BuildError::Unknown(s.to_string()))
    }
}

impl PlannerConfig {
    /// The default options of planner `kind`.
    pub fn new(kind: PlannerKind) -> Self {
        PlannerOptions::default().config(kind)
    }

    /// The planner's own seed (random-bounce's turns), which also seeds the odometry noise
    /// when no other seed is given; `None` for the planners that draw nothing.
    pub fn seed(&self) -> Option<u64> {
        match self {
            Self::RandomBounce(o) => Some(o.seed),
            _ => None,
        }
    }

    /// Command-line name of the planner.
    pub fn name(&self) -> &'static str {
        self.kind().name()
    }

    /// Validates the options (errors name the section and the field).
    ///
    /// # Errors
    /// The first invalid option.
    pub fn validate(&self) -> Result<(), OptionsError> {
        self.settings()
            .validate()
            .map_err(|e| e.in_section(self.kind().info().section))
    }

    /// Builds the planner for `world`, after checking its options
    /// ([`validate`](Self::validate)) and their fit to `world`
    /// ([`PlannerSettings::check_world`]). Online planners get nothing from `world` but what
    /// an operator knows (its frame and the robot); offline ones read its map.
    ///
    /// (It used to build unchecked, an option out of its range running as its default: a
    /// library user's `margin_px: -1.0` ran as `0.0` without a word. The checks against the
    /// robot and the run's sensor, [`PlannerSettings::check`], need the run's settings:
    /// `ccpp_io::scenario::Scenario` makes them all.)
    ///
    /// # Errors
    /// [`BuildError::Options`] for the first option out of its range or unfit for `world`.
    pub fn build(&self, world: &World) -> Result<Box<dyn Planner>, BuildError> {
        let settings = self.checked(world)?;
        Ok(settings.build(world))
    }

    /// [`build`](Self::build) that another thread can give up by setting `stop` (bcd's and
    /// rect-boustrophedon's planning end early; the planner built then must not be driven).
    ///
    /// # Errors
    /// As [`build`](Self::build).
    pub fn build_until(
        &self,
        world: &World,
        stop: &std::sync::atomic::AtomicBool,
    ) -> Result<Box<dyn Planner>, BuildError> {
        let settings = self.checked(world)?;
        Ok(settings.build_until(world, stop))
    }

    /// The settings, once [`validate`](Self::validate) and
    /// [`PlannerSettings::check_world`] accept them.
    fn checked(&self, world: &World) -> Result<&dyn PlannerSettings, BuildError> {
        self.validate()?;
        let settings = self.settings();
        settings
            .check_world(world)
            .map_err(|e| e.in_section(self.kind().info().section))?;
        Ok(settings)
    }
}

/// Error building a planner.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum BuildError {
    /// No planner of that name.
    #[error("unknown planner {0:?}{hint}; run `ccpp planners` for the list", hint = did_you_mean(.0))]
    Unknown(String),
    /// An option of the planner's section is out of its range, or does not suit the world
    /// ([`PlannerConfig::validate`], [`PlannerSettings::check_world`]).
    #[error(transparent)]
    Options(#[from] OptionsError),
}

/// ` (did you mean "NAME"?)` when `name` is a planner's name but for case, underscores for
/// hyphens (its options-file section, `rect_boustrophedon`) or spaces; else nothing.
fn did_you_mean(name: &str) -> String {
    let norm = name.trim().to_ascii_lowercase().replace(['_', ' '], "-");
    // A map file in the planner's place (`--map bcd --planner maze.yaml`: docs review).
    let file_like = norm.contains(['/', '\\'])
        || [".yaml", ".yml", ".png", ".pgm", ".pnm"]
            .iter()
            .any(|ext| norm.ends_with(ext));
    if file_like {
        return " (that looks like a map file, not a planner name: were the map and the planner swapped?)".to_string();
    }
    CATALOG
        .iter()
        .find(|p| p.name == norm)
        .map_or_else(String::new, |p| format!(" (did you mean {:?}?)", p.name))
}

/// Builds the planner `name` with its section of `opts` ([`PlannerConfig::build`], which
/// checks the section's values and their fit to `world`).
///
/// # Errors
/// [`BuildError::Unknown`] for an unknown name, [`BuildError::Options`] for an invalid option.
pub fn build(
    name: &str,
    opts: &PlannerOptions,
    world: &World,
) -> Result<Box<dyn Planner>, BuildError> {
    let kind: PlannerKind = name.parse()?;
    opts.config(kind).build(world)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::grid::GridMap;
    use crate::world::Robot;

    /// `PlannerConfig::build` refuses an option out of its range, naming its section (it used
    /// to build unchecked, the option running as its default), and builds the defaults.
    #[test]
    fn a_config_builds_only_with_options_in_range() {
        let map = GridMap::from_ascii_scaled(
            "##########\n#........#\n#........#\n#...##...#\n#........#\n#........#\n##########",
            4,
            0.05,
        )
        .unwrap();
        let world = World::new(map, Robot::new(0.05), None).unwrap();
        for &kind in PlannerKind::ALL {
            assert!(PlannerConfig::new(kind).build(&world).is_ok(), "{kind}");
        }
        let bcd = bcd::BcdOptions {
            margin_px: -1.0,
            ..bcd::BcdOptions::default()
        };
        let e = PlannerConfig::Bcd(bcd.clone()).build(&world).err().unwrap();
        assert!(
            e.to_string().contains("bcd") && e.to_string().contains("margin_px"),
            "{e}"
        );
        let stop = std::sync::atomic::AtomicBool::new(false);
        assert!(PlannerConfig::Bcd(bcd).build_until(&world, &stop).is_err());
        let mut opts = PlannerOptions::default();
        opts.bcd.margin_px = f64::NAN;
        assert!(build("bcd", &opts, &world).is_err());
    }
}
