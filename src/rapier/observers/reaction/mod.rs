//! Exact reactions of ideal joints (revolute, prismatic, fixed, spherical, with or without a
//! motor) at a state, from the constrained rigid-body equations (not from Rapier's impulses or
//! momentum differences, which carry its integrator's lag).
//!
//! For bodies with mass matrices `M`, applied wrenches `F` (user forces and torques, gravity,
//! gyroscopic terms, soft motors) and joints whose constraints have Jacobian `J` and
//! velocity-product terms `c` (`J a + c = 0` for the accelerations `a`), the multipliers solve
//! `J M^-1 J^T lambda = -c - J M^-1 F`: the joint forces the ideal mechanism needs at this
//! position and velocity, and the accelerations `a = M^-1 (F + J^T lambda)`. They do not depend
//! on the step: the same state gives the same reaction whatever the step control, which
//! momentum balances over a step do not achieve (Rapier's constraint turns a jointed body's
//! velocity by the motion since the previous step, while applied forces act over the current
//! one).
//!
//! **The state's velocities.** Rapier's stored velocities are not the state's: with one solver
//! iteration a step is symplectic Euler, whose velocities live half a step before the positions
//! (the [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld) makes that exactly half the last step), and
//! they satisfy the joints at the previous positions, not the current ones. The solver therefore
//! (1) advances the stored velocities by [`velocity_lag`](ReactionSolver::velocity_lag) with the
//! accelerations it solves at them (second order in the lag: a second pass), and (2) projects
//! them onto the joints'
//! velocity constraints at the current positions (the mass-weighted least change), so that the
//! centripetal and Coriolis terms are those of a state of the ideal mechanism. A mechanism whose
//! motion is fully prescribed (a driven crank) then gets its exact velocities from the
//! projection, whatever the step.
//!
//! **Joints.** [`IdealJoint::from_rapier`] reads each joint from Rapier's description (kind from
//! its locked axes, anchors and axis from its frames, the motor on its free axis), so the solve
//! and the simulation hold the same joint.
//!
//! **Motors.** A soft motor (Rapier's spring-damper `k (x_target - x) + c (v_target - v)`,
//! clamped to its `max_force`, times the row's effective mass in Rapier's acceleration-based
//! model) is an applied wrench computed from the state. A velocity motor that holds its speed
//! ([`IdealJoint::held_motor`]) is one more constraint row (`d(speed)/dt = 0`), its multiplier
//! the motor torque or force.
//!
//! The solve works before the first step, when Rapier has not computed the bodies' mass
//! properties yet: the solver computes those of a body without colliders from its builder's
//! `additional_mass_properties`. A body with colliders and additional mass properties holds its
//! colliders' mass only until Rapier's first step: call Rapier's
//! `recompute_mass_properties_from_colliders` on it before a solve at the initial state (the
//! solver refuses such a body when its stored mass is below the additional one, with
//! [`ReactionSolver::failure`] naming it, but cannot tell otherwise without the colliders).
//! All a user needs, nothing hidden:
//!
//! ```
//! use clearance_joint::rapier::observers::reaction::{IdealJoint, ReactionSolver};
//! use rapier3d_f64::prelude::*;
//! use rapier3d_f64::math::Vector;
//!
//! // A 2 kg arm hanging at rest 0.3 m below a fixed pivot carries its weight (before any step).
//! let mut bodies = RigidBodySet::new();
//! let base = bodies.insert(RigidBodyBuilder::fixed());
//! let arm = bodies.insert(
//!     RigidBodyBuilder::dynamic()
//!         .translation(Vector::new(0.0, -0.3, 0.0))
//!         .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02))),
//! );
//! let mut joints = ImpulseJointSet::new();
//! let pivot = RevoluteJointBuilder::new(Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0));
//! let pivot = joints.insert(base, arm, pivot, true);
//! let joint = IdealJoint::from_rapier(&joints, pivot)?;
//! let mut solver = ReactionSolver::default();
//! let forces = solver.solve(&bodies, &[joint], Vector::new(0.0, -9.81, 0.0)).unwrap();
//! assert!((forces[0] - Vector::new(0.0, 2.0 * 9.81, 0.0)).length() < 1e-9);
//! // At rest, held: no acceleration.
//! let (a, alpha) = solver.acceleration(arm).unwrap();
//! assert!(a.length() < 1e-12 && alpha.length() < 1e-12);
//! # Ok::<(), clearance_joint::Error>(())
//! ```

