//! The contact's effective mass through the mechanism: how heavy the journal feels along a
//! contact direction once the bodies' ideal joints (Rapier's impulse joints) take their share.
//!
//! A contact force along `n` at a point `p` is one more row `J` of the constrained equations
//! (MODEL.md §1: `[-n, -(p - c_i) x n, n, (p - c_j) x n]` on the bearing's and the journal's
//! bodies). With the rows `G` of every ideal joint of the two bodies' island and the masses `M`,
//! the contact feels
//!
//! `1/m = J M^-1 J^T - (G M^-1 J^T)^T (G M^-1 G^T)^-1 (G M^-1 J^T)`,
//!
//! the free bodies' inverse mass less what the joints hold. A pin 0.1 m from the pivot of an arm
//! of 1.35e-3 kg m² about it feels `I/L² = 0.135 kg`, not the free arm's 0.037 kg. The contact
//! laws' damping (through the loaded-impact rate), the rate carried to the state and the step
//! bounds all read this mass.
//!
//! The island is every dynamic body reached from the joint's two bodies through enabled impulse
//! joints (fixed and kinematic bodies end it: they do not move under forces). Each joint's
//! locked axes are rows; a motor on a free axis is a row too when it holds its speed over any
//! contact ([`HELD_MOTOR_RATE`]). Joint limits and Rapier's multibody joints are not rows.
//! Without a row on either body, the correction is exactly zero and the free mass is kept to the
//! bit.

use crate::rapier::observers::reaction::lu::{factor_regularised, lu_solve};
use crate::rapier::pipeline::ledger::world_center_of_mass;
use rapier3d_f64::math::{AngularInertia, Vector};
use rapier3d_f64::prelude::{
    ImpulseJointSet, JointAxesMask, MotorModel, RigidBody, RigidBodyHandle, RigidBodySet,
};

/// The relaxation rate (1/s) from which a joint motor counts as holding its speed: a row of the
/// mechanism rather than a soft force. A motor that relaxes a speed error in 10 us or less (an
/// acceleration-based damping of 1e5/s; a force-based one over the row's effective mass) does so
/// well inside the shortest contact the step control resolves; a softer motor lets the contact
/// move its axis and is left out (a lighter contact, so a shorter step: the safe side).
pub(crate) const HELD_MOTOR_RATE: f64 = 1e5;

/// The pair's inverse mass is floored at this fraction of the free bodies': a contact direction
/// that the ideal joints hold entirely (a redundant mechanism) has no finite effective mass.
const MIN_MOBILITY: f64 = 1e-12;

/// One dynamic body of the island.
#[derive(Clone, Copy, Debug)]
struct IslandBody {
    handle: RigidBodyHandle,
    inv_mass: f64,
    inv_inertia: AngularInertia,
    center_of_mass: Vector,
}

/// One constraint row: the island indices of its bodies (`None`: not dynamic) and its Jacobian
/// blocks (linear and angular, body 1 then body 2).
#[derive(Clone, Copy, Debug)]
struct Row {
    bodies: [Option<usize>; 2],
    jac: [Vector; 4],
}

/// The mechanism around one clearance joint at the current poses: the correction of its
/// effective mass for the ideal joints ([module docs](self)). Rebuilt at each evaluation; keeps
/// its buffers.
#[derive(Clone, Debug, Default)]
pub(crate) struct Mechanism {
    island: Vec<IslandBody>,
    rows: Vec<Row>,
    /// The joint's bearing and journal bodies in the island (`None`: not dynamic).
    pair: [Option<usize>; 2],
    /// `(G M^-1)_pair^T (G M^-1 G^T)^-1 (G M^-1)_pair`: 12 x 12, row-major, over the pair's
    /// linear and angular coordinates (bearing, then journal). Empty without rows on the pair.
    correction: Vec<f64>,
    // Scratch.
    a: Vec<f64>,
    lu: Vec<f64>,
    piv: Vec<usize>,
    b: Vec<f64>,
    x: Vec<f64>,
    column: Vec<f64>,
    scratch: Vec<f64>,
    queue: Vec<RigidBodyHandle>,
}

impl IslandBody {
    fn of(rb: &RigidBody, handle: RigidBodyHandle) -> Self {
        let mp = &rb.mass_properties().local_mprops;
        IslandBody {
            handle,
            inv_mass: mp.inv_mass,
            inv_inertia: mp.world_inv_inertia(rb.rotation()),
            center_of_mass: world_center_of_mass(rb),
        }
    }

    /// `M^-1` of this body applied to a (force, torque) pair.
    fn mobility(&self, f: Vector, t: Vector) -> (Vector, Vector) {
        (self.inv_mass * f, self.inv_inertia * t)
    }
}

