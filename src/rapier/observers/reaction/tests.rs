//! Tests of the reactions against hand-derived results.

use super::lu::{lu_factor, lu_solve};
use super::*;
use crate::rapier::pipeline::ledger::world_center_of_mass;
use rapier3d_f64::math::Rotation;
use rapier3d_f64::prelude::{
    ColliderBuilder, FixedJointBuilder, GenericJoint, GenericJointBuilder, ImpulseJointSet,
    JointAxesMask, JointAxis, MassProperties, MotorModel, PhysicsWorld, PrismaticJointBuilder,
    RevoluteJointBuilder, RigidBodyBuilder, SphericalJointBuilder,
};

#[test]
fn dense_solve_by_hand() {
    // 2x + y = 3, x + 3y = 5 -> x = 0.8, y = 1.4
    let mut a = vec![2.0, 1.0, 1.0, 3.0];
    let mut b = vec![3.0, 5.0];
    let (mut piv, mut scratch) = (Vec::new(), Vec::new());
    assert!(lu_factor(&mut a, &mut piv, 2, 1e-12));
    lu_solve(&a, &piv, &mut b, &mut scratch, 2);
    assert!((b[0] - 0.8).abs() < 1e-15 && (b[1] - 1.4).abs() < 1e-15);
    // With a row swap: y = 2, x + y = 3 -> x = 1.
    let mut a = vec![0.0, 1.0, 1.0, 1.0];
    let mut b = vec![2.0, 3.0];
    assert!(lu_factor(&mut a, &mut piv, 2, 1e-12));
    lu_solve(&a, &piv, &mut b, &mut scratch, 2);
    assert!((b[0] - 1.0).abs() < 1e-15 && (b[1] - 2.0).abs() < 1e-15);
    let mut a = vec![1.0, 2.0, 2.0, 4.0];
    assert!(!lu_factor(&mut a, &mut piv, 2, 1e-12));
}

#[test]
fn spinning_arm_needs_the_centripetal_force() {
    // Arm of 2 kg, COM 0.3 m from a fixed pivot, spinning at 5 rad/s about z, no gravity:
    // the pivot pulls with m w^2 r = 15 N towards itself; no angular acceleration.
    let mut bodies = RigidBodySet::new();
    let base = bodies.insert(RigidBodyBuilder::fixed());
    let arm = bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.3, 0.0, 0.0))
            .linvel(Vector::new(0.0, 1.5, 0.0))
            .angvel(Vector::new(0.0, 0.0, 5.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                2.0,
                Vector::new(0.01, 0.02, 0.03),
            )),
    );
    prepare_mass_properties(&mut bodies);
    let j = IdealRevolute {
        body1: base,
        body2: arm,
        local_anchor1: Vector::ZERO,
        local_anchor2: Vector::new(-0.3, 0.0, 0.0),
        local_axis1: Vector::Z,
    };
    let mut s = ReactionSolver::default();
    let f = s
        .solve(&bodies, &[IdealJoint(j.into())], Vector::ZERO)
        .unwrap()[0];
    assert!((f - Vector::new(-15.0, 0.0, 0.0)).length() < 1e-9, "{f:?}");
}

#[test]
fn torque_driven_arm_by_hand() {
    // Torque 1 N m about z on the arm at rest: I_pivot = 0.03 + 2 * 0.09 = 0.21,
    // alpha = 1/0.21, the pivot supplies m alpha r = 2 * 0.3/0.21 N along +y.
    let mut bodies = RigidBodySet::new();
    let base = bodies.insert(RigidBodyBuilder::fixed());
    let arm = bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.3, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                2.0,
                Vector::new(0.01, 0.02, 0.03),
            )),
    );
    prepare_mass_properties(&mut bodies);
    bodies[arm].add_torque(Vector::new(0.0, 0.0, 1.0), false);
    let j = IdealRevolute {
        body1: base,
        body2: arm,
        local_anchor1: Vector::ZERO,
        local_anchor2: Vector::new(-0.3, 0.0, 0.0),
        local_axis1: Vector::Z,
    };
    let mut s = ReactionSolver::default();
    let f = s
        .solve(&bodies, &[IdealJoint(j.into())], Vector::ZERO)
        .unwrap()[0];
    let expected = 2.0 * 0.3 / 0.21;
    assert!(
        (f - Vector::new(0.0, expected, 0.0)).length() < 1e-9,
        "{f:?}"
    );
}

fn slider(
    bodies: &mut RigidBodySet,
    at: Vector,
    linvel: Vector,
    angvel: Vector,
) -> RigidBodyHandle {
    bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(at)
            .linvel(linvel)
            .angvel(angvel)
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                2.0,
                Vector::new(0.01, 0.02, 0.03),
            )),
    )
}

