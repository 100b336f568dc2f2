//! The ideal joints the solver handles: revolute, prismatic, fixed, spherical, motorised, read
//! from Rapier's joints.

use super::SoftMotor;
use crate::error::{Error, Result};
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{
    GenericJoint, ImpulseJointHandle, ImpulseJointSet, JointAxesMask, JointAxis, RigidBodyHandle,
};

/// An ideal joint for [`ReactionSolver::solve`](super::ReactionSolver::solve): one of Rapier's
/// joints, read from its description ([`from_rapier`](Self::from_rapier)) so that the solve and
/// the simulation hold the same joint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdealJoint(pub(crate) JointModel);

impl IdealJoint {
    /// The ideal joint Rapier's joint `handle` in `joints` holds: a revolute, prismatic, fixed or
    /// spherical joint
    /// (told by its locked axes), its bodies, anchors and axis (its frames' origins and X axes),
    /// and a motor on its free axis (`AngX` of a revolute, `LinX` of a prismatic joint) as the
    /// spring-damper law Rapier applies, evaluated from the state. Limits are not modelled: the
    /// reaction is that of the free joint. An error names what the solver cannot hold: an
    /// unknown handle, other locked axes, or a motor on a fixed or spherical joint.
    pub fn from_rapier(joints: &ImpulseJointSet, handle: ImpulseJointHandle) -> Result<Self> {
        let Some(joint) = joints.get(handle) else {
            return Err(Error::invalid(
                "handle",
                format!("{handle:?} is not in the impulse joint set"),
            ));
        };
        let data = &joint.data;
        let (body1, body2) = (joint.body1(), joint.body2());
        let [local_anchor1, local_anchor2, local_axis1, _] = joint_frames(data);
        let motor = |axis| data.motor(axis).map(SoftMotor::from_rapier);
        let axes = data.locked_axes;
        let model = if axes == JointAxesMask::LOCKED_REVOLUTE_AXES {
            let j = IdealRevolute {
                body1,
                body2,
                local_anchor1,
                local_anchor2,
                local_axis1,
            };
            match motor(JointAxis::AngX) {
                Some(m) => JointModel::SoftMotorRevolute(j, m),
                None => JointModel::Revolute(j),
            }
        } else if axes == JointAxesMask::LOCKED_PRISMATIC_AXES {
            let j = IdealPrismatic {
                body1,
                body2,
                local_anchor1,
                local_anchor2,
                local_axis1,
            };
            match motor(JointAxis::LinX) {
                Some(m) => JointModel::SoftMotorPrismatic(j, m),
                None => JointModel::Prismatic(j),
            }
        } else if axes == JointAxesMask::LOCKED_FIXED_AXES {
            JointModel::Fixed(IdealFixed {
                body1,
                body2,
                local_anchor1,
                local_anchor2,
            })
        } else if axes == JointAxesMask::LOCKED_SPHERICAL_AXES {
            JointModel::Spherical(IdealSpherical {
                body1,
                body2,
                local_anchor1,
                local_anchor2,
            })
        } else {
            return Err(Error::invalid(
                "joint",
                format!(
                    "locks the axes {axes:?}: the reaction solve holds revolute, prismatic, fixed \
                     and spherical joints"
                ),
            ));
        };
        if !matches!(model, JointModel::Fixed(_) | JointModel::Spherical(_))
            || data.motor_axes.is_empty()
        {
            return Ok(IdealJoint(model));
        }
        Err(Error::invalid(
            "joint",
            "has a motor, but a fixed or spherical joint has no free axis the solve can drive",
        ))
    }

    /// The same joint with its motor taken as one that holds its speed: one more constraint row
    /// (`d(speed)/dt = 0`), whose multiplier is the motor's torque or force. Exact for a motor
    /// that holds its speed (a stiff velocity motor); its small speed error is not in it. A joint
    /// without a motor is returned unchanged.
    pub fn held_motor(self) -> Self {
        IdealJoint(match self.0 {
            JointModel::SoftMotorRevolute(j, _) => JointModel::MotorRevolute(j),
            JointModel::SoftMotorPrismatic(j, _) => JointModel::MotorPrismatic(j),
            model => model,
        })
    }

    pub(super) fn bodies(&self) -> (RigidBodyHandle, RigidBodyHandle) {
        self.0.bodies()
    }

    pub(super) fn force_rows(&self) -> usize {
        self.0.force_rows()
    }
}

