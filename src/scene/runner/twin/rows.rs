//! A twin's table rows: the values of the current state, and the row written between two states.

use super::*;

impl Twin {
    /// The row values of the current state into `row_cur`.
    pub(super) fn fill_row(&mut self, t: f64, world: &ClearanceWorld) {
        let bodies = &world.rapier.bodies;
        let axis_ref = self.reference_axis;
        let v = &mut self.row_cur;
        v.clear();
        v.push(t);
        // The impulse a sub-cycled joint still holds at the state, on each body of its pair,
        // after a step in which it touched: Rapier's velocities after such a step are the mean
        // over it, short of that impulse (of an impact inside the step, most of it). Steps
        // without contact are left as they are, so the twins' rows keep one convention (Rapier's
        // velocities; the solve's for the centres of mass).
        // Found once for the state: each such body with its velocities' shortfall.
        let touched = |j: &crate::rapier::joint::ClearanceJoint| {
            j.substeps().iter().any(|s| s.force.normal_force > 0.0)
        };
        let shortfalls: Vec<(RigidBodyHandle, Vector, Vector)> = world
            .clearance
            .iter()
            .filter(|(_, j)| touched(j))
            .filter_map(|(_, j)| j.state_velocity())
            .flatten()
            .map(|(h, v, w)| (h, v - bodies[h].linvel(), w - bodies[h].angvel()))
            .collect();
        let held = |h: RigidBodyHandle| {
            shortfalls
                .iter()
                .find(|(b, _, _)| *b == h)
                .map(|&(_, dv, dw)| (dv, dw))
        };
        let rate = |h: RigidBodyHandle| {
            let w = bodies[h].angvel();
            held(h).map_or(w, |x| w + x.1)
        };
        for b in &self.bodies {
            v.push(b.angle.value().to_degrees());
            v.push(rate(b.handle).dot(axis_ref).to_degrees());
        }
        if self.body_motion {
            for b in self.bodies.iter().filter(|b| b.moves) {
                let rb = &bodies[b.handle];
                let p = *rb.position() * b.local_com;
                let r = *rb.rotation() * b.local_com;
                // The centre of mass's velocity and acceleration at the state: a dynamic body's
                // from the constrained solve (`solve_ideal_reactions`); a tabulated drive's from
                // its table; a steady drive's those of its spin (its frame turns about its
                // origin, so its centre of mass moves with `w x r`).
                let (vel, acc) = match (b.table, b.fixed) {
                    (Some(k), _) => {
                        let (v0, a, w, alpha) = world.prescribed.motions[k].rates(t);
                        (v0 + w.cross(r), a + alpha.cross(r) + w.cross(w.cross(r)))
                    }
                    (None, true) => {
                        let w = rb.angvel();
                        (rb.linvel() + w.cross(r), w.cross(w.cross(r)))
                    }
                    (None, false) => {
                        self.inside.note_acceleration(b.handle, v.len() + 6);
                        let (mut vel, _) = self.reactions.velocity(b.handle).unwrap_or_default();
                        let (acc, _) = self.reactions.acceleration(b.handle).unwrap_or_default();
                        // After a step in which a sub-cycled joint of the body touched: the
                        // joint's velocity at the state, not the solve's (Rapier's advanced
                        // over their lag, which the joint's already holds).
                        if let Some((dv, _)) = held(b.handle) {
                            vel = rb.linvel() + dv;
                        }
                        (vel, acc)
                    }
                };
                v.extend_from_slice(&[p.x, p.y, p.z, vel.x, vel.y, vel.z, acc.x, acc.y, acc.z]);
            }
        }
        for (k, h) in self.hinges.iter().enumerate() {
            let handles = [self.bodies[h.bearing].handle, self.bodies[h.journal].handle];
            let (r1, r2) = (&bodies[handles[0]], &bodies[handles[1]]);
            let joint = match h.joint {
                HingeJoint::Clearance(c) => world.clearance.get(c),
                HingeJoint::Ideal | HingeJoint::LargeStep(_) => None,
            };
            let com = crate::rapier::pipeline::ledger::world_center_of_mass(r2);
            let joint = joint.map(|j| (j, com));
            self.inside.note_hinge(k, v.len(), handles, joint);
            let axis = *r1.rotation() * h.local_axis1;
            v.push(h.angle.value().to_degrees());
            v.push((rate(handles[1]) - rate(handles[0])).dot(axis).to_degrees());
            v.push(h.force);
            match h.joint {
                HingeJoint::Clearance(c) => {
                    let j = world.clearance.get(c).expect("handle of this twin");
                    let r = j.report();
                    let (u, v_axis) = (*r1.rotation() * h.local_u1, *r1.rotation() * h.local_v1);
                    let pose = r.spatial.map(|_| j.spatial_pose(r1, r2, u));
                    // A spatial joint's eccentricity at the bearing's mid-plane (its report's
                    // state is the deepest station's, which may be a face's).
                    let e = pose.map_or(r.state.eccentricity, |p| p.mid_plane_eccentricity());
                    v.push(e.dot(u) * 1e3);
                    v.push(e.dot(v_axis) * 1e3);
                    v.push(r.state.penetration.max(0.0) * 1e6);
                    v.push(if r.state.penetration > 0.0 { 1.0 } else { 0.0 });
                    if let (Some(p), Some(s)) = (pose, r.spatial) {
                        let [tu, tv] = p.tilt();
                        v.extend_from_slice(&[
                            tu.to_degrees(),
                            tv.to_degrees(),
                            p.axial_offset() * 1e3,
                            s.bore_force,
                            s.edge_force[0],
                            s.edge_force[1],
                            s.face_force[0],
                            s.face_force[1],
                        ]);
                        // Where each edge region's resultant acts, from the bearing's centre
                        // along the axis (0 while it carries nothing).
                        v.extend(
                            s.edge_point
                                .map(|at| (at - p.bearing_center).dot(p.bearing_axis) * 1e3),
                        );
                    }
                }
                HingeJoint::LargeStep(k) => {
                    let r = world
                        .large_step
                        .get(k)
                        .expect("handle of this twin")
                        .report();
                    let e = r.eccentricity;
                    v.push(e.dot(*r1.rotation() * h.local_u1) * 1e3);
                    v.push(e.dot(*r1.rotation() * h.local_v1) * 1e3);
                    v.push(h.sample.penetration.max(0.0) * 1e6);
                    v.push(if r.contact { 1.0 } else { 0.0 });
                }
                HingeJoint::Ideal => v.extend_from_slice(&[0.0, 0.0, 0.0, 0.0]),
            }
            if h.spatial && !matches!(h.joint, HingeJoint::Clearance(_)) {
                v.extend_from_slice(&[0.0; SPATIAL_COLUMNS.len()]);
            }
        }
        for (_, f) in &self.joints {
            v.push(*f);
        }
        v.extend(self.motors.iter().flatten());
    }

