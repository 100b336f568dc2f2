//! `ClearanceWorld`: the one world type. Its step runs every set's hooks (the large-step joints'
//! included, which a bare `world.step()` loop can forget), it steps to the bit the same whether a
//! set is filled through its methods or its public field, and it notices a compliant joint added
//! through that field, and a body moved or given a velocity by hand between steps.

use clearance_joint::model::laws::BearingGeometry;
use clearance_joint::prelude::*;
use clearance_joint::rapier::large_step::LargeStepJointBuilder;
use rapier3d_f64::prelude::*;

/// A 2 kg arm whose centre of mass hangs 0.3 m below a fixed base at the origin.
fn arm_world(iterations: usize) -> (PhysicsWorld, RigidBodyHandle, RigidBodyHandle) {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -9.81, 0.0);
    rapier.integration_parameters.num_solver_iterations = iterations;
    let base = rapier.bodies.insert(RigidBodyBuilder::fixed());
    let arm = rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.3, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02)))
            .can_sleep(false),
    );
    (rapier, base, arm)
}

/// The arm's compliant pin: steel, bearing radius 10 mm, clearance 0.2 mm, width 16 mm.
fn compliant_pin() -> ClearanceJoint {
    pin_of(HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016).unwrap())
}

/// The same pin with explicit contact, which needs one solver iteration.
fn explicit_pin() -> ClearanceJoint {
    pin_of(
        HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)
            .unwrap()
            .integration(ContactIntegration::Explicit),
    )
}

/// `design` between the base and the arm 0.3 m out.
fn pin_of(design: HingeDesign) -> ClearanceJoint {
    design
        .joint(
            Vector::ZERO,
            Vector::new(-0.3, 0.0, 0.0),
            Vector::Z,
            Vector::Z,
        )
        .unwrap()
}

fn large_step_pin() -> LargeStepJoint {
    let geometry = BearingGeometry::from_clearance(0.010, 1e-3, 0.016).unwrap();
    LargeStepJointBuilder::new(Vector::Z, geometry)
        .local_anchor2(Vector::new(-0.3, 0.0, 0.0))
        .restitution(0.3)
        .build()
        .unwrap()
}

/// The trap of a bare loop: the large-step joint's hooks forgotten. Inside the world's step they
/// cannot be: the journal stays in its bearing at 60 Hz with Rapier's 4 iterations, and the
/// report reads the weight the pin carries once the arm hangs still.
#[test]
fn large_step_hooks_run_inside_the_world_step() {
    let (rapier, base, arm) = arm_world(4);
    let mut world = ClearanceWorld::new(rapier, StepControl::fixed(1.0 / 60.0));
    let pin = world
        .insert_large_step(base, arm, large_step_pin())
        .unwrap();
    let mut worst: f64 = 0.0;
    while world.time() < 20.0 {
        world.step(20.0).unwrap();
        let r = world.large_step.get(pin).unwrap().report();
        worst = worst.max(r.eccentricity_ratio);
    }
    assert!(worst < 1.1, "the journal left its bearing: |e|/c = {worst}");
    let r = *world.large_step.get(pin).unwrap().report();
    // Swinging down from horizontal and damped by the bounces' restitution and Rapier's joint
    // damping, the arm ends hanging: the pin carries at least its weight, 2 kg x 9.81 m/s^2,
    // plus what its swing still adds.
    assert!(
        r.normal_force > 19.0,
        "the readout is zero or low: {}",
        r.normal_force
    );
    assert!(world.large_step.get(pin).unwrap().bounces() > 0);
    assert!(world.guards().is_clean(), "{:?}", world.guards());
}

/// A world whose joint set was filled apart and put in its public field before the first step
/// steps to the bit like one whose joint came through `insert_clearance`.
#[test]
fn a_set_filled_apart_steps_like_one_filled_through_the_world() {
    let control = StepControl::adaptive(1e-3, 0.0075);
    let (rapier, base, arm) = arm_world(1);
    let mut world = ClearanceWorld::new(rapier, control);
    world.insert_clearance(base, arm, compliant_pin()).unwrap();
    world.step_to(0.05).unwrap();

    let (mut rapier, base2, arm2) = arm_world(1);
    let mut joints = ClearanceJointSet::new();
    joints
        .insert(
            base2,
            arm2,
            compliant_pin(),
            &rapier.bodies,
            &mut rapier.impulse_joints,
        )
        .unwrap();
    let mut apart = ClearanceWorld::new(rapier, control);
    apart.clearance = joints;
    apart.step_to(0.05).unwrap();
    assert_eq!(world.steps(), apart.steps());
    let (a, b) = (&world.rapier.bodies[arm], &apart.rapier.bodies[arm2]);
    assert_eq!(a.translation(), b.translation());
    assert_eq!(a.linvel(), b.linvel());
    assert_eq!(a.angvel(), b.angvel());
}

