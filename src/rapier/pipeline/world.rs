//! [`ClearanceWorld`]: a Rapier world with everything a clearance joint needs around its step,
//! in one type (as Rapier's `PhysicsWorld` bundles its sets): the compliant and large-step
//! clearance joints, the drives, the prescribed motions, and the one step control that takes
//! every step ([`crate::rapier::pipeline::stepper`]). It is the one path to stepping: the scene
//! runner and the bevy_ecs layer are built on it; a plain-Rapier user calls
//! [`ClearanceWorld::step`] in place of `world.step()`, and no hook can be forgotten.
//!
//! ```
//! use clearance_joint::prelude::*;
//! use rapier3d_f64::prelude::*;
//!
//! // A 2 kg arm on a steel pin with 0.2 mm of play, released horizontal under gravity.
//! let mut rapier = PhysicsWorld::new();
//! rapier.gravity = Vector::new(0.0, -9.81, 0.0);
//! rapier.integration_parameters.num_solver_iterations = 1; // the explicit joint's need; sub-cycled takes any
//! let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, 0.02));
//! let base = world.rapier.bodies.insert(RigidBodyBuilder::fixed());
//! let arm = world.rapier.bodies.insert(
//!     RigidBodyBuilder::dynamic()
//!         .translation(Vector::new(0.3, 0.0, 0.0))
//!         .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02)))
//!         .can_sleep(false),
//! );
//! let pin = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)?.joint(
//!     Vector::ZERO,
//!     Vector::new(-0.3, 0.0, 0.0),
//!     Vector::Z,
//!     Vector::Z,
//! )?;
//! let pin = world.insert_clearance(base, arm, pin)?;
//! let mut peak: f64 = 0.0;
//! while world.time() < 0.2 {
//!     world.step(0.2)?; // one accepted step, landing on 0.2 s at the end
//!     peak = peak.max(world.clearance.get(pin).unwrap().report().force.normal_force);
//! }
//! assert!(world.guards().is_clean(), "{:?}", world.guards());
//! assert!(peak > 19.62, "the first impact exceeds the static load: {peak} N");
//! # Ok::<(), clearance_joint::Error>(())
//! ```
//!
//! **Chains of ideal joints.** With one substep Rapier sweeps its joints' constraints once per
//! step (Gauss-Seidel): exact for a body held by one joint, only in part for a chain or a loop,
//! and what it leaves grows with the step, which the adaptive step makes long in free flight.
//! Where a light body sits between stiff joints (a crank on a velocity motor carrying a heavier
//! coupler) raise `integration_parameters.num_internal_pgs_iterations`, which keeps the one
//! substep: on the four-bar of `assets/four_bar.ron` the first impact came 19.7 us late at one
//! sweep, 0.7 us at 32 and 0.3 us at 64, against a fixed 1e-6 s run (the scene format's
//! `run.solver_sweeps`; the scene takes 32).

use crate::error::Result;
use crate::rapier::joint::{ClearanceJoint, ClearanceJointHandle, ClearanceJointSet};
use crate::rapier::large_step::{LargeStepJoint, LargeStepJointHandle, LargeStepJointSet};
use crate::rapier::observers::reaction::{IdealJoint, KinematicState, ReactionSolver};
use crate::rapier::pipeline::body_edits::{BodyEdit, BodyEdits};
use crate::rapier::pipeline::protocol::Wrench;
use crate::rapier::pipeline::step_hooks::StepHooks;
use crate::rapier::pipeline::stepper::{GuardReport, StepControl, StepInfo, Stepper};
use crate::rapier::sources::drive::DriveSet;
use crate::rapier::sources::prescribed::{PrescribedMotion, PrescribedSet};
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{PhysicsWorld, RigidBodyHandle};

