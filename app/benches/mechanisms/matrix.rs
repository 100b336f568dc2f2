//! The mechanism matrix: scenes of the benchmark set, each run at the library's defaults and at
//! fixed steps halved twice, and the figures that compare them. Shared by the benchmark
//! (`cargo bench --bench mechanisms`) and the accuracy test (`app/tests/matrix.rs`).
//!
//! Every run goes through the library's runner ([`Simulation`]); every figure comes from its
//! impact lists ([`Impact`], recorded at every internal step) and its output rows.

#![allow(dead_code)] // the test uses a part of it

use clearance_joint::rapier::observers::metrics::Impact;
use clearance_joint::rapier::pipeline::protocol::Violation;
use clearance_joint::scene::Scene;
use clearance_joint::scene::runner::{RunOptions, Simulation, TwinKind, Twins};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Where a case's statistics are taken after the first impacts (they turn chaotic).
#[derive(Clone, Copy, Debug)]
pub enum Unit {
    /// A driven mechanism: per crank turn of this length, s.
    Turn(f64),
    /// Per second.
    Second,
}

/// The ideal slider-crank's slider acceleration in closed form (crank `l1`, rod `l2`, m;
/// crank speed `omega`, rad/s; crank angle 0 at t = 0).
#[derive(Clone, Copy, Debug)]
pub struct SliderCrankForm {
    /// Crank length, m.
    pub l1: f64,
    /// Rod length, m.
    pub l2: f64,
    /// Crank speed, rad/s.
    pub omega: f64,
}

impl SliderCrankForm {
    /// `x''(theta)` of `x = l1 cos(theta) + sqrt(l2^2 - l1^2 sin^2(theta))`, m/s^2.
    pub fn acceleration(&self, theta: f64) -> f64 {
        let (l1, l2) = (self.l1, self.l2);
        let s = (l2 * l2 - (l1 * theta.sin()).powi(2)).sqrt();
        let q = l1 * l1;
        let x2 = -l1 * theta.cos()
            - q * (2.0 * theta).cos() / s
            - q * q * (2.0 * theta).sin().powi(2) / (4.0 * s.powi(3));
        self.omega * self.omega * x2
    }
}

/// One scene of the matrix.
#[derive(Clone, Debug)]
pub struct Case {
    /// Label in the tables.
    pub name: &'static str,
    /// Scene file under the repository's `assets/`.
    pub file: &'static str,
    /// `--set` overrides that make the variant (applied before the run settings).
    pub set: Vec<String>,
    /// The clearance hinge measured.
    pub hinge: &'static str,
    /// The body whose acceleration is compared with the ideal twin's.
    pub probe: &'static str,
    /// Simulated time, s (full run), and of the quick run.
    pub end_s: f64,
    /// Simulated time of the quick (shortened) run, s.
    pub quick_end_s: f64,
    /// Start of the statistics window, s (its end is the run's end).
    pub window_start_s: f64,
    /// Start of the window in the quick run, s.
    pub quick_window_start_s: f64,
    /// Onsets per turn or per second.
    pub unit: Unit,
    /// Fixed steps, each half the previous; the last is the reference.
    pub fixed_dt: [f64; 3],
    /// Output rows, s (for the acceleration comparison; rows never change the steps).
    pub output_interval_s: f64,
    /// The ideal twin's closed form, where one exists.
    pub closed_form: Option<SliderCrankForm>,
}

/// The perturbations of a start: the measured hinge's clearance times `1 + e` for each `e`. A
/// chaotic window's statistics move under a perturbation no measurement could see (half a
/// micrometre of play) by far more than between step sizes, which follow one trajectory: its
/// converged spread is the spread over perturbed starts, and the default's value is the mean
/// over its own perturbed starts, not one sample (on the slider-crank at 2000 rpm the default's
/// largest force in turns 2-3 was 4,648 N from the nominal start and 8.2-10.2 kN from perturbed
/// ones, against 7.7-11.0 kN for converged runs, measured with the rod's initial speed
/// perturbed).
pub const PERTURBATIONS: [f64; 4] = [1e-4, -1e-4, 1e-3, -1e-3];

