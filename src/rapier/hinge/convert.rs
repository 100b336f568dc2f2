//! One-call conversions between Rapier revolute joints and clearance joints.
//!
//! A scene built with Rapier's `RevoluteJoint`s gets radial play in one hinge with one call,
//! which takes the anchors and axes from the revolute joint itself, removes it from the
//! `ImpulseJointSet`, and adds the equivalent [`ClearanceJoint`] to a [`ClearanceJointSet`]:
//!
//! ```
//! use clearance_joint::model::laws::{Bai, FrictionModel};
//! use clearance_joint::prelude::*;
//! use rapier3d_f64::prelude::*;
//!
//! let mut world = PhysicsWorld::new();
//! world.integration_parameters.num_solver_iterations = 1; // as the scenes run (sub-cycled, the default, takes any)
//! let base = world.bodies.insert(RigidBodyBuilder::fixed());
//! let arm = world.bodies.insert(
//!     RigidBodyBuilder::dynamic()
//!         .translation(Vector::new(0.0, -0.3, 0.0))
//!         .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02))),
//! );
//! let revolute = RevoluteJointBuilder::new(Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0));
//! let hinge = world.impulse_joints.insert(base, arm, revolute, true);
//! let mut clearance = ClearanceJointSet::new();
//!
//! // The one line: 0.2 mm of radial play in a 20 mm steel bearing, 16 mm wide, dry friction.
//! let hinge = clearance.convert_revolute(hinge, BearingSide::Body1, HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)?.friction(FrictionModel::Bai(Bai::DRY)), &mut world.impulse_joints)?;
//!
//! assert_eq!(clearance.get(hinge).unwrap().local_anchor2(), Vector::new(0.0, 0.3, 0.0));
//! // The revolute is gone; the only Rapier joint left is the lock of the out-of-plane motion.
//! assert_eq!(world.impulse_joints.len(), 1);
//!
//! // And back, with the same anchors and axes.
//! let revolute = clearance.revert_to_revolute(hinge, &mut world.bodies, &mut world.impulse_joints)?;
//! assert!(world.impulse_joints.get(revolute).unwrap().data.as_revolute().is_some());
//! assert!(clearance.is_empty());
//! # Ok::<(), clearance_joint::Error>(())
//! ```
//!
//! The same call builds the large-step model (radial play solved inside Rapier's solver, for
//! 1/60 s and 1 kHz worlds with any number of solver iterations) into a [`LargeStepJointSet`]:
//!
//! ```
//! use clearance_joint::rapier::hinge::convert::{BearingSide, ConvertRevolute};
//! use clearance_joint::rapier::hinge::design::{HingeDesign, ClearanceModel};
//! use clearance_joint::rapier::large_step::LargeStepJointSet;
//! use rapier3d_f64::prelude::*;
//!
//! let mut world = PhysicsWorld::new(); // Rapier's defaults: dt = 1/60 s, 4 solver iterations
//! let base = world.bodies.insert(RigidBodyBuilder::fixed());
//! let arm = world.bodies.insert(
//!     RigidBodyBuilder::dynamic()
//!         .translation(Vector::new(0.0, -0.3, 0.0))
//!         .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02))),
//! );
//! let revolute = RevoluteJointBuilder::new(Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0));
//! let hinge = world.impulse_joints.insert(base, arm, revolute, true);
//! let mut play = LargeStepJointSet::new();
//!
//! // The one line, with the model chosen: 0.5 mm of play, restitution 0.5.
//! let hinge = play.convert_revolute(hinge, BearingSide::Body1, HingeDesign::steel_improved_liu(0.010, 0.5e-3, 0.016)?.model(ClearanceModel::LargeStep).restitution(0.5), &mut world.impulse_joints)?;
//!
//! for _ in 0..60 {
//!     play.before_step(&mut world.bodies, &mut world.impulse_joints, &world.integration_parameters);
//!     world.step();
//!     play.after_step(&mut world.bodies, &world.impulse_joints);
//! }
//! let report = play.get(hinge).unwrap().report();
//! assert!(report.eccentricity_ratio < 1.1, "{}", report.eccentricity_ratio);
//! assert!((report.normal_force - 2.0 * 9.81).abs() < 0.01);
//! # Ok::<(), clearance_joint::Error>(())
//! ```
//!
//! What a clearance joint cannot carry is refused with an error before anything changes: a joint
//! that is not a revolute, a revolute with a motor or limits (use a
//! [`TorsionSpring`](crate::rapier::sources::drive::TorsionSpring) for a drive), or a disabled joint.

