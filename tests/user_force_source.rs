//! A force source of the user's own, a linear spring-damper between two bodies, taking part in
//! the steps of a `ClearanceWorld` (and of the ECS schedule) through `StepHooks`: its wrenches,
//! its step limit, its saved state on a rejected step and its guard. Also the swap test: sets
//! edited through the world's public fields are noticed by their revisions.

use clearance_joint::prelude::*;
use rapier3d_f64::prelude::*;

/// A linear spring-damper between an anchor on each of two bodies: force `k (|d| - L0) + c d'`
/// along the line between the anchors, pulling them together when stretched.
#[derive(Clone, Debug)]
struct SpringDamper {
    bodies: [RigidBodyHandle; 2],
    /// The anchors in each body's frame, m.
    anchors: [Vector; 2],
    /// Stiffness, N/m; damping, N s/m; rest length, m.
    k: f64,
    c: f64,
    rest: f64,
    /// The effective mass between the anchors, kg (for the step limit).
    mass: f64,
    /// The stretch beyond which the guard records a violation, m.
    max_stretch: f64,
    /// The stretch at the last evaluation, m.
    stretch: f64,
    wrenches: Vec<Wrench>,
    /// Evaluations of the state the run went through: saved before a step and restored when the
    /// step is rejected, so it counts the accepted states only.
    evaluations: u64,
    /// Every call of `evaluate`, rejected steps included (never restored).
    calls: u64,
    saved: (u64, f64, Vec<Wrench>),
}

impl SpringDamper {
    fn new(bodies: [RigidBodyHandle; 2], k: f64, c: f64, rest: f64, mass: f64) -> Self {
        SpringDamper {
            bodies,
            anchors: [Vector::ZERO; 2],
            k,
            c,
            rest,
            mass,
            max_stretch: f64::INFINITY,
            stretch: 0.0,
            wrenches: Vec::new(),
            evaluations: 0,
            calls: 0,
            saved: (0, 0.0, Vec::new()),
        }
    }
}

impl StepHooks for SpringDamper {
    fn evaluate(&mut self, context: EvaluateContext<'_>) {
        self.calls += 1;
        self.evaluations += 1;
        self.wrenches.clear();
        let [h1, h2] = self.bodies;
        let (Some(rb1), Some(rb2)) = (context.bodies.get(h1), context.bodies.get(h2)) else {
            return;
        };
        let com = |rb: &RigidBody| *rb.position() * rb.mass_properties().local_mprops.local_com;
        let p1 = *rb1.position() * self.anchors[0];
        let p2 = *rb2.position() * self.anchors[1];
        let v1 = rb1.linvel() + rb1.angvel().cross(p1 - com(rb1));
        let v2 = rb2.linvel() + rb2.angvel().cross(p2 - com(rb2));
        let d = p2 - p1;
        let length = d.length();
        let u = if length > 0.0 { d / length } else { Vector::X };
        self.stretch = length - self.rest;
        let tension = self.k * self.stretch + self.c * (v2 - v1).dot(u);
        // Body 1 is pulled towards body 2, and body 2 towards body 1.
        for (body, point, rb, force) in [(h1, p1, rb1, tension * u), (h2, p2, rb2, -tension * u)] {
            self.wrenches.push(Wrench {
                body,
                force,
                torque: (point - com(rb)).cross(force),
            });
        }
    }

    fn wrenches(&self) -> &[Wrench] {
        &self.wrenches
    }

    fn save_state(&mut self) {
        self.saved = (self.evaluations, self.stretch, self.wrenches.clone());
    }

    fn restore_state(&mut self) {
        (self.evaluations, self.stretch) = (self.saved.0, self.saved.1);
        self.wrenches.clone_from(&self.saved.2);
    }

    /// `tolerance` of `2/omega`, the stability limit of the explicit step: the adaptive step
    /// resolves the oscillation to the control's tolerance.
    fn step_limit(&self, step: &StepContext) -> f64 {
        let omega = (self.k / self.mass).sqrt();
        step.tolerance * 2.0 / omega
    }

    fn record_guards(&self, step: &StepContext, guards: &mut GuardReport) {
        if self.stretch.abs() > self.max_stretch {
            guards.record(
                Violation::new(
                    GuardKind::Other,
                    self.stretch.abs(),
                    self.max_stretch,
                    step.t,
                )
                .joint("spring", None)
                .note("the spring is stretched past its maximum"),
            );
        }
    }
}

