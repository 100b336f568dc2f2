//! The spatial joint sub-cycled ([`ContactIntegration::SubCycled`]): a door on one pin resting
//! edge-loaded and friction-held at robot and game steps with its static balance, a face knock
//! against the explicit joint at a tiny fixed step, and the energy of an elastic door. Runs
//! optimised.

use clearance_joint::model::laws::{Bai, FrictionModel};
use clearance_joint::model::spatial::SpatialModel;
use clearance_joint::prelude::*;
use clearance_joint::rapier::observers::metrics::Impact;
use clearance_joint::scene::Scene;
use clearance_joint::scene::runner::{RunOptions, RunResult, Simulation, TwinKind, Twins};
use rapier3d_f64::prelude::*;

const G: f64 = 9.81;
/// The door: 2 kg, its centre of mass 0.2 m off the hinge axis (y).
const MASS: f64 = 2.0;
const ARM: f64 = 0.2;
/// The pin: bearing radius 6 mm, radial clearance 0.1 mm, width 20 mm.
const R_B: f64 = 0.006;
const C: f64 = 0.1e-3;
const WIDTH: f64 = 0.020;

/// A fixed post and a door (its centre of mass `arm` off the axis along x) whose journal sits
/// centred in the post's bore (axis y), in a world of gravity `gravity` stepped by `control` with `iterations` solver iterations; the pin's law is
/// steel improved-Liu with `friction`, spatial (axial play 0.3 mm, collars of 10 mm), integrated
/// as `integration`. Returns `(world, door, pin)`.
fn door_world(
    arm: f64,
    control: StepControl,
    iterations: usize,
    gravity: f64,
    friction: FrictionModel,
    integration: ContactIntegration,
) -> (ClearanceWorld, RigidBodyHandle, ClearanceJointHandle) {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -gravity, 0.0);
    rapier.integration_parameters.num_solver_iterations = iterations;
    let post = rapier.bodies.insert(RigidBodyBuilder::fixed());
    let door = rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(arm, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                MASS,
                Vector::new(0.0150667, 0.0267333, 0.0416667),
            ))
            .can_sleep(false),
    );
    let pin = HingeDesign::steel_improved_liu(R_B, C, WIDTH)
        .unwrap()
        .friction(friction)
        .model(ClearanceModel::Spatial(SpatialModel::steel(0.3e-3, 0.010)))
        .integration(integration)
        .joint(
            Vector::ZERO,
            Vector::new(-arm, 0.0, 0.0),
            Vector::Y,
            Vector::Y,
        )
        .unwrap();
    let mut world = ClearanceWorld::new(rapier, control);
    let pin = world.insert_clearance(post, door, pin).unwrap();
    (world, door, pin)
}

