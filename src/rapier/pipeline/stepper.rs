//! The step control, public: one [`Stepper`] chooses, takes, judges and (when needed) retries
//! every Rapier step of a world that holds clearance joints. It steps whatever takes part in the
//! step through the step protocol ([`StepHooks`]: the joint sets, the drives, the prescribed
//! motions; called the sources here). [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld)
//! bundles it with the sets (the scene runner and the bevy_ecs layer are built on it); a loop that
//! keeps its sets apart calls [`Stepper::step`] with them in place of `world.step()`.
//!
//! What it adds to `PhysicsWorld::step`:
//! - **Consistent variable steps.** With one solver iteration a Rapier step is symplectic Euler
//!   (`v += h F/m`, then `x += h v`), which is second order only while `h` is constant. The
//!   stepper makes it variable-step Störmer-Verlet: the velocity kick of a step `h` after a step
//!   `h_prev` spans `(h_prev + h)/2`, so every user force and torque (the hooks' and your own) and
//!   gravity are scaled by `(h_prev + h)/(2 h)` for the step and restored after it. The first
//!   step from a given state is a half kick (`h_prev = 0`): velocities then live at half steps,
//!   and positions are second-order accurate from the start.
//! - **Joint drift corrected at a consistent rate.** Rapier corrects the drift of its joints'
//!   locked positions within each step, so a drop of the step multiplies the correcting
//!   velocity; on slender bodies that makes the locked tilt grow at each change of the step. The
//!   stepper gives the joints (those with Rapier's default softness, for the step only) the
//!   correction rate of the longest recent step
//!   ([`joint_correction`](crate::rapier::pipeline::joint_correction); [`StepControl::joint_correction`]).
//! - **Step choice** ([`StepControl`]): fixed, or adaptive from the motion (no body turns more
//!   than `tolerance/8` rad in a step: [`motion_step`](crate::rapier::pipeline::motion_step)) and the
//!   contacts (the joints'
//!   [`adaptive_step`](crate::rapier::joint::ClearanceJoint::adaptive_step)), growing by at most
//!   [`StepControl::max_growth`] per step and landing exactly on the time given to
//!   [`Stepper::step`].
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
//!   cannot make progress (no accepted step above the floor for [`STALL_STEPS`] steps) is an
//!   [`Error::Stalled`].
//!
//! ```
//! use clearance_joint::prelude::*;
//! use clearance_joint::rapier::pipeline::stepper::{StepControl, Stepper};
//! use rapier3d_f64::prelude::*;
//!
//! // A 2 kg arm on a steel pin with 0.2 mm of play, released horizontal under gravity.
//! let mut world = PhysicsWorld::new();
//! world.gravity = Vector::new(0.0, -9.81, 0.0);
//! world.integration_parameters.num_solver_iterations = 1;
//! let base = world.bodies.insert(RigidBodyBuilder::fixed());
//! let arm = world.bodies.insert(
//!     RigidBodyBuilder::dynamic()
//!         .translation(Vector::new(0.3, 0.0, 0.0))
//!         .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02)))
//!         .can_sleep(false),
//! );
//! let mut joints = ClearanceJointSet::new();
//! // Improved Liu law, steel on steel: bearing radius 10 mm, clearance 0.2 mm, width 16 mm.
//! let pin = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)?.joint(
//!     Vector::ZERO,
//!     Vector::new(-0.3, 0.0, 0.0),
//!     Vector::Z,
//!     Vector::Z,
//! )?;
//! let pin = joints.insert(base, arm, pin, &world.bodies, &mut world.impulse_joints)?;
//! let mut stepper = Stepper::new(StepControl::adaptive(1e-3, 0.02));
//! let mut peak: f64 = 0.0;
//! while stepper.time() < 0.2 {
//!     stepper.step(&mut world, &mut [&mut joints], 0.2)?;
//!     peak = peak.max(joints.get(pin).unwrap().report().force.normal_force);
//! }
//! assert!(stepper.guards().is_clean(), "{:?}", stepper.guards());
//! assert!(peak > 19.62, "the first impact exceeds the static load: {peak} N");
//! # Ok::<(), clearance_joint::Error>(())
//! ```

use crate::error::{Error, Result};
use crate::rapier::observers::stall::{Stall, StallCause};
use crate::rapier::pipeline::joint_correction::JointCorrection;
use crate::rapier::pipeline::motion_step::motion_step;
use rapier3d_f64::math::{Pose, Vector};
use rapier3d_f64::prelude::{PhysicsWorld, RigidBodyHandle, RigidBodyType};
use serde::{Deserialize, Serialize};

