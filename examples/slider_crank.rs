//! The literature's standard clearance benchmark built with the plain API: a slider-crank whose
//! crank turns at a prescribed 5000 rpm (a kinematic, velocity-based Rapier body), an ideal
//! revolute crank pin, a prismatic slider guide (Rapier's `PrismaticJointBuilder`), gravity, and
//! one clearance joint at the rod-slider pin (the slider carries the bearing), in a
//! `ClearanceWorld` stepped at fixed steps. The ideal and clearance twins are compared on the slider's
//! acceleration and the pin force; the ideal slider's acceleration is checked against the closed
//! form, and the first impact is computed at halving steps.
//!
//! `cargo run --release --example slider_crank`
//!
//! The slider's acceleration is the second difference of its positions at constant steps,
//! `(x[n+1] - 2 x[n] + x[n-1]) / h^2`. With one solver iteration a step is symplectic Euler,
//! `x[n+1] = x[n] + h v[n+1/2]`, so this is exactly `(v[n+1/2] - v[n-1/2]) / h`, the acceleration
//! the step applied at state `n` (the stored velocities live at half steps, so a velocity read
//! at a state is not the state's velocity). The ideal pin force is the exact reaction of the
//! constrained equations at each state (`ClearanceWorld::solve_reactions` with the crank pin, the
//! slider pin and the prismatic guide: it tells the `ReactionSolver` that the stored velocities
//! lag the state by half the last step); the clearance pin force is the contact and friction
//! force.

use clearance_joint::Result;
use clearance_joint::model::angle::twist_angle;
use clearance_joint::rapier::hinge::convert::{BearingSide, ConvertRevolute};
use clearance_joint::rapier::hinge::design::HingeDesign;
use clearance_joint::rapier::joint::ClearanceJointHandle;
use clearance_joint::rapier::observers::metrics::{
    ContactObservation, HingeMetrics, ImpactRecorder,
};
use clearance_joint::rapier::observers::reaction::{
    IdealJoint, ReactionSolver, prepare_mass_properties,
};
use clearance_joint::rapier::pipeline::stepper::StepControl;
use clearance_joint::rapier::pipeline::world::ClearanceWorld;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::*;
use std::f64::consts::TAU;

/// Crank speed, rad/s (5000 rpm).
pub const OMEGA: f64 = 5000.0 * TAU / 60.0;
/// Crank length L1, m.
pub const CRANK: f64 = 0.05;
/// Connecting rod length L2, m.
pub const ROD: f64 = 0.2;
/// Rod and slider masses, kg.
pub const ROD_MASS: f64 = 0.5;
/// Slider mass, kg.
pub const SLIDER_MASS: f64 = 0.5;

/// The rod-slider pin's clearance: 0.5 mm radial play in a 20 mm steel bearing, 16 mm wide,
/// the paper's improved law, frictionless. Explicit contact, as `assets/slider_crank.ron`: the
/// study's fixed steps resolve every contact, and the step-halving study is the explicit joint's.
pub fn pin_clearance() -> Result<HingeDesign> {
    Ok(HingeDesign::steel_improved_liu(0.010, 0.5e-3, 0.016)?
        .integration(clearance_joint::rapier::joint::ContactIntegration::Explicit)
        .name("slider_pin"))
}

/// The slider's position at crank angle `theta` (crank pin at `L1 (cos, sin)`, slider on the x
/// axis): `x = L1 cos(theta) + sqrt(L2^2 - L1^2 sin^2(theta))`.
pub fn closed_form_x(theta: f64) -> f64 {
    CRANK * theta.cos() + (ROD * ROD - (CRANK * theta.sin()).powi(2)).sqrt()
}

