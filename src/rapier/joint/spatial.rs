//! The spatial model of a [`ClearanceJoint`]: four contact regions (the bore at each end, each
//! face), each with its own contact history and impact rate, their laws integrated over the
//! regions' quadrature points ([`crate::model::spatial`]). The joint reports the deepest
//! region's deepest point as its state (what the step control and the guards read) and the
//! regions' resultants.

use super::{ClearanceJoint, ClearanceReport, ContactHistory, Mechanism, friction_slope, motion};
use crate::model::kinematics::{BodyMotion, ForcePair, JournalState, stable_step};
use crate::model::laws::loaded_impact_rate;
use crate::model::laws::{FrictionLaw, NormalContact, NormalForceLaw, NormalModel};
use crate::model::spatial::{
    ContactPoint, End, Shoulder, SpatialModel, SpatialPose, bore_points, bore_region, bore_section,
};
use crate::rapier::pipeline::ledger::{Wrench, world_center_of_mass};
use rapier3d_f64::math::{AngularInertia, Vector};
use rapier3d_f64::prelude::{RigidBody, RigidBodySet};

pub(super) mod subcycle;

/// What a spatial joint computed at its last application, beyond [`ClearanceReport`]'s
/// deepest point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpatialReport {
    /// The journal axis's tilt against the bore's about the bearing's two transverse axes, rad
    /// ([`SpatialPose::tilt`]).
    pub tilt: [f64; 2],
    /// The journal's axial offset from the bearing's centre along the bore's axis, m.
    pub axial_offset: f64,
    /// Normal force of the whole bore (both ends' regions), N.
    pub bore_force: f64,
    /// Normal resultant of the bore's region at each end (`-L/2`, `+L/2`), N: the line load
    /// integrated from the edge to where the penetration vanishes, or to the plane of least
    /// penetration when the whole width touches.
    pub edge_force: [f64; 2],
    /// Where each end's resultant acts (world; the centre of its normal forces), the bearing's
    /// centre when it carries nothing.
    pub edge_point: [Vector; 2],
    /// Length of each end's region along the width, m (0 out of contact).
    pub edge_length: [f64; 2],
    /// The fraction of the width the bore touches (the two regions' lengths over `L`): below 1
    /// the journal bears on an edge.
    pub bore_contact_width: f64,
    /// Normal resultant of the shoulders on the lower and upper face, N.
    pub face_force: [f64; 2],
    /// Where each face's resultant acts (world), the bearing's centre when it carries nothing.
    pub face_point: [Vector; 2],
    /// Quadrature points in contact (bore and faces).
    pub points_in_contact: u32,
    /// Whether the deepest point (the report's `state`) is on a face.
    pub governed_by_face: bool,
    /// Power the contacts' damping and friction dissipate at this state, W (their damping
    /// force times the penetration rate, and friction times the slip, summed over the points).
    pub dissipation_power: f64,
}

/// A contact region of a spatial joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Region {
    /// The bore's region touching that end of the width.
    Bore(End),
    /// The shoulder against that end's face.
    Face(End),
}

impl Region {
    /// The four regions: the bore at each end, then the faces.
    pub const ALL: [Region; 4] = [
        Region::Bore(End::Lower),
        Region::Bore(End::Upper),
        Region::Face(End::Lower),
        Region::Face(End::Upper),
    ];

    /// The law the region carries: the bore's `bore` or the faces' `face`.
    fn law<'a>(self, bore: &'a NormalModel, face: &'a NormalModel) -> &'a NormalModel {
        match self {
            Region::Bore(_) => bore,
            Region::Face(_) => face,
        }
    }
}

/// One quadrature point of a spatial joint at its last application
/// ([`ClearanceJoint::spatial_points`]). The bore's points give the line load along the width:
/// `normal_force / contact.weight` is the force the whole bore would carry at that point's
/// penetration, so its plot against `s` is the pressure distribution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpatialPoint {
    /// The region the point belongs to.
    pub region: Region,
    /// Axial position of the point from the bearing's centre along the bore's axis, m.
    pub s: f64,
    /// Its penetration, gradient, surface point and share of the region's law.
    pub contact: ContactPoint,
    /// The penetration rate the law was given (at the state), m/s.
    pub penetration_rate: f64,
    /// The sliding velocity at the point square to its normal, m/s.
    pub slip: Vector,
    /// Normal force the point applies (its share), N.
    pub normal_force: f64,
    /// Friction force the point applies, N.
    pub friction_force: f64,
}

/// One region's memory between steps.
#[derive(Clone, Copy, Debug)]
pub(super) struct Patch {
    region: Region,
    contact: ContactHistory,
    /// The region's deepest point as a contact state.
    state: Option<JournalState>,
    /// Normal resultant at the last application, N.
    force: f64,
    /// This application's `delta_dot0`, and the penetration rate the state before had (NaN
    /// without one).
    impact_rate: f64,
    rate_before: f64,
}

