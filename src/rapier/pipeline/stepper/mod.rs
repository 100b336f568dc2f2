//! The step control: the one `Stepper` inside a
//! [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld) chooses, takes, judges and
//! (when needed) retries every Rapier step of a world that holds clearance joints. It steps
//! whatever takes part in the step through the step protocol ([`StepHooks`]: the joint sets, the
//! drives, the prescribed motions, a user's own participant; called the sources here). Crate
//! internal: the world is the one public path to it (its settings, [`StepControl`], and what a
//! step did, [`StepInfo`], are public here).
//!
//! What it adds to `PhysicsWorld::step`:
//! - **Consistent variable steps.** With one solver iteration a Rapier step is symplectic Euler
//!   (`v += h F/m`, then `x += h v`), which is second order only while `h` is constant. The
//!   stepper makes it variable-step Störmer-Verlet: the velocity kick of a step `h` after a step
//!   `h_prev` spans `(h_prev + h)/2`, so every user force and torque (the hooks' and your own) and
//!   gravity are scaled by `(h_prev + h)/(2 h)` for the step and restored after it. The first
//!   step from a given state is a half kick (`h_prev = 0`): velocities then live at half steps,
//!   and positions are second-order accurate from the start. With `n` solver iterations Rapier
//!   takes `n` such substeps, which move the bodies by `c_n = (n + 1)/(2 n)` of the step's kick
//!   rather than all of it; the kick follows (`Stepper::kick_for`), so a held force moves the
//!   bodies as the exact motion does at any `n` (with the leapfrog's kick the world would run
//!   `(n - 1)/(2 n)` of a step behind it: 6 ms at 60 Hz and Rapier's four).
//! - **Joint drift corrected at a consistent rate.** Rapier corrects the drift of its joints'
//!   locked positions within each step, so a drop of the step multiplies the correcting
//!   velocity; on slender bodies that makes the locked tilt grow at each change of the step. The
//!   stepper gives the joints (those with Rapier's default softness, for the step only) the
//!   correction rate of the longest recent step
//!   ([`StepControl::joint_correction`]).
//! - **Step choice** ([`StepControl`]): fixed, or adaptive from the motion (no body turns more
//!   than `tolerance/8` rad in a step) and the
//!   contacts (the joints'
//!   [`adaptive_step`](crate::rapier::joint::ClearanceJoint::adaptive_step)), growing by at most
//!   [`StepControl::max_growth`] per step and landing exactly on the time given to
//!   [`ClearanceWorld::step`](crate::rapier::pipeline::world::ClearanceWorld::step).
//! - **Step acceptance.** After the step the force sources are evaluated at the new state (the
//!   forces of the next step) and every clearance joint judges it
//!   ([`judge_step`](crate::rapier::joint::ClearanceJoint::judge_step)): a contact that began deeper than
//!   the contact's own step allows, or a step beyond the stability limit of the contact it ended
//!   in, is rejected; the world is restored from the state saved before the step and the step is
//!   retried shorter. With fixed steps nothing is retried: a step beyond the stability limit is an
//!   [`Error::StepTooLarge`], before (from the state at the step's start) or after it.
//! - **Passes.** A participant may have a step taken again from its start, as long, with new
//!   wrenches ([`StepHooks::resolve_step`]): a sub-cycled clearance joint
//!   ([`ContactIntegration::SubCycled`](crate::rapier::joint::ContactIntegration::SubCycled))
//!   reads the rest of the world's motion from the first pass and delivers its contact's impulse
//!   in the second. The bodies and every participant's state are restored between passes.
//! - **Guards** ([`GuardReport`]): a body that left the physical range is an error
//!   ([`Error::Diverged`]); a contact deeper than its law's validity and runs of steps at the step
//!   floor are recorded (and fail the run under [`StepControl::strict`]); a step control that
//!   cannot make progress (no accepted step above the floor for 100,000 steps; ten world steps
//!   in a row at a sub-cycle's cap of sub-steps; ten adaptive world steps ending in a
//!   sub-cycled contact that asks for world steps below the floor) is an [`Error::Stalled`].

mod control;
mod health;
mod pass;
pub(crate) use pass::substep_share;

use crate::error::{Error, Result};
use crate::rapier::pipeline::joint_correction::JointCorrection;
use crate::rapier::pipeline::motion_step::motion_step;
use health::{check_body_states, check_gravity, check_joint_bodies};
use pass::{BodySnapshot, snapshot_bodies};
use rapier3d_f64::prelude::PhysicsWorld;

