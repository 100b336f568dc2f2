//! The [`Physics`] resource: the Rapier world, the clearance joints and the drives, and what each
//! entity is in them. Its crate-side methods do the work of the systems; the systems only read
//! the components and call them.

use super::components::{Drive, Hinge};
use crate::error::{Error, Result};
use crate::rapier::hinge::convert::{BearingSide, ConvertRevolute};
use crate::rapier::hinge::design::{ClearanceModel, HingeDesign};
use crate::rapier::joint::{ClearanceJoint, ClearanceJointHandle, ClearanceJointSet};
use crate::rapier::large_step::{LargeStepJoint, LargeStepJointHandle, LargeStepJointSet};
use crate::rapier::observers::reaction::{IdealJoint, ReactionSolver};
use crate::rapier::pipeline::stepper::{GuardReport, StepControl};
use crate::rapier::pipeline::world::ClearanceWorld;
use crate::rapier::sources::drive::{DriveHandle, TorsionSpring};
use bevy_ecs::prelude::*;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{ImpulseJointHandle, PhysicsWorld, RigidBody, RigidBodyHandle};
use std::collections::{BTreeMap, BTreeSet};

mod step;

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

/// Two bodies a hinge or a drive joins (bearing, journal).
type BodyPair = (RigidBodyHandle, RigidBodyHandle);

#[derive(Clone, Debug)]
struct RealizedHinge {
    joint: HingeJoint,
    bodies: BodyPair,
    frame: Hinge,
    clearance: Option<HingeDesign>,
}

#[derive(Clone, Debug)]
struct RealizedDrive {
    handle: DriveHandle,
    drive: Drive,
    bodies: BodyPair,
    axis: Vector,
}

/// The physics of an ECS world: a [`ClearanceWorld`] (the Rapier world, the clearance joints,
/// the drives and the step control: the pieces the scene runner and a plain-Rapier loop use),
/// and the map from entities to what they are in it.
#[derive(Resource)]
pub struct Physics {
    /// The world. Set gravity, the step (`world.rapier.integration_parameters.dt`) and colliders
    /// in `world.rapier`; bodies, joints and drives are managed through the components (read
    /// the sets freely, do not insert into them by hand).
    pub world: ClearanceWorld,
    bodies: BTreeMap<Entity, RigidBodyHandle>,
    hinges: BTreeMap<Entity, RealizedHinge>,
    drives: BTreeMap<Entity, RealizedDrive>,
    error: Option<Error>,
    /// Set when the sync systems changed joints, drives or bodies: the force sources are
    /// evaluated again before the next step.
    changed: bool,
    /// Set when the hinges must be reconciled again although no hinge component changed: a
    /// body was inserted or removed, or an error stopped a reconciliation halfway.
    hinges_stale: bool,
    /// Reconciliations of the hinges so far (the tests check that unchanged steps skip them).
    #[cfg(test)]
    pub(super) hinge_passes: u64,
    reactions: ReactionSolver,
    ideal_joints: Vec<IdealJoint>,
    /// Set by [`begin_frame`](Self::begin_frame): the next recorded step empties the hinges'
    /// frame figures first.
    new_frame: bool,
    /// The end of the frame [`run_frame`](super::run_frame) is running, s: its last step lands
    /// there.
    frame_end: Option<f64>,
    /// Each hinge's force at the start of the step just taken, N: the force that step held.
    start_forces: BTreeMap<Entity, f64>,
    /// The ideal hinges' reactions at the state the last record saw, with the step count then.
    ideal_cache: (u64, BTreeMap<Entity, f64>),
}

