//! The spatial model of a [`ClearanceJoint`]: four contact regions (the bore at each end, each
//! face), each with its own contact history and impact rate, their laws integrated over the
//! regions' quadrature points ([`crate::model::spatial`]). The joint reports the deepest
//! region's deepest point as its state (what the step control and the guards read) and the
//! regions' resultants.

use super::{ClearanceJoint, ClearanceReport, ContactHistory, Mechanism, friction_slope, motion};
use crate::model::kinematics::{BodyMotion, ForcePair, JournalState, stable_step};
use crate::model::laws::loaded_impact_rate;
use crate::model::laws::{FrictionLaw, NormalContact, NormalForceLaw, NormalModel};
use crate::model::spatial::{ContactPoint, End, SpatialModel, SpatialPose};
use crate::rapier::pipeline::ledger::{Wrench, world_center_of_mass};
use rapier3d_f64::math::{AngularInertia, Vector};
use rapier3d_f64::prelude::{RigidBody, RigidBodySet};

mod evaluate;
mod places;
pub(super) mod report;
pub(super) mod subcycle;
use evaluate::{Totals, load_region};
use places::Places;
use report::{Region, SpatialPoint, SpatialReport};

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
    /// The rate at which the positions moved the region's penetration over the step that led
    /// to this application's state and over the one before (`(delta - delta_before)/h`, NaN
    /// without one): the rates its contact is carried from (the planar joint's `contact_rate`).
    moved: f64,
    moved_before: f64,
    /// The time since the onset of the region's impact inside the sub-cycle (s), while its
    /// sub-steps resolve it (`subcycle::impact`); `None` out of one.
    impact: Option<f64>,
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
            moved: f64::NAN,
            moved_before: f64::NAN,
            impact: None,
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
    /// Where the pose puts the regions' contacts; the sub-cycle's Jacobian keeps its base
    /// pose's in `base_places`.
    places: Places,
    base_places: Places,
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
            places: Places::default(),
            base_places: Places::default(),
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
    pub(crate) fn check_start(&self, rb1: &RigidBody, rb2: &RigidBody) -> crate::error::Result<()> {
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