impl Mechanism {
    /// Rebuilds the mechanism of the joint between `body1` (bearing) and `body2` (journal) at the
    /// bodies' current poses.
    pub(crate) fn rebuild(
        &mut self,
        bodies: &RigidBodySet,
        joints: &ImpulseJointSet,
        body1: RigidBodyHandle,
        body2: RigidBodyHandle,
    ) {
        self.island.clear();
        self.rows.clear();
        self.correction.clear();
        self.collect_island(bodies, joints, [body1, body2]);
        self.pair = [self.index(body1), self.index(body2)];
        if self.pair == [None, None] {
            return;
        }
        self.collect_rows(bodies, joints);
        let touches_pair = self.rows.iter().any(|r| {
            r.bodies
                .iter()
                .any(|b| b.is_some() && self.pair.contains(b))
        });
        if touches_pair {
            self.factor_correction();
        }
    }

    /// How much less the pair's inverse mass is along `n` at `point` than the free bodies'
    /// (kg^-1, >= 0): `g^T (G M^-1 G^T)^-1 g`, `g = G M^-1 J^T`. Zero without rows on the pair.
    pub(crate) fn held_inverse_mass(&self, point: Vector, n: Vector) -> f64 {
        if self.correction.is_empty() {
            return 0.0;
        }
        let j = self.contact_row(point, n);
        let mut held = 0.0;
        for (p, jp) in j.iter().enumerate() {
            let row = &self.correction[p * 12..p * 12 + 12];
            held += jp * row.iter().zip(&j).map(|(c, jq)| c * jq).sum::<f64>();
        }
        held.max(0.0)
    }

    /// What the ideal joints hold between two loads on the pair, `a^T C b` over its 12
    /// coordinates (`C = g^T (G M^-1 G^T)^-1 g` as [`held_inverse_mass`](Self::held_inverse_mass)
    /// for one row; `a`, `b` contact rows or sums of them). Zero without rows on the pair.
    pub(crate) fn held_between(&self, a: &[f64; 12], b: &[f64; 12]) -> f64 {
        if self.correction.is_empty() {
            return 0.0;
        }
        let mut held = 0.0;
        for (p, ap) in a.iter().enumerate() {
            let row = &self.correction[p * 12..p * 12 + 12];
            held += ap * row.iter().zip(b).map(|(c, bq)| c * bq).sum::<f64>();
        }
        held
    }

    /// The pair's inverse mass along `n` at `point` given the free bodies' `free` (kg^-1), less
    /// what the ideal joints hold, floored at [`MIN_MOBILITY`] of the free one.
    pub(crate) fn inverse_mass(&self, free: f64, point: Vector, n: Vector) -> f64 {
        let held = self.held_inverse_mass(point, n);
        if held == 0.0 {
            return free;
        }
        (free - held).max(MIN_MOBILITY * free)
    }

    /// The pair's mobility through the mechanism, `M^-1 - C` over its 12 coordinates (bearing's
    /// linear and angular, then the journal's; row-major): the velocity change of the two
    /// bodies per unit generalised impulse on them, the ideal joints taking their share. Zero
    /// blocks for a body that is not dynamic.
    pub(crate) fn pair_mobility(&self) -> [f64; 144] {
        let mut p = [0.0; 144];
        for (pos, body) in self.pair.iter().enumerate() {
            let Some(i) = body else { continue };
            let b = &self.island[*i];
            for k in 0..3 {
                let base = 6 * pos;
                p[(base + k) * 12 + base + k] = b.inv_mass;
                let mut e = Vector::ZERO;
                e[k] = 1.0;
                let col = b.inv_inertia * e;
                for r in 0..3 {
                    p[(base + 3 + r) * 12 + base + 3 + k] = col[r];
                }
            }
        }
        if !self.correction.is_empty() {
            for (pq, c) in p.iter_mut().zip(&self.correction) {
                *pq -= c;
            }
        }
        p
    }

