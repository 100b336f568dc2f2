//! Journal-bearing kinematics and the contact force pair (MODEL.md §1): pure functions of
//! poses and velocities, no Rapier state.

use crate::model::laws::{BearingGeometry, FrictionLaw, NormalContact, NormalForceLaw};
use rapier3d_f64::math::Vector;

/// Position of the centre of mass and velocities of one rigid body, in world coordinates.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BodyMotion {
    /// World position of the centre of mass, m.
    pub center_of_mass: Vector,
    /// Linear velocity of the centre of mass, m/s.
    pub linvel: Vector,
    /// Angular velocity, rad/s.
    pub angvel: Vector,
}

impl BodyMotion {
    /// Velocity of the material point at world position `point`.
    #[inline]
    pub fn velocity_at(&self, point: Vector) -> Vector {
        self.linvel + self.angvel.cross(point - self.center_of_mass)
    }
}

/// Journal motion mode (paper Fig. 1b).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub enum ContactMode {
    /// No contact: `delta <= 0`.
    #[default]
    FreeFlight,
    /// A contact that has just begun, from onset until the end of its compression phase
    /// (the first step at which the penetration stops growing).
    Impact,
    /// The rest of a contact: restitution, or the journal following the bearing wall.
    Continuous,
}

/// Geometric and kinematic state of one journal in its bearing (MODEL.md §1).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JournalState {
    /// Eccentricity `e`: the part of `P_j - P_i` normal to the axis, m.
    pub eccentricity: Vector,
    /// Unit normal `n = e/|e|` (bearing centre towards journal centre); an arbitrary
    /// in-plane unit vector when `e = 0`.
    pub normal: Vector,
    /// Penetration `delta = |e| - c`, m (negative: free gap).
    pub penetration: f64,
    /// Penetration rate `delta_dot = v_rel . n`, m/s.
    pub penetration_rate: f64,
    /// In-plane tangential slip velocity `v_t`, m/s.
    pub slip: Vector,
    /// Rate of the eccentricity `de/dt`: the in-plane velocity of the journal's centre relative
    /// to the bearing's, m/s (the journal's path across the gap; unlike `slip` it carries no
    /// relative spin).
    pub eccentricity_rate: Vector,
    /// The common application point of the force pair: midpoint of `Q_i` and `Q_j`.
    pub contact_point: Vector,
}

/// The in-plane reference direction `u` of a bearing with unit axis `axis`: the coordinate axis
/// (x, y or z) least aligned with `axis`, made orthogonal to it (x for an axis along y; then
/// `v = axis x u` is z). The scene runner's CSV columns `*_ecc_u_mm`/`*_ecc_v_mm` report the
/// eccentricity along these directions, in the bearing body's frame.
///
/// ```
/// use clearance_joint::model::kinematics::in_plane_u;
/// use rapier3d_f64::math::Vector;
///
/// assert_eq!(in_plane_u(Vector::Y), Vector::X);
/// assert_eq!(in_plane_u(Vector::X), Vector::Y);
/// let tilted = Vector::new(1.0, 1.0, 0.0).normalize();
/// assert!(in_plane_u(tilted).dot(tilted).abs() < 1e-15);
/// ```
pub fn in_plane_u(axis: Vector) -> Vector {
    let candidates = [Vector::X, Vector::Y, Vector::Z];
    let mut best = candidates[0];
    for c in candidates {
        if c.dot(axis).abs() < best.dot(axis).abs() - 1e-12 {
            best = c;
        }
    }
    (best - best.dot(axis) * axis).normalize()
}