impl Physics {
    /// An empty Rapier world stepping by `dt` (s) under `gravity` (m/s^2), with Rapier's
    /// defaults otherwise (4 solver iterations): ready for ideal, large-step and sub-cycled
    /// compliant hinges (the default). An explicit compliant hinge
    /// (`ContactIntegration::Explicit`) needs one solver iteration; set
    /// `world.rapier.integration_parameters.num_solver_iterations = 1` yourself before spawning such a
    /// hinge (see the [module docs](super) for why and what it costs the world's other bodies).
    pub fn new(dt: f64, gravity: Vector) -> Self {
        let mut world = PhysicsWorld::new();
        world.integration_parameters.dt = dt;
        world.gravity = gravity;
        Self::from_world(world)
    }

    /// Wraps an existing Rapier world as it is: its settings, bodies, colliders and joints stay
    /// (entities refer to its bodies with [`Body::from_handle`](super::Body::from_handle)). The
    /// layer never changes the world's settings; a hinge the settings cannot serve is refused
    /// with an error (see the [module docs](super)).
    pub fn from_world(world: PhysicsWorld) -> Self {
        let dt = world.integration_parameters.dt;
        Physics {
            world: ClearanceWorld::new(world, StepControl::fixed(dt)),
            bodies: BTreeMap::new(),
            hinges: BTreeMap::new(),
            drives: BTreeMap::new(),
            error: None,
            changed: true,
            hinges_stale: true,
            #[cfg(test)]
            hinge_passes: 0,
            reactions: ReactionSolver::default(),
            ideal_joints: Vec::new(),
            new_frame: true,
            frame_end: None,
            start_forces: BTreeMap::new(),
            ideal_cache: (u64::MAX, BTreeMap::new()),
        }
    }

    /// The step control: fixed steps of `world.rapier.integration_parameters.dt` by default (changing
    /// `dt` between steps is followed). With [`StepControl::adaptive`] each run of the schedule
    /// takes ONE accepted step of the stepper's choice, at most up to `time() + dt`: inside
    /// contacts that step is far shorter than a frame, so a game loop runs the schedule until
    /// `time()` reaches the frame's time ([`run_frame`](super::run_frame); each run records its
    /// state and counts, and adds to the frame's mean and peak force).
    pub fn set_step_control(&mut self, control: StepControl) {
        self.world.step_control = control;
    }

    /// What the run-time guards recorded (rejected steps, penetrations beyond a law's validity,
    /// steps at the floor).
    pub fn guards(&self) -> &GuardReport {
        self.world.guards()
    }

    /// The clearance joints (read-only: they follow the
    /// [`ClearanceHinge`](super::ClearanceHinge) components).
    pub fn clearance(&self) -> &ClearanceJointSet {
        &self.world.clearance
    }

    /// The large-step clearance joints (read-only: they follow the
    /// [`ClearanceHinge`](super::ClearanceHinge) components whose [`HingeDesign::model`] is
    /// [`ClearanceModel::LargeStep`]).
    pub fn large_step(&self) -> &LargeStepJointSet {
        &self.world.large_step
    }

    /// The large-step clearance joint of a [`ClearanceHinge`](super::ClearanceHinge) entity.
    pub fn large_step_joint(&self, entity: Entity) -> Option<&LargeStepJoint> {
        match self.joint(entity)? {
            HingeJoint::LargeStep(h) => self.world.large_step.get(h),
            _ => None,
        }
    }

    /// Begins a frame: the hinges' frame figures
    /// ([`HingeState::frame_mean_force`](super::HingeState::frame_mean_force),
    /// [`frame_peak_force`](super::HingeState::frame_peak_force)) cover the steps from the next
    /// one until the next call. [`run_step`](super::run_step) and
    /// [`run_frame`](super::run_frame) call it; a schedule run by hand calls it at the start of
    /// each frame (without it, the frame is every step since the world's first).
    pub fn begin_frame(&mut self) {
        self.new_frame = true;
    }

    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.world.time()
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.world.steps()
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

    /// The Rapier body of a [`Body`](super::Body) entity.
    pub fn body(&self, entity: Entity) -> Option<RigidBodyHandle> {
        self.bodies.get(&entity).copied()
    }