/// A compliant joint inserted through the public field between steps gets its forces evaluated
/// before the next step (as through `insert_clearance`), and in a world the explicit compliant
/// model cannot step (4 solver iterations) it is refused at that step, naming the setting.
#[test]
fn a_joint_added_through_the_field_is_noticed() {
    let (rapier, base, arm) = arm_world(4);
    let mut world = ClearanceWorld::new(rapier, StepControl::fixed(1e-4));
    world.step(1e-4).unwrap();
    let w = &mut world;
    w.clearance
        .insert(
            base,
            arm,
            explicit_pin(),
            &w.rapier.bodies,
            &mut w.rapier.impulse_joints,
        )
        .unwrap();
    let e = world.step(2e-4).unwrap_err().to_string();
    assert!(e.contains("num_solver_iterations"), "{e}");
}

/// The arm on `pin` stepped to 0.02 s, then edited by `edit` between steps, told with `told`
/// (or not), then stepped to 0.05 s: the arm's final state and the steps taken.
fn edited_run(
    pin: ClearanceJoint,
    edit: fn(&mut RigidBody),
    told: Option<bool>,
) -> (Vector, Vector, Vector, u64) {
    let (rapier, base, arm) = arm_world(1);
    let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, 0.0075));
    world.insert_clearance(base, arm, pin).unwrap();
    world.step_to(0.02).unwrap();
    edit(&mut world.rapier.bodies[arm]);
    if let Some(restart_kick) = told {
        world.invalidate(restart_kick);
    }
    world.step_to(0.05).unwrap();
    let rb = &world.rapier.bodies[arm];
    (rb.translation(), rb.linvel(), rb.angvel(), world.steps())
}

/// A velocity set by hand between steps is noticed: the run is the one told with
/// `invalidate(true)`, to the bit, for the explicit and the sub-cycled joint, and so is the run
/// told only `invalidate(false)` (the edit asks for the kick's restart).
#[test]
fn a_velocity_set_by_hand_is_noticed() {
    let kick = |rb: &mut RigidBody| {
        let v = rb.linvel() + Vector::new(0.0, 0.05, 0.0);
        rb.set_linvel(v, true);
    };
    for pin in [compliant_pin, explicit_pin] {
        let told = edited_run(pin(), kick, Some(true));
        assert_eq!(edited_run(pin(), kick, None), told);
        assert_eq!(edited_run(pin(), kick, Some(false)), told);
    }
}

/// A body moved by hand between steps is noticed: the run is the one told with
/// `invalidate(false)`, to the bit; a velocity left as it was is no edit (the run with
/// `set_linvel` to the same velocity is the run without it).
#[test]
fn a_body_moved_by_hand_is_noticed() {
    let nudge = |rb: &mut RigidBody| {
        let p = rb.translation() + Vector::new(0.0, 2e-5, 0.0);
        rb.set_translation(p, true);
    };
    let same = |rb: &mut RigidBody| {
        let v = rb.linvel();
        rb.set_linvel(v, true);
    };
    let nothing = |_: &mut RigidBody| {};
    for pin in [compliant_pin, explicit_pin] {
        assert_eq!(
            edited_run(pin(), nudge, None),
            edited_run(pin(), nudge, Some(false))
        );
        assert_eq!(
            edited_run(pin(), same, None),
            edited_run(pin(), nothing, None)
        );
    }
}

