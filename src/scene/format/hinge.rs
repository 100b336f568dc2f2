//! Hinges (ideal or with a clearance), their validation, the planar model's limits, warnings.

use super::limits::*;
use super::{ClearanceSpec, FrictionSpec, ModelSpec, Scene};
use crate::error::{Error, Result, sig4};
use crate::rapier::hinge::design::HingeDesign;
use crate::rapier::joint::OutOfPlaneLock;
use rapier3d_f64::math::Vector;
use serde::{Deserialize, Serialize};

/// A hinge: ideal (Rapier revolute joint) unless `clearance` is given.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HingeSpec {
    /// Unique name (CSV column prefix).
    pub name: String,
    /// Body carrying the bearing (hole).
    pub bearing: String,
    /// Body carrying the journal (pin).
    pub journal: String,
    /// World position of the hinge (bearing and journal centre) at t = 0, m.
    pub point_m: [f64; 3],
    /// Hinge axis (world, t = 0); positive rotation of the journal body about it is positive angle.
    pub axis: [f64; 3],
    /// Radial play; `None` makes the hinge ideal in both twins.
    #[serde(default)]
    pub clearance: Option<ClearanceSpec>,
    /// Where the journal's centre starts from the bearing's (`point_m`) in the clearance twin,
    /// world, mm (default centred): within the radial clearance, and along the axis only for a
    /// spatial hinge (within half its axial play). The journal body's anchor follows: place its
    /// centre of mass accordingly. The ideal twin's hinge has no play and starts at `point_m`.
    #[serde(default, skip_serializing_if = "is_centred")]
    pub journal_offset_mm: [f64; 3],
}

fn is_centred(offset: &[f64; 3]) -> bool {
    *offset == [0.0; 3]
}

impl HingeSpec {
    /// Whether the hinge's clearance uses the spatial model.
    pub fn is_spatial(&self) -> bool {
        matches!(
            self.clearance.as_ref().map(|c| &c.model),
            Some(ModelSpec::Spatial(_))
        )
    }
}

impl Scene {
    /// The hinges' fields and clearance specs (names into `names`): each hinge's [`HingeDesign`]
    /// (named after the hinge), `None` for an ideal hinge.
    pub(super) fn validate_hinges<'a>(
        &'a self,
        names: &mut std::collections::HashSet<&'a str>,
    ) -> Result<Vec<Option<HingeDesign>>> {
        let mut clearances = Vec::with_capacity(self.hinges.len());
        for h in &self.hinges {
            let p = format!("hinges[{}]", h.name);
            if !is_plain_name(&h.name) {
                return Err(Error::invalid(
                    p,
                    "name must be letters, digits, `_` and `-` (it prefixes CSV columns)",
                ));
            }
            if !names.insert(h.name.as_str()) {
                return Err(Error::invalid(
                    p,
                    "duplicate name (bodies, hinges and drives share one namespace)",
                ));
            }
            for (field, body) in [("bearing", &h.bearing), ("journal", &h.journal)] {
                if self.body_index(body).is_none() {
                    return Err(Error::invalid(
                        format!("{p}.{field}"),
                        format!("no body named `{body}`"),
                    ));
                }
            }
            if h.bearing == h.journal {
                return Err(Error::invalid(
                    format!("{p}.journal"),
                    "must differ from the bearing body",
                ));
            }
            for (i, x) in h.point_m.iter().enumerate() {
                position(&format!("{p}.point_m[{i}]"), *x)?;
            }
            unit(&h.axis, &format!("{p}.axis"))?;
            let clearance = match &h.clearance {
                Some(c) => Some(Self::hinge_clearance(c, &p)?.name(h.name.clone())),
                None => None,
            };
            journal_offset(h, clearance.as_ref(), &p)?;
            clearances.push(clearance);
        }
        Ok(clearances)
    }

    /// The [`HingeDesign`] of the hinge at path `p`, its errors under `p.clearance`.
    fn hinge_clearance(c: &ClearanceSpec, p: &str) -> Result<HingeDesign> {
        let clearance = c
            .clearance()
            .map_err(|e| e.within(&format!("{p}.clearance")))?;
        if c.lock == OutOfPlaneLock::None && !matches!(c.model, ModelSpec::Spatial(_)) {
            return Err(Error::invalid(
                format!("{p}.clearance.lock"),
                "`None` leaves the axial translation and the tilts free, and a scene has no locked axes to \
                 hold them: use `Joint` (plain-API users may lock the bodies' axes themselves)",
            ));
        }
        Ok(clearance)
    }
}

