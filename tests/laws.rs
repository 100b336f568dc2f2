//! Independent checks of the contact and friction laws against MODEL.md §1-§3.
//!
//! Every expected number below is derived by hand from MODEL.md (the arithmetic is in the comments)
//! and recomputed in the test from the formula as written in MODEL.md, never through the crate's
//! own helpers (`step`, `sigma`, `effective_modulus`, `hysteresis_factor`, ...).

use clearance_joint::model::kinematics::*;
use clearance_joint::model::laws::*;
use proptest::prelude::*;
use rapier3d_f64::math::Vector;
use std::f64::consts::PI;

// ---------------------------------------------------------------------------------------------
// Helpers written from MODEL.md, independent of src/
// ---------------------------------------------------------------------------------------------

/// `|a - b| <= rel * |b|` (with `b` the expected value).
#[track_caller]
fn close(actual: f64, expected: f64, rel: f64) {
    let tol = rel * expected.abs();
    assert!(
        (actual - expected).abs() <= tol,
        "actual {actual:e}, expected {expected:e} (rel. error {:e}, allowed {rel:e})",
        (actual - expected).abs() / expected.abs().max(f64::MIN_POSITIVE)
    );
}

fn contact(delta: f64, rate: f64, rate0: f64) -> NormalContact {
    NormalContact {
        penetration: delta,
        penetration_rate: rate,
        impact_rate: rate0,
    }
}

/// MSC Adams STEP as written in MODEL.md §2 (own copy, not the crate's).
fn adams_step(x: f64, x0: f64, h0: f64, x1: f64, h1: f64) -> f64 {
    if x <= x0 {
        h0
    } else if x >= x1 {
        h1
    } else {
        let s = (x - x0) / (x1 - x0);
        h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)
    }
}

/// Paper's table 2 steel: `sigma = (1 - 0.3^2)/207e9 = 0.91/207e9 = 4.396135265700483e-12 1/Pa`.
const SIGMA_STEEL: f64 = 0.91 / 207e9;
/// `E* = 1/(sigma_i + sigma_j) = 207e9/1.82 = 1.1373626373626373e11 Pa`.
const E_STAR_STEEL: f64 = 207e9 / 1.82;

/// `F_K = (pi/2) E* L sqrt(delta/(2(c+delta))) delta^n` (MODEL.md §2).
fn improved_elastic(e_star: f64, l: f64, c: f64, n: f64, delta: f64) -> f64 {
    if delta <= 0.0 {
        return 0.0;
    }
    0.5 * PI * e_star * l * (delta / (2.0 * (c + delta))).sqrt() * delta.powf(n)
}

/// Hand derivation of `K_N = dF_K/d delta` (eq. 17). Write `F_K = s delta^(n+1/2) (2(c+delta))^(-1/2)`
/// with `s = (pi/2) E* L`. Product rule:
///   dF_K/d delta = s [ (n+1/2) delta^(n-1/2) (2(c+delta))^(-1/2) - delta^(n+1/2) (2(c+delta))^(-3/2) ]
///                = s delta^(n-1/2) (2(c+delta))^(-1/2) [ n + 1/2 - delta/(2(c+delta)) ]
///                = s delta^(n-1/2) (2(c+delta))^(-1/2) [ n + c/(2(c+delta)) ].
fn improved_tangent(e_star: f64, l: f64, c: f64, n: f64, delta: f64) -> f64 {
    let s = 0.5 * PI * e_star * l;
    s * delta.powf(n - 0.5) / (2.0 * (c + delta)).sqrt() * (n + c / (2.0 * (c + delta)))
}

#[track_caller]
fn err_names<T: std::fmt::Debug>(r: clearance_joint::Result<T>, field: &str) {
    let msg = r
        .expect_err(&format!("expected an error naming `{field}`"))
        .to_string();
    assert!(
        msg.contains(field),
        "error message does not name `{field}`: {msg}"
    );
}

// ---------------------------------------------------------------------------------------------
// 1. Hand values: normal laws
// ---------------------------------------------------------------------------------------------

#[test]
fn hertz_hand_values() {
    // K = 2e9 N/m^1.5, n = 1.5, delta = 4e-6 m: delta^1.5 = (4e-6)^1.5 = 8e-9, F = 2e9 * 8e-9 = 16 N.
    let h = Hertz::new(2e9, 1.5).unwrap();
    let expected = 2e9 * 4e-6f64.powf(1.5);
    close(expected, 16.0, 1e-12);
    close(h.normal_force(&contact(4e-6, 0.0, 1.0)), expected, 1e-12);
    // purely elastic: the rate changes nothing
    close(h.normal_force(&contact(4e-6, -5.0, 1.0)), 16.0, 1e-12);
    close(h.normal_force(&contact(4e-6, 5.0, 0.1)), 16.0, 1e-12);
    // tangent stiffness K n delta^(n-1) = 2e9 * 1.5 * 2e-3 = 6e6 N/m
    close(h.tangent_stiffness(4e-6), 6e6, 1e-12);
    // linear Hertz (n = 1): K = 5e6 N/m, delta = 3e-5 -> 150 N
    close(
        Hertz::new(5e6, 1.0)
            .unwrap()
            .normal_force(&contact(3e-5, 1.0, 1.0)),
        150.0,
        1e-12,
    );
    // no contact
    assert_eq!(h.normal_force(&contact(0.0, 1.0, 1.0)), 0.0);
    assert_eq!(h.normal_force(&contact(-1e-6, 1.0, 1.0)), 0.0);
}

#[test]
fn kelvin_voigt_hand_values() {
    // K = 1e7 N/m, D = 2e3 N s/m, delta = 1e-5 m, delta_dot = 0.01 m/s: 1e7*1e-5 + 2e3*0.01 = 100 + 20 = 120 N
    let kv = KelvinVoigt::new(1e7, 2e3).unwrap();
    close(
        kv.normal_force(&contact(1e-5, 0.01, 1.0)),
        1e7 * 1e-5 + 2e3 * 0.01,
        1e-12,
    );
    close(kv.normal_force(&contact(1e-5, 0.01, 1.0)), 120.0, 1e-12);
    // separating at 0.02 m/s: 100 - 40 = 60 N
    close(kv.normal_force(&contact(1e-5, -0.02, 1.0)), 60.0, 1e-12);
    // separating at 0.1 m/s: 100 - 200 = -100 N -> clamped at 0 (F_N >= 0, MODEL.md §1)
    assert_eq!(kv.normal_force(&contact(1e-5, -0.1, 1.0)), 0.0);
    // no contact, even while approaching
    assert_eq!(kv.normal_force(&contact(-1e-9, 10.0, 1.0)), 0.0);
    // Kelvin-Voigt is discontinuous at delta = 0 by its MODEL.md definition: at delta -> 0+ the
    // force tends to D delta_dot = 2e3 * 0.01 = 20 N while approaching (documented, not a bug).
    close(kv.normal_force(&contact(1e-300, 0.01, 1.0)), 20.0, 1e-12);
}

