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
//! ```no_run
//! use clearance_joint::scene::runner::convergence::{ConvergenceCheck, tightened};
//! use clearance_joint::scene::runner::{RunOptions, Simulation};
//! use clearance_joint::scene::ValidatedScene;
//!
//! let scene = ValidatedScene::load("assets/solar_panel.ron".as_ref())?;
//! let run = Simulation::from_validated(&scene, RunOptions::default())?.run()?;
//! let finer = Simulation::from_validated(&tightened(&scene)?, RunOptions::default())?.run()?;
//! let check = ConvergenceCheck::compare(&run, &finer);
//! for m in check.flagged() {
//!     println!("not converged: {} {} vs {}", m.name, m.value, m.tighter);
//! }
//! # Ok::<(), clearance_joint::Error>(())
//! ```

use super::{RunResult, TwinKind};
use crate::error::Result;
use crate::scene::{StepMode, ValidatedScene};
use serde::Serialize;

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
                    x.impacts as f64,
                    y.impacts as f64,
                    ONSET_COUNT_BOUND,
                    true,
                    true,
                );
                push(
                    "impacts after a separation",
                    x.separated_impacts as f64,
                    y.separated_impacts as f64,
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
            metrics,
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
mod tests {
    use super::*;

    #[test]
    fn values_shown_to_their_difference() {
        assert_eq!(shown(179.2319, 0.02), "179.232");
        assert_eq!(shown(0.087512233, 4e-7), "0.087512233");
        assert_eq!(shown(53.0, 0.0), "53");
        assert_eq!(shown(52.5, 0.0), "52.50");
        assert_eq!(shown(f64::INFINITY, 1.0), "inf");
    }

    #[test]
    fn estimates_by_hand() {
        // 100.3 against 100.0: 4/3 of 0.3 % is 0.4 %, inside 1 %.
        let m = MetricCheck::new("f".into(), 100.3, 100.0, FORCE_BOUND, true, false);
        assert!((m.estimated_error - 0.004).abs() < 1e-12 && !m.flagged);
        // 1.0 against 1.009: 4/3 of 0.9 % is 1.2 %, flagged.
        let m = MetricCheck::new("f".into(), 1.0, 1.009, FORCE_BOUND, true, false);
        assert!(m.flagged);
        // A count: 103 against 100 is 3 %, at the bound; 104 is beyond.
        let m = MetricCheck::new("n".into(), 103.0, 100.0, ONSET_COUNT_BOUND, true, true);
        assert!(!m.flagged, "{m:?}");
        assert!(MetricCheck::new("n".into(), 104.0, 100.0, ONSET_COUNT_BOUND, true, true).flagged);
        // Absolute: onsets 0.6 us apart estimate 0.8 us, inside 1 us.
        let m = MetricCheck::new("t".into(), 0.1000006, 0.1, ONSET_BOUND_S, false, false);
        assert!((m.estimated_error - 8e-7).abs() < 1e-12 && !m.flagged);
        // An impact in one run only, and a change from 0.
        assert!(MetricCheck::new("t".into(), f64::INFINITY, 0.1, 1e-6, false, false).flagged);
        assert!(MetricCheck::new("n".into(), 1.0, 0.0, ONSET_COUNT_BOUND, true, true).flagged);
        assert!(!MetricCheck::new("n".into(), 0.0, 0.0, ONSET_COUNT_BOUND, true, true).flagged);
    }
}
