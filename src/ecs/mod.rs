//! The bevy_ecs layer (cargo feature `ecs`, on by default): the Rapier world as a resource, rigid
//! bodies, hinges and drives as components, and the per-step systems in a fixed order.
//!
//! A thin layer: the physics is the core's ([`ClearanceJointSet`], [`DriveSet`], the conversions of
//! [`convert`](crate::rapier::convert)). The systems reconcile the Rapier world with the components
//! every step: spawning, changing or removing a component is all a user does.
//!
//! - [`Physics`] (resource): the Rapier `PhysicsWorld`, the clearance joints and the drives.
//! - [`Body`]: a rigid body, from a Rapier description (`RigidBodyBuilder`) or an existing handle.
//! - [`Hinge`]: which two bodies a hinge joins, its anchors and axes; with a mode component:
//!   [`IdealHinge`] (Rapier's revolute joint) or [`ClearanceHinge`] (radial clearance, contact and
//!   friction laws). A hinge with neither joins nothing. When both are present, the clearance wins.
//! - [`Drive`]: a torsion spring `T = T0 - k theta` on a hinge (on the hinge's entity).
//! - [`HingeState`] and [`BodyState`] (added automatically): what the last step did.
//!
//! A `ClearanceHinge` builds the compliant model unless its [`Clearance::model`] is
//! [`ClearanceModel::LargeStep`]: the one-line choice of the large-step model (see
//! [`large_step`](crate::rapier::large_step)), stepped by the same schedule.
//!
//! Swapping an entity's `IdealHinge` for a `ClearanceHinge` is the whole change, at spawn or
//! while running: the sync system converts the Rapier revolute joint into a clearance joint with
//! [`revolute_to_clearance`](crate::rapier::convert::revolute_to_clearance) (and back with
//! [`clearance_to_revolute`](crate::rapier::convert::clearance_to_revolute) when the `ClearanceHinge`
//! is removed again).
//!
//! ```
//! use bevy_ecs::prelude::*;
//! use clearance_joint::rapier::convert::Clearance;
//! use clearance_joint::ecs::*;
//! use rapier3d_f64::math::Vector;
//! use rapier3d_f64::prelude::{MassProperties, RigidBodyBuilder};
//!
//! let mut world = World::new();
//! world.insert_resource(Physics::new(1e-5, Vector::new(0.0, -9.81, 0.0)));
//! let base = world.spawn(Body::new(RigidBodyBuilder::fixed())).id();
//! let arm = world
//!     .spawn(Body::new(
//!         RigidBodyBuilder::dynamic()
//!             .translation(Vector::new(0.0, -0.3, 0.0))
//!             .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02)))
//!             .can_sleep(false),
//!     ))
//!     .id();
//! let pivot = world
//!     .spawn((
//!         Hinge::new(base, arm, Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0)),
//!         // Was: IdealHinge,
//!         ClearanceHinge(Clearance::steel_improved_liu(0.010, 0.2e-3, 0.016)?),
//!     ))
//!     .id();
//! let mut schedule = physics_schedule();
//! for _ in 0..20_000 {
//!     run_step(&mut world, &mut schedule)?;
//! }
//! let state = world.get::<HingeState>(pivot).unwrap();
//! assert_eq!(state.mode, HingeMode::Clearance);
//! assert!((state.force - 19.62).abs() < 0.05, "the journal carries the arm: {} N", state.force);
//! # Ok::<(), clearance_joint::Error>(())
//! ```

use crate::error::{Error, Result, unit_vector};
use crate::model::angle::HingeAngle;
use crate::model::kinematics::ContactMode;
use crate::rapier::convert::{BearingSide, Clearance, ClearanceModel, ConvertRevolute};
use crate::rapier::drive::{DriveSet, TorsionSpring};
use crate::rapier::joint::{ClearanceJoint, ClearanceJointHandle, ClearanceJointSet};
use crate::rapier::large_step::{LargeStepJoint, LargeStepJointHandle, LargeStepJointSet};
use crate::rapier::reaction::{IdealRevolute, ReactionSolver};
use crate::rapier::stepper::{ForceSource, GuardReport, StepControl, StepMode, Stepper};
use bevy_ecs::prelude::*;
use rapier3d_f64::math::{Rotation, Vector};
use rapier3d_f64::prelude::{
    GenericJointBuilder, ImpulseJointHandle, JointAxesMask, PhysicsWorld, RevoluteJoint, RigidBody,
    RigidBodyHandle,
};
use std::collections::{BTreeMap, BTreeSet};

/// The Rapier joint behind a hinge entity.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HingeJoint {
    /// Rapier's revolute joint.
    Ideal(ImpulseJointHandle),
    /// A clearance joint of [`Physics::clearance`].
    Clearance(ClearanceJointHandle),
    /// A large-step clearance joint of [`Physics::large_step`].
    LargeStep(LargeStepJointHandle),
}

/// What a hinge entity is realised as.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum HingeMode {
    /// No joint (not yet synchronised, or neither [`IdealHinge`] nor [`ClearanceHinge`]).
    #[default]
    None,
    /// A Rapier revolute joint.
    Ideal,
    /// A clearance joint.
    Clearance,
    /// A large-step clearance joint ([`ClearanceModel::LargeStep`]).
    LargeStep,
}

#[derive(Clone, Debug)]
struct RealizedHinge {
    joint: HingeJoint,
    bodies: (RigidBodyHandle, RigidBodyHandle),
    frame: Hinge,
    clearance: Option<Clearance>,
}

#[derive(Clone, Debug)]
struct RealizedDrive {
    set: DriveSet,
    drive: Drive,
    bodies: (RigidBodyHandle, RigidBodyHandle),
    axis: Vector,
}

/// The physics of an ECS world: the Rapier world, the clearance joints and the drives, and the
/// map from entities to what they are in Rapier.
#[derive(Resource)]
pub struct Physics {
    /// The Rapier world. Set gravity, the step (`integration_parameters.dt`) and colliders here;
    /// bodies and joints are managed through the components.
    pub world: PhysicsWorld,
    clearance: ClearanceJointSet,
    large_step: LargeStepJointSet,
    bodies: BTreeMap<Entity, RigidBodyHandle>,
    hinges: BTreeMap<Entity, RealizedHinge>,
    drives: BTreeMap<Entity, RealizedDrive>,
    error: Option<Error>,
    /// The step control: the same public piece the scene runner uses.
    stepper: Stepper,
    /// Set when the sync systems changed joints, drives or bodies: the force sources are
    /// evaluated again before the next step.
    changed: bool,
    reactions: ReactionSolver,
    ideal_joints: Vec<IdealRevolute>,
    source_wrenches: Vec<crate::rapier::ledger::Wrench>,
}

impl Physics {
    /// An empty world stepping by `dt` (s) under `gravity` (m/s^2), with one solver iteration
    /// (the clearance hook's force is constant over a step; Rapier's substeps would make every
    /// impact gain energy).
    pub fn new(dt: f64, gravity: Vector) -> Self {
        let mut world = PhysicsWorld::new();
        world.integration_parameters.dt = dt;
        world.integration_parameters.num_solver_iterations = 1;
        world.gravity = gravity;
        Self::from_world(world)
    }

