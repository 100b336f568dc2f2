#![doc = include_str!("../README.md")]
#![warn(missing_docs)]
// `!(x > 0.0)` is how this crate rejects NaN along with non-positive values: intended.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod angle;
pub mod convert;
pub mod drive;
#[cfg(feature = "ecs")]
pub mod ecs;
pub mod error;
pub mod joint;
pub mod kinematics;
pub mod large_step;
pub mod laws;
pub mod ledger;
pub mod metrics;
/// The model: the equations of every law and of the kinematics, the conventions, the
/// interpretations and their parameters, the paper's scene, the time integration and the ideal
/// reactions (`docs/MODEL.md`, the page the source code cites as "MODEL.md §N").
#[doc = include_str!("../docs/MODEL.md")]
pub mod model {}
pub mod output;
pub mod prescribed;
pub mod progress;
pub mod reaction;
pub mod report;
pub mod scene;
pub mod sim;
pub mod stepper;
pub mod study;
pub use error::{Error, Result};

/// The types most users need.
pub mod prelude {
    pub use crate::convert::{BearingSide, Clearance, ConvertRevolute};
    pub use crate::joint::{
        ClearanceJoint, ClearanceJointBuilder, ClearanceJointHandle, ClearanceJointSet,
        OutOfPlaneLock,
    };
    pub use crate::large_step::{
        LargeStepJoint, LargeStepJointBuilder, LargeStepJointHandle, LargeStepJointSet, Restitution,
    };
    pub use crate::laws::*;
    pub use crate::metrics::{ContactObservation, ImpactRecorder};
    pub use crate::reaction::{
        IdealFixed, IdealJoint, IdealPrismatic, IdealRevolute, IdealSpherical, KinematicState,
        ReactionSolver,
    };
    pub use crate::stepper::{ForceSource, StepControl, StepInfo, Stepper};
    pub use rapier3d_f64::math::Vector;
}
