//! The restitution a compliant normal law gives one impact: what an impulse-based (large-step)
//! model needs to bounce like the law would.

use super::normal::{NormalContact, NormalForceLaw, penetration_for_energy};

/// Integration steps per half period of the linearised contact at its deepest point.
const STEPS_PER_HALF_PERIOD: f64 = 400.0;
/// Give up (no rebound: the law holds the surfaces together) after this many half periods.
const MAX_HALF_PERIODS: f64 = 20.0;

/// The coefficient of restitution of a single impact under `law`: a body of `effective_mass`
/// (kg) striking at `approach_speed` (m/s, > 0) with no other force, integrated from first touch
/// to separation (`m delta'' = -F_N(delta, delta', delta_dot0)`, MODEL.md §2, with `delta_dot0` the
/// approach speed), by classical Runge-Kutta with 400 steps per half period of the contact
/// linearised at its deepest point. Returns the separation speed over the approach speed, in
/// [0, 1]; 0 when the law does not let the surfaces part, or for a non-positive mass or speed.
pub fn impact_restitution(
    law: &impl NormalForceLaw,
    effective_mass: f64,
    approach_speed: f64,
) -> f64 {
    let valid = |x: f64| x > 0.0 && x.is_finite();
    if !valid(effective_mass) || !valid(approach_speed) {
        return 0.0;
    }
    let m = effective_mass;
    let v0 = approach_speed;
    let deepest = penetration_for_energy(law, 0.5 * m * v0 * v0, 1e-6);
    let stiffness = law.tangent_stiffness(deepest);
    if !valid(stiffness) {
        return 0.0;
    }
    let half_period = std::f64::consts::PI * (m / stiffness).sqrt();
    let h = half_period / STEPS_PER_HALF_PERIOD;
    let accel = |x: f64, v: f64| {
        -law.normal_force(&NormalContact {
            penetration: x,
            penetration_rate: v,
            impact_rate: v0,
        }) / m
    };
    let (mut x, mut v) = (0.0_f64, v0);
    let max_steps = (MAX_HALF_PERIODS * STEPS_PER_HALF_PERIOD) as usize;
    for _ in 0..max_steps {
        let (k1x, k1v) = (v, accel(x, v));
        let (k2x, k2v) = (
            v + 0.5 * h * k1v,
            accel(x + 0.5 * h * k1x, v + 0.5 * h * k1v),
        );
        let (k3x, k3v) = (
            v + 0.5 * h * k2v,
            accel(x + 0.5 * h * k2x, v + 0.5 * h * k2v),
        );
        let (k4x, k4v) = (v + h * k3v, accel(x + h * k3x, v + h * k3v));
        x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        if x <= 0.0 {
            // Separated: the speed at the crossing (no force acts outside the contact).
            return (-v / v0).clamp(0.0, 1.0);
        }
    }
    0.0
}

/// The natural period (s) of a contact of `law` that moves `effective_mass` (kg) along its
/// normal, now `depth` deep (m) storing `elastic_energy` (J) and moving at `speed` (m/s) along
/// the normal: `2 pi sqrt(m/k)`, `k` the law's tangent stiffness at the deepest point its energy
/// (`1/2 m speed^2` plus the stored) reaches, the contact's stiffest point on the way (the
/// adaptive step's, `ContactAhead::resolving_step`). Exact for a linear law; for Hertz's
/// `K delta^(3/2)` the impact from first touch to separation lasts 0.641 of it (Johnson's
/// `2.943 delta_max/v0`): an impact is over within one such period. Infinite without stiffness.
pub fn contact_period(
    law: &impl NormalForceLaw,
    effective_mass: f64,
    speed: f64,
    depth: f64,
    elastic_energy: f64,
) -> f64 {
    let m = effective_mass;
    let energy = 0.5 * m * speed * speed + elastic_energy.max(0.0);
    let peak = penetration_for_energy(law, energy, 1e-6).max(depth);
    let stiffness = law.tangent_stiffness(peak);
    if !(stiffness > 0.0 && m > 0.0) {
        return f64::INFINITY;
    }
    std::f64::consts::TAU * (m / stiffness).sqrt()
}