pub(crate) use control::{CAP_STALL_STEPS, CONTACT_FLOOR_STALL_STEPS, STALL_STEPS};
pub use control::{StepControl, StepMode};
pub(crate) use health::left_physical_range;

pub(crate) use crate::rapier::pipeline::protocol::{GuardKind, GuardReport, Violation};
use crate::rapier::pipeline::step_hooks::EvaluateContext;
pub(crate) use crate::rapier::pipeline::step_hooks::StepHooks;

/// Passes after the first that one step may take ([`StepHooks::resolve_step`]): a sub-cycled
/// joint takes one.
const MAX_PASSES: u32 = 3;

/// Rejections of one step after which the step control gives up ([`Error::Stalled`]).
const MAX_REJECTIONS: u32 = 60;

/// What one accepted step did
/// ([`ClearanceWorld::step`](crate::rapier::pipeline::world::ClearanceWorld::step)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepInfo {
    /// Time at the step's start, s.
    pub t0: f64,
    /// The step, s.
    pub dt: f64,
    /// The span of the velocity kick (`(h_prev + h)/2` with one solver iteration, `h/2` for the
    /// first step; with `n`, the rule that keeps Rapier's substeps on the exact motion), s: applied
    /// forces and gravity acted for this long, so a momentum change over the step divided by it
    /// is the mean force at the step's start (an ideal joint's reaction, say).
    pub kick: f64,
    /// Steps rejected before this one was accepted.
    pub rejected: u32,
}

/// The step control of a world with clearance joints: see the module docs.
#[derive(Clone, Debug)]
pub(crate) struct Stepper {
    control: StepControl,
    t: f64,
    last_dt: f64,
    /// The velocity kick of the last accepted step, s ([`Self::kick_for`]).
    last_kick: f64,
    steps: u64,
    prepared: bool,
    floor_run: u64,
    /// World steps in a row whose sub-cycle reached its cap ([`CAP_STALL_STEPS`]).
    cap_run: u64,
    /// Adaptive world steps ending in a sub-cycled contact that asks for world steps below the
    /// floor ([`CONTACT_FLOOR_STALL_STEPS`]).
    contact_floor_run: u64,
    saved: Vec<BodySnapshot>,
    guards: GuardReport,
    correction: JointCorrection,
}

impl Stepper {
    /// A stepper at time 0 that has not evaluated its force sources yet.
    pub fn new(control: StepControl) -> Self {
        Stepper {
            control,
            t: 0.0,
            last_dt: 0.0,
            last_kick: 0.0,
            steps: 0,
            prepared: false,
            floor_run: 0,
            cap_run: 0,
            contact_floor_run: 0,
            saved: Vec::new(),
            guards: GuardReport::default(),
            correction: JointCorrection::default(),
        }
    }

    /// Changes the step control (the world's `step_control`, before each step).
    pub(crate) fn set_control(&mut self, control: StepControl) {
        self.control = control;
    }

    /// Simulated time, s: the sum of the accepted steps.
    pub fn time(&self) -> f64 {
        self.t
    }

    /// Accepted steps.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// The last accepted step (0 before the first), s.
    pub fn last_dt(&self) -> f64 {
        self.last_dt
    }

    /// What the guards recorded.
    pub fn guards(&self) -> &GuardReport {
        &self.guards
    }

    /// Forgets the force sources' evaluation: the next step evaluates them again first. Call it
    /// after changing the world between steps (bodies moved by hand, joints or drives added or
    /// removed). With `restart_kick` the next step's kick is a first step's again, as from a new
    /// initial state (after setting velocities by hand), and the clearance joints' contact laws get the
    /// stored rate at that evaluation. Without it they carry the rate to the state with its change
    /// since their last evaluation, across your edit: off by at most half that change, once
    /// ([`ClearanceJointSet::set_last_step`](crate::rapier::joint::ClearanceJointSet::set_last_step)).
    pub fn invalidate(&mut self, restart_kick: bool) {
        self.prepared = false;
        if restart_kick {
            self.last_dt = 0.0;
            self.last_kick = 0.0;
            self.correction.reset();
        }
    }

