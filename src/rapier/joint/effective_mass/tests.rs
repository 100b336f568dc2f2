use super::*;
use crate::rapier::pipeline::ledger::inverse_mass_along;
use rapier3d_f64::prelude::{
    JointAxis, MassProperties, PrismaticJointBuilder, RevoluteJointBuilder, RigidBodyBuilder,
};

/// A fixed base and a 0.5 kg arm (1e-4 kg m² about its centre of mass, 0.05 m from the
/// pivot at the origin, along x), held by `joint` if given.
fn pinned(
    joint: Option<rapier3d_f64::prelude::GenericJoint>,
) -> (
    RigidBodySet,
    ImpulseJointSet,
    RigidBodyHandle,
    RigidBodyHandle,
) {
    let mut bodies = RigidBodySet::new();
    let mut joints = ImpulseJointSet::new();
    let base = bodies.insert(RigidBodyBuilder::fixed());
    let mut rb = RigidBodyBuilder::dynamic()
        .translation(Vector::new(0.05, 0.0, 0.0))
        .additional_mass_properties(MassProperties::new(Vector::ZERO, 0.5, Vector::splat(1e-4)))
        .build();
    rb.recompute_mass_properties_from_colliders(&Default::default());
    let arm = bodies.insert(rb);
    if let Some(j) = joint {
        joints.insert(base, arm, j, true);
    }
    (bodies, joints, base, arm)
}

fn pivot() -> rapier3d_f64::prelude::GenericJoint {
    RevoluteJointBuilder::new(Vector::Z)
        .local_anchor2(Vector::new(-0.05, 0.0, 0.0))
        .build()
        .into()
}

/// The inverse mass the contact feels at `point` along `n` (free, then through the joints).
fn feels(
    bodies: &RigidBodySet,
    joints: &ImpulseJointSet,
    base: RigidBodyHandle,
    arm: RigidBodyHandle,
    point: Vector,
    n: Vector,
) -> (f64, f64) {
    let mut m = Mechanism::default();
    m.rebuild(bodies, joints, base, arm);
    let free =
        inverse_mass_along(&bodies[base], point, n) + inverse_mass_along(&bodies[arm], point, n);
    (free, m.inverse_mass(free, point, n))
}

#[test]
fn a_pinned_arm_feels_its_moment_of_inertia_over_the_lever_squared() {
    // I_pivot = 1e-4 + 0.5 * 0.05^2 = 1.35e-3 kg m^2; at L = 0.1 m across the arm,
    // m = I/L^2 = 0.135 kg. Free: 1/m = 1/0.5 + 0.05^2/1e-4 = 27, m = 0.037 kg.
    let (bodies, joints, base, arm) = pinned(Some(pivot()));
    let p = Vector::new(0.1, 0.0, 0.0);
    let (free, held) = feels(&bodies, &joints, base, arm, p, Vector::Y);
    assert!((1.0 / free - 1.0 / 27.0).abs() < 1e-15, "{free}");
    assert!((1.0 / held - 0.135).abs() < 1e-12 * 0.135, "{}", 1.0 / held);
    // Along the arm the pivot holds the contact: no finite mass (the floor).
    let (free, along) = feels(&bodies, &joints, base, arm, p, Vector::X);
    assert!(along <= 1e-11 * free, "{along}");
}

#[test]
fn without_joints_the_free_mass_is_kept_to_the_bit() {
    let (bodies, joints, base, arm) = pinned(None);
    let p = Vector::new(0.1, 0.003, 0.0);
    let n = Vector::new(0.6, 0.8, 0.0);
    let (free, held) = feels(&bodies, &joints, base, arm, p, n);
    assert_eq!(free.to_bits(), held.to_bits());
}

#[test]
fn a_slider_is_as_heavy_as_itself_along_its_guide() {
    let guide: rapier3d_f64::prelude::GenericJoint =
        PrismaticJointBuilder::new(Vector::X).build().into();
    let (bodies, joints, base, slider) = pinned(Some(guide));
    let p = Vector::new(0.1, 0.02, 0.0);
    // Along the guide: the slider's 0.5 kg (its rotation is held too).
    let (_, along) = feels(&bodies, &joints, base, slider, p, Vector::X);
    assert!((1.0 / along - 0.5).abs() < 1e-12, "{}", 1.0 / along);
    // Oblique at 60 deg to the guide: only the guide's share moves, 1/m = cos^2/0.5.
    let n = Vector::new(0.5, 0.75_f64.sqrt(), 0.0);
    let (_, oblique) = feels(&bodies, &joints, base, slider, p, n);
    assert!((oblique - 0.25 / 0.5).abs() < 1e-12, "{oblique}");
}

