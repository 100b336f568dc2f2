//! The large-step clearance joint (`clearance_joint::rapier::large_step`): bounded eccentricity, no energy
//! gain, stability over clearances and masses at game rate, restitution, friction, the force
//! readout, and what it says when it cannot resolve a step. Release profile (`cargo test
//! --release`); every scene is at most a minute of simulated time at 1/60 s.

use clearance_joint::model::laws::{
    BearingGeometry, ImprovedLiu, MaxDamping, NormalModel, impact_restitution,
};
use clearance_joint::rapier::large_step::{
    LargeStepJointBuilder, LargeStepJointHandle, LargeStepJointSet, LargeStepReport,
};
use rapier3d_f64::prelude::*;

const G: f64 = 9.81;

fn step(world: &mut PhysicsWorld, play: &mut LargeStepJointSet) {
    play.before_step(
        &mut world.bodies,
        &mut world.impulse_joints,
        &world.integration_parameters,
    );
    world.step();
    play.after_step(&mut world.bodies, &world.impulse_joints);
}

/// A rod of `mass` and length 0.6 m pinned 0.3 m from its centre to a fixed bearing at the origin
/// (axis z, gravity -y), released at `angle` from hanging (rad), journal centred. Rapier's
/// defaults: 1/60 s, 4 solver iterations.
struct Pendulum {
    world: PhysicsWorld,
    play: LargeStepJointSet,
    hinge: LargeStepJointHandle,
    arm: RigidBodyHandle,
    mass: f64,
    inertia: f64,
}

impl Pendulum {
    fn new(
        mass: f64,
        clearance: f64,
        angle: f64,
        joint: impl FnOnce(LargeStepJointBuilder) -> LargeStepJointBuilder,
    ) -> Self {
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::new(0.0, -G, 0.0);
        let base = world.bodies.insert(RigidBodyBuilder::fixed());
        let inertia = mass * 0.36 / 12.0;
        let rot = Rotation::from_rotation_z(angle);
        let arm = world.bodies.insert(
            RigidBodyBuilder::dynamic()
                .pose(Pose::from_parts(rot * Vector::new(0.0, -0.3, 0.0), rot))
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    mass,
                    Vector::splat(inertia),
                ))
                .can_sleep(false),
        );
        let geometry = BearingGeometry::from_clearance(0.010, clearance, 0.016).unwrap();
        let built = joint(
            LargeStepJointBuilder::new(Vector::Z, geometry)
                .local_anchor2(Vector::new(0.0, 0.3, 0.0)),
        )
        .build()
        .unwrap();
        let mut play = LargeStepJointSet::new();
        let hinge = play
            .insert(base, arm, built, &world.bodies, &mut world.impulse_joints)
            .unwrap();
        Pendulum {
            world,
            play,
            hinge,
            arm,
            mass,
            inertia,
        }
    }

    fn step(&mut self) -> LargeStepReport {
        step(&mut self.world, &mut self.play);
        *self.play.get(self.hinge).unwrap().report()
    }

    /// Kinetic + gravitational energy (zero: centre of mass at the pin's height), J.
    fn energy(&self) -> f64 {
        let rb = &self.world.bodies[self.arm];
        0.5 * self.mass * rb.linvel().length_squared()
            + 0.5 * self.inertia * rb.angvel().length_squared()
            + self.mass * G * rb.translation().y
    }
}

