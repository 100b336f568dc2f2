//! Is a run converged? The same scene at a tighter step control, compared metric by metric.
//!
//! Every bound of the adaptive step, and a fixed step, is second order in the step: halving the
//! tolerance (or the fixed step) divides a converging metric's error by about 4, so the two runs
//! differ by about 3/4 of the coarser run's error, and `4/3 |x(tol) - x(tol/2)|` estimates it
//! (Richardson's estimate for order 2). A metric whose estimate exceeds its bound
//! ([`MetricCheck::bound`]) is flagged: at this step control its number is not to be trusted.
//! Counts (onsets) and the statistics of a chaotic motion do not converge that way; their
//! difference is compared with the bound as it is, so a count that changes with the step is
//! flagged too. What it cannot see is an error that stays put over a range of tolerances: a
//! crank entering its first impact 11 % too deep at the default tolerance and 10.8 % at 0.002
//! (`tests/stepper.rs`) passes a check at half the tolerance.
//!
//! One call runs a scene and checks it ([`run_checked`]); [`check`] checks a run you already
//! have (from [`Simulation::run`](super::Simulation::run) or
//! [`Simulation::run_observed`](super::Simulation::run_observed)). A scene
//! without a clearance hinge has nothing to compare: the check says so
//! ([`Convergence::NothingToCheck`]) and runs nothing more.
//!
//! ```no_run
//! use clearance_joint::scene::runner::convergence::{self, Convergence};
//! use clearance_joint::scene::ValidatedScene;
//!
//! let scene = ValidatedScene::load("assets/solar_panel.ron".as_ref())?;
//! let (run, convergence) = convergence::run_checked(&scene)?;
//! match &convergence {
//!     Convergence::Checked(check) => {
//!         for m in check.flagged() {
//!             println!("not converged: {} {} vs {}", m.name, m.value, m.tighter);
//!         }
//!         println!("the check: {}", check.cost().describe());
//!     }
//!     Convergence::NothingToCheck { reason } => println!("nothing to check ({reason})"),
//! }
//! println!("{} steps", run.steps);
//! # Ok::<(), clearance_joint::Error>(())
//! ```

use super::{Progress, RunOptions, RunResult, Simulation, TwinKind, Twins};
use crate::error::Result;
use crate::scene::{Scene, StepMode, ValidatedScene};
use serde::{Deserialize, Serialize};

/// Bound on the estimated error of a first impact's onset, s (the mechanism benchmark's).
pub const ONSET_BOUND_S: f64 = 1e-6;
/// Bound on the estimated relative error of a force or a penetration (1 %).
pub const FORCE_BOUND: f64 = 0.01;
/// Bound on the relative change of a count of onsets (3 %).
pub const ONSET_COUNT_BOUND: f64 = 0.03;
/// Bound on the estimated relative error of the fraction of time in contact (5 %).
pub const CONTACT_FRACTION_BOUND: f64 = 0.05;
/// Bound on the estimated error of a hinge's final angle, deg.
pub const ANGLE_BOUND_DEG: f64 = 0.01;

/// The scene at the tighter step control the check compares with: half the tolerance of
/// adaptive steps, or half the fixed step.
pub fn tightened(scene: &ValidatedScene) -> Result<ValidatedScene> {
    let mut tighter = scene.scene().clone();
    let run = &mut tighter.run;
    match run.step {
        StepMode::Adaptive => run.tolerance *= 0.5,
        StepMode::Fixed => run.dt_s *= 0.5,
    }
    tighter.validated()
}

/// Why `scene` gives the check nothing to compare (`None` when it has a clearance hinge): every
/// metric the check compares is a clearance hinge's.
pub fn nothing_to_check(scene: &Scene) -> Option<&'static str> {
    scene
        .hinges
        .iter()
        .all(|h| h.clearance.is_none())
        .then_some("no clearance hinge")
}