use super::design::HingeDesign;
use crate::error::{Error, Result};
use crate::rapier::joint::{ClearanceJoint, ClearanceJointHandle, ClearanceJointSet};
use crate::rapier::large_step::{LargeStepJoint, LargeStepJointHandle, LargeStepJointSet};
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{
    GenericJoint, GenericJointBuilder, ImpulseJointHandle, ImpulseJointSet, JointAxesMask,
    RevoluteJoint, RigidBodySet,
};

/// Which body of a revolute joint carries the bearing (the hole); the other carries the journal
/// (the pin). The eccentricity is measured in the bearing's frame about the bearing's axis, and the
/// contact points sit on each side's radius, so the choice changes the contact kinematics (a
/// slider-crank's rod-slider pin gives different impact statistics either way).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BearingSide {
    /// The joint's body 1 carries the bearing.
    Body1,
    /// The joint's body 2 carries the bearing: the clearance joint's body 1 is then the
    /// revolute's body 2 (anchors and axes swapped with it).
    Body2,
}

/// The clearance joint equivalent to the revolute `joint`: same anchors, same axes (the X axis
/// of each joint frame), with the laws of `clearance`. Refuses what a clearance joint cannot
/// represent: a joint that does not lock exactly the revolute axes, motors, limits, and a disabled
/// joint.
pub fn clearance_joint_from_revolute(
    joint: &GenericJoint,
    clearance: &HingeDesign,
) -> Result<ClearanceJoint> {
    let [a1, a2, x1, x2] = revolute_frames(joint)?;
    clearance.joint(a1, a2, x1, x2)
}

/// The large-step clearance joint equivalent to the revolute `joint` (same anchors and axes),
/// with the geometry and laws of `clearance` (see [`HingeDesign::large_step_joint`]). Refuses what
/// [`clearance_joint_from_revolute`] refuses.
pub(crate) fn large_step_joint_from_revolute(
    joint: &GenericJoint,
    clearance: &HingeDesign,
) -> Result<LargeStepJoint> {
    let [a1, a2, x1, x2] = revolute_frames(joint)?;
    clearance.large_step_joint(a1, a2, x1, x2)
}

/// Anchors and axes `[anchor1, anchor2, axis1, axis2]` of a convertible revolute joint; refuses a
/// joint that does not lock exactly the revolute axes, motors, limits and a disabled joint.
fn revolute_frames(joint: &GenericJoint) -> Result<[Vector; 4]> {
    if joint.locked_axes != JointAxesMask::LOCKED_REVOLUTE_AXES {
        return Err(Error::invalid(
            "revolute",
            format!(
                "is not a revolute joint (locked axes {:?}, a revolute locks {:?}): only a revolute \
                 hinge can be given radial clearance",
                joint.locked_axes,
                JointAxesMask::LOCKED_REVOLUTE_AXES
            ),
        ));
    }
    if !joint.motor_axes.is_empty() {
        return Err(Error::invalid(
            "revolute",
            "has a motor, which a clearance joint cannot carry (its rotation is free, play and \
             contact are the contact law's): remove the motor, or drive the hinge with a \
             `drive::TorsionSpring`",
        ));
    }
    if !joint.limit_axes.is_empty() {
        return Err(Error::invalid(
            "revolute",
            "has limits, which a clearance joint cannot carry (its rotation is free): remove them \
             before converting",
        ));
    }
    if !joint.is_enabled() {
        return Err(Error::invalid(
            "revolute",
            "is disabled: enable it (or leave it out) rather than converting it into an active \
             clearance joint",
        ));
    }
    Ok(crate::rapier::observers::reaction::joint_frames(joint))
}

