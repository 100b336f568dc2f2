//! The ablation table: each technique of the sub-cycled contact turned off in turn
//! ([`SubCycleTechniques`](clearance_joint::rapier::joint::SubCycleTechniques), the scenes'
//! `run.sub_cycle`), per scene, against the scene's converged run.
//!
//! `cargo bench --bench ablation -- --quick` runs the paper's scene, the slider-crank
//! (c = 0.5 mm), the four-bar (the first impacts, as the mechanism matrix's quick mode), the door
//! and the spatial panel over short spans; without `--quick` every scene of the mechanism matrix
//! plus the door and the spatial panel over the matrix's spans. Any other word keeps only the
//! scenes whose name contains it. The table is printed and written to
//! `bench_out/ablation[_quick].md`. The SCARA arm at 1 kHz has its own table
//! (`cargo bench --bench scara_stress -- --ablation`).
//!
//! Rows per scene: the explicit joint at the defaults, the sub-cycled joint with every technique
//! on, with each technique of its kind (planar or spatial) off, and with fixed world steps as
//! many as the adaptive run took (the adaptive world step off). Columns: world steps, the
//! measured hinge's sub-steps, wall time (both twins), the first impact against the reference's
//! (as the mechanism matrix's), the impacts matched in sequence, the window's statistics with
//! their difference from the reference's, and the guards. The reference is the mechanism
//! matrix's (the explicit joint at its finest fixed step) or, for the door and the spatial
//! panel, the explicit joint at the tolerance 0.001. A run that fails, or passes its wall-time
//! cap, is a row that says so.

#[path = "mechanisms/matrix.rs"]
mod matrix;

use matrix::*;
use std::fmt::Write as _;

/// Wall-time cap of an ablation run, s (quick; four times it in the full table).
const CAP_S: f64 = 60.0;

/// The planar sub-cycle's switches (the scenes' `run.sub_cycle.<name>`).
const PLANAR: [&str; 5] = [
    "implicit_friction",
    "implicit_damping",
    "continuation",
    "continuity_rounds",
    "stabilisation",
];
/// The spatial sub-cycle's switches.
const SPATIAL: [&str; 2] = ["jacobian_reuse", "implicit_spatial"];

/// A scene of the table: the matrix's case, whether its measured hinge is spatial, and its
/// reference.
struct Entry {
    case: Case,
    spatial: bool,
    /// `Some(tol)`: the explicit joint at that tolerance (adaptive); `None`: the matrix's
    /// finest fixed step.
    reference_tolerance: Option<f64>,
}

fn spatial_case(
    name: &'static str,
    file: &'static str,
    end: (f64, f64),
    window: (f64, f64),
) -> Case {
    Case {
        name,
        file,
        set: vec![],
        hinge: "hinge",
        probe: "panel",
        end_s: end.0,
        quick_end_s: end.1,
        window_start_s: window.0,
        quick_window_start_s: window.1,
        unit: Unit::Second,
        fixed_dt: [0.0; 3],
        output_interval_s: 1e-4,
        closed_form: None,
    }
}

fn entries(quick: bool) -> Vec<Entry> {
    let quick_names = ["solar panel T", "slider-crank c=0.5mm", "four-bar"];
    let mut out: Vec<Entry> = cases()
        .into_iter()
        .filter(|c| !quick || quick_names.contains(&c.name))
        .map(|case| Entry {
            spatial: case.file == "cantilever.ron",
            case,
            reference_tolerance: None,
        })
        .collect();
    for case in [
        spatial_case("door", "door_hinge.ron", (1.0, 0.2), (0.5, 0.1)),
        spatial_case(
            "spatial panel",
            "solar_panel_spatial.ron",
            (2.0, 0.5),
            (1.0, 0.25),
        ),
    ] {
        out.push(Entry {
            case,
            spatial: true,
            reference_tolerance: Some(0.001),
        });
    }
    out
}

