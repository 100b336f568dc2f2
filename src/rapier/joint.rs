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

mod effective_mass;
mod set;
mod spatial;
mod subcycle;
use effective_mass::Mechanism;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{
    GenericJointBuilder, ImpulseJointHandle, ImpulseJointSet, IntegrationParameters, JointAxesMask,
    RigidBody, RigidBodyHandle, RigidBodySet,
};
pub use set::{ClearanceJointHandle, ClearanceJointSet};
pub use spatial::{Region, SpatialPoint, SpatialReport};
use spatial::{SpatialMemory, SpatialParts};
pub use subcycle::{ContactIntegration, SubStep};
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

/// Builds a [`ClearanceJoint`] with chained setters, like Rapier's `RevoluteJointBuilder`.
/// Body 1 carries the bearing (hole), body 2 the journal (pin).
///
/// ```
/// use clearance_joint::model::laws::{Bai, BearingGeometry, FrictionModel, ImprovedLiu, MaxDamping, NormalModel};
/// use clearance_joint::prelude::*;
/// let geometry = BearingGeometry::from_clearance(0.010, 0.5e-3, 0.016).unwrap();
/// let law = ImprovedLiu::new(1.137e11, 0.016, 0.5e-3, 1.0, 1e-4, MaxDamping::Eta(0.01)).unwrap();
/// let joint = ClearanceJointBuilder::new(Vector::new(0.0, -1.0, 0.0), geometry, NormalModel::ImprovedLiu(law))
///     .local_anchor1(Vector::new(0.4, 0.0, 0.4))
///     .local_anchor2(Vector::new(0.0, 0.0, 0.4))
///     .friction(FrictionModel::Bai(Bai::DRY))
///     .build()
///     .unwrap();
/// assert!((joint.geometry().clearance() - 0.5e-3).abs() < 1e-15);
/// ```
#[derive(Clone, Debug)]
pub struct ClearanceJointBuilder {
    joint: ClearanceJoint,
    spatial: Option<crate::model::spatial::SpatialModel>,
}

