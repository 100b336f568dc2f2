#![doc = include_str!("../README.md")]
#![warn(missing_docs)]
// `!(x > 0.0)` is how this crate rejects NaN along with non-positive values: intended.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

#[cfg(feature = "ecs")]
pub mod ecs;
pub mod error;
pub mod model;
pub mod rapier;
pub mod scene;
pub mod table;
pub use error::{Error, Result};

/// The types most users need.
pub mod prelude {
    pub use crate::model::laws::*;
    pub use crate::rapier::convert::{BearingSide, Clearance, ConvertRevolute};
    pub use crate::rapier::joint::{
        ClearanceJoint, ClearanceJointBuilder, ClearanceJointHandle, ClearanceJointSet,
        OutOfPlaneLock,
    };
    pub use crate::rapier::large_step::{
        LargeStepJoint, LargeStepJointBuilder, LargeStepJointHandle, LargeStepJointSet, Restitution,
    };
    pub use crate::rapier::metrics::{ContactObservation, ImpactRecorder};
    pub use crate::rapier::reaction::{
        IdealFixed, IdealJoint, IdealPrismatic, IdealRevolute, IdealSpherical, KinematicState,
        ReactionSolver,
    };
    pub use crate::rapier::stepper::{ForceSource, StepControl, StepInfo, Stepper};
    pub use rapier3d_f64::math::Vector;
}
