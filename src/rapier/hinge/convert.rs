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
//! world.integration_parameters.num_solver_iterations = 1; // the hook's force is constant over a step
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
//! let hinge = clearance.convert_revolute(hinge, BearingSide::Body1, Clearance::steel_improved_liu(0.010, 0.2e-3, 0.016)?.friction(FrictionModel::Bai(Bai::DRY)), &mut world.impulse_joints)?;
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
//! use clearance_joint::rapier::hinge::convert::{BearingSide, Clearance, ClearanceModel, ConvertRevolute};
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
//! let hinge = play.convert_revolute(hinge, BearingSide::Body1, Clearance::steel_improved_liu(0.010, 0.5e-3, 0.016)?.model(ClearanceModel::LargeStep).restitution(0.5), &mut world.impulse_joints)?;
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

use crate::error::{Error, Result};
use crate::model::laws::{
    BearingGeometry, FrictionLaw, FrictionModel, ImprovedLiu, Material, MaxDamping, NormalModel,
    effective_modulus,
};
use crate::rapier::joint::{
    ClearanceJoint, ClearanceJointBuilder, ClearanceJointHandle, ClearanceJointSet, OutOfPlaneLock,
};
use crate::rapier::large_step::{
    LargeStepJoint, LargeStepJointBuilder, LargeStepJointHandle, LargeStepJointSet,
};
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{
    GenericJoint, GenericJointBuilder, ImpulseJointHandle, ImpulseJointSet, JointAxesMask,
    RevoluteJoint, RigidBodySet,
};

/// Which model of the clearance joint to build: the same bearing, two ways of solving it.
///
/// | model | solved | steps it is stable at | what it gives |
/// |---|---|---|---|
/// | [`Compliant`](Self::Compliant) | contact law, force hook outside Rapier's solver | about 1e-5..1e-4 s for steel, `num_solver_iterations = 1` | force histories, peak forces, penetrations |
/// | [`LargeStep`](Self::LargeStep) | radial limit inside Rapier's solver, Newton restitution, friction moment | any step (1/60 s, 1e-3 s), any iterations | play, rattle, orbit, sustained forces, impulses |
/// | [`Spatial`](Self::Spatial) | contact laws along the width and on the faces, nothing locked | as `Compliant` | tilt, edge loading, axial knocks, moments across the hinge |
///
/// The spatial joint is one line more than the planar one: the journal then tilts and slides
/// axially, and its report says how far and what each kind of contact carries.
///
/// ```
/// use clearance_joint::model::spatial::SpatialModel;
/// use clearance_joint::prelude::*;
/// use rapier3d_f64::prelude::*;
///
/// let mut rapier = PhysicsWorld::new();
/// rapier.gravity = Vector::new(0.0, -9.81, 0.0);
/// rapier.integration_parameters.num_solver_iterations = 1;
/// let post = rapier.bodies.insert(RigidBodyBuilder::fixed());
/// // A 2 kg arm whose centre of mass sits 0.2 m out from a vertical pin: a moment across the axis.
/// let arm = rapier.bodies.insert(
///     RigidBodyBuilder::dynamic()
///         .translation(Vector::new(0.2, 0.0, 0.0))
///         .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02))),
/// );
/// // 0.1 mm of radial play in a 12 mm steel bore 20 mm wide; 0.3 mm of axial play, 10 mm collars.
/// let pin = Clearance::steel_improved_liu(0.006, 0.1e-3, 0.020)?
///     .model(ClearanceModel::Spatial(SpatialModel::steel(0.3e-3, 0.010)))
///     .joint(Vector::ZERO, Vector::new(-0.2, 0.0, 0.0), Vector::Y, Vector::Y)?;
/// let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, 0.0075));
/// let hinge = world.insert_clearance(post, arm, pin)?;
/// let (mut tilt, mut edges) = (0.0_f64, [0.0_f64; 2]);
/// while world.time() < 0.03 {
///     world.step(0.03)?;
///     let s = world.clearance.get(hinge).unwrap().report().spatial.unwrap();
///     tilt = tilt.max(s.tilt[0].hypot(s.tilt[1]));
///     edges = [edges[0].max(s.edge_force[0]), edges[1].max(s.edge_force[1])];
/// }
/// // The journal tilted until the bore's two edges took the moment (free tilt 2c/L = 10 mrad).
/// // Frictionless, it then rocks between its edges and the top face: see `examples/door_hinge.rs`.
/// assert!(tilt > 0.0099, "{tilt}");
/// assert!(edges[0] > 0.0 && edges[1] > 0.0, "{edges:?}");
/// # Ok::<(), clearance_joint::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum ClearanceModel {
    /// The compliant contact-law joint ([`ClearanceJoint`] in a [`ClearanceJointSet`]).
    #[default]
    Compliant,
    /// The large-step joint ([`LargeStepJoint`] in a [`LargeStepJointSet`]): restitution from
    /// [`Clearance::restitution`] (or, when unset, the normal law's own restitution at each
    /// impact) and Coulomb friction with the friction law's sliding coefficient.
    LargeStep,
    /// The compliant joint in space ([`crate::model::spatial`]): the journal tilts and slides
    /// axially, nothing is locked; the bore's law acts along the width in slices, the shoulders
    /// meet the bearing's faces with the face law. A [`ClearanceJoint`] in a
    /// [`ClearanceJointSet`], like `Compliant`, which is its aligned limit.
    Spatial(crate::model::spatial::SpatialModel),
}

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