/// The slider's acceleration at crank angle `theta` at the constant crank speed: `omega^2 x''`,
/// with `S = sqrt(L2^2 - L1^2 sin^2)`, `x'' = -L1 cos - L1^2 cos(2 theta)/S - L1^4 sin^2(2 theta)/(4 S^3)`.
pub fn closed_form_acceleration(theta: f64) -> f64 {
    let s = (ROD * ROD - (CRANK * theta.sin()).powi(2)).sqrt();
    let l2 = CRANK * CRANK;
    let x2 = -CRANK * theta.cos()
        - l2 * (2.0 * theta).cos() / s
        - l2 * l2 * (2.0 * theta).sin().powi(2) / (4.0 * s.powi(3));
    OMEGA * OMEGA * x2
}

/// The world and its handles.
pub struct Mechanism {
    /// The clearance-ready world: the Rapier world (one solver iteration, gravity -9.81 m/s^2
    /// along y) and the clearance joints (none for the ideal twin).
    pub world: ClearanceWorld,
    /// The clearance pin, if any.
    pub pin: Option<ClearanceJointHandle>,
    /// Ground, crank, rod and slider.
    pub bodies: [RigidBodyHandle; 4],
    /// Every ideal joint, for the exact reactions: the crank pin, the slider pin when ideal,
    /// the guide.
    pub ideal: Vec<IdealJoint>,
}

/// Builds the mechanism at top dead centre (crank along +x, slider at rest, the rod turning
/// about its slider end), with the rod-slider pin a clearance joint when `clearance` is given,
/// stepped with `control`.
pub fn build(clearance: Option<HingeDesign>, control: StepControl) -> Result<Mechanism> {
    let (r, l) = (CRANK, ROD);
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::new(0.0, -9.81, 0.0);
    world.integration_parameters.num_solver_iterations = 1; // as the scenes run (sub-cycled, the default, takes any)
    let ground = world.bodies.insert(RigidBodyBuilder::fixed());
    // The crank: prescribed rotation about z through the origin (its frame origin, no mass).
    let crank = world
        .bodies
        .insert(RigidBodyBuilder::kinematic_velocity_based().angvel(Vector::new(0.0, 0.0, OMEGA)));
    let rod_omega = -OMEGA * r / l;
    let rod = world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(r + 0.5 * l, 0.0, 0.0))
            .linvel(Vector::new(0.0, -rod_omega * 0.5 * l, 0.0))
            .angvel(Vector::new(0.0, 0.0, rod_omega))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                ROD_MASS,
                Vector::new(1e-4, ROD_MASS * l * l / 12.0, ROD_MASS * l * l / 12.0),
            ))
            .can_sleep(false),
    );
    let slider = world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(r + l, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                SLIDER_MASS,
                Vector::splat(1e-3),
            ))
            .can_sleep(false),
    );
    // Joint anchors from world points at t = 0, `point - body position`, and the joints in the
    // order the scene runner inserts them (hinges, then the other joints), so that
    // `assets/slider_crank.ron` gives the same bits.
    let rod_at = Vector::new(r + 0.5 * l, 0.0, 0.0);
    let slider_at = Vector::new(r + l, 0.0, 0.0);
    let crank_pin_at = Vector::new(r, 0.0, 0.0);
    let crank_pin = (crank_pin_at, crank_pin_at - rod_at);
    let crank_joint = world.impulse_joints.insert(
        crank,
        rod,
        RevoluteJointBuilder::new(Vector::Z)
            .local_anchor1(crank_pin.0)
            .local_anchor2(crank_pin.1)
            .contacts_enabled(false),
        true,
    );
    // The rod-slider pin, slider first: the slider carries the bearing.
    let slider_pin = (Vector::ZERO, slider_at - rod_at);
    let pin_joint = world.impulse_joints.insert(
        slider,
        rod,
        RevoluteJointBuilder::new(Vector::Z)
            .local_anchor1(slider_pin.0)
            .local_anchor2(slider_pin.1)
            .contacts_enabled(false),
        true,
    );
    let mut ideal = vec![IdealJoint::from_rapier(&world.impulse_joints, crank_joint)?];
    let mut world = ClearanceWorld::new(world, control);
    let pin = match clearance {
        Some(c) => Some(world.clearance.convert_revolute(
            pin_joint,
            BearingSide::Body1,
            c,
            &mut world.rapier.impulse_joints,
        )?),
        None => {
            ideal.push(IdealJoint::from_rapier(
                &world.rapier.impulse_joints,
                pin_joint,
            )?);
            None
        }
    };
    let slide = world.rapier.impulse_joints.insert(
        ground,
        slider,
        PrismaticJointBuilder::new(Vector::X)
            .local_anchor1(slider_at)
            .contacts_enabled(false),
        true,
    );
    ideal.push(IdealJoint::from_rapier(
        &world.rapier.impulse_joints,
        slide,
    )?);
    prepare_mass_properties(&mut world.rapier.bodies);
    Ok(Mechanism {
        world,
        pin,
        bodies: [ground, crank, rod, slider],
        ideal,
    })
}

