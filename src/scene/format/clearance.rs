//! The clearance spec: geometry, materials, contact and friction laws, converted to SI laws.

use super::limits::*;
use crate::error::{Error, Result, in_range, positive, sig4};
use crate::model::laws::{
    Ambrosio, Bai, BearingGeometry, Coulomb, DELTA_MAX_RANGE, EXPONENT_RANGE, FloresEtAl,
    FrictionModel, GonthierEtAl, Hertz, HuntCrossley, ImprovedLiu, KelvinVoigt, LankaraniNikravesh,
    LiuEtAl, Material, MaxDamping, NormalModel, Threlfall, effective_modulus,
};
use crate::model::spatial::{FaceLaw, SpatialGeometry, SpatialModel};
use crate::rapier::hinge::design::{ClearanceModel, HingeDesign};
use crate::rapier::joint::OutOfPlaneLock;
use serde::{Deserialize, Serialize};

/// Geometry, materials and laws of a clearance joint (MODEL.md §1-3, table 2 of the paper).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClearanceSpec {
    /// Bearing (hole) diameter, mm.
    pub bearing_diameter_mm: f64,
    /// Radial clearance `c = R_b - R_j`, mm.
    pub clearance_mm: f64,
    /// Axial length (bearing width) `L`, mm.
    pub width_mm: f64,
    /// Bearing material.
    pub bearing_material: Material,
    /// Journal material.
    pub journal_material: Material,
    /// Normal contact law.
    pub contact: ContactSpec,
    /// Friction law.
    #[serde(default)]
    pub friction: FrictionSpec,
    /// Floor on the impact velocity of the hysteresis laws, mm/s.
    #[serde(default = "default_min_impact_speed")]
    pub min_impact_speed_mm_s: f64,
    /// Gap a free flight must open for the next contact to count as an impact, um (default 0.1).
    #[serde(default = "default_min_separation")]
    pub min_separation_um: f64,
    /// The deepest penetration at which the contact law is trusted, um: a deeper contact is a
    /// guard violation (default `None`: 1 % of the journal radius, see docs/MODEL.md
    /// "Validity").
    #[serde(default)]
    pub max_valid_penetration_um: Option<f64>,
    /// What holds the out-of-plane degrees of freedom.
    #[serde(default)]
    pub lock: OutOfPlaneLock,
    /// Which model solves the hinge: `Compliant` (the default: the contact law as a force, the
    /// paper's model), `LargeStep` (the radial limit inside Rapier's solver, for 1/60 s and
    /// 1 kHz worlds) or `Spatial(..)` (the compliant joint in space: tilt, edge contact, axial
    /// play and thrust faces). See docs/scene-format.md.
    #[serde(default, skip_serializing_if = "is_compliant")]
    pub model: ModelSpec,
    /// The large-step model's coefficient of restitution, in [0, 1] (default `None`: the contact
    /// law's own restitution at each impact). Only the large-step model takes it: the compliant
    /// model's restitution is its contact law's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restitution: Option<f64>,
}

fn is_compliant(model: &ModelSpec) -> bool {
    *model == ModelSpec::Compliant
}

/// Which model solves a clearance hinge ([`ClearanceModel`] in the scene's words: the spatial
/// model's face law and slice count may be left out).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum ModelSpec {
    /// The compliant contact-law joint, planar (the paper's model).
    #[default]
    Compliant,
    /// The large-step joint (the radial limit inside Rapier's solver).
    LargeStep,
    /// The spatial compliant joint ([`crate::model::spatial`]): nothing locked, the journal
    /// tilts and slides axially.
    Spatial(SpatialSpec),
}

/// The spatial model's settings, lengths in metres as the plain API's
/// [`SpatialModel`](crate::model::spatial::SpatialModel).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpatialSpec {
    /// Axial play and shoulders.
    pub geometry: SpatialGeometrySpec,
    /// The shoulders' law against the bearing's faces; default (left out): a flat punch of the
    /// collar's radius on the hinge's materials ([`FaceLaw::flat_punch`], restitution
    /// [`FaceLaw::DEFAULT_RESTITUTION`]).
    #[serde(
        default,
        deserialize_with = "present",
        skip_serializing_if = "Option::is_none"
    )]
    pub face: Option<FaceSpec>,
}

