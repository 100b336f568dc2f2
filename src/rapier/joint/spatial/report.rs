//! What a spatial joint reports: its regions, their quadrature points and their resultants.

use super::evaluate::RegionForces;
use super::*;

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
    pub(super) fn law<'a>(self, bore: &'a NormalModel, face: &'a NormalModel) -> &'a NormalModel {
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

impl SpatialReport {
    /// Adds a region's resultant.
    pub(super) fn add(
        &mut self,
        region: Region,
        forces: &RegionForces,
        points: usize,
        length: f64,
    ) {
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
