//! Work-precision of fixed and adaptive stepping on the paper's scene (clearance twin), with the
//! explicit contact (`run.contact_integration=Explicit`) and sub-cycled (the default, adaptive and
//! fixed world steps).
//! `cargo bench --bench work_precision` writes `bench_out/work_precision.{csv,md,svg}`.
//!
//! Errors are against the finest fixed run (dt = 1e-6 s); its own error is bounded by step
//! halving (the difference to the run at twice its step: Richardson gives the finer run's error as
//! that difference for a first-order quantity and a third of it at second order, as the contact
//! peaks are) and printed with the table.

use clearance_joint::scene::Scene;
use clearance_joint::scene::runner::{RunOptions, Simulation, TwinKind, Twins};
use clearance_joint_app::process::files::write_atomic;
use plotters::prelude::*;
use std::path::Path;
use std::time::Instant;

const GRID: f64 = 1e-4; // output rows (interpolated at exact times: they never change the steps)
/// The journal trajectory is compared over the first impacts, before the rattle turns chaotic.
const ORBIT_WINDOW_S: f64 = 0.25;

#[derive(Clone, Debug)]
struct Outcome {
    wall_s: f64,
    steps: u64,
    /// First-impact peak (N) and time (s), final angle (deg), onsets, separated impacts, time in
    /// contact (fraction), RMS force (N).
    values: [f64; 7],
    ecc_u: Vec<f64>,
    ecc_v: Vec<f64>,
}

fn run(overrides: &[String]) -> Result<Outcome, String> {
    let scene = Scene::solar_panel()
        .with_overrides(overrides)
        .map_err(|e| e.to_string())?;
    let mut best: Option<Outcome> = None;
    // The best of up to 9 runs: runs of a few tenths of a second vary by tens of per cent on a
    // shared machine (three runs of the benchmark with the best of 3 gave the default 0.79 to
    // 1.13 of the paper's fixed step's wall time).
    for _ in 0..9 {
        let sim = Simulation::new(
            &scene,
            RunOptions {
                twins: Twins::ClearanceOnly,
                skip_rows: false,
            },
        )
        .map_err(|e| e.to_string())?;
        let start = Instant::now();
        let r = sim.run().map_err(|e| e.to_string())?;
        let wall_s = start.elapsed().as_secs_f64();
        let twin = r.twin(TwinKind::Clearance).unwrap();
        let m = &twin.hinge_metrics()["hinge"];
        let table = &twin.table;
        let rows = (ORBIT_WINDOW_S / GRID).round() as usize + 1;
        let o = Outcome {
            wall_s,
            steps: r.steps,
            values: [
                m.first_impact_peak_n.unwrap_or(f64::NAN),
                m.first_impact_t_s.unwrap_or(f64::NAN),
                twin.final_angles_deg()["hinge"],
                m.onsets as f64,
                m.impacts as f64,
                m.contact_fraction,
                m.rms_force_n,
            ],
            ecc_u: table.column("hinge_ecc_u_mm").unwrap()[..rows].to_vec(),
            ecc_v: table.column("hinge_ecc_v_mm").unwrap()[..rows].to_vec(),
        };
        let slow = wall_s > 1.0;
        if best.as_ref().is_none_or(|b| o.wall_s < b.wall_s) {
            best = Some(o);
        }
        if slow {
            break; // long runs: one sample is enough, noise is small relative to them
        }
    }
    Ok(best.unwrap())
}

/// Errors of `o` against `reference`: relative for forces, counts and the contact fraction,
/// absolute for the impact time (s) and the angle (deg); then the RMS journal-orbit distance
/// over the first impacts (um).
fn errors(o: &Outcome, reference: &Outcome) -> [f64; 8] {
    let mut e = [0.0; 8];
    for (k, (a, b)) in o.values.iter().zip(&reference.values).enumerate() {
        e[k] = if k == 1 || k == 2 {
            (a - b).abs()
        } else {
            (a - b).abs() / b.abs()
        };
    }
    let n = o.ecc_u.len().min(reference.ecc_u.len());
    let sq: f64 = (0..n)
        .map(|i| {
            (o.ecc_u[i] - reference.ecc_u[i]).powi(2) + (o.ecc_v[i] - reference.ecc_v[i]).powi(2)
        })
        .sum();
    e[7] = 1e3 * (sq / n as f64).sqrt();
    e
}