/// The spatial geometry along the axis ([`SpatialGeometry`]), m.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpatialGeometrySpec {
    /// Axial play `a`: the journal's free axial travel when centred, m (> 0, at most the
    /// bearing's width).
    pub axial_play: f64,
    /// Outer radius of the journal's shoulders (collars), m (above the journal radius, at most
    /// ten bearing radii).
    pub collar_radius: f64,
}

/// The face law ([`FaceLaw`]): a linear spring with Flores et al.'s hysteresis damping.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FaceSpec {
    /// Axial stiffness of one shoulder against its face, N/m.
    pub stiffness: f64,
    /// Coefficient of restitution of a face knock, in (0, 1].
    pub restitution: f64,
}

/// An optional field written as its value (`face: (..)`, not `face: Some((..))`).
fn present<'de, D: serde::Deserializer<'de>, T: Deserialize<'de>>(
    d: D,
) -> std::result::Result<Option<T>, D::Error> {
    T::deserialize(d).map(Some)
}

impl SpatialSpec {
    /// The [`SpatialModel`] these settings describe for the radial geometry `radial` between
    /// the two materials, validated (errors name `model.geometry.<field>` and
    /// `model.face.<field>`).
    fn model(
        &self,
        radial: &BearingGeometry,
        bearing: &Material,
        journal: &Material,
    ) -> Result<SpatialModel> {
        let g = &self.geometry;
        let geometry = SpatialGeometry {
            axial_play: g.axial_play,
            collar_radius: g.collar_radius,
        };
        geometry.validate(radial).map_err_within("model.geometry")?;
        let face = match self.face {
            Some(f) => FaceLaw {
                stiffness: f.stiffness,
                restitution: f.restitution,
            },
            None => FaceLaw::flat_punch(
                effective_modulus(bearing, journal),
                g.collar_radius,
                FaceLaw::DEFAULT_RESTITUTION,
            ),
        };
        let model = SpatialModel { geometry, face };
        model.validate(radial).map_err_within("model")?;
        Ok(model)
    }
}

fn default_min_impact_speed() -> f64 {
    crate::rapier::joint::DEFAULT_MIN_IMPACT_SPEED * 1e3
}
fn default_min_separation() -> f64 {
    crate::rapier::joint::DEFAULT_MIN_SEPARATION * 1e6
}

/// Normal contact law by name (MODEL.md §2). Stiffness `None` means the Lankarani-Nikravesh
/// geometric stiffness from the joint's radii and materials.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum ContactSpec {
    /// `K delta^n`.
    Hertz {
        /// `K`, N/m^n (default: geometric).
        #[serde(default)]
        stiffness: Option<f64>,
        /// `n` (default 1.5).
        #[serde(default = "default_exponent")]
        exponent: f64,
    },
    /// `K delta + D delta_dot`.
    KelvinVoigt {
        /// `K`, N/m.
        stiffness: f64,
        /// `D`, N s/m.
        damping: f64,
    },
    /// Hunt-Crossley.
    HuntCrossley {
        /// `K` (default: geometric).
        #[serde(default)]
        stiffness: Option<f64>,
        /// `n` (default 1.5).
        #[serde(default = "default_exponent")]
        exponent: f64,
        /// `cr`.
        restitution: f64,
    },
    /// Lankarani-Nikravesh (n = 1.5).
    LankaraniNikravesh {
        /// `K` (default: geometric).
        #[serde(default)]
        stiffness: Option<f64>,
        /// `cr`.
        restitution: f64,
    },
    /// Flores et al. 2011.
    FloresEtAl {
        /// `K` (default: geometric).
        #[serde(default)]
        stiffness: Option<f64>,
        /// `n` (default 1.5).
        #[serde(default = "default_exponent")]
        exponent: f64,
        /// `cr`.
        restitution: f64,
    },
    /// Gonthier et al. 2004.
    GonthierEtAl {
        /// `K` (default: geometric).
        #[serde(default)]
        stiffness: Option<f64>,
        /// `n` (default 1.5).
        #[serde(default = "default_exponent")]
        exponent: f64,
        /// `cr`.
        restitution: f64,
    },
    /// Liu et al. 2007 (elastic, cylindrical).
    LiuEtAl,
    /// The paper's improved law.
    ImprovedLiu {
        /// Material exponent `n` (default 1: the paper gives none; n = 1 is Liu's elastic law).
        #[serde(default = "one")]
        exponent: f64,
        /// Damping saturation depth, mm (default 0.1).
        #[serde(default = "default_delta_max_mm")]
        delta_max_mm: f64,
        /// `eta`, s (default 0.01, the paper's "1 %"); ignored when `d_max_n_s_per_m` is given.
        #[serde(default = "default_eta")]
        eta_s: f64,
        /// Explicit maximum damping, N s/m.
        #[serde(default)]
        d_max_n_s_per_m: Option<f64>,
    },
}

