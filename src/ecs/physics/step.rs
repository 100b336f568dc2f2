//! The [`Physics`] resource's step: the forces at the state, one accepted step with the user's
//! hooks, and the hinges' forces the step held.

use super::{HingeJoint, Physics};
use crate::error::{Divergence, Error, Result};
use crate::rapier::observers::reaction::{IdealJoint, IdealRevolute, JointModel};
use crate::rapier::pipeline::stepper::{StepHooks, StepMode};
use crate::rapier::pipeline::world::ClearanceWorld;
use bevy_ecs::prelude::Entity;
use std::collections::BTreeMap;

impl Physics {
    /// Evaluates the joints and drives at the current state when the stepper needs it (see
    /// [`apply_forces`](crate::ecs::apply_forces)).
    pub(in crate::ecs) fn prepare_forces(&mut self, user: &mut dyn StepHooks) -> Result<()> {
        if std::mem::take(&mut self.changed) {
            self.world.invalidate(false);
        }
        follow_dt(&mut self.world);
        self.world.prepare_with(user)
    }

    /// One accepted step of the world's step control, at most `integration_parameters.dt` long
    /// (and ending at most at the frame's end under [`run_frame`](crate::ecs::run_frame)).
    pub(in crate::ecs) fn step(&mut self, user: &mut dyn StepHooks) -> Result<()> {
        let dt = self.world.rapier.integration_parameters.dt;
        follow_dt(&mut self.world);
        // The forces the step holds are those at its start (evaluated by `apply_forces`): read
        // them before it.
        self.start_forces = self.hinge_forces_now()?;
        let until = (self.world.time() + dt).min(self.frame_end.unwrap_or(f64::INFINITY));
        let result = self.world.step_with(until, user);
        // Rapier's `dt` as the user set it (the stepper sets it per step).
        self.world.rapier.integration_parameters.dt = dt;
        result.map(|_| ()).map_err(|e| {
            e.named(
                "Physics::world.rapier.integration_parameters.dt",
                crate::error::ParameterNames {
                    adaptive: "Physics::set_step_control(StepControl::adaptive(..))".into(),
                    contact: Vec::new(),
                },
            )
        })
    }

    /// Whether a step begins a new frame (and clears it).
    pub(in crate::ecs) fn take_new_frame(&mut self) -> bool {
        std::mem::take(&mut self.new_frame)
    }

    /// Sets the end of the frame being run (`None`: no end).
    pub(in crate::ecs) fn set_frame_end(&mut self, end: Option<f64>) {
        self.frame_end = end;
    }

    /// The force each hinge held over the step just taken (its force at the step's start), N.
    pub(in crate::ecs) fn start_force(&self, entity: Entity) -> f64 {
        self.start_forces.get(&entity).copied().unwrap_or(0.0)
    }

    /// Each compliant and ideal hinge's force at the current state, N (a large-step hinge's
    /// readout is its step's own). The ideal reactions are the last record's when it saw this
    /// state; solved here otherwise.
    fn hinge_forces_now(&mut self) -> Result<BTreeMap<Entity, f64>> {
        let ideal_missing = self.hinges.iter().any(|(e, r)| {
            matches!(r.joint, HingeJoint::Ideal(_)) && !self.ideal_cache.1.contains_key(e)
        });
        if self.ideal_cache.0 != self.world.steps() || ideal_missing {
            self.ideal_forces()?;
        }
        let mut forces = self.ideal_cache.1.clone();
        for (e, r) in &self.hinges {
            if let HingeJoint::Clearance(h) = r.joint
                && let Some(j) = self.world.clearance.get(h)
            {
                forces.insert(*e, j.report().force.on_journal.length());
            }
        }
        Ok(forces)
    }

    /// The ideal hinges' reaction magnitudes, N, by entity, at the current state
    /// ([`ClearanceWorld::solve_reactions`], the runner's piece), kept for the next step's
    /// start. A solve that fails (a non-finite state or mass) is an error, never a zero force.
    pub(in crate::ecs) fn ideal_forces(&mut self) -> Result<BTreeMap<Entity, f64>> {
        self.ideal_joints.clear();
        let mut ideal_entities = Vec::new();
        for (e, r) in &self.hinges {
            if let HingeJoint::Ideal(_) = r.joint {
                self.ideal_joints
                    .push(IdealJoint(JointModel::Revolute(IdealRevolute {
                        body1: r.bodies.0,
                        body2: r.bodies.1,
                        local_anchor1: r.frame.local_anchor1,
                        local_anchor2: r.frame.local_anchor2,
                        local_axis1: r.frame.unit_axis1(),
                    })));
                ideal_entities.push(*e);
            }
        }
        let t = self.world.time();
        let forces: BTreeMap<Entity, f64> = self
            .world
            .solve_reactions(&mut self.reactions, &self.ideal_joints)
            .map(|f| {
                ideal_entities
                    .iter()
                    .zip(f)
                    .map(|(e, f)| (*e, f.length()))
                    .collect()
            })
            .ok_or_else(|| Error::diverged(t, Divergence::Reactions { twin: None }))?;
        self.ideal_cache = (self.world.steps(), forces.clone());
        Ok(forces)
    }
}

/// Fixed steps follow `integration_parameters.dt` as the user sets it, between any two steps.
fn follow_dt(world: &mut ClearanceWorld) {
    if world.step_control.mode == StepMode::Fixed {
        world.step_control.max_dt = world.rapier.integration_parameters.dt;
    }
}