    /// Wraps an existing Rapier world (its bodies and joints stay; entities refer to bodies with
    /// [`Body::from_handle`]).
    pub fn from_world(world: PhysicsWorld) -> Self {
        let dt = world.integration_parameters.dt;
        Physics {
            world,
            clearance: ClearanceJointSet::new(),
            large_step: LargeStepJointSet::new(),
            bodies: BTreeMap::new(),
            hinges: BTreeMap::new(),
            drives: BTreeMap::new(),
            error: None,
            stepper: Stepper::new(StepControl::fixed(dt)),
            changed: true,
            reactions: ReactionSolver::default(),
            ideal_joints: Vec::new(),
            source_wrenches: Vec::new(),
        }
    }

    /// The step control: fixed steps of `world.integration_parameters.dt` by default (changing
    /// `dt` between steps is followed). With [`StepControl::adaptive`] each run of the schedule
    /// takes ONE accepted step of the stepper's choice, at most up to `time() + dt`: inside
    /// contacts that step is far shorter than a frame, so a game loop must run the schedule until
    /// `time()` reaches the frame's time (each run records its state and impacts).
    pub fn set_step_control(&mut self, control: StepControl) {
        self.stepper.set_control(control);
    }

    /// What the run-time guards recorded (rejected steps, penetrations beyond a law's validity,
    /// steps at the floor).
    pub fn guards(&self) -> &GuardReport {
        self.stepper.guards()
    }

    /// The clearance joints (read-only: they follow the [`ClearanceHinge`] components).
    pub fn clearance(&self) -> &ClearanceJointSet {
        &self.clearance
    }

    /// The large-step clearance joints (read-only: they follow the [`ClearanceHinge`] components
    /// whose [`Clearance::model`] is [`ClearanceModel::LargeStep`]).
    pub fn large_step(&self) -> &LargeStepJointSet {
        &self.large_step
    }

    /// The large-step clearance joint of a [`ClearanceHinge`] entity.
    pub fn large_step_joint(&self, entity: Entity) -> Option<&LargeStepJoint> {
        match self.joint(entity)? {
            HingeJoint::LargeStep(h) => self.large_step.get(h),
            _ => None,
        }
    }

    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.stepper.time()
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.stepper.steps()
    }

    /// The first error of the systems, if any. While it is set the systems do nothing: the
    /// simulation stops where it failed instead of running on a destroyed state.
    pub fn error(&self) -> Option<&Error> {
        self.error.as_ref()
    }

    /// Takes the error out, letting the systems run again.
    pub fn take_error(&mut self) -> Option<Error> {
        self.error.take()
    }

    /// The Rapier body of a [`Body`] entity.
    pub fn body(&self, entity: Entity) -> Option<RigidBodyHandle> {
        self.bodies.get(&entity).copied()
    }

    /// The Rapier joint of a [`Hinge`] entity.
    pub fn joint(&self, entity: Entity) -> Option<HingeJoint> {
        self.hinges.get(&entity).map(|h| h.joint)
    }

    /// The clearance joint of a [`ClearanceHinge`] entity.
    pub fn clearance_joint(&self, entity: Entity) -> Option<&ClearanceJoint> {
        match self.joint(entity)? {
            HingeJoint::Clearance(h) => self.clearance.get(h),
            HingeJoint::Ideal(_) | HingeJoint::LargeStep(_) => None,
        }
    }

    /// The drive of a [`Drive`] entity.
    pub fn drive(&self, entity: Entity) -> Option<&TorsionSpring> {
        self.drives.get(&entity)?.set.drives().first()
    }

    fn fail(&mut self, error: Error) {
        if self.error.is_none() {
            self.error = Some(error);
        }
    }

    /// Removes the Rapier joint of hinge `entity` (if realised).
    fn unrealize_hinge(&mut self, entity: Entity) {
        if let Some(h) = self.hinges.remove(&entity) {
            self.changed = true;
            match h.joint {
                HingeJoint::Ideal(j) => {
                    self.world.impulse_joints.remove(j, true);
                }
                HingeJoint::Clearance(c) => {
                    self.clearance.remove(
                        c,
                        &mut self.world.bodies,
                        &mut self.world.impulse_joints,
                    );
                    self.clearance_removed(c);
                }
                HingeJoint::LargeStep(k) => {
                    self.large_step.remove(
                        k,
                        &mut self.world.bodies,
                        &mut self.world.impulse_joints,
                    );
                }
            }
        }
    }

    /// Renumbers the clearance handles after the set removed `removed` (later handles shift down).
    fn clearance_removed(&mut self, removed: ClearanceJointHandle) {
        for h in self.hinges.values_mut() {
            if let HingeJoint::Clearance(c) = &mut h.joint
                && c.0 > removed.0
            {
                c.0 -= 1;
            }
        }
    }

    /// Takes back the last torques of drive `entity` and forgets it.
    fn unrealize_drive(&mut self, entity: Entity) {
        if let Some(mut d) = self.drives.remove(&entity) {
            self.changed = true;
            d.set.take_back(&mut self.world.bodies);
        }
    }

    /// Removes the Rapier body of `entity` with every hinge and drive attached to it.
    fn remove_body(&mut self, entity: Entity) {
        let Some(handle) = self.bodies.remove(&entity) else {
            return;
        };
        let attached: Vec<Entity> = self
            .hinges
            .iter()
            .filter(|(_, h)| h.bodies.0 == handle || h.bodies.1 == handle)
            .map(|(e, _)| *e)
            .collect();
        for e in attached {
            self.unrealize_hinge(e);
        }
        let driven: Vec<Entity> = self
            .drives
            .iter()
            .filter(|(_, d)| d.bodies.0 == handle || d.bodies.1 == handle)
            .map(|(e, _)| *e)
            .collect();
        for e in driven {
            self.unrealize_drive(e);
        }
        let w = &mut self.world;
        w.bodies.remove(
            handle,
            &mut w.islands,
            &mut w.colliders,
            &mut w.impulse_joints,
            &mut w.multibody_joints,
            &mut w.soft_bodies,
            true,
        );
    }

    /// Brings hinge `entity` to the `desired` mode between `bodies`.
    fn reconcile_hinge(
        &mut self,
        entity: Entity,
        frame: &Hinge,
        desired: Option<Option<&Clearance>>,
        bodies: (RigidBodyHandle, RigidBodyHandle),
    ) -> Result<()> {
        let context = |e: Error| e.within(&format!("hinge {entity}"));
        frame.validate().map_err(context)?;
        if let Some(r) = self.hinges.get(&entity) {
            let same_place = r.bodies == bodies && r.frame == *frame;
            match (r.joint, desired) {
                (HingeJoint::Ideal(_), Some(None)) if same_place => return Ok(()),
                (HingeJoint::Clearance(_) | HingeJoint::LargeStep(_), Some(Some(c)))
                    if same_place && r.clearance.as_ref() == Some(c) =>
                {
                    return Ok(());
                }
                // The large-step swaps, in place: the same conversions.
                (HingeJoint::Ideal(j), Some(Some(c)))
                    if same_place && c.model == ClearanceModel::LargeStep =>
                {
                    let h = self
                        .large_step
                        .convert_revolute(
                            j,
                            BearingSide::Body1,
                            named(c, entity),
                            &mut self.world.impulse_joints,
                        )
                        .map_err(context)?;
                    let r = self.hinges.get_mut(&entity).expect("realised");
                    r.joint = HingeJoint::LargeStep(h);
                    r.clearance = Some(c.clone());
                    return Ok(());
                }
                (HingeJoint::LargeStep(k), Some(None)) if same_place => {
                    let j = self
                        .large_step
                        .revert_to_revolute(
                            k,
                            &mut self.world.bodies,
                            &mut self.world.impulse_joints,
                        )
                        .map_err(context)?;
                    let r = self.hinges.get_mut(&entity).expect("realised");
                    r.joint = HingeJoint::Ideal(j);
                    r.clearance = None;
                    return Ok(());
                }
                // The swap, in place: the plain API's conversions.
                (HingeJoint::Ideal(j), Some(Some(c))) if same_place => {
                    let h = self
                        .clearance
                        .convert_revolute(
                            j,
                            BearingSide::Body1,
                            named(c, entity),
                            &mut self.world.impulse_joints,
                        )
                        .map_err(context)?;
                    self.changed = true;
                    let r = self.hinges.get_mut(&entity).expect("realised");
                    r.joint = HingeJoint::Clearance(h);
                    r.clearance = Some(c.clone());
                    return Ok(());
                }
                (HingeJoint::Clearance(k), Some(None)) if same_place => {
                    let j = self
                        .clearance
                        .revert_to_revolute(
                            k,
                            &mut self.world.bodies,
                            &mut self.world.impulse_joints,
                        )
                        .map_err(context)?;
                    self.changed = true;
                    let r = self.hinges.get_mut(&entity).expect("realised");
                    r.joint = HingeJoint::Ideal(j);
                    r.clearance = None;
                    self.clearance_removed(k);
                    return Ok(());
                }
                _ => self.unrealize_hinge(entity),
            }
        }
        let Some(clearance) = desired else {
            return Ok(());
        };
        let (joint, clearance) = match clearance {
            None => {
                let j =
                    self.world
                        .impulse_joints
                        .insert(bodies.0, bodies.1, frame.revolute(), true);
                (HingeJoint::Ideal(j), None)
            }
            Some(c) if c.model == ClearanceModel::LargeStep => {
                let joint = named(c, entity)
                    .large_step_joint(
                        frame.local_anchor1,
                        frame.local_anchor2,
                        frame.local_axis1,
                        frame.local_axis2,
                    )
                    .map_err(context)?;
                let h = self.large_step.insert(
                    bodies.0,
                    bodies.1,
                    joint,
                    &mut self.world.impulse_joints,
                );
                (HingeJoint::LargeStep(h), Some(c.clone()))
            }
            Some(c) => {
                let joint = named(c, entity)
                    .joint(
                        frame.local_anchor1,
                        frame.local_anchor2,
                        frame.local_axis1,
                        frame.local_axis2,
                    )
                    .map_err(context)?;
                let h = self.clearance.insert(
                    bodies.0,
                    bodies.1,
                    joint,
                    &mut self.world.impulse_joints,
                );
                (HingeJoint::Clearance(h), Some(c.clone()))
            }
        };
        self.changed = true;
        self.hinges.insert(
            entity,
            RealizedHinge {
                joint,
                bodies,
                frame: frame.clone(),
                clearance,
            },
        );
        Ok(())
    }

    /// Brings the drive of hinge `entity` to `desired`.
    fn reconcile_drive(
        &mut self,
        entity: Entity,
        frame: &Hinge,
        desired: Option<&Drive>,
        bodies: (RigidBodyHandle, RigidBodyHandle),
    ) -> Result<()> {
        if let Some(d) = self.drives.get(&entity) {
            if Some(&d.drive) == desired && d.bodies == bodies && d.axis == frame.local_axis1 {
                return Ok(());
            }
            self.unrealize_drive(entity);
        }
        let Some(drive) = desired else {
            return Ok(());
        };
        let spring = TorsionSpring::new(
            bodies.0,
            bodies.1,
            frame.local_axis1,
            drive.torque0,
            drive.stiffness,
        )
        .map_err(|e| e.within(&format!("drive {entity}")))?;
        let mut set = DriveSet::new();
        set.insert(spring);
        self.changed = true;
        self.drives.insert(
            entity,
            RealizedDrive {
                set,
                drive: *drive,
                bodies,
                axis: frame.local_axis1,
            },
        );
        Ok(())
    }
}

