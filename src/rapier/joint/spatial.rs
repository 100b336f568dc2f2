//! The spatial model of a [`ClearanceJoint`]: every bore and face station of
//! [`crate::model::spatial`] carries its own contact history and force pair; the joint reports
//! the deepest station as its state (what the step control and the guards read) and the sums.

use super::{ClearanceJoint, ClearanceReport, ContactHistory, Mechanism, friction_slope, motion};
use crate::model::kinematics::{
    ForcePair, JournalState, StepBefore, contact_force, force_and_damping, stable_step,
};
use crate::model::laws::{NormalContact, NormalForceLaw, NormalModel, loaded_impact_rate};
use crate::model::spatial::{
    FACE_POINTS, Face, Share, SpatialModel, SpatialPose, bore_station, face_station,
};
use crate::rapier::ledger::{Wrench, world_center_of_mass};
use rapier3d_f64::math::AngularInertia;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{RigidBody, RigidBodySet};

/// What a spatial joint computed at its last application, beyond [`ClearanceReport`]'s
/// deepest-station state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpatialReport {
    /// The journal axis's tilt against the bore's about the bearing's two transverse axes, rad
    /// ([`SpatialPose::tilt`]).
    pub tilt: [f64; 2],
    /// The journal's axial offset from the bearing's centre along the bore's axis, m.
    pub axial_offset: f64,
    /// Normal force of the bore's inner stations (the width away from its edges), N.
    pub bore_force: f64,
    /// Normal force at the bore's edges (the end stations at `-L/2` and `+L/2`), N.
    pub edge_force: [f64; 2],
    /// Normal force of the shoulders on the lower and upper face, N.
    pub face_force: [f64; 2],
    /// Stations in contact (bore and faces).
    pub stations_in_contact: u32,
    /// Whether the deepest station (the report's `state`) is on a face.
    pub governed_by_face: bool,
}

/// Where a station of a spatial joint sits ([`SpatialStation::place`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StationPlace {
    /// A bore station in the bearing's plane at `s` (m from the bearing's centre along the
    /// bore's axis) carrying `share` of the bore law (the trapezoidal weight of its slice);
    /// `edge` 0 or 1 for the end stations at `-L/2` and `+L/2`, `None` inside.
    Bore {
        /// Axial position of the station's plane from the bearing's centre, m.
        s: f64,
        /// Share of the bore law the station carries (the shares add up to 1).
        share: f64,
        /// Which edge of the bore the station is (`None`: an inner station).
        edge: Option<usize>,
    },
    /// Point `index` (0 to [`FACE_POINTS`] - 1) of a shoulder ring against `face`.
    Face {
        /// The bearing face the ring meets.
        face: Face,
        /// The point on the ring.
        index: usize,
    },
}

use StationPlace as Place;

impl StationPlace {
    /// The law this station carries: its share of the bore's law `bore` (its slice's
    /// trapezoidal weight) or of the face law `face` (one ring point's).
    fn law<'a>(self, bore: &'a NormalModel, face: &'a NormalModel) -> Share<'a, NormalModel> {
        match self {
            Place::Bore { share, .. } => Share { law: bore, share },
            Place::Face { .. } => Share {
                law: face,
                share: 1.0 / FACE_POINTS as f64,
            },
        }
    }
}

/// One station of a spatial joint at the joint's last application
/// ([`ClearanceJoint::spatial_stations`]): the pressure distribution along the width is the bore
/// stations' `normal_force / share` against `s`, as a force per unit fraction of the width.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpatialStation {
    /// Where the station sits.
    pub place: StationPlace,
    /// The station's contact state (penetration, normal, rates, contact point), world frame.
    pub state: JournalState,
    /// Normal force the station applies, N (0 out of contact).
    pub normal_force: f64,
    /// Friction force the station applies, N.
    pub friction_force: f64,
}

/// One station's memory between steps.
#[derive(Clone, Copy, Debug)]
pub(super) struct Station {
    place: Place,
    contact: ContactHistory,
    state: Option<JournalState>,
    /// Normal and friction force at the last application, N.
    force: [f64; 2],
    /// This application's `delta_dot0` and the penetration rate the state before it had (NaN
    /// without one), between the evaluation's two passes.
    impact_rate: f64,
    rate_before: f64,
}

