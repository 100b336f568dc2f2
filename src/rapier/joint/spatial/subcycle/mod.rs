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
//! where the sub-steps put them. The integrator carries them beyond the load that balances the
//! free acceleration, held over the step ([`SpatialCycle`]'s held load): at rest the state then
//! bends by the load's change alone, which ROS2 tracks without an offset.
//!
//! **How.** A linearly implicit Rosenbrock method, ROS2 (Verwer et al. 1999: L-stable, second
//! order for any Jacobian), with the linearly implicit Euler step as its embedded first-order
//! estimate. The Jacobian `dL/dx P`, `dL/dv P` is taken by forward differences along the
//! coordinates the pair can move. The stiff terms (the loaded edges' and faces' stiffness, the
//! damping, friction's slope near zero slip) are then integrated implicitly: at rest the
//! sub-steps grow to the whole world step, and the tolerance, not stability, sets them. The
//! sub-step follows the error estimate against the tolerance: positions (of the centres of mass
//! and of the bearing's and journal's centres) against [`POSITION_SCALE`] of the clearance
//! (angles against that over the journal's lever), velocities
//! relative to themselves plus [`VELOCITY_SCALE`]. A contact's onset makes the force bend; the
//! estimate grows there and the sub-steps shrink onto it. From a region's onset, for one period
//! of its contact, the sub-steps are also bounded to `tol` of that period, and a sub-step across
//! the touch is held to that size (`impact`): ROS2's damping of an oscillation it does not
//! resolve is not what its estimate measures.
//!
//! **Memory.** Each region's contact history (onset, `delta_dot0` at the crossing) advances at
//! every accepted sub-step, as the joint's own (the deepest region's). A region in contact keeps
//! its impact rate over the step (raised to its loaded rate at the evaluation before it, as the
//! explicit joint's); a region a trial state presses without a history takes its own approach
//! speed.

use super::super::subcycle::{
    MAX_SUBSTEPS, Pair12, PairStart, SubCycle, SubStep, attributed, axpy, beyond_verlet,
    cross_mobilities, dot, islands, load, mul, part, put, rotate,
};
use super::super::{ClearanceJoint, ContactHistory, Mechanism, motion};
use super::{Mobility, Pair, Places, SpatialParts, Totals, load_region};
use crate::model::kinematics::{BodyMotion, ForcePair, JournalState};
use crate::model::spatial::SpatialPose;
use crate::rapier::pipeline::ledger::{Wrench, world_center_of_mass};
use crate::rapier::pipeline::step_hooks::StepPass;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{RigidBody, RigidBodySet};

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

/// Accepted sub-steps a Jacobian serves at most. ROS2 keeps its order with any Jacobian; a
/// stale one costs accuracy per sub-step, which the error estimate sees. It is also retaken
/// when a region starts or stops touching, when a sub-step is rejected, and when the load moves
/// by [`JACOBIAN_DRIFT`]. A Jacobian costs twelve loads against a sub-step's two: it is retaken
/// where it goes stale, not on a short clock.
const JACOBIAN_AGE: u32 = 32;

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

/// The load's relative change after which the Jacobian is retaken: a tenth, since the error
/// estimate, not the Jacobian, holds the sub-step's accuracy.
const JACOBIAN_DRIFT: f64 = 0.1;

