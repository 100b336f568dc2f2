//! Sub-cycled contact ([`ContactIntegration::SubCycled`]): the invariants and static balances
//! that must hold whatever the world's step, at the steps of robot and game worlds (1 ms with
//! one solver iteration, 1/60 s with Rapier's default four). The impacts against their ODEs are
//! in `tests/references.rs`. Runs optimised.

use clearance_joint::model::laws::{Coulomb, FrictionModel};
use clearance_joint::prelude::*;
use rapier3d_f64::prelude::*;

#[path = "support/turning_arm.rs"]
mod turning_arm;
use turning_arm::{link, penetrations, turning_arm};

const G: f64 = 9.81;
/// The journal's mass, kg, and its bearing: radius 10 mm, clearance 0.2 mm, width 16 mm.
const MASS: f64 = 2.0;
const R_B: f64 = 0.010;
const C: f64 = 0.2e-3;
/// Coulomb friction: `mu_d` and the regularisation speed, m/s.
const MU: f64 = 0.3;
const V_EPS: f64 = 1e-4;

/// The journal's bearing (16 mm wide) with Hertz's law of stiffness `k` (N/m^1.5), no damping
/// and no friction.
fn hertz_design(k: f64) -> HingeDesign {
    use clearance_joint::model::laws::{BearingGeometry, Hertz, NormalModel};
    let hertz = NormalModel::Hertz(Hertz::new(k, 1.5).unwrap());
    HingeDesign::new(BearingGeometry::new(R_B, R_B - C, 0.016).unwrap(), hertz)
}

/// The pin of `design` centred on both bodies' origins.
fn centred(design: HingeDesign) -> ClearanceJoint {
    design
        .joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
        .unwrap()
}

/// The journal's sub-cycled pin of [`hertz_design`].
fn sub_cycled_hertz_pin(k: f64) -> ClearanceJoint {
    centred(hertz_design(k).integration(ContactIntegration::SubCycled))
}

/// A rattle's energy check: more than ten onsets, the largest gain below `bound` (J), the
/// world's guards clean.
fn assert_rattled_without_gain(onsets: usize, worst: f64, bound: f64, world: &ClearanceWorld) {
    assert!(onsets > 10, "{onsets} onsets");
    assert!(worst < bound, "energy gained: {worst:+.3e} J");
    assert!(world.guards().is_clean(), "{:?}", world.guards());
}

/// A world under gravity stepped by `control` with `iterations` solver iterations, holding a
/// fixed base and a free 2 kg journal (0.01 kg m² about each axis) at the origin: `(world, base,
/// journal)`.
fn journal_world(
    control: StepControl,
    iterations: usize,
) -> (ClearanceWorld, RigidBodyHandle, RigidBodyHandle) {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -G, 0.0);
    rapier.integration_parameters.num_solver_iterations = iterations;
    let mut world = ClearanceWorld::new(rapier, control);
    let base = world.rapier.bodies.insert(RigidBodyBuilder::fixed());
    let journal = world.rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                MASS,
                Vector::splat(0.01),
            ))
            .can_sleep(false),
    );
    (world, base, journal)
}

/// A journal of 2 kg hanging in a fixed bearing under gravity, turned by the constant torque
/// `torque` (N m) about the hinge, in a world stepped by `control` with `iterations` solver
/// iterations: steel, the improved law, Coulomb friction, the
/// contact integrated as `integration` says. Stepped to `end` (s); returns the world and the
/// pin.
fn held_journal(
    torque: f64,
    control: StepControl,
    iterations: usize,
    end: f64,
    integration: ContactIntegration,
) -> clearance_joint::Result<(ClearanceWorld, ClearanceJointHandle)> {
    let (mut world, base, journal) = journal_world(control, iterations);
    world.rapier.bodies[journal].add_torque(Vector::new(0.0, 0.0, torque), true);
    let pin = HingeDesign::steel_improved_liu(R_B, C, 0.016)
        .unwrap()
        .friction(FrictionModel::Coulomb(Coulomb::new(MU, V_EPS).unwrap()))
        .integration(integration)
        .joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
        .unwrap();
    let pin = world.insert_clearance(base, journal, pin).unwrap();
    world.step_to(end)?;
    Ok((world, pin))
}

/// A journal that friction holds against a torque comes to rest, at world steps of 1 ms (one
/// solver iteration) and of 1/60 s (Rapier's four iterations), at the default tolerance, with
/// the static balance of its forces: the contact carries the
/// weight, `|F| = m g`, friction carries the torque, `F_t = tau/R_j`, the normal force the rest,
/// `F_N = sqrt((m g)^2 - F_t^2)` (each within 0.1 %), and the journal's centre sits where the
/// resultant points, at `asin(F_t/(m g))` from the bottom (within 0.5 %). The journal rocks in
/// its bearing after the drop (a lightly damped mode of its spin and its path along the wall)
/// and has settled by 12 s. An explicit joint cannot take these steps: friction's stability
/// limit near zero slip is about 1e-7 s here.
#[test]
fn a_friction_held_journal_rests_at_game_and_robot_steps_with_its_static_balance() {
    let r_j = R_B - C;
    let f_t = 2.0;
    let weight = MASS * G;
    let f_n = (weight * weight - f_t * f_t).sqrt();
    for (dt, iterations) in [(1e-3, 1), (1.0 / 60.0, 4)] {
        let sub_cycled = ContactIntegration::SubCycled;
        let control = StepControl {
            tolerance: 0.0075,
            ..StepControl::fixed(dt)
        };
        let (world, pin) = held_journal(f_t * r_j, control, iterations, 12.0, sub_cycled).unwrap();
        let r = world.clearance.get(pin).unwrap().report();
        let e = r.state.eccentricity;
        let angle = (e.x / e.length()).asin().abs();
        println!(
            "dt {dt:.3e} s, {iterations} iteration(s): F_N {:.5} N (static {f_n:.5}), F_t {:.5} N \
             (static {f_t}), |F| {:.5} N, rest angle {:.5} rad (static {:.5}), centre speed \
             {:.2e} m/s, penetration {:.4} um",
            r.force.normal_force,
            r.force.friction_force,
            r.force.on_journal.length(),
            angle,
            (f_t / weight).asin(),
            r.state.eccentricity_rate.length(),
            r.state.penetration * 1e6,
        );
        assert!((r.force.normal_force / f_n - 1.0).abs() < 1e-3);
        assert!((r.force.friction_force / f_t - 1.0).abs() < 1e-3);
        assert!((r.force.on_journal.length() / weight - 1.0).abs() < 1e-3);
        assert!((angle / (f_t / weight).asin() - 1.0).abs() < 5e-3);
        assert!(r.state.eccentricity_rate.length() < 1e-5);
        assert!(world.guards().is_clean(), "{:?}", world.guards());
    }
    // The explicit joint at 1 ms: refused.
    let control = StepControl::fixed(1e-3);
    let explicit = held_journal(f_t * r_j, control, 1, 12.0, ContactIntegration::Explicit);
    assert!(
        matches!(explicit, Err(clearance_joint::Error::StepTooLarge(_))),
        "{:?}",
        explicit.err()
    );
}

