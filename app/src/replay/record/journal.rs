//! A journal's frame: its state in its bearing's directions, from the joint's report or one of
//! its sub-steps.

use super::*;

/// One journal's state in its bearing's `u`/`v` directions (a spatial joint's eccentricity at
/// the bearing's mid-plane, as the scene runner's CSV rows: its report's state is its deepest
/// station's, which may be a face's).
pub(super) fn journal_frame(
    joint: &ClearanceJoint,
    bodies: &RigidBodySet,
    track: &ReplayJournal,
) -> JournalFrame {
    let r = joint.report();
    let (rb1, rb2) = (bodies.get(joint.body1()), bodies.get(joint.body2()));
    let rotation: Rotation = rb1.map(|rb| *rb.rotation()).unwrap_or_default();
    let (u, v) = bearing_directions(rotation, track);
    let pose = match (r.spatial, rb1, rb2) {
        (Some(_), Some(rb1), Some(rb2)) => Some(joint.spatial_pose(rb1, rb2, u)),
        _ => None,
    };
    let e = pose.map_or(r.state.eccentricity, |p| p.mid_plane_eccentricity());
    JournalFrame {
        spatial: pose
            .zip(r.spatial)
            .map(|(p, s)| spatial_frame(&p, &s, u, v)),
        ..planar_frame(e, &r.state, &r.force, r.impact, (u, v))
    }
}

/// A planar joint's frame at one of its sub-steps, in the bearing's directions (its body's
/// `rotation` at the step's end).
pub(super) fn substep_frame(
    s: &SubStep,
    rotation: Rotation,
    track: &ReplayJournal,
) -> JournalFrame {
    let uv = bearing_directions(rotation, track);
    planar_frame(s.state.eccentricity, &s.state, &s.force, s.impact, uv)
}

/// The bearing's in-plane directions `u`, `v` (world) for its body's `rotation`.
pub(super) fn bearing_directions(rotation: Rotation, track: &ReplayJournal) -> (Vector, Vector) {
    let u1 = Vector::from(track.u1);
    (
        rotation * u1,
        rotation * Vector::from(track.axis1).cross(u1),
    )
}

/// A journal's frame from its eccentricity `e`, its state's penetration and its force, along
/// the bearing's `u` and `v` (no spatial part).
pub(super) fn planar_frame(
    e: Vector,
    state: &clearance_joint::model::kinematics::JournalState,
    force: &clearance_joint::model::kinematics::ForcePair,
    impact: bool,
    (u, v): (Vector, Vector),
) -> JournalFrame {
    let f = force.on_journal;
    JournalFrame {
        ecc_u_m: e.dot(u),
        ecc_v_m: e.dot(v),
        force_u_n: f.dot(u),
        force_v_n: f.dot(v),
        force_n: f.length(),
        penetration_m: state.penetration.max(0.0),
        contact: state.penetration > 0.0,
        impact,
        spatial: None,
    }
}

/// A spatial joint's frame values from its pose and report (`u`, `v`: the bearing's
/// directions, world).
pub(super) fn spatial_frame(
    pose: &SpatialPose,
    s: &SpatialReport,
    u: Vector,
    v: Vector,
) -> SpatialFrame {
    let local = |at: Vector| {
        let d = at - pose.bearing_center;
        [d.dot(u), d.dot(v), d.dot(pose.bearing_axis)]
    };
    SpatialFrame {
        tilt_rad: pose.tilt(),
        axial_m: pose.axial_offset(),
        edge_force_n: s.edge_force,
        edge_at_m: s.edge_point.map(local),
        face_force_n: s.face_force,
        face_at_m: s.face_point.map(local),
    }
}
