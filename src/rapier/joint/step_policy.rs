//! The step-size policy of a clearance joint: the journal-path step in free flight, the step that
//! resolves a contact, and the judgement of a step taken.

use super::*;

/// The journal-path step of a journal whose centre moves at `speed` (m/s) relative to the
/// bearing's, in a clearance `clearance` (m): the step that moves it `tolerance` times the
/// clearance, `tol c/|de/dt|`, s (infinite at rest), in free flight and in contact (along the
/// wall the contact's normal then turns by at most about `tolerance` rad a step). Without it a
/// free flight took the step of the bodies' turn: on Flores and Ambrósio's slider-crank a journal
/// crossed its 0.5 mm gap in a few steps of 14 us, and the impacts after the first left the
/// converged sequence within two (measured, `cargo bench --bench mechanisms`); the four-bar's
/// first impact was 60 % high. Without it in contact the slider-crank at c = 0.1 mm rode its
/// wall through the load reversals where converged runs lift off: 0 to 0.5 lift-offs per turn
/// in turns 2-3 against 5 to 6.5 (fixed 1e-6 to 2.5e-7 s), and at tolerances 0.00375, 0.002 and
/// 0.001 1.5-4.5, 3.5-5 and 5-9: a bias of the step, not chaos. With it 4 per turn for 4.6 %
/// more steps; the paper's scene at T, 3T and 5T, the four-bar, the deployable array and the
/// double pendulum take the same steps as without.
pub fn flight_step(tolerance: f64, clearance: f64, speed: f64) -> f64 {
    if speed > 0.0 {
        tolerance * clearance / speed
    } else {
        f64::INFINITY
    }
}

/// The time (s) until a gap of `gap` (m) closes at the rate `rate` (m/s, positive closing) and
/// the acceleration `accel` (m/s^2): the smallest positive `t` with
/// `gap = rate t + accel t^2/2`; infinite when it never closes.
fn time_to_contact(gap: f64, rate: f64, accel: f64) -> f64 {
    if accel.abs() < 1e-300 {
        if rate > 0.0 {
            gap / rate
        } else {
            f64::INFINITY
        }
    } else {
        let disc = rate * rate + 2.0 * accel * gap;
        if disc < 0.0 {
            f64::INFINITY
        } else {
            (-rate + disc.sqrt()) / accel
        }
    }
}

/// Fraction of the predicted time to contact that one free-flight step may cover, so that a
/// contact is approached in shrinking steps and starts near a step boundary.
const APPROACH_FRACTION: f64 = 0.5;

/// The step (s) a journal `gap` (m) off its wall, closing at `rate` (m/s) and `accel` (m/s^2),
/// may take: [`APPROACH_FRACTION`] of the time to contact, and no less than `resolving` gives
/// at the arrival speed; infinite when the gap does not close.
pub(super) fn approach_step(
    gap: f64,
    rate: f64,
    accel: f64,
    resolving: impl Fn(f64) -> f64,
) -> f64 {
    let t = time_to_contact(gap, rate, accel);
    if !(t > 0.0 && t.is_finite()) {
        return f64::INFINITY;
    }
    let arrival = (rate + accel * t).max(0.0);
    (APPROACH_FRACTION * t).max(resolving(arrival))
}
/// The fraction of a contact's natural period one adaptive step in contact may cover, per unit
/// of tolerance: `2 tol` (0.015 of the period at the default 0.0075). The contact laws get the
/// rate at the state (MODEL.md §6), so a contact is integrated at second order like the free
/// motion; the factor balances the two error sources. The first-impact errors and steps it gives
/// are the mechanism matrix's (docs/stepper-and-accuracy.md, `cargo bench --bench mechanisms`).
pub const CONTACT_PERIODS_PER_TOLERANCE: f64 = 2.0;
/// Margin on the damped stability limit used by the adaptive step (and by a sub-cycle's
/// sub-steps with friction explicit).
pub(super) const STABILITY_SAFETY: f64 = 0.8;
/// The fraction of the damped stability limit one adaptive step in contact may cover, per unit
/// of tolerance: `50 tol` (0.375 at the default 0.0075; at most 0.8, the margin kept on that
/// limit). A heavily damped contact (damping ratio above about 4) relaxes at `2/limit`, and a step
/// near the limit is stable, not accurate: scaled with the tolerance, tightening converges it.
/// Measured on `assets/slider_crank.ron`'s first impact in `tests/stepper.rs`; the mechanism
/// matrix (docs/stepper-and-accuracy.md, `cargo bench --bench mechanisms`) shows the rest.
const STABLE_FRACTION_PER_TOLERANCE: f64 = 50.0;

/// The loosest tolerance a contact is resolved to, however loose the step control's, explicit
/// or sub-cycled: a step (or sub-step) in contact covers at most a tenth of its period (five or
/// more an impact), a free one moves the journal by at most 0.05 of the clearance. The elastic
/// kick is explicit, and an impact of two or three kicks hands back more energy than it took:
/// a rattle of small clearance runs away (docs/sub-cycled-contact.md, "Cost against accuracy").
pub(crate) const MAX_CONTACT_TOLERANCE: f64 = 0.05;

