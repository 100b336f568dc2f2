//! Torsion-spring drives on hinges, and their validation.

use super::Scene;
use super::clearance::one;
use super::limits::*;
use crate::error::{Error, Result, in_range};
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
        }
        Ok(())
    }
}
