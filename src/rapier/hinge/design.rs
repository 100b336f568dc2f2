//! [`HingeDesign`]: everything a clearance hinge is beyond the revolute joint it replaces (the
//! radial geometry, the normal and friction laws, the thresholds, which model solves it), from
//! which either joint model is built; [`ClearanceModel`] names the model.

use crate::error::{Error, Result};
use crate::model::laws::{
    BearingGeometry, FrictionLaw, FrictionModel, ImprovedLiu, Material, MaxDamping, NormalModel,
    effective_modulus,
};
use crate::rapier::joint::{ClearanceJoint, ClearanceJointBuilder, OutOfPlaneLock};
use crate::rapier::large_step::{LargeStepJoint, LargeStepJointBuilder};
use rapier3d_f64::math::Vector;

/// Which model of the clearance joint to build: the same bearing, two ways of solving it.
///
/// | model | solved | steps it is stable at | what it gives |
/// |---|---|---|---|
/// | [`Compliant`](Self::Compliant) | contact law, force hook outside Rapier's solver | sub-cycled (the default, in a `ClearanceWorld`): any step, any iterations, the contact resolved inside it; [`Explicit`](crate::rapier::joint::ContactIntegration::Explicit) (and in a loop of your own): about 1e-5..1e-4 s for steel, `num_solver_iterations = 1` | force histories, peak forces, penetrations |
/// | [`LargeStep`](Self::LargeStep) | radial limit inside Rapier's solver, Newton restitution, friction moment | any step (1/60 s, 1e-3 s), any iterations | play, rattle, orbit, sustained forces, impulses |
/// | [`Spatial`](Self::Spatial) | contact laws along the width and on the faces, nothing locked | as `Compliant` | tilt, edge loading, axial knocks, moments across the hinge |
///
/// The spatial joint is one line more than the planar one: the journal then tilts and slides
/// axially, and its report says how far and what each kind of contact carries.
///
/// ```
/// use clearance_joint::model::spatial::SpatialModel;
/// use clearance_joint::prelude::*;
/// use rapier3d_f64::prelude::*;
///
/// let mut rapier = PhysicsWorld::new();
/// rapier.gravity = Vector::new(0.0, -9.81, 0.0);
/// rapier.integration_parameters.num_solver_iterations = 1;
/// let post = rapier.bodies.insert(RigidBodyBuilder::fixed());
/// // A 2 kg arm whose centre of mass sits 0.2 m out from a vertical pin: a moment across the axis.
/// let arm = rapier.bodies.insert(
///     RigidBodyBuilder::dynamic()
///         .translation(Vector::new(0.2, 0.0, 0.0))
///         .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02))),
/// );
/// // 0.1 mm of radial play in a 12 mm steel bore 20 mm wide; 0.3 mm of axial play, 10 mm collars.
/// let pin = HingeDesign::steel_improved_liu(0.006, 0.1e-3, 0.020)?
///     .model(ClearanceModel::Spatial(SpatialModel::steel(0.3e-3, 0.010)))
///     .joint(Vector::ZERO, Vector::new(-0.2, 0.0, 0.0), Vector::Y, Vector::Y)?;
/// let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, 0.0075));
/// let hinge = world.insert_clearance(post, arm, pin)?;
/// let (mut tilt, mut edges) = (0.0_f64, [0.0_f64; 2]);
/// while world.time() < 0.03 {
///     world.step(0.03)?;
///     let s = world.clearance.get(hinge).unwrap().report().spatial.unwrap();
///     tilt = tilt.max(s.tilt[0].hypot(s.tilt[1]));
///     edges = [edges[0].max(s.edge_force[0]), edges[1].max(s.edge_force[1])];
/// }
/// // The journal tilted until the bore's two edges took the moment (free tilt 2c/L = 10 mrad).
/// // Frictionless, it then rocks between its edges and the top face: see `examples/door_hinge.rs`.
/// assert!(tilt > 0.0099, "{tilt}");
/// assert!(edges[0] > 0.0 && edges[1] > 0.0, "{edges:?}");
/// # Ok::<(), clearance_joint::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum ClearanceModel {
    /// The compliant contact-law joint ([`ClearanceJoint`] in a [`ClearanceJointSet`](crate::rapier::joint::ClearanceJointSet)).
    #[default]
    Compliant,
    /// The large-step joint ([`LargeStepJoint`] in a [`LargeStepJointSet`](crate::rapier::large_step::LargeStepJointSet)): restitution from
    /// [`HingeDesign::restitution`] (or, when unset, the normal law's own restitution at each
    /// impact) and Coulomb friction with the friction law's sliding coefficient.
    LargeStep,
    /// The compliant joint in space ([`crate::model::spatial`]): the journal tilts and slides
    /// axially, nothing is locked; the bore's law acts along the width in slices, the shoulders
    /// meet the bearing's faces with the face law. A [`ClearanceJoint`] in a
    /// [`ClearanceJointSet`](crate::rapier::joint::ClearanceJointSet), like `Compliant`, which is its aligned limit.
    Spatial(crate::model::spatial::SpatialModel),
}

