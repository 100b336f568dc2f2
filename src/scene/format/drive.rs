//! Torsion-spring drives on hinges, and their validation.

use super::Scene;
use super::clearance::one;
use super::limits::*;
use crate::error::{Error, Result, in_range, sig4};
use crate::model::kinematics::stable_step;
use serde::{Deserialize, Serialize};

/// A torsion spring `T = scale (T0 - k theta)` on a hinge (MODEL.md §4, eq. 20).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveSpec {
    /// Unique name.
    pub name: String,
    /// The hinge it drives (torque on the journal body, reaction on the bearing body).
    pub hinge: String,
    /// Preload `T0`, N m.
    pub torque0_nm: f64,
    /// Stiffness `k`, N m/deg.
    pub stiffness_nm_per_deg: f64,
    /// Scale on both `T0` and `k` (the paper's T, 3T, 5T).
    #[serde(default = "one")]
    pub torque_scale: f64,
}

impl Scene {
    /// The drives' fields (names into `names`).
    pub(super) fn validate_drives<'a>(
        &'a self,
        names: &mut std::collections::HashSet<&'a str>,
    ) -> Result<()> {
        for d in &self.drives {
            let p = format!("drives[{}]", d.name);
            if !is_plain_name(&d.name) {
                return Err(Error::invalid(
                    p,
                    "name must be letters, digits, `_` and `-` (it prefixes CSV columns)",
                ));
            }
            if !names.insert(d.name.as_str()) {
                return Err(Error::invalid(p, "duplicate name"));
            }
            if self.hinge_index(&d.hinge).is_none() {
                return Err(Error::invalid(
                    format!("{p}.hinge"),
                    format!("no hinge named `{}`", d.hinge),
                ));
            }
            let t = TORQUE_MAX;
            in_range(&format!("{p}.torque0_nm"), d.torque0_nm, -t, t, "N m")?;
            in_range(
                &format!("{p}.stiffness_nm_per_deg"),
                d.stiffness_nm_per_deg,
                0.0,
                t,
                "N m/deg",
            )?;
            let s = TORQUE_SCALE_MAX;
            in_range(&format!("{p}.torque_scale"), d.torque_scale, -s, s, "")?;
            check_scaled_spring(&p, d)?;
        }
        Ok(())
    }

    /// Each drive's spring must be stable at the largest step (the fixed step, or the adaptive
    /// steps' bound): symplectic Euler turns a spring `k` on an inertia `I` unstable beyond
    /// `dt = 2/omega`, `omega = sqrt(k/I)` ([`stable_step`]). `I` is the hinge's two moving
    /// bodies' inertias about the hinge axis through the hinge point, in series (a fixed or
    /// driven body adds none): exact for a body pinned to the ground. Checked after the rest.
    pub(super) fn validate_drive_steps(&self) -> Result<()> {
        let (field, dt) = match self.run.step {
            crate::rapier::pipeline::stepper::StepMode::Fixed => ("run.dt_s", self.run.dt_s),
            crate::rapier::pipeline::stepper::StepMode::Adaptive => {
                ("run.max_dt_s", self.run.max_dt_s)
            }
        };
        for d in &self.drives {
            let Some(h) = self.hinges.iter().find(|h| h.name == d.hinge) else {
                continue;
            };
            let inverse: f64 = [&h.bearing, &h.journal]
                .into_iter()
                .filter_map(|b| self.bodies.iter().find(|s| &s.name == b))
                .filter(|b| !b.fixed && b.motion.is_none())
                .map(|b| 1.0 / inertia_about(b, h.point_m, h.axis))
                .sum();
            let k = (d.torque_scale * d.stiffness_nm_per_deg).abs() * 180.0 / std::f64::consts::PI;
            if !(inverse > 0.0) || !(k > 0.0) {
                continue;
            }
            let (dt_max, omega, _) = stable_step(k, 0.0, 1.0 / inverse);
            if dt > dt_max {
                return Err(Error::invalid(
                    format!("drives[{}].stiffness_nm_per_deg", d.name),
                    format!(
                        "the spring ({} N m/rad with `torque_scale`) is too stiff for the step: \
                         with the bodies' inertia about hinge `{}` ({} kg m^2) its natural \
                         frequency is {} rad/s, and the explicit step is stable only below {} s \
                         (`{field}` = {} s)",
                        sig4(k),
                        h.name,
                        sig4(1.0 / inverse),
                        sig4(omega),
                        sig4(dt_max),
                        sig4(dt)
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// Refuses a negative `torque_scale` on a spring with stiffness: the scale multiplies `k` too,
/// and a negative stiffness pushes the hinge away from rest (the run's spring would refuse it,
/// naming the stiffness the user never set). With no stiffness it only turns the preload round.
fn check_scaled_spring(p: &str, d: &DriveSpec) -> Result<()> {
    if d.torque_scale >= 0.0 || d.stiffness_nm_per_deg <= 0.0 {
        return Ok(());
    }
    Err(Error::invalid(
        format!("{p}.torque_scale"),
        format!(
            "must be 0 to {} for a spring with stiffness (got {}): it scales \
             `stiffness_nm_per_deg` ({} N m/deg) as well as `torque0_nm`, and a negative \
             stiffness would push the hinge away from rest. To turn the preload round, give \
             `torque0_nm` a negative value and keep `torque_scale` positive",
            sig4(TORQUE_SCALE_MAX),
            sig4(d.torque_scale),
            sig4(d.stiffness_nm_per_deg)
        ),
    ))
}

/// The moment of inertia of body `b` about the axis `axis` (unit) through `point`: its
/// principal moments (along the world axes at t = 0) projected on the axis, plus its mass times
/// the square of its centre of mass's distance from the axis.
fn inertia_about(b: &super::BodySpec, point: [f64; 3], axis: [f64; 3]) -> f64 {
    let j = b.inertia_kg_m2;
    let own = (0..3).map(|i| axis[i] * axis[i] * j[i]).sum::<f64>();
    let r: [f64; 3] = std::array::from_fn(|i| b.center_of_mass_m[i] - point[i]);
    let along = (0..3).map(|i| r[i] * axis[i]).sum::<f64>();
    let d2 = (0..3).map(|i| r[i] * r[i]).sum::<f64>() - along * along;
    own + b.mass_kg * d2.max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A negative scale on a spring with stiffness is refused naming `torque_scale`, the field
    /// given, with the range to use; without stiffness it only turns the preload round.
    #[test]
    fn a_negative_torque_scale_names_itself() {
        let e = Scene::solar_panel()
            .with_overrides(&["drive.torque_scale=-5"])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("drives[drive].torque_scale")
                && e.contains("0 to 1000")
                && e.contains("got -5")
                && !e.contains("drives[drive].stiffness_nm_per_deg"),
            "{e}"
        );
        Scene::solar_panel()
            .with_overrides(&["drive.stiffness_nm_per_deg=0", "drive.torque_scale=-1"])
            .unwrap();
    }
}