impl Patch {
    fn new(region: Region) -> Self {
        Patch {
            region,
            contact: ContactHistory::default(),
            state: None,
            force: 0.0,
            impact_rate: 0.0,
            rate_before: f64::NAN,
        }
    }
}

/// The spatial parts of a joint: model, face law, the bearing's transverse axis, regions and
/// their points.
#[derive(Clone, Debug)]
pub(super) struct SpatialParts {
    pub(super) model: SpatialModel,
    pub(super) face_law: NormalModel,
    /// A unit vector square to `local_axis1`, in body 1's frame.
    local_transverse1: Vector,
    patches: [Patch; 4],
    points: Vec<SpatialPoint>,
    /// Scratch for the bore's points.
    bore_scratch: Vec<(f64, ContactPoint)>,
    face_scratch: Vec<ContactPoint>,
    pub(super) report: SpatialReport,
    /// Rate of the fastest region's path across its gap, relative to the gap (1/s).
    flight_rate: f64,
    /// The regions' summed contact stiffness over the governing law's whole stiffness at the
    /// deepest point's depth (1 in flight).
    contact_share: f64,
}

/// The regions' memory, saved before a step that may be rejected.
pub(super) type SpatialMemory = ([Patch; 4], Vec<SpatialPoint>, SpatialReport, f64, f64);

impl SpatialParts {
    pub(super) fn new(model: SpatialModel, face_law: NormalModel, local_axis1: Vector) -> Self {
        SpatialParts {
            model,
            face_law,
            local_transverse1: local_axis1.any_orthonormal_vector(),
            patches: Region::ALL.map(Patch::new),
            points: Vec::new(),
            bore_scratch: Vec::new(),
            face_scratch: Vec::new(),
            report: SpatialReport::default(),
            flight_rate: 0.0,
            contact_share: 1.0,
        }
    }

    pub(super) fn memory(&self) -> SpatialMemory {
        (
            self.patches,
            self.points.clone(),
            self.report,
            self.flight_rate,
            self.contact_share,
        )
    }

    pub(super) fn save_into(&self, memory: &mut SpatialMemory) {
        memory.0 = self.patches;
        memory.1.clone_from(&self.points);
        memory.2 = self.report;
        memory.3 = self.flight_rate;
        memory.4 = self.contact_share;
    }

    pub(super) fn restore(&mut self, memory: &SpatialMemory) {
        self.patches = memory.0;
        self.points.clone_from(&memory.1);
        self.report = memory.2;
        self.flight_rate = memory.3;
        self.contact_share = memory.4;
    }

    pub(super) fn reset(&mut self) {
        self.patches = Region::ALL.map(Patch::new);
        self.points.clear();
        self.report = SpatialReport::default();
        self.flight_rate = 0.0;
        self.contact_share = 1.0;
    }

    /// Elastic energy of the regions at the last application, J: every point's share of its
    /// law's energy at its penetration. Evaluated on demand (a law of Liu's family integrates
    /// its force for its energy: too dear for every point at every step).
    pub(super) fn elastic_energy(&self, bore_law: &NormalModel) -> f64 {
        self.points
            .iter()
            .map(|p| {
                let law = p.region.law(bore_law, &self.face_law);
                p.contact.weight * law.elastic_energy(p.contact.depth)
            })
            .sum()
    }

    /// The share of the governing law the contact carries, for the contact's step
    /// ([`ClearanceJoint::adaptive_step`]): the regions' summed tangent stiffness over the
    /// whole law's at the deepest point's depth. 1 for an aligned journal pressed along the
    /// whole width (the planar joint's step), small for a journal touching at one edge, 1 in
    /// flight (the approaching contact may take the whole width); above 1 when bore and faces
    /// are loaded together.
    pub(super) fn contact_share(&self) -> f64 {
        self.contact_share
    }

    /// The free-flight step: no region's deepest point moves across its gap (the radial
    /// clearance for the bore, the axial play for the faces) more than `tolerance` of it in
    /// one step.
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
    /// of [`SpatialPose::tilt`]: the pose a spatial joint's contacts are evaluated at (the
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

