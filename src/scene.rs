//! Scenes as data (RON): bodies, hinges (ideal or with clearance), drives and run settings.
//! Every value is validated with an error naming its path, e.g. `hinges[hinge].clearance.clearance_mm`.

use crate::error::{Error, Result, finite, non_negative, positive};
use crate::joint::OutOfPlaneLock;
use crate::laws::{
    Ambrosio, Bai, BearingGeometry, Coulomb, FloresEtAl, FrictionModel, GonthierEtAl, Hertz,
    HuntCrossley, ImprovedLiu, KelvinVoigt, LankaraniNikravesh, LiuEtAl, Material, MaxDamping,
    NormalModel, Threlfall, effective_modulus,
};
use rapier3d_f64::math::Vector;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The paper's scene (MODEL.md §4), embedded in the binary.
pub const SOLAR_PANEL_RON: &str = include_str!("../assets/solar_panel.ron");

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
    /// Torsion-spring drives on hinges.
    #[serde(default)]
    pub drives: Vec<DriveSpec>,
    /// Time stepping and output.
    #[serde(default)]
    pub run: RunSettings,
}

/// A rigid body with principal axes along the world axes at t = 0, at rest.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Unique name (CSV column prefix).
    pub name: String,
    /// Mass, kg.
    pub mass_kg: f64,
    /// Principal moments of inertia about the centre of mass (Jx, Jy, Jz), kg m^2.
    pub inertia_kg_m2: [f64; 3],
    /// World position of the centre of mass at t = 0, m.
    pub center_of_mass_m: [f64; 3],
    /// A fixed body (ground): it does not move; mass and inertia are then ignored.
    #[serde(default)]
    pub fixed: bool,
}

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
}

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
    /// What holds the out-of-plane degrees of freedom.
    #[serde(default)]
    pub lock: OutOfPlaneLock,
}