/// The spatial parts of a joint: model, face law, the bearing's transverse axis, stations.
#[derive(Clone, Debug)]
pub(super) struct SpatialParts {
    pub(super) model: SpatialModel,
    pub(super) face_law: NormalModel,
    /// A unit vector square to `local_axis1`, in body 1's frame.
    local_transverse1: Vector,
    pub(super) stations: Vec<Station>,
    pub(super) report: SpatialReport,
    /// Rate of the fastest station's path across its gap, relative to the gap (1/s).
    flight_rate: f64,
    /// The stations' summed contact stiffness over the governing law's whole stiffness at the
    /// deepest station's depth (1 in flight).
    contact_share: f64,
}

/// The stations' memory, saved before a step that may be rejected.
pub(super) type SpatialMemory = (Vec<Station>, SpatialReport, f64, f64);

impl SpatialParts {
    pub(super) fn new(
        model: SpatialModel,
        face_law: NormalModel,
        local_axis1: Vector,
        width: f64,
    ) -> Self {
        let n = model.geometry.slices as usize;
        let mut stations: Vec<Station> = model
            .geometry
            .bore_stations(width)
            .enumerate()
            .map(|(k, (s, share))| Station {
                place: Place::Bore {
                    s,
                    share,
                    edge: [(0, 0), (n, 1)]
                        .into_iter()
                        .find_map(|(end, e)| (k == end).then_some(e)),
                },
                contact: ContactHistory::default(),
                state: None,
                force: [0.0; 2],
                impact_rate: 0.0,
                rate_before: f64::NAN,
            })
            .collect();
        for face in Face::BOTH {
            stations.extend((0..FACE_POINTS).map(|index| Station {
                place: Place::Face { face, index },
                contact: ContactHistory::default(),
                state: None,
                force: [0.0; 2],
                impact_rate: 0.0,
                rate_before: f64::NAN,
            }));
        }
        SpatialParts {
            model,
            face_law,
            local_transverse1: local_axis1.any_orthonormal_vector(),
            stations,
            report: SpatialReport::default(),
            flight_rate: 0.0,
            contact_share: 1.0,
        }
    }

    pub(super) fn memory(&self) -> SpatialMemory {
        (
            self.stations.clone(),
            self.report,
            self.flight_rate,
            self.contact_share,
        )
    }

    pub(super) fn save_into(&self, memory: &mut SpatialMemory) {
        memory.0.clone_from(&self.stations);
        memory.1 = self.report;
        memory.2 = self.flight_rate;
        memory.3 = self.contact_share;
    }

    pub(super) fn restore(&mut self, memory: &SpatialMemory) {
        self.stations.clone_from(&memory.0);
        self.report = memory.1;
        self.flight_rate = memory.2;
        self.contact_share = memory.3;
    }

    pub(super) fn reset(&mut self) {
        for st in &mut self.stations {
            st.contact = ContactHistory::default();
            st.state = None;
            st.force = [0.0; 2];
        }
        self.report = SpatialReport::default();
        self.flight_rate = 0.0;
        self.contact_share = 1.0;
    }

    /// Elastic energy of all stations at the last application, J: each station in contact
    /// carries its share of the bore's law `bore_law` or of the face law. Evaluated on demand
    /// (a law of Liu's family integrates its force for its energy: too dear for every station at
    /// every step).
    pub(super) fn elastic_energy(&self, bore_law: &NormalModel) -> f64 {
        let mut energy = 0.0;
        for st in &self.stations {
            let Some(state) = st.state.filter(|_| st.force[0] > 0.0) else {
                continue;
            };
            energy += st
                .place
                .law(bore_law, &self.face_law)
                .elastic_energy(state.penetration);
        }
        energy
    }