mod body;
mod joints;
pub(crate) mod lu;
mod motor;
mod rows;
mod solve;
#[cfg(test)]
mod tests;

pub use body::KinematicState;
pub use joints::IdealJoint;
pub(crate) use joints::{
    IdealFixed, IdealPrismatic, IdealRevolute, IdealSpherical, JointModel, joint_frames,
};
pub(crate) use motor::SoftMotor;

use crate::rapier::pipeline::ledger::Wrench;
use body::Entry;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{
    ColliderSet, RigidBody, RigidBodyAdditionalMassProps, RigidBodyHandle, RigidBodySet,
};
use rows::Row;

/// Solves for ideal-joint reactions; keeps its buffers between calls (no allocation per step
/// once sized).
#[derive(Clone, Debug, Default)]
pub struct ReactionSolver {
    /// Bodies whose motion is prescribed with a nonzero acceleration (a tabulated drive): their
    /// velocities and accelerations at the state. Other kinematic bodies are taken to move at
    /// constant velocity.
    pub kinematic: Vec<KinematicState>,
    /// How long before the state the bodies' stored velocities are, s: the stored velocities are
    /// advanced by it with the accelerations solved. For Rapier's velocities after a step of the
    /// [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld) its
    /// `solve_reactions` sets it (half the last step with one solver iteration, `h/(2 n)` at
    /// constant steps with `n`; 0 before the first step, whose velocities are the initial
    /// state's); for a plain Rapier loop at constant steps `dt/(2 n)`. Default 0: the stored
    /// velocities are taken as the state's (and only projected onto the joints).
    pub velocity_lag: f64,
    /// Further bodies whose velocities and accelerations at the state the solve reports
    /// ([`velocity`](Self::velocity), [`acceleration`](Self::acceleration)) though no listed
    /// joint holds them (a free body, one held by clearance joints only).
    pub track: Vec<RigidBodyHandle>,
    /// Dense `J M^-1 J^T` and its LU factors, row-major; the same for the position rows alone.
    a: Vec<f64>,
    lu: Vec<f64>,
    piv: Vec<usize>,
    a_pos: Vec<f64>,
    lu_pos: Vec<f64>,
    piv_pos: Vec<usize>,
    scratch: Vec<f64>,
    /// Indices of the position rows.
    pos_rows: Vec<usize>,
    /// Right-hand side, then the multipliers.
    b: Vec<f64>,
    b_pos: Vec<f64>,
    rows: Vec<Row>,
    /// First row of each joint.
    starts: Vec<usize>,
    entries: Vec<Entry>,
    forces: Vec<Vector>,
    motors: Vec<Option<f64>>,
    /// Per joint with a motor: the relative speed along its axis at the state.
    motor_rates: Vec<f64>,
    extra: Vec<Wrench>,
    /// The bodies' acceleration change under the loads of the last
    /// [`load_response`](Self::load_response), per body of the solve, and its multipliers.
    response: Vec<(Vector, Vector)>,
    b_load: Vec<f64>,
    /// Why the last solve returned `None`.
    failure: Option<ReactionFailure>,
}

/// Why a solve of [`ReactionSolver`] returned `None` ([`ReactionSolver::failure`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum ReactionFailure {
    /// A joint's body (or a tracked one) is not in the `RigidBodySet`.
    MissingBody(RigidBodyHandle),
    /// A dynamic body with colliders does not have its mass properties yet: before Rapier's
    /// first step they hold only its colliders' (the builder's `additional_mass_properties` are
    /// added in that step), and the solver is not given the `ColliderSet`. Call
    /// `bodies[handle].recompute_mass_properties_from_colliders(&colliders)` for it (or take
    /// one step) before solving. A body without colliders needs nothing: the solver computes
    /// its mass properties from the builder's `additional_mass_properties`.
    MassPropertiesPending(RigidBodyHandle),
    /// The constrained equations cannot be solved: a non-finite state or mass.
    Unsolvable,
}