/// The journal's starting offset of hinge `h` (at path `p`) with its clearance settings: finite,
/// only on a clearance hinge, radially within the clearance, axially only on a spatial hinge and
/// within half its axial play.
fn journal_offset(h: &HingeSpec, clearance: Option<&HingeDesign>, p: &str) -> Result<()> {
    let field = format!("{p}.journal_offset_mm");
    for (i, x) in h.journal_offset_mm.iter().enumerate() {
        crate::error::finite(&format!("{field}[{i}]"), *x)?;
    }
    if is_centred(&h.journal_offset_mm) {
        return Ok(());
    }
    let Some(c) = clearance else {
        return Err(Error::invalid(
            field,
            "only a clearance hinge has play to start off-centre in: give the hinge a clearance or \
             leave this out",
        ));
    };
    let offset = Vector::from(h.journal_offset_mm) * 1e-3;
    let axis = Vector::from(h.axis).normalize();
    let axial = offset.dot(axis);
    let radial = (offset - axial * axis).length();
    let gap = c.geometry.clearance();
    if radial > gap {
        return Err(Error::invalid(
            field,
            format!(
                "its part across the axis, {} mm, exceeds the radial clearance {} mm: the journal \
                 would start inside the bearing",
                sig4(radial * 1e3),
                sig4(gap * 1e3)
            ),
        ));
    }
    let play = match c.model {
        crate::rapier::hinge::design::ClearanceModel::Spatial(m) => m.geometry.axial_play,
        _ => 0.0,
    };
    if axial.abs() > 0.5 * play * (1.0 + 1e-12) {
        return Err(Error::invalid(
            field,
            if play == 0.0 {
                format!(
                    "has a part along the axis ({} mm): only the spatial model \
                     (`clearance.model: Spatial(..)`) has axial play",
                    sig4(axial * 1e3)
                )
            } else {
                format!(
                    "its part along the axis, {} mm, exceeds half the axial play, {} mm: a \
                     shoulder would start inside its face",
                    sig4(axial * 1e3),
                    sig4(0.5 * play * 1e3)
                )
            },
        ));
    }
    Ok(())
}

impl Scene {
    /// Settings that are valid but probably not what was meant, each naming its field (the CLI
    /// prints them as warnings before running).
    pub fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        for h in &self.hinges {
            let Some(c) = &h.clearance else { continue };
            if let FrictionSpec::Bai { mu_s, mu_d, .. } = c.friction
                && mu_s < mu_d
            {
                out.push(format!(
                    "`hinges[{}].clearance.friction`: Bai with mu_s = {} below mu_d = {} is not stiction \
                     (the coefficient rises from mu_s to mu_d as the journal slips faster); swap them if \
                     stiction was meant",
                    h.name,
                    sig4(mu_s),
                    sig4(mu_d)
                ));
            }
        }
        out
    }

    /// The clearance model is planar (MODEL.md §4): contact and friction act in the plane normal
    /// to each clearance hinge's axis, and the out-of-plane degrees of freedom are held rigidly.
    /// A scene whose loads would act out of that plane is refused, naming what cannot be represented.
    pub(super) fn validate_planar(&self) -> Result<()> {
        let a_ref = Vector::from(self.reference_axis);
        let g = Vector::from(self.gravity);
        // A spatial hinge carries axial loads and moments across its axis through contact.
        for h in self
            .hinges
            .iter()
            .filter(|h| h.clearance.is_some() && !h.is_spatial())
        {
            let p = format!("hinges[{}]", h.name);
            let a = Vector::from(h.axis).normalize();
            if a.cross(a_ref).length() > 1e-9 {
                return Err(Error::invalid(
                    format!("{p}.axis"),
                    "a clearance hinge must be parallel to the scene's reference_axis: the planar clearance \
                     model has no axial or tilting contact, so non-parallel hinges (out-of-plane motion) \
                     cannot be represented; make this hinge ideal, align it, or make it spatial \
                     (`clearance.model: Spatial(..)`)",
                ));
            }
            if g.dot(a).abs() > 1e-9 * g.length().max(1e-300) && g.length() > 0.0 {
                return Err(Error::invalid(
                    "gravity",
                    format!(
                        "has a component along the axis of clearance hinge `{}`: an axial (out-of-plane) load, \
                         which the planar clearance model cannot carry through contact; put gravity in the \
                         hinge plane, make the hinge ideal, or make it spatial (`clearance.model: Spatial(..)`)",
                        h.name
                    ),
                ));
            }
        }
        Ok(())
    }
}