    /// The share of the governing law the contact carries, for the contact's step
    /// ([`ClearanceJoint::adaptive_step`]): the stations' summed tangent stiffness over the
    /// whole law's at the deepest station's depth. 1 for an aligned journal pressed along the
    /// whole width (the planar joint's step), `1/(2N)` for a journal touching at one edge, 1 in
    /// flight (the approaching contact may take the whole width); above 1 when bore and faces
    /// are loaded together.
    pub(super) fn contact_share(&self) -> f64 {
        self.contact_share
    }

    /// The free-flight step: no station's path across its gap (the radial clearance for the
    /// bore, the axial play for the faces) moves more than `tolerance` of it in one step.
    pub(super) fn flight_step(&self, tolerance: f64) -> f64 {
        if self.flight_rate > 0.0 {
            tolerance / self.flight_rate
        } else {
            f64::INFINITY
        }
    }
}

impl ClearanceJoint {
    /// Where the joint's bearing (`rb1`, its body 1) and journal (`rb2`) are now, in world
    /// coordinates, with `transverse` (world, square to the bore's axis) as the first tilt axis
    /// of [`SpatialPose::tilt`]: the pose a spatial joint's stations are evaluated at (the
    /// joint's own transverse axis is fixed in body 1; a caller may measure the tilt about its
    /// own).
    pub fn spatial_pose(
        &self,
        rb1: &RigidBody,
        rb2: &RigidBody,
        transverse: Vector,
    ) -> SpatialPose {
        SpatialPose {
            bearing_center: *rb1.position() * self.local_anchor1,
            bearing_axis: *rb1.rotation() * self.local_axis1,
            bearing_transverse: transverse,
            journal_center: *rb2.position() * self.local_anchor2,
            journal_axis: *rb2.rotation() * self.local_axis2,
        }
    }

    /// A spatial joint's stations at its last application, bore stations first (from `-L/2` to
    /// `+L/2`), then the lower face's ring points, then the upper's; empty for a planar joint or
    /// before the first application. The bore stations' forces are the pressure distribution
    /// along the bearing's width (edge loading, a load off-centre along the width).
    pub fn spatial_stations(&self) -> impl Iterator<Item = SpatialStation> + '_ {
        self.spatial
            .iter()
            .flat_map(|parts| parts.stations.iter())
            .filter_map(|st| {
                st.state.map(|state| SpatialStation {
                    place: st.place,
                    state,
                    normal_force: st.force[0],
                    friction_force: st.force[1],
                })
            })
    }
}

/// Linearised contact sums over the stations in contact, for the step limits.
#[derive(Default)]
struct Linearised {
    stiffness: f64,
    damping: f64,
    /// Smallest stable step of a single station, s.
    single: f64,
    /// `sum F_N dmu/dv` over the stations (the tangential dampers along the slip in
    /// parallel), N s/m.
    friction: f64,
    /// `sum F_N mu/v` over the stations: friction's damping across the slip (`F_N dmu/dv` at
    /// zero slip), N s/m. The planar joint has no such direction (its lock holds the axial
    /// slip); here it is the journal's axial sliding, often the lightest tangential direction.
    friction_cross: f64,
    /// Smallest friction limit of a single station, s.
    friction_single: f64,
}

/// A body's inverse mass and world inverse inertia, evaluated once per application (the
/// stations ask for them dozens of times): `inverse_mass_along` as the ledger's, to the bit.
struct Mobility {
    inv_mass: f64,
    inv_inertia: AngularInertia,
    center_of_mass: Vector,
}

impl Mobility {
    /// `None` for a body that does not move under forces (fixed, kinematic).
    fn of(rb: &RigidBody) -> Option<Self> {
        rb.is_dynamic().then(|| {
            let mp = &rb.mass_properties().local_mprops;
            Mobility {
                inv_mass: mp.inv_mass,
                inv_inertia: mp.world_inv_inertia(rb.rotation()),
                center_of_mass: world_center_of_mass(rb),
            }
        })
    }
}

/// The two bodies' mobilities, and the mechanism around them.
struct Pair<'a>([Option<Mobility>; 2], &'a Mechanism);