/// The ideal revolute joint with the anchors and axes of `joint`. Contacts between the two
/// bodies are disabled, as by the clearance joint's own out-of-plane lock (re-enable them with
/// `GenericJoint::set_contacts_enabled` if your colliders need them).
pub(crate) fn revolute_from_clearance(joint: &ClearanceJoint) -> RevoluteJoint {
    revolute_joint([
        joint.local_anchor1(),
        joint.local_anchor2(),
        joint.local_axis1(),
        joint.local_axis2(),
    ])
}

/// The ideal revolute joint with the anchors and axes of the large-step `joint` (contacts
/// between the bodies disabled, as in [`revolute_from_clearance`]).
pub(crate) fn revolute_from_large_step(joint: &LargeStepJoint) -> RevoluteJoint {
    revolute_joint([
        joint.local_anchor1(),
        joint.local_anchor2(),
        joint.local_axis1(),
        joint.local_axis2(),
    ])
}

/// The ideal revolute joint through `anchor1` / `anchor2` about `axis1` / `axis2` (body frames;
/// axes as given), with contacts between the two bodies disabled: the joint a clearance joint
/// converts back to, and the ECS layer's ideal hinge.
pub(crate) fn revolute_joint([anchor1, anchor2, axis1, axis2]: [Vector; 4]) -> RevoluteJoint {
    let data = GenericJointBuilder::new(JointAxesMask::LOCKED_REVOLUTE_AXES)
        .local_axis1(axis1)
        .local_axis2(axis2)
        .local_anchor1(anchor1)
        .local_anchor2(anchor2)
        .contacts_enabled(false)
        .build();
    RevoluteJoint { data }
}

/// The joint behind `revolute`, or an error naming the handle.
fn revolute_of(
    impulse_joints: &ImpulseJointSet,
    revolute: ImpulseJointHandle,
) -> Result<&rapier3d_f64::prelude::ImpulseJoint> {
    impulse_joints.get(revolute).ok_or_else(|| {
        Error::invalid(
            "revolute",
            format!("no joint with handle {revolute:?} in the ImpulseJointSet"),
        )
    })
}

/// Replaces the revolute joint `revolute` of `impulse_joints` by a clearance joint in `set`
/// between the same bodies, the bearing on the body `bearing` says, with the same anchors and
/// axes and the laws of `clearance`. The clearance joint's body 1 is the bearing's body.
/// Nothing changes when it fails (unknown handle, not a convertible revolute, invalid clearance).
pub(crate) fn revolute_to_clearance(
    set: &mut ClearanceJointSet,
    revolute: ImpulseJointHandle,
    bearing: BearingSide,
    clearance: HingeDesign,
    impulse_joints: &mut ImpulseJointSet,
) -> Result<ClearanceJointHandle> {
    let ij = revolute_of(impulse_joints, revolute)?;
    let (body1, body2) = (ij.body1(), ij.body2());
    let joint = clearance_joint_from_revolute(&ij.data, &clearance)?;
    let (body1, body2, joint) = match bearing {
        BearingSide::Body1 => (body1, body2, joint),
        BearingSide::Body2 => (
            body2,
            body1,
            clearance.joint(
                joint.local_anchor2(),
                joint.local_anchor1(),
                joint.local_axis2(),
                joint.local_axis1(),
            )?,
        ),
    };
    impulse_joints.remove(revolute, true);
    Ok(set.insert_unchecked(body1, body2, joint, impulse_joints))
}