/// Everything a clearance joint needs beyond the revolute joint it replaces: the radial
/// geometry, the normal and friction laws, and options. Built with chained setters.
#[derive(Clone, Debug, PartialEq)]
pub struct Clearance {
    /// Radial geometry of the bearing and journal.
    pub geometry: BearingGeometry,
    /// Normal contact law.
    pub normal: NormalModel,
    /// Friction law (default none).
    pub friction: FrictionModel,
    /// Floor on the impact velocity of the hysteresis laws, m/s (default 1e-4).
    pub min_impact_speed: f64,
    /// Gap a free flight must open for the next onset to count as an
    /// [impact](crate::rapier::observers::metrics#onsets-impacts-and-chatter), m (default 0.1 um; the
    /// large-step model does not count impacts and ignores it).
    pub min_separation: f64,
    /// The deepest penetration at which the contact law is trusted, m; deeper contacts are guard
    /// violations ([`ClearanceJointBuilder::max_valid_penetration`]). `None` (the default): 1 % of
    /// the journal radius ([`crate::rapier::joint::default_max_valid_penetration`]).
    pub max_valid_penetration: Option<f64>,
    /// What holds the out-of-plane degrees of freedom (default [`OutOfPlaneLock::Joint`]);
    /// ignored by [`ClearanceModel::Spatial`], which locks nothing.
    pub lock: OutOfPlaneLock,
    /// Name used in errors and reports (default: the builder's default name).
    pub name: Option<String>,
    /// Which model to build (default [`ClearanceModel::Compliant`]).
    pub model: ClearanceModel,
    /// Coefficient of restitution of the large-step model's bounces; `None` (the default): the
    /// normal law's own restitution at each bounce ([`crate::rapier::large_step::Restitution::Law`]).
    /// The compliant and spatial models take their restitution from their laws:
    /// [`joint`](Self::joint) refuses a set one, naming `restitution`.
    pub restitution: Option<f64>,
    /// How the compliant planar joint integrates its contact (default
    /// [`ContactIntegration::Explicit`](crate::rapier::joint::ContactIntegration::Explicit)).
    pub integration: crate::rapier::joint::ContactIntegration,
}

impl Clearance {
    /// A frictionless clearance with the given geometry and normal law.
    pub fn new(geometry: BearingGeometry, normal: NormalModel) -> Self {
        Clearance {
            geometry,
            normal,
            friction: FrictionModel::None,
            min_impact_speed: crate::rapier::joint::DEFAULT_MIN_IMPACT_SPEED,
            min_separation: crate::rapier::joint::DEFAULT_MIN_SEPARATION,
            max_valid_penetration: None,
            lock: OutOfPlaneLock::Joint,
            name: None,
            model: ClearanceModel::Compliant,
            restitution: None,
            integration: crate::rapier::joint::ContactIntegration::Explicit,
        }
    }

    /// The paper's improved law (MODEL.md §2) with its defaults (`n = 1`, `delta_max = 0.1 mm`,
    /// `eta = 0.01 s`) for a bearing of radius `bearing_radius`, radial clearance `clearance` and
    /// width `length` (all in m) between two materials; frictionless.
    pub fn improved_liu(
        bearing_radius: f64,
        clearance: f64,
        length: f64,
        bearing: Material,
        journal: Material,
    ) -> Result<Self> {
        let geometry = BearingGeometry::from_clearance(bearing_radius, clearance, length)?;
        bearing.validate().map_err(|e| e.within("bearing"))?;
        journal.validate().map_err(|e| e.within("journal"))?;
        let law = ImprovedLiu::new(
            effective_modulus(&bearing, &journal),
            length,
            clearance,
            1.0,
            ImprovedLiu::DEFAULT_DELTA_MAX,
            MaxDamping::Eta(ImprovedLiu::DEFAULT_ETA),
        )?;
        Ok(Self::new(geometry, NormalModel::ImprovedLiu(law)))
    }

    /// The paper's improved law ([`improved_liu`](Self::improved_liu), Liu's cylindrical
    /// elastic term with the penetration-ramped damping) with structural steel on both sides (the
    /// paper's table 2: E = 207 GPa, nu = 0.3). Lengths in m.
    pub fn steel_improved_liu(bearing_radius: f64, clearance: f64, length: f64) -> Result<Self> {
        Self::improved_liu(
            bearing_radius,
            clearance,
            length,
            Material::STEEL,
            Material::STEEL,
        )
    }

    /// The former name of [`steel_improved_liu`](Self::steel_improved_liu), kept as an alias:
    /// steel on steel with the paper's *improved Liu* law (not Hertz, not Lankarani-Nikravesh).
    #[deprecated(note = "says no law: use `Clearance::steel_improved_liu`")]
    pub fn steel(bearing_radius: f64, clearance: f64, length: f64) -> Result<Self> {
        Self::improved_liu(
            bearing_radius,
            clearance,
            length,
            Material::STEEL,
            Material::STEEL,
        )
    }

    /// Sets the friction law.
    pub fn friction(mut self, friction: FrictionModel) -> Self {
        self.friction = friction;
        self
    }

