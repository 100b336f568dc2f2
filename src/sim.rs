//! The runner: builds a scene twice in one Rapier world, an ideal twin (every hinge a Rapier
//! revolute joint) and a clearance twin (hinges with clearance become [`ClearanceJoint`]s), steps
//! both together, and records both.

use crate::angle::{HingeAngle, UnwrappedAngle, twist_angle};
use crate::drive::{DriveSet, TorsionSpring};
use crate::error::{Error, Result};
use crate::joint::{ClearanceJointBuilder, ClearanceJointHandle, ClearanceJointSet};
use crate::output::Table;
use crate::scene::{Scene, StepMode};
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Instant;

/// Which hinges a twin models with clearance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TwinKind {
    /// Every hinge is Rapier's ideal revolute joint.
    Ideal,
    /// Hinges with a clearance spec are clearance joints.
    Clearance,
}

impl TwinKind {
    /// `"ideal"` or `"clearance"`.
    pub fn name(self) -> &'static str {
        match self {
            TwinKind::Ideal => "ideal",
            TwinKind::Clearance => "clearance",
        }
    }
}

/// Which twins to build.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Twins {
    /// Both, side by side in one world (the default).
    #[default]
    Both,
    /// Only the ideal twin (for cost measurements).
    IdealOnly,
    /// Only the clearance twin (for cost measurements).
    ClearanceOnly,
}

/// Run options beyond the scene.
#[derive(Clone, Copy, Debug, Default)]
pub struct RunOptions {
    /// Which twins to build.
    pub twins: Twins,
    /// Keep output rows (off for benchmarks: metrics are still computed every step).
    pub skip_rows: bool,
}

#[derive(Clone, Debug)]
struct BodyTrack {
    name: String,
    handle: RigidBodyHandle,
    mass: f64,
    fixed: bool,
    angle: UnwrappedAngle,
    linvel_before: Vector,
}

#[derive(Clone, Copy, Debug)]
enum HingeJoint {
    Ideal,
    Clearance(ClearanceJointHandle),
}

#[derive(Clone, Debug)]
struct HingeTrack {
    name: String,
    joint: HingeJoint,
    bearing: usize,
    journal: usize,
    local_axis1: Vector,
    local_u1: Vector,
    local_v1: Vector,
    angle: HingeAngle,
    /// Force magnitude acting over the current step, N.
    force: f64,
    metrics: HingeMetrics,
}

/// Per-hinge metrics over every internal step.
#[derive(Clone, Debug, Default, Serialize)]
pub struct HingeMetrics {
    /// Largest joint force, N.
    pub peak_force_n: f64,
    /// Number of contact onsets (issue 2's definition of impacts), chatter of a journal
    /// following the wall included.
    pub impacts: u64,
    /// Contact onsets after a free flight that opened at least the joint's `min_separation`
    /// (0.1 um by default; the first contact always counts): impacts without the chatter.
    pub separated_impacts: u64,
    /// Time of the first contact onset, s.
    pub first_impact_t_s: Option<f64>,
    /// Largest force during the first contact, N.
    pub first_impact_peak_n: Option<f64>,
    /// Largest penetration, um.
    pub max_penetration_um: f64,
    /// Steps spent in contact.
    pub contact_steps: u64,
    /// Fraction of simulated time in contact.
    pub contact_fraction: f64,
    /// Root-mean-square joint force over the run (time-weighted), N.
    pub rms_force_n: f64,
    #[serde(skip)]
    force_sq_time: f64,
    #[serde(skip)]
    contact_time: f64,
    /// Final relative angle, deg.
    pub final_angle_deg: f64,
    #[serde(skip)]
    in_first_contact: bool,
}

/// One twin: its bodies, joints, drives and records.
#[derive(Debug)]
pub struct Twin {
    /// Ideal or clearance.
    pub kind: TwinKind,
    bodies: Vec<BodyTrack>,
    hinges: Vec<HingeTrack>,
    /// The clearance joints of this twin.
    pub clearance: ClearanceJointSet,
    /// The drives of this twin.
    pub drives: DriveSet,
    reaction_order: Vec<(usize, usize, f64)>,
    /// Per body, the momentum change not explained by known forces since the window began, N s.
    window_impulse: Vec<Vector>,
    /// Length of the current reaction window, s.
    window_time: f64,
    reference_axis: Vector,
    /// Output rows.
    pub table: Table,
    /// Invariants and energy over every step.
    pub invariants: Invariants,
}

