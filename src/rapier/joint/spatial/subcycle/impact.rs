//! The spatial sub-cycle's sub-steps in an impact: a fraction of the contact's period.
//!
//! ROS2 is L-stable: it damps an oscillation its sub-steps do not resolve, and its embedded
//! estimate (the linearly implicit Euler step, which damps it more) does not hold that damping
//! to the tolerance. With `N` sub-steps per period of an undamped contact its amplitude falls by
//! `1 - |R(2 pi i/N)| = 4.25 (2 pi/N)^4` a sub-step to leading order (`R` ROS2's stability
//! function), about `1650/N^3` by the peak a quarter period in: 2.2 % at 40 sub-steps a period,
//! 0.52 % at 67 (`2 tol` of the period at the default tolerance, the planar sub-cycle's bound),
//! 0.069 % at 133 (`tol`). A region's sub-steps are therefore bounded while it is in an impact, from its onset
//! for one period of its contact (an impact is over within one: Hertz's lasts 0.641 of it,
//! [`contact_period`]), not in a resting contact, whose sub-steps the implicit step lets grow to
//! the world step.

use super::integrator::{Eval, RegionClock, SpatialCycle};
use super::*;
use crate::model::laws::{NormalForceLaw, contact_period, crossing_fraction};
use crate::model::spatial::Share;

/// The fraction of a contact's period one sub-step may cover in an impact, per unit of
/// tolerance: `tol` (133 sub-steps a period at the default 0.0075, an undamped peak's amplitude
/// 0.069 % low by ROS2's damping; `1650 tol^3`, third order in the tolerance).
pub(crate) const IMPACT_PERIODS_PER_TOLERANCE: f64 = 1.0;

impl SpatialCycle<'_> {
    /// The period (s) of region `k`'s contact at position increments `x`, its points those of
    /// the last evaluation (`parts.points`): the law's share the region's points carry (their
    /// summed tangent stiffness over the law's at the deepest point's depth) and their elastic
    /// energy, the mass the pair moves along the deepest point's gradient through its mobility
    /// (`1/(r P r)`, `r` the point's contact row, as the planar joint's effective mass), and the
    /// rate along it.
    pub(super) fn region_period(&self, parts: &SpatialParts, x: &Pair12, k: usize) -> f64 {
        let region = parts.patches[k].region;
        let law = region.law(&self.joint.normal_law, &parts.face_law);
        let points = parts.points.iter().filter(|p| p.region == region);
        let (mut stiffness, mut elastic) = (0.0, 0.0);
        let mut deepest: Option<&crate::rapier::joint::spatial::report::SpatialPoint> = None;
        for p in points {
            let (w, d) = (p.contact.weight, p.contact.depth);
            if d > 0.0 {
                stiffness += w * law.tangent_stiffness(d);
                elastic += w * law.elastic_energy(d);
            }
            if deepest.is_none_or(|q| d > q.contact.depth) {
                deepest = Some(p);
            }
        }
        let Some(deepest) = deepest else {
            return f64::INFINITY;
        };
        let depth = deepest.contact.depth.max(0.0);
        let whole = law.tangent_stiffness(depth);
        let share = if stiffness > 0.0 && whole > 0.0 {
            stiffness / whole
        } else {
            1.0
        };
        let centres = [
            self.start.com[0] + part(x, 0),
            self.start.com[1] + part(x, 2),
        ];
        let row = load(&centres, deepest.contact.point, deepest.contact.gradient);
        let inverse = dot(&row, &mul(&self.start.mobility, &row));
        if !(inverse > 0.0) {
            return f64::INFINITY;
        }
        let shared = Share { law, share };
        let speed = deepest.penetration_rate;
        contact_period(&shared, 1.0 / inverse, speed, depth, elastic)
    }

    /// The longest sub-step the regions in an impact allow from the state at `x` (the last
    /// evaluation's): [`IMPACT_PERIODS_PER_TOLERANCE`] of the tolerance of each one's period.
    /// A region whose impact has lasted a period is in a resting contact from then on: its
    /// impact ends.
    pub(super) fn impact_bound(
        &self,
        parts: &SpatialParts,
        x: &Pair12,
        clocks: &mut [RegionClock; 4],
    ) -> f64 {
        let mut bound = f64::INFINITY;
        for (k, clock) in clocks.iter_mut().enumerate() {
            let Some(elapsed) = clock.impact else {
                continue;
            };
            let period = self.region_period(parts, x, k);
            if elapsed >= period {
                clock.impact = None;
                continue;
            }
            bound = bound.min(IMPACT_PERIODS_PER_TOLERANCE * self.tolerance * period);
        }
        bound
    }

    /// A sub-step of `step` from `here` to `at` (at position increments `x`, the last
    /// evaluation) in which a region's contact began is redone shorter when it is longer than
    /// the impact's own sub-steps at `at`: the load's kink at the touch is inside it, where
    /// ROS2 is first order and its Jacobian (taken out of contact) blind, and the error estimate
    /// does not hold it (an 80 us sub-step across the panel's touch left its peak 0.8 % low).
    /// The retry lands at the linear crossing (no shorter than the impact's sub-step), so the
    /// touch falls in a sub-step of the impact's size. `None`: keep the sub-step.
    pub(super) fn onset_retry(
        &self,
        parts: &SpatialParts,
        x: &Pair12,
        (here, at): (&Eval, &Eval),
        clocks: &[RegionClock; 4],
        step: f64,
    ) -> Option<f64> {
        let mut retry: Option<f64> = None;
        for (k, clock) in clocks.iter().enumerate() {
            let depth = at.states[k].penetration;
            if clock.history.in_contact || !(depth > 0.0) {
                continue;
            }
            let bound =
                IMPACT_PERIODS_PER_TOLERANCE * self.tolerance * self.region_period(parts, x, k);
            if step <= bound {
                continue;
            }
            let gap = (-here.states[k].penetration).max(0.0);
            let to_touch = crossing_fraction(gap, depth) * step;
            let shorter = to_touch.max(bound).min(0.9 * step);
            retry = Some(retry.map_or(shorter, |r: f64| r.min(shorter)));
        }
        retry
    }
}
