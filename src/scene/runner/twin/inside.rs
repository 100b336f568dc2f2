//! The rows written inside a sub-cycled world step: its joints' sub-steps, not only the states
//! at the step's ends.
//!
//! A row between two states is their linear interpolation ([`Twin::write_row`]). A sub-cycled
//! joint resolves its contact inside the world step ([`ClearanceJoint::substeps`]), and a step
//! of a millisecond may hold a whole impact that the two states around it do not show. The rows
//! inside such a step therefore read the sub-steps around their time (interpolated between the
//! two neighbouring ones): the hinge's force, eccentricity (a planar joint's), penetration and
//! contact flag; and the bodies' accelerations, the interpolated ones corrected by the contact
//! load's departure from its interpolated value through the mechanism (the reaction solver's
//! response at the step's end, [`ReactionSolver::load_response`]).
//!
//! The sub-steps' eccentricities are read in the bearing's directions at the step's end, as the
//! replay's frames inside a step are. A spatial joint's sub-steps carry its deepest station's
//! state, not its mid-plane eccentricity: its force, penetration, contact flag and the bodies'
//! accelerations come from them, its eccentricity, tilt, axial offset and forces by contact kind
//! stay interpolated between the states. So do every body's angle, rate, position and velocity,
//! the hinges' angles and rates, the other joints' forces and the motors' torques.

use super::*;

/// One sub-step's row values of a hinge.
#[derive(Clone, Copy, Debug, Default)]
struct Knot {
    /// Time, s.
    t: f64,
    /// Force magnitude, N; eccentricity along `u` and `v`, mm (`None`: a spatial joint's,
    /// interpolated between the states); penetration, um; contact flag.
    force: f64,
    ecc: Option<[f64; 2]>,
    penetration_um: f64,
    contact: bool,
    /// The contact's load on the journal: force, N, and its moment about the world's origin,
    /// N m.
    load: [Vector; 2],
}

/// A hinge's sub-steps inside the step between the rows' states, and inside the step just taken.
#[derive(Clone, Debug, Default)]
struct HingeInside {
    /// The hinge's first column in a row (its angle).
    col: usize,
    /// Bearing and journal bodies.
    bodies: [RigidBodyHandle; 2],
    /// The sub-steps inside the step between the previous state and the current one, in time
    /// order (the step's end left out: the current state is it).
    knots: Vec<Knot>,
    /// Those of the step taken from the current state (become `knots` at the next state).
    next: Vec<Knot>,
    /// The contact's load at the previous and the current state (`None`: not resolved).
    load: [Option<[Vector; 2]>; 2],
}

/// What the rows inside a sub-cycled step read beyond the states around it.
#[derive(Clone, Debug, Default)]
pub(super) struct InsideRows {
    hinges: Vec<HingeInside>,
    /// The first acceleration column of each dynamic body's rows.
    acc_cols: Vec<(RigidBodyHandle, usize)>,
    /// The load departures of one row (a buffer).
    loads: Vec<(RigidBodyHandle, Vector, Vector)>,
}

/// The load a clearance joint applied to its journal at its last evaluation (what the reaction
/// solve at the state holds): force and moment about the world's origin (`journal_com` the
/// journal's centre of mass at the state).
fn state_load(j: &ClearanceJoint, journal_com: Vector) -> Option<[Vector; 2]> {
    let [_, w] = j.last_wrenches()?;
    Some([w.force, w.torque + journal_com.cross(w.force)])
}

impl InsideRows {
    /// Notes where hinge `k` (bodies `bodies`) starts in the rows and its contact load at the
    /// current state (`fill_row` calls it at each state, in hinge order).
    pub(super) fn note_hinge(
        &mut self,
        k: usize,
        col: usize,
        bodies: [RigidBodyHandle; 2],
        joint: Option<(&ClearanceJoint, Vector)>,
    ) {
        if self.hinges.len() <= k {
            self.hinges.resize_with(k + 1, HingeInside::default);
        }
        let h = &mut self.hinges[k];
        (h.col, h.bodies) = (col, bodies);
        h.load = [h.load[1], joint.and_then(|(j, com)| state_load(j, com))];
    }

    /// Notes a dynamic body's first acceleration column (`fill_row`, at the first state).
    pub(super) fn note_acceleration(&mut self, body: RigidBodyHandle, col: usize) {
        if !self.acc_cols.iter().any(|(b, _)| *b == body) {
            self.acc_cols.push((body, col));
        }
    }

