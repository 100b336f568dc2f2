//! Rapier's substeps (`num_solver_iterations`) under the `ClearanceWorld`'s step: a held force
//! moves the bodies as the exact motion does at any number of substeps and any sequence of
//! steps, and an ideal hinge at a game's 1/60 s with Rapier's four follows its ODE (integrated
//! here by RK4 from the pendulum's equation) and gives the pivot's reaction at the state.

use clearance_joint::model::laws::{Bai, FrictionModel};
use clearance_joint::prelude::*;
use clearance_joint::rapier::observers::reaction::{IdealJoint, ReactionSolver};
use rapier3d_f64::prelude::*;

const G: f64 = 9.81;

fn free_body(world: &mut PhysicsWorld) -> RigidBodyHandle {
    world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.1)))
            .can_sleep(false),
    )
}

/// A body under gravity and a constant force of yours, stepped to irregular times (the last
/// step before each shortened): its height and its sideways travel are the closed forms'.
#[test]
fn a_held_force_moves_the_bodies_exactly_at_any_substeps() {
    let untils = [0.013, 0.031, 0.04, 0.1, 0.1003, 0.25, 0.5, 0.77, 1.0];
    for n in [1, 2, 4, 16] {
        for dt in [1.0 / 60.0, 1e-3] {
            let mut rapier = PhysicsWorld::new();
            rapier.gravity = Vector::new(0.0, -G, 0.0);
            rapier.integration_parameters.num_solver_iterations = n;
            let body = free_body(&mut rapier);
            rapier.bodies[body].add_force(Vector::new(3.0, 0.0, 0.0), true);
            let mut world = ClearanceWorld::new(rapier, StepControl::fixed(dt));
            for until in untils {
                run_to(&mut world, until);
                let t = world.time();
                let p = world.rapier.bodies[body].translation();
                let (y, x) = (-0.5 * G * t * t, 0.5 * 1.5 * t * t);
                assert!(
                    (p.y - y).abs() < 1e-9 && (p.x - x).abs() < 1e-9,
                    "n = {n}, dt = {dt}, t = {t}: ({}, {}) against ({x}, {y})",
                    p.x,
                    p.y
                );
            }
        }
    }
}

/// Steps `world` until `until` (s).
fn run_to(world: &mut ClearanceWorld, until: f64) {
    while world.time() < until - 1e-12 {
        world.step(until).unwrap();
    }
}

/// The plate's width, m: its centre of mass is half of it from the pin.
const PLATE_W: f64 = 0.8;

/// A world under gravity with `n` solver iterations, a fixed base and a 5 kg plate (inertia
/// 0.68 kg m^2 about its centre, on the pin's axis) lying level with its edge on the base's
/// origin: (world, base, plate).
fn level_plate(n: usize) -> (PhysicsWorld, RigidBodyHandle, RigidBodyHandle) {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -G, 0.0);
    rapier.integration_parameters.num_solver_iterations = n;
    let base = rapier.bodies.insert(RigidBodyBuilder::fixed());
    let plate = rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(PLATE_W / 2.0, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                5.0,
                Vector::new(0.42, 0.28, 0.68),
            ))
            .can_sleep(false),
    );
    (rapier, base, plate)
}

/// The plate's hinge angle (rad) and rate by RK4 of `I theta'' = -m g r cos(theta)`, from rest
/// at `theta = 0`, at `t`.
fn pendulum_ode(inertia: f64, m: f64, r: f64, t: f64) -> (f64, f64) {
    let f = |th: f64| -m * G * r * th.cos() / inertia;
    let (mut th, mut w) = (0.0f64, 0.0f64);
    let n = 100_000;
    let h = t / n as f64;
    for _ in 0..n {
        let (k1t, k1w) = (w, f(th));
        let (k2t, k2w) = (w + 0.5 * h * k1w, f(th + 0.5 * h * k1t));
        let (k3t, k3w) = (w + 0.5 * h * k2w, f(th + 0.5 * h * k2t));
        let (k4t, k4w) = (w + h * k3w, f(th + h * k3t));
        th += h / 6.0 * (k1t + 2.0 * k2t + 2.0 * k3t + k4t);
        w += h / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
    }
    (th, w)
}

