//! The Rapier layer: the model's forces applied to a Rapier world, and what a step loop needs
//! around them. Its folders follow the roles:
//!
//! - [`pipeline`]: the world type, the one step control and the step protocol.
//! - [`joint`]: the compliant clearance joint (contact and friction laws as a per-step force).
//! - [`large_step`]: the same play as a constraint inside Rapier's solver, for 1/60 s and 1 kHz.
//! - [`hinge`]: the hinge's specification both joints are built from, and the conversions from and
//!   to Rapier's revolute joint.
//! - [`sources`]: drives (torsion springs, torques) and prescribed motions.
//! - [`observers`]: guards, stall diagnoses, metrics and ideal-joint reactions.
//!
//! Depends on [`crate::model`] only (and on Rapier); knows nothing of scenes or the ECS.

pub mod hinge;
pub mod joint;
pub mod large_step;
pub mod observers;
pub mod pipeline;
pub mod sources;