    /// Whether a spatial joint can start from the bodies' poses: its journal's axis must lie in
    /// its bore (a tilt whose edges alone would press past the law's validity is refused, naming
    /// `local_axis2`). Planar joints pass: their lock aligns the axes.
    pub fn check_start(&self, rb1: &RigidBody, rb2: &RigidBody) -> crate::error::Result<()> {
        if self.spatial.is_none() {
            return Ok(());
        }
        let pose = self.spatial_pose(rb1, rb2, Vector::X);
        let sin = pose.bearing_axis.cross(pose.journal_axis).length();
        let g = &self.geometry;
        let edge = 0.5 * g.length() * sin - g.clearance();
        if edge <= self.max_valid_penetration() {
            return Ok(());
        }
        let sig4 = crate::error::sig4;
        Err(crate::error::Error::invalid(
            "local_axis2",
            format!(
                "puts the journal's axis {} deg from the bore's at the bodies' poses; the bore \
                 lets it tilt {} deg (2c/L), so its edges would start {} um deep, past the law's \
                 validity {} um: give axes that match at the poses (`local_axis1` in body 1's \
                 frame, `local_axis2` in body 2's)",
                sig4(sin.asin().to_degrees()),
                sig4((2.0 * g.clearance() / g.length()).atan().to_degrees()),
                sig4(edge * 1e6),
                sig4(self.max_valid_penetration() * 1e6)
            ),
        ))
    }

    /// A spatial joint's quadrature points in contact at its last application, region by
    /// region ([`Region::ALL`]'s order); empty for a planar joint or out of contact.
    pub fn spatial_points(&self) -> &[SpatialPoint] {
        self.spatial.as_ref().map_or(&[], |parts| &parts.points)
    }
}

/// A body's inverse mass and world inverse inertia, evaluated once per application:
/// `inverse_mass_along` as the ledger's, to the bit.
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

    /// The contact row of a unit force pair along `n` at `point` over the pair's 12
    /// coordinates `[v_1, w_1, v_2, w_2]`: `delta_dot = row . velocities` (zero for a body that
    /// does not move).
    fn row(&self, point: Vector, n: Vector) -> [f64; 12] {
        let mut j = [0.0; 12];
        for (k, sign) in [(0usize, -1.0), (1, 1.0)] {
            let Some(b) = &self.0[k] else { continue };
            let lin = sign * n;
            let ang = (point - b.center_of_mass).cross(lin);
            j[6 * k..6 * k + 3].copy_from_slice(&[lin.x, lin.y, lin.z]);
            j[6 * k + 3..6 * k + 6].copy_from_slice(&[ang.x, ang.y, ang.z]);
        }
        j
    }

    /// `a^T W b`, `W` the pair's mobility less what the mechanism's ideal joints hold: the rate
    /// a load `b` drives along a load `a` (kg^-1 for unit loads).
    fn between(&self, a: &[f64; 12], b: &[f64; 12]) -> f64 {
        let mut free = 0.0;
        for (k, body) in self.0.iter().enumerate() {
            let Some(body) = body else { continue };
            let v = |x: &[f64; 12], o: usize| Vector::new(x[o], x[o + 1], x[o + 2]);
            let (al, aa, bl, ba) = (v(a, 6 * k), v(a, 6 * k + 3), v(b, 6 * k), v(b, 6 * k + 3));
            free += body.inv_mass * al.dot(bl) + aa.dot(body.inv_inertia * ba);
        }
        free - self.1.held_between(a, b)
    }
}

/// A point's contact state for the laws: its penetration, the rate along its gradient, the
/// unit normal and the slip square to it.
fn point_state(
    contact: &ContactPoint,
    eccentricity: Vector,
    eccentricity_rate: Vector,
    bodies: [&BodyMotion; 2],
) -> JournalState {
    let v_rel = bodies[1].velocity_at(contact.point) - bodies[0].velocity_at(contact.point);
    let normal = contact.gradient.normalize();
    let along = v_rel.dot(normal);
    JournalState {
        eccentricity,
        normal,
        penetration: contact.depth,
        penetration_rate: v_rel.dot(contact.gradient),
        slip: v_rel - along * normal,
        eccentricity_rate,
        contact_point: contact.point,
    }
}

/// A region's deepest point as a contact state, and its gap scale (the radial clearance for the
/// bore, the axial play for a face): its path across the gap bounds the free-flight step.
fn deepest_state(
    joint: &ClearanceJoint,
    spatial: &crate::model::spatial::SpatialGeometry,
    pose: &SpatialPose,
    region: Region,
    bodies: [&BodyMotion; 2],
) -> (JournalState, f64) {
    let geometry = &joint.geometry;
    let ai = pose.bearing_axis;
    match region {
        Region::Bore(end) => {
            let section = bore_section(geometry, pose, end.sign() * 0.5 * geometry.length());
            let centres = bodies[1].velocity_at(section.crossing)
                - bodies[0].velocity_at(section.plane_center);
            let rate = centres - centres.dot(ai) * ai;
            let state = point_state(&section.contact, section.eccentricity, rate, bodies);
            (state, geometry.clearance())
        }
        Region::Face(end) => {
            let shoulder = Shoulder::at(geometry, spatial, pose, end);
            let centres = bodies[1].velocity_at(pose.journal_center)
                - bodies[0].velocity_at(pose.bearing_center);
            let eccentricity = (pose.axial_offset() * -end.sign()) * shoulder.normal;
            let rate = centres.dot(ai) * ai;
            let state = point_state(&shoulder.deepest_point(), eccentricity, rate, bodies);
            (state, spatial.axial_play)
        }
    }
}

