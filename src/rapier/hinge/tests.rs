//! The conversions between revolute and clearance joints, and the hinge design's checks.

use super::convert::*;
use super::design::*;
use crate::error::Error;
use crate::model::laws::{Bai, FrictionModel};
use crate::model::laws::{BearingGeometry, NormalModel};
use crate::rapier::joint::{ClearanceJointHandle, ClearanceJointSet};
use crate::rapier::large_step::LargeStepJointSet;
use rapier3d_f64::prelude::*;

struct Rig {
    world: PhysicsWorld,
    base: RigidBodyHandle,
    arm: RigidBodyHandle,
}

fn rig() -> Rig {
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::new(0.0, -9.81, 0.0);
    // Stiff steel contact under a 20 N load: the hook refuses steps above about 3e-5 s.
    world.integration_parameters.dt = 1e-5;
    world.integration_parameters.num_solver_iterations = 1;
    let base = world.bodies.insert(RigidBodyBuilder::fixed());
    let arm = world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.0, -0.3, 0.0))
            .can_sleep(false)
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                2.0,
                Vector::splat(0.02),
            )),
    );
    Rig { world, base, arm }
}

fn revolute() -> RevoluteJointBuilder {
    RevoluteJointBuilder::new(Vector::Z)
        .local_anchor1(Vector::new(0.01, 0.0, 0.0))
        .local_anchor2(Vector::new(0.01, 0.3, 0.0))
}

/// `revolute()` between the rig's base and arm, converted with the bearing on `side`: the
/// set, the clearance joint and the (removed) revolute's handle.
fn converted(
    r: &mut Rig,
    side: BearingSide,
) -> (ClearanceJointSet, ClearanceJointHandle, ImpulseJointHandle) {
    let h = r
        .world
        .impulse_joints
        .insert(r.base, r.arm, revolute(), true);
    let mut set = ClearanceJointSet::new();
    let c = set
        .convert_revolute(h, side, clearance(), &mut r.world.impulse_joints)
        .unwrap();
    (set, c, h)
}

fn clearance() -> HingeDesign {
    HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)
        .unwrap()
        .friction(FrictionModel::Bai(Bai::DRY))
        .name("pivot")
}

#[test]
fn converts_with_the_revolute_anchors_and_axes() {
    let mut r = rig();
    let (set, c, h) = converted(&mut r, BearingSide::Body1);
    assert!(r.world.impulse_joints.get(h).is_none(), "revolute removed");
    let j = set.get(c).unwrap();
    assert_eq!(j.name(), "pivot");
    assert_eq!((j.body1(), j.body2()), (r.base, r.arm));
    assert_eq!(j.local_anchor1(), Vector::new(0.01, 0.0, 0.0));
    assert_eq!(j.local_anchor2(), Vector::new(0.01, 0.3, 0.0));
    assert!((j.local_axis1() - Vector::Z).length() < 1e-15);
    assert!((j.local_axis2() - Vector::Z).length() < 1e-15);
    assert!(matches!(j.friction_law(), FrictionModel::Bai(_)));
    // Only the lock of the out-of-plane motion remains, and it is not a revolute.
    assert_eq!(r.world.impulse_joints.len(), 1);
    let lock = r
        .world
        .impulse_joints
        .get(j.lock_handle().unwrap())
        .unwrap();
    assert!(lock.data.as_revolute().is_none());
}

#[test]
fn the_bearing_side_is_explicit() {
    let mut r = rig();
    let (mut set, c, _) = converted(&mut r, BearingSide::Body2);
    let j = set.get(c).unwrap();
    // The arm carries the bearing: it is the clearance joint's body 1, with its anchor.
    assert_eq!((j.body1(), j.body2()), (r.arm, r.base));
    assert_eq!(j.local_anchor1(), Vector::new(0.01, 0.3, 0.0));
    assert_eq!(j.local_anchor2(), Vector::new(0.01, 0.0, 0.0));
    // Either way the contact carries the arm's weight (2 kg x 9.81 m/s^2): its mean over the
    // last 0.1 s (the light contact rings between 16.5 and 21.7 N, the arm swinging slowly).
    let mut stepper = crate::rapier::pipeline::stepper::Stepper::new(
        crate::rapier::pipeline::stepper::StepControl::fixed(1e-5),
    );
    let (mut sum, mut n) = (0.0, 0.0);
    while stepper.time() < 0.3 {
        stepper.step(&mut r.world, &mut [&mut set], 0.3).unwrap();
        if stepper.time() > 0.2 {
            sum += set.get(c).unwrap().report().force.normal_force;
            n += 1.0;
        }
    }
    let f = sum / n;
    assert!((f - 19.62).abs() < 1.0, "{f}");
}

