//! Scale: a robot arm of 30 joints (a chain of 30 links, 0.1 m and 0.1 kg each, pinned end to end
//! to a fixed base, hanging and swung out by 20 deg under gravity), 2 s at 1e-3 s (robot rate) and
//! at 1/60 s (game rate), Rapier's four solver iterations, with
//! - Rapier's ideal revolute joints (and how far their own anchors drift apart, in units of the
//!   play: Rapier's joint error at that step);
//! - the large-step clearance joint (0.1 mm play, steel, the law's restitution), frictionless and
//!   with Bai dry friction's sliding coefficient, capped at the four substeps (`max_substeps(4)`,
//!   no extra solver work) and with the substeps it asks for (the default);
//! - the compliant clearance joint at its own step (the largest of 1e-5, 5e-6, ... s its stability
//!   check accepts over the first 0.2 s, one solver iteration).
//!
//! `cargo bench --bench scale`. Medians of 5 runs; ratios within one run of the bench.

use clearance_joint::model::laws::{Bai, FrictionModel};
use clearance_joint::rapier::hinge::design::HingeDesign;
use clearance_joint::rapier::joint::ClearanceJointSet;
use clearance_joint::rapier::large_step::{LargeStepJointBuilder, LargeStepJointSet};
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{
    IntegrationParameters, MassProperties, PhysicsWorld, RevoluteJointBuilder, RigidBodyBuilder,
    RigidBodyHandle,
};
use std::time::Instant;

const LINKS: usize = 30;
const LENGTH: f64 = 0.1;
const MASS: f64 = 0.1;

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Model {
    Ideal,
    /// Friction on or off, and the cap on substeps.
    LargeStep(bool, Option<usize>),
    Compliant,
}

struct Chain {
    world: PhysicsWorld,
    compliant: ClearanceJointSet,
    play: LargeStepJointSet,
    /// Each pin: bodies and anchors (to measure the ideal joints' own error).
    pins: Vec<(RigidBodyHandle, RigidBodyHandle, Vector, Vector)>,
}

fn clearance(friction: bool) -> HingeDesign {
    let law = if friction {
        FrictionModel::Bai(Bai::DRY)
    } else {
        FrictionModel::None
    };
    HingeDesign::steel_improved_liu(0.004, 0.1e-3, 0.006)
        .unwrap()
        .friction(law)
}

/// How the chain starts.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Start {
    /// Hanging straight down, turned 20 deg about the base: a swinging chain.
    Swing,
}

fn chain(model: Model, dt: f64, start: Start) -> Chain {
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::new(0.0, -9.81, 0.0);
    world.integration_parameters = IntegrationParameters {
        dt,
        num_solver_iterations: if model == Model::Compliant { 1 } else { 4 },
        ..IntegrationParameters::default()
    };
    let mut compliant = ClearanceJointSet::new();
    let mut play = LargeStepJointSet::new();
    let mut pins = Vec::new();
    let c = clearance(matches!(
        model,
        Model::LargeStep(true, _) | Model::Compliant
    ));
    let j = MASS * LENGTH * LENGTH / 12.0;
    let mut previous = world.bodies.insert(RigidBodyBuilder::fixed());
    // Links lie along +x, turned to `angle` about z.
    let angle = match start {
        Start::Swing => -70f64.to_radians(),
    };
    let rotation = rapier3d_f64::math::Rotation::from_rotation_z(angle);
    for i in 0..LINKS {
        let link = world.bodies.insert(
            RigidBodyBuilder::dynamic()
                .pose(rapier3d_f64::math::Pose::from_parts(
                    rotation * Vector::new((i as f64 + 0.5) * LENGTH, 0.0, 0.0),
                    rotation,
                ))
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    MASS,
                    Vector::new(1e-3 * j, j, j),
                ))
                .can_sleep(false),
        );
        // Body 1's pin: the base's origin, or the previous link's far end.
        let a1 = if i == 0 {
            Vector::ZERO
        } else {
            Vector::new(0.5 * LENGTH, 0.0, 0.0)
        };
        let a2 = Vector::new(-0.5 * LENGTH, 0.0, 0.0);
        match model {
            Model::Ideal => {
                world.impulse_joints.insert(
                    previous,
                    link,
                    RevoluteJointBuilder::new(Vector::Z)
                        .local_anchor1(a1)
                        .local_anchor2(a2)
                        .contacts_enabled(false),
                    true,
                );
            }
            Model::LargeStep(_, cap) => {
                let j = c.large_step_joint(a1, a2, Vector::Z, Vector::Z).unwrap();
                let mut joint = LargeStepJointBuilder::new(Vector::Z, *j.geometry())
                    .local_anchor1(a1)
                    .local_anchor2(a2)
                    .friction(j.friction())
                    .restitution_law(c.normal);
                if let Some(cap) = cap {
                    joint = joint.max_substeps(cap);
                }
                let joint = joint.build().unwrap();
                play.insert(
                    previous,
                    link,
                    joint,
                    &world.bodies,
                    &mut world.impulse_joints,
                )
                .unwrap();
            }
            Model::Compliant => {
                let joint = c.joint(a1, a2, Vector::Z, Vector::Z).unwrap();
                compliant
                    .insert(
                        previous,
                        link,
                        joint,
                        &world.bodies,
                        &mut world.impulse_joints,
                    )
                    .unwrap();
            }
        }
        pins.push((previous, link, a1, a2));
        previous = link;
    }
    Chain {
        world,
        compliant,
        play,
        pins,
    }
}