impl std::fmt::Display for ReactionFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReactionFailure::MissingBody(h) => {
                write!(f, "body {h:?} of an ideal joint is not in the body set")
            }
            ReactionFailure::MassPropertiesPending(h) => write!(
                f,
                "body {h:?} has colliders but no mass properties yet (Rapier computes them at the \
                 first step): call recompute_mass_properties_from_colliders on it before solving"
            ),
            ReactionFailure::Unsolvable => write!(
                f,
                "the ideal joints' equations cannot be solved (a non-finite state or mass)"
            ),
        }
    }
}

impl std::error::Error for ReactionFailure {}

impl ReactionSolver {
    /// The force on each joint's body 2 at its anchor (N, world frame), in the order of
    /// `joints`, at the bodies' current state under their user forces and torques and `gravity`:
    /// for a prismatic joint the part normal to the axis, the only one an ideal slide carries; a
    /// motor's torque or force is [`motor`](Self::motor). Every ideal joint of the mechanism must
    /// be listed: a joint left out is a free motion to the solver. Kinematic bodies are taken to
    /// move at constant velocity (their accelerations are those of a rigid rotation at their
    /// angular velocity) unless [`kinematic`](Self::kinematic) prescribes them. Redundant
    /// constraints (a closed loop, whose reactions rigid dynamics alone do not determine) get a
    /// least-norm share through a relative regularisation of 1e-12, used only when the system is
    /// singular. A joint between two bodies that no force moves (fixed or kinematic on both
    /// sides) carries no unknown: its force is zero (their supports take the load) and it does
    /// not affect the others. Works before the first step (see the [module](self) docs). `None`,
    /// never a made-up force, when a body is missing, a body with colliders has no mass
    /// properties yet, or the system cannot be solved (a non-finite state or mass):
    /// [`failure`](Self::failure) says which. Only the listed joints are constraints: contacts
    /// with colliders are not part of the solve.
    pub fn solve(
        &mut self,
        bodies: &RigidBodySet,
        joints: &[IdealJoint],
        gravity: Vector,
    ) -> Option<&[Vector]> {
        self.solve_with(bodies, joints, gravity, &[])
    }