    /// The Rapier joint of a [`Hinge`] entity.
    pub fn joint(&self, entity: Entity) -> Option<HingeJoint> {
        self.hinges.get(&entity).map(|h| h.joint)
    }

    /// The clearance joint of a [`ClearanceHinge`](super::ClearanceHinge) entity.
    pub fn clearance_joint(&self, entity: Entity) -> Option<&ClearanceJoint> {
        match self.joint(entity)? {
            HingeJoint::Clearance(h) => self.world.clearance.get(h),
            HingeJoint::Ideal(_) | HingeJoint::LargeStep(_) => None,
        }
    }

    /// The drive of a [`Drive`] entity.
    pub fn drive(&self, entity: Entity) -> Option<&TorsionSpring> {
        self.world.drives.get(self.drives.get(&entity)?.handle)
    }

    /// Records `error` unless one is already set (the first error is the cause).
    pub(super) fn fail(&mut self, error: Error) {
        self.hinges_stale = true;
        if self.error.is_none() {
            self.error = Some(error);
        }
    }

    /// Whether the hinges must be reconciled although no hinge component changed (and clears
    /// it): see [`sync_hinges`](super::sync_hinges).
    pub(super) fn take_hinges_stale(&mut self) -> bool {
        std::mem::take(&mut self.hinges_stale)
    }

    /// The joint of hinge `entity` and the bodies it was realised between.
    pub(super) fn realized_hinge(&self, entity: Entity) -> Option<(HingeJoint, BodyPair)> {
        self.hinges.get(&entity).map(|h| (h.joint, h.bodies))
    }

    // ----- Bodies -----

    /// Inserts `body` for `entity` (replacing its previous body) and returns its handle.
    pub(super) fn insert_body(&mut self, entity: Entity, body: RigidBody) -> RigidBodyHandle {
        self.remove_body(entity);
        self.changed = true;
        self.hinges_stale = true;
        let h = self.world.rapier.bodies.insert(body);
        self.bodies.insert(entity, h);
        h
    }

    /// Makes the existing Rapier body `handle` the body of `entity` (its previous body goes, as
    /// on removal).
    pub(super) fn adopt_body(&mut self, entity: Entity, handle: RigidBodyHandle) -> Result<()> {
        if !self.world.rapier.bodies.contains(handle) {
            return Err(Error::invalid(
                format!("body {entity}"),
                format!("no rigid body with handle {handle:?} in the Rapier world"),
            ));
        }
        self.remove_body(entity);
        self.changed = true;
        self.hinges_stale = true;
        self.bodies.insert(entity, handle);
        Ok(())
    }

    /// Removes the bodies of the entities not in `present`.
    pub(super) fn remove_bodies_except(&mut self, present: &BTreeSet<Entity>) {
        for e in absent(self.bodies.keys(), present) {
            self.remove_body(e);
        }
    }