/// `c` with the entity as its name unless it has one.
fn named(c: &Clearance, entity: Entity) -> Clearance {
    let mut c = c.clone();
    if c.name.is_none() {
        c.name = Some(format!("hinge {entity}"));
    }
    c
}

/// A rigid body. Spawn it with a Rapier description ([`Body::new`]); the sync system inserts it
/// into [`Physics::world`] and records its handle. Removing the component (or despawning the
/// entity) removes the body, with the hinges and drives attached to it.
#[derive(Component, Debug)]
#[require(BodyState)]
pub struct Body {
    pending: Option<Box<RigidBody>>,
    handle: Option<RigidBodyHandle>,
}

impl Body {
    /// A body to insert, e.g. from `RigidBodyBuilder::dynamic()...`. Use `can_sleep(false)` for
    /// slow mechanisms: Rapier's sleep thresholds freeze them (the paper's panel fell asleep at 0.5 s).
    pub fn new(body: impl Into<RigidBody>) -> Self {
        Body {
            pending: Some(Box::new(body.into())),
            handle: None,
        }
    }

    /// A body already in [`Physics::world`].
    pub fn from_handle(handle: RigidBodyHandle) -> Self {
        Body {
            pending: None,
            handle: Some(handle),
        }
    }

    /// The Rapier handle, once inserted.
    pub fn handle(&self) -> Option<RigidBodyHandle> {
        self.handle
    }
}

/// Where a body is and how it moves, after the last step.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct BodyState {
    /// Position of the body frame's origin, m.
    pub translation: Vector,
    /// Orientation.
    pub rotation: Rotation,
    /// Linear velocity of the centre of mass, m/s.
    pub linvel: Vector,
    /// Angular velocity, rad/s.
    pub angvel: Vector,
}

/// A hinge between two [`Body`] entities: `body1` carries the bearing, `body2` the journal.
/// Anchors and axes are in each body's frame (as Rapier's `RevoluteJointBuilder`). What it is
/// made of is a second component: [`IdealHinge`] or [`ClearanceHinge`].
#[derive(Component, Clone, Debug, PartialEq)]
#[require(HingeState)]
pub struct Hinge {
    /// The bearing's body entity.
    pub body1: Entity,
    /// The journal's body entity.
    pub body2: Entity,
    /// Bearing centre in body 1's frame, m.
    pub local_anchor1: Vector,
    /// Journal centre in body 2's frame, m.
    pub local_anchor2: Vector,
    /// Hinge axis in body 1's frame.
    pub local_axis1: Vector,
    /// Hinge axis in body 2's frame.
    pub local_axis2: Vector,
}

impl Hinge {
    /// A hinge about `axis` (both bodies' frames), anchors at both bodies' origins.
    pub fn new(body1: Entity, body2: Entity, axis: Vector) -> Self {
        Hinge {
            body1,
            body2,
            local_anchor1: Vector::ZERO,
            local_anchor2: Vector::ZERO,
            local_axis1: axis,
            local_axis2: axis,
        }
    }
    /// Sets the bearing centre in body 1's frame.
    pub fn local_anchor1(mut self, anchor: Vector) -> Self {
        self.local_anchor1 = anchor;
        self
    }
    /// Sets the journal centre in body 2's frame.
    pub fn local_anchor2(mut self, anchor: Vector) -> Self {
        self.local_anchor2 = anchor;
        self
    }
    /// Sets the axis in body 2's frame.
    pub fn local_axis2(mut self, axis: Vector) -> Self {
        self.local_axis2 = axis;
        self
    }
    /// Checks that the anchors are finite and the axes finite and non-zero.
    pub fn validate(&self) -> Result<()> {
        unit_vector("local_axis1", self.local_axis1)?;
        unit_vector("local_axis2", self.local_axis2)?;
        for (field, v) in [
            ("local_anchor1", self.local_anchor1),
            ("local_anchor2", self.local_anchor2),
        ] {
            if !v.is_finite() {
                return Err(Error::invalid(field, format!("must be finite (got {v:?})")));
            }
        }
        Ok(())
    }

