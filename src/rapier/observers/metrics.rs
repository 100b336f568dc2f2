//! Joint metrics a loop of your own can record: the contact list of a clearance joint (onset,
//! approach speed, peak force, deepest penetration, duration of every contact), the fraction of
//! time in contact, peak, RMS and first-impact figures.
//!
//! # Onsets, impacts and chatter
//!
//! Every layer (the joints' reports, these metrics, the scene runner, the bevy_ecs layer's
//! [`HingeState`](crate::ecs::HingeState), the app's summaries and studies) counts contacts
//! with these words:
//!
//! - **Onset**: the penetration crosses 0 into contact: the first state in contact after a
//!   state out of it ([`ClearanceReport::onset`](crate::rapier::joint::ClearanceReport::onset)).
//!   Every contact begins with one.
//! - **Impact**: an onset after a free flight that opened a gap of at least the joint's
//!   `min_separation` ([`HingeDesign::min_separation`](crate::rapier::hinge::design::HingeDesign::min_separation),
//!   0.1 um by default); the
//!   first contact of a joint is always one
//!   ([`ClearanceReport::impact`](crate::rapier::joint::ClearanceReport::impact)).
//! - **Chatter**: the onsets that are not impacts: a journal following the wall that lifts off
//!   by less than `min_separation` and touches again. Chatter = onsets - impacts.
//! - **Bounce**: an onset of the [large-step model](crate::rapier::large_step) whose approach
//!   speed exceeds the joint's `min_impact_speed`, which Newton's impact law gives a rebound
//!   ([`LargeStepJoint::bounces`](crate::rapier::large_step::LargeStepJoint::bounces)). That
//!   model resolves the journal's position to a few percent of the clearance, too coarse for a
//!   separation of `min_separation`: its bounces are its impacts (in these metrics, the scene
//!   runner's and the bevy_ecs layer's), and its chatter the onsets that approach slower.
//!
//! [`HingeMetrics::onsets`] and [`HingeMetrics::impacts`] count the first two over a run; the
//! contact list ([`ImpactRecorder::contacts`]) holds every onset, [`Impact::separated`] marking
//! the impacts.
//!
//! The scene runner records its hinges with the same [`ImpactRecorder`], so a plain-Rapier loop
//! that records the same states gets the same numbers. A state is recorded with the step that
//! follows it: read the joint (a [`ContactObservation`]) before a step, record it with that
//! step's start and length and the joint's sub-steps once the step is taken
//! ([`ImpactRecorder::record_step`]; a sub-cycled joint, the default, resolves its contacts
//! there), and finish with the final state.
//!
//! ```
//! use clearance_joint::rapier::observers::metrics::{ContactObservation, ImpactRecorder};
//! use clearance_joint::prelude::*;
//! use rapier3d_f64::prelude::*;
//!
//! let mut rapier = PhysicsWorld::new(); // gravity along -y
//! rapier.integration_parameters.num_solver_iterations = 1;
//! let mut world = ClearanceWorld::new(rapier, StepControl::fixed(2e-5));
//! let base = world.rapier.bodies.insert(RigidBodyBuilder::fixed());
//! let arm = world.rapier.bodies.insert(
//!     RigidBodyBuilder::dynamic()
//!         .translation(Vector::new(0.0, -0.3, 0.0))
//!         .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02)))
//!         .can_sleep(false),
//! );
//! let revolute = RevoluteJointBuilder::new(Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0));
//! let pivot = world.rapier.impulse_joints.insert(base, arm, revolute, true);
//! let clear = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)?;
//! let pivot = world.clearance.convert_revolute(
//!     pivot,
//!     BearingSide::Body1,
//!     clear,
//!     &mut world.rapier.impulse_joints,
//! )?;
//!
//! world.prepare()?;
//! let mut recorder = ImpactRecorder::new();
//! while world.time() < 0.1 {
//!     let before = ContactObservation::of(world.clearance.get(pivot).unwrap());
//!     let info = world.step(0.1)?;
//!     // With the step's sub-steps, where a sub-cycled joint (the default) resolved its contacts.
//!     let substeps = world.clearance.get(pivot).unwrap().substeps();
//!     recorder.record_step(info.t0, info.dt, &before, substeps);
//! }
//! recorder.finish(world.time(), &ContactObservation::of(world.clearance.get(pivot).unwrap()));
//! // The journal drops through the 0.2 mm gap and bounces on the bearing's floor.
//! let first = &recorder.contacts()[0];
//! assert!(first.approach_speed_m_s > 0.01 && first.peak_force_n > 100.0);
//! assert_eq!(recorder.metrics().onsets as usize, recorder.contacts().len());
//! assert!(recorder.metrics().impacts <= recorder.metrics().onsets);
//! # Ok::<(), clearance_joint::Error>(())
//! ```