pub use crate::rapier::observers::guards::{GuardKind, GuardReport, Violation};
pub use crate::rapier::pipeline::step_hooks::{StepHooks, StepPass};

/// How the step is chosen (`run.step` in scene files).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum StepMode {
    /// A constant step (the paper's way); the last step is shortened to land on the end.
    Fixed,
    /// The step changes between Rapier steps: no body turns more than `tolerance/8` rad in a step
    /// ([`motion_step`]), shorter as a contact approaches and inside it (twice `tolerance` of the
    /// contact's natural period, at most `50 tolerance` of its damped stability limit, within
    /// friction's), at most the
    /// largest step (a safety cap), with rejected steps retried. The default.
    #[default]
    Adaptive,
}

/// Steps at or below this many floors in a row, with no progress in simulated time, stop the
/// run with [`Error::Stalled`].
pub const STALL_STEPS: u64 = 100_000;

/// Passes after the first that one step may take ([`StepHooks::resolve_step`]): a sub-cycled
/// joint takes one.
const MAX_PASSES: u32 = 3;

/// Rejections of one step after which the step control gives up ([`Error::Stalled`]).
const MAX_REJECTIONS: u32 = 60;

/// The step control of a [`Stepper`], built with chained setters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepControl {
    /// Fixed or adaptive.
    pub mode: StepMode,
    /// The fixed step, or the largest adaptive step, s.
    pub max_dt: f64,
    /// Adaptive: the local error each bound of the step holds to: a step covers at most twice
    /// this fraction of a contact's natural period
    /// ([`CONTACT_PERIODS_PER_TOLERANCE`](crate::rapier::joint::CONTACT_PERIODS_PER_TOLERANCE)),
    /// turns no body by more than an eighth of it in rad
    /// ([`TURN_PER_TOLERANCE`](crate::rapier::pipeline::motion_step::TURN_PER_TOLERANCE)), and moves a
    /// journal's centre relative to its bearing's by at most this fraction of the clearance.
    pub tolerance: f64,
    /// Adaptive: the smallest step, s (the floor; see [`STALL_STEPS`]).
    pub min_dt: f64,
    /// Adaptive: the largest ratio of a step to the one before it. Steps that change abruptly
    /// make Rapier's constrained velocities (which it evaluates at the step's start) disagree
    /// with the half-step velocities of the kicked bodies; a bounded ratio keeps that error
    /// first order in the change.
    pub max_growth: f64,
    /// Whether a guard violation ([`GuardReport::is_clean`] false) fails the step with
    /// [`Error::Guard`] instead of only being recorded.
    pub strict: bool,
    /// Whether Rapier's joints correct their drift at the rate of the longest recent step
    /// ([`joint_correction`](crate::rapier::pipeline::joint_correction)), not within each step whatever
    /// its length. On by default: without it a jointed chain of slender bodies can diverge when
    /// the step changes.
    pub joint_correction: bool,
}

impl StepControl {
    /// The shortest step, s (fixed, or an adaptive control's largest; also the default floor
    /// `min_dt`): Rapier's solver divides by the step, and a step of 1e-300 s ends in
    /// non-finite states.
    pub const SMALLEST_STEP: f64 = 1e-10;

    /// The smallest adaptive tolerance: a step covers twice it of a contact period and a body
    /// turns at most an eighth of it in rad, so below it a body turning at 1,000 rad/s needs
    /// steps under the default floor `min_dt` (1e-10 s).
    pub const SMALLEST_TOLERANCE: f64 = 1e-6;

    /// Constant steps of `dt` seconds.
    pub fn fixed(dt: f64) -> Self {
        StepControl {
            mode: StepMode::Fixed,
            max_dt: dt,
            ..Self::adaptive(dt, 0.02)
        }
    }

    /// Adaptive steps of at most `max_dt` seconds, `2 tolerance` of a contact period inside
    /// contacts and `tolerance/8` rad of any body's turn; floor 1e-10 s, growth at most 2 per step,
    /// not strict.
    pub fn adaptive(max_dt: f64, tolerance: f64) -> Self {
        StepControl {
            mode: StepMode::Adaptive,
            max_dt,
            tolerance,
            min_dt: Self::SMALLEST_STEP,
            max_growth: 2.0,
            strict: false,
            joint_correction: true,
        }
    }

