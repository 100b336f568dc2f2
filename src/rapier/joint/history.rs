//! The contact history a joint carries between steps, and how one evaluation moves it.

use super::*;
use crate::model::laws::speed_at_crossing_in_substep;

/// State carried between steps: whether a contact is on, and its impact velocity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct ContactHistory {
    pub(super) in_contact: bool,
    /// Largest gap of the current free flight (infinite before the first contact), m.
    pub(super) max_gap: f64,
    pub(super) compressing: bool,
    pub(super) impact_rate: f64,
}

impl Default for ContactHistory {
    fn default() -> Self {
        ContactHistory {
            in_contact: false,
            max_gap: f64::INFINITY,
            compressing: false,
            impact_rate: 0.0,
        }
    }
}

/// How a contact history moved at one evaluation.
#[derive(Clone, Copy, Debug)]
pub(super) struct Onset {
    pub(super) onset: bool,
    pub(super) impact: bool,
    pub(super) fraction: f64,
    pub(super) approach_speed: f64,
}

impl ContactHistory {
    /// The motion mode the history is in (paper Fig. 1b).
    pub(super) fn mode(&self) -> ContactMode {
        match (self.in_contact, self.compressing) {
            (false, _) => ContactMode::FreeFlight,
            (true, true) => ContactMode::Impact,
            (true, false) => ContactMode::Continuous,
        }
    }

    /// Moves the history to `state`, with `before` the state at the previous evaluation (if any):
    /// records `delta_dot0` at an onset (MODEL.md §2), located at the crossing of delta = 0 inside
    /// the step that led here, and whether the contact is still compressing.
    pub(super) fn advance(
        &mut self,
        before: Option<&JournalState>,
        state: &JournalState,
        min_impact_speed: f64,
        min_separation: f64,
    ) -> Onset {
        self.advance_by(
            before,
            state,
            (min_impact_speed, min_separation),
            speed_at_crossing,
        )
    }

    /// [`advance`](Self::advance) at the end of a planar sub-cycle's sub-step: `before` the
    /// state the sub-step began from, its rates at the state, and `state` read at the velocity
    /// the sub-step drifted at ([`speed_at_crossing_in_substep`]).
    pub(super) fn advance_sub_step(
        &mut self,
        before: &JournalState,
        state: &JournalState,
        min_impact_speed: f64,
        min_separation: f64,
    ) -> Onset {
        let limits = (min_impact_speed, min_separation);
        self.advance_by(Some(before), state, limits, speed_at_crossing_in_substep)
    }

    /// [`advance`](Self::advance) with `crossing` reading the approach speed at the crossing
    /// from the two states' penetration rates and the fraction.
    fn advance_by(
        &mut self,
        before: Option<&JournalState>,
        state: &JournalState,
        (min_impact_speed, min_separation): (f64, f64),
        crossing: fn(f64, f64, f64) -> f64,
    ) -> Onset {
        let onset = state.penetration > 0.0 && !self.in_contact;
        let impact = onset && self.max_gap >= min_separation;
        let (fraction, approach_speed) = match (onset, before) {
            (true, Some(before)) if before.penetration <= 0.0 => {
                let s = crossing_fraction(-before.penetration, state.penetration);
                let rate = crossing(before.penetration_rate, state.penetration_rate, s);
                (s, rate)
            }
            (true, _) => (1.0, state.penetration_rate),
            (false, _) => (1.0, 0.0),
        };
        if state.penetration > 0.0 {
            if onset {
                *self = ContactHistory {
                    in_contact: true,
                    max_gap: 0.0,
                    compressing: true,
                    impact_rate: approach_speed.max(min_impact_speed),
                };
            } else if state.penetration_rate <= 0.0 {
                self.compressing = false;
            }
        } else {
            let gap = -state.penetration;
            let max_gap = if self.in_contact {
                gap
            } else {
                self.max_gap.max(gap)
            };
            *self = ContactHistory {
                max_gap,
                ..ContactHistory::default()
            };
        }
        Onset {
            onset,
            impact,
            fraction,
            approach_speed,
        }
    }
}
