//! Sub-cycled contact of the spatial joint
//! ([`ContactIntegration::SubCycled`](crate::rapier::joint::ContactIntegration::SubCycled)).
//!
//! The planar sub-cycle's frame is kept (`super::super::subcycle`): Rapier's pass 0 gives the
//! rest of the world's acceleration `a` of the pair's 12 velocities, the joint integrates the
//! pair over the world step on its own clock through the pair's mobility `P`, and pass 1
//! delivers the constant wrench that puts the bodies where the sub-steps did, the impulse
//! Rapier's mean velocities do not hold carried to the next step.
//!
//! **What is integrated.** The state is the contact's impulse on the pair so far, `Gamma(t)`,
//! and its time integral `Pi(t)` (24 numbers): the pair's position increments and velocities
//! follow from them exactly, `x = u0 t + a t^2/2 + P Pi`, `v = u0 + a t + P Gamma`, and
//! `dPi/dt = Gamma`, `dGamma/dt = L(x, v)`, `L` the four regions' load on the pair (every
//! quadrature point's normal and friction force, as the explicit joint's). The delivery needs
//! `Gamma(h)` and `Pi(h)`: they are the state, not a quadrature beside it, so the bodies land
//! where the sub-steps put them.
//!
//! **How.** A linearly implicit Rosenbrock method, ROS2 (Verwer et al. 1999: L-stable, second
//! order for any Jacobian), with the linearly implicit Euler step as its embedded first-order
//! estimate. The Jacobian `dL/dx P`, `dL/dv P` is taken by forward differences along the
//! coordinates the pair can move. The stiff terms (the loaded edges' and faces' stiffness, the
//! damping, friction's slope near zero slip) are then integrated implicitly: at rest the
//! sub-steps grow to the whole world step, and the tolerance, not stability, sets them. The
//! sub-step follows the error estimate against the tolerance: positions against
//! [`POSITION_SCALE`] of the clearance (angles against that over the journal's lever), velocities
//! relative to themselves plus [`VELOCITY_SCALE`]. A contact's onset makes the force bend; the
//! estimate grows there and the sub-steps shrink onto it.
//!
//! **Memory.** Each region's contact history (onset, `delta_dot0` at the crossing) advances at
//! every accepted sub-step, as the joint's own (the deepest region's). A region in contact keeps
//! its impact rate over the step (raised to its loaded rate at the evaluation before it, as the
//! explicit joint's); a region a trial state presses without a history takes its own approach
//! speed.

use super::super::subcycle::{MAX_SUBSTEPS, PairStart, SubCycle, SubStep};
use super::super::{ClearanceJoint, ContactHistory, Mechanism, motion};
use super::{Mobility, Pair, SpatialParts, Totals, apply_region, deepest_state, region_points};
use crate::model::kinematics::{BodyMotion, ForcePair, JournalState};
use crate::model::spatial::SpatialPose;
use crate::rapier::pipeline::ledger::{Wrench, world_center_of_mass};
use crate::rapier::pipeline::step_hooks::StepPass;
use rapier3d_f64::math::{Rotation, Vector};
use rapier3d_f64::prelude::{RigidBody, RigidBodySet};

/// A 12-vector over the pair's coordinates: the bearing's linear and angular, then the
/// journal's.
type Pair12 = [f64; 12];
/// A 12 x 12 matrix over the pair's coordinates, row-major.
type Square = [f64; 144];

/// The fraction of the clearance the tolerance is applied to for the sub-steps' position error:
/// a contact's depth is a small fraction of the clearance (the door's edges: 1 %), and its
/// force follows its depth.
pub(crate) const POSITION_SCALE: f64 = 0.01;

/// The speed, per metre of clearance and per second, below which a velocity error is judged
/// absolutely (`tolerance x VELOCITY_SCALE x clearance`): the rate at which the position scale
/// is covered in a millisecond. A resting pair's velocities are near zero; their error then
/// counts against this floor.
pub(crate) const VELOCITY_SCALE: f64 = POSITION_SCALE * 1e3;

