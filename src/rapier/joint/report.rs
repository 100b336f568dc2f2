//! What the hook computed for one joint at its last application.

use super::*;

/// What the hook computed for one joint at its last application.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClearanceReport {
    /// Journal state (eccentricity, penetration, rates).
    pub state: JournalState,
    /// Motion mode.
    pub mode: ContactMode,
    /// Whether a contact began at this application: an
    /// [onset](crate::rapier::observers::metrics#onsets-impacts-and-chatter), chatter included.
    pub onset: bool,
    /// Whether this onset is an [impact](crate::rapier::observers::metrics#onsets-impacts-and-chatter): the
    /// first contact, or one after a free flight that opened a gap of at least the joint's
    /// `min_separation`. Re-contacts after smaller separations are chatter of a journal
    /// following the wall, not impacts.
    pub impact: bool,
    /// `delta_dot0` the normal law used at this application (0 in free flight), m/s: the
    /// approach speed at the crossing of delta = 0, floored by the joint's `min_impact_speed`
    /// and, for a contact loaded deeper than its approach explains, raised to the speed of a
    /// free impact reaching the same depth ([`loaded_impact_rate`]).
    pub impact_rate: f64,
    /// At an onset, the penetration rate interpolated at the crossing of delta = 0 inside the
    /// step that led here ([`speed_at_crossing`]), m/s; 0 otherwise.
    pub approach_speed: f64,
    /// The penetration rate the normal law was given, m/s. `state.penetration_rate` is read from
    /// the bodies' velocities, the mean over the step that led here, half a step behind the
    /// state; in contact the joint carries it to the state ([`StepBefore::carry`], with the step of
    /// [`ClearanceJointSet::set_last_step`]) so that the damping force is second order in the
    /// step. Equal to `state.penetration_rate` in free flight and when the step is unknown (at
    /// the first application). A spatial joint's is its deepest station's.
    pub contact_rate: f64,
    /// At an onset, the fraction of the step that led here at which delta crossed 0
    /// ([`crossing_fraction`]; the onset time is the step's end minus `(1 - fraction)` steps);
    /// 1 otherwise.
    pub onset_fraction: f64,
    /// The force pair applied.
    pub force: ForcePair,
    /// Largest stable step for the contact as linearised now (infinite in free flight), s:
    /// stiffness and damping along the normal. Beyond it the explicit step blows up.
    pub max_stable_dt: f64,
    /// Largest step that resolves friction as linearised now, `2 m_t/(F_N dmu/dv)` (infinite
    /// without contact), s: a friction law whose coefficient rises steeply with slip, like Bai's
    /// near zero slip, acts as a stiff tangential damper. Friction is bounded by `mu_s F_N`, so a
    /// longer step does not blow up; it turns stiction into a numerical chatter of the slip.
    pub friction_stable_dt: f64,
    /// Linearised natural frequency of the contact, rad/s.
    pub omega: f64,
    /// Linearised damping ratio of the contact.
    pub zeta: f64,
    /// Effective mass of the two bodies along the contact normal, kg.
    pub effective_mass: f64,
    /// A spatial joint's tilt, axial offset and forces by contact kind (`None` for the planar
    /// joint). Its `state` above is then the deepest station's (bore or face), `force` the sum
    /// over all stations (`normal_force` the magnitude of the summed normal forces, the resultant
    /// load on the bearing: edges loaded on opposite sides by a moment cancel in it).
    pub spatial: Option<SpatialReport>,
}
