//! What a run observes of its steps, without acting on them:
//!
//! - [`stall`]: why the step control stalled, from the numbers of the contact that stopped it
//!   (what the run-time guards saw is the step protocol's
//!   [`GuardReport`](crate::rapier::pipeline::protocol::GuardReport)).
//! - [`metrics`]: impact lists, contact fraction and per-turn statistics.
//! - [`reaction`]: exact ideal-joint reactions from the constrained equations.

pub mod metrics;
pub mod reaction;
pub mod stall;