impl Pair<'_> {
    /// `1/m` of the pair along `n` at `point` (as `ledger::inverse_mass_along` summed), less
    /// what the mechanism's ideal joints hold ([`Mechanism::inverse_mass`]).
    fn inverse_mass(&self, point: Vector, n: Vector) -> f64 {
        let along = |b: &Option<Mobility>| {
            b.as_ref().map_or(0.0, |b| {
                let rn = (point - b.center_of_mass).cross(n);
                b.inv_mass + rn.dot(b.inv_inertia * rn)
            })
        };
        let free = along(&self.0[0]) + along(&self.0[1]);
        self.1.inverse_mass(free, point, n)
    }

    fn effective_mass(&self, point: Vector, n: Vector) -> f64 {
        1.0 / self.inverse_mass(point, n)
    }
}

impl ClearanceJoint {
    /// The spatial joint's evaluation (the planar one is [`ClearanceJoint::evaluate`]'s own).
    ///
    /// Two passes over the stations: their states and contact histories, then their forces with
    /// the penetration rates carried to the state ([`StepBefore::carry`]): the stations in contact
    /// act in parallel on the same two bodies, so each carries its rate with the summed force
    /// and damping of all of them through the joint's effective mass (the planar joint's
    /// contact when the journal is aligned).
    pub(super) fn evaluate_spatial(
        &mut self,
        bodies: &RigidBodySet,
        steps: [f64; 2],
        mechanism: &Mechanism,
    ) -> Option<(Wrench, Wrench)> {
        let (rb1, rb2) = (bodies.get(self.body1)?, bodies.get(self.body2)?);
        let (m1, m2) = (motion(rb1), motion(rb2));
        let bodies = Pair([Mobility::of(rb1), Mobility::of(rb2)], mechanism);
        let transverse = *rb1.rotation() * self.spatial.as_ref()?.local_transverse1;
        let pose = self.spatial_pose(rb1, rb2, transverse);
        let parts = self.spatial.as_mut()?;
        let geometry = &self.geometry;
        let spatial = parts.model.geometry;
        let (c, a) = (geometry.clearance(), spatial.axial_play);
        let mut report = SpatialReport {
            tilt: pose.tilt(),
            axial_offset: pose.axial_offset(),
            ..SpatialReport::default()
        };
        let mut totals = Totals::default();
        let mut lin = Linearised {
            single: f64::INFINITY,
            friction_single: f64::INFINITY,
            ..Linearised::default()
        };
        let (mut flight_rate, mut stiffness_sum) = (0.0_f64, 0.0);
        // Where the stations' normal forces act on average (weighted by force), for the joint's
        // effective mass: the stations act in parallel on the same two bodies.
        let (mut load_point, mut load) = (Vector::ZERO, 0.0);
        // The deepest station: (index, state, impact rate, the rate its law was given).
        let mut deepest: Option<(usize, JournalState, f64, f64)> = None;
        // The stations' forces and dampings at their stored rates, and the force they applied
        // over the step that led here, for the rates at the state.
        let mut carry = Carry::default();
        for st in parts.stations.iter_mut() {
            let (state, gap_scale) = match st.place {
                Place::Bore { s, .. } => (bore_station(geometry, &pose, s, &m1, &m2), c),
                Place::Face { face, index } => (
                    face_station(geometry, &spatial, &pose, face, index, &m1, &m2),
                    a,
                ),
            };
            let law = st.place.law(&self.normal_law, &parts.face_law);
            flight_rate = flight_rate.max(state.eccentricity_rate.length() / gap_scale);
            st.contact.advance(
                st.state.as_ref(),
                &state,
                self.min_impact_speed,
                self.min_separation,
            );
            st.rate_before = st.state.map_or(f64::NAN, |s| s.penetration_rate);
            st.state = Some(state);
            st.impact_rate = station_impact_rate(&st.contact, &law, state.penetration, || {
                bodies.effective_mass(whole_centre(&pose, st.place, &state), state.normal)
            });
            carry.add(&law, &state, st.impact_rate, st.force[0]);
        }
        let carry_mass = carry.effective_mass(&bodies);
        for (i, st) in parts.stations.iter_mut().enumerate() {
            let Some(stored) = st.state else { continue };
            let law = st.place.law(&self.normal_law, &parts.face_law);
            let impact_rate = st.impact_rate;
            let state = JournalState {
                penetration_rate: carry.rate_at_state(&stored, st.rate_before, carry_mass, steps),
                ..stored
            };
            let pair = contact_force(&state, impact_rate, &law, &self.friction_law);
            if deepest.is_none_or(|d| stored.penetration > d.1.penetration) {
                deepest = Some((i, stored, impact_rate, state.penetration_rate));
            }
            st.force = [pair.normal_force.max(0.0), pair.friction_force];
            if pair.normal_force <= 0.0 {
                continue;
            }
            stiffness_sum += law.tangent_stiffness(state.penetration);
            load_point += pair.normal_force * pair.point;
            load += pair.normal_force;
            report.add(st.place, pair.normal_force);
            totals.add(&state, &pair, [m1.center_of_mass, m2.center_of_mass]);
            // The stability limit at the stored rate, as the planar joint's.
            linearise(
                &mut lin,
                &law,
                &stored,
                impact_rate,
                &pair,
                &self.friction_law,
                &bodies,
            );
        }
        let (index, state, impact_rate, contact_rate) = deepest?;
        let governing = parts.stations[index].place;
        report.governed_by_face = matches!(governing, Place::Face { .. });
        // The joint's effective mass along the deepest station's normal: at the load's centre
        // in contact; in flight the deepest station's whole-contact mass (an aligned journal is
        // then the planar joint, whose contact sits on the mid-plane).
        let m = if load > 0.0 {
            bodies.effective_mass(load_point / load, state.normal)
        } else {
            bodies.effective_mass(whole_centre(&pose, governing, &state), state.normal)
        };
        parts.report = report;
        parts.flight_rate = flight_rate;
        let governing_law = match governing {
            Place::Bore { .. } => &self.normal_law,
            Place::Face { .. } => &parts.face_law,
        };
        let whole = governing_law.tangent_stiffness(state.penetration);
        parts.contact_share = if load > 0.0 && whole > 0.0 && stiffness_sum > 0.0 {
            stiffness_sum / whole
        } else {
            1.0
        };

        // The joint's own history follows the deepest station: its gap is the joint's gap.
        let previous = self.prepared_report().then_some(self.report.state);
        let onset = self.contact.advance(
            previous.as_ref(),
            &state,
            self.min_impact_speed,
            self.min_separation,
        );
        let mode = self.contact.mode();
        // (The load's centre is read only when a station is in contact, `load > 0`.)
        let (max_stable_dt, omega, zeta, friction_stable_dt) =
            step_limits(&lin, m, &state, &pose, &bodies, load_point / load);
        if self.prepared_report() {
            self.previous_rate = Some(self.report.state.penetration_rate);
        }
        self.report = ClearanceReport {
            state,
            mode,
            onset: onset.onset,
            impact: onset.impact,
            impact_rate,
            approach_speed: onset.approach_speed,
            contact_rate,
            onset_fraction: onset.fraction,
            force: ForcePair {
                on_journal: totals.force,
                point: state.contact_point,
                normal_force: totals.normal.length(),
                friction_force: totals.friction.length(),
            },
            max_stable_dt,
            friction_stable_dt,
            omega,
            zeta,
            effective_mass: m,
            spatial: Some(report),
        };
        let w1 = Wrench {
            body: self.body1,
            force: -totals.force,
            torque: totals.torque[0],
        };
        let w2 = Wrench {
            body: self.body2,
            force: totals.force,
            torque: totals.torque[1],
        };
        Some((w1, w2))
    }
}

