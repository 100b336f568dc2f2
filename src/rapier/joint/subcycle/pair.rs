//! The pair's coordinates (12-vectors over the bearing's and the journal's linear and angular
//! parts), the loads and rows on them, and the pair's state at a step's start ([`PairStart`]).

use crate::rapier::joint::ClearanceJoint;
use crate::rapier::joint::effective_mass::Mechanism;
use crate::rapier::pipeline::ledger::world_center_of_mass;
use rapier3d_f64::math::{Rotation, Vector};
use rapier3d_f64::prelude::{RigidBody, RigidBodySet};

/// A 12-vector over the pair's coordinates: the bearing's linear and angular, then the
/// journal's.
pub(crate) type Pair12 = [f64; 12];

pub(crate) fn dot(a: &Pair12, b: &Pair12) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

pub(crate) fn axpy(y: &mut Pair12, s: f64, x: &Pair12) {
    for (y, x) in y.iter_mut().zip(x) {
        *y += s * x;
    }
}

pub(crate) fn mul(p: &[f64; 144], x: &Pair12) -> Pair12 {
    let mut y = [0.0; 12];
    for (r, y) in y.iter_mut().enumerate() {
        *y = dot(p[r * 12..r * 12 + 12].try_into().expect("a row"), x);
    }
    y
}

pub(crate) fn part(x: &Pair12, k: usize) -> Vector {
    Vector::new(x[3 * k], x[3 * k + 1], x[3 * k + 2])
}

pub(crate) fn put(x: &mut Pair12, k: usize, v: Vector) {
    x[3 * k..3 * k + 3].copy_from_slice(&[v.x, v.y, v.z]);
}

/// The pair's coordinates of a load at `point` on the journal (`on_journal`) and its opposite
/// on the bearing, about the centres of mass `com`.
pub(crate) fn load(com: &[Vector; 2], point: Vector, on_journal: Vector) -> Pair12 {
    let mut l = [0.0; 12];
    put(&mut l, 0, -on_journal);
    put(&mut l, 1, (point - com[0]).cross(-on_journal));
    put(&mut l, 2, on_journal);
    put(&mut l, 3, (point - com[1]).cross(on_journal));
    l
}

/// The row that reads the relative velocity along `dir` of the journal's point `q_j` against
/// the bearing's point `q_i`.
pub(super) fn row(com: &[Vector; 2], q_i: Vector, q_j: Vector, dir: Vector) -> Pair12 {
    let mut r = [0.0; 12];
    put(&mut r, 0, -dir);
    put(&mut r, 1, -(q_i - com[0]).cross(dir));
    put(&mut r, 2, dir);
    put(&mut r, 3, (q_j - com[1]).cross(dir));
    r
}

/// The pair at the start of a step: what the sub-cycle integrates from.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PairStart {
    pub(super) com: [Vector; 2],
    /// Bearing centre and journal centre, from each centre of mass.
    pub(super) anchor: [Vector; 2],
    /// The hinge's axis (the bearing's).
    pub(super) axis: Vector,
    /// Rapier's velocities at the start (the mean over the step before).
    pub(super) velocity: Pair12,
    pub(super) mobility: [f64; 144],
    /// The bodies' orientations.
    pub(super) rotation: [Rotation; 2],
}

impl PairStart {
    /// The pair of `joint` at the bodies' current state, with its mobility through `mechanism`
    /// (rebuilt at this state); `None` when a body is gone.
    pub(crate) fn of(
        joint: &ClearanceJoint,
        bodies: &RigidBodySet,
        mechanism: &Mechanism,
    ) -> Option<Self> {
        let rb: [&RigidBody; 2] = [bodies.get(joint.body1)?, bodies.get(joint.body2)?];
        let com = rb.map(world_center_of_mass);
        let anchor = [
            *rb[0].position() * joint.local_anchor1 - com[0],
            *rb[1].position() * joint.local_anchor2 - com[1],
        ];
        let velocity = Self::velocity_now(joint, bodies)?;
        Some(PairStart {
            com,
            anchor,
            axis: *rb[0].rotation() * joint.local_axis1,
            velocity,
            mobility: mechanism.pair_mobility(),
            rotation: rb.map(|b| *b.rotation()),
        })
    }