/// The anchors and X axes of a Rapier joint's two frames, in their bodies' frames:
/// `[anchor1, anchor2, axis1, axis2]`. The axes are the frames' rotations of X, not
/// `GenericJoint::local_axis1()`: in Rapier 0.36 that transforms X as a point by the whole frame,
/// so it adds the anchor to the axis.
pub(crate) fn joint_frames(joint: &GenericJoint) -> [Vector; 4] {
    [
        joint.local_anchor1(),
        joint.local_anchor2(),
        joint.local_frame1.rotation * Vector::X,
        joint.local_frame2.rotation * Vector::X,
    ]
}

/// An ideal revolute joint for the solve: anchors
/// and axis in the bodies' frames (body 1's axis; body 2's follows from the constraint).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct IdealRevolute {
    /// First body (the bearing side).
    pub(crate) body1: RigidBodyHandle,
    /// Second body (the journal side): reactions are the forces on it.
    pub(crate) body2: RigidBodyHandle,
    /// Joint point in body 1's frame, m.
    pub(crate) local_anchor1: Vector,
    /// Joint point in body 2's frame, m.
    pub(crate) local_anchor2: Vector,
    /// Unit hinge axis in body 1's frame.
    pub(crate) local_axis1: Vector,
}

/// An ideal prismatic joint for
/// the solve: body 2 slides along
/// the axis without turning relative to body 1. Limits are not modelled: the reaction is the one
/// of a free slide (a limit in contact adds a force along the axis that the solver does not know).
/// A motor is ([`JointModel::MotorPrismatic`], [`JointModel::SoftMotorPrismatic`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct IdealPrismatic {
    /// First body (the guide).
    pub(crate) body1: RigidBodyHandle,
    /// Second body (the slider): reactions are the forces on it.
    pub(crate) body2: RigidBodyHandle,
    /// A point of the slide line in body 1's frame, m.
    pub(crate) local_anchor1: Vector,
    /// The slider's point on that line in body 2's frame, m.
    pub(crate) local_anchor2: Vector,
    /// Unit slide axis in body 1's frame.
    pub(crate) local_axis1: Vector,
}

/// An ideal fixed joint for
/// the solve: the two bodies move as
/// one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct IdealFixed {
    /// First body.
    pub(crate) body1: RigidBodyHandle,
    /// Second body: reactions are the forces on it.
    pub(crate) body2: RigidBodyHandle,
    /// The joint point in body 1's frame, m (where the reaction force is reported).
    pub(crate) local_anchor1: Vector,
    /// The joint point in body 2's frame, m.
    pub(crate) local_anchor2: Vector,
}

/// An ideal spherical joint (ball and socket) for
/// the solve: the anchors coincide,
/// rotation is free.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct IdealSpherical {
    /// First body.
    pub(crate) body1: RigidBodyHandle,
    /// Second body: reactions are the forces on it.
    pub(crate) body2: RigidBodyHandle,
    /// The joint point in body 1's frame, m.
    pub(crate) local_anchor1: Vector,
    /// The joint point in body 2's frame, m.
    pub(crate) local_anchor2: Vector,
}

/// Any ideal joint the solver handles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum JointModel {
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

impl JointModel {
    pub(super) fn bodies(&self) -> (RigidBodyHandle, RigidBodyHandle) {
        match self {
            JointModel::Revolute(j)
            | JointModel::MotorRevolute(j)
            | JointModel::SoftMotorRevolute(j, _) => (j.body1, j.body2),
            JointModel::Prismatic(j)
            | JointModel::MotorPrismatic(j)
            | JointModel::SoftMotorPrismatic(j, _) => (j.body1, j.body2),
            JointModel::Fixed(j) => (j.body1, j.body2),
            JointModel::Spherical(j) => (j.body1, j.body2),
        }
    }

    /// How many of the joint's rows (the first ones) carry the reported joint force.
    pub(super) fn force_rows(&self) -> usize {
        match self {
            JointModel::Revolute(_)
            | JointModel::MotorRevolute(_)
            | JointModel::SoftMotorRevolute(..)
            | JointModel::Fixed(_)
            | JointModel::Spherical(_) => 3,
            JointModel::Prismatic(_)
            | JointModel::MotorPrismatic(_)
            | JointModel::SoftMotorPrismatic(..) => 2,
        }
    }
}

impl From<IdealRevolute> for JointModel {
    fn from(j: IdealRevolute) -> Self {
        JointModel::Revolute(j)
    }
}

impl From<IdealPrismatic> for JointModel {
    fn from(j: IdealPrismatic) -> Self {
        JointModel::Prismatic(j)
    }
}

impl From<IdealSpherical> for JointModel {
    fn from(j: IdealSpherical) -> Self {
        JointModel::Spherical(j)
    }
}

impl From<IdealFixed> for JointModel {
    fn from(j: IdealFixed) -> Self {
        JointModel::Fixed(j)
    }
}
