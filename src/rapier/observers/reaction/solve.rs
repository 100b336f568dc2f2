//! The solve: the state's velocities (advanced by the lag, projected), then the accelerations.

use super::lu::{factor_regularised, lu_solve};
use super::{IdealJoint, ReactionFailure, ReactionSolver};
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{RigidBodyHandle, RigidBodySet};

impl ReactionSolver {
    pub(super) fn solve_joints_inner(
        &mut self,
        bodies: &RigidBodySet,
        joints: &[IdealJoint],
        gravity: Vector,
    ) -> Option<()> {
        self.entries.clear();
        self.forces.clear();
        self.motors.clear();
        self.starts.clear();
        self.failure = None;
        let mut pairs = Vec::with_capacity(joints.len());
        for j in joints {
            let (h1, h2) = j.bodies();
            pairs.push((
                self.body_index(bodies, h1, gravity)?,
                self.body_index(bodies, h2, gravity)?,
            ));
        }
        for i in 0..self.track.len() {
            self.body_index(bodies, self.track[i], gravity)?;
        }
        // The Jacobian depends on the positions only: rows at the stored velocities, then the
        // matrices (all rows, and the position rows for the projection).
        self.build_rows(joints, &pairs);
        let n = self.rows.len();
        self.assemble();
        self.decouple_inert_rows(n);
        self.pos_rows.clear();
        self.pos_rows
            .extend((0..n).filter(|&i| self.rows[i].position));
        if !factor_regularised(&self.a, &mut self.lu, &mut self.piv, n) {
            self.failure = Some(ReactionFailure::Unsolvable);
            return None;
        }
        let np = self.pos_rows.len();
        if np < n {
            self.a_pos.clear();
            for &i in &self.pos_rows {
                for &k in &self.pos_rows {
                    self.a_pos.push(self.a[i * n + k]);
                }
            }
            if !factor_regularised(&self.a_pos, &mut self.lu_pos, &mut self.piv_pos, np) {
                self.failure = Some(ReactionFailure::Unsolvable);
                return None;
            }
        }
        // The state's velocities: the stored ones advanced by the lag with the accelerations
        // solved at the stored ones, projected onto the joints (an error of second order in the
        // lag; one pass without a lag).
        let passes = if self.velocity_lag > 0.0 { 2 } else { 1 };
        for pass in 0..passes {
            if pass > 0 {
                let lag = self.velocity_lag;
                for e in self.entries.iter_mut().filter(|e| e.dynamic) {
                    e.v = e.stored_v + lag * e.acc;
                    e.w = e.stored_w + lag * e.alpha;
                }
            }
            self.project(n);
            self.build_rows(joints, &pairs);
            self.apply_motors(joints, &pairs);
            self.accelerations(n);
        }
        // The force on body 2: the force rows' multipliers along their directions.
        for (k, j) in joints.iter().enumerate() {
            let s = self.starts[k];
            let mut f = Vector::ZERO;
            for i in 0..j.force_rows() {
                f += self.b[s + i] * self.rows[s + i].jac[2];
            }
            self.forces.push(f);
        }
        Some(())
    }

    /// The change in every body's accelerations under further `loads` (body, force N, moment
    /// about the world's origin N m) at the state of the last solve, read with
    /// [`response`](Self::response): `M^-1 (dF + J^T dlambda)` with `A dlambda = -J M^-1 dF`,
    /// the last solve's factors reused (the accelerations are linear in the applied loads at
    /// given velocities). A load on a body outside the solve is left out. What the rows of a
    /// sub-cycled step add for its contact's force between the states: the state's reactions
    /// hold the contact's force at the state only.
    pub(crate) fn load_response(&mut self, loads: &[(RigidBodyHandle, Vector, Vector)]) {
        self.response.clear();
        self.response.extend(self.entries.iter().map(|e| {
            let (mut f, mut m) = (Vector::ZERO, Vector::ZERO);
            for (_, lf, lm) in loads.iter().filter(|l| l.0 == e.handle) {
                f += *lf;
                m += *lm;
            }
            // A prescribed body keeps its motion whatever the load.
            if e.prescribed.is_some() {
                return (Vector::ZERO, Vector::ZERO);
            }
            e.apply_inv_mass(f, m - e.com.cross(f))
        }));
        let n = self.rows.len();
        if n == 0 || self.lu.len() != n * n {
            return;
        }
        self.b_load.clear();
        for r in &self.rows {
            let rhs = if self.inert(r) {
                0.0
            } else {
                -r.dot(self.response[r.b1], self.response[r.b2])
            };
            self.b_load.push(rhs);
        }
        lu_solve(&self.lu, &self.piv, &mut self.b_load, &mut self.scratch, n);
        for (r, &lambda) in self.rows.iter().zip(&self.b_load) {
            for (b, side) in [(r.b1, 0usize), (r.b2, 2)] {
                let e = &self.entries[b];
                let (da, dalpha) = e.apply_inv_mass(r.jac[side] * lambda, r.jac[side + 1] * lambda);
                self.response[b].0 += da;
                self.response[b].1 += dalpha;
            }
        }
    }