/// The end of the first-impact runs, s: after the first impact's peak.
pub const FIRST_IMPACT_END: f64 = 1e-3;

/// What one run recorded, one entry per state (every step).
pub struct Run {
    /// The step, s.
    pub dt: f64,
    /// Time of each state, s.
    pub t: Vec<f64>,
    /// Crank angle of each state (the kinematic body's rotation, unwrapped), rad.
    pub theta: Vec<f64>,
    /// Slider position, m.
    pub x: Vec<f64>,
    /// Pin force on the slider, N (ideal reaction, or contact and friction force).
    pub force: Vec<f64>,
    /// The pin's metrics and impact list.
    pub recorder: ImpactRecorder,
}

impl Run {
    /// The slider's acceleration at states `1..n-1`, `(x[n+1] - 2 x[n] + x[n-1]) / h^2`, with
    /// the state index.
    pub fn acceleration(&self) -> Vec<(usize, f64)> {
        let h2 = self.dt * self.dt;
        (1..self.x.len().saturating_sub(1))
            .map(|n| (n, (self.x[n + 1] - 2.0 * self.x[n] + self.x[n - 1]) / h2))
            .collect()
    }

    /// The pin's metrics.
    pub fn metrics(&self) -> &HingeMetrics {
        self.recorder.metrics()
    }
}

/// Runs the mechanism with fixed steps `dt` to `end` (s); the ideal twin without `clearance`.
pub fn simulate(clearance: Option<HingeDesign>, dt: f64, end: f64) -> Result<Run> {
    let Mechanism {
        mut world,
        pin,
        bodies: [_, crank, _, slider],
        ideal,
    } = build(clearance, StepControl::fixed(dt))?;
    world.prepare()?;
    let mut reactions = ReactionSolver::default();
    let mut run = Run {
        dt,
        t: Vec::new(),
        theta: Vec::new(),
        x: Vec::new(),
        force: Vec::new(),
        recorder: ImpactRecorder::new(),
    };
    let mut theta = clearance_joint::model::angle::UnwrappedAngle::default();
    loop {
        // The state before the step: its pin force and contact, its positions.
        let obs = match pin {
            Some(pin) => ContactObservation::of(world.clearance.get(pin).expect("pin")),
            None => {
                // The exact reactions at this state (the slider pin is `ideal[1]`).
                let f = world
                    .solve_reactions(&mut reactions, &ideal)
                    .map_or(f64::NAN, |f| f[1].length());
                ContactObservation::ideal(f)
            }
        };
        let bodies = &world.rapier.bodies;
        theta.update(twist_angle(bodies[crank].rotation(), Vector::Z));
        run.t.push(world.time());
        run.theta.push(theta.value());
        run.x.push(bodies[slider].translation().x);
        run.force.push(obs.force);
        if world.time() >= end {
            run.recorder.finish(world.time(), &obs);
            return Ok(run);
        }
        let info = world.step(end)?;
        run.recorder.record(info.t0, info.dt, &obs);
    }
}

/// Largest and smallest of `v`.
pub fn extremes(v: impl Iterator<Item = f64>) -> (f64, f64) {
    v.fold((f64::NEG_INFINITY, f64::INFINITY), |(hi, lo), a| {
        (hi.max(a), lo.min(a))
    })
}