#[test]
#[allow(deprecated)]
fn steel_is_the_improved_liu_alias() {
    assert_eq!(
        HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016).unwrap(),
        HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016).unwrap()
    );
    assert!(matches!(
        HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)
            .unwrap()
            .normal,
        NormalModel::ImprovedLiu(_)
    ));
}

#[test]
fn converts_a_rotated_frame_pair() {
    // Different axes on the two bodies (body 2 built rotated by 90 deg about z).
    let mut r = rig();
    let data = GenericJointBuilder::new(JointAxesMask::LOCKED_REVOLUTE_AXES)
        .local_axis1(Vector::Y)
        .local_axis2(Vector::X)
        .local_anchor1(Vector::new(0.0, 0.0, 0.2))
        .local_anchor2(Vector::new(0.1, 0.0, 0.0))
        .build();
    let h = r.world.impulse_joints.insert(r.base, r.arm, data, true);
    let mut set = ClearanceJointSet::new();
    let c = revolute_to_clearance(
        &mut set,
        h,
        BearingSide::Body1,
        clearance(),
        &mut r.world.impulse_joints,
    )
    .unwrap();
    let j = set.get(c).unwrap();
    assert!((j.local_axis1() - Vector::Y).length() < 1e-15);
    assert!((j.local_axis2() - Vector::X).length() < 1e-15);
    // And back: the revolute has the same frames' axes and anchors.
    let back = clearance_to_revolute(
        &mut set,
        c,
        &mut r.world.bodies,
        &mut r.world.impulse_joints,
    )
    .unwrap();
    let d = &r.world.impulse_joints.get(back).unwrap().data;
    assert!(d.as_revolute().is_some());
    assert!((d.local_frame1.rotation * Vector::X - Vector::Y).length() < 1e-15);
    assert!((d.local_frame2.rotation * Vector::X - Vector::X).length() < 1e-15);
    assert_eq!(d.local_anchor1(), Vector::new(0.0, 0.0, 0.2));
    assert_eq!(d.local_anchor2(), Vector::new(0.1, 0.0, 0.0));
}

#[test]
fn round_trip_restores_an_equivalent_revolute() {
    let mut r = rig();
    let original: GenericJoint = revolute().contacts_enabled(false).into();
    let h = r.world.impulse_joints.insert(r.base, r.arm, original, true);
    let mut set = ClearanceJointSet::new();
    let c = set
        .convert_revolute(
            h,
            BearingSide::Body1,
            clearance(),
            &mut r.world.impulse_joints,
        )
        .unwrap();
    let back = set
        .revert_to_revolute(c, &mut r.world.bodies, &mut r.world.impulse_joints)
        .unwrap();
    assert!(set.is_empty());
    assert_eq!(
        r.world.impulse_joints.len(),
        1,
        "lock removed, revolute back"
    );
    let ij = r.world.impulse_joints.get(back).unwrap();
    assert_eq!((ij.body1(), ij.body2()), (r.base, r.arm));
    assert_eq!(ij.data.local_frame1, original.local_frame1);
    assert_eq!(ij.data.local_frame2, original.local_frame2);
    assert_eq!(ij.data.locked_axes, original.locked_axes);
}