/// Conservation checks over every step (free-floating scenes).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Invariants {
    /// Largest `|P(t) - P(0)|` over the largest single-body linear momentum seen.
    pub linear_momentum_drift: f64,
    /// Largest `|L(t) - L(0)|` (about the origin) over the largest single-body angular momentum seen.
    pub angular_momentum_drift: f64,
    /// Largest growth of total energy (kinetic + spring + contact elastic) above its initial
    /// value, over the peak kinetic energy (with gravity, its potential is included).
    pub energy_growth: f64,
    /// Largest `|E(t) - E(0)|` over the peak kinetic energy.
    pub energy_error: f64,
    /// Peak kinetic energy, J.
    pub peak_kinetic_energy_j: f64,
    #[serde(skip)]
    p0: Option<(Vector, Vector, f64)>,
    #[serde(skip)]
    max_p: f64,
    #[serde(skip)]
    max_l: f64,
    #[serde(skip)]
    max_dp: f64,
    #[serde(skip)]
    max_dl: f64,
    #[serde(skip)]
    max_de: f64,
    #[serde(skip)]
    max_abs_de: f64,
}

/// A scene built in a Rapier world, ready to step.
pub struct Simulation {
    /// The Rapier world holding both twins.
    pub world: PhysicsWorld,
    /// The twins, ideal first.
    pub twins: Vec<Twin>,
    scene: Scene,
    steps_done: u64,
    /// Simulated time: `steps_done * dt` with fixed steps, the sum of the steps otherwise.
    t: f64,
    /// The step before the current one (0 before the first).
    last_dt: f64,
    /// Fixed steps: the number of steps to `end_s`.
    n_steps: u64,
    /// Fixed steps: steps between rows.
    stride: u64,
    /// Index of the next output row.
    next_row: u64,
    skip_rows: bool,
    comparison: ComparisonSums,
}

/// With adaptive steps, the ideal reactions are momentum balances over this many largest steps
/// (2 ms at the defaults): a step-size change leaves a net impulse in one step (Rapier's joint
/// solver restores the position/velocity staggering of the integrator), which a window spreads;
/// measured on the paper's scene, the ideal peak is 0.3497 N with a window of 10 steps, 0.3662 N
/// with 5, against 0.3275 N with fixed steps.
const ADAPTIVE_REACTION_WINDOW: f64 = 20.0;

/// Smallest adaptive step: below it a contact cannot be resolved in f64 time arithmetic.
const MIN_ADAPTIVE_DT: f64 = 1e-10;

/// `Some(speed)` when `rb` has left the physical range: disabled by Rapier's quarantine,
/// non-finite, or faster than half Rapier's speed clamp (Rapier clamps a blown-up body instead of
/// producing NaN, so a clamped speed is the sign of a silent blow-up).
pub(crate) fn left_physical_range(rb: &RigidBody, params: &IntegrationParameters) -> Option<f64> {
    let (v, w) = (rb.linvel(), rb.angvel());
    let bad = !rb.is_enabled() || !rb.translation().is_finite() || !v.is_finite() || !w.is_finite();
    (bad || v.length() > 0.5 * params.max_linear_velocity()).then(|| v.length())
}

/// The clearance twin against the ideal twin, from every internal step (both twins built).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Comparison {
    /// Per body: deviation of its angular rate (about the reference axis) from the ideal twin's.
    pub bodies: BTreeMap<String, RateDeviation>,
    /// Per hinge: settling of the joint force.
    pub hinges: BTreeMap<String, Settling>,
}

/// Rate deviation of one body, clearance twin minus ideal twin.
#[derive(Clone, Debug, Default, Serialize)]
pub struct RateDeviation {
    /// Root-mean-square over the run (time-weighted), deg/s.
    pub rms_deg_s: f64,
    /// Largest absolute deviation, deg/s.
    pub max_deg_s: f64,
}

/// When the joint force of a hinge settles.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Settling {
    /// The last time at which the clearance joint force exceeded the ideal joint force by more
    /// than `band_n`: after it the force stays within one ideal peak of the rigid hinge's load.
    /// 0 when it never did.
    pub settling_time_s: f64,
    /// The band: the ideal twin's peak joint force on this hinge, N.
    pub band_n: f64,
}

