//! Scenes as data (RON): bodies, hinges (ideal or with clearance), drives and run settings.
//! Every value is validated with an error naming its path, e.g. `hinges[hinge].clearance.clearance_mm`.

mod body;
mod clearance;
mod drive;
mod hinge;
mod joint;
mod limits;
mod load;
mod overrides;
mod run;
mod validated;

pub use body::{BodySpec, MotionSpec};
pub use clearance::{
    ClearanceSpec, ContactSpec, FaceSpec, FrictionSpec, ModelSpec, SpatialGeometrySpec, SpatialSpec,
};
pub use drive::DriveSpec;
pub use hinge::HingeSpec;
pub use joint::{JointKindSpec, JointSpec, MotorSpec};
pub use limits::*;
pub use load::SOLAR_PANEL_RON;
pub use overrides::field_within;
pub use run::{RunSettings, StepMode};
pub use validated::ValidatedScene;

use crate::error::{Error, Result, in_range, sig4};
pub(super) use limits::is_plain_name;
use serde::{Deserialize, Serialize};

/// A mechanism and how to run it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Scene name (default output folder `out/<name>`).
    pub name: String,
    /// Gravity, m/s^2.
    #[serde(default)]
    pub gravity: [f64; 3],
    /// Axis about which body angles and rates are reported (unit vector, world).
    pub reference_axis: [f64; 3],
    /// Rigid bodies.
    pub bodies: Vec<BodySpec>,
    /// Hinges between bodies.
    pub hinges: Vec<HingeSpec>,
    /// Ideal joints of Rapier's other kinds (prismatic, fixed, spherical) between bodies;
    /// revolutes, ideal or with clearance, are `hinges`.
    #[serde(default)]
    pub joints: Vec<JointSpec>,
    /// Torsion-spring drives on hinges.
    #[serde(default)]
    pub drives: Vec<DriveSpec>,
    /// Time stepping and output.
    #[serde(default)]
    pub run: RunSettings,
    /// Study presets: named sweeps of one parameter, run by the app's `study <name>`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub studies: Vec<super::StudySpec>,
}

impl Scene {
    /// Index of the body called `name`.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// Where body `i`'s frame is at t = 0 (world, m): the spin axis point of a spinning body
    /// (Rapier turns a kinematic body about its frame origin), its centre of mass otherwise.
    pub fn body_origin(&self, i: usize) -> [f64; 3] {
        let b = &self.bodies[i];
        match &b.motion {
            Some(MotionSpec::Spin { point_m, .. })
            | Some(MotionSpec::TableAngle { point_m, .. }) => *point_m,
            _ => b.center_of_mass_m,
        }
    }

    /// The period of the scene's drive, s: one turn of the first body spinning at a nonzero
    /// rate, or else of the first velocity motor's target (`None` without either). Per-turn statistics are taken over it.
    pub fn drive_period(&self) -> Option<f64> {
        let spin = self.bodies.iter().find_map(|b| match &b.motion {
            Some(MotionSpec::Spin { rate_rad_s, .. }) if *rate_rad_s != 0.0 => Some(*rate_rad_s),
            _ => None,
        });
        let motor = || {
            self.joints.iter().find_map(|j| match &j.motor {
                Some(MotorSpec::Velocity { target_rad_s, .. }) if *target_rad_s != 0.0 => {
                    Some(*target_rad_s)
                }
                _ => None,
            })
        };
        spin.or_else(motor)
            .map(|rate| std::f64::consts::TAU / rate.abs())
    }

    /// Index of the hinge called `name`.
    pub fn hinge_index(&self, name: &str) -> Option<usize> {
        self.hinges.iter().position(|h| h.name == name)
    }

    /// Checks every field; the error names the first invalid one. [`validated`](Self::validated)
    /// does the same and keeps what the check built.
    pub fn validate(&self) -> Result<()> {
        self.check().map(drop)
    }

    /// The scene, checked ([`validate`](Self::validate)), with its hinges' clearance settings
    /// built: what [`Simulation`](crate::scene::runner::Simulation) builds its twins from.
    pub fn validated(&self) -> Result<ValidatedScene> {
        let clearances = self.check()?;
        Ok(ValidatedScene::new(self.clone(), clearances))
    }

    /// The one check of a scene: every field, the error naming the first invalid one; returns
    /// each hinge's [`HingeDesign`](crate::rapier::hinge::design::HingeDesign) (`None` for an ideal hinge).
    fn check(&self) -> Result<Vec<Option<crate::rapier::hinge::design::HingeDesign>>> {
        if !is_plain_name(&self.name) {
            return Err(Error::invalid(
                "name",
                "must be a plain name: letters, digits, `_` and `-` (it names the output folder)",
            ));
        }
        for (i, g) in self.gravity.iter().enumerate() {
            in_range(
                &format!("gravity[{i}]"),
                *g,
                -GRAVITY_MAX,
                GRAVITY_MAX,
                "m/s^2",
            )?;
        }
        unit(&self.reference_axis, "reference_axis")?;
        if self.bodies.is_empty() {
            return Err(Error::invalid("bodies", "a scene needs at least one body"));
        }
        let mut names = std::collections::HashSet::new();
        self.validate_bodies(&mut names)?;
        let clearances = self.validate_hinges(&mut names)?;
        self.validate_joints(&mut names)?;
        self.validate_planar()?;
        self.validate_drives(&mut names)?;
        self.run.validate()?;
        self.validate_drive_steps()?;
        self.validate_periods()?;
        Ok(clearances)
    }

    /// The per-turn statistics of a driven scene must fit: at most
    /// [`MAX_PERIODS`](crate::rapier::observers::metrics::MAX_PERIODS) turns in `run.end_s`.
    fn validate_periods(&self) -> Result<()> {
        let max = crate::rapier::observers::metrics::MAX_PERIODS as f64;
        if let Some(p) = self.drive_period()
            && self.run.end_s / p > max
        {
            return Err(Error::invalid(
                "run.end_s",
                format!(
                    "{} turns of the drive (one every {} s): more than {} for the per-turn \
                     statistics; shorten the run",
                    sig4(self.run.end_s / p),
                    sig4(p),
                    sig4(max)
                ),
            ));
        }
        Ok(())
    }
}
