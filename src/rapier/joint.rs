//! The clearance joint in a Rapier world: a revolute hinge whose radial play is left to the
//! contact law. [`ClearanceJointSet::apply`] is the per-step force hook.

use crate::error::{Error, Result, StepLimit};
use crate::model::kinematics::{
    BodyMotion, ContactMode, ForcePair, JournalState, StepBefore, contact_force, force_and_damping,
    journal_state, stable_step,
};
use crate::model::laws::{
    BearingGeometry, FrictionLaw, FrictionModel, NormalContact, NormalForceLaw, NormalModel,
    crossing_fraction, loaded_impact_rate, penetration_for_energy, speed_at_crossing,
};
use crate::rapier::pipeline::ledger::{
    ForceLedger, Wrench, ensure_mass_properties, inverse_mass_along, world_center_of_mass,
};
use std::sync::OnceLock;

mod builder;
mod effective_mass;
mod history;
mod report;
mod set;
mod spatial;
mod stalled;
mod step_policy;
mod subcycle;
use builder::DEFAULT_VALID_STRAIN;
pub(crate) use builder::validate_max_valid_penetration;
use effective_mass::Mechanism;
use history::{ContactHistory, Onset};
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{
    GenericJointBuilder, ImpulseJointHandle, ImpulseJointSet, IntegrationParameters, JointAxesMask,
    RigidBody, RigidBodyHandle, RigidBodySet,
};
pub use report::ClearanceReport;
pub use set::{ClearanceJointHandle, ClearanceJointSet};
pub use spatial::report::{Region, SpatialPoint, SpatialReport};
use spatial::{SpatialMemory, SpatialParts};
use step_policy::ContactAhead;
pub(crate) use step_policy::flight_step;
pub(crate) use subcycle::MAX_SUBSTEPS;
pub use subcycle::{ContactIntegration, SubCycleTechniques, SubStep};
use subcycle::{PairStart, SubCycle};

/// What holds the degrees of freedom the contact law does not (axial translation and the two tilts).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum OutOfPlaneLock {
    /// A Rapier `GenericJoint` locking the axial translation and the two tilts, relative to the
    /// bodies (works for any axis and any body motion). The default.
    #[default]
    Joint,
    /// Nothing: the caller guarantees planar motion (e.g. with `LockedAxes` on the bodies).
    None,
}

/// Builds a [`ClearanceJoint`] from a [`HingeDesign`](crate::rapier::hinge::design::HingeDesign)
/// and its placement. Body 1 carries the bearing (hole), body 2 the journal (pin).
#[derive(Clone, Debug)]
pub(crate) struct ClearanceJointBuilder {
    joint: ClearanceJoint,
    spatial: Option<crate::model::spatial::SpatialModel>,
}

/// Default of [`HingeDesign::min_impact_speed`](crate::rapier::hinge::design::HingeDesign::min_impact_speed), m/s.
pub(crate) const DEFAULT_MIN_IMPACT_SPEED: f64 = 1e-4;

/// Default of [`HingeDesign::min_separation`](crate::rapier::hinge::design::HingeDesign::min_separation), m.
pub(crate) const DEFAULT_MIN_SEPARATION: f64 = 1e-7;

/// The default validity limit of a joint's penetration, m: 1 % of the journal radius (95 um
/// for a 10 mm bearing with 0.5 mm of clearance), a nominal compressive strain `delta/R_j` of
/// 1 %, within the small strain of the linear elastic laws (docs/MODEL.md, "Validity").
pub(crate) fn default_max_valid_penetration(geometry: &BearingGeometry) -> f64 {
    DEFAULT_VALID_STRAIN * geometry.journal_radius()
}