/// Replaces the clearance joint `handle` of `set` by an ideal revolute joint in
/// `impulse_joints` with the same bodies, anchors and axes (contacts between the two bodies
/// disabled, as by the clearance joint's own out-of-plane lock); the clearance joint's forces are taken back from the bodies and its out-of-plane lock is
/// removed.
///
/// **Energy.** The anchors are apart by the journal's eccentricity `e` (up to `c`) when it
/// switches; Rapier's revolute pulls them together within its next steps, which moves the
/// bodies: a body hanging on the bearing wall is lifted by `c`, gaining `m g c` (measured 0.96
/// `m g c` for a 2 kg arm in 0.2 mm of play, a test of this module). Switch when the journal is
/// near the bearing centre, or budget that energy. The other handles of `set` stay valid;
/// `handle` finds nothing ever after.
pub(crate) fn clearance_to_revolute(
    set: &mut ClearanceJointSet,
    handle: ClearanceJointHandle,
    bodies: &mut RigidBodySet,
    impulse_joints: &mut ImpulseJointSet,
) -> Result<ImpulseJointHandle> {
    let joint = set.remove(handle, bodies, impulse_joints).ok_or_else(|| {
        Error::invalid(
            "clearance joint",
            format!(
                "no joint with handle {handle} in the ClearanceJointSet ({} joints)",
                set.len()
            ),
        )
    })?;
    Ok(impulse_joints.insert(
        joint.body1(),
        joint.body2(),
        revolute_from_clearance(&joint),
        true,
    ))
}

/// Replaces the revolute joint `revolute` of `impulse_joints` by a large-step clearance joint in
/// `set` between the same bodies (body 1 carries the bearing), with the same anchors and axes and
/// the geometry and laws of `clearance` (its [`model`](HingeDesign::model) is not consulted: the
/// set is the choice; but a [`ClearanceModel::Spatial`](crate::rapier::hinge::design::ClearanceModel::Spatial) one is refused, naming `model`, since the
/// large-step joint is planar). Nothing changes when it fails.
pub(crate) fn revolute_to_large_step(
    set: &mut LargeStepJointSet,
    revolute: ImpulseJointHandle,
    clearance: HingeDesign,
    impulse_joints: &mut ImpulseJointSet,
) -> Result<LargeStepJointHandle> {
    let ij = revolute_of(impulse_joints, revolute)?;
    let (body1, body2) = (ij.body1(), ij.body2());
    let joint = large_step_joint_from_revolute(&ij.data, &clearance)?;
    impulse_joints.remove(revolute, true);
    Ok(set.insert_unchecked(body1, body2, joint, impulse_joints))
}

/// Replaces the large-step joint `handle` of `set` by an ideal revolute joint with the same
/// bodies, anchors and axes; the bodies get their substep settings back. The other handles of
/// `set` stay valid. As with [`clearance_to_revolute`], the revolute re-centres the journal: a
/// body hanging on the bearing wall is lifted by `c` and gains `m g c` of energy.
pub(crate) fn large_step_to_revolute(
    set: &mut LargeStepJointSet,
    handle: LargeStepJointHandle,
    bodies: &mut RigidBodySet,
    impulse_joints: &mut ImpulseJointSet,
) -> Result<ImpulseJointHandle> {
    let joint = set.remove(handle, bodies, impulse_joints).ok_or_else(|| {
        Error::invalid(
            "large-step joint",
            format!("no joint with handle {handle} in the LargeStepJointSet"),
        )
    })?;
    Ok(impulse_joints.insert(
        joint.body1(),
        joint.body2(),
        revolute_from_large_step(&joint),
        true,
    ))
}

/// The conversions as methods of the joint sets: [`ClearanceJointSet`] (the compliant model)
/// and [`LargeStepJointSet`] (the large-step model).
pub trait ConvertRevolute {
    /// The set's joint handle.
    type Handle;

