//! The large-step clearance joint: radial play solved as a constraint inside Rapier's own solver,
//! for the steps games and robot controllers use (1/60 s, 1e-3 s) with any
//! `num_solver_iterations`.
//!
//! The [compliant joint](crate::rapier::joint) evaluates a stiff contact law outside Rapier's solver and is
//! stable only at steps of about 1e-5..1e-4 s for steel. This model replaces the law by the
//! *momentum-exchange* treatment of clearance joints of the multibody literature (a unilateral
//! constraint plus Newton's impact law):
//!
//! - **Play, as a Rapier `GenericJoint`.** The axial translation and the two tilts are locked; the
//!   two radial axes are coupled with a limit `[0, c]` on their norm (Rapier's
//!   `limit_linear_coupled`, the way `RopeJoint` works): the journal centre stays within the
//!   clearance circle `|e| <= c`, solved with every other constraint of the world.
//! - **Restitution.** Rapier's limits are inelastic. At a bounce (a contact that begins, with an
//!   approach speed above [`LargeStepJointBuilder::min_impact_speed`]) the hook gives the journal the
//!   normal separation speed `e v_approach` by an impulse pair after the step (Newton's law,
//!   `v_n+ = -e v_n-`). `v_approach` is the normal relative velocity the bodies had before the
//!   step, along the wall's normal after it: never more than the speed the limit absorbed, so a
//!   bounce returns at most `e^2` of the normal kinetic energy. The coefficient is a number, or a
//!   compliant law's own restitution for that impact ([`Restitution::Law`]).
//! - **Coulomb friction on the bearing surface** as the friction moment `mu N R_j` of a journal
//!   bearing: a velocity motor on the hinge rotation (target rate 0) whose largest torque is
//!   `mu N R_j`, `N` the previous step's normal force. It sticks below that torque and slides at
//!   it, inside Rapier's solver, so it is stable at any step. The friction force's push on the
//!   journal centre (it shifts the contact along the wall by at most `atan(mu)`) is left out.
//! - **Resolution, set from the clearance.** Rapier 0.36's coupled limit has no slop term
//!   (`normalized_allowed_linear_error` only feeds continuous collision detection). What a small
//!   clearance does need is a fine enough substep: one whose rotation drift and sliding along the
//!   curved wall each stay within 5 % of `c`, and on which the journal's rocking on the wall
//!   (`sqrt(N/(m_t c))`) stays stable (`omega_r h <= 1`). Before each step the joint
//!   asks for `base 2^k` substeps (`base = num_solver_iterations`) through the
//!   `additional_solver_iterations` of its dynamic bodies, only as many as the rotation drift and
//!   the journal's rocking on the wall need, at most
//!   [`max_substeps`](LargeStepJointBuilder::max_substeps). At 1 kHz the default four are
//!   usually enough; a small clearance under a heavy, fast load at 1/60 s asks for more. The
//!   report says how many were used and whether the cap left the step under-resolved.
//! - **Readout, every step**: the normal force (the limit's impulse over the substep), the
//!   friction torque, the eccentricity (the journal orbit), the contact flag, onsets and bounces
//!   with their approach and rebound speeds.
//! - **Counts**: [onsets](LargeStepJoint::onsets) (every contact that began) and
//!   [bounces](LargeStepJoint::bounces) (onsets faster than `min_impact_speed`, the ones
//!   Newton's law gives a rebound); see the [definitions](crate::rapier::observers::metrics#onsets-impacts-and-chatter).
//!   The model resolves the journal's position to a few percent of `c`, too coarse for the
//!   compliant model's `min_separation`: its bounces stand for its impacts in the metrics.
//!
//! ```
//! use clearance_joint::rapier::large_step::{LargeStepJointBuilder, LargeStepJointSet};
//! use clearance_joint::model::laws::BearingGeometry;
//! use rapier3d_f64::prelude::*;
//!
//! let mut world = PhysicsWorld::new(); // Rapier's defaults: 1/60 s, 4 solver iterations
//! world.gravity = Vector::new(0.0, -9.81, 0.0);
//! let base = world.bodies.insert(RigidBodyBuilder::fixed());
//! let arm = world.bodies.insert(
//!     RigidBodyBuilder::dynamic()
//!         .translation(Vector::new(0.0, -0.3, 0.0))
//!         .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02)))
//!         .can_sleep(false),
//! );
//! // 0.5 mm of radial play in a 20 mm bearing, restitution 0.5, friction 0.2.
//! let geometry = BearingGeometry::from_clearance(0.010, 0.5e-3, 0.016)?;
//! let joint = LargeStepJointBuilder::new(Vector::Z, geometry)
//!     .local_anchor2(Vector::new(0.0, 0.3, 0.0))
//!     .restitution(0.5)
//!     .friction(0.2)
//!     .build()?;
//! let mut play = LargeStepJointSet::new();
//! let hinge = play.insert(base, arm, joint, &world.bodies, &mut world.impulse_joints)?;
//! for _ in 0..120 {
//!     play.before_step(&mut world.bodies, &mut world.impulse_joints, &world.integration_parameters);
//!     world.step();
//!     play.after_step(&mut world.bodies, &world.impulse_joints);
//! }
//! let report = play.get(hinge).unwrap().report();
//! // The arm hangs on the bearing wall: the journal sits at the clearance and carries the weight.
//! assert!(report.contact);
//! assert!((report.eccentricity.length() - 0.5e-3).abs() < 0.05 * 0.5e-3);
//! assert!((report.normal_force - 2.0 * 9.81).abs() < 1e-6 * 19.62, "{}", report.normal_force);
//! # Ok::<(), clearance_joint::Error>(())
//! ```

