//! Robot rate: a SCARA-style two-link arm with radial play in both joints tracks a pick-and-place
//! motion with a PD torque controller at 1 kHz, Rapier's default four solver iterations.
//!
//! The arm (upper link 2 kg x 0.4 m, lower link 1 kg x 0.3 m) turns in a horizontal plane, its
//! weight on the pins' axial locks, so the pins carry only the arm's inertial loads. A controller
//! running at the physics rate reads the joint angles and rates (as encoders would) and commands
//! `tau = Kp (q* - q) + Kd (q*' - q')` on each joint: swing out in 0.5 s, hold, swing back, hold.
//! With 0.1 mm of radial play in each pin (restitution 0.3, friction 0.1) every turn-over of the
//! load from accelerating to braking throws the pins across their play. The same arm and
//! controller on Rapier's ideal revolute joints runs in lockstep beside it: the distance between
//! the two hands is the tracking error the play causes.
//!
//! Each arm is a `ClearanceWorld` stepped at fixed 1 ms steps (`StepControl::fixed`): its `step`
//! takes the place of `world.step()` and runs the large-step joints' hooks around Rapier's step,
//! so none can be forgotten. The controller's torques are ordinary Rapier user torques.
//!
//! `cargo run --release --example robot_backlash`

use clearance_joint::Result;
use clearance_joint::model::angle::HingeAngle;
use clearance_joint::model::laws::BearingGeometry;
use clearance_joint::rapier::large_step::{LargeStepJointBuilder, LargeStepJointHandle};
use clearance_joint::rapier::pipeline::stepper::StepControl;
use clearance_joint::rapier::pipeline::world::ClearanceWorld;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{
    IntegrationParameters, MassProperties, PhysicsWorld, RevoluteJointBuilder, RigidBodyBuilder,
    RigidBodyHandle,
};
use std::f64::consts::PI;
use std::process::ExitCode;
use std::time::Instant;

/// Controller and physics rate, s.
pub const DT: f64 = 1e-3;
/// Simulated time, s.
pub const END: f64 = 6.0;
/// Radial play of each pin, m.
pub const CLEARANCE: f64 = 0.1e-3;
const UPPER: (f64, f64) = (2.0, 0.4); // mass kg, length m
const LOWER: (f64, f64) = (1.0, 0.3);
/// Inertia each joint's controller is tuned for (about its pin, elbow straight), kg m^2.
const TUNED_INERTIA: [f64; 2] = [0.45, 0.035];

/// PD gains per joint (stiffness N m/rad, damping N m s/rad) for a controller ticking every `dt`:
/// closed-loop bandwidth 5 Hz, damping ratio 0.7, slowed to `0.3/dt` rad/s when the tick is too
/// slow for it. Stable at 1 kHz; not at 60 Hz, where the ideal arm diverges within 0.27 s and
/// `ClearanceWorld::step` stops the run with that error.
fn gains(dt: f64) -> [(f64, f64); 2] {
    let w = (2.0 * PI * 5.0).min(0.3 / dt);
    TUNED_INERTIA.map(|i| (i * w * w, 2.0 * 0.7 * i * w))
}
/// Move time and hold time of the pick-and-place cycle, s.
const MOVE: f64 = 0.5;
const HOLD: f64 = 0.25;

/// Target joint angles (rad; zero with the arm straight along x) and rates at `t`: swing out in
/// `MOVE`, hold `HOLD`, swing back, hold, repeat.
pub fn target(t: f64) -> ([f64; 2], [f64; 2]) {
    let out = [90f64.to_radians(), -75f64.to_radians()];
    let period = 2.0 * (MOVE + HOLD);
    let p = t % period;
    let w = PI / MOVE;
    // s goes 0 -> 1 over a move with a cosine profile; ds is its rate.
    let (s, ds) = if p < MOVE {
        (0.5 * (1.0 - (w * p).cos()), 0.5 * w * (w * p).sin())
    } else if p < MOVE + HOLD {
        (1.0, 0.0)
    } else if p < 2.0 * MOVE + HOLD {
        let p = p - MOVE - HOLD;
        (0.5 * (1.0 + (w * p).cos()), -0.5 * w * (w * p).sin())
    } else {
        (0.0, 0.0)
    };
    ([out[0] * s, out[1] * s], [out[0] * ds, out[1] * ds])
}

