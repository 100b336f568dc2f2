//! Issue 16, item 9: at c = 0.1 mm the slider-crank's pin is in continuous contact in converged
//! physics, yet every run counts a few onsets per turn. Physics or artefact?
//!
//! `cargo bench --bench continuous_contact` runs the benchmark slider-crank
//! (`assets/flores_slider_crank.ron`, c = 0.1 mm, three turns) at fixed steps and varies what
//! could make the journal leave the wall numerically: the step, the position correction of
//! Rapier's ideal joints (their softness: natural frequency and damping ratio, which set the
//! fraction of a constraint error corrected per step), and the crank's drive (a velocity-based
//! kinematic body, or a position-based one whose pose is set exactly at every step). For each
//! run it prints the onsets after the first turn, the widest gap each free flight opened, and the
//! ideal joints' position errors (crank pin: the rod's end against the crank pin; guide: the
//! slider off its axis), read from output rows at every step.

use clearance_joint::scene::runner::{RunOptions, Simulation, TwinKind, Twins};
use clearance_joint::scene::{MotionSpec, Scene};
use rapier3d_f64::prelude::*;
use std::path::Path;

const L1: f64 = 0.05;
const L2: f64 = 0.12;
const OMEGA: f64 = 5000.0 * std::f64::consts::TAU / 60.0;
const TURN: f64 = std::f64::consts::TAU / OMEGA;
const C: f64 = 0.1e-3;

#[derive(Clone, Copy)]
enum Crank {
    /// The scene's `Spin`: a velocity-based kinematic body.
    Spin,
    /// A `TableAngle` drive: a position-based kinematic body, its pose exact at every step.
    Table,
}

struct Variant {
    label: String,
    dt: f64,
    /// Joint softness (natural frequency, Hz; damping ratio); `None`: Rapier's default
    /// (1e6 Hz, 1).
    softness: Option<(f64, f64)>,
    crank: Crank,
}

fn main() {
    let mut variants = Vec::new();
    for dt in [1e-6, 5e-7, 2.5e-7, 1.25e-7] {
        variants.push(Variant {
            label: format!("fixed {dt:e}"),
            dt,
            softness: None,
            crank: Crank::Spin,
        });
    }
    for (f, z) in [(1e4, 1.0), (1e8, 1.0), (1e6, 10.0)] {
        variants.push(Variant {
            label: format!("fixed 5e-7, joints {f:e} Hz, damping ratio {z}"),
            dt: 5e-7,
            softness: Some((f, z)),
            crank: Crank::Spin,
        });
    }
    variants.push(Variant {
        label: "fixed 5e-7, crank by exact pose (TableAngle)".into(),
        dt: 5e-7,
        softness: None,
        crank: Crank::Table,
    });
    println!(
        "| run | onsets after turn 1 | of which after a gap >= 0.1 um | widest gap of those free \
         flights (um) | their longest flight (us) | crank-pin error, max (um) | guide error, max \
         (um) | late onsets: crank angle (deg), approach speed (mm/s) |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for v in &variants {
        println!("{}", measure(v));
    }
}

fn measure(v: &Variant) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/flores_slider_crank.ron");
    let mut scene = Scene::load(&path)
        .unwrap()
        .with_overrides(&[
            "slider_pin.clearance_mm=0.1".to_string(),
            "run.step=Fixed".into(),
            format!("run.dt_s={}", v.dt),
            format!("run.output_interval_s={}", v.dt),
            "run.end_s=0.036".into(),
            "run.body_motion=true".into(),
        ])
        .unwrap();
    if let Crank::Table = v.crank {
        // theta = omega t, tabulated every 0.1 ms: linear data, so the cubic Hermite is exact.
        let n = 361;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-4).collect();
        scene.bodies[1].motion = Some(MotionSpec::TableAngle {
            axis: [0.0, 0.0, 1.0],
            point_m: [0.0, 0.0, 0.0],
            angle_rad: t.iter().map(|t| OMEGA * t).collect(),
            t_s: t,
        });
    }
    let mut sim = Simulation::new(
        &scene,
        RunOptions {
            twins: Twins::ClearanceOnly,
            skip_rows: false,
        },
    )
    .unwrap();
    if let Some((f, z)) = v.softness {
        for (_, j) in sim.world.rapier.impulse_joints.iter_mut() {
            j.data.softness = SpringCoefficients::new(f, z);
        }
    }
    let r = match sim.run() {
        Ok(r) => r,
        Err(e) => return format!("| {} | failed: {e} | | | | | | |", v.label),
    };
    let twin = r.twin(TwinKind::Clearance).unwrap();
    let rec = twin.hinge_recorders()["slider_pin"];
    let late: Vec<_> = rec
        .contacts()
        .iter()
        .filter(|i| i.onset_t_s >= TURN)
        .collect();
    let separated = late.iter().filter(|i| i.separated).count();
    let col = |name: &str| twin.table.column(name).unwrap();
    let (t, u, w) = (
        col("t_s"),
        col("slider_pin_ecc_u_mm"),
        col("slider_pin_ecc_v_mm"),
    );
    // The widest gap and longest flight before each late onset (rows at every step).
    let (mut widest, mut longest) = (0.0f64, 0.0f64);
    let list = rec.contacts();
    for (k, i) in list.iter().enumerate().filter(|(_, i)| i.onset_t_s >= TURN) {
        let from = k
            .checked_sub(1)
            .map_or(0.0, |p| list[p].onset_t_s + list[p].duration_s);
        longest = longest.max(i.onset_t_s - from);
        for n in 0..t.len() {
            if t[n] > from && t[n] < i.onset_t_s {
                let gap = C - 1e-3 * (u[n].hypot(w[n]));
                widest = widest.max(gap);
            }
        }
    }
    // Ideal joints' position errors: the rod's crank end against the crank pin, and the slider
    // off the guide's axis (y = 0).
    let (rx, ry, ra, sy) = (
        col("rod_x_m"),
        col("rod_y_m"),
        col("rod_angle_deg"),
        col("slider_y_m"),
    );
    let (mut pin, mut guide) = (0.0f64, 0.0f64);
    for n in 0..t.len() {
        let phi = ra[n].to_radians();
        let end = (rx[n] - 0.5 * L2 * phi.cos(), ry[n] - 0.5 * L2 * phi.sin());
        let crank = (L1 * (OMEGA * t[n]).cos(), L1 * (OMEGA * t[n]).sin());
        pin = pin.max((end.0 - crank.0).hypot(end.1 - crank.1));
        guide = guide.max(sy[n].abs());
    }
    let angles: Vec<String> = late
        .iter()
        .map(|i| {
            format!(
                "{:.0}, {:.0}",
                (OMEGA * i.onset_t_s).to_degrees() % 360.0,
                i.approach_speed_m_s * 1e3
            )
        })
        .collect();
    format!(
        "| {} | {} ({:.1} per turn) | {} | {:.3} | {:.1} | {:.4} | {:.4} | {} |",
        v.label,
        late.len(),
        late.len() as f64 / 2.0,
        separated,
        widest * 1e6,
        longest * 1e6,
        pin * 1e6,
        guide * 1e6,
        angles.join("; ")
    )
}
