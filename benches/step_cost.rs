//! Cost of one step: ideal twin vs clearance twin, and the two ways of holding the out-of-plane
//! degrees of freedom (a relative GenericJoint vs per-body LockedAxes). `cargo bench --bench step_cost`.
//! Medians of 5 runs of the paper's 5-s scene at dt = 1e-4 s; ratios are measured in one run.
//! Then the spatial joint against the planar one on a plain-API arm (`cargo bench --bench
//! step_cost -- spatial` runs that part alone).

use clearance_joint::model::laws::{Bai, FrictionModel};
use clearance_joint::model::spatial::SpatialModel;
use clearance_joint::prelude::*;
use clearance_joint::scene::Scene;
use clearance_joint::scene::runner::{RunOptions, Simulation, Twins};
use rapier3d_f64::prelude::LockedAxes;
use std::time::Instant;

#[path = "../tests/support/arm.rs"]
mod support;

fn median_us_per_step(mut make: impl FnMut() -> Simulation) -> f64 {
    let mut samples: Vec<f64> = (0..5)
        .map(|_| {
            let sim = make();
            let start = Instant::now();
            let r = sim.run().expect("stable run");
            start.elapsed().as_secs_f64() / r.steps as f64 * 1e6
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[2]
}

/// The shared arm (`tests/support/arm.rs`) on a steel pin (radius 10 mm, clearance 0.2 mm, width
/// 16 mm, dry friction) at fixed steps of `dt`, its centre of mass `offset` m off the hinge's
/// mid-plane along the axis; `model` None is the planar joint with its default lock.
fn arm(model: Option<SpatialModel>, offset: f64, dt: f64) -> ClearanceWorld {
    let mut clearance = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)
        .unwrap()
        .friction(FrictionModel::Bai(Bai::DRY));
    if let Some(model) = model {
        clearance = clearance.model(ClearanceModel::Spatial(model));
    }
    support::arm(clearance, offset, StepControl::fixed(dt)).0
}

/// us per step of one run of the arm over 0.25 s at a fixed 5e-6 s (the tilted arm's edge
/// contact, heavily damped, needs less than 1e-5 s).
fn arm_us_per_step(model: Option<SpatialModel>, offset: f64) -> f64 {
    let (dt, until) = (5e-6, 0.25);
    let mut world = arm(model, offset, dt);
    let start = Instant::now();
    let steps = world.step_to(until).expect("stable run");
    start.elapsed().as_secs_f64() / steps as f64 * 1e6
}

fn spatial_cost() {
    let steel = Some(SpatialModel::steel(1e-3, 0.015));
    let cases = [
        ("planar joint (hook + GenericJoint lock)", None, 0.0),
        ("spatial, aligned load", steel, 0.0),
        ("spatial, CoM 50 mm off the mid-plane", steel, 0.05),
    ];
    // Interleaved rounds, so a change of the machine's load between cases moves every case
    // alike; per case the median of 5, and the median of its 5 ratios to the planar run of the
    // same round.
    let rounds: Vec<Vec<f64>> = (0..5)
        .map(|_| {
            cases
                .iter()
                .map(|&(_, model, offset)| arm_us_per_step(model, offset))
                .collect()
        })
        .collect();
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[2]
    };
    println!();
    println!("| arm on one pin (dt = 5e-6 s, 50,000 steps) | us/step | ratio to planar |");
    println!("|---|---|---|");
    for (k, (name, _, _)) in cases.iter().enumerate() {
        let us = median(rounds.iter().map(|r| r[k]).collect());
        let ratio = median(rounds.iter().map(|r| r[k] / r[0]).collect());
        println!("| {name} | {us:.2} | {ratio:.2} |");
    }
}

fn main() {
    if std::env::args().skip(1).any(|a| a == "spatial") {
        spatial_cost();
        return;
    }
    // Fixed steps: the cost of one step, not of a step count that varies.
    let scene = Scene::solar_panel()
        .with_overrides(&["run.step=Fixed"])
        .unwrap();
    let opts = |twins| RunOptions {
        twins,
        skip_rows: true,
    };
    let ideal = median_us_per_step(|| Simulation::new(&scene, opts(Twins::IdealOnly)).unwrap());
    let clearance =
        median_us_per_step(|| Simulation::new(&scene, opts(Twins::ClearanceOnly)).unwrap());
    let both = median_us_per_step(|| Simulation::new(&scene, opts(Twins::Both)).unwrap());
    // LockedAxes instead of the GenericJoint lock: scenes refuse `lock: None` (a scene has no
    // locked axes), so the lock joint is removed from the built world and the bodies locked here.
    let locked_axes = median_us_per_step(|| {
        let mut sim = Simulation::new(&scene, opts(Twins::ClearanceOnly)).unwrap();
        let locks: Vec<_> = sim
            .world
            .clearance
            .iter()
            .filter_map(|(_, j)| j.lock_handle())
            .collect();
        for h in locks {
            sim.world.rapier.impulse_joints.remove(h, true);
        }
        let planar = LockedAxes::TRANSLATION_LOCKED_Y
            | LockedAxes::ROTATION_LOCKED_X
            | LockedAxes::ROTATION_LOCKED_Z;
        for (_, rb) in sim.world.rapier.bodies.iter_mut() {
            rb.set_locked_axes(planar, true);
        }
        sim
    });
    println!("| scene (dt = 1e-4 s, 50,000 steps) | us/step | ratio to ideal |");
    println!("|---|---|---|");
    for (name, us) in [
        ("ideal twin alone (Rapier revolute joint)", ideal),
        ("clearance twin alone (hook + GenericJoint lock)", clearance),
        ("clearance twin alone (hook + LockedAxes)", locked_axes),
        ("both twins in one world (the default run)", both),
    ] {
        println!("| {name} | {us:.2} | {:.2} |", us / ideal);
    }
    spatial_cost();
}