#[test]
fn slider_on_a_fixed_guide_carries_its_weight_not_its_drive() {
    // 2 kg on a guide along x under gravity -y, pushed by 3 N along x: the guide supplies
    // m g = 19.62 N upwards and nothing along the slide.
    let mut bodies = RigidBodySet::new();
    let base = bodies.insert(RigidBodyBuilder::fixed());
    let s = slider(
        &mut bodies,
        Vector::new(0.4, 0.1, 0.0),
        Vector::new(1.0, 0.0, 0.0),
        Vector::ZERO,
    );
    prepare_mass_properties(&mut bodies);
    bodies[s].add_force(Vector::new(3.0, 0.0, 0.0), false);
    let j = IdealPrismatic {
        body1: base,
        body2: s,
        local_anchor1: Vector::new(0.0, 0.1, 0.0),
        local_anchor2: Vector::ZERO,
        local_axis1: Vector::X,
    };
    let mut solver = ReactionSolver::default();
    let f = solver
        .solve(
            &bodies,
            &[IdealJoint(j.into())],
            Vector::new(0.0, -9.81, 0.0),
        )
        .unwrap()[0];
    assert!((f - Vector::new(0.0, 19.62, 0.0)).length() < 1e-9, "{f:?}");
}

#[test]
fn slider_on_a_spinning_guide_needs_the_coriolis_force() {
    // A guide along its x axis turning at w = 3 rad/s about z (kinematic, at the origin);
    // the 2 kg slider at r = 0.5 m moves out at v = 0.2 m/s and turns with it. Along the
    // guide it is free; across it the guide supplies the Coriolis force 2 m w v = 2.4 N
    // (+y), no angular acceleration being needed.
    let (w, r, v) = (3.0, 0.5, 0.2);
    let mut bodies = RigidBodySet::new();
    let guide = bodies
        .insert(RigidBodyBuilder::kinematic_velocity_based().angvel(Vector::new(0.0, 0.0, w)));
    let s = slider(
        &mut bodies,
        Vector::new(r, 0.0, 0.0),
        Vector::new(v, w * r, 0.0),
        Vector::new(0.0, 0.0, w),
    );
    prepare_mass_properties(&mut bodies);
    let j = IdealPrismatic {
        body1: guide,
        body2: s,
        local_anchor1: Vector::ZERO,
        local_anchor2: Vector::ZERO,
        local_axis1: Vector::X,
    };
    let mut solver = ReactionSolver::default();
    let f = solver
        .solve(&bodies, &[IdealJoint(j.into())], Vector::ZERO)
        .unwrap()[0];
    assert!(
        (f - Vector::new(0.0, 2.0 * 2.0 * w * v, 0.0)).length() < 1e-9,
        "{f:?}"
    );
}

#[test]
fn welded_block_on_a_spinning_base() {
    // A 2 kg block welded 0.3 m from the axis of a base turning at 5 rad/s (kinematic):
    // the weld pulls with m w^2 r = 15 N towards the axis and holds its weight 19.62 N.
    let mut bodies = RigidBodySet::new();
    let base = bodies
        .insert(RigidBodyBuilder::kinematic_velocity_based().angvel(Vector::new(0.0, 0.0, 5.0)));
    let b = slider(
        &mut bodies,
        Vector::new(0.3, 0.0, 0.0),
        Vector::new(0.0, 1.5, 0.0),
        Vector::new(0.0, 0.0, 5.0),
    );
    prepare_mass_properties(&mut bodies);
    let j = IdealFixed {
        body1: base,
        body2: b,
        local_anchor1: Vector::new(0.3, 0.0, 0.0),
        local_anchor2: Vector::ZERO,
    };
    let mut solver = ReactionSolver::default();
    let f = solver
        .solve(
            &bodies,
            &[IdealJoint(j.into())],
            Vector::new(0.0, 0.0, -9.81),
        )
        .unwrap()[0];
    assert!(
        (f - Vector::new(-15.0, 0.0, 19.62)).length() < 1e-9,
        "{f:?}"
    );
}

#[test]
fn ball_joint_pendulum_swinging_through_the_bottom() {
    // A 2 kg point-like bob 0.5 m below a ball joint, passing the bottom at 1 m/s: the joint
    // pulls up with m g + m v^2/L = 19.62 + 4 = 23.62 N.
    let mut bodies = RigidBodySet::new();
    let base = bodies.insert(RigidBodyBuilder::fixed());
    let bob = slider(
        &mut bodies,
        Vector::new(0.0, -0.5, 0.0),
        Vector::new(1.0, 0.0, 0.0),
        Vector::new(0.0, 0.0, 2.0),
    );
    prepare_mass_properties(&mut bodies);
    let j = IdealSpherical {
        body1: base,
        body2: bob,
        local_anchor1: Vector::ZERO,
        local_anchor2: Vector::new(0.0, 0.5, 0.0),
    };
    let mut solver = ReactionSolver::default();
    let f = solver
        .solve(
            &bodies,
            &[IdealJoint(j.into())],
            Vector::new(0.0, -9.81, 0.0),
        )
        .unwrap()[0];
    // The bob's own spin (2 rad/s about z) is the pendulum's: no torque is needed at the ball.
    assert!((f - Vector::new(0.0, 23.62, 0.0)).length() < 1e-9, "{f:?}");
}

