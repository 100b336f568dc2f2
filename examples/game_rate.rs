//! Game rate: a sign on a loose hinge pin under a cart rolling over cobblestones, at 1/60 s with
//! Rapier's default integration parameters (four solver iterations).
//!
//! The sign (2 kg, 0.6 x 0.5 m) hangs 0.25 m below a pin with 1 mm of radial play in a bracket on
//! the cart. The cart (a position-driven kinematic body) pulls away, rolls at 1.5 m/s over cobbles
//! (5 mm arches, 0.12 m long) and stops at 20 s. Every cobble's edge kicks the bracket up: the pin
//! rattles in its play (restitution 0.4), and friction in the pin (0.3) calms the swing once the
//! cart has stopped. The same sign on Rapier's ideal revolute joint runs beside it. One minute of
//! game time.
//!
//! The world is a `ClearanceWorld` stepped at fixed 1/60 s steps (`StepControl::fixed`): its
//! `step` takes the place of `world.step()` and runs the large-step joint's hooks around Rapier's
//! step, so none can be forgotten.
//!
//! `cargo run --release --example game_rate`

use clearance_joint::Result;
use clearance_joint::model::angle::HingeAngle;
use clearance_joint::model::laws::BearingGeometry;
use clearance_joint::rapier::large_step::LargeStepJointBuilder;
use clearance_joint::rapier::pipeline::stepper::StepControl;
use clearance_joint::rapier::pipeline::world::ClearanceWorld;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{
    IntegrationParameters, MassProperties, PhysicsWorld, RevoluteJointBuilder, RigidBodyBuilder,
    RigidBodyHandle,
};
use std::f64::consts::PI;
use std::process::ExitCode;
use std::time::Instant;

/// Simulated time, s.
pub const END: f64 = 60.0;
/// The cart stops here, s.
pub const STOP: f64 = 20.0;
/// Radial play of the pin, m.
pub const CLEARANCE: f64 = 1e-3;
/// Sign mass, kg; width and height, m; pin above the centre of mass, m.
const MASS: f64 = 2.0;
const SIZE: (f64, f64) = (0.6, 0.5);
const PIN: f64 = 0.25;
/// Cart: cruising speed (m/s), time to reach it and to stop (s), cobble height and length (m).
const SPEED: f64 = 1.5;
const RAMP: f64 = 1.0;
const COBBLE: (f64, f64) = (0.005, 0.12);

/// What one run measured.
#[derive(Clone, Debug, Default)]
pub struct Run {
    /// Rapier's step, s.
    pub dt: f64,
    /// Rapier's `num_solver_iterations`.
    pub iterations: usize,
    /// Steps taken.
    pub steps: u64,
    /// Largest swing from hanging, deg.
    pub max_swing_deg: f64,
    /// Swing amplitude over the last 5 s, deg.
    pub final_swing_deg: f64,
    /// Largest `|e|/c` at the end of a step (play only).
    pub max_eccentricity_ratio: f64,
    /// Impacts of the pin in its play while the cart rolls (play only).
    pub bounces_rolling: u64,
    /// Impacts after the cart stopped (play only).
    pub bounces_stopped: u64,
    /// Largest impact impulse, N s (play only).
    pub max_impact_impulse: f64,
    /// Normal force on the pin at the end, N (play only; the sign's weight at rest).
    pub final_force_n: f64,
    /// Mechanical energy of the sign (kinetic + gravity, zero hanging at rest) when the cart
    /// stops, J.
    pub energy_at_stop_j: f64,
    /// Largest rise of that energy above its value at the stop, J (nothing drives the sign then).
    pub max_energy_rise_j: f64,
    /// Energy left at the end, J.
    pub final_energy_j: f64,
    /// Largest and mean substeps per step.
    pub max_substeps: usize,
    /// Mean substeps per step.
    pub mean_substeps: f64,
    /// Steps the joint reported under-resolved.
    pub under_resolved: u64,
    /// Wall time per step, us.
    pub us_per_step: f64,
}

/// Principal inertia of the sign board about its centre of mass (z: the pin's axis), kg m^2.
fn inertia() -> Vector {
    let (w, h) = SIZE;
    Vector::new(
        MASS * h * h / 12.0,
        MASS * (w * w + h * h) / 12.0,
        MASS * (w * w + h * h) / 12.0,
    )
}

