//! The constraint rows of each joint kind (Jacobian, velocity-product terms) and `J M^-1 J^T`.

use super::joints::JointModel;
use super::{IdealJoint, ReactionSolver};
use rapier3d_f64::math::Vector;

/// One constraint row between two bodies of the solve.
#[derive(Clone, Copy, Debug)]
pub(super) struct Row {
    /// Indices of the two bodies in the solve's body table.
    pub(super) b1: usize,
    pub(super) b2: usize,
    /// Jacobian blocks: linear and angular for body 1, then for body 2.
    pub(super) jac: [Vector; 4],
    /// The velocity-product term: `J a + c = 0`.
    pub(super) c: f64,
    /// A position constraint (its velocity `J v` is zero); false for a motor's speed row.
    pub(super) position: bool,
}

impl Row {
    pub(super) fn dot(&self, a1: (Vector, Vector), a2: (Vector, Vector)) -> f64 {
        self.jac[0].dot(a1.0)
            + self.jac[1].dot(a1.1)
            + self.jac[2].dot(a2.0)
            + self.jac[3].dot(a2.1)
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
    /// The rows of every joint at the bodies' current velocities (the Jacobian from the
    /// positions, the velocity-product terms `c` from the velocities).
    pub(super) fn build_rows(&mut self, joints: &[IdealJoint], pairs: &[(usize, usize)]) {
        self.rows.clear();
        self.starts.clear();
        for (j, &(i1, i2)) in joints.iter().map(|j| &j.0).zip(pairs) {
            self.starts.push(self.rows.len());
            let (e1, e2) = (&self.entries[i1], &self.entries[i2]);
            let (v1, v2, w1, w2) = (e1.v, e2.v, e1.w, e2.w);
            let held = matches!(
                j,
                JointModel::MotorRevolute(_) | JointModel::MotorPrismatic(_)
            );
            let mut push = |jac: [Vector; 4], c: f64, position: bool| {
                self.rows.push(Row {
                    b1: i1,
                    b2: i2,
                    jac,
                    c,
                    position,
                })
            };
            // Point-coincidence rows `p2 - p1 = 0` along the world axes, `c` the centripetal
            // terms.
            let point_rows =
                |push: &mut dyn FnMut([Vector; 4], f64, bool), r1: Vector, r2: Vector| {
                    let c_lin = w2.cross(w2.cross(r2)) - w1.cross(w1.cross(r1));
                    for d in [Vector::X, Vector::Y, Vector::Z] {
                        push([-d, -r1.cross(d), d, r2.cross(d)], c_lin.dot(d), true);
                    }
                };
            // No relative rotation about the world axes.
            let weld_rows = |push: &mut dyn FnMut([Vector; 4], f64, bool)| {
                for e in [Vector::X, Vector::Y, Vector::Z] {
                    push([Vector::ZERO, -e, Vector::ZERO, e], 0.0, true);
                }
            };
            match j {
                JointModel::Revolute(j)
                | JointModel::MotorRevolute(j)
                | JointModel::SoftMotorRevolute(j, _) => {
                    let r1 = e1.pose * j.local_anchor1 - e1.com;
                    let r2 = e2.pose * j.local_anchor2 - e2.com;
                    let axis = (e1.rot * j.local_axis1).normalize();
                    let (u1, u2) = orthonormal_pair(axis);
                    point_rows(&mut push, r1, r2);
                    // (w2 - w1).t = 0 for the two directions t normal to the axis, which turn
                    // with body 1; a held speed adds t = axis (a speed row).
                    let ang = |t: Vector| (w2 - w1).dot(w1.cross(t));
                    push([Vector::ZERO, -u1, Vector::ZERO, u1], ang(u1), true);
                    push([Vector::ZERO, -u2, Vector::ZERO, u2], ang(u2), true);
                    if held {
                        push([Vector::ZERO, -axis, Vector::ZERO, axis], ang(axis), false);
                    }
                }
                JointModel::Prismatic(j)
                | JointModel::MotorPrismatic(j)
                | JointModel::SoftMotorPrismatic(j, _) => {
                    let p1 = e1.pose * j.local_anchor1;
                    let p2 = e2.pose * j.local_anchor2;
                    let (r1, r2) = (p1 - e1.com, p2 - e2.com);
                    let d = p2 - p1;
                    let axis = (e1.rot * j.local_axis1).normalize();
                    let (u1, u2) = orthonormal_pair(axis);
                    // g = (p2 - p1).t = 0 for t normal to the axis, turning with body 1:
                    // g'' = (a_p2 - a_p1).t + 2 (v_p2 - v_p1).(w1 x t)
                    //   + d.(alpha1 x t + w1 x (w1 x t)); the alpha1 term moves body 1's angular
                    // block to the lever of p2 (the reaction acts at the slider's point). A held
                    // speed along the axis is the same with t = axis (a speed row).
                    let v_rel = (v2 + w2.cross(r2)) - (v1 + w1.cross(r1));
                    let c_pts = w2.cross(w2.cross(r2)) - w1.cross(w1.cross(r1));
                    let row = |t: Vector| {
                        let wt = w1.cross(t);
                        (
                            [-t, -(r1 + d).cross(t), t, r2.cross(t)],
                            c_pts.dot(t) + 2.0 * v_rel.dot(wt) + d.dot(w1.cross(wt)),
                        )
                    };
                    for t in [u1, u2] {
                        let (jac, c) = row(t);
                        push(jac, c, true);
                    }
                    weld_rows(&mut push);
                    if held {
                        let (jac, c) = row(axis);
                        push(jac, c, false);
                    }
                }
                JointModel::Spherical(j) => {
                    let r1 = e1.pose * j.local_anchor1 - e1.com;
                    let r2 = e2.pose * j.local_anchor2 - e2.com;
                    point_rows(&mut push, r1, r2);
                }
                JointModel::Fixed(j) => {
                    let r1 = e1.pose * j.local_anchor1 - e1.com;
                    let r2 = e2.pose * j.local_anchor2 - e2.com;
                    point_rows(&mut push, r1, r2);
                    weld_rows(&mut push);
                }
            }
        }
    }

    /// `A = J M^-1 J^T` into `self.a`: entries between rows sharing a body.
    pub(super) fn assemble(&mut self) {
        let n = self.rows.len();
        self.a.clear();
        self.a.resize(n * n, 0.0);
        for p in 0..n {
            let rp = self.rows[p];
            for (bp, side) in [(rp.b1, 0usize), (rp.b2, 2)] {
                let e = &self.entries[bp];
                if !e.dynamic {
                    continue;
                }
                let (mf, mt) = e.apply_inv_mass(rp.jac[side], rp.jac[side + 1]);
                for (q, rq) in self.rows.iter().enumerate() {
                    for (bq, sq) in [(rq.b1, 0usize), (rq.b2, 2)] {
                        if bq == bp {
                            self.a[p * n + q] += mf.dot(rq.jac[sq]) + mt.dot(rq.jac[sq + 1]);
                        }
                    }
                }
            }
        }
    }
}