impl ClearanceJointBuilder {
    /// A joint about `axis` (in body 1's frame; also used for body 2 unless
    /// [`local_axis2`](Self::local_axis2) is set) with the given geometry and normal law,
    /// frictionless, anchors at both bodies' origins.
    pub fn new(axis: Vector, geometry: BearingGeometry, normal_law: NormalModel) -> Self {
        ClearanceJointBuilder {
            joint: ClearanceJoint {
                name: String::from("clearance joint"),
                local_axis1: axis,
                local_axis2: axis,
                local_anchor1: Vector::ZERO,
                local_anchor2: Vector::ZERO,
                geometry,
                normal_law,
                friction_law: FrictionModel::None,
                min_impact_speed: DEFAULT_MIN_IMPACT_SPEED,
                min_separation: DEFAULT_MIN_SEPARATION,
                max_valid_penetration: None,
                lock: OutOfPlaneLock::Joint,
                body1: RigidBodyHandle::invalid(),
                body2: RigidBodyHandle::invalid(),
                lock_handle: None,
                contact: ContactHistory::default(),
                report: ClearanceReport::default(),
                elastic: OnceLock::new(),
                previous_rate: None,
                last_step: 0.0,
                last_wrenches: None,
                prepared: false,
                spatial: None,
                integration: ContactIntegration::default(),
                cycle: CycleState::default(),
            },
            spatial: None,
        }
    }
    /// Bearing centre in body 1's frame.
    pub fn local_anchor1(mut self, anchor: Vector) -> Self {
        self.joint.local_anchor1 = anchor;
        self
    }
    /// Journal centre in body 2's frame.
    pub fn local_anchor2(mut self, anchor: Vector) -> Self {
        self.joint.local_anchor2 = anchor;
        self
    }
    /// How the contact is integrated over a step ([`ContactIntegration`]; default
    /// [`ContactIntegration::Explicit`]).
    pub fn integration(mut self, integration: ContactIntegration) -> Self {
        self.joint.integration = integration;
        self
    }
    /// Hinge axis in body 2's frame (defaults to the axis given to [`new`](Self::new)).
    pub fn local_axis2(mut self, axis: Vector) -> Self {
        self.joint.local_axis2 = axis;
        self
    }
    /// The friction law (default: none).
    pub fn friction(mut self, friction: FrictionModel) -> Self {
        self.joint.friction_law = friction;
        self
    }
    /// Floor on the impact velocity `delta_dot0` of the hysteresis laws, m/s (default 1e-4): a
    /// contact that begins at a vanishing speed would otherwise get unbounded damping.
    pub fn min_impact_speed(mut self, speed: f64) -> Self {
        self.joint.min_impact_speed = speed;
        self
    }
    /// The gap a free flight must open for the next onset to count as an
    /// [impact](crate::rapier::observers::metrics#onsets-impacts-and-chatter), m (default 0.1 um, about 8
    /// times the resting penetration of the paper's hinge load): onsets after smaller
    /// separations are the chatter of a journal following the wall.
    pub fn min_separation(mut self, gap: f64) -> Self {
        self.joint.min_separation = gap;
        self
    }
    /// The deepest penetration at which the contact law is still trusted, m (default
    /// [`DEFAULT_VALID_STRAIN`] times the journal radius, see
    /// [`default_max_valid_penetration`]). A journal pressed deeper is outside the model; the
    /// steppers report it as a guard violation ([`crate::rapier::pipeline::stepper::GuardReport`]), with
    /// the worst depth, when and how often. It is not a force limit.
    pub fn max_valid_penetration(mut self, depth: f64) -> Self {
        self.joint.max_valid_penetration = Some(depth);
        self
    }
    /// What locks the out-of-plane degrees of freedom (default [`OutOfPlaneLock::Joint`]).
    pub fn lock(mut self, lock: OutOfPlaneLock) -> Self {
        self.joint.lock = lock;
        self
    }
    /// A name used in error messages and outputs.
    pub fn name(mut self, name: impl Into<String>) -> Self {
        self.joint.name = name.into();
        self
    }
    /// Makes the joint spatial ([`crate::model::spatial`]): nothing is locked, the journal
    /// tilts and slides axially, touching the bore along its width (the geometry's length) and
    /// the bearing's faces with its shoulders. The [`lock`](Self::lock) is ignored (always none).
    pub fn spatial(mut self, model: crate::model::spatial::SpatialModel) -> Self {
        self.spatial = Some(model);
        self
    }
    /// Validates and returns the joint: unit axes, finite anchors, a normal law that holds a
    /// clearance (Liu's family) built for the geometry's
    /// ([`NormalModel::check_clearance`]), the floors and the validity limit.
    pub fn build(mut self) -> Result<ClearanceJoint> {
        let j = &mut self.joint;
        j.local_axis1 = crate::error::unit_vector("local_axis1", j.local_axis1)?;
        j.local_axis2 = crate::error::unit_vector("local_axis2", j.local_axis2)?;
        for (field, v) in [
            ("local_anchor1", j.local_anchor1),
            ("local_anchor2", j.local_anchor2),
        ] {
            if !v.is_finite() {
                return Err(Error::invalid(field, format!("must be finite (got {v:?})")));
            }
        }
        // The clearance is held twice, by the geometry and by a law of Liu's family: they agree.
        j.normal_law
            .check_clearance("normal_law", j.geometry.clearance())?;
        crate::error::positive("min_impact_speed", j.min_impact_speed)?;
        crate::error::non_negative("min_separation", j.min_separation)?;
        if let Some(d) = j.max_valid_penetration {
            validate_max_valid_penetration("max_valid_penetration", d, &j.geometry)?;
        }
        if let Some(model) = self.spatial {
            let face_law = model
                .validate(&j.geometry)
                .map_err(|e| e.within("spatial"))?;
            j.lock = OutOfPlaneLock::None;
            j.spatial = Some(SpatialParts::new(model, face_law, j.local_axis1));
        }
        Ok(self.joint)
    }
}

/// State carried between steps: whether a contact is on, and its impact velocity.
#[derive(Clone, Copy, Debug, PartialEq)]
struct ContactHistory {
    in_contact: bool,
    /// Largest gap of the current free flight (infinite before the first contact), m.
    max_gap: f64,
    compressing: bool,
    impact_rate: f64,
}