/// A door on one spatial pin, turned by a torque `tau` about the hinge that friction holds,
/// comes to rest at world steps of 1 ms (one solver iteration) and of 1/60 s (Rapier's four) at
/// the default tolerance, with its static balance by hand: the contact carries the weight
/// (`F = m g` up, within 0.02 %: the sub-cycle holds the weight's balance over the step, and
/// ROS2 leaves no offset of the state's curvature on it; 19.627 N of 19.620 N at 1 ms without)
/// and the torque (its moment about the door's centre of mass is
/// `-tau` about the axis, within 0.5 % of `m g ARM`); the weight's moment about the pin,
/// `m g ARM`, less the face's (its force at its resultant's distance from the axis: the tilted
/// shoulder bears at its rim) is held by the bore's two edges as a couple,
/// `F_edge = (m g ARM - F_face x_face)/l` on each, `l` the distance between the edges'
/// resultants along the axis, within 1 %, and `l` lies within the width. The door swings no
/// more: it creeps at the regularised friction's slip (below 1e-3 rad/s; 7e-4 at 1 ms).
#[test]
fn a_door_rests_edge_loaded_and_friction_held_with_its_static_balance() {
    let weight = MASS * G;
    let tau = 0.05;
    for (dt, iterations) in [(1e-3, 1), (1.0 / 60.0, 4)] {
        let control = StepControl {
            tolerance: 0.0075,
            ..StepControl::fixed(dt)
        };
        let friction = FrictionModel::Bai(Bai::DRY);
        let sub_cycled = ContactIntegration::SubCycled;
        let (mut world, door, pin) = door_world(ARM, control, iterations, G, friction, sub_cycled);
        world.rapier.bodies[door].add_torque(Vector::new(0.0, tau, 0.0), true);
        world.step_to(5.0).unwrap();
        let joint = world.clearance.get(pin).unwrap();
        let [_, on_door] = joint.last_wrenches().unwrap();
        let s = joint.report().spatial.unwrap();
        let spin = world.rapier.bodies[door].angvel().length();
        let l = (s.edge_point[1] - s.edge_point[0]).y.abs();
        let face = s.face_force[0] * s.face_point[0].x + s.face_force[1] * s.face_point[1].x;
        let couple = (weight * ARM - face) / l;
        println!(
            "dt {dt:.3e} s, {iterations} iteration(s): force {:?} N (weight {weight:.4}), \
             torque {:?} N m, edges {:.3}/{:.3} N at {l:.5} m apart (couple {couple:.3} N), faces \
             {:.3}/{:.3} N (moment {face:.4} N m), tilt {:?} rad, spin {spin:.2e} rad/s, {} steps",
            on_door.force,
            on_door.torque,
            s.edge_force[0],
            s.edge_force[1],
            s.face_force[0],
            s.face_force[1],
            s.tilt,
            world.steps(),
        );
        assert!((on_door.force - Vector::new(0.0, weight, 0.0)).length() < 2e-4 * weight);
        let torque = on_door.torque + Vector::new(0.0, tau, 0.0);
        assert!(torque.length() < 5e-3 * weight * ARM, "{torque:?}");
        for f in s.edge_force {
            assert!((f / couple - 1.0).abs() < 1e-2, "{f} against {couple}");
        }
        assert!(l > 0.5 * WIDTH && l <= WIDTH, "{l}");
        // The regularised friction creeps under a steady torque: the edges slip at a few um/s.
        assert!(spin < 1e-3, "{spin}");
        assert!(world.guards().is_clean(), "{:?}", world.guards());
    }
}

/// What one face knock did: the face's peak force (N), the shoulder's deepest penetration (m),
/// and the journal's axial speed after it (m/s).
#[derive(Debug)]
struct Knock {
    peak: f64,
    depth: f64,
    separation: f64,
    /// The least and largest `delta_dot0` the joint reported in contact, m/s.
    impact_rates: (f64, f64),
}

/// A journal (its centre of mass on the pin) moving along its axis at 0.1 m/s without gravity or friction knocks on the
/// bearing's upper face (the play's half, 0.15 mm, away), integrated as `integration` at steps
/// `control`; read at every state (the sub-steps of a sub-cycled joint).
fn face_knock(control: StepControl, integration: ContactIntegration) -> Knock {
    let (mut world, door, pin) = door_world(0.0, control, 1, 0.0, FrictionModel::None, integration);
    world.rapier.bodies[door].set_linvel(Vector::new(0.0, 0.1, 0.0), true);
    let (mut peak, mut depth) = (0.0_f64, 0.0_f64);
    let mut impact_rates = (f64::INFINITY, 0.0_f64);
    while world.time() < 3e-3 {
        world.step(3e-3).unwrap();
        let joint = world.clearance.get(pin).unwrap();
        let mut seen: Vec<(f64, f64)> = joint
            .substeps()
            .iter()
            .map(|s| (s.force.normal_force, s.state.penetration))
            .collect();
        let r = joint.report();
        seen.push((r.force.normal_force, r.state.penetration));
        if r.state.penetration > 0.0 {
            impact_rates = (
                impact_rates.0.min(r.impact_rate),
                impact_rates.1.max(r.impact_rate),
            );
        }
        for (f, d) in seen {
            peak = peak.max(f);
            depth = depth.max(d);
        }
    }
    let separation = world.rapier.bodies[door].linvel().y;
    Knock {
        peak,
        depth,
        separation,
        impact_rates,
    }
}

