//! The step pipeline: the world type, the one step control, the protocol every participant of a
//! step implements, and the storage and bookkeeping they share.
//!
//! - [`world`]: [`ClearanceWorld`](world::ClearanceWorld), a Rapier world with its joints,
//!   drives and motions, stepped in one call.
//! - [`stepper`]: the one step control (variable-step Störmer-Verlet, acceptance, guards).
//! - [`step_hooks`]: the step protocol, a hook trait with default methods and context structs;
//!   [`protocol`]: its vocabulary (wrenches, guard violations, stalled contacts, element ids).
//! - [`element_set`]: the generic set of force elements behind typed generational handles.

pub(crate) mod arena;
pub(crate) mod body_edits;
pub mod element_set;
pub(crate) mod joint_correction;
pub(crate) mod ledger;
pub(crate) mod motion_step;
pub mod protocol;
pub mod step_hooks;
pub mod stepper;
pub mod world;