impl Default for ContactHistory {
    fn default() -> Self {
        ContactHistory {
            in_contact: false,
            max_gap: f64::INFINITY,
            compressing: false,
            impact_rate: 0.0,
        }
    }
}

/// How a contact history moved at one evaluation.
#[derive(Clone, Copy, Debug)]
struct Onset {
    onset: bool,
    impact: bool,
    fraction: f64,
    approach_speed: f64,
}

impl ContactHistory {
    /// The motion mode the history is in (paper Fig. 1b).
    fn mode(&self) -> ContactMode {
        match (self.in_contact, self.compressing) {
            (false, _) => ContactMode::FreeFlight,
            (true, true) => ContactMode::Impact,
            (true, false) => ContactMode::Continuous,
        }
    }

    /// Moves the history to `state`, with `before` the state at the previous evaluation (if any):
    /// records `delta_dot0` at an onset (MODEL.md §2), located at the crossing of delta = 0 inside
    /// the step that led here, and whether the contact is still compressing.
    fn advance(
        &mut self,
        before: Option<&JournalState>,
        state: &JournalState,
        min_impact_speed: f64,
        min_separation: f64,
    ) -> Onset {
        let onset = state.penetration > 0.0 && !self.in_contact;
        let impact = onset && self.max_gap >= min_separation;
        let (fraction, approach_speed) = match (onset, before) {
            (true, Some(before)) if before.penetration <= 0.0 => {
                let s = crossing_fraction(-before.penetration, state.penetration);
                let rate = speed_at_crossing(before.penetration_rate, state.penetration_rate, s);
                (s, rate)
            }
            (true, _) => (1.0, state.penetration_rate),
            (false, _) => (1.0, 0.0),
        };
        if state.penetration > 0.0 {
            if onset {
                *self = ContactHistory {
                    in_contact: true,
                    max_gap: 0.0,
                    compressing: true,
                    impact_rate: approach_speed.max(min_impact_speed),
                };
            } else if state.penetration_rate <= 0.0 {
                self.compressing = false;
            }
        } else {
            let gap = -state.penetration;
            let max_gap = if self.in_contact {
                gap
            } else {
                self.max_gap.max(gap)
            };
            *self = ContactHistory {
                max_gap,
                ..ContactHistory::default()
            };
        }
        Onset {
            onset,
            impact,
            fraction,
            approach_speed,
        }
    }
}

