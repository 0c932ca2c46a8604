//! # ccpp-io
//!
//! File input and output for **ccpp**:
//!
//! * [`map`]: loads ROS `map_server` maps (YAML + PGM/PNG) and bare images into a
//!   [`GridMap`](ccpp_core::grid::GridMap), following `map_server`'s trinary rule exactly (and its
//!   `scale` and `raw` modes; see the module docs for the grey-level, alpha and 16-bit
//!   conventions);
//! * [`write`](mod@write): atomic file writers and a `map_saver`-style map writer;
//! * [`georef`]: `--georef` point-pair files for the affine pixel <-> world fit (seed 003);
//! * [`execution`]: ideal or PID execution, odometry noise and its seed as the command line and
//!   Python ask for them;
//! * [`landmarks`]: `--landmarks` files (CSV or JSON) for the simulator's pose correction;
//! * [`scenario`]: the serializable description of a run ([`Scenario`](scenario::Scenario)),
//!   its one validation (including the memory estimate) and its execution;
//! * [`trace`](mod@trace): `trace.jsonl` / `path.csv` writers and the checked trace reader;
//! * [`zones`]: `--area` / `--keepout` files (`GeoJSON`, YAML polygon lists, Nav2 keepout masks);
//! * [`export`]: path exports a robot stack reads (waypoints CSV/JSON, ROS `nav_msgs/Path`
//!   YAML, `GeoJSON`) and the waypoint readers;
//! * [`plan`]: a known-map planner's route without simulation overhead or metrics;
//! * [`warnings`]: the warnings of a finished run (stderr of `ccpp run`, Python's
//!   `RunResult.warnings`);
//! * [`lock`]: the lock a bench or a Python sweep holds on its output folder;
//! * [`message`]: errors as the one-line messages the command line prints and Python raises;
//! * [`phase`]: optional phase timing (`CCPP_PHASES`);
//! * [`mod@file`]: opening user files (regular files only: a FIFO is refused, not read forever).
//!
//! Errors are [`thiserror`] enums that always name the file concerned; nothing here panics on
//! user data.

pub mod components;
pub mod execution;
pub mod export;
pub mod file;
pub mod georef;
pub mod landmarks;
pub mod lock;
pub mod map;
pub mod message;
pub mod names;
pub mod phase;
pub mod plan;
pub mod scenario;
pub mod trace;
pub mod warnings;
pub mod write;
pub mod zones;

pub use map::{load_map, load_map_bytes, LoadOptions, LoadedMap, MapError, MapYaml, Thresholds};
pub use write::{save_map, write_atomic, WriteError};
