//! The physical ranges a scene's values must lie in, and the checks the validation shares.

use crate::error::{Error, Result, finite, in_range, sig4};

/// Largest initial or prescribed speed of a body (the length of its velocity), m/s: half the
/// run-time guard's 200 m/s (itself half Rapier's speed clamp of 400 m/s), which leaves the
/// bodies a driven body moves room to go faster than it without being taken for a blow-up.
pub const SPEED_MAX: f64 = 100.0;
/// Largest initial or prescribed angular speed, rad/s (about 95,000 rpm).
pub const RATE_MAX: f64 = 1e4;

/// Physical range of a body's mass, kg (fixed bodies: ignored).
pub const MASS_RANGE: (f64, f64) = (1e-6, 1e9);
/// Physical range of a principal moment of inertia, kg m^2.
pub const INERTIA_RANGE: (f64, f64) = (1e-12, 1e12);
/// Largest coordinate of a body's centre of mass or a hinge point, m.
pub const POSITION_MAX: f64 = 1e4;
/// Largest gravity component, m/s^2 (100 g).
pub const GRAVITY_MAX: f64 = 1e3;
/// Largest drive preload, N m (and stiffness, N m/deg).
pub const TORQUE_MAX: f64 = 1e6;
/// Largest drive `torque_scale` (either sign; negative only for a spring without stiffness).
pub const TORQUE_SCALE_MAX: f64 = 1e3;
/// Range of `run.dt_s`, s (also the smallest `run.output_interval_s`).
pub const DT_RANGE: (f64, f64) = (1e-9, 1.0);
/// Range of `run.end_s`, s (also the largest `run.output_interval_s`).
pub const END_RANGE: (f64, f64) = (1e-6, 1e7);
/// Smallest `run.tolerance` (the largest is 1).
pub const TOLERANCE_MIN: f64 = 1e-4;
/// Most Gauss-Seidel sweeps a step (`run.solver_sweeps`): each costs a pass over every joint.
pub const SWEEPS_MAX: usize = 1000;
/// Range of a bearing diameter or width, mm (1 um to 10 m).
pub const LENGTH_MM_RANGE: (f64, f64) = (1e-3, 1e4);
/// Range of a radial clearance, mm (1 nm to 1 m; it must also be below the bearing radius).
pub const CLEARANCE_MM_RANGE: (f64, f64) = (1e-6, 1e3);
/// Range of a speed given in mm/s (friction transition speeds, impact-speed floor).
pub const SPEED_MM_S_RANGE: (f64, f64) = (1e-9, 1e5);

/// Largest motor stiffness: N m/rad (revolute) or N/m (prismatic).
pub const MOTOR_STIFFNESS_MAX: f64 = 1e12;
/// Largest motor damping: N m s/rad (revolute) or N s/m (prismatic).
pub const MOTOR_DAMPING_MAX: f64 = 1e9;
/// Range of a velocity motor's damping factor, 1/s.
pub const MOTOR_FACTOR_RANGE: (f64, f64) = (1e-6, 1e12);

pub(super) fn position(field: &str, x: f64) -> Result<f64> {
    in_range(field, x, -POSITION_MAX, POSITION_MAX, "m")
}

pub(super) fn speed_mm_s(field: &str, v: f64) -> Result<f64> {
    in_range(field, v, SPEED_MM_S_RANGE.0, SPEED_MM_S_RANGE.1, "mm/s")
}

/// Letters, digits, `_` and `-`: safe in CSV headers and file names.
pub(in crate::scene) fn is_plain_name(name: &str) -> bool {
    !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

pub(super) fn unit(v: &[f64; 3], field: &str) -> Result<()> {
    for (i, x) in v.iter().enumerate() {
        finite(&format!("{field}[{i}]"), *x)?;
    }
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if (n - 1.0).abs() > 1e-6 {
        return Err(Error::invalid(
            field,
            format!("must be a unit vector (length {})", sig4(n)),
        ));
    }
    Ok(())
}
