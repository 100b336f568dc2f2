//! The ECS layer against the scene runner: the same mechanism spawned as entities and run from a
//! scene file steps to the same bits (both drive the core's stepper with the same Rapier calls
//! in the same order).
#![cfg(feature = "ecs")]

use bevy_ecs::prelude::*;
use clearance_joint::Result;
use clearance_joint::ecs::{
    Body, ClearanceHinge, Drive, Hinge, HingeMode, HingeState, IdealHinge, Physics,
    physics_schedule, run_step,
};
use clearance_joint::scene::runner::{RunOptions, Simulation, Twins};
use clearance_joint::scene::{Scene, StepMode};
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{MassProperties, RigidBodyBuilder};

fn steps(world: &mut World, schedule: &mut Schedule, n: usize) -> Result<()> {
    for _ in 0..n {
        run_step(world, schedule)?;
    }
    Ok(())
}

#[test]
fn the_papers_scene_through_the_ecs_is_the_runners() {
    // Both twins of the paper's scene as entities, 1 s at the paper's fixed step, the contact
    // sub-cycled (the default): the ECS layer makes the same Rapier calls in the same order as
    // the runner, to the last bit.
    let mut scene = Scene::solar_panel();
    scene.run.step = StepMode::Fixed;
    scene.run.dt_s = 1e-4;
    scene.run.end_s = 1.0;
    let r = Simulation::new(
        &scene,
        RunOptions {
            twins: Twins::Both,
            skip_rows: false,
        },
    )
    .unwrap()
    .run()
    .unwrap();

    let mut world = World::new();
    let mut physics = Physics::new(1e-4, Vector::ZERO);
    // The runner's step control: the tolerance also sizes a sub-cycled contact's sub-steps.
    physics.set_step_control(scene.run.step_control());
    // One iteration, as the runner's world has it.
    physics
        .world
        .rapier
        .integration_parameters
        .num_solver_iterations = 1;
    world.insert_resource(physics);
    let h = &scene.hinges[0];
    let spec = h.clearance.as_ref().unwrap();
    let d = &scene.drives[0];
    let mut hinges = Vec::new();
    for with_clearance in [false, true] {
        let bodies: Vec<Entity> = scene
            .bodies
            .iter()
            .map(|b| {
                world
                    .spawn(Body::new(
                        RigidBodyBuilder::dynamic()
                            .translation(Vector::from(b.center_of_mass_m))
                            .additional_mass_properties(MassProperties::new(
                                Vector::ZERO,
                                b.mass_kg,
                                Vector::from(b.inertia_kg_m2),
                            ))
                            .can_sleep(false),
                    ))
                    .id()
            })
            .collect();
        let point = Vector::from(h.point_m);
        let hinge = Hinge::new(bodies[0], bodies[1], Vector::from(h.axis))
            .local_anchor1(point - Vector::from(scene.bodies[0].center_of_mass_m))
            .local_anchor2(point - Vector::from(scene.bodies[1].center_of_mass_m));
        let drive = Drive::per_degree(d.torque0_nm, d.stiffness_nm_per_deg);
        let e = if with_clearance {
            let c = spec.clearance().unwrap().name("hinge");
            world.spawn((hinge, ClearanceHinge(c), drive))
        } else {
            world.spawn((hinge, IdealHinge, drive))
        };
        hinges.push(e.id());
    }
    let mut schedule = physics_schedule();
    steps(&mut world, &mut schedule, 10_000).unwrap();
    for (twin, e) in r.twins.iter().zip(hinges) {
        let s = world.get::<HingeState>(e).unwrap();
        let angle = twin.final_angles_deg()["hinge"];
        assert_eq!(s.angle.to_degrees(), angle, "{:?}", twin.kind);
        let m = &twin.hinge_metrics()["hinge"];
        assert_eq!(s.onsets, m.onsets, "{:?}", twin.kind);
        assert_eq!(s.impacts, m.impacts, "{:?}", twin.kind);
        if s.mode == HingeMode::Clearance {
            assert_eq!(s.peak_force, m.peak_force_n);
        }
    }
}