/// The load that holds the pair against the acceleration `a` through the mobility `p`:
/// `-P+ a`, `P+` the pseudo-inverse of the symmetric mobility (its eigenvalues below 1e-9 of the
/// largest, the directions the pair cannot move, left out). A pair at rest carries it (the
/// door: its weight), and the sub-cycle holds it over the step ([`SpatialCycle`]).
fn balancing_load(p: &Square, a: &Pair12) -> Pair12 {
    // Jacobi's rotations diagonalise the symmetric part: `m = V D V^T`.
    let mut m: Square = std::array::from_fn(|i| 0.5 * (p[i] + p[(i % 12) * 12 + i / 12]));
    let mut v: Square = std::array::from_fn(|i| if i / 12 == i % 12 { 1.0 } else { 0.0 });
    for _sweep in 0..30 {
        let off: f64 = (0..144)
            .filter(|i| i / 12 != i % 12)
            .map(|i| m[i] * m[i])
            .sum();
        let diag: f64 = (0..12).map(|i| m[i * 13] * m[i * 13]).sum();
        if !(off > 1e-30 * diag) {
            break;
        }
        for r in 0..12 {
            for c in r + 1..12 {
                let mrc = m[r * 12 + c];
                if mrc == 0.0 {
                    continue;
                }
                let theta = 0.5 * (m[c * 13] - m[r * 13]) / mrc;
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let (cos, sin) = (1.0 / (t * t + 1.0).sqrt(), t / (t * t + 1.0).sqrt());
                for k in 0..12 {
                    let (a, b) = (m[k * 12 + r], m[k * 12 + c]);
                    m[k * 12 + r] = cos * a - sin * b;
                    m[k * 12 + c] = sin * a + cos * b;
                }
                for k in 0..12 {
                    let (a, b) = (m[r * 12 + k], m[c * 12 + k]);
                    m[r * 12 + k] = cos * a - sin * b;
                    m[c * 12 + k] = sin * a + cos * b;
                }
                for k in 0..12 {
                    let (a, b) = (v[k * 12 + r], v[k * 12 + c]);
                    v[k * 12 + r] = cos * a - sin * b;
                    v[k * 12 + c] = sin * a + cos * b;
                }
            }
        }
    }
    let largest = (0..12).map(|i| m[i * 13].abs()).fold(0.0, f64::max);
    let mut out = [0.0; 12];
    for e in 0..12 {
        let d = m[e * 13];
        if !(d.abs() > 1e-9 * largest) {
            continue;
        }
        let along: f64 = (0..12).map(|k| v[k * 12 + e] * a[k]).sum();
        for (k, o) in out.iter_mut().enumerate() {
            *o -= v[k * 12 + e] * along / d;
        }
    }
    out
}

/// ROS2's `gamma = 1 + 1/sqrt(2)` (L-stable).
const GAMMA: f64 = 1.0 + std::f64::consts::FRAC_1_SQRT_2;

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

mod factor;
mod group;
mod impact;
mod integrator;

use group::SpatialGroup;
use integrator::{Eval, RegionClock, SpatialCycle};

/// Refuses a body that carries a spatial and a planar sub-cycled joint. The two are integrated
/// apart (a [`SpatialGroup`] holds the spatial joints only), each one's contact reaching the
/// other's pair through Rapier's delivery pass alone, and their stiff contacts then fight over
/// the shared body: the SCARA arm so built left the physical range, or struck at hundreds of
/// kN, at every world rate measured (docs/sub-cycled-contact.md, limits).
pub(in crate::rapier::joint) fn check_apart(joints: &[&ClearanceJoint]) -> crate::Result<()> {
    let sub_cycled = |spatial: bool| {
        joints
            .iter()
            .filter(move |j| j.sub_cycled() && j.spatial.is_some() == spatial)
    };
    let planar: std::collections::HashMap<_, &&ClearanceJoint> = sub_cycled(false)
        .flat_map(|j| [(j.body1(), j), (j.body2(), j)])
        .collect();
    for s in sub_cycled(true) {
        if let Some(p) = [s.body1(), s.body2()].iter().find_map(|b| planar.get(b)) {
            return Err(crate::Error::invalid(
                format!("clearance joint `{}`", s.name()),
                format!(
                    "is spatial and sub-cycled on a body that the planar sub-cycled joint `{}` \
                     also joins: the two would be integrated apart, and their contacts fight \
                     over the shared body. Make the joints that share a body all spatial or all \
                     planar (`HingeDesign::model`), or integrate one of them explicitly \
                     (`ContactIntegration::Explicit`, with one solver iteration)",
                    p.name()
                ),
            ));
        }
    }
    Ok(())
}

/// The planar joints' `subcycle::plan_cycles` for the spatial joints: after Rapier's pass 0,
/// the rest of the world's acceleration, the sub-cycles of each island's spatial sub-cycled
/// joints together ([`SpatialGroup`]), and the impulse pass 1 delivers for each (`None`: nothing
/// to deliver, or not a spatial sub-cycled joint).
pub(in crate::rapier::joint) fn plan_spatial_cycles(
    joints: &mut [&mut ClearanceJoint],
    bodies: &RigidBodySet,
    pass: &StepPass,
    iterations: usize,
) -> Vec<Option<Pair12>> {
    let mut deliveries = vec![None; joints.len()];
    let planned: Vec<usize> = (0..joints.len())
        .filter(|&i| {
            let j = &joints[i];
            j.spatial.is_some()
                && j.cycle.spatial_start.is_some()
                && PairStart::velocity_now(j, bodies).is_some()
        })
        .collect();
    for group in islands(joints, &planned) {
        // With the coupling off (for comparison) each joint on its own.
        if group.iter().all(|&i| joints[i].techniques.spatial_coupling) {
            plan_group(joints, &group, bodies, pass, iterations, &mut deliveries);
        } else {
            for i in group {
                plan_group(joints, &[i], bodies, pass, iterations, &mut deliveries);
            }
        }
    }
    deliveries
}

