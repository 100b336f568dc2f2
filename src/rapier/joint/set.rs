//! [`ClearanceJointSet`]: the compliant joints of a world behind generational handles, their
//! per-step force hook and their part in the step protocol.

use super::*;
use crate::rapier::pipeline::element_set::{ElementHandle, ElementSet};
use crate::rapier::pipeline::protocol::{GuardKind, GuardReport, StalledContact, Violation};
use crate::rapier::pipeline::step_hooks::{EvaluateContext, StepContext, StepHooks, StepPass};
/// Handle of a joint in a [`ClearanceJointSet`], returned by its
/// [`insert`](ClearanceJointSet::insert): generational, as Rapier's `ImpulseJointHandle`
/// ([`ElementHandle`]).
pub type ClearanceJointHandle = ElementHandle<ClearanceJoint>;

/// All clearance joints of a world, and the per-step force hook. The joints are visited (their
/// forces evaluated and added, [`iter`](ElementSet::iter)) in insertion order.
#[derive(Clone, Debug, Default)]
pub struct ClearanceJointSet {
    joints: ElementSet<ClearanceJoint>,
    ledger: ForceLedger,
    /// The forces at the state (every joint's).
    wrenches: Vec<Wrench>,
    /// The forces the stepper applies over the next step: the explicit joints', and in the
    /// step's pass 1 the sub-cycled joints' deliveries.
    applied: Vec<Wrench>,
    /// The sub-cycled joints' deliveries of the step being taken, and whether its pass 1 is on.
    planned: Vec<Wrench>,
    retaking: bool,
    /// Scratch: each joint's bearing and journal bodies when it is sub-cycled.
    partners: Vec<Option<[RigidBodyHandle; 2]>>,
    saved: Vec<JointDynamics>,
    saved_wrenches: Vec<Wrench>,
    saved_applied: Vec<Wrench>,
    /// The step that led to the bodies' state, for the next evaluation, s.
    last_step: f64,
    /// Scratch: the mechanism around the joint being evaluated.
    mechanism: Mechanism,
}

impl ClearanceJointSet {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `joint` between `body1` (bearing) and `body2` (journal) of `bodies`. With
    /// [`OutOfPlaneLock::Joint`] it also inserts into `impulse_joints` the Rapier joint that locks
    /// the axial translation and the two tilts. Refused, naming `body1` or `body2`, unless both
    /// are in `bodies` and not the same body, and naming `local_axis2` when a spatial joint's
    /// journal does not lie in its bore; nothing is added then.
    pub fn insert(
        &mut self,
        body1: RigidBodyHandle,
        body2: RigidBodyHandle,
        joint: ClearanceJoint,
        bodies: &RigidBodySet,
        impulse_joints: &mut ImpulseJointSet,
    ) -> Result<ClearanceJointHandle> {
        crate::rapier::pipeline::step_hooks::joint_pair(bodies, body1, body2)?;
        joint.check_start(&bodies[body1], &bodies[body2])?;
        Ok(self.insert_unchecked(body1, body2, joint, impulse_joints))
    }

    /// [`insert`](Self::insert) between bodies known to be in the world and two (a Rapier
    /// joint's, which Rapier removes with its bodies).
    pub(crate) fn insert_unchecked(
        &mut self,
        body1: RigidBodyHandle,
        body2: RigidBodyHandle,
        mut joint: ClearanceJoint,
        impulse_joints: &mut ImpulseJointSet,
    ) -> ClearanceJointHandle {
        joint.body1 = body1;
        joint.body2 = body2;
        if joint.lock == OutOfPlaneLock::Joint {
            let lock = GenericJointBuilder::new(
                JointAxesMask::LIN_X | JointAxesMask::ANG_Y | JointAxesMask::ANG_Z,
            )
            .local_axis1(joint.local_axis1)
            .local_axis2(joint.local_axis2)
            .local_anchor1(joint.local_anchor1)
            .local_anchor2(joint.local_anchor2)
            .contacts_enabled(false)
            .build();
            joint.lock_handle = Some(impulse_joints.insert(body1, body2, lock, true));
        }
        self.joints.insert(joint)
    }