/// Computes [`JournalState`] from the bearing centre `p_i`, journal centre `p_j`, the unit
/// bearing axis `axis` (world), and both bodies' motion.
pub fn journal_state(
    geometry: &BearingGeometry,
    p_i: Vector,
    p_j: Vector,
    axis: Vector,
    bearing: &BodyMotion,
    journal: &BodyMotion,
) -> JournalState {
    let d = p_j - p_i;
    let eccentricity = d - d.dot(axis) * axis;
    let e = eccentricity.length();
    let normal = if e > 0.0 {
        eccentricity / e
    } else {
        axis.any_orthonormal_vector()
    };
    let q_i = p_i + geometry.bearing_radius() * normal;
    let q_j = p_j + geometry.journal_radius() * normal;
    let v_rel = journal.velocity_at(q_j) - bearing.velocity_at(q_i);
    let penetration_rate = v_rel.dot(normal);
    let slip = v_rel - penetration_rate * normal - v_rel.dot(axis) * axis;
    let centres = journal.velocity_at(p_j) - bearing.velocity_at(p_i);
    JournalState {
        eccentricity,
        normal,
        penetration: e - geometry.clearance(),
        penetration_rate,
        slip,
        eccentricity_rate: centres - centres.dot(axis) * axis,
        contact_point: 0.5 * (q_i + q_j),
    }
}

/// The equal-and-opposite contact force pair of one joint.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ForcePair {
    /// Force on the journal body, N; the bearing body receives its negative at the same point.
    pub on_journal: Vector,
    /// World point where both forces act, so the pair has no net moment.
    pub point: Vector,
    /// Normal force magnitude `F_N >= 0`, N.
    pub normal_force: f64,
    /// Friction force magnitude, N.
    pub friction_force: f64,
}

/// Evaluates the laws at `state`: `F = -F_N n - mu(|v_t|) F_N v_t/|v_t|` on the journal (MODEL.md §1).
/// `impact_rate` is `delta_dot0` of the current contact (already floored positive).
pub fn contact_force(
    state: &JournalState,
    impact_rate: f64,
    normal: &impl NormalForceLaw,
    friction: &impl FrictionLaw,
) -> ForcePair {
    let normal_force = normal.normal_force(&NormalContact {
        penetration: state.penetration,
        penetration_rate: state.penetration_rate,
        impact_rate,
    });
    if normal_force <= 0.0 {
        return ForcePair {
            point: state.contact_point,
            ..ForcePair::default()
        };
    }
    let slip_speed = state.slip.length();
    let (friction_force, friction) = if slip_speed > 0.0 {
        let f = friction.coefficient(slip_speed) * normal_force;
        (f, -f / slip_speed * state.slip)
    } else {
        (0.0, Vector::ZERO)
    };
    ForcePair {
        on_journal: -normal_force * state.normal + friction,
        point: state.contact_point,
        normal_force,
        friction_force,
    }
}

/// The acceleration of the penetration rate over the step that led to the state from everything
/// but the contact's own force (the rest of the mechanism: constraints, drives, gravity, the
/// normal turning), m/s²: the rates read before and after that step (`rate_before`,
/// `rate_after`), the kick between them `kick` (s; the mean of the two steps around the state
/// before it, Verlet's velocity update), and the normal force `force_before` (N) applied over it
/// through the `effective_mass` (kg): `(r_after - r_before)/kick + F_before/m`.
pub fn rest_acceleration(
    rate_before: f64,
    rate_after: f64,
    kick: f64,
    force_before: f64,
    effective_mass: f64,
) -> f64 {
    (rate_after - rate_before) / kick + force_before / effective_mass
}

/// What the state before the last step tells [`rate_at_state`]: the penetration rate stored there
/// (m/s), the contact's normal force applied over the step (N), and the steps `[the one before
/// that state, the last one]` (s; the last 0 when unknown).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepBefore {
    /// The stored penetration rate at the state before the step, m/s.
    pub rate: f64,
    /// The contact's normal force over the step, N.
    pub force: f64,
    /// The step before that state and the step itself, s.
    pub steps: [f64; 2],
}

impl StepBefore {
    /// The rate `stored` at the state after the step carried to it ([`rate_at_state`]), with
    /// the rest of the mechanism's acceleration from the step ([`rest_acceleration`] over the
    /// kick `(h_before + h)/2`) and the contact's `force` (N) and `damping` (N s/m) at `stored`
    /// through the `effective_mass` (kg); `stored` itself when the step is unknown.
    pub fn carry(&self, stored: f64, force: f64, damping: f64, effective_mass: f64) -> f64 {
        let [before, step] = self.steps;
        if !(step > 0.0) {
            return stored;
        }
        let kick = 0.5 * (before + step);
        let rest = rest_acceleration(self.rate, stored, kick, self.force, effective_mass);
        rate_at_state(stored, step, rest, force, damping, effective_mass)
    }
}