/// Runs the sub-cycle of the spatial joints `group` (indices into `joints`, one island) and
/// fills their `deliveries`.
fn plan_group(
    joints: &mut [&mut ClearanceJoint],
    group: &[usize],
    bodies: &RigidBodySet,
    pass: &StepPass,
    iterations: usize,
    deliveries: &mut [Option<Pair12>],
) {
    let (h, kick) = (pass.dt, pass.kick);
    let c_n = crate::rapier::pipeline::stepper::substep_share(iterations);
    let mut parts: Vec<SpatialParts> = group
        .iter()
        .map(|&i| {
            joints[i]
                .spatial
                .take()
                .expect("a planned joint is spatial")
        })
        .collect();
    let mut clocks: Vec<[RegionClock; 4]> = parts
        .iter()
        .map(|p| {
            p.patches.map(|p| RegionClock {
                history: p.contact,
                state: p.state,
                impact_rate: p.impact_rate,
                impact: p.impact,
            })
        })
        .collect();
    let mut runs: Vec<SubCycle> = group
        .iter()
        .map(|&i| std::mem::take(&mut joints[i].cycle.run))
        .collect();
    let shared: &[&mut ClearanceJoint] = joints;
    let members: Vec<&ClearanceJoint> = group.iter().map(|&i| &*shared[i]).collect();
    let starts: Vec<SpatialStart> = members
        .iter()
        .map(|j| j.cycle.spatial_start.expect("a planned joint has a start"))
        .collect();
    let cross: Vec<Vec<(usize, Square)>> = cross_mobilities(&members);
    // The impulses held from the step before, each moving every pair it reaches.
    let held: Vec<Pair12> = members.iter().map(|j| j.cycle.held).collect();
    let moved = |a: usize, impulses: &[Pair12]| {
        let mut v = mul(&starts[a].mobility, &impulses[a]);
        for (b, p) in &cross[a] {
            axpy(&mut v, 1.0, &mul(p, &impulses[*b]));
        }
        v
    };
    let cycles: Vec<SpatialCycle> = (0..group.len())
        .map(|a| {
            let start = &starts[a];
            let now =
                PairStart::velocity_now(members[a], bodies).expect("a planned joint's bodies");
            let a_free: Pair12 = std::array::from_fn(|i| (now[i] - start.velocity[i]) / kick);
            let mut u0 = start.velocity;
            axpy(&mut u0, c_n * kick - 0.5 * h, &a_free);
            axpy(&mut u0, 1.0, &moved(a, &held));
            SpatialCycle::new(members[a], start, (u0, a_free), h, pass.tolerance)
        })
        .collect();
    let before: Vec<(ContactHistory, JournalState)> = members
        .iter()
        .map(|j| (j.contact, j.report.state))
        .collect();
    // The shortest of the members' last sub-steps (0: none yet).
    let guess = members
        .iter()
        .map(|j| j.cycle.substep_guess)
        .filter(|g| *g > 0.0)
        .fold(f64::INFINITY, f64::min);
    let guess = if guess.is_finite() { guess } else { 0.0 };
    let mut cycle = SpatialGroup {
        cycles,
        cross: &cross,
    };
    let last = cycle.run(&mut parts, &before, &mut clocks, guess, &mut runs);
    let deliver: Vec<Pair12> = (0..group.len())
        .map(|a| {
            let mut d = held[a];
            axpy(&mut d, 1.0, &runs[a].mean);
            d.map(|q| q / c_n)
        })
        .collect();
    // The state's velocity beyond the Verlet reading of Rapier's velocities around it (as
    // the planar sub-cycle's), each impulse's share of a shared body in one member's.
    let beyond = beyond_verlet(&held, &deliver, kick, h);
    for (a, run) in runs.iter_mut().enumerate() {
        let own = mul(&starts[a].mobility, &beyond[a]);
        run.start_correction = attributed(a, &members, own, &cross, &beyond);
    }
    let rest = parts.into_iter().zip(clocks).zip(runs);
    for ((a, &i), ((mut parts, clocks), run)) in group.iter().enumerate().zip(rest) {
        let joint = &mut *joints[i];
        joint.cycle.spatial_impacts = clocks.map(|c| c.impact);
        joint.cycle.spatial_regions = Some(clocks.map(|c| (c.history, c.state, c.impact_rate)));
        for (patch, clock) in parts.patches.iter_mut().zip(clocks) {
            patch.contact = clock.history;
            patch.state = clock.state;
            patch.impact_rate = clock.impact_rate;
        }
        joint.spatial = Some(parts);
        joint.cycle.substep_guess = last;
        let mut left = held[a];
        axpy(&mut left, 1.0, &run.impulse);
        axpy(&mut left, -1.0, &deliver[a]);
        joint.cycle.run = run;
        joint.cycle.pending = Some(left);
        deliveries[i] = deliver[a].iter().any(|q| *q != 0.0).then_some(deliver[a]);
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

    /// [`finish_cycle`](ClearanceJoint::finish_cycle) for the spatial joint: the regions
    /// evaluated at the bodies' poses with the sub-cycle's end velocity (their histories are the
    /// sub-cycle's), the states inside the step, the impulse left held.
    pub(in crate::rapier::joint) fn finish_spatial_cycle(
        &mut self,
        bodies: &RigidBodySet,
        mechanism: &Mechanism,
    ) -> Option<(Wrench, Wrench)> {
        let Some(held) = self.cycle.pending.take() else {
            // No sub-cycle ran: the state's velocity is Rapier's (`state_velocity` says none).
            self.cycle.end_velocity = None;
            return None;
        };
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
        // The regions go on from the sub-cycle's end (Rapier's pass 1 restored them as pass 0
        // found them).
        if let Some(ends) = self.cycle.spatial_regions.take() {
            for (patch, (contact, state, rate)) in parts.patches.iter_mut().zip(ends) {
                (patch.contact, patch.state, patch.impact_rate) = (contact, state, rate);
            }
        }
        let result = self.evaluate_regions(&mut parts, &pose, [&m1, &m2], &pair, [0.0, 0.0]);
        // The regions' impact clocks go on from the sub-cycle's end into the next step.
        for (patch, impact) in parts.patches.iter_mut().zip(self.cycle.spatial_impacts) {
            patch.impact = impact;
        }
        self.spatial = Some(parts);
        // The step's last sub-step is the state reported here, and the readers of the step
        // (`ImpactRecorder::record_step`, the runner) take its onset from this report: the
        // evaluation above moved a history the sub-cycle had already moved into the contact,
        // so it would never see one that began in that sub-step.
        if end.onset && self.contact.in_contact {
            self.report.onset = true;
            self.report.impact = end.impact;
            self.report.approach_speed = end.approach_speed;
            self.report.onset_fraction = end.onset_fraction;
        }
        self.report.max_stable_dt = f64::INFINITY;
        self.report.friction_stable_dt = f64::INFINITY;
        self.elastic = std::sync::OnceLock::new();
        self.cycle.adopt_run(held);
        result
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fixed body's block is zero, the other's a full symmetric mobility: the balancing load
    /// undoes the acceleration the moving body can take (`P held = -a` there) and is zero on
    /// the fixed body, whatever acceleration it is given.
    #[test]
    fn the_balancing_load_undoes_what_the_mobility_can_move() {
        let mut p = [0.0; 144];
        let block = [[0.5, 0.1, 0.0], [0.1, 0.7, 0.2], [0.0, 0.2, 0.9]];
        for (r, c) in (0..6).flat_map(|r| (0..6).map(move |c| (r, c))) {
            let v = if r / 3 == c / 3 {
                block[r % 3][c % 3] * (1.0 + (r / 3) as f64)
            } else {
                0.0
            };
            p[(6 + r) * 12 + 6 + c] = v;
        }
        let a: Pair12 = std::array::from_fn(|i| (i as f64 * 0.7).sin());
        let held = balancing_load(&p, &a);
        let moved = mul(&p, &held);
        for i in 0..12 {
            if i < 6 {
                assert!(held[i].abs() < 1e-12, "{held:?}");
            } else {
                assert!((moved[i] + a[i]).abs() < 1e-12, "{moved:?} against {a:?}");
            }
        }
    }
}