/// A revolute hinge with radial clearance between two Rapier rigid bodies.
#[derive(Clone, Debug)]
pub struct ClearanceJoint {
    name: String,
    local_axis1: Vector,
    local_axis2: Vector,
    local_anchor1: Vector,
    local_anchor2: Vector,
    geometry: BearingGeometry,
    normal_law: NormalModel,
    friction_law: FrictionModel,
    min_impact_speed: f64,
    min_separation: f64,
    max_valid_penetration: Option<f64>,
    lock: OutOfPlaneLock,
    body1: RigidBodyHandle,
    body2: RigidBodyHandle,
    lock_handle: Option<ImpulseJointHandle>,
    contact: ContactHistory,
    report: ClearanceReport,
    /// The planar contact's elastic energy at the last application, J, computed on first use and
    /// then shared: the step control, a hysteresis law's loaded rate and the energy balance read
    /// it (a law of Liu's family integrates its force for it; a fixed-step loop that reads none
    /// of them does not pay for it).
    elastic: OnceLock<f64>,
    previous_rate: Option<f64>,
    /// The rate at which the positions moved the penetration over the step that led to the
    /// state of the last application, `(delta - delta_before)/h`, m/s (`None`: no step known).
    moved_rate: Option<f64>,
    /// The step that led to the state of the last application, s (0: unknown).
    last_step: f64,
    /// The wrenches on body 1 and body 2 at the last application.
    last_wrenches: Option<[Wrench; 2]>,
    prepared: bool,
    /// The spatial model's stations (`None`: the planar joint).
    spatial: Option<SpatialParts>,
    integration: ContactIntegration,
    /// Stepped by a loop of the user's own (`ClearanceJointSet::apply_forces`), which holds
    /// the forces over Rapier's step: explicit whatever `integration` says.
    plain_loop: bool,
    /// Which of the sub-cycle's techniques a sub-cycled joint uses.
    techniques: SubCycleTechniques,
    /// The sub-cycle's memory and buffers ([`ContactIntegration::SubCycled`]).
    cycle: CycleState,
}

/// What a sub-cycled joint carries between and within steps.
#[derive(Clone, Debug, Default)]
struct CycleState {
    /// The pair at the state before the next step (taken at each evaluation).
    start: Option<PairStart>,
    /// The impulse of the steps so far that Rapier's velocities do not hold yet, `H`.
    held: [f64; 12],
    /// The displacement held beside it, `E`: the pair stands at Rapier's poses moved by `P E`
    /// (zero with one solver iteration).
    shift: [f64; 12],
    /// The states inside the last step.
    substeps: Vec<SubStep>,
    /// The step's sub-cycle, and the impulse it leaves held, between Rapier's pass 0 and the
    /// evaluation at the step's end.
    run: SubCycle,
    pending: Option<[f64; 12]>,
    /// [`ClearanceJoint::start_velocity_correction`] of the last step.
    start_correction: [f64; 12],
    /// [`ClearanceJoint::state_velocity`]: the pair's velocity at the last step's end, as its
    /// sub-cycle ended it (`None` when no sub-cycle ran).
    end_velocity: Option<[f64; 12]>,
    /// [`ClearanceJoint::step_dissipation`] of the last step, J.
    dissipated: f64,
    /// The contact's impulse over the last step ([`ClearanceJoint::step_impulse`]).
    impulse: [f64; 12],
    /// The sub-steps of the last step.
    substep_count: u32,
    /// The mobilities from the contact loads of the other sub-cycled joints of the island to
    /// this pair (their bearing and journal bodies, `P_ij`), taken with `start`.
    coupled: Vec<([RigidBodyHandle; 2], [f64; 144])>,
    /// A spatial joint's pair at the state before the next step.
    spatial_start: Option<spatial::subcycle::SpatialStart>,
    /// A spatial joint's last accepted sub-step, s: the next step's first guess (0: none).
    substep_guess: f64,
    /// A spatial joint's regions' impact clocks at the sub-cycle's end, for the evaluation at
    /// the step's end (Rapier's pass 1 starts from the regions as pass 0 found them).
    spatial_impacts: [Option<f64>; 4],
    /// A spatial joint's regions' contact histories, deepest states and impact rates at the
    /// sub-cycle's end, for the same evaluation: restored with the rest of the joint before
    /// pass 1, the regions would otherwise meet their contacts again at the step's end and read
    /// `delta_dot0` across the whole step, not at the sub-step that crossed.
    spatial_regions: Option<[(ContactHistory, Option<JournalState>, f64); 4]>,
    /// Whether the joint was explicit at its last evaluation (its force then held over the
    /// step after it; [`ClearanceJoint::set_integration`]).
    explicit_before: bool,
}