mod builder;
pub(crate) mod resolution;
mod set;
pub use set::{LargeStepJointHandle, LargeStepJointSet};

use crate::error::{Error, Result, non_negative, positive, unit_vector};
use crate::model::laws::{BearingGeometry, NormalModel, impact_restitution};
use crate::rapier::pipeline::ledger::{
    Wrench, ensure_mass_properties, inverse_mass_along, world_center_of_mass,
};
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{
    GenericJoint, GenericJointBuilder, ImpulseJointHandle, ImpulseJointSet, IntegrationParameters,
    JointAxesMask, JointAxis, RigidBody, RigidBodyHandle, RigidBodySet, RigidBodyType,
};
use resolution::{quantized_substeps, rocking_frequency, substeps_needed};
use std::collections::BTreeMap;

/// Default of [`LargeStepJointBuilder::max_substeps`].
pub(crate) const DEFAULT_MAX_SUBSTEPS: usize = 64;
/// A journal within this fraction of `c` from the wall counts as touching it.
const CONTACT_TOLERANCE: f64 = 1e-3;
/// Damping of the friction motor: large enough that the motor is a hard velocity constraint
/// (its softness `1/(h d)` vanishes) bounded only by its largest torque.
const FRICTION_DAMPING: f64 = 1e12;
/// Steps the substep count is held before it may fall (it rises at once).
const SUBSTEP_HOLD_STEPS: u32 = 30;

/// The coefficient of restitution of the journal's impacts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Restitution {
    /// A fixed coefficient in [0, 1].
    Coefficient(f64),
    /// The restitution this compliant law gives each impact, at its approach speed and the
    /// effective mass of the two bodies along the normal
    /// ([`impact_restitution`]): the large-step model bounces as
    /// the compliant model would.
    Law(NormalModel),
}

/// Builds a [`LargeStepJoint`] with chained setters, like Rapier's `RevoluteJointBuilder`.
/// Body 1 carries the bearing (hole), body 2 the journal (pin).
///
/// ```
/// use clearance_joint::rapier::large_step::LargeStepJointBuilder;
/// use clearance_joint::model::laws::BearingGeometry;
/// use rapier3d_f64::math::Vector;
/// let geometry = BearingGeometry::from_clearance(0.010, 0.5e-3, 0.016).unwrap();
/// let joint = LargeStepJointBuilder::new(Vector::Z, geometry)
///     .local_anchor1(Vector::new(0.4, 0.0, 0.4))
///     .restitution(0.6)
///     .friction(0.25)
///     .name("door hinge")
///     .build()
///     .unwrap();
/// assert_eq!(joint.friction(), 0.25);
/// assert!((joint.clearance() - 0.5e-3).abs() < 1e-15);
/// ```
#[derive(Clone, Debug)]
pub struct LargeStepJointBuilder {
    joint: LargeStepJoint,
}