/// Running sums behind [`Comparison`].
#[derive(Clone, Debug, Default)]
struct ComparisonSums {
    rate_sq_time: Vec<f64>,
    rate_max: Vec<f64>,
    /// Per hinge, a stack of `(t, excess)` with decreasing excess and increasing time: for any band
    /// `b`, the last time the excess exceeded `b` is the latest entry above `b`.
    excess: Vec<Vec<(f64, f64)>>,
}

impl ComparisonSums {
    fn record(&mut self, ideal: &Twin, clear: &Twin, bodies: &RigidBodySet, t: f64, dt: f64) {
        let n = ideal.bodies.len();
        self.rate_sq_time.resize(n, 0.0);
        self.rate_max.resize(n, 0.0);
        self.excess.resize(ideal.hinges.len(), Vec::new());
        let axis = ideal.reference_axis;
        for (i, (bi, bc)) in ideal.bodies.iter().zip(&clear.bodies).enumerate() {
            let d = (bodies[bc.handle].angvel() - bodies[bi.handle].angvel())
                .dot(axis)
                .to_degrees();
            self.rate_sq_time[i] += d * d * dt;
            self.rate_max[i] = self.rate_max[i].max(d.abs());
        }
        for (k, (hi, hc)) in ideal.hinges.iter().zip(&clear.hinges).enumerate() {
            let excess = hc.force - hi.force;
            let stack = &mut self.excess[k];
            while stack.last().is_some_and(|&(_, e)| e <= excess) {
                stack.pop();
            }
            stack.push((t, excess));
        }
    }

    fn finish(&self, ideal: &Twin, duration: f64) -> Comparison {
        let mut c = Comparison::default();
        for (i, b) in ideal.bodies.iter().enumerate() {
            let rms = if duration > 0.0 {
                (self.rate_sq_time.get(i).copied().unwrap_or(0.0) / duration).sqrt()
            } else {
                0.0
            };
            c.bodies.insert(
                b.name.clone(),
                RateDeviation {
                    rms_deg_s: rms,
                    max_deg_s: self.rate_max.get(i).copied().unwrap_or(0.0),
                },
            );
        }
        for (k, h) in ideal.hinges.iter().enumerate() {
            let band = h.metrics.peak_force_n;
            let last = self
                .excess
                .get(k)
                .and_then(|s| s.iter().rev().find(|&&(_, e)| e > band))
                .map_or(0.0, |&(t, _)| t);
            c.hinges.insert(
                h.name.clone(),
                Settling {
                    settling_time_s: last,
                    band_n: band,
                },
            );
        }
        c
    }
}

/// Where a run is, passed to the callback of [`Simulation::run_with_progress`].
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// Simulated time reached, s.
    pub t: f64,
    /// Simulated time at the end of the run, s.
    pub end: f64,
    /// Internal steps taken so far.
    pub steps: u64,
}

/// The result of a whole run.
#[derive(Debug)]
pub struct RunResult {
    /// The scene that ran (after overrides).
    pub scene: Scene,
    /// Twins with their tables and invariants.
    pub twins: Vec<Twin>,
    /// Internal steps taken.
    pub steps: u64,
    /// Wall time of the whole run (both twins share one world), s.
    pub wall_s: f64,
    /// Clearance twin against ideal twin (when both were built).
    pub comparison: Option<Comparison>,
}

