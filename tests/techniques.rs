//! The sub-cycle's techniques one by one ([`SubCycleTechniques`]): each switch turned off
//! changes what it stands for (more sub-steps, a joint that no longer ends where its sub-cycle
//! put it, energy gained). The damping's and the stabilisation's effect on a damped contact's
//! depth against its ODE is in `tests/references.rs`. Runs optimised.

use clearance_joint::model::laws::{Coulomb, FrictionModel, Hertz, NormalModel};
use clearance_joint::prelude::*;
use clearance_joint::scene::Scene;
use clearance_joint::scene::runner::{RunOptions, Simulation, TwinKind, Twins};
use rapier3d_f64::prelude::*;
use rapier3d_f64::utils::AngularInertiaOps;

#[path = "support/turning_arm.rs"]
mod turning_arm;
use turning_arm::{penetrations, turning_arm};

/// A 2 kg journal hanging in a fixed bearing (radius 10 mm, clearance 0.2 mm, the improved law,
/// Coulomb friction 0.3 regularised over 1e-6 m/s), turned by 0.0196 N m (friction holds it),
/// sub-cycled with `techniques` in 1 ms steps for `end` s: the sub-steps it took.
fn held_journal_substeps(techniques: SubCycleTechniques, end: f64) -> u64 {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -9.81, 0.0);
    rapier.integration_parameters.num_solver_iterations = 1;
    let mut world = ClearanceWorld::new(rapier, StepControl::fixed(1e-3));
    let base = world.rapier.bodies.insert(RigidBodyBuilder::fixed());
    let journal = world.rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.01)))
            .can_sleep(false),
    );
    world.rapier.bodies[journal].add_torque(Vector::new(0.0, 0.0, 2.0 * 0.0098), true);
    let pin = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)
        .unwrap()
        .friction(FrictionModel::Coulomb(Coulomb::new(0.3, 1e-6).unwrap()))
        .integration(ContactIntegration::SubCycled)
        .sub_cycle_techniques(techniques)
        .joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
        .unwrap();
    let pin = world.insert_clearance(base, journal, pin).unwrap();
    let mut substeps = 0;
    while world.time() < end {
        world.step(end).unwrap();
        substeps += world.clearance.get(pin).unwrap().substeps().len() as u64;
    }
    assert!(world.guards().is_clean(), "{:?}", world.guards());
    substeps
}

/// With friction explicit at each sub-step, a journal that friction holds needs sub-steps
/// within friction's stability limit near zero slip (about 5e-7 s here, friction's slope
/// `mu/v_eps` on the journal's 2 kg under its weight): many times the implicit slip's, which the
/// contact's period sets.
#[test]
fn explicit_friction_needs_more_sub_steps_on_a_sticking_journal() {
    let on = SubCycleTechniques::default();
    let (implicit, explicit) = (
        held_journal_substeps(on, 0.2),
        held_journal_substeps(on.implicit_friction(false), 0.2),
    );
    println!("sub-steps over 0.2 s: implicit friction {implicit}, explicit {explicit}");
    assert!(explicit > 10 * implicit, "{implicit} against {explicit}");
}

/// The turning arm on the improved law at 1 ms, one iteration: the largest relative difference
/// between the penetration the pin reports from its last sub-step and the one at Rapier's poses,
/// over the steps in contact (0.3 s).
fn end_mismatch(techniques: SubCycleTechniques) -> f64 {
    let law = HingeDesign::steel_improved_liu(0.006, 0.1e-3, 0.012)
        .unwrap()
        .normal;
    let (mut world, [upper, lower], pin) = turning_arm(law, 1e-3, 1, techniques, false);
    let mut worst = 0.0f64;
    while world.time() < 0.3 {
        world.step(0.3).unwrap();
        let (reported, posed) = penetrations(&world, [upper, lower], pin);
        if reported > 0.0 || posed > 0.0 {
            let off = (posed - reported).abs() / reported.abs().max(posed.abs()).max(1e-7);
            worst = worst.max(off);
        }
    }
    worst
}

/// Rapier corrects its revolute's drift after each step; the sub-cycle moves the pair by as
/// much. Without it the pin's bearing ends elsewhere than its sub-cycle put it: the penetration
/// at Rapier's poses leaves the reported one by more than 1 % (within 1 % with it:
/// `tests/sub_cycling.rs`).
#[test]
fn without_the_stabilisation_the_pin_does_not_end_where_its_sub_cycle_put_it() {
    let on = end_mismatch(SubCycleTechniques::default());
    let off = end_mismatch(SubCycleTechniques::default().stabilisation(false));
    println!("largest mismatch: with the stabilisation {on:.3e}, without {off:.3e}");
    assert!(on < 0.01, "{on:.3e}");
    assert!(off > 0.01, "{off:.3e}");
}

