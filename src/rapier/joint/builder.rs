//! Building a clearance joint: [`ClearanceJointBuilder`]'s setters and checks.

use super::*;

impl ClearanceJointBuilder {
    /// A joint about `axis` (in body 1's frame; also used for body 2 unless
    /// [`local_axis2`](Self::local_axis2) is set) with the given geometry and normal law,
    /// frictionless, anchors at both bodies' origins.
    pub(crate) fn new(axis: Vector, geometry: BearingGeometry, normal_law: NormalModel) -> Self {
        ClearanceJointBuilder {
            joint: ClearanceJoint {
                name: String::from("clearance joint"),
                local_axis1: axis,
                local_axis2: axis,
                local_anchor1: Vector::ZERO,
                local_anchor2: Vector::ZERO,
                geometry,
                normal_law,
                friction_law: FrictionModel::None,
                min_impact_speed: DEFAULT_MIN_IMPACT_SPEED,
                min_separation: DEFAULT_MIN_SEPARATION,
                max_valid_penetration: None,
                lock: OutOfPlaneLock::Joint,
                body1: RigidBodyHandle::invalid(),
                body2: RigidBodyHandle::invalid(),
                lock_handle: None,
                contact: ContactHistory::default(),
                report: ClearanceReport::default(),
                elastic: OnceLock::new(),
                previous_rate: None,
                moved_rate: None,
                last_step: 0.0,
                last_wrenches: None,
                prepared: false,
                spatial: None,
                integration: ContactIntegration::default(),
                plain_loop: false,
                techniques: SubCycleTechniques::default(),
                cycle: CycleState::default(),
            },
            spatial: None,
        }
    }
    /// Bearing centre in body 1's frame.
    pub(crate) fn local_anchor1(mut self, anchor: Vector) -> Self {
        self.joint.local_anchor1 = anchor;
        self
    }
    /// Journal centre in body 2's frame.
    pub(crate) fn local_anchor2(mut self, anchor: Vector) -> Self {
        self.joint.local_anchor2 = anchor;
        self
    }
    /// How the contact is integrated over a step ([`ContactIntegration`]; default
    /// [`ContactIntegration::SubCycled`]).
    pub(crate) fn integration(mut self, integration: ContactIntegration) -> Self {
        self.joint.integration = integration;
        self
    }
    /// Which of the sub-cycle's techniques a sub-cycled joint uses ([`SubCycleTechniques`];
    /// default all).
    pub(crate) fn sub_cycle_techniques(mut self, techniques: SubCycleTechniques) -> Self {
        self.joint.techniques = techniques;
        self
    }
    /// Hinge axis in body 2's frame (defaults to the axis given to [`new`](Self::new)).
    pub(crate) fn local_axis2(mut self, axis: Vector) -> Self {
        self.joint.local_axis2 = axis;
        self
    }
    /// The friction law (default: none).
    pub(crate) fn friction(mut self, friction: FrictionModel) -> Self {
        self.joint.friction_law = friction;
        self
    }
    /// Floor on the impact velocity `delta_dot0` of the hysteresis laws, m/s (default 1e-4): a
    /// contact that begins at a vanishing speed would otherwise get unbounded damping.
    pub(crate) fn min_impact_speed(mut self, speed: f64) -> Self {
        self.joint.min_impact_speed = speed;
        self
    }
    /// The gap a free flight must open for the next onset to count as an
    /// [impact](crate::rapier::observers::metrics#onsets-impacts-and-chatter), m (default 0.1 um, about 8
    /// times the resting penetration of the paper's hinge load): onsets after smaller
    /// separations are the chatter of a journal following the wall.
    pub(crate) fn min_separation(mut self, gap: f64) -> Self {
        self.joint.min_separation = gap;
        self
    }
    /// The deepest penetration at which the contact law is still trusted, m (default 1 % of the
    /// journal radius, a nominal strain of 1 %). A journal pressed deeper is outside the model; the
    /// steppers report it as a guard violation ([`crate::rapier::pipeline::protocol::GuardReport`]), with
    /// the worst depth, when and how often. It is not a force limit.
    pub(crate) fn max_valid_penetration(mut self, depth: f64) -> Self {
        self.joint.max_valid_penetration = Some(depth);
        self
    }
    /// What locks the out-of-plane degrees of freedom (default [`OutOfPlaneLock::Joint`]).
    pub(crate) fn lock(mut self, lock: OutOfPlaneLock) -> Self {
        self.joint.lock = lock;
        self
    }
    /// A name used in error messages and outputs.
    pub(crate) fn name(mut self, name: impl Into<String>) -> Self {
        self.joint.name = name.into();
        self
    }
    /// Makes the joint spatial ([`crate::model::spatial`]): nothing is locked, the journal
    /// tilts and slides axially, touching the bore along its width (the geometry's length) and
    /// the bearing's faces with its shoulders. The [`lock`](Self::lock) is ignored (always none).
    pub(crate) fn spatial(mut self, model: crate::model::spatial::SpatialModel) -> Self {
        self.spatial = Some(model);
        self
    }
    /// Validates and returns the joint: unit axes, finite anchors, a normal law that holds a
    /// clearance (Liu's family) built for the geometry's
    /// ([`NormalModel::check_clearance`]), the floors and the validity limit.
    pub(crate) fn build(mut self) -> Result<ClearanceJoint> {
        let j = &mut self.joint;
        j.local_axis1 = crate::error::unit_vector("local_axis1", j.local_axis1)?;
        j.local_axis2 = crate::error::unit_vector("local_axis2", j.local_axis2)?;
        for (field, v) in [
            ("local_anchor1", j.local_anchor1),
            ("local_anchor2", j.local_anchor2),
        ] {
            if !v.is_finite() {
                return Err(Error::invalid(field, format!("must be finite (got {v:?})")));
            }
        }
        // The clearance is held twice, by the geometry and by a law of Liu's family: they agree.
        j.normal_law
            .check_clearance("normal_law", j.geometry.clearance())?;
        crate::error::positive("min_impact_speed", j.min_impact_speed)?;
        crate::error::non_negative("min_separation", j.min_separation)?;
        if let Some(d) = j.max_valid_penetration {
            validate_max_valid_penetration("max_valid_penetration", d, &j.geometry)?;
        }
        if let Some(model) = self.spatial {
            let face_law = model
                .validate(&j.geometry)
                .map_err(|e| e.within("spatial"))?;
            j.lock = OutOfPlaneLock::None;
            j.spatial = Some(SpatialParts::new(model, face_law, j.local_axis1));
        }
        Ok(self.joint)
    }
}