/// A sub-cycle asked for more sub-steps in one world step than it takes (the tolerance 1e-6 in
/// steps of 1/60 s: about 8 million) says so: a `SubSteps` violation naming the joint, and under
/// a strict step control an error; at the default tolerance the same run is clean.
#[test]
fn a_sub_cycle_beyond_its_sub_step_cap_is_a_guard_violation() {
    use clearance_joint::rapier::pipeline::protocol::GuardKind;
    let sub_cycled = ContactIntegration::SubCycled;
    let control = StepControl {
        tolerance: 1e-6,
        ..StepControl::fixed(1.0 / 60.0)
    };
    let (world, _) = held_journal(0.0, control, 1, 0.05, sub_cycled).unwrap();
    let v = &world.guards().violations;
    assert!(
        v.iter()
            .any(|v| v.kind == GuardKind::SubSteps && v.joint.as_deref() == Some("clearance joint")),
        "{v:?}"
    );
    println!("{}", v[0]);
    let strict = held_journal(
        0.0,
        StepControl {
            strict: true,
            ..control
        },
        1,
        0.05,
        sub_cycled,
    );
    assert!(
        matches!(strict, Err(clearance_joint::Error::Guard { .. })),
        "{:?}",
        strict.err()
    );
    let control = StepControl::fixed(1.0 / 60.0);
    let (world, _) = held_journal(0.0, control, 1, 0.05, sub_cycled).unwrap();
    assert!(world.guards().is_clean(), "{:?}", world.guards());
}

/// A sub-cycle that hits its cap and then throws its journal out says why in the divergence: the
/// journal of the test above with the law's damping explicit (`implicit_damping` off) at the
/// tolerance 1e-6 in steps of 1/60 s hits the cap at its first step, and the rest of its second
/// step, taken in one sub-step far beyond the damped limit, throws the journal out. The message
/// names the cap, the joint and the technique that is off; with the technique on, the same run
/// hits the cap without diverging (the test above).
#[test]
fn a_divergence_after_the_sub_step_cap_names_the_cap() {
    let (mut world, base, journal) = journal_world(
        StepControl {
            tolerance: 1e-6,
            ..StepControl::fixed(1.0 / 60.0)
        },
        1,
    );
    let pin = HingeDesign::steel_improved_liu(R_B, C, 0.016)
        .unwrap()
        .friction(FrictionModel::Coulomb(Coulomb::new(MU, V_EPS).unwrap()))
        .integration(ContactIntegration::SubCycled)
        .sub_cycle_techniques(SubCycleTechniques::default().implicit_damping(false))
        .joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
        .unwrap();
    world.insert_clearance(base, journal, pin).unwrap();
    let error = world.step_to(0.1).expect_err("the journal is thrown out");
    let message = error.to_string();
    println!("{message}");
    assert!(
        matches!(error, clearance_joint::Error::Diverged { .. }),
        "{error:?}"
    );
    for words in [
        "clearance joint `clearance joint` hit its sub-cycle's cap of 100000 sub-steps",
        "shorter world steps",
        "a larger tolerance",
        "`implicit_damping` back on",
    ] {
        assert!(message.contains(words), "`{words}` not in: {message}");
    }
}

/// A pin switched between explicit and sub-cycled contact mid-run
/// ([`ClearanceJoint::set_integration`]) goes on as it was: the 2 kg journal resting at the
/// bottom of its bearing (steel, the improved law, Coulomb friction; adaptive steps of at most
/// 1 ms, one solver iteration), explicit to 1 s, sub-cycled to 1.2 s, set sub-cycled again
/// (a joint reached mid-run and left as it was) to 1.3 s, explicit again to 1.4 s.
/// At every step after each switch the contact stays closed with no new onset, the step's
/// contact impulse is the weight's over the step (within 1e-9 of it; measured 4e-12), and the
/// journal's energy (kinetic at the state, elastic, potential) stays within 1e-15 J of its value
/// at the switch (measured 2e-18 J). Switched to sub-cycled without the explicit force's half
/// kick held, the journal fell into its wall at `g h/2` and rang: the impulse 4.3 % off the
/// weight's, 3.8e-9 J gained.
#[test]
fn a_resting_pin_switched_between_explicit_and_sub_cycled_goes_on_as_it_was() {
    let (mut world, base, journal) = journal_world(StepControl::adaptive(1e-3, 0.0075), 1);
    let pin = HingeDesign::steel_improved_liu(R_B, C, 0.016)
        .unwrap()
        .friction(FrictionModel::Coulomb(Coulomb::new(MU, V_EPS).unwrap()))
        .integration(ContactIntegration::Explicit)
        .joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
        .unwrap();
    let pin = world.insert_clearance(base, journal, pin).unwrap();
    world.step_to(1.0).unwrap();
    let energy = |world: &ClearanceWorld| {
        let (v, w) = world.velocity_at_state(journal).unwrap();
        let rb = &world.rapier.bodies[journal];
        let kinetic = 0.5 * MASS * v.length_squared() + 0.5 * 0.01 * w.length_squared();
        let elastic = world.clearance.get(pin).unwrap().elastic_energy();
        kinetic + elastic + MASS * G * rb.translation().y
    };
    // The second entry reaches the sub-cycled joint through `get_mut` and sets what it is:
    // the world's re-evaluation must keep the impulse the last sub-cycle left held.
    for (integration, end) in [
        (ContactIntegration::SubCycled, 1.2),
        (ContactIntegration::SubCycled, 1.3),
        (ContactIntegration::Explicit, 1.4),
    ] {
        let before = energy(&world);
        world
            .clearance
            .get_mut(pin)
            .unwrap()
            .set_integration(integration);
        let (mut worst_impulse, mut worst_energy, mut steps) = (0.0f64, 0.0f64, 0);
        while world.time() < end - 1e-12 {
            let t0 = world.time();
            world.step(end).unwrap();
            let h = world.time() - t0;
            let j = world.clearance.get(pin).unwrap();
            assert_eq!(j.integration(), integration);
            assert!(j.in_contact() && !j.report().onset, "at {}", world.time());
            assert!(j.substeps().iter().all(|s| !s.onset));
            // The contact's impulse over the step: summed over the sub-steps, or the explicit
            // force held over it.
            let impulse = j
                .step_impulse()
                .unwrap_or(j.report().force.on_journal * h)
                .length();
            worst_impulse = worst_impulse.max((impulse / (MASS * G * h) - 1.0).abs());
            worst_energy = worst_energy.max((energy(&world) - before).abs());
            steps += 1;
        }
        println!(
            "{integration:?} to {end} s: {steps} steps, impulse off the weight's by at most \
             {worst_impulse:.2e}, energy by at most {worst_energy:.2e} J"
        );
        assert!(worst_impulse < 1e-9, "{worst_impulse:e}");
        assert!(worst_energy < 1e-15, "{worst_energy:e} J");
    }
    assert!(world.guards().is_clean(), "{:?}", world.guards());
}