#[test]
fn sweep_clearances_and_masses_at_game_rate() {
    // Released horizontal, 20 s at 1/60 s with Rapier's four iterations: the journal stays within
    // 10 % of c at every step's end, the energy never rises above its start (1e-9 of m g l), and
    // every step is resolved by the substeps the joint asks for.
    for clearance in [0.05e-3, 0.5e-3, 5e-3] {
        for mass in [0.1, 10.0, 100.0] {
            for (e, mu) in [(0.0, 0.0), (0.5, 0.2)] {
                let mut p = Pendulum::new(mass, clearance, std::f64::consts::FRAC_PI_2, |b| {
                    b.restitution(e).friction(mu)
                });
                let (e0, scale) = (p.energy(), mass * G * 0.3);
                let (mut worst, mut gain, mut substeps) = (0.0f64, f64::NEG_INFINITY, 0usize);
                for _ in 0..1200 {
                    let r = p.step();
                    assert!(r.eccentricity.is_finite() && r.normal_force.is_finite());
                    assert!(!r.under_resolved, "c {clearance} m {mass}: {r:?}");
                    worst = worst.max(r.eccentricity_ratio);
                    gain = gain.max(p.energy() - e0);
                    substeps = substeps.max(r.substeps);
                }
                let case = format!("c {clearance} m {mass} e {e} mu {mu}");
                assert!(worst < 1.1 && worst > 0.99, "{case}: |e|/c {worst}");
                assert!(gain < 1e-9 * scale, "{case}: energy gain {gain} J");
                assert!(substeps <= 64, "{case}");
            }
        }
    }
}

#[test]
fn no_energy_gain_over_a_minute_with_bounces_and_friction() {
    // A minute of a swinging, rubbing pin at 1/60 s: the energy of the arm (kinetic + gravity)
    // never rises above its start, and friction takes more than half the swing's energy.
    let mut p = Pendulum::new(2.0, 1e-3, 2.5, |b| b.restitution(0.5).friction(0.1));
    let (e0, scale) = (p.energy(), 2.0 * G * 0.3);
    let mut highest = f64::NEG_INFINITY;
    for _ in 0..3600 {
        p.step();
        highest = highest.max(p.energy());
    }
    assert!(highest - e0 < 1e-9 * scale, "rose {}", highest - e0);
    let swing = e0 + scale; // above hanging at rest
    assert!(
        p.energy() + scale < 0.5 * swing,
        "{} of {swing} J left",
        p.energy() + scale
    );

    // A minute of a journal rattling in its play without gravity (a spinning body thrown across
    // the clearance): the journal strikes the wall until its normal speed is spent and then slides
    // along it, and the kinetic energy never rises.
    for (e, least) in [(1.0, 50), (0.9, 20), (0.5, 5)] {
        let (mut world, mut play, h, body) = shot(0.03, builder().restitution(e));
        world.bodies[body].set_linvel(Vector::new(0.03, 0.017, 0.0), true);
        world.bodies[body].set_angvel(Vector::new(0.0, 0.0, 0.4), true);
        let kinetic = |w: &PhysicsWorld| {
            let rb = &w.bodies[body];
            0.5 * 3.0 * rb.linvel().length_squared() + 0.5 * 0.05 * rb.angvel().length_squared()
        };
        let k0 = kinetic(&world);
        let (mut highest, mut worst) = (0.0f64, 0.0f64);
        for _ in 0..3600 {
            step(&mut world, &mut play);
            highest = highest.max(kinetic(&world));
            worst = worst.max(play.get(h).unwrap().report().eccentricity_ratio);
        }
        let impacts = play.get(h).unwrap().bounces();
        assert!(highest <= k0 * (1.0 + 1e-9), "e {e}: {highest} > {k0}");
        assert!(impacts > least, "e {e}: {impacts} impacts");
        assert!(worst < 1.1, "e {e}: |e|/c {worst}");
    }
}

/// A free body (no gravity) whose journal starts at the bearing centre moving at `speed` along
/// +x towards the wall; the bearing is fixed.
fn shot(
    speed: f64,
    joint: LargeStepJointBuilder,
) -> (
    PhysicsWorld,
    LargeStepJointSet,
    LargeStepJointHandle,
    RigidBodyHandle,
) {
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::ZERO;
    let base = world.bodies.insert(RigidBodyBuilder::fixed());
    let body = world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .linvel(Vector::new(speed, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(Vector::ZERO, 3.0, Vector::splat(0.05)))
            .can_sleep(false),
    );
    let mut play = LargeStepJointSet::new();
    let h = play
        .insert(
            base,
            body,
            joint.build().unwrap(),
            &world.bodies,
            &mut world.impulse_joints,
        )
        .unwrap();
    (world, play, h, body)
}

