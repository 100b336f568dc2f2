//! What a run observes of its steps, without acting on them:
//!
//! - [`guards`]: what the run-time guards saw, the worst of each kind per joint; [`stall`]: why
//!   the step control stalled, from the numbers of the contact that stopped it.
//! - [`metrics`]: impact lists, contact fraction and per-turn statistics.
//! - [`reaction`]: exact ideal-joint reactions from the constrained equations.
//! - [`replay`]: bodies' poses and journals' states, thinned by time, for a replay of a run.

/// The run-time guards' report, part of the step protocol's vocabulary
/// ([`crate::rapier::pipeline::protocol::guards`]).
pub use crate::rapier::pipeline::protocol::guards;
pub mod metrics;
pub mod reaction;
pub mod replay;
pub mod stall;