    /// Evaluates every source at the current state (once, before the first step; the stepper
    /// re-evaluates after every step by itself). Also checks the solver iterations.
    pub fn prepare(
        &mut self,
        world: &mut PhysicsWorld,
        sources: &mut [&mut dyn StepHooks],
    ) -> Result<()> {
        if self.prepared {
            return Ok(());
        }
        self.control.validate()?;
        for s in sources.iter_mut() {
            s.evaluate(EvaluateContext {
                bodies: &mut world.bodies,
                impulse_joints: &world.impulse_joints,
                last_step: self.last_dt,
            });
            s.check_world(&world.integration_parameters)?;
        }
        self.prepared = true;
        Ok(())
    }

    /// The step the control would take now, before landing on `until`.
    fn choose(&self, world: &PhysicsWorld, sources: &[&mut dyn StepHooks]) -> f64 {
        let c = &self.control;
        match c.mode {
            StepMode::Fixed => c.max_dt,
            StepMode::Adaptive => {
                let mut dt = c.max_dt.min(motion_step(world, c.tolerance));
                let step = self.step_context(self.t, 0.0);
                for s in sources {
                    dt = dt.min(s.step_limit(&step));
                }
                if self.last_dt > 0.0 {
                    dt = dt.min(c.max_growth * self.last_dt);
                }
                dt.max(c.min_dt)
            }
        }
    }

    /// Takes one accepted step towards `until` (s; the step lands on it exactly, a fixed step
    /// being taken whole when the remainder is within 1e-6 of it; an infinite `until` is no
    /// target), with `sources` evaluated at the state before it (done by the previous call, or by
    /// [`prepare`](Self::prepare) on the first) and again at the state after it. Returns what the
    /// step did. `until` at or before the current time is refused, and so is a finite `until`
    /// beyond what the clock can reach, where a step of `max_dt` does not change the time in f64;
    /// the world's gravity must be finite and within what one step of `max_dt` can take without
    /// passing the speed guard (`|g| max_dt` at most half Rapier's `max_linear_velocity`), else
    /// it is refused naming `gravity`. An error after the step (a
    /// fixed step beyond a contact's stability limit, a guard under `strict`, a diverged body)
    /// leaves the world and the clock at the state the step reached.
    ///
    /// Between steps the bodies carry only your own forces: the sources' wrenches are added for
    /// the step and taken away after it. Velocity-based kinematic bodies are placed exactly where
    /// their velocities take them over each step (exact rotation: a constant spin is exact in
    /// position, whatever steps were rejected). A kinematic position target
    /// (`set_next_kinematic_position`) set by hand is reached within one step whatever its length:
    /// under adaptive steps prescribe such motion as a function of time with a
    /// [`PrescribedSet`](crate::rapier::sources::prescribed::PrescribedSet), which sets the target of each
    /// step (retried ones included) from the step's end time.
    pub fn step(
        &mut self,
        world: &mut PhysicsWorld,
        sources: &mut [&mut dyn StepHooks],
        until: f64,
    ) -> Result<StepInfo> {
        // Cheap, and `set_control` may have changed it since the last step.
        self.control.validate()?;
        check_gravity(world, self.control.max_dt)?;
        check_joint_bodies(world, sources)?;
        check_body_states(world)?;
        self.prepare(world, sources)?;
        let left = until - self.t;
        if !(left > 0.0) {
            return Err(Error::invalid(
                "until",
                format!(
                    "must be after the current time {} s (got {until} s)",
                    self.t
                ),
            ));
        }
        if until.is_finite() && until + self.control.max_dt == until {
            return Err(Error::invalid(
                "until",
                format!(
                    "is beyond what the clock can reach (got {until} s): there a step of the \
                     largest size, max_dt = {} s, does not change the time in f64; give a time \
                     below 2^52 times max_dt ({} s)",
                    crate::error::sig4(self.control.max_dt),
                    crate::error::sig4(self.control.max_dt * 2f64.powi(52))
                ),
            ));
        }
        let adaptive = self.control.mode == StepMode::Adaptive;
        let mut dt = self.choose(world, sources);
        if adaptive {
            // Divide what is left into equal steps no larger than dt: no sliver step before the
            // target (a 1e-8 s step after a 1e-4 s one would break the growth bound). An
            // infinite `until` is no target. A count within 1e-9 of a whole number is that
            // number: rounding in dt must not add a step (200 steps of 5e-6 s to 1 ms, not 201).
            if left.is_finite() {
                dt = left / (left / dt - 1e-9).ceil().max(1.0);
            }
        } else {
            // The last step lands on `until`: a full step when `left` is one step up to rounding
            // (no sliver after it), else shortened.
            if left < dt * (1.0 - 1e-6) {
                dt = left;
            }
            let step = self.step_context(self.t, dt);
            for s in sources.iter() {
                s.check_step(&step).map_err(|e| self.locate(e))?;
            }
        }
        // Save the state: bodies (always: their forces are restored after the scaled step) and,
        // when a step may be rejected, the sources.
        snapshot_bodies(world, &mut self.saved);
        for s in sources.iter_mut() {
            s.save_state();
        }
        let mut rejected = 0u32;
        loop {
            let kick = self.take_rapier_step(world, sources, dt);
            let retry = if adaptive {
                let step = self.step_context(self.t + dt, dt);
                sources
                    .iter()
                    .filter_map(|s| s.judge_step(&step))
                    .reduce(f64::min)
            } else {
                None
            };
            match retry {
                None => {
                    // The step is taken: the clock follows the world before any check can fail,
                    // so an error leaves both at the state the step reached.
                    let info = StepInfo {
                        t0: self.t,
                        dt,
                        kick,
                        rejected,
                    };
                    self.t = if dt >= left * (1.0 - 1e-6) {
                        until
                    } else {
                        self.t + dt
                    };
                    self.last_dt = dt;
                    self.last_kick = kick;
                    self.correction.accept(dt);
                    self.steps += 1;
                    self.guards.rejected_steps += u64::from(rejected);
                    if !adaptive {
                        // The last step is checked too: the contact it ended in.
                        let step = self.step_context(self.t, dt);
                        for s in sources.iter() {
                            s.check_step(&step).map_err(|e| self.locate(e))?;
                        }
                    }
                    self.check_health(world, sources, dt)?;
                    self.count_floor(world, sources, dt)?;
                    self.count_contact_floor(world, sources)?;
                    return Ok(info);
                }
                Some(shorter) => {
                    rejected += 1;
                    let next = shorter.min(0.5 * dt).max(self.control.min_dt);
                    // Diagnosed at the state the rejected step reached, before it is undone.
                    let stalled = (rejected > MAX_REJECTIONS || next >= dt).then(|| {
                        self.stall_reason(
                            world,
                            sources,
                            &format!(
                                "the step was rejected {rejected} time{} down to {} s: no step \
                                 resolves the contact",
                                if rejected == 1 { "" } else { "s" },
                                crate::error::sig4(dt)
                            ),
                        )
                    });
                    self.restore(world, sources);
                    if let Some(reason) = stalled {
                        return Err(Error::Stalled {
                            t: self.t,
                            stall: reason,
                        });
                    }
                    dt = next;
                }
            }
        }
    }

