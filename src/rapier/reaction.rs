//! Exact reactions of ideal joints (revolute, prismatic, fixed, spherical) at a state, from the constrained rigid-body equations
//! (not from Rapier's impulses or momentum differences, which carry its integrator's lag).
//!
//! For bodies with mass matrices `M`, applied wrenches `F` (user forces and torques, gravity,
//! gyroscopic terms) and joints whose constraints have Jacobian `J` and velocity-product
//! terms `c` (`J a + c = 0` for the accelerations `a`), the multipliers solve
//! `J M^-1 J^T lambda = -c - J M^-1 F`: the joint forces the ideal mechanism needs at this
//! position and velocity. They do not depend on the step: the same state gives the same reaction
//! whatever the step control, which momentum balances over a step do not achieve (Rapier's
//! constraint turns a jointed body's velocity by the motion since the previous step, while applied
//! forces act over the current one).
//!
//! ```
//! use clearance_joint::rapier::reaction::{IdealRevolute, ReactionSolver};
//! use rapier3d_f64::prelude::*;
//! use rapier3d_f64::math::Vector;
//!
//! // A 2 kg arm hanging at rest 0.3 m below a fixed pivot carries its weight.
//! let mut bodies = RigidBodySet::new();
//! let base = bodies.insert(RigidBodyBuilder::fixed());
//! let arm = bodies.insert(
//!     RigidBodyBuilder::dynamic()
//!         .translation(Vector::new(0.0, -0.3, 0.0))
//!         .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02))),
//! );
//! # clearance_joint::rapier::reaction::prepare_mass_properties(&mut bodies);
//! let joint = IdealRevolute {
//!     body1: base,
//!     body2: arm,
//!     local_anchor1: Vector::ZERO,
//!     local_anchor2: Vector::new(0.0, 0.3, 0.0),
//!     local_axis1: Vector::Z,
//! };
//! let mut solver = ReactionSolver::default();
//! let forces = solver.solve(&bodies, &[joint], Vector::new(0.0, -9.81, 0.0)).unwrap();
//! assert!((forces[0] - Vector::new(0.0, 2.0 * 9.81, 0.0)).length() < 1e-9);
//! ```

use crate::rapier::ledger::Wrench;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{RigidBody, RigidBodyHandle, RigidBodySet};

/// An ideal revolute joint for [`ReactionSolver::solve`]: anchors and axis in the bodies' frames
/// (body 1's axis; body 2's follows from the constraint).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdealRevolute {
    /// First body (the bearing side).
    pub body1: RigidBodyHandle,
    /// Second body (the journal side): reactions are the forces on it.
    pub body2: RigidBodyHandle,
    /// Joint point in body 1's frame, m.
    pub local_anchor1: Vector,
    /// Joint point in body 2's frame, m.
    pub local_anchor2: Vector,
    /// Unit hinge axis in body 1's frame.
    pub local_axis1: Vector,
}

/// An ideal prismatic joint for [`ReactionSolver::solve_joints`]: body 2 slides along the axis
/// without turning relative to body 1. Limits and motors are not modelled: the reaction is the
/// one of a free slide (a limit in contact or a motor adds a force along the axis that the
/// solver does not know).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdealPrismatic {
    /// First body (the guide).
    pub body1: RigidBodyHandle,
    /// Second body (the slider): reactions are the forces on it.
    pub body2: RigidBodyHandle,
    /// A point of the slide line in body 1's frame, m.
    pub local_anchor1: Vector,
    /// The slider's point on that line in body 2's frame, m.
    pub local_anchor2: Vector,
    /// Unit slide axis in body 1's frame.
    pub local_axis1: Vector,
}

/// An ideal fixed joint for [`ReactionSolver::solve_joints`]: the two bodies move as one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdealFixed {
    /// First body.
    pub body1: RigidBodyHandle,
    /// Second body: reactions are the forces on it.
    pub body2: RigidBodyHandle,
    /// The joint point in body 1's frame, m (where the reaction force is reported).
    pub local_anchor1: Vector,
    /// The joint point in body 2's frame, m.
    pub local_anchor2: Vector,
}

/// An ideal spherical joint (ball and socket) for [`ReactionSolver::solve_joints`]: the anchors
/// coincide, rotation is free.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdealSpherical {
    /// First body.
    pub body1: RigidBodyHandle,
    /// Second body: reactions are the forces on it.
    pub body2: RigidBodyHandle,
    /// The joint point in body 1's frame, m.
    pub local_anchor1: Vector,
    /// The joint point in body 2's frame, m.
    pub local_anchor2: Vector,
}

