//! One step's Rapier passes: the bodies' snapshot before the step, the passes with the kick
//! and the participants' hooks around Rapier's step, and the restore of a rejected step.

use super::{MAX_PASSES, Stepper};
use crate::rapier::pipeline::step_hooks::{
    EvaluateContext, RapierStepContext, StepHooks, StepPass,
};
use rapier3d_f64::math::{Pose, Vector};
use rapier3d_f64::prelude::{PhysicsWorld, RigidBodyHandle, RigidBodyType};

#[derive(Clone, Copy, Debug)]
pub(super) struct BodySnapshot {
    pub(super) handle: RigidBodyHandle,
    position: Pose,
    next_position: Pose,
    linvel: Vector,
    angvel: Vector,
    force: Vector,
    torque: Vector,
}

/// Replaces `into` with the state of every movable body: pose (and kinematic target),
/// velocities, and the user forces on it.
pub(super) fn snapshot_bodies(world: &PhysicsWorld, into: &mut Vec<BodySnapshot>) {
    into.clear();
    into.extend(
        world
            .bodies
            .iter()
            .filter(|(_, rb)| !rb.is_fixed())
            .map(|(handle, rb)| BodySnapshot {
                handle,
                position: *rb.position(),
                next_position: *rb.next_position(),
                linvel: rb.linvel(),
                angvel: rb.angvel(),
                force: rb.user_force(),
                torque: rb.user_torque(),
            }),
    );
}

impl Stepper {
    /// The velocity kick of a step of `dt` after the last accepted one, for Rapier's `n`
    /// substeps, s. Rapier's `n` substeps of a step `h` under a held acceleration `a` raise the
    /// velocity by `a k` (`k` the kick) and move the body by `h v + c_n a k h`,
    /// `c_n = (n + 1)/(2 n)`: its stored velocity lags the state's by `s = c_n k - h/2` at the
    /// step's start. The kick keeps that relation from step to step,
    /// `k' = (h' + h - 2 (1 - c_n) k)/(2 c_n)`, so a held acceleration moves the bodies as the
    /// exact motion does at every step; from a state whose velocities are the state's (`s = 0`:
    /// the first step, or after `invalidate(true)`) `k = h/(2 c_n)`. With one substep it is
    /// the leapfrog's `(h_prev + h)/2`; with more, the leapfrog's kick would leave the world
    /// `(n - 1)/(2 n)` of a step behind (6 ms at 60 Hz and Rapier's four). Never negative: after
    /// an abrupt fall of the step at many substeps the rule would kick against the force.
    pub(super) fn kick_for(&self, dt: f64, n: usize) -> f64 {
        let c_n = substep_share(n);
        if self.last_dt > 0.0 {
            ((dt + self.last_dt - 2.0 * (1.0 - c_n) * self.last_kick) / (2.0 * c_n)).max(0.0)
        } else {
            dt / (2.0 * c_n)
        }
    }

    /// How long before the state Rapier's stored velocities are after the last accepted step,
    /// s, for its `n` substeps: `h/2 - (1 - c_n) k` ([`Self::kick_for`]); half the step with
    /// one substep, 0 before the first step.
    pub(crate) fn velocity_lag(&self, n: usize) -> f64 {
        0.5 * self.last_dt - (1.0 - substep_share(n)) * self.last_kick
    }

    /// One Rapier step of `dt` from the saved state, with the kick of [`Self::kick_for`]: your forces,
    /// the sources' wrenches and gravity scaled to the kick for this step only, the sources'
    /// hooks around it, the joint correction, exact kinematic poses ([`Self::rapier_pass`]),
    /// taken again from the saved state while a source asks ([`StepHooks::resolve_step`], at
    /// most [`MAX_PASSES`] more); then the sources evaluated at the new state. Returns the
    /// kick, s.
    pub(super) fn take_rapier_step(
        &mut self,
        world: &mut PhysicsWorld,
        sources: &mut [&mut dyn StepHooks],
        dt: f64,
    ) -> f64 {
        let kick = self.kick_for(dt, world.integration_parameters.num_solver_iterations);
        let mut pass = StepPass {
            dt,
            kick,
            tolerance: self.control.tolerance,
            pass: 0,
        };
        loop {
            self.rapier_pass(world, sources, dt, kick);
            let mut again = false;
            for s in sources.iter_mut() {
                again |= s.resolve_step(world, &pass);
            }
            if !again || pass.pass >= MAX_PASSES {
                break;
            }
            self.restore(world, sources);
            pass.pass += 1;
        }
        for s in sources.iter_mut() {
            s.evaluate(EvaluateContext {
                bodies: &mut world.bodies,
                impulse_joints: &world.impulse_joints,
                last_step: dt,
            });
        }
        kick
    }