/// One row: its label and outcome.
struct Row {
    label: String,
    o: Outcome,
    w: Option<WindowStats>,
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let quick = args.iter().any(|a| a == "--quick");
    let filters: Vec<&String> = args.iter().filter(|a| !a.starts_with("--")).collect();
    let cap = if quick { CAP_S } else { 4.0 * CAP_S };
    quiet_abandon();
    let mut table = String::new();
    let _ = writeln!(
        table,
        "| scene | run | world steps | sub-steps | wall (s) | first impact vs reference: onset (us), \
         approach, peak, penetration, duration | impacts matched | window: largest force, deepest, \
         onsets per unit, contact fraction, RMS acc. diff (vs reference) | guards |"
    );
    let _ = writeln!(table, "|---|---|---|---|---|---|---|---|---|");
    let total = std::time::Instant::now();
    for entry in entries(quick) {
        let case = &entry.case;
        if !filters.is_empty() && !filters.iter().any(|f| case.name.contains(f.as_str())) {
            continue;
        }
        let (end, start) = if quick {
            (case.quick_end_s, case.quick_window_start_s)
        } else {
            (case.end_s, case.window_start_s)
        };
        let measure = |set: &[String], stepping: Stepping, label: &str, cap: f64| -> Row {
            let mut c = case.clone();
            c.set.extend(set.iter().cloned());
            let o = guarded(&c, stepping, end, start, cap);
            eprintln!(
                "{}: {label} {} steps, {} sub-steps, {:.2} s{}",
                case.name,
                o.steps,
                o.substeps,
                o.wall_s,
                o.error
                    .as_ref()
                    .map(|e| format!(" ({e})"))
                    .unwrap_or_default()
            );
            let w = o
                .error
                .is_none()
                .then(|| window(&o.impacts, start, end, case.unit));
            Row {
                label: label.into(),
                o,
                w,
            }
        };
        let reference = match entry.reference_tolerance {
            Some(tol) => measure(
                &[
                    "run.contact_integration=Explicit".into(),
                    format!("run.tolerance={tol}"),
                ],
                Stepping::Default,
                &format!("reference: explicit, tolerance {tol}"),
                f64::INFINITY,
            ),
            None => {
                let dt = case.fixed_dt[2];
                measure(
                    &[],
                    Stepping::Fixed(dt),
                    &format!("reference: explicit, fixed {dt:e}"),
                    f64::INFINITY,
                )
            }
        };
        let sub = |more: &[String]| -> Vec<String> {
            let mut s = vec!["run.contact_integration=SubCycled".to_string()];
            s.extend(more.iter().cloned());
            s
        };
        let mut rows = vec![
            measure(
                &["run.contact_integration=Explicit".into()],
                Stepping::Default,
                "explicit",
                cap,
            ),
            measure(&sub(&[]), Stepping::Default, "sub-cycled, all on", cap),
        ];
        let switches: &[&str] = if entry.spatial { &SPATIAL } else { &PLANAR };
        for name in switches {
            let set = sub(&[format!("run.sub_cycle.{name}=false")]);
            rows.push(measure(
                &set,
                Stepping::Default,
                &format!("sub-cycled, {name} off"),
                cap,
            ));
        }
        // The adaptive world step off: fixed steps, as many as the adaptive run took.
        let all_on = &rows[1].o;
        if all_on.error.is_none() && all_on.steps > 0 {
            let dt = end / all_on.steps as f64;
            let set = sub(&["run.step=Fixed".into(), format!("run.dt_s={dt}")]);
            let label = format!("sub-cycled, fixed steps of {}", sig(dt));
            rows.push(measure(&set, Stepping::Default, &label, cap));
        }
        let _ = writeln!(table, "{}", line(case, &reference, &reference));
        for r in &rows {
            let _ = writeln!(table, "{}", line(case, r, &reference));
        }
    }
    let md = format!(
        "## Ablation of the sub-cycled contact{}\n\n{table}\nOnsets per unit: per crank turn for \
         the slider-crank and the four-bar, per second otherwise; the window as the mechanism \
         matrix's (halved in the quick mode; the door's and the spatial panel's from half their \
         span). Sub-steps: the measured hinge's, over the run.\n\nTotal wall time {:.0} s.\n",
        if quick { " (quick: short spans)" } else { "" },
        total.elapsed().as_secs_f64()
    );
    println!("{md}");
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../bench_out");
    let _ = std::fs::create_dir_all(&dir);
    let name = if quick {
        "ablation_quick.md"
    } else {
        "ablation.md"
    };
    if let Err(e) = std::fs::write(dir.join(name), md) {
        eprintln!("cannot write bench_out/{name}: {e}");
    }
}