/// Everything a clearance joint needs beyond the revolute joint it replaces: the radial
/// geometry, the normal and friction laws, and options. Built with chained setters.
#[derive(Clone, Debug, PartialEq)]
pub struct HingeDesign {
    /// Radial geometry of the bearing and journal.
    pub geometry: BearingGeometry,
    /// Normal contact law.
    pub normal: NormalModel,
    /// Friction law (default none).
    pub(crate) friction: FrictionModel,
    /// Floor on the impact velocity of the hysteresis laws, m/s (default 1e-4).
    pub(crate) min_impact_speed: f64,
    /// Gap a free flight must open for the next onset to count as an
    /// [impact](crate::rapier::observers::metrics#onsets-impacts-and-chatter), m (default 0.1 um; the
    /// large-step model does not count impacts and ignores it).
    pub(crate) min_separation: f64,
    /// The deepest penetration at which the contact law is trusted, m; deeper contacts are guard
    /// violations ([`max_valid_penetration`](Self::max_valid_penetration)). `None` (the default): 1 % of
    /// the journal radius.
    pub(crate) max_valid_penetration: Option<f64>,
    /// What holds the out-of-plane degrees of freedom (default [`OutOfPlaneLock::Joint`]);
    /// ignored by [`ClearanceModel::Spatial`], which locks nothing.
    pub(crate) lock: OutOfPlaneLock,
    /// Name used in errors and reports (default: the builder's default name).
    pub name: Option<String>,
    /// Which model to build (default [`ClearanceModel::Compliant`]).
    pub model: ClearanceModel,
    /// Coefficient of restitution of the large-step model's bounces; `None` (the default): the
    /// normal law's own restitution at each bounce ([`crate::rapier::large_step::Restitution::Law`]).
    /// The compliant and spatial models take their restitution from their laws:
    /// [`joint`](Self::joint) refuses a set one, naming `restitution`.
    pub(crate) restitution: Option<f64>,
    /// How the compliant joint integrates its contact (default
    /// [`ContactIntegration::SubCycled`](crate::rapier::joint::ContactIntegration::SubCycled)).
    pub(crate) integration: crate::rapier::joint::ContactIntegration,
    /// Which of the sub-cycle's techniques a sub-cycled joint uses (default all).
    pub(crate) techniques: crate::rapier::joint::SubCycleTechniques,
}

impl HingeDesign {
    /// A frictionless clearance with the given geometry and normal law.
    pub fn new(geometry: BearingGeometry, normal: NormalModel) -> Self {
        HingeDesign {
            geometry,
            normal,
            friction: FrictionModel::None,
            min_impact_speed: crate::rapier::joint::DEFAULT_MIN_IMPACT_SPEED,
            min_separation: crate::rapier::joint::DEFAULT_MIN_SEPARATION,
            max_valid_penetration: None,
            lock: OutOfPlaneLock::Joint,
            name: None,
            model: ClearanceModel::Compliant,
            restitution: None,
            integration: crate::rapier::joint::ContactIntegration::SubCycled,
            techniques: crate::rapier::joint::SubCycleTechniques::default(),
        }
    }

    /// The paper's improved law (MODEL.md §2) with its defaults (`n = 1`, `delta_max = 0.1 mm`,
    /// `eta = 0.01 s`) for a bearing of radius `bearing_radius`, radial clearance `clearance` and
    /// width `length` (all in m) between two materials; frictionless.
    pub fn improved_liu(
        bearing_radius: f64,
        clearance: f64,
        length: f64,
        bearing: Material,
        journal: Material,
    ) -> Result<Self> {
        let geometry = BearingGeometry::from_clearance(bearing_radius, clearance, length)?;
        bearing.validate().map_err(|e| e.within("bearing"))?;
        journal.validate().map_err(|e| e.within("journal"))?;
        let law = ImprovedLiu::new(
            effective_modulus(&bearing, &journal),
            length,
            clearance,
            1.0,
            ImprovedLiu::DEFAULT_DELTA_MAX,
            MaxDamping::Eta(ImprovedLiu::DEFAULT_ETA),
        )?;
        Ok(Self::new(geometry, NormalModel::ImprovedLiu(law)))
    }