/// A journal bouncing elastically (Hertz, no damping, no friction) under gravity in a bearing,
/// sub-cycled in steps of 1/60 s and of 1 ms: every bounce comes back to the bearing's centre,
/// the drop's height, and strikes at `sqrt(2 g c)` (each approach within 2 % of it over 3 s and
/// some 200 bounces), wherever the world's steps fall in the bounces.
#[test]
fn an_elastic_bounce_under_gravity_keeps_its_height_at_any_step() {
    let speed = (2.0 * G * C).sqrt();
    for dt in [1.0 / 60.0, 1e-3] {
        let control = StepControl {
            tolerance: 0.0075,
            ..StepControl::fixed(dt)
        };
        let (mut world, base, journal) = journal_world(control, 1);
        let pin = sub_cycled_hertz_pin(1e10);
        let pin = world.insert_clearance(base, journal, pin).unwrap();
        let mut approaches = Vec::new();
        while world.time() < 3.0 {
            world.step(3.0).unwrap();
            let inside = world.clearance.get(pin).unwrap().substeps();
            approaches.extend(inside.iter().filter(|s| s.onset).map(|s| s.approach_speed));
        }
        let worst = approaches
            .iter()
            .map(|v| (v / speed - 1.0).abs())
            .fold(0.0, f64::max);
        println!(
            "dt {dt:.3e} s: {} bounces, approach speeds {:.5e} to {:.5e} m/s against {speed:.5e}",
            approaches.len(),
            approaches.iter().copied().fold(f64::INFINITY, f64::min),
            approaches.iter().copied().fold(0.0, f64::max),
        );
        assert!(approaches.len() > 150, "{} bounces", approaches.len());
        assert!(worst < 0.02, "an approach {worst:.3e} off sqrt(2 g c)");
    }
}

/// In contact the world steps through the contact in a few steps of its own: a journal resting
/// on its wall (Hertz, no damping, no friction), whose path bounds no step, asks for `20 tol`
/// of its contact's natural period, `2 pi sqrt(m/k)` with `k = 1.5 K delta^0.5` the Hertz
/// law's stiffness at its depth (closed form; the 2 kg journal's normal passes through its
/// centre of mass), within 1 %, at the default tolerance and at half of it. A world step that
/// spans a contact integrates it under the mechanism's state at the step's start (the rest of
/// the world's acceleration and the pair's mobility held): on the deployable array's chattering
/// root hinge every window statistic left its converged range.
#[test]
fn a_resting_sub_cycled_journal_bounds_the_world_step_by_its_contact_period() {
    let k_hertz = 1e10;
    let static_depth = (MASS * G / k_hertz).powf(1.0 / 1.5);
    for tol in [0.0075, 0.00375] {
        let control = StepControl::adaptive(1e-3, tol);
        let (mut world, base, journal) = journal_world(control, 1);
        let pin = sub_cycled_hertz_pin(k_hertz);
        let at_rest = Vector::new(0.0, -(C + static_depth), 0.0);
        world.rapier.bodies[journal].set_translation(at_rest, true);
        let pin = world.insert_clearance(base, journal, pin).unwrap();
        world.step_to(0.01).unwrap();
        let joint = world.clearance.get(pin).unwrap();
        let depth = joint.report().state.penetration;
        let stiffness = 1.5 * k_hertz * depth.sqrt();
        let period = std::f64::consts::TAU * (MASS / stiffness).sqrt();
        let step = joint.adaptive_step(tol, world.last_dt());
        println!(
            "tol {tol}: depth {:.4} um (static {:.4}), step {step:.4e} s, 20 tol of the period \
             {:.4e} s",
            depth * 1e6,
            static_depth * 1e6,
            20.0 * tol * period
        );
        assert!((depth / static_depth - 1.0).abs() < 0.01);
        assert!(
            (step / (20.0 * tol * period) - 1.0).abs() < 0.01,
            "{step:e}"
        );
    }
}

/// A pin whose bearing turns on one of Rapier's revolutes (an arm spun about a fixed pivot by a
/// torque, a second arm dragged through a sub-cycled pin at its tip; one solver iteration, 1 ms
/// steps, no gravity): at each step's end the bodies stand where the sub-cycle put them, the
/// penetration the joint reports from its last sub-step and the one at Rapier's poses agreeing
/// within 1 % of the depth (and 1 nm). Rapier corrects its revolute's drift at the position
/// level after each step, moving the bearing beyond its velocity; the sub-cycle moves it by as
/// much (left out, the wall is found 8 % off at each step's start on the SCARA arm's elbow).
#[test]
fn a_pin_on_a_turning_arm_ends_each_step_where_its_sub_cycle_put_it() {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::ZERO;
    rapier.integration_parameters.num_solver_iterations = 1;
    let mut world = ClearanceWorld::new(rapier, StepControl::fixed(1e-3));
    let base = world.rapier.bodies.insert(RigidBodyBuilder::fixed());
    let upper = link(&mut world, 2.0, 0.4, 0.0, 1.0);
    let lower = link(&mut world, 1.0, 0.3, 0.4, 1.0);
    let pivot = RevoluteJointBuilder::new(Vector::Z).local_anchor2(Vector::new(-0.2, 0.0, 0.0));
    world.rapier.impulse_joints.insert(base, upper, pivot, true);
    let pin = HingeDesign::steel_improved_liu(0.006, 0.1e-3, 0.012)
        .unwrap()
        .integration(ContactIntegration::SubCycled)
        .joint(
            Vector::new(0.2, 0.0, 0.0),
            Vector::new(-0.15, 0.0, 0.0),
            Vector::Z,
            Vector::Z,
        )
        .unwrap();
    let pin = world.insert_clearance(upper, lower, pin).unwrap();
    world.rapier.bodies[upper].add_torque(Vector::new(0.0, 0.0, 2.0), true);
    let (mut compared, mut worst) = (0, 0.0f64);
    while world.time() < 0.3 {
        world.step(0.3).unwrap();
        let (reported, posed) = penetrations(&world, [upper, lower], pin);
        if reported > 0.0 || posed > 0.0 {
            compared += 1;
            let off = (posed - reported).abs() / reported.abs().max(posed.abs()).max(1e-7);
            worst = worst.max(off);
            assert!(
                (posed - reported).abs() <= 1e-9 + 0.01 * reported.abs().max(posed.abs()),
                "t = {:.4} s: penetration at Rapier's poses {posed:.6e} m, at the sub-cycle's \
                 end {reported:.6e} m",
                world.time()
            );
        }
    }
    println!("{compared} steps in contact compared; worst relative difference {worst:.3e}");
    assert!(compared > 100, "{compared}");
}

