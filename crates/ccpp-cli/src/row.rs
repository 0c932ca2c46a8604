//! One result row of `ccpp bench`, shared by the bench driver and its plots (kept apart so
//! that the plots do not import the driver that calls them).

use std::path::PathBuf;

use ccpp_core::metrics::Metrics;

/// One row of the results: a run, or its failure.
pub struct Row {
    /// Map name.
    pub map: String,
    /// Planner name.
    pub planner: String,
    /// The metrics, or the error.
    pub outcome: Result<Metrics, String>,
    /// The run's warnings (as `ccpp run` prints them, without `warning: `); none for a
    /// failed run.
    pub warnings: Vec<String>,
    /// Where the run's files are.
    pub dir: PathBuf,
}