/// Accepted sub-steps a Jacobian serves at most (ROS2 keeps its order with any Jacobian; a
/// stale one costs accuracy per sub-step and the error estimate sees it). It is also retaken
/// when a region starts or stops touching, and when a sub-step is rejected.
const JACOBIAN_AGE: u32 = 8;

/// Which regions touch at `eval`.
fn contact_set(eval: &Eval) -> [bool; 4] {
    eval.states.map(|s| s.penetration > 0.0)
}

/// Whether the load moved from `then` (where the Jacobian was taken) by more than
/// [`JACOBIAN_DRIFT`] of its size: the contact's stiffness has moved with it.
fn changed(now: &Pair12, then: &Pair12) -> bool {
    let norm = |x: &Pair12| x.iter().map(|a| a * a).sum::<f64>().sqrt();
    let diff: Pair12 = std::array::from_fn(|i| now[i] - then[i]);
    norm(&diff) > JACOBIAN_DRIFT * norm(then)
}

/// The load's relative change after which the Jacobian is retaken.
const JACOBIAN_DRIFT: f64 = 0.02;

/// ROS2's `gamma = 1 + 1/sqrt(2)` (L-stable).
const GAMMA: f64 = 1.0 + std::f64::consts::FRAC_1_SQRT_2;

fn part(x: &Pair12, k: usize) -> Vector {
    Vector::new(x[3 * k], x[3 * k + 1], x[3 * k + 2])
}

fn put(x: &mut Pair12, k: usize, v: Vector) {
    x[3 * k..3 * k + 3].copy_from_slice(&[v.x, v.y, v.z]);
}

fn axpy(y: &mut Pair12, s: f64, x: &Pair12) {
    for (y, x) in y.iter_mut().zip(x) {
        *y += s * x;
    }
}

fn mul(p: &Square, x: &Pair12) -> Pair12 {
    std::array::from_fn(|r| (0..12).map(|c| p[r * 12 + c] * x[c]).sum())
}

fn rotate(turn: Vector, r: Vector) -> Vector {
    if turn == Vector::ZERO {
        r
    } else {
        Rotation::from_scaled_axis(turn) * r
    }
}

/// The pair of a spatial joint at the start of a step.
#[derive(Clone, Copy, Debug)]
pub(in crate::rapier::joint) struct SpatialStart {
    com: [Vector; 2],
    /// Bearing centre and journal centre, from each centre of mass.
    anchor: [Vector; 2],
    bearing_axis: Vector,
    transverse: Vector,
    journal_axis: Vector,
    /// Rapier's velocities at the start (the mean over the step before).
    velocity: Pair12,
    mobility: Square,
}

impl SpatialStart {
    /// The pair of `joint` (spatial) at the bodies' state, its mobility through `mechanism`.
    fn of(joint: &ClearanceJoint, bodies: &RigidBodySet, mechanism: &Mechanism) -> Option<Self> {
        let parts = joint.spatial.as_ref()?;
        let rb: [&RigidBody; 2] = [bodies.get(joint.body1)?, bodies.get(joint.body2)?];
        let com = rb.map(world_center_of_mass);
        let velocity = PairStart::velocity_now(joint, bodies)?;
        Some(SpatialStart {
            com,
            anchor: [
                *rb[0].position() * joint.local_anchor1 - com[0],
                *rb[1].position() * joint.local_anchor2 - com[1],
            ],
            bearing_axis: *rb[0].rotation() * joint.local_axis1,
            transverse: *rb[0].rotation() * parts.local_transverse1,
            journal_axis: *rb[1].rotation() * joint.local_axis2,
            velocity,
            mobility: mechanism.pair_mobility(),
        })
    }
}