/// `case` with the measured hinge's clearance times `1 + e` (after the case's own overrides).
pub fn perturbed(case: &Case, e: f64) -> Case {
    let scene = scene(case, Stepping::Default, case.end_s);
    let c = scene
        .hinges
        .iter()
        .find(|h| h.name == case.hinge)
        .and_then(|h| h.clearance.as_ref())
        .expect("the measured hinge has a clearance")
        .clearance_mm;
    let mut out = case.clone();
    out.set
        .push(format!("{}.clearance_mm={}", case.hinge, c * (1.0 + e)));
    out
}

const FLORES: &str = "flores_slider_crank.ron";
const OMEGA_5000: f64 = 5000.0 * std::f64::consts::TAU / 60.0;
const OMEGA_2000: f64 = 2000.0 * std::f64::consts::TAU / 60.0;

fn flores(name: &'static str, set: &[&str], omega: f64) -> Case {
    let turn = std::f64::consts::TAU / omega;
    Case {
        name,
        file: FLORES,
        set: set.iter().map(|s| s.to_string()).collect(),
        hinge: "slider_pin",
        probe: "slider",
        end_s: 3.0 * turn,
        quick_end_s: turn,
        window_start_s: turn,
        quick_window_start_s: 0.5 * turn,
        unit: Unit::Turn(turn),
        fixed_dt: [1e-6, 5e-7, 2.5e-7],
        output_interval_s: 1e-5,
        closed_form: Some(SliderCrankForm {
            l1: 0.05,
            l2: 0.12,
            omega,
        }),
    }
}

/// A shaft cantilevered from one spatial hinge (`assets/cantilever.ron`) with its centre of mass
/// `offset` (m) out along the axis and the inertia `across` (kg m^2) about both transverse axes
/// (half that about its own).
fn cantilever(name: &'static str, offset: f64, across: f64) -> Case {
    Case {
        name,
        file: "cantilever.ron",
        set: vec![
            format!("shaft.center_of_mass_m=[0,0,{offset}]"),
            format!("shaft.inertia_kg_m2=[{across},{across},{}]", 0.5 * across),
        ],
        hinge: "hinge",
        probe: "shaft",
        end_s: 0.2,
        quick_end_s: 0.05,
        window_start_s: 0.1,
        quick_window_start_s: 0.025,
        unit: Unit::Second,
        fixed_dt: [5e-7, 2.5e-7, 1.25e-7],
        output_interval_s: 1e-4,
        closed_form: None,
    }
}