/// `K delta^n (1 + chi delta_dot/delta_dot0)`, clamped at 0, from MODEL.md §2.
fn hysteresis_expected(k: f64, n: f64, chi: f64, delta: f64, rate: f64, rate0: f64) -> f64 {
    (k * delta.powf(n) * (1.0 + chi * rate / rate0)).max(0.0)
}

#[test]
fn hunt_crossley_hand_values() {
    // cr = 0.8: chi = 3(1-0.8)/2 = 0.3. K = 1e10, n = 1.5, delta = 1e-6: K delta^1.5 = 1e10*1e-9 = 10 N.
    // delta_dot/delta_dot0 = 0.5/2 = 0.25: F = 10 (1 + 0.3*0.25) = 10 * 1.075 = 10.75 N
    let law = HuntCrossley::new(1e10, 1.5, 0.8).unwrap();
    let chi = 3.0 * (1.0 - 0.8) / 2.0;
    let f = law.normal_force(&contact(1e-6, 0.5, 2.0));
    close(
        f,
        hysteresis_expected(1e10, 1.5, chi, 1e-6, 0.5, 2.0),
        1e-12,
    );
    close(f, 10.75, 1e-12);
    // restitution: delta_dot/delta_dot0 = -1 -> 10 (1 - 0.3) = 7 N
    close(law.normal_force(&contact(1e-6, -2.0, 2.0)), 7.0, 1e-12);
    // cr = 1 is elastic: chi = 0 -> 10 N whatever the rate
    close(
        HuntCrossley::new(1e10, 1.5, 1.0)
            .unwrap()
            .normal_force(&contact(1e-6, 3.0, 1.0)),
        10.0,
        1e-12,
    );
    assert!(law.uses_impact_rate());
}

#[test]
fn lankarani_nikravesh_stiffness_from_geometry_paper_steel() {
    // R_b = 10 mm, c = 0.5 mm -> R_j = 9.5 mm; steel E = 207 GPa, nu = 0.3 on both sides.
    // sigma_i + sigma_j = 2 * 0.91/207e9 = 8.792270531400966e-12 1/Pa
    // 4/(3 * 8.792270531400966e-12) = 1.5164835164835165e11
    // R_b R_j/(R_b - R_j) = 0.01 * 0.0095 / 0.0005 = 0.19 m, sqrt(0.19) = 0.4358898943540674
    // K = 1.5164835164835165e11 * 0.4358898943540674 = 6.610198397896845e10 N/m^1.5
    let g = BearingGeometry::from_clearance(0.010, 0.0005, 0.016).unwrap();
    close(g.journal_radius(), 0.0095, 1e-12);
    close(g.clearance(), 0.0005, 1e-9);
    let k = LankaraniNikravesh::stiffness_from_geometry(&g, &Material::STEEL, &Material::STEEL);
    let expected =
        4.0 / (3.0 * (SIGMA_STEEL + SIGMA_STEEL)) * (0.010f64 * 0.0095 / (0.010 - 0.0095)).sqrt();
    close(k, expected, 1e-12);
    close(k, 6.610198397896845e10, 1e-9);

    // LN force with that K, n = 1.5, cr = 0.9: chi = 3(1-0.81)/4 = 0.1425.
    // delta = 1e-5: delta^1.5 = 3.1622776601683795e-8, K delta^1.5 = 2090.3282722950007 N.
    // delta_dot/delta_dot0 = 0.1/0.2 = 0.5: F = 2090.328272 * (1 + 0.07125) = 2239.2641616960195 N
    let ln = LankaraniNikravesh::new(k, LankaraniNikravesh::EXPONENT, 0.9).unwrap();
    assert_eq!(LankaraniNikravesh::EXPONENT, 1.5);
    let chi = 3.0 * (1.0 - 0.9 * 0.9) / 4.0;
    let f = ln.normal_force(&contact(1e-5, 0.1, 0.2));
    close(
        f,
        hysteresis_expected(expected, 1.5, chi, 1e-5, 0.1, 0.2),
        1e-12,
    );
    close(f, 2239.2641616960195, 1e-9);
    // elastic part alone
    close(ln.elastic_force(1e-5), 2090.3282722950007, 1e-9);
}

#[test]
fn flores_hand_values() {
    // cr = 0.5: chi = 8(1-0.5)/(5*0.5) = 4/2.5 = 1.6. K = 1e10, n = 1.5, delta = 1e-6 -> 10 N elastic.
    // ratio 0.5: F = 10 (1 + 0.8) = 18 N; ratio -0.5: F = 10 (1 - 0.8) = 2 N; ratio -1: 10 (1-1.6) < 0 -> 0.
    let law = FloresEtAl::new(1e10, 1.5, 0.5).unwrap();
    let chi = 8.0 * (1.0 - 0.5) / (5.0 * 0.5);
    close(
        law.normal_force(&contact(1e-6, 0.5, 1.0)),
        hysteresis_expected(1e10, 1.5, chi, 1e-6, 0.5, 1.0),
        1e-12,
    );
    close(law.normal_force(&contact(1e-6, 0.5, 1.0)), 18.0, 1e-12);
    close(law.normal_force(&contact(1e-6, -0.5, 1.0)), 2.0, 1e-12);
    assert_eq!(law.normal_force(&contact(1e-6, -1.0, 1.0)), 0.0);
    // cr = 0.8: chi = 8*0.2/4 = 0.4; ratio 1 -> 10 * 1.4 = 14 N
    close(
        FloresEtAl::new(1e10, 1.5, 0.8)
            .unwrap()
            .normal_force(&contact(1e-6, 3.0, 3.0)),
        14.0,
        1e-12,
    );
}

#[test]
fn gonthier_hand_values() {
    // cr = 0.5: chi = (1 - 0.25)/0.5 = 1.5. K = 1e10, n = 1.5, delta = 1e-6 -> 10 N elastic.
    // ratio 0.5: F = 10 (1 + 0.75) = 17.5 N; ratio -0.5: 10 (1 - 0.75) = 2.5 N; ratio -1: -5 -> 0.
    let law = GonthierEtAl::new(1e10, 1.5, 0.5).unwrap();
    let chi = (1.0 - 0.5 * 0.5) / 0.5;
    close(
        law.normal_force(&contact(1e-6, 1.0, 2.0)),
        hysteresis_expected(1e10, 1.5, chi, 1e-6, 1.0, 2.0),
        1e-12,
    );
    close(law.normal_force(&contact(1e-6, 1.0, 2.0)), 17.5, 1e-12);
    close(law.normal_force(&contact(1e-6, -1.0, 2.0)), 2.5, 1e-12);
    assert_eq!(law.normal_force(&contact(1e-6, -2.0, 2.0)), 0.0);
    // cr = 0.8: chi = 0.36/0.8 = 0.45; ratio 1 -> 14.5 N
    close(
        GonthierEtAl::new(1e10, 1.5, 0.8)
            .unwrap()
            .normal_force(&contact(1e-6, 1.0, 1.0)),
        14.5,
        1e-12,
    );
}