#[allow(dead_code)]
fn main() -> Result<()> {
    let turn = TAU / OMEGA;
    // The contact's damped stability limit falls to 2.5e-7 s in its deepest, most damped
    // contacts (the stepper refuses a longer fixed step there): half of it.
    let dt = 1.25e-7;
    let ideal = simulate(None, dt, 2.0 * turn)?;
    let clear = simulate(Some(pin_clearance()?), dt, 2.0 * turn)?;
    // The second turn: past the start's transient.
    let second = |r: &Run| {
        let a = r.acceleration();
        extremes(
            a.into_iter()
                .filter(|&(n, _)| r.t[n] >= turn)
                .map(|(_, a)| a),
        )
    };
    let (a_hi, a_lo) = second(&ideal);
    let (c_hi, c_lo) =
        extremes((0..2000).map(|k| closed_form_acceleration(k as f64 * TAU / 2000.0)));
    println!(
        "slider-crank: L1 = {CRANK} m, L2 = {ROD} m, 5000 rpm, fixed steps of {dt:e} s, 2 turns"
    );
    println!(
        "ideal slider acceleration: max {a_hi:.2} m/s^2 (closed form {c_hi:.2}, {:+.2e}), min {a_lo:.2} m/s^2 (closed form {c_lo:.2}, {:+.2e})",
        a_hi / c_hi - 1.0,
        a_lo / c_lo - 1.0
    );
    let worst = ideal
        .acceleration()
        .into_iter()
        .filter(|&(n, _)| ideal.t[n] >= turn)
        .map(|(n, a)| (a - closed_form_acceleration(ideal.theta[n])).abs())
        .fold(0.0, f64::max);
    println!(
        "ideal slider acceleration against the closed form at each state's crank angle: largest deviation {worst:.3} m/s^2 ({:.2e} of the peak)",
        worst / c_lo.abs()
    );
    let (k_hi, k_lo) = second(&clear);
    println!("clearance slider acceleration: max {k_hi:.0} m/s^2, min {k_lo:.0} m/s^2");
    let (mi, mc) = (ideal.metrics(), clear.metrics());
    println!(
        "pin force: ideal peak {:.2} N, RMS {:.2} N; clearance peak {:.1} N, RMS {:.2} N",
        mi.peak_force_n, mi.rms_force_n, mc.peak_force_n, mc.rms_force_n
    );
    println!(
        "clearance pin: {} onsets ({} impacts after a separation), in contact {:.1} % of the time, first impact at {:.6} s, peak {:.1} N",
        mc.onsets,
        mc.impacts,
        100.0 * mc.contact_fraction,
        mc.first_impact_t_s.unwrap_or(f64::NAN),
        mc.first_impact_peak_n.unwrap_or(f64::NAN)
    );
    // The first impact's peak is a spike within microseconds of its onset (0.24 ms); the
    // journal then follows the wall for 9 ms. Runs to 1 ms hold the spike.
    println!("first impact at halving fixed steps (runs to 1 ms):");
    let mut prev: Option<f64> = None;
    for dt in [2.5e-7, 1.25e-7, 6.25e-8, 3.125e-8, 1.5625e-8] {
        let r = simulate(Some(pin_clearance()?), dt, FIRST_IMPACT_END)?;
        let m = r.metrics();
        let peak = m.first_impact_peak_n.unwrap_or(f64::NAN);
        let change = prev.map_or(String::new(), |p| {
            format!(" ({:+.3} % from the step before)", 100.0 * (peak / p - 1.0))
        });
        println!(
            "  dt = {dt:.2e} s: onset {:.7} s, approach {:.1} mm/s, peak {peak:.2} N{change}",
            m.first_impact_t_s.unwrap_or(f64::NAN),
            r.recorder.contacts()[0].approach_speed_m_s * 1e3
        );
        prev = Some(peak);
    }
    Ok(())
}
