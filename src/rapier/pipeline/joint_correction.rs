//! Position correction of Rapier's joints that stays stable when the step changes.
//!
//! Rapier corrects a joint's drift (the small error its velocity-level solve leaves in the
//! locked positions) inside the next step, with the bias velocity `error / (dt + tau0)`
//! (`tau0 = 2 zeta / omega` from the joint's softness; with Rapier's default, 1e6 Hz and
//! `zeta = 1`, `tau0` = 0.32 us, so the correction is the whole error in one step). Under
//! adaptive steps the error made by a long step is then corrected in a short one: when the step
//! drops from 1e-4 s to 2e-6 s near a contact, the bias velocity is 50 times the velocity that
//! made the error. With one solver iteration Rapier's unbiased pass does not take all of it back;
//! on slender bodies (an out-of-plane moment of inertia hundreds of times below the in-plane one,
//! as a bar or a rod has) the tilt about the locked axes then grows by a factor at each change of
//! the step, and the run diverges (measured: the double pendulum of the benchmark set, a bar of
//! 16 mm square section, reaches 200 m/s at t = 0.15 s; the deployable array at 0.089 s). With a
//! constant step, or no position correction, it does not grow.
//!
//! The remedy: correct the error at the rate it was made. [`JointCorrection`] keeps the span `S`,
//! the longest recent step (it follows a longer step at once and decays by [`SPAN_DECAY`] per
//! accepted step), and gives each joint the softness with `tau = S - dt + tau0`, so the bias
//! velocity is `error / (S + tau0)`: a drop of the step no longer multiplies it. At a constant
//! step `S = dt` and the correction is Rapier's. The damping ratio is [`DAMPING_RATIO`], large,
//! so that the constraint's compliance (Rapier's CFM, about `(tau/dt) / (4 zeta^2)`) stays below
//! 1e-5 for step ratios up to 1e3: the locked velocities are still enforced rigidly; only the
//! drift correction is spread out.
//!
//! Only joints whose softness is Rapier's default are touched (a softness you chose is yours),
//! and each joint gets its softness back after the step: between steps the world is as you built
//! it.

use rapier3d_f64::prelude::{ImpulseJointHandle, ImpulseJointSet, SpringCoefficients};

/// Per accepted step, the factor by which the span forgets a longer step: after a drop of the
/// step by 100 the correction reaches the short step's own rate in about 4,600 steps (ln 100 /
/// 0.001), a few contacts' worth.
pub const SPAN_DECAY: f64 = 0.999;

/// The damping ratio of the softness given to the joints: large, so that the constraint stays
/// rigid (see the module docs).
pub const DAMPING_RATIO: f64 = 1e3;

/// The span of the joints' position correction across steps: see the module docs.
#[derive(Clone, Debug, Default)]
pub struct JointCorrection {
    span: f64,
    /// The joints given the step's softness by `apply` (all had Rapier's default).
    touched: Vec<ImpulseJointHandle>,
}

impl JointCorrection {
    /// The span after a step of `dt` seconds: `dt` when longer than the decayed span.
    pub fn span_after(&self, dt: f64) -> f64 {
        dt.max(SPAN_DECAY * self.span)
    }

    /// The current span, s (0 before the first step).
    #[cfg(test)]
    pub fn span(&self) -> f64 {
        self.span
    }

    /// Forgets the span (a new initial state).
    pub fn reset(&mut self) {
        self.span = 0.0;
    }

    /// Gives every joint with Rapier's default softness the softness of a step of `dt`,
    /// remembering which for [`restore`](Self::restore).
    pub fn apply(&mut self, joints: &mut ImpulseJointSet, dt: f64) {
        let default = SpringCoefficients::joint_defaults();
        self.touched.clear();
        self.touched.extend(
            joints
                .iter()
                .filter(|(_, j)| j.data.softness == default)
                .map(|(h, _)| h),
        );
        let softness = softness_for(default, self.span_after(dt), dt);
        for &h in &self.touched {
            if let Some(j) = joints.get_mut(h, false) {
                j.data.softness = softness;
            }
        }
    }