/// Appends the quadrature points of `region` in contact to the parts' points (with their
/// stored rates); returns the region's length along the width (0 for a face).
fn region_points(
    joint: &ClearanceJoint,
    parts: &mut SpatialParts,
    pose: &SpatialPose,
    region: Region,
    bodies: [&BodyMotion; 2],
) -> f64 {
    let geometry = &joint.geometry;
    let ai = pose.bearing_axis;
    let push = |contact: ContactPoint, s: f64, out: &mut Vec<SpatialPoint>| {
        if contact.depth > 0.0 {
            let v_rel = bodies[1].velocity_at(contact.point) - bodies[0].velocity_at(contact.point);
            let normal = contact.gradient.normalize();
            out.push(SpatialPoint {
                region,
                s,
                contact,
                penetration_rate: v_rel.dot(contact.gradient),
                slip: v_rel - v_rel.dot(normal) * normal,
                normal_force: 0.0,
                friction_force: 0.0,
            });
        }
    };
    match region {
        Region::Bore(end) => {
            let Some(r) = bore_region(geometry, pose, end) else {
                return 0.0;
            };
            parts.bore_scratch.clear();
            bore_points(geometry, pose, &r, &mut parts.bore_scratch);
            for &(s, c) in &parts.bore_scratch {
                push(c, s, &mut parts.points);
            }
            r.length()
        }
        Region::Face(end) => {
            let shoulder = Shoulder::at(geometry, &parts.model.geometry, pose, end);
            parts.face_scratch.clear();
            shoulder.points(&mut parts.face_scratch);
            for &c in &parts.face_scratch {
                let s = (c.point - pose.bearing_center).dot(ai);
                push(c, s, &mut parts.points);
            }
            0.0
        }
    }
}

/// A region's elastic load: its row (the sum of its points' elastic forces times their contact
/// rows, the generalised load it puts on the pair), its total, where and along what it acts on
/// average, and its elastic energy when the law reads the impact rate.
struct Load {
    row: [f64; 12],
    total: f64,
    centre: Vector,
    direction: Vector,
    energy: f64,
}

impl Load {
    /// The load of `points` under `law` (`deepest` standing in without an elastic force).
    fn of(points: &[SpatialPoint], law: &NormalModel, deepest: &JournalState, pair: &Pair) -> Self {
        let mut load = Load {
            row: [0.0; 12],
            total: 0.0,
            centre: deepest.contact_point,
            direction: deepest.normal,
            energy: 0.0,
        };
        let (mut moment, mut direction) = (Vector::ZERO, Vector::ZERO);
        let needs_energy = law.uses_impact_rate();
        for p in points {
            let f = p.contact.weight * law.elastic_force(p.contact.depth);
            if needs_energy {
                load.energy += p.contact.weight * law.elastic_energy(p.contact.depth);
            }
            if !(f > 0.0) {
                continue;
            }
            let row = pair.row(p.contact.point, p.contact.gradient);
            for (r, j) in load.row.iter_mut().zip(row) {
                *r += f * j;
            }
            moment += f * p.contact.point;
            direction += f * p.contact.gradient;
            load.total += f;
        }
        let length = direction.length();
        if load.total > 0.0 && length > 0.0 {
            load.centre = moment / load.total;
            load.direction = direction / length;
        }
        load
    }
}

/// Each region's effective mass with every region's load acting: the rate the loads together
/// drive along region `p`'s, `a_p = sum_q R_p . W R_q / F_p`, against its own load,
/// `m_p = F_p/a_p` (`R` the loads' rows, `W` the pair's mobility through the mechanism). Two
/// halves of an aligned journal's width each move half the planar joint's mass with half its
/// force; a tilted journal's two edges move as the rocking they make together. A region without
/// an elastic load takes the mass at its deepest point; the coupled inverse mass is floored at
/// 1e-3 of the region's own (loads that hold each other still).
fn coupled_masses(loads: &[Load; 4], pair: &Pair) -> [f64; 4] {
    std::array::from_fn(|p| {
        let load = &loads[p];
        if !(load.total > 0.0) {
            return pair.effective_mass(load.centre, load.direction);
        }
        let own = pair.between(&load.row, &load.row);
        let coupled: f64 = loads.iter().map(|q| pair.between(&load.row, &q.row)).sum();
        let inverse = coupled.max(1e-3 * own) / (load.total * load.total);
        if inverse > 0.0 && inverse.is_finite() {
            1.0 / inverse
        } else {
            pair.effective_mass(load.centre, load.direction)
        }
    })
}

