//! The systems of a physics step, in [`PhysicsSet`](super::PhysicsSet) order: components to
//! Rapier ([`sync_bodies`], [`sync_hinges`]), the forces and the step ([`apply_forces`],
//! [`step_physics`]: the [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld)'s, which runs
//! every joint set's hooks, the large-step joints' included), and Rapier back to the components
//! ([`record`]). Each does nothing while [`Physics::error`] is set. Entities are
//! visited in order, so that Rapier sees the same calls in the same order on every run.

use super::components::{
    Body, BodyState, ClearanceHinge, Drive, Hinge, HingeMode, HingeState, IdealHinge,
};
use super::physics::{HingeJoint, Physics};
use crate::error::Error;
use crate::model::kinematics::ContactMode;
use crate::rapier::pipeline::step_hooks::StepHooks;
use bevy_ecs::prelude::*;
use rapier3d_f64::math::Vector;
use std::collections::BTreeSet;

/// Inserts new [`Body`] components into Rapier and removes the bodies of removed ones.
pub fn sync_bodies(mut physics: ResMut<Physics>, mut query: Query<(Entity, &mut Body)>) {
    if physics.error().is_some() {
        return;
    }
    let mut items: Vec<(Entity, Mut<Body>)> = query.iter_mut().collect();
    items.sort_by_key(|(e, _)| *e);
    let mut seen = BTreeSet::new();
    for (entity, mut body) in items {
        seen.insert(entity);
        if let Some(rb) = body.pending.take() {
            body.handle = Some(physics.insert_body(entity, *rb));
        } else if let Some(h) = body.handle
            && physics.body(entity) != Some(h)
            && let Err(e) = physics.adopt_body(entity, h)
        {
            physics.fail(e);
            return;
        }
    }
    physics.remove_bodies_except(&seen);
}

/// The hinge components whose addition or change makes [`sync_hinges`] reconcile.
type HingeChanges = Or<(
    Changed<Hinge>,
    Changed<IdealHinge>,
    Changed<ClearanceHinge>,
    Changed<Drive>,
)>;

/// Realises each [`Hinge`] as its mode component says (converting in place when only the mode
/// changed), its [`Drive`], and removes the joints and drives of removed components. It works
/// only in a step where something changed: a hinge component was added, changed or removed, a
/// body was inserted or removed, or an error stopped the systems; otherwise every hinge is as it
/// was.
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
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
    changed: Query<(), HingeChanges>,
    mut removed_hinges: RemovedComponents<Hinge>,
    mut removed_ideal: RemovedComponents<IdealHinge>,
    mut removed_clearance: RemovedComponents<ClearanceHinge>,
    mut removed_drives: RemovedComponents<Drive>,
) {
    // Read every removal, so that none is seen again at the next step.
    let removals = removed_hinges.read().count()
        + removed_ideal.read().count()
        + removed_clearance.read().count()
        + removed_drives.read().count();
    if physics.error().is_some() {
        return;
    }
    let stale = physics.take_hinges_stale();
    if !stale && removals == 0 && changed.is_empty() {
        return;
    }
    #[cfg(test)]
    {
        physics.hinge_passes += 1;
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
        let reconciled = physics
            .reconcile_hinge(entity, frame, desired, bodies)
            .and_then(|()| physics.reconcile_drive(entity, frame, drive, bodies));
        if let Err(e) = reconciled {
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
            let w = &physics.world.rapier.bodies;
            if let (Some(r1), Some(r2)) = (w.get(bodies.0), w.get(bodies.1)) {
                state
                    .angle_tracker
                    .set_reference(r1.rotation(), r2.rotation());
            }
        }
    }
    physics.remove_hinges_except(&seen);
}

/// Your own participant in the physics steps (a resource; optional): a force source of your
/// own, or anything else that implements [`StepHooks`], stepped by [`apply_forces`] and
/// [`step_physics`] after the world's own joints and drives, as
/// [`ClearanceWorld::step_with`](crate::rapier::pipeline::world::ClearanceWorld::step_with)
/// steps it. Several sources go in one type of your own (a tuple struct that forwards).
#[derive(Resource)]
pub struct UserHooks(pub Box<dyn StepHooks + Send + Sync>);

impl UserHooks {
    /// Boxes `hooks`.
    pub fn new(hooks: impl StepHooks + Send + Sync + 'static) -> Self {
        UserHooks(Box::new(hooks))
    }
}

/// Evaluates the force sources (torsion springs, the clearance force hook) at the current state
/// when the stepper needs it: before the first step and after the sync systems changed
/// something. Otherwise the stepper already evaluated them at the end of the last step.
pub fn apply_forces(mut physics: ResMut<Physics>, user: Option<ResMut<UserHooks>>) {
    if physics.error().is_some() {
        return;
    }
    let mut none = ();
    let user: &mut dyn StepHooks = match user {
        Some(hooks) => hooks.into_inner().0.as_mut(),
        None => &mut none,
    };
    if let Err(e) = physics.prepare_forces(user) {
        physics.fail(e);
    }
}