use crate::model::laws::crossing_fraction;
use crate::rapier::joint::ClearanceJoint;
use crate::table::Table;
use serde::Serialize;

mod periods;
pub(crate) use periods::{MAX_PERIODS, per_period, per_period_table};

/// Impacts slower than this (m/s) are not judged by their apparent restitution: at a grazing
/// approach the separation speed is set by the other forces, not by the contact.
const RESTITUTION_MIN_SPEED: f64 = 1e-3;

/// What a clearance joint's force hook saw at one state: the joint force and the contact.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactObservation {
    /// Joint force magnitude, N (the contact and friction force on the journal; for an ideal
    /// joint, its reaction).
    pub force: f64,
    /// Whether a contact began at this state: an [onset](crate::rapier::observers::metrics#onsets-impacts-and-chatter),
    /// chatter included.
    pub onset: bool,
    /// Whether this onset is an [impact](crate::rapier::observers::metrics#onsets-impacts-and-chatter), after a separation
    /// of at least the joint's `min_separation`
    /// ([`ClearanceReport::impact`](crate::rapier::joint::ClearanceReport::impact)).
    pub impact: bool,
    /// Penetration, m (negative: the gap).
    pub penetration: f64,
    /// Penetration rate, m/s (positive approaching).
    pub rate: f64,
    /// At an onset, the approach speed at the crossing of delta = 0, m/s
    /// ([`ClearanceReport::approach_speed`](crate::rapier::joint::ClearanceReport::approach_speed)).
    pub approach_speed: f64,
    /// At an onset, the fraction of the step before this state at which delta crossed 0
    /// ([`ClearanceReport::onset_fraction`](crate::rapier::joint::ClearanceReport::onset_fraction));
    /// 1 (or the default 0, read as 1) otherwise.
    pub onset_fraction: f64,
}

impl ContactObservation {
    /// The joint's state at its last force evaluation (the stepper evaluates the joints at
    /// every accepted state).
    pub fn of(joint: &ClearanceJoint) -> Self {
        let r = joint.report();
        ContactObservation {
            force: r.force.on_journal.length(),
            onset: r.onset,
            impact: r.impact,
            penetration: r.state.penetration,
            rate: r.state.penetration_rate,
            approach_speed: r.approach_speed,
            onset_fraction: r.onset_fraction,
        }
    }

    /// A sub-cycled joint's state inside a step
    /// ([`ClearanceJoint::substeps`](crate::rapier::joint::ClearanceJoint::substeps)).
    pub(crate) fn of_substep(s: &crate::rapier::joint::SubStep) -> Self {
        ContactObservation {
            force: s.force.on_journal.length(),
            onset: s.onset,
            impact: s.impact,
            penetration: s.state.penetration,
            rate: s.state.penetration_rate,
            approach_speed: s.approach_speed,
            onset_fraction: s.onset_fraction,
        }
    }

    /// An ideal joint's state: its reaction force, never in contact.
    pub fn ideal(force: f64) -> Self {
        ContactObservation {
            force,
            penetration: f64::NEG_INFINITY,
            ..Default::default()
        }
    }

    /// Whether the surfaces are in contact (penetration above 0).
    pub(crate) fn in_contact(&self) -> bool {
        self.penetration > 0.0
    }
}

/// One contact of a clearance joint, from its onset to the first state out of contact: an
/// impact or chatter ([`separated`](Self::separated); see the [definitions](crate::rapier::observers::metrics#onsets-impacts-and-chatter)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Impact {
    /// Time of the crossing of delta = 0, s: interpolated inside the step that led to the first
    /// state in contact ([`crossing_fraction`]).
    pub onset_t_s: f64,
    /// Penetration rate at the crossing, m/s (positive approaching;
    /// [`speed_at_crossing`](crate::model::laws::speed_at_crossing)).
    pub approach_speed_m_s: f64,
    /// Largest joint force during the contact, N.
    pub peak_force_n: f64,
    /// Time of the recorded state where the contact's force is largest, s: with
    /// [`peak_force_n`](Self::peak_force_n), the point a plot of thinned rows must still pass
    /// through.
    pub peak_t_s: f64,
    /// Deepest penetration during the contact, um.
    pub max_penetration_um: f64,
    /// Time in contact, s, from the onset to the crossing of delta = 0 at lift-off, interpolated
    /// inside the step that led to the first state out of contact as the onset is (up to the end
    /// of the run for a contact still closed there).
    pub duration_s: f64,
    /// Whether the onset is an [impact](crate::rapier::observers::metrics#onsets-impacts-and-chatter): it came after a free
    /// flight that opened at least the joint's `min_separation` (otherwise it is chatter).
    pub separated: bool,
}