/// What the regions add up to at one application: wrenches, the linearised contact for the
/// step limits (each region's stiffness, damping and friction slopes through its own effective
/// mass: their sum bounds the stiffest mode, [`step_limits`]), and the dissipated power.
#[derive(Default)]
struct Totals {
    force: Vector,
    normal: Vector,
    friction: Vector,
    torque: [Vector; 2],
    /// `sum k_r` (the laws' tangent stiffness), `sum k_r/m_r` (with the damping's slope; each
    /// region's own mass: the trace bound), `sum d_r/m_r`, `sum (friction slopes)/m_r`.
    stiffness: f64,
    stiffness_over_mass: f64,
    /// The loads' own mode (the accelerations `a_r = F_r/m_r` they drive together, coupled
    /// masses): `sum F_r a_r` and `sum k_r a_r^2`, its Rayleigh quotient's denominator and
    /// numerator.
    mode_load: f64,
    mode_stiffness: f64,
    damping_over_mass: f64,
    friction_over_mass: f64,
    dissipation: f64,
}

/// One region's sums over its points at the final rates.
#[derive(Default)]
struct RegionForces {
    normal: f64,
    law_force: f64,
    moment: Vector,
    /// The law's tangent stiffness summed (the contact's own step), and the same with the
    /// damping's change with depth at the point's rate (its stability), N/m.
    tangent: f64,
    stiffness: f64,
    damping: f64,
    friction_along: f64,
    friction_across: f64,
}

impl ClearanceJoint {
    /// The spatial joint's evaluation (the planar one is [`ClearanceJoint::evaluate`]'s own).
    ///
    /// Region by region: its deepest point moves its contact history; its points' forces take
    /// the region's impact rate (a loaded region's raised to the speed of a free impact of that
    /// region storing its energy, through its mass with every region's load acting), with the
    /// penetration rates carried to the state by all regions together
    /// ([`carried_rates`](Self::carried_rates)).
    pub(super) fn evaluate_spatial(
        &mut self,
        bodies: &RigidBodySet,
        steps: [f64; 2],
        mechanism: &Mechanism,
    ) -> Option<(Wrench, Wrench)> {
        let (rb1, rb2) = (bodies.get(self.body1)?, bodies.get(self.body2)?);
        let (m1, m2) = (motion(rb1), motion(rb2));
        let pair = Pair([Mobility::of(rb1), Mobility::of(rb2)], mechanism);
        let transverse = *rb1.rotation() * self.spatial.as_ref()?.local_transverse1;
        let pose = self.spatial_pose(rb1, rb2, transverse);
        let mut parts = self.spatial.take()?;
        let result = self.evaluate_regions(&mut parts, &pose, [&m1, &m2], &pair, steps);
        self.spatial = Some(parts);
        result
    }

