use super::*;

#[test]
fn counts_and_times_in_words() {
    assert_eq!(thousands(0), "0");
    assert_eq!(thousands(999), "999");
    assert_eq!(thousands(41_210), "41,210");
    assert_eq!(thousands(1_234_567), "1,234,567");
    let cost = CheckCost {
        steps: 34_540,
        wall_s: 0.42,
        run_steps: 20_570,
        run_wall_s: 0.2,
    };
    assert_eq!(
        cost.describe(),
        "34,540 steps in 0.42 s, 2.1 times the run's wall time (20,570 steps in 0.20 s)"
    );
    let instant = CheckCost {
        run_wall_s: 0.0,
        ..cost
    };
    assert_eq!(instant.wall_ratio(), None);
}

/// The one call: the paper's scene to its first impact, checked metric by metric with its
/// cost; without a clearance hinge, nothing to check and no claim of convergence. The
/// verdict reads back from its JSON.
#[test]
fn run_checked_compares_or_says_there_is_nothing_to_check() {
    let scene = |set: &[&str]| {
        let mut overrides = vec!["run.end_s=0.1"];
        overrides.extend_from_slice(set);
        Scene::solar_panel()
            .with_overrides(&overrides)
            .unwrap()
            .validated()
            .unwrap()
    };
    let (run, convergence) = run_checked(&scene(&[])).unwrap();
    let check = convergence.checked().expect("a clearance hinge to check");
    assert_eq!(check.metrics.len(), 8, "{check:?}");
    assert!(check.is_clean(), "{check:?}");
    let verdict = convergence.verdict();
    let ConvergenceVerdict::Checked {
        converged,
        not_converged,
        worst,
        cost,
    } = &verdict
    else {
        panic!("{verdict:?}");
    };
    assert_eq!(converged.len(), 8);
    assert!(not_converged.is_empty() && worst.is_none());
    assert_eq!(cost.run_steps, run.steps);
    assert!(cost.steps > run.steps && cost.wall_s > 0.0, "{cost:?}");
    assert_eq!(
        verdict.describe(),
        "converged: all 8 metrics within their bounds"
    );
    let json = serde_json::to_string(&verdict).unwrap();
    assert!(json.contains("\"status\":\"checked\""), "{json}");
    assert_eq!(
        serde_json::from_str::<ConvergenceVerdict>(&json).unwrap(),
        verdict
    );

    let ideal = scene(&["hinge.clearance=null"]);
    assert_eq!(nothing_to_check(&ideal), Some("no clearance hinge"));
    let (_, convergence) = run_checked(&ideal).unwrap();
    assert_eq!(
        convergence,
        Convergence::NothingToCheck {
            reason: "no clearance hinge".into()
        }
    );
    assert!(convergence.strict().is_ok() && convergence.checked().is_none());
    assert_eq!(
        convergence.verdict().describe(),
        "nothing to check (no clearance hinge)"
    );
}

#[test]
fn values_shown_to_their_difference() {
    assert_eq!(shown(179.2319, 0.02), "179.232");
    assert_eq!(shown(0.087512233, 4e-7), "0.087512233");
    assert_eq!(shown(53.0, 0.0), "53");
    assert_eq!(shown(52.5, 0.0), "52.50");
    assert_eq!(shown(f64::INFINITY, 1.0), "inf");
}

#[test]
fn estimates_by_hand() {
    // 100.3 against 100.0: 4/3 of 0.3 % is 0.4 %, inside 1 %.
    let m = MetricCheck::new("f".into(), 100.3, 100.0, FORCE_BOUND, true, false);
    assert!((m.estimated_error - 0.004).abs() < 1e-12 && !m.flagged);
    // 1.0 against 1.009: 4/3 of 0.9 % is 1.2 %, flagged.
    let m = MetricCheck::new("f".into(), 1.0, 1.009, FORCE_BOUND, true, false);
    assert!(m.flagged);
    // A count: 103 against 100 is 3 %, at the bound; 104 is beyond.
    let m = MetricCheck::new("n".into(), 103.0, 100.0, ONSET_COUNT_BOUND, true, true);
    assert!(!m.flagged, "{m:?}");
    assert!(MetricCheck::new("n".into(), 104.0, 100.0, ONSET_COUNT_BOUND, true, true).flagged);
    // Absolute: onsets 0.6 us apart estimate 0.8 us, inside 1 us.
    let m = MetricCheck::new("t".into(), 0.1000006, 0.1, ONSET_BOUND_S, false, false);
    assert!((m.estimated_error - 8e-7).abs() < 1e-12 && !m.flagged);
    // An impact in one run only, and a change from 0.
    assert!(MetricCheck::new("t".into(), f64::INFINITY, 0.1, 1e-6, false, false).flagged);
    assert!(MetricCheck::new("n".into(), 1.0, 0.0, ONSET_COUNT_BOUND, true, true).flagged);
    assert!(!MetricCheck::new("n".into(), 0.0, 0.0, ONSET_COUNT_BOUND, true, true).flagged);
}
