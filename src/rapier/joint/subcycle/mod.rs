//! Sub-cycled contact ([`ContactIntegration::SubCycled`]): inside one Rapier step the joint
//! integrates its two bodies' motion on its own clock, and Rapier's step carries the result.
//!
//! **Free motion from Rapier.** The step is first taken without the joint's force (Rapier's
//! pass 0). The velocities it ends with give every other force's acceleration of the pair over
//! the step (gravity, drives, the user's forces, the ideal joints' reactions, Rapier's own
//! integration), `a = (v_free - v_start)/kick`, held over the step.
//!
//! **The contact on its own clock.** From the pair's state at the step's start, the joint
//! integrates `dv/dt = a + P F(x, v)` over the step, `P` the pair's mobility through the
//! mechanism's ideal joints (the 12 x 12 [`Mechanism::pair_mobility`], at the step's start),
//! with sub-steps sized by the tolerance: `2 tol` of the contact's period and `10 tol` of its
//! damped stability limit in contact ([`ContactAhead::resolving_step`]), halving the time to
//! contact on approach and landing on the wall, and moving the journal by at most `tol` of the
//! clearance in free flight, `tol` taken at most 0.05 (`MAX_CONTACT_TOLERANCE`). A sub-step is a
//! velocity-Verlet step whose elastic force is taken at the sub-step's position and whose
//! dissipative forces (the law's damping, friction) at the velocity of the state, solved
//! implicitly (a trapezoidal rule in the velocity: stable at any sub-step, second order). The
//! friction law's steep slope near zero slip therefore sets no step.
//!
//! **Back to Rapier.** Rapier's step is then taken again (pass 1) with the constant wrench that
//! moves the bodies where the sub-steps did. A force held over a step through Rapier's `N`
//! substeps changes the pair's velocities by `kick P Q` and moves it by `c_N h kick P Q`,
//! `c_N = (N + 1)/(2 N)`; the sub-steps changed the velocities by `P Gamma` (`Gamma` the step's
//! contact impulse) and moved the pair by `P Pi` (`Pi` its time integral), beyond the impulse
//! `H` held from the step before. With one substep the move is met exactly, `Q kick = H + Pi/h`,
//! and the rest of the impulse, `H' = H + Gamma - Q kick`, is held to the next step. With more,
//! the move and the impulse are met over two steps ([`group`]'s `delivery_plan`): the step also
//! leaves a displacement `E'` held (the next sub-cycle starts from Rapier's poses moved by
//! `P E'`), so that the impulse held in Rapier's velocities between the steps keeps its sign
//! instead of turning over at every step, where a velocity-dependent force of the world (a
//! controller's damping) would read it and feed it back. Rapier's velocities are the mean over
//! the step (Verlet's half-step velocities): the next step's true starting velocity is Rapier's
//! plus `(c_N kick - h/2) a + P H'`. Steps without a contact and without a held impulse take
//! pass 0 only.
//!
//! **Each contact goes on from where its last sub-cycle left it.** The sub-cycle moves the pair
//! through its mobility at the step's start; Rapier's pass 1 moves the bodies on their ideal
//! joints, a bearing's body turning under the wrench (the SCARA arm's elbow rides on an upper
//! link that turns 0.05 rad in a 1/60 s step). The next step's start, read from Rapier's
//! poses and velocities, would find the wall moved by what pass 1 made of the wrench beyond
//! the mobility (up to a third of the clearance at 1/60 s). After a step much longer than its
//! contact (more than 20 sub-steps) the difference in the eccentricity and its rate is held to
//! the next step as a displacement and an impulse across the pin, at the centres, so that the
//! next sub-cycle starts where the last one ended and Rapier's pass 1 delivers the rest.
//!
//! The sub-steps' states are the joint's [`substeps`](super::ClearanceJoint::substeps): an
//! impact that begins, peaks and ends inside one world step is reported at its sub-steps
//! (onset, peak, depth, lift-off), and the world steps at the rate of the slow motion, crossing
//! a contact in a few steps ([`ClearanceJoint::world_contact_step`]).

mod group;
mod pair;
mod steps;
mod techniques;
#[cfg(test)]
mod tests;