/// Per-joint metrics over every recorded state.
#[derive(Clone, Debug, Default, Serialize)]
pub struct HingeMetrics {
    /// Largest joint force, N.
    pub peak_force_n: f64,
    /// [Onsets](crate::rapier::observers::metrics#onsets-impacts-and-chatter): every contact that began, chatter included.
    /// JSON key `onsets`.
    pub onsets: u64,
    /// [Impacts](crate::rapier::observers::metrics#onsets-impacts-and-chatter): onsets after a free flight that opened at
    /// least the joint's `min_separation` (the first contact always counts); `onsets - impacts`
    /// is the chatter. JSON key `separated_impacts`.
    #[serde(rename = "separated_impacts")]
    pub impacts: u64,
    /// Time of the first contact onset, s.
    pub first_impact_t_s: Option<f64>,
    /// Largest force during the first contact, N.
    pub first_impact_peak_n: Option<f64>,
    /// Largest penetration, um.
    pub max_penetration_um: f64,
    /// Steps spent in contact.
    pub contact_steps: u64,
    /// Fraction of recorded time in contact, each contact from its onset to its lift-off as in
    /// [`Impact::duration_s`].
    pub contact_fraction: f64,
    /// Root-mean-square joint force over the run (time-weighted), N.
    pub rms_force_n: f64,
    /// Largest apparent restitution of an impact, the separation speed over the approach speed
    /// (from the first state out of and into contact), over impacts that approached faster than
    /// 1 mm/s (a grazing approach's separation speed is set by the other forces, not by the
    /// contact); above 1 a contact gave back more than it took (0 without such an impact).
    pub max_restitution: f64,
    /// Final relative angle, deg (set by the scene runner; 0 from a bare recorder).
    pub final_angle_deg: f64,
    /// A spatial joint's tilt, axial travel and forces by contact kind
    /// ([`ImpactRecorder::record_spatial`]); absent for a planar joint.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spatial: Option<SpatialMetrics>,
}

/// What a spatial clearance joint did over the recorded states
/// ([`SpatialReport`](crate::rapier::joint::SpatialReport)): how far its journal tilted and
/// slid, and the largest force of each kind of contact. Lower and upper are the bearing's ends
/// at `-L/2` and `+L/2` along the hinge's axis (its edges, its faces).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SpatialMetrics {
    /// Largest tilt of the journal's axis against the bore's (the length of the two tilt
    /// components), deg.
    pub max_tilt_deg: f64,
    /// Largest axial offset of the journal from the bearing's centre (either way), mm.
    pub max_axial_offset_mm: f64,
    /// Largest normal force of the whole bore, N.
    pub peak_bore_force_n: f64,
    /// Largest resultant of the bore's regions at its lower and upper ends, N.
    pub peak_edge_force_n: [f64; 2],
    /// Largest force of the shoulders on the lower and upper faces, N.
    pub peak_face_force_n: [f64; 2],
    /// Contact onsets on the lower and upper faces (axial knocks, chatter included).
    pub face_contacts: [u64; 2],
    /// Fraction of the recorded time a face carried load.
    pub face_contact_fraction: f64,
    /// Fraction of the recorded time the bore was loaded over part of its width only: the
    /// journal bears on the bearing's edges (tilted, or loaded by a moment).
    pub edge_loaded_fraction: f64,
}

/// Records a joint's states, one per step, into [`HingeMetrics`] and an impact list. The
/// scene runner's hinges are recorded by it; see the module docs for a loop of your own.
#[derive(Clone, Debug, Default)]
pub struct ImpactRecorder {
    metrics: HingeMetrics,
    impacts: Vec<Impact>,
    force_sq_time: f64,
    contact_time: f64,
    onset_rate: f64,
    in_first_contact: bool,
    /// Whether the last impact of the list is still open.
    open: bool,
    /// The step that led to the state being recorded (the last recorded `dt`), s.
    last_dt: f64,
    /// The penetration at the last recorded state, m (positive: it was in contact).
    last_penetration: f64,
    finished: bool,
    /// A spatial joint: whether each face carried load at the last state, and the time a face
    /// carried load and an edge was loaded, s.
    face_was_loaded: [bool; 2],
    face_time: f64,
    edge_time: f64,
    /// Sub-steps recorded by [`record_step`](Self::record_step).
    substeps: u64,
}