/// A Rapier world with clearance joints, drives and prescribed motions, stepped by one step
/// control ([`crate::rapier::pipeline::stepper`]). The sets and the step control are public
/// fields, as in Rapier's `PhysicsWorld`: read them freely; add and remove joints and motions
/// with the `insert_*`/`remove_*` methods (which also add their Rapier parts and tell the step
/// control when forces must be evaluated again), drives with the drive set's own
/// [`insert`](DriveSet::insert) and [`remove`](DriveSet::remove) (they have no Rapier part). A
/// compliant joint or a drive added, removed or edited through the fields is noticed at the
/// next step (by the sets' revisions, [`ElementSet::revision`](crate::rapier::pipeline::element_set::ElementSet::revision)),
/// and so is a dynamic body moved or given a velocity by hand between steps (its pose and
/// velocities against those the last step left: the joints are evaluated at the new state, and
/// after a velocity set by hand the kick restarts as after
/// [`invalidate(true)`](Self::invalidate)). After an edit the world cannot see (your own
/// participant's state, Rapier's joints or mass properties), call
/// [`invalidate`](Self::invalidate).
///
/// Force sources of your own take part in the steps through
/// [`step_with`](Self::step_with): any type that implements [`StepHooks`] (its wrenches, step
/// limit, acceptance, saved state and guards), run after the world's own sets.
pub struct ClearanceWorld {
    /// The Rapier world: bodies, colliders, Rapier's own joints, gravity, integration parameters.
    pub rapier: PhysicsWorld,
    /// The compliant clearance joints (contact and friction laws as forces).
    pub clearance: ClearanceJointSet,
    /// The large-step clearance joints (the play as a constraint of Rapier's solver).
    pub large_step: LargeStepJointSet,
    /// The torsion springs and torques.
    pub drives: DriveSet,
    /// The tabulated (prescribed) motions of kinematic bodies.
    pub prescribed: PrescribedSet,
    /// The step control: fixed or adaptive steps, their bounds, strictness. Set it between
    /// steps; each step checks it, naming a field out of its domain.
    pub step_control: StepControl,
    stepper: Stepper,
    /// The revisions of the compliant joint set and the drive set at the last step (`None`
    /// before the first): a change means their forces must be evaluated again before the next
    /// step.
    revisions: Option<[u64; 2]>,
    /// Scratch: the sources' wrenches for a reaction solve.
    wrenches: Vec<Wrench>,
    /// The dynamic bodies as the last step left them: a pose or a velocity set by hand between
    /// steps is noticed at the next.
    edits: BodyEdits,
}

impl ClearanceWorld {
    /// Wraps `rapier` (its settings, bodies and joints stay as they are) with empty sets and a
    /// stepper of `control`.
    pub fn new(rapier: PhysicsWorld, control: StepControl) -> Self {
        ClearanceWorld {
            rapier,
            clearance: ClearanceJointSet::new(),
            large_step: LargeStepJointSet::new(),
            drives: DriveSet::new(),
            prescribed: PrescribedSet::default(),
            step_control: control,
            stepper: Stepper::new(control),
            revisions: None,
            wrenches: Vec::new(),
            edits: BodyEdits::default(),
        }
    }

    // ----- Joints, drives, motions -----

    /// Adds a compliant clearance joint between `body1` (bearing) and `body2` (journal), with its
    /// Rapier lock. Refused, naming `body1` or `body2`, unless both are bodies of
    /// `self.rapier.bodies` and not the same body, and naming `local_axis2` when a spatial
    /// joint's journal does not lie in its bore; nothing is
    /// added then.
    pub fn insert_clearance(
        &mut self,
        body1: RigidBodyHandle,
        body2: RigidBodyHandle,
        joint: ClearanceJoint,
    ) -> Result<ClearanceJointHandle> {
        let w = &mut self.rapier;
        let handle =
            self.clearance
                .insert(body1, body2, joint, &w.bodies, &mut w.impulse_joints)?;
        self.stepper.invalidate(false);
        Ok(handle)
    }

    /// Removes a compliant clearance joint (and its Rapier lock); `None` for a handle of no joint.
    pub fn remove_clearance(&mut self, handle: ClearanceJointHandle) -> Option<ClearanceJoint> {
        self.stepper.invalidate(false);
        let w = &mut self.rapier;
        self.clearance
            .remove(handle, &mut w.bodies, &mut w.impulse_joints)
    }