fn default_min_impact_speed() -> f64 {
    crate::joint::DEFAULT_MIN_IMPACT_SPEED * 1e3
}
fn default_min_separation() -> f64 {
    crate::joint::DEFAULT_MIN_SEPARATION * 1e6
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
fn one() -> f64 {
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

/// Time stepping and output.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunSettings {
    /// Fixed steps: the step, s (default 1e-4, the paper's).
    #[serde(default = "default_dt")]
    pub dt_s: f64,
    /// Adaptive steps: the largest step, s (default 1e-3). Free flight is second order in the
    /// step (variable-step Störmer-Verlet), so it needs no smaller step; contacts are approached
    /// and resolved by the step control whatever this is.
    #[serde(default = "default_max_dt")]
    pub max_dt_s: f64,
    /// Simulated time, s.
    #[serde(default = "default_end")]
    pub end_s: f64,
    /// Interval between CSV rows, s: a row is the first state at or after each multiple of it
    /// (with fixed steps, every `round(interval/dt)`-th step). Rows never change the steps: the
    /// physics does not depend on the output interval.
    #[serde(default = "default_dt")]
    pub output_interval_s: f64,
    /// How the step is chosen.
    #[serde(default)]
    pub step: StepMode,
    /// Adaptive steps: the fraction of a contact's natural period `2 pi/omega` one step may cover.
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    /// Whether a guard violation (a penetration beyond the law's validity, energy gained, steps
    /// at the floor) fails the run instead of being reported (`--strict`).
    #[serde(default)]
    pub strict: bool,
}

pub use crate::stepper::StepMode;

fn default_tolerance() -> f64 {
    0.0075
}

fn default_max_dt() -> f64 {
    1e-3
}

fn default_dt() -> f64 {
    1e-4
}
fn default_end() -> f64 {
    5.0
}

impl RunSettings {
    /// The stepper's control for these settings.
    pub fn step_control(&self) -> crate::stepper::StepControl {
        let c = match self.step {
            StepMode::Fixed => crate::stepper::StepControl::fixed(self.dt_s),
            StepMode::Adaptive => {
                crate::stepper::StepControl::adaptive(self.max_dt_s, self.tolerance)
            }
        };
        c.strict(self.strict)
    }

    /// The step control in words, e.g. "adaptive steps of at most 1e-4 s (tolerance 0.02 of a
    /// contact period)".
    pub fn stepping(&self) -> String {
        match self.step {
            StepMode::Fixed => format!("fixed step {:e} s", self.dt_s),
            StepMode::Adaptive => format!(
                "adaptive steps of at most {:e} s (tolerance {} of a contact period)",
                self.max_dt_s, self.tolerance
            ),
        }
    }
}

impl Default for RunSettings {
    fn default() -> Self {
        RunSettings {
            dt_s: default_dt(),
            max_dt_s: default_max_dt(),
            end_s: default_end(),
            output_interval_s: default_dt(),
            step: StepMode::default(),
            tolerance: default_tolerance(),
            strict: false,
        }
    }
}

impl Scene {
    /// Parses a scene from RON text; `origin` names the source in errors.
    pub fn from_ron(text: &str, origin: &str) -> Result<Scene> {
        let scene: Scene = ron::from_str(text).map_err(|e| Error::Parse {
            what: origin.to_string(),
            reason: e.to_string(),
        })?;
        scene.validate()?;
        Ok(scene)
    }

    /// Reads and parses a scene file.
    pub fn load(path: &Path) -> Result<Scene> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            action: "cannot read scene",
            path: path.into(),
            source,
        })?;
        Self::from_ron(&text, &path.display().to_string())
    }

    /// The paper's scene (MODEL.md §4).
    pub fn solar_panel() -> Scene {
        Self::from_ron(SOLAR_PANEL_RON, "assets/solar_panel.ron")
            .expect("the embedded scene is valid")
    }

    /// The scene as RON text.
    pub fn to_ron(&self) -> String {
        ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default()).unwrap_or_default()
    }

    /// Applies `path=value` overrides. The first segment of `path` is a top-level field (`run`,
    /// `gravity`, ...) or the name of a body, hinge or drive; the following segments are fields,
    /// found at any depth below when unique (`hinge.clearance_mm` is
    /// `hinges[hinge].clearance.clearance_mm`). The value is JSON (`0.25`, `[0,0,-9.81]`,
    /// `{"HuntCrossley":{"restitution":0.9}}`) or else a bare word (`Lubricated`).
    pub fn with_overrides<S: AsRef<str>>(&self, overrides: &[S]) -> Result<Scene> {
        if overrides.is_empty() {
            return Ok(self.clone());
        }
        let mut value =
            serde_json::to_value(self).map_err(|e| Error::invalid("scene", e.to_string()))?;
        for o in overrides {
            let o = o.as_ref();
            let (path, raw) = o.split_once('=').ok_or_else(|| Error::Parse {
                what: format!("override `{o}`"),
                reason: "expected `path=value`".into(),
            })?;
            let new: serde_json::Value = serde_json::from_str(raw.trim())
                .unwrap_or_else(|_| serde_json::Value::String(raw.trim().to_string()));
            let slot = locate(&mut value, path.trim())?;
            *slot = new;
        }
        let scene: Scene = serde_json::from_value(value).map_err(|e| Error::Parse {
            what: format!(
                "overrides {:?}",
                overrides.iter().map(|s| s.as_ref()).collect::<Vec<_>>()
            ),
            reason: e.to_string(),
        })?;
        scene.validate()?;
        Ok(scene)
    }

    /// Index of the body called `name`.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// Index of the hinge called `name`.
    pub fn hinge_index(&self, name: &str) -> Option<usize> {
        self.hinges.iter().position(|h| h.name == name)
    }

    /// Checks every field; the error names the first invalid one.
    pub fn validate(&self) -> Result<()> {
        if !is_plain_name(&self.name) {
            return Err(Error::invalid(
                "name",
                "must be a plain name: letters, digits, `_` and `-` (it names the output folder)",
            ));
        }
        for (i, g) in self.gravity.iter().enumerate() {
            finite(&format!("gravity[{i}]"), *g)?;
        }
        unit(&self.reference_axis, "reference_axis")?;
        if self.bodies.is_empty() {
            return Err(Error::invalid("bodies", "a scene needs at least one body"));
        }
        let mut names = std::collections::HashSet::new();
        for b in &self.bodies {
            let p = format!("bodies[{}]", b.name);
            if !is_plain_name(&b.name) {
                return Err(Error::invalid(
                    p,
                    "name must be letters, digits, `_` and `-` (it prefixes CSV columns)",
                ));
            }
            if !names.insert(b.name.as_str()) {
                return Err(Error::invalid(p, "duplicate name"));
            }
            positive(&format!("{p}.mass_kg"), b.mass_kg)?;
            for (i, j) in b.inertia_kg_m2.iter().enumerate() {
                positive(&format!("{p}.inertia_kg_m2[{i}]"), *j)?;
            }
            let [a, bb, c] = b.inertia_kg_m2;
            if a + bb < c || bb + c < a || a + c < bb {
                return Err(Error::invalid(
                    format!("{p}.inertia_kg_m2"),
                    "violates the triangle inequality of principal moments",
                ));
            }
            for (i, x) in b.center_of_mass_m.iter().enumerate() {
                finite(&format!("{p}.center_of_mass_m[{i}]"), *x)?;
            }
        }
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
                finite(&format!("{p}.point_m[{i}]"), *x)?;
            }
            unit(&h.axis, &format!("{p}.axis"))?;
            if let Some(c) = &h.clearance {
                c.build().map_err(|e| e.within(&format!("{p}.clearance")))?;
                if c.lock == OutOfPlaneLock::None {
                    return Err(Error::invalid(
                        format!("{p}.clearance.lock"),
                        "`None` leaves the axial translation and the tilts free, and a scene has no locked axes to \
                         hold them: use `Joint` (plain-API users may lock the bodies' axes themselves)",
                    ));
                }
            }
        }
        self.validate_planar()?;
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
            finite(&format!("{p}.torque0_nm"), d.torque0_nm)?;
            non_negative(&format!("{p}.stiffness_nm_per_deg"), d.stiffness_nm_per_deg)?;
            finite(&format!("{p}.torque_scale"), d.torque_scale)?;
        }
        let r = &self.run;
        positive("run.dt_s", r.dt_s)?;
        positive("run.max_dt_s", r.max_dt_s)?;
        positive("run.end_s", r.end_s)?;
        positive("run.output_interval_s", r.output_interval_s)?;
        crate::error::in_range_open_closed("run.tolerance", r.tolerance, 0.0, 1.0)?;
        if r.end_s / r.output_interval_s > MAX_ROWS {
            return Err(Error::invalid(
                "run.output_interval_s",
                format!(
                    "{} rows to reach run.end_s = {}: more than {MAX_ROWS:e} (memory); use a larger interval",
                    r.end_s / r.output_interval_s,
                    r.end_s
                ),
            ));
        }
        if r.step == StepMode::Fixed && r.end_s / r.dt_s > 1e9 {
            return Err(Error::invalid(
                "run.dt_s",
                format!(
                    "{} steps to reach run.end_s = {}: too many",
                    r.end_s / r.dt_s,
                    r.end_s
                ),
            ));
        }
        Ok(())
    }
}

