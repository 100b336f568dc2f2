//! Bookkeeping of the user forces this crate adds to Rapier bodies.
//!
//! Rapier keeps user forces across steps until `reset_forces`. To leave a user's own forces
//! untouched, every force source of this crate removes exactly what it added at the previous
//! step before adding the new value (exact when it was the only contributor: `(0 + p) - p = 0`).

pub(crate) use crate::rapier::pipeline::protocol::Wrench;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{RigidBodyHandle, RigidBodySet};

/// The wrenches added at the last application, to be taken back at the next one.
#[derive(Clone, Debug, Default)]
pub struct ForceLedger {
    applied: Vec<Wrench>,
}

impl ForceLedger {
    /// Takes back every wrench of the previous application and adds `wrenches` instead.
    pub fn replace(
        &mut self,
        bodies: &mut RigidBodySet,
        wrenches: impl IntoIterator<Item = Wrench>,
    ) {
        for w in self.applied.drain(..) {
            if let Some(rb) = bodies.get_mut(w.body) {
                rb.add_force(-w.force, false);
                rb.add_torque(-w.torque, false);
            }
        }
        for w in wrenches {
            if let Some(rb) = bodies.get_mut(w.body) {
                let wake = w.force != Vector::ZERO || w.torque != Vector::ZERO;
                rb.add_force(w.force, wake);
                rb.add_torque(w.torque, wake);
                self.applied.push(w);
            }
        }
    }
}

/// World centre of mass of `rb`, computed from its pose and local mass properties so that it is
/// right before the first step (Rapier's `center_of_mass()` is stale until then).
pub(crate) fn world_center_of_mass(rb: &rapier3d_f64::prelude::RigidBody) -> Vector {
    *rb.position() * rb.mass_properties().local_mprops.local_com
}

/// Ensures the local mass properties of a dynamic body are computed (Rapier fills them in at the
/// first step; the hook needs the centre of mass before that).
pub(crate) fn ensure_mass_properties(
    bodies: &mut RigidBodySet,
    colliders: Option<&rapier3d_f64::prelude::ColliderSet>,
    handle: RigidBodyHandle,
) {
    if let Some(rb) = bodies.get_mut(handle)
        && rb.is_dynamic()
        && rb.mass_properties().local_mprops.inv_mass == 0.0
    {
        let empty = rapier3d_f64::prelude::ColliderSet::new();
        rb.recompute_mass_properties_from_colliders(colliders.unwrap_or(&empty));
    }
}

/// `1/m + (r x n) . I^-1 (r x n)` of a dynamic body for a unit force along `n` at `point`: the
/// inverse of its effective mass there; 0 for fixed and kinematic bodies.
pub(crate) fn inverse_mass_along(
    rb: &rapier3d_f64::prelude::RigidBody,
    point: Vector,
    n: Vector,
) -> f64 {
    if !rb.is_dynamic() {
        return 0.0;
    }
    let mp = &rb.mass_properties().local_mprops;
    let rn = (point - world_center_of_mass(rb)).cross(n);
    mp.inv_mass + rn.dot(mp.world_inv_inertia(rb.rotation()) * rn)
}