/// Checks `run`, a complete run of `scene`: runs the scene again at the tighter step control
/// ([`tightened`]), the clearance twin only and without output rows, calling `progress` after
/// each of its steps, and compares ([`ConvergenceCheck::compare`]). A scene without a clearance
/// hinge, or a run without the clearance twin, is [`Convergence::NothingToCheck`], with no
/// second run. An incomplete run ([`RunResult::stopped`]) is refused: there is no end to
/// compare. Errors of the tighter run are returned as they are (a stall, a strict guard).
pub fn check(
    scene: &ValidatedScene,
    run: &RunResult,
    progress: impl FnMut(&Progress),
) -> Result<Convergence> {
    if let Some(e) = &run.stopped {
        return Err(crate::Error::invalid(
            "convergence",
            format!(
                "the run stopped at t = {} s ({e}): an incomplete run has no end to compare",
                crate::error::sig4(run.reached_s)
            ),
        ));
    }
    let reason = match run.twin(TwinKind::Clearance) {
        None => Some("no clearance twin in the run"),
        Some(t) if t.clearance_hinges().is_empty() => Some("no clearance hinge"),
        Some(_) => nothing_to_check(scene),
    };
    if let Some(reason) = reason {
        return Ok(Convergence::NothingToCheck {
            reason: reason.to_string(),
        });
    }
    let tighter = tightened(scene)?;
    let options = RunOptions {
        twins: Twins::ClearanceOnly,
        skip_rows: true,
    };
    let finer = Simulation::from_validated(&tighter, options)?
        .run_with_progress(progress)
        .map_err(|e| e.with_step_mode(tighter.run.step == StepMode::Adaptive))?;
    Ok(Convergence::Checked(ConvergenceCheck::compare(run, &finer)))
}

/// Runs `scene` (both twins, with their rows: [`RunOptions::default`]) and checks it
/// ([`check`]): the run and its check in one call. A run the step control stops is an error, as
/// from [`Simulation::run`].
pub fn run_checked(scene: &ValidatedScene) -> Result<(RunResult, Convergence)> {
    let run = Simulation::from_validated(scene, RunOptions::default())?
        .run()
        .map_err(|e| e.with_step_mode(scene.run.step == StepMode::Adaptive))?;
    let convergence = check(scene, &run, |_| {})?;
    Ok((run, convergence))
}

/// What [`check`] found.
#[derive(Clone, Debug, PartialEq)]
pub enum Convergence {
    /// The run against the tighter one, metric by metric.
    Checked(ConvergenceCheck),
    /// Nothing to compare (`reason`: no clearance hinge); no second run was made. This is not a
    /// convergence: no metric was checked.
    NothingToCheck {
        /// Why, in words.
        reason: String,
    },
}

impl Convergence {
    /// The comparison, if one was made.
    pub fn checked(&self) -> Option<&ConvergenceCheck> {
        match self {
            Convergence::Checked(c) => Some(c),
            Convergence::NothingToCheck { .. } => None,
        }
    }

    /// The verdict in brief, as a run's summary records it.
    pub fn verdict(&self) -> ConvergenceVerdict {
        match self {
            Convergence::Checked(c) => c.verdict(),
            Convergence::NothingToCheck { reason } => ConvergenceVerdict::NothingToCheck {
                reason: reason.clone(),
            },
        }
    }

    /// [`ConvergenceCheck::strict`] of a comparison; `Ok` when there was nothing to compare
    /// (whoever asked for a check decides whether that is an error).
    pub fn strict(&self) -> Result<()> {
        self.checked().map_or(Ok(()), ConvergenceCheck::strict)
    }
}

/// What the check cost, against the run it checks: the tighter run's internal steps and wall
/// time, and the run's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CheckCost {
    /// Internal steps of the tighter run.
    pub steps: u64,
    /// Wall time of the tighter run, s.
    pub wall_s: f64,
    /// Internal steps of the run checked.
    pub run_steps: u64,
    /// Wall time of the run checked, s.
    pub run_wall_s: f64,
}

impl CheckCost {
    /// The check's wall time over the run's (`None` when the run took no measurable time).
    pub fn wall_ratio(&self) -> Option<f64> {
        (self.run_wall_s > 0.0).then(|| self.wall_s / self.run_wall_s)
    }

