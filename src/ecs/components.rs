//! The components a user spawns ([`Body`], [`Hinge`] with [`IdealHinge`] or [`ClearanceHinge`],
//! [`Drive`]) and those the systems write back ([`BodyState`], [`HingeState`]).

use crate::error::{Error, Result, unit_vector};
use crate::model::angle::HingeAngle;
use crate::model::kinematics::ContactMode;
use crate::rapier::hinge::design::HingeDesign;
use bevy_ecs::prelude::*;
use rapier3d_f64::math::{Rotation, Vector};
use rapier3d_f64::prelude::{RevoluteJoint, RigidBody, RigidBodyHandle};

/// A rigid body. Spawn it with a Rapier description ([`Body::new`]); the sync system inserts it
/// into [`Physics::world`](super::Physics::world) and records its handle. Removing the component
/// (or despawning the entity) removes the body, with the hinges and drives attached to it.
#[derive(Component, Debug)]
#[require(BodyState)]
pub struct Body {
    /// The description still to insert (taken by [`sync_bodies`](super::sync_bodies)).
    pub(super) pending: Option<Box<RigidBody>>,
    pub(super) handle: Option<RigidBodyHandle>,
}

impl Body {
    /// A body to insert, e.g. from `RigidBodyBuilder::dynamic()...`. Use `can_sleep(false)` for
    /// slow mechanisms: Rapier's sleep thresholds freeze them (the paper's panel fell asleep at 0.5 s).
    pub fn new(body: impl Into<RigidBody>) -> Self {
        Body {
            pending: Some(Box::new(body.into())),
            handle: None,
        }
    }

    /// A body already in [`Physics::world`](super::Physics::world).
    pub fn from_handle(handle: RigidBodyHandle) -> Self {
        Body {
            pending: None,
            handle: Some(handle),
        }
    }

    /// The Rapier handle, once inserted.
    pub fn handle(&self) -> Option<RigidBodyHandle> {
        self.handle
    }
}

/// Where a body is and how it moves, after the last step.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct BodyState {
    /// Position of the body frame's origin, m.
    pub translation: Vector,
    /// Orientation.
    pub rotation: Rotation,
    /// Linear velocity of the centre of mass, m/s.
    pub linvel: Vector,
    /// Angular velocity, rad/s.
    pub angvel: Vector,
}

/// A hinge between two [`Body`] entities: `body1` carries the bearing, `body2` the journal.
/// Anchors and axes are in each body's frame (as Rapier's `RevoluteJointBuilder`). What it is
/// made of is a second component: [`IdealHinge`] or [`ClearanceHinge`].
#[derive(Component, Clone, Debug, PartialEq)]
#[require(HingeState)]
pub struct Hinge {
    /// The bearing's body entity.
    pub body1: Entity,
    /// The journal's body entity.
    pub body2: Entity,
    /// Bearing centre in body 1's frame, m.
    pub local_anchor1: Vector,
    /// Journal centre in body 2's frame, m.
    pub local_anchor2: Vector,
    /// Hinge axis in body 1's frame.
    pub local_axis1: Vector,
    /// Hinge axis in body 2's frame.
    pub local_axis2: Vector,
}

impl Hinge {
    /// A hinge about `axis` (both bodies' frames), anchors at both bodies' origins.
    pub fn new(body1: Entity, body2: Entity, axis: Vector) -> Self {
        Hinge {
            body1,
            body2,
            local_anchor1: Vector::ZERO,
            local_anchor2: Vector::ZERO,
            local_axis1: axis,
            local_axis2: axis,
        }
    }
    /// Sets the bearing centre in body 1's frame.
    pub fn local_anchor1(mut self, anchor: Vector) -> Self {
        self.local_anchor1 = anchor;
        self
    }
    /// Sets the journal centre in body 2's frame.
    pub fn local_anchor2(mut self, anchor: Vector) -> Self {
        self.local_anchor2 = anchor;
        self
    }
    /// Sets the axis in body 2's frame.
    pub fn local_axis2(mut self, axis: Vector) -> Self {
        self.local_axis2 = axis;
        self
    }
    /// Checks that the anchors are finite and the axes finite and non-zero.
    pub fn validate(&self) -> Result<()> {
        unit_vector("local_axis1", self.local_axis1)?;
        unit_vector("local_axis2", self.local_axis2)?;
        for (field, v) in [
            ("local_anchor1", self.local_anchor1),
            ("local_anchor2", self.local_anchor2),
        ] {
            if !v.is_finite() {
                return Err(Error::invalid(field, format!("must be finite (got {v:?})")));
            }
        }
        Ok(())
    }

