//! The coverage planners, one module each, behind the [`Planner`] trait,
//! and the catalogue that builds them by name.

pub mod ba_star;
pub mod bcd;
pub mod bsa;
pub mod bsa_bfs;
pub mod bsa_extended;
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
    /// An option value no planner can work with (see [`PlannerOptions::validate`]).
    #[error("option {field} = {value}: {reason}")]
    BadOption {
        /// The option, as written in a config file (`section.name`).
        field: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        reason: &'static str,
    },
}

impl PlannerOptions {
    /// Checks every numeric option: sizes finite and positive, margins and tolerances finite
    /// and not negative, the rest finite. `resolution` (metres per map pixel) is the smallest
    /// tile, cell or lane side accepted, and a tenth of it the smallest rectangular robot side:
    /// finer ones only multiply the work (a cell side of `1e-300` m overflowed the cell
    /// indices).
    ///
    /// # Errors
    /// [`BuildError::BadOption`] naming the first bad option.
    pub fn validate(&self, resolution: f64) -> Result<(), BuildError> {
        let bad = |field, value, reason| {
            Err(BuildError::BadOption {
                field,
                value,
                reason,
            })
        };
        let finite = |field, v: f64| {
            if v.is_finite() {
                Ok(())
            } else {
                bad(field, v, "must be a finite number")
            }
        };
        let non_negative = |field, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                bad(field, v, "must be a finite number >= 0")
            }
        };
        let side = |field, v: f64| {
            if v.is_finite() && v >= resolution {
                Ok(())
            } else {
                bad(
                    field,
                    v,
                    "must be a finite length of at least one map pixel",
                )
            }
        };
        let pid = |o: &crate::exec::Execution| -> Result<(), BuildError> {
            let crate::exec::Execution::Pid(p) = o else {
                return Ok(());
            };
            if !(p.dt_s.is_finite() && p.dt_s > 0.0) {
                return bad("pid.dt_s", p.dt_s, "must be a finite number > 0");
            }
            for g in [&p.linear, &p.angular] {
                for v in [g.kp, g.ki, g.kd, g.output_limit, g.integral_limit] {
                    finite("pid gains", v)?;
                }
            }
            non_negative("pid.tolerance_m", p.tolerance_m)?;
            non_negative("pid.heading_tolerance_rad", p.heading_tolerance_rad)?;
            non_negative("pid.align_rad", p.align_rad)?;
            non_negative("pid.min_speed_mps", p.min_speed_mps)?;
            non_negative("pid.min_turn_rate", p.min_turn_rate)?;
            non_negative("pid.lookahead_m", p.lookahead_m)?;
            if let Some(n) = &p.noise {
                non_negative("pid.noise.linear_rel_std", n.linear_rel_std)?;
                non_negative("pid.noise.angular_rel_std", n.angular_rel_std)?;
                non_negative("pid.noise.heading_drift_std", n.heading_drift_std)?;
            }
            Ok(())
        };
        let rb = &self.random_bounce;
        if let Some(b) = rb.budget_m {
            non_negative("random_bounce.budget_m", b)?;
        }
        finite("random_bounce.min_turn_deg", rb.min_turn_deg)?;
        finite("random_bounce.max_turn_deg", rb.max_turn_deg)?;
        if let Some(t) = self.ba_star.tile_side_m {
            side("ba_star.tile_side_m", t)?;
        }
        if let Some(l) = self.bcd.lane_spacing_m {
            side("bcd.lane_spacing_m", l)?;
        }
        non_negative("bcd.margin_px", self.bcd.margin_px)?;
        if let Some(c) = self.bsa_bfs.cell_side_m {
            side("bsa_bfs.cell_side_m", c)?;
        }
        non_negative(
            "bsa_bfs.clearance_margin_m",
            self.bsa_bfs.clearance_margin_m,
        )?;
        pid(&self.bsa_bfs.exec)?;
        let rect = &self.rect_boustrophedon;
        for (field, v) in [
            ("rect_boustrophedon.length_m", rect.length_m),
            ("rect_boustrophedon.width_m", rect.width_m),
        ] {
            if !(v.is_finite() && v >= 0.1 * resolution) {
                return bad(
                    field,
                    v,
                    "must be a finite length of at least a tenth of a map pixel",
                );
            }
        }
        for v in rect.area.iter().flatten() {
            finite("rect_boustrophedon.area", *v)?;
        }
        if let Some(c) = rect.clearance_radius_m {
            non_negative("rect_boustrophedon.clearance_radius_m", c)?;
        }
        pid(&rect.exec)?;
        non_negative("bsa_extended.clearance_px", self.bsa_extended.clearance_px)?;
        non_negative(
            "bsa_extended.pipe_halfwidth",
            self.bsa_extended.pipe_halfwidth,
        )?;
        Ok(())
    }
}