    /// One Rapier pass of a step of `dt` with velocity kick `kick` (s): the user's forces and the
    /// sources' wrenches scaled to the kick for the pass only, the sources' hooks around
    /// Rapier's step.
    fn rapier_pass(
        &mut self,
        world: &mut PhysicsWorld,
        sources: &mut [&mut dyn StepHooks],
        dt: f64,
        kick: f64,
    ) {
        let gravity = world.gravity;
        let scale = kick / dt;
        // For this step only: your forces and the sources' wrenches, scaled to the kick.
        for b in &self.saved {
            if let Some(rb) = world.bodies.get_mut(b.handle)
                && rb.is_dynamic()
                && scale != 1.0
            {
                rb.reset_forces(false);
                rb.reset_torques(false);
                rb.add_force(b.force * scale, false);
                rb.add_torque(b.torque * scale, false);
            }
        }
        for s in sources.iter() {
            for w in s.wrenches() {
                if let Some(rb) = world.bodies.get_mut(w.body)
                    && rb.is_dynamic()
                {
                    let wake = w.force != Vector::ZERO || w.torque != Vector::ZERO;
                    rb.add_force(w.force * scale, wake);
                    rb.add_torque(w.torque * scale, wake);
                }
            }
        }
        world.gravity = gravity * scale;
        world.integration_parameters.dt = dt;
        for s in sources.iter_mut() {
            s.before_rapier_step(RapierStepContext {
                world: &mut *world,
                t0: self.t,
                dt,
            });
        }
        if self.control.joint_correction {
            self.correction.apply(&mut world.impulse_joints, dt);
        }
        world.step();
        self.correction.restore(&mut world.impulse_joints);
        world.gravity = gravity;
        exact_kinematic_poses(world, &self.saved, dt);
        self.restore_forces(world);
        for s in sources.iter_mut() {
            s.after_rapier_step(RapierStepContext {
                world: &mut *world,
                t0: self.t,
                dt,
            });
        }
    }

    fn restore_forces(&self, world: &mut PhysicsWorld) {
        for b in &self.saved {
            if let Some(rb) = world.bodies.get_mut(b.handle)
                && rb.is_dynamic()
            {
                rb.reset_forces(false);
                rb.reset_torques(false);
                rb.add_force(b.force, false);
                rb.add_torque(b.torque, false);
            }
        }
    }

    /// Puts the bodies and the sources back as they were before the step.
    pub(super) fn restore(&self, world: &mut PhysicsWorld, sources: &mut [&mut dyn StepHooks]) {
        for b in &self.saved {
            if let Some(rb) = world.bodies.get_mut(b.handle) {
                rb.set_position(b.position, false);
                if rb.is_kinematic() {
                    rb.set_next_kinematic_position(b.next_position);
                }
                rb.set_linvel(b.linvel, false);
                rb.set_angvel(b.angvel, false);
            }
        }
        self.restore_forces(world);
        for s in sources.iter_mut() {
            s.restore_state();
        }
    }
}

/// Puts every velocity-based kinematic body where its velocities take it in `dt` from its pose
/// before the step, `saved` (rotation by the exact exponential about its centre of mass): Rapier's
/// solver turns such bodies to first order in the angle, so a crank driven at a constant speed
/// fell behind by 0.18 deg in three turns at 5000 rpm. Its pose is then exact at every state
/// whatever steps were taken or rejected (a constant spin is `w t` up to rounding).
fn exact_kinematic_poses(world: &mut PhysicsWorld, saved: &[BodySnapshot], dt: f64) {
    for b in saved {
        if let Some(rb) = world.bodies.get_mut(b.handle)
            && rb.body_type() == RigidBodyType::KinematicVelocityBased
        {
            let com = rb.mass_properties().local_mprops.local_com;
            let pose = rb.vels().integrate(dt, &b.position, &com);
            rb.set_position(pose, false);
        }
    }
}

/// `c_n = (n + 1)/(2 n)`: the share of a step's velocity kick Rapier's `n` substeps move the
/// bodies by over the step (1 for one substep; towards 1/2, the exact motion's, for many).
pub(crate) fn substep_share(n: usize) -> f64 {
    let n = n.max(1) as f64;
    (n + 1.0) / (2.0 * n)
}