    /// Removes the joint's forces from its bodies (and its lock joint from `impulse_joints`) and
    /// returns it (`None` for a handle of no joint of this set). The other joints keep their
    /// handles and their order; `handle` finds nothing ever after.
    pub fn remove(
        &mut self,
        handle: ClearanceJointHandle,
        bodies: &mut RigidBodySet,
        impulse_joints: &mut ImpulseJointSet,
    ) -> Option<ClearanceJoint> {
        let mut joint = self.joints.remove(handle)?;
        if let Some(lock) = joint.lock_handle.take() {
            impulse_joints.remove(lock, true);
        }
        // A saved state is by position: it no longer matches the joints.
        self.saved.clear();
        // Take back the removed joint's last forces only: the others' stay as last applied.
        self.wrenches.clear();
        self.wrenches.extend(
            self.joints
                .values()
                .filter_map(|j| j.last_wrenches)
                .flatten(),
        );
        self.applied.clear();
        self.applied.extend(
            self.joints
                .values()
                .filter(|j| !j.sub_cycled())
                .filter_map(|j| j.last_wrenches)
                .flatten(),
        );
        self.ledger.replace(bodies, self.wrenches.iter().copied());
        Some(joint)
    }

    /// The joint behind `handle`, mutably (`None` once it was removed); raises the
    /// [`revision`](ElementSet::revision).
    pub fn get_mut(&mut self, handle: ClearanceJointHandle) -> Option<&mut ClearanceJoint> {
        self.joints.get_mut(handle)
    }

    /// The force hook: call before every `PhysicsPipeline::step`. It evaluates every joint from
    /// the bodies' current poses and velocities and replaces the forces it applied at the
    /// previous call with the new contact and friction forces (your own user forces are left
    /// alone). The forces are held over your step: every joint is integrated explicitly here, a
    /// sub-cycled one ([`ContactIntegration::SubCycled`], the default) too, with the explicit
    /// joint's checks below (its sub-cycle needs the two passes of the
    /// [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld)'s step).
    ///
    /// Errors (after applying the forces):
    /// - `num_solver_iterations` is not 1: Rapier's substeps hold the hook's force constant
    ///   across substeps and the scheme then gains energy at every impact.
    /// - [`Error::StepTooLarge`]: `dt` exceeds the stability limit of a contact as linearised now.
    pub fn apply(
        &mut self,
        bodies: &mut RigidBodySet,
        impulse_joints: &ImpulseJointSet,
        params: &IntegrationParameters,
    ) -> Result<()> {
        self.apply_forces(bodies, impulse_joints);
        // The step about to be taken is the one the next call's state comes from.
        self.set_last_step(params.dt);
        self.check_substeps(params)?;
        self.check_step(params.dt)
    }

    /// Sets the length of the step that led to the bodies' current state, s, for the next
    /// [`evaluate`](StepHooks::evaluate) or [`apply_forces`](Self::apply_forces).
    ///
    /// Rapier's velocities after a step are the mean over it (a Verlet step), half a step behind
    /// the state; a contact's damping read from them is wrong by a first-order error in the step
    /// (every contact peak then converges at first order). Knowing the step, the joints carry the
    /// penetration rate to the state ([`ClearanceReport::contact_rate`]). [`apply`](Self::apply)
    /// sets it to `params.dt` itself, and the
    /// [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld) to each step it takes; call it yourself only
    /// when you call `evaluate` or `apply_forces` in your own loop. 0 (the default, and the value
    /// for velocities that are the state's own: at the start, or after you set them by hand)
    /// gives the laws the stored rate. A negative or non-finite `dt` counts as 0.
    pub fn set_last_step(&mut self, dt: f64) {
        self.last_step = if dt > 0.0 && dt.is_finite() { dt } else { 0.0 };
    }