/// The matrix: the slider-crank (c = 0.5 and 0.1 mm, the bearing on the rod, 2000 rpm), the
/// four-bar (the improved law, and Flores et al.'s), the paper's solar panel at T, 3T and 5T, the
/// deployable array, the double pendulum and four cantilevers on a spatial hinge (offsets 0.05 to
/// 0.4 m, inertias 2e-4 to 0.2 kg m^2).
pub fn cases() -> Vec<Case> {
    let panel = |name: &'static str, scale: &str| Case {
        name,
        file: "solar_panel.ron",
        set: vec![format!("drive.torque_scale={scale}")],
        hinge: "hinge",
        probe: "panel",
        end_s: 5.0,
        quick_end_s: 0.25,
        window_start_s: 1.0,
        quick_window_start_s: 0.125,
        unit: Unit::Second,
        fixed_dt: [8e-6, 4e-6, 2e-6],
        output_interval_s: 1e-4,
        closed_form: None,
    };
    let four_bar = Case {
        name: "four-bar",
        file: "four_bar.ron",
        set: vec![],
        hinge: "rocker_pin",
        probe: "rocker",
        end_s: 0.2,
        quick_end_s: 0.05,
        window_start_s: 0.1,
        quick_window_start_s: 0.025,
        unit: Unit::Turn(0.1),
        // With the scene's 32 sweeps over the joints the first impact's peak is 5,283 N at all
        // three steps (it moved at first order, 5,341, 5,312 and 5,297 N, while the contact
        // laws read the stored rate; with one sweep 5,177, 5,229 and 5,257 N then).
        fixed_dt: [2.5e-7, 1.25e-7, 6.25e-8],
        output_interval_s: 1e-4,
        closed_form: None,
    };
    vec![
        flores("slider-crank c=0.5mm", &[], OMEGA_5000),
        flores(
            "slider-crank c=0.1mm",
            &["slider_pin.clearance_mm=0.1"],
            OMEGA_5000,
        ),
        // The same pin turned round: the rod carries the bearing, the slider the journal.
        flores(
            "slider-crank bearing on rod",
            &["slider_pin.bearing=rod", "slider_pin.journal=slider"],
            OMEGA_5000,
        ),
        flores(
            "slider-crank 2000rpm",
            &[
                "crank.rate_rad_s=209.43951023931953",
                "rod.velocity_m_s=[0,5.235987755982989,0]",
                "rod.angular_velocity_rad_s=[0,0,-87.26646259971649]",
            ],
            OMEGA_2000,
        ),
        four_bar.clone(),
        // A damped hysteresis law (Flores et al., cr 0.8, the geometric stiffness) at the pin of
        // a closed loop held by a motor: its damping reads the contact's effective mass through
        // the loop.
        Case {
            name: "four-bar Flores",
            set: vec![r#"rocker_pin.contact={"FloresEtAl":{"restitution":0.8}}"#.into()],
            ..four_bar.clone()
        },
        panel("solar panel T", "1"),
        panel("solar panel 3T", "3"),
        panel("solar panel 5T", "5"),
        Case {
            name: "deployable array",
            file: "deployable_array.ron",
            set: vec![],
            hinge: "root",
            probe: "panel3",
            end_s: 2.0,
            quick_end_s: 0.3,
            window_start_s: 0.5,
            quick_window_start_s: 0.15,
            unit: Unit::Second,
            // Its fixed runs' first onset is 17.1933-17.1934 ms at these steps. While the contact
            // laws read the stored rate it moved at first order with the step (17.2084, 17.1984
            // and 17.1963 ms at 2e-5, 1e-5 and 5e-6 s, 17.1948, 17.1941 and 17.1937 ms at these),
            // and a reference at 5e-6 s was 2.9 us from the limit.
            fixed_dt: [2.5e-6, 1.25e-6, 6.25e-7],
            // Rows every 0.1 ms: its contacts last about 0.3 ms, and with rows every 1 ms the
            // RMS acceleration difference over the quick window's 150 rows was a count of the
            // rows that fell in a contact (0.04052 m/s^2 in runs where none did, up to 1.19
            // where one did; the five-start means of the fixed 2.5e-6, 1.25e-6 and 6.25e-7 s
            // runs 0.17, 0.52 and 0.53). At 0.1 ms the fixed 2.5e-6 s starts give 0.534-0.615,
            // at 0.01 ms 0.534-0.624 (docs/sub-cycled-contact.md, Limits).
            output_interval_s: 1e-4,
            closed_form: None,
        },
        Case {
            name: "double pendulum",
            file: "double_pendulum.ron",
            set: vec![],
            hinge: "elbow",
            probe: "link2",
            end_s: 1.0,
            quick_end_s: 0.25,
            window_start_s: 0.25,
            quick_window_start_s: 0.125,
            unit: Unit::Second,
            // Its window's RMS acceleration difference moves with the step: 0.3408, 0.3385 and
            // 0.3378 at these steps (0.3550 and 0.3382 at 4e-6 and 1e-6 s while the contact laws
            // read the stored rate); references down to 1e-6 s made a spread too wide.
            fixed_dt: [1e-6, 5e-7, 2.5e-7],
            output_interval_s: 1e-4,
            closed_form: None,
        },
        cantilever("cantilever 0.2 m, 2e-3", 0.2, 0.002),
        cantilever("cantilever 0.05 m, 2e-4", 0.05, 2e-4),
        cantilever("cantilever 0.1 m, 2e-2", 0.1, 0.02),
        cantilever("cantilever 0.4 m, 0.2", 0.4, 0.2),
    ]
}

