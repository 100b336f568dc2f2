//! The SCARA arm of `examples/robot_backlash.rs` on compliant, sub-cycled pins
//! (`ContactIntegration::SubCycled`) with Rapier's four solver iterations, across pin clearances
//! and world rates: the stress table of `docs/sub-cycled-contact.md`.
//!
//! `cargo bench --bench scara_stress` (`-- --quick`: one clearance, three rates). For each
//! clearance and world rate the controller ticks at the world rate (its torque held over a tick)
//! and three arms run the same 1.5 s pick-and-place cycle: the ideal arm (Rapier revolutes), the
//! arm on sub-cycled pins stepped once per tick, and the reference, the same pins integrated
//! explicitly by the adaptive stepper at a tight tolerance (one solver iteration) under the same
//! controller. The table gives, against the reference: each pin's largest force and deepest
//! penetration, and the RMS distance of the hand from the ideal arm's hand (what the play costs;
//! the reference's against an ideal arm at the reference's steps); and the cost of a world step
//! against the ideal arm's at the world rate, measured in the same run.
//!
//! `-- --ablation`: the arm at 1 kHz and 0.1 mm with each technique of the planar sub-cycle
//! off in turn ([`SubCycleTechniques`]) against the same reference: world steps, sub-steps,
//! wall time, the pins' peaks, depths and onsets, the hand's offset; printed and written to
//! `bench_out/ablation_arm.md`.
//!
//! `SCARA_ENSEMBLE=1`: the largest force of a rattling arm is one sample of a chaotic run, so
//! the arms are compared as ensembles. For each clearance (`SCARA_CLEARANCES` in mm, default
//! `0.01,0.1`) and world rate (`SCARA_RATES`, default 1000) the sub-cycled arm and the
//! reference run from the nominal start and four perturbed ones (the clearance times
//! 1 -+ 1e-4 and 1 -+ 1e-3); each run's metrics and each pin's five largest impacts (approach
//! speed, force) are printed, then the sub-cycled arms' mean of each metric against the
//! references' [min, max] and mean, flagged where it is more than 5 % outside the range.
//! `SCARA_REFERENCE_TOLERANCE` and `SCARA_REFERENCE_MAX_DT` (default 0.001 and 1e-5 s) set the
//! reference's convergence, `SCARA_STARTS=1` runs the nominal start only,
//! `SCARA_STEPS_PER_TICK=4` steps the sub-cycled arm's world four times per controller tick.
//! `SCARA_RATE=difference` (every mode) reads each joint's rate for the controller as its
//! angle's change over the last tick, `SCARA_RATE=state` as the bodies' velocity at the state
//! (`ClearanceWorld::velocity_at_state`), `SCARA_RATE_FILTER=0.005` through a low pass of that
//! time constant (s). `SCARA_PERTURB=gain` makes the starts scale the controller's gains instead
//! of the clearance, `SCARA_PERTURBATIONS=0,-0.01,0.01` sets the starts' relative
//! perturbations, `SCARA_REFERENCE=none` leaves the reference out,
//! `SCARA_IDEAL_STEPS_PER_TICK=40` steps the ideal arm's world 40 times per tick, and
//! `SCARA_COST=3` only times a world step of the sub-cycled arm against the ideal arm's, the two
//! run in turn three times (each tolerance of `SCARA_TOLERANCE`; the fastest of the three
//! too). A list `SCARA_TOLERANCE=0.0075,0.02,0.05` runs one sub-cycled arm per tolerance
//! against the same references and ends each clearance with a work-precision table: per
//! tolerance, sub-steps per world step, cost per world step over the ideal arm's (the fastest
//! start's over the fastest of five ideal runs), the peaks', depths' and hand offset's means
//! against the references' (flagged more than 5 % outside their range), guard messages.
//! `SCARA_CLOCK=cpu` times every cost by the process's CPU time instead of the wall clock
//! (a shared machine's other work then lengthens neither arm). `SCARA_TRACE=/tmp/arm` (every mode) writes, per arm, each tick's
//! state of each pin (at the joint's report and from Rapier's bodies), each step's first
//! sub-step and every impact to `/tmp/arm_<arm>_<clearance in um>_<world steps>.csv`.
//! `SCARA_DETAIL=0.007,0.0075` (every mode) prints on stderr each world step's report of each
//! pin inside that window (s): penetration, rates, forces, effective mass, tilt, axial offset,
//! each region's force, and a sub-cycled pin's sub-steps.
//!
//! Knobs for diagnosis (environment): `SCARA_RATES=60,1000` (world rates, Hz),
//! `SCARA_TOLERANCE` (the sub-cycled arms' tolerance, default 0.0075), `SCARA_PINS=shoulder` or
//! `elbow` (play in that pin only, the other an ideal revolute), `SCARA_ITERS` (the sub-cycled
//! arms' solver iterations, default 4), `SCARA_IMPACTS=1` (each arm's five largest impacts),
//! `SCARA_AXIAL` (the links' inertia about their length over the transverse one, default 0.1;
//! `examples/robot_backlash.rs` has 0.001), `SCARA_PLANE=1` (each arm's largest drop of the
//! lower link's centre of mass out of the arm's plane and its largest spin about its length), `SCARA_SPATIAL=0.1`
//! (both pins spatial, with 0.1 mm of axial play and collars of twice the pin's radius;
//! `SCARA_UNCOUPLED=1` each spatial pin sub-cycled on its own), `SCARA_END=0.1` (a shorter
//! run, s).

use clearance_joint::model::laws::{Coulomb, FrictionModel};
use clearance_joint::prelude::*;
use clearance_joint::rapier::observers::metrics::{ContactObservation, Impact, ImpactRecorder};
use rapier3d_f64::prelude::*;
use std::f64::consts::PI;
use std::time::Instant;