/// An arm on a sub-cycled pin in a fixed bearing, a second arm hung on it through one of
/// Rapier's revolutes (the SCARA arm's shoulder, its elbow ideal), driven by a constant torque
/// and braked by dampers that read Rapier's velocities before each step and hold their torques
/// over it (as the SCARA arm's PD controller does, with its damping gains), without gravity,
/// friction or contact damping (Hertz), in 1 ms steps with one, two and four solver
/// iterations. The pin, pressed outwards as the arm spins up, rattles on its wall. The arms'
/// energy, read from the bodies alone (kinetic at Rapier's velocities plus the Hertz potential
/// at Rapier's poses), never exceeds the start's plus the torques' work (each held torque times
/// its body's turn over the step) by more than 2 % of the largest energy: the frictionless,
/// undamped contact does no work. The sub-cycle's impulse reaches Rapier's velocities through
/// its substeps; a delivery whose part held between the steps changes sign at every step feeds
/// the dampers a velocity that alternates, and they pump the impacts up (with four iterations
/// the energy had gained 7.1 % of the largest, with two 0.3 %).
#[test]
fn a_damped_arm_rattling_on_a_fixed_pin_with_a_second_arm_gains_no_energy() {
    use clearance_joint::model::laws::{BearingGeometry, Hertz, NormalModel};
    use rapier3d_f64::utils::AngularInertiaOps;
    let (k_hertz, clearance) = (1e10, 0.1e-3);
    // Drive torque, N m, and the dampers' rates, N m s: the SCARA controller's damping gains.
    let (tau, damping) = (2.0, [19.8, 1.54]);
    for iterations in [1, 2, 4] {
        let mut rapier = PhysicsWorld::new();
        rapier.gravity = Vector::ZERO;
        rapier.integration_parameters.num_solver_iterations = iterations;
        let mut world = ClearanceWorld::new(rapier, StepControl::fixed(1e-3));
        let base = world.rapier.bodies.insert(RigidBodyBuilder::fixed());
        // Slender links (the SCARA arm's): a thousandth of the transverse inertia about their
        // length; drifting at `drift`, so that the pin starts rattling.
        let drift = Vector::new(0.003, 0.004, 0.0);
        let link = |world: &mut ClearanceWorld, mass: f64, length: f64, start: f64| {
            let j = mass * length * length / 12.0;
            world.rapier.bodies.insert(
                RigidBodyBuilder::dynamic()
                    .translation(Vector::new(start + 0.5 * length, 0.0, 0.0))
                    .linvel(drift)
                    .additional_mass_properties(MassProperties::new(
                        Vector::ZERO,
                        mass,
                        Vector::new(1e-3 * j, j, j),
                    ))
                    .can_sleep(false),
            )
        };
        let upper = link(&mut world, 2.0, 0.4, 0.0);
        let lower = link(&mut world, 1.0, 0.3, 0.4);
        let elbow = RevoluteJointBuilder::new(Vector::Z)
            .local_anchor1(Vector::new(0.2, 0.0, 0.0))
            .local_anchor2(Vector::new(-0.15, 0.0, 0.0))
            .contacts_enabled(false);
        world
            .rapier
            .impulse_joints
            .insert(upper, lower, elbow, true);
        let hertz = NormalModel::Hertz(Hertz::new(k_hertz, 1.5).unwrap());
        let geometry = BearingGeometry::new(0.006, 0.006 - clearance, 0.012).unwrap();
        let pin = HingeDesign::new(geometry, hertz)
            .integration(ContactIntegration::SubCycled)
            .joint(
                Vector::ZERO,
                Vector::new(-0.2, 0.0, 0.0),
                Vector::Z,
                Vector::Z,
            )
            .unwrap();
        let pin = world.insert_clearance(base, upper, pin).unwrap();
        let energy = |world: &ClearanceWorld| {
            let bodies = &world.rapier.bodies;
            let kinetic: f64 = [upper, lower]
                .iter()
                .map(|&h| {
                    let b = &bodies[h];
                    let w = b.angvel();
                    let i = b.mass_properties().effective_world_inv_inertia.inverse();
                    0.5 * b.mass() * b.linvel().length_squared() + 0.5 * w.dot(i * w)
                })
                .sum();
            let j = world.clearance.get(pin).unwrap();
            let (b1, b2) = (&bodies[base], &bodies[upper]);
            let d = *b2.position() * j.local_anchor2() - *b1.position() * j.local_anchor1();
            let axis = *b1.rotation() * j.local_axis1();
            let depth = ((d - d.dot(axis) * axis).length() - clearance).max(0.0);
            kinetic + k_hertz * depth.powf(2.5) / 2.5
        };
        // Rapier fills the bodies' masses at its first step: the energy from there on.
        world.step(1.0).unwrap();
        let start = energy(&world);
        let (mut work, mut worst, mut onsets, mut scale) = (0.0, 0.0f64, 0, start);
        while world.time() < 0.3 {
            let bodies = &mut world.rapier.bodies;
            let (w_u, w_l) = (bodies[upper].angvel().z, bodies[lower].angvel().z);
            let elbow_brake = -damping[1] * (w_l - w_u);
            let on_upper = tau - damping[0] * w_u - elbow_brake;
            for (body, torque) in [(upper, on_upper), (lower, elbow_brake)] {
                bodies[body].reset_torques(false);
                bodies[body].add_torque(Vector::new(0.0, 0.0, torque), true);
            }
            let before = [upper, lower].map(|b| *bodies[b].rotation());
            world.step(1.0).unwrap();
            let bodies = &world.rapier.bodies;
            // Each torque, held over the step, works by itself times its body's turn.
            for ((body, torque), before) in
                [(upper, on_upper), (lower, elbow_brake)].iter().zip(before)
            {
                work += torque
                    * (*bodies[*body].rotation() * before.inverse())
                        .to_scaled_axis()
                        .z;
            }
            scale = scale.max(energy(&world));
            let j = world.clearance.get(pin).unwrap();
            onsets += j.substeps().iter().filter(|s| s.onset).count();
            worst = worst.max(energy(&world) - start - work);
        }
        println!(
            "{iterations} iteration(s): {onsets} onsets, torques' work {work:.4e} J, energy at \
             the end {:.4e} J, largest {scale:.4e} J; largest gain beyond the start's and the \
             work {:+.3e} of the largest",
            energy(&world),
            worst / scale
        );
        assert_rattled_without_gain(onsets, worst, 0.02 * scale, &world);
    }
}