/// How a case is stepped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stepping {
    /// The library's defaults: adaptive, `tolerance` 0.0075, `max_dt_s` 1e-3 s.
    Default,
    /// A fixed step, s.
    Fixed(f64),
}

impl Stepping {
    /// `default` or the step.
    pub fn label(&self) -> String {
        match self {
            Stepping::Default => "default".into(),
            Stepping::Fixed(dt) => format!("fixed {dt:e}"),
        }
    }
}

/// One run of a case.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// How it was stepped.
    pub stepping: Stepping,
    /// The run's error, if it failed (nothing else is then meaningful).
    pub error: Option<String>,
    /// Guard violations, the worst of each kind per joint (empty: clean).
    pub violations: Vec<Violation>,
    /// Internal steps.
    pub steps: u64,
    /// The measured hinge's sub-steps over the run (0 when it is explicit).
    pub substeps: u64,
    /// Wall time of the run (both twins in one world), s.
    pub wall_s: f64,
    /// The measured hinge's contacts, recorded at every internal step.
    pub impacts: Vec<Impact>,
    /// Simulated time, s.
    pub end_s: f64,
    /// Largest joint force and penetration over the whole run, N and um.
    pub peak_force_n: f64,
    /// Largest penetration over the whole run, um.
    pub max_penetration_um: f64,
    /// RMS over the window's rows of the probe body's acceleration, clearance minus ideal twin
    /// (vector difference), m/s^2.
    pub rms_acc_diff: f64,
    /// Largest difference of the ideal twin's probe acceleration along x from the closed form,
    /// over the largest closed-form acceleration (all rows).
    pub closed_form_error: Option<f64>,
}

impl Outcome {
    /// Ran to the end with no guard violation.
    pub fn clean(&self) -> bool {
        self.error.is_none() && self.violations.is_empty()
    }
}

/// The repository's `assets/` folder.
pub fn assets() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets")
}

/// The case's scene with its variant, `end_s` and the stepping applied.
pub fn scene(case: &Case, stepping: Stepping, end_s: f64) -> Scene {
    let base = Scene::load(&assets().join(case.file)).expect("the matrix's scenes load");
    let mut set = vec![
        format!("run.end_s={end_s}"),
        format!("run.output_interval_s={}", case.output_interval_s),
        "run.body_motion=true".into(),
        "run.strict=false".into(),
    ];
    match stepping {
        Stepping::Default => {
            set.extend(
                [
                    "run.step=Adaptive",
                    "run.tolerance=0.0075",
                    "run.max_dt_s=0.001",
                ]
                .map(String::from),
            );
            // The ablation's choice of contact integration (`Explicit` or `SubCycled`), else
            // the scene's own (the library's default unless its file chooses).
            if let Ok(integration) = std::env::var("MECHANISMS_INTEGRATION") {
                set.push(format!("run.contact_integration={integration}"));
            }
        }
        Stepping::Fixed(dt) => {
            // The references: the explicit model at converged fixed steps.
            set.extend([
                "run.step=Fixed".into(),
                format!("run.dt_s={dt}"),
                "run.contact_integration=Explicit".into(),
            ]);
        }
    }
    // The case's own settings last: a case may override the stepping's (a study of one knob).
    set.extend(case.set.iter().cloned());
    base.with_overrides(&set)
        .expect("the matrix's overrides apply")
}