    /// Sets the floor on the impact velocity of the hysteresis laws, m/s.
    pub fn min_impact_speed(mut self, speed: f64) -> Self {
        self.min_impact_speed = speed;
        self
    }

    /// Sets the gap a free flight must open for the next onset to count as an
    /// [impact](crate::rapier::observers::metrics#onsets-impacts-and-chatter), m (checked when the joint is
    /// built: not negative).
    pub fn min_separation(mut self, gap: f64) -> Self {
        self.min_separation = gap;
        self
    }

    /// Sets the deepest penetration at which the contact law is trusted, m (checked when the
    /// joint is built: positive, at most the journal radius).
    pub fn max_valid_penetration(mut self, depth: f64) -> Self {
        self.max_valid_penetration = Some(depth);
        self
    }

    /// Sets what holds the out-of-plane degrees of freedom of the planar joint (the spatial
    /// model locks nothing and ignores it).
    pub fn lock(mut self, lock: OutOfPlaneLock) -> Self {
        self.lock = lock;
        self
    }

    /// Sets how the compliant planar joint integrates its contact
    /// ([`ContactIntegration`](crate::rapier::joint::ContactIntegration)).
    pub fn integration(mut self, integration: crate::rapier::joint::ContactIntegration) -> Self {
        self.integration = integration;
        self
    }

    /// Sets the name used in errors and reports.
    pub fn name(mut self, name: impl Into<String>) -> Self {
        self.name = Some(name.into());
        self
    }

    /// Chooses the model: `.model(ClearanceModel::LargeStep)` for 1/60 s or 1 kHz worlds,
    /// `.model(ClearanceModel::Spatial(..))` for a journal that tilts and slides axially.
    pub fn model(mut self, model: ClearanceModel) -> Self {
        self.model = model;
        self
    }

    /// Sets the large-step model's coefficient of restitution (in [0, 1]). The compliant and
    /// spatial models take theirs from the normal law: [`joint`](Self::joint) refuses a set one.
    pub fn restitution(mut self, coefficient: f64) -> Self {
        self.restitution = Some(coefficient);
        self
    }

    /// A validated clearance joint with these laws, about `local_axis1` / `local_axis2` through
    /// `local_anchor1` / `local_anchor2` (body frames; body 1 carries the bearing).
    pub fn joint(
        &self,
        local_anchor1: Vector,
        local_anchor2: Vector,
        local_axis1: Vector,
        local_axis2: Vector,
    ) -> Result<ClearanceJoint> {
        if self.model == ClearanceModel::LargeStep {
            return Err(Error::invalid(
                "model",
                "is LargeStep, but a compliant clearance joint was asked for: insert it into a \
                 LargeStepJointSet (or use `Clearance::large_step_joint`), or choose \
                 ClearanceModel::Compliant",
            ));
        }
        if let Some(e) = self.restitution {
            return Err(Error::invalid(
                "restitution",
                format!(
                    "is set ({}), but the compliant and spatial models take their restitution from \
                     the normal law (its damping): leave `restitution` unset, choose a law with the \
                     restitution you want (e.g. a hysteresis law's `restitution`), or choose \
                     ClearanceModel::LargeStep, which uses it",
                    crate::error::sig4(e)
                ),
            ));
        }
        let mut b = ClearanceJointBuilder::new(local_axis1, self.geometry, self.normal)
            .local_axis2(local_axis2)
            .local_anchor1(local_anchor1)
            .local_anchor2(local_anchor2)
            .friction(self.friction)
            .min_impact_speed(self.min_impact_speed)
            .min_separation(self.min_separation)
            .lock(self.lock)
            .integration(self.integration);
        if let Some(depth) = self.max_valid_penetration {
            b = b.max_valid_penetration(depth);
        }
        if let Some(name) = &self.name {
            b = b.name(name.clone());
        }
        if let ClearanceModel::Spatial(model) = self.model {
            b = b.spatial(model);
        }
        b.build()
    }
}

impl Clearance {
    /// A validated large-step clearance joint with this geometry (whatever [`model`](Self::model)
    /// says, except [`ClearanceModel::Spatial`], refused naming `model`: the large-step joint is
    /// planar and cannot tilt or slide axially): restitution [`restitution`](Self::restitution) or the normal law's own, Coulomb
    /// friction with the friction law's sliding coefficient (`mu_d`), the same impact-speed floor
    /// and name, about `local_axis1` / `local_axis2` through `local_anchor1` / `local_anchor2`.
    pub fn large_step_joint(
        &self,
        local_anchor1: Vector,
        local_anchor2: Vector,
        local_axis1: Vector,
        local_axis2: Vector,
    ) -> Result<LargeStepJoint> {
        if let ClearanceModel::Spatial(_) = self.model {
            return Err(Error::invalid(
                "model",
                "is Spatial, but a large-step joint was asked for: the large-step model is \
                 planar (Rapier's solver locks its axial motion and tilts). Build the spatial \
                 joint with `Clearance::joint` into a ClearanceJointSet (or a ClearanceWorld), or \
                 choose ClearanceModel::LargeStep",
            ));
        }
        // The law's restitution is evaluated at the law's clearance: it must be the bearing's.
        self.normal
            .check_clearance("normal", self.geometry.clearance())?;
        let mut b = LargeStepJointBuilder::new(local_axis1, self.geometry)
            .local_axis2(local_axis2)
            .local_anchor1(local_anchor1)
            .local_anchor2(local_anchor2)
            .friction(self.friction.sliding_coefficient())
            .min_impact_speed(self.min_impact_speed);
        b = match self.restitution {
            Some(e) => b.restitution(e),
            None => b.restitution_law(self.normal),
        };
        if let Some(name) = &self.name {
            b = b.name(name.clone());
        }
        b.build()
    }
}