/// The deployable array (`assets/deployable_array.ron`: a yoke and three panels unfolding on
/// four planar clearance hinges in a chain, free-floating, no gravity) sub-cycled at the
/// adaptive defaults over its first impacts (0.3 s, 139 onsets). Its hinges share bodies (the
/// yoke is the root's journal and the next hinge's bearing) and are integrated in one
/// sub-cycle: each hinge's held impulse moves the shared body once, and the readers that add
/// the hinges' `start_velocity_correction` per body read it once. The runner's invariants at
/// every state: momentum drifts below 1e-12 of its scale, and the energy balance grows by less
/// than the ideal twin's own integration error (1.5e-4 of the energy's scale; 3.9e-6 here,
/// 1.4e-2 with the shared yoke's correction counted by both its hinges).
#[test]
fn a_sub_cycled_chain_sharing_its_bodies_keeps_momentum_and_energy() {
    use clearance_joint::scene::Scene;
    use clearance_joint::scene::runner::{RunOptions, Simulation, Twins};
    let scene = Scene::load(std::path::Path::new("assets/deployable_array.ron"))
        .unwrap()
        .with_overrides(&[
            "run.step=Adaptive",
            "run.tolerance=0.0075",
            "run.max_dt_s=0.001",
            "run.contact_integration=SubCycled",
            "run.end_s=0.3",
        ])
        .unwrap();
    let options = RunOptions {
        twins: Twins::ClearanceOnly,
        skip_rows: true,
    };
    let r = Simulation::new(&scene, options).unwrap().run().unwrap();
    let s = &r.summary().twins["clearance"];
    let inv = &s.invariants;
    println!(
        "{} onsets; momentum drift {:?}/{:?}, energy growth {:?}, error {:?}",
        s.onsets,
        inv.linear_momentum_drift,
        inv.angular_momentum_drift,
        inv.energy_growth,
        inv.energy_error
    );
    assert!(s.onsets > 50, "{}", s.onsets);
    assert!(inv.linear_momentum_drift.unwrap() < 1e-12);
    assert!(inv.angular_momentum_drift.unwrap() < 1e-12);
    assert!(inv.energy_growth.unwrap() < 1.5e-4);
}

/// An arm on one of Rapier's revolutes, spun up by a constant torque, with a second arm hung on
/// it by a sub-cycled pin (steel's Hertz stiffness, no damping, no friction, clearance 0.1 mm),
/// without gravity, at a game's 1/60 s with Rapier's four iterations and at 1 ms with one: the
/// SCARA arm's elbow. The pin is pressed outwards as the arm turns and rattles on its wall,
/// several impacts inside each 1/60 s step. The frictionless, undamped contact does no work:
/// the arms' energy at each state (kinetic at the bodies' velocities there, the Verlet reading
/// of Rapier's plus what the pin holds, and the Hertz potential at the pin's depth there) never
/// exceeds the first state's plus the torque's work (the torque times the arm's turn) by more
/// than 3 % of the largest energy (2.0 % at 1/60 s, 5e-8 at 1 ms). The arm turns under the pin
/// while the contact moves it; each sub-cycle goes on from where the last one left the pin (its
/// eccentricity and rate), whatever Rapier's pass 1 made of the step's wrench. Started from
/// Rapier's state instead, the arms leave the physical range within a second.
#[test]
fn an_undamped_pin_on_a_turning_arm_gains_no_energy_at_game_steps() {
    use clearance_joint::model::laws::{Hertz, NormalModel};
    use rapier3d_f64::utils::AngularInertiaOps;
    // The shared arm's pin: 0.1 mm of clearance, turned by 2 N m.
    let (k_hertz, tau) = (1e10, 2.0);
    for (dt, iterations) in [(1.0 / 60.0, 4), (1e-3, 1)] {
        let hertz = NormalModel::Hertz(Hertz::new(k_hertz, 1.5).unwrap());
        let (mut world, [upper, lower], pin) =
            turning_arm(hertz, dt, iterations, SubCycleTechniques::default(), false);
        // The bodies' velocities at a state: the Verlet reading of Rapier's velocities around
        // it (the mean of the steps' before and after it, at fixed steps) plus what the pin's
        // sub-cycle still holds there (`start_velocity_correction`).
        let velocities = |world: &ClearanceWorld| {
            [upper, lower].map(|h| {
                let b = &world.rapier.bodies[h];
                (b.linvel(), b.angvel())
            })
        };
        let energy_at = |world: &ClearanceWorld, before: [(Vector, Vector); 2], depth: f64| {
            let j = world.clearance.get(pin).unwrap();
            let correction = j.start_velocity_correction();
            let now = velocities(world);
            let mut kinetic = 0.0;
            for k in 0..2 {
                let b = &world.rapier.bodies[[upper, lower][k]];
                let (_, dv, dw) = correction[k];
                let v = 0.5 * (before[k].0 + now[k].0) + dv;
                let w = 0.5 * (before[k].1 + now[k].1) + dw;
                let i = b.mass_properties().effective_world_inv_inertia.inverse();
                kinetic += 0.5 * b.mass() * v.length_squared() + 0.5 * w.dot(i * w);
            }
            kinetic + k_hertz * depth.max(0.0).powf(2.5) / 2.5
        };
        // Rapier fills the bodies' masses at its first step: the energy from the state after it.
        world.step(1.0).unwrap();
        let (mut work, mut worst, mut scale, mut onsets) = (0.0, 0.0f64, 0.0f64, 0);
        let mut start = None;
        while world.time() < 1.0 {
            let before = velocities(&world);
            let depth = world.clearance.get(pin).unwrap().report().state.penetration;
            let turned = *world.rapier.bodies[upper].rotation();
            world.step(1.0).unwrap();
            // The state at the step's start.
            let e = energy_at(&world, before, depth);
            let start = *start.get_or_insert(e);
            scale = scale.max(e);
            worst = worst.max(e - start - work);
            // The torque, held over the step, works by itself times the arm's turn.
            let turn = *world.rapier.bodies[upper].rotation() * turned.inverse();
            work += tau * turn.to_scaled_axis().z;
            let j = world.clearance.get(pin).unwrap();
            onsets += j.substeps().iter().filter(|s| s.onset).count();
        }
        println!(
            "dt {dt:.4e} s, {iterations} iteration(s): {onsets} onsets, torque's work {work:.4e} \
             J, largest energy {scale:.4e} J; largest gain beyond the start's and the work \
             {:+.3e} of the largest",
            worst / scale
        );
        assert_rattled_without_gain(onsets, worst, 0.03 * scale, &world);
    }
}