/// One region's memory inside the sub-cycle.
#[derive(Clone, Copy, Debug)]
struct RegionClock {
    history: ContactHistory,
    state: Option<JournalState>,
    impact_rate: f64,
}

impl RegionClock {
    /// The impact rate the region's law reads at `state`: its own in contact, else the state's
    /// approach (a trial state pressing a region that has no contact yet).
    fn rate_at(&self, state: &JournalState, floor: f64) -> f64 {
        if self.history.in_contact {
            self.impact_rate
        } else {
            state.penetration_rate.max(floor)
        }
    }
}

/// The regions at one state of the pair.
#[derive(Clone, Copy, Debug, Default)]
struct Eval {
    /// The contact's load on the pair's 12 coordinates.
    load: Pair12,
    /// Each region's deepest point.
    states: [JournalState; 4],
    force: ForcePair,
    /// Power the damping and friction dissipate, W.
    dissipation: f64,
}

impl Eval {
    fn deepest(&self) -> usize {
        (0..4)
            .max_by(|&a, &b| {
                let (pa, pb) = (self.states[a].penetration, self.states[b].penetration);
                pa.total_cmp(&pb)
            })
            .unwrap_or(0)
    }
}

/// The sub-cycle's state: `Pi` and `Gamma`.
#[derive(Clone, Copy, Debug, Default)]
struct Impulses {
    pi: Pair12,
    gamma: Pair12,
}

/// The Jacobian of the load: `dL/dx`, `dL/dv` (over the pair's coordinates) and the same through
/// the mobility, `A = dL/dx P`, `B = dL/dv P`.
struct Slopes {
    lx: Square,
    lv: Square,
    a: Square,
    b: Square,
}

/// An LU factorisation of `I - gamma s B - (gamma s)^2 A` with its row order.
struct Factor {
    lu: Square,
    order: [usize; 12],
    gs: f64,
}

impl Factor {
    /// `None` when the matrix is singular (the sub-step is then halved).
    fn of(slopes: &Slopes, s: f64) -> Option<Self> {
        let gs = GAMMA * s;
        let mut m: Square = std::array::from_fn(|i| {
            let id = if i / 12 == i % 12 { 1.0 } else { 0.0 };
            id - gs * slopes.b[i] - gs * gs * slopes.a[i]
        });
        let mut order: [usize; 12] = std::array::from_fn(|i| i);
        for col in 0..12 {
            let pivot = (col..12)
                .max_by(|&x, &y| m[x * 12 + col].abs().total_cmp(&m[y * 12 + col].abs()))
                .unwrap_or(col);
            if !(m[pivot * 12 + col].abs() > 0.0) {
                return None;
            }
            if pivot != col {
                for c in 0..12 {
                    m.swap(col * 12 + c, pivot * 12 + c);
                }
                order.swap(col, pivot);
            }
            let d = m[col * 12 + col];
            for r in col + 1..12 {
                let f = m[r * 12 + col] / d;
                m[r * 12 + col] = f;
                for c in col + 1..12 {
                    m[r * 12 + c] -= f * m[col * 12 + c];
                }
            }
        }
        Some(Factor { lu: m, order, gs })
    }

    /// `(I - gamma s J) k = r` for the system `dPi/dt = Gamma`, `dGamma/dt = L`:
    /// `k_Gamma = M^-1 (r_Gamma + gamma s A r_Pi)`, `k_Pi = r_Pi + gamma s k_Gamma`.
    fn solve(&self, slopes: &Slopes, r: &Impulses) -> Impulses {
        let mut rhs = r.gamma;
        axpy(&mut rhs, self.gs, &mul(&slopes.a, &r.pi));
        let mut x: Pair12 = std::array::from_fn(|i| rhs[self.order[i]]);
        for i in 0..12 {
            for c in 0..i {
                x[i] -= self.lu[i * 12 + c] * x[c];
            }
        }
        for i in (0..12).rev() {
            for c in i + 1..12 {
                x[i] -= self.lu[i * 12 + c] * x[c];
            }
            x[i] /= self.lu[i * 12 + i];
        }
        let mut pi = r.pi;
        axpy(&mut pi, self.gs, &x);
        Impulses { pi, gamma: x }
    }
}