#[test]
fn a_stiff_velocity_motor_holds_and_a_soft_one_does_not() {
    let motor = |factor: f64| -> rapier3d_f64::prelude::GenericJoint {
        RevoluteJointBuilder::new(Vector::Z)
            .local_anchor2(Vector::new(-0.05, 0.0, 0.0))
            .motor_velocity(1.0, factor)
            .build()
            .into()
    };
    let p = Vector::new(0.1, 0.0, 0.0);
    let (bodies, joints, base, arm) = pinned(Some(motor(1e8)));
    let (free, held) = feels(&bodies, &joints, base, arm, p, Vector::Y);
    assert!(held <= 1e-11 * free, "a held crank does not yield: {held}");
    let (bodies, joints, base, arm) = pinned(Some(motor(10.0)));
    let (_, soft) = feels(&bodies, &joints, base, arm, p, Vector::Y);
    assert!((1.0 / soft - 0.135).abs() < 1e-12, "{}", 1.0 / soft);
    let mut limited = motor(1e8);
    limited.set_motor_max_force(JointAxis::AngX, 5.0);
    let (bodies, joints, base, arm) = pinned(Some(limited));
    let (_, capped) = feels(&bodies, &joints, base, arm, p, Vector::Y);
    assert!((1.0 / capped - 0.135).abs() < 1e-12, "{}", 1.0 / capped);
}

/// Two arms in a chain, the second pinned to the first's tip: the mobility between the
/// pairs (base, arm 1) and (arm 1, arm 2) is the same read from either pair's mechanism
/// (`P_ab = P_ba^T`: the mobility is symmetric), and a pair's own block is its
/// `pair_mobility`.
#[test]
fn the_mobility_between_two_pairs_of_a_chain_is_symmetric_and_holds_the_own_block() {
    let (mut bodies, mut joints, base, arm1) = pinned(Some(pivot()));
    let mut rb = RigidBodyBuilder::dynamic()
        .translation(Vector::new(0.15, 0.0, 0.0))
        .additional_mass_properties(MassProperties::new(Vector::ZERO, 0.3, Vector::splat(5e-5)))
        .build();
    rb.recompute_mass_properties_from_colliders(&Default::default());
    let arm2 = bodies.insert(rb);
    let elbow = RevoluteJointBuilder::new(Vector::Z)
        .local_anchor1(Vector::new(0.05, 0.0, 0.0))
        .local_anchor2(Vector::new(-0.05, 0.0, 0.0));
    joints.insert(arm1, arm2, elbow, true);
    let mechanism = |pair: [RigidBodyHandle; 2]| {
        let mut m = Mechanism::default();
        m.rebuild(&bodies, &joints, pair[0], pair[1]);
        m
    };
    let (a, b) = ([base, arm1], [arm1, arm2]);
    let (ma, mb) = (mechanism(a), mechanism(b));
    let (p_ab, p_ba) = (ma.cross_mobility(b).unwrap(), mb.cross_mobility(a).unwrap());
    let scale = p_ab.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    // Arm 1 turns about the pivot: 1/I_pivot = 1/(1e-4 + 0.5 0.05^2) at least, less what
    // arm 2 holds.
    assert!(scale > 100.0, "{scale}");
    for r in 0..12 {
        for c in 0..12 {
            let (x, y) = (p_ab[r * 12 + c], p_ba[c * 12 + r]);
            assert!(
                (x - y).abs() <= 1e-9 * scale,
                "P_ab[{r}][{c}] {x} vs P_ba^T {y}, scale {scale}"
            );
        }
    }
    let own = mb.cross_mobility(b).unwrap();
    for (x, y) in own.iter().zip(mb.pair_mobility()) {
        assert!((x - y).abs() <= 1e-12 * scale, "{x} vs {y}");
    }
    // The base is fixed: no load moves it, no load on it moves anything.
    for k in 0..6 {
        for c in 0..12 {
            assert_eq!(p_ab[k * 12 + c], 0.0);
            assert_eq!(p_ba[c * 12 + k], 0.0);
        }
    }
}