    /// At a new state: the sub-steps of the step that led to it become those between the rows'
    /// states.
    pub(super) fn advance(&mut self) {
        for h in &mut self.hinges {
            std::mem::swap(&mut h.knots, &mut h.next);
            h.next.clear();
        }
    }

    /// After the step of `dt` from `t0`: hinge `k`'s sub-steps in it (none for an explicit
    /// joint), in the bearing's directions `u`, `v` at the step's end.
    pub(super) fn record(
        &mut self,
        k: usize,
        (t0, dt): (f64, f64),
        j: &ClearanceJoint,
        (u, v): (Vector, Vector),
    ) {
        let Some(h) = self.hinges.get_mut(k) else {
            return;
        };
        h.next.clear();
        let Some((last, inside)) = j.substeps().split_last() else {
            return;
        };
        // Only the sub-steps of this step: they end at its end.
        if (last.t - dt).abs() > 1e-9 * dt {
            return;
        }
        let planar = j.report().spatial.is_none();
        h.next.extend(inside.iter().map(|s| {
            let (e, f) = (s.state.eccentricity, s.force.on_journal);
            Knot {
                t: t0 + s.t,
                force: f.length(),
                ecc: planar.then(|| [e.dot(u) * 1e3, e.dot(v) * 1e3]),
                penetration_um: s.state.penetration.max(0.0) * 1e6,
                contact: s.state.penetration > 0.0,
                load: [f, s.moment],
            }
        }));
    }

    /// Replaces in `row` (time `t`, `w` of the way from `prev` to `cur`, interpolated linearly
    /// between them) the hinges' columns by their sub-steps around `t`, and corrects the
    /// bodies' accelerations by the contact loads' departure from their interpolated values
    /// (with `reactions` solved at `cur`; `accelerations`: the rows hold them).
    pub(super) fn correct(
        &mut self,
        row: &mut [f64],
        (t, w): (f64, f64),
        (prev, cur): (&[f64], &[f64]),
        reactions: &mut ReactionSolver,
        accelerations: bool,
    ) {
        self.loads.clear();
        for h in self.hinges.iter().filter(|h| !h.knots.is_empty()) {
            let i = h.knots.partition_point(|k| k.t <= t);
            let end = |s: &[f64]| Knot {
                t: s[0],
                force: s[h.col + 2],
                ecc: Some([s[h.col + 3], s[h.col + 4]]),
                penetration_um: s[h.col + 5],
                contact: s[h.col + 6] > 0.5,
                load: [Vector::ZERO; 2],
            };
            let (a, b) = match (i.checked_sub(1).map(|k| &h.knots[k]), h.knots.get(i)) {
                (Some(a), Some(b)) => (*a, *b),
                (None, Some(b)) => (end(prev), *b),
                (Some(a), None) => (*a, end(cur)),
                (None, None) => continue,
            };
            let s = if b.t > a.t {
                ((t - a.t) / (b.t - a.t)).clamp(0.0, 1.0)
            } else {
                1.0
            };
            let lerp = |x: f64, y: f64| x + (y - x) * s;
            let c = h.col;
            row[c + 2] = lerp(a.force, b.force);
            if let (Some(ea), Some(eb)) = (a.ecc, b.ecc) {
                row[c + 3] = lerp(ea[0], eb[0]);
                row[c + 4] = lerp(ea[1], eb[1]);
            }
            row[c + 5] = lerp(a.penetration_um, b.penetration_um);
            row[c + 6] = if (if s >= 0.5 { b } else { a }).contact {
                1.0
            } else {
                0.0
            };
            if !accelerations {
                continue;
            }
            // The load's departure from the one the interpolated accelerations hold (the
            // states' loads, interpolated as the rows are).
            let [Some(l0), Some(l1)] = h.load else {
                continue;
            };
            let la = if i == 0 { l0 } else { a.load };
            let lb = if i == h.knots.len() { l1 } else { b.load };
            let d = [0, 1].map(|k| (la[k] + (lb[k] - la[k]) * s) - (l0[k] + (l1[k] - l0[k]) * w));
            if d[0] != Vector::ZERO || d[1] != Vector::ZERO {
                self.loads.push((h.bodies[1], d[0], d[1]));
                self.loads.push((h.bodies[0], -d[0], -d[1]));
            }
        }
        if self.loads.is_empty() {
            return;
        }
        reactions.load_response(&self.loads);
        for &(body, col) in &self.acc_cols {
            if let Some((da, _)) = reactions.response(body) {
                row[col] += da.x;
                row[col + 1] += da.y;
                row[col + 2] += da.z;
            }
        }
    }
}
