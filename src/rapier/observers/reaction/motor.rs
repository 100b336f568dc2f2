//! Joint motors: the soft motor's law at a state, and the motors' torques and forces in the solve.

use super::body::Entry;
use super::joints::JointModel;
use super::{IdealJoint, ReactionSolver};
use rapier3d_f64::math::{Rotation, Vector};
use rapier3d_f64::prelude::{JointMotor, MotorModel};

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
    /// The applied wrenches at the state's velocities: the bodies' own, then the soft motors'
    /// (recorded in `self.motors`, as are the held motors' placeholders).
    pub(super) fn apply_motors(&mut self, joints: &[IdealJoint], pairs: &[(usize, usize)]) {
        for e in &mut self.entries {
            (e.f, e.t) = e.applied();
        }
        self.motors.clear();
        self.motor_rates.clear();
        for (j, &(i1, i2)) in joints.iter().map(|j| &j.0).zip(pairs) {
            let (e1, e2) = (self.entries[i1], self.entries[i2]);
            self.motor_rates.push(match j {
                JointModel::MotorRevolute(j) | JointModel::SoftMotorRevolute(j, _) => {
                    (e1.rot * j.local_axis1).normalize().dot(e2.w - e1.w)
                }
                JointModel::MotorPrismatic(j) | JointModel::SoftMotorPrismatic(j, _) => {
                    let axis = (e1.rot * j.local_axis1).normalize();
                    let p2 = e2.pose * j.local_anchor2;
                    axis.dot((e2.v + e2.w.cross(p2 - e2.com)) - (e1.v + e1.w.cross(p2 - e1.com)))
                }
                _ => 0.0,
            });
            let motor = match j {
                JointModel::SoftMotorRevolute(j, m) => {
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
                JointModel::SoftMotorPrismatic(j, m) => {
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
                JointModel::MotorRevolute(_) | JointModel::MotorPrismatic(_) => Some(0.0),
                _ => None,
            };
            self.motors.push(motor);
        }
    }
}

fn inv_or_zero(x: f64) -> f64 {
    if x > 0.0 { 1.0 / x } else { 0.0 }
}