#[test]
fn liu_hand_values_paper_joint() {
    // Paper joint: E* = 207e9/1.82 = 1.1373626373626373e11 Pa, L = 16 mm, c = 0.5 mm.
    // (pi/2) E* L = 1.5707963267948966 * 1.1373626373626373e11 * 0.016 = 2.858504084804779e9 N/m
    // delta = 10 um: sqrt(1e-5/(2 * 5.1e-4)) = sqrt(9.803921568627451e-3) = 0.09901475429766743
    // F = 2.858504084804779e9 * 1e-5 * 0.09901475429766743 = 2830.3407961582393 N
    close(
        effective_modulus(&Material::STEEL, &Material::STEEL),
        E_STAR_STEEL,
        1e-12,
    );
    let liu = LiuEtAl::new(E_STAR_STEEL, 0.016, 5e-4).unwrap();
    let expected =
        0.5 * PI * E_STAR_STEEL * 0.016 * 1e-5 * (1e-5f64 / (2.0 * (5e-4 + 1e-5))).sqrt();
    close(liu.normal_force(&contact(1e-5, 0.0, 1.0)), expected, 1e-12);
    close(
        liu.normal_force(&contact(1e-5, 0.0, 1.0)),
        2830.3407961582393,
        1e-9,
    );
    // elastic only: the rate does nothing
    close(
        liu.normal_force(&contact(1e-5, -100.0, 1.0)),
        2830.3407961582393,
        1e-9,
    );
    // delta = c = 0.5 mm: sqrt(c/(4c)) = 0.5; F = 2.858504e9 * 5e-4 * 0.5 = 714626.0212011948 N
    close(
        liu.elastic_force(5e-4),
        2.858504084804779e9 * 5e-4 * 0.5,
        1e-9,
    );
    assert_eq!(liu.normal_force(&contact(-1e-6, 1.0, 1.0)), 0.0);
}

#[test]
fn improved_liu_elastic_and_tangent_stiffness_by_hand() {
    let (c, l) = (5e-4, 0.016);
    let s = 2.858504084804779e9; // (pi/2) E* L, see liu_hand_values_paper_joint
    // n = 1 is Liu's law: delta = 10 um -> 2830.3407961582393 N (as above)
    let n1 = ImprovedLiu::new(E_STAR_STEEL, l, c, 1.0, 1e-4, MaxDamping::Eta(0.0)).unwrap();
    close(n1.elastic_force(1e-5), 2830.3407961582393, 1e-9);
    // n = 1.5, delta = 100 um: sqrt(1e-4/(2*6e-4)) = sqrt(1/12) = 0.28867513459481287,
    // delta^1.5 = 1e-6: F_K = 2.858504e9 * 0.288675 * 1e-6 = 825.179051420842 N
    let n15 = ImprovedLiu::new(E_STAR_STEEL, l, c, 1.5, 1e-4, MaxDamping::Eta(0.0)).unwrap();
    close(
        n15.elastic_force(1e-4),
        improved_elastic(E_STAR_STEEL, l, c, 1.5, 1e-4),
        1e-12,
    );
    close(
        n15.elastic_force(1e-4),
        s * (1.0f64 / 12.0).sqrt() * 1e-6,
        1e-9,
    );
    close(n15.elastic_force(1e-4), 825.179051420842, 1e-9);

    // K_N = s delta^(n-1/2) (2(c+delta))^(-1/2) (n + c/(2(c+delta))) (derivation at improved_tangent).
    // n = 1, delta = 100 um: 2(c+delta) = 1.2e-3, c/(2(c+delta)) = 5/12 = 0.4166667,
    //   delta^0.5/sqrt(1.2e-3) = 0.01/0.034641016 = 0.28867513; K_N = s * 0.28867513 * 1.4166667
    //   = 2.858504e9 * 0.40895644 = 1.169003656179526e9 N/m
    close(n1.tangent_stiffness(1e-4), 1.169003656179526e9, 1e-9);
    // n = 1.5, delta = 100 um: delta^1/sqrt(1.2e-3) = 1e-4/0.034641016 = 2.8867513e-3;
    //   K_N = s * 2.8867513e-3 * (1.5 + 0.4166667) = 2.858504e9 * 5.5329400e-3 = 1.5815931818899473e7 N/m
    close(n15.tangent_stiffness(1e-4), 1.5815931818899473e7, 1e-9);
    // n = 1.5, delta = 10 um: 1.781289867139157e6 N/m (same formula)
    close(n15.tangent_stiffness(1e-5), 1.781289867139157e6, 1e-9);
    // and the hand formula against the code over a range of depths and exponents
    for n in [1.0, 1.2, 1.5, 2.0, 3.0] {
        let law = ImprovedLiu::new(E_STAR_STEEL, l, c, n, 1e-4, MaxDamping::Eta(0.0)).unwrap();
        for d in [1e-9, 1e-7, 3e-6, 1e-5, 1e-4, 5e-4, 2e-3] {
            close(
                law.tangent_stiffness(d),
                improved_tangent(E_STAR_STEEL, l, c, n, d),
                1e-12,
            );
            close(
                law.elastic_force(d),
                improved_elastic(E_STAR_STEEL, l, c, n, d),
                1e-12,
            );
            // and the hand derivative against a central difference of the hand force
            let h = d * 1e-5;
            let fd = (improved_elastic(E_STAR_STEEL, l, c, n, d + h)
                - improved_elastic(E_STAR_STEEL, l, c, n, d - h))
                / (2.0 * h);
            close(improved_tangent(E_STAR_STEEL, l, c, n, d), fd, 1e-7);
        }
    }
}