/// What the stations carry their rates to the state with ([`StepBefore::carry`]): their normal
/// forces and dampings at the stored rates, the normal force they applied over the step that led
/// here, and where the load acts (for the effective mass).
#[derive(Default)]
struct Carry {
    force: f64,
    damping: f64,
    force_before: f64,
    load_point: Vector,
    normal: Vector,
}

impl Carry {
    /// Adds a station at `state` (its stored rate), whose normal force over the last step was
    /// `force_before` (N).
    fn add(
        &mut self,
        law: &impl NormalForceLaw,
        state: &JournalState,
        impact_rate: f64,
        force_before: f64,
    ) {
        self.force_before += force_before;
        if !(state.penetration > 0.0) {
            return;
        }
        let c = NormalContact {
            penetration: state.penetration,
            penetration_rate: state.penetration_rate,
            impact_rate,
        };
        let (force, damping) = force_and_damping(law, &c);
        self.force += force;
        self.damping += damping;
        self.load_point += force * state.contact_point;
        self.normal += force * state.normal;
    }

    /// The effective mass at the load's centre along its mean normal (0 without a load).
    fn effective_mass(&self, bodies: &Pair) -> f64 {
        let n = self.normal.length();
        if self.force > 0.0 && n > 0.0 {
            bodies.effective_mass(self.load_point / self.force, self.normal / n)
        } else {
            0.0
        }
    }