/// Where the hand (the tip of the lower link) is for joint angles `q`, from the shoulder, m.
pub fn hand(q: [f64; 2]) -> Vector {
    let along = |a: f64| Vector::new(a.cos(), a.sin(), 0.0);
    UPPER.1 * along(q[0]) + LOWER.1 * along(q[0] + q[1])
}

/// One arm in its own world, with its controller.
struct Arm {
    world: ClearanceWorld,
    dt: f64,
    pairs: [(RigidBodyHandle, RigidBodyHandle); 2],
    lower: RigidBodyHandle,
    pins: Vec<LargeStepJointHandle>,
    angles: [HingeAngle; 2],
}

fn link(world: &mut PhysicsWorld, (mass, length): (f64, f64), start: f64) -> RigidBodyHandle {
    let j = mass * length * length / 12.0;
    world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(start + 0.5 * length, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                mass,
                Vector::new(1e-3 * j, j, j),
            ))
            .can_sleep(false),
    )
}

impl Arm {
    /// The arm, with play in both pins (`true`) or on ideal revolute joints. Gravity is along -z,
    /// the pins' axis.
    fn new(with_play: bool, dt: f64) -> Result<Arm> {
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::new(0.0, 0.0, -9.81);
        world.integration_parameters = IntegrationParameters {
            dt,
            ..IntegrationParameters::default() // 4 solver iterations
        };
        let base = world.bodies.insert(RigidBodyBuilder::fixed());
        let upper = link(&mut world, UPPER, 0.0);
        let lower = link(&mut world, LOWER, UPPER.1);
        let pairs = [(base, upper), (upper, lower)];
        let anchors = [
            (Vector::ZERO, Vector::new(-0.5 * UPPER.1, 0.0, 0.0)),
            (
                Vector::new(0.5 * UPPER.1, 0.0, 0.0),
                Vector::new(-0.5 * LOWER.1, 0.0, 0.0),
            ),
        ];
        let mut world = ClearanceWorld::new(world, StepControl::fixed(dt));
        let mut pins = Vec::new();
        for (i, ((b1, b2), (a1, a2))) in pairs.into_iter().zip(anchors).enumerate() {
            if with_play {
                // The one difference from the ideal arm: the pin's joint.
                let joint = LargeStepJointBuilder::new(
                    Vector::Z,
                    BearingGeometry::from_clearance(0.006, CLEARANCE, 0.012)?,
                )
                .local_anchor1(a1)
                .local_anchor2(a2)
                .restitution(0.3)
                .friction(0.1)
                .name(["shoulder", "elbow"][i])
                .build()?;
                pins.push(world.insert_large_step(b1, b2, joint)?);
            } else {
                world.rapier.impulse_joints.insert(
                    b1,
                    b2,
                    RevoluteJointBuilder::new(Vector::Z)
                        .local_anchor1(a1)
                        .local_anchor2(a2)
                        .contacts_enabled(false),
                    true,
                );
            }
        }
        Ok(Arm {
            world,
            dt,
            pairs,
            lower,
            pins,
            angles: Default::default(),
        })
    }

    /// Encoders: joint angles and rates.
    fn joints(&mut self) -> ([f64; 2], [f64; 2]) {
        let (mut q, mut rate) = ([0.0; 2], [0.0; 2]);
        for (k, (b1, b2)) in self.pairs.iter().enumerate() {
            let bodies = &self.world.rapier.bodies;
            let (r1, r2) = (&bodies[*b1], &bodies[*b2]);
            q[k] = self.angles[k].update(r1.rotation(), r2.rotation(), Vector::Z);
            rate[k] = (r2.angvel() - r1.angvel()).z;
        }
        (q, rate)
    }