impl Scene {
    /// The clearance model is planar (MODEL.md §4): contact and friction act in the plane normal
    /// to each clearance hinge's axis, and the out-of-plane degrees of freedom are held rigidly.
    /// A scene whose loads would act out of that plane is refused, naming what cannot be represented.
    fn validate_planar(&self) -> Result<()> {
        let a_ref = Vector::from(self.reference_axis);
        let g = Vector::from(self.gravity);
        for h in self.hinges.iter().filter(|h| h.clearance.is_some()) {
            let p = format!("hinges[{}]", h.name);
            let a = Vector::from(h.axis).normalize();
            if a.cross(a_ref).length() > 1e-9 {
                return Err(Error::invalid(
                    format!("{p}.axis"),
                    "a clearance hinge must be parallel to the scene's reference_axis: the planar clearance \
                     model has no axial or tilting contact, so non-parallel hinges (out-of-plane motion) \
                     cannot be represented; make this hinge ideal or align it",
                ));
            }
            if g.dot(a).abs() > 1e-9 * g.length().max(1e-300) && g.length() > 0.0 {
                return Err(Error::invalid(
                    "gravity",
                    format!(
                        "has a component along the axis of clearance hinge `{}`: an axial (out-of-plane) load, \
                         which the planar clearance model cannot carry through contact; put gravity in the \
                         hinge plane or make the hinge ideal",
                        h.name
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// Most output rows a run may keep (each row is a few hundred bytes for a small scene).
const MAX_ROWS: f64 = 1e7;

/// Letters, digits, `_` and `-`: safe in CSV headers and file names.
fn is_plain_name(name: &str) -> bool {
    !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

fn unit(v: &[f64; 3], field: &str) -> Result<()> {
    for (i, x) in v.iter().enumerate() {
        finite(&format!("{field}[{i}]"), *x)?;
    }
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if (n - 1.0).abs() > 1e-6 {
        return Err(Error::invalid(
            field,
            format!("must be a unit vector (length {n})"),
        ));
    }
    Ok(())
}

/// The laws and geometry of a validated clearance spec.
#[derive(Clone, Copy, Debug)]
pub struct ClearanceParams {
    /// Radial geometry (SI).
    pub geometry: BearingGeometry,
    /// Normal law.
    pub normal: NormalModel,
    /// Friction law.
    pub friction: FrictionModel,
    /// Floor on the impact speed, m/s.
    pub min_impact_speed: f64,
    /// Gap that separates two impacts, m.
    pub min_separation: f64,
}

impl ClearanceSpec {
    /// Validates and converts to SI laws; errors name the field relative to this spec.
    pub fn build(&self) -> Result<ClearanceParams> {
        let c = positive("clearance_mm", self.clearance_mm)? * 1e-3;
        let rb = positive("bearing_diameter_mm", self.bearing_diameter_mm)? * 0.5e-3;
        let len = positive("width_mm", self.width_mm)? * 1e-3;
        if c >= rb {
            return Err(Error::invalid(
                "clearance_mm",
                format!(
                    "the journal would be larger than nothing: clearance {} mm >= bearing radius {} mm",
                    self.clearance_mm,
                    rb * 1e3
                ),
            ));
        }
        let geometry = BearingGeometry::from_clearance(rb, c, len)?;
        self.bearing_material
            .validate()
            .map_err(|e| e.within("bearing_material"))?;
        self.journal_material
            .validate()
            .map_err(|e| e.within("journal_material"))?;
        let e_star = effective_modulus(&self.bearing_material, &self.journal_material);
        let geometric = LankaraniNikravesh::stiffness_from_geometry(
            &geometry,
            &self.bearing_material,
            &self.journal_material,
        );
        // The geometric stiffness is Lankarani-Nikravesh's, in N/m^1.5: a default only for n = 1.5.
        let k_n = |s: &Option<f64>, n: f64| -> Result<f64> {
            match s {
                Some(k) => Ok(*k),
                None if n == LankaraniNikravesh::EXPONENT => Ok(geometric),
                None => Err(Error::invalid(
                    "stiffness",
                    format!(
                        "must be given for exponent {n}: the default (the Lankarani-Nikravesh geometric stiffness) \
                         is in N/m^1.5 and holds only for exponent 1.5"
                    ),
                )),
            }
        };
        let normal = (|| -> Result<NormalModel> {
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
                        positive("delta_max_mm", *delta_max_mm)? * 1e-3,
                        damping,
                    )?)
                }
            })
        })()
        .map_err_within("contact")?;
        let mm = 1e-3;
        let friction = (|| -> Result<FrictionModel> {
            Ok(match &self.friction {
                FrictionSpec::None => FrictionModel::None,
                FrictionSpec::Coulomb { mu_d, v_eps_mm_s } => {
                    FrictionModel::Coulomb(Coulomb::new(*mu_d, v_eps_mm_s * mm)?)
                }
                FrictionSpec::Threlfall { mu_d, v0_mm_s } => {
                    FrictionModel::Threlfall(Threlfall::new(*mu_d, v0_mm_s * mm)?)
                }
                FrictionSpec::Ambrosio {
                    mu_d,
                    v0_mm_s,
                    v1_mm_s,
                } => FrictionModel::Ambrosio(Ambrosio::new(*mu_d, v0_mm_s * mm, v1_mm_s * mm)?),
                FrictionSpec::Bai {
                    mu_s,
                    mu_d,
                    v_s_mm_s,
                    v_d_mm_s,
                } => FrictionModel::Bai(Bai::new(*mu_s, *mu_d, v_s_mm_s * mm, v_d_mm_s * mm)?),
                FrictionSpec::Dry => FrictionModel::Bai(Bai::DRY),
                FrictionSpec::Lubricated => FrictionModel::Bai(Bai::LUBRICATED),
            })
        })()
        .map_err_within("friction")?;
        let min_impact_speed = positive("min_impact_speed_mm_s", self.min_impact_speed_mm_s)? * mm;
        let min_separation = non_negative("min_separation_um", self.min_separation_um)? * 1e-6;
        Ok(ClearanceParams {
            geometry,
            normal,
            friction,
            min_impact_speed,
            min_separation,
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

/// Finds the JSON slot an override path names (see [`Scene::with_overrides`]).
fn locate<'a>(root: &'a mut serde_json::Value, path: &str) -> Result<&'a mut serde_json::Value> {
    let unknown = |reason: String| Error::invalid(path, reason);
    let mut segments = path.split('.');
    let first = segments
        .next()
        .filter(|s| !s.is_empty())
        .ok_or_else(|| unknown("empty parameter path".into()))?;
    let obj = root
        .as_object_mut()
        .ok_or_else(|| unknown("scene is not an object".into()))?;
    let mut cur: &mut serde_json::Value = if obj.contains_key(first) {
        obj.get_mut(first).unwrap()
    } else {
        let named = |it: &serde_json::Value| it.get("name").and_then(|n| n.as_str()) == Some(first);
        let list = ["bodies", "hinges", "drives"].into_iter().find(|l| {
            obj.get(*l)
                .and_then(|v| v.as_array())
                .is_some_and(|items| items.iter().any(named))
        });
        list.and_then(|l| {
            obj.get_mut(l)?
                .as_array_mut()?
                .iter_mut()
                .find(|it| named(it))
        })
        .ok_or_else(|| {
            unknown(format!(
                "`{first}` is neither a top-level field nor the name of a body, hinge or drive"
            ))
        })?
    };
    for seg in segments {
        cur = descend(cur, seg).map_err(unknown)?;
    }
    Ok(cur)
}

/// The child `key` of `v`, or the unique field called `key` at any depth below it.
fn descend<'a>(
    v: &'a mut serde_json::Value,
    key: &str,
) -> std::result::Result<&'a mut serde_json::Value, String> {
    fn paths(
        v: &serde_json::Value,
        key: &str,
        prefix: &mut Vec<String>,
        out: &mut Vec<Vec<String>>,
    ) {
        if let Some(o) = v.as_object() {
            for (k, child) in o {
                prefix.push(k.clone());
                if k == key {
                    out.push(prefix.clone());
                }
                paths(child, key, prefix, out);
                prefix.pop();
            }
        }
    }
    let mut found = Vec::new();
    paths(v, key, &mut Vec::new(), &mut found);
    match found.len() {
        0 => Err(format!(
            "no field `{key}` here (is the hinge ideal, or the name misspelt?)"
        )),
        1 => {
            let mut cur = v;
            for k in &found[0] {
                cur = cur.get_mut(k.as_str()).expect("path just found");
            }
            Ok(cur)
        }
        _ => Err(format!(
            "`{key}` is ambiguous: {}",
            found
                .iter()
                .map(|p| p.join("."))
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
}
