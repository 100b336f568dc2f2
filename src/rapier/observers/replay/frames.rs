//! Building a replay's frames from the joints' states and the bodies' shapes.

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
    state: &crate::model::kinematics::JournalState,
    force: &crate::model::kinematics::ForcePair,
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

/// The largest contact force of a frame's journals, N.
pub(super) fn force(f: &ReplayFrame) -> f64 {
    f.journals.iter().map(|j| j.force_n).fold(0.0, f64::max)
}

/// The frame of `a` and `b` with the larger contact force, carrying the other's impact flags
/// (an impact's frame dropped still shows on the timeline).
pub(super) fn merge_pair(a: ReplayFrame, b: ReplayFrame) -> ReplayFrame {
    let (mut keep, drop) = if force(&b) > force(&a) {
        (b, a)
    } else {
        (a, b)
    };
    for (k, d) in keep.journals.iter_mut().zip(&drop.journals) {
        k.impact |= d.impact;
    }
    keep
}

/// The in-plane `u` direction of a hinge: the axis of the frame least aligned with `axis`,
/// made orthogonal to it (x for an axis along y; then `v = axis x u` is z). The scene runner's
/// CSV columns `*_ecc_u_mm`/`*_ecc_v_mm` use the same directions.
pub(crate) fn in_plane_u(axis: Vector) -> Vector {
    let candidates = [Vector::X, Vector::Y, Vector::Z];
    let mut best = candidates[0];
    for c in candidates {
        if c.dot(axis).abs() < best.dot(axis).abs() - 1e-12 {
            best = c;
        }
    }
    (best - best.dot(axis) * axis).normalize()
}

/// A body's shapes: its colliders' (boxes, cylinders, balls; capsules as cylinders), else the
/// box with its mass and principal inertia.
pub(super) fn body_shapes(rb: &RigidBody, colliders: &ColliderSet) -> Vec<ReplayShape> {
    let mut shapes = Vec::new();
    for &c in rb.colliders() {
        let Some(col) = colliders.get(c) else {
            continue;
        };
        let pose = col.position_wrt_parent().copied().unwrap_or_default();
        let center_m = pose.translation.to_array();
        let q = pose.rotation;
        let rotation = [q.x, q.y, q.z, q.w];
        let shape = col.shape();
        if let Some(b) = shape.as_cuboid() {
            shapes.push(ReplayShape::Box {
                half_extents_m: b.half_extents.to_array(),
                center_m,
                rotation,
            });
        } else if let Some(cy) = shape.as_cylinder() {
            shapes.push(ReplayShape::Cylinder {
                radius_m: cy.radius,
                half_height_m: cy.half_height,
                center_m,
                rotation,
            });
        } else if let Some(b) = shape.as_ball() {
            shapes.push(ReplayShape::Ball {
                radius_m: b.radius,
                center_m,
            });
        } else if let Some(cap) = shape.as_capsule() {
            shapes.push(ReplayShape::Cylinder {
                radius_m: cap.radius,
                half_height_m: cap.half_height() + cap.radius,
                center_m,
                rotation,
            });
        }
    }
    if shapes.is_empty() {
        let m = &rb.mass_properties().local_mprops;
        let mass = m.mass();
        let j = m.principal_inertia();
        if mass > 0.0 && mass.is_finite() {
            // A uniform box: J_x = m (a_y^2 + a_z^2) / 12 with full extents a, so
            // a_x^2 = 6 (J_y + J_z - J_x) / m.
            let full = |a: f64, b: f64, c: f64| (6.0 * (b + c - a) / mass).max(0.0).sqrt();
            let half = [
                0.5 * full(j.x, j.y, j.z),
                0.5 * full(j.y, j.z, j.x),
                0.5 * full(j.z, j.x, j.y),
            ];
            let q = m.principal_inertia_local_frame;
            shapes.push(ReplayShape::Box {
                half_extents_m: half,
                center_m: m.local_com.to_array(),
                rotation: [q.x, q.y, q.z, q.w],
            });
        }
    }
    shapes
}
