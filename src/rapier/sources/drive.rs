//! Torsion-spring drive between two bodies (MODEL.md §4, eq. 20): `T = T0 - k theta`.

use crate::error::{Result, in_range, unit_vector};
use crate::model::angle::HingeAngle;
use crate::rapier::pipeline::element_set::{ElementHandle, ElementSet};
use crate::rapier::pipeline::ledger::ForceLedger;
use crate::rapier::pipeline::protocol::Wrench;
use crate::rapier::pipeline::step_hooks::{EvaluateContext, StepHooks};
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{RigidBodyHandle, RigidBodySet};

/// A torsion spring about a hinge axis: torque `+T a` on body 2, `-T a` on body 1 (a pure couple,
/// so total momentum is unchanged). `theta` is body 2's rotation relative to body 1 about the
/// axis, zero when the drive is created.
#[derive(Clone, Debug)]
pub struct TorsionSpring {
    body1: RigidBodyHandle,
    body2: RigidBodyHandle,
    local_axis1: Vector,
    torque0: f64,
    stiffness: f64,
    angle: HingeAngle,
    last_torque: f64,
}

impl TorsionSpring {
    /// The largest preload, N m: a torque beyond it drives any body of a mechanism past the
    /// speed guard within a step.
    pub(crate) const MAX_TORQUE: f64 = 1e9;

    /// The largest stiffness, N m/rad.
    pub(crate) const MAX_STIFFNESS: f64 = 1e12;

    /// Preload `torque0` (N m, at most 1e9 either way) and `stiffness` (N m/rad, from 0 to
    /// 1e12), about
    /// `local_axis1` (body 1's frame); errors name `torque0`, `stiffness` or `axis`.
    pub fn new(
        body1: RigidBodyHandle,
        body2: RigidBodyHandle,
        local_axis1: Vector,
        torque0: f64,
        stiffness: f64,
    ) -> Result<Self> {
        in_range(
            "torque0",
            torque0,
            -Self::MAX_TORQUE,
            Self::MAX_TORQUE,
            "N m",
        )?;
        in_range("stiffness", stiffness, 0.0, Self::MAX_STIFFNESS, "N m/rad")?;
        Ok(TorsionSpring {
            body1,
            body2,
            local_axis1: unit_vector("axis", local_axis1)?,
            torque0,
            stiffness,
            angle: HingeAngle::default(),
            last_torque: 0.0,
        })
    }

    /// The torque law `T(theta) = T0 - k theta`, N m.
    pub fn torque_at(&self, theta: f64) -> f64 {
        self.torque0 - self.stiffness * theta
    }

    /// Potential energy `-(T0 theta - k theta^2/2)` of the spring at `theta`, J (so that kinetic
    /// plus potential energy is conserved by an ideal mechanism).
    pub fn potential_energy(&self, theta: f64) -> f64 {
        -(self.torque0 * theta - 0.5 * self.stiffness * theta * theta)
    }

    /// The relative angle at the last application, rad.
    pub fn angle(&self) -> f64 {
        self.angle.value()
    }

    /// The torque applied at the last application, N m.
    pub fn torque(&self) -> f64 {
        self.last_torque
    }

    /// Measures the relative angle and returns the couple to apply.
    fn evaluate(&mut self, bodies: &RigidBodySet) -> Option<(Wrench, Wrench)> {
        let (rb1, rb2) = (bodies.get(self.body1)?, bodies.get(self.body2)?);
        let theta = self
            .angle
            .update(rb1.rotation(), rb2.rotation(), self.local_axis1);
        let torque = self.torque_at(theta);
        self.last_torque = torque;
        let t = torque * (*rb1.rotation() * self.local_axis1);
        Some((
            Wrench {
                body: self.body1,
                force: Vector::ZERO,
                torque: -t,
            },
            Wrench {
                body: self.body2,
                force: Vector::ZERO,
                torque: t,
            },
        ))
    }
}

/// Handle of a drive in a [`DriveSet`], returned by its [`insert`](DriveSet::insert):
/// generational, as the joint sets' handles.
pub type DriveHandle = ElementHandle<TorsionSpring>;

