//! # ccpp-io
//!
//! File input and output for **ccpp**:
//!
//! * [`map`]: loads ROS `map_server` maps (YAML + PGM/PNG) and bare images into a
//!   [`GridMap`](ccpp_core::grid::GridMap), following `map_server`'s trinary rule exactly (see
//!   the module docs for the grey-level, alpha and 16-bit conventions);
//! * [`write`](mod@write): atomic file writers and a `map_saver`-style map writer;
//! * [`georef`]: `--georef` point-pair files for the affine pixel <-> world fit (seed 003);
//! * [`landmarks`]: `--landmarks` files (CSV or JSON) for the simulator's pose correction;
//! * [`trace`]: reading a run's `trace.jsonl` back.
//!
//! Errors are [`thiserror`] enums that always name the file concerned; nothing here panics on
//! user data.

pub mod georef;
pub mod landmarks;
pub mod map;
pub mod trace;
pub mod write;

pub use map::{load_map, load_map_bytes, LoadOptions, LoadedMap, MapError, MapYaml, Thresholds};
pub use write::{save_map, write_atomic, WriteError};
