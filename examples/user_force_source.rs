//! A force source of your own in a `ClearanceWorld`: a linear spring-damper between two bodies
//! that takes part in the step control (its step limit), in the rejected steps (its saved
//! state) and in the guards (a maximum stretch), stepped with `ClearanceWorld::step_with`.
//!
//! Run: `cargo run --release --example user_force_source`

use clearance_joint::prelude::*;
use rapier3d_f64::prelude::*;

/// A spring-damper between the centres of mass of two bodies: force `k (|d| - L0) + c d'`.
struct SpringDamper {
    bodies: [RigidBodyHandle; 2],
    k: f64,
    c: f64,
    rest: f64,
    /// The effective mass between the bodies, kg: sets the oscillation's frequency.
    mass: f64,
    max_stretch: f64,
    stretch: f64,
    wrenches: Vec<Wrench>,
    /// The state a rejected step goes back to.
    saved: (f64, Vec<Wrench>),
}

impl StepHooks for SpringDamper {
    /// The force at the bodies' current state: the wrenches of the next step.
    fn evaluate(&mut self, context: EvaluateContext<'_>) {
        self.wrenches.clear();
        let (Some(rb1), Some(rb2)) = (
            context.bodies.get(self.bodies[0]),
            context.bodies.get(self.bodies[1]),
        ) else {
            return;
        };
        let d = rb2.translation() - rb1.translation();
        let u = d.normalize_or(Vector::X);
        self.stretch = d.length() - self.rest;
        let tension = self.k * self.stretch + self.c * (rb2.linvel() - rb1.linvel()).dot(u);
        for (body, force) in [
            (self.bodies[0], tension * u),
            (self.bodies[1], -tension * u),
        ] {
            self.wrenches.push(Wrench {
                body,
                force,
                torque: Vector::ZERO,
            });
        }
    }
    fn wrenches(&self) -> &[Wrench] {
        &self.wrenches
    }
    fn save_state(&mut self) {
        self.saved = (self.stretch, self.wrenches.clone());
    }
    fn restore_state(&mut self) {
        self.stretch = self.saved.0;
        self.wrenches.clone_from(&self.saved.1);
    }
    /// A `tolerance` fraction of the explicit step's stability limit `2/omega`.
    fn step_limit(&self, step: &StepContext) -> f64 {
        step.tolerance * 2.0 / (self.k / self.mass).sqrt()
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

fn main() -> Result<(), clearance_joint::Error> {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::ZERO;
    rapier.integration_parameters.num_solver_iterations = 1; // the spring's force once a step
    let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(0.05, 0.01));
    let base = world.rapier.bodies.insert(RigidBodyBuilder::fixed());
    // A 1 kg body released 0.1 m beyond the spring's rest length of 0.5 m.
    let body = world.rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.6, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(Vector::ZERO, 1.0, Vector::splat(0.1)))
            .can_sleep(false),
    );
    let (k, mass, zeta) = (4.0 * std::f64::consts::PI.powi(2), 1.0, 0.05);
    let mut spring = SpringDamper {
        bodies: [base, body],
        k,
        c: 2.0 * zeta * (k * mass).sqrt(),
        rest: 0.5,
        mass,
        max_stretch: 0.09,
        stretch: 0.0,
        wrenches: Vec::new(),
        saved: (0.0, Vec::new()),
    };
    // Step 3 s with the spring in every step; note the upward crossings of the rest length.
    let mut crossings = Vec::new();
    let mut last = 0.1;
    while world.time() < 3.0 {
        world.step_with(3.0, &mut spring)?;
        let x = world.rapier.bodies[body].translation().x - 0.5;
        if last < 0.0 && x >= 0.0 {
            // Linear between the two states.
            crossings.push(world.time() - world.last_dt() * x / (x - last));
        }
        last = x;
    }
    let omega = (k / mass).sqrt();
    let period = 2.0 * std::f64::consts::PI / (omega * (1.0 - zeta * zeta).sqrt());
    let measured = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    println!(
        "{} steps (the spring's step limit: {:.2e} s); period {measured:.5} s, closed form {period:.5} s",
        world.steps(),
        0.01 * 2.0 / omega
    );
    for message in world.guards().messages() {
        println!("guard: {message}");
    }
    Ok(())
}
