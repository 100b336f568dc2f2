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
//! (the [`Stepper`](crate::rapier::stepper::Stepper) makes that exactly half the last step), and
//! they satisfy the joints at the previous positions, not the current ones. The solver therefore
//! (1) advances the stored velocities by [`velocity_lag`](ReactionSolver::velocity_lag) with the
//! accelerations it solves at them (second order in the lag: a second pass), and (2) projects
//! them onto the joints'
//! velocity constraints at the current positions (the mass-weighted least change), so that the
//! centripetal and Coriolis terms are those of a state of the ideal mechanism. A mechanism whose
//! motion is fully prescribed (a driven crank) then gets its exact velocities from the
//! projection, whatever the step.
//!
//! **Motors.** A velocity motor that holds its speed ([`IdealJoint::MotorRevolute`],
//! [`IdealJoint::MotorPrismatic`]) is one more constraint row (`d(speed)/dt = 0`), its multiplier
//! the motor torque or force. A soft motor ([`SoftMotor`]: Rapier's spring-damper
//! `k (x_target - x) + c (v_target - v)`, times the row's effective mass in Rapier's
//! acceleration-based model) is an applied wrench computed from the state.
//!
//! ```
//! use clearance_joint::rapier::reaction::{IdealRevolute, ReactionSolver};
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
//! # clearance_joint::rapier::reaction::prepare_mass_properties(&mut bodies);
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
//! // At rest, held: no acceleration.
//! let (a, alpha) = solver.acceleration(arm).unwrap();
//! assert!(a.length() < 1e-12 && alpha.length() < 1e-12);
//! ```

use crate::rapier::ledger::Wrench;
use rapier3d_f64::math::{AngularInertia, Pose, Rotation, Vector};
use rapier3d_f64::prelude::{JointMotor, MotorModel, RigidBody, RigidBodyHandle, RigidBodySet};

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

/// An ideal prismatic joint for [`ReactionSolver::solve_joints`]: body 2 slides along the axis
/// without turning relative to body 1. Limits are not modelled: the reaction is the one of a
/// free slide (a limit in contact adds a force along the axis that the solver does not know).
/// A motor is ([`IdealJoint::MotorPrismatic`], [`IdealJoint::SoftMotorPrismatic`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdealPrismatic {
    /// First body (the guide).
    pub body1: RigidBodyHandle,
    /// Second body (the slider): reactions are the forces on it.
    pub body2: RigidBodyHandle,
    /// A point of the slide line in body 1's frame, m.
    pub local_anchor1: Vector,
    /// The slider's point on that line in body 2's frame, m.
    pub local_anchor2: Vector,
    /// Unit slide axis in body 1's frame.
    pub local_axis1: Vector,
}

/// An ideal fixed joint for [`ReactionSolver::solve_joints`]: the two bodies move as one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdealFixed {
    /// First body.
    pub body1: RigidBodyHandle,
    /// Second body: reactions are the forces on it.
    pub body2: RigidBodyHandle,
    /// The joint point in body 1's frame, m (where the reaction force is reported).
    pub local_anchor1: Vector,
    /// The joint point in body 2's frame, m.
    pub local_anchor2: Vector,
}

/// An ideal spherical joint (ball and socket) for [`ReactionSolver::solve_joints`]: the anchors
/// coincide, rotation is free.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdealSpherical {
    /// First body.
    pub body1: RigidBodyHandle,
    /// Second body: reactions are the forces on it.
    pub body2: RigidBodyHandle,
    /// The joint point in body 1's frame, m.
    pub local_anchor1: Vector,
    /// The joint point in body 2's frame, m.
    pub local_anchor2: Vector,
}

/// A soft joint motor, Rapier's ([`JointMotor`] with its [`MotorModel`]): on the joint's free
/// axis it exerts on body 2 (and the opposite on body 1)
/// `F = k (x_target - x) + c (v_target - v)`, clamped to `max_force`: N m about the axis for a
/// revolute (`x` the angle, rad), N along the axis for a prismatic joint (`x` the displacement,
/// m). With [`MotorModel::AccelerationBased`] (Rapier's default) `F` is further multiplied by
/// the effective mass of the motor's row as Rapier builds it: `1/(a . (I1^-1 + I2^-1) a)` about
/// the axis `a` of a revolute, the two bodies' inverse masses and lever terms along a prismatic
/// axis (the joint's other rows and the rest of the mechanism play no part).
///
/// This is the limit of Rapier's implicit motor row as the step shrinks (Rapier evaluates the
/// law at the end of each step): the motor's force as a function of the state. The angle is
/// Rapier's, `2 asin` of the relative rotation's component along the axis (in `[-pi, pi]`, the
/// error to the target wrapped to the shorter way round), zero when the bodies' frames are
/// aligned, as for a joint built with `RevoluteJointBuilder::new(axis)` between bodies that
/// start unrotated; the displacement is `(p2 - p1) . a`, zero when the anchors coincide.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoftMotor {
    /// Target angle (rad) or displacement (m).
    pub target_pos: f64,
    /// Target angular (rad/s) or linear (m/s) speed.
    pub target_vel: f64,
    /// Stiffness `k`: N m/rad or N/m force-based, 1/s^2 acceleration-based.
    pub stiffness: f64,
    /// Damping `c`: N m s/rad or N s/m force-based, 1/s acceleration-based.
    pub damping: f64,
    /// The largest force or torque the motor exerts (N or N m; `f64::MAX` for none).
    pub max_force: f64,
    /// How Rapier reads the stiffness and damping.
    pub model: MotorModel,
}

impl SoftMotor {
    /// A force-based motor (stiffness and damping in physical units) without a force limit.
    pub fn force_based(target_pos: f64, target_vel: f64, stiffness: f64, damping: f64) -> Self {
        SoftMotor {
            target_pos,
            target_vel,
            stiffness,
            damping,
            max_force: f64::MAX,
            model: MotorModel::ForceBased,
        }
    }

    /// The motor of a Rapier joint axis (`joint.motor(JointAxis::AngX)`, say).
    pub fn from_rapier(motor: &JointMotor) -> Self {
        SoftMotor {
            target_pos: motor.target_pos,
            target_vel: motor.target_vel,
            stiffness: motor.stiffness,
            damping: motor.damping,
            max_force: motor.max_force,
            model: motor.model,
        }
    }