    /// Removes the Rapier body of `entity` with every hinge and drive attached to it.
    fn remove_body(&mut self, entity: Entity) {
        let Some(handle) = self.bodies.remove(&entity) else {
            return;
        };
        self.hinges_stale = true;
        let joins = |(a, b): BodyPair| a == handle || b == handle;
        let attached: Vec<Entity> = self
            .hinges
            .iter()
            .filter(|(_, h)| joins(h.bodies))
            .map(|(e, _)| *e)
            .collect();
        for e in attached {
            self.unrealize_hinge(e);
        }
        let driven: Vec<Entity> = self
            .drives
            .iter()
            .filter(|(_, d)| joins(d.bodies))
            .map(|(e, _)| *e)
            .collect();
        for e in driven {
            self.unrealize_drive(e);
        }
        let w = &mut self.world.rapier;
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

    // ----- Hinges and drives -----

    /// Removes the joints and drives of the entities not in `present`.
    pub(super) fn remove_hinges_except(&mut self, present: &BTreeSet<Entity>) {
        for e in absent(self.hinges.keys().chain(self.drives.keys()), present) {
            self.unrealize_hinge(e);
            self.unrealize_drive(e);
        }
    }

    /// Removes the Rapier joint of hinge `entity` (if realised).
    fn unrealize_hinge(&mut self, entity: Entity) {
        if let Some(h) = self.hinges.remove(&entity) {
            self.changed = true;
            match h.joint {
                HingeJoint::Ideal(j) => {
                    self.world.rapier.impulse_joints.remove(j, true);
                }
                HingeJoint::Clearance(c) => {
                    self.world.remove_clearance(c);
                }
                HingeJoint::LargeStep(k) => {
                    self.world.remove_large_step(k);
                }
            }
        }
    }

    /// Removes the drive of `entity` (its torques act during the steps only: nothing to take
    /// back from the bodies).
    fn unrealize_drive(&mut self, entity: Entity) {
        if let Some(d) = self.drives.remove(&entity) {
            self.changed = true;
            self.world.drives.remove(d.handle);
        }
    }

    /// Brings hinge `entity` to the `desired` mode between `bodies`: `None` no joint,
    /// `Some(None)` ideal, `Some(Some(c))` clearance `c`.
    pub(super) fn reconcile_hinge(
        &mut self,
        entity: Entity,
        frame: &Hinge,
        desired: Option<Option<&HingeDesign>>,
        bodies: BodyPair,
    ) -> Result<()> {
        let context = |e: Error| e.within(&format!("hinge {entity}"));
        frame.validate().map_err(context)?;
        if let Some(Some(c)) = desired
            && c.model != ClearanceModel::LargeStep
        {
            check_compliant(&self.world.rapier, entity, c)?;
        }
        if let Some(r) = self.hinges.get(&entity) {
            let same_place = r.bodies == bodies && r.frame == *frame;
            let w = &mut self.world;
            // The swaps, in place: the plain API's conversions. The world sees the sets' sizes
            // change; the compliant swaps also mark the forces for evaluation (`changed`).
            let swapped = match (r.joint, desired) {
                (HingeJoint::Ideal(_), Some(None)) if same_place => return Ok(()),
                (HingeJoint::Clearance(_) | HingeJoint::LargeStep(_), Some(Some(c)))
                    if same_place && r.clearance.as_ref() == Some(c) =>
                {
                    return Ok(());
                }
                (HingeJoint::Ideal(j), Some(Some(c)))
                    if same_place && c.model == ClearanceModel::LargeStep =>
                {
                    let h = w
                        .large_step
                        .convert_revolute(
                            j,
                            BearingSide::Body1,
                            named(c, entity),
                            &mut w.rapier.impulse_joints,
                        )
                        .map_err(context)?;
                    Some((HingeJoint::LargeStep(h), Some(c)))
                }
                (HingeJoint::LargeStep(k), Some(None)) if same_place => {
                    let j = w
                        .large_step
                        .revert_to_revolute(k, &mut w.rapier.bodies, &mut w.rapier.impulse_joints)
                        .map_err(context)?;
                    Some((HingeJoint::Ideal(j), None))
                }
                (HingeJoint::Ideal(j), Some(Some(c))) if same_place => {
                    let h = w
                        .clearance
                        .convert_revolute(
                            j,
                            BearingSide::Body1,
                            named(c, entity),
                            &mut w.rapier.impulse_joints,
                        )
                        .map_err(context)?;
                    self.changed = true;
                    Some((HingeJoint::Clearance(h), Some(c)))
                }
                (HingeJoint::Clearance(k), Some(None)) if same_place => {
                    let j = w
                        .clearance
                        .revert_to_revolute(k, &mut w.rapier.bodies, &mut w.rapier.impulse_joints)
                        .map_err(context)?;
                    self.changed = true;
                    Some((HingeJoint::Ideal(j), None))
                }
                _ => None,
            };
            match swapped {
                Some((joint, clearance)) => {
                    let r = self.hinges.get_mut(&entity).expect("realised");
                    r.joint = joint;
                    r.clearance = clearance.cloned();
                    return Ok(());
                }
                None => self.unrealize_hinge(entity),
            }
        }
        let Some(clearance) = desired else {
            return Ok(());
        };
        let (a1, a2, x1, x2) = (
            frame.local_anchor1,
            frame.local_anchor2,
            frame.local_axis1,
            frame.local_axis2,
        );
        let w = &mut self.world;
        let joint = match clearance {
            None => HingeJoint::Ideal(w.rapier.impulse_joints.insert(
                bodies.0,
                bodies.1,
                frame.revolute(),
                true,
            )),
            Some(c) if c.model == ClearanceModel::LargeStep => {
                let joint = named(c, entity)
                    .large_step_joint(a1, a2, x1, x2)
                    .map_err(context)?;
                HingeJoint::LargeStep(
                    w.insert_large_step(bodies.0, bodies.1, joint)
                        .map_err(context)?,
                )
            }
            Some(c) => {
                let joint = named(c, entity).joint(a1, a2, x1, x2).map_err(context)?;
                HingeJoint::Clearance(
                    w.insert_clearance(bodies.0, bodies.1, joint)
                        .map_err(context)?,
                )
            }
        };
        self.changed = true;
        self.hinges.insert(
            entity,
            RealizedHinge {
                joint,
                bodies,
                frame: frame.clone(),
                clearance: clearance.cloned(),
            },
        );
        Ok(())
    }

    /// Brings the drive of hinge `entity` to `desired`.
    pub(super) fn reconcile_drive(
        &mut self,
        entity: Entity,
        frame: &Hinge,
        desired: Option<&Drive>,
        bodies: BodyPair,
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
        let handle = self.world.drives.insert(spring);
        self.changed = true;
        self.drives.insert(
            entity,
            RealizedDrive {
                handle,
                drive: *drive,
                bodies,
                axis: frame.local_axis1,
            },
        );
        Ok(())
    }
}

/// Refuses a compliant clearance hinge in a world whose settings cannot step it, naming what it
/// needs and why; the world's settings are the user's and stay as they are. A sub-cycled hinge
/// takes any number of iterations.
fn check_compliant(world: &PhysicsWorld, entity: Entity, c: &HingeDesign) -> Result<()> {
    let n = world.integration_parameters.num_solver_iterations;
    let sub_cycled = c.integration == crate::rapier::joint::ContactIntegration::SubCycled;
    if n == 1 || sub_cycled {
        return Ok(());
    }
    let (kind, alternative) = match &c.model {
        ClearanceModel::Spatial(_) => ("spatial", " (planar: it cannot tilt or slide axially)"),
        _ => ("compliant", ""),
    };
    Err(Error::invalid(
        "Physics::world.rapier.integration_parameters.num_solver_iterations",
        format!(
            "the {kind} clearance model of hinge {entity} needs 1 (the world has {n}): its \
             contact force is evaluated once per step and held over it, and Rapier's substeps \
             would make every impact gain energy. Set it to 1 (every body of the world then gets \
             one iteration: stacks of resting bodies soften), sub-cycle the hinge's \
             contact (`HingeDesign::integration(ContactIntegration::SubCycled)`), or give the hinge \
             the large-step model{alternative}, `HingeDesign::model(ClearanceModel::LargeStep)`, \
             which work with any number of iterations"
        ),
    ))
}

/// `c` with the entity as its name unless it has one.
fn named(c: &HingeDesign, entity: Entity) -> HingeDesign {
    let mut c = c.clone();
    if c.name.is_none() {
        c.name = Some(format!("hinge {entity}"));
    }
    c
}

/// The entities of `realized` not in `present`.
fn absent<'a>(
    realized: impl Iterator<Item = &'a Entity>,
    present: &BTreeSet<Entity>,
) -> Vec<Entity> {
    realized
        .filter(|e| !present.contains(*e))
        .copied()
        .collect()
}