/// Distance the cart has covered at `t`: accelerates for `RAMP`, cruises, brakes for `RAMP`
/// before `STOP`.
fn travel(t: f64) -> f64 {
    let a = SPEED / RAMP;
    let t = t.min(STOP);
    if t < RAMP {
        0.5 * a * t * t
    } else if t < STOP - RAMP {
        0.5 * SPEED * RAMP + SPEED * (t - RAMP)
    } else {
        let left = STOP - t;
        0.5 * SPEED * RAMP + SPEED * (STOP - 2.0 * RAMP) + 0.5 * SPEED * RAMP
            - 0.5 * a * left * left
    }
}

/// The bracket's height over the cobbles: arches `h |sin(pi x / L)|`.
fn cobbles(x: f64) -> f64 {
    let (h, l) = COBBLE;
    h * (PI * x / l).sin().abs()
}

/// Kinetic plus gravitational energy of the sign relative to the bracket's rest height `ground`,
/// J (zero hanging at rest). From the sign's own mass and inertia: Rapier fills in mass
/// properties at the first step.
fn energy(world: &PhysicsWorld, body: RigidBodyHandle) -> f64 {
    let rb = &world.bodies[body];
    let local = rb.rotation().inverse() * rb.angvel();
    let ground = cobbles(travel(STOP));
    0.5 * MASS * rb.linvel().length_squared()
        + 0.5 * (inertia() * local).dot(local)
        + MASS * -world.gravity.y * (rb.translation().y - ground + PIN)
}

/// One minute of the sign: with play (`true`, at most `max_substeps` substeps per step, `None`
/// for the joint's default) or on
/// Rapier's ideal revolute joint.
pub fn simulate(with_play: bool, max_substeps: Option<usize>) -> Result<Run> {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -9.81, 0.0);
    rapier.integration_parameters = IntegrationParameters::default(); // 1/60 s, 4 iterations
    let dt = rapier.integration_parameters.dt;
    let cart = rapier
        .bodies
        .insert(RigidBodyBuilder::kinematic_position_based());
    let body = rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.0, -PIN, 0.0))
            .additional_mass_properties(MassProperties::new(Vector::ZERO, MASS, inertia()))
            .can_sleep(false),
    );
    let mut world = ClearanceWorld::new(rapier, StepControl::fixed(dt));
    let pin = if with_play {
        // The one difference from the ideal sign: the pin's joint.
        let mut joint = LargeStepJointBuilder::new(
            Vector::Z,
            BearingGeometry::from_clearance(0.006, CLEARANCE, 0.01)?,
        )
        .local_anchor2(Vector::new(0.0, PIN, 0.0))
        .restitution(0.4)
        .friction(0.3)
        .name("sign pin");
        if let Some(cap) = max_substeps {
            joint = joint.max_substeps(cap);
        }
        let joint = joint.build()?;
        Some(world.insert_large_step(cart, body, joint)?)
    } else {
        world.rapier.impulse_joints.insert(
            cart,
            body,
            RevoluteJointBuilder::new(Vector::Z)
                .local_anchor2(Vector::new(0.0, PIN, 0.0))
                .contacts_enabled(false),
            true,
        );
        None
    };
    let steps = (END / dt).round() as u64;
    let mut run = Run {
        dt,
        iterations: world.rapier.integration_parameters.num_solver_iterations,
        steps,
        ..Run::default()
    };
    let mut swing = HingeAngle::default();
    let (mut substeps, mut stopped) = (0u64, false);
    let start = Instant::now();
    for step in 0..steps {
        let t = (step + 1) as f64 * dt;
        let x = travel(t);
        let bodies = &mut world.rapier.bodies;
        bodies[cart].set_next_kinematic_translation(Vector::new(x, cobbles(x), 0.0));
        world.step(t)?; // was: world.step(), with the joints' hooks around it

        // The swing from hanging, in (-180, 180] deg.
        let bodies = &world.rapier.bodies;
        let a = swing
            .update(bodies[cart].rotation(), bodies[body].rotation(), Vector::Z)
            .to_degrees();
        let a = (a + 180.0).rem_euclid(360.0) - 180.0;
        run.max_swing_deg = run.max_swing_deg.max(a.abs());
        if t > END - 5.0 {
            run.final_swing_deg = run.final_swing_deg.max(a.abs());
        }
        if t >= STOP {
            let e = energy(&world.rapier, body);
            if !stopped {
                run.energy_at_stop_j = e;
                stopped = true;
            }
            run.max_energy_rise_j = run.max_energy_rise_j.max(e - run.energy_at_stop_j);
        }
        if let Some(pin) = pin {
            let r = world.large_step.get(pin).expect("inserted").report();
            run.max_eccentricity_ratio = run.max_eccentricity_ratio.max(r.eccentricity_ratio);
            run.max_impact_impulse = run.max_impact_impulse.max(r.impact_impulse);
            if r.bounce {
                if t < STOP {
                    run.bounces_rolling += 1;
                } else {
                    run.bounces_stopped += 1;
                }
            }
            run.max_substeps = run.max_substeps.max(r.substeps);
            run.under_resolved += u64::from(r.under_resolved);
            substeps += r.substeps as u64;
            run.final_force_n = r.normal_force;
        }
    }
    run.us_per_step = start.elapsed().as_secs_f64() / steps as f64 * 1e6;
    run.final_energy_j = energy(&world.rapier, body);
    if pin.is_some() {
        run.mean_substeps = substeps as f64 / steps as f64;
    } else {
        run.max_substeps = run.iterations;
        run.mean_substeps = run.iterations as f64;
    }
    Ok(run)
}

