//! # ccpp-core
//!
//! The I/O-free heart of **ccpp**, a complete coverage path planning toolkit for mobile robots on
//! 2-D occupancy grids: grids and frames ([`grid`]), geometry ([`geometry`], [`collide`]), the
//! distance transform ([`dt`]), synthetic maps ([`gen`]), the ground truth ([`world`]), work areas and keep-out zones ([`zones`]), the online step protocol
//! ([`planner`]), the deterministic graph searches ([`search`]), the simulator ([`sim`]), the trace ([`trace`]), tiles ([`tiles`]), the metrics
//! ([`metrics`]) and the planners ([`planners`]); motion execution by PID tracking on a
//! unicycle ([`exec`]), pose correction from non-unique landmarks ([`landmarks`]) and the
//! least-squares affine pixel <-> world fit ([`georef`]).
//!
//! Data flows one way: map -> [`world::World`] -> [`sim::Simulator`] <-> planner ->
//! [`trace::Trace`] -> [`metrics::Metrics`]. Planners never score themselves.

mod bits;
pub mod collide;
pub mod display;
pub mod dt;
pub mod exec;
pub mod gen;
pub mod geometry;
pub mod georef;
pub mod grid;
pub mod hash;
pub mod inflate;
pub mod landmarks;
pub mod metrics;
mod options;
pub mod planner;
pub mod planners;
pub mod raster;
pub mod rng;
pub mod route;
pub mod search;
pub mod sim;
pub mod tiles;
pub mod trace;
pub mod world;
pub mod zones;

pub use geometry::{Point, Pose};
pub use grid::{Cell, GridMap, MapFrame};