    /// Adds a large-step clearance joint between `body1` (bearing) and `body2` (journal), with
    /// its Rapier joint. Refused, naming `body1` or `body2`, unless both are bodies of
    /// `self.rapier.bodies` and not the same body; nothing is added then.
    pub fn insert_large_step(
        &mut self,
        body1: RigidBodyHandle,
        body2: RigidBodyHandle,
        joint: LargeStepJoint,
    ) -> Result<LargeStepJointHandle> {
        // No force to evaluate: its hooks run inside each step.
        let w = &mut self.rapier;
        self.large_step
            .insert(body1, body2, joint, &w.bodies, &mut w.impulse_joints)
    }

    /// Removes a large-step clearance joint (and its Rapier joint); `None` for a handle of no
    /// joint.
    pub fn remove_large_step(&mut self, handle: LargeStepJointHandle) -> Option<LargeStepJoint> {
        let w = &mut self.rapier;
        self.large_step
            .remove(handle, &mut w.bodies, &mut w.impulse_joints)
    }

    /// Adds a prescribed motion; returns its index in [`PrescribedSet::motions`]. Refused, naming
    /// `motions[i].body` or its path's field, unless its body is a position-based kinematic body
    /// of this world and its axis or direction a unit vector; nothing is added then.
    pub fn insert_prescribed(&mut self, motion: PrescribedMotion) -> Result<usize> {
        let index = self.prescribed.motions.len();
        motion.check(index, &self.rapier.bodies)?;
        self.prescribed.motions.push(motion);
        Ok(index)
    }

    // ----- The step -----

    /// Takes one accepted step towards `until` (s), landing on it exactly (the step control,
    /// acceptance, guards: [`crate::rapier::pipeline::stepper`]; the joints', drives' and
    /// motions' hooks in their order); returns what the step did. Call it in place of Rapier's
    /// `PhysicsWorld::step`. The joints and drives are evaluated at the state before the step
    /// (by the previous step, or by [`prepare`](Self::prepare) on the first) and again at the
    /// state after it. `until` must be finite, after the current time and within what the clock
    /// can reach (a step of `max_dt` must change the time there); else it is refused, naming
    /// `until`. The world's gravity must be finite and within what one step of `max_dt` can
    /// take without passing the speed guard (`|g| max_dt` at most half Rapier's
    /// `max_linear_velocity`), else it is refused naming `gravity`. An error after the step (a
    /// fixed step beyond a contact's stability limit, a guard under `strict`, a diverged body)
    /// leaves the world and the clock at the state the step reached.
    ///
    /// Between steps the bodies carry only your own forces: the sources' wrenches are added for
    /// the step and taken away after it. Velocity-based kinematic bodies are placed exactly where
    /// their velocities take them over each step. A kinematic position target
    /// (`set_next_kinematic_position`) set by hand is reached within one step whatever its
    /// length: under adaptive steps prescribe such motion as a function of time with
    /// [`insert_prescribed`](Self::insert_prescribed), which sets the target of each step
    /// (retried ones included) from the step's end time.
    ///
    /// The same as [`step_with`](Self::step_with) with no hooks of your own (`&mut ()`).
    pub fn step(&mut self, until: f64) -> Result<StepInfo> {
        self.step_with(until, &mut ())
    }

    /// [`step`](Self::step) with your own participant `user` in the step, after the world's
    /// own (drives, compliant joints, large-step joints, prescribed motions, in that order):
    /// its [`StepHooks`] are called as theirs, so its wrenches act over the step, its
    /// [`step_limit`](StepHooks::step_limit) bounds the adaptive step, its
    /// [`judge_step`](StepHooks::judge_step) may reject it (its
    /// [`save_state`](StepHooks::save_state)/[`restore_state`](StepHooks::restore_state) then
    /// undo it) and its [`record_guards`](StepHooks::record_guards) fill
    /// [`guards`](Self::guards). Pass the same participant at every step (a tuple or a struct of
    /// your own holds several); after changing it between steps, call
    /// [`invalidate`](Self::invalidate).
    pub fn step_with(&mut self, until: f64, user: &mut dyn StepHooks) -> Result<StepInfo> {
        if !until.is_finite() {
            return Err(crate::Error::invalid(
                "until",
                format!("must be a finite time in seconds (got {until})"),
            ));
        }
        self.follow_changes();
        let (stepper, physics, mut hooks) = self.parts(user);
        let result = stepper.step(physics, &mut hooks, until);
        self.edits.record(&self.rapier.bodies);
        result
    }

