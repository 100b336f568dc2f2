//! The ideal joints the solver handles: revolute, prismatic, fixed, spherical, motorised.

use super::SoftMotor;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::RigidBodyHandle;

/// An ideal revolute joint for [`ReactionSolver::solve`](super::ReactionSolver::solve): anchors
/// and axis in the bodies' frames (body 1's axis; body 2's follows from the constraint).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdealRevolute {
    /// First body (the bearing side).
    pub body1: RigidBodyHandle,
    /// Second body (the journal side): reactions are the forces on it.
    pub body2: RigidBodyHandle,
    /// Joint point in body 1's frame, m.
    pub local_anchor1: Vector,
    /// Joint point in body 2's frame, m.
    pub local_anchor2: Vector,
    /// Unit hinge axis in body 1's frame.
    pub local_axis1: Vector,
}

/// An ideal prismatic joint for
/// [`ReactionSolver::solve_joints`](super::ReactionSolver::solve_joints): body 2 slides along
/// the axis without turning relative to body 1. Limits are not modelled: the reaction is the one
/// of a free slide (a limit in contact adds a force along the axis that the solver does not know).
/// A motor is ([`IdealJoint::MotorPrismatic`], [`IdealJoint::SoftMotorPrismatic`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdealPrismatic {
    /// First body (the guide).
    pub body1: RigidBodyHandle,
    /// Second body (the slider): reactions are the forces on it.
    pub body2: RigidBodyHandle,
    /// A point of the slide line in body 1's frame, m.
    pub local_anchor1: Vector,
    /// The slider's point on that line in body 2's frame, m.
    pub local_anchor2: Vector,
    /// Unit slide axis in body 1's frame.
    pub local_axis1: Vector,
}

/// An ideal fixed joint for
/// [`ReactionSolver::solve_joints`](super::ReactionSolver::solve_joints): the two bodies move as
/// one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdealFixed {
    /// First body.
    pub body1: RigidBodyHandle,
    /// Second body: reactions are the forces on it.
    pub body2: RigidBodyHandle,
    /// The joint point in body 1's frame, m (where the reaction force is reported).
    pub local_anchor1: Vector,
    /// The joint point in body 2's frame, m.
    pub local_anchor2: Vector,
}

/// An ideal spherical joint (ball and socket) for
/// [`ReactionSolver::solve_joints`](super::ReactionSolver::solve_joints): the anchors coincide,
/// rotation is free.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdealSpherical {
    /// First body.
    pub body1: RigidBodyHandle,
    /// Second body: reactions are the forces on it.
    pub body2: RigidBodyHandle,
    /// The joint point in body 1's frame, m.
    pub local_anchor1: Vector,
    /// The joint point in body 2's frame, m.
    pub local_anchor2: Vector,
}

/// Any ideal joint the solver handles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IdealJoint {
    /// A hinge: 3 linear and 2 angular constraints.
    Revolute(IdealRevolute),
    /// A slide: 2 linear (normal to the axis) and 3 angular constraints.
    Prismatic(IdealPrismatic),
    /// A weld: 3 linear and 3 angular constraints.
    Fixed(IdealFixed),
    /// A ball joint: 3 linear constraints.
    Spherical(IdealSpherical),
    /// A revolute whose velocity motor holds the relative angular speed constant: the revolute's
    /// constraints plus one along the axis (its multiplier is the motor torque). Exact for a
    /// motor that holds its speed; a stiff motor's small speed error is not in it.
    MotorRevolute(IdealRevolute),
    /// A prismatic joint whose velocity motor holds the relative speed along the axis constant:
    /// one more row (its multiplier is the motor force), as [`MotorRevolute`](Self::MotorRevolute).
    MotorPrismatic(IdealPrismatic),
    /// A revolute with a soft motor: the motor's torque is applied from the state.
    SoftMotorRevolute(IdealRevolute, SoftMotor),
    /// A prismatic joint with a soft motor: the motor's force is applied from the state.
    SoftMotorPrismatic(IdealPrismatic, SoftMotor),
}

impl IdealJoint {
    pub(super) fn bodies(&self) -> (RigidBodyHandle, RigidBodyHandle) {
        match self {
            IdealJoint::Revolute(j)
            | IdealJoint::MotorRevolute(j)
            | IdealJoint::SoftMotorRevolute(j, _) => (j.body1, j.body2),
            IdealJoint::Prismatic(j)
            | IdealJoint::MotorPrismatic(j)
            | IdealJoint::SoftMotorPrismatic(j, _) => (j.body1, j.body2),
            IdealJoint::Fixed(j) => (j.body1, j.body2),
            IdealJoint::Spherical(j) => (j.body1, j.body2),
        }
    }

    /// How many of the joint's rows (the first ones) carry the reported joint force.
    pub(super) fn force_rows(&self) -> usize {
        match self {
            IdealJoint::Revolute(_)
            | IdealJoint::MotorRevolute(_)
            | IdealJoint::SoftMotorRevolute(..)
            | IdealJoint::Fixed(_)
            | IdealJoint::Spherical(_) => 3,
            IdealJoint::Prismatic(_)
            | IdealJoint::MotorPrismatic(_)
            | IdealJoint::SoftMotorPrismatic(..) => 2,
        }
    }
}

impl From<IdealRevolute> for IdealJoint {
    fn from(j: IdealRevolute) -> Self {
        IdealJoint::Revolute(j)
    }
}

impl From<IdealPrismatic> for IdealJoint {
    fn from(j: IdealPrismatic) -> Self {
        IdealJoint::Prismatic(j)
    }
}

impl From<IdealSpherical> for IdealJoint {
    fn from(j: IdealSpherical) -> Self {
        IdealJoint::Spherical(j)
    }
}

impl From<IdealFixed> for IdealJoint {
    fn from(j: IdealFixed) -> Self {
        IdealJoint::Fixed(j)
    }
}
