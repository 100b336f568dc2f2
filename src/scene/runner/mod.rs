//! The runner: builds a scene twice in one Rapier world, an ideal twin (every hinge a Rapier
//! revolute joint) and a clearance twin (hinges with clearance become [`ClearanceJoint`](crate::rapier::joint::ClearanceJoint)s), steps
//! both together, and records both.

mod comparison;
pub mod convergence;
mod invariants;
mod twin;

pub use comparison::{Comparison, RateDeviation, Settling};
pub use invariants::{ENERGY_GROWTH_LIMIT, Invariants, MOTOR_SPEED_ERROR_LIMIT};
pub use twin::{HingeJoint, Twin, TwinHinge, TwinKind};

use crate::error::Result;
use crate::rapier::pipeline::stepper::{GuardKind, GuardReport, Violation};
use crate::rapier::pipeline::world::ClearanceWorld;
use crate::scene::{Scene, ValidatedScene};
use comparison::ComparisonSums;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::*;
use std::time::Instant;

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

pub use crate::rapier::observers::metrics::HingeMetrics;

/// A scene built in a Rapier world, ready to step.
pub struct Simulation {
    /// The world holding both twins, with its step control (the same public piece a
    /// plain-Rapier loop uses).
    pub world: ClearanceWorld,
    /// The twins, ideal first.
    pub twins: Vec<Twin>,
    scene: Scene,
    /// Index of the next output row (row `k` is at `k * output_interval_s`, the last at `end_s`).
    next_row: u64,
    /// Time of the previous state (rows between it and the current one are interpolated).
    t_prev: f64,
    /// The row at `end_s` is written.
    rows_done: bool,
    skip_rows: bool,
    comparison: ComparisonSums,
    /// Time of the last state the twins read (the start of the step under way), s.
    last_read: f64,
}

use crate::rapier::pipeline::stepper::left_physical_range;

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
    /// What the run-time guards saw (the stepper's, plus energy growth).
    pub guards: GuardReport,
    /// `None` for a run that reached its end; for one the step control stopped
    /// ([`Simulation::run_keeping_partial`]), the error that stopped it: everything above then
    /// holds what was computed up to [`reached_s`](Self::reached_s).
    pub stopped: Option<crate::Error>,
    /// Simulated time of the last state recorded, s: `run.end_s` for a complete run.
    pub reached_s: f64,
}

impl RunResult {
    /// Whether the run reached its end (no [`stopped`](Self::stopped) error).
    pub fn is_complete(&self) -> bool {
        self.stopped.is_none()
    }
}

impl Simulation {
    /// Builds the world for `scene`, checking it ([`from_validated`](Self::from_validated)
    /// takes a scene checked already).
    pub fn new(scene: &Scene, options: RunOptions) -> Result<Simulation> {
        Self::from_validated(&scene.validated()?, options)
    }