/// The reaction solve knows the large-step joints through their constraint forces: a link hanging
/// from a large-step pin carries a second link on an ideal revolute, and the revolute's exact
/// reaction is the lower link's weight (a solve blind to the pin would let the upper link fall
/// freely and find no reaction).
#[test]
fn reactions_see_the_large_step_joints() {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -9.81, 0.0);
    let base = rapier.bodies.insert(RigidBodyBuilder::fixed());
    let link = |y: f64, m: f64| {
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.0, y, 0.0))
            .additional_mass_properties(MassProperties::new(Vector::ZERO, m, Vector::splat(0.01)))
            .can_sleep(false)
    };
    let upper = rapier.bodies.insert(link(-0.2, 1.0));
    let lower = rapier.bodies.insert(link(-0.6, 3.0));
    let elbow = RevoluteJointBuilder::new(Vector::Z)
        .local_anchor1(Vector::new(0.0, -0.2, 0.0))
        .local_anchor2(Vector::new(0.0, 0.2, 0.0))
        .contacts_enabled(false);
    let elbow = rapier.impulse_joints.insert(upper, lower, elbow, true);
    let mut world = ClearanceWorld::new(rapier, StepControl::fixed(1.0 / 60.0));
    let geometry = BearingGeometry::from_clearance(0.010, 1e-3, 0.016).unwrap();
    let pin = LargeStepJointBuilder::new(Vector::Z, geometry)
        .local_anchor2(Vector::new(0.0, 0.2, 0.0))
        .restitution(0.3)
        .build()
        .unwrap();
    world.insert_large_step(base, upper, pin).unwrap();
    world.step_to(5.0).unwrap();
    let joints = [IdealJoint::from_rapier(&world.rapier.impulse_joints, elbow).unwrap()];
    let mut solver = ReactionSolver::default();
    let f = world.solve_reactions(&mut solver, &joints).unwrap()[0];
    let weight = 3.0 * 9.81;
    assert!(
        (f.length() - weight).abs() < 0.02 * weight,
        "elbow reaction {f:?}, the lower link weighs {weight} N"
    );
}

/// `step_to` refuses a time it could never reach (no endless loop), naming the argument.
#[test]
fn step_to_refuses_an_unreachable_time() {
    let (rapier, _, _) = arm_world(1);
    let mut world = ClearanceWorld::new(rapier, StepControl::fixed(1e-3));
    for until in [f64::INFINITY, f64::NAN] {
        let e = world.step_to(until).unwrap_err().to_string();
        assert!(e.contains("`until`") && e.contains("finite"), "{e}");
    }
    assert_eq!(world.step_to(0.01).unwrap(), 10);
    assert_eq!(world.step_to(0.005).unwrap(), 0);
}

/// The handle of a body inserted into `r` and removed again: one the world no longer has.
fn removed_body(r: &mut PhysicsWorld) -> RigidBodyHandle {
    let gone = r.bodies.insert(RigidBodyBuilder::dynamic());
    remove_body(r, gone);
    gone
}

/// Removes `body` from `r` (with its Rapier joints).
fn remove_body(r: &mut PhysicsWorld, body: RigidBodyHandle) {
    r.bodies.remove(
        body,
        &mut r.islands,
        &mut r.colliders,
        &mut r.impulse_joints,
        &mut r.multibody_joints,
        &mut r.soft_bodies,
        true,
    );
}

/// A joint on a body the world does not have (removed, `RigidBodyHandle::invalid()`) or on one
/// body twice is refused at insertion, naming `body1` or `body2`, and nothing is added: the world
/// still steps. (Unchecked, Rapier panicked at the step on a removed body and tried to allocate
/// 34 GB for the invalid handle.)
#[test]
fn joints_on_missing_or_same_bodies_are_refused_naming_the_body() {
    let (rapier, base, arm) = arm_world(1);
    let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, 0.0075));
    let gone = removed_body(&mut world.rapier);
    let invalid = RigidBodyHandle::invalid();
    for (b1, b2, field, says) in [
        (base, gone, "body2", "not in the world"),
        (gone, arm, "body1", "not in the world"),
        (base, invalid, "body2", "not in the world"),
        (invalid, arm, "body1", "not in the world"),
        (arm, arm, "body2", "same body as body1"),
    ] {
        for e in [
            world.insert_clearance(b1, b2, compliant_pin()).unwrap_err(),
            world
                .insert_large_step(b1, b2, large_step_pin())
                .unwrap_err(),
        ] {
            let e = e.to_string();
            assert!(
                e.contains(&format!("`{field}`")) && e.contains(says),
                "{field}: {e}"
            );
        }
    }
    assert!(world.clearance.is_empty() && world.large_step.is_empty());
    assert_eq!(world.rapier.impulse_joints.len(), 0);
    world.step_to(0.01).unwrap();
}