/// Runs `end` s at `dt`; returns us per step, the largest substeps, and the largest joint error
/// in units of the play (clearance: `|e|/c`; ideal: anchor separation over c); `None` if the
/// compliant hook refuses the step.
fn run(model: Model, dt: f64, end: f64, start: Start) -> Option<(f64, usize, f64)> {
    let mut c = chain(model, dt, start);
    let steps = (end / dt).round() as usize;
    let (mut substeps, mut worst) = (4usize, 0.0f64);
    let mut clock = 0.0;
    for _ in 0..steps {
        let t = Instant::now();
        match model {
            Model::Ideal => {}
            Model::LargeStep(..) => c.play.before_step(
                &mut c.world.bodies,
                &mut c.world.impulse_joints,
                &c.world.integration_parameters,
            ),
            Model::Compliant => c
                .compliant
                .apply(
                    &mut c.world.bodies,
                    &c.world.impulse_joints,
                    &c.world.integration_parameters,
                )
                .ok()?,
        }
        c.world.step();
        c.play
            .after_step(&mut c.world.bodies, &c.world.impulse_joints);
        clock += t.elapsed().as_secs_f64();
        match model {
            Model::LargeStep(..) => {
                for (_, j) in c.play.iter() {
                    substeps = substeps.max(j.report().substeps);
                    worst = worst.max(j.report().eccentricity_ratio);
                }
            }
            Model::Ideal => {
                for (b1, b2, a1, a2) in &c.pins {
                    let p1 = *c.world.bodies[*b1].position() * *a1;
                    let p2 = *c.world.bodies[*b2].position() * *a2;
                    worst = worst.max((p2 - p1).length() / 0.1e-3);
                }
            }
            Model::Compliant => substeps = 1,
        }
    }
    Some((clock / steps as f64 * 1e6, substeps, worst))
}

/// One run of a variant: us per step, largest substeps, largest joint error over c.
type Measured = (f64, usize, f64);
/// A variant of the chain to time.
type Variant<'a> = dyn Fn() -> Option<Measured> + 'a;

/// Medians over 5 rounds, the variants interleaved within each round (so a busy machine slows
/// them alike); `None` if any run of a variant fails.
fn medians(variants: &[&Variant<'_>]) -> Vec<Option<Measured>> {
    let mut runs: Vec<Vec<Measured>> = vec![Vec::new(); variants.len()];
    let mut failed = vec![false; variants.len()];
    for _ in 0..5 {
        for (k, v) in variants.iter().enumerate() {
            match v() {
                Some(r) => runs[k].push(r),
                None => failed[k] = true,
            }
        }
    }
    runs.into_iter()
        .zip(failed)
        .map(|(mut r, failed)| {
            if failed {
                return None;
            }
            r.sort_by(|a, b| a.0.total_cmp(&b.0));
            Some(r[2])
        })
        .collect()
}

fn main() {
    let start = Start::Swing;
    println!(
        "| {LINKS}-joint chain, swinging from 20 deg, 2 s | step (s) | us/step | ratio to ideal | substeps (max) | largest joint error / c | wall per simulated second (s) |"
    );
    println!("|---|---|---|---|---|---|---|");
    let models = [
        ("ideal revolutes (error: anchors apart)", Model::Ideal),
        (
            "large step, frictionless, 4 substeps",
            Model::LargeStep(false, Some(4)),
        ),
        (
            "large step, friction, 4 substeps",
            Model::LargeStep(true, Some(4)),
        ),
        (
            "large step, friction, substeps as needed",
            Model::LargeStep(true, None),
        ),
    ];
    for (label, dt) in [("1e-3", 1e-3), ("1/60", 1.0 / 60.0)] {
        let closures: Vec<Box<Variant<'_>>> = models
            .iter()
            .map(|&(_, m)| Box::new(move || run(m, dt, 2.0, start)) as Box<Variant<'_>>)
            .collect();
        let refs: Vec<&Variant<'_>> = closures.iter().map(|c| c.as_ref()).collect();
        let results = medians(&refs);
        let ideal = results[0].expect("ideal joints run");
        for ((name, _), r) in models.iter().zip(results) {
            let r = r.expect("runs");
            println!(
                "| {name} | {label} | {:.2} | {:.2} | {} | {:.3} | {:.4} |",
                r.0,
                r.0 / ideal.0,
                r.1,
                r.2,
                r.0 * 1e-6 / dt
            );
        }
    }
    let mut dt = 1e-5;
    loop {
        let ideal = || run(Model::Ideal, 1e-3, 2.0, start);
        let compliant = || run(Model::Compliant, dt, 0.2, start);
        let r = medians(&[&ideal, &compliant]);
        if let (Some(ideal), Some(c)) = (r[0], r[1]) {
            println!(
                "| compliant (its step, 1 iteration, first 0.2 s) | {dt:e} | {:.2} | {:.2} (per step, vs ideal at 1e-3) | 1 | - | {:.3} |",
                c.0,
                c.0 / ideal.0,
                c.0 * 1e-6 / dt
            );
            break;
        }
        dt *= 0.5;
        if dt < 1e-8 {
            println!("| compliant | refused down to 1e-8 s | | | | | |");
            break;
        }
    }
}