pub(crate) use group::{attributed, beyond_verlet, cross_mobilities, islands, plan_cycles};
pub(crate) use pair::PairStart;
pub(crate) use pair::{Pair12, axpy, dot, load, mul, part, put, rotate};
pub(crate) use steps::SubCycle;
pub use techniques::SubCycleTechniques;

use super::effective_mass::Mechanism;
use super::step_policy::approach_step;
use super::{ClearanceJoint, ClearanceReport, ContactAhead};
use crate::model::kinematics::{ForcePair, JournalState, stable_step};
use crate::model::laws::{NormalContact, NormalForceLaw, loaded_impact_rate};
use crate::rapier::pipeline::ledger::{Wrench, world_center_of_mass};
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{RigidBodyHandle, RigidBodySet};
use serde::{Deserialize, Serialize};

/// How a compliant clearance joint integrates its contact and friction forces over a step
/// ([`HingeDesign::integration`](crate::rapier::hinge::design::HingeDesign::integration)).
///
/// The default is [`SubCycled`](Self::SubCycled): at the default tolerance it takes fewer world
/// steps and less time than [`Explicit`](Self::Explicit) wherever the world chooses its steps
/// (adaptive steps, Rapier's step of a game or a controller). `Explicit` stays for comparison,
/// and for a loop of your own that calls
/// [`ClearanceJointSet::apply`](crate::rapier::joint::ClearanceJointSet::apply): that loop gets
/// the explicit forces whatever the joint's integration (docs/sub-cycled-contact.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum ContactIntegration {
    /// The forces are evaluated once per Rapier step at its start and held over it: the step
    /// must resolve every contact (the step control shortens it to a fraction of the contact's
    /// period and of its stability limit, and of friction's near zero slip), and Rapier must
    /// take it in one substep (`num_solver_iterations = 1`).
    Explicit,
    /// The contact is integrated on the joint's own clock inside each Rapier step, its damping
    /// and friction implicitly; Rapier's step carries the result (two Rapier passes: the rest of
    /// the world's motion, then the contact's impulse; docs/sub-cycled-contact.md). The
    /// world's step is set by its slow motion: the joint adds no stability limit, and Rapier may
    /// take any number of solver iterations. Needs the
    /// [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld) (or a layer built on
    /// it: the scene runner, the bevy_ecs layer); a loop of your own that calls
    /// `ClearanceJointSet::apply` gets the explicit forces, with the explicit joint's checks.
    #[default]
    SubCycled,
}

/// One state inside the last Rapier step of a sub-cycled joint: where its contact was, at the
/// end of a sub-step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SubStep {
    /// Time since the step's start, s.
    pub t: f64,
    /// The journal's state, its rates at the state.
    pub state: JournalState,
    /// The contact force pair at the state.
    pub force: ForcePair,
    /// The moment of the contact's load on the journal about the world's origin at the state,
    /// N m (the bearing takes its negative): with `force.on_journal` the whole load, a spatial
    /// joint's stations' sum included, which `force.point` alone does not carry.
    pub moment: Vector,
    /// Whether a contact began at this state (an onset; see
    /// [`ClearanceReport::onset`](super::ClearanceReport::onset)).
    pub onset: bool,
    /// Whether the onset is an impact ([`ClearanceReport::impact`](super::ClearanceReport::impact)).
    pub impact: bool,
    /// At an onset, the penetration rate at the crossing of delta = 0, m/s; 0 otherwise.
    pub approach_speed: f64,
    /// At an onset, the fraction of the sub-step before this state at which delta crossed 0;
    /// 1 otherwise.
    pub onset_fraction: f64,
}

/// Sub-steps in one world step beyond which the joint stops resolving and finishes the step in
/// one sub-step (a guard: at the default tolerance an impact takes about 70).
pub(crate) const MAX_SUBSTEPS: u32 = 100_000;

/// Fraction of the predicted time to contact that one free sub-step may cover.
const APPROACH_FRACTION: f64 = 0.5;

/// The fraction of a contact's damped stability limit one sub-step may cover, per unit of
/// tolerance: `10 tol` (0.075 at the default 0.0075), at most 0.8 (the kick's elastic force is
/// explicit). A heavily damped contact relaxes at about `2/limit`, and a sub-step that covers
/// a fifth of what the explicit step may (`50 tol`) resolves that relaxation to the tolerance
/// (the improved law's single impact: its depth within 1e-3 of its ODE at the default,
/// `tests/references.rs`).
const STABLE_FRACTION_PER_TOLERANCE: f64 = 10.0;