    /// Steps until the clock reaches `until` (s, finite; at or before the current time nothing is
    /// done); returns the number of accepted steps taken.
    pub fn step_to(&mut self, until: f64) -> Result<u64> {
        self.step_to_with(until, &mut ())
    }

    /// [`step_to`](Self::step_to) with your own participant `user` in every step
    /// ([`step_with`](Self::step_with)).
    pub fn step_to_with(&mut self, until: f64, user: &mut dyn StepHooks) -> Result<u64> {
        if !until.is_finite() {
            return Err(crate::Error::invalid(
                "until",
                format!("must be a finite time in seconds (got {until})"),
            ));
        }
        let start = self.stepper.steps();
        while self.time() < until {
            self.step_with(until, user)?;
        }
        Ok(self.stepper.steps() - start)
    }

    /// Evaluates the joints and drives at the current state if the next step has not yet
    /// (done by [`step`](Self::step) on its own; call it to read the joints' forces at the
    /// initial state before the first step). Also checks the world's settings.
    pub fn prepare(&mut self) -> Result<()> {
        self.prepare_with(&mut ())
    }

    /// [`prepare`](Self::prepare) with your own participant `user`
    /// ([`step_with`](Self::step_with)).
    pub fn prepare_with(&mut self, user: &mut dyn StepHooks) -> Result<()> {
        self.follow_changes();
        let (stepper, physics, mut hooks) = self.parts(user);
        let result = stepper.prepare(physics, &mut hooks);
        self.edits.record(&self.rapier.bodies);
        result
    }

    /// Takes a step of the last step's size (or `dt` before the first: > 0 and at most the
    /// control's `max_dt`, else refused naming `dt`), lets `read` look at the world and the
    /// step, then restores the state before it exactly: e.g. an ideal joint's reaction at the
    /// final time, which only the step after it determines.
    pub fn peek<R>(
        &mut self,
        dt: f64,
        read: impl FnOnce(&PhysicsWorld, &StepInfo) -> R,
    ) -> Result<R> {
        self.peek_with(dt, &mut (), read)
    }

    /// [`peek`](Self::peek) with your own participant `user` ([`step_with`](Self::step_with)),
    /// whose state is restored with the world's.
    pub fn peek_with<R>(
        &mut self,
        dt: f64,
        user: &mut dyn StepHooks,
        read: impl FnOnce(&PhysicsWorld, &StepInfo) -> R,
    ) -> Result<R> {
        self.follow_changes();
        let (stepper, physics, mut hooks) = self.parts(user);
        let result = stepper.peek(physics, &mut hooks, dt, read);
        self.edits.record(&self.rapier.bodies);
        result
    }

    /// Forgets the evaluation of the joints and drives, after you changed the world between
    /// steps in a way it does not notice by itself (your own participant's state, Rapier's joints
    /// or mass properties; a body moved or given a velocity is noticed): the next step evaluates
    /// them again first. With `restart_kick` the next step's kick is a first step's again, as from
    /// a new initial state (as after setting velocities by hand), and the clearance joints' contact laws
    /// get the stored rate at that evaluation. Without it they carry the rate to the state with
    /// its change since their last evaluation, across your edit: off by at most half that
    /// change, once
    /// ([`ClearanceJointSet::set_last_step`](crate::rapier::joint::ClearanceJointSet::set_last_step)).
    pub fn invalidate(&mut self, restart_kick: bool) {
        self.stepper.invalidate(restart_kick);
    }