/// Times the clock cannot reach are refused, naming `until`, and nothing moves: an infinite one,
/// and ones so large that a step of the control's largest size does not change the time there
/// (before, `step(f64::MAX)` and `step(1e307)` returned `Ok` after a 0 s step). A step to a
/// large time the clock can count is still taken.
#[test]
fn times_the_clock_cannot_reach_are_refused_naming_until() {
    let (rapier, base, arm) = arm_world(1);
    let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, 0.0075));
    world.insert_clearance(base, arm, compliant_pin()).unwrap();
    let start = world.rapier.bodies[arm].translation();
    for until in [f64::MAX, 1e307, 1e30, f64::INFINITY] {
        let e = world.step(until).unwrap_err().to_string();
        assert!(e.contains("`until`"), "step({until}): {e}");
        assert_eq!(world.time(), 0.0);
        assert_eq!(world.rapier.bodies[arm].translation(), start);
        let e = world.step_to(until).unwrap_err().to_string();
        assert!(e.contains("`until`"), "step_to({until}): {e}");
    }
    let info = world.step(1e6).unwrap();
    assert!(info.dt > 0.0 && world.time() > 0.0, "{info:?}");
}

/// `peek` takes a step of `dt` before the first step: one the step control would not take (not
/// finite, not positive, longer than its largest step) is refused naming `dt`; before, `peek(1e300)`
/// returned `Ok` with nothing moved.
#[test]
fn peek_refuses_a_step_the_control_would_not_take() {
    let (rapier, base, arm) = arm_world(1);
    let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, 0.0075));
    world.insert_clearance(base, arm, compliant_pin()).unwrap();
    for dt in [1e300, 1.0, f64::INFINITY, f64::NAN, 0.0, -1e-4] {
        let e = world.peek(dt, |_, _| ()).unwrap_err().to_string();
        assert!(e.contains("`dt`"), "peek({dt}): {e}");
        assert_eq!(world.time(), 0.0);
    }
    let moved = world
        .peek(1e-4, |w, info| (info.dt, w.bodies[arm].linvel().length()))
        .unwrap();
    assert!(moved.0 == 1e-4 && moved.1 > 0.0, "{moved:?}");
}

/// Gravity that takes a free body past the speed guard (half Rapier's `max_linear_velocity`)
/// within one of the control's largest steps is refused before the step, naming `gravity`;
/// before, 1e300 m/s^2 gave `Ok`, clean guards and a motionless arm.
#[test]
fn gravity_beyond_the_speed_guard_in_one_step_is_refused() {
    for g in [1e300, 1e10, 1e6, f64::INFINITY] {
        let (mut rapier, base, arm) = arm_world(1);
        rapier.gravity = Vector::new(0.0, -g, 0.0);
        let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, 0.0075));
        world.insert_clearance(base, arm, compliant_pin()).unwrap();
        let e = world.step(0.01).unwrap_err().to_string();
        assert!(e.contains("`gravity`"), "gravity {g}: {e}");
        assert_eq!(world.time(), 0.0);
    }
    // 100 g is honoured.
    let (mut rapier, base, arm) = arm_world(1);
    rapier.gravity = Vector::new(0.0, -981.0, 0.0);
    let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, 0.0075));
    world.insert_clearance(base, arm, compliant_pin()).unwrap();
    world.step_to(0.01).unwrap();
}