/// A spatial clearance converts a revolute without a lock (nothing is held ideally), steps,
/// and reverts to a revolute with the original frames; the large-step set refuses it, naming
/// `model`, and leaves the revolute in place.
#[test]
fn a_spatial_clearance_converts_without_a_lock_and_reverts() {
    use crate::model::spatial::SpatialModel;
    let spatial = || clearance().model(ClearanceModel::Spatial(SpatialModel::steel(0.2e-3, 0.015)));
    for side in [BearingSide::Body1, BearingSide::Body2] {
        let mut r = rig();
        let original: GenericJoint = revolute().contacts_enabled(false).into();
        let h = r.world.impulse_joints.insert(r.base, r.arm, original, true);
        let mut large = LargeStepJointSet::new();
        let e = large
            .convert_revolute(
                h,
                BearingSide::Body1,
                spatial(),
                &mut r.world.impulse_joints,
            )
            .unwrap_err();
        assert!(
            matches!(&e, Error::Invalid { field, .. } if field == "model"),
            "{e}"
        );
        assert!(large.is_empty() && r.world.impulse_joints.get(h).is_some());
        let mut set = ClearanceJointSet::new();
        let c = set
            .convert_revolute(h, side, spatial(), &mut r.world.impulse_joints)
            .unwrap();
        assert!(r.world.impulse_joints.is_empty(), "no lock inserted");
        let j = set.get(c).unwrap();
        assert!(j.lock_handle().is_none() && j.spatial_model().is_some());
        let anchors = match side {
            BearingSide::Body1 => [Vector::new(0.01, 0.0, 0.0), Vector::new(0.01, 0.3, 0.0)],
            BearingSide::Body2 => [Vector::new(0.01, 0.3, 0.0), Vector::new(0.01, 0.0, 0.0)],
        };
        assert_eq!([j.local_anchor1(), j.local_anchor2()], anchors);
        for _ in 0..2_000 {
            set.apply(
                &mut r.world.bodies,
                &r.world.impulse_joints,
                &r.world.integration_parameters,
            )
            .unwrap();
            r.world.step();
        }
        assert!(set.get(c).unwrap().report().spatial.is_some());
        let back = set
            .revert_to_revolute(c, &mut r.world.bodies, &mut r.world.impulse_joints)
            .unwrap();
        assert!(set.is_empty());
        assert_eq!(r.world.impulse_joints.len(), 1, "the revolute alone");
        let ij = r.world.impulse_joints.get(back).unwrap();
        // The revolute joins the clearance joint's bodies (body 1 the bearing's) with its
        // anchors: the original's, swapped when the arm carried the bearing.
        let (b1, b2, a1, a2) = match side {
            BearingSide::Body1 => (r.base, r.arm, anchors[0], anchors[1]),
            BearingSide::Body2 => (r.arm, r.base, anchors[0], anchors[1]),
        };
        assert_eq!((ij.body1(), ij.body2()), (b1, b2));
        assert_eq!((ij.data.local_anchor1(), ij.data.local_anchor2()), (a1, a2));
        assert!((ij.data.local_frame1.rotation * Vector::X - Vector::Z).length() < 1e-15);
        assert!((ij.data.local_frame2.rotation * Vector::X - Vector::Z).length() < 1e-15);
        assert_eq!(ij.data.locked_axes, original.locked_axes);
    }
}

#[test]
fn converted_mid_run_the_hinge_keeps_the_arm_and_carries_its_weight() {
    let mut r = rig();
    let h = r.world.impulse_joints.insert(
        r.base,
        r.arm,
        RevoluteJointBuilder::new(Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0)),
        true,
    );
    let mut set = ClearanceJointSet::new();
    for _ in 0..100 {
        set.apply(
            &mut r.world.bodies,
            &r.world.impulse_joints,
            &r.world.integration_parameters,
        )
        .unwrap();
        r.world.step();
    }
    let c = set
        .convert_revolute(
            h,
            BearingSide::Body1,
            clearance(),
            &mut r.world.impulse_joints,
        )
        .unwrap();
    for _ in 0..20_000 {
        set.apply(
            &mut r.world.bodies,
            &r.world.impulse_joints,
            &r.world.integration_parameters,
        )
        .unwrap();
        r.world.step();
    }
    let report = set.get(c).unwrap().report();
    assert!(report.state.penetration > 0.0, "resting on the journal");
    let f = report.force.on_journal.length();
    assert!((f - 2.0 * 9.81).abs() < 0.02, "carries the weight: {f} N");
    // The arm fell by the clearance plus a fraction of a micrometre of contact deflection.
    let y = r.world.bodies[r.arm].translation().y;
    assert!((y + 0.3 + 0.2e-3).abs() < 1e-6, "arm at {y}");
}

