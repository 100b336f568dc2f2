//! Two spatial sub-cycled pins in series: a double pendulum hung on a spatial shoulder and a
//! spatial elbow that share the upper link, released level under gravity across the pins'
//! axis. Each pin's contact presses the upper link stiffly; the sub-cycle integrates the two
//! pins as one system. Runs optimised.

use clearance_joint::model::laws::{Coulomb, FrictionModel};
use clearance_joint::model::spatial::SpatialModel;
use clearance_joint::prelude::*;
use clearance_joint::rapier::observers::metrics::{ContactObservation, Impact, ImpactRecorder};
use rapier3d_f64::prelude::*;

/// Links: mass (kg) and length (m), upper then lower (the SCARA bench's).
const LINKS: [(f64, f64); 2] = [(2.0, 0.4), (1.0, 0.3)];
/// Pins: bearing radius 6 mm, radial clearance 0.1 mm, width 12 mm, axial play 0.1 mm, collars
/// of 12 mm.
const R_B: f64 = 0.006;
const C: f64 = 0.1e-3;
const WIDTH: f64 = 0.012;
const PLAY: f64 = 0.1e-3;

/// The run: each pin's impacts (onset, peak force, depth), and the world's steps; or the
/// world's error (a divergence).
type Run = Result<([Vec<Impact>; 2], u64), clearance_joint::Error>;

/// The pendulum (links along x, pins along z, gravity along -y) stepped by `control` with
/// `iterations` solver iterations, its pins (shoulder, elbow) of `models` integrated as
/// `integration` with `techniques`: the world, the pins and the links.
fn build(
    integration: ContactIntegration,
    techniques: SubCycleTechniques,
    control: StepControl,
    iterations: usize,
    models: [ClearanceModel; 2],
) -> clearance_joint::Result<(
    ClearanceWorld,
    Vec<ClearanceJointHandle>,
    [RigidBodyHandle; 2],
)> {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -9.81, 0.0);
    rapier.integration_parameters.num_solver_iterations = iterations;
    let base = rapier.bodies.insert(RigidBodyBuilder::fixed());
    let mut start = 0.0;
    let links = LINKS.map(|(mass, length)| {
        let j = mass * length * length / 12.0;
        let body = rapier.bodies.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(start + 0.5 * length, 0.0, 0.0))
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    mass,
                    Vector::new(0.1 * j, j, j),
                ))
                .can_sleep(false),
        );
        start += length;
        body
    });
    let mut world = ClearanceWorld::new(rapier, control);
    let pairs = [(base, links[0]), (links[0], links[1])];
    let anchors = [
        (Vector::ZERO, -0.5 * LINKS[0].1),
        (Vector::new(0.5 * LINKS[0].1, 0.0, 0.0), -0.5 * LINKS[1].1),
    ];
    let mut pins = Vec::new();
    for (((b1, b2), (a1, a2)), model) in pairs.into_iter().zip(anchors).zip(models) {
        let joint = HingeDesign::steel_improved_liu(R_B, C, WIDTH)?
            .friction(FrictionModel::Coulomb(Coulomb::new(0.1, 1e-4)?))
            .model(model)
            .integration(integration)
            .sub_cycle_techniques(techniques)
            .joint(a1, Vector::new(a2, 0.0, 0.0), Vector::Z, Vector::Z)?;
        pins.push(world.insert_clearance(b1, b2, joint)?);
    }
    Ok((world, pins, links))
}

/// The spatial pins: axial play 0.1 mm, collars of 12 mm.
fn spatial() -> ClearanceModel {
    ClearanceModel::Spatial(SpatialModel::steel(PLAY, 2.0 * R_B))
}

/// The pendulum of [`build`] on two spatial pins, run to `end` (s).
fn pendulum(
    integration: ContactIntegration,
    techniques: SubCycleTechniques,
    control: StepControl,
    iterations: usize,
    end: f64,
) -> Run {
    let models = [spatial(), spatial()];
    let (mut world, pins, _) = build(integration, techniques, control, iterations, models)?;
    world.prepare()?;
    let mut recorders: [ImpactRecorder; 2] = Default::default();
    while world.time() < end {
        let before: Vec<ContactObservation> = pins
            .iter()
            .map(|h| ContactObservation::of(world.clearance.get(*h).expect("inserted")))
            .collect();
        let info = world.step(end)?;
        for (k, h) in pins.iter().enumerate() {
            let j = world.clearance.get(*h).expect("inserted");
            recorders[k].record_step(info.t0, info.dt, &before[k], j.substeps());
        }
    }
    Ok((recorders.map(|r| r.contacts().to_vec()), world.steps()))
}

/// The sub-cycled pendulum at world steps of 1 ms with Rapier's four iterations.
fn sub_cycled(techniques: SubCycleTechniques, end: f64) -> Run {
    let control = StepControl {
        tolerance: 0.0075,
        ..StepControl::fixed(1e-3)
    };
    pendulum(ContactIntegration::SubCycled, techniques, control, 4, end)
}

/// The largest peak force of a run's impacts at either pin, N.
fn largest(impacts: &[Vec<Impact>; 2]) -> f64 {
    impacts
        .iter()
        .flatten()
        .map(|i| i.peak_force_n)
        .fold(0.0, f64::max)
}

