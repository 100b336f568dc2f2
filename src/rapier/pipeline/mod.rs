//! The step pipeline: the world type, the one step control, the protocol every participant of a
//! step implements, and the storage and bookkeeping they share.
//!
//! - [`world`]: [`ClearanceWorld`](world::ClearanceWorld), a Rapier world with its joints,
//!   drives and motions, stepped in one call.
//! - [`stepper`]: the one step control (variable-step Störmer-Verlet, acceptance, guards);
//!   [`motion_step`]: the step the bodies' own motion needs.
//! - [`step_hooks`]: the step protocol, a hook trait with default methods and context structs;
//!   [`protocol`]: its vocabulary (wrenches, guard violations, stalled contacts, element ids).
//! - [`element_set`]: the generic set of force elements behind typed generational handles.
//! - [`joint_correction`]: Rapier's joint drift correction kept stable across changes of the step.
//! - [`ledger`]: the forces and torques each source applied in a step.

pub(crate) mod arena;
pub mod element_set;
pub mod joint_correction;
pub mod ledger;
pub mod motion_step;
pub mod protocol;
pub mod step_hooks;
pub mod stepper;
pub mod world;