/// Sub-steps of a contact one world step may cover in or on the way into contact
/// ([`ClearanceJoint::world_contact_step`]): 10, `20 tol` of the contact's period and `100 tol`
/// of its damped stability limit. A world step spanning whole impacts gives the bodies beyond
/// the pair only their mean (Rapier's one constant wrench); a pair that moves no other body
/// needs the bound too, measured (docs/sub-cycled-contact.md, "The world's step": the deployable
/// array's window statistics, the panel at 5T, the damped slider-crank).
const WORLD_SUBSTEPS_IN_CONTACT: f64 = 10.0;

impl ClearanceJoint {
    /// Switches how the contact is integrated ([`ContactIntegration`]), as
    /// [`HingeDesign::integration`](crate::rapier::hinge::design::HingeDesign::integration) sets
    /// it at build; from the next step on. Reach the joint through
    /// [`ClearanceJointSet::get_mut`](crate::rapier::joint::ClearanceJointSet::get_mut): the
    /// world then evaluates its joints again before that step, at the state as it stands, and
    /// the contact goes on in the new mode with its history (a closed contact stays one, with
    /// its impact rate). Switched to sub-cycled, the joint holds its explicit force's half kick
    /// for the first sub-cycle (Rapier's velocities after an explicit step lack it, as they
    /// lack a sub-cycled step's held impulse); switched to explicit, the impulse a sub-cycled
    /// joint held for the next step is dropped, which is right where Rapier's velocities lack
    /// just the half kick of its force, as under a steady load (a resting pin goes on to
    /// rounding both ways: `cargo test --release --test sub_cycling switched`); inside an
    /// impact the rest of the held impulse is lost. A spatial joint switched to sub-cycled
    /// starts from Rapier's velocities (no half kick held). Explicit needs Rapier's
    /// `num_solver_iterations = 1` and steps the contact allows: the next step says so
    /// otherwise, as at build.
    pub fn set_integration(&mut self, integration: ContactIntegration) -> &mut Self {
        self.integration = integration;
        self
    }

    /// At the first evaluation of a joint switched to sub-cycled after an explicit step
    /// (`last_step` s long): the impulse it holds for the next step is the half kick of its
    /// force at the state, `F h/2`. Rapier's velocities after the explicit step are the mean
    /// over it and lack that half kick to the state (the Verlet reading), as after a
    /// sub-cycled step they lack the impulse held: so the sub-cycle starts from the state's
    /// velocity. Without it a resting pin switched over falls at `g h/2` into its wall. A
    /// switch the other way needs nothing: the explicit joint reads Rapier's velocities the
    /// same way, its half kick included in the step's force.
    pub(crate) fn hold_explicit_half_kick(&mut self, last_step: f64) {
        let explicit_now = !self.sub_cycled();
        let was_explicit = std::mem::replace(&mut self.cycle.explicit_before, explicit_now);
        if !(was_explicit && self.sub_cycled() && self.spatial.is_none()) {
            return;
        }
        if let Some([w1, w2]) = self.last_wrenches {
            let half = 0.5 * last_step;
            for (k, v) in [w1.force, w1.torque, w2.force, w2.torque]
                .into_iter()
                .enumerate()
            {
                put(&mut self.cycle.held, k, v * half);
            }
        }
    }

