//! How finely Rapier must cut a step for a radial-play constraint to mean something: pure
//! functions of numbers, no Rapier.
//!
//! Rapier solves a step of `dt` in `n` substeps `h = dt/n` (`num_solver_iterations`), each a
//! linearised velocity solve followed by a position update. Two errors of that scheme grow with
//! `h` and are fixed in absolute size, so a small clearance `c` sees them first:
//!
//! - **Rotation drift.** A point at lever `r` on a body turning at `omega` leaves the chord of its
//!   arc by `|omega x (omega x r)| h^2/2` per substep (every Rapier joint has this error; the last
//!   substep's is left at the end of the step). A clearance smaller than it is noise.
//! - **Sliding along the curved wall.** Each substep moves the journal along the tangent of the
//!   clearance circle; a relative speed `v` along the wall leaves the circle by `(v h)^2/(2c)`
//!   (measured: 14 % of c = 1 mm for a sign whose bracket is kicked up at 0.39 m/s by cobbles at
//!   1/60 s with 4 substeps; 2.9 % with 16).
//! - **Rocking of the journal on the wall.** Pressed against the bearing by a load `N`, the
//!   journal is a pendulum of length `c` along the wall: tangential stiffness `N/c` against the
//!   effective mass `m_t` of the two bodies along the wall, so `omega_r = sqrt(N/(m_t c))`. Each
//!   substep rebuilds the wall's normal from the positions, which is symplectic Euler on this
//!   pendulum: stable only for `omega_r h < 2`. Beyond it the journal flips from side to side every
//!   substep and leaves the circle by many `c` (measured: 26 c for c = 0.05 mm on an arm turning at
//!   6 rad/s at 1/60 s with 4 substeps, and 1.19 c for c = 0.5 mm).

/// Largest `omega_r h` per substep: half the symplectic Euler limit of 2.
pub const ROCKING_LIMIT: f64 = 1.0;

/// Largest step-end penetration left by one substep's rotation drift, as a fraction of `c`.
pub const DRIFT_FRACTION: f64 = 0.05;

/// Angular frequency of the journal rocking on the bearing wall, rad/s: `sqrt(N/(m_t c))` for a
/// normal load `normal_force` (N), effective mass along the wall `tangential_mass` (kg) and
/// radial clearance `clearance` (m). 0 without load or for non-positive inputs.
pub fn rocking_frequency(normal_force: f64, tangential_mass: f64, clearance: f64) -> f64 {
    if normal_force > 0.0 && tangential_mass > 0.0 && clearance > 0.0 {
        let w = (normal_force / (tangential_mass * clearance)).sqrt();
        if w.is_finite() { w } else { 0.0 }
    } else {
        0.0
    }
}

/// The number of substeps (not rounded) one step of `dt` needs so that `omega_r h <=`
/// [`ROCKING_LIMIT`], the rotation drift `a h^2/2 <=` [`DRIFT_FRACTION`]` c` and the sliding
/// error `(v h)^2/(2c) <= DRIFT_FRACTION c`, where `drift_acceleration` is the in-plane
/// centripetal acceleration of the journal centre relative to the bearing centre,
/// `|omega2 x (omega2 x r2) - omega1 x (omega1 x r1)|` (m/s^2), and `sliding_speed` the in-plane
/// speed of the journal centre along the wall (m/s).
pub fn substeps_needed(
    dt: f64,
    rocking_frequency: f64,
    drift_acceleration: f64,
    sliding_speed: f64,
    clearance: f64,
) -> f64 {
    if !(dt > 0.0 && clearance > 0.0) {
        return 1.0;
    }
    let rocking = dt * rocking_frequency.max(0.0) / ROCKING_LIMIT;
    let drift = dt * (drift_acceleration.max(0.0) / (2.0 * DRIFT_FRACTION * clearance)).sqrt();
    let sliding = dt * sliding_speed.max(0.0) / ((2.0 * DRIFT_FRACTION).sqrt() * clearance);
    let n = rocking.max(drift).max(sliding).max(1.0);
    if n.is_finite() { n } else { f64::INFINITY }
}