/// Runs a case (both twins) and measures it; `window_start_s` starts the acceleration window. A
/// run still going after `cap_s` of wall time is abandoned and reported as such (a stalling run
/// would otherwise hold the whole matrix up).
pub fn run(
    case: &Case,
    stepping: Stepping,
    end_s: f64,
    window_start_s: f64,
    cap_s: f64,
) -> Outcome {
    let scene = scene(case, stepping, end_s);
    let mut out = Outcome {
        stepping,
        error: None,
        violations: Vec::new(),
        steps: 0,
        substeps: 0,
        wall_s: 0.0,
        impacts: Vec::new(),
        end_s,
        peak_force_n: 0.0,
        max_penetration_um: 0.0,
        rms_acc_diff: f64::NAN,
        closed_form_error: None,
    };
    let start = Instant::now();
    let reached = std::cell::Cell::new(0.0);
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        Simulation::new(
            &scene,
            RunOptions {
                twins: Twins::Both,
                skip_rows: false,
            },
        )
        .and_then(|sim| {
            sim.run_with_progress(|p| {
                reached.set(p.t);
                // Every 16 steps: a sub-cycled step may take up to `MAX_SUBSTEPS` sub-steps
                // (a technique switched off in the ablation), so a thousand can take minutes.
                if p.steps % 16 == 0 && start.elapsed().as_secs_f64() > cap_s {
                    std::panic::panic_any(Abandoned);
                }
            })
        })
    }));
    out.wall_s = start.elapsed().as_secs_f64();
    let r = match result {
        Ok(Ok(r)) => r,
        Ok(Err(e)) => {
            out.error = Some(e.to_string());
            return out;
        }
        Err(p) if p.is::<Abandoned>() => {
            out.error = Some(format!(
                "abandoned after {cap_s} s of wall time at t = {:.6} s",
                reached.get()
            ));
            return out;
        }
        Err(p) => std::panic::resume_unwind(p),
    };
    out.steps = r.steps;
    out.violations = r.guards.violations.clone();
    let (ideal, clear) = (
        r.twin(TwinKind::Ideal).unwrap(),
        r.twin(TwinKind::Clearance).unwrap(),
    );
    let rec = clear.hinge_recorders()[case.hinge];
    out.impacts = rec.contacts().to_vec();
    out.substeps = rec.substeps_recorded();
    out.peak_force_n = rec.metrics().peak_force_n;
    out.max_penetration_um = rec.metrics().max_penetration_um;
    let t = ideal.table.column("t_s").unwrap();
    let acc = |table: &clearance_joint::table::Table, axis: &str| {
        table
            .column(&format!("{}_a{axis}_m_s2", case.probe))
            .unwrap()
    };
    let (ix, iy, cx, cy) = (
        acc(&ideal.table, "x"),
        acc(&ideal.table, "y"),
        acc(&clear.table, "x"),
        acc(&clear.table, "y"),
    );
    let (iz, cz) = (acc(&ideal.table, "z"), acc(&clear.table, "z"));
    let (mut sum, mut n) = (0.0, 0usize);
    for k in 0..t.len() {
        if t[k] >= window_start_s - 1e-12 {
            sum += (cx[k] - ix[k]).powi(2) + (cy[k] - iy[k]).powi(2) + (cz[k] - iz[k]).powi(2);
            n += 1;
        }
    }
    out.rms_acc_diff = if n > 0 {
        (sum / n as f64).sqrt()
    } else {
        f64::NAN
    };
    if let Some(form) = case.closed_form {
        let mut worst: f64 = 0.0;
        let mut scale: f64 = 0.0;
        for k in 0..t.len() {
            let a = form.acceleration(form.omega * t[k]);
            worst = worst.max((ix[k] - a).abs());
            scale = scale.max(a.abs());
        }
        out.closed_form_error = Some(worst / scale);
    }
    out
}

/// The payload of the panic that abandons a run over its wall-time cap.
struct Abandoned;