/// Released level, the links fall together in the clearance and the shoulder's journal lands
/// first (after 4.5 ms: `sqrt(2 c/g)`); the shoulder's impact stops the upper link under the
/// still falling lower one, and the elbow lands next. The sub-cycled pendulum at 1 ms steps
/// and four iterations follows the explicit joint at the reference's fine steps (adaptive at a
/// tolerance of 1e-3, at most 10 us, one iteration: every contact resolved on the world's
/// clock, the two contacts' coupling through the upper link Rapier's own) impact by impact:
/// its first impact at each pin within 2 % in peak force and depth (0.5 % and 0.7 % low), its
/// first three impacts at each pin within 5 % in peak force and 0.2 ms in onset. With each pin
/// sub-cycled on its own (`spatial_coupling` off: each integrates its stiff contact against an
/// upper link the other's contact leaves alone, and Rapier's pass 1 adds both corrections on
/// it) the shoulder's second impact is 2114 N against the reference's 281 N: the run's largest
/// impact is more than twice the reference's (the SCARA arm on two such pins leaves the
/// physical range in 22 ms; docs/spatial-joint.md).
#[test]
fn two_spatial_pins_in_series_follow_the_explicit_joints_impacts() {
    let end = 0.03;
    let reference = pendulum(
        ContactIntegration::Explicit,
        SubCycleTechniques::default(),
        StepControl::adaptive(1e-5, 1e-3),
        1,
        end,
    )
    .expect("the explicit pendulum runs");
    let (coupled, steps) =
        sub_cycled(SubCycleTechniques::default(), end).expect("the sub-cycled pendulum runs");
    for (k, name) in ["shoulder", "elbow"].iter().enumerate() {
        let (r, s) = (&reference.0[k], &coupled[k]);
        assert!(r.len() >= 3 && s.len() >= 3, "{name}: {r:?} against {s:?}");
        for (n, (r, s)) in r.iter().zip(s).take(3).enumerate() {
            println!(
                "{name} impact {n}: explicit onset {:.5} s, {:.1} N, {:.3} um; sub-cycled onset \
                 {:.5} s, {:.1} N, {:.3} um ({steps} world steps)",
                r.onset_t_s,
                r.peak_force_n,
                r.max_penetration_um,
                s.onset_t_s,
                s.peak_force_n,
                s.max_penetration_um,
            );
            let force = s.peak_force_n / r.peak_force_n - 1.0;
            let depth = s.max_penetration_um / r.max_penetration_um - 1.0;
            let bound = if n == 0 { 0.02 } else { 0.05 };
            assert!(force.abs() < bound, "{name} {n}: force {force:+.4}");
            assert!(
                n > 0 || depth.abs() < bound,
                "{name} {n}: depth {depth:+.4}"
            );
            assert!((s.onset_t_s - r.onset_t_s).abs() < 2e-4, "{name} {n}");
        }
    }
    let uncoupled = sub_cycled(SubCycleTechniques::default().spatial_coupling(false), end);
    if let Ok((impacts, _)) = uncoupled {
        let (off, on) = (largest(&impacts), largest(&reference.0));
        println!("each pin on its own: largest impact {off:.1} N against {on:.1} N");
        assert!(off > 2.0 * on, "{off} against {on}");
    }
}

/// A planar and a spatial sub-cycled pin on one body would be integrated apart (each one's
/// contact reaching the other's pair through Rapier's delivery pass only; the SCARA arm so built
/// leaves the physical range: docs/sub-cycled-contact.md, limits): the world refuses to step,
/// naming both pins and what to do, also when a live pin is switched into that state. Two
/// spatial pins, or the mixed pair explicit, step.
#[test]
fn a_planar_and_a_spatial_sub_cycled_pin_on_one_body_are_refused() {
    let control = StepControl::fixed(1e-3);
    let techniques = SubCycleTechniques::default();
    let mixed = [ClearanceModel::Compliant, spatial()];
    let (mut world, _, _) =
        build(ContactIntegration::SubCycled, techniques, control, 4, mixed).unwrap();
    let refusal = world.step(1e-3).unwrap_err().to_string();
    println!("{refusal}");
    for words in ["clearance joint", "all spatial or all planar", "Explicit"] {
        assert!(refusal.contains(words), "{words}: {refusal}");
    }
    let (mut world, _, _) = build(
        ContactIntegration::SubCycled,
        techniques,
        control,
        4,
        [spatial(), spatial()],
    )
    .unwrap();
    world.step(1e-3).unwrap();
    let explicit = StepControl::adaptive(1e-3, 0.0075);
    let (mut world, pins, _) =
        build(ContactIntegration::Explicit, techniques, explicit, 1, mixed).unwrap();
    world.step(1e-3).unwrap();
    world
        .clearance
        .get_mut(pins[0])
        .unwrap()
        .set_integration(ContactIntegration::SubCycled);
    world
        .clearance
        .get_mut(pins[1])
        .unwrap()
        .set_integration(ContactIntegration::SubCycled);
    let refusal = world.step(2e-3).unwrap_err().to_string();
    assert!(refusal.contains("all spatial or all planar"), "{refusal}");
}
