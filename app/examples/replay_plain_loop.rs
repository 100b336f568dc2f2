//! A replay from your own Rapier loop: a pendulum arm (a box collider) on a revolute hinge with
//! 0.2 mm of play, released at 60 degrees under gravity, stepped by a `ClearanceWorld`; the app's
//! `ReplayRecorder` reads the world after every step, and its `ReplayPage` writes the
//! self-contained `replay.html`.
//!
//! `cargo run --release -p clearance_joint_app --example replay_plain_loop [OUT_DIR]`
//! (default `out/replay_plain_loop`).

use clearance_joint::prelude::*;
use clearance_joint_app::replay::record::{JournalFrame, Recording, ReplayRecorder};
use clearance_joint_app::replay::{Line, ReplayPage, Series};
use rapier3d_f64::prelude::*;
use std::path::PathBuf;

/// Runs the arm for `end` s and returns what the recorder kept.
pub fn run(end: f64) -> clearance_joint::Result<Recording> {
    let mut world = PhysicsWorld::new(); // gravity -9.81 m/s^2 along y
    world.integration_parameters.num_solver_iterations = 1;
    let base = world.bodies.insert(RigidBodyBuilder::fixed());
    // The arm: 0.6 m long, pivot at its top end, started 60 degrees from hanging.
    let angle = 60f64.to_radians();
    let arm = world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.3 * angle.sin(), -0.3 * angle.cos(), 0.0))
            .rotation(Vector::new(0.0, 0.0, angle)),
    );
    // Its collider gives its mass (steel-like density) and its shape in the replay; no contact
    // with anything (the hinge holds it).
    let collider = ColliderBuilder::cuboid(0.02, 0.3, 0.01)
        .density(7800.0)
        .collision_groups(InteractionGroups::none());
    world
        .colliders
        .insert_with_parent(collider, arm, &mut world.bodies);
    let hinge = RevoluteJointBuilder::new(Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0));
    let hinge = world.impulse_joints.insert(base, arm, hinge, true);
    let mut clearance = ClearanceJointSet::new();
    let play = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)?;
    let hinge =
        clearance.convert_revolute(hinge, BearingSide::Body1, play, &mut world.impulse_joints)?;

    let mut world = ClearanceWorld::new(world, StepControl::adaptive(1e-3, 0.0075));
    world.clearance = clearance;
    world.prepare()?;
    let rapier = &mut world.rapier;
    // Mass properties before the first step (Rapier computes them in it).
    clearance_joint::rapier::observers::reaction::prepare_mass_properties(&mut rapier.bodies);
    // A frame per ms in free flight, per 10 us in contact (every onset and the state before it).
    let mut recorder = ReplayRecorder::new(1e-3, 1e-5)?;
    recorder.track_body("base", "clearance", base, &rapier.bodies, &rapier.colliders);
    recorder.track_body("arm", "clearance", arm, &rapier.bodies, &rapier.colliders);
    recorder.track_journal("hinge", "clearance", 0, hinge, &world.clearance)?;
    recorder.record(0.0, &world.rapier.bodies, &[&world.clearance]);
    while world.time() < end {
        world.step(end)?;
        recorder.record(world.time(), &world.rapier.bodies, &[&world.clearance]);
    }
    Ok(recorder.finish())
}

fn main() -> clearance_joint::Result<()> {
    let out = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("out/replay_plain_loop"));
    std::fs::create_dir_all(&out).map_err(|source| clearance_joint::Error::Io {
        action: "cannot create",
        path: out.clone(),
        source,
    })?;
    let recording = run(1.0)?;
    // Plot the journal's force and eccentricity from the recording itself.
    let t: Vec<f64> = recording.frames.iter().map(|f| f.t).collect();
    let line = |label: &str, v: Vec<f64>| Line {
        label: label.into(),
        group: "clearance".into(),
        t: t.clone(),
        v,
    };
    let journal = |f: &dyn Fn(&JournalFrame) -> f64| {
        recording
            .frames
            .iter()
            .map(|fr| f(&fr.journals[0]))
            .collect()
    };
    let series = vec![
        Series {
            title: "hinge: contact force (N)".into(),
            lines: vec![line("clearance", journal(&|j| j.force_n))],
        },
        Series {
            title: "hinge: eccentricity |e| (mm)".into(),
            lines: vec![line(
                "clearance",
                journal(&|j| j.ecc_u_m.hypot(j.ecc_v_m) * 1e3),
            )],
        },
    ];
    let page = ReplayPage {
        title: "pendulum with 0.2 mm of play: replay".into(),
        subtitle: "plain Rapier loop, adaptive steps of at most 1 ms, 1 s".into(),
        notes: format!(
            "{} frames kept by the recorder's rule (1 ms in free flight, 10 us in contact).",
            recording.frames.len()
        ),
        recording: &recording,
        series,
    };
    let path = page.write(&out)?;
    println!(
        "{} frames, {} impacts; wrote {}",
        recording.frames.len(),
        recording
            .frames
            .iter()
            .filter(|f| f.journals[0].impact)
            .count(),
        path.display()
    );
    Ok(())
}