    /// The ideal Rapier revolute joint of this hinge (axes normalised, contacts between the
    /// bodies disabled).
    pub fn revolute(&self) -> RevoluteJoint {
        crate::rapier::hinge::convert::revolute_joint([
            self.local_anchor1,
            self.local_anchor2,
            self.local_axis1.normalize_or_zero(),
            self.local_axis2.normalize_or_zero(),
        ])
    }

    /// The unit axis in body 1's frame (a realised hinge was validated; `x` stands in otherwise).
    pub(super) fn unit_axis1(&self) -> Vector {
        unit_vector("axis", self.local_axis1).unwrap_or(Vector::X)
    }
}

/// Makes a [`Hinge`] an ideal Rapier revolute joint.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct IdealHinge;

/// Makes a [`Hinge`] a clearance joint with these laws (takes precedence over [`IdealHinge`]).
/// [`HingeDesign::model`] chooses the model: the compliant contact law (the default, its contact
/// sub-cycled inside each step with any number of solver iterations; with
/// `ContactIntegration::Explicit` it needs small steps and a world with
/// `num_solver_iterations = 1`, which you set: a world with more is refused, see the
/// [module docs](super)) or the large-step constraint,
/// `ClearanceHinge(HingeDesign::steel_improved_liu(..)?.model(ClearanceModel::LargeStep))`, for 1/60 s or 1 kHz
/// worlds with any number of solver iterations. The spatial model,
/// `.model(ClearanceModel::Spatial(SpatialModel::steel(axial_play, collar_radius)))`, frees the
/// journal's tilt and axial slide (no lock joint; [`HingeState::spatial`] reports them); it steps
/// as the compliant model does.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct ClearanceHinge(pub HingeDesign);

/// A torsion spring `T = T0 - k theta` on the [`Hinge`] of the same entity: `+T` on body 2 and
/// `-T` on body 1 about the hinge axis; `theta` is zero where the drive starts.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct Drive {
    /// Preload `T0`, N m.
    pub torque0: f64,
    /// Stiffness `k`, N m/rad.
    pub stiffness: f64,
}

impl Drive {
    /// Preload `torque0` (N m) and stiffness (N m/rad).
    pub fn torsion_spring(torque0: f64, stiffness: f64) -> Self {
        Drive { torque0, stiffness }
    }
    /// Preload `torque0` (N m) and stiffness in N m/deg (the paper's unit).
    pub fn per_degree(torque0: f64, stiffness_nm_per_deg: f64) -> Self {
        Drive {
            torque0,
            stiffness: stiffness_nm_per_deg.to_degrees(),
        }
    }
}

/// What a hinge entity is realised as.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum HingeMode {
    /// No joint (not yet synchronised, or neither [`IdealHinge`] nor [`ClearanceHinge`]).
    #[default]
    None,
    /// A Rapier revolute joint.
    Ideal,
    /// A clearance joint.
    Clearance,
    /// A large-step clearance joint
    /// ([`ClearanceModel::LargeStep`](crate::rapier::hinge::design::ClearanceModel::LargeStep)).
    LargeStep,
}