    fn evaluate_regions(
        &mut self,
        parts: &mut SpatialParts,
        pose: &SpatialPose,
        motions: [&BodyMotion; 2],
        pair: &Pair,
        steps: [f64; 2],
    ) -> Option<(Wrench, Wrench)> {
        let mut report = SpatialReport {
            tilt: pose.tilt(),
            axial_offset: pose.axial_offset(),
            edge_point: [pose.bearing_center; 2],
            face_point: [pose.bearing_center; 2],
            ..SpatialReport::default()
        };
        let mut totals = Totals::default();
        let mut flight_rate = 0.0_f64;
        parts.points.clear();
        let spatial = parts.model.geometry;
        // First the regions' states, histories, points and loads; their masses take all loads.
        let mut seen: [(JournalState, std::ops::Range<usize>, f64); 4] = Default::default();
        let mut loads: [Option<Load>; 4] = Default::default();
        for (k, view) in seen.iter_mut().enumerate() {
            let region = parts.patches[k].region;
            let (state, gap) = deepest_state(self, &spatial, pose, region, motions);
            flight_rate = flight_rate.max(state.eccentricity_rate.length() / gap);
            let start = parts.points.len();
            let length = region_points(self, parts, pose, region, motions);
            let law = region.law(&self.normal_law, &parts.face_law);
            let patch = &mut parts.patches[k];
            patch.contact.advance(
                patch.state.as_ref(),
                &state,
                self.min_impact_speed,
                self.min_separation,
            );
            patch.rate_before = patch.state.map_or(f64::NAN, |s| s.penetration_rate);
            patch.state = Some(state);
            let range = start..parts.points.len();
            loads[k] = Some(Load::of(&parts.points[range.clone()], law, &state, pair));
            *view = (state, range, length);
        }
        let loads = loads.map(|l| l.expect("every region is loaded above"));
        let masses = coupled_masses(&loads, pair);
        for (k, patch) in parts.patches.iter_mut().enumerate() {
            let law = patch.region.law(&self.normal_law, &parts.face_law);
            patch.impact_rate = if patch.contact.in_contact && law.uses_impact_rate() {
                patch
                    .contact
                    .impact_rate
                    .max(loaded_impact_rate(loads[k].energy, masses[k]))
            } else {
                patch.contact.impact_rate
            };
        }
        let carried = self.carried_rates(parts, &seen, &loads, pair, steps);
        // The deepest region: (index, state at its stored rate, impact rate, rate at the state).
        let mut deepest: Option<(usize, JournalState, f64, f64)> = None;
        for (k, (state, range, length)) in seen.into_iter().enumerate() {
            let region = parts.patches[k].region;
            let law = *region.law(&self.normal_law, &parts.face_law);
            let (load, m) = (&loads[k], masses[k]);
            let patch = &mut parts.patches[k];
            let points = &mut parts.points[range];
            let carried = carried[k];
            let forces = apply_region(
                points,
                &law,
                &self.friction_law,
                patch.impact_rate,
                carried,
                [motions[0].center_of_mass, motions[1].center_of_mass],
                &mut totals,
            );
            patch.force = forces.law_force;
            if deepest.is_none_or(|d| state.penetration > d.1.penetration) {
                deepest = Some((
                    k,
                    state,
                    patch.impact_rate,
                    state.penetration_rate + carried,
                ));
            }
            if forces.normal > 0.0 {
                report.add(region, &forces, points.len(), length);
                linearise(&mut totals, &forces, pair, load, m, &state);
            }
        }
        let (index, state, impact_rate, contact_rate) = deepest?;
        let governing = parts.patches[index].region;
        report.governed_by_face = matches!(governing, Region::Face(_));
        report.dissipation_power = totals.dissipation;
        report.bore_contact_width =
            (report.edge_length[0] + report.edge_length[1]) / self.geometry.length();
        let governing_law = governing.law(&self.normal_law, &parts.face_law);
        let m = if totals.mode_stiffness > 0.0 && totals.mode_load > 0.0 {
            // The mass that gives the regions' summed stiffness the frequency of the motion
            // their loads drive together (its Rayleigh quotient `sum k a^2 / sum F a`): the
            // planar joint's mass for an aligned journal, a rocking one for two edges.
            totals.stiffness * totals.mode_load / totals.mode_stiffness
        } else {
            pair.effective_mass(whole_centre(pose, governing, &state), state.normal)
        };
        let whole = governing_law.tangent_stiffness(state.penetration);
        parts.contact_share = if totals.stiffness > 0.0 && whole > 0.0 {
            totals.stiffness / whole
        } else {
            1.0
        };
        parts.flight_rate = flight_rate;
        parts.report = report;

        // The joint's own history follows the deepest point: its gap is the joint's gap.
        let previous = self.prepared_report().then_some(self.report.state);
        let onset = self.contact.advance(
            previous.as_ref(),
            &state,
            self.min_impact_speed,
            self.min_separation,
        );
        let mode = self.contact.mode();
        let (max_stable_dt, omega, zeta, friction_stable_dt) = step_limits(&totals);
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

impl ClearanceJoint {
    /// Each region's penetration rate carried from its stored rate to the state (`v - stored`,
    /// m/s; 0 out of contact, at the start, or after a step of unknown length), all regions
    /// together: the trapezoidal half step of
    /// [`StepBefore::carry`](crate::model::kinematics::StepBefore::carry) with the regions' forces acting
    /// on one another. With `c_pq = R_p . W R_q / (F_p F_q)` (the rate one region's unit load
    /// drives along another's), region `p`'s rest of the acceleration is its measured change of
    /// rate over the kick plus `sum_q c_pq F_q,before` (every region's force over the step that
    /// led here), and `(I + h/2 C D) (v - stored) = h/2 (rest - C F)`, `F` and `D` the regions'
    /// forces and dampings at their stored rates. An aligned journal's two halves then carry the
    /// planar joint's rate; a rocking pair of edges each sees the other's force change with its
    /// own.
    fn carried_rates(
        &self,
        parts: &SpatialParts,
        seen: &[(JournalState, std::ops::Range<usize>, f64); 4],
        loads: &[Load; 4],
        pair: &Pair,
        steps: [f64; 2],
    ) -> [f64; 4] {
        let mut out = [0.0; 4];
        let [before, step] = steps;
        if !(step > 0.0) {
            return out;
        }
        let kick = 0.5 * (before + step);
        // The regions that carry: in contact, with a rate before and a load to act along.
        let active: Vec<usize> = (0..4)
            .filter(|&k| {
                let (state, patch) = (&seen[k].0, &parts.patches[k]);
                state.penetration > 0.0 && patch.rate_before.is_finite() && loads[k].total > 0.0
            })
            .collect();
        let n = active.len();
        if n == 0 {
            return out;
        }
        let unit = |k: usize| loads[k].row.map(|r| r / loads[k].total);
        let rows: Vec<[f64; 12]> = active.iter().map(|&k| unit(k)).collect();
        let mut force = [0.0; 4];
        let mut damping = [0.0; 4];
        for (a, &k) in active.iter().enumerate() {
            let law = parts.patches[k]
                .region
                .law(&self.normal_law, &parts.face_law);
            for p in &parts.points[seen[k].1.clone()] {
                let c = NormalContact {
                    penetration: p.contact.depth,
                    penetration_rate: p.penetration_rate,
                    impact_rate: parts.patches[k].impact_rate,
                };
                let (f, d) = crate::model::kinematics::force_and_damping(law, &c);
                force[a] += p.contact.weight * f;
                damping[a] += p.contact.weight * d;
            }
        }
        // The system (I + h/2 C D) x = h/2 (rest - C F), row by row.
        let half = 0.5 * step;
        let mut m = [[0.0; 5]; 4];
        for a in 0..n {
            let k = active[a];
            let patch = &parts.patches[k];
            let stored = seen[k].0.penetration_rate;
            let mut rest = (stored - patch.rate_before) / kick;
            let mut pushed = 0.0;
            for b in 0..n {
                let c = pair.between(&rows[a], &rows[b]);
                rest += c * parts.patches[active[b]].force;
                pushed += c * force[b];
                m[a][b] = half * c * damping[b] + if a == b { 1.0 } else { 0.0 };
            }
            m[a][4] = half * (rest - pushed);
        }
        let solved = solve_small(&mut m, n);
        for (a, &k) in active.iter().enumerate() {
            let x = solved[a];
            out[k] = if x.is_finite() { x } else { 0.0 };
        }
        out
    }
}

/// Solves the `n` by `n` system whose augmented rows are `m` (the right-hand side in column 4)
/// by Gaussian elimination with partial pivoting; NaN where it is singular.
fn solve_small(m: &mut [[f64; 5]; 4], n: usize) -> [f64; 4] {
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))
            .unwrap_or(col);
        m.swap(col, pivot);
        let d = m[col][col];
        if d == 0.0 {
            return [f64::NAN; 4];
        }
        let top = m[col];
        for row in m.iter_mut().take(n).skip(col + 1) {
            let f = row[col] / d;
            for (x, t) in row.iter_mut().zip(top).skip(col) {
                *x -= f * t;
            }
        }
    }
    let mut x = [0.0; 4];
    for row in (0..n).rev() {
        let tail: f64 = (row + 1..n).map(|c| m[row][c] * x[c]).sum();
        x[row] = (m[row][4] - tail) / m[row][row];
    }
    x
}