#[test]
fn motor_holding_an_arm_level_supplies_its_moment() {
    // A 2 kg arm, centre of mass 0.3 m out along x from a pivot on a fixed base, at rest
    // under gravity -y, held by a velocity motor at zero speed: the pivot carries the weight
    // (19.62 N up), and the motor's moment m g r = 5.886 N m is in the extra row.
    let mut bodies = RigidBodySet::new();
    let base = bodies.insert(RigidBodyBuilder::fixed());
    let arm = slider(
        &mut bodies,
        Vector::new(0.3, 0.0, 0.0),
        Vector::ZERO,
        Vector::ZERO,
    );
    prepare_mass_properties(&mut bodies);
    let j = IdealRevolute {
        body1: base,
        body2: arm,
        local_anchor1: Vector::ZERO,
        local_anchor2: Vector::new(-0.3, 0.0, 0.0),
        local_axis1: Vector::Z,
    };
    let mut solver = ReactionSolver::default();
    let g = Vector::new(0.0, -9.81, 0.0);
    let f = solver
        .solve(&bodies, &[IdealJoint(JointModel::MotorRevolute(j))], g)
        .unwrap()[0];
    assert!((f - Vector::new(0.0, 19.62, 0.0)).length() < 1e-9, "{f:?}");
    let tau = solver.motor(0).unwrap();
    assert!((tau - 2.0 * 9.81 * 0.3).abs() < 1e-9, "{tau}");
    // Without the motor the arm falls: the pivot carries less than the weight,
    // m g (1 - m r^2 / I_pivot) with I_pivot = 0.03 + 2 * 0.09 = 0.21.
    let f = solver.solve(&bodies, &[IdealJoint(j.into())], g).unwrap()[0];
    let expected = 19.62 * (1.0 - 2.0 * 0.09 / 0.21);
    assert!((f.y - expected).abs() < 1e-9, "{f:?} against {expected}");
}

#[test]
fn weld_on_an_accelerating_driven_base() {
    // A base turning up from rest with a prescribed 10 rad/s^2 about z; a 2 kg block welded
    // 0.3 m out along x: the weld pushes it along +y with m alpha r = 6 N.
    let mut bodies = RigidBodySet::new();
    let base = bodies.insert(RigidBodyBuilder::kinematic_position_based());
    let b = slider(
        &mut bodies,
        Vector::new(0.3, 0.0, 0.0),
        Vector::ZERO,
        Vector::ZERO,
    );
    prepare_mass_properties(&mut bodies);
    let j = IdealFixed {
        body1: base,
        body2: b,
        local_anchor1: Vector::new(0.3, 0.0, 0.0),
        local_anchor2: Vector::ZERO,
    };
    let mut solver = ReactionSolver::default();
    // Without the prescribed acceleration the base would be taken to move steadily.
    let f = solver
        .solve(&bodies, &[IdealJoint(j.into())], Vector::ZERO)
        .unwrap()[0];
    assert!(f.length() < 1e-12);
    solver.kinematic.push(KinematicState {
        body: base,
        linvel: Vector::ZERO,
        angvel: Vector::ZERO,
        linacc: Vector::ZERO,
        angacc: Vector::new(0.0, 0.0, 10.0),
    });
    let f = solver
        .solve(&bodies, &[IdealJoint(j.into())], Vector::ZERO)
        .unwrap()[0];
    assert!((f - Vector::new(0.0, 6.0, 0.0)).length() < 1e-9, "{f:?}");
}

/// The 2 kg arm of these tests on a fixed base: centre of mass `r` = 0.3 m out along its
/// own x axis, turned by `angle` about z, spinning at `w` about z (consistent velocities).
fn arm_at(angle: f64, w: f64) -> (RigidBodySet, IdealRevolute) {
    let mut bodies = RigidBodySet::new();
    let base = bodies.insert(RigidBodyBuilder::fixed());
    let rot = Rotation::from_rotation_z(angle);
    let com = rot * Vector::new(0.3, 0.0, 0.0);
    let arm = bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(com)
            .rotation(Vector::new(0.0, 0.0, angle))
            .linvel(Vector::new(0.0, 0.0, w).cross(com))
            .angvel(Vector::new(0.0, 0.0, w))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                2.0,
                Vector::new(0.01, 0.02, 0.03),
            )),
    );
    prepare_mass_properties(&mut bodies);
    let j = IdealRevolute {
        body1: base,
        body2: arm,
        local_anchor1: Vector::ZERO,
        local_anchor2: Vector::new(-0.3, 0.0, 0.0),
        local_axis1: Vector::Z,
    };
    (bodies, j)
}