/// Simulated time: one swing out, hold, swing back, hold, s.
const END: f64 = 1.5;
const UPPER: (f64, f64) = (2.0, 0.4); // mass kg, length m
const LOWER: (f64, f64) = (1.0, 0.3);
/// Inertia each joint's controller is tuned for (about its pin, elbow straight), kg m^2.
const TUNED_INERTIA: [f64; 2] = [0.45, 0.035];
/// Pin: bearing radius and width, m; dry friction.
const PIN_RADIUS: f64 = 0.006;
const PIN_WIDTH: f64 = 0.012;
const MU: f64 = 0.1;
/// The reference's tolerance (the default is 0.0075).
const REFERENCE_TOLERANCE: f64 = 0.001;
/// The reference's largest step, s: Rapier's ideal joints converge with the step, not with the
/// tolerance.
const REFERENCE_MAX_DT: f64 = 1e-5;
const MOVE: f64 = 0.5;
const HOLD: f64 = 0.25;

/// PD gains per joint for a controller ticking every `dt`: closed-loop bandwidth 5 Hz, damping
/// ratio 0.7, slowed to `0.03/dt` rad/s when the tick is too slow for it (below 200 Hz: the
/// ideal arm at 60 Hz diverges with `0.1/dt`).
fn gains(dt: f64) -> [(f64, f64); 2] {
    let w = (2.0 * PI * 5.0).min(0.03 / dt);
    TUNED_INERTIA.map(|i| (i * w * w, 2.0 * 0.7 * i * w))
}

/// Target joint angles and rates at `t`: swing out in `MOVE`, hold, swing back, hold.
fn target(t: f64) -> ([f64; 2], [f64; 2]) {
    let out = [90f64.to_radians(), -75f64.to_radians()];
    let p = t % (2.0 * (MOVE + HOLD));
    let w = PI / MOVE;
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

#[derive(Clone, Copy, Debug, PartialEq)]
enum Pins {
    Ideal,
    Compliant(ContactIntegration),
}

struct Arm {
    world: ClearanceWorld,
    pairs: [(RigidBodyHandle, RigidBodyHandle); 2],
    lower: RigidBodyHandle,
    pins: Vec<ClearanceJointHandle>,
    recorders: [ImpactRecorder; 2],
    angles: [clearance_joint::model::angle::HingeAngle; 2],
    /// The joint angles at the last tick (`SCARA_RATE=difference`).
    last_angles: [Option<f64>; 2],
    /// The rates the controller read at the last tick, low-passed (`SCARA_RATE_FILTER`).
    filtered: [Option<f64>; 2],
}

/// `SCARA_SPATIAL=0.1`: the pins spatial, with that axial play in mm and collars of twice the
/// pin's radius; unset, planar.
fn spatial_pins() -> ClearanceModel {
    match std::env::var("SCARA_SPATIAL")
        .ok()
        .and_then(|t| t.parse::<f64>().ok())
    {
        Some(play) => ClearanceModel::Spatial(
            clearance_joint::model::spatial::SpatialModel::steel(play * 1e-3, 2.0 * PIN_RADIUS),
        ),
        None => ClearanceModel::Compliant,
    }
}

/// The links' inertia about their length over the transverse one (`SCARA_AXIAL`). At a
/// thousandth (the example's slender links) Rapier's joints do not hold the lower link in the
/// arm's plane at 60 and 120 Hz, the ideal arm's too (its centre of mass leaves the plane by
/// up to 0.21 and 0.08 m, spinning across it at up to 230 and 26 rad/s); at a tenth the ideal
/// arm's stays within 2 mm of the plane at 60 Hz.
fn axial_inertia() -> f64 {
    std::env::var("SCARA_AXIAL")
        .ok()
        .and_then(|t| t.parse().ok())
        .unwrap_or(0.1)
}

fn link(world: &mut PhysicsWorld, (mass, length): (f64, f64), start: f64) -> RigidBodyHandle {
    let j = mass * length * length / 12.0;
    world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(start + 0.5 * length, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                mass,
                Vector::new(axial_inertia() * j, j, j),
            ))
            .can_sleep(false),
    )
}