/// The paper's scene sub-cycled: a free-floating satellite and its panel, the satellite turning
/// at about 1.4e-4 rad/s by the first impact. Its first impact's deepest penetration against the
/// scipy RK45 model written from the published laws (`benches/reference/solar_panel_rk45.py`,
/// rtol 1e-8: 1.4948 um), at the default tolerance and at world steps of 1e-6 s, where the
/// satellite turns some 1e-10 rad per step: a turn below 2e-8 rad read as none moved the
/// bearing by the satellite's whole turn (1.5613 um at 1e-6 s). The default's sub-steps (`2 tol`
/// of the contact's period) read the deepest point within `1 - cos(2 pi tol)` = 1.1e-3 of it.
#[test]
fn the_paper_scenes_first_impact_goes_as_deep_as_its_ode_at_any_world_step() {
    use clearance_joint::scene::runner::{RunOptions, Simulation};
    use clearance_joint::scene::{Scene, StepMode};
    const REFERENCE_UM: f64 = 1.4948;
    for (fixed, bound) in [(None, 1.2e-3), (Some(1e-6), 2e-4)] {
        let mut scene = Scene::solar_panel();
        scene.run.end_s = 0.1;
        scene.run.contact_integration = ContactIntegration::SubCycled;
        if let Some(dt) = fixed {
            scene.run.step = StepMode::Fixed;
            scene.run.dt_s = dt;
        }
        let options = RunOptions {
            skip_rows: true,
            ..Default::default()
        };
        let result = Simulation::new(&scene, options).unwrap().run().unwrap();
        let metrics = result.twins[1].hinge_metrics();
        let depth_um = metrics["hinge"].max_penetration_um;
        let error = depth_um / REFERENCE_UM - 1.0;
        println!("world steps {fixed:?}: deepest {depth_um:.5} um ({error:+.2e})");
        assert!(error.abs() < bound, "world steps {fixed:?}: {depth_um} um");
    }
}

/// What [`bounce`] saw: the bounces, the free step ends after the first, and the worst energy
/// error there of `g c`, from the velocity at the state and from Rapier's.
struct Bounces {
    bounces: usize,
    free_ends: usize,
    state_worst: f64,
    rapier_worst: f64,
    /// The time and the journal's velocity at the state (linear, angular) at the first free
    /// step end after the first bounce.
    first: Option<(f64, Vector, Vector)>,
}

/// A journal dropped from the centre of its bearing (Hertz, no damping, no friction) bouncing
/// for 0.1 s at world steps of 1 ms with Rapier's four iterations, sub-cycled at `tolerance`
/// ([`bounce_with`]).
fn bounce(tolerance: f64) -> Bounces {
    let control = StepControl {
        tolerance,
        ..StepControl::fixed(1e-3)
    };
    bounce_with(control, 4, sub_cycled_hertz_pin(1e10))
}

/// The journal of [`bounce`] on `pin`, stepped by `control` with `iterations` solver
/// iterations: its energy `v^2/2 + g e_y` (0 in closed form) at every free step end after the
/// first bounce, from the velocity at the state (a sub-cycled joint's, Rapier's for an explicit
/// one) and from Rapier's. The guards stay clean.
fn bounce_with(control: StepControl, iterations: usize, pin: ClearanceJoint) -> Bounces {
    let (mut world, base, journal) = journal_world(control, iterations);
    let pin = world.insert_clearance(base, journal, pin).unwrap();
    let (mut state_worst, mut rapier_worst, mut free_ends, mut bounces) = (0.0f64, 0.0f64, 0, 0);
    let mut first = None;
    while world.time() < 0.1 {
        world.step(0.1).unwrap();
        let joint = world.clearance.get(pin).unwrap();
        // A sub-cycled step's onsets are its sub-steps'; an explicit step's, its report's.
        bounces += match joint.substeps() {
            [] => usize::from(joint.report().onset),
            steps => steps.iter().filter(|s| s.onset).count(),
        };
        let st = joint.report().state;
        if bounces == 0 || st.penetration > 0.0 {
            continue;
        }
        free_ends += 1;
        let (v, spin) = world.velocity_at_state(journal).unwrap();
        if let Some([_, (body, _, w)]) = joint.state_velocity() {
            assert_eq!((body, spin), (journal, w));
        }
        first.get_or_insert((world.time(), v, spin));
        let rapier = world.rapier.bodies[journal].linvel();
        // The journal's height in its bearing: a spatial joint's at the bearing's mid-plane (its
        // report's state is its deepest region's, which may be a face's).
        let e_y = match joint.report().spatial {
            None => st.eccentricity.y,
            Some(_) => {
                let b = &world.rapier.bodies;
                let pose = joint.spatial_pose(&b[base], &b[journal], Vector::X);
                pose.mid_plane_eccentricity().y
            }
        };
        let energy = |v: Vector| (0.5 * v.length_squared() + G * e_y).abs() / (G * C);
        state_worst = state_worst.max(energy(v));
        rapier_worst = rapier_worst.max(energy(rapier));
    }
    assert!(world.guards().is_clean(), "{:?}", world.guards());
    Bounces {
        bounces,
        free_ends,
        state_worst,
        rapier_worst,
        first,
    }
}