    /// The penetration rate of a station at `state` (its stored rate; `rate_before` the state
    /// before it had, NaN if none) at the state: in contact with a known step, the stored
    /// rate carried by the stations' summed force and damping; the stored rate otherwise.
    fn rate_at_state(
        &self,
        state: &JournalState,
        rate_before: f64,
        m: f64,
        steps: [f64; 2],
    ) -> f64 {
        let stored = state.penetration_rate;
        if !(state.penetration > 0.0 && m > 0.0 && rate_before.is_finite()) {
            return stored;
        }
        let before = StepBefore {
            rate: rate_before,
            force: self.force_before,
            steps,
        };
        before.carry(stored, self.force, self.damping, m)
    }
}

/// The stations' force pairs summed: the force on the journal, its normal and friction parts, and
/// the torque on each body about its centre of mass.
#[derive(Default)]
struct Totals {
    force: Vector,
    normal: Vector,
    friction: Vector,
    torque: [Vector; 2],
}

impl Totals {
    /// Adds one station's pair; `centres` are the bearing's and the journal's centres of mass.
    fn add(&mut self, state: &JournalState, pair: &ForcePair, centres: [Vector; 2]) {
        self.force += pair.on_journal;
        self.normal -= pair.normal_force * state.normal;
        self.friction += pair.on_journal + pair.normal_force * state.normal;
        self.torque[1] += (pair.point - centres[1]).cross(pair.on_journal);
        self.torque[0] += (pair.point - centres[0]).cross(-pair.on_journal);
    }
}

impl SpatialReport {
    /// Adds a station's normal force to its kind's total.
    fn add(&mut self, place: Place, normal_force: f64) {
        self.stations_in_contact += 1;
        match place {
            Place::Bore { edge: Some(e), .. } => self.edge_force[e] += normal_force,
            Place::Bore { edge: None, .. } => self.bore_force += normal_force,
            Place::Face { face, .. } => self.face_force[face as usize] += normal_force,
        }
    }
}

/// The joint's stability and friction limits from the stations' linearised sums, against the
/// effective mass `m` at the load's centre `centre`: `(max_stable_dt, omega, zeta,
/// friction_stable_dt)`. Each station's own limit holds too.
fn step_limits(
    lin: &Linearised,
    m: f64,
    state: &JournalState,
    pose: &SpatialPose,
    bodies: &Pair,
    centre: Vector,
) -> (f64, f64, f64, f64) {
    let (max_stable_dt, omega, zeta) = if lin.stiffness > 0.0 || lin.damping > 0.0 {
        let (dt, omega, zeta) = stable_step(lin.stiffness, lin.damping, m);
        (dt.min(lin.single), omega, zeta)
    } else {
        (f64::INFINITY, 0.0, 0.0)
    };
    let friction_stable_dt = if lin.friction > 0.0 || lin.friction_cross > 0.0 {
        // The tangential dampers act in parallel at the load's centre (as the normal's
        // effective mass; the planar joint's point when the journal is aligned), along the slip
        // and across it.
        let t = friction_direction(state, pose.bearing_axis);
        let along = 2.0 / (bodies.inverse_mass(centre, t) * lin.friction);
        let across =
            2.0 / (bodies.inverse_mass(centre, state.normal.cross(t)) * lin.friction_cross);
        along.min(across).min(lin.friction_single)
    } else {
        f64::INFINITY
    };
    (max_stable_dt, omega, zeta, friction_stable_dt)
}

