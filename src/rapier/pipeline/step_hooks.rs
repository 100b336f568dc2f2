//! The step protocol: what the [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld) asks of everything
//! that takes part in a step, as a hook trait with default methods (as Rapier's
//! `PhysicsHooks`), each hook given a context struct (as Rapier's `PairFilterContext`). Every
//! joint set of this crate implements it
//! ([`ClearanceJointSet`](crate::rapier::joint::ClearanceJointSet),
//! [`LargeStepJointSet`](crate::rapier::large_step::LargeStepJointSet)), as do the drives
//! ([`DriveSet`](crate::rapier::sources::drive::DriveSet)) and the prescribed motions
//! ([`PrescribedSet`](crate::rapier::sources::prescribed::PrescribedSet)); a user's own force
//! source implements it too and steps with them through
//! [`ClearanceWorld::step_with`](crate::rapier::pipeline::world::ClearanceWorld::step_with). A
//! participant overrides what it needs, the rest does nothing. Its vocabulary (wrenches,
//! violations, stalled contacts, element ids) is in [`protocol`](crate::rapier::pipeline::protocol).
//!
//! One step of the stepper, in the order the hooks are called:
//! 1. [`check_bodies`](StepHooks::check_bodies) before every step;
//!    [`check_world`](StepHooks::check_world) once before the first step (the solver settings a
//!    participant needs), then [`evaluate`](StepHooks::evaluate) at
//!    the state before the step.
//! 2. The step's length: the smallest [`step_limit`](StepHooks::step_limit) (adaptive), or a
//!    fixed step checked by [`check_step`](StepHooks::check_step).
//! 3. [`save_state`](StepHooks::save_state) (the step may be rejected or taken again); the
//!    [`wrenches`](StepHooks::wrenches) are added to the bodies for this step only;
//!    [`before_rapier_step`](StepHooks::before_rapier_step), Rapier's step,
//!    [`after_rapier_step`](StepHooks::after_rapier_step); then
//!    [`evaluate`](StepHooks::evaluate) at the new state.
//!    After each Rapier pass, [`resolve_step`](StepHooks::resolve_step): a participant may ask
//!    for the step to be taken again from its start with its new wrenches (the bodies and
//!    every participant's state restored first).
//! 4. [`judge_step`](StepHooks::judge_step) (adaptive): a participant that asks for a shorter
//!    step has the step undone ([`restore_state`](StepHooks::restore_state), the bodies restored
//!    by the stepper) and retried from 3.
//! 5. On acceptance: [`check_step`](StepHooks::check_step) again (fixed steps: the contact the step
//!    ended in) and [`record_guards`](StepHooks::record_guards).
//!
//! Users rarely call these methods themselves: [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld)
//! and the stepper do. A loop that calls `world.step()` itself uses each set's own
//! `apply`/`before_step`/`after_step` instead.

use crate::error::Result;
use crate::rapier::pipeline::protocol::{GuardReport, StalledContact, Wrench};
use rapier3d_f64::prelude::{
    ImpulseJointSet, IntegrationParameters, PhysicsWorld, RigidBodyHandle, RigidBodySet,
};