/// The nominal compressive strain `delta/R_j` up to which the contact laws are trusted by
/// default: 1 %. Every law here is linear elastic (small strain); at a strain `e` the
/// Green-Lagrange strain `e + e^2/2` differs from the linear one by `e/2`, 0.5 % at 1 %, and
/// the approach `delta` spreads over a depth of the order of the journal radius `R_j`.
/// docs/MODEL.md ("Validity") gives the argument and what it does not cover.
pub(crate) const DEFAULT_VALID_STRAIN: f64 = 0.01;

/// Checks a validity limit `depth` (m) for `field`: positive, finite, and at most the journal
/// radius (a deeper "penetration" is no contact of two cylinders).
pub(crate) fn validate_max_valid_penetration(
    field: &str,
    depth: f64,
    geometry: &BearingGeometry,
) -> Result<f64> {
    crate::error::positive(field, depth)?;
    let r = geometry.journal_radius();
    if depth > r {
        return Err(Error::invalid(
            field,
            format!(
                "must be at most the journal radius {} m (got {} m): the limit is a depth of \
                 contact, small against the journal (default {} m, {} % of its radius)",
                crate::error::sig4(r),
                crate::error::sig4(depth),
                crate::error::sig4(default_max_valid_penetration(geometry)),
                DEFAULT_VALID_STRAIN * 100.0
            ),
        ));
    }
    Ok(depth)
}