/// Any ideal joint the solver handles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IdealJoint {
    /// A hinge: 3 linear and 2 angular constraints.
    Revolute(IdealRevolute),
    /// A slide: 2 linear (normal to the axis) and 3 angular constraints.
    Prismatic(IdealPrismatic),
    /// A weld: 3 linear and 3 angular constraints.
    Fixed(IdealFixed),
    /// A ball joint: 3 linear constraints.
    Spherical(IdealSpherical),
    /// A revolute whose velocity motor holds the relative angular speed constant: the revolute's
    /// constraints plus one along the axis (its multiplier is the motor torque). Exact for a
    /// motor that holds its speed; a soft motor's speed error is not in it.
    MotorRevolute(IdealRevolute),
}

impl IdealJoint {
    fn bodies(&self) -> (RigidBodyHandle, RigidBodyHandle) {
        match self {
            IdealJoint::Revolute(j) => (j.body1, j.body2),
            IdealJoint::Prismatic(j) => (j.body1, j.body2),
            IdealJoint::Fixed(j) => (j.body1, j.body2),
            IdealJoint::Spherical(j) => (j.body1, j.body2),
            IdealJoint::MotorRevolute(j) => (j.body1, j.body2),
        }
    }

    /// Constraint rows (linear rows first) and how many are linear.
    fn rows(&self) -> (usize, usize) {
        match self {
            IdealJoint::Revolute(_) => (5, 3),
            IdealJoint::Prismatic(_) => (5, 2),
            IdealJoint::Fixed(_) => (6, 3),
            IdealJoint::Spherical(_) => (3, 3),
            IdealJoint::MotorRevolute(_) => (6, 3),
        }
    }
}

impl From<IdealRevolute> for IdealJoint {
    fn from(j: IdealRevolute) -> Self {
        IdealJoint::Revolute(j)
    }
}

impl From<IdealPrismatic> for IdealJoint {
    fn from(j: IdealPrismatic) -> Self {
        IdealJoint::Prismatic(j)
    }
}

impl From<IdealSpherical> for IdealJoint {
    fn from(j: IdealSpherical) -> Self {
        IdealJoint::Spherical(j)
    }
}

impl From<IdealFixed> for IdealJoint {
    fn from(j: IdealFixed) -> Self {
        IdealJoint::Fixed(j)
    }
}

/// Solves for ideal-joint reactions; keeps its buffers between calls (no allocation per step
/// once sized).
#[derive(Clone, Debug, Default)]
pub struct ReactionSolver {
    /// Dense `J M^-1 J^T`, row-major.
    a: Vec<f64>,
    /// Right-hand side, then the multipliers.
    b: Vec<f64>,
    a_copy: Vec<f64>,
    b_copy: Vec<f64>,
    /// Per joint and row: the Jacobian blocks `(linear, angular)` for body 1 and body 2.
    rows: Vec<[Vector; 4]>,
    /// First row of each joint.
    starts: Vec<usize>,
    forces: Vec<Vector>,
    joints: Vec<IdealJoint>,
    extra: Vec<Wrench>,
    /// Bodies whose motion is prescribed with a nonzero acceleration (a tabulated drive): their
    /// velocities and accelerations at the state. Other kinematic bodies are taken to move at
    /// constant velocity.
    pub kinematic: Vec<KinematicState>,
}

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

/// What the solver needs of one body.
struct BodyTerms {
    inv_mass: f64,
    com: Vector,
    angvel: Vector,
    /// Applied force and torque (with gravity and the gyroscopic term).
    force: Vector,
    torque: Vector,
    dynamic: bool,
}

fn terms(rb: &RigidBody, handle: RigidBodyHandle, gravity: Vector, extra: &[Wrench]) -> BodyTerms {
    let (mut f_extra, mut t_extra) = (Vector::ZERO, Vector::ZERO);
    for w in extra.iter().filter(|w| w.body == handle) {
        f_extra += w.force;
        t_extra += w.torque;
    }
    let mp = &rb.mass_properties().local_mprops;
    let com = crate::rapier::ledger::world_center_of_mass(rb);
    let w = rb.angvel();
    let dynamic = rb.is_dynamic();
    let rot = *rb.rotation() * mp.principal_inertia_local_frame;
    let iw = rot * (mp.principal_inertia() * (rot.inverse() * w));
    let gyro = if rb.gyroscopic_forces_enabled() {
        w.cross(iw)
    } else {
        Vector::ZERO
    };
    let mass = if mp.inv_mass > 0.0 {
        1.0 / mp.inv_mass
    } else {
        0.0
    };
    BodyTerms {
        inv_mass: if dynamic { mp.inv_mass } else { 0.0 },
        com,
        angvel: w,
        force: rb.user_force() + f_extra + mass * rb.gravity_scale() * gravity,
        torque: rb.user_torque() + t_extra - gyro,
        dynamic,
    }
}