impl Arm {
    fn new(
        pins: Pins,
        clearance: f64,
        control: StepControl,
        techniques: SubCycleTechniques,
    ) -> clearance_joint::Result<Arm> {
        let mut rapier = PhysicsWorld::new();
        rapier.gravity = Vector::new(0.0, 0.0, -9.81);
        // Four iterations, Rapier's default, except for the explicit reference, which needs one.
        if pins == Pins::Compliant(ContactIntegration::Explicit) {
            rapier.integration_parameters.num_solver_iterations = 1;
        }
        if let (Pins::Compliant(ContactIntegration::SubCycled), Some(n)) = (
            pins,
            std::env::var("SCARA_ITERS")
                .ok()
                .and_then(|t| t.parse().ok()),
        ) {
            rapier.integration_parameters.num_solver_iterations = n;
        }
        let base = rapier.bodies.insert(RigidBodyBuilder::fixed());
        let upper = link(&mut rapier, UPPER, 0.0);
        let lower = link(&mut rapier, LOWER, UPPER.1);
        let pairs = [(base, upper), (upper, lower)];
        let anchors = [
            (Vector::ZERO, Vector::new(-0.5 * UPPER.1, 0.0, 0.0)),
            (
                Vector::new(0.5 * UPPER.1, 0.0, 0.0),
                Vector::new(-0.5 * LOWER.1, 0.0, 0.0),
            ),
        ];
        let mut world = ClearanceWorld::new(rapier, control);
        let mut handles = Vec::new();
        for (i, ((b1, b2), (a1, a2))) in pairs.into_iter().zip(anchors).enumerate() {
            let only = std::env::var("SCARA_PINS").unwrap_or_default();
            let ideal_here = (only == "shoulder" && i == 1) || (only == "elbow" && i == 0);
            match pins {
                Pins::Compliant(integration) if !ideal_here => {
                    let joint = HingeDesign::steel_improved_liu(PIN_RADIUS, clearance, PIN_WIDTH)?
                        .friction(FrictionModel::Coulomb(Coulomb::new(MU, 1e-4)?))
                        .integration(integration)
                        .sub_cycle_techniques(techniques)
                        .model(spatial_pins())
                        .name(["shoulder", "elbow"][i])
                        .joint(a1, a2, Vector::Z, Vector::Z)?;
                    handles.push(world.insert_clearance(b1, b2, joint)?);
                }
                _ => {
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
        }
        world.prepare()?;
        Ok(Arm {
            world,
            pairs,
            lower,
            pins: handles,
            recorders: Default::default(),
            angles: Default::default(),
            last_angles: [None; 2],
            filtered: [None; 2],
        })
    }

    /// The hand: the tip of the lower link.
    fn hand(&self) -> Vector {
        *self.world.rapier.bodies[self.lower].position() * Vector::new(0.5 * LOWER.1, 0.0, 0.0)
    }

    /// The controller's torques at `t` (held over the tick), then the world stepped to `until`.
    fn tick(&mut self, t: f64, until: f64, gains: [(f64, f64); 2]) -> clearance_joint::Result<()> {
        let (qt, rt) = target(t);
        for (k, (b1, b2)) in self.pairs.iter().enumerate() {
            let bodies = &self.world.rapier.bodies;
            let (r1, r2) = (&bodies[*b1], &bodies[*b2]);
            let q = self.angles[k].update(r1.rotation(), r2.rotation(), Vector::Z);
            let mut rate = (r2.angvel() - r1.angvel()).z;
            // `SCARA_RATE=state`: the bodies' velocity at the state
            // (`ClearanceWorld::velocity_at_state`: a sub-cycled step's Rapier velocities do
            // not hold the part of its impulse delivered with the next step).
            if std::env::var("SCARA_RATE").is_ok_and(|r| r == "state") {
                let w = |b| self.world.velocity_at_state(b).expect("in the world").1;
                rate = (w(*b2) - w(*b1)).z;
            }
            // `SCARA_RATE=difference`: the joint's rate read as its angle's change over the
            // last tick, the same in every arm, instead of the bodies' stored velocities
            // (a sub-cycled step stores the mean over the step, the reference's the end's).
            if std::env::var("SCARA_RATE").is_ok_and(|r| r == "difference") {
                if let Some(last) = self.last_angles[k] {
                    rate = (q - last) / (until - t);
                }
                self.last_angles[k] = Some(q);
            }
            // `SCARA_RATE_FILTER=tau` (s): the rate read through a first-order low pass of
            // time constant `tau` at the tick, the same in every arm (diagnosis: what the
            // controller makes of the rattle's velocity jumps).
            if let Some(tau) = std::env::var("SCARA_RATE_FILTER")
                .ok()
                .and_then(|t| t.parse::<f64>().ok())
            {
                let f = self.filtered[k].unwrap_or(rate);
                rate = f + (rate - f) * ((until - t) / tau).min(1.0);
                self.filtered[k] = Some(rate);
            }
            let (kp, kd) = gains[k];
            let tau = Vector::new(0.0, 0.0, kp * (qt[k] - q) + kd * (rt[k] - rate));
            for (body, sign) in [(*b2, 1.0), (*b1, -1.0)] {
                let rb = &mut self.world.rapier.bodies[body];
                if k == 0 || sign > 0.0 {
                    rb.reset_torques(false);
                }
                rb.add_torque(sign * tau, true);
            }
        }
        // Torques changed by hand: the joints' evaluation at this state stands, the forces on
        // the bodies are read by Rapier's step.
        while self.world.time() < until {
            let before: Vec<ContactObservation> = self
                .pins
                .iter()
                .map(|h| ContactObservation::of(self.world.clearance.get(*h).expect("inserted")))
                .collect();
            let info = self.world.step(until)?;
            for (k, h) in self.pins.iter().enumerate() {
                let j = self.world.clearance.get(*h).expect("inserted");
                self.recorders[k].record_step(info.t0, info.dt, &before[k], j.substeps());
                detail(j, k, info.t0 + info.dt);
            }
        }
        Ok(())
    }
}

/// What one arm did over the run.
#[derive(Clone, Debug, Default)]
struct Outcome {
    /// Per pin: largest force (N), deepest penetration (um), onsets.
    peak: [f64; 2],
    depth: [f64; 2],
    onsets: [u64; 2],
    /// The hands at each tick.
    hands: Vec<Vector>,
    steps: u64,
    /// Largest sub-steps of one world step (either pin).
    max_substeps: usize,
    /// Sub-steps over the run, both pins.
    substeps: u64,
    wall_s: f64,
    /// The process's CPU time over the run, s ([`cpu_seconds`]).
    cpu_s: f64,
    /// The guards' messages (empty: the run stayed valid).
    guards: Vec<String>,
    /// The lower link's largest drop out of the arm's plane (m) and spin about the plane's
    /// in-plane axes (rad/s).
    out_of_plane: (f64, f64),
    /// Per pin: the five largest impacts by force, largest first.
    top: [Vec<Impact>; 2],
}

fn run(
    pins: Pins,
    clearance: f64,
    rate: f64,
    control: StepControl,
) -> clearance_joint::Result<Outcome> {
    // `SCARA_UNCOUPLED=1`: each spatial pin sub-cycled on its own (diagnosis: the two pins
    // in series then diverge).
    let uncoupled = std::env::var("SCARA_UNCOUPLED").is_ok();
    let techniques = SubCycleTechniques::default().spatial_coupling(!uncoupled);
    run_with(pins, clearance, rate, control, techniques)
}

fn run_with(
    pins: Pins,
    clearance: f64,
    rate: f64,
    control: StepControl,
    techniques: SubCycleTechniques,
) -> clearance_joint::Result<Outcome> {
    let tick = 1.0 / rate;
    let scale = f64::from_bits(GAIN_SCALE.load(std::sync::atomic::Ordering::Relaxed));
    let gains = gains(tick).map(|(kp, kd)| (kp * scale, kd * scale));
    let mut arm = Arm::new(pins, clearance, control, techniques)?;
    // `SCARA_END=0.1`: a shorter run (s; diagnosis of the first impacts).
    let end = std::env::var("SCARA_END")
        .ok()
        .and_then(|t| t.parse().ok())
        .unwrap_or(END);
    let ticks = (end / tick).round() as u64;
    let mut o = Outcome::default();
    let clock = Instant::now();
    let cpu = cpu_seconds();
    // `SCARA_TRACE=path`: each tick's state of each pin, as the sub-cycle ended it and as
    // Rapier's bodies have it, written to `path`.
    let mut trace = std::env::var("SCARA_TRACE").ok().map(|_| String::new());
    for i in 0..ticks {
        let t = i as f64 * tick;
        arm.tick(t, (i + 1) as f64 * tick, gains)?;
        if let Some(out) = trace.as_mut() {
            trace_tick(&arm, (i + 1) as f64 * tick, out);
        }
        o.hands.push(arm.hand());
        let lower = &arm.world.rapier.bodies[arm.lower];
        let w = lower.angvel();
        o.out_of_plane.0 = o.out_of_plane.0.max(lower.center_of_mass().z.abs());
        o.out_of_plane.1 = o.out_of_plane.1.max(w.x.hypot(w.y));
        for h in &arm.pins {
            let n = arm
                .world
                .clearance
                .get(*h)
                .expect("inserted")
                .substeps()
                .len();
            o.max_substeps = o.max_substeps.max(n);
        }
    }
    o.wall_s = clock.elapsed().as_secs_f64();
    o.cpu_s = cpu_seconds() - cpu;
    if let (Some(out), Ok(path)) = (trace, std::env::var("SCARA_TRACE")) {
        let path = format!(
            "{path}_{pins:?}_{}_{}.csv",
            clearance * 1e6,
            arm.world.steps()
        );
        let mut all = out;
        for (k, r) in arm.recorders.iter().enumerate() {
            for i in r.contacts() {
                all.push_str(&format!(
                    "impact,{k},{:.7},{:.6},{:.3},{:.5},{:.4},{:.2}\n",
                    i.onset_t_s,
                    i.approach_speed_m_s,
                    i.peak_force_n,
                    i.peak_t_s,
                    i.max_penetration_um,
                    i.duration_s * 1e6
                ));
            }
        }
        let _ = std::fs::write(&path, all);
    }
    o.steps = arm.world.steps();
    for k in 0..arm.pins.len() {
        o.substeps += arm.recorders[k].substeps_recorded();
        let m = arm.recorders[k].metrics();
        o.peak[k] = m.peak_force_n;
        o.depth[k] = m.max_penetration_um;
        o.onsets[k] = m.onsets;
        let mut list: Vec<Impact> = arm.recorders[k].contacts().to_vec();
        list.sort_by(|a, b| b.peak_force_n.total_cmp(&a.peak_force_n));
        list.truncate(5);
        o.top[k] = list;
    }
    o.guards = arm.world.guards().messages();
    if std::env::var("SCARA_PLANE").is_ok() {
        eprintln!(
            "{pins:?}, {} mm, {rate} Hz: the lower link {:.2e} m out of the plane at most, \
             spinning across it at up to {:.3} rad/s",
            clearance * 1e3,
            o.out_of_plane.0,
            o.out_of_plane.1
        );
    }
    if std::env::var("SCARA_IMPACTS").is_ok() {
        for (k, list) in o.top.iter().enumerate() {
            for i in list {
                eprintln!(
                    "{pins:?} pin {k}: onset {:.5} s, approach {:.4} m/s, peak {:.1} N at {:.5}, depth {:.3} um, {:.1} us",
                    i.onset_t_s,
                    i.approach_speed_m_s,
                    i.peak_force_n,
                    i.peak_t_s,
                    i.max_penetration_um,
                    i.duration_s * 1e6
                );
            }
        }
    }
    Ok(o)
}

/// One tick's line per pin (`SCARA_TRACE`): time, pin, the eccentricity and its rate at the
/// joint's report (a sub-cycled joint's: the sub-cycle's end), the same read from Rapier's
/// bodies (their velocities plus the joint's velocity correction), and the links' spins.
fn trace_tick(arm: &Arm, t: f64, out: &mut String) {
    let bodies = &arm.world.rapier.bodies;
    if arm.pins.is_empty() {
        let (u, l) = (&bodies[arm.pairs[1].0], &bodies[arm.pairs[1].1]);
        out.push_str(&format!(
            "tick,{t:.6},9,0,0,0,0,0,0,0,0,{:.6e},{:.6e}\n",
            u.angvel().z,
            l.angvel().z
        ));
    }
    for (k, h) in arm.pins.iter().enumerate() {
        let j = arm.world.clearance.get(*h).expect("inserted");
        let (b1, b2) = (&bodies[j.body1()], &bodies[j.body2()]);
        let p1 = *b1.position() * j.local_anchor1();
        let p2 = *b2.position() * j.local_anchor2();
        let mut v = [b1.linvel(), b1.angvel(), b2.linvel(), b2.angvel()];
        for (n, (_, dv, dw)) in j.start_velocity_correction().into_iter().enumerate() {
            v[2 * n] += dv;
            v[2 * n + 1] += dw;
        }
        let vp1 = v[0] + v[1].cross(p1 - b1.center_of_mass());
        let vp2 = v[2] + v[3].cross(p2 - b2.center_of_mass());
        let (e, r) = (p2 - p1, vp2 - vp1);
        let s = &j.report().state;
        if let Some(f) = j.substeps().first() {
            let f0 = &f.state;
            out.push_str(&format!(
                "first,{t:.6},{k},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{}\n",
                f0.eccentricity.x,
                f0.eccentricity.y,
                f0.eccentricity_rate.x,
                f0.eccentricity_rate.y,
                f.t,
                j.substeps().len()
            ));
        }
        out.push_str(&format!(
            "tick,{t:.6},{k},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e}\n",
            s.eccentricity.x,
            s.eccentricity.y,
            s.eccentricity_rate.x,
            s.eccentricity_rate.y,
            e.x,
            e.y,
            r.x,
            r.y,
            b1.angvel().z,
            b2.angvel().z
        ));
    }
}

/// `SCARA_DETAIL=t0,t1` (s): each world step's state of each pin inside that window, on
/// stderr: penetration (um) and its rate, the law's rates, forces, effective mass, tilt, axial
/// offset and each region's force; a sub-cycled joint's sub-steps too.
fn detail(j: &ClearanceJoint, k: usize, t: f64) {
    let Some(w) = std::env::var("SCARA_DETAIL").ok() else {
        return;
    };
    let b: Vec<f64> = w.split(',').filter_map(|x| x.parse().ok()).collect();
    if b.len() != 2 || t < b[0] || t > b[1] {
        return;
    }
    let r = j.report();
    let s = &r.state;
    let sp = r.spatial.unwrap_or_default();
    eprintln!(
        "D {t:.7} {k} pen {:.4} rate {:.5} crate {:.5} irate {:.5} FN {:.2} Ff {:.2} m {:.4} tilt {:.3e} {:.3e} ax {:.3e} edge {:.2} {:.2} len {:.3e} {:.3e} face {:.2} {:.2} n {:.4} {:.4} {:.4} pt {:.5} {:.5} {:.5}",
        s.penetration * 1e6,
        s.penetration_rate,
        r.contact_rate,
        r.impact_rate,
        r.force.normal_force,
        r.force.friction_force,
        r.effective_mass,
        sp.tilt[0],
        sp.tilt[1],
        sp.axial_offset,
        sp.edge_force[0],
        sp.edge_force[1],
        sp.edge_length[0],
        sp.edge_length[1],
        sp.face_force[0],
        sp.face_force[1],
        s.normal.x,
        s.normal.y,
        s.normal.z,
        s.contact_point.x,
        s.contact_point.y,
        s.contact_point.z,
    );
    for q in j.substeps() {
        eprintln!(
            "S {:.7} {k} pen {:.4} rate {:.5} FN {:.2} Ff {:.2} F {:.2} {:.2} {:.2}",
            t - j.substeps().last().map_or(0.0, |l| l.t) + q.t,
            q.state.penetration * 1e6,
            q.state.penetration_rate,
            q.force.normal_force,
            q.force.friction_force,
            q.force.on_journal.x,
            q.force.on_journal.y,
            q.force.on_journal.z
        );
    }
}

/// RMS distance between two arms' hands, mm.
/// The CPU time the process's threads have run, s (Linux's `schedstat`; 0 elsewhere): unlike
/// the wall clock, not lengthened by the time other work on a shared machine holds the core.
fn cpu_seconds() -> f64 {
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else {
        return 0.0;
    };
    tasks
        .filter_map(|t| std::fs::read_to_string(t.ok()?.path().join("schedstat")).ok())
        .filter_map(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .sum::<f64>()
        * 1e-9
}

fn rms_offset(a: &Outcome, b: &Outcome) -> f64 {
    let sq: f64 = a
        .hands
        .iter()
        .zip(&b.hands)
        .map(|(p, q)| (*p - *q).length_squared())
        .sum();
    (sq / a.hands.len() as f64).sqrt() * 1e3
}

fn pct(x: f64, reference: f64) -> String {
    if reference > 0.0 {
        format!("{:+.1} %", (x / reference - 1.0) * 100.0)
    } else {
        format!("{x:.3e} (ref 0)")
    }
}

fn main() {
    if std::env::args().any(|a| a == "--ablation") {
        ablation();
        return;
    }
    if std::env::var("SCARA_ENSEMBLE").is_ok() {
        ensemble();
        return;
    }
    let quick = std::env::args().any(|a| a == "--quick");
    // The sub-cycled arms' tolerance (`SCARA_TOLERANCE`, default the library's 0.0075).
    let tolerance = std::env::var("SCARA_TOLERANCE")
        .ok()
        .and_then(|t| t.parse().ok())
        .unwrap_or(0.0075);
    let clearances: &[f64] = if quick {
        &[0.1e-3]
    } else {
        &[0.01e-3, 0.1e-3, 1e-3]
    };
    let rates: Vec<f64> = match std::env::var("SCARA_RATES") {
        Ok(list) => list.split(',').filter_map(|r| r.parse().ok()).collect(),
        Err(_) if quick => vec![60.0, 1000.0, 10_000.0],
        Err(_) => vec![60.0, 250.0, 1000.0, 4000.0, 10_000.0],
    };
    println!(
        "| clearance (mm) | world rate (Hz) | world steps | largest sub-steps per step | peak force shoulder, elbow (N) vs reference | deepest penetration shoulder, elbow (um) vs reference | onsets vs reference | hand RMS offset from the ideal arm (mm) vs reference | cost per world step / ideal arm's |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for &c in clearances {
        for &rate in &rates {
            let tick = 1.0 / rate;
            let ideal = run(Pins::Ideal, c, rate, StepControl::fixed(tick));
            let sub = run(
                Pins::Compliant(ContactIntegration::SubCycled),
                c,
                rate,
                StepControl {
                    tolerance,
                    ..StepControl::fixed(tick)
                },
            );
            let reference = run(
                Pins::Compliant(ContactIntegration::Explicit),
                c,
                rate,
                StepControl::adaptive(tick.min(REFERENCE_MAX_DT), REFERENCE_TOLERANCE),
            );
            // The reference's own ideal arm, at the reference's steps: what the play costs
            // when neither arm carries Rapier's error at the world rate.
            let ideal_reference = run(
                Pins::Ideal,
                c,
                rate,
                StepControl::fixed(tick.min(REFERENCE_MAX_DT)),
            )
            .expect("the ideal arm at the reference's steps");
            let (ideal, sub, reference) = match (ideal, sub, reference) {
                (Ok(i), Ok(s), Ok(r)) => (i, s, r),
                (i, s, r) => {
                    let err = |x: &clearance_joint::Result<Outcome>| match x {
                        Ok(_) => "ok".to_string(),
                        Err(e) => format!("{e}"),
                    };
                    println!(
                        "| {} | {rate} | failed: ideal {}; sub-cycled {}; reference {} |",
                        c * 1e3,
                        err(&i),
                        err(&s),
                        err(&r)
                    );
                    continue;
                }
            };
            for (name, o) in [("sub-cycled", &sub), ("reference", &reference)] {
                for g in &o.guards {
                    eprintln!("  {} mm, {rate} Hz, {name}: {g}", c * 1e3);
                }
            }
            let (off, off_ref) = (
                rms_offset(&sub, &ideal),
                rms_offset(&reference, &ideal_reference),
            );
            let cost = (sub.wall_s / sub.steps as f64) / (ideal.wall_s / ideal.steps as f64);
            println!(
                "| {} | {rate} | {} | {} | {:.1}, {:.1} ({}, {}) | {:.3}, {:.3} ({}, {}) | {}, {} ({}, {}) | {:.4} ({}) | {:.2} |",
                c * 1e3,
                sub.steps,
                sub.max_substeps,
                sub.peak[0],
                sub.peak[1],
                pct(sub.peak[0], reference.peak[0]),
                pct(sub.peak[1], reference.peak[1]),
                sub.depth[0],
                sub.depth[1],
                pct(sub.depth[0], reference.depth[0]),
                pct(sub.depth[1], reference.depth[1]),
                sub.onsets[0],
                sub.onsets[1],
                reference.onsets[0],
                reference.onsets[1],
                off,
                pct(off, off_ref),
                cost
            );
        }
    }
}

/// The arm at 1 kHz and 0.1 mm, sub-cycled with each planar technique off in turn, against the
/// explicit reference (`-- --ablation`).
fn ablation() {
    let (c, rate) = (0.1e-3, 1000.0);
    let tick = 1.0 / rate;
    let control = StepControl {
        tolerance: 0.0075,
        ..StepControl::fixed(tick)
    };
    let ideal = run(Pins::Ideal, c, rate, StepControl::fixed(tick)).expect("the ideal arm");
    let reference = run(
        Pins::Compliant(ContactIntegration::Explicit),
        c,
        rate,
        StepControl::adaptive(REFERENCE_MAX_DT, REFERENCE_TOLERANCE),
    )
    .expect("the reference");
    let ideal_reference = run(Pins::Ideal, c, rate, StepControl::fixed(REFERENCE_MAX_DT))
        .expect("the ideal arm at the reference's steps");
    let all = SubCycleTechniques::default();
    let mut rows: Vec<(String, SubCycleTechniques)> = vec![("all on".into(), all)];
    for (name, _) in all.switches().into_iter().take(5) {
        let off = match name {
            "implicit_friction" => all.implicit_friction(false),
            "implicit_damping" => all.implicit_damping(false),
            "continuation" => all.continuation(false),
            "continuity_rounds" => all.continuity_rounds(false),
            _ => all.stabilisation(false),
        };
        rows.push((format!("{name} off"), off));
    }
    let mut md = String::from(
        "| arm, 0.1 mm, 1 kHz | world steps | sub-steps | wall (s) | peak force shoulder, elbow (N) \
         vs reference | deepest penetration shoulder, elbow (um) vs reference | onsets \
         | hand RMS offset from the ideal arm (mm) vs reference | guards |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    md.push_str(&format!(
        "| reference: explicit, tolerance {REFERENCE_TOLERANCE}, steps of at most {REFERENCE_MAX_DT:e} s \
         | {} | 0 | {:.2} | {:.1}, {:.1} | {:.3}, {:.3} | {}, {} | {:.4} | {} |\n",
        reference.steps,
        reference.wall_s,
        reference.peak[0],
        reference.peak[1],
        reference.depth[0],
        reference.depth[1],
        reference.onsets[0],
        reference.onsets[1],
        rms_offset(&reference, &ideal_reference),
        if reference.guards.is_empty() { "clean".into() } else { reference.guards.join("; ") }
    ));
    let off_ref = rms_offset(&reference, &ideal_reference);
    for (label, techniques) in rows {
        let sub = run_with(
            Pins::Compliant(ContactIntegration::SubCycled),
            c,
            rate,
            control,
            techniques,
        );
        let line = match sub {
            Err(e) => {
                format!("| sub-cycled, {label} | - | - | - | - | - | - | - | **failed**: {e} |")
            }
            Ok(s) => {
                let off = rms_offset(&s, &ideal);
                format!(
                    "| sub-cycled, {label} | {} | {} | {:.2} | {:.1}, {:.1} ({}, {}) | {:.3}, {:.3} ({}, {}) | {}, {} | {:.4} ({}) | {} |",
                    s.steps,
                    s.substeps,
                    s.wall_s,
                    s.peak[0],
                    s.peak[1],
                    pct(s.peak[0], reference.peak[0]),
                    pct(s.peak[1], reference.peak[1]),
                    s.depth[0],
                    s.depth[1],
                    pct(s.depth[0], reference.depth[0]),
                    pct(s.depth[1], reference.depth[1]),
                    s.onsets[0],
                    s.onsets[1],
                    off,
                    pct(off, off_ref),
                    if s.guards.is_empty() {
                        "clean".into()
                    } else {
                        s.guards.join("; ")
                    }
                )
            }
        };
        eprintln!("{line}");
        md.push_str(&line);
        md.push('\n');
    }
    println!("{md}");
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("bench_out");
    let _ = std::fs::create_dir_all(&dir);
    if let Err(e) = std::fs::write(dir.join("ablation_arm.md"), md) {
        eprintln!("cannot write bench_out/ablation_arm.md: {e}");
    }
}

/// Relative perturbations of the clearance in the ensemble: the nominal start and four a user
/// would take for the same arm.
const PERTURBATIONS: [f64; 5] = [0.0, -1e-4, 1e-4, -1e-3, 1e-3];

/// The controller's gains' scale for the next run (1; the ensemble's `SCARA_PERTURB=gain`),
/// as the bits of an `f64`.
static GAIN_SCALE: std::sync::atomic::AtomicU64 =
    std::sync::atomic::AtomicU64::new(0x3FF0_0000_0000_0000);

/// The metrics compared across an ensemble: name, and the value from a run and its hand's RMS
/// offset (mm).
type Metric = (&'static str, fn(&Outcome, f64) -> f64);

/// Mean approach speed of a pin's five largest impacts, m/s (0 without impacts).
fn top_approach(o: &Outcome, pin: usize) -> f64 {
    let t = &o.top[pin];
    t.iter().map(|i| i.approach_speed_m_s).sum::<f64>() / t.len().max(1) as f64
}

const METRICS: [Metric; 9] = [
    ("peak force shoulder (N)", |o, _| o.peak[0]),
    ("peak force elbow (N)", |o, _| o.peak[1]),
    ("deepest penetration shoulder (um)", |o, _| o.depth[0]),
    ("deepest penetration elbow (um)", |o, _| o.depth[1]),
    ("onsets shoulder", |o, _| o.onsets[0] as f64),
    ("onsets elbow", |o, _| o.onsets[1] as f64),
    ("hand RMS offset from the ideal arm (mm)", |_, off| off),
    (
        "five largest impacts' mean approach, shoulder (m/s)",
        |o, _| top_approach(o, 0),
    ),
    (
        "five largest impacts' mean approach, elbow (m/s)",
        |o, _| top_approach(o, 1),
    ),
];

/// The arm's ensembles (`SCARA_ENSEMBLE=1`): sub-cycled against the reference from perturbed
/// starts.
fn ensemble() {
    let list = |name: &str, default: &[f64]| -> Vec<f64> {
        match std::env::var(name) {
            Ok(l) => l.split(',').filter_map(|r| r.parse().ok()).collect(),
            Err(_) => default.to_vec(),
        }
    };
    // `SCARA_TOLERANCE=0.0075,0.02,0.05`: one sub-cycled arm per tolerance, each against the
    // same reference runs (the work-precision table).
    let tolerances = list("SCARA_TOLERANCE", &[0.0075]);
    let clearances = list("SCARA_CLEARANCES", &[0.01, 0.1]);
    let rates = list("SCARA_RATES", &[1000.0]);
    // `SCARA_COST=n`: the cost of a world step against the ideal arm's, the two run in turn
    // n times (timings on a shared machine are noisy), then nothing else.
    // Each run's wall time per world step (of the whole run); `SCARA_CLOCK=cpu`: its CPU
    // time ([`cpu_seconds`]).
    let cpu = std::env::var("SCARA_CLOCK").is_ok_and(|c| c == "cpu");
    let per_step = |o: &Outcome| if cpu { o.cpu_s } else { o.wall_s } / o.steps as f64;
    if let Some(&n) = list("SCARA_COST", &[]).first() {
        for &rate in &rates {
            for &mm in &clearances {
                for &tolerance in &tolerances {
                    let control = StepControl {
                        tolerance,
                        ..StepControl::fixed(1.0 / rate)
                    };
                    // The fastest of the n runs of each arm: the least disturbed by the other
                    // work on the machine.
                    let (mut best_ideal, mut best_sub) = (f64::INFINITY, f64::INFINITY);
                    for _ in 0..n as usize {
                        let ideal = run(Pins::Ideal, 0.0, rate, control).expect("the ideal arm");
                        let sub = run(
                            Pins::Compliant(ContactIntegration::SubCycled),
                            mm * 1e-3,
                            rate,
                            control,
                        )
                        .expect("the sub-cycled arm");
                        best_ideal = best_ideal.min(per_step(&ideal));
                        best_sub = best_sub.min(per_step(&sub));
                        println!(
                            "{mm} mm, {rate} Hz, tolerance {tolerance}: ideal {:.2} us, sub-cycled {:.1} us \
                             a world step ({:.1} sub-steps of both pins): {:.1} times",
                            per_step(&ideal) * 1e6,
                            per_step(&sub) * 1e6,
                            sub.substeps as f64 / sub.steps as f64,
                            per_step(&sub) / per_step(&ideal)
                        );
                        for g in &sub.guards {
                            eprintln!("  {mm} mm, {rate} Hz, tolerance {tolerance}: {g}");
                        }
                    }
                    println!(
                        "{mm} mm, {rate} Hz, tolerance {tolerance}: fastest of {n}: ideal {:.2} us, \
                         sub-cycled {:.1} us: {:.1} times",
                        best_ideal * 1e6,
                        best_sub * 1e6,
                        best_sub / best_ideal
                    );
                }
            }
        }
        return;
    }
    // The reference's own convergence: its tolerance and largest step, and the starts run
    // (the first `SCARA_STARTS` of the perturbations).
    let ref_tolerance = list("SCARA_REFERENCE_TOLERANCE", &[REFERENCE_TOLERANCE])[0];
    let ref_max_dt = list("SCARA_REFERENCE_MAX_DT", &[REFERENCE_MAX_DT])[0];
    // `SCARA_PERTURBATIONS`: the starts' relative perturbations (default the five above);
    // `SCARA_PERTURB=gain`: they scale the controller's gains instead of the clearance (the
    // arm's slow motion moved, as a world step's error of it moves it).
    let perturbations = list("SCARA_PERTURBATIONS", &PERTURBATIONS);
    let on_gain = std::env::var("SCARA_PERTURB").is_ok_and(|w| w == "gain");
    let starts = list("SCARA_STARTS", &[perturbations.len() as f64])[0] as usize;
    // The sub-cycled arm's world steps per controller tick: its world's step apart from the
    // controller's tick.
    let per_tick = list("SCARA_STEPS_PER_TICK", &[1.0])[0];
    for &rate in &rates {
        let tick = 1.0 / rate;
        // `SCARA_IDEAL_STEPS_PER_TICK`: the ideal arm's world steps per tick (diagnosis).
        let ideal_per_tick = list("SCARA_IDEAL_STEPS_PER_TICK", &[1.0])[0];
        let ideal = run(
            Pins::Ideal,
            0.0,
            rate,
            StepControl::fixed(tick / ideal_per_tick),
        )
        .expect("the ideal arm");
        // The ideal arm's cost per world step: the fastest of five runs (the least disturbed by
        // the other work on the machine), as the sub-cycled arm's is the fastest of its starts.
        let ideal_cost = (0..5)
            .map(|_| {
                let o = run(
                    Pins::Ideal,
                    0.0,
                    rate,
                    StepControl::fixed(tick / ideal_per_tick),
                )
                .expect("the ideal arm");
                per_step(&o)
            })
            .fold(f64::INFINITY, f64::min);
        let ideal_reference = run(
            Pins::Ideal,
            0.0,
            rate,
            StepControl::fixed(tick.min(ref_max_dt)),
        )
        .expect("the ideal arm at the reference's steps");
        let names: Vec<String> = tolerances
            .iter()
            .map(|t| {
                if tolerances.len() > 1 {
                    format!("sub-cycled {t}")
                } else {
                    "sub-cycled".to_string()
                }
            })
            .collect();
        for &mm in &clearances {
            println!("\n### {mm} mm, {rate} Hz\n");
            println!(
                "| clearance x | arm | peak force shoulder, elbow (N) | deepest penetration shoulder, elbow (um) | onsets | hand RMS offset (mm) | five largest impacts shoulder: approach (m/s) / force (N) | elbow |"
            );
            println!("|---|---|---|---|---|---|---|---|");
            // Per arm (the sub-cycled at each tolerance, then the reference): each start's
            // metrics.
            let mut values: Vec<Vec<[f64; METRICS.len()]>> = vec![Vec::new(); tolerances.len() + 1];
            // Per tolerance, over its starts: sub-steps and world steps, the largest sub-steps
            // of a world step, the fastest cost per world step, guard messages, failed runs.
            let mut work =
                vec![(0u64, 0u64, 0usize, f64::INFINITY, 0usize, 0usize); tolerances.len()];
            for &p in perturbations.iter().take(starts) {
                let (c, g) = if on_gain {
                    (mm * 1e-3, 1.0 + p)
                } else {
                    (mm * 1e-3 * (1.0 + p), 1.0)
                };
                GAIN_SCALE.store(g.to_bits(), std::sync::atomic::Ordering::Relaxed);
                // `SCARA_REFERENCE=none`: the sub-cycled arms only (diagnosis, profiles).
                let skip = std::env::var("SCARA_REFERENCE").is_ok_and(|r| r == "none");
                let mut arms = Vec::new();
                for (i, &tolerance) in tolerances.iter().enumerate() {
                    arms.push((
                        i,
                        names[i].as_str(),
                        run(
                            Pins::Compliant(ContactIntegration::SubCycled),
                            c,
                            rate,
                            StepControl {
                                tolerance,
                                ..StepControl::fixed(tick / per_tick)
                            },
                        ),
                        &ideal,
                    ));
                }
                if !skip {
                    arms.push((
                        tolerances.len(),
                        "reference",
                        run(
                            Pins::Compliant(ContactIntegration::Explicit),
                            c,
                            rate,
                            StepControl::adaptive(tick.min(ref_max_dt), ref_tolerance),
                        ),
                        &ideal_reference,
                    ));
                }
                for (k, name, o, ideal) in arms {
                    let o = match o {
                        Ok(o) => o,
                        Err(e) => {
                            println!("| 1{p:+e} | {name} | failed: {e} |||||");
                            if let Some(w) = work.get_mut(k) {
                                w.5 += 1;
                            }
                            continue;
                        }
                    };
                    for g in &o.guards {
                        eprintln!("  {mm} mm x 1{p:+e}, {rate} Hz, {name}: {g}");
                    }
                    if let Some(w) = work.get_mut(k) {
                        w.0 += o.substeps;
                        w.1 += o.steps;
                        w.2 = w.2.max(o.max_substeps);
                        w.3 = w.3.min(per_step(&o));
                        w.4 += o.guards.len();
                    }
                    let off = rms_offset(&o, ideal);
                    let impacts = |pin: usize| {
                        o.top[pin]
                            .iter()
                            .map(|i| format!("{:.4}/{:.0}", i.approach_speed_m_s, i.peak_force_n))
                            .collect::<Vec<_>>()
                            .join(", ")
                    };
                    println!(
                        "| 1{p:+e} | {name} | {:.1}, {:.1} | {:.3}, {:.3} | {}, {} | {:.4} | {} | {} |",
                        o.peak[0],
                        o.peak[1],
                        o.depth[0],
                        o.depth[1],
                        o.onsets[0],
                        o.onsets[1],
                        off,
                        impacts(0),
                        impacts(1)
                    );
                    values[k].push(METRICS.map(|(_, f)| f(&o, off)));
                }
            }
            GAIN_SCALE.store(1f64.to_bits(), std::sync::atomic::Ordering::Relaxed);
            let stats = |v: &[[f64; METRICS.len()]], m: usize| {
                let x: Vec<f64> = v.iter().map(|r| r[m]).collect();
                let mean = x.iter().sum::<f64>() / x.len().max(1) as f64;
                let min = x.iter().copied().fold(f64::INFINITY, f64::min);
                let max = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                (mean, min, max)
            };
            // Outside: the sub-cycled mean more than 5 % beyond the references' range.
            let verdict = |s: (f64, f64, f64), r: (f64, f64, f64)| {
                if s.0 < r.1 * 0.95 {
                    Some(format!("**below** ({})", pct(s.0, r.1)))
                } else if s.0 > r.2 * 1.05 {
                    Some(format!("**above** ({})", pct(s.0, r.2)))
                } else {
                    None
                }
            };
            let reference = &values[tolerances.len()];
            for (t, name) in names.iter().enumerate() {
                println!(
                    "\n| {mm} mm, {rate} Hz | {name} mean [min, max] | reference mean [min, max] | sub-cycled mean vs reference range |"
                );
                println!("|---|---|---|---|");
                for (m, (metric, _)) in METRICS.iter().enumerate() {
                    let (s, r) = (stats(&values[t], m), stats(reference, m));
                    println!(
                        "| {metric} | {:.4} [{:.4}, {:.4}] | {:.4} [{:.4}, {:.4}] | {} |",
                        s.0,
                        s.1,
                        s.2,
                        r.0,
                        r.1,
                        r.2,
                        verdict(s, r).unwrap_or_else(|| "inside".into())
                    );
                }
            }
            // The work-precision table: per tolerance, the work and the bounded metrics' means
            // against the references' mean, flagged where more than 5 % outside their range.
            println!(
                "\n| {mm} mm, {rate} Hz, {} starts: tolerance | sub-steps per world step (both pins) | largest per world step | cost per world step / ideal arm's | peak force shoulder, elbow vs reference | deepest penetration shoulder, elbow vs reference | hand RMS offset vs reference | guard messages, failed runs |",
                starts.min(perturbations.len())
            );
            println!("|---|---|---|---|---|---|---|---|");
            for (t, &tolerance) in tolerances.iter().enumerate() {
                let cell = |metrics: &[usize]| {
                    metrics
                        .iter()
                        .map(|&m| {
                            let (s, r) = (stats(&values[t], m), stats(reference, m));
                            let flag = verdict(s, r).map_or(String::new(), |v| format!(" {v}"));
                            format!("{:.4} ({}){flag}", s.0, pct(s.0, r.0))
                        })
                        .collect::<Vec<_>>()
                        .join(", ")
                };
                let w = work[t];
                println!(
                    "| {tolerance} | {:.1} | {} | {:.1} | {} | {} | {} | {}, {} |",
                    w.0 as f64 / w.1.max(1) as f64,
                    w.2,
                    w.3 / ideal_cost,
                    cell(&[0, 1]),
                    cell(&[2, 3]),
                    cell(&[6]),
                    w.4,
                    w.5
                );
            }
        }
    }
}