/// One accepted step of the [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld) (fixed steps
/// of `world.rapier.integration_parameters.dt` unless [`Physics::set_step_control`] chose otherwise):
/// variable-step consistent kicks, step acceptance, guards. An error stops the systems where the
/// state was last valid.
pub fn step_physics(mut physics: ResMut<Physics>, user: Option<ResMut<UserHooks>>) {
    if physics.error().is_some() {
        return;
    }
    let mut none = ();
    let user: &mut dyn StepHooks = match user {
        Some(hooks) => hooks.into_inner().0.as_mut(),
        None => &mut none,
    };
    if let Err(e) = physics.step(user) {
        physics.fail(e);
    }
}

/// Copies the state of the step into [`HingeState`] and [`BodyState`], and adds the step to
/// each hinge's frame figures.
pub fn record(
    mut physics: ResMut<Physics>,
    mut hinges: Query<(Entity, &Hinge, &mut HingeState)>,
    mut bodies: Query<(&Body, &mut BodyState)>,
) {
    if physics.error().is_some() {
        return;
    }
    let ideal_forces = match physics.ideal_forces() {
        Ok(f) => f,
        Err(e) => {
            physics.fail(e);
            return;
        }
    };
    let new_frame = physics.take_new_frame();
    let physics = &*physics;
    let h = physics.world.last_dt();
    let w = &physics.world.rapier;
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
        let Some((joint, (b1, b2))) = physics.realized_hinge(entity) else {
            continue;
        };
        let (Some(rb1), Some(rb2)) = (w.bodies.get(b1), w.bodies.get(b2)) else {
            continue;
        };
        let axis1 = frame.unit_axis1();
        state.angle = state
            .angle_tracker
            .update(rb1.rotation(), rb2.rotation(), axis1);
        state.rate = (rb2.angvel() - rb1.angvel()).dot(*rb1.rotation() * axis1);
        // The impulse the step carried beyond its force times `h` (a large-step bounce's).
        let mut extra_impulse = 0.0;
        // A sub-cycled contact's largest force inside the step.
        let mut inside_peak: f64 = 0.0;
        match joint {
            HingeJoint::Ideal(_) => {
                state.force = ideal_forces.get(&entity).copied().unwrap_or(0.0);
                state.penetration = 0.0;
                state.eccentricity = Vector::ZERO;
                state.eccentricity_ratio = 0.0;
                state.contact = ContactMode::FreeFlight;
                (state.impulse, state.substeps, state.under_resolved) = (0.0, 0, false);
                state.spatial = None;
            }
            HingeJoint::Clearance(c) => {
                if let Some(j) = physics.clearance().get(c) {
                    let rep = j.report();
                    state.force = rep.force.on_journal.length();
                    state.penetration = rep.state.penetration;
                    state.eccentricity = rep.state.eccentricity;
                    state.eccentricity_ratio =
                        rep.state.eccentricity.length() / j.geometry().clearance();
                    state.contact = rep.mode;
                    state.spatial = rep.spatial;
                    (state.impulse, state.substeps, state.under_resolved) = (0.0, 0, false);
                    match j.step_impulse() {
                        // Sub-cycled: the contacts inside the step, from its sub-steps.
                        Some(impulse) => {
                            let inside = j.substeps();
                            state.substeps = inside.len();
                            state.onsets += inside.iter().filter(|s| s.onset).count() as u64;
                            state.impacts += inside.iter().filter(|s| s.impact).count() as u64;
                            let peak = inside
                                .iter()
                                .map(|s| s.force.on_journal.length())
                                .fold(0.0, f64::max);
                            inside_peak = peak;
                            extra_impulse = impulse.length() - physics.start_force(entity) * h;
                        }
                        None => {
                            state.onsets += u64::from(rep.onset);
                            state.impacts += u64::from(rep.impact);
                        }
                    }
                }
            }
            HingeJoint::LargeStep(k) => {
                if let Some(j) = physics.large_step().get(k) {
                    let rep = j.report();
                    state.force = rep.normal_force;
                    state.penetration = rep.eccentricity.length() - j.clearance();
                    state.eccentricity = rep.eccentricity;
                    state.eccentricity_ratio = rep.eccentricity_ratio;
                    state.impulse = rep.impact_impulse;
                    state.substeps = rep.substeps;
                    state.under_resolved = rep.under_resolved;
                    state.spatial = None;
                    state.contact = match (rep.contact, rep.onset) {
                        (false, _) => ContactMode::FreeFlight,
                        (true, true) => ContactMode::Impact,
                        (true, false) => ContactMode::Continuous,
                    };
                    state.onsets += u64::from(rep.onset);
                    state.impacts += u64::from(rep.bounce);
                    extra_impulse = rep.impact_impulse;
                }
            }
        }
        state.peak_force = state.peak_force.max(state.force).max(inside_peak);
        // The force the step held: the state's at its start; a large-step hinge's readout is
        // its step's own.
        let start = match joint {
            HingeJoint::LargeStep(_) => state.force,
            _ => physics.start_force(entity),
        };
        let force = state.force;
        state.add_step(
            new_frame,
            h,
            start * h + extra_impulse,
            start,
            force.max(inside_peak),
        );
    }
}