#[test]
fn soft_revolute_motor_by_hand() {
    // Level arm turning at 1 rad/s under gravity -y; a force-based motor k = 10 N m/rad,
    // c = 2 N m s/rad towards 0.5 rad at rest: torque 10 * 0.5 + 2 * (0 - 1) = 3 N m.
    // alpha = (3 - m g r)/I_pivot, I_pivot = 0.03 + 2 * 0.09 = 0.21.
    let (bodies, j) = arm_at(0.0, 1.0);
    let g = Vector::new(0.0, -9.81, 0.0);
    let m = SoftMotor::force_based(0.5, 0.0, 10.0, 2.0);
    let mut solver = ReactionSolver::default();
    let f = solver
        .solve(
            &bodies,
            &[IdealJoint(JointModel::SoftMotorRevolute(j, m))],
            g,
        )
        .unwrap()[0];
    assert!((solver.motor(0).unwrap() - 3.0).abs() < 1e-12);
    let alpha = (3.0 - 2.0 * 9.81 * 0.3) / 0.21;
    let (a, al) = solver.acceleration(j.body2).unwrap();
    let expected_a = Vector::new(-0.3, alpha * 0.3, 0.0);
    assert!(
        (al - Vector::new(0.0, 0.0, alpha)).length() < 1e-9,
        "{al:?}"
    );
    assert!((a - expected_a).length() < 1e-9, "{a:?}");
    // The pivot supplies m a - m g.
    assert!((f - (2.0 * expected_a - 2.0 * g)).length() < 1e-9, "{f:?}");
    // Acceleration-based: the same law times the row's inertia, the arm's own 0.03 about z
    // (Rapier's motor row is not coupled to the joint's point constraints).
    let m = SoftMotor {
        model: MotorModel::AccelerationBased,
        ..m
    };
    solver.solve(
        &bodies,
        &[IdealJoint(JointModel::SoftMotorRevolute(j, m))],
        g,
    );
    assert!((solver.motor(0).unwrap() - 0.03 * 3.0).abs() < 1e-12);
    // A force limit clamps it.
    let m = SoftMotor {
        max_force: 1.0,
        ..m
    };
    solver.solve(
        &bodies,
        &[IdealJoint(JointModel::SoftMotorRevolute(j, m))],
        g,
    );
    assert!((solver.motor(0).unwrap() - 0.03 * 3.0).abs() < 1e-12);
    let m = SoftMotor {
        max_force: 0.05,
        ..m
    };
    solver.solve(
        &bodies,
        &[IdealJoint(JointModel::SoftMotorRevolute(j, m))],
        g,
    );
    assert_eq!(solver.motor(0), Some(0.05));
}

#[test]
fn soft_motor_angle_is_rapiers() {
    // At rest turned by 0.2 rad towards 0.5 rad: 10 * 0.3 = 3 N m.
    let (bodies, j) = arm_at(0.2, 0.0);
    let mut solver = ReactionSolver::default();
    let m = SoftMotor::force_based(0.5, 0.0, 10.0, 0.0);
    solver.solve(
        &bodies,
        &[IdealJoint(JointModel::SoftMotorRevolute(j, m))],
        Vector::ZERO,
    );
    assert!((solver.motor(0).unwrap() - 3.0).abs() < 1e-12);
    // At -3 rad towards +3 rad the short way is through pi: the error is
    // -6 + 2 pi = 0.283 rad, the torque -2.83 N m (a quaternion past pi is read as such).
    let (bodies, j) = arm_at(-3.0, 0.0);
    let m = SoftMotor::force_based(3.0, 0.0, 10.0, 0.0);
    solver.solve(
        &bodies,
        &[IdealJoint(JointModel::SoftMotorRevolute(j, m))],
        Vector::ZERO,
    );
    let expected = -10.0 * (-6.0 + std::f64::consts::TAU);
    assert!((solver.motor(0).unwrap() - expected).abs() < 1e-9);
    let (bodies, j) = arm_at(3.5, 0.0);
    let m = SoftMotor::force_based(0.0, 0.0, 10.0, 0.0);
    solver.solve(
        &bodies,
        &[IdealJoint(JointModel::SoftMotorRevolute(j, m))],
        Vector::ZERO,
    );
    let expected = -10.0 * (3.5 - std::f64::consts::TAU);
    assert!((solver.motor(0).unwrap() - expected).abs() < 1e-9);
}

