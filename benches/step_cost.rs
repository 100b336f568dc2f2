//! Cost of one step: ideal twin vs clearance twin, and the two ways of holding the out-of-plane
//! degrees of freedom (a relative GenericJoint vs per-body LockedAxes). `cargo bench --bench step_cost`.
//! Medians of 5 runs of the paper's 5-s scene at dt = 1e-4 s; ratios are measured in one run.

use clearance_joint::scene::Scene;
use clearance_joint::scene::runner::{RunOptions, Simulation, Twins};
use rapier3d_f64::prelude::LockedAxes;
use std::time::Instant;

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

fn main() {
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
}