    /// The force evaluation of [`apply`](Self::apply) without its checks, for callers that choose
    /// the step after seeing the contact state (adaptive stepping) and then check it themselves
    /// ([`StepHooks::check_step`]).
    pub fn apply_forces(&mut self, bodies: &mut RigidBodySet, impulse_joints: &ImpulseJointSet) {
        // The loop holds these forces over its step: every joint is explicit here, checks and
        // step bounds included, a sub-cycled one too (no sub-cycle runs, and none is pending).
        for joint in self.joints.values_mut() {
            joint.plain_loop = true;
            joint.cycle.pending = None;
        }
        self.evaluate(bodies, impulse_joints);
        self.ledger.replace(bodies, self.wrenches.iter().copied());
    }

    /// Evaluates every joint at the bodies' current state (contact history, report, the
    /// wrenches of [`wrenches`](Self::wrenches)) without touching the bodies' forces: the
    /// [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld) adds the wrenches for the duration of its step only,
    /// so the bodies carry nothing but the user's own forces between steps. A joint whose body is
    /// gone reports free flight and applies nothing.
    ///
    /// `impulse_joints` are the world's Rapier joints: the contact's effective mass is taken
    /// through the ideal joints that hold its bodies (an arm's pivot, a slider's guide), which
    /// set how hard a journal strikes its wall (the laws' damping, the step bounds).
    pub(crate) fn evaluate(&mut self, bodies: &mut RigidBodySet, impulse_joints: &ImpulseJointSet) {
        self.wrenches.clear();
        self.applied.clear();
        self.retaking = false;
        self.partners.clear();
        self.partners.extend(
            self.joints
                .values()
                .map(|j| j.sub_cycled().then_some([j.body1, j.body2])),
        );
        for (index, joint) in self.joints.values_mut().enumerate() {
            if !joint.prepared {
                ensure_mass_properties(bodies, None, joint.body1);
                ensure_mass_properties(bodies, None, joint.body2);
                joint.prepared = true;
            }
            self.mechanism
                .rebuild(bodies, impulse_joints, joint.body1, joint.body2);
            let finished = if joint.spatial.is_some() {
                joint.finish_spatial_cycle(bodies, &self.mechanism)
            } else {
                joint.finish_cycle(bodies)
            };
            // A re-evaluation between steps (the world's after `get_mut`, or `invalidate`
            // without a restarted kick) of a joint sub-cycled over the last step keeps what
            // that step left held: the impulse Rapier's velocities still lack.
            let carried =
                joint.sub_cycled() && !joint.cycle.explicit_before && self.last_step > 0.0;
            if finished.is_none() && !carried {
                // Explicit, or a sub-cycled joint's first evaluation (velocities its own).
                joint.cycle.held = [0.0; 12];
                joint.cycle.shift = [0.0; 12];
                joint.cycle.start_correction = [0.0; 12];
                joint.cycle.substep_count = 0;
                joint.cycle.substeps.clear();
            }
            let first = finished.is_none();
            joint.last_wrenches = finished
                .or_else(|| joint.evaluate(bodies, self.last_step, &self.mechanism))
                .map(|(w1, w2)| [w1, w2]);
            if first {
                joint.hold_explicit_half_kick(self.last_step);
            }
            joint.take_start(bodies, &self.mechanism);
            joint.take_spatial_start(bodies, &self.mechanism);
            let partners = self.partners.iter().enumerate();
            let others = partners
                .filter(|(i, _)| *i != index)
                .filter_map(|(_, p)| *p);
            joint.take_coupling(&self.mechanism, others);
            if joint.last_wrenches.is_none() {
                joint.contact = ContactHistory::default();
                joint.report = ClearanceReport::default();
                joint.elastic = OnceLock::new();
                joint.previous_rate = None;
                joint.moved_rate = None;
                if let Some(parts) = &mut joint.spatial {
                    parts.reset();
                }
            }
            self.wrenches
                .extend(joint.last_wrenches.into_iter().flatten());
            if !joint.sub_cycled() {
                self.applied
                    .extend(joint.last_wrenches.into_iter().flatten());
            }
        }
    }