/// The normal force `F` (N) and damping `D = dF/d delta_dot` (N s/m) of `law` at `contact`, as
/// [`rate_at_state`] takes them: both 0 where the law's force is not positive (no adhesion: the
/// contact force is then 0 whatever the rate).
pub fn force_and_damping(law: &impl NormalForceLaw, contact: &NormalContact) -> (f64, f64) {
    match law.normal_force(contact) {
        f if f > 0.0 => (f, law.damping_coefficient(contact)),
        _ => (0.0, 0.0),
    }
}

/// The penetration rate at the state, m/s, from the rate `stored` in the bodies' velocities.
///
/// Verlet's velocities are the mean over the step that led to the state (`step`, s), so they lag
/// it by half a step; a damping force read from them is wrong by `D a h/2`, a first-order error
/// in the step on every contact peak. Carried half a step forward with the rest of the
/// mechanism's acceleration `rest` ([`rest_acceleration`], m/s²) and the contact's own force
/// `force` (N, at `stored`) and damping `damping = dF/d delta_dot` (N s/m) taken implicitly, so a
/// stiff damper does not shorten the stable step:
///
/// `v = stored + (h/2)(rest - F/m)/(1 + h D/(2 m))`
///
/// (a trapezoidal half step of `m dv/dt = m rest - F(v)`, exact when `F` is affine in the rate,
/// as for every damping law here). `step = 0` (velocities that are the state's own, as at the
/// start) returns `stored`.
pub fn rate_at_state(
    stored: f64,
    step: f64,
    rest: f64,
    force: f64,
    damping: f64,
    effective_mass: f64,
) -> f64 {
    let half = 0.5 * step;
    let v =
        stored + half * (rest - force / effective_mass) / (1.0 + half * damping / effective_mass);
    if v.is_finite() { v } else { stored }
}