#[test]
fn soft_and_held_prismatic_motors_by_hand() {
    // 2 kg slider 0.1 m along a fixed guide on x, moving at 0.5 m/s, gravity -y; a
    // force-based motor k = 100 N/m, c = 4 N s/m towards 0.3 m: 100 * 0.2 + 4 * (0 - 0.5)
    // = 18 N along x, a = 9 m/s^2; the guide carries the weight.
    let mut bodies = RigidBodySet::new();
    let base = bodies.insert(RigidBodyBuilder::fixed());
    let s = slider(
        &mut bodies,
        Vector::new(0.1, 0.0, 0.0),
        Vector::new(0.5, 0.0, 0.0),
        Vector::ZERO,
    );
    prepare_mass_properties(&mut bodies);
    let j = IdealPrismatic {
        body1: base,
        body2: s,
        local_anchor1: Vector::ZERO,
        local_anchor2: Vector::ZERO,
        local_axis1: Vector::X,
    };
    let g = Vector::new(0.0, -9.81, 0.0);
    let m = SoftMotor::force_based(0.3, 0.0, 100.0, 4.0);
    let mut solver = ReactionSolver::default();
    let f = solver
        .solve(
            &bodies,
            &[IdealJoint(JointModel::SoftMotorPrismatic(j, m))],
            g,
        )
        .unwrap()[0];
    assert!((solver.motor(0).unwrap() - 18.0).abs() < 1e-12);
    assert!((f - Vector::new(0.0, 19.62, 0.0)).length() < 1e-9, "{f:?}");
    let (a, al) = solver.acceleration(s).unwrap();
    assert!((a - Vector::new(9.0, 0.0, 0.0)).length() < 1e-9 && al.length() < 1e-9);
    // Acceleration-based: times the row's mass, the slider's 2 kg (its point is its centre
    // of mass; the guide is fixed).
    let m = SoftMotor {
        model: MotorModel::AccelerationBased,
        ..m
    };
    solver.solve(
        &bodies,
        &[IdealJoint(JointModel::SoftMotorPrismatic(j, m))],
        g,
    );
    assert!((solver.motor(0).unwrap() - 36.0).abs() < 1e-12);
    // Held speed against a 3 N push: the motor pulls back 3 N, nothing accelerates.
    bodies[s].add_force(Vector::new(3.0, 0.0, 0.0), false);
    let f = solver
        .solve(&bodies, &[IdealJoint(JointModel::MotorPrismatic(j))], g)
        .unwrap()[0];
    assert!((solver.motor(0).unwrap() + 3.0).abs() < 1e-12);
    assert!((f - Vector::new(0.0, 19.62, 0.0)).length() < 1e-9, "{f:?}");
    assert!(solver.acceleration(s).unwrap().0.length() < 1e-12);
}

#[test]
fn velocities_are_projected_onto_the_joints() {
    // The arm's stored velocities disagree: spinning at 5 rad/s, its centre of mass at rest.
    // The least change in the mass metric that turns it about the pivot: minimise
    // m (0.3 w)^2 + I (w - 5)^2 -> w = 5 I/(m 0.09 + I) = 5 * 0.03/0.21 = 5/7 rad/s.
    let (mut bodies, j) = arm_at(0.0, 5.0);
    bodies[j.body2].set_linvel(Vector::ZERO, false);
    let mut solver = ReactionSolver::default();
    let f = solver
        .solve(&bodies, &[IdealJoint(j.into())], Vector::ZERO)
        .unwrap()[0];
    let w = 5.0 / 7.0;
    let (v, wv) = solver.velocity(j.body2).unwrap();
    assert!((wv - Vector::new(0.0, 0.0, w)).length() < 1e-12, "{wv:?}");
    assert!(
        (v - Vector::new(0.0, 0.3 * w, 0.0)).length() < 1e-12,
        "{v:?}"
    );
    // The centripetal pull at the projected speed.
    assert!((f - Vector::new(-2.0 * w * w * 0.3, 0.0, 0.0)).length() < 1e-9);
}

#[test]
fn stored_velocities_are_advanced_by_the_lag() {
    // Level arm, stored 2 rad/s, 0.01 s before the state: under gravity alone the angular
    // acceleration at level is -m g r/I_pivot whatever the speed, so the state's speed is
    // 2 + 0.01 alpha, and the pivot pulls with its centripetal force.
    let (bodies, j) = arm_at(0.0, 2.0);
    let g = Vector::new(0.0, -9.81, 0.0);
    let mut solver = ReactionSolver {
        velocity_lag: 0.01,
        ..ReactionSolver::default()
    };
    let f = solver.solve(&bodies, &[IdealJoint(j.into())], g).unwrap()[0];
    let alpha = -2.0 * 9.81 * 0.3 / 0.21;
    let w = 2.0 + 0.01 * alpha;
    let (_, wv) = solver.velocity(j.body2).unwrap();
    assert!((wv.z - w).abs() < 1e-12, "{wv:?} against {w}");
    assert!((f.x + 2.0 * w * w * 0.3).abs() < 1e-9, "{f:?}");
    // A tracked free body falls.
    let mut bodies = bodies;
    let free = slider(&mut bodies, Vector::Y, Vector::ZERO, Vector::ZERO);
    prepare_mass_properties(&mut bodies);
    solver.track = vec![free];
    solver.solve(&bodies, &[IdealJoint(j.into())], g).unwrap();
    assert!((solver.acceleration(free).unwrap().0 - g).length() < 1e-12);
    assert!((solver.velocity(free).unwrap().0 - 0.01 * g).length() < 1e-12);
}

