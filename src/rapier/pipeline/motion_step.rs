//! The step the bodies' own motion needs, for the adaptive [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld):
//! the contacts are not the only thing a step must resolve. A crank at 5000 rpm turns 30 deg in
//! a 1 ms step; Rapier's joints are linearised at the step's start and its kinematic bodies
//! turned to first order, so the constraint, a slider's acceleration and the approach to the
//! next contact are then wrong by tens of percent with no contact in sight.
//!
//! The rule: **no movable body turns by more than `tolerance/8` radians in one step**
//! ([`TURN_PER_TOLERANCE`], [`turn_step`]), `h <= tol/(8 |w|)`. A mechanism's accelerations
//! change as its bodies turn (the centripetal and linkage terms are functions of the angles),
//! and the errors of a step that
//! turns a body by `w h` are of order `(w h)^2` of them: measured on Flores and Ambrósio's
//! slider-crank (5000 rpm, L1/L2 = 0.42), fixed steps of 1.1, 2.1 and 3.4 deg give the slider's
//! acceleration within 0.08 %, 0.3 % and (at 30 deg) 55 % of its peak; at a turn of 0.0075 rad
//! (0.43 deg) it is within 0.02 %. Why an eighth: [`TURN_PER_TOLERANCE`]. A contact's own time
//! scale is bounded separately
//! ([`ClearanceJoint::adaptive_step`](crate::rapier::joint::ClearanceJoint::adaptive_step):
//! `2 tol` of its natural period in contact; `tol` of the clearance per step of the journal's
//! path, across the gap and along the wall, [`flight_step`](crate::rapier::joint::flight_step));
//! the step is the smallest of these and `max_dt`, which is a safety cap.
//!
//! What the rule does not see: a body that translates without turning under a stiff force of
//! your own (a stiff linear spring). Cap `max_dt` below a tenth of such a period yourself.
//! (An estimate from the change of the bodies' accelerations was tried and measured: Rapier moves
//! the bodies with velocities that include its joints' position correction, so accelerations
//! read from velocities or poses carry a term that does not shrink with the step, and the
//! estimated rate of change grows as `1/h`: the step control then shrank without end.)

use rapier3d_f64::prelude::PhysicsWorld;

/// The angle, in rad per unit of tolerance, a movable body may turn in one adaptive step: `tol/8`
/// (0.054 deg at the default 0.0075). Each bound of the step is its own error source, and the
/// factors balance them (as
/// [`CONTACT_PERIODS_PER_TOLERANCE`](crate::rapier::joint::CONTACT_PERIODS_PER_TOLERANCE) does
/// for the contact): at a turn of `tol` the turn is the largest error on a driven mechanism;
/// scenes whose bodies turn slowly are not affected at the default tolerance.
///
/// Measured in docs/stepper-and-accuracy.md (step choice, the work-precision table of
/// `cargo bench --bench work_precision` and the mechanism matrix of `cargo bench --bench mechanisms`).
pub const TURN_PER_TOLERANCE: f64 = 0.125;

/// The step that turns a body spinning at `angular_speed` (rad/s) by `angle` radians,
/// `angle/|w|`, s (infinite at rest).
pub fn turn_step(angle: f64, angular_speed: f64) -> f64 {
    let w = angular_speed.abs();
    if w > 0.0 { angle / w } else { f64::INFINITY }
}

/// The largest step the motion of `world` allows now: [`turn_step`] of `tolerance/8`
/// ([`TURN_PER_TOLERANCE`]) for every movable body (dynamic or kinematic) at its current angular
/// velocity, s.
pub fn motion_step(world: &PhysicsWorld, tolerance: f64) -> f64 {
    world
        .bodies
        .iter()
        .filter(|(_, rb)| !rb.is_fixed())
        .map(|(_, rb)| turn_step(TURN_PER_TOLERANCE * tolerance, rb.angvel().length()))
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turn_step_by_hand() {
        // 600 rpm = 20 pi rad/s; 0.02 pi rad in 1 ms.
        let w = 20.0 * std::f64::consts::PI;
        assert!((turn_step(0.02 * std::f64::consts::PI, w) - 1e-3).abs() < 1e-15);
        assert!((turn_step(0.01, -w) - 0.01 / w).abs() < 1e-18);
        assert_eq!(turn_step(0.01, 0.0), f64::INFINITY);
    }
}
