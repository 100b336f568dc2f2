//! The joint sets' handles are generational (as Rapier's): removing a joint leaves every other
//! handle valid, a removed joint's handle finds nothing (also after its slot is reused), and the
//! sets visit their joints in insertion order.

use clearance_joint::rapier::hinge::design::HingeDesign;
use clearance_joint::rapier::joint::ClearanceJointSet;
use clearance_joint::rapier::large_step::LargeStepJointSet;
use rapier3d_f64::prelude::*;

/// A world with a fixed base and `n` free arms, each hung 0.3 m below the base.
fn world(n: usize) -> (PhysicsWorld, RigidBodyHandle, Vec<RigidBodyHandle>) {
    let mut world = PhysicsWorld::new();
    let base = world.bodies.insert(RigidBodyBuilder::fixed());
    let arms = (0..n)
        .map(|i| {
            world.bodies.insert(
                RigidBodyBuilder::dynamic()
                    .translation(Vector::new(i as f64, -0.3, 0.0))
                    .additional_mass_properties(MassProperties::new(
                        Vector::ZERO,
                        2.0,
                        Vector::splat(0.02),
                    )),
            )
        })
        .collect();
    (world, base, arms)
}

fn clearance(name: &str) -> HingeDesign {
    HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)
        .unwrap()
        .name(name)
}

const ANCHOR2: Vector = Vector::new(0.0, 0.3, 0.0);

#[test]
fn clearance_handles_survive_removals_and_stale_ones_find_nothing() {
    let (mut w, base, arms) = world(4);
    let mut set = ClearanceJointSet::new();
    let insert = |set: &mut ClearanceJointSet, w: &mut PhysicsWorld, i: usize, name: &str| {
        let anchor1 = Vector::new(i as f64, 0.0, 0.0);
        let joint = clearance(name)
            .joint(anchor1, ANCHOR2, Vector::Z, Vector::Z)
            .unwrap();
        set.insert(base, arms[i], joint, &w.bodies, &mut w.impulse_joints)
            .unwrap()
    };
    let a = insert(&mut set, &mut w, 0, "a");
    let b = insert(&mut set, &mut w, 1, "b");
    let c = insert(&mut set, &mut w, 2, "c");
    assert_eq!(w.impulse_joints.len(), 3, "one out-of-plane lock per joint");

    let removed = set.remove(a, &mut w.bodies, &mut w.impulse_joints).unwrap();
    assert_eq!(removed.name(), "a");
    assert_eq!(w.impulse_joints.len(), 2, "its lock went with it");
    // The others keep their handles.
    assert_eq!(set.get(b).unwrap().name(), "b");
    assert_eq!(set.get(c).unwrap().name(), "c");
    // The stale handle is refused everywhere, also once a new joint reuses its slot.
    let d = insert(&mut set, &mut w, 3, "d");
    assert_ne!(d, a);
    assert!(set.get(a).is_none() && set.get_mut(a).is_none() && !set.contains(a));
    assert!(
        set.remove(a, &mut w.bodies, &mut w.impulse_joints)
            .is_none()
    );
    assert_eq!(set.get(d).unwrap().name(), "d");
    assert_eq!(set.len(), 3);
    // Insertion order, whatever slot `d` took.
    let order: Vec<_> = set.iter().map(|(h, j)| (h, j.name().to_owned())).collect();
    assert_eq!(order, [(b, "b".into()), (c, "c".into()), (d, "d".into())]);
    // Removing one in the middle keeps the order of the rest.
    set.remove(c, &mut w.bodies, &mut w.impulse_joints).unwrap();
    let names: Vec<_> = set.iter().map(|(_, j)| j.name()).collect();
    assert_eq!(names, ["b", "d"]);
    assert_eq!(w.impulse_joints.len(), 2);
}