    /// The force on body 2 along the axis for a position error `x - x_target` (wrapped for an
    /// angle), a speed `v` and the row's effective mass `row_mass` (used by the
    /// acceleration-based model only).
    pub fn force(&self, position_error: f64, v: f64, row_mass: f64) -> f64 {
        let f = -self.stiffness * position_error + self.damping * (self.target_vel - v);
        let f = match self.model {
            MotorModel::ForceBased => f,
            MotorModel::AccelerationBased => row_mass * f,
        };
        f.clamp(-self.max_force, self.max_force)
    }
}

/// Any ideal joint the solver handles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IdealJoint {
    /// A hinge: 3 linear and 2 angular constraints.
    Revolute(IdealRevolute),
    /// A slide: 2 linear (normal to the axis) and 3 angular constraints.
    Prismatic(IdealPrismatic),
    /// A weld: 3 linear and 3 angular constraints.
    Fixed(IdealFixed),
    /// A ball joint: 3 linear constraints.
    Spherical(IdealSpherical),
    /// A revolute whose velocity motor holds the relative angular speed constant: the revolute's
    /// constraints plus one along the axis (its multiplier is the motor torque). Exact for a
    /// motor that holds its speed; a stiff motor's small speed error is not in it.
    MotorRevolute(IdealRevolute),
    /// A prismatic joint whose velocity motor holds the relative speed along the axis constant:
    /// one more row (its multiplier is the motor force), as [`MotorRevolute`](Self::MotorRevolute).
    MotorPrismatic(IdealPrismatic),
    /// A revolute with a soft motor: the motor's torque is applied from the state.
    SoftMotorRevolute(IdealRevolute, SoftMotor),
    /// A prismatic joint with a soft motor: the motor's force is applied from the state.
    SoftMotorPrismatic(IdealPrismatic, SoftMotor),
}

impl IdealJoint {
    fn bodies(&self) -> (RigidBodyHandle, RigidBodyHandle) {
        match self {
            IdealJoint::Revolute(j)
            | IdealJoint::MotorRevolute(j)
            | IdealJoint::SoftMotorRevolute(j, _) => (j.body1, j.body2),
            IdealJoint::Prismatic(j)
            | IdealJoint::MotorPrismatic(j)
            | IdealJoint::SoftMotorPrismatic(j, _) => (j.body1, j.body2),
            IdealJoint::Fixed(j) => (j.body1, j.body2),
            IdealJoint::Spherical(j) => (j.body1, j.body2),
        }
    }

    /// How many of the joint's rows (the first ones) carry the reported joint force.
    fn force_rows(&self) -> usize {
        match self {
            IdealJoint::Revolute(_)
            | IdealJoint::MotorRevolute(_)
            | IdealJoint::SoftMotorRevolute(..)
            | IdealJoint::Fixed(_)
            | IdealJoint::Spherical(_) => 3,
            IdealJoint::Prismatic(_)
            | IdealJoint::MotorPrismatic(_)
            | IdealJoint::SoftMotorPrismatic(..) => 2,
        }
    }
}

impl From<IdealRevolute> for IdealJoint {
    fn from(j: IdealRevolute) -> Self {
        IdealJoint::Revolute(j)
    }
}

impl From<IdealPrismatic> for IdealJoint {
    fn from(j: IdealPrismatic) -> Self {
        IdealJoint::Prismatic(j)
    }
}

impl From<IdealSpherical> for IdealJoint {
    fn from(j: IdealSpherical) -> Self {
        IdealJoint::Spherical(j)
    }
}

impl From<IdealFixed> for IdealJoint {
    fn from(j: IdealFixed) -> Self {
        IdealJoint::Fixed(j)
    }
}

/// The prescribed state of a kinematic body at the state solved: velocity and acceleration of
/// its centre of mass (its frame origin when it has no mass), angular velocity and acceleration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KinematicState {
    /// The body.
    pub body: RigidBodyHandle,
    /// Velocity of the centre of mass, m/s.
    pub linvel: Vector,
    /// Angular velocity, rad/s.
    pub angvel: Vector,
    /// Acceleration of the centre of mass, m/s^2.
    pub linacc: Vector,
    /// Angular acceleration, rad/s^2.
    pub angacc: Vector,
}

/// One body of the solve.
#[derive(Clone, Copy, Debug)]
struct Entry {
    handle: RigidBodyHandle,
    dynamic: bool,
    gyroscopic: bool,
    inv_mass: f64,
    inv_inertia: AngularInertia,
    /// World rotation of the principal axes and the principal inertia (gyroscopic term).
    principal_rot: Rotation,
    principal: Vector,
    pose: Pose,
    rot: Rotation,
    com: Vector,
    /// Stored velocities (Rapier's, or the prescribed ones of a driven body).
    stored_v: Vector,
    stored_w: Vector,
    /// The state's velocities.
    v: Vector,
    w: Vector,
    /// Applied force and torque that do not depend on the velocities (user forces, extra
    /// wrenches, gravity).
    f0: Vector,
    t0: Vector,
    /// All applied at the state's velocities (with the gyroscopic term and soft motors).
    f: Vector,
    t: Vector,
    /// Prescribed accelerations of a driven body.
    prescribed: Option<(Vector, Vector)>,
    /// The accelerations solved.
    acc: Vector,
    alpha: Vector,
}

impl Entry {
    fn new(
        rb: &RigidBody,
        handle: RigidBodyHandle,
        gravity: Vector,
        extra: &[Wrench],
        kinematic: &[KinematicState],
    ) -> Entry {
        let (mut f_extra, mut t_extra) = (Vector::ZERO, Vector::ZERO);
        for w in extra.iter().filter(|w| w.body == handle) {
            f_extra += w.force;
            t_extra += w.torque;
        }
        let mp = &rb.mass_properties().local_mprops;
        let dynamic = rb.is_dynamic();
        let mass = if mp.inv_mass > 0.0 {
            1.0 / mp.inv_mass
        } else {
            0.0
        };
        let mut e = Entry {
            handle,
            dynamic,
            gyroscopic: rb.gyroscopic_forces_enabled(),
            inv_mass: if dynamic { mp.inv_mass } else { 0.0 },
            inv_inertia: mp.world_inv_inertia(rb.rotation()),
            principal_rot: *rb.rotation() * mp.principal_inertia_local_frame,
            principal: mp.principal_inertia(),
            pose: *rb.position(),
            rot: *rb.rotation(),
            com: crate::rapier::ledger::world_center_of_mass(rb),
            stored_v: rb.linvel(),
            stored_w: rb.angvel(),
            v: rb.linvel(),
            w: rb.angvel(),
            f0: rb.user_force() + f_extra + mass * rb.gravity_scale() * gravity,
            t0: rb.user_torque() + t_extra,
            f: Vector::ZERO,
            t: Vector::ZERO,
            prescribed: None,
            acc: Vector::ZERO,
            alpha: Vector::ZERO,
        };
        if let Some(k) = kinematic.iter().find(|k| k.body == handle) {
            (e.stored_v, e.stored_w) = (k.linvel, k.angvel);
            (e.v, e.w) = (k.linvel, k.angvel);
            e.prescribed = Some((k.linacc, k.angacc));
        }
        e
    }