/// A 5 kg plate on an ideal revolute, released level, at 1/60 s with `n` substeps: its angle at
/// 0.1 s and 0.5 s (rad) and the pivot's reaction at 0.5 s (N, on the plate) read from
/// `solve_reactions`.
fn ideal_plate(n: usize) -> (f64, f64, Vector) {
    let (mut rapier, base, plate) = level_plate(n);
    let rev =
        RevoluteJointBuilder::new(Vector::Z).local_anchor2(Vector::new(-PLATE_W / 2.0, 0.0, 0.0));
    let joint = rapier.impulse_joints.insert(base, plate, rev, true);
    let dt = 1.0 / 60.0;
    let mut world = ClearanceWorld::new(rapier, StepControl::fixed(dt));
    let angle = |world: &ClearanceWorld| world.rapier.bodies[plate].rotation().to_scaled_axis().z;
    run_to(&mut world, 6.0 * dt);
    let early = angle(&world);
    run_to(&mut world, 30.0 * dt);
    let ideal = [IdealJoint::from_rapier(&world.rapier.impulse_joints, joint).unwrap()];
    let mut solver = ReactionSolver::default();
    let reaction = world.solve_reactions(&mut solver, &ideal).unwrap()[0];
    (early, angle(&world), reaction)
}

#[test]
fn an_ideal_hinge_at_60_hz_follows_its_ode_with_four_substeps() {
    let (m, r, izz) = (5.0, 0.4, 0.68);
    let inertia = izz + m * r * r;
    let (early_ode, _) = pendulum_ode(inertia, m, r, 0.1);
    let (th, w) = pendulum_ode(inertia, m, r, 0.5);
    // The pivot's force on the plate at 0.5 s: m a_com + m g up, a_com from the ODE's state.
    let alpha = -m * G * r * th.cos() / inertia;
    let (c, s) = (th.cos(), th.sin());
    let a_com = Vector::new(
        -r * w * w * c - r * alpha * s,
        -r * w * w * s + r * alpha * c,
        0.0,
    );
    let reaction_ode = a_com * m + Vector::new(0.0, m * G, 0.0);
    // Rapier's own error at 1/60 s with one substep: 0.0003 deg at 0.1 s, 0.71 deg and 2.2 % of
    // the reaction at 0.5 s; with four, 0.0001 deg, 0.18 deg and 0.56 %. A world running
    // behind by (n - 1)/(2 n) of a step misses by 0.43 and 2.0 deg, and 2.7 %, with four.
    for (n, late_deg, reaction_share) in [(1, 1.0, 0.03), (4, 0.5, 0.012)] {
        let (early, late, reaction) = ideal_plate(n);
        assert!(
            (early - early_ode).abs().to_degrees() < 0.01,
            "n = {n}: {} deg at 0.1 s against the ODE's {}",
            early.to_degrees(),
            early_ode.to_degrees()
        );
        assert!(
            (late - th).abs().to_degrees() < late_deg,
            "n = {n}: {} deg at 0.5 s against the ODE's {}",
            late.to_degrees(),
            th.to_degrees()
        );
        assert!(
            (reaction - reaction_ode).length() < reaction_share * reaction_ode.length(),
            "n = {n}: reaction {reaction:?} N against the ODE's {reaction_ode:?}"
        );
    }
}

/// The largest contact force of a 5 kg plate released level on a sub-cycled steel pin (0.2 mm
/// of play, dry friction), over 1 s at 1/60 s with `n` solver iterations, N.
fn sub_cycled_plate_peak(n: usize) -> f64 {
    let (rapier, base, plate) = level_plate(n);
    let mut world = ClearanceWorld::new(rapier, StepControl::fixed(1.0 / 60.0));
    let pin = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)
        .unwrap()
        .friction(FrictionModel::Bai(Bai::DRY))
        .integration(ContactIntegration::SubCycled)
        .joint(
            Vector::ZERO,
            Vector::new(-PLATE_W / 2.0, 0.0, 0.0),
            Vector::Z,
            Vector::Z,
        )
        .unwrap();
    let pin = world.insert_clearance(base, plate, pin).unwrap();
    let mut peak: f64 = 0.0;
    while world.time() < 1.0 - 1e-12 {
        world.step(1.0).unwrap();
        for s in world.clearance.get(pin).unwrap().substeps() {
            peak = peak.max(s.force.normal_force);
        }
    }
    assert!(world.guards().is_clean(), "{:?}", world.guards());
    peak
}

/// A sub-cycled pin at a game's rate strikes as hard with Rapier's four or sixteen substeps as
/// with one (2304.9 N at each); a world running behind by `(n - 1)/(2 n)` of a step struck
/// 2703.8 N with four. (The same plate with an inertia of 0.693 kg m^2 about its pin's axis:
/// 2308.8 N at 1, 4 and 16, against 2306.2 N from the explicit joint at adaptive steps of at most
/// 1 ms and the tolerance 1e-5, one iteration.)
#[test]
fn a_sub_cycled_pin_at_60_hz_strikes_alike_at_any_substeps() {
    let one = sub_cycled_plate_peak(1);
    for n in [4, 16] {
        let peak = sub_cycled_plate_peak(n);
        assert!(
            (peak / one - 1.0).abs() < 0.005,
            "n = {n}: {peak} N against {one} N with one substep"
        );
    }
}
