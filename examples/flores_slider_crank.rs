//! Flores and Ambrósio's slider-crank, the standard benchmark of the clearance-joint literature,
//! built with the plain API: crank L1 = 0.05 m turning at a prescribed 5000 rpm (a kinematic,
//! velocity-based body), rod L2 = 0.12 m (0.21 kg, 2.5e-4 kg m^2), slider 0.14 kg on a prismatic
//! guide, gravity along -y, and a clearance joint at the rod-slider pin (bearing on the slider,
//! R = 10 mm, c = 0.5 mm, steel, Lankarani-Nikravesh cr = 0.9 with the geometric stiffness,
//! Ambrósio friction mu = 0.01, v0 = 0.1 mm/s, v1 = 10 mm/s). Started with the crank at 0 deg,
//! the journal centred, rod and slider at the velocities of the ideal mechanism. One
//! `ClearanceWorld` holds it all and takes every step (adaptive by default).
//!
//! `cargo run --release --example flores_slider_crank -- [adaptive[:TOL[:MAX_DT]]|FIXED_DT] [CLEARANCE_MM] [TURNS]`
//!
//! prints the first impact, the largest force and deepest penetration in crank turns 2-3, the
//! steps, the wall time, and the ideal twin's slider acceleration against its closed form.

use clearance_joint::Result;
use clearance_joint::model::angle::{UnwrappedAngle, twist_angle};
use clearance_joint::model::laws::{
    Ambrosio, BearingGeometry, FrictionModel, LankaraniNikravesh, Material, NormalModel,
};
use clearance_joint::rapier::hinge::convert::{BearingSide, ConvertRevolute};
use clearance_joint::rapier::hinge::design::HingeDesign;
use clearance_joint::rapier::joint::ClearanceJointHandle;
use clearance_joint::rapier::observers::metrics::{ContactObservation, ImpactRecorder};
use clearance_joint::rapier::pipeline::stepper::StepControl;
use clearance_joint::rapier::pipeline::world::ClearanceWorld;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::*;
use std::f64::consts::TAU;

/// Crank speed, rad/s (5000 rpm).
pub const OMEGA: f64 = 5000.0 * TAU / 60.0;
/// Crank length L1, m.
pub const CRANK: f64 = 0.05;
/// Rod length L2, m.
pub const ROD: f64 = 0.12;
/// Rod mass, kg.
pub const ROD_MASS: f64 = 0.21;
/// Rod moment of inertia about its centre of mass, kg m^2.
pub const ROD_INERTIA: f64 = 2.5e-4;
/// Slider mass, kg.
pub const SLIDER_MASS: f64 = 0.14;
/// One crank turn, s.
pub const TURN: f64 = TAU / OMEGA;

/// The pin's clearance: radial play `c` (m) in a 10 mm steel bearing (16 mm wide, which the
/// Lankarani-Nikravesh law does not use), cr = 0.9, geometric stiffness, Ambrósio friction.
/// Explicit contact, as `assets/flores_slider_crank.ron`: the crank's turn sets the steps either
/// way, and the explicit joint costs less per step; the recorder reads the contact at each step.
pub fn pin_clearance(c: f64) -> Result<HingeDesign> {
    let geometry = BearingGeometry::from_clearance(0.010, c, 0.016)?;
    let k =
        LankaraniNikravesh::stiffness_from_geometry(&geometry, &Material::STEEL, &Material::STEEL);
    let law = LankaraniNikravesh::new(k, LankaraniNikravesh::EXPONENT, 0.9)?;
    Ok(
        HingeDesign::new(geometry, NormalModel::LankaraniNikravesh(law))
            .friction(FrictionModel::Ambrosio(Ambrosio::new(0.01, 1e-4, 1e-2)?))
            .integration(clearance_joint::rapier::joint::ContactIntegration::Explicit)
            .name("slider_pin"),
    )
}

/// The slider's acceleration at crank angle `theta` at the constant crank speed (crank pin at
/// `L1 (cos, sin)`, slider on the x axis): `omega^2 x''` with `S = sqrt(L2^2 - L1^2 sin^2)`,
/// `x'' = -L1 cos - L1^2 cos(2 theta)/S - L1^4 sin^2(2 theta)/(4 S^3)`.
pub fn closed_form_acceleration(theta: f64) -> f64 {
    let s = (ROD * ROD - (CRANK * theta.sin()).powi(2)).sqrt();
    let l2 = CRANK * CRANK;
    let x2 = -CRANK * theta.cos()
        - l2 * (2.0 * theta).cos() / s
        - l2 * l2 * (2.0 * theta).sin().powi(2) / (4.0 * s.powi(3));
    OMEGA * OMEGA * x2
}