    /// After Rapier's pass `pass.pass` of a step: at pass 0 the sub-cycled joints run their
    /// sub-cycles (the planar joints of one island together, `subcycle::plan_cycles`; the
    /// spatial joints of one island together, `spatial::subcycle::plan_spatial_cycles`) and
    /// the set asks for pass 1 with their deliveries when one has an impulse to deliver; later
    /// passes stand.
    pub(crate) fn resolve_step(
        &mut self,
        bodies: &RigidBodySet,
        pass: &StepPass,
        iterations: usize,
    ) -> bool {
        if pass.pass > 0 {
            self.retaking = false;
            return false;
        }
        self.planned.clear();
        let mut joints: Vec<&mut ClearanceJoint> = self.joints.values_mut().collect();
        // The planar joints of one island together, and the spatial joints of one island
        // together.
        let mut deliveries = subcycle::plan_cycles(&mut joints, bodies, pass, iterations);
        let spatial = spatial::subcycle::plan_spatial_cycles(&mut joints, bodies, pass, iterations);
        for (deliver, s) in deliveries.iter_mut().zip(spatial) {
            if s.is_some() {
                *deliver = s;
            }
        }
        for (joint, deliver) in joints.iter().zip(deliveries) {
            if let Some(deliver) = deliver {
                self.planned.extend(joint.delivery(&deliver, pass.kick));
            }
        }
        self.retaking = !self.planned.is_empty();
        if self.retaking {
            self.applied.extend_from_slice(&self.planned);
        }
        self.retaking
    }

    /// The force and torque on each body from the last evaluation (two per joint: bearing,
    /// journal).
    pub fn wrenches(&self) -> &[Wrench] {
        &self.wrenches
    }

    /// Refuses Rapier substeps (`num_solver_iterations != 1`) when the set holds joints that
    /// are not sub-cycled (a sub-cycled joint delivers its impulse through any number).
    pub(crate) fn check_substeps(&self, params: &IntegrationParameters) -> Result<()> {
        let explicit = self.joints.values().any(|j| !j.sub_cycled());
        if params.num_solver_iterations != 1 && explicit {
            return Err(Error::invalid(
                "num_solver_iterations",
                format!(
                    "is {}, but the compliant clearance joints of a ClearanceJointSet need 1: their \
                     contact force is evaluated once per step and held over it, and Rapier's \
                     substeps would make every impact gain energy. Set Rapier's \
                     `integration_parameters.num_solver_iterations = 1` (every body of the world \
                     then gets one iteration: stacks of resting bodies soften), sub-cycle the \
                     joints' contact (`HingeDesign::integration(ContactIntegration::SubCycled)`, \
                     the default, the same laws resolved inside each step with any number of \
                     iterations; it needs a ClearanceWorld's step: a loop of your own that calls \
                     `ClearanceJointSet::apply` holds the forces over the step, explicitly), or \
                     build the hinges with the large-step model, \
                     `HingeDesign::model(ClearanceModel::LargeStep)` into a LargeStepJointSet, which \
                     works with any number of iterations and steps as long as 1/60 s",
                    params.num_solver_iterations
                ),
            ));
        }
        Ok(())
    }

    /// Checks `dt` against every joint's current stability limit.
    pub(crate) fn check_step(&self, dt: f64) -> Result<()> {
        for j in self.joints.values() {
            if j.prepared && j.last_wrenches.is_none() {
                return Err(Error::invalid(
                    format!("clearance joint `{}`", j.name),
                    "its bearing or journal body is not in the body set (removed after the joint \
                     was inserted?): the joint has no state to check the step against",
                ));
            }
            let r = &j.report;
            if dt > r.max_stable_dt && !j.sub_cycled() {
                let (dt_max, depth, omega, zeta) = match j.impact_met(dt) {
                    Some(impact) => impact,
                    None => (r.max_stable_dt, r.state.penetration, r.omega, r.zeta),
                };
                return Err(Error::StepTooLarge(Box::new(StepLimit::new(
                    j.name.clone(),
                    dt,
                    dt_max,
                    depth * 1e6,
                    omega,
                    zeta,
                    j.normal_law.kind().stiff_parameter(zeta),
                ))));
            }
        }
        Ok(())
    }