    /// The pair's velocities in `bodies` now (`None` when a body is gone).
    pub(crate) fn velocity_now(joint: &ClearanceJoint, bodies: &RigidBodySet) -> Option<Pair12> {
        let mut v = [0.0; 12];
        for (k, h) in [joint.body1, joint.body2].into_iter().enumerate() {
            let b = bodies.get(h)?;
            put(&mut v, 2 * k, b.linvel());
            put(&mut v, 2 * k + 1, b.angvel());
        }
        Some(v)
    }

    /// Where Rapier's pass 0 put the bodies beyond the integration of their velocities (its
    /// joints' position stabilisation, which removes the drift of the velocity-level
    /// constraints): the shift of each centre of mass and the turn of each body (rotation
    /// vector) over the step of `h` whose velocities went from the start's to `now`, with
    /// `c_n` the share of a velocity change that Rapier's substeps turn into displacement.
    /// The sub-cycle moves the bodies by it too, spread over the step, so that they end where
    /// Rapier puts them.
    pub(crate) fn stabilisation(
        &self,
        joint: &ClearanceJoint,
        bodies: &RigidBodySet,
        now: &Pair12,
        h: f64,
        c_n: f64,
    ) -> Option<[[Vector; 2]; 2]> {
        let rb: [&RigidBody; 2] = [bodies.get(joint.body1)?, bodies.get(joint.body2)?];
        let mut out = [[Vector::ZERO; 2]; 2];
        for k in 0..2 {
            if !rb[k].is_dynamic() {
                continue;
            }
            let moved = |i: usize| {
                h * part(&self.velocity, i) + c_n * h * (part(now, i) - part(&self.velocity, i))
            };
            out[0][k] = world_center_of_mass(rb[k]) - self.com[k] - moved(2 * k);
            let expected = moved(2 * k + 1);
            let turn = turn_near(*rb[k].rotation() * self.rotation[k].inverse(), expected);
            out[1][k] = turn - expected;
        }
        Some(out)
    }

    /// The pair's mobility applied to `impulse`.
    pub(crate) fn moved_by(&self, impulse: &Pair12) -> Pair12 {
        mul(&self.mobility, impulse)
    }

    /// Rapier's velocities at the start.
    pub(crate) fn velocity(&self) -> &Pair12 {
        &self.velocity
    }
}

/// Where the pair is inside the sub-cycle: displacements of the centres of mass, rotation
/// vectors, and velocities.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Motion {
    pub(super) shift: [Vector; 2],
    pub(super) turn: [Vector; 2],
    pub(super) v: Pair12,
}

/// The rotation vector (axis times angle, the shorter way round) of `q`, to the last bit at any
/// angle. glam's `to_scaled_axis` gives zero for a vector part below 1e-8, a turn below
/// 2e-8 rad, while a free-floating satellite turning at 1.4e-4 rad/s turns less than that in a
/// step of 1e-4 s: a turn read as none is a turn taken for Rapier's correction.
/// The rotation vector of `q` nearest to `expected` (rad): `q`'s angle about its axis, whole
/// turns added or taken. A body spinning faster than half a turn per step (an arm spun up at a
/// game's 1/60 s) turns the long way round, and its velocities say which way.
pub(super) fn turn_near(q: Rotation, expected: Vector) -> Vector {
    let short = rotation_vector(q);
    let angle = short.length();
    if angle == 0.0 {
        return short;
    }
    let axis = short / angle;
    let tau = std::f64::consts::TAU;
    let whole = ((expected.dot(axis) - angle) / tau).round();
    (angle + whole * tau) * axis
}

pub(super) fn rotation_vector(q: Rotation) -> Vector {
    let q = if q.w < 0.0 { -q } else { q };
    let v = Vector::new(q.x, q.y, q.z);
    let s = v.length();
    if s == 0.0 {
        return Vector::ZERO;
    }
    v * (2.0 * s.atan2(q.w) / s)
}

pub(crate) fn rotate(turn: Vector, r: Vector) -> Vector {
    if turn == Vector::ZERO {
        r
    } else {
        Rotation::from_scaled_axis(turn) * r
    }
}
