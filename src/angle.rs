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
