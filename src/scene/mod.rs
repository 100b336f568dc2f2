//! Scenes and the runner: a mechanism described in a RON file, run as an ideal and a clearance
//! twin side by side, with its time series, impact lists, summary and guards written whole.
//!
//! - The scene format ([`Scene`] and its parts), validated with errors naming the field.
//! - Study presets declared in a scene ([`StudySpec`]): named sweeps the app's `study` runs.
//! - [`runner`]: builds the twins in one Rapier world and steps them with the
//!   [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld).
//! - [`output`]: result files written whole or not at all, folder locks, memory estimates.
//! - [`report`]: the summary (`summary.json`) and the printed comparison.
//!
//! Built on [`crate::rapier`] and [`crate::model`]; the app's sweeps, studies and figures are
//! built on this layer, never the other way.

mod errors;
mod format;
pub mod output;
pub mod report;
pub mod runner;
mod study;

pub use format::*;
pub use study::*;