/// What the spatial sub-cycle integrates over one world step of `h` (s) from the pair's state
/// `start`, with the velocity `u0` at the state, under the rest of the world's acceleration
/// `a_free`.
struct SpatialCycle<'a> {
    joint: &'a ClearanceJoint,
    start: &'a SpatialStart,
    u0: Pair12,
    a_free: Pair12,
    h: f64,
    tolerance: f64,
    /// Coordinates the pair's mobility moves (the others never change).
    moving: [bool; 12],
    /// Position scale of each coordinate (m; rad for the angular ones), against which the
    /// tolerance is applied.
    scale: Pair12,
}

impl SpatialCycle<'_> {
    fn new<'a>(
        joint: &'a ClearanceJoint,
        start: &'a SpatialStart,
        (u0, a_free): (Pair12, Pair12),
        h: f64,
        tolerance: f64,
    ) -> SpatialCycle<'a> {
        let g = &joint.geometry;
        let lever = (0.5 * g.length()).max(g.journal_radius());
        let length = POSITION_SCALE * g.clearance();
        let moving = std::array::from_fn(|r| (0..12).any(|c| start.mobility[r * 12 + c] != 0.0));
        let scale = std::array::from_fn(|i| {
            if (i / 3) % 2 == 0 {
                length
            } else {
                length / lever
            }
        });
        SpatialCycle {
            joint,
            start,
            u0,
            a_free,
            h,
            tolerance,
            moving,
            scale,
        }
    }

    /// The pair's position increments and velocities at `t` with the impulses `y`.
    fn kinematics(&self, t: f64, y: &Impulses) -> (Pair12, Pair12) {
        let p = &self.start.mobility;
        let mut x = mul(p, &y.pi);
        axpy(&mut x, t, &self.u0);
        axpy(&mut x, 0.5 * t * t, &self.a_free);
        let mut v = mul(p, &y.gamma);
        axpy(&mut v, 1.0, &self.u0);
        axpy(&mut v, t, &self.a_free);
        (x, v)
    }

    /// The pose and the bodies' motions at position increments `x` and velocities `v`.
    fn pose(&self, x: &Pair12, v: &Pair12) -> (SpatialPose, [BodyMotion; 2]) {
        let s = self.start;
        let com = [s.com[0] + part(x, 0), s.com[1] + part(x, 2)];
        let (turn_i, turn_j) = (part(x, 1), part(x, 3));
        let pose = SpatialPose {
            bearing_center: com[0] + rotate(turn_i, s.anchor[0]),
            bearing_axis: rotate(turn_i, s.bearing_axis),
            bearing_transverse: rotate(turn_i, s.transverse),
            journal_center: com[1] + rotate(turn_j, s.anchor[1]),
            journal_axis: rotate(turn_j, s.journal_axis),
        };
        let motion = |k: usize| BodyMotion {
            center_of_mass: com[k],
            linvel: part(v, 2 * k),
            angvel: part(v, 2 * k + 1),
        };
        (pose, [motion(0), motion(1)])
    }

    /// The regions' load and states at `x`, `v`.
    fn eval(
        &self,
        parts: &mut SpatialParts,
        x: &Pair12,
        v: &Pair12,
        clocks: &[RegionClock; 4],
    ) -> Eval {
        let j = self.joint;
        let (pose, motions) = self.pose(x, v);
        let bodies = [&motions[0], &motions[1]];
        let centres = [motions[0].center_of_mass, motions[1].center_of_mass];
        let geometry = parts.model.geometry;
        let mut totals = Totals::default();
        let mut out = Eval::default();
        parts.points.clear();
        for (k, clock) in clocks.iter().enumerate() {
            let region = parts.patches[k].region;
            let (state, _) = deepest_state(j, &geometry, &pose, region, bodies);
            let first = parts.points.len();
            region_points(j, parts, &pose, region, bodies);
            let law = *region.law(&j.normal_law, &parts.face_law);
            let rate = clock.rate_at(&state, j.min_impact_speed);
            let points = &mut parts.points[first..];
            apply_region(
                points,
                &law,
                &j.friction_law,
                rate,
                0.0,
                centres,
                &mut totals,
            );
            out.states[k] = state;
        }
        put(&mut out.load, 0, -totals.force);
        put(&mut out.load, 1, totals.torque[0]);
        put(&mut out.load, 2, totals.force);
        put(&mut out.load, 3, totals.torque[1]);
        let deepest = &out.states[out.deepest()];
        out.force = ForcePair {
            on_journal: totals.force,
            point: deepest.contact_point,
            normal_force: totals.normal.length(),
            friction_force: totals.friction.length(),
        };
        out.dissipation = totals.dissipation;
        out
    }

    /// The load's Jacobian at `x`, `v` (whose load is `base`), by forward differences along the
    /// coordinates the pair moves: steps of 1e-6 of the position scale (the contacts' depths
    /// resolve it) and 1e-3 of it per second for velocities (well inside friction's linear
    /// range near zero slip).
    fn slopes(
        &self,
        parts: &mut SpatialParts,
        (x, v): (&Pair12, &Pair12),
        base: &Pair12,
        clocks: &[RegionClock; 4],
    ) -> Slopes {
        let mut lx = [0.0; 144];
        let mut lv = [0.0; 144];
        for c in (0..12).filter(|&c| self.moving[c]) {
            for (jac, dv, e) in [(&mut lx, false, 1e-6), (&mut lv, true, 1e-3)] {
                let step = e * self.scale[c];
                let (mut xp, mut vp) = (*x, *v);
                if dv {
                    vp[c] += step;
                } else {
                    xp[c] += step;
                }
                let load = self.eval(parts, &xp, &vp, clocks).load;
                for r in 0..12 {
                    jac[r * 12 + c] = (load[r] - base[r]) / step;
                }
            }
        }
        let p = &self.start.mobility;
        let through = |l: &Square| -> Square {
            std::array::from_fn(|i| {
                let (r, c) = (i / 12, i % 12);
                (0..12).map(|k| l[r * 12 + k] * p[k * 12 + c]).sum()
            })
        };
        Slopes {
            a: through(&lx),
            b: through(&lv),
            lx,
            lv,
        }
    }

    /// One ROS2 sub-step of `s` from `t`, `y` (load `f0` there): the new state, the load at its
    /// second stage's point is not kept. Returns the state and its scaled error (accept at or
    /// below 1); `None` when the linear system is singular.
    fn ros2(
        &self,
        parts: &mut SpatialParts,
        (t, y, f0): (f64, &Impulses, &Pair12),
        slopes: &Slopes,
        s: f64,
        clocks: &[RegionClock; 4],
    ) -> Option<(Impulses, f64)> {
        let factor = Factor::of(slopes, s)?;
        // The load's change with time along the free motion: dx/dt = u0 + a t, dv/dt = a.
        let mut drift = self.u0;
        axpy(&mut drift, t, &self.a_free);
        let mut ft = mul(&slopes.lx, &drift);
        axpy(&mut ft, 1.0, &mul(&slopes.lv, &self.a_free));
        let gs = GAMMA * s;
        let mut r1 = Impulses {
            pi: y.gamma,
            gamma: *f0,
        };
        axpy(&mut r1.gamma, gs, &ft);
        let k1 = factor.solve(slopes, &r1);
        let mut y1 = *y;
        axpy(&mut y1.pi, s, &k1.pi);
        axpy(&mut y1.gamma, s, &k1.gamma);
        let (x1, v1) = self.kinematics(t + s, &y1);
        let f1 = self.eval(parts, &x1, &v1, clocks).load;
        let mut r2 = Impulses {
            pi: y1.gamma,
            gamma: f1,
        };
        axpy(&mut r2.pi, -2.0, &k1.pi);
        axpy(&mut r2.gamma, -2.0, &k1.gamma);
        axpy(&mut r2.gamma, -gs, &ft);
        let k2 = factor.solve(slopes, &r2);
        let mut next = *y;
        let mut err = Impulses::default();
        for (n, e, a, b) in [
            (&mut next.pi, &mut err.pi, &k1.pi, &k2.pi),
            (&mut next.gamma, &mut err.gamma, &k1.gamma, &k2.gamma),
        ] {
            axpy(n, 1.5 * s, a);
            axpy(n, 0.5 * s, b);
            axpy(e, 0.5 * s, a);
            axpy(e, 0.5 * s, b);
        }
        let (_, v_new) = self.kinematics(t + s, &next);
        Some((next, self.error(&err, &v_new)))
    }

    /// The largest error against the tolerance, body by body: displacements and rotations
    /// across the axis against their scale (the edges' and faces' depths follow them), rotations
    /// about the axis against the clearance over the journal's radius (they slide the journal
    /// along its wall), velocities against themselves plus [`VELOCITY_SCALE`] of their scale.
    fn error(&self, err: &Impulses, v: &Pair12) -> f64 {
        let p = &self.start.mobility;
        let (ex, ev) = (mul(p, &err.pi), mul(p, &err.gamma));
        let g = &self.joint.geometry;
        let axis = self.start.bearing_axis;
        let floor = VELOCITY_SCALE / POSITION_SCALE;
        let tol = self.tolerance;
        let mut worst = 0.0_f64;
        for k in 0..4 {
            let (e, de, u) = (part(&ex, k), part(&ev, k), part(v, k));
            let scales = if k % 2 == 0 {
                vec![(e, de, u, self.scale[3 * k])]
            } else {
                let along = |x: Vector| x.dot(axis) * axis;
                vec![
                    (
                        e - along(e),
                        de - along(de),
                        u - along(u),
                        self.scale[3 * k],
                    ),
                    (
                        along(e),
                        along(de),
                        along(u),
                        g.clearance() / g.journal_radius(),
                    ),
                ]
            };
            for (e, de, u, scale) in scales {
                let position = e.length() / (tol * scale);
                let velocity = de.length() / (tol * (u.length() + floor * scale));
                worst = worst.max(position).max(velocity);
            }
        }
        worst
    }

    /// Integrates the step from the joint's `history` and `before` (the state at the step's
    /// start) and the regions' `clocks`, with a first sub-step of `guess` (s); fills `out` and
    /// returns the last accepted sub-step (the next step's guess).
    fn run(
        &self,
        parts: &mut SpatialParts,
        (history, before): (ContactHistory, &JournalState),
        clocks: &mut [RegionClock; 4],
        guess: f64,
        out: &mut SubCycle,
    ) -> f64 {
        let j = self.joint;
        out.samples.clear();
        out.dissipated = 0.0;
        let mut hist = history;
        let mut prev = *before;
        let mut y = Impulses::default();
        let mut t = 0.0;
        let (x, v) = self.kinematics(0.0, &y);
        let mut here = self.eval(parts, &x, &v, clocks);
        let mut s = if guess > 0.0 {
            guess.min(self.h)
        } else {
            self.h
        };
        let mut slopes = self.slopes(parts, (&x, &v), &here.load, clocks);
        let mut count = 0u32;
        let mut accepted = s;
        // Accepted sub-steps since the Jacobian was taken, and the regions in contact there.
        let (mut age, mut contacts, mut taken_at) = (0u32, contact_set(&here), here.load);
        while t < self.h {
            let left = self.h - t;
            // No sliver of a last sub-step.
            let step = if s >= 0.95 * left || count >= MAX_SUBSTEPS {
                left
            } else {
                s
            };
            let trial = self.ros2(parts, (t, &y, &here.load), &slopes, step, clocks);
            let floor = 1e-9 * self.h;
            let (next, err) = match trial {
                Some((next, err)) if err.is_finite() => (next, err),
                _ if step > floor => {
                    s = 0.5 * step;
                    continue;
                }
                _ => (y, 0.0),
            };
            if err > 1.0 && step > floor && count < MAX_SUBSTEPS {
                s = step * (0.9 / err.sqrt()).clamp(0.1, 0.9);
                if age > 0 {
                    // A Jacobian of an earlier state may be what failed: retake it here.
                    let (x, v) = self.kinematics(t, &y);
                    slopes = self.slopes(parts, (&x, &v), &here.load, clocks);
                    (age, taken_at) = (0, here.load);
                }
                continue;
            }
            count += 1;
            accepted = step;
            let t_next = if step == left { self.h } else { t + step };
            let (x, v) = self.kinematics(t_next, &next);
            let at = self.eval(parts, &x, &v, clocks);
            out.dissipated += 0.5 * step * (here.dissipation + at.dissipation);
            self.advance(clocks, &at.states);
            let state = at.states[at.deepest()];
            let onset = hist.advance(Some(&prev), &state, j.min_impact_speed, j.min_separation);
            out.samples.push(SubStep {
                t: t_next,
                state,
                force: at.force,
                onset: onset.onset,
                impact: onset.impact,
                approach_speed: onset.approach_speed,
                onset_fraction: onset.fraction,
            });
            prev = state;
            (t, y, here) = (t_next, next, at);
            s = step * (0.9 / err.max(1e-12).sqrt()).clamp(0.2, 4.0);
            age += 1;
            let touching = contact_set(&here);
            let moved = changed(&here.load, &taken_at);
            if t < self.h && (age >= JACOBIAN_AGE || touching != contacts || moved) {
                slopes = self.slopes(parts, (&x, &v), &here.load, clocks);
                (age, contacts, taken_at) = (0, touching, here.load);
            }
        }
        let (_, v) = self.kinematics(self.h, &y);
        out.impulse = y.gamma;
        out.mean = y.pi.map(|p| p / self.h);
        out.end_velocity = v;
        out.history = hist;
        out.substeps = count;
        accepted
    }

    /// Each region's history moved to the accepted `states`; a region whose contact began takes
    /// its approach at the crossing as its impact rate.
    fn advance(&self, clocks: &mut [RegionClock; 4], states: &[JournalState; 4]) {
        let j = self.joint;
        for (clock, state) in clocks.iter_mut().zip(states) {
            let was = clock.history.in_contact;
            let before = clock.state.as_ref();
            clock
                .history
                .advance(before, state, j.min_impact_speed, j.min_separation);
            if !was && clock.history.in_contact {
                clock.impact_rate = clock.history.impact_rate;
            }
            clock.state = Some(*state);
        }
    }
}