    /// Sets the adaptive tolerance ([`tolerance`](Self::tolerance): half the fraction of a
    /// contact period one step may cover, and 8 times the angle in rad a body may turn in one
    /// step).
    pub fn with_tolerance(mut self, tolerance: f64) -> Self {
        self.tolerance = tolerance;
        self
    }

    /// Sets the floor of the adaptive step, s.
    pub fn min_dt(mut self, dt: f64) -> Self {
        self.min_dt = dt;
        self
    }

    /// Sets the largest growth ratio of one step over the previous.
    pub fn max_growth(mut self, ratio: f64) -> Self {
        self.max_growth = ratio;
        self
    }

    /// Makes guard violations errors.
    pub fn strict(mut self, strict: bool) -> Self {
        self.strict = strict;
        self
    }

    /// Turns the step-consistent drift correction of Rapier's joints on (the default) or off
    /// (Rapier's own correction, the whole drift within each step).
    pub fn joint_correction(mut self, on: bool) -> Self {
        self.joint_correction = on;
        self
    }

    /// Checks the fields: finite steps of at least [`SMALLEST_STEP`](Self::SMALLEST_STEP), a
    /// tolerance from [`SMALLEST_TOLERANCE`](Self::SMALLEST_TOLERANCE) to 1, growth above 1.
    pub fn validate(&self) -> Result<()> {
        let ok = |v: f64| v.is_finite() && v > 0.0;
        let step = match self.mode {
            StepMode::Fixed => "dt",
            StepMode::Adaptive => "max_dt",
        };
        if !(ok(self.max_dt) && self.max_dt >= Self::SMALLEST_STEP) {
            return Err(Error::invalid(
                step,
                format!(
                    "must be a finite step of at least {} s (got {} s): Rapier's solver divides by \
                     the step, and shorter ones end in non-finite states",
                    Self::SMALLEST_STEP,
                    self.max_dt
                ),
            ));
        }
        if self.mode == StepMode::Adaptive {
            if !(self.tolerance >= Self::SMALLEST_TOLERANCE && self.tolerance <= 1.0) {
                return Err(Error::invalid(
                    "tolerance",
                    format!(
                        "must be in [{}, 1]: a step covers twice it of a contact's period and \
                         turns a body by an eighth of it in rad, so a smaller one asks a fast \
                         body for steps below the floor `min_dt` (got {})",
                        Self::SMALLEST_TOLERANCE,
                        self.tolerance
                    ),
                ));
            }
            if !(ok(self.min_dt) && self.min_dt <= self.max_dt) {
                return Err(Error::invalid(
                    "min_dt",
                    format!(
                        "must be positive and at most the largest step {} s (got {})",
                        self.max_dt, self.min_dt
                    ),
                ));
            }
            if !(self.max_growth.is_finite() && self.max_growth > 1.0) {
                return Err(Error::invalid(
                    "max_growth",
                    format!("must be a finite ratio above 1 (got {})", self.max_growth),
                ));
            }
        }
        Ok(())
    }
}

/// What one accepted step did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepInfo {
    /// Time at the step's start, s.
    pub t0: f64,
    /// The step, s.
    pub dt: f64,
    /// The span of the velocity kick, `(h_prev + h)/2` (`h/2` for the first step), s: applied
    /// forces and gravity acted for this long, so a momentum change over the step divided by it
    /// is the mean force at the step's start (an ideal joint's reaction, say).
    pub kick: f64,
    /// Steps rejected before this one was accepted.
    pub rejected: u32,
}

#[derive(Clone, Copy, Debug)]
struct BodySnapshot {
    handle: RigidBodyHandle,
    position: Pose,
    next_position: Pose,
    linvel: Vector,
    angvel: Vector,
    force: Vector,
    torque: Vector,
}