    /// The cost in words: `41,210 steps in 1.9 s, 2.1 times the run's wall time (20,570 steps
    /// in 0.9 s)`.
    pub fn describe(&self) -> String {
        let ratio = match self.wall_ratio() {
            Some(r) if r >= 1.0 => format!("{r:.1} times the run's wall time"),
            Some(r) => format!("{r:.2} times the run's wall time"),
            None => "the run's wall time too short to compare".to_string(),
        };
        format!(
            "{} steps in {} s, {ratio} ({} steps in {} s)",
            thousands(self.steps),
            seconds(self.wall_s),
            thousands(self.run_steps),
            seconds(self.run_wall_s)
        )
    }
}

/// `n` with a comma every three digits: `41,210`.
fn thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// A wall time in seconds to 0.01 s below 10 s, to 0.1 s above.
fn seconds(s: f64) -> String {
    if s < 10.0 {
        format!("{s:.2}")
    } else {
        format!("{s:.1}")
    }
}

/// A run's convergence in brief, as its `summary.json` records it (`status`, then the fields of
/// that status): which metrics converged, which did not, the worst, and what the check cost.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum ConvergenceVerdict {
    /// No check was run (`reason`: not asked for, or the run did not reach its end).
    NotChecked {
        /// Why, in words.
        reason: String,
    },
    /// Nothing to compare (no clearance hinge); no second run.
    NothingToCheck {
        /// Why, in words.
        reason: String,
    },
    /// The tighter run failed (`error`), so nothing was compared.
    Failed {
        /// Its error, in words.
        error: String,
    },
    /// Compared metric by metric ([`ConvergenceCheck`]).
    Checked {
        /// The metrics within their bounds, by name (`hinge peak force (N)`).
        converged: Vec<String>,
        /// The metrics beyond their bounds, by name.
        not_converged: Vec<String>,
        /// The worst of those in words ([`MetricCheck::describe`]; null when none).
        worst: Option<String>,
        /// What the check cost.
        cost: CheckCost,
    },
}

impl Default for ConvergenceVerdict {
    fn default() -> Self {
        ConvergenceVerdict::NotChecked {
            reason: "no convergence check was run".to_string(),
        }
    }
}

impl ConvergenceVerdict {
    /// Whether metrics were compared ([`ConvergenceVerdict::Checked`]).
    pub fn is_checked(&self) -> bool {
        matches!(self, ConvergenceVerdict::Checked { .. })
    }

    /// Whether a check answered: compared, or found nothing to compare (neither skipped nor
    /// failed).
    pub fn is_answered(&self) -> bool {
        matches!(
            self,
            ConvergenceVerdict::Checked { .. } | ConvergenceVerdict::NothingToCheck { .. }
        )
    }

    /// The metrics beyond their bounds (none unless checked).
    pub fn not_converged(&self) -> &[String] {
        match self {
            ConvergenceVerdict::Checked { not_converged, .. } => not_converged,
            _ => &[],
        }
    }

    /// The verdict in one line: `converged: all 8 metrics within their bounds`, `NOT
    /// CONVERGED: 1 of 8 metrics (hinge onsets), the worst ...; the other 7 converged`,
    /// `nothing to check (no clearance hinge)`, `not checked (...)`, `check failed: ...`.
    pub fn describe(&self) -> String {
        match self {
            ConvergenceVerdict::NotChecked { reason } => format!("not checked ({reason})"),
            ConvergenceVerdict::NothingToCheck { reason } => {
                format!("nothing to check ({reason})")
            }
            ConvergenceVerdict::Failed { error } => {
                format!("check failed (its run at the tighter step control: {error})")
            }
            ConvergenceVerdict::Checked {
                converged,
                not_converged,
                worst,
                ..
            } => {
                let total = converged.len() + not_converged.len();
                if not_converged.is_empty() {
                    format!("converged: all {total} metrics within their bounds")
                } else {
                    format!(
                        "NOT CONVERGED: {} of {total} metrics ({}), the worst {}; the other {} \
                         converged",
                        not_converged.len(),
                        not_converged.join(", "),
                        worst.as_deref().unwrap_or("-"),
                        converged.len()
                    )
                }
            }
        }
    }
}

