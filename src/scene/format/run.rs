//! Run settings: time stepping and output, and their validation.

use super::limits::*;
use crate::error::{Error, Result, in_range, positive, sig4};
use serde::{Deserialize, Serialize};

/// Time stepping and output.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunSettings {
    /// Fixed steps: the step, s (default 1e-4, the paper's).
    #[serde(default = "default_dt")]
    pub dt_s: f64,
    /// Adaptive steps: the largest step, s (default 1e-3), a safety cap. The step is chosen from
    /// the motion (no body turns more than `tolerance/8` rad in a step) and the contacts
    /// (twice `tolerance` of a contact's period); what neither sees, a stiff force of your own on a
    /// body that does not turn, needs this cap below a tenth of its period.
    #[serde(default = "default_max_dt")]
    pub max_dt_s: f64,
    /// Simulated time, s.
    #[serde(default = "default_end")]
    pub end_s: f64,
    /// Interval between CSV rows, s: a row is the first state at or after each multiple of it
    /// (with fixed steps, every `round(interval/dt)`-th step). Rows never change the steps: the
    /// physics does not depend on the output interval.
    #[serde(default = "default_dt")]
    pub output_interval_s: f64,
    /// How the step is chosen.
    #[serde(default)]
    pub step: StepMode,
    /// Adaptive steps (default 0.0075): half the fraction of a contact's natural period
    /// `2 pi/omega` one step may cover inside and ahead of a contact (a step covers `2 tolerance`
    /// of it: 1.5 % at the default), 8 times the angle in radians any movable body may turn in
    /// one step (0.054 deg at the default: the ideal slider-crank at 5000 rpm then keeps its
    /// slider acceleration within 6.5e-7 of its peak from the closed form), and the fraction of
    /// the clearance a journal's centre may move relative to its bearing's in one step, in free
    /// flight and in contact.
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    /// Whether a guard violation (a penetration beyond the law's validity, energy gained, steps
    /// at the floor) fails the run instead of being reported (`--strict`).
    #[serde(default)]
    pub strict: bool,
    /// Writes each moving body's centre-of-mass position, velocity and acceleration along the
    /// world axes (`<body>_x_m`, ..., `<body>_vz_m_s`, ..., `<body>_az_m_s2`) in the rows: a
    /// dynamic body's velocity and acceleration solved at each state from the constrained
    /// equations (the joints' and the clearance contacts' forces known), a driven body's its
    /// drive's.
    #[serde(default)]
    pub body_motion: bool,
    /// Gauss-Seidel sweeps Rapier makes over the ideal joints' constraints in each step
    /// (Rapier's `num_internal_pgs_iterations`; default 1, at most [`SWEEPS_MAX`]). One sweep
    /// solves a body held by one joint exactly, and a chain or loop of ideal joints only in part:
    /// what the sweep leaves grows with the step. Raise it where a light body sits between stiff
    /// joints: the four-bar's crank (`assets/four_bar.ron`), on a velocity motor and carrying a
    /// coupler 4.5 times its inertia about the pivot, takes 32 (measured there: at the default
    /// steps the first impact comes 19.7, 9.5, 2.2, 0.7 and 0.3 us after a fixed 1e-6 s run's at
    /// 1, 4, 16, 32 and 64 sweeps). Each sweep is a pass over the joints: the paper's scene, which
    /// needs one, ran 24 % longer at 32.
    #[serde(default = "default_solver_sweeps")]
    pub solver_sweeps: usize,
    /// How the compliant hinges (planar and spatial) integrate their contact: `Explicit` (the
    /// forces held over each step, which must then resolve every contact) or `SubCycled` (each
    /// contact integrated on the hinge's own clock inside the step, its damping and friction
    /// implicitly; the step follows the slow motion).
    #[serde(default)]
    pub contact_integration: crate::rapier::joint::ContactIntegration,
    /// Which of the sub-cycle's techniques the sub-cycled hinges use (default all on; e.g.
    /// `--set run.sub_cycle.implicit_friction=false`): one off gives the plainer method, for
    /// comparison ([`SubCycleTechniques`](crate::rapier::joint::SubCycleTechniques)). Read
    /// only with `contact_integration: SubCycled`. Left out of the scene's written form while
    /// all are on.
    #[serde(
        default,
        skip_serializing_if = "crate::rapier::joint::SubCycleTechniques::all_on"
    )]
    pub sub_cycle: crate::rapier::joint::SubCycleTechniques,
}

pub use crate::rapier::pipeline::stepper::StepMode;

fn default_tolerance() -> f64 {
    0.0075
}

fn default_solver_sweeps() -> usize {
    1
}

fn default_max_dt() -> f64 {
    1e-3
}

