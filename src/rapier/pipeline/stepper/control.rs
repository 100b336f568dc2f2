//! The step control's settings: [`StepMode`] and [`StepControl`], plain data with public fields
//! (as Rapier's `IntegrationParameters`), checked at every step.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// How the step is chosen (`run.step` in scene files).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum StepMode {
    /// A constant step (the paper's way); the last step is shortened to land on the end.
    Fixed,
    /// The step changes between Rapier steps: no body turns more than `tolerance/8` rad in a step
    /// (the bodies' own motion), shorter as a contact approaches and inside it (twice `tolerance` of the
    /// contact's natural period, at most `50 tolerance` of its damped stability limit, within
    /// friction's), at most the
    /// largest step (a safety cap), with rejected steps retried. The default.
    #[default]
    Adaptive,
}

/// Steps at or below this many floors in a row, with no progress in simulated time, stop the
/// run with [`Error::Stalled`](crate::Error::Stalled).
pub(crate) const STALL_STEPS: u64 = 100_000;

/// World steps in a row whose sub-cycle reached its cap of sub-steps that stop the run with
/// [`Error::Stalled`](crate::Error::Stalled): each such step costs the cap's sub-steps and ends
/// unresolved, so a contact no sub-step resolves would crawl on at seconds a world step.
pub(crate) const CAP_STALL_STEPS: u64 = 10;

/// Adaptive world steps ending in a sub-cycled contact that asks for world steps below the
/// floor `min_dt` (no step between them ending in one that asks for more) that stop the run with
/// [`Error::Stalled`](crate::Error::Stalled), as the explicit joint's retries stop at such a
/// contact at once: the world's step would sit at the floor while it lasts. Ten, not one: a
/// count that a lone state cannot reach, as [`CAP_STALL_STEPS`].
pub(crate) const CONTACT_FLOOR_STALL_STEPS: u64 = 10;

/// The step control of a [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld):
/// plain data, as Rapier's `IntegrationParameters`. Start from [`fixed`](Self::fixed) or
/// [`adaptive`](Self::adaptive) and set the other fields with struct update syntax:
///
/// ```
/// use clearance_joint::rapier::pipeline::stepper::StepControl;
///
/// let control = StepControl {
///     strict: true,
///     min_dt: 1e-6,
///     ..StepControl::adaptive(1e-3, 0.0075)
/// };
/// # assert!(control.strict);
/// ```
///
/// The fields are checked at every step (a control set between steps included), and one out of
/// its domain is refused naming it: finite steps of at least 1e-10 s, an adaptive `tolerance`
/// from 1e-6 to 1, `min_dt` positive and at most `max_dt`, `max_growth` above 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepControl {
    /// Fixed or adaptive.
    pub mode: StepMode,
    /// The fixed step, or the largest adaptive step, s.
    pub max_dt: f64,
    /// Adaptive: the local error each bound of the step holds to: a step covers at most twice
    /// this fraction of a contact's natural period
    /// (a tolerance of 0.05 is a tenth of a period), turns no body by more than an eighth of it
    /// in rad, and moves a
    /// journal's centre relative to its bearing's by at most this fraction of the clearance.
    pub tolerance: f64,
    /// Adaptive: the smallest step, s (the floor; 100,000 steps at it in a row
    /// without progress stall the run, and so does a contact that needs steps below it, explicit
    /// or sub-cycled).
    pub min_dt: f64,
    /// Adaptive: the largest ratio of a step to the one before it. Steps that change abruptly
    /// make Rapier's constrained velocities (which it evaluates at the step's start) disagree
    /// with the half-step velocities of the kicked bodies; a bounded ratio keeps that error
    /// first order in the change.
    pub max_growth: f64,
    /// Whether a guard violation ([`GuardReport::is_clean`](super::GuardReport::is_clean) false) fails the step with
    /// [`Error::Guard`](crate::Error::Guard) instead of only being recorded.
    pub strict: bool,
    /// Whether Rapier's joints correct their drift at the rate of the longest recent step
    /// (the span decays by 0.1 % per step), not within each step whatever
    /// its length. On by default: without it a jointed chain of slender bodies can diverge when
    /// the step changes.
    pub joint_correction: bool,
}

impl StepControl {
    /// The shortest step, s (fixed, or an adaptive control's largest; also the default floor
    /// `min_dt`): Rapier's solver divides by the step, and a step of 1e-300 s ends in
    /// non-finite states.
    pub(crate) const SMALLEST_STEP: f64 = 1e-10;

    /// The smallest adaptive tolerance: a step covers twice it of a contact period and a body
    /// turns at most an eighth of it in rad, so below it a body turning at 1,000 rad/s needs
    /// steps under the default floor `min_dt` (1e-10 s).
    pub(crate) const SMALLEST_TOLERANCE: f64 = 1e-6;

    /// Constant steps of `dt` seconds.
    pub fn fixed(dt: f64) -> Self {
        StepControl {
            mode: StepMode::Fixed,
            max_dt: dt,
            ..Self::adaptive(dt, 0.02)
        }
    }

    /// Adaptive steps of at most `max_dt` seconds, `2 tolerance` of a contact period inside
    /// contacts and `tolerance/8` rad of any body's turn; floor 1e-10 s, growth at most 2 per step,
    /// not strict.
    pub fn adaptive(max_dt: f64, tolerance: f64) -> Self {
        StepControl {
            mode: StepMode::Adaptive,
            max_dt,
            tolerance,
            min_dt: Self::SMALLEST_STEP,
            max_growth: 2.0,
            strict: false,
            joint_correction: true,
        }
    }

    /// Checks the fields: finite steps of at least 1e-10 s, a tolerance from 1e-6 to 1, growth
    /// above 1.
    pub(crate) fn validate(&self) -> Result<()> {
        let ok = |v: f64| v.is_finite() && v > 0.0;
        let step = match self.mode {
            StepMode::Fixed => "dt",
            StepMode::Adaptive => "max_dt",
        };
        if !(ok(self.max_dt) && self.max_dt >= Self::SMALLEST_STEP) {
            return Err(Error::invalid(
                step,
                format!(
                    "must be a finite step of at least {} s (got {} s): Rapier's solver divides by \
                     the step, and shorter ones end in non-finite states",
                    Self::SMALLEST_STEP,
                    self.max_dt
                ),
            ));
        }
        if self.mode == StepMode::Adaptive {
            if !(self.tolerance >= Self::SMALLEST_TOLERANCE && self.tolerance <= 1.0) {
                return Err(Error::invalid(
                    "tolerance",
                    format!(
                        "must be in [{}, 1]: a step covers twice it of a contact's period and \
                         turns a body by an eighth of it in rad, so a smaller one asks a fast \
                         body for steps below the floor `min_dt` (got {})",
                        Self::SMALLEST_TOLERANCE,
                        self.tolerance
                    ),
                ));
            }
            if !(ok(self.min_dt) && self.min_dt <= self.max_dt) {
                return Err(Error::invalid(
                    "min_dt",
                    format!(
                        "must be positive and at most the largest step {} s (got {})",
                        self.max_dt, self.min_dt
                    ),
                ));
            }
            if !(self.max_growth.is_finite() && self.max_growth > 1.0) {
                return Err(Error::invalid(
                    "max_growth",
                    format!("must be a finite ratio above 1 (got {})", self.max_growth),
                ));
            }
        }
        Ok(())
    }
}