impl ClearanceJoint {
    /// Takes a spatial sub-cycled joint's pair before the next step (at each evaluation).
    pub(in crate::rapier::joint) fn take_spatial_start(
        &mut self,
        bodies: &RigidBodySet,
        mechanism: &Mechanism,
    ) {
        self.cycle.spatial_start = if self.sub_cycled() && self.spatial.is_some() {
            SpatialStart::of(self, bodies, mechanism)
        } else {
            None
        };
    }

    /// The planar joints' `subcycle::plan_cycles` for the spatial joint: after Rapier's pass 0,
    /// the rest of the world's acceleration, the sub-cycle, and the impulse pass 1 delivers.
    pub(in crate::rapier::joint) fn plan_spatial_cycle(
        &mut self,
        bodies: &RigidBodySet,
        pass: &StepPass,
        iterations: usize,
    ) -> Option<Pair12> {
        let start = self.cycle.spatial_start?;
        let now = PairStart::velocity_now(self, bodies)?;
        let (h, kick) = (pass.dt, pass.kick);
        let c_n = (iterations as f64 + 1.0) / (2.0 * iterations.max(1) as f64);
        let a_free: Pair12 = std::array::from_fn(|i| (now[i] - start.velocity[i]) / kick);
        let mut u0 = start.velocity;
        axpy(&mut u0, c_n * kick - 0.5 * h, &a_free);
        axpy(&mut u0, 1.0, &mul(&start.mobility, &self.cycle.held));
        let mut parts = self.spatial.take()?;
        let mut clocks = parts.patches.map(|p| RegionClock {
            history: p.contact,
            state: p.state,
            impact_rate: p.impact_rate,
        });
        let mut run = std::mem::take(&mut self.cycle.run);
        let cycle = SpatialCycle::new(self, &start, (u0, a_free), h, pass.tolerance);
        let before = (self.contact, &self.report.state);
        let guess = self.cycle.substep_guess;
        let last = cycle.run(&mut parts, before, &mut clocks, guess, &mut run);
        for (patch, clock) in parts.patches.iter_mut().zip(clocks) {
            patch.contact = clock.history;
            patch.state = clock.state;
            patch.impact_rate = clock.impact_rate;
        }
        self.spatial = Some(parts);
        self.cycle.substep_guess = last;
        let mut deliver = self.cycle.held;
        axpy(&mut deliver, 1.0, &run.mean);
        deliver.iter_mut().for_each(|q| *q /= c_n);
        let mut held = self.cycle.held;
        axpy(&mut held, 1.0, &run.impulse);
        axpy(&mut held, -1.0, &deliver);
        // The state's velocity beyond the Verlet reading of Rapier's velocities around it (as
        // the planar sub-cycle's).
        let w = (2.0 * kick - h) / (2.0 * kick);
        let mut beyond = self.cycle.held;
        axpy(&mut beyond, -w, &deliver);
        run.start_correction = mul(&start.mobility, &beyond);
        self.cycle.run = run;
        self.cycle.pending = Some(held);
        deliver.iter().any(|q| *q != 0.0).then_some(deliver)
    }