/// The dynamic state of a joint between steps (what a rejected step must restore).
#[derive(Clone, Debug, Default)]
struct JointDynamics {
    contact: ContactHistory,
    report: ClearanceReport,
    elastic: OnceLock<f64>,
    previous_rate: Option<f64>,
    moved_rate: Option<f64>,
    last_step: f64,
    last_wrenches: Option<[Wrench; 2]>,
    prepared: bool,
    spatial: Option<SpatialMemory>,
    held: [f64; 12],
    shift: [f64; 12],
    substeps: Vec<SubStep>,
}

/// Slope `dmu/dv` of a friction law at slip speed `v` (one-sided difference at 0, where the
/// regularised laws are steepest).
fn friction_slope(law: &impl FrictionLaw, v: f64) -> f64 {
    let h = (1e-4 * v).max(1e-9);
    let lo = (v - h).max(0.0);
    let hi = v + h;
    (law.coefficient(hi) - law.coefficient(lo)) / (hi - lo)
}

impl ClearanceJoint {
    /// The joint's name.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// Bearing body.
    pub fn body1(&self) -> RigidBodyHandle {
        self.body1
    }
    /// Journal body.
    pub fn body2(&self) -> RigidBodyHandle {
        self.body2
    }
    /// Radial geometry.
    pub fn geometry(&self) -> &BearingGeometry {
        &self.geometry
    }
    /// Normal law.
    pub fn normal_law(&self) -> &NormalModel {
        &self.normal_law
    }
    /// Friction law.
    pub fn friction_law(&self) -> &FrictionModel {
        &self.friction_law
    }
    /// Hinge axis in body 1's frame (unit).
    pub fn local_axis1(&self) -> Vector {
        self.local_axis1
    }
    /// Hinge axis in body 2's frame (unit).
    pub fn local_axis2(&self) -> Vector {
        self.local_axis2
    }
    /// Bearing centre in body 1's frame.
    pub fn local_anchor1(&self) -> Vector {
        self.local_anchor1
    }
    /// Journal centre in body 2's frame.
    pub fn local_anchor2(&self) -> Vector {
        self.local_anchor2
    }
    /// The Rapier joint locking the out-of-plane motion, if any.
    pub fn lock_handle(&self) -> Option<ImpulseJointHandle> {
        self.lock_handle
    }
    /// How the contact is integrated ([`ContactIntegration`]): as designed, except in a loop of
    /// your own ([`ClearanceJointSet::apply`]), which holds the forces over Rapier's step and so
    /// integrates every joint explicitly.
    pub fn integration(&self) -> ContactIntegration {
        if self.plain_loop {
            ContactIntegration::Explicit
        } else {
            self.integration
        }
    }
    /// Which of the sub-cycle's techniques the joint uses ([`SubCycleTechniques`]; read when
    /// it is sub-cycled).
    pub fn sub_cycle_techniques(&self) -> SubCycleTechniques {
        self.techniques
    }
    /// A sub-cycled joint's states inside the last step, in time order, the step's end last
    /// (empty for an explicit joint, and before the first step): its contacts resolved where
    /// the step itself is too long to see them. A loop that records a sub-cycled joint's
    /// contacts records these ([`ImpactRecorder::record_step`](crate::rapier::observers::metrics::ImpactRecorder::record_step)).
    pub fn substeps(&self) -> &[SubStep] {
        &self.cycle.substeps
    }
    /// Whether the contact is sub-cycled ([`ContactIntegration::SubCycled`]).
    fn sub_cycled(&self) -> bool {
        self.integration() == ContactIntegration::SubCycled
    }
    /// What the hook computed at its last application.
    pub fn report(&self) -> &ClearanceReport {
        &self.report
    }
    /// The force and torque (about each centre of mass) the joint applied at its last
    /// application: on the bearing's body, then the journal's (`None` before the first, or when
    /// a body is gone). A spatial joint's sum over its stations.
    pub fn last_wrenches(&self) -> Option<[Wrench; 2]> {
        self.last_wrenches
    }
    /// At an onset, the impact the step met as a step short enough would resolve it: its
    /// deepest penetration (the approach's kinetic energy at the crossing, `delta_dot0`, stored
    /// in the law's spring at the effective mass, at most the depth reached), and the stable
    /// step, natural frequency and damping ratio there; `None` when no contact began or when
    /// that impact would take a step of `dt` (s). A refused fixed step's advice then comes from
    /// the state before it, not from the depth a step too long pressed to (at 1 ms the paper's
    /// scene presses to 5.6 um where a resolved impact reaches 1.6 um: advice from that depth
    /// would ask for a step five times shorter than the impact needs).
    fn impact_met(&self, dt: f64) -> Option<(f64, f64, f64, f64)> {
        let r = &self.report;
        if !r.onset {
            return None;
        }
        let law = self.governing_law();
        let m = r.effective_mass;
        let energy = 0.5 * m * r.impact_rate * r.impact_rate;
        let depth = penetration_for_energy(law, energy, 1e-6).min(r.state.penetration);
        let c = NormalContact {
            penetration: depth,
            penetration_rate: 0.0,
            impact_rate: r.impact_rate,
        };
        let (dt_max, omega, zeta) =
            stable_step(law.tangent_stiffness(depth), law.damping_coefficient(&c), m);
        (dt_max < dt).then_some((dt_max, depth, omega, zeta))
    }