/// The point where the whole contact would act were it at this station: on the bearing's
/// mid-plane for a bore station (where the planar joint's contact sits), on the axis for a
/// shoulder point (an axial knock's). Its effective mass is the whole contact's.
fn whole_centre(pose: &SpatialPose, place: Place, state: &JournalState) -> Vector {
    match place {
        Place::Bore { s, .. } => state.contact_point - s * pose.bearing_axis,
        Place::Face { .. } => {
            let r = state.contact_point - pose.bearing_center;
            pose.bearing_center + r.dot(pose.bearing_axis) * pose.bearing_axis
        }
    }
}

/// `delta_dot0` for a station's law in its current contact (as
/// [`ClearanceJoint::law_impact_rate`] for the planar joint): a loaded contact's rate is the
/// speed of a free impact of the whole contact (the whole law, `effective_mass` the whole
/// contact's) reaching the station's depth. The station's share of the energy over its share
/// of the mass is the same ratio; the planar joint's when the journal is aligned.
fn station_impact_rate(
    contact: &ContactHistory,
    law: &Share<'_, NormalModel>,
    depth: f64,
    effective_mass: impl FnOnce() -> f64,
) -> f64 {
    if contact.in_contact && law.uses_impact_rate() {
        contact.impact_rate.max(loaded_impact_rate(
            law.law.elastic_energy(depth),
            effective_mass(),
        ))
    } else {
        contact.impact_rate
    }
}

/// The slip direction, or a tangent when the station does not slip.
fn friction_direction(state: &JournalState, axis: Vector) -> Vector {
    let v = state.slip.length();
    if v > 0.0 {
        state.slip / v
    } else {
        let t = state.normal.cross(axis);
        let len = t.length();
        if len > 1e-9 {
            t / len
        } else {
            state.normal.any_orthonormal_vector()
        }
    }
}

/// Adds one station in contact to the linearised sums (stiffness, damping, friction slope) and
/// to the single-station limits.
fn linearise(
    lin: &mut Linearised,
    law: &impl NormalForceLaw,
    state: &JournalState,
    impact_rate: f64,
    pair: &ForcePair,
    friction: &impl crate::model::laws::FrictionLaw,
    bodies: &Pair,
) {
    let m = bodies.effective_mass(state.contact_point, state.normal);
    let c = NormalContact {
        penetration: state.penetration,
        penetration_rate: state.penetration_rate,
        impact_rate,
    };
    // dF/d delta = K_tangent + (dD/d delta) delta_dot (as the planar joint).
    let k =
        law.tangent_stiffness(state.penetration) + law.damping_slope(&c) * state.penetration_rate;
    let d = law.damping_coefficient(&c);
    lin.stiffness += k;
    lin.damping += d;
    lin.single = lin.single.min(stable_step(k, d, m).0);
    // Friction `mu(v) F_N v/|v|` linearised: `F_N dmu/dv` along the slip, `F_N mu/v` across
    // it (both `F_N dmu/dv(0)` at zero slip). Past the static peak `dmu/dv < 0` and only the
    // cross term damps; it is what the explicit step must resolve (Bai's law just past `v_s`:
    // `mu_s/v_s`, 3000 s/m dry).
    let v = state.slip.length();
    let slope = friction_slope(friction, v);
    let cross = if v > 0.0 {
        friction.coefficient(v) / v
    } else {
        slope
    };
    let t = friction_direction(state, state.normal.any_orthonormal_vector());
    let inv_m = |t| bodies.inverse_mass(state.contact_point, t);
    if slope > 0.0 {
        lin.friction += pair.normal_force * slope;
        lin.friction_single = lin
            .friction_single
            .min(2.0 / (inv_m(t) * pair.normal_force * slope));
    }
    if cross > 0.0 {
        lin.friction_cross += pair.normal_force * cross;
        lin.friction_single = lin
            .friction_single
            .min(2.0 / (inv_m(state.normal.cross(t)) * pair.normal_force * cross));
    }
}