/// What a hinge did over the last step, and over the last frame (`frame_*`). `force` is a
/// sample at the state the step reached: in a rattle it jumps between 0 and the contact's peak
/// from one step to the next, and [`frame_mean_force`](Self::frame_mean_force) is the load the
/// frame carried.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct HingeState {
    /// What the hinge is realised as.
    pub mode: HingeMode,
    /// Relative rotation of body 2 about the axis since the hinge was first realised, rad.
    pub angle: f64,
    /// Relative angular rate about the axis, rad/s.
    pub rate: f64,
    /// Joint force magnitude over the last step, N. Clearance: the contact force (exact). Large
    /// step: the normal force of the radial limit (its last substep's impulse over the substep).
    /// Ideal: the exact reaction at the state the step reached, from the constrained equations of
    /// the ideal revolute hinges under gravity, your forces and the drives
    /// ([`ReactionSolver`](crate::rapier::observers::reaction::ReactionSolver)); contacts with colliders and
    /// other kinds of joints on the same bodies are not part of it.
    pub force: f64,
    /// Largest `force` so far, N.
    pub peak_force: f64,
    /// The joint force averaged over the last frame, N: its impulse over the frame's steps over
    /// the frame's time, each state's force held over the step that followed it (as
    /// [`HingeMetrics::rms_force_n`](crate::rapier::observers::metrics::HingeMetrics::rms_force_n) weighs
    /// it). A frame is one [`run_step`](super::run_step), the steps of one
    /// [`run_frame`](super::run_frame), or the steps since [`Physics::begin_frame`](super::Physics::begin_frame).
    /// Large step: the normal force times each step plus the bounces' impulses
    /// ([`impulse`](Self::impulse)); ideal: the reaction at each step's start as the last step
    /// computed it.
    pub frame_mean_force: f64,
    /// The largest joint force at the last frame's states, N: the state it began at and every
    /// state it reached (at least every `force` read after its steps).
    pub frame_peak_force: f64,
    /// [Onsets](crate::rapier::observers::metrics#onsets-impacts-and-chatter) so far: every contact that
    /// began, chatter included (clearance and large step; 0 for ideal hinges). Equals
    /// [`HingeMetrics::onsets`](crate::rapier::observers::metrics::HingeMetrics::onsets) of the same states.
    pub onsets: u64,
    /// [Impacts](crate::rapier::observers::metrics#onsets-impacts-and-chatter) so far: onsets after a free
    /// flight that opened at least the joint's `min_separation` (large step: its bounces, onsets
    /// faster than its `min_impact_speed`); `onsets - impacts` is the chatter. Equals
    /// [`HingeMetrics::impacts`](crate::rapier::observers::metrics::HingeMetrics::impacts) of the same
    /// states. 0 for ideal hinges.
    pub impacts: u64,
    /// Penetration (clearance; negative: free gap), m.
    pub penetration: f64,
    /// Eccentricity of the journal in the bearing (clearance; world), m.
    pub eccentricity: Vector,
    /// `|e|/c`, the eccentricity over the radial clearance (clearance; 0 for ideal hinges): 0
    /// centred, 1 on the wall, above 1 pressed into it (compliant model; the large-step model
    /// leaves at most a few percent above 1 on a resolved step, see
    /// [`LargeStepReport::eccentricity_ratio`](crate::rapier::large_step::LargeStepReport::eccentricity_ratio)).
    pub eccentricity_ratio: f64,
    /// Motion mode (clearance).
    pub contact: ContactMode,
    /// Normal impulse of a bounce in the last step, N s (large step: `m_n (1 + e) v_approach`,
    /// see [`LargeStepReport::impact_impulse`](crate::rapier::large_step::LargeStepReport::impact_impulse));
    /// 0 without a bounce, and always 0 for the compliant model, whose contacts are resolved
    /// as force histories in `force`, and for ideal hinges.
    pub impulse: f64,
    /// The hinge's own substeps in the last step: a large-step hinge's Rapier substeps (it
    /// chooses them, see [`large_step`](crate::rapier::large_step)); a sub-cycled hinge's
    /// contact sub-steps ([`ClearanceJoint::substeps`](crate::rapier::joint::ClearanceJoint::substeps)'s
    /// length); 0 for the other modes, whose substeps are the world's `num_solver_iterations`.
    pub substeps: usize,
    /// Whether the last step needed more substeps than the large-step joint allows, so that its
    /// eccentricity and force may be off by more than the model's resolution promises (large
    /// step; `false` for the other modes).
    pub under_resolved: bool,
    /// A spatial hinge's tilt, axial offset and forces by contact kind over the last step
    /// ([`ClearanceModel::Spatial`](crate::rapier::hinge::design::ClearanceModel::Spatial)); `None`
    /// for the other models and for ideal hinges. For a spatial hinge, `penetration`,
    /// `eccentricity` and `contact` are its deepest station's (a bore station or, when
    /// [`governed_by_face`](crate::rapier::joint::SpatialReport::governed_by_face), a face's).
    pub spatial: Option<crate::rapier::joint::SpatialReport>,
    /// The unwrapped relative angle, referenced where the hinge was first realised.
    pub(super) angle_tracker: HingeAngle,
    /// The impulse of the last frame's steps so far, N s.
    pub(super) frame_impulse: f64,
    /// The time of the last frame's steps so far, s.
    pub(super) frame_time: f64,
}

impl HingeState {
    /// Adds a step of `h` (s) to the frame: `impulse` (N s) over it, between states of force
    /// `start` and `end` (N); `new_frame` empties the frame first.
    pub(super) fn add_step(&mut self, new_frame: bool, h: f64, impulse: f64, start: f64, end: f64) {
        if new_frame {
            (self.frame_impulse, self.frame_time, self.frame_peak_force) = (0.0, 0.0, 0.0);
        }
        self.frame_impulse += impulse;
        self.frame_time += h;
        self.frame_peak_force = self.frame_peak_force.max(start).max(end);
        if self.frame_time > 0.0 {
            self.frame_mean_force = self.frame_impulse / self.frame_time;
        }
    }
}