/// A world without gravity: a fixed base and a free 1 kg body at `x0` on the x axis.
fn oscillator_world(x0: f64, control: StepControl) -> (ClearanceWorld, [RigidBodyHandle; 2]) {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::ZERO;
    rapier.integration_parameters.num_solver_iterations = 1;
    let mut world = ClearanceWorld::new(rapier, control);
    let base = world.rapier.bodies.insert(RigidBodyBuilder::fixed());
    let mass = world.rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(x0, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(Vector::ZERO, 1.0, Vector::splat(0.1)))
            .can_sleep(false),
    );
    (world, [base, mass])
}

/// The mass's x over time, sampled at every accepted step until `duration` (s).
fn run(
    world: &mut ClearanceWorld,
    source: &mut SpringDamper,
    body: RigidBodyHandle,
    duration: f64,
) -> Vec<(f64, f64)> {
    let mut samples = vec![(0.0, world.rapier.bodies[body].translation().x)];
    while world.time() < duration {
        world.step_with(duration, source).unwrap();
        samples.push((world.time(), world.rapier.bodies[body].translation().x));
    }
    samples
}

/// The times of the upward zero crossings of `x - rest` and the peaks of `x - rest` (linear
/// interpolation between samples; the peaks are the largest samples between crossings).
fn crossings_and_peaks(samples: &[(f64, f64)], rest: f64) -> (Vec<f64>, Vec<f64>) {
    let mut up = Vec::new();
    let mut peaks = Vec::new();
    let mut peak: f64 = 0.0;
    for w in samples.windows(2) {
        let ((t0, a), (t1, b)) = ((w[0].0, w[0].1 - rest), (w[1].0, w[1].1 - rest));
        peak = peak.max(b);
        if a < 0.0 && b >= 0.0 {
            up.push(t0 + (t1 - t0) * (-a) / (b - a));
        }
        if a > 0.0 && b <= 0.0 {
            peaks.push(peak);
            peak = 0.0;
        }
    }
    (up, peaks)
}

#[test]
fn the_two_body_oscillator_matches_the_damped_closed_form() {
    // k = 4 pi^2 N/m on 1 kg: omega = 2 pi rad/s; damping ratio 0.05.
    let (k, m, zeta, rest, a0) = (4.0 * std::f64::consts::PI.powi(2), 1.0, 0.05, 0.5, 0.1);
    let omega: f64 = (k / m).sqrt();
    let c = 2.0 * zeta * (k * m).sqrt();
    let (mut world, bodies) = oscillator_world(rest + a0, StepControl::adaptive(0.05, 0.01));
    let mut spring = SpringDamper::new(bodies, k, c, rest, m);
    let samples = run(&mut world, &mut spring, bodies[1], 5.0);
    // Closed form of the free damped oscillator: period 2 pi / (omega sqrt(1 - zeta^2)), and
    // successive peaks of one sign in the ratio exp(-zeta omega Td).
    let period = 2.0 * std::f64::consts::PI / (omega * (1.0 - zeta * zeta).sqrt());
    let decay = (-zeta * omega * period).exp();
    let (up, peaks) = crossings_and_peaks(&samples, rest);
    assert!(up.len() >= 4 && peaks.len() >= 4, "{up:?} {peaks:?}");
    let measured = (up[up.len() - 1] - up[0]) / (up.len() - 1) as f64;
    let ratio = (peaks[peaks.len() - 1] / peaks[0]).powf(1.0 / (peaks.len() - 1) as f64);
    // Steps of at most 0.02/omega: the Verlet scheme's phase error is (omega h)^2/24 ~ 2e-5
    // per radian, and the damping read from Rapier's mean velocity over the last step (half a
    // step behind the state) shifts the stiffness by c h/(2 m) ~ zeta omega h ~ 1e-3 of k, half
    // that in the period (5e-4 measured). The sampled peaks lie within (omega h)^2/2 ~ 2e-4 of
    // the true ones. Tolerances: 1e-3 of the period, 3e-3 of the decay ratio.
    assert!(
        (measured / period - 1.0).abs() < 1e-3,
        "period {measured} s against the closed form's {period} s"
    );
    assert!(
        (ratio / decay - 1.0).abs() < 3e-3,
        "decay per period {ratio} against the closed form's {decay}"
    );
    // The first peak is the release (at rest, a peak of the closed form); the next one a damped
    // period later.
    assert!((peaks[0] / a0 - 1.0).abs() < 1e-3, "{} {a0}", peaks[0]);
    assert!(
        (peaks[1] / (a0 * decay) - 1.0).abs() < 3e-3,
        "{} {}",
        peaks[1],
        a0 * decay
    );
    assert!(world.guards().is_clean(), "{:?}", world.guards());
}

