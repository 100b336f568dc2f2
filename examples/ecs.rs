//! Drop-in, bevy_ecs: the two-link arm of `drop_in.rs` as entities. Bodies are `Body`
//! components, hinges are `Hinge` components with a mode: `IdealHinge` or `ClearanceHinge`. The
//! physics systems run in a fixed order (sync, drives, clearance forces, Rapier step, record).
//!
//! Three runs of the same spawning code: all hinges ideal; the elbow spawned with a
//! `ClearanceHinge` in place of its `IdealHinge` (the one-line change); and the elbow swapped from
//! ideal to clearance while running, at half time (the sync system converts the Rapier joint).
//!
//! `cargo run --release --example ecs`

use bevy_ecs::prelude::*;
use clearance_joint::Result;
use clearance_joint::ecs::{
    Body, ClearanceHinge, Hinge, HingeMode, HingeState, IdealHinge, Physics, physics_schedule,
    run_step,
};
use clearance_joint::model::laws::{Bai, FrictionModel};
use clearance_joint::rapier::hinge::design::HingeDesign;
use rapier3d_f64::math::{Pose, Rotation, Vector};
use rapier3d_f64::prelude::{MassProperties, RigidBodyBuilder};
use std::process::ExitCode;

/// Step, s (as in `drop_in.rs`: the elbow's contact is stable only below about 3.8e-5 s).
pub const DT: f64 = 2e-5;
/// Simulated time, s.
pub const END: f64 = 1.0;
/// Initial angle of the straight arm from the downward vertical, deg.
pub const START_DEG: f64 = 30.0;
const UPPER: (f64, f64) = (1.0, 0.4); // mass kg, length m
const LOWER: (f64, f64) = (0.5, 0.3);

/// The elbow's clearance: a 10 mm steel bearing, 8 mm wide, 0.1 mm radial play, dry friction.
/// Explicit contact: the run's fixed steps resolve every contact, and the lower link's momentum
/// balance over a step then reads the contact force the joint reports at the step's start (a
/// sub-cycled joint, the default, delivers a step's contact impulse spread over the step).
pub fn elbow_clearance() -> Result<HingeDesign> {
    Ok(HingeDesign::steel_improved_liu(0.005, 0.1e-3, 0.008)?
        .friction(FrictionModel::Bai(Bai::DRY))
        .integration(clearance_joint::rapier::joint::ContactIntegration::Explicit)
        .name("elbow"))
}

fn link((mass, length): (f64, f64), center: Vector, rotation: Rotation) -> Body {
    let j = mass * length * length / 12.0;
    Body::new(
        RigidBodyBuilder::dynamic()
            .pose(Pose::from_parts(center, rotation))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                mass,
                Vector::new(j, 1e-3 * j, j),
            ))
            .can_sleep(false),
    )
}

/// Spawns the arm; the elbow is ideal or has clearance. Returns the (shoulder, elbow) entities.
fn spawn(world: &mut World, elbow_has_clearance: bool) -> Result<(Entity, Entity)> {
    let mut physics = Physics::new(DT, Vector::new(0.0, -9.81, 0.0));
    // The compliant clearance model needs one solver iteration; the setting is the whole world's.
    physics
        .world
        .rapier
        .integration_parameters
        .num_solver_iterations = 1;
    world.insert_resource(physics);
    let r = Rotation::from_rotation_z(START_DEG.to_radians());
    let down = r * Vector::NEG_Y;
    let base = world.spawn(Body::new(RigidBodyBuilder::fixed())).id();
    let upper = world.spawn(link(UPPER, 0.5 * UPPER.1 * down, r)).id();
    let lower = world
        .spawn(link(LOWER, (UPPER.1 + 0.5 * LOWER.1) * down, r))
        .id();
    let shoulder = world
        .spawn((
            Hinge::new(base, upper, Vector::Z).local_anchor2(Vector::new(0.0, 0.5 * UPPER.1, 0.0)),
            IdealHinge,
        ))
        .id();
    let elbow_hinge = Hinge::new(upper, lower, Vector::Z)
        .local_anchor1(Vector::new(0.0, -0.5 * UPPER.1, 0.0))
        .local_anchor2(Vector::new(0.0, 0.5 * LOWER.1, 0.0));
    let elbow = if elbow_has_clearance {
        world.spawn((elbow_hinge, ClearanceHinge(elbow_clearance()?)))
    } else {
        world.spawn((elbow_hinge, IdealHinge))
    }
    .id();
    Ok((shoulder, elbow))
}

/// What one run ended with.
#[derive(Clone, Debug)]
pub struct Run {
    /// The shoulder's state.
    pub shoulder: HingeState,
    /// The elbow's state.
    pub elbow: HingeState,
}

/// Runs the arm; `swap_at` (s) swaps the elbow's `IdealHinge` for a `ClearanceHinge` while running.
pub fn simulate(elbow_has_clearance: bool, swap_at: Option<f64>) -> Result<Run> {
    let mut world = World::new();
    let (shoulder, elbow) = spawn(&mut world, elbow_has_clearance)?;
    let mut schedule = physics_schedule();
    let steps = (END / DT).round() as u64;
    for step in 0..steps {
        if swap_at.is_some_and(|t| step == (t / DT).round() as u64) {
            // The whole change, while running: swap the component.
            world
                .entity_mut(elbow)
                .remove::<IdealHinge>()
                .insert(ClearanceHinge(elbow_clearance()?));
        }
        run_step(&mut world, &mut schedule)?;
    }
    Ok(Run {
        shoulder: *world.get::<HingeState>(shoulder).expect("spawned"),
        elbow: *world.get::<HingeState>(elbow).expect("spawned"),
    })
}

/// The three runs: ideal, clearance from the start, swapped at half time.
pub fn run() -> Result<[Run; 3]> {
    Ok([
        simulate(false, None)?,
        simulate(true, None)?,
        simulate(false, Some(0.5 * END))?,
    ])
}

/// The printed comparison.
pub fn report(runs: &[Run; 3]) -> String {
    let mut s = format!(
        "ecs: two-link arm released at {START_DEG} deg under gravity, {END} s, dt = {DT:e} s, via bevy_ecs\n\
         elbow: IdealHinge vs ClearanceHinge (0.1 mm radial play, steel, dry friction)\n\n\
         {:<28}{:>14}{:>14}{:>14}\n",
        "", "ideal", "clearance", "swapped@0.5s"
    );
    let mut row = |label: &str, f: &dyn Fn(&Run) -> String| {
        s.push_str(&format!("{label:<28}"));
        for r in runs {
            s.push_str(&format!("{:>14}", f(r)));
        }
        s.push('\n');
    };
    let mode = |m: HingeMode| format!("{m:?}");
    row("elbow mode", &|r| mode(r.elbow.mode));
    row("final shoulder angle (deg)", &|r| {
        format!("{:.4}", r.shoulder.angle.to_degrees())
    });
    row("final elbow angle (deg)", &|r| {
        format!("{:.4}", r.elbow.angle.to_degrees())
    });
    row("peak elbow force (N) *", &|r| {
        format!("{:.3}", r.elbow.peak_force)
    });
    row("elbow onsets", &|r| r.elbow.onsets.to_string());
    row("elbow impacts", &|r| r.elbow.impacts.to_string());
    s.push_str("* ideal: the exact reaction of the ideal joint; clearance: the contact force\n");
    s
}

fn main() -> ExitCode {
    match run() {
        Ok(runs) => {
            print!("{}", report(&runs));
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