/// What the joint did over the last step (all zero before the first).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LargeStepReport {
    /// Eccentricity `e` of the journal centre from the bearing centre, normal to the axis (world),
    /// m: the journal orbit.
    pub eccentricity: Vector,
    /// `|e|/c`: 1 on the wall up to the step's position error. The substeps are chosen, from
    /// the state before the step, to hold the last substep's rotation drift and the sliding
    /// error along the curved wall to 5 % of
    /// `c` each: a step not flagged [`under_resolved`](Self::under_resolved) ends at most 10 %
    /// outside the circle (measured: 1.053 on a swinging arm at 1/60 s, 1.085 on the cobbled
    /// sign of `examples/game_rate.rs` capped at four substeps; a step that ends further out is
    /// flagged), and the drift can as well leave a journal that bears on the wall inside it (see
    /// [`contact`](Self::contact)).
    pub eccentricity_ratio: f64,
    /// Whether the journal bears on the bearing at the end of the step: the limit carried a force
    /// in the last substep ([`normal_force`](Self::normal_force) > 0), or `|e|` is within 0.1 % of
    /// `c`. A journal that bears on the wall can read `|e|/c` below 1 by the step's position error
    /// ([`eccentricity_ratio`](Self::eccentricity_ratio)): 0.984 on the arm of
    /// `examples/robot_backlash.rs` at 1 kHz.
    pub contact: bool,
    /// Whether a contact began in this step: an
    /// [onset](crate::rapier::observers::metrics#onsets-impacts-and-chatter).
    pub onset: bool,
    /// Whether that onset was a [bounce](crate::rapier::observers::metrics#onsets-impacts-and-chatter): its
    /// approach speed exceeded the joint's `min_impact_speed`, so Newton's law gave it a rebound.
    pub bounce: bool,
    /// Normal approach speed of this step's bounce, m/s (0 without one).
    pub approach_speed: f64,
    /// Normal separation speed the bounce was given, `e v_approach`, m/s.
    pub rebound_speed: f64,
    /// The coefficient of restitution used at this bounce.
    pub restitution: f64,
    /// The bounce's normal impulse by Newton's law, `m_n (1 + e) v_approach`, N s (`m_n` the
    /// effective mass of the two bodies along the normal): an impact in a large step is an
    /// impulse, not a force history.
    pub impact_impulse: f64,
    /// Normal contact force, N: the limit's impulse in the last substep over the substep. The
    /// sustained load of a journal resting on or following the wall (exact at rest: `m g` for a
    /// hanging arm); an impact inside the step shows in [`impact_impulse`](Self::impact_impulse).
    pub normal_force: f64,
    /// The normal force on the journal body, `-N e/|e|` (world), N.
    pub force_on_journal: Vector,
    /// Friction moment on the journal body about the hinge axis, N m (signed, about body 1's axis).
    pub friction_torque: f64,
    /// The friction motor's largest moment in this step, `mu N R_j` from the previous step's `N`.
    pub friction_limit: f64,
    /// Substeps Rapier took for the joint's bodies in this step.
    pub substeps: usize,
    /// Substeps the step needed (unrounded; the resolution criteria of [`large_step`](crate::rapier::large_step)).
    pub substeps_needed: f64,
    /// Whether the step was not resolved: it needed more substeps than
    /// [`max_substeps`](LargeStepJointBuilder::max_substeps) allowed (judged from the state
    /// before the step), or it ended more than `2 DRIFT_FRACTION` (10 %) of `c` outside the
    /// circle, which a step whose motion changed within it can (a contact onset). Its
    /// eccentricity and force may then be off by more than the resolution promises.
    pub under_resolved: bool,
    /// Rocking frequency of the journal on the wall used for the substep choice, rad/s.
    pub rocking_frequency: f64,
}