    /// `M^-1 (f, t)` of this body (zero unless dynamic).
    fn apply_inv_mass(&self, f: Vector, t: Vector) -> (Vector, Vector) {
        if !self.dynamic {
            return (Vector::ZERO, Vector::ZERO);
        }
        (self.inv_mass * f, self.inv_inertia * t)
    }

    /// The applied wrench at the state's velocities (before soft motors): with the gyroscopic
    /// term `-w x (I w)`.
    fn applied(&self) -> (Vector, Vector) {
        let gyro = if self.gyroscopic {
            let r = self.principal_rot;
            self.w.cross(r * (self.principal * (r.inverse() * self.w)))
        } else {
            Vector::ZERO
        };
        (self.f0, self.t0 - gyro)
    }

    /// The accelerations without the joints: `M^-1 F`, or the prescribed ones of a driven body
    /// (zero for a fixed body and a kinematic body moving steadily).
    fn free_acceleration(&self) -> (Vector, Vector) {
        match self.prescribed {
            Some(p) => p,
            None => self.apply_inv_mass(self.f, self.t),
        }
    }
}

/// One constraint row between two bodies of the solve.
#[derive(Clone, Copy, Debug)]
struct Row {
    /// Indices of the two bodies in the solve's body table.
    b1: usize,
    b2: usize,
    /// Jacobian blocks: linear and angular for body 1, then for body 2.
    jac: [Vector; 4],
    /// The velocity-product term: `J a + c = 0`.
    c: f64,
    /// A position constraint (its velocity `J v` is zero); false for a motor's speed row.
    position: bool,
}

impl Row {
    fn dot(&self, a1: (Vector, Vector), a2: (Vector, Vector)) -> f64 {
        self.jac[0].dot(a1.0)
            + self.jac[1].dot(a1.1)
            + self.jac[2].dot(a2.0)
            + self.jac[3].dot(a2.1)
    }
}

/// Solves for ideal-joint reactions; keeps its buffers between calls (no allocation per step
/// once sized).
#[derive(Clone, Debug, Default)]
pub struct ReactionSolver {
    /// Bodies whose motion is prescribed with a nonzero acceleration (a tabulated drive): their
    /// velocities and accelerations at the state. Other kinematic bodies are taken to move at
    /// constant velocity.
    pub kinematic: Vec<KinematicState>,
    /// How long before the state the bodies' stored velocities are, s: the stored velocities are
    /// advanced by it with the accelerations solved. Half the last step for Rapier's velocities
    /// after a step of the [`Stepper`](crate::rapier::stepper::Stepper)
    /// (`stepper.last_dt() / 2`; 0 before the first step, whose velocities are the initial
    /// state's) or of a plain Rapier loop at constant steps (`dt / 2`). Default 0: the stored
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
    revolutes: Vec<IdealJoint>,
    extra: Vec<Wrench>,
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

/// Rapier's revolute angle: `2 asin` of the relative rotation's component along the axis
/// (`local_axis1`, body 1's frame), the relative rotation taken with a nonnegative real part.
fn rapier_angle(rot1: Rotation, rot2: Rotation, local_axis1: Vector) -> f64 {
    let q = rot1.inverse() * rot2;
    let s = if q.w < 0.0 { -1.0 } else { 1.0 };
    2.0 * (s * q.xyz().dot(local_axis1.normalize()))
        .clamp(-1.0, 1.0)
        .asin()
}

/// `a - b` wrapped to `[-pi, pi]`, as Rapier compares a motor's angle with its target.
fn angle_difference(a: f64, b: f64) -> f64 {
    let d = a - b;
    let other = d - d.signum() * std::f64::consts::TAU;
    if d.abs() < other.abs() { d } else { other }
}

impl ReactionSolver {
    /// The force on each joint's body 2 (N, world frame), in the order of `joints`, at the bodies'
    /// current state under their user forces and torques and `gravity`. Redundant constraints (a
    /// closed loop, whose reactions rigid dynamics alone do not determine) get a least-norm
    /// share through a relative regularisation of 1e-12, used only when the system is singular.
    /// `None` when a body is missing. Only the listed joints are constraints: contacts with
    /// colliders are not part of the solve.
    pub fn solve(
        &mut self,
        bodies: &RigidBodySet,
        joints: &[IdealRevolute],
        gravity: Vector,
    ) -> Option<&[Vector]> {
        self.solve_with(bodies, joints, gravity, &[])
    }

    /// [`solve`](Self::solve) with further applied wrenches on the bodies: those of the force
    /// sources the [`Stepper`](crate::rapier::stepper::Stepper) adds during its steps only (drives,
    /// clearance contacts), which the bodies' user forces do not hold between steps.
    pub fn solve_with(
        &mut self,
        bodies: &RigidBodySet,
        joints: &[IdealRevolute],
        gravity: Vector,
        extra: &[Wrench],
    ) -> Option<&[Vector]> {
        let mut all = std::mem::take(&mut self.revolutes);
        all.clear();
        all.extend(joints.iter().map(|&j| IdealJoint::Revolute(j)));
        let ok = self
            .solve_joints_with(bodies, &all, gravity, extra)
            .is_some();
        self.revolutes = all;
        if ok { Some(&self.forces) } else { None }
    }