/// [`run`], with a panic of the run (a diverged technique-off run may trip an assertion)
/// reported as its error instead of ending the table.
fn guarded(case: &Case, stepping: Stepping, end: f64, start: f64, cap: f64) -> Outcome {
    let t0 = std::time::Instant::now();
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        run(case, stepping, end, start, cap)
    }));
    result.unwrap_or_else(|p| {
        let what = p
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_else(|| "a panic".into());
        Outcome {
            stepping,
            error: Some(format!("panicked: {what}")),
            violations: Vec::new(),
            steps: 0,
            substeps: 0,
            wall_s: t0.elapsed().as_secs_f64(),
            impacts: Vec::new(),
            end_s: end,
            peak_force_n: 0.0,
            max_penetration_um: 0.0,
            rms_acc_diff: f64::NAN,
            closed_form_error: None,
        }
    })
}

fn guards(o: &Outcome) -> String {
    match &o.error {
        Some(e) => {
            let short: String = e.chars().take(110).collect();
            format!("**failed**: {short}")
        }
        None if o.violations.is_empty() => "clean".into(),
        None => {
            let mut kinds: Vec<String> = o.violations.iter().map(violation_kind).collect();
            kinds.dedup();
            format!("flagged: {}", kinds.join("; "))
        }
    }
}

fn line(case: &Case, r: &Row, reference: &Row) -> String {
    let (o, ro) = (&r.o, &reference.o);
    let cost = format!(
        "| {} | {} | {} | {} | {:.2} |",
        case.name, r.label, o.steps, o.substeps, o.wall_s
    );
    if o.error.is_some() || ro.error.is_some() {
        return format!("{cost} - | - | - | {} |", guards(o));
    }
    let first = match (o.impacts.first(), ro.impacts.first()) {
        (Some(a), Some(b)) => format!(
            "{:+.2}, {}, {}, {}, {}",
            (a.onset_t_s - b.onset_t_s) * 1e6,
            pct(rel(a.approach_speed_m_s, b.approach_speed_m_s)),
            pct(rel(a.peak_force_n, b.peak_force_n)),
            pct(rel(a.max_penetration_um, b.max_penetration_um)),
            pct(rel(a.duration_s, b.duration_s))
        ),
        _ => format!(
            "impacts: {}, reference {}",
            o.impacts.len(),
            ro.impacts.len()
        ),
    };
    let (w, rw) = (r.w.unwrap_or_default(), reference.w.unwrap_or_default());
    let stat = |v: f64, rv: f64| {
        if std::ptr::eq(r, reference) {
            sig(v)
        } else {
            format!("{} ({})", sig(v), pct(rel(v, rv)))
        }
    };
    let window = [
        stat(w.largest_force_n, rw.largest_force_n),
        stat(w.deepest_um, rw.deepest_um),
        stat(w.onsets_per_unit, rw.onsets_per_unit),
        stat(w.contact_fraction, rw.contact_fraction),
        stat(o.rms_acc_diff, ro.rms_acc_diff),
    ]
    .join("; ");
    format!(
        "{cost} {first} | {} of {} | {window} | {} |",
        matched(&o.impacts, &ro.impacts),
        ro.impacts.len(),
        guards(o)
    )
}