#[test]
fn the_step_limit_limits_the_steps() {
    let steps = |k: f64| {
        let (mut world, bodies) = oscillator_world(0.6, StepControl::adaptive(0.05, 0.01));
        let mut spring = SpringDamper::new(bodies, k, 0.1, 0.5, 1.0);
        world.step_to_with(2.0, &mut spring).unwrap();
        world.steps()
    };
    let (soft, stiff) = (steps(40.0), steps(160.0));
    // omega doubles: the step halves.
    assert!(
        (stiff as f64) > 1.8 * soft as f64,
        "{soft} steps at k = 40 N/m, {stiff} at 160 N/m"
    );
    // Without the source the free body would step at max_dt: 40 steps.
    assert!(soft > 100, "{soft}");
}

#[test]
fn a_rejected_step_restores_the_source() {
    // A 2 kg arm on a steel pin with 0.2 mm of play, released horizontal under gravity: its
    // explicit contact's impacts have steps rejected. The spring-damper holds a second body in
    // the same world.
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -9.81, 0.0);
    rapier.integration_parameters.num_solver_iterations = 1;
    let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, 0.02));
    let base = world.rapier.bodies.insert(RigidBodyBuilder::fixed());
    let arm = world.rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.3, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02)))
            .can_sleep(false),
    );
    let bob = world.rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.0, -1.0, 1.0))
            .additional_mass_properties(MassProperties::new(Vector::ZERO, 1.0, Vector::splat(0.1)))
            .can_sleep(false),
    );
    let pin = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)
        .unwrap()
        .integration(ContactIntegration::Explicit)
        .joint(
            Vector::ZERO,
            Vector::new(-0.3, 0.0, 0.0),
            Vector::Z,
            Vector::Z,
        )
        .unwrap();
    world.insert_clearance(base, arm, pin).unwrap();
    let mut spring = SpringDamper::new([base, bob], 100.0, 1.0, 1.0, 1.0);
    spring.anchors[1] = Vector::ZERO;
    world.step_to_with(0.2, &mut spring).unwrap();
    let rejected = world.guards().rejected_steps;
    assert!(rejected > 0, "the impacts had no step rejected");
    // One evaluation at the start and one per accepted step; each rejected step's evaluation
    // was undone by `restore_state`.
    assert_eq!(spring.evaluations, world.steps() + 1);
    assert_eq!(spring.calls, spring.evaluations + rejected);
}

#[test]
fn the_source_guard_shows_in_the_world_guards() {
    let (mut world, bodies) = oscillator_world(0.6, StepControl::adaptive(0.05, 0.01));
    let mut spring = SpringDamper::new(bodies, 40.0, 0.0, 0.5, 1.0);
    spring.max_stretch = 0.08;
    world.step_to_with(1.0, &mut spring).unwrap();
    let v = world
        .guards()
        .violations
        .iter()
        .find(|v| v.joint.as_deref() == Some("spring"))
        .expect("the spring's guard");
    assert_eq!(v.kind, GuardKind::Other);
    assert!(v.worst > 0.099 && v.limit == 0.08 && v.count > 1, "{v:?}");
    assert_eq!(v.to_string(), "the spring is stretched past its maximum");
    assert!(!world.guards().is_clean());
}

#[cfg(feature = "ecs")]
#[test]
fn the_source_runs_in_the_ecs_schedule_as_in_the_plain_world() {
    use bevy_ecs::prelude::World;
    use clearance_joint::ecs::{Physics, UserHooks, physics_schedule, run_step};
    let (dt, n) = (1e-3, 1500);
    let (k, c) = (40.0, 0.5);
    // The plain world, fixed steps of dt.
    let (mut plain, bodies) = oscillator_world(0.6, StepControl::fixed(dt));
    let mut spring = SpringDamper::new(bodies, k, c, 0.5, 1.0);
    for i in 1..=n {
        plain.step_with(i as f64 * dt, &mut spring).unwrap();
    }
    // The same Rapier world under the ECS schedule (fixed steps of its dt).
    let (mut inner, bodies) = oscillator_world(0.6, StepControl::fixed(dt));
    inner.rapier.integration_parameters.dt = dt;
    let rapier = std::mem::replace(&mut inner.rapier, PhysicsWorld::new());
    let mut world = World::new();
    world.insert_resource(Physics::from_world(rapier));
    world.insert_resource(UserHooks::new(SpringDamper::new(bodies, k, c, 0.5, 1.0)));
    let mut schedule = physics_schedule();
    for _ in 0..n {
        run_step(&mut world, &mut schedule).unwrap();
    }
    let physics = world.resource::<Physics>();
    assert_eq!(physics.steps(), n);
    let (a, b) = (
        plain.rapier.bodies[bodies[1]].translation(),
        physics.world.rapier.bodies[bodies[1]].translation(),
    );
    assert!((a - b).length() < 1e-12, "plain {a:?}, ECS {b:?}");
    // It moved: the spring pulled it back through its rest length.
    assert!((a.x - 0.6).abs() > 0.05, "{a:?}");
}