/// The world, the pin (if any) and the crank, rod and slider.
pub struct Mechanism {
    /// The clearance-ready world: Rapier's, and the clearance joints (none for the ideal twin).
    pub world: ClearanceWorld,
    /// The clearance pin.
    pub pin: Option<ClearanceJointHandle>,
    /// Crank, rod, slider.
    pub bodies: [RigidBodyHandle; 3],
}

/// Builds the mechanism with the crank along +x, the rod-slider pin a clearance joint when
/// `clearance` is given, stepped with `control`.
pub fn build(clearance: Option<HingeDesign>, control: StepControl) -> Result<Mechanism> {
    let (r, l) = (CRANK, ROD);
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::new(0.0, -9.81, 0.0);
    world.integration_parameters.num_solver_iterations = 1;
    let ground = world.bodies.insert(RigidBodyBuilder::fixed());
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
                Vector::new(1e-5, ROD_INERTIA, ROD_INERTIA),
            ))
            .can_sleep(false),
    );
    let slider = world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(r + l, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                SLIDER_MASS,
                Vector::splat(1e-4),
            ))
            .can_sleep(false),
    );
    let rod_at = Vector::new(r + 0.5 * l, 0.0, 0.0);
    let crank_pin_at = Vector::new(r, 0.0, 0.0);
    world.impulse_joints.insert(
        crank,
        rod,
        RevoluteJointBuilder::new(Vector::Z)
            .local_anchor1(crank_pin_at)
            .local_anchor2(crank_pin_at - rod_at)
            .contacts_enabled(false),
        true,
    );
    let pin_joint = world.impulse_joints.insert(
        slider,
        rod,
        RevoluteJointBuilder::new(Vector::Z)
            .local_anchor2(Vector::new(0.5 * l, 0.0, 0.0))
            .contacts_enabled(false),
        true,
    );
    world.impulse_joints.insert(
        ground,
        slider,
        PrismaticJointBuilder::new(Vector::X)
            .local_anchor1(Vector::new(r + l, 0.0, 0.0))
            .contacts_enabled(false),
        true,
    );
    let mut world = ClearanceWorld::new(world, control);
    let pin = match clearance {
        Some(c) => Some(world.clearance.convert_revolute(
            pin_joint,
            BearingSide::Body1,
            c,
            &mut world.rapier.impulse_joints,
        )?),
        None => None,
    };
    Ok(Mechanism {
        world,
        pin,
        bodies: [crank, rod, slider],
    })
}

/// What a run gave.
#[derive(Debug, Default)]
pub struct Run {
    /// The pin's impacts and metrics.
    pub recorder: ImpactRecorder,
    /// Largest force in crank turns 2-3 (from `TURN`), N.
    pub late_peak_n: f64,
    /// Deepest penetration in crank turns 2-3, um.
    pub late_penetration_um: f64,
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps.
    pub rejected: u64,
    /// Crank angle at the end minus `OMEGA t`, rad.
    pub crank_error_rad: f64,
    /// Largest difference of the slider's acceleration from its closed form at the state's
    /// crank angle, after the first half turn, m/s^2: the change of the slider's mean velocity
    /// (position difference over the step) from the step before to the step after the state,
    /// over the kick. (Rapier's stored velocities exclude its joints' position correction,
    /// which the positions include: their differences are off by a step-independent 2 %.)
    pub worst_acceleration_error: f64,
    /// Whether the guards stayed clean.
    pub clean: bool,
    /// The guard violations, in words (the worst of each kind).
    pub violations: Vec<String>,
}