    /// The paper's improved law ([`improved_liu`](Self::improved_liu), Liu's cylindrical
    /// elastic term with the penetration-ramped damping) with structural steel on both sides (the
    /// paper's table 2: E = 207 GPa, nu = 0.3). Lengths in m.
    pub fn steel_improved_liu(bearing_radius: f64, clearance: f64, length: f64) -> Result<Self> {
        Self::improved_liu(
            bearing_radius,
            clearance,
            length,
            Material::STEEL,
            Material::STEEL,
        )
    }

    /// Sets the friction law (default: none).
    pub fn friction(mut self, friction: FrictionModel) -> Self {
        self.friction = friction;
        self
    }

    /// Sets the floor on the impact velocity `delta_dot0` of the hysteresis laws, m/s (default
    /// 1e-4): a contact that begins at a vanishing speed would otherwise get unbounded damping.
    pub fn min_impact_speed(mut self, speed: f64) -> Self {
        self.min_impact_speed = speed;
        self
    }

    /// Sets the gap a free flight must open for the next onset to count as an
    /// [impact](crate::rapier::observers::metrics#onsets-impacts-and-chatter), m (default 0.1 um,
    /// about 8 times the resting penetration of the paper's hinge load: onsets after smaller
    /// separations are the chatter of a journal following the wall; checked when the joint is
    /// built: not negative).
    pub fn min_separation(mut self, gap: f64) -> Self {
        self.min_separation = gap;
        self
    }

    /// Sets the deepest penetration at which the contact law is trusted, m (default 1 % of the
    /// journal radius, a nominal strain of 1 %; checked when the joint is built: positive, at
    /// most the journal radius). A journal pressed deeper is outside the model; the step loop
    /// reports it as a guard violation
    /// ([`GuardReport`](crate::rapier::pipeline::protocol::GuardReport)), with the worst depth,
    /// when and how often. It is not a force limit.
    pub fn max_valid_penetration(mut self, depth: f64) -> Self {
        self.max_valid_penetration = Some(depth);
        self
    }

    /// Sets what holds the out-of-plane degrees of freedom of the planar joint (the spatial
    /// model locks nothing and ignores it).
    pub fn lock(mut self, lock: OutOfPlaneLock) -> Self {
        self.lock = lock;
        self
    }

    /// Sets how the compliant planar joint integrates its contact
    /// ([`ContactIntegration`](crate::rapier::joint::ContactIntegration)).
    pub fn integration(mut self, integration: crate::rapier::joint::ContactIntegration) -> Self {
        self.integration = integration;
        self
    }

    /// Sets which of the sub-cycle's techniques a sub-cycled joint uses
    /// ([`SubCycleTechniques`](crate::rapier::joint::SubCycleTechniques); default all, and
    /// an explicit joint ignores them): one off gives the plainer method, for comparison.
    pub fn sub_cycle_techniques(
        mut self,
        techniques: crate::rapier::joint::SubCycleTechniques,
    ) -> Self {
        self.techniques = techniques;
        self
    }

    /// Sets the name used in errors and reports.
    pub fn name(mut self, name: impl Into<String>) -> Self {
        self.name = Some(name.into());
        self
    }

    /// Chooses the model: `.model(ClearanceModel::LargeStep)` for 1/60 s or 1 kHz worlds,
    /// `.model(ClearanceModel::Spatial(..))` for a journal that tilts and slides axially.
    pub fn model(mut self, model: ClearanceModel) -> Self {
        self.model = model;
        self
    }

    /// Sets the large-step model's coefficient of restitution (in [0, 1]). The compliant and
    /// spatial models take theirs from the normal law: [`joint`](Self::joint) refuses a set one.
    pub fn restitution(mut self, coefficient: f64) -> Self {
        self.restitution = Some(coefficient);
        self
    }