/// A sub-cycled step's whole impulse is in the velocity at the state, not in Rapier's: a
/// journal dropped from the centre of its bearing (Hertz, no damping, no friction) bounces at
/// world steps of 1 ms with Rapier's four iterations, each bounce inside one step. Between the
/// bounces its energy holds (closed form): out of contact at a step's end,
/// `v^2/2 + g e_y = 0` at the eccentricity `e_y`. With the joint's
/// [`ClearanceJoint::state_velocity`] and [`ClearanceWorld::velocity_at_state`] it holds
/// within 2 % of `g c` (the wall's) at every such step, while Rapier's velocities, the mean
/// over the step without the part of the impulse delivered with the next step, miss it by
/// more than a tenth after a bounce (what a controller's damping reading them feeds on).
#[test]
fn a_bounce_inside_a_step_is_whole_in_the_velocity_at_the_state() {
    let Bounces {
        bounces,
        free_ends,
        state_worst,
        rapier_worst,
        ..
    } = bounce(0.0075);
    println!(
        "{bounces} bounces, {free_ends} free step ends: energy off by at most {state_worst:.2e} \
         (the state's velocity) and {rapier_worst:.2e} (Rapier's) of g c"
    );
    assert!(
        bounces >= 5 && free_ends > 40,
        "{bounces} bounces, {free_ends} ends"
    );
    assert!(state_worst < 0.02, "{state_worst:.3e}");
    assert!(rapier_worst > 0.1, "{rapier_worst:.3e}");
}

/// The rows inside a sub-cycled step read its sub-steps: the paper's first impact (0.44 ms)
/// inside 1 ms world steps, rows every 10 us. Against the explicit joint at fixed 1 us steps
/// (a converged run whose rows interpolate states 1 us apart), the rows' hinge force,
/// penetration, eccentricity and the panel's acceleration over the impact agree within 1 % of
/// their peaks (measured 0.24 %, 0.08 %, 2e-6 mm and 0.23 %), and the rows' largest force
/// within 0.5 % of the peak the impact recorder took from the sub-steps (0.18 %: rows 10 us
/// apart). Interpolated between the world step's ends, the rows missed the impact whole (no
/// row in contact, the acceleration zero throughout). At the state after the impact's step the
/// rows' velocity and rate hold the impulse the joint still holds (1e-4 of the reference's).
#[test]
fn the_rows_inside_a_sub_cycled_step_follow_its_impact() {
    use clearance_joint::scene::runner::{RunOptions, Simulation, TwinKind};
    use clearance_joint::scene::{Scene, StepMode};
    let run = |integration, dt| {
        let mut scene = Scene::solar_panel();
        scene.run.end_s = 0.0885;
        scene.run.output_interval_s = 1e-5;
        scene.run.body_motion = true;
        scene.run.strict = false;
        scene.run.step = StepMode::Fixed;
        scene.run.dt_s = dt;
        scene.run.contact_integration = integration;
        Simulation::new(&scene, RunOptions::default())
            .unwrap()
            .run()
            .unwrap()
    };
    let sub = run(ContactIntegration::SubCycled, 1e-3);
    let reference = run(ContactIntegration::Explicit, 1e-6);
    // The twins: ideal first, then clearance.
    assert_eq!(sub.twins[1].kind, TwinKind::Clearance);
    let (a, b) = (&sub.twins[1].table, &reference.twins[1].table);
    let t = a.column("t_s").unwrap();
    assert_eq!(t, b.column("t_s").unwrap());
    // Over the impact (onset 87.51 ms, lift-off 87.95 ms) and around it.
    let window: Vec<usize> = (0..t.len())
        .filter(|&k| (0.0873..=0.0882).contains(&t[k]))
        .collect();
    for (column, bound) in [
        ("hinge_force_n", 0.01),
        ("hinge_penetration_um", 0.01),
        ("hinge_ecc_u_mm", 0.01),
        ("panel_ax_m_s2", 0.01),
    ] {
        let (x, y) = (a.column(column).unwrap(), b.column(column).unwrap());
        let peak = window.iter().map(|&k| y[k].abs()).fold(0.0, f64::max);
        let worst = window
            .iter()
            .map(|&k| (x[k] - y[k]).abs())
            .fold(0.0, f64::max);
        println!("{column}: rows off by at most {worst:.4e} (reference's peak {peak:.4e})");
        assert!(
            peak > 0.0 && worst < bound * peak,
            "{column}: {worst:.4e} of {peak:.4e}"
        );
    }
    let contact = |table: &clearance_joint::table::Table| {
        let c = table.column("hinge_contact").unwrap();
        window.iter().filter(|&&k| c[k] == 1.0).count()
    };
    let (ca, cb) = (contact(a), contact(b));
    assert!(
        cb > 40 && ca.abs_diff(cb) <= 1,
        "rows in contact {ca} vs {cb}"
    );
    // At the world state after the impact's step (88 ms) the rows read the bodies' velocities
    // at the state, the impulse the joint still holds included (Rapier's, the mean over the
    // step, read 1.51e-3 m/s and +0.99 deg/s there).
    let state = t.iter().position(|&x| (x - 0.088).abs() < 1e-9).unwrap();
    for (column, scale) in [("panel_vx_m_s", 5e-3), ("hinge_rate_deg_s", 0.5)] {
        let (x, y) = (
            a.column(column).unwrap()[state],
            b.column(column).unwrap()[state],
        );
        println!("{column} at 88 ms: {x:.5e} against {y:.5e}");
        assert!(
            (x - y).abs() < 0.02 * scale,
            "{column}: {x:.5e} against {y:.5e}"
        );
    }
    let force = a.column("hinge_force_n").unwrap();
    let rows_peak = force.iter().fold(0.0, |m: f64, f| m.max(*f));
    let recorded = sub.twins[1].hinge_metrics()["hinge"].peak_force_n;
    println!("largest force: rows {rows_peak:.3} N, recorder {recorded:.3} N");
    assert!(
        (rows_peak / recorded - 1.0).abs() < 5e-3,
        "{rows_peak} vs {recorded}"
    );
}

