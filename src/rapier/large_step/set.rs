//! [`LargeStepJointSet`]: the large-step joints of a world behind generational handles, the
//! hooks around each Rapier step and their part in the step protocol.

use super::*;
use crate::rapier::pipeline::element_set::{ElementHandle, ElementSet};
use crate::rapier::pipeline::step_hooks::{RapierStepContext, StepHooks};
/// Handle of a joint in a [`LargeStepJointSet`], returned by its
/// [`insert`](LargeStepJointSet::insert): generational, as Rapier's `ImpulseJointHandle`
/// ([`ElementHandle`]).
pub type LargeStepJointHandle = ElementHandle<LargeStepJoint>;

/// All large-step clearance joints of a world, and the per-step hooks.
///
/// Call [`before_step`](Self::before_step) before every `PhysicsPipeline::step` and
/// [`after_step`](Self::after_step) after it. The set manages the `additional_solver_iterations`
/// of its joints' dynamic bodies (see the [module](super) docs): it never sets them below the value
/// a body had when its first joint was inserted, and restores that value when the body's last
/// joint is removed. Joints that share a dynamic body share one substep count (Rapier substeps a
/// connected component together); the force readout assumes no other body in that component asks
/// for more. The joints are visited ([`iter`](ElementSet::iter), the hooks) in insertion order.
#[derive(Clone, Debug, Default)]
pub struct LargeStepJointSet {
    joints: ElementSet<LargeStepJoint>,
    /// `additional_solver_iterations` of each managed body before the set touched it.
    base_extra: BTreeMap<(u32, u32), usize>,
    /// Group of each joint, in the joints' order (joints sharing a dynamic body), rebuilt after
    /// insertions and removals.
    groups: Vec<usize>,
    groups_valid: bool,
    /// Per-step scratch: what each joint needs, and each group's largest count.
    needs: Vec<Need>,
    group_max: Vec<usize>,
    /// The joints' states before a step the stepper may reject.
    saved: Vec<(JointState, LargeStepReport)>,
}

/// What one joint asks of the coming step.
#[derive(Clone, Copy, Debug, Default)]
struct Need {
    substeps: usize,
    needed: f64,
    rocking: f64,
    relative_velocity: Vector,
}

impl LargeStepJointSet {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `joint` between `body1` (bearing) and `body2` (journal) of `bodies`, and its Rapier
    /// joint to `impulse_joints`. Refused, naming `body1` or `body2`, unless both are in `bodies`
    /// and not the same body; nothing is added then.
    pub fn insert(
        &mut self,
        body1: RigidBodyHandle,
        body2: RigidBodyHandle,
        joint: LargeStepJoint,
        bodies: &RigidBodySet,
        impulse_joints: &mut ImpulseJointSet,
    ) -> Result<LargeStepJointHandle> {
        crate::rapier::pipeline::step_hooks::joint_pair(bodies, body1, body2)?;
        Ok(self.insert_unchecked(body1, body2, joint, impulse_joints))
    }

    /// [`insert`](Self::insert) between bodies known to be in the world and two (a Rapier
    /// joint's, which Rapier removes with its bodies).
    pub(crate) fn insert_unchecked(
        &mut self,
        body1: RigidBodyHandle,
        body2: RigidBodyHandle,
        mut joint: LargeStepJoint,
        impulse_joints: &mut ImpulseJointSet,
    ) -> LargeStepJointHandle {
        joint.body1 = body1;
        joint.body2 = body2;
        joint.state = JointState::default();
        joint.report = LargeStepReport::default();
        joint.handle = Some(impulse_joints.insert(body1, body2, joint.rapier_joint(), true));
        self.groups_valid = false;
        self.joints.insert(joint)
    }

    /// Removes the joint (and its Rapier joint) and returns it (`None` for a handle of no joint
    /// of this set). Bodies no other joint of the set uses get their
    /// `additional_solver_iterations` back. The other joints keep their handles and their order;
    /// `handle` finds nothing ever after.
    pub fn remove(
        &mut self,
        handle: LargeStepJointHandle,
        bodies: &mut RigidBodySet,
        impulse_joints: &mut ImpulseJointSet,
    ) -> Option<LargeStepJoint> {
        let mut joint = self.joints.remove(handle)?;
        self.groups_valid = false;
        // A saved state is by position: it no longer matches the joints.
        self.saved.clear();
        if let Some(h) = joint.handle.take() {
            impulse_joints.remove(h, true);
        }
        for body in [joint.body1, joint.body2] {
            let used = self.iter().any(|(_, j)| j.body1 == body || j.body2 == body);
            if !used
                && let Some(base) = self.base_extra.remove(&body.into_raw_parts())
                && let Some(rb) = bodies.get_mut(body)
                && rb.additional_solver_iterations() != base
            {
                rb.set_additional_solver_iterations(base);
            }
        }
        Some(joint)
    }