    /// Takes a step of the last step's size (or `dt` if none), lets `read` look at the world and
    /// the step, then restores the state before it exactly: e.g. an ideal joint's reaction at
    /// the final time, which only the step after it determines. `dt` must be > 0 and at most
    /// the control's `max_dt`, else it is refused naming `dt`.
    pub fn peek<R>(
        &mut self,
        world: &mut PhysicsWorld,
        sources: &mut [&mut dyn StepHooks],
        dt: f64,
        read: impl FnOnce(&PhysicsWorld, &StepInfo) -> R,
    ) -> Result<R> {
        if !(dt > 0.0 && dt <= self.control.max_dt) {
            return Err(Error::invalid(
                "dt",
                format!(
                    "the peek's step must be > 0 and at most the control's largest step, \
                     max_dt = {} s (got {} s)",
                    crate::error::sig4(self.control.max_dt),
                    crate::error::sig4(dt)
                ),
            ));
        }
        self.prepare(world, sources)?;
        let (t, last, last_kick, steps, guards, control, correction) = (
            self.t,
            self.last_dt,
            self.last_kick,
            self.steps,
            self.guards.clone(),
            self.control,
            self.correction.clone(),
        );
        let h = if last > 0.0 { last } else { dt };
        // A fixed step of `h` with the sources saved, then everything put back.
        for s in sources.iter_mut() {
            s.save_state();
        }
        let mut probe = control;
        probe.mode = StepMode::Fixed;
        probe.max_dt = h;
        self.control = probe;
        let mut saved_bodies = Vec::new();
        snapshot_bodies(world, &mut saved_bodies);
        let result = self.step(world, sources, t + h);
        let out = result.map(|info| read(world, &info));
        self.saved = saved_bodies;
        self.restore(world, sources);
        self.t = t;
        self.last_dt = last;
        self.last_kick = last_kick;
        self.steps = steps;
        self.guards = guards;
        self.control = control;
        self.correction = correction;
        out
    }
}