/// The sets' own `insert` takes the body set: a joint on a removed body, on
/// `RigidBodyHandle::invalid()` or on a made-up handle with a huge index is refused there,
/// naming the body, and adds nothing to Rapier's joints (Rapier's insert sizes a table by the
/// body's index: 34 GB for the invalid handle). A joint whose body is removed afterwards is
/// refused at the step, before Rapier's step runs (which panicked on it).
#[test]
fn a_set_joint_on_a_missing_body_is_refused() {
    let made_up = RigidBodyHandle::from_raw_parts(1 << 30, 0);
    for large in [true, false] {
        for which in 0..3 {
            let (mut r, base, _) = arm_world(if large { 4 } else { 1 });
            let gone = [removed_body(&mut r), RigidBodyHandle::invalid(), made_up][which];
            let (mut joints, mut play) = (ClearanceJointSet::new(), LargeStepJointSet::new());
            let e = if large {
                play.insert(
                    base,
                    gone,
                    large_step_pin(),
                    &r.bodies,
                    &mut r.impulse_joints,
                )
                .map(|_| ())
            } else {
                joints
                    .insert(
                        base,
                        gone,
                        compliant_pin(),
                        &r.bodies,
                        &mut r.impulse_joints,
                    )
                    .map(|_| ())
            };
            let e = e.unwrap_err().to_string();
            assert!(
                e.contains("`body2`") && e.contains("not in the world"),
                "large {large}, case {which}: {e}"
            );
            assert!(joints.is_empty() && play.is_empty());
            assert_eq!(r.impulse_joints.len(), 0);
        }
        // Removed after insertion: refused at the step.
        let (mut r, base, _) = arm_world(if large { 4 } else { 1 });
        let later = r.bodies.insert(RigidBodyBuilder::dynamic());
        let (mut joints, mut play) = (ClearanceJointSet::new(), LargeStepJointSet::new());
        if large {
            play.insert(
                base,
                later,
                large_step_pin(),
                &r.bodies,
                &mut r.impulse_joints,
            )
            .unwrap();
        } else {
            joints
                .insert(
                    base,
                    later,
                    compliant_pin(),
                    &r.bodies,
                    &mut r.impulse_joints,
                )
                .unwrap();
        }
        remove_body(&mut r, later);
        let mut world = ClearanceWorld::new(r, StepControl::fixed(1e-4));
        (world.clearance, world.large_step) = (joints, play);
        let e = world.step(1e-3).unwrap_err().to_string();
        assert!(
            e.contains("`body2`") && e.contains("not in the world"),
            "large {large}, removed later: {e}"
        );
    }
}

/// A prescribed motion the world cannot honour is refused, naming its field: on a dynamic body
/// (Rapier moves only position-based kinematic bodies to a pose; unchecked, the arm swung under
/// gravity while its table said 1 rad), on a body the world does not have, or about a zero axis
/// (unchecked, a non-unit rotation). Refused at `insert_prescribed`, and at the step when the
/// motion is pushed into the public field; `PrescribedMotion::angle` normalises its axis.
#[test]
fn prescribed_motions_the_world_cannot_honour_are_refused() {
    use clearance_joint::rapier::sources::prescribed::{PrescribedMotion, PrescribedPath, Table};
    let table = || Table::new(&[0.0, 0.1], &[0.0, 1.0]).unwrap();
    // The arm world with a removed body and a position-based kinematic one (the same handles
    // every time it is built).
    let build = || {
        let (mut rapier, _, arm) = arm_world(1);
        let gone = removed_body(&mut rapier);
        let kinematic = rapier
            .bodies
            .insert(RigidBodyBuilder::kinematic_position_based());
        let world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, 0.0075));
        (world, arm, gone, kinematic)
    };
    let (_, arm, gone, kinematic) = build();
    let motion = |body, axis| PrescribedMotion {
        body,
        start: Pose::IDENTITY,
        path: PrescribedPath::Angle { axis },
        table: table(),
    };
    let e = PrescribedMotion::angle(kinematic, Pose::IDENTITY, Vector::ZERO, table()).unwrap_err();
    assert!(e.to_string().contains("`axis`"), "{e}");
    let scaled = PrescribedMotion::angle(kinematic, Pose::IDENTITY, 3.0 * Vector::Z, table());
    assert_eq!(
        scaled.unwrap().path,
        PrescribedPath::Angle { axis: Vector::Z }
    );
    for (m, field, says) in [
        (motion(arm, Vector::Z), "motions[0].body", "Dynamic body"),
        (
            motion(gone, Vector::Z),
            "motions[0].body",
            "not in the world",
        ),
        (
            motion(kinematic, Vector::ZERO),
            "motions[0].path.axis",
            "unit vector",
        ),
        (
            motion(kinematic, 2.0 * Vector::Z),
            "motions[0].path.axis",
            "unit vector",
        ),
    ] {
        let mut world = build().0;
        let e = world.insert_prescribed(m.clone()).unwrap_err().to_string();
        assert!(e.contains(&format!("`{field}`")) && e.contains(says), "{e}");
        assert!(world.prescribed.motions.is_empty());
        world.prescribed.motions.push(m);
        let e = world.step(0.01).unwrap_err().to_string();
        assert!(e.contains(&format!("`{field}`")) && e.contains(says), "{e}");
        assert_eq!(world.time(), 0.0);
    }
    // A good one turns its body as its table says.
    let mut world = build().0;
    let start = *world.rapier.bodies[kinematic].position();
    let m = PrescribedMotion::angle(kinematic, start, Vector::Z, table()).unwrap();
    assert_eq!(world.insert_prescribed(m).unwrap(), 0);
    world.step_to(0.1).unwrap();
    let turned = world.rapier.bodies[kinematic].rotation().to_scaled_axis();
    assert!((turned - Vector::Z).length() < 1e-9, "{turned:?}");
}