/// What the hook computed for one joint at its last application.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClearanceReport {
    /// Journal state (eccentricity, penetration, rates).
    pub state: JournalState,
    /// Motion mode.
    pub mode: ContactMode,
    /// Whether a contact began at this application: an
    /// [onset](crate::rapier::observers::metrics#onsets-impacts-and-chatter), chatter included.
    pub onset: bool,
    /// Whether this onset is an [impact](crate::rapier::observers::metrics#onsets-impacts-and-chatter): the
    /// first contact, or one after a free flight that opened a gap of at least the joint's
    /// `min_separation`. Re-contacts after smaller separations are chatter of a journal
    /// following the wall, not impacts.
    pub impact: bool,
    /// `delta_dot0` the normal law used at this application (0 in free flight), m/s: the
    /// approach speed at the crossing of delta = 0, floored by the joint's `min_impact_speed`
    /// and, for a contact loaded deeper than its approach explains, raised to the speed of a
    /// free impact reaching the same depth ([`loaded_impact_rate`]).
    pub impact_rate: f64,
    /// At an onset, the penetration rate interpolated at the crossing of delta = 0 inside the
    /// step that led here ([`speed_at_crossing`]), m/s; 0 otherwise.
    pub approach_speed: f64,
    /// The penetration rate the normal law was given, m/s. `state.penetration_rate` is read from
    /// the bodies' velocities, the mean over the step that led here, half a step behind the
    /// state; in contact the joint carries it to the state ([`StepBefore::carry`], with the step of
    /// [`ClearanceJointSet::set_last_step`]) so that the damping force is second order in the
    /// step. Equal to `state.penetration_rate` in free flight and when the step is unknown (at
    /// the first application). A spatial joint's is its deepest station's.
    pub contact_rate: f64,
    /// At an onset, the fraction of the step that led here at which delta crossed 0
    /// ([`crossing_fraction`]; the onset time is the step's end minus `(1 - fraction)` steps);
    /// 1 otherwise.
    pub onset_fraction: f64,
    /// The force pair applied.
    pub force: ForcePair,
    /// Largest stable step for the contact as linearised now (infinite in free flight), s:
    /// stiffness and damping along the normal. Beyond it the explicit step blows up.
    pub max_stable_dt: f64,
    /// Largest step that resolves friction as linearised now, `2 m_t/(F_N dmu/dv)` (infinite
    /// without contact), s: a friction law whose coefficient rises steeply with slip, like Bai's
    /// near zero slip, acts as a stiff tangential damper. Friction is bounded by `mu_s F_N`, so a
    /// longer step does not blow up; it turns stiction into a numerical chatter of the slip.
    pub friction_stable_dt: f64,
    /// Linearised natural frequency of the contact, rad/s.
    pub omega: f64,
    /// Linearised damping ratio of the contact.
    pub zeta: f64,
    /// Effective mass of the two bodies along the contact normal, kg.
    pub effective_mass: f64,
    /// A spatial joint's tilt, axial offset and forces by contact kind (`None` for the planar
    /// joint). Its `state` above is then the deepest station's (bore or face), `force` the sum
    /// over all stations (`normal_force` the magnitude of the summed normal forces, the resultant
    /// load on the bearing: edges loaded on opposite sides by a moment cancel in it).
    pub spatial: Option<SpatialReport>,
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
    /// The step that led to the state of the last application, s (0: unknown).
    last_step: f64,
    /// The wrenches on body 1 and body 2 at the last application.
    last_wrenches: Option<[Wrench; 2]>,
    prepared: bool,
    /// The spatial model's stations (`None`: the planar joint).
    spatial: Option<SpatialParts>,
    integration: ContactIntegration,
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
    /// The states inside the last step.
    substeps: Vec<SubStep>,
    /// The step's sub-cycle, and the impulse it leaves held, between Rapier's pass 0 and the
    /// evaluation at the step's end.
    run: SubCycle,
    pending: Option<[f64; 12]>,
    /// [`ClearanceJoint::start_velocity_correction`] of the last step.
    start_correction: [f64; 12],
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
}

/// Default of [`ClearanceJointBuilder::min_impact_speed`], m/s.
pub const DEFAULT_MIN_IMPACT_SPEED: f64 = 1e-4;

/// Default of [`ClearanceJointBuilder::min_separation`], m.
pub const DEFAULT_MIN_SEPARATION: f64 = 1e-7;

/// The nominal compressive strain `delta/R_j` up to which the contact laws are trusted by
/// default: 1 %. Every law here is linear elastic (small strain); at a strain `e` the
/// Green-Lagrange strain `e + e^2/2` differs from the linear one by `e/2`, 0.5 % at 1 %, and
/// the approach `delta` spreads over a depth of the order of the journal radius `R_j`.
/// docs/MODEL.md ("Validity") gives the argument and what it does not cover.
pub const DEFAULT_VALID_STRAIN: f64 = 0.01;

/// The default validity limit of a joint's penetration, m: [`DEFAULT_VALID_STRAIN`] times the
/// journal radius (95 um for a 10 mm bearing with 0.5 mm of clearance).
pub fn default_max_valid_penetration(geometry: &BearingGeometry) -> f64 {
    DEFAULT_VALID_STRAIN * geometry.journal_radius()
}

/// Checks a validity limit `depth` (m) for `field`: positive, finite, and at most the journal
/// radius (a deeper "penetration" is no contact of two cylinders).
pub fn validate_max_valid_penetration(
    field: &str,
    depth: f64,
    geometry: &BearingGeometry,
) -> Result<f64> {
    crate::error::positive(field, depth)?;
    let r = geometry.journal_radius();
    if depth > r {
        return Err(Error::invalid(
            field,
            format!(
                "must be at most the journal radius {} m (got {} m): the limit is a depth of \
                 contact, small against the journal (default {} m, {} % of its radius)",
                crate::error::sig4(r),
                crate::error::sig4(depth),
                crate::error::sig4(default_max_valid_penetration(geometry)),
                DEFAULT_VALID_STRAIN * 100.0
            ),
        ));
    }
    Ok(depth)
}