#[test]
fn improved_liu_max_damping_and_step_ramp() {
    let (c, l, dmax) = (5e-4, 0.016, ImprovedLiu::DEFAULT_DELTA_MAX);
    assert_eq!(dmax, 1e-4); // delta_max = 0.1 mm
    assert_eq!(ImprovedLiu::DEFAULT_ETA, 0.01); // eta = 1 % read as 0.01 s
    // D_max = eta K_N(delta_max) = 0.01 * 1.169003656179526e9 = 1.169003656179526e7 N s/m (n = 1)
    let law = ImprovedLiu::new(E_STAR_STEEL, l, c, 1.0, dmax, MaxDamping::Eta(0.01)).unwrap();
    let d_max = 0.01 * improved_tangent(E_STAR_STEEL, l, c, 1.0, dmax);
    close(law.max_damping(), d_max, 1e-12);
    close(law.max_damping(), 1.169003656179526e7, 1e-9);
    // n = 1.5: D_max = 0.01 * 1.5815931818899473e7 = 1.5815931818899473e5 N s/m
    let law15 = ImprovedLiu::new(E_STAR_STEEL, l, c, 1.5, dmax, MaxDamping::Eta(0.01)).unwrap();
    close(law15.max_damping(), 1.5815931818899473e5, 1e-9);

    // STEP ramp D_imp = STEP(delta, 0, 0, delta_max, D_max); F = F_K + D_imp delta_dot.
    let rate = 0.01; // m/s
    // delta = delta_max/4: s = 0.25, s^2 (3 - 2s) = 0.0625 * 2.5 = 0.15625
    let d = 0.25e-4;
    let expected = improved_elastic(E_STAR_STEEL, l, c, 1.0, d) + 0.15625 * d_max * rate;
    close(law.normal_force(&contact(d, rate, 1.0)), expected, 1e-12);
    close(
        law.damping_coefficient(&contact(d, rate, 1.0)),
        0.15625 * d_max,
        1e-12,
    );
    close(adams_step(d, 0.0, 0.0, dmax, d_max), 0.15625 * d_max, 1e-12);
    // F_K(25 um) = 11026.918904142527 N; + 0.15625 * 1.169003656e7 * 0.01 = 18265.6821 N -> 29292.6010 N
    close(
        law.normal_force(&contact(d, rate, 1.0)),
        11026.918904142527 + 0.15625 * 1.169003656179526e5,
        1e-9,
    );
    // delta = delta_max/2: s = 0.5 -> 0.25 * 2 = 0.5
    close(
        law.damping_coefficient(&contact(0.5e-4, rate, 1.0)),
        0.5 * d_max,
        1e-12,
    );
    // delta = 3/4 delta_max: s = 0.75 -> 0.5625 * 1.5 = 0.84375
    close(
        law.damping_coefficient(&contact(0.75e-4, rate, 1.0)),
        0.84375 * d_max,
        1e-12,
    );
    // at and beyond delta_max: D_max
    close(
        law.damping_coefficient(&contact(1e-4, rate, 1.0)),
        d_max,
        1e-12,
    );
    close(
        law.damping_coefficient(&contact(3e-4, rate, 1.0)),
        d_max,
        1e-12,
    );
    let expected = improved_elastic(E_STAR_STEEL, l, c, 1.0, 3e-4) + d_max * (-0.002);
    close(
        law.normal_force(&contact(3e-4, -0.002, 1.0)),
        expected,
        1e-12,
    );
    // the damping term never pulls: delta = 10 um, separating at 1 m/s:
    // F_K = 2830.34 N, D_imp = 1e7-ish * s^2(3-2s) with s = 0.1 -> 0.028 * 1.169e7 = 327328 N s/m
    // -> 2830 - 327328 < 0 -> 0
    assert_eq!(law.normal_force(&contact(1e-5, -1.0, 1.0)), 0.0);
    // the improved law does not read delta_dot0
    close(
        law.normal_force(&contact(0.5e-4, rate, 1e-6)),
        law.normal_force(&contact(0.5e-4, rate, 10.0)),
        1e-15,
    );

    // explicit D_max overrides eta
    let ex = ImprovedLiu::new(E_STAR_STEEL, l, c, 1.0, dmax, MaxDamping::Explicit(5e4)).unwrap();
    assert_eq!(ex.max_damping(), 5e4);
    // delta = delta_max/2, rate 0.01: F = F_K(50 um) + 0.5 * 5e4 * 0.01 = F_K + 250 N
    close(
        ex.normal_force(&contact(0.5e-4, 0.01, 1.0)),
        improved_elastic(E_STAR_STEEL, l, c, 1.0, 0.5e-4) + 250.0,
        1e-12,
    );
    // non-default delta_max = 50 um: D_max = eta K_N(50 um); at 25 um (s = 0.5) D = D_max/2
    let lw = ImprovedLiu::new(E_STAR_STEEL, l, c, 1.0, 5e-5, MaxDamping::Eta(0.02)).unwrap();
    let d_max = 0.02 * improved_tangent(E_STAR_STEEL, l, c, 1.0, 5e-5);
    close(lw.max_damping(), d_max, 1e-12);
    close(
        lw.damping_coefficient(&contact(2.5e-5, 0.0, 1.0)),
        0.5 * d_max,
        1e-12,
    );
}

#[test]
fn normal_model_dispatch_matches_laws() {
    let models = [
        (
            NormalModel::Hertz(Hertz::new(1e10, 1.5).unwrap()),
            10.0 * (1.0 + 0.0),
        ),
        // KV K = 1e7, D = 1e3: 1e7 * 1e-6 + 1e3 * 0.5 = 10 + 500 = 510 N
        (
            NormalModel::KelvinVoigt(KelvinVoigt::new(1e7, 1e3).unwrap()),
            510.0,
        ),
        // HC cr 0.8 chi 0.3, ratio 0.5: 10 * 1.15 = 11.5
        (
            NormalModel::HuntCrossley(HuntCrossley::new(1e10, 1.5, 0.8).unwrap()),
            11.5,
        ),
        // LN cr 0.8 chi 0.27, ratio 0.5: 10 * 1.135 = 11.35
        (
            NormalModel::LankaraniNikravesh(LankaraniNikravesh::new(1e10, 1.5, 0.8).unwrap()),
            11.35,
        ),
        // Flores cr 0.8 chi 0.4: 10 * 1.2 = 12
        (
            NormalModel::FloresEtAl(FloresEtAl::new(1e10, 1.5, 0.8).unwrap()),
            12.0,
        ),
        // Gonthier cr 0.8 chi 0.45: 10 * 1.225 = 12.25
        (
            NormalModel::GonthierEtAl(GonthierEtAl::new(1e10, 1.5, 0.8).unwrap()),
            12.25,
        ),
        // Liu E* = 1e11, L = 0.01, c = 1e-6: sqrt(1e-6/(4e-6)) = 0.5, (pi/2)*1e9*1e-6*0.5 = 250 pi
        (
            NormalModel::LiuEtAl(LiuEtAl::new(1e11, 0.01, 1e-6).unwrap()),
            250.0 * PI,
        ),
        // Improved n = 1, same as Liu, explicit D_max = 1e3, delta = delta_max -> + 1e3 * 0.5 = 500
        (
            NormalModel::ImprovedLiu(
                ImprovedLiu::new(1e11, 0.01, 1e-6, 1.0, 1e-6, MaxDamping::Explicit(1e3)).unwrap(),
            ),
            250.0 * PI + 500.0,
        ),
    ];
    for (m, expected) in models {
        close(m.normal_force(&contact(1e-6, 0.5, 1.0)), expected, 1e-12);
        assert_eq!(m.normal_force(&contact(0.0, 0.5, 1.0)), 0.0, "{}", m.name());
    }
}

// ---------------------------------------------------------------------------------------------
// 1. Hand values: friction laws
// ---------------------------------------------------------------------------------------------

#[test]
fn coulomb_hand_values() {
    // mu = mu_d min(1, v/v_eps), mu_d = 0.2, v_eps = 1 mm/s
    let f = Coulomb::new(0.2, 1e-3).unwrap();
    assert_eq!(f.coefficient(0.0), 0.0);
    close(f.coefficient(0.25e-3), 0.2 * 0.25, 1e-12); // 0.05
    close(f.coefficient(1e-3), 0.2, 1e-12);
    assert_eq!(f.coefficient(2e-3), 0.2);
    assert_eq!(f.coefficient(100.0), 0.2);
    assert_eq!(f.max_coefficient(), 0.2);
}