/// All drives of a world, visited in insertion order. Under the
/// [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld) their torques act during the steps
/// only; a loop that calls `world.step()` itself calls [`DriveSet::apply`] before every step.
#[derive(Clone, Debug, Default)]
pub struct DriveSet {
    drives: ElementSet<TorsionSpring>,
    ledger: ForceLedger,
    wrenches: Vec<Wrench>,
    saved: Vec<(HingeAngle, f64)>,
    saved_wrenches: Vec<Wrench>,
}

impl DriveSet {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }
    /// Adds a drive; returns its handle.
    pub fn insert(&mut self, drive: TorsionSpring) -> DriveHandle {
        self.drives.insert(drive)
    }
    /// Removes the drive and returns it (`None` for a handle of no drive of this set); the others
    /// keep their handles and order. Its torque leaves the next evaluation (a loop that applies
    /// the torques itself calls [`apply`](Self::apply) or [`take_back`](Self::take_back)).
    pub fn remove(&mut self, handle: DriveHandle) -> Option<TorsionSpring> {
        let d = self.drives.remove(handle)?;
        // A saved state is by position: it no longer matches the drives.
        self.saved.clear();
        Some(d)
    }
    /// Replaces the torques applied at the previous call by the current ones (for a loop that
    /// calls `world.step()` itself; the [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld) uses
    /// [`evaluate`](StepHooks::evaluate) and adds the torques for its step only).
    pub fn apply(&mut self, bodies: &mut RigidBodySet) {
        self.evaluate(bodies);
        self.ledger.replace(bodies, self.wrenches.iter().copied());
    }

    /// Measures the angles and computes the torques of [`wrenches`](Self::wrenches), without
    /// touching the bodies' forces.
    pub(crate) fn evaluate(&mut self, bodies: &RigidBodySet) {
        self.wrenches.clear();
        for d in self.drives.values_mut() {
            if let Some((w1, w2)) = d.evaluate(bodies) {
                self.wrenches.push(w1);
                self.wrenches.push(w2);
            }
        }
    }

    /// The torques of the last evaluation, two per drive.
    pub(crate) fn wrenches(&self) -> &[Wrench] {
        &self.wrenches
    }
    /// Takes back, exactly, every torque this set applied at its last [`apply`](Self::apply)
    /// (for a drive removed from the world).
    pub fn take_back(&mut self, bodies: &mut RigidBodySet) {
        self.wrenches.clear();
        self.ledger.replace(bodies, std::iter::empty());
    }

    /// Saves the angle trackers and applied torques (before a step that may be rejected).
    pub(crate) fn save_state(&mut self) {
        self.drives
            .save_into(&mut self.saved, |d| (d.angle, d.last_torque));
        self.saved_wrenches.clone_from(&self.wrenches);
    }

    /// Restores what [`save_state`](Self::save_state) saved.
    pub(crate) fn restore_state(&mut self) {
        self.drives
            .restore_from(&self.saved, |d, &(angle, torque)| {
                d.angle = angle;
                d.last_torque = torque;
            });
        self.wrenches.clone_from(&self.saved_wrenches);
    }

    /// Total potential energy of the springs at their last measured angles, J.
    pub fn potential_energy(&self) -> f64 {
        self.drives
            .values()
            .map(|d| d.potential_energy(d.angle()))
            .sum()
    }
}

/// The drives take part in the stepper's steps: their torques, saved and restored with a rejected
/// step ([`crate::rapier::pipeline::step_hooks`]).
/// Reading the set is reading its [`ElementSet`]: [`get`](ElementSet::get),
/// [`contains`](ElementSet::contains), [`iter`](ElementSet::iter) (insertion order),
/// [`len`](ElementSet::len), [`revision`](ElementSet::revision). Adding and removing go through
/// the set's own methods, which also keep the Rapier side and the forces in step.
impl std::ops::Deref for DriveSet {
    type Target = ElementSet<TorsionSpring>;

    fn deref(&self) -> &Self::Target {
        &self.drives
    }
}

impl StepHooks for DriveSet {
    fn evaluate(&mut self, context: EvaluateContext<'_>) {
        DriveSet::evaluate(self, context.bodies);
    }
    fn wrenches(&self) -> &[Wrench] {
        DriveSet::wrenches(self)
    }
    fn save_state(&mut self) {
        DriveSet::save_state(self);
    }
    fn restore_state(&mut self) {
        DriveSet::restore_state(self);
    }
}