#[test]
fn a_weld_between_bodies_that_do_not_move_leaves_the_other_reactions() {
    // The hanging arm of the module example (2 kg, held by its pivot: 2 g up) beside a bracket
    // welded to the ground and a kinematic plate spinning on a fixed pin: those joints join
    // bodies no force moves, carry no unknown, and must neither zero nor disturb the arm's.
    let g = Vector::new(0.0, -9.81, 0.0);
    let mut bodies = RigidBodySet::new();
    let base = bodies.insert(RigidBodyBuilder::fixed());
    let bracket = bodies.insert(RigidBodyBuilder::fixed().translation(Vector::new(0.5, 0.0, 0.0)));
    let plate = bodies
        .insert(RigidBodyBuilder::kinematic_velocity_based().angvel(Vector::new(0.0, 0.0, 3.0)));
    let arm = bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.0, -0.3, 0.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                2.0,
                Vector::splat(0.02),
            )),
    );
    prepare_mass_properties(&mut bodies);
    let hinge = JointModel::Revolute(IdealRevolute {
        body1: base,
        body2: arm,
        local_anchor1: Vector::ZERO,
        local_anchor2: Vector::new(0.0, 0.3, 0.0),
        local_axis1: Vector::Z,
    });
    let weld = JointModel::Fixed(IdealFixed {
        body1: base,
        body2: bracket,
        local_anchor1: Vector::new(0.5, 0.0, 0.0),
        local_anchor2: Vector::ZERO,
    });
    let pin = JointModel::Revolute(IdealRevolute {
        body1: bracket,
        body2: plate,
        local_anchor1: Vector::new(-0.5, 0.0, 0.0),
        local_anchor2: Vector::ZERO,
        local_axis1: Vector::Z,
    });
    let mut s = ReactionSolver::default();
    for joints in [vec![hinge, weld], vec![weld, pin, hinge], vec![pin, hinge]] {
        let joints: Vec<IdealJoint> = joints.into_iter().map(IdealJoint).collect();
        let f = s.solve(&bodies, &joints, g).unwrap().to_vec();
        let k = joints.iter().position(|j| j.0 == hinge).unwrap();
        assert!(
            (f[k] - Vector::new(0.0, 2.0 * 9.81, 0.0)).length() < 1e-9,
            "{f:?}"
        );
        for (i, f) in f.iter().enumerate().filter(|(i, _)| *i != k) {
            assert_eq!(
                *f,
                Vector::ZERO,
                "joint {i} between bodies that do not move"
            );
        }
    }
}

/// A hanging arm of 2 kg, 0.3 m below a fixed pivot; optionally with a 1 kg ball collider.
fn hanging_arm(collider: bool) -> (PhysicsWorld, IdealRevolute) {
    let mut world = PhysicsWorld::new();
    let base = world.bodies.insert(RigidBodyBuilder::fixed());
    let arm = world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.0, -0.3, 0.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                2.0,
                Vector::splat(0.02),
            )),
    );
    if collider {
        // Radius 0.1 m, density chosen for 1 kg.
        let density = 1.0 / (4.0 / 3.0 * std::f64::consts::PI * 0.1f64.powi(3));
        let ball = ColliderBuilder::ball(0.1).density(density);
        world
            .colliders
            .insert_with_parent(ball, arm, &mut world.bodies);
    }
    let joint = IdealRevolute {
        body1: base,
        body2: arm,
        local_anchor1: Vector::ZERO,
        local_anchor2: Vector::new(0.0, 0.3, 0.0),
        local_axis1: Vector::Z,
    };
    (world, joint)
}

#[test]
fn solves_before_the_first_step_without_preparation() {
    // Rapier has not computed the arm's mass yet; the solver does, from the builder's props.
    let (world, joint) = hanging_arm(false);
    assert_eq!(
        world.bodies[joint.body2]
            .mass_properties()
            .local_mprops
            .inv_mass,
        0.0
    );
    let g = Vector::new(0.0, -9.81, 0.0);
    let mut solver = ReactionSolver::default();
    let f = solver
        .solve(&world.bodies, &[IdealJoint(joint.into())], g)
        .unwrap()[0];
    assert!(
        (f - Vector::new(0.0, 2.0 * 9.81, 0.0)).length() < 1e-9,
        "{f:?}"
    );
    assert_eq!(solver.failure(), None);
    // Bit for bit what the prepared bodies give.
    let mut prepared = world.bodies.clone();
    prepare_mass_properties(&mut prepared);
    assert_eq!(
        solver
            .solve(&prepared, &[IdealJoint(joint.into())], g)
            .unwrap()[0],
        f
    );
}