/// The region's points' forces at their rates carried by `carried` (m/s), into `totals`; each
/// point's force pair acts at its surface point along its gradient (the elastic part is the
/// gradient of the region's elastic energy), friction against its slip.
fn apply_region(
    points: &mut [SpatialPoint],
    law: &NormalModel,
    friction: &impl FrictionLaw,
    impact_rate: f64,
    carried: f64,
    centres: [Vector; 2],
    totals: &mut Totals,
) -> RegionForces {
    let mut sums = RegionForces::default();
    for p in points.iter_mut() {
        let (w, g) = (p.contact.weight, p.contact.gradient);
        let c = NormalContact {
            penetration: p.contact.depth,
            penetration_rate: p.penetration_rate + carried,
            impact_rate,
        };
        p.penetration_rate = c.penetration_rate;
        let f = w * law.normal_force(&c);
        if !(f > 0.0) {
            continue;
        }
        let g2 = g.length_squared();
        let normal = f * g2.sqrt();
        let (slip, speed) = (p.slip, p.slip.length());
        let mu = if speed > 0.0 {
            friction.coefficient(speed)
        } else {
            0.0
        };
        let friction_force = mu * normal;
        let friction_vector = if speed > 0.0 {
            -friction_force / speed * slip
        } else {
            Vector::ZERO
        };
        let on_journal = -f * g + friction_vector;
        totals.force += on_journal;
        totals.normal -= f * g;
        totals.friction += friction_vector;
        totals.torque[1] += (p.contact.point - centres[1]).cross(on_journal);
        totals.torque[0] += (p.contact.point - centres[0]).cross(-on_journal);
        let elastic = w * law.elastic_force(p.contact.depth);
        totals.dissipation += (f - elastic) * c.penetration_rate + friction_force * speed;
        p.normal_force = normal;
        p.friction_force = friction_force;
        sums.normal += normal;
        sums.law_force += f;
        sums.moment += normal * p.contact.point;
        let tangent = law.tangent_stiffness(c.penetration);
        sums.tangent += w * tangent * g2;
        sums.stiffness += w * (tangent + law.damping_slope(&c) * c.penetration_rate) * g2;
        sums.damping += w * law.damping_coefficient(&c) * g2;
        let slope = friction_slope(friction, speed);
        let across = if speed > 0.0 { mu / speed } else { slope };
        sums.friction_along += normal * slope.max(0.0);
        sums.friction_across += normal * across.max(0.0);
    }
    sums
}

