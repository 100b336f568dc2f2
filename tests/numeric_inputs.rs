//! Every public numeric entry point of the library, fed any number (NaN, the infinities, signed
//! zeros, subnormals, huge and tiny values, ordinary ones): it returns an error or a value it
//! documents, and never panics, hangs or allocates without bound (issue 17, item 7).
//!
//! The contract checked, by kind of entry point:
//! - constructors and builders (`new`, `build`, `validate`): an error for a non-finite
//!   parameter, and whatever they accept gives finite values at finite states;
//! - pure functions of numbers (laws, kinematics, angles, tables, step choice): no panic, a
//!   finite result for finite arguments in their documented domain, NaN only for a NaN input;
//! - functions that size an output: an error beyond their documented bound (the impact
//!   recorder's per-turn table: `src/rapier/observers/metrics/tests.rs`).

use clearance_joint::model::angle::{HingeAngle, UnwrappedAngle, twist_angle};
use clearance_joint::model::kinematics::{BodyMotion, contact_force, journal_state, stable_step};
use clearance_joint::model::laws::*;
use clearance_joint::rapier::hinge::design::HingeDesign;
use clearance_joint::rapier::large_step::LargeStepJointBuilder;
use clearance_joint::rapier::pipeline::stepper::StepControl;
use clearance_joint::rapier::pipeline::world::ClearanceWorld;
use clearance_joint::rapier::sources::drive::TorsionSpring;
use clearance_joint::rapier::sources::prescribed::Table;
use clearance_joint::{Error, error};
use proptest::prelude::*;
use rapier3d_f64::math::{Rotation, Vector};
use rapier3d_f64::prelude::{PhysicsWorld, RigidBodyHandle};

/// The numbers that break code: NaN, the infinities, signed zeros, the extremes of the normal
/// range, subnormals, and ordinary values of both signs over many decades.
fn any_number() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => prop::sample::select(vec![
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            0.0,
            -0.0,
            f64::MIN_POSITIVE,
            f64::MIN_POSITIVE / 4.0,
            -f64::MIN_POSITIVE / 4.0,
            5e-324,
            f64::MAX,
            f64::MIN,
            1e300,
            -1e300,
            1e-300,
            1.0,
            -1.0,
            f64::EPSILON,
        ]),
        1 => (-20.0..20.0f64, any::<bool>()).prop_map(|(e, neg)| {
            let x = 10f64.powf(e);
            if neg { -x } else { x }
        }),
        1 => any::<f64>(),
    ]
}

fn any_vector() -> impl Strategy<Value = Vector> {
    (any_number(), any_number(), any_number()).prop_map(|(x, y, z)| Vector::new(x, y, z))
}

/// A number that is not finite makes a constructor fail.
fn refuses_non_finite<T>(args: &[f64], r: &Result<T, Error>) -> Result<(), TestCaseError> {
    if args.iter().any(|x| !x.is_finite()) {
        prop_assert!(r.is_err(), "accepted non-finite arguments {args:?}");
    }
    Ok(())
}

/// The reference laws at valid parameters (the paper's improved law and one of each family).
fn laws() -> Vec<NormalModel> {
    let geometry = BearingGeometry::from_clearance(0.01, 2e-4, 0.016).unwrap();
    let e = effective_modulus(&Material::STEEL, &Material::STEEL);
    vec![
        NormalModel::Hertz(Hertz::new(1e9, 1.5).unwrap()),
        NormalModel::KelvinVoigt(KelvinVoigt::new(1e9, 1e3).unwrap()),
        NormalModel::HuntCrossley(HuntCrossley::new(1e9, 1.5, 0.5).unwrap()),
        NormalModel::LankaraniNikravesh(LankaraniNikravesh::new(1e9, 1.5, 0.5).unwrap()),
        NormalModel::FloresEtAl(FloresEtAl::new(1e9, 1.5, 0.5).unwrap()),
        NormalModel::GonthierEtAl(GonthierEtAl::new(1e9, 1.5, 0.5).unwrap()),
        NormalModel::LiuEtAl(LiuEtAl::new(e, geometry.length(), geometry.clearance()).unwrap()),
        NormalModel::ImprovedLiu(
            ImprovedLiu::new(
                e,
                geometry.length(),
                geometry.clearance(),
                1.0,
                ImprovedLiu::DEFAULT_DELTA_MAX,
                MaxDamping::Eta(ImprovedLiu::DEFAULT_ETA),
            )
            .unwrap(),
        ),
    ]
}

