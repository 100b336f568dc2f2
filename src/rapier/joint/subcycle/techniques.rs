//! The techniques of the sub-cycle, each one a switch ([`SubCycleTechniques`]): all on by
//! default; one off is the plainer method it replaces, kept for comparison
//! (`cargo bench --bench ablation`, docs/sub-cycled-contact.md).

use serde::{Deserialize, Serialize};

/// Which techniques a sub-cycled joint ([`ContactIntegration::SubCycled`](super::ContactIntegration::SubCycled))
/// uses. The default has every one on; turning one off gives the plainer method it stands for,
/// for comparison (what each buys: docs/sub-cycled-contact.md, "What each technique buys").
/// An explicit joint ignores them.
///
/// ```
/// use clearance_joint::prelude::*;
/// let plain = SubCycleTechniques::default().implicit_friction(false);
/// assert!(!plain.implicit_friction && plain.implicit_damping);
/// let design = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)?
///     .integration(ContactIntegration::SubCycled)
///     .sub_cycle_techniques(plain);
/// # let _ = design;
/// # Ok::<(), clearance_joint::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct SubCycleTechniques {
    /// Planar: friction taken at the velocity of the state, its slip solved implicitly (false
    /// position). Off: friction at the velocity before each kick (explicit), and each sub-step
    /// in contact held within friction's explicit stability limit near zero slip (as the
    /// explicit joint's step: `0.8 x 2/(w_t F_N dmu/dv)`).
    pub implicit_friction: bool,
    /// Planar: the law's damping taken at the rate of the state (implicit). Off: at the rate
    /// before each kick (explicit; the sub-step stays within `10 tolerance` of the damped
    /// stability limit either way).
    pub implicit_damping: bool,
    /// Planar: after a step longer than 20 sub-steps, the next sub-cycle goes on from where the
    /// last one left the pin (the difference held as a displacement and an impulse across it).
    /// Off: every sub-cycle starts from Rapier's state.
    pub continuation: bool,
    /// Planar: three rounds of the continuation's correction over the joints of one island
    /// (each joint's correction moves the others' pairs). Off: one round.
    pub continuity_rounds: bool,
    /// Planar: Rapier's joint stabilisation, as pass 0 shows it, spread over the sub-steps
    /// (the bodies end where Rapier puts them; the laws read the rate the positions move at).
    /// Off: the sub-cycle moves the pair at its velocities alone.
    pub stabilisation: bool,
    /// Spatial: a Jacobian serves up to 32 accepted sub-steps, retaken when the load moves by a
    /// tenth, a region starts or stops touching, or a sub-step is rejected. Off: retaken at
    /// every accepted sub-step.
    pub jacobian_reuse: bool,
    /// Spatial: the Rosenbrock step (ROS2) with the load's Jacobian (linearly implicit). Off: a
    /// zero Jacobian, ROS2 explicit: the sub-steps are then held by stability, up to the cap of
    /// 100,000 a world step.
    pub implicit_spatial: bool,
    /// Spatial: the spatial joints of one island (two pins sharing a body) integrated as one
    /// system, each contact's stiffness implicit on every pair it moves. Off: each spatial
    /// joint on its own, the others' contacts left to Rapier's pass 1 (two pins in series then
    /// overshoot on the body they share: the SCARA arm on two spatial pins diverges).
    pub spatial_coupling: bool,
}

impl Default for SubCycleTechniques {
    fn default() -> Self {
        SubCycleTechniques {
            implicit_friction: true,
            implicit_damping: true,
            continuation: true,
            continuity_rounds: true,
            stabilisation: true,
            jacobian_reuse: true,
            implicit_spatial: true,
            spatial_coupling: true,
        }
    }
}

impl SubCycleTechniques {
    /// Sets [`implicit_friction`](Self::implicit_friction).
    pub fn implicit_friction(mut self, on: bool) -> Self {
        self.implicit_friction = on;
        self
    }
    /// Sets [`implicit_damping`](Self::implicit_damping).
    pub fn implicit_damping(mut self, on: bool) -> Self {
        self.implicit_damping = on;
        self
    }
    /// Sets [`continuation`](Self::continuation).
    pub fn continuation(mut self, on: bool) -> Self {
        self.continuation = on;
        self
    }
    /// Sets [`continuity_rounds`](Self::continuity_rounds).
    pub fn continuity_rounds(mut self, on: bool) -> Self {
        self.continuity_rounds = on;
        self
    }
    /// Sets [`stabilisation`](Self::stabilisation).
    pub fn stabilisation(mut self, on: bool) -> Self {
        self.stabilisation = on;
        self
    }
    /// Sets [`jacobian_reuse`](Self::jacobian_reuse).
    pub fn jacobian_reuse(mut self, on: bool) -> Self {
        self.jacobian_reuse = on;
        self
    }
    /// Sets [`implicit_spatial`](Self::implicit_spatial).
    pub fn implicit_spatial(mut self, on: bool) -> Self {
        self.implicit_spatial = on;
        self
    }
    /// Sets [`spatial_coupling`](Self::spatial_coupling).
    pub fn spatial_coupling(mut self, on: bool) -> Self {
        self.spatial_coupling = on;
        self
    }
    /// Whether every technique is on (the default).
    pub fn all_on(&self) -> bool {
        *self == Self::default()
    }
    /// The switches by name (`implicit_friction`, ...), as the scenes' `run.sub_cycle` spells
    /// them, each with its setting.
    pub fn switches(&self) -> [(&'static str, bool); 8] {
        [
            ("implicit_friction", self.implicit_friction),
            ("implicit_damping", self.implicit_damping),
            ("continuation", self.continuation),
            ("continuity_rounds", self.continuity_rounds),
            ("stabilisation", self.stabilisation),
            ("jacobian_reuse", self.jacobian_reuse),
            ("implicit_spatial", self.implicit_spatial),
            ("spatial_coupling", self.spatial_coupling),
        ]
    }
}