impl BodyTerms {
    /// `M^-1 (f, t)` of this body.
    fn apply_inv_mass(&self, rb: &RigidBody, f: Vector, t: Vector) -> (Vector, Vector) {
        if !self.dynamic {
            return (Vector::ZERO, Vector::ZERO);
        }
        let mp = &rb.mass_properties().local_mprops;
        (self.inv_mass * f, mp.world_inv_inertia(rb.rotation()) * t)
    }
}

/// Two unit vectors orthogonal to `axis` and to each other.
fn orthonormal_pair(axis: Vector) -> (Vector, Vector) {
    let helper = if axis.x.abs() < 0.6 {
        Vector::X
    } else if axis.y.abs() < 0.6 {
        Vector::Y
    } else {
        Vector::Z
    };
    let t1 = axis.cross(helper).normalize();
    (t1, axis.cross(t1))
}

impl ReactionSolver {
    /// The force on each joint's body 2 (N, world frame), in the order of `joints`, at the bodies'
    /// current state under their user forces and torques and `gravity`. Redundant constraints (a
    /// closed loop, whose reactions rigid dynamics alone do not determine) get a least-norm
    /// share through a relative regularisation of 1e-12, used only when the system is singular.
    /// `None` when a body is missing. Only the listed joints are constraints: contacts with
    /// colliders are not part of the solve.
    pub fn solve(
        &mut self,
        bodies: &RigidBodySet,
        joints: &[IdealRevolute],
        gravity: Vector,
    ) -> Option<&[Vector]> {
        self.solve_with(bodies, joints, gravity, &[])
    }

    /// [`solve`](Self::solve) with further applied wrenches on the bodies: those of the force
    /// sources the [`Stepper`](crate::rapier::stepper::Stepper) adds during its steps only (drives,
    /// clearance contacts), which the bodies' user forces do not hold between steps.
    pub fn solve_with(
        &mut self,
        bodies: &RigidBodySet,
        joints: &[IdealRevolute],
        gravity: Vector,
        extra: &[Wrench],
    ) -> Option<&[Vector]> {
        let mut all = std::mem::take(&mut self.joints);
        all.clear();
        all.extend(joints.iter().map(|&j| IdealJoint::Revolute(j)));
        let ok = self
            .solve_joints_with(bodies, &all, gravity, extra)
            .is_some();
        self.joints = all;
        if ok { Some(&self.forces) } else { None }
    }

    /// [`solve_joints`](Self::solve_joints) with further applied wrenches, as in
    /// [`solve_with`](Self::solve_with).
    pub fn solve_joints_with(
        &mut self,
        bodies: &RigidBodySet,
        joints: &[IdealJoint],
        gravity: Vector,
        extra: &[Wrench],
    ) -> Option<&[Vector]> {
        self.extra.clear();
        self.extra.extend_from_slice(extra);
        let r = self.solve_joints_inner(bodies, joints, gravity).is_some();
        self.extra.clear();
        if r { Some(&self.forces) } else { None }
    }

    /// [`solve`](Self::solve) for any mix of revolute, prismatic, fixed and spherical joints: the force on
    /// each joint's body 2 at its anchor (N, world frame; for a prismatic joint the part normal to
    /// the axis, the only one an ideal slide carries). Every ideal joint of the mechanism must be
    /// listed: a joint left out is a free motion to the solver. Kinematic bodies are taken to move
    /// at constant velocity (their accelerations are those of a rigid rotation at their angular
    /// velocity).
    pub fn solve_joints(
        &mut self,
        bodies: &RigidBodySet,
        joints: &[IdealJoint],
        gravity: Vector,
    ) -> Option<&[Vector]> {
        self.solve_joints_with(bodies, joints, gravity, &[])
    }