fn default_dt() -> f64 {
    1e-4
}
fn default_end() -> f64 {
    5.0
}

impl RunSettings {
    /// The stepper's control for these settings.
    pub fn step_control(&self) -> crate::rapier::pipeline::stepper::StepControl {
        use crate::rapier::pipeline::stepper::StepControl;
        let c = match self.step {
            // The tolerance also sets a sub-cycled contact's sub-steps.
            StepMode::Fixed => StepControl {
                tolerance: self.tolerance,
                ..StepControl::fixed(self.dt_s)
            },
            StepMode::Adaptive => StepControl::adaptive(self.max_dt_s, self.tolerance),
        };
        StepControl {
            strict: self.strict,
            ..c
        }
    }

    /// The step control in words, e.g. "adaptive steps of at most 1e-3 s (tolerance 0.0075:
    /// twice it of a contact period, an eighth of it in rad of a body's turn)".
    pub fn stepping(&self) -> String {
        match self.step {
            StepMode::Fixed => format!("fixed step {:e} s", self.dt_s),
            StepMode::Adaptive => format!(
                "adaptive steps of at most {:e} s (tolerance {}: twice it of a contact period, an eighth of it in rad of a body's turn)",
                self.max_dt_s, self.tolerance
            ),
        }
    }
}

impl Default for RunSettings {
    fn default() -> Self {
        RunSettings {
            dt_s: default_dt(),
            max_dt_s: default_max_dt(),
            end_s: default_end(),
            output_interval_s: default_dt(),
            step: StepMode::default(),
            tolerance: default_tolerance(),
            strict: false,
            body_motion: false,
            solver_sweeps: default_solver_sweeps(),
            contact_integration: Default::default(),
            sub_cycle: Default::default(),
        }
    }
}

impl RunSettings {
    /// Checks the settings; errors name the field as `run.<field>`.
    pub(super) fn validate(&self) -> Result<()> {
        let r = self;
        positive("run.dt_s", r.dt_s)?;
        in_range("run.dt_s", r.dt_s, DT_RANGE.0, DT_RANGE.1, "s")?;
        in_range("run.max_dt_s", r.max_dt_s, DT_RANGE.0, DT_RANGE.1, "s")?;
        positive("run.end_s", r.end_s)?;
        in_range("run.end_s", r.end_s, END_RANGE.0, END_RANGE.1, "s")?;
        positive("run.output_interval_s", r.output_interval_s)?;
        in_range(
            "run.output_interval_s",
            r.output_interval_s,
            DT_RANGE.0,
            END_RANGE.1,
            "s",
        )?;
        crate::error::in_range_open_closed("run.tolerance", r.tolerance, 0.0, 1.0)?;
        in_range("run.tolerance", r.tolerance, TOLERANCE_MIN, 1.0, "")?;
        if !(1..=SWEEPS_MAX).contains(&r.solver_sweeps) {
            return Err(Error::invalid(
                "run.solver_sweeps",
                format!(
                    "must be 1 to {SWEEPS_MAX} Gauss-Seidel sweeps a step (got {})",
                    r.solver_sweeps
                ),
            ));
        }
        if !r.sub_cycle.all_on()
            && r.contact_integration != crate::rapier::joint::ContactIntegration::SubCycled
        {
            // A switch that nothing reads would compare a run with itself.
            return Err(Error::invalid(
                "run.sub_cycle",
                "switches the sub-cycle's techniques: read only with \
                 run.contact_integration = SubCycled (here Explicit)",
            ));
        }
        if r.end_s / r.output_interval_s > MAX_ROWS {
            return Err(Error::invalid(
                "run.output_interval_s",
                format!(
                    "{} rows to reach run.end_s = {} s: more than {} (memory); use a larger interval",
                    sig4(r.end_s / r.output_interval_s),
                    sig4(r.end_s),
                    sig4(MAX_ROWS)
                ),
            ));
        }
        if r.step == StepMode::Fixed && r.end_s / r.dt_s > MAX_STEPS {
            return Err(Error::invalid(
                "run.dt_s",
                format!(
                    "{} steps to reach run.end_s = {} s: more than {}; use a larger step or a shorter run",
                    sig4(r.end_s / r.dt_s),
                    sig4(r.end_s),
                    sig4(MAX_STEPS)
                ),
            ));
        }
        Ok(())
    }
}

/// Most output rows a run may keep (each row is a few hundred bytes for a small scene; the CLI
/// also checks the bytes of a run against the memory available before it starts).
const MAX_ROWS: f64 = 1e7;
/// Most steps (`run.end_s / run.dt_s`) a run may take.
const MAX_STEPS: f64 = 1e9;