/// The journal-path step of a journal whose centre moves at `speed` (m/s) relative to the
/// bearing's, in a clearance `clearance` (m): the step that moves it `tolerance` times the
/// clearance, `tol c/|de/dt|`, s (infinite at rest), in free flight and in contact (along the
/// wall the contact's normal then turns by at most about `tolerance` rad a step). Without it a
/// free flight took the step of the bodies' turn: on Flores and Ambrósio's slider-crank a journal
/// crossed its 0.5 mm gap in a few steps of 14 us, and the impacts after the first left the
/// converged sequence within two (measured, `cargo bench --bench mechanisms`); the four-bar's
/// first impact was 60 % high. Without it in contact the slider-crank at c = 0.1 mm rode its
/// wall through the load reversals where converged runs lift off: 0 to 0.5 lift-offs per turn
/// in turns 2-3 against 5 to 6.5 (fixed 1e-6 to 2.5e-7 s), and at tolerances 0.00375, 0.002 and
/// 0.001 1.5-4.5, 3.5-5 and 5-9: a bias of the step, not chaos. With it 4 per turn for 4.6 %
/// more steps; the paper's scene at T, 3T and 5T, the four-bar, the deployable array and the
/// double pendulum take the same steps as without.
pub fn flight_step(tolerance: f64, clearance: f64, speed: f64) -> f64 {
    if speed > 0.0 {
        tolerance * clearance / speed
    } else {
        f64::INFINITY
    }
}

/// Fraction of the predicted time to contact that one free-flight step may cover, so that a
/// contact is approached in shrinking steps and starts near a step boundary.
const APPROACH_FRACTION: f64 = 0.5;
/// The fraction of a contact's natural period one adaptive step in contact may cover, per unit
/// of tolerance: `2 tol` (0.015 of the period at the default 0.0075). The contact laws get the
/// rate at the state (MODEL.md §6), so a contact is integrated at second order like the free
/// motion; the factor balances the two error sources. The first-impact errors and steps it gives
/// are the mechanism matrix's (docs/stepper-and-accuracy.md, `cargo bench --bench mechanisms`).
pub const CONTACT_PERIODS_PER_TOLERANCE: f64 = 2.0;
/// Margin on the damped stability limit used by the adaptive step.
const STABILITY_SAFETY: f64 = 0.8;
/// The fraction of the damped stability limit one adaptive step in contact may cover, per unit
/// of tolerance: `50 tol` (0.375 at the default 0.0075; at most 0.8, the margin kept on that
/// limit). A heavily damped contact (damping ratio above about 4) relaxes at `2/limit`, and a step
/// near the limit is stable, not accurate: scaled with the tolerance, tightening converges it.
/// Measured on `assets/slider_crank.ron`'s first impact in `tests/stepper.rs`; the mechanism
/// matrix (docs/stepper-and-accuracy.md, `cargo bench --bench mechanisms`) shows the rest.
pub const STABLE_FRACTION_PER_TOLERANCE: f64 = 50.0;

/// The fraction of a contact's damped stability limit an adaptive step may take at `tolerance`
/// ([`STABLE_FRACTION_PER_TOLERANCE`], [`STABILITY_SAFETY`]).
fn stable_fraction(tolerance: f64) -> f64 {
    (STABLE_FRACTION_PER_TOLERANCE * tolerance).min(STABILITY_SAFETY)
}

/// A contact as the step control sees it ahead: the effective mass along its normal (kg), the
/// approach speed (m/s) and depth (m) it starts from, the current contact's `delta_dot0` (m/s;
/// `None` before it begins) and the joint's floor on it.
#[derive(Clone, Copy, Debug)]
struct ContactAhead {
    mass: f64,
    approach_speed: f64,
    depth: f64,
    impact_rate: Option<f64>,
    min_impact_speed: f64,
}