/// The clearance joint equivalent to the revolute `joint`: same anchors, same axes (the X axis
/// of each joint frame), with the laws of `clearance`. Refuses what a clearance joint cannot
/// represent: a joint that does not lock exactly the revolute axes, motors, limits, and a disabled
/// joint.
pub fn clearance_joint_from_revolute(
    joint: &GenericJoint,
    clearance: &Clearance,
) -> Result<ClearanceJoint> {
    let [a1, a2, x1, x2] = revolute_frames(joint)?;
    clearance.joint(a1, a2, x1, x2)
}

/// The large-step clearance joint equivalent to the revolute `joint` (same anchors and axes),
/// with the geometry and laws of `clearance` (see [`Clearance::large_step_joint`]). Refuses what
/// [`clearance_joint_from_revolute`] refuses.
pub fn large_step_joint_from_revolute(
    joint: &GenericJoint,
    clearance: &Clearance,
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
    // The X axis of each joint frame. Not `GenericJoint::local_axis1()`: in Rapier 0.36 it
    // transforms X as a point by the whole frame, so it adds the anchor to the axis.
    Ok([
        joint.local_anchor1(),
        joint.local_anchor2(),
        joint.local_frame1.rotation * Vector::X,
        joint.local_frame2.rotation * Vector::X,
    ])
}

/// The ideal revolute joint with the anchors and axes of `joint`. Contacts between the two
/// bodies are disabled, as by the clearance joint's own out-of-plane lock (re-enable them with
/// `GenericJoint::set_contacts_enabled` if your colliders need them).
pub fn revolute_from_clearance(joint: &ClearanceJoint) -> RevoluteJoint {
    revolute_joint([
        joint.local_anchor1(),
        joint.local_anchor2(),
        joint.local_axis1(),
        joint.local_axis2(),
    ])
}