    /// Saves every joint's contact history and report and its last wrenches (before a step that
    /// may be rejected; no allocation after the first call).
    pub(crate) fn save_state(&mut self) {
        self.saved
            .resize_with(self.joints.len(), JointDynamics::default);
        for (d, j) in self.saved.iter_mut().zip(self.joints.values()) {
            j.save_into(d);
        }
        self.saved_wrenches.clone_from(&self.wrenches);
        self.saved_applied.clone_from(&self.applied);
    }

    /// Restores what [`save_state`](Self::save_state) saved.
    pub(crate) fn restore_state(&mut self) {
        self.joints
            .restore_from(&self.saved, |j, d| j.set_dynamics(d));
        self.wrenches.clone_from(&self.saved_wrenches);
        self.applied.clone_from(&self.saved_applied);
        if self.retaking {
            // Taken again for pass 1: with the deliveries of pass 0.
            self.applied.extend_from_slice(&self.planned);
        } else {
            for j in self.joints.values_mut() {
                j.cycle.pending = None;
            }
        }
    }

    /// [`ClearanceJoint::judge_step`] over all joints, with their contact state saved by the last
    /// [`save_state`](Self::save_state): the shortest retry step asked for, if any.
    pub(crate) fn judge_step(&self, dt: f64, tolerance: f64) -> Option<f64> {
        self.joints
            .values()
            .enumerate()
            .filter_map(|(i, j)| {
                let was = self.saved.get(i).is_some_and(|d| d.contact.in_contact);
                j.judge_step(dt, tolerance, was)
            })
            .reduce(f64::min)
    }

    /// Smallest [`ClearanceJoint::adaptive_step`] over all joints (infinite without joints).
    pub(crate) fn adaptive_step(&self, tolerance: f64, last_dt: f64) -> f64 {
        self.joints
            .values()
            .map(|j| j.adaptive_step(tolerance, last_dt))
            .fold(f64::INFINITY, f64::min)
    }
}

/// The clearance joints take part in the stepper's steps: their contact forces, step limits,
/// acceptance and guards ([`crate::rapier::pipeline::step_hooks`]).
/// Reading the set is reading its [`ElementSet`]: [`get`](ElementSet::get),
/// [`contains`](ElementSet::contains), [`iter`](ElementSet::iter) (insertion order),
/// [`len`](ElementSet::len), [`revision`](ElementSet::revision). Adding and removing go through
/// the set's own methods, which also keep the Rapier side and the forces in step.
impl std::ops::Deref for ClearanceJointSet {
    type Target = ElementSet<ClearanceJoint>;

    fn deref(&self) -> &Self::Target {
        &self.joints
    }
}