impl ContactAhead {
    /// The step that resolves this contact of `law` (elastic energy `elastic` J at its depth) to
    /// `2 tolerance` of its natural period ([`CONTACT_PERIODS_PER_TOLERANCE`]), taken at the
    /// deepest point its energy reaches, and to `stable` (a fraction, e.g. [`stable_fraction`])
    /// of its damped stability limit there.
    fn resolving_step(
        &self,
        law: &impl NormalForceLaw,
        elastic: f64,
        tolerance: f64,
        stable_share: f64,
    ) -> f64 {
        let m = self.mass;
        let v = self.approach_speed;
        let energy = 0.5 * m * v * v + elastic;
        let peak = penetration_for_energy(law, energy, 1e-6).max(self.depth);
        let stiffness = law.tangent_stiffness(peak);
        if !(stiffness > 0.0) {
            return f64::INFINITY;
        }
        let mut impact_rate = self
            .impact_rate
            .unwrap_or_else(|| v.max(self.min_impact_speed));
        if law.uses_impact_rate() {
            impact_rate = impact_rate.max(loaded_impact_rate(energy, m));
        }
        let c = NormalContact {
            penetration: peak,
            penetration_rate: v,
            impact_rate,
        };
        let (stable, omega, _) = stable_step(stiffness, law.damping_coefficient(&c), m);
        let period = std::f64::consts::TAU / omega;
        (CONTACT_PERIODS_PER_TOLERANCE * tolerance * period).min(stable_share * stable)
    }
}