    /// [`solve_joints`](Self::solve_joints) with further applied wrenches, as in
    /// [`solve_with`](Self::solve_with).
    pub fn solve_joints_with(
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

    /// [`solve`](Self::solve) for any mix of revolute, prismatic, fixed and spherical joints, with
    /// or without motors: the force on each joint's body 2 at its anchor (N, world frame; for a
    /// prismatic joint the part normal to the axis, the only one an ideal slide carries; a
    /// motor's torque or force is [`motor`](Self::motor)). Every ideal joint of the mechanism
    /// must be listed: a joint left out is a free motion to the solver. Kinematic bodies are
    /// taken to move at constant velocity (their accelerations are those of a rigid rotation at
    /// their angular velocity) unless [`kinematic`](Self::kinematic) prescribes them.
    pub fn solve_joints(
        &mut self,
        bodies: &RigidBodySet,
        joints: &[IdealJoint],
        gravity: Vector,
    ) -> Option<&[Vector]> {
        self.solve_joints_with(bodies, joints, gravity, &[])
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
        let rb = bodies.get(handle)?;
        self.entries.push(Entry::new(
            rb,
            handle,
            gravity,
            &self.extra,
            &self.kinematic,
        ));
        Some(self.entries.len() - 1)
    }

    fn solve_joints_inner(
        &mut self,
        bodies: &RigidBodySet,
        joints: &[IdealJoint],
        gravity: Vector,
    ) -> Option<()> {
        self.entries.clear();
        self.forces.clear();
        self.motors.clear();
        self.starts.clear();
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
        self.pos_rows.clear();
        self.pos_rows
            .extend((0..n).filter(|&i| self.rows[i].position));
        if !factor_regularised(&self.a, &mut self.lu, &mut self.piv, n) {
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

    /// The rows of every joint at the bodies' current velocities (the Jacobian from the
    /// positions, the velocity-product terms `c` from the velocities).
    fn build_rows(&mut self, joints: &[IdealJoint], pairs: &[(usize, usize)]) {
        self.rows.clear();
        self.starts.clear();
        for (j, &(i1, i2)) in joints.iter().zip(pairs) {
            self.starts.push(self.rows.len());
            let (e1, e2) = (&self.entries[i1], &self.entries[i2]);
            let (v1, v2, w1, w2) = (e1.v, e2.v, e1.w, e2.w);
            let held = matches!(
                j,
                IdealJoint::MotorRevolute(_) | IdealJoint::MotorPrismatic(_)
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
                IdealJoint::Revolute(j)
                | IdealJoint::MotorRevolute(j)
                | IdealJoint::SoftMotorRevolute(j, _) => {
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
                IdealJoint::Prismatic(j)
                | IdealJoint::MotorPrismatic(j)
                | IdealJoint::SoftMotorPrismatic(j, _) => {
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
                IdealJoint::Spherical(j) => {
                    let r1 = e1.pose * j.local_anchor1 - e1.com;
                    let r2 = e2.pose * j.local_anchor2 - e2.com;
                    point_rows(&mut push, r1, r2);
                }
                IdealJoint::Fixed(j) => {
                    let r1 = e1.pose * j.local_anchor1 - e1.com;
                    let r2 = e2.pose * j.local_anchor2 - e2.com;
                    point_rows(&mut push, r1, r2);
                    weld_rows(&mut push);
                }
            }
        }
    }

    /// `A = J M^-1 J^T` into `self.a`: entries between rows sharing a body.
    fn assemble(&mut self) {
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
            self.b_pos.push(r.dot((e1.v, e1.w), (e2.v, e2.w)));
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

    /// The applied wrenches at the state's velocities: the bodies' own, then the soft motors'
    /// (recorded in `self.motors`, as are the held motors' placeholders).
    fn apply_motors(&mut self, joints: &[IdealJoint], pairs: &[(usize, usize)]) {
        for e in &mut self.entries {
            (e.f, e.t) = e.applied();
        }
        self.motors.clear();
        self.motor_rates.clear();
        for (j, &(i1, i2)) in joints.iter().zip(pairs) {
            let (e1, e2) = (self.entries[i1], self.entries[i2]);
            self.motor_rates.push(match j {
                IdealJoint::MotorRevolute(j) | IdealJoint::SoftMotorRevolute(j, _) => {
                    (e1.rot * j.local_axis1).normalize().dot(e2.w - e1.w)
                }
                IdealJoint::MotorPrismatic(j) | IdealJoint::SoftMotorPrismatic(j, _) => {
                    let axis = (e1.rot * j.local_axis1).normalize();
                    let p2 = e2.pose * j.local_anchor2;
                    axis.dot((e2.v + e2.w.cross(p2 - e2.com)) - (e1.v + e1.w.cross(p2 - e1.com)))
                }
                _ => 0.0,
            });
            let motor = match j {
                IdealJoint::SoftMotorRevolute(j, m) => {
                    let axis = (e1.rot * j.local_axis1).normalize();
                    let angle = rapier_angle(e1.rot, e2.rot, j.local_axis1);
                    let rate = axis.dot(e2.w - e1.w);
                    let inv = |e: &Entry| {
                        if e.dynamic {
                            axis.dot(e.inv_inertia * axis)
                        } else {
                            0.0
                        }
                    };
                    let mass = inv_or_zero(inv(&e1) + inv(&e2));
                    let tau = m.force(angle_difference(angle, m.target_pos), rate, mass);
                    self.entries[i2].t += tau * axis;
                    self.entries[i1].t -= tau * axis;
                    Some(tau)
                }
                IdealJoint::SoftMotorPrismatic(j, m) => {
                    let p1 = e1.pose * j.local_anchor1;
                    let p2 = e2.pose * j.local_anchor2;
                    let axis = (e1.rot * j.local_axis1).normalize();
                    // Body 1's point under the slider's (Rapier's lever for body 1).
                    let (r1, r2) = (p2 - e1.com, p2 - e2.com);
                    let rate = axis.dot((e2.v + e2.w.cross(r2)) - (e1.v + e1.w.cross(r1)));
                    let inv = |e: &Entry, r: Vector| {
                        if e.dynamic {
                            let ra = r.cross(axis);
                            e.inv_mass + ra.dot(e.inv_inertia * ra)
                        } else {
                            0.0
                        }
                    };
                    let mass = inv_or_zero(inv(&e1, r1) + inv(&e2, r2));
                    let f = m.force((p2 - p1).dot(axis) - m.target_pos, rate, mass) * axis;
                    self.entries[i2].f += f;
                    self.entries[i2].t += r2.cross(f);
                    self.entries[i1].f -= f;
                    self.entries[i1].t -= r1.cross(f);
                    Some(f.dot(axis))
                }
                // The held motors' multipliers come with the solve.
                IdealJoint::MotorRevolute(_) | IdealJoint::MotorPrismatic(_) => Some(0.0),
                _ => None,
            };
            self.motors.push(motor);
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
            self.b
                .push(-(r.c + r.dot((e1.acc, e1.alpha), (e2.acc, e2.alpha))));
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

fn inv_or_zero(x: f64) -> f64 {
    if x > 0.0 { 1.0 / x } else { 0.0 }
}

/// LU factors of the `n x n` row-major `a` into `lu`, with a relative regularisation of 1e-12
/// on the diagonal when `a` is singular (redundant constraints: a least-norm share). False when
/// even that fails.
fn factor_regularised(a: &[f64], lu: &mut Vec<f64>, piv: &mut Vec<usize>, n: usize) -> bool {
    lu.clear();
    lu.extend_from_slice(a);
    if lu_factor(lu, piv, n) {
        return true;
    }
    lu.clear();
    lu.extend_from_slice(a);
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for i in 0..n {
        lu[i * n + i] += 1e-12 * scale;
    }
    lu_factor(lu, piv, n)
}

/// LU factorisation with partial pivoting of the `n x n` row-major `a` in place (`piv` the row
/// order). False when `a` is singular to working precision.
fn lu_factor(a: &mut [f64], piv: &mut Vec<usize>, n: usize) -> bool {
    piv.clear();
    piv.extend(0..n);
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
            piv.swap(pivot, col);
        }
        for i in col + 1..n {
            let f = a[i * n + col] / a[col * n + col];
            a[i * n + col] = f;
            if f != 0.0 {
                for k in col + 1..n {
                    a[i * n + k] -= f * a[col * n + k];
                }
            }
        }
    }
    true
}

/// Solves `A x = b` from the factors of [`lu_factor`]; the solution replaces `b`.
fn lu_solve(lu: &[f64], piv: &[usize], b: &mut [f64], scratch: &mut Vec<f64>, n: usize) {
    scratch.clear();
    scratch.extend(piv.iter().map(|&p| b[p]));
    b.copy_from_slice(scratch);
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= lu[i * n + k] * b[k];
        }
        b[i] = s;
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= lu[i * n + k] * b[k];
        }
        b[i] = s / lu[i * n + i];
    }
}

/// Computes the local mass properties of every dynamic body that has none yet (Rapier does it at
/// the first step; the solver needs them before).
pub fn prepare_mass_properties(bodies: &mut RigidBodySet) {
    let handles: Vec<RigidBodyHandle> = bodies.iter().map(|(h, _)| h).collect();
    for h in handles {
        crate::rapier::ledger::ensure_mass_properties(bodies, None, h);
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
        let (mut piv, mut scratch) = (Vec::new(), Vec::new());
        assert!(lu_factor(&mut a, &mut piv, 2));
        lu_solve(&a, &piv, &mut b, &mut scratch, 2);
        assert!((b[0] - 0.8).abs() < 1e-15 && (b[1] - 1.4).abs() < 1e-15);
        // With a row swap: y = 2, x + y = 3 -> x = 1.
        let mut a = vec![0.0, 1.0, 1.0, 1.0];
        let mut b = vec![2.0, 3.0];
        assert!(lu_factor(&mut a, &mut piv, 2));
        lu_solve(&a, &piv, &mut b, &mut scratch, 2);
        assert!((b[0] - 1.0).abs() < 1e-15 && (b[1] - 2.0).abs() < 1e-15);
        let mut a = vec![1.0, 2.0, 2.0, 4.0];
        assert!(!lu_factor(&mut a, &mut piv, 2));
    }

    #[test]
    fn spinning_arm_needs_the_centripetal_force() {
        // Arm of 2 kg, COM 0.3 m from a fixed pivot, spinning at 5 rad/s about z, no gravity:
        // the pivot pulls with m w^2 r = 15 N towards itself; no angular acceleration.
        let mut bodies = RigidBodySet::new();
        let base = bodies.insert(RigidBodyBuilder::fixed());
        let arm = bodies.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(0.3, 0.0, 0.0))
                .linvel(Vector::new(0.0, 1.5, 0.0))
                .angvel(Vector::new(0.0, 0.0, 5.0))
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
        let mut s = ReactionSolver::default();
        let f = s.solve(&bodies, &[j], Vector::ZERO).unwrap()[0];
        assert!((f - Vector::new(-15.0, 0.0, 0.0)).length() < 1e-9, "{f:?}");
    }

    #[test]
    fn torque_driven_arm_by_hand() {
        // Torque 1 N m about z on the arm at rest: I_pivot = 0.03 + 2 * 0.09 = 0.21,
        // alpha = 1/0.21, the pivot supplies m alpha r = 2 * 0.3/0.21 N along +y.
        let mut bodies = RigidBodySet::new();
        let base = bodies.insert(RigidBodyBuilder::fixed());
        let arm = bodies.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(0.3, 0.0, 0.0))
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    2.0,
                    Vector::new(0.01, 0.02, 0.03),
                )),
        );
        prepare_mass_properties(&mut bodies);
        bodies[arm].add_torque(Vector::new(0.0, 0.0, 1.0), false);
        let j = IdealRevolute {
            body1: base,
            body2: arm,
            local_anchor1: Vector::ZERO,
            local_anchor2: Vector::new(-0.3, 0.0, 0.0),
            local_axis1: Vector::Z,
        };
        let mut s = ReactionSolver::default();
        let f = s.solve(&bodies, &[j], Vector::ZERO).unwrap()[0];
        let expected = 2.0 * 0.3 / 0.21;
        assert!(
            (f - Vector::new(0.0, expected, 0.0)).length() < 1e-9,
            "{f:?}"
        );
    }