impl ImpactRecorder {
    /// An empty recorder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Records the state at time `t` (s), which held for the step `dt` (s) that followed it:
    /// the state before the step, with the step's start and length.
    pub fn record(&mut self, t: f64, dt: f64, obs: &ContactObservation) {
        let m = &mut self.metrics;
        m.peak_force_n = m.peak_force_n.max(obs.force);
        self.force_sq_time += obs.force * obs.force * dt;
        let in_contact = obs.in_contact();
        // The last state was in contact and this one is not.
        let lift_off = self.last_penetration > 0.0 && !in_contact;
        if obs.impact {
            m.impacts += 1;
        }
        // The crossing of delta = 0 inside the step that led here.
        let (onset_t, approach) = if obs.onset && obs.onset_fraction > 0.0 {
            (
                t - (1.0 - obs.onset_fraction.min(1.0)) * self.last_dt,
                obs.approach_speed,
            )
        } else {
            (t, obs.rate)
        };
        // A lift-off: the last state's step was counted in contact whole; the contact ended at
        // the crossing of delta = 0 inside it, interpolated as the onset is.
        if lift_off {
            let after =
                (1.0 - crossing_fraction(self.last_penetration, -obs.penetration)) * self.last_dt;
            self.contact_time -= after;
            if self.open
                && let Some(i) = self.impacts.last_mut()
            {
                i.duration_s -= after;
            }
        }
        self.last_dt = dt;
        self.last_penetration = obs.penetration;
        if obs.onset {
            self.onset_rate = approach;
        }
        if lift_off && self.onset_rate > RESTITUTION_MIN_SPEED {
            m.max_restitution = m.max_restitution.max(-obs.rate / self.onset_rate);
        }
        if self.open && (!in_contact || obs.onset) {
            self.open = false;
        }
        if obs.onset {
            // In contact from the crossing on.
            self.contact_time += t - onset_t;
            m.onsets += 1;
            if m.first_impact_t_s.is_none() {
                m.first_impact_t_s = Some(onset_t);
                m.first_impact_peak_n = Some(0.0);
                self.in_first_contact = true;
            }
            self.impacts.push(Impact {
                onset_t_s: onset_t,
                approach_speed_m_s: approach,
                separated: obs.impact,
                // From the crossing: the part of the step before this state spent in contact.
                duration_s: t - onset_t,
                peak_t_s: t,
                ..Impact::default()
            });
            self.open = true;
        }
        if self.in_first_contact {
            if in_contact {
                m.first_impact_peak_n = Some(m.first_impact_peak_n.unwrap_or(0.0).max(obs.force));
            } else {
                self.in_first_contact = false;
            }
        }
        if in_contact {
            if dt > 0.0 {
                m.contact_steps += 1;
                self.contact_time += dt;
            }
            m.max_penetration_um = m.max_penetration_um.max(obs.penetration * 1e6);
        }
        if self.open
            && let Some(i) = self.impacts.last_mut()
        {
            if obs.force > i.peak_force_n {
                i.peak_force_n = obs.force;
                i.peak_t_s = t;
            }
            i.max_penetration_um = i.max_penetration_um.max(obs.penetration * 1e6);
            i.duration_s += dt;
        }
    }

    /// Records one step of a joint taken from `t0` for `dt` (s): `before` the joint's state at
    /// the step's start ([`ContactObservation::of`] read before the step), `substeps` its states
    /// inside the step ([`ClearanceJoint::substeps`](crate::rapier::joint::ClearanceJoint::substeps)
    /// read after it; the last is the step's end, recorded with the next step). Without
    /// sub-steps (an explicit joint) it is [`record`](Self::record)`(t0, dt, before)`.
    pub fn record_step(
        &mut self,
        t0: f64,
        dt: f64,
        before: &ContactObservation,
        substeps: &[crate::rapier::joint::SubStep],
    ) {
        self.substeps += substeps.len() as u64;
        let Some((_, inside)) = substeps.split_last() else {
            self.record(t0, dt, before);
            return;
        };
        let mut obs = *before;
        let mut t = 0.0;
        for s in inside {
            self.record(t0 + t, s.t - t, &obs);
            obs = ContactObservation::of_substep(s);
            t = s.t;
        }
        self.record(t0 + t, dt - t, &obs);
    }