/// Velocities before a step, and how the step was cut.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct PreStep {
    /// Velocity of the journal centre relative to the bearing's material point under it.
    relative_velocity: Vector,
    dt: f64,
    substeps: usize,
    friction_limit: f64,
    substeps_needed: f64,
    rocking_frequency: f64,
}

/// State carried between steps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct JointState {
    prepared: bool,
    in_contact: bool,
    /// Normal force of the last step and whether that step began a contact.
    normal_force: f64,
    last_onset: bool,
    /// Substeps asked for, and for how many steps fewer would have done.
    substeps: usize,
    low_steps: u32,
    onsets: u64,
    bounces: u64,
    pre: Option<PreStep>,
    /// In-plane relative velocity before the last step.
    last_relative_velocity: Option<Vector>,
    /// The `additional_solver_iterations` of body 1 and body 2 before the set touched them.
    floors: [usize; 2],
}

/// A revolute hinge with radial play between two Rapier rigid bodies, solved as a constraint.
#[derive(Clone, Debug)]
pub struct LargeStepJoint {
    name: String,
    local_axis1: Vector,
    local_axis2: Vector,
    local_anchor1: Vector,
    local_anchor2: Vector,
    geometry: BearingGeometry,
    restitution: Restitution,
    friction: f64,
    min_impact_speed: f64,
    max_substeps: usize,
    body1: RigidBodyHandle,
    body2: RigidBodyHandle,
    handle: Option<ImpulseJointHandle>,
    state: JointState,
    report: LargeStepReport,
}

impl LargeStepJoint {
    /// The joint's name.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// Bearing body.
    pub fn body1(&self) -> RigidBodyHandle {
        self.body1
    }
    /// Journal body.
    pub fn body2(&self) -> RigidBodyHandle {
        self.body2
    }
    /// Radial geometry.
    pub fn geometry(&self) -> &BearingGeometry {
        &self.geometry
    }
    /// Radial clearance `c`, m.
    pub fn clearance(&self) -> f64 {
        self.geometry.clearance()
    }
    /// Restitution of bounces.
    pub fn restitution(&self) -> &Restitution {
        &self.restitution
    }
    /// Coulomb friction coefficient of the bearing surface.
    pub fn friction(&self) -> f64 {
        self.friction
    }
    /// Approach speed below which an onset does not bounce, m/s.
    pub fn min_impact_speed(&self) -> f64 {
        self.min_impact_speed
    }
    /// Most substeps per step the joint asks for.
    pub fn max_substeps(&self) -> usize {
        self.max_substeps
    }
    /// Hinge axis in body 1's frame (unit).
    pub fn local_axis1(&self) -> Vector {
        self.local_axis1
    }
    /// Hinge axis in body 2's frame (unit).
    pub fn local_axis2(&self) -> Vector {
        self.local_axis2
    }
    /// Bearing centre in body 1's frame.
    pub fn local_anchor1(&self) -> Vector {
        self.local_anchor1
    }
    /// Journal centre in body 2's frame.
    pub fn local_anchor2(&self) -> Vector {
        self.local_anchor2
    }
    /// The Rapier joint carrying the constraint, once inserted.
    pub fn rapier_handle(&self) -> Option<ImpulseJointHandle> {
        self.handle
    }
    /// What the joint did over the last step.
    pub fn report(&self) -> &LargeStepReport {
        &self.report
    }
    /// [Onsets](crate::rapier::observers::metrics#onsets-impacts-and-chatter) so far: every contact that
    /// began.
    pub fn onsets(&self) -> u64 {
        self.state.onsets
    }
    /// [Bounces](crate::rapier::observers::metrics#onsets-impacts-and-chatter) so far: onsets whose
    /// approach speed exceeded `min_impact_speed` (they bounced, or would have with a non-zero
    /// restitution).
    pub fn bounces(&self) -> u64 {
        self.state.bounces
    }

