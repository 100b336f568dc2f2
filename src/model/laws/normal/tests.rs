use super::*;

#[test]
fn the_laws_clearance_must_be_the_bearings() {
    let law = NormalModel::ImprovedLiu(
        ImprovedLiu::new(1.137e11, 0.016, 0.5e-3, 1.0, 1e-4, MaxDamping::Eta(0.01)).unwrap(),
    );
    assert_eq!(law.clearance(), Some(0.5e-3));
    // The geometry's R_b - (R_b - c) differs from c in the last bits: accepted.
    let c = 0.010 - (0.010 - 0.5e-3);
    law.check_clearance("normal", c).unwrap();
    let e = law
        .check_clearance("normal", 0.2e-3)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`normal`") && e.contains("5e-4") && e.contains("2e-4"),
        "{e}"
    );
    let liu = NormalModel::LiuEtAl(LiuEtAl::new(1.137e11, 0.016, 0.3e-3).unwrap());
    assert!(liu.check_clearance("normal", 0.5e-3).is_err());
    // A law without a clearance agrees with any bearing.
    let hertz = NormalModel::Hertz(Hertz::new(1e10, 1.5).unwrap());
    assert_eq!(hertz.clearance(), None);
    hertz.check_clearance("normal", 0.5e-3).unwrap();
}

fn contact(delta: f64, rate: f64, rate0: f64) -> NormalContact {
    NormalContact {
        penetration: delta,
        penetration_rate: rate,
        impact_rate: rate0,
    }
}

#[test]
fn hertz_hand_values() {
    let h = Hertz::new(1e10, 1.5).unwrap();
    // 1e10 * (1e-6)^1.5 = 1e10 * 1e-9 = 10 N
    assert!((h.normal_force(&contact(1e-6, 1.0, 1.0)) - 10.0).abs() < 1e-9);
    assert!((h.tangent_stiffness(1e-6) - 1.5e7).abs() < 1e-3);
    assert!((h.elastic_energy(1e-6) - 10.0 * 1e-6 / 2.5).abs() < 1e-18);
    assert_eq!(h.normal_force(&contact(-1e-6, 1.0, 1.0)), 0.0);
}

#[test]
fn hysteresis_factors_hand_values() {
    let cr = 0.8;
    assert!((HuntCrossley::new(1.0, 1.5, cr).unwrap().hysteresis_factor() - 0.3).abs() < 1e-15);
    assert!(
        (LankaraniNikravesh::new(1.0, 1.5, cr)
            .unwrap()
            .hysteresis_factor()
            - 0.27)
            .abs()
            < 1e-15
    );
    assert!((FloresEtAl::new(1.0, 1.5, cr).unwrap().hysteresis_factor() - 0.4).abs() < 1e-15);
    assert!((GonthierEtAl::new(1.0, 1.5, cr).unwrap().hysteresis_factor() - 0.45).abs() < 1e-15);
    // LN at delta = 1e-6, K = 1e10: elastic 10 N; delta_dot/delta_dot0 = 0.5 -> 10 (1 + 0.135)
    let ln = LankaraniNikravesh::new(1e10, 1.5, cr).unwrap();
    assert!((ln.normal_force(&contact(1e-6, 0.5, 1.0)) - 11.35).abs() < 1e-9);
    // restitution phase with a large rate: clamped at 0, never pulling
    assert_eq!(ln.normal_force(&contact(1e-6, -10.0, 1.0)), 0.0);
}

#[test]
fn ln_stiffness_from_geometry_hand_value() {
    let g = super::super::BearingGeometry::new(0.01, 0.0095, 0.016).unwrap();
    let s = super::super::Material::STEEL;
    // sigma = 0.91/207e9 = 4.3961e-12; K = 4/(3*8.7923e-12) * sqrt(0.01*0.0095/0.0005) = 1.5165e11 * 0.43589
    let k = LankaraniNikravesh::stiffness_from_geometry(&g, &s, &s);
    let expected = 4.0 / (3.0 * 2.0 * 0.91 / 207e9) * (0.01f64 * 0.0095 / 0.0005).sqrt();
    assert!((k - expected).abs() / expected < 1e-14);
    assert!((k - 6.6104e10).abs() / 6.6104e10 < 1e-4, "{k}");
}