/// Replaces `into` with the state of every movable body: pose (and kinematic target),
/// velocities, and the user forces on it.
fn snapshot_bodies(world: &PhysicsWorld, into: &mut Vec<BodySnapshot>) {
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

/// The step control of a world with clearance joints: see the module docs.
#[derive(Clone, Debug)]
pub struct Stepper {
    control: StepControl,
    t: f64,
    last_dt: f64,
    steps: u64,
    prepared: bool,
    floor_run: u64,
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
            steps: 0,
            prepared: false,
            floor_run: 0,
            saved: Vec::new(),
            guards: GuardReport::default(),
            correction: JointCorrection::default(),
        }
    }

    /// The step control.
    pub fn control(&self) -> &StepControl {
        &self.control
    }

    /// Changes the step control (e.g. the ECS layer follows `integration_parameters.dt`).
    pub fn set_control(&mut self, control: StepControl) {
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
    /// removed). With `restart_kick` the next step is a half kick again, as from a new initial
    /// state (after setting velocities by hand), and the clearance joints' contact laws get the
    /// stored rate at that evaluation. Without it they carry the rate to the state with its change
    /// since their last evaluation, across your edit: off by at most half that change, once
    /// ([`ClearanceJointSet::set_last_step`](crate::rapier::joint::ClearanceJointSet::set_last_step)).
    pub fn invalidate(&mut self, restart_kick: bool) {
        self.prepared = false;
        if restart_kick {
            self.last_dt = 0.0;
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
            s.set_last_step(self.last_dt);
            s.evaluate(&mut world.bodies, &world.impulse_joints);
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
                for s in sources {
                    dt = dt.min(s.step_limit(c.tolerance, self.last_dt));
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
            for s in sources.iter() {
                s.check_step(dt).map_err(|e| self.locate(e))?;
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
                sources
                    .iter()
                    .filter_map(|s| s.judge_step(dt, self.control.tolerance))
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
                    self.correction.accept(dt);
                    self.steps += 1;
                    self.guards.rejected_steps += u64::from(rejected);
                    if !adaptive {
                        // The last step is checked too: the contact it ended in.
                        for s in sources.iter() {
                            s.check_step(dt).map_err(|e| self.locate(e))?;
                        }
                    }
                    self.check_health(world, sources, dt)?;
                    self.count_floor(world, sources, dt)?;
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

    /// One Rapier step of `dt` from the saved state, with the kick `(h_prev + h)/2`: your forces,
    /// the sources' wrenches and gravity scaled to the kick for this step only, the sources'
    /// hooks around it, the joint correction, exact kinematic poses ([`Self::rapier_pass`]),
    /// taken again from the saved state while a source asks ([`StepHooks::resolve_step`], at
    /// most [`MAX_PASSES`] more); then the sources evaluated at the new state. Returns the
    /// kick, s.
    fn take_rapier_step(
        &mut self,
        world: &mut PhysicsWorld,
        sources: &mut [&mut dyn StepHooks],
        dt: f64,
    ) -> f64 {
        let kick = 0.5 * (self.last_dt + dt);
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
            s.set_last_step(dt);
            s.evaluate(&mut world.bodies, &world.impulse_joints);
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
            s.before_rapier_step(world, self.t, dt);
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
            s.after_rapier_step(world);
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
        let (t, last, steps, guards, control, correction) = (
            self.t,
            self.last_dt,
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
        self.steps = steps;
        self.guards = guards;
        self.control = control;
        self.correction = correction;
        out
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
    fn restore(&self, world: &mut PhysicsWorld, sources: &mut [&mut dyn StepHooks]) {
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

    /// The stall message for `seen`: the contact that stops the steps, its state and its cause
    /// ([`crate::rapier::observers::stall`]).
    fn stall_reason(
        &self,
        world: &PhysicsWorld,
        sources: &[&mut dyn StepHooks],
        seen: &str,
    ) -> Box<Stall> {
        if let Some(turn) = self.turn_stall(world) {
            return Box::new(Stall::turn_bound(seen.into(), self.control.min_dt, turn));
        }
        // The contact whose step limit is the shortest stops the step control.
        let limit =
            |c: &crate::rapier::observers::stall::StalledContact| c.stable_dt.min(c.friction_dt);
        let contact = sources
            .iter()
            .filter_map(|s| s.stalled_contact(&world.bodies))
            .min_by(|a, b| limit(a).total_cmp(&limit(b)));
        Box::new(Stall::at_contact(seen.into(), contact, self.control.min_dt))
    }

    /// The turn bound in words when it alone asks for steps at the floor: the fastest-turning
    /// movable body may turn `tolerance/8` rad a step.
    fn turn_stall(&self, world: &PhysicsWorld) -> Option<StallCause> {
        let per_step =
            crate::rapier::pipeline::motion_step::TURN_PER_TOLERANCE * self.control.tolerance;
        let (handle, rb) = world
            .bodies
            .iter()
            .filter(|(_, rb)| !rb.is_fixed())
            .max_by(|a, b| a.1.angvel().length().total_cmp(&b.1.angvel().length()))?;
        let w = rb.angvel().length();
        let step = crate::rapier::pipeline::motion_step::turn_step(per_step, w);
        (step <= 2.0 * self.control.min_dt).then_some(StallCause::TurnBound {
            body: handle,
            rate: w,
            per_step,
            step,
        })
    }

    fn count_floor(
        &mut self,
        world: &PhysicsWorld,
        sources: &[&mut dyn StepHooks],
        dt: f64,
    ) -> Result<()> {
        if self.control.mode == StepMode::Adaptive && dt <= self.control.min_dt * (1.0 + 1e-9) {
            self.guards.floor_steps += 1;
            self.floor_run += 1;
            // One state counted; the worst is the longest run in a row (closest to a stall).
            let v = Violation::new(
                GuardKind::Floor,
                self.floor_run as f64,
                STALL_STEPS as f64,
                self.t,
            )
            .note(format!("{} s", crate::error::sig4(self.control.min_dt)));
            self.guards.record(v);
            if self.floor_run >= STALL_STEPS {
                let seen = format!("{} steps in a row at the floor", self.floor_run);
                return Err(Error::Stalled {
                    t: self.t,
                    stall: self.stall_reason(world, sources, &seen),
                });
            }
        } else {
            self.floor_run = 0;
        }
        Ok(())
    }

    /// Non-physical bodies are errors; penetrations beyond validity are recorded.
    fn check_health(
        &mut self,
        world: &PhysicsWorld,
        sources: &[&mut dyn StepHooks],
        dt: f64,
    ) -> Result<()> {
        for b in &self.saved {
            if let Some(rb) = world.bodies.get(b.handle)
                && let Some(speed) = left_physical_range(rb, &world.integration_parameters)
            {
                return Err(Error::Diverged {
                    t: self.t,
                    reason: diverged_body(
                        world,
                        sources,
                        b.handle,
                        speed,
                        self.control.joint_correction,
                    ),
                });
            }
        }
        let fixed = self.control.mode == StepMode::Fixed;
        for s in sources {
            s.record_guards(&mut self.guards, self.t, dt, fixed);
        }
        if self.control.strict && !self.guards.is_clean() {
            return Err(Error::Guard {
                t: self.t,
                violations: self.guards.violations.clone(),
            });
        }
        Ok(())
    }

    /// Adds the time, the step mode and the parameter that set the step to a step-limit error
    /// (the joints know none of them).
    fn locate(&self, mut e: Error) -> Error {
        if let Error::StepTooLarge(limit) = &mut e {
            limit.t = Some(self.t);
            limit.field = "StepControl::max_dt".into();
        }
        e.with_step_mode(self.control.mode == StepMode::Adaptive)
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

/// The world's gravity must be finite (a NaN one would only show as a body leaving the
/// physical range), and within what the speed guard lets a step take: a free body falling for
/// one step of `max_dt` must stay below the guard, half Rapier's `max_linear_velocity` (beyond
/// it the first step leaves the physical range, or Rapier's clamps leave the bodies still).
fn check_gravity(world: &PhysicsWorld, max_dt: f64) -> Result<()> {
    let g = world.gravity;
    if !g.is_finite() {
        return Err(Error::invalid(
            "gravity",
            format!("the world's gravity must be finite (got {g:?})"),
        ));
    }
    let guard = 0.5 * world.integration_parameters.max_linear_velocity();
    let bound = guard / max_dt;
    if g.length() > bound {
        return Err(Error::invalid(
            "gravity",
            format!(
                "{} m/s^2 would take a free body past the speed guard ({} m/s, half \
                 `integration_parameters.max_linear_velocity()`) within one step of max_dt = {} \
                 s: give a gravity of at most {} m/s^2 (or a shorter max_dt)",
                crate::error::sig4(g.length()),
                crate::error::sig4(guard),
                crate::error::sig4(max_dt),
                crate::error::sig4(bound)
            ),
        ));
    }
    Ok(())
}

/// Every body's pose and velocities are finite before a step: a NaN set by hand would otherwise
/// show only as a body leaving the physical range after it, with nothing to say why.
fn check_body_states(world: &PhysicsWorld) -> Result<()> {
    for (handle, rb) in world.bodies.iter() {
        let bad = [
            (
                "position",
                rb.translation().is_finite() && rb.rotation().is_finite(),
            ),
            ("linvel", rb.linvel().is_finite()),
            ("angvel", rb.angvel().is_finite()),
        ]
        .into_iter()
        .find(|(_, ok)| !ok);
        if let Some((field, _)) = bad {
            return Err(Error::invalid(
                field,
                format!(
                    "body {:?} has a non-finite {field} before the step (position {:?}, linvel \
                     {:?}, angvel {:?}): set finite values",
                    handle.into_raw_parts(),
                    rb.translation(),
                    rb.linvel(),
                    rb.angvel()
                ),
            ));
        }
    }
    Ok(())
}

/// Every impulse joint (Rapier's own, a clearance joint's lock, a large-step joint's) and every
/// participant's joint joins bodies of the world: Rapier's step panics on one whose body is gone.
fn check_joint_bodies(world: &PhysicsWorld, sources: &[&mut dyn StepHooks]) -> Result<()> {
    for (handle, joint) in world.impulse_joints.iter() {
        crate::rapier::pipeline::step_hooks::joint_bodies(
            &world.bodies,
            || format!("impulse joint {:?}", handle.into_raw_parts()),
            joint.body1(),
            joint.body2(),
        )?;
    }
    for s in sources {
        s.check_bodies(&world.bodies)?;
    }
    Ok(())
}

/// What a divergence says of `body`: its handle, what joins it (Rapier's impulse joints, the
/// sources' clearance joints), its speed and the likely cause.
fn diverged_body(
    world: &PhysicsWorld,
    sources: &[&mut dyn StepHooks],
    body: rapier3d_f64::prelude::RigidBodyHandle,
    speed: f64,
    joint_correction: bool,
) -> String {
    let mut joined: Vec<String> = world
        .impulse_joints
        .attached_joints(body)
        .map(|(_, _, h, _)| format!("impulse joint {:?}", h.into_raw_parts()))
        .collect();
    // Rapier's joints: the ones whose drift correction can make it diverge.
    let jointed = !joined.is_empty();
    for s in sources {
        s.joints_of(body, &mut joined);
    }
    let joined = if joined.is_empty() {
        String::new()
    } else {
        format!(", joined by {}", joined.join(", "))
    };
    let speed = state_in_words(world.bodies.get(body), speed);
    let correction = if jointed && !joint_correction {
        "; with the joint correction off (`StepControl::joint_correction`), also Rapier's joint \
         drift correction under changing steps, which makes a chain of slender bodies tilt out of \
         its plane"
    } else {
        ""
    };
    format!(
        "body {:?}{joined} left the physical range ({speed}, the guard being {} m/s); likely \
         cause: a motor, drive or prescribed motion that moves it too fast, a contact too stiff \
         for the step, or a non-finite input (gravity, a force, a mass){correction}",
        body.into_raw_parts(),
        crate::error::sig4(0.5 * world.integration_parameters.max_linear_velocity())
    )
}

/// What is out of range in a diverged body's state: its pose, its velocities, Rapier's quarantine,
/// or its `speed` (m/s).
fn state_in_words(rb: Option<&rapier3d_f64::prelude::RigidBody>, speed: f64) -> String {
    let Some(rb) = rb else {
        return "it is no longer in the world".into();
    };
    if !(rb.translation().is_finite() && rb.rotation().is_finite()) {
        format!("its position is not finite: {:?}", rb.translation())
    } else if !(rb.linvel().is_finite() && rb.angvel().is_finite()) {
        format!(
            "its velocity is not finite: linvel {:?}, angvel {:?}",
            rb.linvel(),
            rb.angvel()
        )
    } else if !rb.is_enabled() {
        "Rapier disabled it".into()
    } else {
        format!("speed {} m/s", crate::error::sig4(speed))
    }
}

/// `Some(speed)` when `rb` has left the physical range: disabled by Rapier's quarantine,
/// non-finite, or faster than half Rapier's speed clamp (Rapier clamps a blown-up body instead of
/// producing NaN, so a clamped speed is the sign of a silent blow-up).
pub fn left_physical_range(
    rb: &rapier3d_f64::prelude::RigidBody,
    params: &rapier3d_f64::prelude::IntegrationParameters,
) -> Option<f64> {
    let (v, w) = (rb.linvel(), rb.angvel());
    let bad = !rb.is_enabled() || !rb.translation().is_finite() || !v.is_finite() || !w.is_finite();
    (bad || v.length() > 0.5 * params.max_linear_velocity()).then(|| v.length())
}