    /// The sub-steps of the sub-cycled steps recorded so far by
    /// [`record_step`](Self::record_step) (0 for an explicit joint): what a sub-cycled joint's
    /// contacts cost beyond the world's steps.
    pub fn substeps_recorded(&self) -> u64 {
        self.substeps
    }

    /// Records a spatial joint's report at a state ([`ClearanceReport::spatial`]), which held
    /// for the step `dt` (s) that followed it, into [`HingeMetrics::spatial`]: call it beside
    /// [`record`](Self::record) with the same state (and with `dt = 0` for the final one).
    /// Time fractions are completed by [`finish`](Self::finish).
    ///
    /// [`ClearanceReport::spatial`]: crate::rapier::joint::ClearanceReport::spatial
    pub fn record_spatial(&mut self, dt: f64, report: &crate::rapier::joint::SpatialReport) {
        let first = self.metrics.spatial.is_none();
        let m = self.metrics.spatial.get_or_insert_with(Default::default);
        let tilt = report.tilt[0].hypot(report.tilt[1]).to_degrees();
        m.max_tilt_deg = m.max_tilt_deg.max(tilt);
        m.max_axial_offset_mm = m.max_axial_offset_mm.max(report.axial_offset.abs() * 1e3);
        m.peak_bore_force_n = m.peak_bore_force_n.max(report.bore_force);
        for k in 0..2 {
            m.peak_edge_force_n[k] = m.peak_edge_force_n[k].max(report.edge_force[k]);
            m.peak_face_force_n[k] = m.peak_face_force_n[k].max(report.face_force[k]);
            let on = report.face_force[k] > 0.0;
            if on && (first || !self.face_was_loaded[k]) {
                m.face_contacts[k] += 1;
            }
            self.face_was_loaded[k] = on;
        }
        if report.face_force.iter().any(|&f| f > 0.0) {
            self.face_time += dt;
        }
        if report.bore_force > 0.0 && report.bore_contact_width < 1.0 {
            self.edge_time += dt;
        }
    }

    /// Records the final state at time `t` (it carries no time) and completes the time-weighted
    /// figures over the recorded time `t` (from 0). Recording after it is not meaningful.
    pub fn finish(&mut self, t: f64, last: &ContactObservation) {
        if self.finished {
            return;
        }
        self.record(t, 0.0, last);
        self.finished = true;
        if t > 0.0 {
            self.metrics.rms_force_n = (self.force_sq_time / t).sqrt();
            self.metrics.contact_fraction = self.contact_time / t;
            if let Some(m) = &mut self.metrics.spatial {
                m.face_contact_fraction = self.face_time / t;
                m.edge_loaded_fraction = self.edge_time / t;
            }
        }
    }

    /// The figures so far (RMS force and contact fraction once [`finish`](Self::finish)ed).
    pub fn metrics(&self) -> &HingeMetrics {
        &self.metrics
    }

    /// Sets the final relative angle reported with the metrics, deg.
    pub fn set_final_angle_deg(&mut self, angle: f64) {
        self.metrics.final_angle_deg = angle;
    }

    /// Every contact so far, in order of onset: one per onset, chatter included
    /// ([`Impact::separated`] marks the impacts).
    pub fn contacts(&self) -> &[Impact] {
        &self.impacts
    }

    /// Time in contact so far, s.
    pub fn contact_time(&self) -> f64 {
        self.contact_time
    }

    /// The contact list as a table: `onset_t_s, approach_speed_mm_s, peak_force_n, peak_t_s,
    /// max_penetration_um, duration_s, separated` (1 for an impact, 0 for chatter).
    pub(crate) fn contacts_table(&self) -> Table {
        let mut t = Table::new(
            [
                "onset_t_s",
                "approach_speed_mm_s",
                "peak_force_n",
                "peak_t_s",
                "max_penetration_um",
                "duration_s",
                "separated",
            ]
            .map(String::from)
            .to_vec(),
        );
        for i in &self.impacts {
            t.values.extend_from_slice(&[
                i.onset_t_s,
                i.approach_speed_m_s * 1e3,
                i.peak_force_n,
                i.peak_t_s,
                i.max_penetration_um,
                i.duration_s,
                if i.separated { 1.0 } else { 0.0 },
            ]);
        }
        t
    }
}

#[cfg(test)]
mod tests;