/// One metric of one clearance hinge at the run's step control and at the tighter one.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MetricCheck {
    /// Hinge and metric, e.g. `hinge first impact peak (N)`.
    pub name: String,
    /// The run's value.
    pub value: f64,
    /// The value at the tighter step control.
    pub tighter: f64,
    /// The run's estimated error, in the unit of [`bound`](Self::bound): `4/3` of the difference
    /// for a converging metric, the difference itself for a count; relative to the tighter
    /// value where the bound is relative.
    pub estimated_error: f64,
    /// The bound it is held to (absolute in the metric's unit, or relative: see
    /// [`relative`](Self::relative)).
    pub bound: f64,
    /// Whether the bound (and the estimate) is relative to the tighter value.
    pub relative: bool,
    /// Whether the estimate exceeds the bound.
    pub flagged: bool,
}

impl MetricCheck {
    /// The check in words: `hinge peak force (N): 180.3 against 179.2, estimated error 0.82 %
    /// (bound 1 %)` (the run's value first, the tighter run's second).
    pub fn describe(&self) -> String {
        let sig = crate::error::sig4;
        let (err, bound) = if self.relative {
            (
                format!("{} %", sig(100.0 * self.estimated_error)),
                format!("{} %", sig(100.0 * self.bound)),
            )
        } else {
            (sig(self.estimated_error), sig(self.bound))
        };
        let diff = (self.value - self.tighter).abs();
        format!(
            "{}: {} against {}, estimated error {err} (bound {bound})",
            self.name,
            shown(self.value, diff),
            shown(self.tighter, diff)
        )
    }

    fn new(
        name: String,
        value: f64,
        tighter: f64,
        bound: f64,
        relative: bool,
        count: bool,
    ) -> Self {
        let factor = if count { 1.0 } else { 4.0 / 3.0 };
        let diff = factor * (value - tighter).abs();
        let estimated_error = match (relative, tighter.abs() > 0.0) {
            (false, _) => diff,
            (true, true) => diff / tighter.abs(),
            // Relative to 0: no change is converged, any change is not.
            (true, false) if diff == 0.0 => 0.0,
            (true, false) => f64::INFINITY,
        };
        MetricCheck {
            name,
            value,
            tighter,
            flagged: !(estimated_error <= bound),
            estimated_error,
            bound,
            relative,
        }
    }
}

/// `x` with enough significant digits to show a difference `diff` (4 to 10).
fn shown(x: f64, diff: f64) -> String {
    if !(x.is_finite() && x != 0.0) {
        return crate::error::sig4(x);
    }
    // A count (or any whole number up to 2^53) as it is.
    if x.fract() == 0.0 && x.abs() < 9e15 {
        return format!("{x:.0}");
    }
    let digits = if diff > 0.0 && diff.is_finite() {
        ((x.abs() / diff).log10().ceil() as i64 + 2).clamp(4, 10)
    } else {
        4
    };
    let decimals = (digits - 1 - x.abs().log10().floor() as i64).max(0) as usize;
    format!("{x:.decimals$}")
}

/// A run's clearance hinges against the same scene at a tighter step control ([`tightened`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ConvergenceCheck {
    /// The tighter run's step control in words.
    pub tighter: String,
    /// Internal steps of the run and of the tighter run.
    pub steps: [u64; 2],
    /// Wall time of the run and of the tighter run, s.
    pub wall_s: [f64; 2],
    /// Every metric of every clearance hinge, hinge by hinge.
    pub metrics: Vec<MetricCheck>,
}