impl StepHooks for ClearanceJointSet {
    fn evaluate(&mut self, context: EvaluateContext<'_>) {
        for joint in self.joints.values_mut() {
            joint.plain_loop = false;
        }
        self.set_last_step(context.last_step);
        ClearanceJointSet::evaluate(self, context.bodies, context.impulse_joints);
    }
    /// What the stepper applies: the explicit joints' forces at the state, and in a step's
    /// pass 1 the sub-cycled joints' deliveries ([`ClearanceJointSet::wrenches`] holds every
    /// joint's force at the state, for readers).
    #[allow(clippy::misnamed_getters)]
    fn wrenches(&self) -> &[Wrench] {
        &self.applied
    }
    fn resolve_step(
        &mut self,
        world: &rapier3d_f64::prelude::PhysicsWorld,
        pass: &StepPass,
    ) -> bool {
        let iterations = world.integration_parameters.num_solver_iterations;
        ClearanceJointSet::resolve_step(self, &world.bodies, pass, iterations)
    }
    fn save_state(&mut self) {
        ClearanceJointSet::save_state(self);
    }
    fn restore_state(&mut self) {
        ClearanceJointSet::restore_state(self);
    }
    fn check_world(&self, params: &IntegrationParameters) -> Result<()> {
        self.check_substeps(params)?;
        spatial::subcycle::check_apart(&self.iter().map(|(_, j)| j).collect::<Vec<_>>())
    }
    fn step_limit(&self, step: &StepContext) -> f64 {
        self.adaptive_step(step.tolerance, step.last_dt)
    }
    fn check_step(&self, step: &StepContext) -> Result<()> {
        ClearanceJointSet::check_step(self, step.dt)
    }
    fn judge_step(&self, step: &StepContext) -> Option<f64> {
        ClearanceJointSet::judge_step(self, step.dt, step.tolerance)
    }
    fn record_guards(&self, step: &StepContext, guards: &mut GuardReport) {
        let (t, dt, fixed) = (step.t, step.dt, step.fixed);
        for (handle, j) in self.iter() {
            let limit = j.report().friction_stable_dt;
            if fixed && dt > limit && !j.sub_cycled() {
                guards.record(
                    Violation::new(GuardKind::Friction, dt / limit, 1.0, t)
                        .joint(j.name(), Some(handle.id()))
                        .note(format!(
                            "step {} s, friction's limit {} s",
                            crate::error::sig4(dt),
                            crate::error::sig4(limit)
                        )),
                );
            }
            if let Some(n) = j.substeps_beyond_cap() {
                guards.record(
                    Violation::new(
                        GuardKind::SubSteps,
                        f64::from(n),
                        f64::from(subcycle::MAX_SUBSTEPS),
                        t,
                    )
                    .joint(j.name(), Some(handle.id())),
                );
            }
            let (depth, valid) = (j.deepest_in_step(), j.max_valid_penetration());
            let ratio = depth / valid;
            if ratio > guards.worst_penetration_ratio {
                guards.worst_penetration_ratio = ratio;
            }
            if ratio > 1.0 {
                guards.record(
                    Violation::new(GuardKind::Penetration, depth, valid, t)
                        .joint(j.name(), Some(handle.id())),
                );
            }
        }
    }
    fn stalled_contact(&self, bodies: &RigidBodySet) -> Option<StalledContact> {
        self.iter()
            .filter(|(_, j)| j.report().state.penetration > 0.0)
            .min_by(|(_, a), (_, b)| {
                let limit = |j: &ClearanceJoint| {
                    j.report().max_stable_dt.min(j.report().friction_stable_dt)
                };
                limit(a).total_cmp(&limit(b))
            })
            .map(|(h, j)| super::stalled::stalled_contact_of(h, j, bodies))
    }
    fn sub_cycled_contact_step(&self, step: &StepContext) -> f64 {
        self.iter()
            .filter_map(|(_, j)| j.contact_world_step(step.tolerance, step.last_dt))
            .fold(f64::INFINITY, f64::min)
    }
    fn divergence_causes(&self, body: RigidBodyHandle, causes: &mut Vec<String>) {
        for (_, j) in self.iter() {
            if j.body1() == body || j.body2() == body {
                causes.extend(j.cap_in_words());
            }
        }
    }
    fn joints_of(&self, body: RigidBodyHandle, names: &mut Vec<String>) {
        for (_, j) in self.iter() {
            if j.body1() == body || j.body2() == body {
                names.push(format!("clearance joint `{}`", j.name()));
            }
        }
    }
    fn check_bodies(&self, bodies: &RigidBodySet) -> Result<()> {
        for (_, j) in self.iter() {
            crate::rapier::pipeline::step_hooks::joint_bodies(
                bodies,
                || format!("clearance joint `{}`", j.name()),
                j.body1(),
                j.body2(),
            )?;
        }
        Ok(())
    }
}