/// The impact speed that would bring a contact of `effective_mass` (kg) to a depth storing
/// `elastic_energy` (J): `sqrt(2 E/m)`, m/s.
///
/// The hysteresis laws' damping `chi K delta^n/delta_dot0` is calibrated on a free impact, in
/// which the depth reached follows from the approach speed (`E(delta) <= m delta_dot0^2/2`). A
/// contact that began slowly (a re-contact at a few um/s) and is then loaded deeper by the rest
/// of the mechanism is no such impact: with its own `delta_dot0` its damping would grow without
/// bound (`1/delta_dot0`) and its stable step would fall to nothing. The joint takes the larger
/// of the approach speed and this speed as `delta_dot0`: the damping of a contact never exceeds
/// that of a free impact reaching the same depth. A free impact is left untouched only when `m`
/// is the mass the contact really moves: the joint passes its effective mass through the
/// mechanism's ideal joints (a free body's mass along the normal would be too light for a pinned
/// one, and the raise would act mid-impact).
pub fn loaded_impact_rate(elastic_energy: f64, effective_mass: f64) -> f64 {
    if elastic_energy > 0.0 && effective_mass > 0.0 && effective_mass.is_finite() {
        (2.0 * elastic_energy / effective_mass).sqrt()
    } else {
        0.0
    }
}

/// Where between two states the surfaces met: the fraction of the step from the state before
/// (a gap `gap_before` >= 0, m) to the state after (`depth_after` > 0, m) at which the
/// penetration crossed 0, linear in time (positions move linearly over a step), in (0, 1].
pub fn crossing_fraction(gap_before: f64, depth_after: f64) -> f64 {
    let (g, d) = (gap_before.max(0.0), depth_after.max(0.0));
    if g + d > 0.0 { g / (g + d) } else { 1.0 }
}

/// The approach speed at the crossing of `fraction` ([`crossing_fraction`]) into a step, from the
/// penetration rates read at the states before and after it (m/s). A state's velocities are the
/// ones of the step that led to it, so the two readings are the speeds at the middles of the
/// step before and of this one: interpolated linearly in time between them (equal steps
/// assumed), `r_after + (r_after - r_before)(fraction - 1/2)`.
pub fn speed_at_crossing(rate_before: f64, rate_after: f64, fraction: f64) -> f64 {
    rate_after + (rate_after - rate_before) * (fraction - 0.5)
}

