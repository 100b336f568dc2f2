//! The bodies of the solve: prescribed kinematic states; each body's mass, state and wrench.

use crate::rapier::pipeline::ledger::Wrench;
use rapier3d_f64::math::{AngularInertia, Pose, Rotation, Vector};
use rapier3d_f64::prelude::{RigidBody, RigidBodyHandle};

/// The prescribed state of a kinematic body at the state solved: velocity and acceleration of
/// its centre of mass (its frame origin when it has no mass), angular velocity and acceleration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KinematicState {
    /// The body.
    pub body: RigidBodyHandle,
    /// Velocity of the centre of mass, m/s.
    pub linvel: Vector,
    /// Angular velocity, rad/s.
    pub angvel: Vector,
    /// Acceleration of the centre of mass, m/s^2.
    pub linacc: Vector,
    /// Angular acceleration, rad/s^2.
    pub angacc: Vector,
}

/// One body of the solve.
#[derive(Clone, Copy, Debug)]
pub(super) struct Entry {
    pub(super) handle: RigidBodyHandle,
    pub(super) dynamic: bool,
    pub(super) gyroscopic: bool,
    pub(super) inv_mass: f64,
    pub(super) inv_inertia: AngularInertia,
    /// World rotation of the principal axes and the principal inertia (gyroscopic term).
    pub(super) principal_rot: Rotation,
    pub(super) principal: Vector,
    pub(super) pose: Pose,
    pub(super) rot: Rotation,
    pub(super) com: Vector,
    /// Stored velocities (Rapier's, or the prescribed ones of a driven body).
    pub(super) stored_v: Vector,
    pub(super) stored_w: Vector,
    /// The state's velocities.
    pub(super) v: Vector,
    pub(super) w: Vector,
    /// Applied force and torque that do not depend on the velocities (user forces, extra
    /// wrenches, gravity).
    pub(super) f0: Vector,
    pub(super) t0: Vector,
    /// All applied at the state's velocities (with the gyroscopic term and soft motors).
    pub(super) f: Vector,
    pub(super) t: Vector,
    /// Prescribed accelerations of a driven body.
    pub(super) prescribed: Option<(Vector, Vector)>,
    /// The accelerations solved.
    pub(super) acc: Vector,
    pub(super) alpha: Vector,
}

impl Entry {
    pub(super) fn new(
        rb: &RigidBody,
        handle: RigidBodyHandle,
        gravity: Vector,
        extra: &[Wrench],
        kinematic: &[KinematicState],
    ) -> Entry {
        let (mut f_extra, mut t_extra) = (Vector::ZERO, Vector::ZERO);
        for w in extra.iter().filter(|w| w.body == handle) {
            f_extra += w.force;
            t_extra += w.torque;
        }
        let mp = &rb.mass_properties().local_mprops;
        let dynamic = rb.is_dynamic();
        let mass = if mp.inv_mass > 0.0 {
            1.0 / mp.inv_mass
        } else {
            0.0
        };
        let mut e = Entry {
            handle,
            dynamic,
            gyroscopic: rb.gyroscopic_forces_enabled(),
            inv_mass: if dynamic { mp.inv_mass } else { 0.0 },
            inv_inertia: mp.world_inv_inertia(rb.rotation()),
            principal_rot: *rb.rotation() * mp.principal_inertia_local_frame,
            principal: mp.principal_inertia(),
            pose: *rb.position(),
            rot: *rb.rotation(),
            com: crate::rapier::pipeline::ledger::world_center_of_mass(rb),
            stored_v: rb.linvel(),
            stored_w: rb.angvel(),
            v: rb.linvel(),
            w: rb.angvel(),
            f0: rb.user_force() + f_extra + mass * rb.gravity_scale() * gravity,
            t0: rb.user_torque() + t_extra,
            f: Vector::ZERO,
            t: Vector::ZERO,
            prescribed: None,
            acc: Vector::ZERO,
            alpha: Vector::ZERO,
        };
        if let Some(k) = kinematic.iter().find(|k| k.body == handle) {
            (e.stored_v, e.stored_w) = (k.linvel, k.angvel);
            (e.v, e.w) = (k.linvel, k.angvel);
            e.prescribed = Some((k.linacc, k.angacc));
        }
        e
    }

    /// `M^-1 (f, t)` of this body (zero unless dynamic).
    pub(super) fn apply_inv_mass(&self, f: Vector, t: Vector) -> (Vector, Vector) {
        if !self.dynamic {
            return (Vector::ZERO, Vector::ZERO);
        }
        (self.inv_mass * f, self.inv_inertia * t)
    }

    /// The applied wrench at the state's velocities (before soft motors): with the gyroscopic
    /// term `-w x (I w)`.
    pub(super) fn applied(&self) -> (Vector, Vector) {
        let gyro = if self.gyroscopic {
            let r = self.principal_rot;
            self.w.cross(r * (self.principal * (r.inverse() * self.w)))
        } else {
            Vector::ZERO
        };
        (self.f0, self.t0 - gyro)
    }

    /// The accelerations without the joints: `M^-1 F`, or the prescribed ones of a driven body
    /// (zero for a fixed body and a kinematic body moving steadily).
    pub(super) fn free_acceleration(&self) -> (Vector, Vector) {
        match self.prescribed {
            Some(p) => p,
            None => self.apply_inv_mass(self.f, self.t),
        }
    }
}