impl Simulation {
    /// Builds the world for `scene`.
    pub fn new(scene: &Scene, options: RunOptions) -> Result<Simulation> {
        scene.validate()?;
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::from(scene.gravity);
        world.integration_parameters.dt = scene.run.dt_s;
        // One substep: the hook's force is constant over the step (RAPIER_NOTES: substeps gain energy).
        world.integration_parameters.num_solver_iterations = 1;
        let kinds: &[TwinKind] = match options.twins {
            Twins::Both => &[TwinKind::Ideal, TwinKind::Clearance],
            Twins::IdealOnly => &[TwinKind::Ideal],
            Twins::ClearanceOnly => &[TwinKind::Clearance],
        };
        let mut twins = Vec::new();
        for &kind in kinds {
            twins.push(Twin::build(scene, kind, &mut world)?);
        }
        let n_steps = (scene.run.end_s / scene.run.dt_s).round().max(1.0) as u64;
        let stride = (scene.run.output_interval_s / scene.run.dt_s)
            .round()
            .max(1.0) as u64;
        Ok(Simulation {
            world,
            twins,
            scene: scene.clone(),
            steps_done: 0,
            t: 0.0,
            last_dt: 0.0,
            n_steps,
            stride,
            next_row: 0,
            skip_rows: options.skip_rows,
            comparison: ComparisonSums::default(),
        })
    }

    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.t
    }

    fn adaptive(&self) -> bool {
        self.scene.run.step == StepMode::Adaptive
    }

    fn done(&self) -> bool {
        if self.adaptive() {
            self.t >= self.scene.run.end_s
        } else {
            self.steps_done >= self.n_steps
        }
    }

    /// Whether the state at the current time is an output row.
    fn row_due(&self) -> bool {
        if self.skip_rows {
            false
        } else if self.adaptive() {
            self.t >= self.next_row as f64 * self.scene.run.output_interval_s
        } else {
            self.steps_done % self.stride == 0
        }
    }

    /// The next step: fixed, or the adaptive choice landing exactly on row times and the end.
    fn choose_dt(&self) -> f64 {
        let run = &self.scene.run;
        if !self.adaptive() {
            return run.dt_s;
        }
        let mut dt = run.dt_s;
        for twin in &self.twins {
            dt = dt.min(twin.clearance.adaptive_step(run.tolerance, self.last_dt));
        }
        dt = dt.max(MIN_ADAPTIVE_DT);
        // The nearest target (next row, end): divide what is left into equal steps no larger than
        // dt, so no sliver step is left before it (Rapier's joints correct their position error
        // fully each step: a 1e-8 s step turns a tiny error into a velocity kick).
        let mut target = run.end_s;
        let row = self.next_row as f64 * run.output_interval_s;
        if !self.skip_rows && row > self.t {
            target = target.min(row);
        }
        let left = target - self.t;
        if left > 0.0 {
            dt = left / (left / dt).ceil();
        }
        dt
    }

    /// Time after a step of `dt`: exact multiples with fixed steps, exact landing on row times and
    /// the end with adaptive ones.
    fn advance_time(&self, dt: f64) -> f64 {
        let run = &self.scene.run;
        if !self.adaptive() {
            return (self.steps_done + 1) as f64 * run.dt_s;
        }
        let row = self.next_row as f64 * run.output_interval_s;
        let t = self.t + dt;
        // Snap to a target reached up to rounding, or the next step would be a sliver of 1e-17 s.
        let reached = |target: f64| t >= target - 1e-9 * dt;
        if !self.skip_rows && row > self.t && reached(row) {
            row
        } else if reached(run.end_s) {
            run.end_s
        } else {
            t
        }
    }

    /// Runs to `run.end_s`.
    pub fn run(self) -> Result<RunResult> {
        self.run_with_progress(|_| {})
    }

    /// Runs to `run.end_s`, calling `progress` after every internal step (e.g. to show simulated
    /// time, steps per second and an ETA on a terminal; the call should be cheap).
    pub fn run_with_progress(mut self, mut progress: impl FnMut(&Progress)) -> Result<RunResult> {
        let start = Instant::now();
        while !self.done() {
            self.step()?;
            progress(&Progress {
                t: self.time(),
                end: self.scene.run.end_s,
                steps: self.steps_done,
            });
        }
        self.finish()?;
        let comparison = match self.twins.as_slice() {
            [ideal, _] => Some(self.comparison.finish(ideal, self.time())),
            _ => None,
        };
        Ok(RunResult {
            comparison,
            scene: self.scene,
            twins: self.twins,
            steps: self.steps_done,
            wall_s: start.elapsed().as_secs_f64(),
        })
    }

    /// Advances one internal step: forces from the hooks, Rapier's step, then records.
    pub fn step(&mut self) -> Result<()> {
        let record = self.row_due();
        let t = self.time();
        self.before_step(record)?;
        let dt = self.choose_dt();
        for twin in &self.twins {
            if let Err(mut e) = twin.clearance.check_step(dt) {
                // Name the scene's field and the time: the set knows neither.
                if let Error::StepTooLarge { field, t: at, .. } = &mut e {
                    *field = "run.dt_s".into();
                    *at = Some(t);
                }
                return Err(e);
            }
        }
        self.world.integration_parameters.dt = dt;
        self.world.step();
        let gravity = self.world.gravity;
        // Ideal reactions: one step with fixed steps; with adaptive ones a window of 20 largest
        // steps, over which the impulses of step-size changes average out (see solve_ideal_reactions).
        let window = if self.adaptive() {
            ADAPTIVE_REACTION_WINDOW * self.scene.run.dt_s
        } else {
            self.scene.run.dt_s
        };
        for twin in &mut self.twins {
            twin.solve_ideal_reactions(&self.world.bodies, dt, gravity, window);
            twin.update_force_metrics(t, dt);
            if record {
                twin.fill_forces_of_last_row();
            }
        }
        if let [ideal, clear] = self.twins.as_slice() {
            self.comparison
                .record(ideal, clear, &self.world.bodies, t, dt);
        }
        self.t = self.advance_time(dt);
        self.steps_done += 1;
        self.last_dt = dt;
        self.check_health()
    }

    /// Evaluates hooks at the current state and records invariants (and a row).
    fn before_step(&mut self, record: bool) -> Result<()> {
        let t = self.time();
        let params = self.world.integration_parameters;
        for twin in &mut self.twins {
            twin.drives.apply(&mut self.world.bodies);
            twin.clearance.apply_forces(&mut self.world.bodies);
            twin.clearance.check_substeps(&params)?;
            for b in &mut twin.bodies {
                b.linvel_before = self.world.bodies[b.handle].linvel();
            }
            twin.update_invariants(&self.world.bodies, self.world.gravity);
            if record {
                twin.push_row(t, &self.world.bodies);
            }
        }
        if record {
            self.next_row += 1;
        }
        Ok(())
    }

    /// Records the final state (a last row at `end_s`) and final angles.
    fn finish(&mut self) -> Result<()> {
        let record = !self.skip_rows;
        self.before_step(record)?;
        let duration = self.time();
        for twin in &mut self.twins {
            if record {
                twin.fill_forces_of_last_row();
            }
            for h in &mut twin.hinges {
                let m = &mut h.metrics;
                m.final_angle_deg = h.angle.value().to_degrees();
                if duration > 0.0 {
                    m.rms_force_n = (m.force_sq_time / duration).sqrt();
                    m.contact_fraction = m.contact_time / duration;
                }
            }
        }
        Ok(())
    }

    fn check_health(&self) -> Result<()> {
        for twin in &self.twins {
            for b in &twin.bodies {
                let rb = &self.world.bodies[b.handle];
                if let Some(speed) = left_physical_range(rb, &self.world.integration_parameters) {
                    return Err(Error::Diverged {
                        t: self.time(),
                        reason: format!(
                            "body `{}` of the {} twin left the physical range (speed {speed:.3e} m/s)",
                            b.name,
                            twin.kind.name(),
                        ),
                    });
                }
            }
        }
        Ok(())
    }
}