fn builder() -> LargeStepJointBuilder {
    LargeStepJointBuilder::new(
        Vector::Z,
        BearingGeometry::from_clearance(0.01, 0.5e-3, 0.016).unwrap(),
    )
}

#[test]
fn a_single_impact_rebounds_with_the_coefficient() {
    for e in [0.0, 0.3, 0.7, 1.0] {
        // 20 mm/s across 0.5 mm: the impact comes in the second step at 1/60 s.
        let (mut world, mut play, h, body) = shot(0.02, builder().restitution(e));
        let mut impacts = Vec::new();
        for _ in 0..3 {
            step(&mut world, &mut play);
            let r = *play.get(h).unwrap().report();
            if r.bounce {
                impacts.push(r);
            }
        }
        assert_eq!(impacts.len(), 1, "e {e}");
        let r = impacts[0];
        let v = world.bodies[body].linvel().x;
        // The journal (3 kg, the bearing fixed) leaves at e times its approach speed.
        assert!(
            (r.approach_speed - 0.02).abs() < 1e-12,
            "{}",
            r.approach_speed
        );
        assert!((v + e * 0.02).abs() < 1e-9, "e {e}: rebound {v}");
        assert!((r.rebound_speed - e * 0.02).abs() < 1e-12);
        assert!((r.impact_impulse - 3.0 * (1.0 + e) * 0.02).abs() < 1e-9);
    }
}

#[test]
fn restitution_from_a_compliant_law_is_the_laws_own() {
    // The paper's law for this bearing: the rebound the law gives a 3 kg body at 20 mm/s.
    let law = ImprovedLiu::new(1.137e11, 0.016, 0.5e-3, 1.0, 1e-4, MaxDamping::Eta(0.01)).unwrap();
    let expected = impact_restitution(&law, 3.0, 0.02);
    assert!(expected > 0.0 && expected < 1.0, "{expected}");
    let (mut world, mut play, h, body) = shot(
        0.02,
        builder().restitution_law(NormalModel::ImprovedLiu(law)),
    );
    for _ in 0..3 {
        step(&mut world, &mut play);
    }
    let v = world.bodies[body].linvel().x;
    assert!(
        (v + expected * 0.02).abs() < 1e-9,
        "{v} vs {}",
        -expected * 0.02
    );
    assert_eq!(play.get(h).unwrap().bounces(), 1);
}

#[test]
fn friction_sticks_below_its_moment_and_slides_at_it() {
    // Hanging at rest on the wall, N = m g = 19.62 N; mu = 0.2 and R_j = 9.5 mm give a friction
    // moment of 0.037278 N m. A torque below it holds the arm; above it the arm turns, braked by
    // exactly that moment.
    let limit = 0.2 * 2.0 * G * 0.0095;
    for (factor, sticks) in [(0.5, true), (2.0, false)] {
        let mut p = Pendulum::new(2.0, 0.5e-3, 0.0, |b| b.friction(0.2));
        for _ in 0..30 {
            p.step(); // settle onto the wall
        }
        let torque = factor * limit;
        p.world.bodies[p.arm].add_torque(Vector::new(0.0, 0.0, torque), true);
        let w0 = p.world.bodies[p.arm].angvel().z;
        let r = p.step();
        let r = if sticks { r } else { p.step() };
        // From the last step's normal force (the arm has just settled: within 1e-3 of m g).
        assert!(
            (r.friction_limit - limit).abs() < 1e-3 * limit,
            "{}",
            r.friction_limit
        );
        assert!(r.friction_torque.abs() <= r.friction_limit * (1.0 + 1e-9));
        let w = p.world.bodies[p.arm].angvel().z;
        if sticks {
            assert!((w - w0).abs() < 1e-9, "held: {w}");
            assert!(
                (r.friction_torque + torque).abs() < 1e-6 * torque,
                "{}",
                r.friction_torque
            );
        } else {
            assert!(w > 1e-3, "turns: {w}");
            assert!(
                (r.friction_torque + r.friction_limit).abs() < 1e-6 * limit,
                "{} vs {}",
                r.friction_torque,
                r.friction_limit
            );
        }
    }
    // Swinging, the friction moment never exceeds mu N R_j of the step.
    let mut p = Pendulum::new(2.0, 0.5e-3, 1.0, |b| b.friction(0.3).restitution(0.5));
    for _ in 0..600 {
        let r = p.step();
        assert!(
            r.friction_torque.abs() <= r.friction_limit * (1.0 + 1e-9) + 1e-12,
            "{r:?}"
        );
    }
}