/// Silences the report of the panic that abandons a run (other panics are reported as usual).
pub fn quiet_abandon() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if !info.payload().is::<Abandoned>() {
            default(info);
        }
    }));
}

/// Statistics of a window `[start, end]` of an impact list.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WindowStats {
    /// Largest peak force of the contacts that overlap the window, N.
    pub largest_force_n: f64,
    /// Deepest penetration of the contacts that overlap the window, um.
    pub deepest_um: f64,
    /// Contact onsets in the window, per turn or per second.
    pub onsets_per_unit: f64,
    /// Fraction of the window in contact (contacts clipped at its bounds).
    pub contact_fraction: f64,
}

/// The window statistics of `impacts` over `[start, end]`.
pub fn window(impacts: &[Impact], start: f64, end: f64, unit: Unit) -> WindowStats {
    let mut w = WindowStats::default();
    let mut onsets = 0usize;
    let mut contact = 0.0;
    for i in impacts {
        let (a, b) = (i.onset_t_s, i.onset_t_s + i.duration_s);
        if b < start || a > end {
            continue;
        }
        w.largest_force_n = w.largest_force_n.max(i.peak_force_n);
        w.deepest_um = w.deepest_um.max(i.max_penetration_um);
        if a >= start {
            onsets += 1;
        }
        contact += (b.min(end) - a.max(start)).max(0.0);
    }
    let len = end - start;
    let units = match unit {
        Unit::Turn(turn) => len / turn,
        Unit::Second => len,
    };
    w.onsets_per_unit = onsets as f64 / units;
    w.contact_fraction = contact / len;
    w
}

/// How many of the first impacts of `a` match those of `b` in sequence: onsets within 1 us and
/// peaks within 1 % (the bounds `run --check` holds a first impact to).
pub fn matched(a: &[Impact], b: &[Impact]) -> usize {
    use clearance_joint::scene::runner::convergence::{FORCE_BOUND, ONSET_BOUND_S};
    a.iter()
        .zip(b)
        .take_while(|(x, y)| {
            (x.onset_t_s - y.onset_t_s).abs() <= ONSET_BOUND_S
                && (x.peak_force_n / y.peak_force_n - 1.0).abs() <= FORCE_BOUND
        })
        .count()
}

/// Relative difference `a/b - 1`.
pub fn rel(a: f64, b: f64) -> f64 {
    a / b - 1.0
}

/// A guard violation's kind and subject: the guard, the joint and the twin (the values and the
/// time differ between runs, these do not).
pub fn violation_kind(v: &Violation) -> String {
    format!(
        "{:?} {} {}",
        v.kind,
        v.joint.as_deref().unwrap_or("-"),
        v.twin.as_deref().unwrap_or("-")
    )
}

/// The violations of `run` of a kind the `converged` run does not show: what the defaults
/// flagged beyond the converged physics itself (e.g. a first impact deeper than the contact
/// law's validity limit is flagged in every run, converged or not).
pub fn new_violations(run: &Outcome, converged: &Outcome) -> Vec<String> {
    let known: Vec<String> = converged.violations.iter().map(violation_kind).collect();
    run.violations
        .iter()
        .filter(|v| !known.contains(&violation_kind(v)))
        .map(|v| v.to_string())
        .collect()
}

/// `x` to four significant digits (scientific outside 1e-3..1e5), `-` when not finite.
pub fn sig(x: f64) -> String {
    if !x.is_finite() {
        return "-".into();
    }
    let a = x.abs();
    if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e5).contains(&a) {
        format!("{x:.3e}")
    } else {
        let digits = (4 - 1 - a.log10().floor() as i32).max(0) as usize;
        format!("{x:.digits$}")
    }
}

/// `x` as a signed percentage with two decimals, `-` when not finite.
pub fn pct(x: f64) -> String {
    if x.is_finite() {
        format!("{:+.2} %", 100.0 * x)
    } else {
        "-".into()
    }
}