/// A face knock sub-cycled inside world steps of 1 ms matches the explicit joint at fixed 1e-7 s
/// steps: peak force, depth and separation speed within 1e-3 at the tolerance 1e-4, and closer
/// as the tolerance tightens from the default.
#[test]
fn a_face_knock_matches_the_explicit_joint_at_a_tiny_step() {
    let reference = face_knock(StepControl::fixed(1e-7), ContactIntegration::Explicit);
    println!("explicit at 1e-7 s: {reference:?}");
    assert!(reference.peak > 100.0 && reference.separation < -0.05);
    let mut last = f64::INFINITY;
    for tolerance in [0.0075, 1e-3, 1e-4] {
        let control = StepControl {
            tolerance,
            ..StepControl::fixed(1e-3)
        };
        let k = face_knock(control, ContactIntegration::SubCycled);
        let errors = [
            k.peak / reference.peak - 1.0,
            k.depth / reference.depth - 1.0,
            k.separation / reference.separation - 1.0,
        ];
        let worst = errors.iter().map(|e| e.abs()).fold(0.0, f64::max);
        println!("sub-cycled at tolerance {tolerance}: {k:?}, errors {errors:?}");
        assert!(worst <= last.max(1e-4), "{worst} after {last}");
        last = worst;
    }
    assert!(last < 1e-3, "{last}");
}

/// A face knock sub-cycled at world steps of 10 us, which its contact spans (about 90 us, nine
/// steps), keeps the approach speed as `delta_dot0` from step to step (within 1e-3 of 0.1 m/s,
/// as the explicit joint at 1e-7 s), and with it the explicit joint's peak, depth and separation
/// speed within 1e-3: each step's end evaluates the regions from where the sub-cycle left them,
/// not from where Rapier's second pass restored them (the state before the step), which read
/// every step in contact as a new onset and its crossing speed across the whole step.
#[test]
fn a_face_knock_over_several_world_steps_keeps_its_impact_rate() {
    let reference = face_knock(StepControl::fixed(1e-7), ContactIntegration::Explicit);
    let control = StepControl {
        tolerance: 1e-4,
        ..StepControl::fixed(1e-5)
    };
    let k = face_knock(control, ContactIntegration::SubCycled);
    println!("explicit at 1e-7 s: {reference:?}\nsub-cycled at 1e-5 s: {k:?}");
    for rate in [
        reference.impact_rates.0,
        reference.impact_rates.1,
        k.impact_rates.0,
        k.impact_rates.1,
    ] {
        assert!((rate / 0.1 - 1.0).abs() < 1e-3, "{rate}");
    }
    let errors = [
        k.peak / reference.peak - 1.0,
        k.depth / reference.depth - 1.0,
        k.separation / reference.separation - 1.0,
    ];
    println!("errors {errors:?}");
    assert!(errors.iter().all(|e| e.abs() < 1e-3), "{errors:?}");
}

/// The door with its damping and friction off (the bore's law without damping, the faces'
/// restitution 1) sub-cycled on its adaptive steps over 0.3 s of knocks and edge contacts (the
/// runner's energy balance): its energy never grows (1e-9 of its scale), and its loss is the
/// integration's error: ROS2 damps what it does not resolve, and the loss falls with the
/// tolerance (at most 1e-3 of the energy's scale at 0.001, and ten times less than at the
/// default 0.0075).
#[test]
fn an_elastic_sub_cycled_door_keeps_its_energy() {
    let text = std::fs::read_to_string("assets/door_hinge.ron").unwrap();
    let elastic = text.replace(
        "collar_radius: 0.010))",
        "collar_radius: 0.010), face: (stiffness: 2.27e9, restitution: 1.0))",
    );
    assert_ne!(text, elastic, "the door's model line");
    let error = |tolerance: &str| {
        let scene = Scene::from_ron(&elastic, "door_hinge (elastic)")
            .unwrap()
            .with_overrides(&[
                "hinge.eta_s=0",
                "hinge.friction=None",
                "run.contact_integration=SubCycled",
                "run.end_s=0.3",
                &format!("run.tolerance={tolerance}"),
            ])
            .unwrap();
        let options = RunOptions {
            twins: Twins::ClearanceOnly,
            skip_rows: false,
        };
        let r = Simulation::new(&scene, options).unwrap().run().unwrap();
        let s = r.summary().twins["clearance"].clone();
        println!(
            "tolerance {tolerance}: {} onsets, energy error {:?}, growth {:?}",
            s.onsets, s.invariants.energy_error, s.invariants.energy_growth
        );
        assert!(s.onsets > 5);
        assert!(s.invariants.energy_growth.unwrap() < 1e-9);
        s.invariants.energy_error.unwrap()
    };
    let (default, tight) = (error("0.0075"), error("0.001"));
    assert!(tight < 1e-3, "{tight}");
    assert!(tight < 0.1 * default, "{tight} against {default}");
}