    /// The hand: the tip of the lower link, from the bodies (the play moves the links).
    fn hand(&self) -> Vector {
        *self.world.rapier.bodies[self.lower].position() * Vector::new(0.5 * LOWER.1, 0.0, 0.0)
    }

    /// One controller tick and physics step at `t`; returns the encoder angles.
    fn step(&mut self, t: f64) -> Result<[f64; 2]> {
        let (q, rate) = self.joints();
        let (qt, rt) = target(t);
        let gains = gains(self.dt);
        for (k, (b1, b2)) in self.pairs.iter().enumerate() {
            let (kp, kd) = gains[k];
            let tau = Vector::new(0.0, 0.0, kp * (qt[k] - q[k]) + kd * (rt[k] - rate[k]));
            // The motor's torque on the driven link and its reaction on the driving one (the
            // shoulder's goes to the fixed base). User torques persist in Rapier: reset first.
            for (body, sign) in [(*b2, 1.0), (*b1, -1.0)] {
                let rb = &mut self.world.rapier.bodies[body];
                if k == 0 || sign > 0.0 {
                    rb.reset_torques(false);
                }
                rb.add_torque(sign * tau, true);
            }
        }
        self.world.step(t + self.dt)?; // was: world.step(), with the joints' hooks around it
        Ok(q)
    }
}

/// What the run measured.
#[derive(Clone, Debug, Default)]
pub struct Outcome {
    /// RMS and largest distance of the ideal arm's hand from the target path, mm.
    pub ideal_tip_error_mm: (f64, f64),
    /// RMS and largest distance of the arm-with-play's hand from the target path, mm.
    pub play_tip_error_mm: (f64, f64),
    /// RMS and largest distance between the two hands: the error the play causes, mm.
    pub play_effect_mm: (f64, f64),
    /// RMS difference of the encoder angles between the two arms (shoulder, elbow), deg.
    pub angle_effect_deg: [f64; 2],
    /// Pin bounces (shoulder, elbow): onsets faster than the pins' `min_impact_speed`.
    pub bounces: [u64; 2],
    /// Largest `|e|/c` (shoulder, elbow) at the end of a step.
    pub max_eccentricity_ratio: [f64; 2],
    /// Largest normal force in each pin, N.
    pub max_pin_force_n: [f64; 2],
    /// Largest substeps per step of the arm with play.
    pub max_substeps: usize,
    /// Pin-steps reported under-resolved.
    pub under_resolved: u64,
    /// Wall time per step: ideal arm, arm with play, us.
    pub us_per_step: (f64, f64),
}

/// Both arms in lockstep for [`END`] at [`DT`].
pub fn run() -> Result<Outcome> {
    run_at(DT, END)
}