/// The ideal revolute joint with the anchors and axes of the large-step `joint` (contacts
/// between the bodies disabled, as in [`revolute_from_clearance`]).
pub fn revolute_from_large_step(joint: &LargeStepJoint) -> RevoluteJoint {
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
pub fn revolute_joint([anchor1, anchor2, axis1, axis2]: [Vector; 4]) -> RevoluteJoint {
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
pub fn revolute_to_clearance(
    set: &mut ClearanceJointSet,
    revolute: ImpulseJointHandle,
    bearing: BearingSide,
    clearance: Clearance,
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
/// `impulse_joints` with the same bodies, anchors and axes (see [`revolute_from_clearance`]);
/// the clearance joint's forces are taken back from the bodies and its out-of-plane lock is
/// removed.
///
/// **Energy.** The anchors are apart by the journal's eccentricity `e` (up to `c`) when it
/// switches; Rapier's revolute pulls them together within its next steps, which moves the
/// bodies: a body hanging on the bearing wall is lifted by `c`, gaining `m g c` (measured 0.96
/// `m g c` for a 2 kg arm in 0.2 mm of play, a test of this module). Switch when the journal is
/// near the bearing centre, or budget that energy. The other handles of `set` stay valid;
/// `handle` finds nothing ever after.
pub fn clearance_to_revolute(
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
/// the geometry and laws of `clearance` (its [`model`](Clearance::model) is not consulted: the
/// set is the choice; but a [`ClearanceModel::Spatial`] one is refused, naming `model`, since the
/// large-step joint is planar). Nothing changes when it fails.
pub fn revolute_to_large_step(
    set: &mut LargeStepJointSet,
    revolute: ImpulseJointHandle,
    clearance: Clearance,
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
pub fn large_step_to_revolute(
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

    /// See [`revolute_to_clearance`] and [`revolute_to_large_step`]: `bearing` says which body
    /// of the revolute carries the bearing.
    fn convert_revolute(
        &mut self,
        revolute: ImpulseJointHandle,
        bearing: BearingSide,
        clearance: Clearance,
        impulse_joints: &mut ImpulseJointSet,
    ) -> Result<Self::Handle>;

    /// See [`clearance_to_revolute`] and [`large_step_to_revolute`]. The revolute re-centres
    /// the journal: a body hanging on the bearing wall is lifted by the clearance `c` and gains
    /// `m g c` of energy (see [`clearance_to_revolute`]).
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
        clearance: Clearance,
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
        clearance: Clearance,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::laws::{Bai, FrictionModel};
    use rapier3d_f64::prelude::*;

    struct Rig {
        world: PhysicsWorld,
        base: RigidBodyHandle,
        arm: RigidBodyHandle,
    }

    fn rig() -> Rig {
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::new(0.0, -9.81, 0.0);
        // Stiff steel contact under a 20 N load: the hook refuses steps above about 3e-5 s.
        world.integration_parameters.dt = 1e-5;
        world.integration_parameters.num_solver_iterations = 1;
        let base = world.bodies.insert(RigidBodyBuilder::fixed());
        let arm = world.bodies.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(0.0, -0.3, 0.0))
                .can_sleep(false)
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    2.0,
                    Vector::splat(0.02),
                )),
        );
        Rig { world, base, arm }
    }

    fn revolute() -> RevoluteJointBuilder {
        RevoluteJointBuilder::new(Vector::Z)
            .local_anchor1(Vector::new(0.01, 0.0, 0.0))
            .local_anchor2(Vector::new(0.01, 0.3, 0.0))
    }

    /// `revolute()` between the rig's base and arm, converted with the bearing on `side`: the
    /// set, the clearance joint and the (removed) revolute's handle.
    fn converted(
        r: &mut Rig,
        side: BearingSide,
    ) -> (ClearanceJointSet, ClearanceJointHandle, ImpulseJointHandle) {
        let h = r
            .world
            .impulse_joints
            .insert(r.base, r.arm, revolute(), true);
        let mut set = ClearanceJointSet::new();
        let c = set
            .convert_revolute(h, side, clearance(), &mut r.world.impulse_joints)
            .unwrap();
        (set, c, h)
    }

    fn clearance() -> Clearance {
        Clearance::steel_improved_liu(0.010, 0.2e-3, 0.016)
            .unwrap()
            .friction(FrictionModel::Bai(Bai::DRY))
            .name("pivot")
    }

    #[test]
    fn converts_with_the_revolute_anchors_and_axes() {
        let mut r = rig();
        let (set, c, h) = converted(&mut r, BearingSide::Body1);
        assert!(r.world.impulse_joints.get(h).is_none(), "revolute removed");
        let j = set.get(c).unwrap();
        assert_eq!(j.name(), "pivot");
        assert_eq!((j.body1(), j.body2()), (r.base, r.arm));
        assert_eq!(j.local_anchor1(), Vector::new(0.01, 0.0, 0.0));
        assert_eq!(j.local_anchor2(), Vector::new(0.01, 0.3, 0.0));
        assert!((j.local_axis1() - Vector::Z).length() < 1e-15);
        assert!((j.local_axis2() - Vector::Z).length() < 1e-15);
        assert!(matches!(j.friction_law(), FrictionModel::Bai(_)));
        // Only the lock of the out-of-plane motion remains, and it is not a revolute.
        assert_eq!(r.world.impulse_joints.len(), 1);
        let lock = r
            .world
            .impulse_joints
            .get(j.lock_handle().unwrap())
            .unwrap();
        assert!(lock.data.as_revolute().is_none());
    }

    #[test]
    fn the_bearing_side_is_explicit() {
        let mut r = rig();
        let (mut set, c, _) = converted(&mut r, BearingSide::Body2);
        let j = set.get(c).unwrap();
        // The arm carries the bearing: it is the clearance joint's body 1, with its anchor.
        assert_eq!((j.body1(), j.body2()), (r.arm, r.base));
        assert_eq!(j.local_anchor1(), Vector::new(0.01, 0.3, 0.0));
        assert_eq!(j.local_anchor2(), Vector::new(0.01, 0.0, 0.0));
        // Either way the contact carries the arm's weight at rest (2 kg x 9.81 m/s^2).
        let mut stepper = crate::rapier::pipeline::stepper::Stepper::new(
            crate::rapier::pipeline::stepper::StepControl::fixed(1e-5),
        );
        while stepper.time() < 0.3 {
            stepper.step(&mut r.world, &mut [&mut set], 0.3).unwrap();
        }
        let f = set.get(c).unwrap().report().force.normal_force;
        assert!((f - 19.62).abs() < 1.0, "{f}");
    }

    #[test]
    #[allow(deprecated)]
    fn steel_is_the_improved_liu_alias() {
        assert_eq!(
            Clearance::steel_improved_liu(0.010, 0.2e-3, 0.016).unwrap(),
            Clearance::steel_improved_liu(0.010, 0.2e-3, 0.016).unwrap()
        );
        assert!(matches!(
            Clearance::steel_improved_liu(0.010, 0.2e-3, 0.016)
                .unwrap()
                .normal,
            NormalModel::ImprovedLiu(_)
        ));
    }

    #[test]
    fn converts_a_rotated_frame_pair() {
        // Different axes on the two bodies (body 2 built rotated by 90 deg about z).
        let mut r = rig();
        let data = GenericJointBuilder::new(JointAxesMask::LOCKED_REVOLUTE_AXES)
            .local_axis1(Vector::Y)
            .local_axis2(Vector::X)
            .local_anchor1(Vector::new(0.0, 0.0, 0.2))
            .local_anchor2(Vector::new(0.1, 0.0, 0.0))
            .build();
        let h = r.world.impulse_joints.insert(r.base, r.arm, data, true);
        let mut set = ClearanceJointSet::new();
        let c = revolute_to_clearance(
            &mut set,
            h,
            BearingSide::Body1,
            clearance(),
            &mut r.world.impulse_joints,
        )
        .unwrap();
        let j = set.get(c).unwrap();
        assert!((j.local_axis1() - Vector::Y).length() < 1e-15);
        assert!((j.local_axis2() - Vector::X).length() < 1e-15);
        // And back: the revolute has the same frames' axes and anchors.
        let back = clearance_to_revolute(
            &mut set,
            c,
            &mut r.world.bodies,
            &mut r.world.impulse_joints,
        )
        .unwrap();
        let d = &r.world.impulse_joints.get(back).unwrap().data;
        assert!(d.as_revolute().is_some());
        assert!((d.local_frame1.rotation * Vector::X - Vector::Y).length() < 1e-15);
        assert!((d.local_frame2.rotation * Vector::X - Vector::X).length() < 1e-15);
        assert_eq!(d.local_anchor1(), Vector::new(0.0, 0.0, 0.2));
        assert_eq!(d.local_anchor2(), Vector::new(0.1, 0.0, 0.0));
    }

    #[test]
    fn round_trip_restores_an_equivalent_revolute() {
        let mut r = rig();
        let original: GenericJoint = revolute().contacts_enabled(false).into();
        let h = r.world.impulse_joints.insert(r.base, r.arm, original, true);
        let mut set = ClearanceJointSet::new();
        let c = set
            .convert_revolute(
                h,
                BearingSide::Body1,
                clearance(),
                &mut r.world.impulse_joints,
            )
            .unwrap();
        let back = set
            .revert_to_revolute(c, &mut r.world.bodies, &mut r.world.impulse_joints)
            .unwrap();
        assert!(set.is_empty());
        assert_eq!(
            r.world.impulse_joints.len(),
            1,
            "lock removed, revolute back"
        );
        let ij = r.world.impulse_joints.get(back).unwrap();
        assert_eq!((ij.body1(), ij.body2()), (r.base, r.arm));
        assert_eq!(ij.data.local_frame1, original.local_frame1);
        assert_eq!(ij.data.local_frame2, original.local_frame2);
        assert_eq!(ij.data.locked_axes, original.locked_axes);
    }

    /// A spatial clearance converts a revolute without a lock (nothing is held ideally), steps,
    /// and reverts to a revolute with the original frames; the large-step set refuses it, naming
    /// `model`, and leaves the revolute in place.
    #[test]
    fn a_spatial_clearance_converts_without_a_lock_and_reverts() {
        use crate::model::spatial::SpatialModel;
        let spatial =
            || clearance().model(ClearanceModel::Spatial(SpatialModel::steel(0.2e-3, 0.015)));
        for side in [BearingSide::Body1, BearingSide::Body2] {
            let mut r = rig();
            let original: GenericJoint = revolute().contacts_enabled(false).into();
            let h = r.world.impulse_joints.insert(r.base, r.arm, original, true);
            let mut large = LargeStepJointSet::new();
            let e = large
                .convert_revolute(
                    h,
                    BearingSide::Body1,
                    spatial(),
                    &mut r.world.impulse_joints,
                )
                .unwrap_err();
            assert!(
                matches!(&e, Error::Invalid { field, .. } if field == "model"),
                "{e}"
            );
            assert!(large.is_empty() && r.world.impulse_joints.get(h).is_some());
            let mut set = ClearanceJointSet::new();
            let c = set
                .convert_revolute(h, side, spatial(), &mut r.world.impulse_joints)
                .unwrap();
            assert!(r.world.impulse_joints.is_empty(), "no lock inserted");
            let j = set.get(c).unwrap();
            assert!(j.lock_handle().is_none() && j.spatial_model().is_some());
            let anchors = match side {
                BearingSide::Body1 => [Vector::new(0.01, 0.0, 0.0), Vector::new(0.01, 0.3, 0.0)],
                BearingSide::Body2 => [Vector::new(0.01, 0.3, 0.0), Vector::new(0.01, 0.0, 0.0)],
            };
            assert_eq!([j.local_anchor1(), j.local_anchor2()], anchors);
            for _ in 0..2_000 {
                set.apply(
                    &mut r.world.bodies,
                    &r.world.impulse_joints,
                    &r.world.integration_parameters,
                )
                .unwrap();
                r.world.step();
            }
            assert!(set.get(c).unwrap().report().spatial.is_some());
            let back = set
                .revert_to_revolute(c, &mut r.world.bodies, &mut r.world.impulse_joints)
                .unwrap();
            assert!(set.is_empty());
            assert_eq!(r.world.impulse_joints.len(), 1, "the revolute alone");
            let ij = r.world.impulse_joints.get(back).unwrap();
            // The revolute joins the clearance joint's bodies (body 1 the bearing's) with its
            // anchors: the original's, swapped when the arm carried the bearing.
            let (b1, b2, a1, a2) = match side {
                BearingSide::Body1 => (r.base, r.arm, anchors[0], anchors[1]),
                BearingSide::Body2 => (r.arm, r.base, anchors[0], anchors[1]),
            };
            assert_eq!((ij.body1(), ij.body2()), (b1, b2));
            assert_eq!((ij.data.local_anchor1(), ij.data.local_anchor2()), (a1, a2));
            assert!((ij.data.local_frame1.rotation * Vector::X - Vector::Z).length() < 1e-15);
            assert!((ij.data.local_frame2.rotation * Vector::X - Vector::Z).length() < 1e-15);
            assert_eq!(ij.data.locked_axes, original.locked_axes);
        }
    }

    #[test]
    fn converted_mid_run_the_hinge_keeps_the_arm_and_carries_its_weight() {
        let mut r = rig();
        let h = r.world.impulse_joints.insert(
            r.base,
            r.arm,
            RevoluteJointBuilder::new(Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0)),
            true,
        );
        let mut set = ClearanceJointSet::new();
        for _ in 0..100 {
            set.apply(
                &mut r.world.bodies,
                &r.world.impulse_joints,
                &r.world.integration_parameters,
            )
            .unwrap();
            r.world.step();
        }
        let c = set
            .convert_revolute(
                h,
                BearingSide::Body1,
                clearance(),
                &mut r.world.impulse_joints,
            )
            .unwrap();
        for _ in 0..20_000 {
            set.apply(
                &mut r.world.bodies,
                &r.world.impulse_joints,
                &r.world.integration_parameters,
            )
            .unwrap();
            r.world.step();
        }
        let report = set.get(c).unwrap().report();
        assert!(report.state.penetration > 0.0, "resting on the journal");
        let f = report.force.on_journal.length();
        assert!((f - 2.0 * 9.81).abs() < 0.02, "carries the weight: {f} N");
        // The arm fell by the clearance plus a fraction of a micrometre of contact deflection.
        let y = r.world.bodies[r.arm].translation().y;
        assert!((y + 0.3 + 0.2e-3).abs() < 1e-6, "arm at {y}");
    }

    #[test]
    fn reverting_re_centres_the_journal_and_injects_m_g_c() {
        // Resting on the bearing wall, the arm hangs c lower than on an ideal pin; the revolute
        // put back pulls its anchors together and lifts it by c: m g c of energy (3.9 mJ).
        let mut r = rig();
        let (mut set, c, _) = converted(&mut r, BearingSide::Body1);
        for _ in 0..20_000 {
            set.apply(
                &mut r.world.bodies,
                &r.world.impulse_joints,
                &r.world.integration_parameters,
            )
            .unwrap();
            r.world.step();
        }
        let energy = |w: &PhysicsWorld| {
            let rb = &w.bodies[r.arm];
            let kinetic = 0.5 * 2.0 * rb.linvel().length_squared()
                + 0.5 * 0.02 * rb.angvel().length_squared();
            kinetic + 2.0 * 9.81 * rb.translation().y
        };
        let e0 = energy(&r.world);
        set.revert_to_revolute(c, &mut r.world.bodies, &mut r.world.impulse_joints)
            .unwrap();
        let mut highest = e0;
        for _ in 0..20_000 {
            r.world.step();
            highest = highest.max(energy(&r.world));
        }
        // Measured: 3.76 mJ, 0.96 m g c (the arm, hinged 0.01 m off its centre line, also swings).
        let mgc = 2.0 * 9.81 * 0.2e-3;
        let rise = highest - e0;
        assert!(
            rise > 0.9 * mgc && rise < 1.1 * mgc,
            "energy rose by {rise} J"
        );
    }

    #[test]
    fn refusals_leave_everything_unchanged() {
        let mut r = rig();
        let mut set = ClearanceJointSet::new();
        let check = |e: Error, needle: &str| {
            let msg = e.to_string();
            assert!(msg.contains(needle), "{msg}");
        };
        let cases: Vec<(GenericJoint, &str)> = vec![
            (
                PrismaticJointBuilder::new(Vector::X).into(),
                "not a revolute",
            ),
            (FixedJointBuilder::new().into(), "not a revolute"),
            (revolute().motor_velocity(1.0, 0.5).into(), "motor"),
            (revolute().limits([-1.0, 1.0]).into(), "limits"),
            (
                {
                    let mut j: GenericJoint = revolute().into();
                    j.set_enabled(false);
                    j
                },
                "disabled",
            ),
        ];
        for (joint, needle) in cases {
            let h = r.world.impulse_joints.insert(r.base, r.arm, joint, true);
            let n = r.world.impulse_joints.len();
            check(
                set.convert_revolute(
                    h,
                    BearingSide::Body1,
                    clearance(),
                    &mut r.world.impulse_joints,
                )
                .unwrap_err(),
                needle,
            );
            assert_eq!(r.world.impulse_joints.len(), n, "nothing removed");
            assert!(set.is_empty());
            r.world.impulse_joints.remove(h, false);
        }
        // An unknown handle, in both directions.
        let h = r
            .world
            .impulse_joints
            .insert(r.base, r.arm, revolute(), true);
        r.world.impulse_joints.remove(h, false);
        check(
            set.convert_revolute(
                h,
                BearingSide::Body1,
                clearance(),
                &mut r.world.impulse_joints,
            )
            .unwrap_err(),
            "no joint with handle",
        );
        // A stale handle: its joint was converted back already.
        let h = r
            .world
            .impulse_joints
            .insert(r.base, r.arm, revolute(), true);
        let c = set
            .convert_revolute(
                h,
                BearingSide::Body1,
                clearance(),
                &mut r.world.impulse_joints,
            )
            .unwrap();
        let h = set
            .revert_to_revolute(c, &mut r.world.bodies, &mut r.world.impulse_joints)
            .unwrap();
        let n = r.world.impulse_joints.len();
        check(
            set.revert_to_revolute(c, &mut r.world.bodies, &mut r.world.impulse_joints)
                .unwrap_err(),
            "no joint with handle",
        );
        assert_eq!(r.world.impulse_joints.len(), n, "nothing changed");
        r.world.impulse_joints.remove(h, false);
        // An invalid clearance is refused by the laws, naming the field.
        check(
            Clearance::steel_improved_liu(0.010, 0.02, 0.016).unwrap_err(),
            "clearance",
        );
        check(
            Clearance::steel_improved_liu(0.010, 0.2e-3, -0.016).unwrap_err(),
            "length",
        );
        let h = r
            .world
            .impulse_joints
            .insert(r.base, r.arm, revolute(), true);
        check(
            set.convert_revolute(
                h,
                BearingSide::Body1,
                clearance().min_impact_speed(-1.0),
                &mut r.world.impulse_joints,
            )
            .unwrap_err(),
            "min_impact_speed",
        );
        assert!(r.world.impulse_joints.get(h).is_some(), "revolute kept");
    }

    #[test]
    fn large_step_conversion_keeps_frames_and_maps_the_laws() {
        let mut r = rig();
        let h = r
            .world
            .impulse_joints
            .insert(r.base, r.arm, revolute(), true);
        // A LargeStep clearance is refused by the compliant set, naming the field.
        let mut compliant = ClearanceJointSet::new();
        let msg = compliant
            .convert_revolute(
                h,
                BearingSide::Body1,
                clearance().model(ClearanceModel::LargeStep),
                &mut r.world.impulse_joints,
            )
            .unwrap_err()
            .to_string();
        assert!(msg.contains("`model`"), "{msg}");
        assert!(r.world.impulse_joints.get(h).is_some(), "revolute kept");

        let mut play = LargeStepJointSet::new();
        let k = play
            .convert_revolute(
                h,
                BearingSide::Body1,
                clearance().model(ClearanceModel::LargeStep),
                &mut r.world.impulse_joints,
            )
            .unwrap();
        let j = play.get(k).unwrap();
        assert_eq!(j.name(), "pivot");
        assert_eq!((j.body1(), j.body2()), (r.base, r.arm));
        assert_eq!(j.local_anchor1(), Vector::new(0.01, 0.0, 0.0));
        assert_eq!(j.local_anchor2(), Vector::new(0.01, 0.3, 0.0));
        assert!((j.local_axis1() - Vector::Z).length() < 1e-15);
        assert!((j.clearance() - 0.2e-3).abs() < 1e-15);
        // Bai DRY slides at mu_d = 0.25; restitution from the law unless set.
        assert_eq!(j.friction(), 0.25);
        assert!(matches!(
            j.restitution(),
            crate::rapier::large_step::Restitution::Law(NormalModel::ImprovedLiu(_))
        ));
        assert_eq!(
            r.world.impulse_joints.len(),
            1,
            "one Rapier joint carries it all"
        );
        let data = &r
            .world
            .impulse_joints
            .get(j.rapier_handle().unwrap())
            .unwrap()
            .data;
        assert_eq!(
            data.coupled_axes,
            JointAxesMask::LIN_Y | JointAxesMask::LIN_Z
        );
        assert!((data.limits[1].max - 0.2e-3).abs() < 1e-15);

        // And back to the same revolute.
        let back = play
            .revert_to_revolute(k, &mut r.world.bodies, &mut r.world.impulse_joints)
            .unwrap();
        assert!(play.is_empty());
        let d = &r.world.impulse_joints.get(back).unwrap().data;
        assert!(d.as_revolute().is_some());
        assert_eq!(d.local_anchor2(), Vector::new(0.01, 0.3, 0.0));
        // A set restitution is a fixed coefficient; refusals are the revolute's.
        let j = clearance()
            .restitution(0.4)
            .large_step_joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
            .unwrap();
        assert_eq!(
            *j.restitution(),
            crate::rapier::large_step::Restitution::Coefficient(0.4)
        );
        let msg = clearance()
            .restitution(1.5)
            .large_step_joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("`restitution`"), "{msg}");
        let h = r
            .world
            .impulse_joints
            .insert(r.base, r.arm, revolute().limits([-1.0, 1.0]), true);
        let msg = play
            .convert_revolute(
                h,
                BearingSide::Body1,
                clearance(),
                &mut r.world.impulse_joints,
            )
            .unwrap_err()
            .to_string();
        assert!(msg.contains("limits"), "{msg}");
    }

    #[test]
    fn a_law_built_for_another_clearance_is_refused_naming_the_field() {
        // The geometry says 0.5 mm, the improved law was built for 0.2 mm.
        let geometry = BearingGeometry::from_clearance(0.010, 0.5e-3, 0.016).unwrap();
        let law = Clearance::steel_improved_liu(0.010, 0.2e-3, 0.016)
            .unwrap()
            .normal;
        let c = Clearance::new(geometry, law);
        let msg = c
            .joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("`normal_law`") && msg.contains("clearance"),
            "{msg}"
        );
        let msg = c
            .large_step_joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("`normal`") && msg.contains("clearance"),
            "{msg}"
        );
        // The same law with its own geometry builds.
        let ok = Clearance::steel_improved_liu(0.010, 0.2e-3, 0.016).unwrap();
        ok.joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
            .unwrap();
    }
}
