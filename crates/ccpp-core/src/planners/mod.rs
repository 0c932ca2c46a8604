//! The coverage planners, one module each, behind the [`Planner`] trait,
//! and the catalogue that builds them by name.

pub mod ba_star;
pub mod ba_star_extended;
pub mod bcd;
pub mod bsa;
pub mod bsa_bfs;
pub mod bsa_extended;
pub mod extension;
pub mod random_bounce;
pub mod rect_boustrophedon;

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
        name: "ba-star",
        description: "BA* (Viet et al. 2013): boustrophedon regions on 2r tiles, A* + smoothed backtracking to the nearest corner tile",
        offline: false,
    },
    PlannerInfo {
        name: "ba-star-extended",
        description: "BA* plus the seed-002 extension: online wall following of the rims its tiles leave, merged into straight known-free segments",
        offline: false,
    },
    PlannerInfo {
        name: "bsa",
        description: "Backtracking Spiral Algorithm: spirals on robot-sized cells, BFS backtracking over visited cells",
        offline: false,
    },
    PlannerInfo {
        name: "bsa-extended",
        description: "BSA plus wall following at map resolution and gap-crossing return paths, for coverage near obstacles",
        offline: false,
    },
    PlannerInfo {
        name: "bsa-bfs",
        description: "Vacuum-robot BSA (seed 003): cells +x,+y,-x,-y, return-cell stack, BFS return over visited cells, PID execution",
        offline: false,
    },
    PlannerInfo {
        name: "random-bounce",
        description: "Roomba-like baseline: straight until the sensed obstacle, seeded random turn, distance budget",
        offline: false,
    },
    PlannerInfo {
        name: "bcd",
        description: "Boustrophedon cellular decomposition of the known map, lanes 2 r_tool apart (the known-map baseline)",
        offline: true,
    },
    PlannerInfo {
        name: "rect-boustrophedon",
        description: "Known-map lane waypoints for a rectangular robot (seed 001): lanes b apart, waypoints every l, blocked edges joined by clearance A*",
        offline: true,
    },
];

/// Options of every planner, one section each (the single source of truth for CLI, config
/// files and bindings).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PlannerOptions {
    /// `random-bounce`.
    pub random_bounce: random_bounce::RandomBounceOptions,
    /// `ba-star`.
    pub ba_star: ba_star::BaStarOptions,
    /// `ba-star-extended`.
    pub ba_star_extended: ba_star_extended::BaStarExtendedOptions,
    /// `bcd`.
    pub bcd: bcd::BcdOptions,
    /// `bsa-bfs`.
    pub bsa_bfs: bsa_bfs::BsaBfsOptions,
    /// `rect-boustrophedon`.
    pub rect_boustrophedon: rect_boustrophedon::RectOptions,
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
        "ba-star" => {
            let mut o = opts.ba_star.clone();
            if o.tile_side_m.is_none() {
                o.tile_side_m = Some(2.0 * world.robot().radius);
            }
            Ok(Box::new(ba_star::BaStar::new(o)))
        }
        "ba-star-extended" => {
            let mut o = opts.ba_star_extended.clone();
            if o.ba_star.tile_side_m.is_none() {
                o.ba_star.tile_side_m = Some(2.0 * world.robot().radius);
            }
            Ok(Box::new(ba_star_extended::BaStarExtended::new(o)))
        }
        "bcd" => Ok(Box::new(bcd::Bcd::new(world, &opts.bcd))),
        "bsa-bfs" => Ok(Box::new(bsa_bfs::BsaBfs::new(opts.bsa_bfs.clone()))),
        "rect-boustrophedon" => Ok(Box::new(rect_boustrophedon::RectBoustrophedon::new(
            world,
            &opts.rect_boustrophedon,
        ))),
        "bsa" => Ok(Box::new(bsa::Bsa::new(opts.bsa))),
        "bsa-extended" => Ok(Box::new(bsa::Bsa::extended(opts.bsa_extended.clone()))),
        other => Err(BuildError::Unknown(other.to_string())),
    }
}