    /// The Rapier joint of this clearance: axial translation and both tilts locked, the two
    /// radial axes coupled with the limit `[0, c]` on their norm, and (with friction) a velocity
    /// motor on the rotation whose largest torque the hook sets every step. Contacts between the
    /// two bodies are disabled, as for Rapier's own revolute joints in this crate.
    pub(crate) fn rapier_joint(&self) -> GenericJoint {
        let mut b = GenericJointBuilder::new(
            JointAxesMask::LIN_X | JointAxesMask::ANG_Y | JointAxesMask::ANG_Z,
        )
        .coupled_axes(JointAxesMask::LIN_Y | JointAxesMask::LIN_Z)
        .limits(JointAxis::LinY, [0.0, self.clearance()])
        .local_axis1(self.local_axis1)
        .local_axis2(self.local_axis2)
        .local_anchor1(self.local_anchor1)
        .local_anchor2(self.local_anchor2)
        .contacts_enabled(false);
        if self.friction > 0.0 {
            b = b
                .motor_velocity(JointAxis::AngX, 0.0, FRICTION_DAMPING)
                .motor_max_force(JointAxis::AngX, 0.0);
        }
        b.build()
    }

    /// World geometry now: journal centre, hinge axis, eccentricity.
    fn geometry_now(&self, rb1: &RigidBody, rb2: &RigidBody) -> (Vector, Vector, Vector) {
        let axis = *rb1.rotation() * self.local_axis1;
        let p1 = *rb1.position() * self.local_anchor1;
        let p2 = *rb2.position() * self.local_anchor2;
        let d = p2 - p1;
        (p2, axis, d - d.dot(axis) * axis)
    }

    /// Velocity of the journal centre relative to the material point of the bearing body under
    /// it, world. Before a step (`dt` given), a position-based kinematic body moves by the pose
    /// its user set for that step, not by its last velocity.
    fn relative_velocity(&self, rb1: &RigidBody, rb2: &RigidBody, dt: Option<f64>) -> Vector {
        let p2 = *rb2.position() * self.local_anchor2;
        let at = |rb: &RigidBody| match dt {
            Some(dt) if dt > 0.0 && rb.body_type() == RigidBodyType::KinematicPositionBased => {
                let local = rb.position().inverse() * p2;
                (*rb.next_position() * local - p2) / dt
            }
            _ => rb.linvel() + rb.angvel().cross(p2 - world_center_of_mass(rb)),
        };
        at(rb2) - at(rb1)
    }

    /// The substeps this joint needs for the coming step of `dt`, the rocking frequency used, and
    /// the relative velocity before the step.
    fn needs(&self, rb1: &RigidBody, rb2: &RigidBody, dt: f64) -> (f64, f64, Vector) {
        let (p2, axis, e) = self.geometry_now(rb1, rb2);
        let in_plane = |v: Vector| v - v.dot(axis) * axis;
        // Rotation drift of the journal centre relative to the bearing point under it.
        let centripetal = |rb: &RigidBody| {
            let w = rb.angvel();
            w.cross(w.cross(p2 - world_center_of_mass(rb)))
        };
        let drift = in_plane(centripetal(rb2) - centripetal(rb1)).length();
        // Rocking under the load of the last step (not an impact's spike).
        let load = if self.state.last_onset {
            0.0
        } else {
            self.state.normal_force
        };
        let normal = if e.length() > 0.0 {
            e.normalize()
        } else {
            axis.any_orthonormal_vector()
        };
        let tangent = axis.cross(normal);
        // Sliding along the wall: in contact the tangential part of the relative velocity; in
        // free flight all of it (where the journal will strike is not known), plus the change
        // the last step saw (gravity, driven bodies and impacts change it within the step).
        let relative_velocity = self.relative_velocity(rb1, rb2, Some(dt));
        let v = in_plane(relative_velocity);
        let change = self
            .state
            .last_relative_velocity
            .map_or(0.0, |last| (v - last).length());
        let sliding = if self.state.in_contact {
            (v - v.dot(normal) * normal).length()
        } else {
            v.length()
        } + change;
        let w = inverse_mass_along(rb1, p2, tangent) + inverse_mass_along(rb2, p2, tangent);
        let rocking = if w > 0.0 {
            rocking_frequency(load, 1.0 / w, self.clearance())
        } else {
            0.0
        };
        (
            substeps_needed(dt, rocking, drift, sliding, self.clearance()),
            rocking,
            relative_velocity,
        )
    }

