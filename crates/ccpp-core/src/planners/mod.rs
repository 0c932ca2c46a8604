//! The coverage planners, one module each, behind the [`Planner`](crate::planner::Planner) trait,
//! and the catalogue that builds them by name.

pub mod bsa;
pub mod bsa_extended;
pub mod random_bounce;

use serde::{Deserialize, Serialize};

use crate::planner::Planner;
use crate::world::World;

/// One catalogue entry.
#[derive(Clone, Copy, Debug)]
pub struct PlannerInfo {
    /// Name used on the command line.
    pub name: &'static str,
    /// One-line description.
    pub description: &'static str,
    /// `true` when the planner reads the whole map up front.
    pub offline: bool,
}

/// Every planner ccpp knows.
pub const CATALOG: &[PlannerInfo] = &[
    PlannerInfo {
        name: "random-bounce",
        description: "Roomba-like baseline: straight until the sensed obstacle, seeded random turn, distance budget (online)",
        offline: false,
    },
    PlannerInfo {
        name: "bsa",
        description: "Backtracking Spiral Algorithm: spirals on robot-sized cells, BFS backtracking over visited cells (online)",
        offline: false,
    },
    PlannerInfo {
        name: "bsa-extended",
        description: "BSA plus wall following at map resolution and gap-crossing return paths, for coverage near obstacles (online)",
        offline: false,
    },
];

/// Options of every planner, one section each (the single source of truth for CLI, config
/// files and bindings).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PlannerOptions {
    /// `random-bounce`.
    pub random_bounce: random_bounce::RandomBounceOptions,
    /// `bsa`.
    pub bsa: bsa::BsaOptions,
    /// `bsa-extended`.
    pub bsa_extended: bsa_extended::BsaExtendedOptions,
}

/// Error building a planner.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum BuildError {
    /// No planner of that name.
    #[error("unknown planner {0:?}; run `ccpp planners` for the list")]
    Unknown(String),
}

/// Builds the planner `name`. Online planners get nothing from `world` but operator settings
/// derived from it (such as the random-bounce distance budget); offline ones read its map.
///
/// # Errors
/// [`BuildError::Unknown`] for an unknown name.
pub fn build(
    name: &str,
    opts: &PlannerOptions,
    world: &World,
) -> Result<Box<dyn Planner>, BuildError> {
    match name {
        "random-bounce" => {
            let mut o = opts.random_bounce.clone();
            if o.budget_m.is_none() {
                let ideal = world.accessible_area_m2() / (2.0 * world.robot().tool_radius);
                o.budget_m = Some(3.0 * ideal);
            }
            Ok(Box::new(random_bounce::RandomBounce::new(o)))
        }
        "bsa" => Ok(Box::new(bsa::Bsa::new(opts.bsa))),
        "bsa-extended" => Ok(Box::new(bsa::Bsa::extended(opts.bsa_extended.clone()))),
        other => Err(BuildError::Unknown(other.to_string())),
    }
}
