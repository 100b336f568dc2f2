//! The `clearance_joint` app: what the command line does, on top of the library's scene runner.
//!
//! - [`study`]: sweeps over any scene field (parallel, resumable, shardable) and the paper's
//!   studies with their reports.
//! - [`figures`]: the figures of a run and of the studies (PNG and SVG).
//! - [`progress`]: progress display on a terminal.
//!
//! The binary (`src/main.rs`) parses arguments and prints. The library crate `clearance_joint`
//! knows nothing of this crate: depending on it builds none of the app's dependencies.

#![warn(missing_docs)]
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod figures;
pub mod progress;
pub mod study;