    /// Finishes the step just taken: readout, contact bookkeeping, and the impact's bounce.
    fn finish(&mut self, bodies: &mut RigidBodySet, impulse_joints: &ImpulseJointSet) {
        let Some(pre) = self.state.pre.take() else {
            return;
        };
        let Some(ij) = self.handle.and_then(|h| impulse_joints.get(h)) else {
            return;
        };
        let (Some(rb1), Some(rb2)) = (bodies.get(self.body1), bodies.get(self.body2)) else {
            return;
        };
        let h = pre.dt / pre.substeps.max(1) as f64;
        let inv_h = if h > 0.0 { 1.0 / h } else { 0.0 };
        let lambda = ij.data.limits[JointAxis::LinY as usize].impulse.max(0.0);
        let normal_force = lambda * inv_h;
        let friction_torque = if self.friction > 0.0 {
            // The motor's impulse acts on body 1 with a + sign (Rapier's convention): the moment
            // on the journal is its negative.
            -ij.data.motors[JointAxis::AngX as usize].impulse * inv_h
        } else {
            0.0
        };
        let (p2, axis, e) = self.geometry_now(rb1, rb2);
        let c = self.clearance();
        let ecc = e.length();
        let normal = if ecc > 0.0 {
            e / ecc
        } else {
            axis.any_orthonormal_vector()
        };
        let contact = lambda > 0.0 || ecc >= c * (1.0 - CONTACT_TOLERANCE);
        let onset = contact && !self.state.in_contact;
        let mut report = LargeStepReport {
            eccentricity: e,
            eccentricity_ratio: ecc / c,
            contact,
            onset,
            normal_force,
            force_on_journal: -normal_force * normal,
            friction_torque,
            friction_limit: pre.friction_limit,
            substeps: pre.substeps,
            substeps_needed: pre.substeps_needed,
            // Needed more than it got, as judged before the step, or ended outside what the
            // substeps promise (a step can change within it, e.g. at a contact onset).
            under_resolved: pre.substeps_needed > pre.substeps as f64
                || ecc > c * (1.0 + 2.0 * resolution::DRIFT_FRACTION),
            rocking_frequency: pre.rocking_frequency,
            ..LargeStepReport::default()
        };
        if onset {
            self.state.onsets += 1;
            // Before the step, with that step's geometry (the lever arms turn during the step), along
            // the wall's normal after it.
            let approach = pre.relative_velocity.dot(normal);
            if approach > self.min_impact_speed {
                let w = inverse_mass_along(rb1, p2, normal) + inverse_mass_along(rb2, p2, normal);
                let m_n = if w > 0.0 { 1.0 / w } else { 0.0 };
                let e_coef = self.restitution.coefficient(m_n, approach).clamp(0.0, 1.0);
                let now = self.relative_velocity(rb1, rb2, None).dot(normal);
                let target = -e_coef * approach;
                if now > target && m_n > 0.0 {
                    // Newton's impact law: the normal separation speed e v_approach.
                    let p = m_n * (now - target);
                    if let Some(rb) = bodies.get_mut(self.body2) {
                        rb.apply_impulse_at_point(-p * normal, p2, true);
                    }
                    if let Some(rb) = bodies.get_mut(self.body1) {
                        rb.apply_impulse_at_point(p * normal, p2, true);
                    }
                }
                report.bounce = true;
                report.approach_speed = approach;
                report.rebound_speed = e_coef * approach;
                report.restitution = e_coef;
                report.impact_impulse = m_n * (1.0 + e_coef) * approach;
                self.state.bounces += 1;
            }
        }
        self.state.in_contact = contact;
        self.state.normal_force = normal_force;
        self.state.last_onset = onset;
        self.report = report;
    }
}