    /// The joint behind `handle`, mutably (`None` once it was removed); raises the
    /// [`revision`](ElementSet::revision).
    pub fn get_mut(&mut self, handle: LargeStepJointHandle) -> Option<&mut LargeStepJoint> {
        self.joints.get_mut(handle)
    }

    /// Prepares the coming step (call right before `PhysicsPipeline::step`, after setting `dt`):
    /// chooses the substeps each group of joints needs, sets the friction motors' largest torque
    /// from the last normal force, and records the velocities the restitution needs.
    pub fn before_step(
        &mut self,
        bodies: &mut RigidBodySet,
        impulse_joints: &mut ImpulseJointSet,
        params: &IntegrationParameters,
    ) {
        let base = params.num_solver_iterations.max(1);
        let dt = params.dt;
        // 1. What each joint needs.
        self.needs.clear();
        self.needs.resize(self.joints.len(), Need::default());
        for (i, joint) in self.joints.values_mut().enumerate() {
            if !joint.state.prepared {
                ensure_mass_properties(bodies, None, joint.body1);
                ensure_mass_properties(bodies, None, joint.body2);
                for (k, body) in [joint.body1, joint.body2].into_iter().enumerate() {
                    if let Some(rb) = bodies.get(body) {
                        joint.state.floors[k] = *self
                            .base_extra
                            .entry(body.into_raw_parts())
                            .or_insert(rb.additional_solver_iterations());
                    }
                }
                joint.state.prepared = true;
            }
            let (Some(rb1), Some(rb2)) = (bodies.get(joint.body1), bodies.get(joint.body2)) else {
                continue;
            };
            let (needed, rocking, relative_velocity) = joint.needs(rb1, rb2, dt);
            let target = quantized_substeps(needed, base, joint.max_substeps);
            let s = &mut joint.state;
            // Rise at once; fall only after the lower count has sufficed for a while.
            if target >= s.substeps || s.substeps < base {
                s.substeps = target;
                s.low_steps = 0;
            } else {
                s.low_steps += 1;
                if s.low_steps >= SUBSTEP_HOLD_STEPS {
                    s.substeps = target;
                    s.low_steps = 0;
                }
            }
            self.needs[i] = Need {
                substeps: s.substeps,
                needed,
                rocking,
                relative_velocity,
            };
        }
        // 2. Joints sharing a dynamic body are substepped together: one count per group.
        if !self.groups_valid {
            self.groups = self.groups(bodies);
            self.groups_valid = true;
        }
        self.group_max.clear();
        self.group_max.resize(self.joints.len(), 0);
        for (need, &g) in self.needs.iter().zip(&self.groups) {
            self.group_max[g] = self.group_max[g].max(need.substeps);
        }
        for (joint, &g) in self.joints.values().zip(&self.groups) {
            let extra = self.group_max[g].saturating_sub(base);
            for (body, floor) in [joint.body1, joint.body2]
                .into_iter()
                .zip(joint.state.floors)
            {
                if let Some(rb) = bodies.get(body)
                    && rb.is_dynamic()
                    && rb.additional_solver_iterations() != extra.max(floor)
                    && let Some(rb) = bodies.get_mut(body)
                {
                    rb.set_additional_solver_iterations(extra.max(floor));
                }
            }
        }
        // 3. Friction motors and the pre-step record.
        for (i, joint) in self.joints.values_mut().enumerate() {
            let (Some(rb1), Some(rb2)) = (bodies.get(joint.body1), bodies.get(joint.body2)) else {
                continue;
            };
            let extra = rb1
                .additional_solver_iterations()
                .max(rb2.additional_solver_iterations());
            let load = if joint.state.last_onset {
                0.0
            } else {
                joint.state.normal_force
            };
            let friction_limit = joint.friction * load * joint.geometry.journal_radius();
            let need = self.needs[i];
            let relative_velocity = need.relative_velocity;
            let axis = *rb1.rotation() * joint.local_axis1;
            joint.state.last_relative_velocity =
                Some(relative_velocity - relative_velocity.dot(axis) * axis);
            joint.state.pre = Some(PreStep {
                relative_velocity,
                dt,
                substeps: base + extra,
                friction_limit,
                substeps_needed: need.needed,
                rocking_frequency: need.rocking,
            });
            if joint.friction > 0.0
                && let Some(h) = joint.handle
            {
                let current = impulse_joints
                    .get(h)
                    .map(|ij| ij.data.motors[JointAxis::AngX as usize].max_force);
                if current.is_some_and(|m| m != friction_limit)
                    && let Some(ij) = impulse_joints.get_mut(h, false)
                {
                    ij.data.set_motor_max_force(JointAxis::AngX, friction_limit);
                }
            }
        }
    }

    /// Finishes the step just taken (call right after `PhysicsPipeline::step`): reads the normal
    /// force and friction torque, updates the reports, and gives each impact its bounce.
    pub fn after_step(&mut self, bodies: &mut RigidBodySet, impulse_joints: &ImpulseJointSet) {
        for joint in self.joints.values_mut() {
            joint.finish(bodies, impulse_joints);
        }
    }