fn default_exponent() -> f64 {
    1.5
}
pub(super) fn one() -> f64 {
    1.0
}
fn default_delta_max_mm() -> f64 {
    0.1
}
fn default_eta() -> f64 {
    ImprovedLiu::DEFAULT_ETA
}

/// Friction law by name (MODEL.md §3). Speeds in mm/s.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum FrictionSpec {
    /// No friction.
    #[default]
    None,
    /// Regularised Coulomb.
    Coulomb {
        /// `mu_d`.
        mu_d: f64,
        /// `v_eps`, mm/s.
        v_eps_mm_s: f64,
    },
    /// Threlfall.
    Threlfall {
        /// `mu_d`.
        mu_d: f64,
        /// `v_0`, mm/s.
        v0_mm_s: f64,
    },
    /// Ambrosio.
    Ambrosio {
        /// `mu_d`.
        mu_d: f64,
        /// `v_0`, mm/s.
        v0_mm_s: f64,
        /// `v_1`, mm/s.
        v1_mm_s: f64,
    },
    /// Bai / Adams stiction.
    Bai {
        /// `mu_s`.
        mu_s: f64,
        /// `mu_d`.
        mu_d: f64,
        /// `v_s`, mm/s.
        v_s_mm_s: f64,
        /// `v_d`, mm/s.
        v_d_mm_s: f64,
    },
    /// Bai with the paper's dry coefficients (table 3).
    Dry,
    /// Bai with the paper's lubricated coefficients (table 3).
    Lubricated,
}

impl ClearanceSpec {
    /// The [`HingeDesign`] this spec describes, in SI units, validated (errors name the field
    /// relative to this spec, e.g. `contact.eta_s`): geometry, laws, impact-speed floor, impact
    /// separation, validity limit, lock, model and restitution. The hinge's name is the
    /// caller's to set ([`HingeDesign::name`]).
    pub fn clearance(&self) -> Result<HingeDesign> {
        let geometry = self.geometry()?;
        let normal = self.normal_law(&geometry)?;
        let friction = self.friction_law()?;
        let mm = 1e-3;
        let min_impact_speed =
            speed_mm_s("min_impact_speed_mm_s", self.min_impact_speed_mm_s)? * mm;
        let min_separation =
            in_range("min_separation_um", self.min_separation_um, 0.0, 1e4, "um")? * 1e-6;
        let model = match &self.model {
            ModelSpec::Compliant => ClearanceModel::Compliant,
            ModelSpec::LargeStep => ClearanceModel::LargeStep,
            ModelSpec::Spatial(spec) => ClearanceModel::Spatial(spec.model(
                &geometry,
                &self.bearing_material,
                &self.journal_material,
            )?),
        };
        let mut clearance = HingeDesign::new(geometry, normal)
            .friction(friction)
            .min_impact_speed(min_impact_speed)
            .min_separation(min_separation)
            .lock(self.lock)
            .model(model);
        if let Some(depth) = self.max_valid_penetration(&geometry)? {
            clearance = clearance.max_valid_penetration(depth);
        }
        if let Some(e) = self.restitution {
            if self.model != ModelSpec::LargeStep {
                return Err(Error::invalid(
                    "restitution",
                    "only the large-step model takes a restitution (`model: LargeStep`): the \
                     compliant model's restitution is its contact law's",
                ));
            }
            clearance = clearance.restitution(in_range("restitution", e, 0.0, 1.0, "")?);
        }
        Ok(clearance)
    }

    /// The radial geometry (SI), validated.
    fn geometry(&self) -> Result<BearingGeometry> {
        let (lo, hi) = LENGTH_MM_RANGE;
        let c = positive("clearance_mm", self.clearance_mm)? * 1e-3;
        in_range(
            "clearance_mm",
            self.clearance_mm,
            CLEARANCE_MM_RANGE.0,
            CLEARANCE_MM_RANGE.1,
            "mm",
        )?;
        let rb = in_range(
            "bearing_diameter_mm",
            self.bearing_diameter_mm,
            lo,
            hi,
            "mm",
        )? * 0.5e-3;
        let len = in_range("width_mm", self.width_mm, lo, hi, "mm")? * 1e-3;
        if c >= rb {
            return Err(Error::invalid(
                "clearance_mm",
                format!(
                    "the journal would be larger than nothing: clearance {} mm >= bearing radius {} mm",
                    sig4(self.clearance_mm),
                    sig4(rb * 1e3)
                ),
            ));
        }
        BearingGeometry::from_clearance(rb, c, len)
    }