impl SpatialReport {
    /// Adds a region's resultant.
    fn add(&mut self, region: Region, forces: &RegionForces, points: usize, length: f64) {
        self.points_in_contact += points as u32;
        let at = forces.moment / forces.normal;
        match region {
            Region::Bore(end) => {
                let e = end as usize;
                self.edge_force[e] = forces.normal;
                self.edge_point[e] = at;
                self.edge_length[e] = length;
                self.bore_force += forces.normal;
            }
            Region::Face(end) => {
                let e = end as usize;
                self.face_force[e] = forces.normal;
                self.face_point[e] = at;
            }
        }
    }
}

/// Adds a region in contact to the linearised sums, through its effective mass at its load's
/// centre (along its load, and along and across its deepest point's slip for friction).
fn linearise(
    totals: &mut Totals,
    forces: &RegionForces,
    pair: &Pair,
    load: &Load,
    coupled_mass: f64,
    deepest: &JournalState,
) {
    // The region's own inverse mass: its load row's, per unit load.
    let inv_m = if load.total > 0.0 {
        pair.between(&load.row, &load.row) / (load.total * load.total)
    } else {
        pair.inverse_mass(load.centre, load.direction)
    };
    totals.stiffness += forces.tangent;
    totals.stiffness_over_mass += forces.stiffness.max(0.0) * inv_m;
    if load.total > 0.0 {
        let a = load.total / coupled_mass;
        totals.mode_load += load.total * a;
        totals.mode_stiffness += forces.tangent.max(0.0) * a * a;
    }
    totals.damping_over_mass += forces.damping.max(0.0) * inv_m;
    if forces.friction_along > 0.0 || forces.friction_across > 0.0 {
        let t = friction_direction(deepest, load.direction);
        let across = load.direction.cross(t);
        // Along and across the slip are two directions at one point: the larger rate of the
        // two bounds the region's own friction mode.
        totals.friction_over_mass += (forces.friction_along * pair.inverse_mass(load.centre, t))
            .max(forces.friction_across * pair.inverse_mass(load.centre, across));
    }
}

/// The joint's stability and friction limits: `(max_stable_dt, omega, zeta,
/// friction_stable_dt)`. The regions act in parallel on the same two bodies; the sum of each
/// one's `k/m` bounds the squared frequency of the stiffest mode they make together (the trace
/// of `M^-1 K`: a journal on both edges rocks faster than either edge alone), and likewise for
/// their damping and friction's tangential dampers.
fn step_limits(totals: &Totals) -> (f64, f64, f64, f64) {
    let (max_stable_dt, omega, zeta) =
        if totals.stiffness_over_mass > 0.0 || totals.damping_over_mass > 0.0 {
            stable_step(totals.stiffness_over_mass, totals.damping_over_mass, 1.0)
        } else {
            (f64::INFINITY, 0.0, 0.0)
        };
    let friction_stable_dt = if totals.friction_over_mass > 0.0 {
        2.0 / totals.friction_over_mass
    } else {
        f64::INFINITY
    };
    (max_stable_dt, omega, zeta, friction_stable_dt)
}

/// The point where the whole contact would act were it at this region: on the bearing's
/// mid-plane for the bore (where the planar joint's contact sits), on the axis for a face (an
/// axial knock's). Its effective mass is the whole contact's.
fn whole_centre(pose: &SpatialPose, region: Region, state: &JournalState) -> Vector {
    let r = state.contact_point - pose.bearing_center;
    let along = r.dot(pose.bearing_axis) * pose.bearing_axis;
    match region {
        Region::Bore(_) => state.contact_point - along,
        Region::Face(_) => pose.bearing_center + along,
    }
}

/// The slip direction, or a tangent when the point does not slip.
fn friction_direction(state: &JournalState, normal: Vector) -> Vector {
    let v = state.slip.length();
    if v > 0.0 {
        state.slip / v
    } else {
        normal.any_orthonormal_vector()
    }
}