    /// [`solve`](Self::solve) with further applied wrenches on the bodies: those of the force
    /// sources the step loop adds during its steps only (drives, clearance contacts), which the
    /// bodies' user forces do not hold between steps
    /// ([`ClearanceWorld::solve_reactions`](crate::rapier::pipeline::world::ClearanceWorld::solve_reactions)).
    pub(crate) fn solve_with(
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

    /// The motor torque (N m about the axis, revolute) or force (N along the axis, prismatic) on
    /// body 2 of joint `k` of the last solve: the held-speed row's multiplier or the soft
    /// motor's law at the state. `None` without a motor (or before a solve).
    pub fn motor(&self, k: usize) -> Option<f64> {
        self.motors.get(k).copied().flatten()
    }

    /// Velocity of the centre of mass (m/s) and angular velocity (rad/s) of `body` at the state
    /// of the last solve: the stored ones advanced by [`velocity_lag`](Self::velocity_lag) and
    /// made consistent with the joints. `None` for a body neither in the joints nor in
    /// [`track`](Self::track).
    pub fn velocity(&self, body: RigidBodyHandle) -> Option<(Vector, Vector)> {
        self.entry(body).map(|e| (e.v, e.w))
    }

    /// Acceleration of the centre of mass (m/s^2) and angular acceleration (rad/s^2) of `body`
    /// at the state of the last solve, `M^-1 (F + J^T lambda)` (the prescribed ones of a driven
    /// body). `None` for a body neither in the joints nor in [`track`](Self::track).
    pub fn acceleration(&self, body: RigidBodyHandle) -> Option<(Vector, Vector)> {
        self.entry(body).map(|e| (e.acc, e.alpha))
    }

    /// The relative speed of joint `k`'s bodies along its motor's axis at the state of the last
    /// solve: rad/s about a revolute's axis, m/s along a prismatic axis (body 2 relative to
    /// body 1). Times [`motor`](Self::motor), the power the motor delivers. `None` without a
    /// motor.
    pub fn motor_rate(&self, k: usize) -> Option<f64> {
        self.motors
            .get(k)
            .copied()
            .flatten()
            .map(|_| self.motor_rates[k])
    }

    /// Why the last solve returned `None` (`None` after a solve that succeeded or before any).
    pub fn failure(&self) -> Option<ReactionFailure> {
        self.failure
    }

    /// The change in `body`'s accelerations (centre of mass m/s^2, angular rad/s^2) under the
    /// loads of the last [`load_response`](Self::load_response). `None` for a body not in the
    /// solve.
    pub(crate) fn response(&self, body: RigidBodyHandle) -> Option<(Vector, Vector)> {
        let i = self.entries.iter().position(|e| e.handle == body)?;
        self.response.get(i).copied()
    }

    fn entry(&self, body: RigidBodyHandle) -> Option<&Entry> {
        self.entries.iter().find(|e| e.handle == body)
    }

    /// Index of `handle` in the body table, adding it first if needed.
    fn body_index(
        &mut self,
        bodies: &RigidBodySet,
        handle: RigidBodyHandle,
        gravity: Vector,
    ) -> Option<usize> {
        if let Some(i) = self.entries.iter().position(|e| e.handle == handle) {
            return Some(i);
        }
        let Some(rb) = bodies.get(handle) else {
            self.failure = Some(ReactionFailure::MissingBody(handle));
            return None;
        };
        let computed;
        let rb = match pending_mass_properties(rb) {
            Pending::No => rb,
            Pending::WithoutColliders => {
                computed = with_mass_properties(rb);
                &computed
            }
            Pending::WithColliders => {
                self.failure = Some(ReactionFailure::MassPropertiesPending(handle));
                return None;
            }
        };
        self.entries.push(Entry::new(
            rb,
            handle,
            gravity,
            &self.extra,
            &self.kinematic,
        ));
        Some(self.entries.len() - 1)
    }
}

/// Whether a body's mass properties are still those before Rapier's first step, which adds the
/// builder's additional mass properties to the colliders' (attaching a collider adds its own at
/// once).
enum Pending {
    No,
    WithoutColliders,
    WithColliders,
}

fn pending_mass_properties(rb: &RigidBody) -> Pending {
    let mp = rb.mass_properties();
    if !rb.is_dynamic() {
        return Pending::No;
    }
    if rb.colliders().is_empty() {
        return if mp.local_mprops.inv_mass == 0.0 {
            Pending::WithoutColliders
        } else {
            Pending::No
        };
    }
    let additional = match mp.additional_local_mprops.as_deref() {
        Some(RigidBodyAdditionalMassProps::MassProps(p)) => p.mass(),
        Some(RigidBodyAdditionalMassProps::Mass(m)) => *m,
        None => 0.0,
    };
    // Computed, the mass is the colliders' plus the additional one: never below the latter.
    if mp.local_mprops.inv_mass == 0.0 || mp.local_mprops.mass() < additional {
        Pending::WithColliders
    } else {
        Pending::No
    }
}

/// A copy of a body without colliders, with the mass properties Rapier computes at its first
/// step (those of the builder's `additional_mass_properties`).
fn with_mass_properties(rb: &RigidBody) -> RigidBody {
    let mut rb = rb.clone();
    rb.recompute_mass_properties_from_colliders(&ColliderSet::new());
    rb
}

/// Computes the local mass properties of every dynamic body that has none yet (Rapier does it at
/// the first step), from the bodies' additional mass properties: what a reader of the bodies'
/// inertia (e.g. a replay drawing a body without colliders as its equivalent box) needs before
/// the first step. Colliders' mass is not included (the `ColliderSet` is not given):
/// for a body with colliders, call Rapier's `recompute_mass_properties_from_colliders`. The
/// [`ReactionSolver`] does not need this call.
pub fn prepare_mass_properties(bodies: &mut RigidBodySet) {
    let handles: Vec<RigidBodyHandle> = bodies.iter().map(|(h, _)| h).collect();
    for h in handles {
        crate::rapier::pipeline::ledger::ensure_mass_properties(bodies, None, h);
    }
}