/// What the stepper asks of a participant in a step; every method has a default that does
/// nothing (see the [module](self) docs for the order of the calls).
pub trait StepHooks {
    /// Evaluates at the bodies' current state, without touching their forces: the wrenches of
    /// the next step. Default: nothing.
    fn evaluate(&mut self, _context: EvaluateContext<'_>) {}

    /// The wrenches of the last evaluation, added to the bodies for the next step only.
    /// Default: none.
    fn wrenches(&self) -> &[Wrench] {
        &[]
    }

    /// Saves the internal state (before a step that may be rejected). Default: nothing.
    fn save_state(&mut self) {}

    /// Restores the state saved last (the stepper restores the bodies). Default: nothing.
    fn restore_state(&mut self) {}

    /// Whether the world's settings can step this participant (checked before the first step
    /// and after [`ClearanceWorld::invalidate`](crate::rapier::pipeline::world::ClearanceWorld::invalidate)). Default:
    /// any settings.
    fn check_world(&self, _params: &IntegrationParameters) -> Result<()> {
        Ok(())
    }

    /// The longest adaptive step this participant allows from the current state, s (the
    /// context's `tolerance`, `last_dt` and `t`; its `dt` is 0). Default: no limit.
    fn step_limit(&self, _step: &StepContext) -> f64 {
        f64::INFINITY
    }

    /// Whether a fixed step `step.dt` is within the stability limit of this participant's state
    /// (before the step, and again at the state the step ended in): an
    /// [`Error::StepTooLarge`](crate::Error::StepTooLarge) if not. Default: any step.
    fn check_step(&self, _step: &StepContext) -> Result<()> {
        Ok(())
    }

    /// Judges an adaptive step `step.dt` just taken (evaluated at its end, `step.t`):
    /// `Some(shorter)` rejects it, to be retried at most `shorter` long. Default: accepted.
    fn judge_step(&self, _step: &StepContext) -> Option<f64> {
        None
    }

    /// Right before each Rapier step (a retried one included), with the step's start `t0` and
    /// length `dt` (`world.integration_parameters.dt` is set to it): e.g. the next poses of
    /// prescribed kinematic bodies, or the substeps of large-step joints. Default: nothing.
    fn before_rapier_step(&mut self, _context: RapierStepContext<'_>) {}

    /// Right after each Rapier step, before [`evaluate`](Self::evaluate): e.g. reading the
    /// constraint forces of large-step joints and bouncing their impacts. Default: nothing.
    fn after_rapier_step(&mut self, _context: RapierStepContext<'_>) {}

    /// After each Rapier pass of a step (after [`after_rapier_step`](Self::after_rapier_step)):
    /// whether the step must be taken again from its start, as long, with this participant's
    /// [`wrenches`](Self::wrenches) as they are now. The stepper then restores the bodies and
    /// every participant's state ([`restore_state`](Self::restore_state)) and takes pass
    /// `pass.pass + 1`. A sub-cycled clearance joint reads the rest of the world's motion from
    /// pass 0, taken without its force, and asks for pass 1 with the force that moves the bodies
    /// as its sub-steps did. Default: the pass stands.
    fn resolve_step(&mut self, _world: &PhysicsWorld, _pass: &StepPass) -> bool {
        false
    }

    /// Records in `guards`, after an accepted step `step.dt` ending at `step.t`, what the
    /// run-time guards must know of this participant's state (penetrations beyond a law's
    /// validity, a fixed step beyond friction's limit when `step.fixed`, a spring stretched too
    /// far). Default: nothing.
    fn record_guards(&self, _step: &StepContext, _guards: &mut GuardReport) {}

    /// The contact of this participant whose step limit is the shortest, with its numbers, for a
    /// stall's diagnosis; `None` when none is in contact. This crate's compliant joint set
    /// reports its contacts; a participant of your own keeps the default: none.
    fn stalled_contact(&self, _bodies: &RigidBodySet) -> Option<StalledContact> {
        None
    }

    /// The shortest world step this participant's sub-cycled contacts ask for at the state
    /// (`step.tolerance`, `step.last_dt` the step just taken), s; infinite when none does. Below
    /// the floor `min_dt` the world's step sits at the floor while the contact lasts, and the
    /// adaptive step control stops such a run, as its retries stop an explicit contact below
    /// the floor. This crate's compliant joint set reports its planar sub-cycled joints in
    /// contact; a participant of your own keeps the default: none.
    fn sub_cycled_contact_step(&self, _step: &StepContext) -> f64 {
        f64::INFINITY
    }

    /// Names (in words) this participant's joints that join `body`, for a divergence's message.
    /// Default: none.
    fn joints_of(&self, _body: RigidBodyHandle, _names: &mut Vec<String>) {}

    /// Adds to `causes` (in words) what this participant knows made `body` diverge in the step
    /// just taken, for the divergence's message ahead of the generic causes. This crate's
    /// compliant joint set names a sub-cycle that hit its cap of sub-steps. Default: nothing.
    fn divergence_causes(&self, _body: RigidBodyHandle, _causes: &mut Vec<String>) {}

    /// Checks that this participant's joints join bodies of `bodies` (before every step; an error
    /// names `body1` or `body2`, as this crate's joint sets word it). Default: nothing to check.
    fn check_bodies(&self, _bodies: &RigidBodySet) -> Result<()> {
        Ok(())
    }
}

/// No participant: what [`ClearanceWorld::step`](crate::rapier::pipeline::world::ClearanceWorld::step)
/// steps with beside its own sets.
impl StepHooks for () {}

/// What [`StepHooks::evaluate`] sees: the bodies at the state to evaluate and the world's
/// Rapier joints (the mechanism a force source acts in).
#[non_exhaustive]
pub struct EvaluateContext<'a> {
    /// The bodies (mutable only to compute mass properties Rapier has not yet).
    pub bodies: &'a mut RigidBodySet,
    /// The world's Rapier joints.
    pub impulse_joints: &'a ImpulseJointSet,
    /// The length of the step that led to this state, s: 0 before the first step (and after a
    /// restart, when the velocities are the state's own). Rapier's velocities are the mean over
    /// that step; a source that reads rates can carry them to the state.
    pub last_step: f64,
}

/// The step a hook is asked about ([`StepHooks::step_limit`], [`StepHooks::check_step`],
/// [`StepHooks::judge_step`], [`StepHooks::record_guards`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct StepContext {
    /// The time of the state the participant was last evaluated at, s: the step's start before
    /// it is taken, its end after.
    pub t: f64,
    /// The step, s (0 when it is still to be chosen, in [`StepHooks::step_limit`]).
    pub dt: f64,
    /// The last accepted step, s (0 before the first).
    pub last_dt: f64,
    /// The step control's tolerance.
    pub tolerance: f64,
    /// Whether the steps are fixed (no step is rejected or retried).
    pub fixed: bool,
}

/// The world around one Rapier step ([`StepHooks::before_rapier_step`],
/// [`StepHooks::after_rapier_step`]).
#[non_exhaustive]
pub struct RapierStepContext<'a> {
    /// The Rapier world; `integration_parameters.dt` is the step.
    pub world: &'a mut PhysicsWorld,
    /// The step's start, s.
    pub t0: f64,
    /// The step, s.
    pub dt: f64,
}

