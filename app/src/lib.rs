//! The `clearance_joint` app: what the command line does, on top of the library's scene runner.
//!
//! Folders:
//! - [`cli`]: the commands' work between argument parsing and printing: a scene run into its
//!   result set, a sweep or a shard of it, the merge of shard tables.
//! - [`study`]: sweeps over any scene field (parallel, resumable, shardable) and studies, the
//!   named sweeps a scene file declares (the paper's three for its scene), with their reports.
//! - [`figures`]: the figures of a run and of the studies (PNG and SVG).
//! - [`process`]: this process's plumbing: files in flight removed on an interrupt, folder
//!   locks, memory probing and sizes.
//! - [`progress`]: progress of a long run on a terminal.
//! - [`replay`]: the self-contained `replay.html` of a run (3D, journal insets, timeline).
//! - [`resultset`]: a result set (data, figures, report, replay) written as one unit.
//! - [`summary`]: `summary.json` with the effective scene (the scene after overrides).
//! - [`advice`]: the library's errors phrased for the command line (its options added).
//!
//! The binary (`src/bin/clearance_joint/`, a file per command) parses arguments, calls these, prints and sets the exit code. The
//! library crate `clearance_joint` knows nothing of this crate: depending on it builds none of
//! the app's dependencies.

#![warn(missing_docs)]
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod advice;
pub mod cli;
pub mod figures;
pub mod process;
pub mod progress;
pub mod replay;
pub mod resultset;
pub mod study;
pub mod summary;