#[test]
fn liu_and_improved_hand_values() {
    // E* = 1e11, L = 0.01 -> scale = pi/2 * 1e9; c = 1e-4, delta = 1e-4:
    // sqrt(1e-4/(2*2e-4)) = 0.5; Liu F = scale * 1e-4 * 0.5
    let liu = LiuEtAl::new(1e11, 0.01, 1e-4).unwrap();
    let scale = 0.5 * PI * 1e9;
    assert!((liu.elastic_force(1e-4) - scale * 0.5e-4).abs() < 1e-6);
    // improved with n = 1 and no damping equals Liu
    let imp = ImprovedLiu::new(1e11, 0.01, 1e-4, 1.0, 1e-4, MaxDamping::Eta(0.0)).unwrap();
    assert!((imp.elastic_force(3e-6) - liu.elastic_force(3e-6)).abs() < 1e-9);
    assert!((imp.tangent_stiffness(3e-6) - liu.tangent_stiffness(3e-6)).abs() < 1e-3);
    // K_N at delta = c = 1e-4 with n = 1: g = 0.5, g' = c/(4 (2c)^2 g) = 1/(8c) = 1250;
    // K_N = scale (0.5 + 1e-4 * 1250) = scale * 0.625
    assert!((imp.tangent_stiffness(1e-4) - scale * 0.625).abs() < 1e-3);
    // eta = 0.01 s -> D_max = 0.01 * K_N(delta_max)
    let imp = ImprovedLiu::new(1e11, 0.01, 1e-4, 1.0, 1e-4, MaxDamping::Eta(0.01)).unwrap();
    assert!((imp.max_damping() - 0.01 * scale * 0.625).abs() < 1e-6);
    // D_imp at delta_max/2 = D_max/2 (STEP midpoint); force = F_K + D delta_dot
    let c = contact(0.5e-4, 0.001, 1.0);
    let expected = imp.elastic_force(0.5e-4) + 0.5 * imp.max_damping() * 0.001;
    assert!((imp.normal_force(&c) - expected).abs() < 1e-6 * expected);
}

#[test]
fn tangent_stiffness_matches_finite_difference() {
    let laws = [
        NormalModel::ImprovedLiu(
            ImprovedLiu::new(1.1e11, 0.016, 5e-4, 1.5, 1e-4, MaxDamping::Eta(0.01)).unwrap(),
        ),
        NormalModel::LiuEtAl(LiuEtAl::new(1.1e11, 0.016, 5e-4).unwrap()),
        NormalModel::Hertz(Hertz::new(1e10, 1.5).unwrap()),
    ];
    for law in laws {
        for d in [1e-7, 2e-6, 5e-5] {
            let h = d * 1e-6;
            let fd = (law.elastic_force(d + h) - law.elastic_force(d - h)) / (2.0 * h);
            assert!(
                (fd - law.tangent_stiffness(d)).abs() < 1e-6 * fd.abs(),
                "{} at {d}",
                law.name()
            );
        }
    }
}

#[test]
fn numeric_energy_matches_closed_form() {
    // Liu with c >> delta behaves like delta^1.5 / sqrt(2c); compare default quadrature
    // against Hertz's closed form through a law that uses the default.
    let liu = LiuEtAl::new(1e11, 0.01, 1e-4).unwrap();
    let d = 2e-6;
    // trapezoid with many points as reference
    let n = 200_000;
    let mut e = 0.0;
    for i in 0..n {
        let a = d * i as f64 / n as f64;
        let b = d * (i + 1) as f64 / n as f64;
        e += 0.5 * (liu.elastic_force(a) + liu.elastic_force(b)) * (b - a);
    }
    assert!((liu.elastic_energy(d) - e).abs() < 1e-7 * e);
}

#[test]
fn penetration_for_energy_inverts_the_elastic_energy() {
    let hertz = Hertz::new(1e10, 1.5).unwrap();
    let d = penetration_for_energy(&hertz, hertz.elastic_energy(3e-6), 1e-9);
    assert!((d - 3e-6).abs() < 1e-12, "{d}");
    let liu = LiuEtAl::new(1.137e11, 0.016, 5e-4).unwrap();
    for target in [1e-7, 2e-6, 4e-5] {
        let d = penetration_for_energy(&liu, liu.elastic_energy(target), 1e-6);
        assert!((d - target).abs() < 0.03 * target, "{target} -> {d}");
    }
    assert_eq!(penetration_for_energy(&liu, 0.0, 1e-6), 0.0);
}

#[test]
fn invalid_parameters_are_named() {
    let err = Hertz::new(-1.0, 1.5).unwrap_err().to_string();
    assert!(
        err.contains("stiffness") && err.contains("between 1 and 1e16"),
        "{err}"
    );
    let err = HuntCrossley::new(1.0, 1.5, 1.5).unwrap_err().to_string();
    assert!(err.contains("restitution"), "{err}");
    let err = ImprovedLiu::new(1e11, 0.01, f64::NAN, 1.0, 1e-4, MaxDamping::Eta(0.01))
        .unwrap_err()
        .to_string();
    assert!(err.contains("clearance") && err.contains("NaN"), "{err}");
}