/// The cantilever (`assets/cantilever.ron`: a 2 kg shaft whose weight's moment tilts its
/// journal onto the bore's two edges, the improved law's damping on, no friction) over its
/// first 0.05 s, the scene runner's clearance twin at the default tolerance, integrated as
/// `integration`.
fn cantilever(integration: &str, overrides: &[&str]) -> RunResult {
    let mut set = vec![
        format!("run.contact_integration={integration}"),
        "run.end_s=0.05".to_string(),
    ];
    set.extend(overrides.iter().map(|s| s.to_string()));
    run_cantilever(&set, true)
}

/// `assets/cantilever.ron` with `set`, the scene runner's clearance twin, its rows skipped or
/// kept.
fn run_cantilever(set: &[String], skip_rows: bool) -> RunResult {
    let scene = Scene::load(std::path::Path::new("assets/cantilever.ron"))
        .unwrap()
        .with_overrides(set)
        .unwrap();
    let options = RunOptions {
        twins: Twins::ClearanceOnly,
        skip_rows,
    };
    Simulation::new(&scene, options).unwrap().run().unwrap()
}

/// The sub-cycled cantilever's contact list holds every state its hinge spent in contact: the
/// contact in which the shaft comes to rest on the edges (from about 18 ms on, still closed at
/// the end) begins at the last sub-step of a world step, and its onset is the one the step's
/// end reports. The list's largest force and deepest penetration are the hinge's over the run,
/// its durations add up to the time in contact, its last contact lasts to the end, and its
/// window after 25 ms (the contact the shaft rests in) matches the explicit joint's at the
/// default tolerance (largest force and deepest penetration within 1 %: 203.460 N and 30.7202 um
/// against 203.463 N and 30.7204 um).
#[test]
fn a_sub_cycled_cantilever_lists_the_contact_it_rests_in() {
    let (end, window) = (0.05, 0.025);
    let read = |integration: &str| {
        let r = cantilever(integration, &[]);
        let twin = r.twin(TwinKind::Clearance).unwrap();
        let rec = twin.hinge_recorders()["hinge"];
        (rec.contacts().to_vec(), rec.metrics().clone())
    };
    // The window's largest force and deepest penetration, N and um.
    let in_window = |contacts: &[Impact]| {
        contacts
            .iter()
            .filter(|i| i.onset_t_s + i.duration_s >= window)
            .fold((0.0f64, 0.0f64), |(f, d), i| {
                (f.max(i.peak_force_n), d.max(i.max_penetration_um))
            })
    };
    let (contacts, m) = read("SubCycled");
    let (largest, deepest) = contacts.iter().fold((0.0f64, 0.0f64), |(f, d), i| {
        (f.max(i.peak_force_n), d.max(i.max_penetration_um))
    });
    let time: f64 = contacts.iter().map(|i| i.duration_s).sum();
    let last = contacts.last().unwrap();
    let (explicit, _) = read("Explicit");
    let (sub, reference) = (in_window(&contacts), in_window(&explicit));
    println!(
        "sub-cycled: {} contacts, largest {largest:.3} N (hinge {:.3} N), deepest {deepest:.4} um \
         (hinge {:.4} um), time in contact {time:.6} s (hinge {:.6} s), last from {:.5} s for \
         {:.5} s; window {sub:?}, explicit {reference:?}",
        contacts.len(),
        m.peak_force_n,
        m.max_penetration_um,
        m.contact_fraction * end,
        last.onset_t_s,
        last.duration_s,
    );
    assert_eq!(largest, m.peak_force_n);
    assert_eq!(deepest, m.max_penetration_um);
    assert!((time - m.contact_fraction * end).abs() < 1e-9 * end);
    assert!((last.onset_t_s + last.duration_s - end).abs() < 1e-9);
    assert!(
        (sub.0 / reference.0 - 1.0).abs() < 1e-2,
        "{sub:?} {reference:?}"
    );
    assert!(
        (sub.1 / reference.1 - 1.0).abs() < 1e-2,
        "{sub:?} {reference:?}"
    );
}