    /// The ideal Rapier revolute joint of this hinge (axes normalised, contacts between the
    /// bodies disabled).
    pub fn revolute(&self) -> RevoluteJoint {
        RevoluteJoint {
            data: GenericJointBuilder::new(JointAxesMask::LOCKED_REVOLUTE_AXES)
                .local_axis1(self.local_axis1.normalize_or_zero())
                .local_axis2(self.local_axis2.normalize_or_zero())
                .local_anchor1(self.local_anchor1)
                .local_anchor2(self.local_anchor2)
                .contacts_enabled(false)
                .build(),
        }
    }
}

/// Makes a [`Hinge`] an ideal Rapier revolute joint.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct IdealHinge;

/// Makes a [`Hinge`] a clearance joint with these laws (takes precedence over [`IdealHinge`]).
/// [`Clearance::model`] chooses the model: the compliant contact law (the default; it needs small
/// steps and `num_solver_iterations = 1`, as [`Physics::new`] sets) or the large-step constraint,
/// `ClearanceHinge(Clearance::steel_improved_liu(..)?.model(ClearanceModel::LargeStep))`, for 1/60 s or 1 kHz
/// worlds with any number of solver iterations.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct ClearanceHinge(pub Clearance);

/// A torsion spring `T = T0 - k theta` on the [`Hinge`] of the same entity: `+T` on body 2 and
/// `-T` on body 1 about the hinge axis; `theta` is zero where the drive starts.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct Drive {
    /// Preload `T0`, N m.
    pub torque0: f64,
    /// Stiffness `k`, N m/rad.
    pub stiffness: f64,
}

impl Drive {
    /// Preload `torque0` (N m) and stiffness (N m/rad).
    pub fn torsion_spring(torque0: f64, stiffness: f64) -> Self {
        Drive { torque0, stiffness }
    }
    /// Preload `torque0` (N m) and stiffness in N m/deg (the paper's unit).
    pub fn per_degree(torque0: f64, stiffness_nm_per_deg: f64) -> Self {
        Drive {
            torque0,
            stiffness: stiffness_nm_per_deg.to_degrees(),
        }
    }
}

/// What a hinge did over the last step.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct HingeState {
    /// What the hinge is realised as.
    pub mode: HingeMode,
    /// Relative rotation of body 2 about the axis since the hinge was first realised, rad.
    pub angle: f64,
    /// Relative angular rate about the axis, rad/s.
    pub rate: f64,
    /// Joint force magnitude over the last step, N. Clearance: the contact force (exact). Large
    /// step: the normal force of the radial limit (its last substep's impulse over the substep).
    /// Ideal: the exact reaction at the state the step reached, from the constrained equations of
    /// the ideal revolute hinges under gravity, your forces and the drives
    /// ([`ReactionSolver`]); contacts with colliders and other
    /// kinds of joints on the same bodies are not part of it.
    pub force: f64,
    /// Largest `force` so far, N.
    pub peak_force: f64,
    /// Contact onsets so far (clearance; large step: impacts, onsets above the joint's
    /// `min_impact_speed`).
    pub impacts: u64,
    /// Penetration (clearance; negative: free gap), m.
    pub penetration: f64,
    /// Eccentricity of the journal in the bearing (clearance; world), m.
    pub eccentricity: Vector,
    /// Motion mode (clearance).
    pub contact: ContactMode,
    angle_tracker: HingeAngle,
}

/// The stages of a physics step, in this order.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PhysicsSet {
    /// Components to Rapier: bodies, hinges (with conversions), drives.
    Sync,
    /// Torsion-spring torques and clearance contact and friction forces at the current state,
    /// when the stepper has not evaluated them yet ([`apply_forces`]).
    Forces,
    /// One accepted step of the [`Stepper`].
    Step,
    /// Rapier to [`HingeState`] and [`BodyState`].
    Record,
}

/// Inserts new [`Body`] components into Rapier and removes the bodies of removed ones.
pub fn sync_bodies(mut physics: ResMut<Physics>, mut query: Query<(Entity, &mut Body)>) {
    if physics.error.is_some() {
        return;
    }
    let mut items: Vec<(Entity, Mut<Body>)> = query.iter_mut().collect();
    items.sort_by_key(|(e, _)| *e);
    let mut seen = BTreeSet::new();
    for (entity, mut body) in items {
        seen.insert(entity);
        if let Some(rb) = body.pending.take() {
            physics.remove_body(entity);
            physics.changed = true;
            let h = physics.world.bodies.insert(*rb);
            physics.bodies.insert(entity, h);
            body.handle = Some(h);
        } else if let Some(h) = body.handle
            && physics.bodies.get(&entity) != Some(&h)
        {
            if !physics.world.bodies.contains(h) {
                physics.fail(Error::invalid(
                    format!("body {entity}"),
                    format!("no rigid body with handle {h:?} in the Rapier world"),
                ));
                return;
            }
            // A new handle for this entity: its previous body goes, as on removal.
            physics.remove_body(entity);
            physics.changed = true;
            physics.bodies.insert(entity, h);
        }
    }
    let gone: Vec<Entity> = physics
        .bodies
        .keys()
        .filter(|e| !seen.contains(*e))
        .copied()
        .collect();
    for e in gone {
        physics.remove_body(e);
    }
}

/// Realises each [`Hinge`] as its mode component says (converting in place when only the mode
/// changed), its [`Drive`], and removes the joints and drives of removed components.
#[allow(clippy::type_complexity)]
pub fn sync_hinges(
    mut physics: ResMut<Physics>,
    mut query: Query<(
        Entity,
        &Hinge,
        Has<IdealHinge>,
        Option<&ClearanceHinge>,
        Option<&Drive>,
        &mut HingeState,
    )>,
) {
    if physics.error.is_some() {
        return;
    }
    let mut items: Vec<_> = query.iter_mut().collect();
    items.sort_by_key(|item| item.0);
    let mut seen = BTreeSet::new();
    for (entity, frame, ideal, clearance, drive, mut state) in items {
        seen.insert(entity);
        let body = |e: Entity, field: &str| {
            physics.body(e).ok_or_else(|| {
                Error::invalid(
                    format!("hinge {entity}.{field}"),
                    format!(
                        "entity {e} has no Body (spawn a hinge's bodies with or before it, and \
                         despawn the hinge with them)"
                    ),
                )
            })
        };
        let bodies = match (body(frame.body1, "body1"), body(frame.body2, "body2")) {
            (Ok(b1), Ok(b2)) => (b1, b2),
            (Err(e), _) | (_, Err(e)) => {
                physics.fail(e);
                return;
            }
        };
        let desired = match (clearance, ideal) {
            (Some(c), _) => Some(Some(&c.0)),
            (None, true) => Some(None),
            (None, false) => None,
        };
        if let Err(e) = physics.reconcile_hinge(entity, frame, desired, bodies) {
            physics.fail(e);
            return;
        }
        if let Err(e) = physics.reconcile_drive(entity, frame, drive, bodies) {
            physics.fail(e);
            return;
        }
        state.mode = match physics.joint(entity) {
            None => HingeMode::None,
            Some(HingeJoint::Ideal(_)) => HingeMode::Ideal,
            Some(HingeJoint::Clearance(_)) => HingeMode::Clearance,
            Some(HingeJoint::LargeStep(_)) => HingeMode::LargeStep,
        };
        if !state.angle_tracker.has_reference() {
            let w = &physics.world.bodies;
            if let (Some(r1), Some(r2)) = (w.get(bodies.0), w.get(bodies.1)) {
                state
                    .angle_tracker
                    .set_reference(r1.rotation(), r2.rotation());
            }
        }
    }
    let gone: Vec<Entity> = physics
        .hinges
        .keys()
        .chain(physics.drives.keys())
        .filter(|e| !seen.contains(*e))
        .copied()
        .collect();
    for e in gone {
        physics.unrealize_hinge(e);
        physics.unrealize_drive(e);
    }
}