/// Runs to `end` (s) with `control`.
pub fn simulate(clearance: Option<HingeDesign>, control: StepControl, end: f64) -> Result<Run> {
    let Mechanism {
        mut world,
        pin,
        bodies: [crank, _, slider],
    } = build(clearance, control)?;
    world.prepare()?;
    let mut run = Run::default();
    let mut theta = UnwrappedAngle::default();
    // Position differences: the mean velocity of each step.
    let mut last_x = world.rapier.bodies[slider].translation().x;
    let mut last_mean: Option<(f64, f64)> = None;
    let observe = |w: &ClearanceWorld| {
        pin.map(|p| ContactObservation::of(w.clearance.get(p).expect("pin")))
            .unwrap_or_default()
    };
    while world.time() < end {
        let obs = observe(&world);
        theta.update(twist_angle(
            world.rapier.bodies[crank].rotation(),
            Vector::Z,
        ));
        let th = theta.value();
        let info = world.step(end)?;
        run.recorder.record(info.t0, info.dt, &obs);
        if info.t0 >= TURN {
            run.late_peak_n = run.late_peak_n.max(obs.force);
            run.late_penetration_um = run.late_penetration_um.max(obs.penetration * 1e6);
        }
        let x = world.rapier.bodies[slider].translation().x;
        let mean = (x - last_x) / info.dt;
        if info.t0 >= 0.5 * TURN {
            let a = last_mean.map_or(0.0, |(mv, _)| (mean - mv) / info.kick);
            let e = (a - closed_form_acceleration(th)).abs();
            run.worst_acceleration_error = run.worst_acceleration_error.max(e);
        }
        last_mean = Some((mean, info.dt));
        last_x = x;
    }
    run.recorder.finish(world.time(), &observe(&world));
    theta.update(twist_angle(
        world.rapier.bodies[crank].rotation(),
        Vector::Z,
    ));
    run.crank_error_rad = theta.value() - OMEGA * world.time();
    run.steps = world.steps();
    run.rejected = world.guards().rejected_steps;
    run.clean = world.guards().is_clean();
    run.violations = world.guards().messages();
    Ok(run)
}

#[allow(dead_code)]
fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let control = match args.first().map(String::as_str) {
        None | Some("adaptive") => StepControl::adaptive(1e-3, 0.0075),
        Some(a) if a.starts_with("adaptive:") => {
            // adaptive:TOLERANCE[:MAX_DT]
            let mut p = a
                .split(':')
                .skip(1)
                .map(|x| x.parse::<f64>().expect("a number"));
            let tol = p.next().expect("a tolerance");
            StepControl::adaptive(p.next().unwrap_or(1e-3), tol)
        }
        Some(dt) => StepControl::fixed(dt.parse().expect("a step in s")),
    };
    let c = args
        .get(1)
        .map_or(0.5, |s| s.parse().expect("clearance in mm"))
        * 1e-3;
    let turns: f64 = args.get(2).map_or(3.0, |s| s.parse().expect("turns"));
    let end = turns * TURN;
    let wall = std::time::Instant::now();
    let ideal = simulate(None, control, end)?;
    let ideal_wall = wall.elapsed().as_secs_f64();
    let peak = OMEGA * OMEGA * CRANK * (1.0 + CRANK / ROD);
    println!(
        "ideal: {} steps ({} rejected), {:.3} s wall; slider acceleration off its closed form by at most {:.3e} of its peak; crank {:+.3e} deg behind",
        ideal.steps,
        ideal.rejected,
        ideal_wall,
        ideal.worst_acceleration_error / peak,
        -ideal.crank_error_rad.to_degrees()
    );
    let wall = std::time::Instant::now();
    let run = simulate(Some(pin_clearance(c)?), control, end)?;
    let wall = wall.elapsed().as_secs_f64();
    let first = run.recorder.contacts().first().copied().unwrap_or_default();
    println!(
        "clearance c = {} mm: {} steps ({} rejected), {:.3} s wall; crank {:+.3e} deg behind",
        c * 1e3,
        run.steps,
        run.rejected,
        wall,
        -run.crank_error_rad.to_degrees()
    );
    println!(
        "  first impact: onset {:.4} us, approach {:.2} mm/s, peak {:.0} N, {:.2} um deep, {:.2} us long",
        first.onset_t_s * 1e6,
        first.approach_speed_m_s * 1e3,
        first.peak_force_n,
        first.max_penetration_um,
        first.duration_s * 1e6
    );
    let m = run.recorder.metrics();
    println!(
        "  turns 2-3: largest force {:.0} N, deepest {:.2} um; onsets {} ({} impacts), contact {:.1} %",
        run.late_peak_n,
        run.late_penetration_um,
        m.onsets,
        m.impacts,
        100.0 * m.contact_fraction
    );
    {
        println!("  the first impacts: onset, approach speed, peak, penetration, duration");
        for i in run.recorder.contacts().iter().take(6) {
            println!(
                "  {:.3} us {:.1} mm/s {:.0} N {:.2} um {:.2} us",
                i.onset_t_s * 1e6,
                i.approach_speed_m_s * 1e3,
                i.peak_force_n,
                i.max_penetration_um,
                i.duration_s * 1e6
            );
        }
    }
    for v in &run.violations {
        println!("  guard: {v}");
    }
    Ok(())
}