    /// Appends to `out` the forces the joints' constraints exerted over the last step, as
    /// wrenches on both bodies (the normal force at the journal centre and the friction moment,
    /// from the [`report`](LargeStepJoint::report)s): what an exact reaction solve
    /// ([`ReactionSolver`](crate::rapier::observers::reaction::ReactionSolver)) must be given to know the
    /// joints, which are no ideal joints. Not the step protocol's
    /// [`wrenches`](crate::rapier::pipeline::step_hooks::StepHooks::wrenches): Rapier's solver applies these
    /// forces itself.
    pub(crate) fn constraint_wrenches(&self, bodies: &RigidBodySet, out: &mut Vec<Wrench>) {
        for j in self.joints.values() {
            let (Some(rb1), Some(rb2)) = (bodies.get(j.body1), bodies.get(j.body2)) else {
                continue;
            };
            let r = &j.report;
            let axis = *rb1.rotation() * j.local_axis1;
            let p2 = *rb2.position() * j.local_anchor2;
            let f = r.force_on_journal;
            let moment = r.friction_torque * axis;
            out.push(Wrench {
                body: j.body1,
                force: -f,
                torque: (p2 - world_center_of_mass(rb1)).cross(-f) - moment,
            });
            out.push(Wrench {
                body: j.body2,
                force: f,
                torque: (p2 - world_center_of_mass(rb2)).cross(f) + moment,
            });
        }
    }

    /// Group index of each joint, in the joints' order: joints sharing a dynamic body are in the
    /// same group.
    fn groups(&self, bodies: &RigidBodySet) -> Vec<usize> {
        let n = self.joints.len();
        let mut parent: Vec<usize> = (0..n).collect();
        fn find(parent: &mut [usize], mut i: usize) -> usize {
            while parent[i] != i {
                parent[i] = parent[parent[i]];
                i = parent[i];
            }
            i
        }
        let mut owner: BTreeMap<(u32, u32), usize> = BTreeMap::new();
        for (i, j) in self.joints.values().enumerate() {
            for body in [j.body1, j.body2] {
                if !bodies.get(body).is_some_and(|rb| rb.is_dynamic()) {
                    continue;
                }
                match owner.get(&body.into_raw_parts()) {
                    Some(&k) => {
                        let (a, b) = (find(&mut parent, i), find(&mut parent, k));
                        parent[a] = b;
                    }
                    None => {
                        owner.insert(body.into_raw_parts(), i);
                    }
                }
            }
        }
        (0..n).map(|i| find(&mut parent, i)).collect()
    }
}

/// The large-step joints take part in the stepper's steps: their substeps and friction motors
/// before each Rapier step, their readout and bounces after it, saved and restored with a
/// rejected step ([`crate::rapier::pipeline::step_hooks`]). Under a
/// [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld) no hook can be forgotten.
/// Reading the set is reading its [`ElementSet`]: [`get`](ElementSet::get),
/// [`contains`](ElementSet::contains), [`iter`](ElementSet::iter) (insertion order),
/// [`len`](ElementSet::len), [`revision`](ElementSet::revision). Adding and removing go through
/// the set's own methods, which also keep the Rapier side and the forces in step.
impl std::ops::Deref for LargeStepJointSet {
    type Target = ElementSet<LargeStepJoint>;

    fn deref(&self) -> &Self::Target {
        &self.joints
    }
}

impl StepHooks for LargeStepJointSet {
    fn save_state(&mut self) {
        self.joints
            .save_into(&mut self.saved, |j| (j.state, j.report));
    }
    fn restore_state(&mut self) {
        self.joints.restore_from(&self.saved, |j, (state, report)| {
            j.state = *state;
            j.report = *report;
        });
    }
    fn before_rapier_step(&mut self, context: RapierStepContext<'_>) {
        let world = context.world;
        self.before_step(
            &mut world.bodies,
            &mut world.impulse_joints,
            &world.integration_parameters,
        );
    }
    fn after_rapier_step(&mut self, context: RapierStepContext<'_>) {
        let world = context.world;
        self.after_step(&mut world.bodies, &world.impulse_joints);
    }
    fn joints_of(&self, body: RigidBodyHandle, names: &mut Vec<String>) {
        for (_, j) in self.iter() {
            if j.body1() == body || j.body2() == body {
                names.push(format!("large-step clearance joint `{}`", j.name()));
            }
        }
    }
    fn check_bodies(&self, bodies: &rapier3d_f64::prelude::RigidBodySet) -> crate::Result<()> {
        for (_, j) in self.iter() {
            crate::rapier::pipeline::step_hooks::joint_bodies(
                bodies,
                || format!("large-step clearance joint `{}`", j.name()),
                j.body1(),
                j.body2(),
            )?;
        }
        Ok(())
    }
}