/// Largest stable step of symplectic Euler for the contact linearised at `state`:
/// `m x'' = -k x - d x'` is stable for `omega dt <= 2 (sqrt(1 + zeta^2) - zeta)`,
/// `omega = sqrt(k/m)`, `zeta = d/(2 m omega)` (the eigenvalues of the one-step map).
/// Returns `(dt_max, omega, zeta)`. Without stiffness (`k <= 0`) damping alone limits the step to
/// `2 m/d` (reported with `omega = 0`, `zeta` infinite); without either `dt_max` is infinite. A
/// NaN stiffness or damping counts as none; the step is never NaN.
pub fn stable_step(stiffness: f64, damping: f64, effective_mass: f64) -> (f64, f64, f64) {
    if !(effective_mass > 0.0) || !effective_mass.is_finite() {
        return (f64::INFINITY, 0.0, 0.0);
    }
    let omega = (stiffness / effective_mass).sqrt();
    // No stiffness (or one too small against the mass to be represented).
    if !(omega > 0.0) {
        // Pure damping `m x'' = -d x'`: `v (1 - dt d/m)` per step, stable for `dt <= 2 m/d`.
        return if damping > 0.0 {
            (2.0 * (effective_mass / damping), 0.0, f64::INFINITY)
        } else {
            (f64::INFINITY, 0.0, 0.0)
        };
    }
    if omega.is_infinite() {
        return (0.0, omega, 0.0);
    }
    let d = damping.max(0.0);
    let zeta = match d / (2.0 * effective_mass * omega) {
        // `2 m` overflowed against an infinite damping: divide in another order.
        z if z.is_nan() => d / effective_mass / (2.0 * omega),
        z => z,
    };
    // `sqrt(1 + zeta^2) - zeta` cancels for a huge damping ratio (and is NaN for an infinite
    // one): its asymptote `1/(2 zeta)` there.
    let root = if zeta > 1e8 {
        0.5 / zeta
    } else {
        (1.0 + zeta * zeta).sqrt() - zeta
    };
    (2.0 * root / omega, omega, zeta)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::laws::{Bai, FrictionModel, Hertz};

    fn geometry() -> BearingGeometry {
        BearingGeometry::new(0.010, 0.0095, 0.016).unwrap()
    }

    #[test]
    fn the_rate_at_the_state_by_hand() {
        // m = 2 kg, h = 1e-3 s, stored 0.5 m/s, rest 10 m/s², F = 40 N, D = 1000 N s/m:
        // 0.5 + 5e-4 (10 - 20)/(1 + 5e-4 * 500) = 0.5 - 5e-3/1.25 = 0.496.
        let v = rate_at_state(0.5, 1e-3, 10.0, 40.0, 1000.0, 2.0);
        assert!((v - 0.496).abs() < 1e-15, "{v}");
        // No step: the stored rate. No mass to move: the stored rate, never NaN.
        assert_eq!(rate_at_state(0.5, 0.0, 10.0, 40.0, 1000.0, 2.0), 0.5);
        assert_eq!(rate_at_state(0.5, 1e-3, 10.0, 40.0, 1000.0, 0.0), 0.5);
        // (0.3 - 0.1)/2e-3 + 40/2 = 120 m/s².
        let a = rest_acceleration(0.1, 0.3, 2e-3, 40.0, 2.0);
        assert!((a - 120.0).abs() < 1e-12, "{a}");
        // Kelvin-Voigt 1e6 delta + 1e3 delta_dot: 1e-6 m in at 0.5 m/s gives 1 + 500 N, slope
        // 1e3; pulling out at 0.5 m/s, 1 - 500 < 0: no force, no damping.
        let law = crate::model::laws::KelvinVoigt::new(1e6, 1e3).unwrap();
        let at = |rate| NormalContact {
            penetration: 1e-6,
            penetration_rate: rate,
            impact_rate: 0.5,
        };
        assert_eq!(force_and_damping(&law, &at(0.5)), (501.0, 1e3));
        assert_eq!(force_and_damping(&law, &at(-0.5)), (0.0, 0.0));
    }

    #[test]
    fn the_rate_at_the_state_makes_a_damped_oscillator_second_order() {
        // m x'' = -k x - d x' + m sin(3t) by leapfrog with the force read at the stored velocity
        // (first order) and at the rate carried to the state (second order).
        let (m, k, d) = (1.0, 1.0, 1.0);
        let run = |h: f64, carried: bool| {
            let n = (10.0 / h).round() as usize;
            let (mut x, mut v, mut t) = (1.0_f64, 0.0_f64, 0.0_f64);
            let (mut v_before, mut f_before, mut h_before) = (0.0, 0.0, 0.0);
            for i in 0..n {
                let h_in = if i == 0 { 0.0 } else { h };
                let rate = if carried && i > 0 {
                    let kick = 0.5 * (h_before + h_in);
                    let rest = rest_acceleration(v_before, v, kick, f_before, m);
                    rate_at_state(v, h_in, rest, k * x + d * v, d, m)
                } else {
                    v
                };
                let f = k * x + d * rate;
                let kick = if i == 0 { 0.5 * h } else { h };
                (v_before, f_before, h_before) = (v, f, h_in);
                v += kick * (-f / m + (3.0 * t).sin());
                x += h * v;
                t += h;
            }
            x
        };
        let reference = run(1e-5, true);
        for (carried, lo, hi) in [(false, 1.8, 2.2), (true, 3.6, 5.0)] {
            let e: Vec<f64> = [0.02, 0.01, 0.005]
                .iter()
                .map(|&h| (run(h, carried) - reference).abs())
                .collect();
            for w in e.windows(2) {
                let ratio = w[0] / w[1];
                assert!(ratio > lo && ratio < hi, "carried {carried}: {e:?}");
            }
        }
    }

    #[test]
    fn eccentricity_penetration_and_rates_by_hand() {
        let axis = Vector::new(0.0, -1.0, 0.0);
        let p_i = Vector::new(0.4, 0.0, 0.4);
        // journal centre 0.6 mm along +x, plus an axial offset that must be ignored
        let p_j = p_i + Vector::new(0.6e-3, 0.003, 0.0);
        let bearing = BodyMotion::default();
        let journal = BodyMotion {
            center_of_mass: Vector::new(0.4, 0.0, 0.0),
            linvel: Vector::new(0.01, 0.0, 0.02),
            angvel: Vector::ZERO,
        };
        let s = journal_state(&geometry(), p_i, p_j, axis, &bearing, &journal);
        assert!((s.eccentricity - Vector::new(0.6e-3, 0.0, 0.0)).length() < 1e-15);
        assert!((s.penetration - 0.1e-3).abs() < 1e-15);
        assert!((s.normal - Vector::X).length() < 1e-15);
        assert!((s.penetration_rate - 0.01).abs() < 1e-15);
        assert!((s.slip - Vector::new(0.0, 0.0, 0.02)).length() < 1e-15);
        // The journal's centre moves with its body (no spin), the bearing's is at rest.
        assert!((s.eccentricity_rate - Vector::new(0.01, 0.0, 0.02)).length() < 1e-15);
        // Q_i = P_i + 10 mm x, Q_j = P_j + 9.5 mm x (axial offset kept): midpoint
        let expected = 0.5 * ((p_i + 0.010 * Vector::X) + (p_j + 0.0095 * Vector::X));
        assert!((s.contact_point - expected).length() < 1e-15);
    }

    #[test]
    fn rotation_adds_surface_velocity() {
        // Bearing spinning about the axis at w: its surface point Q_i moves at w x (Q_i - com).
        let axis = Vector::Z;
        let bearing = BodyMotion {
            center_of_mass: Vector::ZERO,
            linvel: Vector::ZERO,
            angvel: Vector::new(0.0, 0.0, 2.0),
        };
        let journal = BodyMotion::default();
        let s = journal_state(
            &geometry(),
            Vector::ZERO,
            Vector::new(1e-3, 0.0, 0.0),
            axis,
            &bearing,
            &journal,
        );
        // Q_i = (0.010, 0, 0) moves at (0, 0.02, 0); v_rel = -(0, 0.02, 0): pure slip
        assert!(s.penetration_rate.abs() < 1e-15);
        assert!((s.slip - Vector::new(0.0, -0.02, 0.0)).length() < 1e-15);
        // The centres do not move relative to each other: a spin is no path across the gap.
        assert!(s.eccentricity_rate.length() < 1e-15);
    }

    #[test]
    fn force_pair_opposes_penetration_and_slip() {
        let s = JournalState {
            eccentricity: Vector::X * 0.5001e-3,
            normal: Vector::X,
            penetration: 1e-7,
            penetration_rate: 0.0,
            slip: Vector::new(0.0, 0.0, 1.0),
            eccentricity_rate: Vector::ZERO,
            contact_point: Vector::ZERO,
        };
        let law = Hertz::new(1e12, 1.5).unwrap();
        let f = contact_force(&s, 1.0, &law, &FrictionModel::Bai(Bai::DRY));
        // F_N = 1e12 * 1e-7^1.5 = 1e12 * 3.1623e-11 = 31.623 N, friction 0.25 F_N along -z
        assert!((f.normal_force - 31.622776601683793).abs() < 1e-9);
        assert!(
            (f.on_journal - Vector::new(-f.normal_force, 0.0, -0.25 * f.normal_force)).length()
                < 1e-9
        );
    }

    #[test]
    fn stable_step_by_hand() {
        // undamped: 2/omega; omega = sqrt(4e8/4) = 1e4
        let (dt, omega, zeta) = stable_step(4e8, 0.0, 4.0);
        assert!((omega - 1e4).abs() < 1e-9 && zeta == 0.0 && (dt - 2e-4).abs() < 1e-15);
        // zeta = 1: 2 (sqrt 2 - 1)/omega
        let (dt, _, zeta) = stable_step(4e8, 2.0 * 4.0 * 1e4, 4.0);
        assert!((zeta - 1.0).abs() < 1e-15 && (dt - 2.0 * (2f64.sqrt() - 1.0) / 1e4).abs() < 1e-15);
        assert!(stable_step(0.0, 0.0, 1.0).0.is_infinite());
        // pure damping: 2 m/d
        assert!((stable_step(0.0, 4.0, 2.0).0 - 1.0).abs() < 1e-15);
        assert!((stable_step(-5.0, 8.0, 2.0).0 - 0.5).abs() < 1e-15);
    }
}