    /// The normal law (SI) and the materials, validated; errors name `contact.<field>`.
    fn normal_law(&self, geometry: &BearingGeometry) -> Result<NormalModel> {
        // The law's clearance as the spec gives it (the geometry's `R_b - (R_b - c)` may differ
        // in the last bit; the joint checks that the two agree).
        let (c, len) = (self.clearance_mm * 1e-3, geometry.length());
        self.bearing_material
            .validate()
            .map_err(|e| e.within("bearing_material"))?;
        self.journal_material
            .validate()
            .map_err(|e| e.within("journal_material"))?;
        let e_star = effective_modulus(&self.bearing_material, &self.journal_material);
        let geometric = LankaraniNikravesh::stiffness_from_geometry(
            geometry,
            &self.bearing_material,
            &self.journal_material,
        );
        // The geometric stiffness is Lankarani-Nikravesh's, in N/m^1.5: a default only for n = 1.5.
        let k_n = |s: &Option<f64>, n: f64| -> Result<f64> {
            // The exponent first: a NaN or absurd exponent is the fault, not the missing stiffness.
            in_range("exponent", n, EXPONENT_RANGE.0, EXPONENT_RANGE.1, "")?;
            match s {
                Some(k) => Ok(*k),
                None if n == LankaraniNikravesh::EXPONENT => Ok(geometric),
                None => Err(Error::invalid(
                    "stiffness",
                    format!(
                        "must be given for exponent {}: the default (the Lankarani-Nikravesh geometric stiffness) \
                         is in N/m^1.5 and holds only for exponent 1.5",
                        sig4(n)
                    ),
                )),
            }
        };
        (|| -> Result<NormalModel> {
            Ok(match &self.contact {
                ContactSpec::Hertz {
                    stiffness,
                    exponent,
                } => NormalModel::Hertz(Hertz::new(k_n(stiffness, *exponent)?, *exponent)?),
                ContactSpec::KelvinVoigt { stiffness, damping } => {
                    NormalModel::KelvinVoigt(KelvinVoigt::new(*stiffness, *damping)?)
                }
                ContactSpec::HuntCrossley {
                    stiffness,
                    exponent,
                    restitution,
                } => NormalModel::HuntCrossley(HuntCrossley::new(
                    k_n(stiffness, *exponent)?,
                    *exponent,
                    *restitution,
                )?),
                ContactSpec::LankaraniNikravesh {
                    stiffness,
                    restitution,
                } => NormalModel::LankaraniNikravesh(LankaraniNikravesh::new(
                    k_n(stiffness, LankaraniNikravesh::EXPONENT)?,
                    LankaraniNikravesh::EXPONENT,
                    *restitution,
                )?),
                ContactSpec::FloresEtAl {
                    stiffness,
                    exponent,
                    restitution,
                } => NormalModel::FloresEtAl(FloresEtAl::new(
                    k_n(stiffness, *exponent)?,
                    *exponent,
                    *restitution,
                )?),
                ContactSpec::GonthierEtAl {
                    stiffness,
                    exponent,
                    restitution,
                } => NormalModel::GonthierEtAl(GonthierEtAl::new(
                    k_n(stiffness, *exponent)?,
                    *exponent,
                    *restitution,
                )?),
                ContactSpec::LiuEtAl => NormalModel::LiuEtAl(LiuEtAl::new(e_star, len, c)?),
                ContactSpec::ImprovedLiu {
                    exponent,
                    delta_max_mm,
                    eta_s,
                    d_max_n_s_per_m,
                } => {
                    let damping = match d_max_n_s_per_m {
                        Some(d) => MaxDamping::Explicit(*d),
                        None => MaxDamping::Eta(*eta_s),
                    };
                    NormalModel::ImprovedLiu(ImprovedLiu::new(
                        e_star,
                        len,
                        c,
                        *exponent,
                        in_range(
                            "delta_max_mm",
                            *delta_max_mm,
                            DELTA_MAX_RANGE.0 * 1e3,
                            DELTA_MAX_RANGE.1 * 1e3,
                            "mm",
                        )? * 1e-3,
                        damping,
                    )?)
                }
            })
        })()
        .map_err_within("contact")
    }