#[test]
fn a_body_with_colliders_before_the_first_step_is_refused_with_the_fix() {
    let (mut world, joint) = hanging_arm(true);
    let g = Vector::new(0.0, -9.81, 0.0);
    let mut solver = ReactionSolver::default();
    assert!(
        solver
            .solve(&world.bodies, &[IdealJoint(joint.into())], g)
            .is_none()
    );
    let failure = solver.failure().unwrap();
    assert_eq!(failure, ReactionFailure::MassPropertiesPending(joint.body2));
    assert!(
        failure
            .to_string()
            .contains("recompute_mass_properties_from_colliders")
    );
    // The fix it names: the arm then weighs 3 kg (2 kg added, 1 kg of collider).
    world.bodies[joint.body2].recompute_mass_properties_from_colliders(&world.colliders);
    let f = solver
        .solve(&world.bodies, &[IdealJoint(joint.into())], g)
        .unwrap()[0];
    assert!(
        (f - Vector::new(0.0, 3.0 * 9.81, 0.0)).length() < 1e-9,
        "{f:?}"
    );
    assert_eq!(solver.failure(), None);
}

#[test]
fn a_missing_body_is_named() {
    let (world, joint) = hanging_arm(false);
    let mut solver = ReactionSolver::default();
    let g = Vector::ZERO;
    // Joints of this world solved against another, empty set of bodies.
    assert!(
        solver
            .solve(&RigidBodySet::new(), &[IdealJoint(joint.into())], g)
            .is_none()
    );
    assert_eq!(
        solver.failure(),
        Some(ReactionFailure::MissingBody(joint.body1))
    );
    // A solve that succeeds clears it.
    assert!(
        solver
            .solve(&world.bodies, &[IdealJoint(joint.into())], g)
            .is_some()
    );
    assert_eq!(solver.failure(), None);
}

proptest::proptest! {
    /// A soft motor's force is NaN or within its limit, whatever its numbers and the state.
    #[test]
    fn a_soft_motors_force_stays_within_its_limit(
        target in any_number(), rate in any_number(), k in any_number(), c in any_number(),
        error in any_number(), v in any_number(), row_mass in any_number(),
    ) {
        let m = SoftMotor::force_based(target, rate, k.abs(), c.abs());
        let f = m.force(error, v, row_mass);
        proptest::prop_assert!(f.is_nan() || (-m.max_force..=m.max_force).contains(&f));
    }
}

/// Numbers with the edge cases a law meets: NaN, infinities, zeros, subnormals, extremes.
fn any_number() -> impl proptest::strategy::Strategy<Value = f64> {
    use proptest::prelude::*;
    prop_oneof![
        3 => prop::sample::select(vec![
            f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 0.0, -0.0, f64::MIN_POSITIVE, 5e-324,
            f64::MAX, -f64::MAX, 1e-300, 1e300,
        ]),
        7 => any::<f64>(),
    ]
}

/// `IdealJoint::from_rapier` reads each kind of Rapier joint as the description written by hand
/// (kind, bodies, anchors, axis, motor), and a held motor becomes the speed constraint.
#[test]
fn ideal_joints_read_from_rapier_match_their_descriptions() {
    let mut bodies = RigidBodySet::new();
    let a = bodies.insert(RigidBodyBuilder::fixed());
    let b = bodies.insert(RigidBodyBuilder::dynamic());
    let (p1, p2) = (Vector::new(0.1, -0.2, 0.3), Vector::new(-0.4, 0.5, 0.0));
    let axis = Vector::new(1.0, 2.0, 2.0) / 3.0;
    let mut joints = ImpulseJointSet::new();
    let mut read = |j: GenericJoint| {
        let h = joints.insert(a, b, j, true);
        IdealJoint::from_rapier(&joints, h).unwrap().0
    };
    let close = |u: Vector, v: Vector| (u - v).length() < 1e-15;
    let JointModel::Revolute(r) = read(
        RevoluteJointBuilder::new(axis)
            .local_anchor1(p1)
            .local_anchor2(p2)
            .into(),
    ) else {
        panic!("not read as a revolute")
    };
    assert_eq!(
        (r.body1, r.body2, r.local_anchor1, r.local_anchor2),
        (a, b, p1, p2)
    );
    assert!(close(r.local_axis1, axis), "{:?}", r.local_axis1);
    let JointModel::Prismatic(s) = read(PrismaticJointBuilder::new(axis).local_anchor1(p1).into())
    else {
        panic!("not read as a prismatic joint")
    };
    assert!(close(s.local_axis1, axis) && s.local_anchor1 == p1);
    assert!(matches!(
        read(FixedJointBuilder::new().local_anchor2(p2).into()),
        JointModel::Fixed(f) if f.local_anchor2 == p2
    ));
    assert!(matches!(
        read(SphericalJointBuilder::new().local_anchor1(p1).into()),
        JointModel::Spherical(f) if f.local_anchor1 == p1
    ));
    let motorised = RevoluteJointBuilder::new(axis).motor(0.5, 2.0, 30.0, 4.0);
    let h = joints.insert(a, b, motorised, true);
    let soft = IdealJoint::from_rapier(&joints, h).unwrap();
    let JointModel::SoftMotorRevolute(_, m) = soft.0 else {
        panic!("the motor was not read")
    };
    let rapier_motor = joints.get(h).unwrap().data.motor(JointAxis::AngX).unwrap();
    assert_eq!(m, SoftMotor::from_rapier(rapier_motor));
    assert!(matches!(soft.held_motor().0, JointModel::MotorRevolute(_)));
}

