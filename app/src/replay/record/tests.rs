use super::shapes::body_shapes;
use super::thinning::force;
use super::*;

#[test]
fn equivalent_box_of_a_uniform_box_is_the_box() {
    // A 2 x 3 x 4 m box of 12 kg: J = m/12 (b^2 + c^2), ...
    let m: f64 = 12.0;
    let (a, b, c): (f64, f64, f64) = (2.0, 3.0, 4.0);
    let j = Vector::new(
        m / 12.0 * (b * b + c * c),
        m / 12.0 * (a * a + c * c),
        m / 12.0 * (a * a + b * b),
    );
    let mut bodies = RigidBodySet::new();
    let h = bodies.insert(
        RigidBodyBuilder::dynamic().additional_mass_properties(MassProperties::new(
            Vector::ZERO,
            m,
            j,
        )),
    );
    clearance_joint::rapier::observers::reaction::prepare_mass_properties(&mut bodies);
    let shapes = body_shapes(&bodies[h], &ColliderSet::new());
    let ReplayShape::Box { half_extents_m, .. } = shapes[0] else {
        panic!("expected a box, got {shapes:?}");
    };
    for (got, want) in half_extents_m.iter().zip([1.0, 1.5, 2.0]) {
        assert!((got - want).abs() < 1e-9, "{half_extents_m:?}");
    }
}

#[test]
fn thinning_keeps_contacts_and_the_last_state() {
    let mut r = ReplayRecorder::new(0.1, 0.01).unwrap();
    let bodies = RigidBodySet::new();
    for k in 0..=150 {
        r.record(k as f64 * 1e-3, &bodies, &[]);
    }
    let rec = r.finish();
    let t: Vec<f64> = rec.frames.iter().map(|f| f.t).collect();
    // Every 0.1 s, and the last state.
    assert_eq!(t.len(), 3, "{t:?}");
    assert_eq!(t[0], 0.0);
    assert!((t[1] - 0.1).abs() < 1e-12 && t[2] == 0.15, "{t:?}");
    assert!(ReplayRecorder::new(0.1, 0.2).is_err());
}

#[test]
fn the_cap_halves_frames_and_keeps_the_first_and_last() {
    let mut r = ReplayRecorder::new(1e-3, 1e-3).unwrap().with_max_frames(10);
    let bodies = RigidBodySet::new();
    for k in 0..=100 {
        r.record(k as f64 * 1e-3, &bodies, &[]);
    }
    let rec = r.finish();
    assert!(rec.frames.len() <= 10, "{}", rec.frames.len());
    assert_eq!(rec.frames[0].t, 0.0);
    assert_eq!(rec.frames.last().unwrap().t, 0.1);
    assert!(rec.interval_s > 1e-3 && rec.contact_interval_s > 1e-3);
    assert!(ReplayRecorder::new(f64::NAN, 0.1).is_err());
}

/// A sub-cycled joint's impact inside one 1/60 s step is in the recording at its sub-steps:
/// the recording's largest force is the largest sub-step force, at that sub-step's time,
/// where the steps' own states see nothing of the impact.
#[test]
fn a_sub_cycled_impact_inside_a_step_is_recorded_at_its_sub_steps() {
    use clearance_joint::prelude::*;
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -9.81, 0.0);
    let base = rapier.bodies.insert(RigidBodyBuilder::fixed());
    let arm = rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.0, -0.3, 0.0))
            .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02)))
            .can_sleep(false),
    );
    let pin = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)
        .unwrap()
        .integration(ContactIntegration::SubCycled)
        .joint(
            Vector::ZERO,
            Vector::new(0.0, 0.3, 0.0),
            Vector::Z,
            Vector::Z,
        )
        .unwrap();
    let mut world = ClearanceWorld::new(rapier, StepControl::fixed(1.0 / 60.0));
    let hinge = world.insert_clearance(base, arm, pin).unwrap();
    let mut r = ReplayRecorder::new(1.0 / 60.0, 1e-5).unwrap();
    let (b, c) = (&world.rapier.bodies, &world.rapier.colliders);
    r.track_body("base", "clearance", base, b, c);
    r.track_body("arm", "clearance", arm, b, c);
    r.track_journal("pin", "clearance", 0, hinge, &world.clearance)
        .unwrap();
    let (mut peak, mut peak_t, mut at_steps) = (0.0_f64, 0.0, 0.0_f64);
    while world.time() < 0.1 {
        let t0 = world.time();
        world.step(0.1).unwrap();
        r.record(world.time(), &world.rapier.bodies, &[&world.clearance]);
        let j = world.clearance.get(hinge).unwrap();
        at_steps = at_steps.max(j.report().force.normal_force);
        for s in j.substeps() {
            if s.force.on_journal.length() > peak {
                (peak, peak_t) = (s.force.on_journal.length(), t0 + s.t);
            }
        }
    }
    let recording = r.finish();
    let kept = recording
        .frames
        .iter()
        .max_by(|a, b| force(a).total_cmp(&force(b)))
        .unwrap();
    assert!(
        peak > 5.0 * at_steps.max(19.62),
        "{peak} N inside, {at_steps} N at the steps"
    );
    assert_eq!(force(kept), peak);
    assert!(
        (kept.t - peak_t).abs() < 1e-12,
        "{} against {peak_t}",
        kept.t
    );
}