/// The tolerance a contact is resolved to when the step control asks for `tolerance`: at most
/// [`MAX_CONTACT_TOLERANCE`].
pub(crate) fn contact_tolerance(tolerance: f64) -> f64 {
    tolerance.min(MAX_CONTACT_TOLERANCE)
}

/// The fraction of a contact's damped stability limit an adaptive step may take at `tolerance`
/// ([`STABLE_FRACTION_PER_TOLERANCE`], [`STABILITY_SAFETY`]).
fn stable_fraction(tolerance: f64) -> f64 {
    (STABLE_FRACTION_PER_TOLERANCE * tolerance).min(STABILITY_SAFETY)
}

/// A contact as the step control sees it ahead: the effective mass along its normal (kg), the
/// approach speed (m/s) and depth (m) it starts from, the current contact's `delta_dot0` (m/s;
/// `None` before it begins) and the joint's floor on it.
#[derive(Clone, Copy, Debug)]
pub(super) struct ContactAhead {
    pub(super) mass: f64,
    pub(super) approach_speed: f64,
    pub(super) depth: f64,
    pub(super) impact_rate: Option<f64>,
    pub(super) min_impact_speed: f64,
}

impl ContactAhead {
    /// The step that resolves this contact of `law` (elastic energy `elastic` J at its depth) to
    /// `2 tolerance` of its natural period ([`CONTACT_PERIODS_PER_TOLERANCE`]), taken at the
    /// deepest point its energy reaches, and to `stable` (a fraction, e.g. [`stable_fraction`])
    /// of its damped stability limit there.
    pub(super) fn resolving_step(
        &self,
        law: &impl NormalForceLaw,
        elastic: f64,
        tolerance: f64,
        stable_share: f64,
    ) -> f64 {
        let m = self.mass;
        let v = self.approach_speed;
        let energy = 0.5 * m * v * v + elastic;
        let peak = penetration_for_energy(law, energy, 1e-6).max(self.depth);
        let stiffness = law.tangent_stiffness(peak);
        if !(stiffness > 0.0) {
            return f64::INFINITY;
        }
        let mut impact_rate = self
            .impact_rate
            .unwrap_or_else(|| v.max(self.min_impact_speed));
        if law.uses_impact_rate() {
            impact_rate = impact_rate.max(loaded_impact_rate(energy, m));
        }
        let c = NormalContact {
            penetration: peak,
            penetration_rate: v,
            impact_rate,
        };
        let (stable, omega, _) = stable_step(stiffness, law.damping_coefficient(&c), m);
        let period = std::f64::consts::TAU / omega;
        (CONTACT_PERIODS_PER_TOLERANCE * tolerance * period).min(stable_share * stable)
    }
}

impl ClearanceJoint {
    /// The largest step that resolves this joint's contact dynamics to `tolerance`, from the state
    /// of the last application. `last_dt` is the step taken before it (to estimate the gap's
    /// acceleration).
    ///
    /// - In contact: twice `tolerance` of the contact's
    ///   natural period `2 pi/omega`, with `omega` at the deepest point the contact's energy
    ///   reaches (its elastic energy plus the kinetic energy of its normal motion, in or out), and
    ///   within the damped stability limit there. The step follows the contact's energy, not the
    ///   phase of its oscillation.
    /// - In free flight: the journal's centre moves at most `tolerance` times the clearance
    ///   relative to the bearing's in one step (its path across the gap decides
    ///   where and how fast the next impact comes), and the contact ahead is predicted from the
    ///   gap, closing speed and acceleration; a step covers at most half the time to it, and no
    ///   less than the step that contact will need.
    /// - A sub-cycled joint ([`ContactIntegration::SubCycled`]) resolves its contacts in its
    ///   sub-steps: the journal's path bounds the step, and in contact or approaching the wall
    ///   the step covers at most 10 of the sub-steps the contact needs (`20 tolerance` of its
    ///   period) and half the time to the wall.
    pub fn adaptive_step(&self, tolerance: f64, last_dt: f64) -> f64 {
        let tolerance = contact_tolerance(tolerance);
        let r = &self.report;
        let m = r.effective_mass;
        if !(m > 0.0 && m.is_finite()) {
            return f64::INFINITY;
        }
        if self.sub_cycled() {
            // The sub-steps resolve the contact; the world steps through it in a few steps (a
            // spatial joint's: every region's path across its gap bounds the step).
            if let Some(parts) = &self.spatial {
                return parts.flight_step(tolerance);
            }
            return flight_step(
                tolerance,
                self.geometry.clearance(),
                r.state.eccentricity_rate.length(),
            )
            .min(self.world_contact_step(tolerance, last_dt));
        }
        let delta = r.state.penetration;
        let rate = r.state.penetration_rate;
        let contact_step =
            |approach_speed: f64, depth: f64| self.contact_step(approach_speed, depth, tolerance);
        let flight = match &self.spatial {
            Some(parts) => parts.flight_step(tolerance),
            None => flight_step(
                tolerance,
                self.geometry.clearance(),
                r.state.eccentricity_rate.length(),
            ),
        };
        if delta > 0.0 {
            // |rate|, not the approach only: a step that grows as the journal moves out of the
            // wall and shrinks as it moves in pumps energy into a long contact's oscillation
            // (variable-step Verlet is not symplectic). On the paper's scene at 3T the journal
            // then lifted off where converged runs stay on the wall: 148 onsets per second
            // against 120 (docs/stepper-and-accuracy.md, "steps in a long contact").
            // The journal's path bound holds in contact too ([`flight_step`]): a contact whose
            // load turns, and a light one about to lift off, have a long period, and the
            // journal's path along the wall decides where it leaves it.
            return contact_step(rate.abs(), delta)
                .min(flight)
                .min(stable_fraction(tolerance) * r.max_stable_dt)
                .min(STABILITY_SAFETY * r.friction_stable_dt);
        }
        approach_step(-delta, rate, self.rate_change(last_dt), |speed| {
            contact_step(speed, 0.0)
        })
        .min(flight)
    }