/// Evaluates the force sources (torsion springs, the clearance force hook) at the current state
/// when the stepper needs it: before the first step and after the sync systems changed
/// something. Otherwise the stepper already evaluated them at the end of the last step.
pub fn apply_forces(mut physics: ResMut<Physics>) {
    if physics.error.is_some() {
        return;
    }
    let Physics {
        world,
        clearance,
        drives,
        stepper,
        changed,
        ..
    } = &mut *physics;
    if std::mem::take(changed) {
        stepper.invalidate(false);
    }
    follow_dt(stepper, world);
    let mut sources = ecs_sources(clearance, drives);
    if let Err(e) = stepper.prepare(world, &mut sources) {
        physics.fail(e);
    }
}

/// Fixed steps follow `integration_parameters.dt` as the user sets it, between any two steps.
fn follow_dt(stepper: &mut Stepper, world: &PhysicsWorld) {
    let mut control = *stepper.control();
    if control.mode == StepMode::Fixed {
        control.max_dt = world.integration_parameters.dt;
        stepper.set_control(control);
    }
}

/// The force sources of the ECS world, in a fixed order (drives by entity, then the clearance
/// joints: the runner's order, so both add forces to a body in the same order, to the bit).
fn ecs_sources<'a>(
    clearance: &'a mut ClearanceJointSet,
    drives: &'a mut BTreeMap<Entity, RealizedDrive>,
) -> Vec<&'a mut dyn ForceSource> {
    let mut v: Vec<&mut dyn ForceSource> = Vec::with_capacity(1 + drives.len());
    for d in drives.values_mut() {
        v.push(&mut d.set);
    }
    v.push(clearance);
    v
}

/// One accepted step of the [`Stepper`] (fixed steps of `world.integration_parameters.dt` unless
/// [`Physics::set_step_control`] chose otherwise): variable-step consistent kicks, step
/// acceptance, guards. An error stops the systems where the state was last valid.
pub fn step_physics(mut physics: ResMut<Physics>) {
    if physics.error.is_some() {
        return;
    }
    let Physics {
        world,
        clearance,
        drives,
        stepper,
        ..
    } = &mut *physics;
    let dt = world.integration_parameters.dt;
    follow_dt(stepper, world);
    let until = stepper.time() + dt;
    let mut sources = ecs_sources(clearance, drives);
    let result = stepper.step(world, &mut sources, until);
    drop(sources);
    // Rapier's `dt` as the user set it (the stepper sets it per step).
    physics.world.integration_parameters.dt = dt;
    if let Err(mut e) = result {
        if let Error::StepTooLarge { field, .. } = &mut e {
            *field = "Physics::world.integration_parameters.dt".into();
        }
        physics.fail(e);
    }
}

/// Prepares the large-step clearance joints for the step
/// ([`LargeStepJointSet::before_step`]: substeps, friction motors).
pub fn prepare_large_step(mut physics: ResMut<Physics>) {
    if physics.error.is_some() {
        return;
    }
    let Physics {
        world, large_step, ..
    } = &mut *physics;
    large_step.before_step(
        &mut world.bodies,
        &mut world.impulse_joints,
        &world.integration_parameters,
    );
}

/// Finishes the step for the large-step clearance joints ([`LargeStepJointSet::after_step`]:
/// readout and the impacts' bounce), before [`record`].
pub fn finish_large_step(mut physics: ResMut<Physics>) {
    if physics.error.is_some() {
        return;
    }
    let Physics {
        world, large_step, ..
    } = &mut *physics;
    large_step.after_step(&mut world.bodies, &world.impulse_joints);
}

/// Copies the state of the step into [`HingeState`] and [`BodyState`].
pub fn record(
    mut physics: ResMut<Physics>,
    mut hinges: Query<(Entity, &Hinge, &mut HingeState)>,
    mut bodies: Query<(&Body, &mut BodyState)>,
) {
    if physics.error.is_some() {
        return;
    }
    let physics = &mut *physics;
    // Exact ideal reactions at this state (the runner's piece).
    physics.ideal_joints.clear();
    let mut ideal_entities = Vec::new();
    for (e, r) in &physics.hinges {
        if let HingeJoint::Ideal(_) = r.joint {
            physics.ideal_joints.push(IdealRevolute {
                body1: r.bodies.0,
                body2: r.bodies.1,
                local_anchor1: r.frame.local_anchor1,
                local_anchor2: r.frame.local_anchor2,
                local_axis1: unit_vector("axis", r.frame.local_axis1).unwrap_or(Vector::X),
            });
            ideal_entities.push(*e);
        }
    }
    let gravity = physics.world.gravity;
    // The sources' wrenches act during the steps only: the solver gets them explicitly.
    physics.source_wrenches.clear();
    let Physics {
        drives,
        clearance,
        source_wrenches,
        ..
    } = &mut *physics;
    for d in drives.values() {
        source_wrenches.extend_from_slice(d.set.wrenches());
    }
    source_wrenches.extend_from_slice(clearance.wrenches());
    let ideal_forces: BTreeMap<Entity, f64> = physics
        .reactions
        .solve_with(
            &physics.world.bodies,
            &physics.ideal_joints,
            gravity,
            &physics.source_wrenches,
        )
        .map(|f| {
            ideal_entities
                .iter()
                .zip(f)
                .map(|(e, f)| (*e, f.length()))
                .collect()
        })
        .unwrap_or_default();
    let w = &physics.world;
    for (body, mut state) in bodies.iter_mut() {
        if let Some(rb) = body.handle.and_then(|h| w.bodies.get(h)) {
            *state = BodyState {
                translation: rb.translation(),
                rotation: *rb.rotation(),
                linvel: rb.linvel(),
                angvel: rb.angvel(),
            };
        }
    }
    for (entity, frame, mut state) in hinges.iter_mut() {
        let Some(r) = physics.hinges.get(&entity) else {
            continue;
        };
        let (Some(rb1), Some(rb2)) = (w.bodies.get(r.bodies.0), w.bodies.get(r.bodies.1)) else {
            continue;
        };
        let axis1 = unit_vector("axis", frame.local_axis1).unwrap_or(Vector::X);
        state.angle = state
            .angle_tracker
            .update(rb1.rotation(), rb2.rotation(), axis1);
        state.rate = (rb2.angvel() - rb1.angvel()).dot(*rb1.rotation() * axis1);
        match r.joint {
            HingeJoint::Ideal(_) => {
                state.force = ideal_forces.get(&entity).copied().unwrap_or(0.0);
                state.penetration = 0.0;
                state.eccentricity = Vector::ZERO;
                state.contact = ContactMode::FreeFlight;
            }
            HingeJoint::Clearance(c) => {
                if let Some(j) = physics.clearance.get(c) {
                    let rep = j.report();
                    state.force = rep.force.on_journal.length();
                    state.penetration = rep.state.penetration;
                    state.eccentricity = rep.state.eccentricity;
                    state.contact = rep.mode;
                    if rep.onset {
                        state.impacts += 1;
                    }
                }
            }
            HingeJoint::LargeStep(k) => {
                if let Some(j) = physics.large_step.get(k) {
                    let rep = j.report();
                    state.force = rep.normal_force;
                    state.penetration = rep.eccentricity.length() - j.clearance();
                    state.eccentricity = rep.eccentricity;
                    state.contact = match (rep.contact, rep.onset) {
                        (false, _) => ContactMode::FreeFlight,
                        (true, true) => ContactMode::Impact,
                        (true, false) => ContactMode::Continuous,
                    };
                    if rep.impact {
                        state.impacts += 1;
                    }
                }
            }
        }
        state.peak_force = state.peak_force.max(state.force);
    }
}