/// What the reaction solve cannot hold is refused with an error naming the argument.
#[test]
fn ideal_joints_the_solve_cannot_hold_are_refused() {
    let mut bodies = RigidBodySet::new();
    let a = bodies.insert(RigidBodyBuilder::fixed());
    let b = bodies.insert(RigidBodyBuilder::dynamic());
    let mut joints = ImpulseJointSet::new();
    let slot = GenericJointBuilder::new(JointAxesMask::LIN_X | JointAxesMask::LIN_Y).build();
    let slot = joints.insert(a, b, slot, true);
    let e = IdealJoint::from_rapier(&joints, slot)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("joint") && e.contains("revolute, prismatic, fixed"),
        "{e}"
    );
    let mut weld: GenericJoint = FixedJointBuilder::new().into();
    weld.set_motor(JointAxis::AngX, 0.0, 1.0, 0.0, 1.0);
    let weld = joints.insert(a, b, weld, true);
    let e = IdealJoint::from_rapier(&joints, weld)
        .unwrap_err()
        .to_string();
    assert!(e.contains("motor"), "{e}");
    joints.remove(slot, true);
    let e = IdealJoint::from_rapier(&joints, slot)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("handle") && e.contains("not in the impulse joint set"),
        "{e}"
    );
}

#[test]
fn load_response_is_the_difference_of_two_solves() {
    // A spinning arm on its pivot under gravity, a ball-jointed second arm at its tip, and a
    // free body beside them: the response to a force pair between the second arm and the free
    // body (a contact's load, at a point off both centres of mass) is what a full solve with
    // the pair as applied wrenches adds to the accelerations.
    let (mut bodies, j) = arm_at(0.4, 3.0);
    let tip = Rotation::from_rotation_z(0.4) * Vector::new(0.6, 0.0, 0.0);
    let mass = MassProperties::new(Vector::ZERO, 0.7, Vector::new(0.004, 0.005, 0.006));
    let second = bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(tip + Vector::new(0.0, -0.2, 0.05))
            .additional_mass_properties(mass),
    );
    let free = bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(1.0, 0.5, 0.0))
            .additional_mass_properties(mass),
    );
    prepare_mass_properties(&mut bodies);
    let ball = IdealSpherical {
        body1: j.body2,
        body2: second,
        local_anchor1: Vector::new(0.3, 0.0, 0.0),
        local_anchor2: Vector::new(0.0, 0.2, -0.05),
    };
    let joints = [
        IdealJoint(JointModel::Revolute(j)),
        IdealJoint(JointModel::Spherical(ball)),
    ];
    let g = Vector::new(0.0, -9.81, 0.0);
    let (f, p) = (Vector::new(3.0, -1.0, 2.0), Vector::new(0.9, 0.1, 0.3));
    let com = |h| world_center_of_mass(&bodies[h]);
    let pair = [
        Wrench {
            body: second,
            force: f,
            torque: (p - com(second)).cross(f),
        },
        Wrench {
            body: free,
            force: -f,
            torque: (p - com(free)).cross(-f),
        },
    ];
    let mut solver = ReactionSolver {
        track: vec![free],
        ..Default::default()
    };
    let handles = [j.body2, second, free];
    solver.solve_with(&bodies, &joints, g, &pair).unwrap();
    let loaded: Vec<_> = handles.map(|h| solver.acceleration(h).unwrap()).into();
    solver.solve_with(&bodies, &joints, g, &[]).unwrap();
    solver.load_response(&[(second, f, p.cross(f)), (free, -f, p.cross(-f))]);
    for (k, h) in handles.into_iter().enumerate() {
        let (a, alpha) = solver.acceleration(h).unwrap();
        let (da, dalpha) = solver.response(h).unwrap();
        let (ea, ealpha) = (loaded[k].0 - a, loaded[k].1 - alpha);
        assert!(ea.length() > 0.1, "body {k}: the load moves it");
        assert!((da - ea).length() < 1e-9 * ea.length(), "{da:?} vs {ea:?}");
        assert!(
            (dalpha - ealpha).length() < 1e-9 * ealpha.length().max(1.0),
            "{dalpha:?} vs {ealpha:?}"
        );
    }
}