    /// A validated clearance joint with these laws, about `local_axis1` / `local_axis2` through
    /// `local_anchor1` / `local_anchor2` (body frames; body 1 carries the bearing, body 2 the
    /// journal): unit axes, finite anchors, a normal law that holds a clearance (Liu's family)
    /// built for the geometry's ([`NormalModel::check_clearance`]), the floors and the validity
    /// limit. Without a revolute joint to convert
    /// ([`ConvertRevolute`](crate::rapier::hinge::convert::ConvertRevolute)), this builds one from
    /// scratch:
    ///
    /// ```
    /// use clearance_joint::model::laws::{Bai, BearingGeometry, FrictionModel, ImprovedLiu, MaxDamping, NormalModel};
    /// use clearance_joint::prelude::*;
    /// let geometry = BearingGeometry::from_clearance(0.010, 0.5e-3, 0.016)?;
    /// let law = ImprovedLiu::new(1.137e11, 0.016, 0.5e-3, 1.0, 1e-4, MaxDamping::Eta(0.01))?;
    /// let axis = Vector::new(0.0, -1.0, 0.0);
    /// let joint = HingeDesign::new(geometry, NormalModel::ImprovedLiu(law))
    ///     .friction(FrictionModel::Bai(Bai::DRY))
    ///     .joint(Vector::new(0.4, 0.0, 0.4), Vector::new(0.0, 0.0, 0.4), axis, axis)?;
    /// assert!((joint.geometry().clearance() - 0.5e-3).abs() < 1e-15);
    /// # Ok::<(), clearance_joint::Error>(())
    /// ```
    pub fn joint(
        &self,
        local_anchor1: Vector,
        local_anchor2: Vector,
        local_axis1: Vector,
        local_axis2: Vector,
    ) -> Result<ClearanceJoint> {
        if self.model == ClearanceModel::LargeStep {
            return Err(Error::invalid(
                "model",
                "is LargeStep, but a compliant clearance joint was asked for: insert it into a \
                 LargeStepJointSet (or use `HingeDesign::large_step_joint`), or choose \
                 ClearanceModel::Compliant",
            ));
        }
        if let Some(e) = self.restitution {
            return Err(Error::invalid(
                "restitution",
                format!(
                    "is set ({}), but the compliant and spatial models take their restitution from \
                     the normal law (its damping): leave `restitution` unset, choose a law with the \
                     restitution you want (e.g. a hysteresis law's `restitution`), or choose \
                     ClearanceModel::LargeStep, which uses it",
                    crate::error::sig4(e)
                ),
            ));
        }
        let mut b = ClearanceJointBuilder::new(local_axis1, self.geometry, self.normal)
            .local_axis2(local_axis2)
            .local_anchor1(local_anchor1)
            .local_anchor2(local_anchor2)
            .friction(self.friction)
            .min_impact_speed(self.min_impact_speed)
            .min_separation(self.min_separation)
            .lock(self.lock)
            .integration(self.integration)
            .sub_cycle_techniques(self.techniques);
        if let Some(depth) = self.max_valid_penetration {
            b = b.max_valid_penetration(depth);
        }
        if let Some(name) = &self.name {
            b = b.name(name.clone());
        }
        if let ClearanceModel::Spatial(model) = self.model {
            b = b.spatial(model);
        }
        b.build()
    }
}

impl HingeDesign {
    /// A validated large-step clearance joint with this geometry (whatever [`model`](Self::model)
    /// says, except [`ClearanceModel::Spatial`], refused naming `model`: the large-step joint is
    /// planar and cannot tilt or slide axially): restitution [`restitution`](Self::restitution) or the normal law's own, Coulomb
    /// friction with the friction law's sliding coefficient (`mu_d`), the same impact-speed floor
    /// and name, about `local_axis1` / `local_axis2` through `local_anchor1` / `local_anchor2`.
    pub fn large_step_joint(
        &self,
        local_anchor1: Vector,
        local_anchor2: Vector,
        local_axis1: Vector,
        local_axis2: Vector,
    ) -> Result<LargeStepJoint> {
        if let ClearanceModel::Spatial(_) = self.model {
            return Err(Error::invalid(
                "model",
                "is Spatial, but a large-step joint was asked for: the large-step model is \
                 planar (Rapier's solver locks its axial motion and tilts). Build the spatial \
                 joint with `HingeDesign::joint` into a ClearanceJointSet (or a ClearanceWorld), or \
                 choose ClearanceModel::LargeStep",
            ));
        }
        // The law's restitution is evaluated at the law's clearance: it must be the bearing's.
        self.normal
            .check_clearance("normal", self.geometry.clearance())?;
        let mut b = LargeStepJointBuilder::new(local_axis1, self.geometry)
            .local_axis2(local_axis2)
            .local_anchor1(local_anchor1)
            .local_anchor2(local_anchor2)
            .friction(self.friction.sliding_coefficient())
            .min_impact_speed(self.min_impact_speed);
        b = match self.restitution {
            Some(e) => b.restitution(e),
            None => b.restitution_law(self.normal),
        };
        if let Some(name) = &self.name {
            b = b.name(name.clone());
        }
        b.build()
    }
}