    /// [`finish_cycle`](ClearanceJoint::finish_cycle) for the spatial joint: the regions
    /// evaluated at the bodies' poses with the sub-cycle's end velocity (their histories are the
    /// sub-cycle's), the states inside the step, the impulse left held.
    pub(in crate::rapier::joint) fn finish_spatial_cycle(
        &mut self,
        bodies: &RigidBodySet,
        mechanism: &Mechanism,
    ) -> Option<(Wrench, Wrench)> {
        let held = self.cycle.pending.take()?;
        let end = *self.cycle.run.samples.last()?;
        let (rb1, rb2) = (bodies.get(self.body1)?, bodies.get(self.body2)?);
        let v = self.cycle.run.end_velocity;
        let (mut m1, mut m2) = (motion(rb1), motion(rb2));
        (m1.linvel, m1.angvel, m2.linvel, m2.angvel) =
            (part(&v, 0), part(&v, 1), part(&v, 2), part(&v, 3));
        let pair = Pair([Mobility::of(rb1), Mobility::of(rb2)], mechanism);
        let mut parts = self.spatial.take()?;
        let transverse = *rb1.rotation() * parts.local_transverse1;
        let pose = self.spatial_pose(rb1, rb2, transverse);
        self.contact = self.cycle.run.history;
        self.report.state = end.state;
        let result = self.evaluate_regions(&mut parts, &pose, [&m1, &m2], &pair, [0.0, 0.0]);
        self.spatial = Some(parts);
        self.report.max_stable_dt = f64::INFINITY;
        self.report.friction_stable_dt = f64::INFINITY;
        self.elastic = std::sync::OnceLock::new();
        self.cycle.adopt_run(held);
        result
    }
}