/// Builds the planner `name`. Online planners get nothing from `world` but operator settings
/// derived from it (such as the random-bounce distance budget); offline ones read its map.
///
/// # Errors
/// [`BuildError::Unknown`] for an unknown name, [`BuildError::BadOption`] when
/// [`PlannerOptions::validate`] refuses `opts` on this world's resolution.
pub fn build(
    name: &str,
    opts: &PlannerOptions,
    world: &World,
) -> Result<Box<dyn Planner>, BuildError> {
    opts.validate(world.frame().resolution)?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridMap;
    use crate::world::Robot;

    #[test]
    fn bad_option_values_are_refused_by_build() {
        // Found by fuzzing `--config`: `bsa_bfs: {cell_side_m: 0}` overflowed the cell indices
        // (a panic in debug builds); NaN, negative and sub-pixel sizes are refused the same way.
        let map = GridMap::from_ascii_scaled("#####\n#...#\n#####", 10, 0.05).unwrap();
        let world = World::new(map, Robot::new(0.1), None).unwrap();
        let refused = |opts: &PlannerOptions, planner: &str, field: &str| match build(
            planner, opts, &world,
        ) {
            Err(BuildError::BadOption { field: f, .. }) => assert_eq!(f, field),
            Err(e) => panic!("{field}: {e}"),
            Ok(_) => panic!("{field}: accepted"),
        };
        for v in [0.0, -1.0, f64::NAN, 1e-300, 0.049] {
            let mut o = PlannerOptions::default();
            o.bsa_bfs.cell_side_m = Some(v);
            refused(&o, "bsa-bfs", "bsa_bfs.cell_side_m");
            // The whole file is checked, whichever planner runs.
            refused(&o, "ba-star", "bsa_bfs.cell_side_m");
        }
        let mut o = PlannerOptions::default();
        o.ba_star.tile_side_m = Some(f64::INFINITY);
        refused(&o, "ba-star", "ba_star.tile_side_m");
        let mut o = PlannerOptions::default();
        o.rect_boustrophedon.width_m = 1e-9;
        refused(&o, "rect-boustrophedon", "rect_boustrophedon.width_m");
        let mut o = PlannerOptions::default();
        o.bcd.margin_px = -0.5;
        refused(&o, "bcd", "bcd.margin_px");
        let e = build("bsa-bfs", &o, &world).err().unwrap().to_string();
        assert!(e.contains("bcd.margin_px") && e.contains(">= 0"), "{e}");
        // A margin wider than the map is accepted and leaves nothing to cover (it overflowed
        // the start search of BCD, found by fuzzing).
        let mut o = PlannerOptions::default();
        o.bcd.margin_px = 8.9e74;
        let mut p = build("bcd", &o, &world).unwrap();
        let run = crate::sim::simulate(&world, p.as_mut(), &crate::sim::SimConfig::default());
        assert!(run.trace.poses().count() <= 2);
        // Defaults and exactly one pixel are accepted.
        let mut o = PlannerOptions::default();
        o.bsa_bfs.cell_side_m = Some(0.05);
        for p in CATALOG {
            assert!(build(p.name, &o, &world).is_ok(), "{}", p.name);
        }
    }
}
