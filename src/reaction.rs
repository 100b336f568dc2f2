//! Exact reactions of ideal revolute joints at a state, from the constrained rigid-body equations
//! (not from Rapier's impulses or momentum differences, which carry its integrator's lag).
//!
//! For bodies with mass matrices `M`, applied wrenches `F` (user forces and torques, gravity,
//! gyroscopic terms) and revolute joints whose constraints have Jacobian `J` and velocity-product
//! terms `c` (`J a + c = 0` for the accelerations `a`), the multipliers solve
//! `J M^-1 J^T lambda = -c - J M^-1 F`: the joint forces the ideal mechanism needs at this
//! position and velocity. They do not depend on the step: the same state gives the same reaction
//! whatever the step control, which momentum balances over a step do not achieve (Rapier's
//! constraint turns a jointed body's velocity by the motion since the previous step, while applied
//! forces act over the current one).
//!
//! ```
//! use clearance_joint::reaction::{IdealRevolute, ReactionSolver};
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
//! # clearance_joint::reaction::prepare_mass_properties(&mut bodies);
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

use crate::ledger::Wrench;
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

/// Rows per revolute joint: three linear (anchors coincide) and two angular (axes stay aligned).
const ROWS: usize = 5;

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
    extra: Vec<Wrench>,
    /// Per joint and row: the Jacobian blocks `(linear, angular)` for body 1 and body 2.
    rows: Vec<[Vector; 4]>,
    forces: Vec<Vector>,
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
    let com = crate::ledger::world_center_of_mass(rb);
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
    /// current state under their user forces and torques and `gravity`. Only these revolute
    /// joints are taken as constraints: contacts with colliders and other joints are not (see
    /// [`solve_with`](Self::solve_with) for forces you know of, such as the wrenches of
    /// [`ForceSource`](crate::stepper::ForceSource)s). Redundant constraints (a
    /// closed loop, whose reactions rigid dynamics alone do not determine) get a least-norm
    /// share through a relative regularisation of 1e-12, used only when the system is singular. `None` when a body is missing.
    pub fn solve(
        &mut self,
        bodies: &RigidBodySet,
        joints: &[IdealRevolute],
        gravity: Vector,
    ) -> Option<&[Vector]> {
        self.solve_with(bodies, joints, gravity, &[])
    }

    /// [`solve`](Self::solve) with further applied wrenches on the bodies: those of the force
    /// sources the [`Stepper`](crate::stepper::Stepper) adds during its steps only (drives,
    /// clearance contacts), which the bodies' user forces do not hold between steps.
    pub fn solve_with(
        &mut self,
        bodies: &RigidBodySet,
        joints: &[IdealRevolute],
        gravity: Vector,
        extra: &[Wrench],
    ) -> Option<&[Vector]> {
        self.extra.clear();
        self.extra.extend_from_slice(extra);
        let n = joints.len() * ROWS;
        self.a.clear();
        self.a.resize(n * n, 0.0);
        self.b.clear();
        self.rows.clear();
        self.forces.clear();
        // Jacobian rows and right-hand sides.
        for j in joints {
            let (rb1, rb2) = (bodies.get(j.body1)?, bodies.get(j.body2)?);
            let (t1, t2) = (
                terms(rb1, j.body1, gravity, &self.extra),
                terms(rb2, j.body2, gravity, &self.extra),
            );
            let r1 = *rb1.position() * j.local_anchor1 - t1.com;
            let r2 = *rb2.position() * j.local_anchor2 - t2.com;
            let axis = (*rb1.rotation() * j.local_axis1).normalize();
            let (u1, u2) = orthonormal_pair(axis);
            let (w1, w2) = (t1.angvel, t2.angvel);
            let (a1f, a1t) = t1.apply_inv_mass(rb1, t1.force, t1.torque);
            let (a2f, a2t) = t2.apply_inv_mass(rb2, t2.force, t2.torque);
            // Linear rows: p2 - p1 = 0, `J a + c = 0` with c the centripetal terms.
            let c_lin = w2.cross(w2.cross(r2)) - w1.cross(w1.cross(r1));
            let free_lin = a2f + a2t.cross(r2) - a1f - a1t.cross(r1);
            for d in [Vector::X, Vector::Y, Vector::Z] {
                self.rows.push([-d, -r1.cross(d), d, r2.cross(d)]);
                self.b.push(-(c_lin.dot(d) + free_lin.dot(d)));
            }
            // Angular rows: (w2 - w1).t = 0 for the two directions t normal to the axis, which
            // turn with body 1.
            for t in [u1, u2] {
                let c_ang = (w2 - w1).dot(w1.cross(t));
                self.rows.push([Vector::ZERO, -t, Vector::ZERO, t]);
                self.b.push(-(c_ang + (a2t - a1t).dot(t)));
            }
        }
        // A = J M^-1 J^T: entries between rows sharing a body.
        for (p, jp) in joints.iter().enumerate() {
            for (q, jq) in joints.iter().enumerate() {
                for (bp, hp) in [(0usize, jp.body1), (2, jp.body2)] {
                    for (bq, hq) in [(0usize, jq.body1), (2, jq.body2)] {
                        if hp != hq {
                            continue;
                        }
                        let rb = bodies.get(hp)?;
                        let t = terms(rb, hp, gravity, &self.extra);
                        if !t.dynamic {
                            continue;
                        }
                        for i in 0..ROWS {
                            let row_p = self.rows[p * ROWS + i];
                            let (mf, mt) = t.apply_inv_mass(rb, row_p[bp], row_p[bp + 1]);
                            for k in 0..ROWS {
                                let row_q = self.rows[q * ROWS + k];
                                self.a[(p * ROWS + i) * n + q * ROWS + k] +=
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
        for k in 0..joints.len() {
            let l = &self.b[k * ROWS..k * ROWS + 3];
            self.forces.push(Vector::new(l[0], l[1], l[2]));
        }
        Some(&self.forces)
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
        crate::ledger::ensure_mass_properties(bodies, None, h);
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

    /// A 2 kg arm, centre of mass 0.3 m along x from a fixed pivot about z, with the given
    /// velocities: the bodies and the pivot.
    fn arm(linvel: Vector, angvel: Vector) -> (RigidBodySet, RigidBodyHandle, IdealRevolute) {
        let mut bodies = RigidBodySet::new();
        let base = bodies.insert(RigidBodyBuilder::fixed());
        let arm = bodies.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(0.3, 0.0, 0.0))
                .linvel(linvel)
                .angvel(angvel)
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
        (bodies, arm, j)
    }

    #[test]
    fn spinning_arm_needs_the_centripetal_force() {
        // Spinning at 5 rad/s about z, no gravity: the pivot pulls with m w^2 r = 15 N towards
        // itself; no angular acceleration.
        let (bodies, _, j) = arm(Vector::new(0.0, 1.5, 0.0), Vector::new(0.0, 0.0, 5.0));
        let mut s = ReactionSolver::default();
        let f = s.solve(&bodies, &[j], Vector::ZERO).unwrap()[0];
        assert!((f - Vector::new(-15.0, 0.0, 0.0)).length() < 1e-9, "{f:?}");
    }

    #[test]
    fn torque_driven_arm_by_hand() {
        // Torque 1 N m about z on the arm at rest: I_pivot = 0.03 + 2 * 0.09 = 0.21,
        // alpha = 1/0.21, the pivot supplies m alpha r = 2 * 0.3/0.21 N along +y.
        let (mut bodies, arm, j) = arm(Vector::ZERO, Vector::ZERO);
        bodies[arm].add_torque(Vector::new(0.0, 0.0, 1.0), false);
        let mut s = ReactionSolver::default();
        let f = s.solve(&bodies, &[j], Vector::ZERO).unwrap()[0];
        let expected = 2.0 * 0.3 / 0.21;
        assert!(
            (f - Vector::new(0.0, expected, 0.0)).length() < 1e-9,
            "{f:?}"
        );
    }
}