impl Twin {
    fn build(scene: &Scene, kind: TwinKind, world: &mut PhysicsWorld) -> Result<Twin> {
        let mut bodies = Vec::new();
        for b in &scene.bodies {
            let com = Vector::from(b.center_of_mass_m);
            let builder = if b.fixed {
                RigidBodyBuilder::fixed()
            } else {
                RigidBodyBuilder::dynamic()
            };
            let rb = builder
                .translation(com)
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    b.mass_kg,
                    Vector::from(b.inertia_kg_m2),
                ))
                .can_sleep(false)
                .build();
            let handle = world.bodies.insert(rb);
            bodies.push(BodyTrack {
                name: b.name.clone(),
                handle,
                mass: b.mass_kg,
                fixed: b.fixed,
                angle: UnwrappedAngle::default(),
                linvel_before: Vector::ZERO,
            });
        }
        let mut clearance = ClearanceJointSet::new();
        let mut hinges = Vec::new();
        for h in &scene.hinges {
            let (ib, ij) = (
                scene.body_index(&h.bearing).unwrap(),
                scene.body_index(&h.journal).unwrap(),
            );
            let point = Vector::from(h.point_m);
            let axis = Vector::from(h.axis).normalize();
            // Bodies start unrotated with their frame at the centre of mass.
            let a1 = point - Vector::from(scene.bodies[ib].center_of_mass_m);
            let a2 = point - Vector::from(scene.bodies[ij].center_of_mass_m);
            let (b1, b2) = (bodies[ib].handle, bodies[ij].handle);
            let joint = match (&h.clearance, kind) {
                (Some(spec), TwinKind::Clearance) => {
                    let p = spec
                        .build()
                        .map_err(|e| e.within(&format!("hinges[{}].clearance", h.name)))?;
                    let j = ClearanceJointBuilder::new(axis, p.geometry, p.normal)
                        .local_anchor1(a1)
                        .local_anchor2(a2)
                        .friction(p.friction)
                        .min_impact_speed(p.min_impact_speed)
                        .min_separation(p.min_separation)
                        .lock(spec.lock)
                        .name(h.name.clone())
                        .build()?;
                    HingeJoint::Clearance(clearance.insert(b1, b2, j, &mut world.impulse_joints))
                }
                _ => {
                    let j = RevoluteJointBuilder::new(axis)
                        .local_anchor1(a1)
                        .local_anchor2(a2)
                        .contacts_enabled(false);
                    {
                        world.impulse_joints.insert(b1, b2, j, true);
                        HingeJoint::Ideal
                    }
                }
            };
            let u = in_plane_u(axis);
            hinges.push(HingeTrack {
                name: h.name.clone(),
                joint,
                bearing: ib,
                journal: ij,
                local_axis1: axis,
                local_u1: u,
                local_v1: axis.cross(u),
                angle: HingeAngle::default(),
                force: 0.0,
                metrics: HingeMetrics::default(),
            });
        }
        let mut drives = DriveSet::new();
        for d in &scene.drives {
            let hi = scene.hinge_index(&d.hinge).unwrap();
            let h = &hinges[hi];
            let per_rad = d.stiffness_nm_per_deg.to_degrees();
            let spring = TorsionSpring::new(
                bodies[h.bearing].handle,
                bodies[h.journal].handle,
                h.local_axis1,
                d.torque_scale * d.torque0_nm,
                d.torque_scale * per_rad,
            )
            .map_err(|e| e.within(&format!("drives[{}]", d.name)))?;
            drives.insert(spring);
        }
        let fixed: Vec<bool> = bodies.iter().map(|b| b.fixed).collect();
        let reaction_order = reaction_order(&hinges, &fixed);
        let mut columns = vec!["t_s".to_string()];
        for b in &bodies {
            columns.push(format!("{}_angle_deg", b.name));
            columns.push(format!("{}_rate_deg_s", b.name));
        }
        for h in &hinges {
            for c in [
                "angle_deg",
                "rate_deg_s",
                "force_n",
                "ecc_u_mm",
                "ecc_v_mm",
                "penetration_um",
                "contact",
            ] {
                columns.push(format!("{}_{c}", h.name));
            }
        }
        Ok(Twin {
            kind,
            bodies,
            hinges,
            clearance,
            drives,
            reaction_order,
            window_impulse: vec![Vector::ZERO; scene.bodies.len()],
            window_time: 0.0,
            reference_axis: Vector::from(scene.reference_axis).normalize(),
            table: Table::new(columns),
            invariants: Invariants::default(),
        })
    }

    /// Ideal-joint reactions from the momentum balance of the bodies,
    /// `F_joint = (m dv - (F_user + m g) dt) / T`, eliminated from the leaves of the joint tree,
    /// over windows of at least `window` seconds (one step with fixed steps, where it is exact per
    /// step). With steps of varying size a single step is not enough: Rapier's joint
    /// stabilisation removes the position error of one step within the next, so impulse moves
    /// between steps of different length; the smooth ideal reaction is exact over the window.
    fn solve_ideal_reactions(
        &mut self,
        bodies: &RigidBodySet,
        dt: f64,
        gravity: Vector,
        window: f64,
    ) {
        for h in &mut self.hinges {
            if let HingeJoint::Clearance(c) = h.joint {
                h.force = self
                    .clearance
                    .get(c)
                    .map_or(0.0, |j| j.report().force.on_journal.length());
            }
        }
        if self.reaction_order.is_empty() {
            return;
        }
        for (b, impulse) in self.bodies.iter().zip(&mut self.window_impulse) {
            let rb = &bodies[b.handle];
            *impulse += b.mass * (rb.linvel() - b.linvel_before)
                - (rb.user_force() + b.mass * gravity) * dt;
        }
        self.window_time += dt;
        if self.window_time < window * (1.0 - 1e-9) {
            return; // the hinges keep the last window's reaction
        }
        // Eliminate in place on the window's impulses (no allocation per step).
        let window_time = self.window_time;
        let residual = &mut self.window_impulse;
        for r in residual.iter_mut() {
            *r /= window_time;
        }
        for &(hi, body, sign) in &self.reaction_order {
            let h = &mut self.hinges[hi];
            // Force on the journal body.
            let f = sign * residual[body];
            residual[h.journal] -= f;
            residual[h.bearing] += f;
            h.force = f.length();
        }
        self.window_impulse.fill(Vector::ZERO);
        self.window_time = 0.0;
    }

    fn update_force_metrics(&mut self, t: f64, dt: f64) {
        for h in &mut self.hinges {
            let m = &mut h.metrics;
            m.peak_force_n = m.peak_force_n.max(h.force);
            m.force_sq_time += h.force * h.force * dt;
            if let HingeJoint::Clearance(c) = h.joint {
                let r = self.clearance.get(c).expect("handle of this twin").report();
                let in_contact = r.state.penetration > 0.0;
                if r.impact {
                    m.separated_impacts += 1;
                }
                if r.onset {
                    m.impacts += 1;
                    if m.first_impact_t_s.is_none() {
                        m.first_impact_t_s = Some(t);
                        m.first_impact_peak_n = Some(0.0);
                        m.in_first_contact = true;
                    }
                }
                if m.in_first_contact {
                    if in_contact {
                        m.first_impact_peak_n =
                            Some(m.first_impact_peak_n.unwrap_or(0.0).max(h.force));
                    } else {
                        m.in_first_contact = false;
                    }
                }
                if in_contact {
                    m.contact_steps += 1;
                    m.contact_time += dt;
                    m.max_penetration_um = m.max_penetration_um.max(r.state.penetration * 1e6);
                }
            }
        }
    }

    fn update_invariants(&mut self, bodies: &RigidBodySet, gravity: Vector) {
        let (mut p, mut l, mut ke, mut pe) = (Vector::ZERO, Vector::ZERO, 0.0, 0.0);
        let inv = &mut self.invariants;
        for b in &self.bodies {
            let rb = &bodies[b.handle];
            let com = crate::ledger::world_center_of_mass(rb);
            let (v, w) = (rb.linvel(), rb.angvel());
            let mp = &rb.mass_properties().local_mprops;
            // I w in world: R I_principal R^T w (principal frame = body frame here).
            let rot = *rb.rotation() * mp.principal_inertia_local_frame;
            let iw = rot * (mp.principal_inertia() * (rot.inverse() * w));
            let pb = b.mass * v;
            let lb = com.cross(pb) + iw;
            p += pb;
            l += lb;
            ke += 0.5 * b.mass * v.length_squared() + 0.5 * w.dot(iw);
            pe -= b.mass * gravity.dot(com);
            inv.max_p = inv.max_p.max(pb.length());
            inv.max_l = inv.max_l.max(lb.length());
        }
        pe += self.drives.potential_energy();
        pe += self
            .clearance
            .iter()
            .map(|(_, j)| j.elastic_energy())
            .sum::<f64>();
        let e = ke + pe;
        let (p0, l0, e0) = *inv.p0.get_or_insert((p, l, e));
        inv.max_dp = inv.max_dp.max((p - p0).length());
        inv.max_dl = inv.max_dl.max((l - l0).length());
        inv.max_de = inv.max_de.max(e - e0);
        inv.max_abs_de = inv.max_abs_de.max((e - e0).abs());
        inv.peak_kinetic_energy_j = inv.peak_kinetic_energy_j.max(ke);
        let rel = |d: f64, scale: f64| if scale > 0.0 { d / scale } else { 0.0 };
        inv.linear_momentum_drift = rel(inv.max_dp, inv.max_p);
        inv.angular_momentum_drift = rel(inv.max_dl, inv.max_l);
        inv.energy_growth = rel(inv.max_de, inv.peak_kinetic_energy_j);
        inv.energy_error = rel(inv.max_abs_de, inv.peak_kinetic_energy_j);
    }

    fn push_row(&mut self, t: f64, bodies: &RigidBodySet) {
        let axis_ref = self.reference_axis;
        let v = &mut self.table.values;
        v.push(t);
        for b in &mut self.bodies {
            let rb = &bodies[b.handle];
            // Bodies start unrotated: the body's rotation is its rotation since t = 0.
            let q = *rb.rotation();
            v.push(b.angle.update(twist_angle(&q, axis_ref)).to_degrees());
            v.push(rb.angvel().dot(axis_ref).to_degrees());
        }
        for h in &mut self.hinges {
            let (r1, r2) = (
                &bodies[self.bodies[h.bearing].handle],
                &bodies[self.bodies[h.journal].handle],
            );
            let angle = h.angle.update(r1.rotation(), r2.rotation(), h.local_axis1);
            let axis = *r1.rotation() * h.local_axis1;
            v.push(angle.to_degrees());
            v.push((r2.angvel() - r1.angvel()).dot(axis).to_degrees());
            v.push(f64::NAN); // force over the step, filled after it
            match h.joint {
                HingeJoint::Clearance(c) => {
                    let r = self.clearance.get(c).expect("handle of this twin").report();
                    let e = r.state.eccentricity;
                    v.push(e.dot(*r1.rotation() * h.local_u1) * 1e3);
                    v.push(e.dot(*r1.rotation() * h.local_v1) * 1e3);
                    v.push(r.state.penetration.max(0.0) * 1e6);
                    v.push(if r.state.penetration > 0.0 { 1.0 } else { 0.0 });
                }
                HingeJoint::Ideal => v.extend_from_slice(&[0.0, 0.0, 0.0, 0.0]),
            }
        }
    }

    fn fill_forces_of_last_row(&mut self) {
        let n = self.table.columns.len();
        let start = self.table.values.len() - n;
        let first_hinge_col = 1 + 2 * self.bodies.len();
        for (k, h) in self.hinges.iter().enumerate() {
            self.table.values[start + first_hinge_col + 7 * k + 2] = h.force;
        }
    }

    /// Per-hinge metrics by hinge name.
    pub fn hinge_metrics(&self) -> BTreeMap<String, HingeMetrics> {
        self.hinges
            .iter()
            .map(|h| (h.name.clone(), h.metrics.clone()))
            .collect()
    }

    /// Final angles (deg) of every body and hinge, by name.
    pub fn final_angles_deg(&self) -> BTreeMap<String, f64> {
        let mut m = BTreeMap::new();
        for b in &self.bodies {
            m.insert(b.name.clone(), b.angle.value().to_degrees());
        }
        for h in &self.hinges {
            m.insert(h.name.clone(), h.angle.value().to_degrees());
        }
        m
    }
}