    /// Appends the row at time `t`, `w` of the way from the previous state to the current one
    /// (linear; the contact flag from the nearer state).
    /// Inside a sub-cycled step, its sub-steps around `t` replace the interpolation where
    /// they resolve it ([`inside`](super::inside)).
    pub(in crate::scene::runner) fn write_row(&mut self, t: f64, w: f64) {
        let contact_cols = &self.contact_columns;
        let (prev, cur) = (&self.row_prev, &self.row_cur);
        let v = &mut self.table.values;
        let start = v.len();
        v.push(t);
        let (a, b) = (prev.get(1..).unwrap_or(&[]), cur.get(1..).unwrap_or(&[]));
        // The row's columns at once, not a test of `w` and of the contact columns per value
        // (rows outnumber the states several times over in an adaptive run).
        if w >= 1.0 {
            v.extend_from_slice(b);
        } else if a.len() != b.len() {
            // No previous state with these columns: the current one's values.
            v.extend(b.iter().enumerate().map(|(i, &y)| {
                let x = a.get(i).copied().unwrap_or(y);
                if w <= 0.0 {
                    x
                } else if contact_cols.contains(&(i + 1)) {
                    if w >= 0.5 { y } else { x }
                } else {
                    x + (y - x) * w
                }
            }));
        } else if w <= 0.0 {
            v.extend_from_slice(a);
        } else {
            v.extend(a.iter().zip(b).map(|(&x, &y)| x + (y - x) * w));
            // The contact flags from the nearer state.
            for &i in contact_cols {
                if let (Some(&x), Some(&y)) = (prev.get(i), cur.get(i)) {
                    v[start + i] = if w >= 0.5 { y } else { x };
                }
            }
        }
        if w > 0.0 && w < 1.0 {
            self.inside.correct(
                &mut v[start..],
                (t, w),
                (prev, cur),
                &mut self.reactions,
                self.body_motion,
            );
        }
    }

    /// After the step of `dt` from `t0`: the sub-steps of this twin's sub-cycled hinges in it,
    /// for the rows inside it (written at the next state).
    pub(super) fn record_inside(&mut self, world: &ClearanceWorld, (t0, dt): (f64, f64)) {
        let bodies = &world.rapier.bodies;
        for (k, h) in self.hinges.iter().enumerate() {
            let HingeJoint::Clearance(c) = h.joint else {
                continue;
            };
            let Some(j) = world.clearance.get(c) else {
                continue;
            };
            let rot = *bodies[self.bodies[h.bearing].handle].rotation();
            self.inside
                .record(k, (t0, dt), j, (rot * h.local_u1, rot * h.local_v1));
        }
    }
}