    /// The mobility from loads on another pair of bodies (`other`: bearing, journal) to this
    /// joint's pair, `P_ab = M^-1 [a = b] - C_ab` over the two pairs' 12 coordinates (row:
    /// this pair's, column: the other's; row-major): how a contact force in another clearance
    /// joint of the same island moves this pair, through a shared body or the ideal joints.
    /// `None` when no body of `other` is in this joint's island (the pairs do not interact
    /// within a step).
    pub(crate) fn cross_mobility(&self, other: [RigidBodyHandle; 2]) -> Option<[f64; 144]> {
        let ids = other.map(|h| self.index(h));
        if ids == [None, None] {
            return None;
        }
        let mut p = [0.0; 144];
        for (pa, a) in self.pair.iter().enumerate() {
            for (pb, b) in ids.iter().enumerate() {
                let Some(i) = a.filter(|a| Some(*a) == *b) else {
                    continue;
                };
                let body = &self.island[i];
                for k in 0..3 {
                    let mut e = Vector::ZERO;
                    e[k] = 1.0;
                    let (r, c) = (6 * pa, 6 * pb);
                    p[(r + k) * 12 + c + k] = body.inv_mass;
                    let col = body.inv_inertia * e;
                    for q in 0..3 {
                        p[(r + 3 + q) * 12 + c + 3 + k] = col[q];
                    }
                }
            }
        }
        if self.correction.is_empty() {
            return Some(p);
        }
        // The other pair's `(G M^-1)`, row by row; `x = A^-1 (G M^-1)_pair` from the factoring.
        let n = self.rows.len();
        let mut other_b = vec![0.0; n * 12];
        for (k, row) in self.rows.iter().enumerate() {
            for (side, body) in row.bodies.iter().enumerate() {
                for pos in (0..2).filter(|&pos| body.is_some() && ids[pos] == *body) {
                    let b = &self.island[body.expect("checked")];
                    let (mf, mt) = b.mobility(row.jac[2 * side], row.jac[2 * side + 1]);
                    let base = k * 12 + 6 * pos;
                    for d in 0..3 {
                        other_b[base + d] += mf[d];
                        other_b[base + 3 + d] += mt[d];
                    }
                }
            }
        }
        for r in 0..12 {
            for c in 0..12 {
                p[r * 12 + c] -= (0..n)
                    .map(|k| self.x[k * 12 + r] * other_b[k * 12 + c])
                    .sum::<f64>();
            }
        }
        Some(p)
    }

    fn index(&self, handle: RigidBodyHandle) -> Option<usize> {
        self.island.iter().position(|b| b.handle == handle)
    }

    /// Every dynamic body reached from `start` through enabled impulse joints.
    fn collect_island(
        &mut self,
        bodies: &RigidBodySet,
        joints: &ImpulseJointSet,
        start: [RigidBodyHandle; 2],
    ) {
        self.queue.clear();
        self.queue.extend(start);
        while let Some(h) = self.queue.pop() {
            if self.index(h).is_some() {
                continue;
            }
            let Some(rb) = bodies.get(h).filter(|rb| rb.is_dynamic()) else {
                continue;
            };
            self.island.push(IslandBody::of(rb, h));
            for (b1, b2, _, joint) in joints.attached_joints(h) {
                if joint.data.is_enabled() {
                    self.queue.push(if b1 == h { b2 } else { b1 });
                }
            }
        }
    }

    /// The rows of every enabled impulse joint with a body in the island.
    fn collect_rows(&mut self, bodies: &RigidBodySet, joints: &ImpulseJointSet) {
        for i in 0..self.island.len() {
            let h = self.island[i].handle;
            for (b1, b2, _, joint) in joints.attached_joints(h) {
                let (i1, i2) = (self.index(b1), self.index(b2));
                // Each joint once: from its first body in the island.
                let first = i1.or(i2);
                if !joint.data.is_enabled() || first != Some(i) {
                    continue;
                }
                let (Some(rb1), Some(rb2)) = (bodies.get(b1), bodies.get(b2)) else {
                    continue;
                };
                self.push_joint_rows(&joint.data, [i1, i2], rb1, rb2);
            }
        }
    }

    /// The rows of one Rapier joint: its locked axes in body 1's joint frame, and its held
    /// motors ([`HELD_MOTOR_RATE`]).
    fn push_joint_rows(
        &mut self,
        joint: &rapier3d_f64::prelude::GenericJoint,
        ids: [Option<usize>; 2],
        rb1: &RigidBody,
        rb2: &RigidBody,
    ) {
        let frame1 = *rb1.position() * joint.local_frame1;
        let anchor2 = (*rb2.position() * joint.local_frame2).translation;
        let (c1, c2) = (world_center_of_mass(rb1), world_center_of_mass(rb2));
        let axes = [Vector::X, Vector::Y, Vector::Z].map(|e| frame1.rotation * e);
        let linear = [
            JointAxesMask::LIN_X,
            JointAxesMask::LIN_Y,
            JointAxesMask::LIN_Z,
        ];
        let angular = [
            JointAxesMask::ANG_X,
            JointAxesMask::ANG_Y,
            JointAxesMask::ANG_Z,
        ];
        for k in 0..3 {
            let e = axes[k];
            // Relative motion of the anchors along e (Rapier's lever: body 2's anchor for both).
            let lin = [-e, -(anchor2 - c1).cross(e), e, (anchor2 - c2).cross(e)];
            let ang = [Vector::ZERO, -e, Vector::ZERO, e];
            for (mask, jac, motor) in [(linear[k], lin, k), (angular[k], ang, k + 3)] {
                let row = Row { bodies: ids, jac };
                if joint.locked_axes.contains(mask)
                    || (joint.motor_axes.contains(mask) && self.holds(&joint.motors[motor], &row))
                {
                    self.rows.push(row);
                }
            }
        }
    }