/// One Rapier pass of a step, as [`StepHooks::resolve_step`] sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct StepPass {
    /// The step, s.
    pub dt: f64,
    /// Its velocity kick, s (`(h_prev + h)/2` with one solver iteration, `h/2` for a first step;
    /// with Rapier's `n` substeps, the rule that keeps them on the exact motion): the stepper
    /// scales every force by `kick/dt` for the step.
    pub kick: f64,
    /// The step control's tolerance.
    pub tolerance: f64,
    /// The pass, from 0.
    pub pass: u32,
}

/// `Ok` when `body1` and `body2` are both in `bodies`; else an error naming the one missing
/// (`body1` or `body2`), with `joint()` (in words, formed only then) the joint that holds it.
pub(crate) fn joint_bodies(
    bodies: &RigidBodySet,
    joint: impl FnOnce() -> String,
    body1: RigidBodyHandle,
    body2: RigidBodyHandle,
) -> Result<()> {
    for (field, body) in [("body1", body1), ("body2", body2)] {
        if !bodies.contains(body) {
            let (index, generation) = body.into_raw_parts();
            let joint = joint();
            return Err(crate::Error::invalid(
                field,
                format!(
                    "{joint} joins a body (index {index}, generation {generation}) that is not in \
                     the world's bodies (removed, invalid or of another world): insert joints \
                     between bodies of this world, and remove a joint before its body"
                ),
            ));
        }
    }
    Ok(())
}

/// A new joint's two bodies: both in `bodies` ([`joint_bodies`]) and not the same body, naming
/// `body1` or `body2` as the sets' `insert` methods name them.
pub(crate) fn joint_pair(
    bodies: &RigidBodySet,
    body1: RigidBodyHandle,
    body2: RigidBodyHandle,
) -> Result<()> {
    joint_bodies(bodies, || "the joint".to_string(), body1, body2)?;
    if body1 == body2 {
        let (index, generation) = body1.into_raw_parts();
        return Err(crate::Error::invalid(
            "body2",
            format!(
                "is the same body as body1 (index {index}, generation {generation}): a joint \
                 joins two bodies; pass the journal's body as body2 and the bearing's as body1"
            ),
        ));
    }
    Ok(())
}