    /// The world step a sub-cycled joint allows near contact, from its state at the last step's
    /// end: in contact, [`WORLD_SUBSTEPS_IN_CONTACT`] of the sub-steps the contact needs there
    /// (`ContactAhead::resolving_step` at `10 tol` of the tolerance); approaching the wall at
    /// the penetration rate, at most half the time to it and no less than that step at its
    /// arrival speed; otherwise no bound (s).
    pub(crate) fn world_contact_step(&self, tolerance: f64, last_dt: f64) -> f64 {
        let st = &self.report.state;
        let (depth, rate) = (st.penetration, st.penetration_rate);
        let step = |speed: f64, depth: f64| {
            let contact = ContactAhead {
                mass: self.report.effective_mass,
                approach_speed: speed,
                depth,
                impact_rate: self.contact.in_contact.then_some(self.contact.impact_rate),
                min_impact_speed: self.min_impact_speed,
            };
            let elastic = self.normal_law.elastic_energy(depth.max(0.0));
            let (k, tolerance) = (
                WORLD_SUBSTEPS_IN_CONTACT,
                super::step_policy::contact_tolerance(tolerance),
            );
            let stable = k * STABLE_FRACTION_PER_TOLERANCE * tolerance;
            contact.resolving_step(&self.normal_law, elastic, k * tolerance, stable)
        };
        if depth > 0.0 {
            return step(rate.abs(), depth);
        }
        // The gap's acceleration too, not its rate only: a journal pressed on its wall by a
        // load that lifts off in a bounce is on its way back, and a step from the lift-off that
        // the rate alone leaves unbounded spans the flight, the landing and much of the next
        // contact (the paper's panel at 5T: its bounces on the wall lost their speed faster
        // than the converged runs' and ended 60 ms early, docs/sub-cycled-contact.md).
        approach_step(-depth, rate, self.gap_acceleration(last_dt), |speed| {
            step(speed, 0.0)
        })
    }

    /// A planar sub-cycled joint in contact: the world step its contact asks for
    /// ([`world_contact_step`](Self::world_contact_step)), s, for the adaptive step control's
    /// check against its floor. `None` out of contact, for an explicit joint (its steps are
    /// rejected down to its contact's limit) and for a spatial one (its world step follows the
    /// regions' paths, not the contact: its sub-steps alone resolve it, under error control).
    pub(crate) fn contact_world_step(&self, tolerance: f64, last_dt: f64) -> Option<f64> {
        let planar = self.sub_cycled() && self.spatial.is_none();
        (planar && self.report.state.penetration > 0.0)
            .then(|| self.world_contact_step(tolerance, last_dt))
    }

    /// The gap's closing acceleration at the last step's end, m/s^2: over its last sub-step
    /// when that was in free flight, else over the last step when it was in free flight
    /// throughout (0 when neither is known).
    fn gap_acceleration(&self, last_dt: f64) -> f64 {
        match self.cycle.substeps.as_slice() {
            [.., a, b] if b.t > a.t && a.state.penetration <= 0.0 => {
                (b.state.penetration_rate - a.state.penetration_rate) / (b.t - a.t)
            }
            _ => self.rate_change(last_dt),
        }
    }

    /// The mobility from `other`'s contact loads to this joint's pair, when the two are
    /// sub-cycled in one island (taken with the start, [`ClearanceJoint::take_coupling`]).
    pub(crate) fn coupling_to(&self, other: &ClearanceJoint) -> Option<[f64; 144]> {
        let pair = [other.body1, other.body2];
        self.cycle
            .coupled
            .iter()
            .find(|(p, _)| *p == pair)
            .map(|(_, m)| *m)
    }

    /// Takes the mobilities from the contact loads of the other sub-cycled joints' pairs
    /// (`partners`: their bearing and journal bodies) to this pair through `mechanism`, rebuilt
    /// for this joint at the state: the pairs whose contacts move this one within a step.
    pub(crate) fn take_coupling(
        &mut self,
        mechanism: &Mechanism,
        partners: impl Iterator<Item = [RigidBodyHandle; 2]>,
    ) {
        self.cycle.coupled.clear();
        if self.cycle.start.is_none() && self.cycle.spatial_start.is_none() {
            return;
        }
        for pair in partners {
            if self.cycle.coupled.iter().any(|(p, _)| *p == pair) {
                continue;
            }
            if let Some(p) = mechanism.cross_mobility(pair) {
                self.cycle.coupled.push((pair, p));
            }
        }
    }