    /// Whether a motor on `row`'s axis holds its speed over a contact: unlimited, and relaxing
    /// a speed error at [`HELD_MOTOR_RATE`] or faster.
    fn holds(&self, motor: &rapier3d_f64::prelude::JointMotor, row: &Row) -> bool {
        if motor.max_force < f64::MAX || !(motor.damping > 0.0) {
            return false;
        }
        let rate = match motor.model {
            MotorModel::AccelerationBased => motor.damping,
            MotorModel::ForceBased => motor.damping * self.row_dot(row, row),
        };
        rate >= HELD_MOTOR_RATE
    }

    /// `r M^-1 s^T` of two rows.
    fn row_dot(&self, r: &Row, s: &Row) -> f64 {
        let mut sum = 0.0;
        for (side_r, br) in r.bodies.iter().enumerate() {
            let Some(br) = br else { continue };
            let (mf, mt) = self.island[*br].mobility(r.jac[2 * side_r], r.jac[2 * side_r + 1]);
            for (side_s, bs) in s.bodies.iter().enumerate() {
                if *bs == Some(*br) {
                    sum += mf.dot(s.jac[2 * side_s]) + mt.dot(s.jac[2 * side_s + 1]);
                }
            }
        }
        sum
    }

    /// Factors `G M^-1 G^T` and forms the 12 x 12 correction over the pair's coordinates.
    fn factor_correction(&mut self) {
        let n = self.rows.len();
        self.a.clear();
        for p in 0..n {
            for q in 0..n {
                self.a.push(self.row_dot(&self.rows[p], &self.rows[q]));
            }
        }
        if !factor_regularised(&self.a, &mut self.lu, &mut self.piv, n) {
            // A non-finite pose or mass: no correction rather than a made-up one.
            return;
        }
        // b[k][c] = (G M^-1)_pair: row k's mobility in the pair's 12 coordinates.
        self.b.clear();
        self.b.resize(n * 12, 0.0);
        for (k, row) in self.rows.iter().enumerate() {
            for (side, body) in row.bodies.iter().enumerate() {
                let Some(pos) = self.pair.iter().position(|p| p.is_some() && p == body) else {
                    continue;
                };
                let b = &self.island[body.expect("a pair body is in the island")];
                let (mf, mt) = b.mobility(row.jac[2 * side], row.jac[2 * side + 1]);
                let base = k * 12 + 6 * pos;
                self.b[base..base + 3].copy_from_slice(&[mf.x, mf.y, mf.z]);
                self.b[base + 3..base + 6].copy_from_slice(&[mt.x, mt.y, mt.z]);
            }
        }
        // x = A^-1 b, column by column; correction = b^T x.
        self.x.clear();
        self.x.resize(n * 12, 0.0);
        for c in 0..12 {
            self.column.clear();
            self.column.extend((0..n).map(|k| self.b[k * 12 + c]));
            lu_solve(&self.lu, &self.piv, &mut self.column, &mut self.scratch, n);
            for k in 0..n {
                self.x[k * 12 + c] = self.column[k];
            }
        }
        self.correction.clear();
        for p in 0..12 {
            for q in 0..12 {
                self.correction.push(
                    (0..n)
                        .map(|k| self.b[k * 12 + p] * self.x[k * 12 + q])
                        .sum(),
                );
            }
        }
    }

    /// The contact row `[-n, -(p - c_i) x n, n, (p - c_j) x n]` over the pair's 12 coordinates
    /// (zero for a body that is not dynamic).
    fn contact_row(&self, point: Vector, n: Vector) -> [f64; 12] {
        let mut j = [0.0; 12];
        for (pos, sign) in [(0usize, -1.0), (1, 1.0)] {
            let Some(i) = self.pair[pos] else { continue };
            let lin = sign * n;
            let ang = (point - self.island[i].center_of_mass).cross(lin);
            j[6 * pos..6 * pos + 3].copy_from_slice(&[lin.x, lin.y, lin.z]);
            j[6 * pos + 3..6 * pos + 6].copy_from_slice(&[ang.x, ang.y, ang.z]);
        }
        j
    }
}

#[cfg(test)]
mod tests;