    /// The penetration rate's change over the last step, m/s^2 (0 without a rate before it).
    pub(super) fn rate_change(&self, last_dt: f64) -> f64 {
        match self.previous_rate {
            Some(prev) if last_dt > 0.0 => (self.report.state.penetration_rate - prev) / last_dt,
            _ => 0.0,
        }
    }

    /// The step that resolves a contact now `depth` deep (m) whose journal moves at
    /// `approach_speed` (m/s) along the normal to `2 tolerance` of its natural period, taken at
    /// the deepest point the contact can reach (its elastic energy plus that kinetic energy), and
    /// within the damped stability limit there. A
    /// spatial joint's contact carries the governing law's
    /// [`contact_share`](spatial::SpatialParts::contact_share): a tilted journal pressed at its
    /// edge is as stiff as the few stations that touch, not the whole width.
    pub(super) fn contact_step(&self, approach_speed: f64, depth: f64, tolerance: f64) -> f64 {
        let law = self.governing_law();
        let share = self.spatial.as_ref().map_or(1.0, |p| p.contact_share());
        if share != 1.0 {
            let law = crate::model::spatial::Share { law, share };
            let elastic = law.elastic_energy(depth);
            return self.contact_step_of(&law, elastic, approach_speed, depth, tolerance);
        }
        // The planar joint's elastic energy at its own depth is known from its application.
        let elastic = if self.spatial.is_none() && depth == self.report.state.penetration {
            self.elastic_energy()
        } else {
            law.elastic_energy(depth)
        };
        self.contact_step_of(law, elastic, approach_speed, depth, tolerance)
    }

    /// [`contact_step`](Self::contact_step) for `law`, whose elastic energy at `depth` is
    /// `elastic` (J).
    pub(super) fn contact_step_of(
        &self,
        law: &impl NormalForceLaw,
        elastic: f64,
        approach_speed: f64,
        depth: f64,
        tolerance: f64,
    ) -> f64 {
        let contact = ContactAhead {
            mass: self.report.effective_mass,
            approach_speed,
            depth,
            impact_rate: self.contact.in_contact.then_some(self.contact.impact_rate),
            min_impact_speed: self.min_impact_speed,
        };
        contact.resolving_step(law, elastic, tolerance, stable_fraction(tolerance))
    }

    /// Judges a step of `dt` that ended in the state of the last application, for a joint that
    /// was (`was_in_contact`) or was not in contact when the step began. `None` when the step
    /// resolved the contact; otherwise the shorter step to retry with:
    /// - the step went beyond the stability limit of the contact it ended in;
    /// - a contact began inside the step and got deeper than a step of the contact's own size
    ///   (`2 tolerance` of its period) would have let it: the step crossed the onset blind;
    /// - the step was longer than friction's limit ([`ClearanceReport::friction_stable_dt`]).
    pub fn judge_step(&self, dt: f64, tolerance: f64, was_in_contact: bool) -> Option<f64> {
        let tolerance = contact_tolerance(tolerance);
        let r = &self.report;
        let delta = r.state.penetration;
        if !(delta > 0.0) || self.sub_cycled() {
            return None;
        }
        let limit = r.max_stable_dt.min(r.friction_stable_dt);
        if dt > limit {
            return Some((STABILITY_SAFETY * limit).min(0.5 * dt));
        }
        if was_in_contact {
            return None;
        }
        let rate = r.state.penetration_rate.max(0.0);
        let h_c = self.contact_step(rate, delta, tolerance);
        if dt <= h_c || delta <= rate * h_c {
            return None;
        }
        // Retry with a step that ends shortly before the onset (then the approach shrinks the
        // steps to the contact's own), or with the contact's own step.
        let inside = if rate > 0.0 { delta / rate } else { dt };
        let before = (dt - inside).max(0.0);
        Some(h_c.max(0.9 * before).min(0.5 * dt))
    }
}