/// The approach speed at the crossing of `fraction` ([`crossing_fraction`]) into a sub-step of a
/// sub-cycle, from the penetration rate at the state before it (`rate_at_state`, its velocity
/// at the state) and the one its drift moves at (`rate_drift`, the velocity after the state's
/// kick: the rate at the sub-step's middle under a constant acceleration), m/s:
/// `rate_at_state + 2 fraction (rate_drift - rate_at_state)`, exact in a free flight under a
/// constant acceleration. [`speed_at_crossing`] reads the two as half a step further apart,
/// and on a sub-step that lands on the wall after a long flight it falls short by a quarter of
/// the rate the flight's acceleration brings over the sub-step.
pub fn speed_at_crossing_in_substep(rate_at_state: f64, rate_drift: f64, fraction: f64) -> f64 {
    rate_at_state + 2.0 * fraction * (rate_drift - rate_at_state)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::laws::{Hertz, ImprovedLiu, KelvinVoigt, LankaraniNikravesh, MaxDamping};

    /// A free flight under a constant acceleration `a`, read as a sub-cycle reads it: the rate
    /// at the state `r0`, the drift's rate `r0 + a s/2`. The crossing's rate is
    /// `r0 + a f s` at every fraction `f`; read as two mid-step rates (equal steps apart) it
    /// would fall short by `a s/4` at the sub-step's end.
    #[test]
    fn a_sub_steps_crossing_reads_a_constant_acceleration_exactly() {
        let (r0, a, s) = (-2e-4, 0.6, 1e-3);
        let drift = r0 + 0.5 * a * s;
        for f in [0.0, 0.25, 0.5, 0.9, 1.0] {
            let exact = r0 + a * f * s;
            let got = speed_at_crossing_in_substep(r0, drift, f);
            assert!((got - exact).abs() < 1e-15, "{f}: {got} against {exact}");
        }
        let short = r0 + a * s - speed_at_crossing(r0, drift, 1.0);
        assert!((short - 0.25 * a * s).abs() < 1e-15, "{short}");
    }

    #[test]
    fn an_elastic_law_returns_all_the_energy() {
        let law = Hertz::new(1e9, 1.5).unwrap();
        let e = impact_restitution(&law, 2.0, 0.1);
        assert!((e - 1.0).abs() < 1e-6, "{e}");
    }

    #[test]
    fn kelvin_voigt_matches_the_damped_oscillator() {
        // F = k x + d x' on free flight: separation when F reaches 0 (x > 0, force-free coast).
        // For small damping the linear oscillator gives e ~ exp(-zeta pi / sqrt(1 - zeta^2)), a
        // little more than that because the force vanishes before x does.
        let (m, k) = (1.0_f64, 1e6_f64);
        let zeta: f64 = 0.05;
        let d = 2.0 * zeta * (k * m).sqrt();
        let law = KelvinVoigt::new(k, d).unwrap();
        let e = impact_restitution(&law, m, 0.5);
        let linear = (-zeta * std::f64::consts::PI / (1.0 - zeta * zeta).sqrt()).exp();
        assert!(e > linear && e < linear + 0.05, "{e} vs {linear}");
    }

    #[test]
    fn lankarani_nikravesh_gives_about_its_coefficient() {
        // The law is built to return about cr for cr near 1 (Lankarani & Nikravesh 1990).
        for cr in [0.9, 0.95] {
            let law = LankaraniNikravesh::new(1e10, 1.5, cr).unwrap();
            let e = impact_restitution(&law, 1.0, 0.2);
            assert!((e - cr).abs() < 0.02, "cr {cr}: {e}");
        }
    }

    #[test]
    fn the_papers_law_bounces_and_refuses_nonsense() {
        let law =
            ImprovedLiu::new(1.137e11, 0.016, 0.5e-3, 1.0, 1e-4, MaxDamping::Eta(0.01)).unwrap();
        let e = impact_restitution(&law, 5.0, 0.05);
        assert!(e > 0.0 && e < 1.0, "{e}");
        assert_eq!(impact_restitution(&law, 0.0, 0.05), 0.0);
        assert_eq!(impact_restitution(&law, 5.0, -1.0), 0.0);
        assert_eq!(impact_restitution(&law, f64::NAN, 1.0), 0.0);
    }

    /// The period against closed forms on a single knock: a linear law's `2 pi sqrt(m/k)`
    /// whatever the speed; Hertz's impact (an RK4 integration from touch to separation, as
    /// `impact_restitution`'s) lasts Johnson's `2.943 delta_max/v0`, 0.641 of the period.
    #[test]
    fn the_contact_period_matches_a_single_knock() {
        let (m, k) = (2.0, 2.3e9);
        let linear = Hertz::new(k, 1.0).unwrap();
        let exact = std::f64::consts::TAU * (m / k).sqrt();
        for (speed, depth) in [(0.1, 0.0), (0.01, 0.0), (0.0, 1e-6)] {
            let elastic = linear.elastic_energy(depth);
            let t = contact_period(&linear, m, speed, depth, elastic);
            assert!((t / exact - 1.0).abs() < 1e-9, "{t} against {exact}");
        }
        let (kh, v0) = (1e9, 0.1);
        let hertz = Hertz::new(kh, 1.5).unwrap();
        let t = contact_period(&hertz, m, v0, 0.0, 0.0);
        let deepest = (2.5 * 0.5 * m * v0 * v0 / kh).powf(0.4);
        let johnson = 2.943 * deepest / v0;
        let (mut x, mut v, mut time, h) = (0.0_f64, v0, 0.0, 1e-8);
        let accel = |x: f64| -kh * x.max(0.0).powf(1.5) / m;
        while x >= 0.0 {
            let (k1x, k1v) = (v, accel(x));
            let (k2x, k2v) = (v + 0.5 * h * k1v, accel(x + 0.5 * h * k1x));
            let (k3x, k3v) = (v + 0.5 * h * k2v, accel(x + 0.5 * h * k2x));
            let (k4x, k4v) = (v + h * k3v, accel(x + h * k3x));
            x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
            v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
            time += h;
        }
        assert!(
            (time / johnson - 1.0).abs() < 1e-3,
            "{time} against {johnson}"
        );
        assert!((time / t - 0.641).abs() < 1e-3, "{time} over {t}");
        assert_eq!(contact_period(&hertz, m, 0.0, 0.0, 0.0), f64::INFINITY);
    }
}
