use super::*;

fn obs(force: f64, pen_um: f64, rate: f64, onset: bool) -> ContactObservation {
    ContactObservation {
        force,
        onset,
        impact: onset,
        penetration: pen_um * 1e-6,
        rate,
        approach_speed: rate,
        onset_fraction: 1.0,
    }
}

#[test]
fn two_contacts_by_hand() {
    let mut r = ImpactRecorder::new();
    // Free, contact over two steps, free, a second contact still closed at the end.
    let states = [
        (0.0, 0.1, obs(0.0, -1.0, 0.01, false)),
        (0.1, 0.1, obs(10.0, 2.0, 0.02, true)),
        (0.2, 0.1, obs(30.0, 3.0, 0.0, false)),
        (0.3, 0.2, obs(0.0, -0.5, -0.01, false)),
        (0.5, 0.5, obs(5.0, 1.0, 0.004, true)),
    ];
    for (t, dt, o) in &states {
        r.record(*t, *dt, o);
    }
    r.finish(1.0, &obs(6.0, 1.5, 0.0, false));
    let i = r.contacts();
    assert_eq!(i.len(), 2);
    assert_eq!(i[0].onset_t_s, 0.1);
    assert_eq!(i[0].approach_speed_m_s, 0.02);
    assert_eq!(i[0].peak_force_n, 30.0);
    assert_eq!(i[0].max_penetration_um, 3.0);
    // Lifted off inside the step from 0.2 (3 um deep) to 0.3 (0.5 um of gap): at 3/3.5 of it.
    let lift_off = 0.2 + 0.1 * 3.0 / 3.5;
    assert!((i[0].duration_s - (lift_off - 0.1)).abs() < 1e-15);
    assert_eq!(i[1].peak_force_n, 6.0);
    assert_eq!(i[1].duration_s, 0.5);
    // Each peak at its state's time: 30 N at 0.2 s, and 6 N at the final state, 1 s.
    assert_eq!((i[0].peak_t_s, i[1].peak_t_s), (0.2, 1.0));
    let m = r.metrics();
    assert_eq!((m.onsets, m.impacts), (2, 2));
    assert_eq!(m.first_impact_t_s, Some(0.1));
    assert_eq!(m.first_impact_peak_n, Some(30.0));
    assert_eq!(m.peak_force_n, 30.0);
    assert!((m.contact_fraction - (lift_off - 0.1 + 0.5)).abs() < 1e-15);
    // Sum of F^2 dt = 100*0.1 + 900*0.1 + 25*0.5 = 112.5 over 1 s.
    assert!((m.rms_force_n - 112.5f64.sqrt()).abs() < 1e-12);
    // Restitution: left at 0.01 m/s after approaching at 0.02.
    assert!((m.max_restitution - 0.5).abs() < 1e-15);
    assert_eq!(r.contacts_table().rows(), 2);
}

#[test]
fn ideal_joint_has_no_impacts() {
    let mut r = ImpactRecorder::new();
    r.record(0.0, 0.5, &ContactObservation::ideal(2.0));
    r.finish(0.5, &ContactObservation::ideal(4.0));
    assert!(r.contacts().is_empty());
    assert_eq!(r.metrics().peak_force_n, 4.0);
    assert_eq!(r.metrics().contact_fraction, 0.0);
    assert_eq!(r.metrics().rms_force_n, 2.0);
}

#[test]
fn per_turn_statistics_by_hand() {
    let imp = |t: f64, d: f64, f: f64| Impact {
        onset_t_s: t,
        duration_s: d,
        peak_force_n: f,
        separated: true,
        ..Impact::default()
    };
    // Turns of 1 s over 2.5 s; a contact from 0.5 to 1.25 s spans the first bound.
    let list = [imp(0.2, 0.1, 5.0), imp(0.5, 0.75, 9.0), imp(2.1, 0.2, 3.0)];
    let p = per_period(&list, 1.0, 2.5).unwrap();
    assert_eq!(p.len(), 3);
    assert_eq!((p[0].onsets, p[1].onsets, p[2].onsets), (2, 0, 1));
    assert_eq!((p[0].peak_force_n, p[1].peak_force_n), (9.0, 0.0));
    assert!((p[0].contact_s - 0.6).abs() < 1e-12);
    assert!((p[1].contact_s - 0.25).abs() < 1e-12);
    assert!((p[2].contact_s - 0.2).abs() < 1e-12 && p[2].length_s == 0.5);
    let t = per_period_table(&p);
    assert!((t.row(2)[5] - 0.4).abs() < 1e-12);
    assert!(per_period(&list, 0.0, 1.0).unwrap().is_empty());
    // Too many periods to tabulate: an error, not an allocation of the whole memory.
    assert!(per_period(&[], 1e-300, 1.0).is_err());
    assert!(per_period(&[], 1e-6, 1e4).is_err());
    assert!(per_period(&[], 1.0, f64::INFINITY).is_err());
}

proptest::proptest! {
    /// The recorder and the per-turn table fed any number (tests/numeric_inputs.rs): no panic,
    /// and no table beyond [`MAX_PERIODS`].
    #[test]
    fn metrics_any_numbers(
        period in proptest::num::f64::ANY, end in proptest::num::f64::ANY,
        onset in proptest::num::f64::ANY, duration in proptest::num::f64::ANY,
        t in proptest::num::f64::ANY, dt in proptest::num::f64::ANY,
        force in proptest::num::f64::ANY,
    ) {
        let impacts = [Impact { onset_t_s: onset, duration_s: duration, peak_force_n: force, ..Impact::default() }];
        match per_period(&impacts, period, end) {
            Ok(p) => proptest::prop_assert!(p.len() <= MAX_PERIODS),
            Err(e) => proptest::prop_assert!(e.to_string().contains("period"), "{e}"),
        }
        let mut rec = ImpactRecorder::new();
        let obs = ContactObservation::ideal(force);
        rec.record(t, dt, &obs);
        rec.record(t, dt, &ContactObservation { onset: true, impact: true, penetration: force.abs(), ..obs });
        rec.finish(t, &obs);
        rec.set_final_angle_deg(force);
        let _ = (rec.metrics(), rec.contact_time(), rec.contacts_table());
    }
}