    /// The deepest penetration at which the contact law is trusted, m
    /// ([`HingeDesign::max_valid_penetration`](crate::rapier::hinge::design::HingeDesign::max_valid_penetration);
    /// default 1 % of the journal radius).
    pub fn max_valid_penetration(&self) -> f64 {
        self.max_valid_penetration
            .unwrap_or_else(|| default_max_valid_penetration(&self.geometry))
    }
    /// The floor on the impact velocity `delta_dot0` of the hysteresis laws, m/s
    /// ([`HingeDesign::min_impact_speed`](crate::rapier::hinge::design::HingeDesign::min_impact_speed)).
    pub(crate) fn min_impact_speed_floor(&self) -> f64 {
        self.min_impact_speed
    }
    /// Whether the joint was in contact at its last application.
    pub fn in_contact(&self) -> bool {
        self.contact.in_contact
    }
    /// Elastic energy stored in the contact at the last application, J (all stations of a
    /// spatial joint).
    pub fn elastic_energy(&self) -> f64 {
        match &self.spatial {
            Some(parts) => parts.elastic_energy(&self.normal_law),
            None => *self.elastic.get_or_init(|| {
                self.normal_law
                    .elastic_energy(self.report.state.penetration)
            }),
        }
    }

    /// The spatial model, `None` for the planar joint.
    pub fn spatial_model(&self) -> Option<&crate::model::spatial::SpatialModel> {
        self.spatial.as_ref().map(|p| &p.model)
    }

    /// The law of the contact the report's `state` is at: the bore's normal law, or a spatial
    /// joint's face law when its deepest station is on a face.
    pub(crate) fn governing_law(&self) -> &NormalModel {
        match (&self.spatial, self.report.spatial) {
            (Some(parts), Some(r)) if r.governed_by_face => &parts.face_law,
            _ => &self.normal_law,
        }
    }

    /// Saves the dynamic state into `d` (reusing its buffers).
    fn save_into(&self, d: &mut JointDynamics) {
        d.contact = self.contact;
        d.report = self.report;
        d.elastic.clone_from(&self.elastic);
        d.previous_rate = self.previous_rate;
        d.moved_rate = self.moved_rate;
        d.last_step = self.last_step;
        d.last_wrenches = self.last_wrenches;
        d.prepared = self.prepared;
        d.held = self.cycle.held;
        d.shift = self.cycle.shift;
        d.substeps.clone_from(&self.cycle.substeps);
        match (&self.spatial, &mut d.spatial) {
            (Some(parts), Some(memory)) => parts.save_into(memory),
            (Some(parts), memory) => *memory = Some(parts.memory()),
            (None, memory) => *memory = None,
        }
    }

    fn set_dynamics(&mut self, d: &JointDynamics) {
        self.contact = d.contact;
        self.report = d.report;
        self.elastic.clone_from(&d.elastic);
        self.previous_rate = d.previous_rate;
        self.moved_rate = d.moved_rate;
        self.last_step = d.last_step;
        self.last_wrenches = d.last_wrenches;
        self.prepared = d.prepared;
        self.cycle.held = d.held;
        self.cycle.shift = d.shift;
        self.cycle.substeps.clone_from(&d.substeps);
        if let (Some(parts), Some(memory)) = (&mut self.spatial, &d.spatial) {
            parts.restore(memory);
        }
    }

