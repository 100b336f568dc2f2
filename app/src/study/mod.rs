//! Parameter sweeps, the paper's three studies, their metrics, figures and reports.
//!
//! - [`grid`]: sweep axes (`--set path=v1,v2,...`), their Cartesian product in a fixed order,
//!   deterministic folder names, and shards (`--shard K/N`).
//! - [`sweep`]: runs the points in parallel (rayon), each an ideal-vs-clearance run in its own
//!   folder with a manifest written last (resume reuses finished points and redoes half-written
//!   ones), writes the metrics table (CSV and JSON), and merges shard tables.
//! - [`metrics`]: per-run metrics, from the runner's every-step values and from the output rows.
//! - Figures are drawn by [`crate::figures`].
//! - [`preset`]: the paper's studies (clearance, torque, friction) as named sweeps, run end to end.
//! - [`report`]: each study's `report.md`, with the verdict of our numbers on every conclusion of the paper.

pub mod grid;
pub mod metrics;
pub mod preset;
pub mod report;
pub mod sweep;

pub use grid::{Axis, Grid, Point, Shard};
pub use metrics::RunMetrics;
pub use preset::{StudyKind, StudyOptions, StudyOutcome, run_studies};
pub use sweep::{ExecOptions, MetricsTable, Progress, Sweep, merge};