/// The turning arm on an undamped Hertz pin at 1/60 s with Rapier's four iterations for 1 s:
/// `(largest energy gain beyond the torque's work over the largest energy, guards clean, the
/// lower link's final position)`; `None` when the world refuses a step.
fn game_step_arm(techniques: SubCycleTechniques, both: bool) -> Option<(f64, bool, Vector)> {
    let hertz = NormalModel::Hertz(Hertz::new(1e10, 1.5).unwrap());
    let (mut world, [upper, lower], _) = turning_arm(hertz, 1.0 / 60.0, 4, techniques, both);
    let energy = |world: &ClearanceWorld| -> f64 {
        [upper, lower]
            .map(|h| {
                let b = &world.rapier.bodies[h];
                let w = b.angvel();
                let i = b.mass_properties().effective_world_inv_inertia.inverse();
                0.5 * b.mass() * b.linvel().length_squared() + 0.5 * w.dot(i * w)
            })
            .iter()
            .sum()
    };
    world.step(1.0).ok()?;
    let (mut work, mut worst, mut scale) = (0.0, 0.0f64, 0.0f64);
    let start = energy(&world);
    while world.time() < 1.0 {
        let turned = *world.rapier.bodies[upper].rotation();
        world.step(1.0).ok()?;
        let turn = *world.rapier.bodies[upper].rotation() * turned.inverse();
        work += 2.0 * turn.to_scaled_axis().z;
        let e = energy(&world);
        scale = scale.max(e);
        worst = worst.max(e - start - work);
    }
    let clean = world.guards().is_clean();
    Some((
        worst / scale,
        clean,
        world.rapier.bodies[lower].translation(),
    ))
}

/// At 1/60 s each step spans many impacts of the pin while the arm turns under it. Each
/// sub-cycle going on from where the last one left the pin, the arm gains no energy beyond
/// 5 % of its largest (Rapier's velocities read at the step's ends); started from Rapier's
/// state instead it gains more, trips a guard or is refused. With the shoulder a second
/// sub-cycled pin, the continuity's rounds over the two pins move the result.
#[test]
fn without_the_continuation_a_pin_at_game_steps_gains_energy() {
    let all = SubCycleTechniques::default();
    let (gain, clean, _) = game_step_arm(all, false).expect("the arm at 1/60 s");
    println!("all on: gain {gain:+.3e} of the largest energy, guards clean {clean}");
    assert!(gain < 0.05 && clean, "{gain:+.3e}, clean {clean}");
    let off = game_step_arm(all.continuation(false), false);
    println!("continuation off: {off:?}");
    assert!(
        off.is_none_or(|(gain, clean, _)| gain > 0.05 || !clean),
        "{off:?}"
    );
    let (_, _, rounds) = game_step_arm(all, true).expect("two pins at 1/60 s");
    let one = game_step_arm(all.continuity_rounds(false), true);
    println!("two pins, lower link at {rounds:?}; one round of continuity: {one:?}");
    assert!(one.is_none_or(|(_, _, at)| at != rounds), "{one:?}");
}

/// The door (`assets/door_hinge.ron`, sub-cycled, its first 0.06 s: the knock on the face):
/// its measured hinge's sub-steps and first impact's peak force, with `off` switched off.
fn door(off: Option<&str>) -> (u64, f64) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/door_hinge.ron");
    let mut set = vec![
        "run.end_s=0.06".to_string(),
        "run.contact_integration=SubCycled".to_string(),
    ];
    set.extend(off.map(|name| format!("run.sub_cycle.{name}=false")));
    let scene = Scene::load(&path).unwrap().with_overrides(&set).unwrap();
    let options = RunOptions {
        twins: Twins::ClearanceOnly,
        skip_rows: true,
    };
    let r = Simulation::new(&scene, options).unwrap().run().unwrap();
    let rec = r.twin(TwinKind::Clearance).unwrap().hinge_recorders()["hinge"];
    let peak = rec.contacts().first().expect("the knock").peak_force_n;
    (rec.substeps_recorded(), peak)
}

/// The spatial sub-cycle: with a zero Jacobian (ROS2 explicit) the stiff face's knock needs
/// more sub-steps (measured 3.0 times over 0.2 s); with the Jacobian retaken at every sub-step
/// the result moves (ROS2's stages use it) but each stays about within the 1 % the first
/// impacts are held to, so within 2 % of each other (here 2886.4 and 2921.3 N, the converged
/// knock 2916.0 N; with both twins over 0.2 s 0.61 % below and 0.06 % above it:
/// `cargo bench --bench ablation -- --quick door`).
#[test]
fn the_spatial_sub_cycles_jacobian_sets_its_sub_steps() {
    let (steps, peak) = door(None);
    let (explicit_steps, _) = door(Some("implicit_spatial"));
    let (fresh_steps, fresh_peak) = door(Some("jacobian_reuse"));
    println!(
        "sub-steps: {steps} (peak {peak:.3} N), zero Jacobian {explicit_steps}, Jacobian at \
         every sub-step {fresh_steps} (peak {fresh_peak:.3} N)"
    );
    assert!(explicit_steps as f64 > 1.3 * steps as f64);
    assert!(fresh_peak != peak || fresh_steps != steps);
    assert!((fresh_peak / peak - 1.0).abs() < 2e-2);
}

/// The scene's `run.sub_cycle` sets each switch by name; a misspelt one is refused, and so is
/// a switch turned off where nothing reads it (an explicit run), naming the field.
#[test]
fn the_scenes_sub_cycle_switches_reach_the_joint() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/solar_panel.ron");
    let base = Scene::load(&path).unwrap();
    for (name, _) in SubCycleTechniques::default().switches() {
        let scene = base
            .with_overrides(&[
                "run.contact_integration=SubCycled".to_string(),
                format!("run.sub_cycle.{name}=false"),
            ])
            .unwrap();
        let off = scene.run.sub_cycle.switches();
        assert!(off.iter().all(|(n, on)| (*n == name) != *on), "{off:?}");
    }
    let wrong = base.with_overrides(&["run.sub_cycle.implicit_frictoin=false"]);
    assert!(wrong.is_err());
    let unread = base.with_overrides(&[
        "run.contact_integration=Explicit",
        "run.sub_cycle.implicit_friction=false",
    ]);
    let message = unread.expect_err("refused on an explicit run").to_string();
    assert!(message.contains("run.sub_cycle"), "{message}");
}
