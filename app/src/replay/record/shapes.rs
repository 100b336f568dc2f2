//! The shapes a replay draws for a body: its colliders', else its equivalent box.

use super::*;

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
