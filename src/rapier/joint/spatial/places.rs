//! Where a pose puts the spatial joint's contacts, apart from how fast they move: a region's
//! deepest point and its quadrature points depend on the pair's positions only, and cost most
//! of an evaluation (the bore's sections, their root along the width). The sub-cycle's
//! Jacobian perturbs each velocity the pair moves along at one pose, and reads the places once.

use super::report::{Region, SpatialPoint};
use super::{ClearanceJoint, point_state};
use crate::model::kinematics::{BodyMotion, JournalState};
use crate::model::spatial::{
    ContactPoint, Shoulder, SpatialGeometry, SpatialPose, bore_points, bore_region, bore_section,
};
use rapier3d_f64::math::Vector;
use std::ops::Range;

/// A region's deepest point at a pose, and the two points whose velocities give its
/// eccentricity's rate (the bore's: the journal axis's crossing and the bore's centre in the
/// end plane, across the axis; a face's: the two centres, along it).
#[derive(Clone, Copy, Debug)]
pub(super) struct DeepestPlace {
    contact: ContactPoint,
    eccentricity: Vector,
    centres: [Vector; 2],
    /// The bearing's axis, and whether the rate is taken along it (a face) or across it.
    axis: Vector,
    along: bool,
    /// The region's gap scale: the radial clearance for the bore, the axial play for a face.
    pub(super) gap: f64,
}

impl DeepestPlace {
    /// The region's deepest point at `pose`.
    pub(super) fn at(
        joint: &ClearanceJoint,
        spatial: &SpatialGeometry,
        pose: &SpatialPose,
        region: Region,
    ) -> Self {
        let geometry = &joint.geometry;
        let ai = pose.bearing_axis;
        match region {
            Region::Bore(end) => {
                let section = bore_section(geometry, pose, end.sign() * 0.5 * geometry.length());
                DeepestPlace {
                    contact: section.contact,
                    eccentricity: section.eccentricity,
                    centres: [section.plane_center, section.crossing],
                    axis: ai,
                    along: false,
                    gap: geometry.clearance(),
                }
            }
            Region::Face(end) => {
                let shoulder = Shoulder::at(geometry, spatial, pose, end);
                DeepestPlace {
                    contact: shoulder.deepest_point(),
                    eccentricity: (pose.axial_offset() * -end.sign()) * shoulder.normal,
                    centres: [pose.bearing_center, pose.journal_center],
                    axis: ai,
                    along: true,
                    gap: spatial.axial_play,
                }
            }
        }
    }

    /// Its contact state with the bodies moving as `bodies`.
    pub(super) fn state(&self, bodies: [&BodyMotion; 2]) -> JournalState {
        let ai = self.axis;
        let centres =
            bodies[1].velocity_at(self.centres[1]) - bodies[0].velocity_at(self.centres[0]);
        let rate = if self.along {
            centres.dot(ai) * ai
        } else {
            centres - centres.dot(ai) * ai
        };
        point_state(&self.contact, self.eccentricity, rate, bodies)
    }
}

/// Every region's deepest point and quadrature points in contact at one pose.
#[derive(Clone, Debug, Default)]
pub(super) struct Places {
    pub(super) deepest: Vec<DeepestPlace>,
    /// `(region, s, contact)` of the points in contact, region after region.
    points: Vec<(Region, f64, ContactPoint)>,
    ranges: [Range<usize>; 4],
    /// Each region's length along the width (0 for a face or a region without contact).
    pub(super) lengths: [f64; 4],
    bore_scratch: Vec<(f64, ContactPoint)>,
    face_scratch: Vec<ContactPoint>,
}

impl Places {
    /// Reads `regions` at `pose`, reusing the buffers.
    pub(super) fn read(
        &mut self,
        joint: &ClearanceJoint,
        spatial: &SpatialGeometry,
        pose: &SpatialPose,
        regions: [Region; 4],
    ) {
        self.deepest.clear();
        self.points.clear();
        for (k, region) in regions.into_iter().enumerate() {
            self.deepest
                .push(DeepestPlace::at(joint, spatial, pose, region));
            let first = self.points.len();
            self.lengths[k] = self.read_points(joint, spatial, pose, region);
            self.ranges[k] = first..self.points.len();
        }
    }

    fn read_points(
        &mut self,
        joint: &ClearanceJoint,
        spatial: &SpatialGeometry,
        pose: &SpatialPose,
        region: Region,
    ) -> f64 {
        let geometry = &joint.geometry;
        let touching = |c: &ContactPoint| c.depth > 0.0;
        match region {
            Region::Bore(end) => {
                let Some(r) = bore_region(geometry, pose, end) else {
                    return 0.0;
                };
                self.bore_scratch.clear();
                bore_points(geometry, pose, &r, &mut self.bore_scratch);
                let inside = self.bore_scratch.iter().filter(|(_, c)| touching(c));
                self.points.extend(inside.map(|&(s, c)| (region, s, c)));
                r.length()
            }
            Region::Face(end) => {
                let shoulder = Shoulder::at(geometry, spatial, pose, end);
                self.face_scratch.clear();
                shoulder.points(&mut self.face_scratch);
                let ai = pose.bearing_axis;
                for &c in self.face_scratch.iter().filter(|c| touching(c)) {
                    let s = (c.point - pose.bearing_center).dot(ai);
                    self.points.push((region, s, c));
                }
                0.0
            }
        }
    }

    /// Appends region `k`'s points in contact to `out`, with the rates the bodies moving as
    /// `bodies` give them.
    pub(super) fn moving(&self, k: usize, bodies: [&BodyMotion; 2], out: &mut Vec<SpatialPoint>) {
        for &(region, s, contact) in &self.points[self.ranges[k].clone()] {
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
    }
}