    fn solve_joints_inner(
        &mut self,
        bodies: &RigidBodySet,
        joints: &[IdealJoint],
        gravity: Vector,
    ) -> Option<()> {
        self.b.clear();
        self.rows.clear();
        self.starts.clear();
        self.forces.clear();
        // Jacobian rows and right-hand sides.
        for j in joints {
            self.starts.push(self.rows.len());
            let (h1, h2) = j.bodies();
            let (rb1, rb2) = (bodies.get(h1)?, bodies.get(h2)?);
            let (mut t1, mut t2) = (
                terms(rb1, h1, gravity, &self.extra),
                terms(rb2, h2, gravity, &self.extra),
            );
            let (mut a1f, mut a1t) = t1.apply_inv_mass(rb1, t1.force, t1.torque);
            let (mut a2f, mut a2t) = t2.apply_inv_mass(rb2, t2.force, t2.torque);
            // A driven body's state and accelerations are prescribed.
            let (mut v1, mut v2) = (rb1.linvel(), rb2.linvel());
            for k in &self.kinematic {
                if k.body == h1 {
                    (v1, t1.angvel, a1f, a1t) = (k.linvel, k.angvel, k.linacc, k.angacc);
                }
                if k.body == h2 {
                    (v2, t2.angvel, a2f, a2t) = (k.linvel, k.angvel, k.linacc, k.angacc);
                }
            }
            let (w1, w2) = (t1.angvel, t2.angvel);
            match j {
                IdealJoint::Revolute(j) | IdealJoint::MotorRevolute(j) => {
                    let r1 = *rb1.position() * j.local_anchor1 - t1.com;
                    let r2 = *rb2.position() * j.local_anchor2 - t2.com;
                    let axis = (*rb1.rotation() * j.local_axis1).normalize();
                    let (u1, u2) = orthonormal_pair(axis);
                    // Linear rows: p2 - p1 = 0, `J a + c = 0` with c the centripetal terms.
                    let c_lin = w2.cross(w2.cross(r2)) - w1.cross(w1.cross(r1));
                    let free_lin = a2f + a2t.cross(r2) - a1f - a1t.cross(r1);
                    for d in [Vector::X, Vector::Y, Vector::Z] {
                        self.rows.push([-d, -r1.cross(d), d, r2.cross(d)]);
                        self.b.push(-(c_lin.dot(d) + free_lin.dot(d)));
                    }
                    // Angular rows: (w2 - w1).t = 0 for the two directions t normal to the
                    // axis, which turn with body 1.
                    let motor =
                        matches!(joints[self.starts.len() - 1], IdealJoint::MotorRevolute(_));
                    let dirs: &[Vector] = if motor { &[u1, u2, axis] } else { &[u1, u2] };
                    for &t in dirs {
                        let c_ang = (w2 - w1).dot(w1.cross(t));
                        self.rows.push([Vector::ZERO, -t, Vector::ZERO, t]);
                        self.b.push(-(c_ang + (a2t - a1t).dot(t)));
                    }
                }
                IdealJoint::Prismatic(j) => {
                    let p1 = *rb1.position() * j.local_anchor1;
                    let p2 = *rb2.position() * j.local_anchor2;
                    let (r1, r2) = (p1 - t1.com, p2 - t2.com);
                    let d = p2 - p1;
                    let axis = (*rb1.rotation() * j.local_axis1).normalize();
                    let (u1, u2) = orthonormal_pair(axis);
                    // Linear rows: g = (p2 - p1).t = 0 for t normal to the axis, turning with
                    // body 1. g'' = (a_p2 - a_p1).t + 2 (v_p2 - v_p1).(w1 x t)
                    //   + d.(alpha1 x t + w1 x (w1 x t)); the alpha1 term moves body 1's angular
                    // block to the lever of p2 (the reaction acts at the slider's point).
                    let v_rel = (v2 + w2.cross(r2)) - (v1 + w1.cross(r1));
                    let c_pts = w2.cross(w2.cross(r2)) - w1.cross(w1.cross(r1));
                    let free_pts = a2f + a2t.cross(r2) - a1f - a1t.cross(r1);
                    for t in [u1, u2] {
                        let wt = w1.cross(t);
                        let c = c_pts.dot(t) + 2.0 * v_rel.dot(wt) + d.dot(w1.cross(wt));
                        let free = free_pts.dot(t) + a1t.dot(t.cross(d));
                        self.rows.push([-t, -(r1 + d).cross(t), t, r2.cross(t)]);
                        self.b.push(-(c + free));
                    }
                    // Angular rows: w2 - w1 = 0 along the world axes (no relative rotation at
                    // all, so the turning of the directions adds nothing).
                    for e in [Vector::X, Vector::Y, Vector::Z] {
                        self.rows.push([Vector::ZERO, -e, Vector::ZERO, e]);
                        self.b.push(-(a2t - a1t).dot(e));
                    }
                }
                IdealJoint::Spherical(j) => {
                    let r1 = *rb1.position() * j.local_anchor1 - t1.com;
                    let r2 = *rb2.position() * j.local_anchor2 - t2.com;
                    let c_lin = w2.cross(w2.cross(r2)) - w1.cross(w1.cross(r1));
                    let free_lin = a2f + a2t.cross(r2) - a1f - a1t.cross(r1);
                    for d in [Vector::X, Vector::Y, Vector::Z] {
                        self.rows.push([-d, -r1.cross(d), d, r2.cross(d)]);
                        self.b.push(-(c_lin.dot(d) + free_lin.dot(d)));
                    }
                }
                IdealJoint::Fixed(j) => {
                    let r1 = *rb1.position() * j.local_anchor1 - t1.com;
                    let r2 = *rb2.position() * j.local_anchor2 - t2.com;
                    let c_lin = w2.cross(w2.cross(r2)) - w1.cross(w1.cross(r1));
                    let free_lin = a2f + a2t.cross(r2) - a1f - a1t.cross(r1);
                    for d in [Vector::X, Vector::Y, Vector::Z] {
                        self.rows.push([-d, -r1.cross(d), d, r2.cross(d)]);
                        self.b.push(-(c_lin.dot(d) + free_lin.dot(d)));
                    }
                    for e in [Vector::X, Vector::Y, Vector::Z] {
                        self.rows.push([Vector::ZERO, -e, Vector::ZERO, e]);
                        self.b.push(-(a2t - a1t).dot(e));
                    }
                }
            }
        }
        let n = self.rows.len();
        self.a.clear();
        self.a.resize(n * n, 0.0);
        // A = J M^-1 J^T: entries between rows sharing a body.
        for (p, jp) in joints.iter().enumerate() {
            let (sp, np) = (self.starts[p], jp.rows().0);
            let bp_h = jp.bodies();
            for (q, jq) in joints.iter().enumerate() {
                let (sq, nq) = (self.starts[q], jq.rows().0);
                let bq_h = jq.bodies();
                for (bp, hp) in [(0usize, bp_h.0), (2, bp_h.1)] {
                    for (bq, hq) in [(0usize, bq_h.0), (2, bq_h.1)] {
                        if hp != hq {
                            continue;
                        }
                        let rb = bodies.get(hp)?;
                        let t = terms(rb, hp, gravity, &self.extra);
                        if !t.dynamic {
                            continue;
                        }
                        for i in 0..np {
                            let row_p = self.rows[sp + i];
                            let (mf, mt) = t.apply_inv_mass(rb, row_p[bp], row_p[bp + 1]);
                            for k in 0..nq {
                                let row_q = self.rows[sq + k];
                                self.a[(sp + i) * n + sq + k] +=
                                    mf.dot(row_q[bq]) + mt.dot(row_q[bq + 1]);
                            }
                        }
                    }
                }
            }
        }
        self.a_copy.clone_from(&self.a);
        self.b_copy.clone_from(&self.b);
        if !solve_dense(&mut self.a, &mut self.b, n) {
            // Redundant constraints: a least-norm share through a small regularisation.
            let scale = self.a_copy.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for i in 0..n {
                self.a_copy[i * n + i] += 1e-12 * scale;
            }
            std::mem::swap(&mut self.a, &mut self.a_copy);
            std::mem::swap(&mut self.b, &mut self.b_copy);
            if !solve_dense(&mut self.a, &mut self.b, n) {
                return None;
            }
        }
        // The force on body 2: the linear rows' multipliers along their directions.
        for (k, j) in joints.iter().enumerate() {
            let (s, lin) = (self.starts[k], j.rows().1);
            let mut f = Vector::ZERO;
            for i in 0..lin {
                f += self.b[s + i] * self.rows[s + i][2];
            }
            self.forces.push(f);
        }
        Some(())
    }
}