    /// Replaces the revolute joint `revolute` of `impulse_joints` by a clearance joint in this
    /// set between the same bodies, with the same anchors and axes and the laws of `clearance`;
    /// `bearing` says which body of the revolute carries the bearing (the clearance joint's body
    /// 1 is the bearing's body). Nothing changes when it fails (unknown handle, not a
    /// convertible revolute, invalid clearance). A [`LargeStepJointSet`] builds a large-step
    /// joint and refuses a
    /// [`ClearanceModel::Spatial`](crate::rapier::hinge::design::ClearanceModel::Spatial) design,
    /// naming `model` (the large-step joint is planar).
    fn convert_revolute(
        &mut self,
        revolute: ImpulseJointHandle,
        bearing: BearingSide,
        clearance: HingeDesign,
        impulse_joints: &mut ImpulseJointSet,
    ) -> Result<Self::Handle>;

    /// Replaces the clearance joint `handle` of this set by an ideal revolute joint in
    /// `impulse_joints` with the same bodies, anchors and axes (contacts between the two bodies
    /// disabled); the clearance joint's forces are taken back from the bodies and its
    /// out-of-plane lock is removed (a [`LargeStepJointSet`] also gives the bodies their substep
    /// settings back). The other handles of the set stay valid; `handle` finds nothing ever
    /// after.
    ///
    /// **Energy.** The anchors are apart by the journal's eccentricity `e` (up to `c`) when it
    /// switches; Rapier's revolute pulls them together within its next steps, which moves the
    /// bodies: a body hanging on the bearing wall is lifted by `c`, gaining `m g c` (measured
    /// 0.96 `m g c` for a 2 kg arm in 0.2 mm of play, a test of this module). Switch when the
    /// journal is near the bearing centre, or budget that energy.
    fn revert_to_revolute(
        &mut self,
        handle: Self::Handle,
        bodies: &mut RigidBodySet,
        impulse_joints: &mut ImpulseJointSet,
    ) -> Result<ImpulseJointHandle>;
}

impl ConvertRevolute for LargeStepJointSet {
    type Handle = LargeStepJointHandle;

    fn convert_revolute(
        &mut self,
        revolute: ImpulseJointHandle,
        bearing: BearingSide,
        clearance: HingeDesign,
        impulse_joints: &mut ImpulseJointSet,
    ) -> Result<LargeStepJointHandle> {
        if bearing != BearingSide::Body1 {
            // The radial limit is symmetric: which side is the hole only names the frames. The
            // large-step model measures the eccentricity in the revolute's body-1 frame.
            return Err(Error::invalid(
                "bearing",
                "the large-step model takes the bearing on the revolute's body 1 \
                 (BearingSide::Body1); swap the bodies of the revolute joint instead",
            ));
        }
        revolute_to_large_step(self, revolute, clearance, impulse_joints)
    }

    fn revert_to_revolute(
        &mut self,
        handle: LargeStepJointHandle,
        bodies: &mut RigidBodySet,
        impulse_joints: &mut ImpulseJointSet,
    ) -> Result<ImpulseJointHandle> {
        large_step_to_revolute(self, handle, bodies, impulse_joints)
    }
}

impl ConvertRevolute for ClearanceJointSet {
    type Handle = ClearanceJointHandle;

    fn convert_revolute(
        &mut self,
        revolute: ImpulseJointHandle,
        bearing: BearingSide,
        clearance: HingeDesign,
        impulse_joints: &mut ImpulseJointSet,
    ) -> Result<ClearanceJointHandle> {
        revolute_to_clearance(self, revolute, bearing, clearance, impulse_joints)
    }

    fn revert_to_revolute(
        &mut self,
        handle: ClearanceJointHandle,
        bodies: &mut RigidBodySet,
        impulse_joints: &mut ImpulseJointSet,
    ) -> Result<ImpulseJointHandle> {
        clearance_to_revolute(self, handle, bodies, impulse_joints)
    }
}