#[test]
fn the_force_readout_is_the_static_load() {
    // Hanging at rest: the pin carries m g, to the solver's precision, for any mass.
    for mass in [0.1, 2.0, 100.0] {
        let mut p = Pendulum::new(mass, 0.2e-3, 0.0, |b| b);
        let mut r = p.step();
        for _ in 0..60 {
            r = p.step();
        }
        assert!(r.contact && !r.onset);
        assert!(
            (r.normal_force - mass * G).abs() < 1e-9 * mass * G,
            "{mass}: {}",
            r.normal_force
        );
        assert!((r.force_on_journal - Vector::new(0.0, mass * G, 0.0)).length() < 1e-6 * mass * G);
        assert!((r.eccentricity - Vector::new(0.0, -0.2e-3, 0.0)).length() < 1e-9);
    }
    // A two-link chain: the upper pin carries both links, the lower one its own link.
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::new(0.0, -G, 0.0);
    let base = world.bodies.insert(RigidBodyBuilder::fixed());
    let link = |world: &mut PhysicsWorld, y: f64, m: f64| {
        world.bodies.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(0.0, y, 0.0))
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    m,
                    Vector::splat(0.01),
                ))
                .can_sleep(false),
        )
    };
    let (a, b) = (link(&mut world, -0.2, 3.0), link(&mut world, -0.6, 1.0));
    let mut play = LargeStepJointSet::new();
    let joint = |a1: Vector, a2: Vector| {
        LargeStepJointBuilder::new(
            Vector::Z,
            BearingGeometry::from_clearance(0.005, 0.1e-3, 0.01).unwrap(),
        )
        .local_anchor1(a1)
        .local_anchor2(a2)
        .build()
        .unwrap()
    };
    let top = play
        .insert(
            base,
            a,
            joint(Vector::ZERO, Vector::new(0.0, 0.2, 0.0)),
            &world.bodies,
            &mut world.impulse_joints,
        )
        .unwrap();
    let low = play
        .insert(
            a,
            b,
            joint(Vector::new(0.0, -0.2, 0.0), Vector::new(0.0, 0.2, 0.0)),
            &world.bodies,
            &mut world.impulse_joints,
        )
        .unwrap();
    for _ in 0..120 {
        step(&mut world, &mut play);
    }
    let n = |h| play.get(h).unwrap().report().normal_force;
    assert!((n(top) - 4.0 * G).abs() < 1e-6, "{}", n(top));
    assert!((n(low) - G).abs() < 1e-6, "{}", n(low));
}

#[test]
fn an_unresolved_step_says_so() {
    // The same pendulum capped at Rapier's four substeps: the journal's rocking on the wall is
    // beyond the step and the journal leaves the circle; every such step is flagged.
    let mut capped = Pendulum::new(2.0, 0.05e-3, std::f64::consts::FRAC_PI_2, |b| {
        b.max_substeps(4)
    });
    let (mut worst, mut flagged) = (0.0f64, 0);
    for _ in 0..120 {
        let r = capped.step();
        worst = worst.max(r.eccentricity_ratio);
        flagged += u32::from(r.under_resolved);
        if r.eccentricity_ratio > 1.1 {
            assert!(r.under_resolved || r.substeps_needed > 4.0, "{r:?}");
        }
    }
    assert!(worst > 2.0, "{worst}");
    assert!(flagged > 10, "{flagged}");
}

