//! Building a large-step joint: [`LargeStepJointBuilder`]'s setters and checks, and the
//! restitution of its impacts.

use super::*;

impl Restitution {
    /// The coefficient for one impact of `approach_speed` (m/s) between bodies of
    /// `effective_mass` (kg) along the normal.
    pub fn coefficient(&self, effective_mass: f64, approach_speed: f64) -> f64 {
        match self {
            Restitution::Coefficient(e) => *e,
            Restitution::Law(law) => impact_restitution(law, effective_mass, approach_speed),
        }
    }
}

impl LargeStepJointBuilder {
    /// A joint about `axis` (in body 1's frame; also body 2's unless
    /// [`local_axis2`](Self::local_axis2) is set) with the radial geometry `geometry` (its clearance
    /// is the play; its journal radius is the friction moment's arm), anchors at both bodies'
    /// origins, inelastic (restitution 0) and frictionless.
    pub fn new(axis: Vector, geometry: BearingGeometry) -> Self {
        LargeStepJointBuilder {
            joint: LargeStepJoint {
                name: String::from("large-step clearance joint"),
                local_axis1: axis,
                local_axis2: axis,
                local_anchor1: Vector::ZERO,
                local_anchor2: Vector::ZERO,
                geometry,
                restitution: Restitution::Coefficient(0.0),
                friction: 0.0,
                min_impact_speed: crate::rapier::joint::DEFAULT_MIN_IMPACT_SPEED,
                max_substeps: DEFAULT_MAX_SUBSTEPS,
                body1: RigidBodyHandle::invalid(),
                body2: RigidBodyHandle::invalid(),
                handle: None,
                state: JointState::default(),
                report: LargeStepReport::default(),
            },
        }
    }
    /// Bearing centre in body 1's frame.
    pub fn local_anchor1(mut self, anchor: Vector) -> Self {
        self.joint.local_anchor1 = anchor;
        self
    }
    /// Journal centre in body 2's frame.
    pub fn local_anchor2(mut self, anchor: Vector) -> Self {
        self.joint.local_anchor2 = anchor;
        self
    }
    /// Hinge axis in body 2's frame (defaults to the axis given to [`new`](Self::new)).
    pub fn local_axis2(mut self, axis: Vector) -> Self {
        self.joint.local_axis2 = axis;
        self
    }
    /// A fixed coefficient of restitution in [0, 1] (default 0: onsets do not rebound).
    pub fn restitution(mut self, coefficient: f64) -> Self {
        self.joint.restitution = Restitution::Coefficient(coefficient);
        self
    }
    /// Bounce as the compliant law `law` would at each impact (see [`Restitution::Law`]).
    pub fn restitution_law(mut self, law: NormalModel) -> Self {
        self.joint.restitution = Restitution::Law(law);
        self
    }
    /// Coulomb friction coefficient `mu >= 0` of the bearing surface (default 0): the hinge
    /// sticks below the friction moment `mu N R_j` and slides at it.
    pub fn friction(mut self, mu: f64) -> Self {
        self.joint.friction = mu;
        self
    }
    /// Approach speed below which a contact onset does not bounce, m/s (default 1e-4, as the
    /// compliant joint's).
    pub fn min_impact_speed(mut self, speed: f64) -> Self {
        self.joint.min_impact_speed = speed;
        self
    }
    /// Most substeps per step the joint may ask Rapier for, at least `num_solver_iterations`
    /// (default 64). A step that needs more is taken anyway and reported under-resolved.
    pub fn max_substeps(mut self, substeps: usize) -> Self {
        self.joint.max_substeps = substeps;
        self
    }
    /// A name used in error messages and outputs.
    pub fn name(mut self, name: impl Into<String>) -> Self {
        self.joint.name = name.into();
        self
    }
    /// Validates and returns the joint.
    pub fn build(mut self) -> Result<LargeStepJoint> {
        let j = &mut self.joint;
        j.local_axis1 = unit_vector("local_axis1", j.local_axis1)?;
        j.local_axis2 = unit_vector("local_axis2", j.local_axis2)?;
        for (field, v) in [
            ("local_anchor1", j.local_anchor1),
            ("local_anchor2", j.local_anchor2),
        ] {
            if !v.is_finite() {
                return Err(Error::invalid(field, format!("must be finite (got {v:?})")));
            }
        }
        if let Restitution::Coefficient(e) = j.restitution {
            non_negative("restitution", e)?;
            if e > 1.0 {
                return Err(Error::invalid(
                    "restitution",
                    format!("must be in [0, 1] (got {e}): above 1 an impact would create energy"),
                ));
            }
        }
        non_negative("friction", j.friction)?;
        positive("min_impact_speed", j.min_impact_speed)?;
        if j.max_substeps == 0 {
            return Err(Error::invalid("max_substeps", "must be at least 1 (got 0)"));
        }
        Ok(self.joint)
    }
}