    /// Evaluates the joint at the bodies' state, reached by a step of `step` s (0: unknown),
    /// with `mechanism` the ideal joints around it at that state (its effective masses).
    fn evaluate(
        &mut self,
        bodies: &RigidBodySet,
        step: f64,
        mechanism: &Mechanism,
    ) -> Option<(Wrench, Wrench)> {
        let steps = [std::mem::replace(&mut self.last_step, step), step];
        if self.spatial.is_some() {
            return self.evaluate_spatial(bodies, steps, mechanism);
        }
        let (rb1, rb2) = (bodies.get(self.body1)?, bodies.get(self.body2)?);
        let (m1, m2) = (motion(rb1), motion(rb2));
        let axis = *rb1.rotation() * self.local_axis1;
        let p_i = *rb1.position() * self.local_anchor1;
        let p_j = *rb2.position() * self.local_anchor2;
        let state = journal_state(&self.geometry, p_i, p_j, axis, &m1, &m2);

        // Contact history: record delta_dot0 at onset (MODEL.md §2), located at the crossing of
        // delta = 0 inside the step that led here (the previous application is the state
        // before it), and classify the mode.
        let before = self.prepared_report().then_some(self.report.state);
        let Onset {
            onset,
            impact,
            fraction: onset_fraction,
            approach_speed,
        } = self.contact.advance(
            before.as_ref(),
            &state,
            self.min_impact_speed,
            self.min_separation,
        );
        // The rate at which the positions moved the penetration over the step that led here
        // (see `contact_rate`).
        let moved_rate = before
            .filter(|_| step > 0.0)
            .map(|b| (state.penetration - b.penetration) / step)
            .filter(|r| r.is_finite());
        let mode = self.contact.mode();
        // Through the mechanism's ideal joints: the mass the contact moves, not the free
        // bodies' (effective_mass.rs).
        let inverse_mass = |point: Vector, n: Vector| {
            let free = inverse_mass_along(rb1, point, n) + inverse_mass_along(rb2, point, n);
            mechanism.inverse_mass(free, point, n)
        };
        let effective_mass = 1.0 / inverse_mass(state.contact_point, state.normal);
        let elastic = OnceLock::new();
        let impact_rate = self.law_impact_rate(
            || *elastic.get_or_init(|| self.normal_law.elastic_energy(state.penetration)),
            effective_mass,
        );
        let contact_rate =
            self.contact_rate(&state, impact_rate, effective_mass, steps, moved_rate);
        let at_state = JournalState {
            penetration_rate: contact_rate,
            ..state
        };
        let force = contact_force(&at_state, impact_rate, &self.normal_law, &self.friction_law);

        // Linearised contact for the step-size limit, at the stored rate: carried over a step
        // longer than that limit, the rate is no longer a rate of the contact (a 1 ms step
        // through the paper's first impact carried it to a negative stiffness).
        let (max_stable_dt, omega, zeta) = if state.penetration > 0.0 {
            let c = NormalContact {
                penetration: state.penetration,
                penetration_rate: state.penetration_rate,
                impact_rate,
            };
            // dF/d delta = K_tangent + (dD/d delta) delta_dot (MODEL.md §2 laws, linearised).
            let stiffness = self.normal_law.tangent_stiffness(state.penetration)
                + self.normal_law.damping_slope(&c) * state.penetration_rate;
            stable_step(
                stiffness,
                self.normal_law.damping_coefficient(&c),
                effective_mass,
            )
        } else {
            (f64::INFINITY, 0.0, 0.0)
        };
        // Friction as a tangential damper: `d(mu F_N)/dv = F_N dmu/dv` along the slip.
        let mut friction_stable_dt = f64::INFINITY;
        if force.normal_force > 0.0 {
            let v = state.slip.length();
            let slope = friction_slope(&self.friction_law, v);
            if slope > 0.0 {
                let t = if v > 0.0 {
                    state.slip / v
                } else {
                    state.normal.cross(axis)
                };
                let inv_m = inverse_mass(state.contact_point, t);
                friction_stable_dt = 2.0 / (inv_m * force.normal_force * slope);
            }
        }
        if self.prepared_report() {
            self.previous_rate = Some(self.report.state.penetration_rate);
        }
        self.moved_rate = moved_rate;
        self.elastic = elastic;
        self.report = ClearanceReport {
            state,
            mode,
            onset,
            impact,
            impact_rate,
            approach_speed,
            contact_rate,
            onset_fraction,
            force,
            max_stable_dt,
            friction_stable_dt,
            omega,
            zeta,
            effective_mass,
            spatial: None,
        };
        let f = force.on_journal;
        let w2 = Wrench {
            body: self.body2,
            force: f,
            torque: (force.point - m2.center_of_mass).cross(f),
        };
        let w1 = Wrench {
            body: self.body1,
            force: -f,
            torque: (force.point - m1.center_of_mass).cross(-f),
        };
        Some((w1, w2))
    }
}