#[test]
fn large_step_handles_survive_removals_and_stale_ones_find_nothing() {
    let (mut w, base, arms) = world(4);
    let mut set = LargeStepJointSet::new();
    let insert = |set: &mut LargeStepJointSet, w: &mut PhysicsWorld, i: usize, name: &str| {
        let anchor1 = Vector::new(i as f64, 0.0, 0.0);
        let joint = clearance(name)
            .large_step_joint(anchor1, ANCHOR2, Vector::Z, Vector::Z)
            .unwrap();
        set.insert(base, arms[i], joint, &w.bodies, &mut w.impulse_joints)
            .unwrap()
    };
    let a = insert(&mut set, &mut w, 0, "a");
    let b = insert(&mut set, &mut w, 1, "b");
    let c = insert(&mut set, &mut w, 2, "c");
    // A step, so that the set manages its bodies' substeps.
    set.before_step(
        &mut w.bodies,
        &mut w.impulse_joints,
        &w.integration_parameters,
    );
    w.step();
    set.after_step(&mut w.bodies, &w.impulse_joints);

    assert_eq!(
        set.remove(b, &mut w.bodies, &mut w.impulse_joints)
            .unwrap()
            .name(),
        "b"
    );
    assert_eq!(w.impulse_joints.len(), 2);
    assert_eq!(set.get(a).unwrap().name(), "a");
    assert_eq!(set.get(c).unwrap().name(), "c");
    let d = insert(&mut set, &mut w, 3, "d");
    assert_ne!(d, b);
    assert!(set.get(b).is_none() && set.get_mut(b).is_none() && !set.contains(b));
    assert!(
        set.remove(b, &mut w.bodies, &mut w.impulse_joints)
            .is_none()
    );
    let order: Vec<_> = set.iter().map(|(h, j)| (h, j.name().to_owned())).collect();
    assert_eq!(order, [(a, "a".into()), (c, "c".into()), (d, "d".into())]);
    // The hooks run over the set as it is now.
    set.before_step(
        &mut w.bodies,
        &mut w.impulse_joints,
        &w.integration_parameters,
    );
    w.step();
    set.after_step(&mut w.bodies, &w.impulse_joints);
    assert_eq!(set.len(), 3);
}

/// The drives' handles too: removing one leaves the others' handles and order, a removed drive's
/// handle finds nothing, also after a new drive is inserted, and only the drives left act.
#[test]
fn drive_handles_survive_removals_and_stale_ones_find_nothing() {
    use clearance_joint::rapier::sources::drive::{DriveSet, TorsionSpring};
    let (mut w, base, arms) = world(3);
    let mut drives = DriveSet::new();
    let handles: Vec<_> = (0..3)
        .map(|i| {
            let torque = (i + 1) as f64;
            drives.insert(TorsionSpring::new(base, arms[i], Vector::Z, torque, 0.0).unwrap())
        })
        .collect();
    let removed = drives.remove(handles[1]).expect("a drive of this set");
    assert_eq!(removed.torque_at(0.0), 2.0);
    assert!(drives.get(handles[1]).is_none() && drives.remove(handles[1]).is_none());
    let fresh = drives.insert(TorsionSpring::new(base, arms[1], Vector::Z, 9.0, 0.0).unwrap());
    assert_ne!(fresh, handles[1]);
    assert!(drives.get(handles[1]).is_none());
    assert_eq!(drives.get(handles[0]).unwrap().torque_at(0.0), 1.0);
    assert_eq!(drives.get(handles[2]).unwrap().torque_at(0.0), 3.0);
    // Insertion order: the first, the third, then the fresh one.
    let order: Vec<f64> = drives.iter().map(|(_, d)| d.torque_at(0.0)).collect();
    assert_eq!(order, vec![1.0, 3.0, 9.0]);
    drives.apply(&mut w.bodies);
    let torques: Vec<f64> = arms.iter().map(|&a| w.bodies[a].user_torque().z).collect();
    assert_eq!(torques, vec![1.0, 9.0, 3.0]);
}