/// A loose tolerance does not coarsen an impact past its resolution: the journal of
/// [`a_bounce_inside_a_step_is_whole_in_the_velocity_at_the_state`] (Hertz, no damping, no
/// friction) bounces at world steps of 1 ms with Rapier's four iterations, at tolerances from
/// the default to 0.2. Its energy at the free step ends (`v^2/2 + g e_y`, the state's velocity)
/// stays within a tenth of `g c` at every one (8e-4 at the default, 0.08 from 0.05 on): a
/// contact's sub-step covers at most a tenth of its period whatever the tolerance. With
/// `MAX_CONTACT_TOLERANCE` raised to 1, sub-steps of `2 tol` of the period, two or three an
/// impact at 0.1 and 0.2, end the same bounces 0.58 and 2.8 times `g c` off.
#[test]
fn a_loose_tolerance_still_resolves_each_impact() {
    let mut worsts = Vec::new();
    for tolerance in [0.0075, 0.02, 0.05, 0.1, 0.2] {
        let Bounces {
            bounces,
            free_ends,
            state_worst: worst,
            ..
        } = bounce(tolerance);
        println!(
            "tolerance {tolerance}: {bounces} bounces, {free_ends} free step ends: energy off \
             by at most {worst:.2e} of g c"
        );
        assert!(
            bounces >= 5 && free_ends > 40,
            "{bounces} bounces, {free_ends} ends"
        );
        worsts.push((tolerance, worst));
    }
    // After every tolerance's line is printed.
    for (tolerance, worst) in worsts {
        assert!(worst < 0.1, "tolerance {tolerance}: {worst:.3e} of g c");
    }
}

/// The explicit joint resolves a contact to at most the same tolerance: the journal of
/// [`bounce`] with an explicit pin at adaptive steps (one iteration) keeps its energy at its
/// free step ends within a tenth of `g c` at tolerances up to 0.2 (Rapier's velocities, half a
/// step behind the state: 0.027 at the default, 0.052 from 0.05 on). Without the bound its
/// steps of `2 tol` of the period ended the bounces 0.25 (0.1) and 15 (0.2) times `g c` off.
#[test]
fn a_loose_tolerance_still_resolves_each_explicit_impact() {
    let mut worsts = Vec::new();
    for tolerance in [0.0075, 0.02, 0.05, 0.1, 0.2] {
        let pin = centred(hertz_design(1e10).integration(ContactIntegration::Explicit));
        let Bounces {
            bounces: onsets,
            free_ends,
            state_worst: worst,
            ..
        } = bounce_with(StepControl::adaptive(1e-3, tolerance), 1, pin);
        println!(
            "tolerance {tolerance}: {onsets} onsets, {free_ends} free step ends: energy off by at \
             most {worst:.2e} of g c"
        );
        assert!(
            onsets >= 5 && free_ends > 40,
            "{onsets} onsets, {free_ends} ends"
        );
        worsts.push((tolerance, worst));
    }
    for (tolerance, worst) in worsts {
        assert!(worst < 0.1, "tolerance {tolerance}: {worst:.3e} of g c");
    }
}

/// The planar limit of the velocity at the state: the journal of [`bounce`] on a spatial pin
/// (the same Hertz bore, no tilt: its loads are all in the bearing's plane; axial play 0.3 mm,
/// shoulders of 15 mm) bounces at the planar pin's world steps (1 ms, Rapier's four iterations),
/// the same bounces and free step ends, its energy at those from the velocity at the state
/// within 2 % of `g c` (measured 8.3e-3; 7.9e-5 at the tolerance 1e-3), Rapier's more than a
/// tenth off (2.1). At the first state after the first bounce (8 ms) the two pins' velocities at
/// the state are the explicit joint's at fixed 1 us steps (its Rapier velocity carried over the
/// half step to the state) within 2e-3 of the rebound speed at the default tolerance (measured
/// 3.1e-5 planar, 1.1e-3 spatial: each sub-cycle's error of the impact) and within 2e-4 at the
/// tolerance 1e-3 (measured 1.3e-9 and 1.8e-5), without spin.
#[test]
fn a_spatial_pin_without_tilt_has_the_planar_pins_velocity_at_the_state() {
    use clearance_joint::model::spatial::SpatialModel;
    let spatial_pin = || {
        centred(
            hertz_design(1e10)
                .integration(ContactIntegration::SubCycled)
                .model(ClearanceModel::Spatial(SpatialModel::steel(0.3e-3, 0.015))),
        )
    };
    // The reference: the explicit pin at fixed 1 us steps, read at 8 ms.
    let reference = {
        let pin = centred(hertz_design(1e10).integration(ContactIntegration::Explicit));
        let (mut world, base, journal) = journal_world(StepControl::fixed(1e-6), 1);
        world.insert_clearance(base, journal, pin).unwrap();
        while world.time() < 8e-3 - 1e-12 {
            world.step(8e-3).unwrap();
        }
        assert!(world.guards().is_clean(), "{:?}", world.guards());
        // Rapier's velocity after an explicit step is the mean over it: out of contact, the
        // state's is it carried by gravity over the half step.
        world.rapier.bodies[journal].linvel() - Vector::new(0.0, G * 0.5e-6, 0.0)
    };
    let speed = reference.length();
    let mut bad = Vec::new();
    for (tolerance, bound) in [(0.0075, 2e-3), (1e-3, 2e-4)] {
        let control = StepControl {
            tolerance,
            ..StepControl::fixed(1e-3)
        };
        let planar = bounce_with(control, 4, sub_cycled_hertz_pin(1e10));
        let spatial = bounce_with(control, 4, spatial_pin());
        for (name, b) in [("planar", &planar), ("spatial", &spatial)] {
            let (t, v, w) = b.first.expect("a free step end after a bounce");
            let off = (v - reference).length() / speed;
            println!(
                "tolerance {tolerance}, {name}: {} bounces, {} free step ends, energy off by at \
                 most {:.2e} (the state's velocity) and {:.2e} (Rapier's) of g c; at {t} s \
                 {:.7e} m/s against {:.7e} m/s ({off:.1e} of it), spin {:.1e} rad/s",
                b.bounces,
                b.free_ends,
                b.state_worst,
                b.rapier_worst,
                v.y,
                reference.y,
                w.length(),
            );
            assert!(
                (t - 8e-3).abs() < 1e-12,
                "{name}: the first free end at {t} s"
            );
            if off > bound || w.length() > 1e-9 {
                bad.push(format!(
                    "tolerance {tolerance}, {name}: {off:.2e} off, spin {w:?}"
                ));
            }
        }
        assert_eq!(
            (spatial.bounces, spatial.free_ends),
            (planar.bounces, planar.free_ends)
        );
        assert!(spatial.state_worst < 0.02, "{:.3e}", spatial.state_worst);
        assert!(spatial.rapier_worst > 0.1, "{:.3e}", spatial.rapier_worst);
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}