/// Gaussian elimination with partial pivoting on the `n x n` row-major `a`; the solution replaces
/// `b`. False when `a` is singular to working precision.
fn solve_dense(a: &mut [f64], b: &mut [f64], n: usize) -> bool {
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if !(scale > 0.0) && n > 0 {
        return false;
    }
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&i, &k| a[i * n + col].abs().total_cmp(&a[k * n + col].abs()))
            .unwrap_or(col);
        if !(a[pivot * n + col].abs() > 1e-12 * scale) {
            return false;
        }
        if pivot != col {
            for k in 0..n {
                a.swap(pivot * n + k, col * n + k);
            }
            b.swap(pivot, col);
        }
        for i in col + 1..n {
            let f = a[i * n + col] / a[col * n + col];
            if f != 0.0 {
                for k in col..n {
                    a[i * n + k] -= f * a[col * n + k];
                }
                b[i] -= f * b[col];
            }
        }
    }
    for col in (0..n).rev() {
        let mut s = b[col];
        for k in col + 1..n {
            s -= a[col * n + k] * b[k];
        }
        b[col] = s / a[col * n + col];
    }
    true
}

/// Computes the local mass properties of every dynamic body that has none yet (Rapier does it at
/// the first step; the solver needs them before).
pub fn prepare_mass_properties(bodies: &mut RigidBodySet) {
    let handles: Vec<RigidBodyHandle> = bodies.iter().map(|(h, _)| h).collect();
    for h in handles {
        crate::rapier::ledger::ensure_mass_properties(bodies, None, h);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rapier3d_f64::prelude::{MassProperties, RigidBodyBuilder};

    #[test]
    fn dense_solve_by_hand() {
        // 2x + y = 3, x + 3y = 5 -> x = 0.8, y = 1.4
        let mut a = vec![2.0, 1.0, 1.0, 3.0];
        let mut b = vec![3.0, 5.0];
        assert!(solve_dense(&mut a, &mut b, 2));
        assert!((b[0] - 0.8).abs() < 1e-15 && (b[1] - 1.4).abs() < 1e-15);
        let mut a = vec![1.0, 2.0, 2.0, 4.0];
        assert!(!solve_dense(&mut a, &mut [1.0, 2.0], 2));
    }

    #[test]
    fn spinning_arm_needs_the_centripetal_force() {
        // Arm of 2 kg, COM 0.3 m from a fixed pivot, spinning at 5 rad/s about z, no gravity:
        // the pivot pulls with m w^2 r = 15 N towards itself; no angular acceleration.
        let mut bodies = RigidBodySet::new();
        let base = bodies.insert(RigidBodyBuilder::fixed());
        let arm = bodies.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(0.3, 0.0, 0.0))
                .linvel(Vector::new(0.0, 1.5, 0.0))
                .angvel(Vector::new(0.0, 0.0, 5.0))
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    2.0,
                    Vector::new(0.01, 0.02, 0.03),
                )),
        );
        prepare_mass_properties(&mut bodies);
        let j = IdealRevolute {
            body1: base,
            body2: arm,
            local_anchor1: Vector::ZERO,
            local_anchor2: Vector::new(-0.3, 0.0, 0.0),
            local_axis1: Vector::Z,
        };
        let mut s = ReactionSolver::default();
        let f = s.solve(&bodies, &[j], Vector::ZERO).unwrap()[0];
        assert!((f - Vector::new(-15.0, 0.0, 0.0)).length() < 1e-9, "{f:?}");
    }

    #[test]
    fn torque_driven_arm_by_hand() {
        // Torque 1 N m about z on the arm at rest: I_pivot = 0.03 + 2 * 0.09 = 0.21,
        // alpha = 1/0.21, the pivot supplies m alpha r = 2 * 0.3/0.21 N along +y.
        let mut bodies = RigidBodySet::new();
        let base = bodies.insert(RigidBodyBuilder::fixed());
        let arm = bodies.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(0.3, 0.0, 0.0))
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    2.0,
                    Vector::new(0.01, 0.02, 0.03),
                )),
        );
        prepare_mass_properties(&mut bodies);
        bodies[arm].add_torque(Vector::new(0.0, 0.0, 1.0), false);
        let j = IdealRevolute {
            body1: base,
            body2: arm,
            local_anchor1: Vector::ZERO,
            local_anchor2: Vector::new(-0.3, 0.0, 0.0),
            local_axis1: Vector::Z,
        };
        let mut s = ReactionSolver::default();
        let f = s.solve(&bodies, &[j], Vector::ZERO).unwrap()[0];
        let expected = 2.0 * 0.3 / 0.21;
        assert!(
            (f - Vector::new(0.0, expected, 0.0)).length() < 1e-9,
            "{f:?}"
        );
    }

    fn slider(
        bodies: &mut RigidBodySet,
        at: Vector,
        linvel: Vector,
        angvel: Vector,
    ) -> RigidBodyHandle {
        bodies.insert(
            RigidBodyBuilder::dynamic()
                .translation(at)
                .linvel(linvel)
                .angvel(angvel)
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    2.0,
                    Vector::new(0.01, 0.02, 0.03),
                )),
        )
    }

    #[test]
    fn slider_on_a_fixed_guide_carries_its_weight_not_its_drive() {
        // 2 kg on a guide along x under gravity -y, pushed by 3 N along x: the guide supplies
        // m g = 19.62 N upwards and nothing along the slide.
        let mut bodies = RigidBodySet::new();
        let base = bodies.insert(RigidBodyBuilder::fixed());
        let s = slider(
            &mut bodies,
            Vector::new(0.4, 0.1, 0.0),
            Vector::new(1.0, 0.0, 0.0),
            Vector::ZERO,
        );
        prepare_mass_properties(&mut bodies);
        bodies[s].add_force(Vector::new(3.0, 0.0, 0.0), false);
        let j = IdealPrismatic {
            body1: base,
            body2: s,
            local_anchor1: Vector::new(0.0, 0.1, 0.0),
            local_anchor2: Vector::ZERO,
            local_axis1: Vector::X,
        };
        let mut solver = ReactionSolver::default();
        let f = solver
            .solve_joints(&bodies, &[j.into()], Vector::new(0.0, -9.81, 0.0))
            .unwrap()[0];
        assert!((f - Vector::new(0.0, 19.62, 0.0)).length() < 1e-9, "{f:?}");
    }

    #[test]
    fn slider_on_a_spinning_guide_needs_the_coriolis_force() {
        // A guide along its x axis turning at w = 3 rad/s about z (kinematic, at the origin);
        // the 2 kg slider at r = 0.5 m moves out at v = 0.2 m/s and turns with it. Along the
        // guide it is free; across it the guide supplies the Coriolis force 2 m w v = 2.4 N
        // (+y), no angular acceleration being needed.
        let (w, r, v) = (3.0, 0.5, 0.2);
        let mut bodies = RigidBodySet::new();
        let guide = bodies
            .insert(RigidBodyBuilder::kinematic_velocity_based().angvel(Vector::new(0.0, 0.0, w)));
        let s = slider(
            &mut bodies,
            Vector::new(r, 0.0, 0.0),
            Vector::new(v, w * r, 0.0),
            Vector::new(0.0, 0.0, w),
        );
        prepare_mass_properties(&mut bodies);
        let j = IdealPrismatic {
            body1: guide,
            body2: s,
            local_anchor1: Vector::ZERO,
            local_anchor2: Vector::ZERO,
            local_axis1: Vector::X,
        };
        let mut solver = ReactionSolver::default();
        let f = solver
            .solve_joints(&bodies, &[j.into()], Vector::ZERO)
            .unwrap()[0];
        assert!(
            (f - Vector::new(0.0, 2.0 * 2.0 * w * v, 0.0)).length() < 1e-9,
            "{f:?}"
        );
    }

    #[test]
    fn welded_block_on_a_spinning_base() {
        // A 2 kg block welded 0.3 m from the axis of a base turning at 5 rad/s (kinematic):
        // the weld pulls with m w^2 r = 15 N towards the axis and holds its weight 19.62 N.
        let mut bodies = RigidBodySet::new();
        let base = bodies.insert(
            RigidBodyBuilder::kinematic_velocity_based().angvel(Vector::new(0.0, 0.0, 5.0)),
        );
        let b = slider(
            &mut bodies,
            Vector::new(0.3, 0.0, 0.0),
            Vector::new(0.0, 1.5, 0.0),
            Vector::new(0.0, 0.0, 5.0),
        );
        prepare_mass_properties(&mut bodies);
        let j = IdealFixed {
            body1: base,
            body2: b,
            local_anchor1: Vector::new(0.3, 0.0, 0.0),
            local_anchor2: Vector::ZERO,
        };
        let mut solver = ReactionSolver::default();
        let f = solver
            .solve_joints(&bodies, &[j.into()], Vector::new(0.0, 0.0, -9.81))
            .unwrap()[0];
        assert!(
            (f - Vector::new(-15.0, 0.0, 19.62)).length() < 1e-9,
            "{f:?}"
        );
    }

    #[test]
    fn ball_joint_pendulum_swinging_through_the_bottom() {
        // A 2 kg point-like bob 0.5 m below a ball joint, passing the bottom at 1 m/s: the joint
        // pulls up with m g + m v^2/L = 19.62 + 4 = 23.62 N.
        let mut bodies = RigidBodySet::new();
        let base = bodies.insert(RigidBodyBuilder::fixed());
        let bob = slider(
            &mut bodies,
            Vector::new(0.0, -0.5, 0.0),
            Vector::new(1.0, 0.0, 0.0),
            Vector::new(0.0, 0.0, 2.0),
        );
        prepare_mass_properties(&mut bodies);
        let j = IdealSpherical {
            body1: base,
            body2: bob,
            local_anchor1: Vector::ZERO,
            local_anchor2: Vector::new(0.0, 0.5, 0.0),
        };
        let mut solver = ReactionSolver::default();
        let f = solver
            .solve_joints(&bodies, &[j.into()], Vector::new(0.0, -9.81, 0.0))
            .unwrap()[0];
        // The bob's own spin (2 rad/s about z) is the pendulum's: no torque is needed at the ball.
        assert!((f - Vector::new(0.0, 23.62, 0.0)).length() < 1e-9, "{f:?}");
    }

    #[test]
    fn motor_holding_an_arm_level_supplies_its_moment() {
        // A 2 kg arm, centre of mass 0.3 m out along x from a pivot on a fixed base, at rest
        // under gravity -y, held by a velocity motor at zero speed: the pivot carries the weight
        // (19.62 N up), and the motor's moment m g r = 5.886 N m is in the extra row.
        let mut bodies = RigidBodySet::new();
        let base = bodies.insert(RigidBodyBuilder::fixed());
        let arm = slider(
            &mut bodies,
            Vector::new(0.3, 0.0, 0.0),
            Vector::ZERO,
            Vector::ZERO,
        );
        prepare_mass_properties(&mut bodies);
        let j = IdealRevolute {
            body1: base,
            body2: arm,
            local_anchor1: Vector::ZERO,
            local_anchor2: Vector::new(-0.3, 0.0, 0.0),
            local_axis1: Vector::Z,
        };
        let mut solver = ReactionSolver::default();
        let g = Vector::new(0.0, -9.81, 0.0);
        let f = solver
            .solve_joints(&bodies, &[IdealJoint::MotorRevolute(j)], g)
            .unwrap()[0];
        assert!((f - Vector::new(0.0, 19.62, 0.0)).length() < 1e-9, "{f:?}");
        assert!(
            (solver.b[5] - 2.0 * 9.81 * 0.3).abs() < 1e-9,
            "{}",
            solver.b[5]
        );
        // Without the motor the arm falls: the pivot carries less than the weight,
        // m g (1 - m r^2 / I_pivot) with I_pivot = 0.03 + 2 * 0.09 = 0.21.
        let f = solver.solve(&bodies, &[j], g).unwrap()[0];
        let expected = 19.62 * (1.0 - 2.0 * 0.09 / 0.21);
        assert!((f.y - expected).abs() < 1e-9, "{f:?} against {expected}");
    }

    #[test]
    fn weld_on_an_accelerating_driven_base() {
        // A base turning up from rest with a prescribed 10 rad/s^2 about z; a 2 kg block welded
        // 0.3 m out along x: the weld pushes it along +y with m alpha r = 6 N.
        let mut bodies = RigidBodySet::new();
        let base = bodies.insert(RigidBodyBuilder::kinematic_position_based());
        let b = slider(
            &mut bodies,
            Vector::new(0.3, 0.0, 0.0),
            Vector::ZERO,
            Vector::ZERO,
        );
        prepare_mass_properties(&mut bodies);
        let j = IdealFixed {
            body1: base,
            body2: b,
            local_anchor1: Vector::new(0.3, 0.0, 0.0),
            local_anchor2: Vector::ZERO,
        };
        let mut solver = ReactionSolver::default();
        // Without the prescribed acceleration the base would be taken to move steadily.
        let f = solver
            .solve_joints(&bodies, &[j.into()], Vector::ZERO)
            .unwrap()[0];
        assert!(f.length() < 1e-12);
        solver.kinematic.push(KinematicState {
            body: base,
            linvel: Vector::ZERO,
            angvel: Vector::ZERO,
            linacc: Vector::ZERO,
            angacc: Vector::new(0.0, 0.0, 10.0),
        });
        let f = solver
            .solve_joints(&bodies, &[j.into()], Vector::ZERO)
            .unwrap()[0];
        assert!((f - Vector::new(0.0, 6.0, 0.0)).length() < 1e-9, "{f:?}");
    }
}