impl ClearanceJoint {
    /// `delta_dot0` for the law in the current contact whose elastic energy `elastic()` gives
    /// (J): the contact's own, raised for a hysteresis law to [`loaded_impact_rate`] there (0 in
    /// free flight).
    fn law_impact_rate(&self, elastic: impl FnOnce() -> f64, effective_mass: f64) -> f64 {
        if !self.contact.in_contact {
            return self.contact.impact_rate;
        }
        let rate = self.contact.impact_rate;
        if self.normal_law.uses_impact_rate() {
            rate.max(loaded_impact_rate(elastic(), effective_mass))
        } else {
            rate
        }
    }

    /// The penetration rate for the normal law at `state`, `steps` the step before the last
    /// application's state and the step since, `moved` the rate at which the positions moved the
    /// penetration over the step since (`(delta - delta_before)/h`): in contact, the rate at the
    /// state ([`StepBefore::carry`]), with the rest of the mechanism's acceleration from the last
    /// application ([`StepBefore`]); the bodies' stored rate without a contact, a known step or
    /// an earlier application.
    ///
    /// The rate carried is the positions' own over each step, `moved`, not the rate the bodies'
    /// stored velocities give (`state.penetration_rate`), when both this step's and the step
    /// before's are known. Rapier moves the positions with its solver's velocities biased by the
    /// ideal joints' drift correction (`error / h`, of the order of the joint's acceleration times
    /// `h/2`) and stores them unbiased, and a point of a turning body moves along its chord, not
    /// along the velocity read at the state (a difference `w^2 r h/2`): the stored rate differs
    /// from the rate of the penetration the law sees by a term of order `h`, which a heavily
    /// damped contact integrates into its depth (`assets/slider_crank.ron`, damping ratio about
    /// 30, pressed by the drive for 3.5 ms: `6.6e-4` m/s at fixed steps of 1e-7 s; its ODE
    /// reference is in `tests/references.rs`).
    fn contact_rate(
        &self,
        state: &JournalState,
        impact_rate: f64,
        effective_mass: f64,
        steps: [f64; 2],
        moved: Option<f64>,
    ) -> f64 {
        let stored = state.penetration_rate;
        if !(state.penetration > 0.0 && self.prepared_report()) {
            return stored;
        }
        let (now, then) = match (moved, self.moved_rate) {
            (Some(now), Some(then)) => (now, then),
            _ => (stored, self.report.state.penetration_rate),
        };
        let c = NormalContact {
            penetration: state.penetration,
            penetration_rate: now,
            impact_rate,
        };
        let (force, damping) = force_and_damping(&self.normal_law, &c);
        let before = StepBefore {
            rate: then,
            force: self.report.force.normal_force,
            steps,
        };
        before.carry(now, force, damping, effective_mass)
    }

    /// Whether a report from an earlier application exists.
    fn prepared_report(&self) -> bool {
        self.report.effective_mass > 0.0
    }
}

fn motion(rb: &RigidBody) -> BodyMotion {
    BodyMotion {
        center_of_mass: world_center_of_mass(rb),
        linvel: rb.linvel(),
        angvel: rb.angvel(),
    }
}

#[cfg(test)]
mod tests;
