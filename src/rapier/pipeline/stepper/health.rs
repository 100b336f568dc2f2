//! The step control's checks and diagnoses: the world's and bodies' state before a step, the
//! guards after it, and the words of a divergence or a stall.

use super::{
    CAP_STALL_STEPS, CONTACT_FLOOR_STALL_STEPS, GuardKind, STALL_STEPS, StepControl, StepMode,
    Stepper, Violation,
};
use crate::error::{Divergence, Error, Result};
use crate::rapier::observers::stall::{Stall, StallCause};
use crate::rapier::pipeline::step_hooks::{StepContext, StepHooks};
use rapier3d_f64::prelude::{
    MassProperties, PhysicsWorld, RigidBody, RigidBodyAdditionalMassProps,
};

impl Stepper {
    /// The stall message for `seen`: the contact that stops the steps, its state and its cause
    /// ([`crate::rapier::observers::stall`]).
    pub(super) fn stall_reason(
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
            |c: &crate::rapier::pipeline::protocol::StalledContact| c.stable_dt.min(c.friction_dt);
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

    pub(super) fn count_floor(
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

    /// Counts adaptive world steps that end in a sub-cycled contact asking for world steps below
    /// the floor `min_dt`, or the default floor where `min_dt` is raised above it (a step
    /// ending in one that asks for more starts the count again; one out of contact leaves it,
    /// as a journal held on its wall chatters in and out);
    /// [`CONTACT_FLOOR_STALL_STEPS`] of them stop the run, as the explicit joint's retries stop
    /// at such a contact at once: the world's step sits at the floor while it lasts.
    pub(super) fn count_contact_floor(
        &mut self,
        world: &PhysicsWorld,
        sources: &[&mut dyn StepHooks],
    ) -> Result<()> {
        if self.control.mode != StepMode::Adaptive {
            return Ok(());
        }
        let step = self.step_context(self.t, 0.0);
        let asked = sources
            .iter()
            .map(|s| s.sub_cycled_contact_step(&step))
            .fold(f64::INFINITY, f64::min);
        // The default floor, not a raised one: steps of a floor you raised are your choice, and
        // the sub-cycle resolves the contact inside them.
        let floor = self.control.min_dt.min(StepControl::SMALLEST_STEP);
        if asked >= floor {
            if asked.is_finite() {
                self.contact_floor_run = 0;
            }
            return Ok(());
        }
        self.contact_floor_run += 1;
        if self.contact_floor_run < CONTACT_FLOOR_STALL_STEPS {
            return Ok(());
        }
        let seen = format!(
            "{} world steps ended in a sub-cycled contact that asks for world steps of {} s, \
             under the floor: its sub-steps resolve it, but the world's step sits at the floor \
             and the run crawls",
            self.contact_floor_run,
            crate::error::sig4(asked)
        );
        Err(self.stalled_at_contact(seen, world, sources))
    }

    /// Counts world steps in a row whose sub-cycle reached its cap of sub-steps (`capped`);
    /// [`CAP_STALL_STEPS`] of them stop the run: the contact's numbers say why no sub-step the
    /// cap allows (`dt` over the cap) resolves it.
    fn count_cap(
        &mut self,
        world: &PhysicsWorld,
        sources: &[&mut dyn StepHooks],
        dt: f64,
        capped: bool,
    ) -> Result<()> {
        self.cap_run = if capped { self.cap_run + 1 } else { 0 };
        if self.cap_run < CAP_STALL_STEPS {
            return Ok(());
        }
        let cap = crate::rapier::joint::MAX_SUBSTEPS;
        let floor = dt / f64::from(cap);
        let seen = format!(
            "{} world steps in a row at the sub-cycle's cap of {cap} sub-steps (sub-steps of {} s \
             at most)",
            self.cap_run,
            crate::error::sig4(floor)
        );
        Err(self.stalled_at_contact(seen, world, sources))
    }

    /// The stall `seen`, diagnosed at the stiffest contact the sources report (the one whose
    /// stable step is the shortest).
    fn stalled_at_contact(
        &self,
        seen: String,
        world: &PhysicsWorld,
        sources: &[&mut dyn StepHooks],
    ) -> Error {
        let contact = sources
            .iter()
            .filter_map(|s| s.stalled_contact(&world.bodies))
            .min_by(|a, b| a.stable_dt.total_cmp(&b.stable_dt));
        Error::Stalled {
            t: self.t,
            stall: Box::new(Stall::at_contact(seen, contact, self.control.min_dt)),
        }
    }

    /// Non-physical bodies are errors; penetrations beyond validity are recorded.
    pub(super) fn check_health(
        &mut self,
        world: &PhysicsWorld,
        sources: &[&mut dyn StepHooks],
        dt: f64,
    ) -> Result<()> {
        for b in &self.saved {
            if let Some(rb) = world.bodies.get(b.handle)
                && let Some(speed) = left_physical_range(rb, &world.integration_parameters)
            {
                return Err(Error::diverged(
                    self.t,
                    diverged_body(
                        world,
                        sources,
                        b.handle,
                        speed,
                        self.control.joint_correction,
                    ),
                ));
            }
        }
        let step = self.step_context(self.t, dt);
        let capped = |g: &crate::rapier::pipeline::protocol::GuardReport| -> u64 {
            let sub_steps = g
                .violations
                .iter()
                .filter(|v| v.kind == GuardKind::SubSteps);
            sub_steps.map(|v| v.count).sum()
        };
        let capped_before = capped(&self.guards);
        for s in sources {
            s.record_guards(&step, &mut self.guards);
        }
        self.count_cap(world, sources, dt, capped(&self.guards) > capped_before)?;
        if self.control.strict && !self.guards.is_clean() {
            return Err(Error::Guard {
                t: self.t,
                violations: self.guards.violations.clone(),
            });
        }
        Ok(())
    }

    /// The step context of a step `dt` (s) whose participants are evaluated at time `t` (s).
    pub(super) fn step_context(&self, t: f64, dt: f64) -> StepContext {
        StepContext {
            t,
            dt,
            last_dt: self.last_dt,
            tolerance: self.control.tolerance,
            fixed: self.control.mode == StepMode::Fixed,
        }
    }

    /// Adds the time, the step mode and the parameter that set the step to a step-limit error
    /// (the joints know none of them).
    pub(super) fn locate(&self, mut e: Error) -> Error {
        if let Error::StepTooLarge(limit) = &mut e {
            limit.t = Some(self.t);
            limit.field = "StepControl::max_dt".into();
        }
        e.with_step_mode(self.control.mode == StepMode::Adaptive)
    }
}

/// The world's gravity must be finite (a NaN one would only show as a body leaving the
/// physical range), and within what the speed guard lets a step take: a free body falling for
/// one step of `max_dt` must stay below the guard, half Rapier's `max_linear_velocity` (beyond
/// it the first step leaves the physical range, or Rapier's clamps leave the bodies still).
pub(super) fn check_gravity(world: &PhysicsWorld, max_dt: f64) -> Result<()> {
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

/// Every body's pose, velocities, mass properties and user forces are finite before a step: a
/// NaN set by hand (a controller's torque, a mass) would otherwise show only as a body leaving
/// the physical range after it, with nothing to say which input it was.
pub(super) fn check_body_states(world: &PhysicsWorld) -> Result<()> {
    for (handle, rb) in world.bodies.iter() {
        let mprops = &rb.mass_properties().local_mprops;
        let bad = [
            (
                "position",
                rb.translation().is_finite() && rb.rotation().is_finite(),
            ),
            ("linvel", rb.linvel().is_finite()),
            ("angvel", rb.angvel().is_finite()),
            ("mass", finite_mass(mprops) && additional_mass_is_finite(rb)),
            ("user_force", rb.user_force().is_finite()),
            ("user_torque", rb.user_torque().is_finite()),
        ]
        .into_iter()
        .find(|(_, ok)| !ok);
        if let Some((field, _)) = bad {
            let what = match field {
                "mass" => format!(
                    "mass {:?}, principal inertia {:?}, additional mass properties {:?}",
                    rb.mass(),
                    mprops.principal_inertia(),
                    rb.mass_properties().additional_local_mprops
                ),
                "user_force" | "user_torque" => format!(
                    "user force {:?}, user torque {:?}: a force added with `add_force` or \
                     `add_torque` since the last step (Rapier keeps them until \
                     `reset_forces`/`reset_torques`)",
                    rb.user_force(),
                    rb.user_torque()
                ),
                _ => format!(
                    "position {:?}, linvel {:?}, angvel {:?}",
                    rb.translation(),
                    rb.linvel(),
                    rb.angvel()
                ),
            };
            return Err(Error::invalid(
                field,
                format!(
                    "body {:?} has a non-finite {field} before the step ({what}): set finite values",
                    handle.into_raw_parts(),
                ),
            ));
        }
    }
    Ok(())
}

/// Whether mass properties hold a finite mass and inertia.
fn finite_mass(m: &MassProperties) -> bool {
    m.inv_mass.is_finite() && m.inv_principal_inertia.is_finite()
}

/// Whether a body's additional mass properties (`set_additional_mass_properties`,
/// `set_additional_mass`; Rapier folds them into the body's mass at its next step) are finite.
fn additional_mass_is_finite(rb: &RigidBody) -> bool {
    match rb.mass_properties().additional_local_mprops.as_deref() {
        Some(RigidBodyAdditionalMassProps::MassProps(m)) => finite_mass(m),
        Some(RigidBodyAdditionalMassProps::Mass(m)) => m.is_finite(),
        None => true,
    }
}

/// Every impulse joint (Rapier's own, a clearance joint's lock, a large-step joint's) and every
/// participant's joint joins bodies of the world: Rapier's step panics on one whose body is gone.
pub(super) fn check_joint_bodies(
    world: &PhysicsWorld,
    sources: &[&mut dyn StepHooks],
) -> Result<()> {
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
) -> Divergence {
    let mut joined: Vec<String> = world
        .impulse_joints
        .attached_joints(body)
        .map(|(_, _, h, _)| format!("impulse joint {:?}", h.into_raw_parts()))
        .collect();
    // Rapier's joints: the ones whose drift correction can make it diverge.
    let jointed = !joined.is_empty();
    let mut known = Vec::new();
    for s in sources {
        s.joints_of(body, &mut joined);
        s.divergence_causes(body, &mut known);
    }
    let state = state_in_words(world.bodies.get(body), speed);
    let correction = if jointed && !joint_correction {
        "; with the joint correction off (`StepControl::joint_correction`), also Rapier's joint \
         drift correction under changing steps, which makes a chain of slender bodies tilt out of \
         its plane"
    } else {
        ""
    };
    Divergence::Body {
        body: format!("{:?}", body.into_raw_parts()),
        joined,
        state,
        guard: 0.5 * world.integration_parameters.max_linear_velocity(),
        cause: format!(
            "{}a motor, drive or prescribed motion that moves it too fast, a contact too stiff for \
             the step, or a non-finite input (gravity, a force, a mass){correction}",
            known
                .iter()
                .map(|k| format!("{k}; else "))
                .collect::<String>()
        ),
    }
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
pub(crate) fn left_physical_range(
    rb: &rapier3d_f64::prelude::RigidBody,
    params: &rapier3d_f64::prelude::IntegrationParameters,
) -> Option<f64> {
    let (v, w) = (rb.linvel(), rb.angvel());
    let bad = !rb.is_enabled() || !rb.translation().is_finite() || !v.is_finite() || !w.is_finite();
    (bad || v.length() > 0.5 * params.max_linear_velocity()).then(|| v.length())
}
