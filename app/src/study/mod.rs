//! Parameter sweeps, and studies (named sweeps a scene declares; the paper's three for its
//! scene) with their metrics and reports.
//!
//! - [`grid`]: sweep axes (`--set path=v1,v2,...`), their Cartesian product in a fixed order,
//!   deterministic folder names, and shards (`--shard K/N`).
//! - [`sweep`]: runs the points in parallel (rayon), each an ideal-vs-clearance run in its own
//!   folder with a manifest written last (resume reuses finished points and redoes half-written
//!   ones), writes the metrics table (CSV and JSON), and merges shard tables.
//! - [`metrics`]: per-run metrics, from the runner's every-step values and from the output rows.
//! - [`preset`]: a scene's study presets (its `studies`, or the paper's three), resolved to sweeps.
//! - [`case`]: a finished case of a study (plain data the reports read).
//! - [`report`]: each study's `report.md`; for the paper's studies on its scene, the verdict of
//!   our numbers on every conclusion of the paper.
//! - [`runner`]: runs studies end to end: cases, tables, figures (drawn by [`crate::figures`]), reports.
//!
//! Dependencies point one way: `runner` -> `report` -> `preset`, `case` -> `sweep`, `metrics`, `grid`.

pub mod case;
pub mod grid;
pub mod metrics;
pub mod preset;
pub mod report;
pub mod runner;
pub mod sweep;

pub use case::StudyCase;
pub use grid::{Axis, Grid, Point, Shard};
pub use metrics::RunMetrics;
pub use preset::{Study, StudyKind, presets, select};
pub use runner::{StudyOptions, StudyOutcome, run_studies};
pub use sweep::{ExecOptions, MetricsTable, Progress, Sweep, merge};