    /// Whether row `r` joins two bodies that no force moves (fixed, kinematic): it carries no
    /// unknown (its row and column of `J M^-1 J^T` are zero), and its multiplier is zero: the
    /// bodies' supports take whatever it would carry.
    fn inert(&self, r: &super::rows::Row) -> bool {
        !self.entries[r.b1].dynamic && !self.entries[r.b2].dynamic
    }

    /// Puts a unit of the matrix's scale on the diagonal of every inert row (a zero row and
    /// column), so that the factorisation does not see a singular matrix and the row's
    /// multiplier, with a zero right-hand side, is zero.
    fn decouple_inert_rows(&mut self, n: usize) {
        let scale = (0..n).fold(0.0f64, |m, i| m.max(self.a[i * n + i].abs()));
        let unit = if scale > 0.0 && scale.is_finite() {
            scale
        } else {
            1.0
        };
        for i in 0..n {
            if self.inert(&self.rows[i]) {
                self.a[i * n + i] = unit;
            }
        }
    }

    /// Makes the dynamic bodies' velocities satisfy the position rows, `J v = 0`, with the
    /// least change in the mass metric: `v -= M^-1 J^T mu`, `(J M^-1 J^T) mu = J v`.
    fn project(&mut self, n: usize) {
        let np = self.pos_rows.len();
        if np == 0 {
            return;
        }
        self.b_pos.clear();
        for &i in &self.pos_rows {
            let r = &self.rows[i];
            let (e1, e2) = (&self.entries[r.b1], &self.entries[r.b2]);
            let jv = if self.inert(r) {
                0.0
            } else {
                r.dot((e1.v, e1.w), (e2.v, e2.w))
            };
            self.b_pos.push(jv);
        }
        if np < n {
            lu_solve(
                &self.lu_pos,
                &self.piv_pos,
                &mut self.b_pos,
                &mut self.scratch,
                np,
            );
        } else {
            lu_solve(&self.lu, &self.piv, &mut self.b_pos, &mut self.scratch, n);
        }
        for (k, &i) in self.pos_rows.iter().enumerate() {
            let r = self.rows[i];
            let mu = self.b_pos[k];
            for (b, side) in [(r.b1, 0usize), (r.b2, 2)] {
                let e = &mut self.entries[b];
                let (dv, dw) = e.apply_inv_mass(r.jac[side] * mu, r.jac[side + 1] * mu);
                e.v -= dv;
                e.w -= dw;
            }
        }
    }

    /// Solves `A lambda = -c - J M^-1 F` at the state's velocities and sets every body's
    /// accelerations `M^-1 (F + J^T lambda)` and the held motors' multipliers.
    fn accelerations(&mut self, n: usize) {
        for e in &mut self.entries {
            (e.acc, e.alpha) = e.free_acceleration();
        }
        self.b.clear();
        for r in &self.rows {
            let (e1, e2) = (&self.entries[r.b1], &self.entries[r.b2]);
            let rhs = if self.inert(r) {
                0.0
            } else {
                -(r.c + r.dot((e1.acc, e1.alpha), (e2.acc, e2.alpha)))
            };
            self.b.push(rhs);
        }
        lu_solve(&self.lu, &self.piv, &mut self.b, &mut self.scratch, n);
        for (r, &lambda) in self.rows.iter().zip(&self.b) {
            for (b, side) in [(r.b1, 0usize), (r.b2, 2)] {
                let e = &mut self.entries[b];
                let (da, dalpha) = e.apply_inv_mass(r.jac[side] * lambda, r.jac[side + 1] * lambda);
                e.acc += da;
                e.alpha += dalpha;
            }
        }
        // A held motor's speed row is its joint's last.
        for (k, m) in self.motors.iter_mut().enumerate() {
            if let Some(v) = m {
                let next = self.starts.get(k + 1).copied().unwrap_or(n);
                if !self.rows[next - 1].position {
                    *v = self.b[next - 1];
                }
            }
        }
    }
}