/// The in-plane `u` direction of a hinge: the world axis least aligned with `axis`, made
/// orthogonal to it (world x for the paper's hinge; then `v = axis x u` is world z).
fn in_plane_u(axis: Vector) -> Vector {
    let candidates = [Vector::X, Vector::Y, Vector::Z];
    let mut best = candidates[0];
    for c in candidates {
        if c.dot(axis).abs() < best.dot(axis).abs() - 1e-12 {
            best = c;
        }
    }
    (best - best.dot(axis) * axis).normalize()
}

/// Elimination order for the ideal-joint reactions: repeatedly take a body with exactly one
/// unsolved ideal joint; its residual momentum change is that joint's force. Returns
/// `(hinge, body, sign)` with force on the journal `= sign * residual[body]`. A fixed body's
/// balance is unknown (the ground supplies any force), so it is never used.
fn reaction_order(hinges: &[HingeTrack], fixed: &[bool]) -> Vec<(usize, usize, f64)> {
    let mut unsolved: Vec<usize> = hinges
        .iter()
        .enumerate()
        .filter(|(_, h)| matches!(h.joint, HingeJoint::Ideal))
        .map(|(i, _)| i)
        .collect();
    let mut order = Vec::new();
    while !unsolved.is_empty() {
        let count = |b: usize, u: &[usize]| {
            u.iter()
                .filter(|&&i| hinges[i].bearing == b || hinges[i].journal == b)
                .count()
        };
        let pick = unsolved.iter().enumerate().find_map(|(k, &i)| {
            let h = &hinges[i];
            if !fixed[h.journal] && count(h.journal, &unsolved) == 1 {
                Some((k, i, h.journal, 1.0))
            } else if !fixed[h.bearing] && count(h.bearing, &unsolved) == 1 {
                Some((k, i, h.bearing, -1.0))
            } else {
                None
            }
        });
        match pick {
            Some((k, i, b, s)) => {
                order.push((i, b, s));
                unsolved.remove(k);
            }
            None => break, // a closed loop: its reactions are not determined by momentum alone
        }
    }
    order
}