    fn slider(
        bodies: &mut RigidBodySet,
        at: Vector,
        linvel: Vector,
        angvel: Vector,
    ) -> RigidBodyHandle {
        bodies.insert(
            RigidBodyBuilder::dynamic()
                .translation(at)
                .linvel(linvel)
                .angvel(angvel)
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    2.0,
                    Vector::new(0.01, 0.02, 0.03),
                )),
        )
    }

    #[test]
    fn slider_on_a_fixed_guide_carries_its_weight_not_its_drive() {
        // 2 kg on a guide along x under gravity -y, pushed by 3 N along x: the guide supplies
        // m g = 19.62 N upwards and nothing along the slide.
        let mut bodies = RigidBodySet::new();
        let base = bodies.insert(RigidBodyBuilder::fixed());
        let s = slider(
            &mut bodies,
            Vector::new(0.4, 0.1, 0.0),
            Vector::new(1.0, 0.0, 0.0),
            Vector::ZERO,
        );
        prepare_mass_properties(&mut bodies);
        bodies[s].add_force(Vector::new(3.0, 0.0, 0.0), false);
        let j = IdealPrismatic {
            body1: base,
            body2: s,
            local_anchor1: Vector::new(0.0, 0.1, 0.0),
            local_anchor2: Vector::ZERO,
            local_axis1: Vector::X,
        };
        let mut solver = ReactionSolver::default();
        let f = solver
            .solve_joints(&bodies, &[j.into()], Vector::new(0.0, -9.81, 0.0))
            .unwrap()[0];
        assert!((f - Vector::new(0.0, 19.62, 0.0)).length() < 1e-9, "{f:?}");
    }

    #[test]
    fn slider_on_a_spinning_guide_needs_the_coriolis_force() {
        // A guide along its x axis turning at w = 3 rad/s about z (kinematic, at the origin);
        // the 2 kg slider at r = 0.5 m moves out at v = 0.2 m/s and turns with it. Along the
        // guide it is free; across it the guide supplies the Coriolis force 2 m w v = 2.4 N
        // (+y), no angular acceleration being needed.
        let (w, r, v) = (3.0, 0.5, 0.2);
        let mut bodies = RigidBodySet::new();
        let guide = bodies
            .insert(RigidBodyBuilder::kinematic_velocity_based().angvel(Vector::new(0.0, 0.0, w)));
        let s = slider(
            &mut bodies,
            Vector::new(r, 0.0, 0.0),
            Vector::new(v, w * r, 0.0),
            Vector::new(0.0, 0.0, w),
        );
        prepare_mass_properties(&mut bodies);
        let j = IdealPrismatic {
            body1: guide,
            body2: s,
            local_anchor1: Vector::ZERO,
            local_anchor2: Vector::ZERO,
            local_axis1: Vector::X,
        };
        let mut solver = ReactionSolver::default();
        let f = solver
            .solve_joints(&bodies, &[j.into()], Vector::ZERO)
            .unwrap()[0];
        assert!(
            (f - Vector::new(0.0, 2.0 * 2.0 * w * v, 0.0)).length() < 1e-9,
            "{f:?}"
        );
    }

    #[test]
    fn welded_block_on_a_spinning_base() {
        // A 2 kg block welded 0.3 m from the axis of a base turning at 5 rad/s (kinematic):
        // the weld pulls with m w^2 r = 15 N towards the axis and holds its weight 19.62 N.
        let mut bodies = RigidBodySet::new();
        let base = bodies.insert(
            RigidBodyBuilder::kinematic_velocity_based().angvel(Vector::new(0.0, 0.0, 5.0)),
        );
        let b = slider(
            &mut bodies,
            Vector::new(0.3, 0.0, 0.0),
            Vector::new(0.0, 1.5, 0.0),
            Vector::new(0.0, 0.0, 5.0),
        );
        prepare_mass_properties(&mut bodies);
        let j = IdealFixed {
            body1: base,
            body2: b,
            local_anchor1: Vector::new(0.3, 0.0, 0.0),
            local_anchor2: Vector::ZERO,
        };
        let mut solver = ReactionSolver::default();
        let f = solver
            .solve_joints(&bodies, &[j.into()], Vector::new(0.0, 0.0, -9.81))
            .unwrap()[0];
        assert!(
            (f - Vector::new(-15.0, 0.0, 19.62)).length() < 1e-9,
            "{f:?}"
        );
    }

    #[test]
    fn ball_joint_pendulum_swinging_through_the_bottom() {
        // A 2 kg point-like bob 0.5 m below a ball joint, passing the bottom at 1 m/s: the joint
        // pulls up with m g + m v^2/L = 19.62 + 4 = 23.62 N.
        let mut bodies = RigidBodySet::new();
        let base = bodies.insert(RigidBodyBuilder::fixed());
        let bob = slider(
            &mut bodies,
            Vector::new(0.0, -0.5, 0.0),
            Vector::new(1.0, 0.0, 0.0),
            Vector::new(0.0, 0.0, 2.0),
        );
        prepare_mass_properties(&mut bodies);
        let j = IdealSpherical {
            body1: base,
            body2: bob,
            local_anchor1: Vector::ZERO,
            local_anchor2: Vector::new(0.0, 0.5, 0.0),
        };
        let mut solver = ReactionSolver::default();
        let f = solver
            .solve_joints(&bodies, &[j.into()], Vector::new(0.0, -9.81, 0.0))
            .unwrap()[0];
        // The bob's own spin (2 rad/s about z) is the pendulum's: no torque is needed at the ball.
        assert!((f - Vector::new(0.0, 23.62, 0.0)).length() < 1e-9, "{f:?}");
    }

    #[test]
    fn motor_holding_an_arm_level_supplies_its_moment() {
        // A 2 kg arm, centre of mass 0.3 m out along x from a pivot on a fixed base, at rest
        // under gravity -y, held by a velocity motor at zero speed: the pivot carries the weight
        // (19.62 N up), and the motor's moment m g r = 5.886 N m is in the extra row.
        let mut bodies = RigidBodySet::new();
        let base = bodies.insert(RigidBodyBuilder::fixed());
        let arm = slider(
            &mut bodies,
            Vector::new(0.3, 0.0, 0.0),
            Vector::ZERO,
            Vector::ZERO,
        );
        prepare_mass_properties(&mut bodies);
        let j = IdealRevolute {
            body1: base,
            body2: arm,
            local_anchor1: Vector::ZERO,
            local_anchor2: Vector::new(-0.3, 0.0, 0.0),
            local_axis1: Vector::Z,
        };
        let mut solver = ReactionSolver::default();
        let g = Vector::new(0.0, -9.81, 0.0);
        let f = solver
            .solve_joints(&bodies, &[IdealJoint::MotorRevolute(j)], g)
            .unwrap()[0];
        assert!((f - Vector::new(0.0, 19.62, 0.0)).length() < 1e-9, "{f:?}");
        let tau = solver.motor(0).unwrap();
        assert!((tau - 2.0 * 9.81 * 0.3).abs() < 1e-9, "{tau}");
        // Without the motor the arm falls: the pivot carries less than the weight,
        // m g (1 - m r^2 / I_pivot) with I_pivot = 0.03 + 2 * 0.09 = 0.21.
        let f = solver.solve(&bodies, &[j], g).unwrap()[0];
        let expected = 19.62 * (1.0 - 2.0 * 0.09 / 0.21);
        assert!((f.y - expected).abs() < 1e-9, "{f:?} against {expected}");
    }

    #[test]
    fn weld_on_an_accelerating_driven_base() {
        // A base turning up from rest with a prescribed 10 rad/s^2 about z; a 2 kg block welded
        // 0.3 m out along x: the weld pushes it along +y with m alpha r = 6 N.
        let mut bodies = RigidBodySet::new();
        let base = bodies.insert(RigidBodyBuilder::kinematic_position_based());
        let b = slider(
            &mut bodies,
            Vector::new(0.3, 0.0, 0.0),
            Vector::ZERO,
            Vector::ZERO,
        );
        prepare_mass_properties(&mut bodies);
        let j = IdealFixed {
            body1: base,
            body2: b,
            local_anchor1: Vector::new(0.3, 0.0, 0.0),
            local_anchor2: Vector::ZERO,
        };
        let mut solver = ReactionSolver::default();
        // Without the prescribed acceleration the base would be taken to move steadily.
        let f = solver
            .solve_joints(&bodies, &[j.into()], Vector::ZERO)
            .unwrap()[0];
        assert!(f.length() < 1e-12);
        solver.kinematic.push(KinematicState {
            body: base,
            linvel: Vector::ZERO,
            angvel: Vector::ZERO,
            linacc: Vector::ZERO,
            angacc: Vector::new(0.0, 0.0, 10.0),
        });
        let f = solver
            .solve_joints(&bodies, &[j.into()], Vector::ZERO)
            .unwrap()[0];
        assert!((f - Vector::new(0.0, 6.0, 0.0)).length() < 1e-9, "{f:?}");
    }

    /// The 2 kg arm of these tests on a fixed base: centre of mass `r` = 0.3 m out along its
    /// own x axis, turned by `angle` about z, spinning at `w` about z (consistent velocities).
    fn arm_at(angle: f64, w: f64) -> (RigidBodySet, IdealRevolute) {
        let mut bodies = RigidBodySet::new();
        let base = bodies.insert(RigidBodyBuilder::fixed());
        let rot = Rotation::from_rotation_z(angle);
        let com = rot * Vector::new(0.3, 0.0, 0.0);
        let arm = bodies.insert(
            RigidBodyBuilder::dynamic()
                .translation(com)
                .rotation(Vector::new(0.0, 0.0, angle))
                .linvel(Vector::new(0.0, 0.0, w).cross(com))
                .angvel(Vector::new(0.0, 0.0, w))
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
        (bodies, j)
    }

    #[test]
    fn soft_revolute_motor_by_hand() {
        // Level arm turning at 1 rad/s under gravity -y; a force-based motor k = 10 N m/rad,
        // c = 2 N m s/rad towards 0.5 rad at rest: torque 10 * 0.5 + 2 * (0 - 1) = 3 N m.
        // alpha = (3 - m g r)/I_pivot, I_pivot = 0.03 + 2 * 0.09 = 0.21.
        let (bodies, j) = arm_at(0.0, 1.0);
        let g = Vector::new(0.0, -9.81, 0.0);
        let m = SoftMotor::force_based(0.5, 0.0, 10.0, 2.0);
        let mut solver = ReactionSolver::default();
        let f = solver
            .solve_joints(&bodies, &[IdealJoint::SoftMotorRevolute(j, m)], g)
            .unwrap()[0];
        assert!((solver.motor(0).unwrap() - 3.0).abs() < 1e-12);
        let alpha = (3.0 - 2.0 * 9.81 * 0.3) / 0.21;
        let (a, al) = solver.acceleration(j.body2).unwrap();
        let expected_a = Vector::new(-0.3, alpha * 0.3, 0.0);
        assert!(
            (al - Vector::new(0.0, 0.0, alpha)).length() < 1e-9,
            "{al:?}"
        );
        assert!((a - expected_a).length() < 1e-9, "{a:?}");
        // The pivot supplies m a - m g.
        assert!((f - (2.0 * expected_a - 2.0 * g)).length() < 1e-9, "{f:?}");
        // Acceleration-based: the same law times the row's inertia, the arm's own 0.03 about z
        // (Rapier's motor row is not coupled to the joint's point constraints).
        let m = SoftMotor {
            model: MotorModel::AccelerationBased,
            ..m
        };
        solver.solve_joints(&bodies, &[IdealJoint::SoftMotorRevolute(j, m)], g);
        assert!((solver.motor(0).unwrap() - 0.03 * 3.0).abs() < 1e-12);
        // A force limit clamps it.
        let m = SoftMotor {
            max_force: 1.0,
            ..m
        };
        solver.solve_joints(&bodies, &[IdealJoint::SoftMotorRevolute(j, m)], g);
        assert!((solver.motor(0).unwrap() - 0.03 * 3.0).abs() < 1e-12);
        let m = SoftMotor {
            max_force: 0.05,
            ..m
        };
        solver.solve_joints(&bodies, &[IdealJoint::SoftMotorRevolute(j, m)], g);
        assert_eq!(solver.motor(0), Some(0.05));
    }

    #[test]
    fn soft_motor_angle_is_rapiers() {
        // At rest turned by 0.2 rad towards 0.5 rad: 10 * 0.3 = 3 N m.
        let (bodies, j) = arm_at(0.2, 0.0);
        let mut solver = ReactionSolver::default();
        let m = SoftMotor::force_based(0.5, 0.0, 10.0, 0.0);
        solver.solve_joints(
            &bodies,
            &[IdealJoint::SoftMotorRevolute(j, m)],
            Vector::ZERO,
        );
        assert!((solver.motor(0).unwrap() - 3.0).abs() < 1e-12);
        // At -3 rad towards +3 rad the short way is through pi: the error is
        // -6 + 2 pi = 0.283 rad, the torque -2.83 N m (a quaternion past pi is read as such).
        let (bodies, j) = arm_at(-3.0, 0.0);
        let m = SoftMotor::force_based(3.0, 0.0, 10.0, 0.0);
        solver.solve_joints(
            &bodies,
            &[IdealJoint::SoftMotorRevolute(j, m)],
            Vector::ZERO,
        );
        let expected = -10.0 * (-6.0 + std::f64::consts::TAU);
        assert!((solver.motor(0).unwrap() - expected).abs() < 1e-9);
        let (bodies, j) = arm_at(3.5, 0.0);
        let m = SoftMotor::force_based(0.0, 0.0, 10.0, 0.0);
        solver.solve_joints(
            &bodies,
            &[IdealJoint::SoftMotorRevolute(j, m)],
            Vector::ZERO,
        );
        let expected = -10.0 * (3.5 - std::f64::consts::TAU);
        assert!((solver.motor(0).unwrap() - expected).abs() < 1e-9);
    }

    #[test]
    fn soft_and_held_prismatic_motors_by_hand() {
        // 2 kg slider 0.1 m along a fixed guide on x, moving at 0.5 m/s, gravity -y; a
        // force-based motor k = 100 N/m, c = 4 N s/m towards 0.3 m: 100 * 0.2 + 4 * (0 - 0.5)
        // = 18 N along x, a = 9 m/s^2; the guide carries the weight.
        let mut bodies = RigidBodySet::new();
        let base = bodies.insert(RigidBodyBuilder::fixed());
        let s = slider(
            &mut bodies,
            Vector::new(0.1, 0.0, 0.0),
            Vector::new(0.5, 0.0, 0.0),
            Vector::ZERO,
        );
        prepare_mass_properties(&mut bodies);
        let j = IdealPrismatic {
            body1: base,
            body2: s,
            local_anchor1: Vector::ZERO,
            local_anchor2: Vector::ZERO,
            local_axis1: Vector::X,
        };
        let g = Vector::new(0.0, -9.81, 0.0);
        let m = SoftMotor::force_based(0.3, 0.0, 100.0, 4.0);
        let mut solver = ReactionSolver::default();
        let f = solver
            .solve_joints(&bodies, &[IdealJoint::SoftMotorPrismatic(j, m)], g)
            .unwrap()[0];
        assert!((solver.motor(0).unwrap() - 18.0).abs() < 1e-12);
        assert!((f - Vector::new(0.0, 19.62, 0.0)).length() < 1e-9, "{f:?}");
        let (a, al) = solver.acceleration(s).unwrap();
        assert!((a - Vector::new(9.0, 0.0, 0.0)).length() < 1e-9 && al.length() < 1e-9);
        // Acceleration-based: times the row's mass, the slider's 2 kg (its point is its centre
        // of mass; the guide is fixed).
        let m = SoftMotor {
            model: MotorModel::AccelerationBased,
            ..m
        };
        solver.solve_joints(&bodies, &[IdealJoint::SoftMotorPrismatic(j, m)], g);
        assert!((solver.motor(0).unwrap() - 36.0).abs() < 1e-12);
        // Held speed against a 3 N push: the motor pulls back 3 N, nothing accelerates.
        bodies[s].add_force(Vector::new(3.0, 0.0, 0.0), false);
        let f = solver
            .solve_joints(&bodies, &[IdealJoint::MotorPrismatic(j)], g)
            .unwrap()[0];
        assert!((solver.motor(0).unwrap() + 3.0).abs() < 1e-12);
        assert!((f - Vector::new(0.0, 19.62, 0.0)).length() < 1e-9, "{f:?}");
        assert!(solver.acceleration(s).unwrap().0.length() < 1e-12);
    }

    #[test]
    fn velocities_are_projected_onto_the_joints() {
        // The arm's stored velocities disagree: spinning at 5 rad/s, its centre of mass at rest.
        // The least change in the mass metric that turns it about the pivot: minimise
        // m (0.3 w)^2 + I (w - 5)^2 -> w = 5 I/(m 0.09 + I) = 5 * 0.03/0.21 = 5/7 rad/s.
        let (mut bodies, j) = arm_at(0.0, 5.0);
        bodies[j.body2].set_linvel(Vector::ZERO, false);
        let mut solver = ReactionSolver::default();
        let f = solver.solve(&bodies, &[j], Vector::ZERO).unwrap()[0];
        let w = 5.0 / 7.0;
        let (v, wv) = solver.velocity(j.body2).unwrap();
        assert!((wv - Vector::new(0.0, 0.0, w)).length() < 1e-12, "{wv:?}");
        assert!(
            (v - Vector::new(0.0, 0.3 * w, 0.0)).length() < 1e-12,
            "{v:?}"
        );
        // The centripetal pull at the projected speed.
        assert!((f - Vector::new(-2.0 * w * w * 0.3, 0.0, 0.0)).length() < 1e-9);
    }

    #[test]
    fn stored_velocities_are_advanced_by_the_lag() {
        // Level arm, stored 2 rad/s, 0.01 s before the state: under gravity alone the angular
        // acceleration at level is -m g r/I_pivot whatever the speed, so the state's speed is
        // 2 + 0.01 alpha, and the pivot pulls with its centripetal force.
        let (bodies, j) = arm_at(0.0, 2.0);
        let g = Vector::new(0.0, -9.81, 0.0);
        let mut solver = ReactionSolver {
            velocity_lag: 0.01,
            ..ReactionSolver::default()
        };
        let f = solver.solve(&bodies, &[j], g).unwrap()[0];
        let alpha = -2.0 * 9.81 * 0.3 / 0.21;
        let w = 2.0 + 0.01 * alpha;
        let (_, wv) = solver.velocity(j.body2).unwrap();
        assert!((wv.z - w).abs() < 1e-12, "{wv:?} against {w}");
        assert!((f.x + 2.0 * w * w * 0.3).abs() < 1e-9, "{f:?}");
        // A tracked free body falls.
        let mut bodies = bodies;
        let free = slider(&mut bodies, Vector::Y, Vector::ZERO, Vector::ZERO);
        prepare_mass_properties(&mut bodies);
        solver.track = vec![free];
        solver.solve(&bodies, &[j], g).unwrap();
        assert!((solver.acceleration(free).unwrap().0 - g).length() < 1e-12);
        assert!((solver.velocity(free).unwrap().0 - 0.01 * g).length() < 1e-12);
    }
}