    /// At the evaluation after a sub-cycled step: the report from the sub-cycle's end, the
    /// states inside the step, the impulse left held. `None` when no step was planned (the
    /// joint is then evaluated as an explicit one) or a body is gone.
    pub(crate) fn finish_cycle(&mut self, bodies: &RigidBodySet) -> Option<(Wrench, Wrench)> {
        let Some(held) = self.cycle.pending.take() else {
            self.cycle.end_velocity = None;
            return None;
        };
        let end = *self.cycle.run.samples.last()?;
        let (rb1, rb2) = (bodies.get(self.body1)?, bodies.get(self.body2)?);
        let history = self.cycle.run.history;
        let start = self.report.state;
        let mass = self.cycle.run.end_mass;
        let law = &self.normal_law;
        let delta = end.state.penetration;
        let impact_rate = if history.in_contact && law.uses_impact_rate() {
            history
                .impact_rate
                .max(loaded_impact_rate(law.elastic_energy(delta), mass))
        } else {
            history.impact_rate
        };
        let (omega, zeta) = if delta > 0.0 {
            let c = NormalContact {
                penetration: delta,
                penetration_rate: end.state.penetration_rate,
                impact_rate,
            };
            let k = law.tangent_stiffness(delta);
            let (_, omega, zeta) = stable_step(k, law.damping_coefficient(&c), mass);
            (omega, zeta)
        } else {
            (0.0, 0.0)
        };
        self.contact = history;
        self.report = ClearanceReport {
            state: end.state,
            mode: history.mode(),
            onset: end.onset,
            impact: end.impact,
            impact_rate,
            approach_speed: end.approach_speed,
            contact_rate: end.state.penetration_rate,
            onset_fraction: end.onset_fraction,
            force: end.force,
            max_stable_dt: f64::INFINITY,
            friction_stable_dt: f64::INFINITY,
            omega,
            zeta,
            effective_mass: mass,
            spatial: None,
        };
        self.elastic = std::sync::OnceLock::new();
        // A step in free flight throughout leaves the rate it began with, for the gap's
        // acceleration over it ([`Self::gap_acceleration`]).
        let flight = start.penetration <= 0.0
            && self
                .cycle
                .run
                .samples
                .iter()
                .all(|s| s.state.penetration <= 0.0);
        self.previous_rate = flight.then_some(start.penetration_rate);
        self.moved_rate = None;
        self.cycle.adopt_run(held);
        let f = end.force.on_journal;
        let p = end.force.point;
        let (c1, c2) = (world_center_of_mass(rb1), world_center_of_mass(rb2));
        Some((
            Wrench {
                body: self.body1,
                force: -f,
                torque: (p - c1).cross(-f),
            },
            Wrench {
                body: self.body2,
                force: f,
                torque: (p - c2).cross(f),
            },
        ))
    }

    /// The wrenches that deliver the impulse `deliver` (`Q kick`) over a step whose kick is
    /// `kick` (s): a force and torque on each body, held over the step.
    pub(crate) fn delivery(&self, deliver: &Pair12, kick: f64) -> [Wrench; 2] {
        [(self.body1, 0), (self.body2, 2)].map(|(body, k)| Wrench {
            body,
            force: part(deliver, k) / kick,
            torque: part(deliver, k + 1) / kick,
        })
    }

    /// Takes the pair's state before the next step (at each evaluation; `None` for a joint that
    /// is not sub-cycled or whose body is gone).
    pub(crate) fn take_start(&mut self, bodies: &RigidBodySet, mechanism: &Mechanism) {
        // A spatial joint takes its own start (`take_spatial_start`).
        self.cycle.start = if self.sub_cycled() && self.spatial.is_none() {
            PairStart::of(self, bodies, mechanism)
        } else {
            None
        };
    }

    /// The velocity (linear, angular) of the bearing's body and of the journal's at the state
    /// the last step began from, beyond the Verlet reading of Rapier's velocities around that
    /// state (`(h v_before + h_prev v_after)/(h_prev + h)`, `v_before` the velocity stored
    /// before the step, `v_after` after it, `h_prev` and `h` the steps before and after the
    /// state): the part of a sub-cycled contact's impulse inside the steps that Rapier's mean
    /// velocities spread over them. Zero for an explicit joint and for steps without contact.
    /// Add it to read the bodies' momentum or energy at that state; with several sub-cycled
    /// joints, add every joint's correction of a body: each impulse's share of a body two
    /// joints share is in one joint's correction only (a body beyond the joints' pairs that an
    /// impulse moves through Rapier's joints is in none).
    pub fn start_velocity_correction(&self) -> [(RigidBodyHandle, Vector, Vector); 2] {
        let c = &self.cycle.start_correction;
        [(self.body1, 0), (self.body2, 2)].map(|(b, k)| (b, part(c, k), part(c, k + 1)))
    }