#[test]
fn threlfall_hand_values() {
    // mu = mu_d (1 - exp(-3 v/v0)), mu_d = 0.2, v0 = 1 mm/s
    let f = Threlfall::new(0.2, 1e-3).unwrap();
    assert_eq!(f.coefficient(0.0), 0.0);
    // v = v0/3: 0.2 (1 - e^-1) = 0.2 * 0.6321205588285577 = 0.12642411176571153
    close(f.coefficient(1e-3 / 3.0), 0.12642411176571153, 1e-12);
    // v = v0: 0.2 (1 - e^-3) = 0.2 * 0.950212931632136 = 0.1900425863264272
    close(f.coefficient(1e-3), 0.2 * (1.0 - (-3.0f64).exp()), 1e-12);
    close(f.coefficient(1e-3), 0.1900425863264272, 1e-12);
    close(f.coefficient(1.0), 0.2, 1e-12);
    assert_eq!(f.max_coefficient(), 0.2);
}

#[test]
fn ambrosio_hand_values() {
    // mu_d = 0.2, v0 = 1 mm/s, v1 = 3 mm/s: c_d = 0 (v <= v0), (v - v0)/(v1 - v0), 1 (v > v1)
    let f = Ambrosio::new(0.2, 1e-3, 3e-3).unwrap();
    assert_eq!(f.coefficient(0.0), 0.0);
    assert_eq!(f.coefficient(0.5e-3), 0.0);
    assert_eq!(f.coefficient(1e-3), 0.0);
    // v = 1.5 mm/s: c_d = 0.5/2 = 0.25 -> 0.05
    close(f.coefficient(1.5e-3), 0.05, 1e-12);
    // v = 2 mm/s: c_d = 0.5 -> 0.1
    close(f.coefficient(2e-3), 0.1, 1e-12);
    close(f.coefficient(3e-3), 0.2, 1e-12);
    assert_eq!(f.coefficient(5e-3), 0.2);
    assert_eq!(f.max_coefficient(), 0.2);
    // v0 = 0 allowed: linear from rest
    close(
        Ambrosio::new(0.4, 0.0, 2e-3).unwrap().coefficient(0.5e-3),
        0.1,
        1e-12,
    );
}

/// MODEL.md §3, Bai / Adams stiction, written from the spec with the local STEP.
fn bai_expected(mu_s: f64, mu_d: f64, v_s: f64, v_d: f64, v: f64) -> f64 {
    if v >= v_d {
        mu_d
    } else if v >= v_s {
        adams_step(v, v_s, mu_s, v_d, mu_d)
    } else {
        adams_step(v, -v_s, -mu_s, v_s, mu_s)
    }
}

#[test]
fn bai_table_3_hand_values() {
    // table 3: v_s = 0.1 mm/s = 1e-4 m/s, v_d = 10 mm/s = 1e-2 m/s
    assert_eq!(Bai::DRY, Bai::new(0.3, 0.25, 1e-4, 1e-2).unwrap());
    assert_eq!(Bai::LUBRICATED, Bai::new(0.08, 0.05, 1e-4, 1e-2).unwrap());
    assert_eq!(Bai::DRY.max_coefficient(), 0.3);
    assert_eq!(Bai::LUBRICATED.max_coefficient(), 0.08);

    for (law, mu_s, mu_d) in [(Bai::DRY, 0.3, 0.25), (Bai::LUBRICATED, 0.08, 0.05)] {
        // v = 0: odd STEP midpoint, s = (0 + v_s)/(2 v_s) = 0.5 -> -mu_s + 2 mu_s * 0.5 = 0
        assert!(law.coefficient(0.0).abs() < 1e-15);
        // v = v_s: mu_s; v = v_d: mu_d; beyond: mu_d
        close(law.coefficient(1e-4), mu_s, 1e-12);
        close(law.coefficient(1e-2), mu_d, 1e-12);
        assert_eq!(law.coefficient(1.0), mu_d);
        for v in [
            0.0, 1e-6, 3e-5, 0.5e-4, 0.99e-4, 1e-4, 2e-4, 2.575e-3, 5e-3, 9.99e-3, 1e-2, 0.5,
        ] {
            let e = bai_expected(mu_s, mu_d, 1e-4, 1e-2, v);
            assert!(
                (law.coefficient(v) - e).abs() <= 1e-14,
                "v = {v}: {} vs {e}",
                law.coefficient(v)
            );
        }
    }
    // v = v_s/2: s = (0.5e-4 + 1e-4)/2e-4 = 0.75, s^2 (3-2s) = 0.5625 * 1.5 = 0.84375,
    //   mu = -mu_s + 2 mu_s * 0.84375 = 0.6875 mu_s: dry 0.20625, lubricated 0.055
    close(Bai::DRY.coefficient(0.5e-4), 0.20625, 1e-12);
    close(Bai::LUBRICATED.coefficient(0.5e-4), 0.055, 1e-12);
    // v = v_s + (v_d - v_s)/4 = 1e-4 + 2.475e-3 = 2.575e-3: s = 0.25 -> 0.15625,
    //   mu = mu_s + (mu_d - mu_s) * 0.15625: dry 0.3 - 0.05*0.15625 = 0.2921875,
    //   lubricated 0.08 - 0.03 * 0.15625 = 0.0753125
    close(Bai::DRY.coefficient(2.575e-3), 0.2921875, 1e-12);
    close(Bai::LUBRICATED.coefficient(2.575e-3), 0.0753125, 1e-12);
    // v = 5 mm/s, lubricated: s = 4.9e-3/9.9e-3 = 0.494949..., s^2(3-2s) = 0.4924242...,
    //   mu = 0.08 - 0.03 * 0.4924242 = 0.06522726499769659
    close(
        Bai::LUBRICATED.coefficient(5e-3),
        0.06522726499769659,
        1e-12,
    );
}

#[test]
fn frictionless_is_zero() {
    for v in [0.0, 1e-9, 1e-3, 1.0, 1e6] {
        assert_eq!(Frictionless.coefficient(v), 0.0);
        assert_eq!(FrictionModel::None.coefficient(v), 0.0);
    }
    assert_eq!(Frictionless.max_coefficient(), 0.0);
    assert_eq!(FrictionModel::None.max_coefficient(), 0.0);
}