    /// The velocity (linear, angular) of `body` at the world's state: a sub-cycled joint's,
    /// planar or spatial
    /// ([`ClearanceJoint::state_velocity`](crate::rapier::joint::ClearanceJoint::state_velocity))
    /// where one ended its last step on a pair with the body, Rapier's otherwise (`None` for a
    /// body not in the world): after a sub-cycled step Rapier's velocities hold only part of the
    /// step's contact impulse.
    pub fn velocity_at_state(&self, body: RigidBodyHandle) -> Option<(Vector, Vector)> {
        let rb = self.rapier.bodies.get(body)?;
        let joints = self
            .clearance
            .iter()
            .filter_map(|(_, j)| j.state_velocity());
        Some(
            joints
                .flatten()
                .find(|(b, _, _)| *b == body)
                .map_or((rb.linvel(), rb.angvel()), |(_, v, w)| (v, w)),
        )
    }

    /// The simulated time, s.
    pub fn time(&self) -> f64 {
        self.stepper.time()
    }

    /// Accepted steps so far.
    pub fn steps(&self) -> u64 {
        self.stepper.steps()
    }

    /// The last accepted step, s (0 before the first).
    pub fn last_dt(&self) -> f64 {
        self.stepper.last_dt()
    }

    /// What the run-time guards recorded.
    pub fn guards(&self) -> &GuardReport {
        self.stepper.guards()
    }

    // ----- Reactions -----

    /// The force on each ideal joint's body 2 at the current state (N, world frame, in the order
    /// of `joints`; [`ReactionSolver::solve`]), with what the step loop knows and a
    /// bare solve would not: the joints' and drives' wrenches (they act during the steps only;
    /// a large-step joint's, its constraint's force over the last step),
    /// the prescribed motions' rates at this time, and the stored velocities' lag behind the
    /// state (half the last step with one solver iteration). `None` when the solve fails ([`ReactionSolver::failure`] says why).
    pub fn solve_reactions<'s>(
        &mut self,
        solver: &'s mut ReactionSolver,
        joints: &[IdealJoint],
    ) -> Option<&'s [Vector]> {
        let t = self.time();
        solver.velocity_lag = self
            .stepper
            .velocity_lag(self.rapier.integration_parameters.num_solver_iterations);
        solver.kinematic.clear();
        for m in &self.prescribed.motions {
            let (linvel, linacc, angvel, angacc) = m.rates(t);
            solver.kinematic.push(KinematicState {
                body: m.body,
                linvel,
                angvel,
                linacc,
                angacc,
            });
        }
        self.wrenches.clear();
        self.wrenches.extend_from_slice(self.drives.wrenches());
        self.wrenches.extend_from_slice(self.clearance.wrenches());
        // The large-step joints' constraint forces of the last step (no ideal joints to solve).
        self.large_step
            .constraint_wrenches(&self.rapier.bodies, &mut self.wrenches);
        solver.solve_with(
            &self.rapier.bodies,
            joints,
            self.rapier.gravity,
            &self.wrenches,
        )
    }

    // ----- Internals -----

    /// The stepper, the Rapier world and the hooks in their order: drives, compliant joints,
    /// large-step joints, prescribed motions, the user's (the forces are added to a body in that
    /// order).
    fn parts<'a>(
        &'a mut self,
        user: &'a mut dyn StepHooks,
    ) -> (
        &'a mut Stepper,
        &'a mut PhysicsWorld,
        [&'a mut dyn StepHooks; 5],
    ) {
        self.stepper.set_control(self.step_control);
        (
            &mut self.stepper,
            &mut self.rapier,
            [
                &mut self.drives,
                &mut self.clearance,
                &mut self.large_step,
                &mut self.prescribed,
                user,
            ],
        )
    }

    /// A force source edited through its public field since the last step (a compliant joint or
    /// a drive added, removed or edited, seen by the sets' revisions): its forces are evaluated
    /// again before the next step. Only these: an evaluation at the same state again is not free
    /// (the joints' reports would lose the onset they flagged), and the other sets carry no
    /// forces to evaluate.
    fn follow_changes(&mut self) {
        match self.edits.since(&self.rapier.bodies) {
            BodyEdit::None => {}
            BodyEdit::Moved => self.stepper.invalidate(false),
            BodyEdit::Velocity => self.stepper.invalidate(true),
        }
        let revisions = [self.clearance.revision(), self.drives.revision()];
        if self.revisions != Some(revisions) {
            if self.revisions.is_some() {
                self.stepper.invalidate(false);
            }
            self.revisions = Some(revisions);
        }
    }
}