    /// The friction law (SI), validated; errors name `friction.<field>`.
    fn friction_law(&self) -> Result<FrictionModel> {
        let mm = 1e-3;
        (|| -> Result<FrictionModel> {
            Ok(match &self.friction {
                FrictionSpec::None => FrictionModel::None,
                FrictionSpec::Coulomb { mu_d, v_eps_mm_s } => {
                    speed_mm_s("v_eps_mm_s", *v_eps_mm_s)?;
                    FrictionModel::Coulomb(Coulomb::new(*mu_d, v_eps_mm_s * mm)?)
                }
                FrictionSpec::Threlfall { mu_d, v0_mm_s } => {
                    speed_mm_s("v0_mm_s", *v0_mm_s)?;
                    FrictionModel::Threlfall(Threlfall::new(*mu_d, v0_mm_s * mm)?)
                }
                FrictionSpec::Ambrosio {
                    mu_d,
                    v0_mm_s,
                    v1_mm_s,
                } => {
                    in_range("v0_mm_s", *v0_mm_s, 0.0, SPEED_MM_S_RANGE.1, "mm/s")?;
                    speed_mm_s("v1_mm_s", *v1_mm_s)?;
                    greater("v1_mm_s", *v1_mm_s, "v0_mm_s", *v0_mm_s)?;
                    FrictionModel::Ambrosio(Ambrosio::new(*mu_d, v0_mm_s * mm, v1_mm_s * mm)?)
                }
                FrictionSpec::Bai {
                    mu_s,
                    mu_d,
                    v_s_mm_s,
                    v_d_mm_s,
                } => {
                    speed_mm_s("v_s_mm_s", *v_s_mm_s)?;
                    speed_mm_s("v_d_mm_s", *v_d_mm_s)?;
                    greater("v_d_mm_s", *v_d_mm_s, "v_s_mm_s", *v_s_mm_s)?;
                    FrictionModel::Bai(Bai::new(*mu_s, *mu_d, v_s_mm_s * mm, v_d_mm_s * mm)?)
                }
                FrictionSpec::Dry => FrictionModel::Bai(Bai::DRY),
                FrictionSpec::Lubricated => FrictionModel::Bai(Bai::LUBRICATED),
            })
        })()
        .map_err_within("friction")
    }

    /// The validity limit of the penetration, m (`None`: the joint's default), validated
    /// against the journal radius; the error speaks the scene's unit.
    fn max_valid_penetration(&self, geometry: &BearingGeometry) -> Result<Option<f64>> {
        self.max_valid_penetration_um
            .map(|um| {
                crate::rapier::joint::validate_max_valid_penetration(
                    "max_valid_penetration_um",
                    um * 1e-6,
                    geometry,
                )
            })
            .transpose()
            .map_err(|e| match e {
                // The scene's unit: micrometres.
                Error::Invalid { field, .. } => Error::invalid(
                    field,
                    format!(
                        "must be positive, finite and at most the journal radius {} um (got {}); \
                         default {} um, 1 % of the journal radius",
                        sig4(geometry.journal_radius() * 1e6),
                        sig4(self.max_valid_penetration_um.unwrap_or(f64::NAN)),
                        sig4(crate::rapier::joint::default_max_valid_penetration(geometry) * 1e6)
                    ),
                ),
                other => other,
            })
    }
}

trait WithinExt<T> {
    fn map_err_within(self, prefix: &str) -> Result<T>;
}
impl<T> WithinExt<T> for Result<T> {
    fn map_err_within(self, prefix: &str) -> Result<T> {
        self.map_err(|e| e.within(prefix))
    }
}

/// A transition speed `field` (mm/s) must exceed the one before it, `lower` (in the scene's
/// fields and unit: the law checks the same in m/s under its own names).
fn greater(field: &str, value: f64, lower: &str, bound: f64) -> Result<()> {
    if value <= bound {
        return Err(Error::invalid(
            field,
            format!(
                "must be greater than `{lower}` = {} mm/s (got {} mm/s)",
                crate::error::sig4(bound),
                crate::error::sig4(value)
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests;