    /// Builds the world for a checked scene: its hinges' joints from the
    /// [`HingeDesign`](crate::rapier::hinge::design::HingeDesign)s its check built.
    pub fn from_validated(scene: &ValidatedScene, options: RunOptions) -> Result<Simulation> {
        let control = scene.run.step_control();
        control.validate().map_err(|e| e.within("run"))?;
        let mut physics = PhysicsWorld::new();
        physics.gravity = Vector::from(scene.gravity);
        physics.integration_parameters.dt = scene.run.dt_s;
        // One substep: an explicit hinge's force is constant over the step (substeps would gain
        // energy); a sub-cycled one takes any number, and its scene figures are measured at one.
        physics.integration_parameters.num_solver_iterations = 1;
        physics.integration_parameters.num_internal_pgs_iterations = scene.run.solver_sweeps;
        let mut world = ClearanceWorld::new(physics, control);
        let kinds: &[TwinKind] = match options.twins {
            Twins::Both => &[TwinKind::Ideal, TwinKind::Clearance],
            Twins::IdealOnly => &[TwinKind::Ideal],
            Twins::ClearanceOnly => &[TwinKind::Clearance],
        };
        let mut twins = Vec::new();
        for &kind in kinds {
            twins.push(Twin::build(scene, kind, &mut world)?);
        }
        if !options.skip_rows {
            // The rows' values in one allocation of their final size (the rows are known from
            // the start): grown by doubling, a table is copied as it grows and may hold up to
            // twice its values. A row at each multiple of the interval below the end, and one
            // at the end (the scene's check bounds their number).
            let rows = (scene.run.end_s / scene.run.output_interval_s).ceil() as usize + 1;
            for twin in &mut twins {
                let n = twin.table.columns.len();
                twin.table.values.reserve_exact(rows.saturating_mul(n));
            }
        }
        // Mass properties before the first step (Rapier computes them in it; the reactions and
        // the hooks need them at the initial state).
        crate::rapier::observers::reaction::prepare_mass_properties(&mut world.rapier.bodies);
        Ok(Simulation {
            world,
            twins,
            scene: scene.scene().clone(),
            next_row: 0,
            t_prev: 0.0,
            rows_done: false,
            skip_rows: options.skip_rows,
            comparison: ComparisonSums::default(),
            last_read: 0.0,
        })
    }

    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.world.time()
    }

    fn done(&self) -> bool {
        self.time() >= self.scene.run.end_s
    }

    /// Writes the rows whose times lie in `(t_prev, t]` (and the row at 0 at the first state),
    /// interpolated between the previous state and the current one: rows sit exactly at
    /// multiples of `output_interval_s` (and at `end_s`) whatever the steps, and never change them.
    fn write_rows(&mut self, t: f64) {
        if self.skip_rows {
            return;
        }
        let run = &self.scene.run;
        let (oi, end) = (run.output_interval_s, run.end_s);
        // Rounding of summed steps: a row within a billionth of a step counts as reached.
        let slack = 1e-9 * run.max_dt_s.max(run.dt_s);
        while !self.rows_done {
            let grid = self.next_row as f64 * oi;
            let last = grid >= end - slack;
            let r = if last { end } else { grid };
            if r > t + slack {
                return;
            }
            let w = if t > self.t_prev {
                ((r - self.t_prev) / (t - self.t_prev)).clamp(0.0, 1.0)
            } else {
                1.0
            };
            for twin in &mut self.twins {
                twin.write_row(r, w);
            }
            self.next_row += 1;
            self.rows_done = last;
        }
    }

    /// Where the next step may go at most: the end. Rows never shorten a step (a row is the
    /// first state at or after its time), so the physics is the same for any output interval.
    fn target(&self) -> f64 {
        self.scene.run.end_s
    }

    /// Runs to `run.end_s`.
    pub fn run(self) -> Result<RunResult> {
        self.run_with_progress(|_| {})
    }

    /// Runs to `run.end_s`, calling `progress` after every internal step (e.g. to show simulated
    /// time, steps per second and an ETA on a terminal; the call should be cheap). Any error
    /// stops it and is returned; [`run_keeping_partial`](Self::run_keeping_partial) keeps what a
    /// stalled run computed.
    pub fn run_with_progress(self, progress: impl FnMut(&Progress)) -> Result<RunResult> {
        let mut result = self.run_keeping_partial(progress)?;
        match result.stopped.take() {
            Some(e) => Err(e),
            None => Ok(result),
        }
    }

    /// Like [`run_with_progress`](Self::run_with_progress), but a run the step control stops
    /// ([`Error::Stalled`](crate::Error::Stalled)) returns what was computed up to the last
    /// state it recorded: its rows, impacts, metrics and guards, with the error in
    /// [`RunResult::stopped`] and the time reached in [`RunResult::reached_s`]. Other errors
    /// (bad input, a diverged body, a strict guard, a fixed step too long) are returned as
    /// errors.
    pub fn run_keeping_partial(self, progress: impl FnMut(&Progress)) -> Result<RunResult> {
        self.run_observed(progress, |_| {})
    }

    /// As [`run_keeping_partial`](Self::run_keeping_partial) (a stalled run returns what it
    /// computed, with the error in [`RunResult::stopped`]), also calling `observe` with the
    /// simulation at the initial state and after every internal step (the force sources
    /// evaluated at each of those states), e.g. to record a replay: [`Simulation::world`] holds
    /// the bodies and joints, each twin's [`bodies`](Twin::bodies) and
    /// [`hinges`](Twin::hinges) name them.
    pub fn run_observed(
        mut self,
        mut progress: impl FnMut(&Progress),
        mut observe: impl FnMut(&Simulation),
    ) -> Result<RunResult> {
        let start = Instant::now();
        let mut stopped = None;
        self.world.prepare()?;
        observe(&self);
        while !self.done() {
            match self.step() {
                Ok(()) => {}
                Err(e @ crate::Error::Stalled { .. }) => {
                    stopped = Some(e);
                    break;
                }
                Err(e) => return Err(e),
            }
            progress(&Progress {
                t: self.time(),
                end: self.scene.run.end_s,
                steps: self.world.steps(),
            });
            observe(&self);
        }
        let reached = if stopped.is_none() {
            self.finish()?;
            self.time()
        } else {
            self.finish_partial()
        };
        let comparison = match self.twins.as_slice() {
            [ideal, _] => Some(self.comparison.finish(ideal, reached)),
            _ => None,
        };
        let guards = self.guards();
        if stopped.is_none() && self.scene.run.strict && !guards.is_clean() {
            return Err(crate::Error::Guard {
                t: self.time(),
                violations: guards.violations.clone(),
            });
        }
        Ok(RunResult {
            comparison,
            scene: self.scene,
            twins: self.twins,
            steps: self.world.steps(),
            wall_s: start.elapsed().as_secs_f64(),
            guards,
            stopped,
            reached_s: reached,
        })
    }

    /// What the guards saw so far: the stepper's, plus the twins' energy balance and velocity
    /// motors (judged over the states recorded so far).
    pub fn guards(&self) -> GuardReport {
        let mut guards = self.world.guards().clone();
        for twin in &self.twins {
            let inv = &twin.invariants;
            let g = inv.energy_growth.unwrap_or(0.0);
            if g > ENERGY_GROWTH_LIMIT {
                guards.record(
                    Violation::new(
                        GuardKind::Energy,
                        g,
                        ENERGY_GROWTH_LIMIT,
                        inv.energy_growth_at,
                    )
                    .twin(twin.kind.name())
                    .note(start_mismatch_note(inv)),
                );
            }
            if let (Some(e), Some((name, t))) = (inv.motor_speed_error, &inv.motor_speed_error_at)
                && e > MOTOR_SPEED_ERROR_LIMIT
            {
                // A zero target's miss is reported as it is, against the limit times the floor.
                let (worst, limit, unit) = match inv.motor_speed_miss {
                    Some((miss, 0.0, unit)) => (miss, MOTOR_SPEED_ERROR_LIMIT * 1e-3, Some(unit)),
                    _ => (e, MOTOR_SPEED_ERROR_LIMIT, None),
                };
                let advice = match &inv.motor_start_mismatch {
                    Some(_) if *t == 0.0 => start_mismatch_note(inv),
                    _ => "; raise its `factor`, shorten the steps (`run.max_dt_s`) or, in a chain \
                          of ideal joints, raise `run.solver_sweeps`"
                        .to_string(),
                };
                let mut v = Violation::new(GuardKind::MotorSpeed, worst, limit, *t)
                    .twin(twin.kind.name())
                    .note(advice);
                v.unit = unit;
                v.joint = Some(name.clone());
                v.count = inv.motor_speed_violations.max(1);
                v.first_t_s = inv.motor_speed_first_violation_at.unwrap_or(*t);
                guards.record(v);
            }
        }
        guards
    }

    /// Advances one accepted internal step: records the state before it (invariants, a row when
    /// due, the contact samples), lets the stepper take it, then completes what only the step
    /// determines (ideal reactions, metrics).
    pub fn step(&mut self) -> Result<()> {
        // The sources' forces at the first state, before it is read.
        self.world.prepare()?;
        let t = self.time();
        let rows = !self.skip_rows;
        for twin in &mut self.twins {
            twin.before_step(&mut self.world, rows)?;
        }
        self.last_read = t;
        let target = self.target();
        let stepped = self
            .world
            .step(target)
            .map_err(|e| name_bodies(name_step_field(e, "run.dt_s"), &self.twins));
        let info = stepped.map_err(|e| self.name_diverged_body(e))?;
        for twin in &mut self.twins {
            twin.after_step(&self.world, &info);
        }
        self.write_rows(t);
        self.t_prev = t;
        if let [ideal, clear] = self.twins.as_slice() {
            self.comparison
                .record(ideal, clear, &self.world.rapier.bodies, info.t0, info.dt);
        }
        Ok(())
    }

    /// Closes a run the step control stopped, at the last state [`step`](Self::step) read
    /// (the start of the step that failed: a step taken but not completed is not counted): its
    /// rows, the recorders' final figures. Returns that state's time, s.
    fn finish_partial(&mut self) -> f64 {
        let t = self.last_read;
        self.write_rows(t);
        self.t_prev = t;
        for twin in &mut self.twins {
            for h in &mut twin.hinges {
                h.finish_recording(t);
            }
        }
        t
    }

    /// Names, in a divergence, the body that left the physical range as the scene names it (the
    /// stepper knows only Rapier's handles), with the likely cause.
    fn name_diverged_body(&self, e: crate::Error) -> crate::Error {
        let crate::Error::Diverged { t, .. } = e else {
            return e;
        };
        let params = &self.world.rapier.integration_parameters;
        let found = self.twins.iter().find_map(|twin| {
            twin.bodies.iter().find_map(|b| {
                let rb = self.world.rapier.bodies.get(b.handle)?;
                left_physical_range(rb, params).map(|speed| (twin.kind, b, speed))
            })
        });
        let Some((kind, body, speed)) = found else {
            return e;
        };
        let spec = self.scene.bodies.iter().find(|s| s.name == body.name);
        let drives: Vec<String> = self
            .scene
            .bodies
            .iter()
            .filter(|b| b.motion.is_some())
            .map(|b| format!("`bodies[{}].motion`", b.name))
            .chain(
                self.scene
                    .joints
                    .iter()
                    .filter(|j| j.motor.is_some())
                    .map(|j| format!("`joints[{}].motor`", j.name)),
            )
            .chain(
                self.scene
                    .drives
                    .iter()
                    .map(|d| format!("`drives[{}]`", d.name)),
            )
            .collect();
        let cause = if spec.is_some_and(|s| s.motion.is_some()) {
            format!(
                "its prescribed motion (`bodies[{}].motion`) moves it faster than the model \
                 carries",
                body.name
            )
        } else if !drives.is_empty() {
            format!(
                "the drive ({}) moves the mechanism faster than it can follow, or a contact is \
                 too stiff for the step",
                drives.join(", ")
            )
        } else {
            "an initial velocity too high, or a contact too stiff for the step".to_string()
        };
        let state = if speed.is_finite() {
            format!("speed {} m/s", crate::error::sig4(speed))
        } else {
            "its state is not finite".to_string()
        };
        crate::Error::diverged(
            t,
            crate::error::Divergence::Body {
                body: format!("`{}` of the {} twin", body.name, kind.name()),
                joined: Vec::new(),
                state,
                guard: 0.5 * params.max_linear_velocity(),
                cause,
            },
        )
    }

    /// Records the final state: invariants, a last row at `end_s` (its reactions, velocities and
    /// accelerations solved at that state like every other), final metrics.
    fn finish(&mut self) -> Result<()> {
        self.world.prepare()?;
        let t = self.time();
        let rows = !self.skip_rows;
        for twin in &mut self.twins {
            twin.before_step(&mut self.world, rows)?;
        }
        self.write_rows(t);
        let duration = self.time();
        for twin in &mut self.twins {
            // The final state counts for peaks and onsets (it carries no time).
            for h in &mut twin.hinges {
                h.finish_recording(duration);
            }
        }
        Ok(())
    }
}

/// What a velocity motor that starts off its target adds to a guard's message (empty for none).
fn start_mismatch_note(inv: &Invariants) -> String {
    match &inv.motor_start_mismatch {
        Some((name, rate, target, unit)) => format!(
            "; the velocity motor `{name}` starts at {} {unit} against its target {} {unit}: the \
             bodies' initial velocities do not match the motor, which jumps them to speed in the \
             first steps (work the energy balance does not see); give them initial velocities \
             consistent with it",
            crate::error::sig4(*rate),
            crate::error::sig4(*target)
        ),
        None => String::new(),
    }
}

/// Names the scene's bodies in a stall's message (the stepper knows only Rapier handles).
fn name_bodies(mut e: crate::Error, twins: &[Twin]) -> crate::Error {
    if let crate::Error::Stalled { stall, .. } = &mut e {
        for twin in twins {
            for b in &twin.bodies {
                stall.name_body(
                    b.handle,
                    format!("body `{}` (of the {} twin)", b.name, twin.kind.name()),
                );
            }
        }
    }
    e
}

/// Names the scene's fields in a step-limit error (the stepper knows only the API's names).
fn name_step_field(e: crate::Error, name: &str) -> crate::Error {
    crate::scene::errors::in_scene(e, name)
}
