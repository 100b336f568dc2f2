//! `MECHANISMS_STUDY`: is a flagged window statistic the default's error or an unconverged range?
//! Each listed stepping runs all five starts (nominal and [`PERTURBATIONS`]), so a fixed step's
//! ensemble is compared with the default's, start by start, over the matrix's own window.
//!
//! `MECHANISMS_STUDY="2.5e-7,1.25e-7,tol=0.002,sub=0.002" cargo bench --bench mechanisms --
//! "c=0.1mm"`: a number is an explicit fixed step (s); `tol=X` the explicit adaptive default at
//! tolerance `X`; `sub=X` the sub-cycled adaptive default at tolerance `X`. `MECHANISMS_SET`
//! (`key=value` pairs separated by `;`) is applied to every run of the study after the case's own
//! settings (`MECHANISMS_SET="run.max_dt_s=1e-4"`: a knob's effect on every start).

use crate::matrix::*;

/// One stepping of the study: a fixed step, or the adaptive default at a tolerance with its
/// contact integration.
fn parse(item: &str) -> (Stepping, Option<(String, &'static str)>) {
    if let Some(tol) = item.strip_prefix("tol=") {
        (Stepping::Default, Some((tol.to_string(), "Explicit")))
    } else if let Some(tol) = item.strip_prefix("sub=") {
        (Stepping::Default, Some((tol.to_string(), "SubCycled")))
    } else {
        (
            Stepping::Fixed(
                item.parse()
                    .expect("a fixed step in seconds, tol=X or sub=X"),
            ),
            None,
        )
    }
}

/// Runs the study over `cases` and prints per start and per stepping the window statistics
/// (largest force, deepest penetration, onsets per unit, contact fraction, RMS acc. difference).
pub fn study(spec: &str, cases: &[Case], quick: bool) {
    println!(
        "| scene | stepping | start | steps | wall (s) | force (N) | depth (um) | onsets | contact | acc (m/s^2) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for case in cases {
        let (end, start) = if quick {
            (case.quick_end_s, case.quick_window_start_s)
        } else {
            (case.end_s, case.window_start_s)
        };
        for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let (stepping, tol) = parse(item);
            let mut base = case.clone();
            if let Some((tol, integration)) = &tol {
                // The adaptive stepper at this tolerance (the case's settings go last).
                base.set.push(format!("run.tolerance={tol}"));
                base.set
                    .push(format!("run.contact_integration={integration}"));
            }
            if let Ok(extra) = std::env::var("MECHANISMS_SET") {
                base.set.extend(
                    extra
                        .split(';')
                        .map(str::trim)
                        .filter(|s| !s.is_empty())
                        .map(String::from),
                );
            }
            let starts: Vec<(String, Case)> =
                std::iter::once(("nominal".to_string(), base.clone()))
                    .chain(
                        PERTURBATIONS
                            .iter()
                            .map(|&e| (format!("c x (1 {e:+e})"), perturbed(&base, e))),
                    )
                    .collect();
            let mut all = Vec::new();
            for (label, c) in &starts {
                let o = run(c, stepping, end, start, f64::INFINITY);
                if let Some(e) = &o.error {
                    println!("| {} | {item} | {label} | failed: {e} |", case.name);
                    continue;
                }
                let w = window(&o.impacts, start, end, case.unit);
                println!(
                    "| {} | {item} | {label} | {} | {:.1} | {} | {} | {} | {} | {} |",
                    case.name,
                    o.steps,
                    o.wall_s,
                    sig(w.largest_force_n),
                    sig(w.deepest_um),
                    sig(w.onsets_per_unit),
                    sig(w.contact_fraction),
                    sig(o.rms_acc_diff)
                );
                all.push((w, o.rms_acc_diff));
            }
            let n = all.len() as f64;
            let mean = |g: &dyn Fn(&(WindowStats, f64)) -> f64| all.iter().map(g).sum::<f64>() / n;
            println!(
                "| {} | {item} | **mean of {}** | | | {} | {} | {} | {} | {} |",
                case.name,
                all.len(),
                sig(mean(&|x| x.0.largest_force_n)),
                sig(mean(&|x| x.0.deepest_um)),
                sig(mean(&|x| x.0.onsets_per_unit)),
                sig(mean(&|x| x.0.contact_fraction)),
                sig(mean(&|x| x.1))
            );
        }
    }
}