/// The three runs: ideal revolute; with play, substeps as the joint needs them (the default);
/// with play, capped at Rapier's four (the cheapest, and reported under-resolved).
pub struct Runs {
    /// Rapier's revolute joint.
    pub ideal: Run,
    /// The large-step joint with its default `max_substeps`.
    pub play: Run,
    /// The large-step joint with `max_substeps(4)`.
    pub capped: Run,
}

/// All three runs.
pub fn run() -> Result<Runs> {
    Ok(Runs {
        ideal: simulate(false, Some(4))?,
        play: simulate(true, None)?,
        capped: simulate(true, Some(4))?,
    })
}

/// The printed comparison.
pub fn report(runs: &Runs) -> String {
    let Runs {
        ideal,
        play,
        capped,
    } = runs;
    let mut s = format!(
        "game_rate: a 2 kg sign under a cart on cobbles (stops at {STOP} s), {END} s at dt = 1/60 s, \
         {} solver iterations\n\
         pin: Rapier revolute vs large-step clearance joint (1 mm play, restitution 0.4, friction 0.3)\n\
         play: the substeps the joint asks for; play@4: capped at 4 substeps (max_substeps(4))\n\n\
         {:<36}{:>14}{:>14}{:>14}\n",
        play.iterations, "", "ideal", "play", "play@4"
    );
    let mut row = |label: &str, a: String, b: String, c: String| {
        s.push_str(&format!("{label:<36}{a:>14}{b:>14}{c:>14}\n"))
    };
    let pair = |f: fn(&Run) -> f64, digits: usize| {
        (
            format!("{:.*}", digits, f(ideal)),
            format!("{:.*}", digits, f(play)),
            format!("{:.*}", digits, f(capped)),
        )
    };
    let (a, b, c) = pair(|r| r.max_swing_deg, 2);
    row("largest swing (deg)", a, b, c);
    let (a, b, c) = pair(|r| r.final_swing_deg, 3);
    row("swing, last 5 s (deg)", a, b, c);
    let (_, b, c) = pair(|r| r.max_eccentricity_ratio, 4);
    row("largest |e|/c", "-".into(), b, c);
    let impacts = |r: &Run| format!("{} / {}", r.bounces_rolling, r.bounces_stopped);
    row(
        "pin bounces: rolling / stopped",
        "0 / 0".into(),
        impacts(play),
        impacts(capped),
    );
    let (_, b, c) = pair(|r| r.max_impact_impulse, 4);
    row("largest impact impulse (N s)", "-".into(), b, c);
    let (_, b, c) = pair(|r| r.final_force_n, 4);
    row("pin force at the end (N)", "-".into(), b, c);
    let (a, b, c) = pair(|r| r.energy_at_stop_j, 4);
    row("sign energy when the cart stops (J)", a, b, c);
    let (a, b, c) = pair(|r| r.max_energy_rise_j, 6);
    row("largest energy rise after (J)", a, b, c);
    let (a, b, c) = pair(|r| r.final_energy_j, 4);
    row("energy at the end (J)", a, b, c);
    let substeps = |r: &Run| format!("{} / {:.1}", r.max_substeps, r.mean_substeps);
    row(
        "substeps per step (max / mean)",
        substeps(ideal),
        substeps(play),
        substeps(capped),
    );
    row(
        "under-resolved steps",
        "-".into(),
        play.under_resolved.to_string(),
        capped.under_resolved.to_string(),
    );
    let (a, b, c) = pair(|r| r.us_per_step, 2);
    row("wall time per step (us)", a, b, c);
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