#[test]
fn a_spatial_frame_carries_the_joints_tilt_and_edge_forces() {
    use clearance_joint::model::spatial::SpatialModel;
    use clearance_joint::prelude::*;
    // The library's spatial example: an arm 0.2 m out from a vertical pin tilts its journal
    // onto both edges of the bore.
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -9.81, 0.0);
    rapier.integration_parameters.num_solver_iterations = 1;
    let post = rapier.bodies.insert(RigidBodyBuilder::fixed());
    let arm = rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.2, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                2.0,
                Vector::splat(0.02),
            )),
    );
    // Explicit: the frames are compared with the report at each step's end, where the explicit
    // joint's steps resolve the contacts.
    let pin = HingeDesign::steel_improved_liu(0.006, 0.1e-3, 0.020)
        .unwrap()
        .integration(ContactIntegration::Explicit)
        .model(ClearanceModel::Spatial(SpatialModel::steel(0.3e-3, 0.010)))
        .joint(
            Vector::ZERO,
            Vector::new(-0.2, 0.0, 0.0),
            Vector::Y,
            Vector::Y,
        )
        .unwrap();
    let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, 0.0075));
    let hinge = world.insert_clearance(post, arm, pin).unwrap();
    let mut r = ReplayRecorder::new(1e-3, 1e-5).unwrap();
    let (b, c) = (&world.rapier.bodies, &world.rapier.colliders);
    r.track_body("post", "clearance", post, b, c);
    r.track_body("arm", "clearance", arm, b, c);
    r.track_journal("pin", "clearance", 0, hinge, &world.clearance)
        .unwrap();
    let mut seen = false;
    while world.time() < 0.03 {
        world.step(0.03).unwrap();
        r.record(world.time(), &world.rapier.bodies, &[&world.clearance]);
        let joint = world.clearance.get(hinge).unwrap();
        let s = joint.report().spatial.unwrap();
        let last = r.frames().last().unwrap();
        if last.t != world.time() || s.edge_force[0] <= 0.0 || s.edge_force[1] <= 0.0 {
            continue;
        }
        // A kept frame in edge contact: its values are the joint's report's.
        seen = true;
        let f = last.journals[0].spatial.expect("a spatial frame");
        assert_eq!(f.edge_force_n, s.edge_force);
        assert_eq!(f.face_force_n, s.face_force);
        // Tilt in the recorder's u/v is the report's (the joint's transverse axis is u).
        assert!((f.tilt_rad[0].hypot(f.tilt_rad[1]) - s.tilt[0].hypot(s.tilt[1])).abs() < 1e-12);
        assert!((f.axial_m - s.axial_offset).abs() < 1e-12);
        // Each edge acts at its end of the width, on the bore's wall.
        let w = 0.020;
        let [lo, hi] = f.edge_at_m;
        assert!(lo[2] < 0.0 && lo[2] >= -0.5 * w - 1e-9, "{lo:?}");
        assert!(hi[2] > 0.0 && hi[2] <= 0.5 * w + 1e-9, "{hi:?}");
        assert!((lo[0].hypot(lo[1]) - 0.006).abs() < 0.2e-3, "{lo:?}");
    }
    assert!(seen, "no kept frame with both edges in contact");
    // A planar joint's frame serializes without the spatial part.
    let planar = serde_json::to_string(&JournalFrame::default()).unwrap();
    assert!(!planar.contains("spatial"), "{planar}");
}