/// A spatial joint whose journal axis does not lie in its bore at the bodies' poses (90 deg off,
/// or tilted past what the clearance lets it) is refused at insertion naming `local_axis2`
/// (unchecked, it was accepted and failed later with other causes); one tilted inside its free
/// tilt is accepted.
#[test]
fn a_spatial_journal_out_of_its_bore_is_refused_naming_the_axis() {
    use clearance_joint::model::spatial::SpatialModel;
    // Free tilt 2c/L = 0.4 mm / 16 mm = 25 mrad.
    let spatial = |axis2: Vector| {
        HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)
            .unwrap()
            .model(ClearanceModel::Spatial(SpatialModel::steel(0.3e-3, 0.015)))
            .joint(Vector::ZERO, Vector::new(-0.3, 0.0, 0.0), Vector::Z, axis2)
            .unwrap()
    };
    let tilted = |rad: f64| Vector::new(rad.sin(), 0.0, rad.cos());
    for axis2 in [Vector::X, tilted(0.1)] {
        let (rapier, base, arm) = arm_world(1);
        let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, 0.0075));
        let e = world
            .insert_clearance(base, arm, spatial(axis2))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`local_axis2`") && e.contains("deg from the bore's"),
            "{e}"
        );
        assert!(world.clearance.is_empty());
    }
    let (rapier, base, arm) = arm_world(1);
    let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, 0.0075));
    world
        .insert_clearance(base, arm, spatial(tilted(0.02)))
        .unwrap();
    world.step_to(0.01).unwrap();
}

/// A floor `min_dt` raised above the world steps a sub-cycled contact asks for is the user's
/// choice, and the sub-cycle resolves the contact inside the floor's steps: the arm strikes and
/// rests on its pin for 0.3 s at steps of at least 1e-4 s, without a stall (the steps at the floor
/// are recorded, as the guards record any), its peak the one at the default floor within 2 %.
#[test]
fn a_raised_floor_is_stepped_by_the_sub_cycle() {
    let peak_at = |min_dt: f64| {
        let (rapier, base, arm) = arm_world(1);
        let mut control = StepControl::adaptive(1e-3, 0.0075);
        control.min_dt = min_dt;
        let mut world = ClearanceWorld::new(rapier, control);
        let pin = world.insert_clearance(base, arm, compliant_pin()).unwrap();
        let mut peak: f64 = 0.0;
        while world.time() < 0.3 {
            world.step(0.3).unwrap();
            let j = world.clearance.get(pin).unwrap();
            peak = j
                .substeps()
                .iter()
                .fold(peak, |p, s| p.max(s.force.normal_force));
        }
        let g = world.guards();
        assert!(min_dt > 1e-10 || g.is_clean(), "{g:?}");
        (peak, world.steps())
    };
    let (raised, steps) = peak_at(1e-4);
    let (floor, _) = peak_at(1e-10);
    assert!(
        steps <= 3001,
        "{steps} steps for 0.3 s at steps of at least 1e-4 s"
    );
    assert!(floor > 19.62, "no impact: {floor} N");
    assert!(
        (raised / floor - 1.0).abs() < 0.02,
        "peak {raised} N at the raised floor against {floor} N"
    );
}