fn fmt_errors(e: &[f64; 8]) -> String {
    format!(
        "{:.2} % | {:.1e} | {:.1e} | {:.1} % | {:.1} % | {:.1} % | {:.2} % | {:.3}",
        100.0 * e[0],
        e[1],
        e[2],
        100.0 * e[3],
        100.0 * e[4],
        100.0 * e[5],
        100.0 * e[6],
        e[7]
    )
}

/// The bounds, those `run --check` holds a run to: first-impact peak 1 %, final angle
/// 0.01 deg, onsets 3 %, time in contact 5 %.
fn within_bounds(e: &[f64; 8]) -> bool {
    use clearance_joint::scene::runner::convergence::{
        ANGLE_BOUND_DEG, CONTACT_FRACTION_BOUND, FORCE_BOUND, ONSET_COUNT_BOUND,
    };
    e[0] <= FORCE_BOUND
        && e[2] <= ANGLE_BOUND_DEG
        && e[3] <= ONSET_COUNT_BOUND
        && e[5] <= CONTACT_FRACTION_BOUND
}

struct Row {
    mode: &'static str,
    param: f64,
    outcome: Result<Outcome, String>,
}

const DEFAULT_TOL: f64 = 0.0075;
/// Sub-cycled contact (`run.contact_integration=SubCycled`) on adaptive world steps.
const SUB_ADAPTIVE: &str = "sub-cycled, adaptive, max 1e-3";
/// Sub-cycled contact on fixed world steps.
const SUB_FIXED: &str = "sub-cycled, fixed";

