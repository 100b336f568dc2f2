//! The step protocol's vocabulary, shared by the stepper and every participant of a step (this
//! crate's joint sets and sources, and a user's own): the [`Wrench`] a force source adds to a
//! body, the [`Violation`]s and [`GuardReport`] of the run-time guards, the [`StalledContact`]
//! a stall is diagnosed from, and the [`ElementId`] that names an element of a set in them. It
//! imports nothing of the joint models, the sources or the observers, so each of them can use it.

mod guards;

pub use guards::{GuardKind, GuardReport, Violation};

use crate::model::laws::LawKind;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::RigidBodyHandle;

/// Force and torque (about the centre of mass) a source adds to one body for a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wrench {
    /// The body.
    pub body: RigidBodyHandle,
    /// Force, N.
    pub force: Vector,
    /// Torque about the body's centre of mass, N m.
    pub torque: Vector,
}

/// An element of a set named by its slot and generation, whatever its type: how a
/// [`Violation`] or a [`StalledContact`] names the joint or element it concerns. Every typed
/// [`ElementHandle`](crate::rapier::pipeline::element_set::ElementHandle) converts into one
/// ([`ElementHandle::id`](crate::rapier::pipeline::element_set::ElementHandle::id)); a user's
/// own source that keeps its elements elsewhere builds one with
/// [`from_raw_parts`](Self::from_raw_parts). Its `Display` is `slot`v`generation`, as bevy's
/// `Entity`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ElementId {
    slot: u32,
    generation: u32,
}

impl ElementId {
    /// The id of slot `slot` at generation `generation`.
    pub fn from_raw_parts(slot: u32, generation: u32) -> Self {
        ElementId { slot, generation }
    }

    /// The slot and the generation.
    pub fn into_raw_parts(self) -> (u32, u32) {
        (self.slot, self.generation)
    }
}

/// `slot`v`generation`, as bevy's `Entity`.
impl std::fmt::Display for ElementId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}v{}", self.slot, self.generation)
    }
}

/// One body's share of the inverse effective mass along the contact normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyShare {
    /// The body.
    pub handle: RigidBodyHandle,
    /// Its mass, kg.
    pub mass: f64,
    /// Its smallest principal moment of inertia, kg m^2.
    pub inertia: f64,
    /// `(r x n) . I^-1 (r x n)`, 1/kg: the rotational part of its inverse mass at the contact.
    pub rotational_inverse_mass: f64,
}

/// The contact the step control could not resolve, as this crate's joint sets report it
/// ([`StepHooks::stalled_contact`](crate::rapier::pipeline::step_hooks::StepHooks::stalled_contact))
/// for a stall's diagnosis: the joint, and its contact state in words through its `Display`
/// (the numbers the diagnosis reads are the crate's).
#[derive(Clone, Debug, PartialEq)]
pub struct StalledContact {
    /// The name of the joint (or element) in contact.
    pub joint: String,
    /// Its handle in its set, if it has one.
    pub handle: Option<ElementId>,
    /// The normal law.
    pub(crate) law: LawKind,
    /// Penetration, m (negative: a gap).
    pub(crate) penetration: f64,
    /// Penetration rate, m/s.
    pub(crate) rate: f64,
    /// The approach speed the hysteresis laws divide by, `delta_dot0`, m/s (0 in free flight).
    pub(crate) impact_rate: f64,
    /// The joint's floor on it, m/s.
    pub(crate) min_impact_speed: f64,
    /// Linearised damping ratio.
    pub(crate) zeta: f64,
    /// Linearised natural frequency, rad/s: from `dF/d delta`, the spring's tangent stiffness
    /// plus the slope of a hysteresis law's damping times the rate.
    pub(crate) omega: f64,
    /// The spring's own tangent stiffness at the penetration, N/m (the law without its
    /// damping): against `omega^2 m` it tells a stiff spring from a steep damping.
    pub(crate) elastic_stiffness: f64,
    /// Whether the contact is a shoulder on a bearing face (the spatial joint's face law), not
    /// the journal on the bore.
    pub(crate) face: bool,
    /// Damped stability limit of the step, s.
    pub(crate) stable_dt: f64,
    /// Friction's step limit, s.
    pub(crate) friction_dt: f64,
    /// Normal force, N.
    pub(crate) normal_force: f64,
    /// Effective mass along the normal, kg.
    pub(crate) effective_mass: f64,
    /// Each movable body's share (fixed and kinematic bodies have none).
    pub(crate) bodies: Vec<BodyShare>,
    /// The law's validity limit, m.
    pub(crate) max_valid_penetration: f64,
    /// The deepest penetration the contact can reach from its state (elastic energy plus the
    /// kinetic energy of the approach), m.
    pub(crate) reachable_penetration: f64,
    /// The stable step of the contact at the validity limit, s (what a contact that stays valid
    /// needs).
    pub(crate) stable_dt_at_valid: f64,
}

/// The contact state in words: the joint, its penetration, rate, `delta_dot0`, damping ratio,
/// stable steps and effective mass.
impl std::fmt::Display for StalledContact {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let place = if self.face {
            ", a shoulder on a bearing face"
        } else {
            ""
        };
        let handle = self
            .handle
            .map_or(String::new(), |h| format!(" (handle {h})"));
        write!(
            f,
            "joint `{}`{handle}{place}: penetration {} um, rate {} m/s, delta_dot0 {} m/s, damping ratio \
             {}, stable step {} s (friction's {} s), effective mass {} kg",
            self.joint,
            crate::error::sig4(self.penetration * 1e6),
            crate::error::sig4(self.rate),
            crate::error::sig4(self.impact_rate),
            crate::error::sig4(self.zeta),
            crate::error::sig4(self.stable_dt),
            crate::error::sig4(self.friction_dt),
            crate::error::sig4(self.effective_mass)
        )
    }
}