impl ConvergenceCheck {
    /// Compares the clearance twin of `run` with that of `tighter`, hinge by hinge: the first
    /// impact's onset and peak, the largest force and penetration, the onsets (chatter included)
    /// and the impacts after a real separation, the fraction of time in contact and the final
    /// angle. A hinge that has an impact in one run and none in
    /// the other has its first-impact metrics flagged (compared as infinite).
    pub fn compare(run: &RunResult, tighter: &RunResult) -> Self {
        let mut metrics = Vec::new();
        if let (Some(a), Some(b)) = (
            run.twin(TwinKind::Clearance),
            tighter.twin(TwinKind::Clearance),
        ) {
            let (ma, mb) = (a.hinge_metrics(), b.hinge_metrics());
            let (angle_a, angle_b) = (a.final_angles_deg(), b.final_angles_deg());
            for h in a.clearance_hinges() {
                let (Some(x), Some(y)) = (ma.get(h), mb.get(h)) else {
                    continue;
                };
                let first = |m: Option<f64>| m.unwrap_or(f64::INFINITY);
                let mut push = |what: &str, v: f64, w: f64, bound: f64, rel: bool, count: bool| {
                    metrics.push(MetricCheck::new(
                        format!("{h} {what}"),
                        v,
                        w,
                        bound,
                        rel,
                        count,
                    ));
                };
                if x.first_impact_t_s.is_some() || y.first_impact_t_s.is_some() {
                    push(
                        "first impact (s)",
                        first(x.first_impact_t_s),
                        first(y.first_impact_t_s),
                        ONSET_BOUND_S,
                        false,
                        false,
                    );
                    push(
                        "first impact peak (N)",
                        first(x.first_impact_peak_n),
                        first(y.first_impact_peak_n),
                        FORCE_BOUND,
                        true,
                        false,
                    );
                }
                push(
                    "peak force (N)",
                    x.peak_force_n,
                    y.peak_force_n,
                    FORCE_BOUND,
                    true,
                    false,
                );
                push(
                    "max penetration (um)",
                    x.max_penetration_um,
                    y.max_penetration_um,
                    FORCE_BOUND,
                    true,
                    false,
                );
                push(
                    "onsets",
                    x.onsets as f64,
                    y.onsets as f64,
                    ONSET_COUNT_BOUND,
                    true,
                    true,
                );
                push(
                    "impacts after a separation",
                    x.impacts as f64,
                    y.impacts as f64,
                    ONSET_COUNT_BOUND,
                    true,
                    true,
                );
                push(
                    "contact fraction",
                    x.contact_fraction,
                    y.contact_fraction,
                    CONTACT_FRACTION_BOUND,
                    true,
                    false,
                );
                if let (Some(&v), Some(&w)) = (angle_a.get(h), angle_b.get(h)) {
                    push("final angle (deg)", v, w, ANGLE_BOUND_DEG, false, false);
                }
            }
        }
        ConvergenceCheck {
            tighter: tighter.scene.run.stepping(),
            steps: [run.steps, tighter.steps],
            wall_s: [run.wall_s, tighter.wall_s],
            metrics,
        }
    }

    /// What the check cost against the run.
    pub fn cost(&self) -> CheckCost {
        CheckCost {
            steps: self.steps[1],
            wall_s: self.wall_s[1],
            run_steps: self.steps[0],
            run_wall_s: self.wall_s[0],
        }
    }

    /// The verdict in brief: which metrics converged, which did not, the worst, the cost.
    pub fn verdict(&self) -> ConvergenceVerdict {
        let names = |flagged: bool| {
            self.metrics
                .iter()
                .filter(|m| m.flagged == flagged)
                .map(|m| m.name.clone())
                .collect()
        };
        ConvergenceVerdict::Checked {
            converged: names(false),
            not_converged: names(true),
            worst: self.worst().map(MetricCheck::describe),
            cost: self.cost(),
        }
    }

    /// The flagged metrics, in order.
    pub fn flagged(&self) -> impl Iterator<Item = &MetricCheck> {
        self.metrics.iter().filter(|m| m.flagged)
    }

    /// Whether no metric is flagged.
    pub fn is_clean(&self) -> bool {
        self.flagged().next().is_none()
    }

    /// [`Error::NotConverged`](crate::Error::NotConverged) naming the worst flagged metric, or
    /// `Ok` when none is.
    pub fn strict(&self) -> Result<()> {
        match self.worst() {
            None => Ok(()),
            Some(w) => Err(crate::Error::NotConverged {
                flagged: self.flagged().count(),
                worst: w.describe(),
            }),
        }
    }

    /// The flagged metric furthest beyond its bound (estimate over bound), if any.
    pub fn worst(&self) -> Option<&MetricCheck> {
        // The first of equals (a first impact that is the largest force too).
        let excess = |m: &MetricCheck| m.estimated_error / m.bound;
        self.flagged()
            .reduce(|w, m| if excess(m) > excess(w) { m } else { w })
    }
}

#[cfg(test)]
mod tests;