fn main() {
    let grid = format!("run.output_interval_s={GRID:e}");
    let mut rows = Vec::new();
    for dt in [2e-4, 1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6, 1e-6] {
        let o = vec![
            "run.contact_integration=Explicit".to_string(),
            "run.step=Fixed".to_string(),
            format!("run.dt_s={dt:e}"),
            grid.clone(),
        ];
        eprintln!("fixed dt = {dt:e}");
        rows.push(Row {
            mode: "fixed",
            param: dt,
            outcome: run(&o),
        });
    }
    // Adaptive with the default largest step (1e-3 s), and with the paper's 1e-4 s.
    for (mode, max_dt) in [("adaptive, max 1e-3", 1e-3), ("adaptive, max 1e-4", 1e-4)] {
        for tol in [0.03, 0.015, DEFAULT_TOL, 0.004, 0.002] {
            if max_dt == 1e-4 && tol != DEFAULT_TOL {
                continue;
            }
            let o = vec![
                "run.contact_integration=Explicit".into(),
                "run.step=Adaptive".into(),
                format!("run.tolerance={tol}"),
                format!("run.max_dt_s={max_dt:e}"),
                grid.clone(),
            ];
            eprintln!("{mode}, tolerance = {tol}");
            rows.push(Row {
                mode,
                param: tol,
                outcome: run(&o),
            });
        }
    }
    // Sub-cycled contact: adaptive world steps at the same tolerances, and fixed world steps of a
    // game's frame, a robot controller's period and the paper's step.
    for tol in [0.03, 0.015, DEFAULT_TOL, 0.004, 0.002] {
        let o = vec![
            "run.contact_integration=SubCycled".into(),
            "run.step=Adaptive".into(),
            format!("run.tolerance={tol}"),
            "run.max_dt_s=1e-3".into(),
            grid.clone(),
        ];
        eprintln!("{SUB_ADAPTIVE}, tolerance = {tol}");
        rows.push(Row {
            mode: SUB_ADAPTIVE,
            param: tol,
            outcome: run(&o),
        });
    }
    for dt in [1.0 / 60.0, 1e-3, 1e-4] {
        let o = vec![
            "run.contact_integration=SubCycled".into(),
            "run.step=Fixed".into(),
            format!("run.dt_s={dt:e}"),
            grid.clone(),
        ];
        eprintln!("{SUB_FIXED}, dt = {dt:e}");
        rows.push(Row {
            mode: SUB_FIXED,
            param: dt,
            outcome: run(&o),
        });
    }
    let find = |mode: &str, param: f64| {
        rows.iter()
            .find(|r| r.mode == mode && r.param == param)
            .and_then(|r| r.outcome.as_ref().ok())
            .cloned()
    };
    let reference = find("fixed", 1e-6).expect("reference run");
    let half = find("fixed", 2e-6).expect("halved run");
    let ref_err = errors(&half, &reference);

    let mut csv = String::from(
        "mode,parameter,steps,wall_s,peak_n,impact_t_s,final_angle_deg,onsets,separated,contact_fraction,rms_force_n,\
         peak_rel_error,impact_time_error_s,final_angle_error_deg,onsets_rel_error,separated_rel_error,contact_rel_error,rms_force_rel_error,orbit_rms_error_um,status\n",
    );
    let mut md = String::from(
        "| mode | dt (s) or tolerance | steps | wall (s) | first-impact peak | impact time (s) | final angle (deg) | onsets | separated | time in contact | RMS force | orbit, first 0.25 s (um) |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut points: Vec<(&'static str, f64, [f64; 8])> = Vec::new();
    for r in &rows {
        match &r.outcome {
            Ok(o) => {
                let e = errors(o, &reference);
                let v = &o.values;
                csv.push_str(&format!(
                    "{},{:e},{},{:.4},{:.4},{:.6},{:.6},{},{},{:.6},{:.5},{:.3e},{:.3e},{:.3e},{:.3e},{:.3e},{:.3e},{:.3e},{:.4},ok\n",
                    r.mode, r.param, o.steps, o.wall_s, v[0], v[1], v[2], v[3], v[4], v[5], v[6],
                    e[0], e[1], e[2], e[3], e[4], e[5], e[6], e[7]
                ));
                let label = if r.mode.starts_with("adaptive, max 1e-3") && r.param == DEFAULT_TOL {
                    format!("**{} (explicit, default tolerance)**", r.mode)
                } else if r.mode == SUB_ADAPTIVE && r.param == DEFAULT_TOL {
                    format!("**{} (default)**", r.mode)
                } else {
                    r.mode.to_string()
                };
                md.push_str(&format!(
                    "| {label} | {:e} | {} | {:.3} | {} |\n",
                    r.param,
                    o.steps,
                    o.wall_s,
                    fmt_errors(&e)
                ));
                if !(r.mode == "fixed" && r.param == 1e-6) {
                    points.push((r.mode, o.wall_s, e));
                }
            }
            Err(e) => {
                let short = e.split(':').next().unwrap_or(e).replace(',', ";");
                csv.push_str(&format!(
                    "{},{:e},,,,,,,,,,,,,,,,,,refused: {short}\n",
                    r.mode, r.param
                ));
                md.push_str(&format!(
                    "| {} | {:e} | refused: beyond the contact's stability limit | | | | | | | | | |\n",
                    r.mode, r.param
                ));
            }
        }
    }
    let v = &reference.values;
    md.push_str(&format!(
        "\nErrors against the reference, fixed dt = 1e-6 s (first-impact peak {:.3} N at t = {:.6} s, final angle {:.5} deg, {} onsets, {} separated impacts, {:.3} % of the time in contact, RMS force {:.4} N). Its own error, estimated by step halving from the run at 2e-6 s: {}.\n",
        v[0], v[1], v[2], v[3], v[4], 100.0 * v[5], v[6], fmt_errors(&ref_err)
    ));
    let explicit = find("adaptive, max 1e-3", DEFAULT_TOL);
    let paper = find("fixed", 1e-4);
    if let (Some(d), Some(p)) = (find(SUB_ADAPTIVE, DEFAULT_TOL), &paper) {
        md.push_str(&format!(
            "\nThe default (sub-cycled, adaptive, tolerance {DEFAULT_TOL}): {} of the paper's fixed 1e-4 s run's wall time; within the bounds: {}.\n",
            ratio(d.wall_s, p.wall_s),
            if within_bounds(&errors(&d, &reference)) { "yes" } else { "no" }
        ));
    }
    if let (Some(d), Some(p)) = (explicit, paper) {
        let de = errors(&d, &reference);
        md.push_str(&format!(
            "\nExplicit, adaptive (largest step 1e-3 s, tolerance {DEFAULT_TOL}): {} of the paper's fixed 1e-4 s run's wall time; within the bounds (peak 1 %, angle 0.01 deg, onsets 3 %, contact 5 %): {}.\n",
            ratio(d.wall_s, p.wall_s),
            if within_bounds(&de) { "yes" } else { "no" }
        ));
        // The cheapest fixed step as accurate as explicit adaptive on every metric, and the cheapest
        // within the bounds.
        let fixed: Vec<&(&str, f64, [f64; 8])> = points.iter().filter(|p| p.0 == "fixed").collect();
        let all = fixed
            .iter()
            // Differences below the reference's own error are ties.
            .filter(|p| (0..8).all(|k| p.2[k] <= de[k].max(ref_err[k])))
            .map(|p| p.1)
            .fold(f64::INFINITY, f64::min);
        let bounds = fixed
            .iter()
            .filter(|p| within_bounds(&p.2))
            .map(|p| p.1)
            .fold(f64::INFINITY, f64::min);
        md.push_str(&format!(
            "Cheapest fixed step within the bounds: {} (explicit adaptive is {} faster). Cheapest fixed step at least as accurate as explicit adaptive on every metric (differences below the reference's own error count as ties): {}{}.\n",
            fmt_time(bounds),
            speedup(bounds, d.wall_s),
            fmt_time(all),
            if all.is_finite() {
                format!(" (explicit adaptive is {} faster)", speedup(all, d.wall_s))
            } else {
                " (none of the fixed steps run, down to 2e-6 s)".to_string()
            }
        ));
    }
    // The workspace's `bench_out/` (cargo runs a bench in its package's folder, `app/`).
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../bench_out");
    std::fs::create_dir_all(&dir).unwrap();
    write_atomic(&dir.join("work_precision.csv"), csv.as_bytes()).unwrap();
    write_atomic(&dir.join("work_precision.md"), md.as_bytes()).unwrap();
    plot(&dir.join("work_precision.svg"), &points).unwrap();
    println!("{md}");
}

fn ratio(a: f64, b: f64) -> String {
    format!("{:.2}", a / b)
}

fn speedup(slow: f64, fast: f64) -> String {
    if slow.is_finite() {
        format!("{:.1} times", slow / fast)
    } else {
        "-".into()
    }
}

fn fmt_time(t: f64) -> String {
    if t.is_finite() {
        format!("{t:.3} s")
    } else {
        "never (within the runs)".into()
    }
}

fn plot(
    path: &Path,
    points: &[(&'static str, f64, [f64; 8])],
) -> Result<(), Box<dyn std::error::Error>> {
    std::fs::create_dir_all(path.parent().unwrap())?;
    // Text needs a font with plotters' ab_glyph backend: the one the crate ships.
    plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        include_bytes!("../assets/fonts/DejaVuSans.ttf"),
    )
    .map_err(|_| "font")?;
    let root = SVGBackend::new(path, (900, 420)).into_drawing_area();
    root.fill(&WHITE)?;
    let (left, right) = root.split_horizontally(450);
    let tmin = points.iter().map(|p| p.1).fold(f64::INFINITY, f64::min) / 2.0;
    let tmax = points.iter().map(|p| p.1).fold(0.0, f64::max) * 2.0;
    for (area, title, pick, unit) in [
        (&left, "first-impact peak force", 0usize, "relative error"),
        (&right, "contact onsets over 5 s", 3usize, "relative error"),
    ] {
        let val = |p: &(&str, f64, [f64; 8])| p.2[pick];
        let emin = points
            .iter()
            .map(val)
            .filter(|v| *v > 0.0)
            .fold(f64::INFINITY, f64::min)
            / 2.0;
        let emax = points.iter().map(val).fold(0.0, f64::max) * 2.0;
        let mut chart = ChartBuilder::on(area)
            .caption(title, ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d((tmin..tmax).log_scale(), (emin..emax).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("wall time (s)")
            .y_desc(unit)
            .draw()?;
        for (mode, color) in [
            ("fixed", RED),
            ("adaptive, max 1e-3", BLUE),
            ("adaptive, max 1e-4", GREEN),
            (SUB_ADAPTIVE, MAGENTA),
            (SUB_FIXED, BLACK),
        ] {
            let mut series: Vec<(f64, f64)> = points
                .iter()
                .filter(|p| p.0 == mode)
                .map(|p| (p.1, val(p).max(emin)))
                .collect();
            series.sort_by(|a, b| a.0.total_cmp(&b.0));
            chart
                .draw_series(LineSeries::new(series.clone(), color.stroke_width(2)))?
                .label(mode)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
            chart.draw_series(
                series
                    .iter()
                    .map(|&(x, y)| Circle::new((x, y), 4, color.filled())),
            )?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()?;
    }
    root.present()?;
    Ok(())
}