#[test]
fn reverting_re_centres_the_journal_and_injects_m_g_c() {
    // Resting on the bearing wall, the arm hangs c lower than on an ideal pin; the revolute
    // put back pulls its anchors together and lifts it by c: m g c of energy (3.9 mJ).
    let mut r = rig();
    let (mut set, c, _) = converted(&mut r, BearingSide::Body1);
    for _ in 0..20_000 {
        set.apply(
            &mut r.world.bodies,
            &r.world.impulse_joints,
            &r.world.integration_parameters,
        )
        .unwrap();
        r.world.step();
    }
    let energy = |w: &PhysicsWorld| {
        let rb = &w.bodies[r.arm];
        let kinetic =
            0.5 * 2.0 * rb.linvel().length_squared() + 0.5 * 0.02 * rb.angvel().length_squared();
        kinetic + 2.0 * 9.81 * rb.translation().y
    };
    let e0 = energy(&r.world);
    set.revert_to_revolute(c, &mut r.world.bodies, &mut r.world.impulse_joints)
        .unwrap();
    let mut highest = e0;
    for _ in 0..20_000 {
        r.world.step();
        highest = highest.max(energy(&r.world));
    }
    // Measured: 3.76 mJ, 0.96 m g c (the arm, hinged 0.01 m off its centre line, also swings).
    let mgc = 2.0 * 9.81 * 0.2e-3;
    let rise = highest - e0;
    assert!(
        rise > 0.9 * mgc && rise < 1.1 * mgc,
        "energy rose by {rise} J"
    );
}

#[test]
fn refusals_leave_everything_unchanged() {
    let mut r = rig();
    let mut set = ClearanceJointSet::new();
    let check = |e: Error, needle: &str| {
        let msg = e.to_string();
        assert!(msg.contains(needle), "{msg}");
    };
    let cases: Vec<(GenericJoint, &str)> = vec![
        (
            PrismaticJointBuilder::new(Vector::X).into(),
            "not a revolute",
        ),
        (FixedJointBuilder::new().into(), "not a revolute"),
        (revolute().motor_velocity(1.0, 0.5).into(), "motor"),
        (revolute().limits([-1.0, 1.0]).into(), "limits"),
        (
            {
                let mut j: GenericJoint = revolute().into();
                j.set_enabled(false);
                j
            },
            "disabled",
        ),
    ];
    for (joint, needle) in cases {
        let h = r.world.impulse_joints.insert(r.base, r.arm, joint, true);
        let n = r.world.impulse_joints.len();
        check(
            set.convert_revolute(
                h,
                BearingSide::Body1,
                clearance(),
                &mut r.world.impulse_joints,
            )
            .unwrap_err(),
            needle,
        );
        assert_eq!(r.world.impulse_joints.len(), n, "nothing removed");
        assert!(set.is_empty());
        r.world.impulse_joints.remove(h, false);
    }
    // An unknown handle, in both directions.
    let h = r
        .world
        .impulse_joints
        .insert(r.base, r.arm, revolute(), true);
    r.world.impulse_joints.remove(h, false);
    check(
        set.convert_revolute(
            h,
            BearingSide::Body1,
            clearance(),
            &mut r.world.impulse_joints,
        )
        .unwrap_err(),
        "no joint with handle",
    );
    // A stale handle: its joint was converted back already.
    let h = r
        .world
        .impulse_joints
        .insert(r.base, r.arm, revolute(), true);
    let c = set
        .convert_revolute(
            h,
            BearingSide::Body1,
            clearance(),
            &mut r.world.impulse_joints,
        )
        .unwrap();
    let h = set
        .revert_to_revolute(c, &mut r.world.bodies, &mut r.world.impulse_joints)
        .unwrap();
    let n = r.world.impulse_joints.len();
    check(
        set.revert_to_revolute(c, &mut r.world.bodies, &mut r.world.impulse_joints)
            .unwrap_err(),
        "no joint with handle",
    );
    assert_eq!(r.world.impulse_joints.len(), n, "nothing changed");
    r.world.impulse_joints.remove(h, false);
    // An invalid clearance is refused by the laws, naming the field.
    check(
        HingeDesign::steel_improved_liu(0.010, 0.02, 0.016).unwrap_err(),
        "clearance",
    );
    check(
        HingeDesign::steel_improved_liu(0.010, 0.2e-3, -0.016).unwrap_err(),
        "length",
    );
    let h = r
        .world
        .impulse_joints
        .insert(r.base, r.arm, revolute(), true);
    check(
        set.convert_revolute(
            h,
            BearingSide::Body1,
            clearance().min_impact_speed(-1.0),
            &mut r.world.impulse_joints,
        )
        .unwrap_err(),
        "min_impact_speed",
    );
    assert!(r.world.impulse_joints.get(h).is_some(), "revolute kept");
}