/// The dynamic state of a joint between steps (what a rejected step must restore).
#[derive(Clone, Debug, Default)]
struct JointDynamics {
    contact: ContactHistory,
    report: ClearanceReport,
    elastic: OnceLock<f64>,
    previous_rate: Option<f64>,
    last_step: f64,
    last_wrenches: Option<[Wrench; 2]>,
    prepared: bool,
    spatial: Option<SpatialMemory>,
    held: [f64; 12],
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
    /// How the contact is integrated ([`ContactIntegration`]).
    pub fn integration(&self) -> ContactIntegration {
        self.integration
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
        self.integration == ContactIntegration::SubCycled
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
    /// ([`ClearanceJointBuilder::max_valid_penetration`]; default
    /// [`default_max_valid_penetration`]).
    pub fn max_valid_penetration(&self) -> f64 {
        self.max_valid_penetration
            .unwrap_or_else(|| default_max_valid_penetration(&self.geometry))
    }
    /// The floor on the impact velocity `delta_dot0` of the hysteresis laws, m/s
    /// ([`ClearanceJointBuilder::min_impact_speed`]).
    pub fn min_impact_speed_floor(&self) -> f64 {
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
    pub fn governing_law(&self) -> &NormalModel {
        match (&self.spatial, self.report.spatial) {
            (Some(parts), Some(r)) if r.governed_by_face => &parts.face_law,
            _ => &self.normal_law,
        }
    }

    /// The largest step that resolves this joint's contact dynamics to `tolerance`, from the state
    /// of the last application. `last_dt` is the step taken before it (to estimate the gap's
    /// acceleration).
    ///
    /// - In contact: twice `tolerance` ([`CONTACT_PERIODS_PER_TOLERANCE`]) of the contact's
    ///   natural period `2 pi/omega`, with `omega` at the deepest point the contact's energy
    ///   reaches (its elastic energy plus the kinetic energy of its normal motion, in or out), and
    ///   within the damped stability limit there. The step follows the contact's energy, not the
    ///   phase of its oscillation.
    /// - In free flight: the journal's centre moves at most `tolerance` times the clearance
    ///   relative to the bearing's in one step ([`flight_step`]: its path across the gap decides
    ///   where and how fast the next impact comes), and the contact ahead is predicted from the
    ///   gap, closing speed and acceleration; a step covers at most half the time to it, and no
    ///   less than the step that contact will need.
    /// - A sub-cycled joint ([`ContactIntegration::SubCycled`]) resolves its contacts in its
    ///   sub-steps: the journal's path bounds the step, and in contact or approaching the wall
    ///   the step covers at most 10 of the sub-steps the contact needs (`20 tolerance` of its
    ///   period) and half the time to the wall.
    pub fn adaptive_step(&self, tolerance: f64, last_dt: f64) -> f64 {
        let r = &self.report;
        let m = r.effective_mass;
        if !(m > 0.0 && m.is_finite()) {
            return f64::INFINITY;
        }
        if self.sub_cycled() {
            // The sub-steps resolve the contact; the world steps through it in a few steps (a
            // spatial joint's: every region's path across its gap bounds the step).
            if let Some(parts) = &self.spatial {
                return parts.flight_step(tolerance);
            }
            return flight_step(
                tolerance,
                self.geometry.clearance(),
                r.state.eccentricity_rate.length(),
            )
            .min(self.world_contact_step(tolerance));
        }
        let delta = r.state.penetration;
        let rate = r.state.penetration_rate;
        let contact_step =
            |approach_speed: f64, depth: f64| self.contact_step(approach_speed, depth, tolerance);
        let flight = match &self.spatial {
            Some(parts) => parts.flight_step(tolerance),
            None => flight_step(
                tolerance,
                self.geometry.clearance(),
                r.state.eccentricity_rate.length(),
            ),
        };
        if delta > 0.0 {
            // |rate|, not the approach only: a step that grows as the journal moves out of the
            // wall and shrinks as it moves in pumps energy into a long contact's oscillation
            // (variable-step Verlet is not symplectic). On the paper's scene at 3T the journal
            // then lifted off where converged runs stay on the wall: 148 onsets per second
            // against 120 (docs/stepper-and-accuracy.md, "steps in a long contact").
            // The journal's path bound holds in contact too ([`flight_step`]): a contact whose
            // load turns, and a light one about to lift off, have a long period, and the
            // journal's path along the wall decides where it leaves it.
            return contact_step(rate.abs(), delta)
                .min(flight)
                .min(stable_fraction(tolerance) * r.max_stable_dt)
                .min(STABILITY_SAFETY * r.friction_stable_dt);
        }
        let gap = -delta;
        let accel = match self.previous_rate {
            Some(prev) if last_dt > 0.0 => (rate - prev) / last_dt,
            _ => 0.0,
        };
        // Smallest positive t with gap = rate t + accel t^2/2.
        let time_to_contact = if accel.abs() < 1e-300 {
            if rate > 0.0 {
                gap / rate
            } else {
                f64::INFINITY
            }
        } else {
            let disc = rate * rate + 2.0 * accel * gap;
            if disc < 0.0 {
                f64::INFINITY
            } else {
                (-rate + disc.sqrt()) / accel
            }
        };
        if !(time_to_contact > 0.0 && time_to_contact.is_finite()) {
            return flight;
        }
        let speed_at_contact = (rate + accel * time_to_contact).max(0.0);
        (APPROACH_FRACTION * time_to_contact)
            .max(contact_step(speed_at_contact, 0.0))
            .min(flight)
    }

    /// The step that resolves a contact now `depth` deep (m) whose journal moves at
    /// `approach_speed` (m/s) along the normal to `2 tolerance` of its natural period
    /// ([`CONTACT_PERIODS_PER_TOLERANCE`]), taken at the deepest point the contact can reach (its
    /// elastic energy plus that kinetic energy), and within the damped stability limit there. A
    /// spatial joint's contact carries the governing law's
    /// [`contact_share`](spatial::SpatialParts::contact_share): a tilted journal pressed at its
    /// edge is as stiff as the few stations that touch, not the whole width.
    fn contact_step(&self, approach_speed: f64, depth: f64, tolerance: f64) -> f64 {
        let law = self.governing_law();
        let share = self.spatial.as_ref().map_or(1.0, |p| p.contact_share());
        if share != 1.0 {
            let law = crate::model::spatial::Share { law, share };
            let elastic = law.elastic_energy(depth);
            return self.contact_step_of(&law, elastic, approach_speed, depth, tolerance);
        }
        // The planar joint's elastic energy at its own depth is known from its application.
        let elastic = if self.spatial.is_none() && depth == self.report.state.penetration {
            self.elastic_energy()
        } else {
            law.elastic_energy(depth)
        };
        self.contact_step_of(law, elastic, approach_speed, depth, tolerance)
    }

    /// [`contact_step`](Self::contact_step) for `law`, whose elastic energy at `depth` is
    /// `elastic` (J).
    fn contact_step_of(
        &self,
        law: &impl NormalForceLaw,
        elastic: f64,
        approach_speed: f64,
        depth: f64,
        tolerance: f64,
    ) -> f64 {
        let contact = ContactAhead {
            mass: self.report.effective_mass,
            approach_speed,
            depth,
            impact_rate: self.contact.in_contact.then_some(self.contact.impact_rate),
            min_impact_speed: self.min_impact_speed,
        };
        contact.resolving_step(law, elastic, tolerance, stable_fraction(tolerance))
    }

    /// Judges a step of `dt` that ended in the state of the last application, for a joint that
    /// was (`was_in_contact`) or was not in contact when the step began. `None` when the step
    /// resolved the contact; otherwise the shorter step to retry with:
    /// - the step went beyond the stability limit of the contact it ended in;
    /// - a contact began inside the step and got deeper than a step of the contact's own size
    ///   (`2 tolerance` of its period) would have let it: the step crossed the onset blind;
    /// - the step was longer than friction's limit ([`ClearanceReport::friction_stable_dt`]).
    pub fn judge_step(&self, dt: f64, tolerance: f64, was_in_contact: bool) -> Option<f64> {
        let r = &self.report;
        let delta = r.state.penetration;
        if !(delta > 0.0) || self.sub_cycled() {
            return None;
        }
        let limit = r.max_stable_dt.min(r.friction_stable_dt);
        if dt > limit {
            return Some((STABILITY_SAFETY * limit).min(0.5 * dt));
        }
        if was_in_contact {
            return None;
        }
        let rate = r.state.penetration_rate.max(0.0);
        let h_c = self.contact_step(rate, delta, tolerance);
        if dt <= h_c || delta <= rate * h_c {
            return None;
        }
        // Retry with a step that ends shortly before the onset (then the approach shrinks the
        // steps to the contact's own), or with the contact's own step.
        let inside = if rate > 0.0 { delta / rate } else { dt };
        let before = (dt - inside).max(0.0);
        Some(h_c.max(0.9 * before).min(0.5 * dt))
    }

    /// Saves the dynamic state into `d` (reusing its buffers).
    fn save_into(&self, d: &mut JointDynamics) {
        d.contact = self.contact;
        d.report = self.report;
        d.elastic.clone_from(&self.elastic);
        d.previous_rate = self.previous_rate;
        d.last_step = self.last_step;
        d.last_wrenches = self.last_wrenches;
        d.prepared = self.prepared;
        d.held = self.cycle.held;
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
        self.last_step = d.last_step;
        self.last_wrenches = d.last_wrenches;
        self.prepared = d.prepared;
        self.cycle.held = d.held;
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
        let contact_rate = self.contact_rate(&state, impact_rate, effective_mass, steps);
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

    /// The penetration rate for the normal law at `state` (whose rate is the bodies' stored one),
    /// `steps` the step before the last application's state and the step since: in contact, the
    /// rate at the state ([`StepBefore::carry`]), with the rest of the mechanism's acceleration from
    /// the last application ([`StepBefore`]); the stored rate without a contact, a known
    /// step or an earlier application.
    fn contact_rate(
        &self,
        state: &JournalState,
        impact_rate: f64,
        effective_mass: f64,
        steps: [f64; 2],
    ) -> f64 {
        let stored = state.penetration_rate;
        if !(state.penetration > 0.0 && self.prepared_report()) {
            return stored;
        }
        let c = NormalContact {
            penetration: state.penetration,
            penetration_rate: stored,
            impact_rate,
        };
        let (force, damping) = force_and_damping(&self.normal_law, &c);
        let before = StepBefore {
            rate: self.report.state.penetration_rate,
            force: self.report.force.normal_force,
            steps,
        };
        before.carry(stored, force, damping, effective_mass)
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
mod tests {
    use super::flight_step;

    #[test]
    fn flight_step_by_hand() {
        // 0.0075 of a 0.5 mm gap is 3.75 um: 3.75 us at 1 m/s, 0.9375 us at 4 m/s.
        assert!((flight_step(0.0075, 0.5e-3, 1.0) - 3.75e-6).abs() < 1e-18);
        assert!((flight_step(0.0075, 0.5e-3, 4.0) - 0.9375e-6).abs() < 1e-18);
        assert_eq!(flight_step(0.0075, 0.5e-3, 0.0), f64::INFINITY);
    }
}