fn frictions() -> Vec<FrictionModel> {
    vec![
        FrictionModel::None,
        FrictionModel::Coulomb(Coulomb::new(0.3, 1e-4).unwrap()),
        FrictionModel::Threlfall(Threlfall::new(0.3, 1e-4).unwrap()),
        FrictionModel::Ambrosio(Ambrosio::new(0.3, 1e-4, 1e-2).unwrap()),
        FrictionModel::Bai(Bai::DRY),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn law_constructors_refuse_what_is_not_finite(
        a in any_number(), b in any_number(), c in any_number(), d in any_number(),
    ) {
        refuses_non_finite(&[a, b], &Hertz::new(a, b))?;
        refuses_non_finite(&[a, b], &KelvinVoigt::new(a, b))?;
        refuses_non_finite(&[a, b, c], &HuntCrossley::new(a, b, c))?;
        refuses_non_finite(&[a, b, c], &LankaraniNikravesh::new(a, b, c))?;
        refuses_non_finite(&[a, b, c], &FloresEtAl::new(a, b, c))?;
        refuses_non_finite(&[a, b, c], &GonthierEtAl::new(a, b, c))?;
        refuses_non_finite(&[a, b, c], &LiuEtAl::new(a, b, c))?;
        for damping in [MaxDamping::Eta(d), MaxDamping::Explicit(d)] {
            refuses_non_finite(&[a, b, c, 1.0, 1e-4, d], &ImprovedLiu::new(a, b, c, 1.0, 1e-4, damping))?;
        }
        refuses_non_finite(&[a, b], &Coulomb::new(a, b))?;
        refuses_non_finite(&[a, b], &Threlfall::new(a, b))?;
        refuses_non_finite(&[a, b, c], &Ambrosio::new(a, b, c))?;
        refuses_non_finite(&[a, b, c, d], &Bai::new(a, b, c, d))?;
        refuses_non_finite(&[a, b], &Material::new(a, b))?;
        refuses_non_finite(&[a, b, c], &BearingGeometry::new(a, b, c))?;
        refuses_non_finite(&[a, b, c], &BearingGeometry::from_clearance(a, b, c))?;
        // Whatever a law accepts evaluates finite at a finite contact.
        if let Ok(l) = HuntCrossley::new(a, b, c) {
            let f = l.normal_force(&NormalContact { penetration: 1e-6, penetration_rate: 0.1, impact_rate: 0.1 });
            prop_assert!(f.is_finite(), "HuntCrossley({a}, {b}, {c}): F = {f}");
        }
        if let Ok(l) = Bai::new(a, b, c, d) {
            prop_assert!(l.coefficient(1e-3).is_finite());
        }
    }

    #[test]
    fn laws_evaluate_any_state_without_panic(
        pen in any_number(), rate in any_number(), rate0 in any_number(), energy in any_number(),
        guess in any_number(), mass in any_number(), speed in any_number(),
    ) {
        let c = NormalContact { penetration: pen, penetration_rate: rate, impact_rate: rate0 };
        let finite = [pen, rate, rate0].iter().all(|x| x.is_finite() && x.abs() < 1e3);
        for law in laws() {
            let f = law.normal_force(&c);
            let _ = (law.elastic_force(pen), law.tangent_stiffness(pen), law.elastic_energy(pen));
            let _ = (law.damping_coefficient(&c), law.damping_slope(&c));
            if finite {
                prop_assert!(!f.is_nan(), "{}: F = {f} at {c:?}", law.name());
            }
            let d = penetration_for_energy(&law, energy, guess);
            prop_assert!(!d.is_nan() || energy.is_nan(), "{}: {d}", law.name());
            let e = impact_restitution(&law, mass, speed);
            prop_assert!((0.0..=1.0).contains(&e), "{}: restitution {e} for m {mass}, v {speed}", law.name());
        }
        for law in frictions() {
            let mu = law.coefficient(speed);
            prop_assert!(mu.is_nan() == speed.is_nan() || !speed.is_finite(), "{law:?}: mu({speed}) = {mu}");
        }
    }

    #[test]
    fn smooth_steps_and_stability_limits(
        x in any_number(), x0 in any_number(), h0 in any_number(), x1 in any_number(), h1 in any_number(),
    ) {
        let s = step(x, x0, h0, x1, h1);
        if [x, x0, h0, x1, h1].iter().all(|v| v.is_finite() && v.abs() < 1e100) && x0 < x1 {
            prop_assert!(s.is_finite(), "step({x}, {x0}, {h0}, {x1}, {h1}) = {s}");
        }
        let (dt, omega, zeta) = stable_step(x, x0, h0);
        prop_assert!(!dt.is_nan() && dt >= 0.0, "stable_step({x}, {x0}, {h0}) = {dt}, {omega}, {zeta}");
    }

    #[test]
    fn kinematics_and_contact_any_state(
        p_i in any_vector(), p_j in any_vector(), axis in any_vector(),
        v1 in any_vector(), w2 in any_vector(), rate0 in any_number(),
    ) {
        let geometry = BearingGeometry::from_clearance(0.01, 2e-4, 0.016).unwrap();
        let m1 = BodyMotion { center_of_mass: p_i, linvel: v1, angvel: Vector::ZERO };
        let m2 = BodyMotion { center_of_mass: p_j, linvel: Vector::ZERO, angvel: w2 };
        let _ = m1.velocity_at(p_j);
        let state = journal_state(&geometry, p_i, p_j, axis, &m1, &m2);
        for (law, friction) in laws().iter().zip(frictions().iter().cycle()) {
            let f = contact_force(&state, rate0, law, friction);
            let all = [p_i, p_j, axis, v1, w2].iter().all(|v| v.is_finite() && v.length() < 1e3);
            if all && axis.length() > 1e-3 && rate0.is_finite() && rate0 > 1e-6 && rate0 < 1e3 {
                prop_assert!(f.on_journal.is_finite(), "{}: {f:?} at {state:?}", law.name());
            }
        }
    }

    #[test]
    fn angles_any_rotation(
        angle in any_number(), axis in any_vector(), wraps in prop::collection::vec(any_number(), 1..6),
    ) {
        let q = if axis.is_finite() && axis.length() > 1e-6 && angle.is_finite() {
            Rotation::from_axis_angle(axis.normalize(), angle)
        } else {
            Rotation::IDENTITY
        };
        let _ = twist_angle(&q, axis);
        let mut u = UnwrappedAngle::default();
        for w in &wraps {
            let _ = u.update(*w);
        }
        let _ = u.value();
        let mut h = HingeAngle::default();
        let _ = h.update(&Rotation::IDENTITY, &q, axis);
        let _ = h.update(&q, &q, axis);
        let _ = h.value();
    }

    #[test]
    fn tables_any_time_and_values(
        times in prop::collection::vec(any_number(), 0..5),
        values in prop::collection::vec(any_number(), 0..5),
        t in any_number(),
    ) {
        let r = Table::new(&times, &values);
        refuses_non_finite(&[times.clone(), values.clone()].concat(), &r)?;
        if let Ok(table) = r {
            let (v, d, dd) = table.eval(t);
            if t.is_nan() {
                prop_assert!(v.is_nan() && d.is_nan() && dd.is_nan());
            } else if t.is_finite() && t.abs() < 1e10 && times.iter().all(|x| x.abs() < 1e10) {
                prop_assert!(!v.is_nan() && !d.is_nan(), "eval({t}) = {v}, {d}, {dd} on {times:?}, {values:?}");
            }
            let m = table.max_rate();
            prop_assert!(m >= 0.0, "max_rate {m}");
        }
    }

    #[test]
    fn builders_refuse_what_is_not_finite(
        a in any_number(), b in any_number(), axis in any_vector(), anchor in any_vector(),
    ) {
        let geometry = BearingGeometry::from_clearance(0.01, 2e-4, 0.016).unwrap();
        let law = laws().pop().unwrap();
        let r = HingeDesign::new(geometry, law)
            .min_impact_speed(a)
            .min_separation(b)
            .max_valid_penetration(a)
            .joint(anchor, anchor, axis, axis);
        let vectors = [axis.x, axis.y, axis.z, anchor.x, anchor.y, anchor.z];
        refuses_non_finite(&[&vectors[..], &[a, b]].concat(), &r)?;
        let r = LargeStepJointBuilder::new(axis, geometry)
            .local_anchor1(anchor)
            .local_anchor2(anchor)
            .local_axis2(axis)
            .restitution(a)
            .friction(b)
            .min_impact_speed(b)
            .build();
        refuses_non_finite(&[&vectors[..], &[a, b]].concat(), &r)?;
        let r = clearance_joint::rapier::hinge::design::HingeDesign::steel_improved_liu(a, b, 0.016);
        refuses_non_finite(&[a, b], &r)?;
        if let Ok(c) = clearance_joint::rapier::hinge::design::HingeDesign::steel_improved_liu(0.01, 2e-4, 0.016) {
            let c = c.min_impact_speed(a).restitution(b);
            let r = c.joint(anchor, anchor, axis, axis);
            refuses_non_finite(&[&vectors[..], &[a]].concat(), &r)?;
            let r = c.large_step_joint(anchor, anchor, axis, axis);
            refuses_non_finite(&[&vectors[..], &[a, b]].concat(), &r)?;
        }
        let h = RigidBodyHandle::invalid();
        let r = TorsionSpring::new(h, h, axis, a, b);
        refuses_non_finite(&[&vectors[..3], &[a, b]].concat(), &r)?;
        if let Ok(s) = r {
            let _ = (s.torque_at(a), s.potential_energy(b));
        }
    }

    #[test]
    fn step_control_refuses_what_is_not_finite(
        dt in any_number(), tol in any_number(), floor in any_number(), growth in any_number(),
    ) {
        // The world checks its control at every step (and at `prepare`).
        let check = |c: StepControl| ClearanceWorld::new(PhysicsWorld::new(), c).prepare();
        refuses_non_finite(&[dt], &check(StepControl::fixed(dt)))?;
        let c = StepControl {
            min_dt: floor,
            max_growth: growth,
            ..StepControl::adaptive(dt, tol)
        };
        refuses_non_finite(&[dt, tol, floor, growth], &check(c))?;
        if check(c).is_ok() {
            prop_assert!(c.max_dt > 0.0 && c.min_dt <= c.max_dt);
        }
    }

    #[test]
    fn shared_checks_any_number(x in any_number(), lo in any_number(), hi in any_number(), v in any_vector()) {
        refuses_non_finite(&[x], &error::positive("x", x))?;
        refuses_non_finite(&[x], &error::non_negative("x", x))?;
        refuses_non_finite(&[x], &error::finite("x", x))?;
        refuses_non_finite(&[x], &error::in_range_open_closed("x", x, lo, hi))?;
        refuses_non_finite(&[x], &error::in_range("x", x, lo, hi, "m"))?;
        refuses_non_finite(&[v.x, v.y, v.z], &error::unit_vector("v", v))?;
        prop_assert!(!error::sig4(x).is_empty());
    }
}

/// The three calls the issue found panicking or exhausting memory.
#[test]
fn the_reported_panics_are_values_or_errors() {
    let t = Table::new(&[0.0, 1.0], &[0.0, 1.0]).unwrap();
    let (v, d, dd) = t.eval(f64::NAN);
    assert!(v.is_nan() && d.is_nan() && dd.is_nan());
}