#[test]
fn large_step_conversion_keeps_frames_and_maps_the_laws() {
    let mut r = rig();
    let h = r
        .world
        .impulse_joints
        .insert(r.base, r.arm, revolute(), true);
    // A LargeStep clearance is refused by the compliant set, naming the field.
    let mut compliant = ClearanceJointSet::new();
    let msg = compliant
        .convert_revolute(
            h,
            BearingSide::Body1,
            clearance().model(ClearanceModel::LargeStep),
            &mut r.world.impulse_joints,
        )
        .unwrap_err()
        .to_string();
    assert!(msg.contains("`model`"), "{msg}");
    assert!(r.world.impulse_joints.get(h).is_some(), "revolute kept");

    let mut play = LargeStepJointSet::new();
    let k = play
        .convert_revolute(
            h,
            BearingSide::Body1,
            clearance().model(ClearanceModel::LargeStep),
            &mut r.world.impulse_joints,
        )
        .unwrap();
    let j = play.get(k).unwrap();
    assert_eq!(j.name(), "pivot");
    assert_eq!((j.body1(), j.body2()), (r.base, r.arm));
    assert_eq!(j.local_anchor1(), Vector::new(0.01, 0.0, 0.0));
    assert_eq!(j.local_anchor2(), Vector::new(0.01, 0.3, 0.0));
    assert!((j.local_axis1() - Vector::Z).length() < 1e-15);
    assert!((j.clearance() - 0.2e-3).abs() < 1e-15);
    // Bai DRY slides at mu_d = 0.25; restitution from the law unless set.
    assert_eq!(j.friction(), 0.25);
    assert!(matches!(
        j.restitution(),
        crate::rapier::large_step::Restitution::Law(NormalModel::ImprovedLiu(_))
    ));
    assert_eq!(
        r.world.impulse_joints.len(),
        1,
        "one Rapier joint carries it all"
    );
    let data = &r
        .world
        .impulse_joints
        .get(j.rapier_handle().unwrap())
        .unwrap()
        .data;
    assert_eq!(
        data.coupled_axes,
        JointAxesMask::LIN_Y | JointAxesMask::LIN_Z
    );
    assert!((data.limits[1].max - 0.2e-3).abs() < 1e-15);

    // And back to the same revolute.
    let back = play
        .revert_to_revolute(k, &mut r.world.bodies, &mut r.world.impulse_joints)
        .unwrap();
    assert!(play.is_empty());
    let d = &r.world.impulse_joints.get(back).unwrap().data;
    assert!(d.as_revolute().is_some());
    assert_eq!(d.local_anchor2(), Vector::new(0.01, 0.3, 0.0));
    // A set restitution is a fixed coefficient; refusals are the revolute's.
    let j = clearance()
        .restitution(0.4)
        .large_step_joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
        .unwrap();
    assert_eq!(
        *j.restitution(),
        crate::rapier::large_step::Restitution::Coefficient(0.4)
    );
    let msg = clearance()
        .restitution(1.5)
        .large_step_joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("`restitution`"), "{msg}");
    let h = r
        .world
        .impulse_joints
        .insert(r.base, r.arm, revolute().limits([-1.0, 1.0]), true);
    let msg = play
        .convert_revolute(
            h,
            BearingSide::Body1,
            clearance(),
            &mut r.world.impulse_joints,
        )
        .unwrap_err()
        .to_string();
    assert!(msg.contains("limits"), "{msg}");
}

#[test]
fn a_law_built_for_another_clearance_is_refused_naming_the_field() {
    // The geometry says 0.5 mm, the improved law was built for 0.2 mm.
    let geometry = BearingGeometry::from_clearance(0.010, 0.5e-3, 0.016).unwrap();
    let law = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)
        .unwrap()
        .normal;
    let c = HingeDesign::new(geometry, law);
    let msg = c
        .joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("`normal_law`") && msg.contains("clearance"),
        "{msg}"
    );
    let msg = c
        .large_step_joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("`normal`") && msg.contains("clearance"),
        "{msg}"
    );
    // The same law with its own geometry builds.
    let ok = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016).unwrap();
    ok.joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
        .unwrap();
}