/// The sub-cycled cantilever's energy balance: the work its contact's damping did is what the
/// sub-steps' forces did (`ClearanceJoint::step_dissipation`), and the bodies' energy plus that
/// work never grows (1e-9 of the energy's scale; the power at each world step's start held over
/// the step made 1.5 % of it), the balance's error is the integration's (below 1e-3), and the
/// work is the explicit joint's at the default tolerance within 1e-3 (0.031718 J against
/// 0.031720 J). With the damping off the energy never grows either; the integration's loss is
/// 2.3e-2 of the scale at the default tolerance (ROS2 damps the edges' rocking it does not
/// resolve; 4.8e-4 at the tolerance 0.001, the explicit joint's error 7.6e-3).
#[test]
fn a_sub_cycled_cantilever_balances_its_energy() {
    let read = |integration: &str, overrides: &[&str]| {
        let r = cantilever(integration, overrides);
        r.summary().twins["clearance"].invariants.clone()
    };
    let sub = read("SubCycled", &[]);
    let explicit = read("Explicit", &[]);
    let elastic = read("SubCycled", &["hinge.eta_s=0"]);
    println!(
        "damped: growth {:?}, error {:?}, dissipated {:.6} J (explicit {:.6} J); undamped: \
         growth {:?}, error {:?}",
        sub.energy_growth,
        sub.energy_error,
        sub.dissipated_j,
        explicit.dissipated_j,
        elastic.energy_growth,
        elastic.energy_error,
    );
    assert!(sub.energy_growth.unwrap() < 1e-9);
    assert!(sub.energy_error.unwrap() < 1e-3);
    assert!((sub.dissipated_j / explicit.dissipated_j - 1.0).abs() < 1e-3);
    assert!(elastic.energy_growth.unwrap() < 1e-9);
    assert!(elastic.energy_error.unwrap() < 5e-2);
}

/// The cantilever over its first 30 ms with the bodies' motion in its rows, written at every
/// millisecond: sub-cycled at fixed world steps of 1 ms (its rows are the world states), or
/// explicit at adaptive steps of at most 1 us at the tolerance 0.001 (a converged run). Returns
/// the rows' times and the shaft's velocity.
fn cantilever_states(sub_cycled: bool) -> (Vec<f64>, Vec<Vector>) {
    let mut set = vec![
        "run.end_s=0.03",
        "run.output_interval_s=1e-3",
        "run.body_motion=true",
    ];
    set.extend(if sub_cycled {
        [
            "run.step=Fixed",
            "run.dt_s=1e-3",
            "run.contact_integration=SubCycled",
        ]
    } else {
        [
            "run.max_dt_s=1e-6",
            "run.tolerance=0.001",
            "run.contact_integration=Explicit",
        ]
    });
    let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
    let result = run_cantilever(&set, false);
    let table = &result.twins[0].table;
    let v = table
        .columns(&["shaft_vx_m_s", "shaft_vy_m_s", "shaft_vz_m_s"])
        .unwrap();
    let velocity = (0..v[0].len())
        .map(|k| Vector::new(v[0][k], v[1][k], v[2][k]))
        .collect();
    (table.column("t_s").unwrap(), velocity)
}

/// The rows of a spatial sub-cycled run give the bodies' velocity at the world states: the
/// cantilever's shaft falls through its clearance, touches the bore at 10 and 19 ms and lands on
/// its edges from 21 ms on, at world steps of 1 ms; at every state to 30 ms its velocity in the
/// rows is the converged explicit run's within 1e-3 of its largest speed (0.2 m/s; measured
/// 5.1e-4, at 10 ms, in contact). Read from Rapier's velocities (the mean over a step, short of
/// the part of its contact's impulse delivered with the next step) they were 4.1e-2 of it off
/// (at 23 ms); with the joint's velocity at the state added to the reaction solve's (Rapier's
/// carried over their lag, which the joint's velocity already holds) 0.22 (at 24 ms).
#[test]
fn a_spatial_sub_cycled_runs_rows_hold_the_velocity_at_the_state() {
    let (t, sub) = cantilever_states(true);
    let (t_fine, fine) = cantilever_states(false);
    assert_eq!(t, t_fine);
    let scale = fine.iter().fold(0.0f64, |m, v| m.max(v.length()));
    let (mut worst, mut at) = (0.0f64, 0.0);
    for k in 0..t.len() {
        let off = (sub[k] - fine[k]).length() / scale;
        if off > worst {
            (worst, at) = (off, t[k]);
        }
    }
    println!("largest speed {scale:.4e} m/s; rows off by at most {worst:.2e} of it, at {at} s");
    assert!(scale > 0.15, "{scale}");
    assert!(worst < 1e-3, "{worst:.3e} of {scale:.3e} m/s at {at} s");
}