    /// Gives the joints touched by [`apply`](Self::apply) Rapier's default softness back.
    pub fn restore(&mut self, joints: &mut ImpulseJointSet) {
        for h in self.touched.drain(..) {
            if let Some(j) = joints.get_mut(h, false) {
                j.data.softness = SpringCoefficients::joint_defaults();
            }
        }
    }

    /// Counts an accepted step of `dt` seconds for the span (a rejected one does not count).
    pub fn accept(&mut self, dt: f64) {
        self.span = self.span_after(dt);
    }
}

/// The softness whose bias rate is `1 / (span + tau0)` at a step of `dt` (Rapier's rate is
/// `omega / (dt omega + 2 zeta) = 1 / (dt + 2 zeta / omega)`), `tau0` being `default`'s.
pub fn softness_for(
    default: SpringCoefficients<f64>,
    span: f64,
    dt: f64,
) -> SpringCoefficients<f64> {
    let tau0 = 2.0 * default.damping_ratio / default.angular_frequency();
    let tau = (span - dt).max(0.0) + tau0;
    let omega = 2.0 * DAMPING_RATIO / tau;
    SpringCoefficients::new(omega / std::f64::consts::TAU, DAMPING_RATIO)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bias_rate_follows_the_span_not_the_step() {
        let d = SpringCoefficients::joint_defaults();
        let tau0 = 2.0 / (std::f64::consts::TAU * 1e6);
        // A constant step: Rapier's own rate.
        let s = softness_for(d, 1e-5, 1e-5);
        assert!((s.erp_inv_dt(1e-5) - d.erp_inv_dt(1e-5)).abs() < 1e-9 * d.erp_inv_dt(1e-5));
        // After a drop from 1e-4 s to 1e-6 s: the rate of the long step.
        let s = softness_for(d, 1e-4, 1e-6);
        let expected = 1.0 / (1e-4 + tau0);
        assert!((s.erp_inv_dt(1e-6) - expected).abs() < 1e-9 * expected);
        // Still rigid: Rapier's CFM coefficient stays small.
        assert!(s.cfm_coeff(1e-6) < 1e-4, "{}", s.cfm_coeff(1e-6));
    }

    #[test]
    fn the_span_jumps_up_and_decays_down() {
        let mut c = JointCorrection::default();
        c.accept(1e-4);
        assert_eq!(c.span(), 1e-4);
        c.accept(1e-6);
        assert_eq!(c.span(), SPAN_DECAY * 1e-4);
        c.accept(2e-4);
        assert_eq!(c.span(), 2e-4);
    }

    #[test]
    fn only_default_joints_are_touched_and_get_their_softness_back() {
        use rapier3d_f64::prelude::*;
        let mut bodies = RigidBodySet::new();
        let a = bodies.insert(RigidBodyBuilder::fixed());
        let b = bodies.insert(RigidBodyBuilder::dynamic());
        let mut joints = ImpulseJointSet::new();
        let plain = joints.insert(a, b, RevoluteJointBuilder::new(Vector::Z), true);
        let mine = SpringCoefficients::new(50.0, 0.5);
        let soft = joints.insert(
            a,
            b,
            RevoluteJointBuilder::new(Vector::Z).softness(mine),
            true,
        );
        let mut c = JointCorrection::default();
        c.accept(1e-4);
        c.apply(&mut joints, 1e-6);
        let during = joints.get(plain).unwrap().data.softness;
        let span = c.span_after(1e-6);
        assert_eq!(span, SPAN_DECAY * 1e-4);
        let expected = softness_for(SpringCoefficients::joint_defaults(), span, 1e-6);
        assert_eq!(during, expected);
        assert_eq!(joints.get(soft).unwrap().data.softness, mine);
        c.restore(&mut joints);
        assert_eq!(
            joints.get(plain).unwrap().data.softness,
            SpringCoefficients::joint_defaults()
        );
        assert_eq!(joints.get(soft).unwrap().data.softness, mine);
    }
}
