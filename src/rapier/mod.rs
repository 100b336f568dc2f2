//! The Rapier layer: the model's forces applied to a Rapier world, and what a step loop needs
//! around them.
//!
//! - [`joint`]: the clearance joint (compliant contact and friction as a per-step force), its set.
//! - [`joint_correction`]: Rapier's joint drift correction kept stable across changes of the step.
//! - [`large_step`]: the same play as a constraint inside Rapier's solver, for 1/60 s and 1 kHz.
//! - [`convert`]: a clearance joint from a Rapier revolute joint, with the bearing side chosen.
//! - [`stepper`]: the one step control (variable-step Störmer-Verlet, acceptance, guards);
//!   [`motion_step`]: the step the bodies' own motion needs.
//! - [`guards`]: what the run-time guards saw, the worst of each kind per joint; [`stall`]: why
//!   the step control stalled, from the numbers of the contact that stopped it.
//! - [`drive`]: torsion springs and torques; [`prescribed`]: prescribed (kinematic) motions.
//! - [`reaction`]: exact ideal-joint reactions from the constrained equations.
//! - [`metrics`]: impact lists, contact fraction and per-turn statistics.
//! - [`ledger`]: the forces and torques each source applied in a step.
//! - [`replay`]: bodies' poses and journals' states, thinned by time, for a replay of a run.
//!
//! Depends on [`crate::model`] only (and on Rapier); knows nothing of scenes or the ECS.

pub(crate) mod arena;
pub mod convert;
pub mod drive;
pub mod guards;
pub mod joint;
pub mod joint_correction;
pub mod large_step;
pub mod ledger;
pub mod metrics;
pub mod motion_step;
pub mod prescribed;
pub mod reaction;
pub mod replay;
pub mod stall;
pub mod step_hooks;
pub mod stepper;
pub mod world;
