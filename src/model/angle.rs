//! Continuous (unwrapped) rotation angles about a fixed axis.

use rapier3d_f64::math::{Rotation, Vector};
use std::f64::consts::{PI, TAU};

/// Twist angle of `rotation` about the unit `axis`, in (-2 pi, 2 pi]: the swing-twist
/// decomposition's twist, `2 atan2(q_v . axis, q_w)`.
pub fn twist_angle(rotation: &Rotation, axis: Vector) -> f64 {
    2.0 * Vector::new(rotation.x, rotation.y, rotation.z)
        .dot(axis)
        .atan2(rotation.w)
}

/// Tracks an angle across steps and removes the 2 pi jumps of [`twist_angle`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct UnwrappedAngle {
    value: f64,
}

impl UnwrappedAngle {
    /// Feeds the wrapped angle of the current step; returns the continuous angle (rad).
    pub fn update(&mut self, wrapped: f64) -> f64 {
        let mut delta = (wrapped - self.value) % TAU;
        if delta > PI {
            delta -= TAU;
        } else if delta < -PI {
            delta += TAU;
        }
        self.value += delta;
        self.value
    }

    /// The last continuous angle (rad).
    pub fn value(&self) -> f64 {
        self.value
    }
}

/// The angle of a hinge: body 2's rotation relative to body 1 about the hinge axis (in body 1's
/// frame), zero at the first measurement and continuous (unwrapped) after it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HingeAngle {
    /// Relative orientation `q1^-1 q2` at the first measurement.
    reference: Option<Rotation>,
    angle: UnwrappedAngle,
}

impl HingeAngle {
    /// Measures the angle from the bodies' rotations `q1`, `q2`; `local_axis1` is the unit hinge
    /// axis in body 1's frame. Returns the continuous angle (rad).
    pub fn update(&mut self, q1: &Rotation, q2: &Rotation, local_axis1: Vector) -> f64 {
        let relative = q1.inverse() * *q2;
        let reference = *self.reference.get_or_insert(relative);
        // A hinge turn is a rotation in body 1's frame applied after the reference:
        // relative = turn * reference, so turn = relative * reference^-1.
        self.angle
            .update(twist_angle(&(relative * reference.inverse()), local_axis1))
    }

    /// Fixes the reference orientation now (otherwise the first [`update`](Self::update) does).
    pub fn set_reference(&mut self, q1: &Rotation, q2: &Rotation) {
        self.reference = Some(q1.inverse() * *q2);
    }

    /// Whether the reference orientation is set.
    pub fn has_reference(&self) -> bool {
        self.reference.is_some()
    }

    /// The last continuous angle (rad).
    pub fn value(&self) -> f64 {
        self.angle.value()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn twist_about_axis() {
        let axis = Vector::new(0.0, -1.0, 0.0);
        let q = Rotation::from_axis_angle(axis, 0.7);
        assert!((twist_angle(&q, axis) - 0.7).abs() < 1e-14);
        assert!((twist_angle(&q, -axis) + 0.7).abs() < 1e-14);
    }

    #[test]
    fn hinge_angle_with_a_rotated_body() {
        // Body 2 starts turned 90 deg about x; the hinge (body 1's z) then turns it by 0.5 rad.
        let q1 = Rotation::IDENTITY;
        let q2_0 = Rotation::from_axis_angle(Vector::X, std::f64::consts::FRAC_PI_2);
        let mut h = HingeAngle::default();
        assert_eq!(h.update(&q1, &q2_0, Vector::Z), 0.0);
        let q2 = Rotation::from_axis_angle(Vector::Z, 0.5) * q2_0;
        assert!((h.update(&q1, &q2, Vector::Z) - 0.5).abs() < 1e-12);
        // Both bodies turned together by any rotation: no hinge angle.
        let common = Rotation::from_axis_angle(Vector::new(0.3, -0.2, 0.9).normalize(), 1.1);
        assert!((h.update(&(common * q1), &(common * q2), Vector::Z) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn unwraps_past_a_full_turn() {
        let axis = Vector::Z;
        let mut a = UnwrappedAngle::default();
        let mut last = 0.0;
        for i in 0..=800 {
            let angle = i as f64 * 0.01; // up to 8 rad, more than a turn
            last = a.update(twist_angle(&Rotation::from_axis_angle(axis, angle), axis));
            assert!((last - angle).abs() < 1e-12, "{angle} -> {last}");
        }
        assert!((last - 8.0).abs() < 1e-12);
    }
}