/// `needed` substeps rounded up to `base 2^k` (so the count changes rarely), at least `base`, at
/// most `max` (and `max` when `needed` is infinite).
pub fn quantized_substeps(needed: f64, base: usize, max: usize) -> usize {
    let base = base.max(1);
    let max = max.max(base);
    let mut n = base;
    while (n as f64) < needed && n < max {
        n = n.saturating_mul(2);
    }
    n.min(max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rocking_frequency_by_hand() {
        // 20 N on 0.5 kg along the wall in 0.5 mm: sqrt(20 / 2.5e-4) = 282.84 rad/s.
        assert!((rocking_frequency(20.0, 0.5, 0.5e-3) - 282.842712).abs() < 1e-5);
        assert_eq!(rocking_frequency(0.0, 0.5, 0.5e-3), 0.0);
        assert_eq!(rocking_frequency(20.0, 0.0, 0.5e-3), 0.0);
        assert_eq!(rocking_frequency(f64::NAN, 0.5, 0.5e-3), 0.0);
    }

    #[test]
    fn substeps_by_hand() {
        // Rocking 282.84 rad/s at 1/60 s: 4.714 substeps.
        let n = substeps_needed(1.0 / 60.0, 282.842712, 0.0, 0.0, 0.5e-3);
        assert!((n - 4.714045).abs() < 1e-5, "{n}");
        // Drift: an arm turning at 6 rad/s with the journal 0.3 m from its centre of mass,
        // a = 36 x 0.3 = 10.8 m/s^2; c = 0.05 mm: dt sqrt(a/(0.1 c)) = 24.49 substeps at 1/60 s.
        let n = substeps_needed(1.0 / 60.0, 0.0, 10.8, 0.0, 0.05e-3);
        assert!((n - 24.494897).abs() < 1e-5, "{n}");
        // Sliding at 0.16 m/s along a 1 mm clearance: dt v/(sqrt(0.1) c) = 8.433 at 1/60 s.
        let n = substeps_needed(1.0 / 60.0, 0.0, 0.0, 0.16, 1e-3);
        assert!((n - 8.432740).abs() < 1e-5, "{n}");
        assert_eq!(substeps_needed(1e-3, 0.0, 0.0, 0.0, 0.5e-3), 1.0);
    }

    #[test]
    fn quantized_to_powers_of_two_of_the_base() {
        assert_eq!(quantized_substeps(1.0, 4, 64), 4);
        assert_eq!(quantized_substeps(4.7, 4, 64), 8);
        assert_eq!(quantized_substeps(24.5, 4, 64), 32);
        assert_eq!(quantized_substeps(1e9, 4, 64), 64);
        assert_eq!(quantized_substeps(f64::INFINITY, 4, 48), 48);
        assert_eq!(quantized_substeps(3.0, 1, 64), 4);
        assert_eq!(quantized_substeps(5.0, 4, 2), 4, "never below the base");
    }

    #[test]
    fn any_numbers_give_a_count() {
        // Every input from the awkward values (non-finite, zero, negative, tiny, huge) gives a
        // frequency that is not NaN, at least one substep, and a count within the bounds.
        let values = [
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            0.0,
            -1.0,
            1e-300,
            0.5e-3,
            1e300,
        ];
        for &x in &values {
            for &x0 in &values {
                for &h0 in &values {
                    let r = rocking_frequency(x, x0, h0);
                    assert!(
                        !r.is_nan() && r >= 0.0,
                        "rocking_frequency({x}, {x0}, {h0}) = {r}"
                    );
                    let q = quantized_substeps(r, 4, 4096);
                    assert!((4..=4096).contains(&q), "quantized_substeps({r}) = {q}");
                    for &x1 in &values {
                        for &h1 in &values {
                            let n = substeps_needed(x, x0, h0, x1, h1);
                            assert!(!n.is_nan() && n >= 1.0, "substeps_needed = {n}");
                            let q = quantized_substeps(n, 1, 64);
                            assert!((1..=64).contains(&q), "quantized_substeps({n}) = {q}");
                        }
                    }
                }
            }
        }
    }
}