/// Adds the physics systems to `schedule`, in [`PhysicsSet`] order.
pub fn add_physics_systems(schedule: &mut Schedule) {
    schedule.configure_sets(
        (
            PhysicsSet::Sync,
            PhysicsSet::Forces,
            PhysicsSet::Step,
            PhysicsSet::Record,
        )
            .chain(),
    );
    schedule.add_systems((
        (sync_bodies, sync_hinges).chain().in_set(PhysicsSet::Sync),
        apply_forces.in_set(PhysicsSet::Forces),
        step_physics.in_set(PhysicsSet::Step),
        record.in_set(PhysicsSet::Record),
    ));
    schedule.add_systems((
        prepare_large_step
            .in_set(PhysicsSet::Forces)
            .after(apply_forces),
        finish_large_step.in_set(PhysicsSet::Record).before(record),
    ));
}

/// A schedule with the physics systems: one run is one physics step.
pub fn physics_schedule() -> Schedule {
    let mut schedule = Schedule::default();
    add_physics_systems(&mut schedule);
    schedule
}

/// Runs `schedule` (one physics step) and returns the error it met, if any (taken out of
/// [`Physics`]).
pub fn run_step(world: &mut World, schedule: &mut Schedule) -> Result<()> {
    if !world.contains_resource::<Physics>() {
        return Err(Error::invalid(
            "Physics",
            "no such resource in the world: insert one with `world.insert_resource(Physics::new(dt, gravity))`",
        ));
    }
    schedule.run(world);
    world.clear_trackers();
    match world.resource_mut::<Physics>().take_error() {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::laws::{Bai, FrictionModel};
    use crate::scene::runner::{RunOptions, Simulation, Twins};
    use crate::scene::{Scene, StepMode};
    use rapier3d_f64::prelude::{MassProperties, RigidBodyBuilder};

    fn clearance() -> Clearance {
        Clearance::steel_improved_liu(0.010, 0.2e-3, 0.016)
            .unwrap()
            .friction(FrictionModel::Bai(Bai::DRY))
    }

    /// A 2 kg arm whose centre of mass hangs 0.3 m below `(x, 0, 0)`.
    fn arm_at(x: f64) -> Body {
        Body::new(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(x, -0.3, 0.0))
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    2.0,
                    Vector::splat(0.02),
                ))
                .can_sleep(false),
        )
    }

    /// A 2 kg arm hanging 0.3 m below a fixed base on an ideal hinge about z.
    fn pendulum(dt: f64) -> (World, Schedule, Entity, Entity) {
        let mut world = World::new();
        world.insert_resource(Physics::new(dt, Vector::new(0.0, -9.81, 0.0)));
        let base = world.spawn(Body::new(RigidBodyBuilder::fixed())).id();
        let arm = world.spawn(arm_at(0.0)).id();
        let hinge = world
            .spawn((
                Hinge::new(base, arm, Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0)),
                IdealHinge,
            ))
            .id();
        (world, physics_schedule(), arm, hinge)
    }

    fn steps(world: &mut World, schedule: &mut Schedule, n: usize) -> Result<()> {
        for _ in 0..n {
            run_step(world, schedule)?;
        }
        Ok(())
    }

    #[test]
    fn swapping_the_mode_converts_the_rapier_joint_both_ways() {
        let (mut world, mut schedule, arm, hinge) = pendulum(1e-5);
        steps(&mut world, &mut schedule, 10).unwrap();
        let p = world.resource::<Physics>();
        assert!(matches!(p.joint(hinge), Some(HingeJoint::Ideal(_))));
        assert_eq!(p.world.impulse_joints.len(), 1);
        assert_eq!(
            world.get::<HingeState>(hinge).unwrap().mode,
            HingeMode::Ideal
        );

        // Swap in place: the revolute becomes a clearance joint (plus its out-of-plane lock).
        world
            .entity_mut(hinge)
            .remove::<IdealHinge>()
            .insert(ClearanceHinge(clearance()));
        steps(&mut world, &mut schedule, 20_000).unwrap();
        let p = world.resource::<Physics>();
        let j = p.clearance_joint(hinge).expect("converted");
        assert_eq!(j.local_anchor2(), Vector::new(0.0, 0.3, 0.0));
        assert_eq!(p.clearance().len(), 1);
        assert_eq!(p.world.impulse_joints.len(), 1, "only the lock");
        let s = world.get::<HingeState>(hinge).unwrap();
        assert_eq!(s.mode, HingeMode::Clearance);
        assert!(s.impacts > 0);
        assert!((s.force - 19.62).abs() < 0.02, "{}", s.force);
        assert!(s.penetration > 0.0);

        // And back: ideal again, and the contact force taken off the arm.
        world
            .entity_mut(hinge)
            .remove::<ClearanceHinge>()
            .insert(IdealHinge);
        steps(&mut world, &mut schedule, 1).unwrap();
        let p = world.resource::<Physics>();
        assert!(p.clearance().is_empty());
        assert!(matches!(p.joint(hinge), Some(HingeJoint::Ideal(_))));
        let rb = &p.world.bodies[p.body(arm).unwrap()];
        assert_eq!(rb.user_force(), Vector::ZERO);
        assert_eq!(rb.user_torque(), Vector::ZERO);

        // Neither mode: no joint at all; the arm falls.
        world.entity_mut(hinge).remove::<IdealHinge>();
        steps(&mut world, &mut schedule, 100).unwrap();
        let p = world.resource::<Physics>();
        assert_eq!(p.joint(hinge), None);
        assert_eq!(p.world.impulse_joints.len(), 0);
        assert_eq!(
            world.get::<HingeState>(hinge).unwrap().mode,
            HingeMode::None
        );
        assert!(world.get::<BodyState>(arm).unwrap().linvel.y < -0.005);
    }

    #[test]
    fn clearance_takes_precedence_and_handles_follow_removals() {
        // Two pendulums; removing the first clearance joint renumbers the second's handle.
        let (mut world, mut schedule, _, first) = pendulum(1e-5);
        let base = world.spawn(Body::new(RigidBodyBuilder::fixed())).id();
        let arm = world.spawn(arm_at(1.0)).id();
        let second = world
            .spawn((
                Hinge::new(base, arm, Vector::Z)
                    .local_anchor1(Vector::new(1.0, 0.0, 0.0))
                    .local_anchor2(Vector::new(0.0, 0.3, 0.0)),
                ClearanceHinge(clearance().name("second")),
            ))
            .id();
        // Both components: the clearance wins.
        world
            .entity_mut(first)
            .insert(ClearanceHinge(clearance().name("first")));
        steps(&mut world, &mut schedule, 2).unwrap();
        assert_eq!(world.resource::<Physics>().clearance().len(), 2);
        world.entity_mut(first).remove::<ClearanceHinge>();
        steps(&mut world, &mut schedule, 2).unwrap();
        let p = world.resource::<Physics>();
        assert_eq!(p.clearance().len(), 1);
        assert!(matches!(p.joint(first), Some(HingeJoint::Ideal(_))));
        assert_eq!(p.clearance_joint(second).unwrap().name(), "second");
    }

    #[test]
    fn bodies_of_an_existing_rapier_world_by_handle() {
        let mut rapier = PhysicsWorld::new();
        rapier.integration_parameters.num_solver_iterations = 1;
        rapier.integration_parameters.dt = 1e-5;
        let base = rapier.bodies.insert(RigidBodyBuilder::fixed());
        let arm = rapier.bodies.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(0.0, -0.3, 0.0))
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    2.0,
                    Vector::splat(0.02),
                ))
                .can_sleep(false),
        );
        let mut world = World::new();
        world.insert_resource(Physics::from_world(rapier));
        let (b, a) = (
            world.spawn(Body::from_handle(base)).id(),
            world.spawn(Body::from_handle(arm)).id(),
        );
        let hinge = world
            .spawn((
                Hinge::new(b, a, Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0)),
                ClearanceHinge(clearance()),
            ))
            .id();
        let mut schedule = physics_schedule();
        steps(&mut world, &mut schedule, 20_000).unwrap();
        let p = world.resource::<Physics>();
        assert_eq!(p.body(a), Some(arm));
        assert_eq!(p.world.bodies.len(), 2);
        // PhysicsWorld::new() has Rapier's default gravity, -9.81 along y.
        let s = world.get::<HingeState>(hinge).unwrap();
        assert!((s.force - 19.62).abs() < 0.02, "{}", s.force);

        // A handle that is not in the world is refused.
        let mut other = PhysicsWorld::new();
        for _ in 0..5 {
            other.bodies.insert(RigidBodyBuilder::fixed());
        }
        let stale = other.bodies.insert(RigidBodyBuilder::fixed());
        world.spawn(Body::from_handle(stale));
        let msg = run_step(&mut world, &mut schedule).unwrap_err().to_string();
        assert!(msg.contains("no rigid body with handle"), "{msg}");
    }

    #[test]
    fn despawning_a_hinge_with_its_body_removes_them_from_rapier() {
        let (mut world, mut schedule, arm, hinge) = pendulum(1e-5);
        world
            .entity_mut(hinge)
            .insert((ClearanceHinge(clearance()), Drive::torsion_spring(0.1, 0.0)));
        steps(&mut world, &mut schedule, 10).unwrap();
        world.despawn(hinge);
        world.despawn(arm);
        steps(&mut world, &mut schedule, 10).unwrap();
        let p = world.resource::<Physics>();
        assert_eq!(p.world.bodies.len(), 1, "the base is left");
        assert_eq!(p.world.impulse_joints.len(), 0);
        assert!(p.clearance().is_empty());
        assert!(p.drive(hinge).is_none());
    }

    #[test]
    fn removing_a_drive_takes_back_its_torque_exactly() {
        let mut world = World::new();
        world.insert_resource(Physics::new(1e-3, Vector::ZERO));
        let body = |x: f64| {
            Body::new(
                RigidBodyBuilder::dynamic()
                    .translation(Vector::new(x, 0.0, 0.0))
                    .additional_mass_properties(MassProperties::new(
                        Vector::ZERO,
                        1.0,
                        Vector::new(0.1, 0.2, 0.3),
                    ))
                    .can_sleep(false),
            )
        };
        let (a, b) = (world.spawn(body(0.0)).id(), world.spawn(body(1.0)).id());
        let axis = Vector::new(0.3, -1.0, 0.2);
        let hinge = world
            .spawn((
                Hinge::new(a, b, axis).local_anchor1(Vector::new(0.5, 0.0, 0.0)),
                Drive::per_degree(0.5, 0.01),
            ))
            .id();
        let mut schedule = physics_schedule();
        steps(&mut world, &mut schedule, 50).unwrap();
        let p = world.resource::<Physics>();
        assert!(
            p.drive(hinge).unwrap().angle() > 0.0,
            "the spring turned body b"
        );
        assert!(p.joint(hinge).is_none(), "no mode component: no joint");
        world.entity_mut(hinge).remove::<Drive>();
        steps(&mut world, &mut schedule, 1).unwrap();
        let p = world.resource::<Physics>();
        for e in [a, b] {
            let rb = &p.world.bodies[p.body(e).unwrap()];
            assert_eq!(rb.user_torque(), Vector::ZERO, "torque left on {e}");
        }
    }

    #[test]
    fn errors_are_values_and_stop_the_systems() {
        // No resource.
        let mut empty = World::new();
        let e = run_step(&mut empty, &mut physics_schedule()).unwrap_err();
        assert!(e.to_string().contains("Physics"), "{e}");

        // A hinge to an entity without a body.
        let (mut world, mut schedule, _, _) = pendulum(1e-5);
        let ghost = world.spawn_empty().id();
        let base = world.spawn(Body::new(RigidBodyBuilder::fixed())).id();
        let bad = world
            .spawn((Hinge::new(base, ghost, Vector::Z), IdealHinge))
            .id();
        let e = run_step(&mut world, &mut schedule).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains(&format!("hinge {bad}.body2")) && msg.contains("has no Body"),
            "{msg}"
        );
        world.despawn(bad);
        run_step(&mut world, &mut schedule).unwrap();

        // A step too large for the contact: refused when the journal hits the bearing, and the
        // world does not move on until the error is taken.
        let (mut world, mut schedule, _, hinge) = pendulum(1e-4);
        world.entity_mut(hinge).insert(ClearanceHinge(clearance()));
        let e = steps(&mut world, &mut schedule, 2_000).unwrap_err();
        match &e {
            Error::StepTooLarge { field, t, .. } => {
                assert_eq!(field, "Physics::world.integration_parameters.dt");
                assert!(t.is_some_and(|t| t.is_finite() && t > 0.0));
            }
            other => panic!("expected StepTooLarge, got {other}"),
        }
        let t = world.resource::<Physics>().time();
        world
            .resource_mut::<Physics>()
            .fail(Error::invalid("x", "y"));
        schedule.run(&mut world);
        assert_eq!(
            world.resource::<Physics>().time(),
            t,
            "halted while an error is set"
        );

        // An invalid frame is named, for ideal hinges too.
        let (mut world, mut schedule, _, hinge) = pendulum(1e-5);
        world.get_mut::<Hinge>(hinge).unwrap().local_axis2 = Vector::ZERO;
        let msg = run_step(&mut world, &mut schedule).unwrap_err().to_string();
        assert!(msg.contains(&format!("hinge {hinge}.local_axis2")), "{msg}");
        world.get_mut::<Hinge>(hinge).unwrap().local_anchor1 = Vector::new(f64::NAN, 0.0, 0.0);
        world.get_mut::<Hinge>(hinge).unwrap().local_axis2 = Vector::Z;
        let msg = run_step(&mut world, &mut schedule).unwrap_err().to_string();
        assert!(
            msg.contains(&format!("hinge {hinge}.local_anchor1")),
            "{msg}"
        );

        // An invalid clearance is named.
        let (mut world, mut schedule, _, hinge) = pendulum(1e-5);
        let mut c = clearance();
        c.min_impact_speed = -1.0;
        world.entity_mut(hinge).insert(ClearanceHinge(c));
        let msg = run_step(&mut world, &mut schedule).unwrap_err().to_string();
        assert!(
            msg.contains(&format!("hinge {hinge}.min_impact_speed")),
            "{msg}"
        );
    }

    #[test]
    fn an_unnamed_clearance_hinge_is_realised_once() {
        // The joint is named after its entity; the component is not. Comparing the two rebuilt
        // the joint (and reset its contact history) at every step: 17,659 "impacts" in 20,000
        // steps instead of the pendulum's 18.
        let (mut world, mut schedule, _, hinge) = pendulum(1e-5);
        world.entity_mut(hinge).insert(ClearanceHinge(clearance()));
        steps(&mut world, &mut schedule, 20_000).unwrap();
        let s = world.get::<HingeState>(hinge).unwrap();
        assert!(s.impacts > 0 && s.impacts < 100, "{} impacts", s.impacts);
        let p = world.resource::<Physics>();
        assert_eq!(
            p.clearance_joint(hinge).unwrap().name(),
            format!("hinge {hinge}")
        );
    }

    #[test]
    fn large_step_hinge_at_game_rate_with_rapiers_defaults() {
        // 1/60 s and Rapier's four solver iterations: the compliant model refuses both.
        let (mut world, mut schedule, arm, hinge) = pendulum(1.0 / 60.0);
        world
            .resource_mut::<Physics>()
            .world
            .integration_parameters
            .num_solver_iterations = 4;
        let large = clearance()
            .model(ClearanceModel::LargeStep)
            .restitution(0.5);
        world
            .entity_mut(hinge)
            .insert(ClearanceHinge(large.clone()));
        steps(&mut world, &mut schedule, 120).unwrap();
        let p = world.resource::<Physics>();
        assert!(matches!(p.joint(hinge), Some(HingeJoint::LargeStep(_))));
        assert!(p.clearance().is_empty());
        assert_eq!(p.large_step().len(), 1);
        assert_eq!(
            p.world.impulse_joints.len(),
            1,
            "the revolute became the play joint"
        );
        let j = p.large_step_joint(hinge).unwrap();
        assert_eq!(j.friction(), 0.25, "Bai DRY's sliding coefficient");
        let s = world.get::<HingeState>(hinge).unwrap();
        assert_eq!(s.mode, HingeMode::LargeStep);
        // Hanging at rest on the wall: the journal at the clearance, the force the weight.
        assert!((s.force - 19.62).abs() < 1e-6, "{}", s.force);
        assert!(s.penetration.abs() < 0.05 * 0.2e-3, "{}", s.penetration);
        assert_eq!(s.contact, ContactMode::Continuous);

        // Back to ideal and to large-step again, in place.
        world
            .entity_mut(hinge)
            .remove::<ClearanceHinge>()
            .insert(IdealHinge);
        steps(&mut world, &mut schedule, 2).unwrap();
        let p = world.resource::<Physics>();
        assert!(p.large_step().is_empty());
        assert!(matches!(p.joint(hinge), Some(HingeJoint::Ideal(_))));
        let rb = &p.world.bodies[p.body(arm).unwrap()];
        assert_eq!(rb.additional_solver_iterations(), 0, "substeps handed back");
        world.entity_mut(hinge).insert(ClearanceHinge(large));
        steps(&mut world, &mut schedule, 2).unwrap();
        assert_eq!(
            world.get::<HingeState>(hinge).unwrap().mode,
            HingeMode::LargeStep
        );
        // Compliant <-> large step: the model change rebuilds the joint.
        world.entity_mut(hinge).insert(ClearanceHinge(clearance()));
        world.resource_mut::<Physics>().world.integration_parameters = {
            let mut p = world.resource::<Physics>().world.integration_parameters;
            p.num_solver_iterations = 1;
            p.dt = 1e-5;
            p
        };
        steps(&mut world, &mut schedule, 2).unwrap();
        let p = world.resource::<Physics>();
        assert!(p.large_step().is_empty());
        assert_eq!(p.clearance().len(), 1);
        assert_eq!(
            world.get::<HingeState>(hinge).unwrap().mode,
            HingeMode::Clearance
        );
    }

    #[test]
    fn the_papers_scene_through_the_ecs_is_the_runners() {
        // Both twins of the paper's scene as entities, 1 s at the paper's fixed step: the ECS
        // layer makes the same Rapier calls in the same order as the runner, to the last bit.
        let mut scene = Scene::solar_panel();
        scene.run.step = StepMode::Fixed;
        scene.run.dt_s = 1e-4;
        scene.run.end_s = 1.0;
        let r = Simulation::new(
            &scene,
            RunOptions {
                twins: Twins::Both,
                skip_rows: false,
            },
        )
        .unwrap()
        .run()
        .unwrap();

        let mut world = World::new();
        world.insert_resource(Physics::new(1e-4, Vector::ZERO));
        let h = &scene.hinges[0];
        let spec = h.clearance.as_ref().unwrap();
        let d = &scene.drives[0];
        let mut hinges = Vec::new();
        for with_clearance in [false, true] {
            let bodies: Vec<Entity> = scene
                .bodies
                .iter()
                .map(|b| {
                    world
                        .spawn(Body::new(
                            RigidBodyBuilder::dynamic()
                                .translation(Vector::from(b.center_of_mass_m))
                                .additional_mass_properties(MassProperties::new(
                                    Vector::ZERO,
                                    b.mass_kg,
                                    Vector::from(b.inertia_kg_m2),
                                ))
                                .can_sleep(false),
                        ))
                        .id()
                })
                .collect();
            let point = Vector::from(h.point_m);
            let hinge = Hinge::new(bodies[0], bodies[1], Vector::from(h.axis))
                .local_anchor1(point - Vector::from(scene.bodies[0].center_of_mass_m))
                .local_anchor2(point - Vector::from(scene.bodies[1].center_of_mass_m));
            let drive = Drive::per_degree(d.torque0_nm, d.stiffness_nm_per_deg);
            let e = if with_clearance {
                let c = spec.clearance().unwrap().name("hinge");
                world.spawn((hinge, ClearanceHinge(c), drive))
            } else {
                world.spawn((hinge, IdealHinge, drive))
            };
            hinges.push(e.id());
        }
        let mut schedule = physics_schedule();
        steps(&mut world, &mut schedule, 10_000).unwrap();
        for (twin, e) in r.twins.iter().zip(hinges) {
            let s = world.get::<HingeState>(e).unwrap();
            let angle = twin.final_angles_deg()["hinge"];
            assert_eq!(s.angle.to_degrees(), angle, "{:?}", twin.kind);
            let m = &twin.hinge_metrics()["hinge"];
            assert_eq!(s.impacts, m.impacts, "{:?}", twin.kind);
            if s.mode == HingeMode::Clearance {
                assert_eq!(s.peak_force, m.peak_force_n);
            }
        }
    }
}