/// The arm of the swap test: a base, a 2 kg arm at (0.3, 0, 0), gravity, one solver
/// iteration, adaptive steps.
fn arm_world() -> (ClearanceWorld, RigidBodyHandle, RigidBodyHandle) {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -9.81, 0.0);
    rapier.integration_parameters.num_solver_iterations = 1;
    let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-4, 0.02));
    let base = world.rapier.bodies.insert(RigidBodyBuilder::fixed());
    let arm = world.rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.3, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02)))
            .can_sleep(false),
    );
    (world, base, arm)
}

/// The pin of the swap test: its journal `offset` (m) from the bearing's centre along x.
fn pin(offset: f64) -> ClearanceJoint {
    HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)
        .unwrap()
        .joint(
            Vector::ZERO,
            Vector::new(-0.3 + offset, 0.0, 0.0),
            Vector::Z,
            Vector::Z,
        )
        .unwrap()
}

#[test]
fn a_swap_through_the_public_fields_is_noticed() {
    // Old: a centred journal and a +5 N m drive. New: a journal pressed 5 um into the wall
    // (a contact force from the first step) and a -3 N m drive.
    let pressed = 0.2e-3 + 5e-6;
    let (mut swapped, base, arm) = arm_world();
    let old_pin = swapped.insert_clearance(base, arm, pin(0.0)).unwrap();
    let old_drive = swapped
        .drives
        .insert(TorsionSpring::new(base, arm, Vector::Z, 5.0, 0.0).unwrap());
    swapped.prepare().unwrap();
    // The swap, through the fields: the same number of joints and of drives.
    let w = &mut swapped;
    w.clearance
        .remove(old_pin, &mut w.rapier.bodies, &mut w.rapier.impulse_joints)
        .unwrap();
    let new_pin = w
        .clearance
        .insert(
            base,
            arm,
            pin(pressed),
            &w.rapier.bodies,
            &mut w.rapier.impulse_joints,
        )
        .unwrap();
    w.drives.remove(old_drive).unwrap();
    w.drives
        .insert(TorsionSpring::new(base, arm, Vector::Z, -3.0, 0.0).unwrap());
    // Built directly with the new pin and drive.
    let (mut direct, base, arm) = arm_world();
    let direct_pin = direct.insert_clearance(base, arm, pin(pressed)).unwrap();
    direct
        .drives
        .insert(TorsionSpring::new(base, arm, Vector::Z, -3.0, 0.0).unwrap());
    for step in 0..50 {
        let (a, b) = (swapped.step(1.0).unwrap(), direct.step(1.0).unwrap());
        assert_eq!(a.dt, b.dt, "step {step}");
        let (ra, rb) = (&swapped.rapier.bodies[arm], &direct.rapier.bodies[arm]);
        assert!(
            (ra.linvel() - rb.linvel()).length() < 1e-12
                && (ra.angvel() - rb.angvel()).length() < 1e-12,
            "step {step}: swapped {:?} {:?}, direct {:?} {:?}",
            ra.linvel(),
            ra.angvel(),
            rb.linvel(),
            rb.angvel()
        );
        // Between steps the bodies carry none of the drives' torques.
        assert_eq!(ra.user_torque(), Vector::ZERO);
        let force = |w: &ClearanceWorld, h| w.clearance.get(h).unwrap().report().force.normal_force;
        assert_eq!(force(&swapped, new_pin), force(&direct, direct_pin));
        if step == 0 {
            assert!(
                force(&direct, direct_pin) > 0.0,
                "the new pin is in contact at once"
            );
            // The -3 N m drive turns the arm clockwise about z from the first step.
            assert!(ra.angvel().z < 0.0, "{:?}", ra.angvel());
        }
    }
}