#[test]
fn friction_model_dispatch_matches_laws() {
    let c = Coulomb::new(0.2, 1e-3).unwrap();
    let t = Threlfall::new(0.2, 1e-3).unwrap();
    let a = Ambrosio::new(0.2, 1e-3, 3e-3).unwrap();
    for v in [0.0, 0.5e-4, 1.5e-3, 1.0] {
        assert_eq!(FrictionModel::Coulomb(c).coefficient(v), c.coefficient(v));
        assert_eq!(FrictionModel::Threlfall(t).coefficient(v), t.coefficient(v));
        assert_eq!(FrictionModel::Ambrosio(a).coefficient(v), a.coefficient(v));
        assert_eq!(
            FrictionModel::Bai(Bai::DRY).coefficient(v),
            Bai::DRY.coefficient(v)
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Kinematics hand value (MODEL.md §1) feeding the laws
// ---------------------------------------------------------------------------------------------

#[test]
fn contact_force_hand_value_paper_joint() {
    // Bearing at the origin, axis z, journal centre at (0.51 mm, 0, 2 mm): the axial 2 mm is dropped,
    // e = (0.51 mm, 0, 0), |e| = 0.51 mm, c = 0.5 mm -> delta = 10 um, n = +x.
    let g = BearingGeometry::from_clearance(0.010, 0.0005, 0.016).unwrap();
    let bearing = BodyMotion::default();
    // journal translating at (0, 1, 0.3) m/s: v_rel = (0, 1, 0.3); delta_dot = 0; slip = (0, 1, 0)
    let journal = BodyMotion {
        center_of_mass: Vector::new(0.0, 0.0, 0.002),
        linvel: Vector::new(0.0, 1.0, 0.3),
        angvel: Vector::ZERO,
    };
    let st = journal_state(
        &g,
        Vector::ZERO,
        Vector::new(0.51e-3, 0.0, 0.002),
        Vector::Z,
        &bearing,
        &journal,
    );
    assert!((st.penetration - 1e-5).abs() < 1e-15, "{}", st.penetration);
    assert!((st.normal - Vector::X).length() < 1e-12);
    assert!(st.penetration_rate.abs() < 1e-15);
    assert!((st.slip - Vector::new(0.0, 1.0, 0.0)).length() < 1e-15);
    // Q_i = (10 mm, 0, 0), Q_j = (0.51 + 9.5 mm, 0, 2 mm) = (10.01 mm, 0, 2 mm); midpoint (10.005 mm, 0, 1 mm)
    assert!((st.contact_point - Vector::new(10.005e-3, 0.0, 1e-3)).length() < 1e-15);

    // ImprovedLiu, n = 1, eta = 0.01: F_N = F_K(10 um) = 2830.3407961582393 N (delta_dot = 0)
    // lubricated Bai at v = 1 m/s >= v_d: mu = 0.05 -> friction 141.51703980791197 N along -y
    let law =
        ImprovedLiu::new(E_STAR_STEEL, 0.016, 5e-4, 1.0, 1e-4, MaxDamping::Eta(0.01)).unwrap();
    let f = contact_force(&st, 1.0, &law, &Bai::LUBRICATED);
    close(f.normal_force, 2830.3407961582393, 1e-9);
    close(f.friction_force, 141.51703980791197, 1e-9);
    let expected = Vector::new(-2830.3407961582393, -141.51703980791197, 0.0);
    assert!(
        (f.on_journal - expected).length() < 1e-9 * expected.length(),
        "{:?}",
        f.on_journal
    );
    assert!((f.point - st.contact_point).length() == 0.0);

    // free flight: no force at all
    let st_free = journal_state(
        &g,
        Vector::ZERO,
        Vector::new(0.4e-3, 0.0, 0.0),
        Vector::Z,
        &bearing,
        &journal,
    );
    assert!(st_free.penetration < 0.0);
    let f = contact_force(&st_free, 1.0, &law, &Bai::DRY);
    assert_eq!(f.on_journal, Vector::ZERO);
    assert_eq!(f.normal_force, 0.0);
}

// ---------------------------------------------------------------------------------------------
// 3. Invalid parameters are errors naming the parameter
// ---------------------------------------------------------------------------------------------

#[test]
fn invalid_normal_parameters_are_named() {
    err_names(Hertz::new(-1.0, 1.5), "stiffness");
    err_names(Hertz::new(0.0, 1.5), "stiffness");
    err_names(Hertz::new(f64::NAN, 1.5), "stiffness");
    err_names(Hertz::new(f64::INFINITY, 1.5), "stiffness");
    err_names(Hertz::new(1e9, f64::NAN), "exponent");
    err_names(Hertz::new(1e9, 0.5), "exponent");
    err_names(KelvinVoigt::new(-1e7, 1.0), "stiffness");
    err_names(KelvinVoigt::new(1e7, -1.0), "damping");
    err_names(KelvinVoigt::new(1e7, f64::NAN), "damping");
    // restitution must be in (0, 1]
    err_names(HuntCrossley::new(1e9, 1.5, 0.0), "restitution");
    err_names(HuntCrossley::new(1e9, 1.5, 1.0 + 1e-12), "restitution");
    err_names(HuntCrossley::new(1e9, 1.5, f64::NAN), "restitution");
    err_names(HuntCrossley::new(-1e9, 1.5, 0.5), "stiffness");
    err_names(LankaraniNikravesh::new(1e9, 1.5, 0.0), "restitution");
    err_names(LankaraniNikravesh::new(1e9, 1.5, 1.5), "restitution");
    err_names(LankaraniNikravesh::new(1e9, 1.5, -0.5), "restitution");
    err_names(FloresEtAl::new(1e9, 1.5, 0.0), "restitution");
    err_names(FloresEtAl::new(1e9, 1.5, 2.0), "restitution");
    err_names(GonthierEtAl::new(1e9, 1.5, 0.0), "restitution");
    err_names(GonthierEtAl::new(1e9, 1.5, 1.01), "restitution");
    err_names(GonthierEtAl::new(f64::NAN, 1.5, 0.5), "stiffness");
    // cr = 1 is valid (elastic limit)
    assert!(FloresEtAl::new(1e9, 1.5, 1.0).is_ok());
    err_names(LiuEtAl::new(-1.0, 0.016, 5e-4), "effective_modulus");
    err_names(LiuEtAl::new(1e11, 0.0, 5e-4), "length");
    err_names(LiuEtAl::new(1e11, 0.016, 0.0), "clearance");
    err_names(LiuEtAl::new(1e11, 0.016, f64::NAN), "clearance");
    let eta = MaxDamping::Eta(0.01);
    err_names(
        ImprovedLiu::new(f64::NAN, 0.016, 5e-4, 1.0, 1e-4, eta),
        "effective_modulus",
    );
    err_names(
        ImprovedLiu::new(1e11, -0.016, 5e-4, 1.0, 1e-4, eta),
        "length",
    );
    err_names(
        ImprovedLiu::new(1e11, 0.016, -5e-4, 1.0, 1e-4, eta),
        "clearance",
    );
    err_names(
        ImprovedLiu::new(1e11, 0.016, 5e-4, 0.5, 1e-4, eta),
        "exponent",
    );
    err_names(
        ImprovedLiu::new(1e11, 0.016, 5e-4, f64::NAN, 1e-4, eta),
        "exponent",
    );
    err_names(
        ImprovedLiu::new(1e11, 0.016, 5e-4, 1.0, 0.0, eta),
        "delta_max",
    );
    err_names(
        ImprovedLiu::new(1e11, 0.016, 5e-4, 1.0, 1e-4, MaxDamping::Eta(-0.01)),
        "eta",
    );
    err_names(
        ImprovedLiu::new(1e11, 0.016, 5e-4, 1.0, 1e-4, MaxDamping::Eta(f64::NAN)),
        "eta",
    );
    err_names(
        ImprovedLiu::new(1e11, 0.016, 5e-4, 1.0, 1e-4, MaxDamping::Explicit(-1.0)),
        "d_max",
    );
    // NaN is reported as such
    let msg = Hertz::new(f64::NAN, 1.5).unwrap_err().to_string();
    assert!(msg.contains("NaN"), "{msg}");
}

#[test]
fn invalid_friction_parameters_are_named() {
    err_names(Coulomb::new(-0.1, 1e-3), "mu_d");
    err_names(Coulomb::new(f64::NAN, 1e-3), "mu_d");
    err_names(Coulomb::new(0.1, 0.0), "v_eps");
    err_names(Threlfall::new(-0.1, 1e-3), "mu_d");
    err_names(Threlfall::new(0.1, 0.0), "v0");
    err_names(Threlfall::new(0.1, f64::NAN), "v0");
    err_names(Ambrosio::new(-0.1, 0.0, 1e-3), "mu_d");
    err_names(Ambrosio::new(0.1, -1e-3, 1e-3), "v0");
    err_names(Ambrosio::new(0.1, 2e-3, 1e-3), "v1");
    err_names(Ambrosio::new(0.1, 1e-3, 1e-3), "v1");
    err_names(Bai::new(-0.3, 0.25, 1e-4, 1e-2), "mu_s");
    err_names(Bai::new(0.3, f64::NAN, 1e-4, 1e-2), "mu_d");
    err_names(Bai::new(0.3, 0.25, 0.0, 1e-2), "v_s");
    err_names(Bai::new(0.3, 0.25, 1e-4, f64::NAN), "v_d");
    // v_d <= v_s
    err_names(Bai::new(0.3, 0.25, 1e-2, 1e-4), "v_d");
    err_names(Bai::new(0.3, 0.25, 1e-3, 1e-3), "v_d");
}

#[test]
fn invalid_geometry_and_material_are_named() {
    // journal_radius >= bearing_radius
    err_names(BearingGeometry::new(0.010, 0.010, 0.016), "journal_radius");
    err_names(BearingGeometry::new(0.010, 0.011, 0.016), "journal_radius");
    err_names(BearingGeometry::new(0.0, 0.0095, 0.016), "bearing_radius");
    err_names(
        BearingGeometry::new(0.010, -0.0095, 0.016),
        "journal_radius",
    );
    err_names(BearingGeometry::new(0.010, 0.0095, 0.0), "length");
    err_names(BearingGeometry::new(0.010, 0.0095, f64::NAN), "length");
    // clearance <= 0
    err_names(
        BearingGeometry::from_clearance(0.010, 0.0, 0.016),
        "clearance",
    );
    err_names(
        BearingGeometry::from_clearance(0.010, -1e-4, 0.016),
        "clearance",
    );
    err_names(
        BearingGeometry::from_clearance(0.010, f64::NAN, 0.016),
        "clearance",
    );
    err_names(
        BearingGeometry::from_clearance(0.010, 0.010, 0.016),
        "clearance",
    );
    err_names(Material::new(-207e9, 0.3), "youngs_modulus_pa");
    err_names(Material::new(207e9, 0.6), "poisson_ratio");
    err_names(Material::new(207e9, -1.0), "poisson_ratio");
    assert!(Material::new(207e9, 0.5).is_ok());
    assert!(BearingGeometry::new(0.010, 0.0095, 0.016).is_ok());
}

// ---------------------------------------------------------------------------------------------
// 2. Properties
// ---------------------------------------------------------------------------------------------

/// `10^x` for x uniform in `[lo, hi)`: a log-uniform positive number.
fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> + Clone {
    (lo..hi).prop_map(|x| 10f64.powf(x))
}

/// Any normal law of MODEL.md §2 with random valid parameters.
fn normal_model() -> impl Strategy<Value = NormalModel> {
    let k = log_uniform(3.0, 12.0);
    let n = 1.0..3.0f64;
    let cr = prop_oneof![0.05..1.0f64, Just(1.0)];
    let e_star = log_uniform(9.0, 12.0);
    let len = log_uniform(-3.0, 0.0);
    let c = log_uniform(-6.0, -2.0);
    let dmax = log_uniform(-6.0, -3.0);
    let damping = prop_oneof![
        (0.0..0.1f64).prop_map(MaxDamping::Eta),
        (0.0..1e9f64).prop_map(MaxDamping::Explicit)
    ];
    prop_oneof![
        (k.clone(), n.clone()).prop_map(|(k, n)| NormalModel::Hertz(Hertz::new(k, n).unwrap())),
        (k.clone(), 0.0..1e6f64)
            .prop_map(|(k, d)| NormalModel::KelvinVoigt(KelvinVoigt::new(k, d).unwrap())),
        (k.clone(), n.clone(), cr.clone())
            .prop_map(|(k, n, cr)| NormalModel::HuntCrossley(HuntCrossley::new(k, n, cr).unwrap())),
        (k.clone(), n.clone(), cr.clone()).prop_map(|(k, n, cr)| NormalModel::LankaraniNikravesh(
            LankaraniNikravesh::new(k, n, cr).unwrap()
        )),
        (k.clone(), n.clone(), cr.clone())
            .prop_map(|(k, n, cr)| NormalModel::FloresEtAl(FloresEtAl::new(k, n, cr).unwrap())),
        (k, n.clone(), cr)
            .prop_map(|(k, n, cr)| NormalModel::GonthierEtAl(GonthierEtAl::new(k, n, cr).unwrap())),
        (e_star.clone(), len.clone(), c.clone())
            .prop_map(|(e, l, c)| NormalModel::LiuEtAl(LiuEtAl::new(e, l, c).unwrap())),
        (e_star, len, c, n, dmax, damping).prop_map(
            |(e, l, c, n, dm, d)| NormalModel::ImprovedLiu(
                ImprovedLiu::new(e, l, c, n, dm, d).unwrap()
            )
        ),
    ]
}

/// Any friction law of MODEL.md §3 with random valid parameters (and the paper's two Bai sets).
fn friction_model() -> impl Strategy<Value = FrictionModel> {
    let mu = 0.0..1.0f64;
    prop_oneof![
        Just(FrictionModel::None),
        (mu.clone(), log_uniform(-6.0, 0.0))
            .prop_map(|(m, v)| FrictionModel::Coulomb(Coulomb::new(m, v).unwrap())),
        (mu.clone(), log_uniform(-6.0, 0.0))
            .prop_map(|(m, v)| FrictionModel::Threlfall(Threlfall::new(m, v).unwrap())),
        (
            mu.clone(),
            prop_oneof![Just(0.0), log_uniform(-6.0, -1.0)],
            log_uniform(-6.0, -1.0)
        )
            .prop_map(|(m, v0, w)| FrictionModel::Ambrosio(Ambrosio::new(m, v0, v0 + w).unwrap())),
        (
            mu.clone(),
            mu,
            log_uniform(-6.0, -2.0),
            log_uniform(-3.0, 2.0)
        )
            .prop_map(|(ms, md, vs, r)| FrictionModel::Bai(
                Bai::new(ms, md, vs, vs * (1.0 + r)).unwrap()
            )),
        Just(FrictionModel::Bai(Bai::DRY)),
        Just(FrictionModel::Bai(Bai::LUBRICATED)),
    ]
}

/// A slip speed: exactly 0, tiny, or anywhere up to 100 m/s on a log scale.
fn slip_speed() -> impl Strategy<Value = f64> {
    prop_oneof![Just(0.0), log_uniform(-12.0, 2.0), 0.0..0.02f64]
}

/// A unit vector (rejecting near-zero draws).
fn unit_vector() -> impl Strategy<Value = Vector> {
    (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64)
        .prop_filter("non-degenerate", |(x, y, z)| x * x + y * y + z * z > 0.01)
        .prop_map(|(x, y, z)| Vector::new(x, y, z).normalize())
}

fn vec3(scale: f64) -> impl Strategy<Value = Vector> {
    (-scale..scale, -scale..scale, -scale..scale).prop_map(|(x, y, z)| Vector::new(x, y, z))
}

fn body(pos: f64, lin: f64, ang: f64) -> impl Strategy<Value = BodyMotion> {
    (vec3(pos), vec3(lin), vec3(ang)).prop_map(|(c, v, w)| BodyMotion {
        center_of_mass: c,
        linvel: v,
        angvel: w,
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn normal_force_is_never_negative(
        law in normal_model(),
        delta in prop_oneof![-1e-2..1e-2f64, log_uniform(-15.0, -2.0)],
        rate in prop_oneof![-100.0..100.0f64, log_uniform(-9.0, 2.0), log_uniform(-9.0, 2.0).prop_map(|x| -x)],
        rate0 in prop_oneof![-10.0..10.0f64, log_uniform(-6.0, 1.0), Just(0.0)],
    ) {
        let f = law.normal_force(&contact(delta, rate, rate0));
        prop_assert!(f >= 0.0, "{}: F = {f} at delta {delta}, rate {rate}, rate0 {rate0}", law.name());
    }

    #[test]
    fn normal_force_is_zero_without_penetration(
        law in normal_model(),
        delta in prop_oneof![Just(0.0), Just(-0.0), -1.0..0.0f64, log_uniform(-15.0, 0.0).prop_map(|x| -x)],
        rate in -100.0..100.0f64,
        rate0 in -10.0..10.0f64,
    ) {
        prop_assert_eq!(law.normal_force(&contact(delta, rate, rate0)), 0.0, "{}", law.name());
    }

    /// With bounded rates (|delta_dot| <= 10 m/s, delta_dot0 in [1 mm/s, 10 m/s]) the force tends
    /// to 0 as delta -> 0+. Bounds from the MODEL.md formulas at the extreme parameters:
    /// hysteresis K delta^n (1 + chi 1e4) <= 1e12 delta * 3.1e5 (chi <= 30.4 for Flores, cr = 0.05),
    /// i.e. <= 3.1e-3 N at 1e-20 m, 3.1e-8 N at 1e-25 m, 3.1e-13 N at 1e-30 m; the Liu terms are far
    /// smaller (delta^1.5 and STEP ~ delta^2). Kelvin-Voigt is discontinuous at 0 by definition
    /// (K delta + D delta_dot -> D delta_dot), so for it only non-approaching rates are drawn.
    #[test]
    fn normal_force_is_continuous_at_zero(
        law in normal_model(),
        rate in -10.0..10.0f64,
        rate0 in 1e-3..10.0f64,
    ) {
        let rate = if matches!(law, NormalModel::KelvinVoigt(_)) { -rate.abs() } else { rate };
        for (eps, bound) in [(1e-20, 1e-2), (1e-25, 1e-6), (1e-30, 1e-10)] {
            let f = law.normal_force(&contact(eps, rate, rate0));
            prop_assert!(f <= bound, "{}: F({eps}) = {f} > {bound} (rate {rate}, rate0 {rate0})", law.name());
        }
    }

    #[test]
    fn friction_coefficient_is_bounded(law in friction_model(), v in slip_speed()) {
        let mu = law.coefficient(v);
        let max = law.max_coefficient();
        prop_assert!(mu >= 0.0, "{law:?}: mu({v}) = {mu} < 0");
        prop_assert!(mu <= max, "{law:?}: mu({v}) = {mu} > max {max}");
        prop_assert!(max.is_finite() && max >= 0.0);
    }

    /// Through `journal_state` and `contact_force`: the friction part of the force on the journal
    /// (`on_journal + F_N n`) is at most `max_coefficient F_N` and opposes the slip.
    #[test]
    fn contact_friction_is_bounded_and_opposes_slip(
        normal_law in normal_model(),
        friction in friction_model(),
        axis in unit_vector(),
        dir in unit_vector(),
        p_i in vec3(1.0),
        axial in -0.01..0.01f64,
        r_b in 1e-3..0.1f64,
        c_frac in 1e-3..0.2f64,
        delta_frac in prop_oneof![log_uniform(-6.0, -1.0), -0.5..0.5f64],
        bearing in body(1.0, 1.0, 10.0),
        journal in body(1.0, 1.0, 10.0),
        rate0 in log_uniform(-3.0, 1.0),
    ) {
        let c = r_b * c_frac;
        let geometry = BearingGeometry::new(r_b, r_b - c, 0.016).unwrap();
        // in-plane direction: dir with its axial part removed
        let radial = dir - dir.dot(axis) * axis;
        prop_assume!(radial.length() > 0.05);
        let radial = radial.normalize();
        let e = c * (1.0 + delta_frac);
        let p_j = p_i + e * radial + axial * axis;
        let st = journal_state(&geometry, p_i, p_j, axis, &bearing, &journal);
        let f = contact_force(&st, rate0, &normal_law, &friction);
        prop_assert!(f.normal_force >= 0.0);
        if st.penetration <= 0.0 {
            prop_assert_eq!(f.on_journal, Vector::ZERO);
            prop_assert_eq!(f.normal_force, 0.0);
            return Ok(());
        }
        let fn_ = f.normal_force;
        let fric = f.on_journal + fn_ * st.normal;
        let fric_mag = fric.length();
        let mu_max = friction.max_coefficient();
        let tol = 8.0 * f64::EPSILON * fn_;
        prop_assert!(
            fric_mag <= mu_max * fn_ * (1.0 + 1e-12) + tol,
            "{friction:?}: |F_t| = {fric_mag:e} > mu_max {mu_max} * F_N {fn_:e}"
        );
        prop_assert!(f.friction_force <= mu_max * fn_ * (1.0 + 1e-12));
        let slip = st.slip;
        prop_assert!(
            fric.dot(slip) <= 1e-12 * fn_ * slip.length(),
            "friction {fric:?} does not oppose slip {slip:?}"
        );
        // the normal part is -F_N n: what is left is in-plane and tangent (orthogonal to n and axis)
        // (loose tolerance: n is only perpendicular to the axis to rounding, and that error is
        // amplified by |v_rel|/|v_t| in v_t.n)
        let (fn_dot, fa_dot) = (fric.dot(st.normal), fric.dot(axis));
        prop_assert!(fn_dot.abs() <= 1e-9 * fn_ + tol, "F_t.n = {fn_dot:e}, F_N = {fn_:e}");
        prop_assert!(fa_dot.abs() <= 1e-9 * fn_ + tol, "F_t.a = {fa_dot:e}, F_N = {fn_:e}");
        // and the magnitude is mu(|v_t|) F_N
        let expected = friction.coefficient(slip.length()) * fn_;
        prop_assert!((fric_mag - expected).abs() <= 1e-12 * fn_ + tol, "{fric_mag:e} vs {expected:e}");
    }
}