    /// The velocity (linear, angular) of the bearing's body and of the journal's at the state
    /// the last step ended at, as the joint's sub-cycle ended it (`None` for an explicit joint,
    /// and when no sub-cycle ran): the pair's velocity at the step's start carried over the step
    /// by the rest of the world's acceleration and, through the pair's mobility, the step's
    /// contact impulse (`u0 + a h + P Gamma`), at the end of a planar joint's sub-steps or of a
    /// spatial joint's integration of its impulse alike. Rapier's velocities after a sub-cycled
    /// step are the mean over the step and do not yet hold the part of the step's contact
    /// impulse delivered with the next step (of an impact inside the step, up to most of it):
    /// read the bodies' velocity at the state here, for their momentum and energy at it or a
    /// force of yours that acts on it
    /// ([`ClearanceWorld::velocity_at_state`](crate::rapier::pipeline::world::ClearanceWorld::velocity_at_state)
    /// for any body). It is the state's whole velocity: Rapier's lag behind the state, which
    /// the reaction solve carries its velocities over, is in it already. Each impulse of the
    /// joints sub-cycled together is in every pair it moves.
    pub fn state_velocity(&self) -> Option<[(RigidBodyHandle, Vector, Vector); 2]> {
        let v = self.cycle.end_velocity?;
        Some([(self.body1, 0), (self.body2, 2)].map(|(b, k)| (b, part(&v, k), part(&v, k + 1))))
    }

    /// The contact's impulse on the journal over the last step, N s, summed over a sub-cycled
    /// joint's sub-steps (`None` for an explicit joint, and before the first sub-cycled step):
    /// with [`substeps`](Self::substeps), what the step's contacts did when the step is longer
    /// than they are.
    pub fn step_impulse(&self) -> Option<Vector> {
        (self.sub_cycled() && !self.cycle.substeps.is_empty()).then(|| part(&self.cycle.impulse, 2))
    }

    /// The energy the contact's damping and friction took over the last step, J, integrated over
    /// a sub-cycled joint's sub-steps (`None` for an explicit joint, and before the first
    /// sub-cycled step).
    pub fn step_dissipation(&self) -> Option<f64> {
        (self.sub_cycled() && !self.cycle.substeps.is_empty()).then_some(self.cycle.dissipated)
    }

    /// Sub-steps the last step took, when it reached [`MAX_SUBSTEPS`] (its rest then went in
    /// one sub-step).
    pub(crate) fn substeps_beyond_cap(&self) -> Option<u32> {
        (self.cycle.substep_count > MAX_SUBSTEPS).then_some(self.cycle.substep_count)
    }

    /// When the last step reached [`MAX_SUBSTEPS`], what that did and what to do, for a
    /// divergence's message: the rest of the step went in one sub-step, far beyond what the
    /// contact allows, and such a sub-step is what throws a body out.
    pub(crate) fn cap_in_words(&self) -> Option<String> {
        let n = self.substeps_beyond_cap()?;
        let off: Vec<String> = self
            .techniques
            .switches()
            .iter()
            .filter(|(_, on)| !on)
            .map(|(name, _)| format!("`{name}`"))
            .collect();
        let techniques = if off.is_empty() {
            String::new()
        } else {
            format!(
                ", or turn the sub-cycle's {} back on (off here, the sub-steps are held to \
                 stability)",
                off.join(", ")
            )
        };
        Some(format!(
            "clearance joint `{}` hit its sub-cycle's cap of {} sub-steps in the step ({n} \
             sub-steps) and took the rest of the step in one sub-step, which its contact cannot \
             take: take shorter world steps (a smaller fixed step or `max_dt`), a larger \
             tolerance (the sub-steps scale with it up to 0.05){techniques}",
            self.name, MAX_SUBSTEPS
        ))
    }

    /// The deepest penetration of the last step, m: over its sub-steps for a sub-cycled joint,
    /// at its end for an explicit one.
    pub(crate) fn deepest_in_step(&self) -> f64 {
        self.cycle
            .substeps
            .iter()
            .map(|s| s.state.penetration)
            .fold(self.report.state.penetration, f64::max)
    }
}