/// Both arms in lockstep for `end` s, controller and physics at the step `dt` (s).
pub fn run_at(dt: f64, end: f64) -> Result<Outcome> {
    let mut ideal = Arm::new(false, dt)?;
    let mut play = Arm::new(true, dt)?;
    let steps = (end / dt).round() as u64;
    let mut o = Outcome::default();
    let (mut sq, mut wall) = ([0.0f64; 3], [0.0f64; 2]);
    let mut angle_sq = [0.0f64; 2];
    let stat = |sq: &mut f64, max: &mut f64, x: f64| {
        *sq += x * x;
        *max = max.max(x * 1e3);
    };
    for step in 0..steps {
        let t = step as f64 * dt;
        let clock = Instant::now();
        let qi = ideal.step(t)?;
        wall[0] += clock.elapsed().as_secs_f64();
        let clock = Instant::now();
        let qp = play.step(t)?;
        wall[1] += clock.elapsed().as_secs_f64();
        let path = hand(target(t + dt).0);
        let (hi, hp) = (ideal.hand(), play.hand());
        stat(
            &mut sq[0],
            &mut o.ideal_tip_error_mm.1,
            (hi - path).length(),
        );
        stat(&mut sq[1], &mut o.play_tip_error_mm.1, (hp - path).length());
        stat(&mut sq[2], &mut o.play_effect_mm.1, (hp - hi).length());
        for k in 0..2 {
            angle_sq[k] += (qp[k] - qi[k]).powi(2);
        }
        for (k, pin) in play.pins.iter().enumerate() {
            let r = play.world.large_step.get(*pin).expect("inserted").report();
            o.max_eccentricity_ratio[k] = o.max_eccentricity_ratio[k].max(r.eccentricity_ratio);
            o.max_pin_force_n[k] = o.max_pin_force_n[k].max(r.normal_force);
            o.max_substeps = o.max_substeps.max(r.substeps);
            o.under_resolved += u64::from(r.under_resolved);
        }
    }
    let n = steps as f64;
    let rms = |s: f64| (s / n).sqrt() * 1e3;
    o.ideal_tip_error_mm.0 = rms(sq[0]);
    o.play_tip_error_mm.0 = rms(sq[1]);
    o.play_effect_mm.0 = rms(sq[2]);
    for (k, pin) in play.pins.iter().enumerate() {
        o.angle_effect_deg[k] = (angle_sq[k] / n).sqrt().to_degrees();
        o.bounces[k] = play.world.large_step.get(*pin).expect("inserted").bounces();
    }
    o.us_per_step = (wall[0] / n * 1e6, wall[1] / n * 1e6);
    Ok(o)
}

/// The printed comparison.
pub fn report(o: &Outcome) -> String {
    let mut s = format!(
        "robot_backlash: SCARA two-link arm, PD at the physics rate, {END} s, dt = {DT:e} s, 4 solver iterations\n\
         pins: Rapier revolutes (ideal) vs large-step clearance joints (play: 0.1 mm, restitution 0.3, \
         friction 0.1)\n\n\
         {:<42}{:>20}{:>20}\n",
        "", "ideal", "play"
    );
    let mut row =
        |label: &str, a: String, b: String| s.push_str(&format!("{label:<42}{a:>20}{b:>20}\n"));
    let pair = |a: (f64, f64), d: usize| format!("{:.*} / {:.*}", d, a.0, d, a.1);
    let both = |a: [f64; 2], d: usize| format!("{:.*} / {:.*}", d, a[0], d, a[1]);
    row(
        "hand off the path, RMS / max (mm)",
        pair(o.ideal_tip_error_mm, 4),
        pair(o.play_tip_error_mm, 4),
    );
    row(
        "hand off the ideal arm's, RMS / max (mm)",
        "-".into(),
        pair(o.play_effect_mm, 4),
    );
    row(
        "encoder angles off the ideal's, RMS (deg)",
        "-".into(),
        both(o.angle_effect_deg, 5),
    );
    row(
        "pin bounces, shoulder / elbow",
        "0 / 0".into(),
        format!("{} / {}", o.bounces[0], o.bounces[1]),
    );
    row(
        "largest |e|/c, shoulder / elbow",
        "-".into(),
        both(o.max_eccentricity_ratio, 4),
    );
    row(
        "largest pin force, shoulder / elbow (N)",
        "-".into(),
        both(o.max_pin_force_n, 1),
    );
    row(
        "substeps per step (max)",
        "4".into(),
        o.max_substeps.to_string(),
    );
    row(
        "under-resolved pin-steps",
        "-".into(),
        o.under_resolved.to_string(),
    );
    row(
        "wall time per step (us)",
        format!("{:.2}", o.us_per_step.0),
        format!("{:.2}", o.us_per_step.1),
    );
    s
}

fn main() -> ExitCode {
    match run() {
        Ok(outcome) => {
            print!("{}", report(&outcome));
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