#[test]
fn deterministic_and_substeps_handed_back() {
    let run = || {
        let mut p = Pendulum::new(2.0, 0.2e-3, 2.0, |b| b.restitution(0.5).friction(0.1));
        (0..300).map(|_| p.step()).collect::<Vec<_>>()
    };
    assert_eq!(run(), run(), "bit-identical reports");

    // The set raises the bodies' additional_solver_iterations, keeps a body's own value as a
    // floor, and gives it back when the joint goes.
    let mut p = Pendulum::new(2.0, 0.05e-3, 1.5, |b| b);
    p.world.bodies[p.arm].set_additional_solver_iterations(2);
    let mut most = 0;
    for _ in 0..30 {
        p.step();
        most = most.max(p.world.bodies[p.arm].additional_solver_iterations());
    }
    assert!(most >= 12, "{most}");
    let joint = p
        .play
        .remove(p.hinge, &mut p.world.bodies, &mut p.world.impulse_joints)
        .unwrap();
    assert_eq!(p.world.bodies[p.arm].additional_solver_iterations(), 2);
    assert_eq!(p.world.impulse_joints.len(), 0);
    assert!(joint.bounces() == 0 && p.play.is_empty());
}

#[test]
fn invalid_joints_are_refused_naming_the_field() {
    let check = |b: LargeStepJointBuilder, field: &str| {
        let msg = b.build().unwrap_err().to_string();
        assert!(msg.contains(&format!("`{field}`")), "{msg}");
    };
    check(builder().restitution(1.2), "restitution");
    check(builder().restitution(-0.1), "restitution");
    check(builder().restitution(f64::NAN), "restitution");
    check(builder().friction(-1.0), "friction");
    check(builder().friction(f64::INFINITY), "friction");
    check(builder().min_impact_speed(0.0), "min_impact_speed");
    check(builder().max_substeps(0), "max_substeps");
    check(builder().local_axis2(Vector::ZERO), "local_axis2");
    check(
        builder().local_anchor1(Vector::new(f64::NAN, 0.0, 0.0)),
        "local_anchor1",
    );
    check(
        LargeStepJointBuilder::new(
            Vector::ZERO,
            BearingGeometry::from_clearance(0.01, 0.5e-3, 0.016).unwrap(),
        ),
        "local_axis1",
    );
}

#[test]
fn the_readouts_keep_their_documented_bounds() {
    // `eccentricity_ratio`: a step not flagged under-resolved ends within the two 5 % budgets of
    // the resolution (rotation drift, sliding); `contact`: the limit carried a force, or the
    // journal is within 0.1 % of c. Checked on arms that are resolved and on arms capped at
    // Rapier's four substeps (which flag steps), with bounces and friction.
    // The resolution's budget for each of the two errors: 5 % of c.
    const DRIFT_FRACTION: f64 = 0.05;
    let (mut resolved, mut flagged, mut bearing_inside) = (0, 0, 0);
    for clearance in [0.05e-3, 0.5e-3, 5e-3] {
        for cap in [4, 64] {
            let mut p = Pendulum::new(2.0, clearance, 2.5, |b| {
                b.restitution(0.5).friction(0.2).max_substeps(cap)
            });
            for _ in 0..600 {
                let r = p.step();
                let case = format!("c {clearance} cap {cap}: {r:?}");
                if r.under_resolved {
                    flagged += 1;
                } else {
                    resolved += 1;
                    assert!(r.eccentricity_ratio <= 1.0 + 2.0 * DRIFT_FRACTION, "{case}");
                }
                if r.contact {
                    assert!(
                        r.normal_force > 0.0 || r.eccentricity_ratio >= 0.999,
                        "{case}"
                    );
                    bearing_inside += u32::from(r.eccentricity_ratio < 0.999);
                } else {
                    assert!(
                        r.normal_force == 0.0 && r.eccentricity_ratio < 0.999,
                        "{case}"
                    );
                }
            }
        }
    }
    assert!(
        resolved > 1000 && flagged > 10,
        "{resolved} resolved, {flagged} flagged"
    );
    println!("{resolved} resolved, {flagged} flagged, {bearing_inside} in contact inside 0.999 c");
}
