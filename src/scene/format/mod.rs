//! Scenes as data (RON): bodies, hinges (ideal or with clearance), drives and run settings.
//! Every value is validated with an error naming its path, e.g. `hinges[hinge].clearance.clearance_mm`.

use crate::error::{Error, Result, excerpt, finite, in_range, non_negative, positive, sig4};
use crate::model::laws::{
    Ambrosio, Bai, BearingGeometry, Coulomb, DELTA_MAX_RANGE, EXPONENT_RANGE, FloresEtAl,
    FrictionModel, GonthierEtAl, Hertz, HuntCrossley, ImprovedLiu, KelvinVoigt, LankaraniNikravesh,
    LiuEtAl, Material, MaxDamping, NormalModel, Threlfall, effective_modulus,
};
use crate::rapier::convert::Clearance;
use crate::rapier::joint::OutOfPlaneLock;
use rapier3d_f64::math::Vector;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The paper's scene (MODEL.md §4), embedded in the binary.
pub const SOLAR_PANEL_RON: &str = include_str!("../../assets/solar_panel.ron");

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
    /// A prescribed motion: the body is kinematic (Rapier's velocity-based kinematic body) and
    /// drives the mechanism; its mass and inertia are then ignored.
    #[serde(default)]
    pub motion: Option<MotionSpec>,
    /// Initial velocity of the centre of mass, m/s (dynamic bodies; default at rest).
    #[serde(default)]
    pub velocity_m_s: [f64; 3],
    /// Initial angular velocity, rad/s (dynamic bodies; default at rest).
    #[serde(default)]
    pub angular_velocity_rad_s: [f64; 3],
}

/// A prescribed motion of a kinematic body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum MotionSpec {
    /// Constant angular speed `rate_rad_s` about `axis` (unit, world) through `point_m` (world,
    /// m) from t = 0 (a crank).
    Spin {
        /// Rotation axis (unit vector, world).
        axis: [f64; 3],
        /// A point of the axis, m.
        point_m: [f64; 3],
        /// Angular speed, rad/s (right-hand rule about `axis`).
        rate_rad_s: f64,
    },
    /// Constant velocity `velocity_m_s` (m/s, world) without rotation.
    Translate {
        /// Velocity, m/s.
        velocity_m_s: [f64; 3],
    },
    /// A tabulated angle `angle_rad` at times `t_s` about `axis` through `point_m`, interpolated
    /// smoothly (cubic Hermite; rate continuous), relative to its value at t = 0.
    TableAngle {
        /// Rotation axis (unit vector, world).
        axis: [f64; 3],
        /// A point of the axis, m.
        point_m: [f64; 3],
        /// Times, s, strictly increasing.
        t_s: Vec<f64>,
        /// Angles at those times, rad.
        angle_rad: Vec<f64>,
    },
    /// A tabulated position `position_m` at times `t_s` along `direction`, interpolated as
    /// [`TableAngle`](Self::TableAngle), relative to its value at t = 0.
    TablePosition {
        /// Direction (unit vector, world).
        direction: [f64; 3],
        /// Times, s, strictly increasing.
        t_s: Vec<f64>,
        /// Positions at those times, m.
        position_m: Vec<f64>,
    },
}

/// An ideal joint that is not a revolute (revolutes are `hinges`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointSpec {
    /// Unique name (CSV column prefix).
    pub name: String,
    /// First body (the guide of a prismatic joint).
    pub body1: String,
    /// Second body (the slider): the joint force reported is the force on it.
    pub body2: String,
    /// World position of the joint point at t = 0, m (the slider's point of a prismatic joint).
    pub point_m: [f64; 3],
    /// Which joint.
    pub kind: JointKindSpec,
    /// A motor on the joint's free axis: `Velocity` or `Position` on a `Revolute` joint,
    /// `LinearVelocity` or `LinearPosition` on a `Prismatic` joint without `limits_m`.
    #[serde(default)]
    pub motor: Option<MotorSpec>,
}

/// A joint motor, Rapier's (`set_motor_velocity`, `set_motor`). Its torque or force is written
/// as `<joint>_motor_nm` (revolute) or `<joint>_motor_n` (prismatic), the torque or force on
/// body 2 about or along the axis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum MotorSpec {
    /// Holds the relative angular speed at `target_rad_s` (revolute), Rapier's velocity motor
    /// (acceleration-based) with damping `factor` (1/s; high: a stiff motor). The joint forces
    /// and the motor torque reported are those of a motor that holds its speed exactly.
    Velocity {
        /// Target relative angular speed of body 2 about the axis, rad/s.
        target_rad_s: f64,
        /// Rapier's motor damping factor, 1/s.
        factor: f64,
    },
    /// A torsional spring and damper towards an angle (revolute), Rapier's force-based motor:
    /// torque `stiffness (target_rad - angle) + damping (target_rad_s - rate)` on body 2, the
    /// angle of body 2 relative to body 1 about the axis from the start (in `[-pi, pi]`, the
    /// error taken the shorter way round). With no stiffness and a `target_rad_s` it is a soft
    /// velocity motor (a torque falling linearly with speed). Reported exactly: the torque is
    /// a function of the state.
    Position {
        /// Target angle, rad, in `[-pi, pi]`.
        target_rad: f64,
        /// Stiffness, N m/rad.
        stiffness_nm_per_rad: f64,
        /// Damping, N m s/rad.
        damping_nm_s_per_rad: f64,
        /// Target relative angular speed of the damping term, rad/s (default 0: the damping
        /// resists any motion).
        #[serde(default)]
        target_rad_s: f64,
    },
    /// Holds the relative speed along the axis at `target_m_s` (prismatic), as
    /// [`Velocity`](Self::Velocity).
    LinearVelocity {
        /// Target speed of body 2 along the axis, m/s.
        target_m_s: f64,
        /// Rapier's motor damping factor, 1/s.
        factor: f64,
    },
    /// A linear spring and damper towards a displacement (prismatic), Rapier's force-based
    /// motor: force `stiffness (target_m - x) + damping (target_m_s - speed)` on body 2 along the
    /// axis, `x` its displacement from the start.
    LinearPosition {
        /// Target displacement along the axis from the start, m.
        target_m: f64,
        /// Stiffness, N/m.
        stiffness_n_per_m: f64,
        /// Damping, N s/m.
        damping_n_s_per_m: f64,
        /// Target speed of the damping term, m/s (default 0).
        #[serde(default)]
        target_m_s: f64,
    },
}

impl MotorSpec {
    /// The variant's name as written in a scene.
    pub fn name(&self) -> &'static str {
        match self {
            MotorSpec::Velocity { .. } => "Velocity",
            MotorSpec::Position { .. } => "Position",
            MotorSpec::LinearVelocity { .. } => "LinearVelocity",
            MotorSpec::LinearPosition { .. } => "LinearPosition",
        }
    }
}

/// The kinds of [`JointSpec`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum JointKindSpec {
    /// Body 2 slides along `axis` (unit, world at t = 0) without turning relative to body 1,
    /// optionally between `limits_m` (displacement from the start, m).
    Prismatic {
        /// Slide axis (unit vector, world, t = 0).
        axis: [f64; 3],
        /// Travel limits `[min, max]` along the axis from the start position, m.
        #[serde(default)]
        limits_m: Option<[f64; 2]>,
    },
    /// An ideal revolute about `axis` (unit, world at t = 0) that may carry a `motor` (a
    /// revolute without motor is better written as a hinge, which may also take a clearance).
    Revolute {
        /// Hinge axis (unit vector, world, t = 0).
        axis: [f64; 3],
    },
    /// The bodies move as one.
    Fixed,
    /// A ball joint: the joint points coincide, rotation is free.
    Spherical,
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
    /// Writes each moving body's centre-of-mass position, velocity and acceleration along the
    /// world axes (`<body>_x_m`, ..., `<body>_vz_m_s`, ..., `<body>_az_m_s2`) in the rows: a
    /// dynamic body's velocity and acceleration solved at each state from the constrained
    /// equations (the joints' and the clearance contacts' forces known), a driven body's its
    /// drive's.
    #[serde(default)]
    pub body_motion: bool,
}

pub use crate::rapier::stepper::StepMode;

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
    pub fn step_control(&self) -> crate::rapier::stepper::StepControl {
        let c = match self.step {
            StepMode::Fixed => crate::rapier::stepper::StepControl::fixed(self.dt_s),
            StepMode::Adaptive => {
                crate::rapier::stepper::StepControl::adaptive(self.max_dt_s, self.tolerance)
            }
        };
        c.strict(self.strict)
    }

    /// The step control in words, e.g. "adaptive steps of at most 1e-3 s (tolerance 0.0075 of a
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
            body_motion: false,
        }
    }
}

impl Scene {
    /// Parses a scene from RON text; `origin` names the source in errors.
    pub fn from_ron(text: &str, origin: &str) -> Result<Scene> {
        // Editors on some systems start UTF-8 files with a byte-order mark: not RON, but harmless.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let scene: Scene = ron::from_str(text).map_err(|e| {
            let hint = variant_hint(text, &e.span.end).map_or(String::new(), |h| format!(" ({h})"));
            Error::parse(origin, format!("{}{hint}", excerpt(&e.to_string(), 300)))
        })?;
        scene.validate()?;
        scene.validate_studies()?;
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
            let (path, raw) = o
                .split_once('=')
                .ok_or_else(|| Error::parse(format!("override `{o}`"), "expected `path=value`"))?;
            let new: serde_json::Value = serde_json::from_str(raw.trim())
                .unwrap_or_else(|_| serde_json::Value::String(raw.trim().to_string()));
            let path = path.trim();
            let slot = locate(&mut value, path)?;
            check_group(path, slot, &new)?;
            *slot = new;
        }
        let scene: Scene = serde_json::from_value(value).map_err(|e| {
            Error::parse(
                format!(
                    "overrides {:?}",
                    overrides.iter().map(|s| s.as_ref()).collect::<Vec<_>>()
                ),
                e.to_string(),
            )
        })?;
        scene.validate()?;
        Ok(scene)
    }

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

    /// Checks every field; the error names the first invalid one.
    pub fn validate(&self) -> Result<()> {
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
            if b.fixed || b.motion.is_some() {
                // A ground or driven body: its mass and inertia are ignored (0 is fine).
                non_negative(&format!("{p}.mass_kg"), b.mass_kg)?;
                for (i, j) in b.inertia_kg_m2.iter().enumerate() {
                    non_negative(&format!("{p}.inertia_kg_m2[{i}]"), *j)?;
                }
            } else {
                let (lo, hi) = MASS_RANGE;
                in_range(&format!("{p}.mass_kg"), b.mass_kg, lo, hi, "kg")?;
                let (lo, hi) = INERTIA_RANGE;
                for (i, j) in b.inertia_kg_m2.iter().enumerate() {
                    in_range(&format!("{p}.inertia_kg_m2[{i}]"), *j, lo, hi, "kg m^2")?;
                }
                let [a, bb, c] = b.inertia_kg_m2;
                if a + bb < c || bb + c < a || a + c < bb {
                    return Err(Error::invalid(
                        format!("{p}.inertia_kg_m2"),
                        "violates the triangle inequality of principal moments",
                    ));
                }
            }
            for (i, x) in b.center_of_mass_m.iter().enumerate() {
                position(&format!("{p}.center_of_mass_m[{i}]"), *x)?;
            }
            for (i, v) in b.velocity_m_s.iter().enumerate() {
                in_range(
                    &format!("{p}.velocity_m_s[{i}]"),
                    *v,
                    -SPEED_MAX,
                    SPEED_MAX,
                    "m/s",
                )?;
            }
            for (i, w) in b.angular_velocity_rad_s.iter().enumerate() {
                in_range(
                    &format!("{p}.angular_velocity_rad_s[{i}]"),
                    *w,
                    -RATE_MAX,
                    RATE_MAX,
                    "rad/s",
                )?;
            }
            match &b.motion {
                Some(_) if b.fixed => {
                    return Err(Error::invalid(
                        format!("{p}.motion"),
                        "a fixed body cannot also have a prescribed motion: remove `fixed: true` or the motion",
                    ));
                }
                Some(MotionSpec::Spin {
                    axis,
                    point_m,
                    rate_rad_s,
                }) => {
                    unit(axis, &format!("{p}.motion.axis"))?;
                    for (i, x) in point_m.iter().enumerate() {
                        position(&format!("{p}.motion.point_m[{i}]"), *x)?;
                    }
                    in_range(
                        &format!("{p}.motion.rate_rad_s"),
                        *rate_rad_s,
                        -RATE_MAX,
                        RATE_MAX,
                        "rad/s",
                    )?;
                }
                Some(MotionSpec::TableAngle {
                    axis,
                    point_m,
                    t_s,
                    angle_rad,
                }) => {
                    unit(axis, &format!("{p}.motion.axis"))?;
                    for (i, x) in point_m.iter().enumerate() {
                        position(&format!("{p}.motion.point_m[{i}]"), *x)?;
                    }
                    crate::rapier::prescribed::Table::new(t_s, angle_rad)
                        .map_err(|e| table_error(e, &p, "angle_rad"))?;
                }
                Some(MotionSpec::TablePosition {
                    direction,
                    t_s,
                    position_m,
                }) => {
                    unit(direction, &format!("{p}.motion.direction"))?;
                    crate::rapier::prescribed::Table::new(t_s, position_m)
                        .map_err(|e| table_error(e, &p, "position_m"))?;
                }
                Some(MotionSpec::Translate { velocity_m_s }) => {
                    for (i, v) in velocity_m_s.iter().enumerate() {
                        in_range(
                            &format!("{p}.motion.velocity_m_s[{i}]"),
                            *v,
                            -SPEED_MAX,
                            SPEED_MAX,
                            "m/s",
                        )?;
                    }
                }
                None => {}
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
                position(&format!("{p}.point_m[{i}]"), *x)?;
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
        for j in &self.joints {
            let p = format!("joints[{}]", j.name);
            if !is_plain_name(&j.name) {
                return Err(Error::invalid(
                    p,
                    "name must be letters, digits, `_` and `-` (it prefixes CSV columns)",
                ));
            }
            if !names.insert(j.name.as_str()) {
                return Err(Error::invalid(
                    p,
                    "duplicate name (bodies, hinges, joints and drives share one namespace)",
                ));
            }
            for (field, body) in [("body1", &j.body1), ("body2", &j.body2)] {
                if self.body_index(body).is_none() {
                    return Err(Error::invalid(
                        format!("{p}.{field}"),
                        format!("no body named `{body}`"),
                    ));
                }
            }
            if j.body1 == j.body2 {
                return Err(Error::invalid(
                    format!("{p}.body2"),
                    "must differ from body1",
                ));
            }
            for (i, x) in j.point_m.iter().enumerate() {
                position(&format!("{p}.point_m[{i}]"), *x)?;
            }
            if let JointKindSpec::Revolute { axis } = &j.kind {
                unit(axis, &format!("{p}.kind.axis"))?;
            }
            if let Some(m) = &j.motor {
                validate_motor(m, &j.kind, &format!("{p}.motor"))?;
            }
            if let JointKindSpec::Prismatic { axis, limits_m } = &j.kind {
                unit(axis, &format!("{p}.kind.axis"))?;
                if let Some([lo, hi]) = limits_m {
                    position(&format!("{p}.kind.limits_m[0]"), *lo)?;
                    position(&format!("{p}.kind.limits_m[1]"), *hi)?;
                    if !(lo < hi) || *lo > 0.0 || *hi < 0.0 {
                        return Err(Error::invalid(
                            format!("{p}.kind.limits_m"),
                            format!(
                                "must be [min, max] with min <= 0 <= max and min < max (the start is 0; got [{lo}, {hi}])"
                            ),
                        ));
                    }
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
        let r = &self.run;
        positive("run.dt_s", r.dt_s)?;
        in_range("run.dt_s", r.dt_s, DT_RANGE.0, DT_RANGE.1, "s")?;
        in_range("run.max_dt_s", r.max_dt_s, DT_RANGE.0, DT_RANGE.1, "s")?;
        positive("run.end_s", r.end_s)?;
        in_range("run.end_s", r.end_s, END_RANGE.0, END_RANGE.1, "s")?;
        positive("run.output_interval_s", r.output_interval_s)?;
        in_range(
            "run.output_interval_s",
            r.output_interval_s,
            DT_RANGE.0,
            END_RANGE.1,
            "s",
        )?;
        crate::error::in_range_open_closed("run.tolerance", r.tolerance, 0.0, 1.0)?;
        in_range("run.tolerance", r.tolerance, TOLERANCE_MIN, 1.0, "")?;
        if r.end_s / r.output_interval_s > MAX_ROWS {
            return Err(Error::invalid(
                "run.output_interval_s",
                format!(
                    "{} rows to reach run.end_s = {} s: more than {} (memory); use a larger interval",
                    sig4(r.end_s / r.output_interval_s),
                    sig4(r.end_s),
                    sig4(MAX_ROWS)
                ),
            ));
        }
        if r.step == StepMode::Fixed && r.end_s / r.dt_s > MAX_STEPS {
            return Err(Error::invalid(
                "run.dt_s",
                format!(
                    "{} steps to reach run.end_s = {} s: more than {}; use a larger step or a shorter run",
                    sig4(r.end_s / r.dt_s),
                    sig4(r.end_s),
                    sig4(MAX_STEPS)
                ),
            ));
        }
        Ok(())
    }
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

/// A table's error with the scene's field names (`t_s` and the value list's name).
fn table_error(e: Error, body: &str, values: &str) -> Error {
    match e {
        Error::Invalid { field, reason } => Error::invalid(
            format!(
                "{body}.motion.{}",
                field
                    .replacen("values", values, 1)
                    .replacen("times", "t_s", 1)
            ),
            reason,
        ),
        other => other,
    }
}

/// Most output rows a run may keep (each row is a few hundred bytes for a small scene; the CLI
/// also checks the bytes of a run against the memory available before it starts).
const MAX_ROWS: f64 = 1e7;
/// Most steps (`run.end_s / run.dt_s`) a run may take.
const MAX_STEPS: f64 = 1e9;

/// Largest initial or prescribed speed of a body, m/s (half Rapier's speed clamp of 400 m/s).
pub const SPEED_MAX: f64 = 200.0;
/// Largest initial or prescribed angular speed, rad/s (about 95,000 rpm).
pub const RATE_MAX: f64 = 1e4;

/// Physical range of a body's mass, kg (fixed bodies: ignored).
pub const MASS_RANGE: (f64, f64) = (1e-6, 1e9);
/// Physical range of a principal moment of inertia, kg m^2.
pub const INERTIA_RANGE: (f64, f64) = (1e-12, 1e12);
/// Largest coordinate of a body's centre of mass or a hinge point, m.
pub const POSITION_MAX: f64 = 1e4;
/// Largest gravity component, m/s^2 (100 g).
pub const GRAVITY_MAX: f64 = 1e3;
/// Largest drive preload, N m (and stiffness, N m/deg).
pub const TORQUE_MAX: f64 = 1e6;
/// Largest drive `torque_scale` (either sign).
pub const TORQUE_SCALE_MAX: f64 = 1e3;
/// Range of `run.dt_s`, s (also the smallest `run.output_interval_s`).
pub const DT_RANGE: (f64, f64) = (1e-9, 1.0);
/// Range of `run.end_s`, s (also the largest `run.output_interval_s`).
pub const END_RANGE: (f64, f64) = (1e-6, 1e7);
/// Smallest `run.tolerance` (the largest is 1).
pub const TOLERANCE_MIN: f64 = 1e-4;
/// Range of a bearing diameter or width, mm (1 um to 10 m).
pub const LENGTH_MM_RANGE: (f64, f64) = (1e-3, 1e4);
/// Range of a radial clearance, mm (1 nm to 1 m; it must also be below the bearing radius).
pub const CLEARANCE_MM_RANGE: (f64, f64) = (1e-6, 1e3);
/// Range of a speed given in mm/s (friction transition speeds, impact-speed floor).
pub const SPEED_MM_S_RANGE: (f64, f64) = (1e-9, 1e5);

/// Largest motor stiffness: N m/rad (revolute) or N/m (prismatic).
pub const MOTOR_STIFFNESS_MAX: f64 = 1e12;
/// Largest motor damping: N m s/rad (revolute) or N s/m (prismatic).
pub const MOTOR_DAMPING_MAX: f64 = 1e9;
/// Range of a velocity motor's damping factor, 1/s.
pub const MOTOR_FACTOR_RANGE: (f64, f64) = (1e-6, 1e12);

/// A joint's motor (at `p`, e.g. `joints[motor].motor`) against the joint's kind and the
/// physical ranges of its fields.
fn validate_motor(m: &MotorSpec, kind: &JointKindSpec, p: &str) -> Result<()> {
    let (revolute, prismatic) = (
        matches!(kind, JointKindSpec::Revolute { .. }),
        matches!(kind, JointKindSpec::Prismatic { .. }),
    );
    let wrong = |needs: &str, other: &str| {
        Err(Error::invalid(
            p,
            format!("a `{}` motor needs a `{needs}` joint{other}", m.name()),
        ))
    };
    let factor = |f: f64| {
        in_range(
            &format!("{p}.factor"),
            f,
            MOTOR_FACTOR_RANGE.0,
            MOTOR_FACTOR_RANGE.1,
            "1/s",
        )
    };
    let spring = |k: (&str, f64, &str), c: (&str, f64, &str)| -> Result<()> {
        in_range(&format!("{p}.{}", k.0), k.1, 0.0, MOTOR_STIFFNESS_MAX, k.2)?;
        in_range(&format!("{p}.{}", c.0), c.1, 0.0, MOTOR_DAMPING_MAX, c.2)?;
        if k.1 == 0.0 && c.1 == 0.0 {
            return Err(Error::invalid(
                p,
                format!("`{}` and `{}` are both 0: the motor does nothing", k.0, c.0),
            ));
        }
        Ok(())
    };
    let rate =
        |field: &str, v: f64| in_range(&format!("{p}.{field}"), v, -RATE_MAX, RATE_MAX, "rad/s");
    let speed =
        |field: &str, v: f64| in_range(&format!("{p}.{field}"), v, -SPEED_MAX, SPEED_MAX, "m/s");
    match m {
        MotorSpec::Velocity {
            target_rad_s,
            factor: f,
        } => {
            if !revolute {
                return wrong("Revolute", " (on a `Prismatic` joint: `LinearVelocity`)");
            }
            rate("target_rad_s", *target_rad_s)?;
            factor(*f)?;
        }
        MotorSpec::Position {
            target_rad,
            stiffness_nm_per_rad,
            damping_nm_s_per_rad,
            target_rad_s,
        } => {
            if !revolute {
                return wrong("Revolute", " (on a `Prismatic` joint: `LinearPosition`)");
            }
            // Rapier measures the angle in [-pi, pi]: a target beyond is never reached.
            let pi = std::f64::consts::PI;
            in_range(&format!("{p}.target_rad"), *target_rad, -pi, pi, "rad")?;
            spring(
                ("stiffness_nm_per_rad", *stiffness_nm_per_rad, "N m/rad"),
                ("damping_nm_s_per_rad", *damping_nm_s_per_rad, "N m s/rad"),
            )?;
            rate("target_rad_s", *target_rad_s)?;
        }
        MotorSpec::LinearVelocity {
            target_m_s,
            factor: f,
        } => {
            if !prismatic {
                return wrong("Prismatic", " (on a `Revolute` joint: `Velocity`)");
            }
            speed("target_m_s", *target_m_s)?;
            factor(*f)?;
        }
        MotorSpec::LinearPosition {
            target_m,
            stiffness_n_per_m,
            damping_n_s_per_m,
            target_m_s,
        } => {
            if !prismatic {
                return wrong("Prismatic", " (on a `Revolute` joint: `Position`)");
            }
            position(&format!("{p}.target_m"), *target_m)?;
            spring(
                ("stiffness_n_per_m", *stiffness_n_per_m, "N/m"),
                ("damping_n_s_per_m", *damping_n_s_per_m, "N s/m"),
            )?;
            speed("target_m_s", *target_m_s)?;
        }
    }
    if let JointKindSpec::Prismatic {
        limits_m: Some(_), ..
    } = kind
    {
        return Err(Error::invalid(
            p,
            "a motor on a prismatic joint with `limits_m` is not supported: the reported \
             reactions would not know when the limit, not the motor, holds the slider",
        ));
    }
    Ok(())
}

fn position(field: &str, x: f64) -> Result<f64> {
    in_range(field, x, -POSITION_MAX, POSITION_MAX, "m")
}

fn speed_mm_s(field: &str, v: f64) -> Result<f64> {
    in_range(field, v, SPEED_MM_S_RANGE.0, SPEED_MM_S_RANGE.1, "mm/s")
}

/// Letters, digits, `_` and `-`: safe in CSV headers and file names.
pub(super) fn is_plain_name(name: &str) -> bool {
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
            format!("must be a unit vector (length {})", sig4(n)),
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
    /// The [`Clearance`] this spec describes (validated; errors name the field relative to
    /// this spec).
    pub fn clearance(&self) -> Result<Clearance> {
        let p = self.build()?;
        Ok(Clearance {
            min_impact_speed: p.min_impact_speed,
            min_separation: p.min_separation,
            ..Clearance::new(p.geometry, p.normal)
                .friction(p.friction)
                .lock(self.lock)
        })
    }

    /// Validates and converts to SI laws; errors name the field relative to this spec.
    pub fn build(&self) -> Result<ClearanceParams> {
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
        .map_err_within("contact")?;
        let mm = 1e-3;
        let friction = (|| -> Result<FrictionModel> {
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
                    FrictionModel::Bai(Bai::new(*mu_s, *mu_d, v_s_mm_s * mm, v_d_mm_s * mm)?)
                }
                FrictionSpec::Dry => FrictionModel::Bai(Bai::DRY),
                FrictionSpec::Lubricated => FrictionModel::Bai(Bai::LUBRICATED),
            })
        })()
        .map_err_within("friction")?;
        let min_impact_speed =
            speed_mm_s("min_impact_speed_mm_s", self.min_impact_speed_mm_s)? * mm;
        let min_separation =
            in_range("min_separation_um", self.min_separation_um, 0.0, 1e4, "um")? * 1e-6;
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

/// The enum variants of a scene (contact and friction laws) and how each is written, for hints
/// when a variant is written in the wrong form (`LiuEtAl()`, a bare `ImprovedLiu`).
const VARIANT_FORMS: [(&str, &str); 16] = [
    (
        "Hertz",
        "Hertz(stiffness: Some(K), exponent: n), or Hertz() for n = 1.5 and the geometric stiffness",
    ),
    ("KelvinVoigt", "KelvinVoigt(stiffness: K, damping: D)"),
    (
        "HuntCrossley",
        "HuntCrossley(restitution: cr), optionally with stiffness: Some(K) and exponent: n",
    ),
    (
        "LankaraniNikravesh",
        "LankaraniNikravesh(restitution: cr), optionally with stiffness: Some(K)",
    ),
    (
        "FloresEtAl",
        "FloresEtAl(restitution: cr), optionally with stiffness: Some(K) and exponent: n",
    ),
    (
        "GonthierEtAl",
        "GonthierEtAl(restitution: cr), optionally with stiffness: Some(K) and exponent: n",
    ),
    ("LiuEtAl", "LiuEtAl, with no parameters and no parentheses"),
    (
        "ImprovedLiu",
        "ImprovedLiu(exponent: n, delta_max_mm: d, eta_s: eta), or ImprovedLiu() for the defaults",
    ),
    ("None", "None, with no parameters and no parentheses"),
    ("Coulomb", "Coulomb(mu_d: mu, v_eps_mm_s: v)"),
    ("Threlfall", "Threlfall(mu_d: mu, v0_mm_s: v)"),
    ("Ambrosio", "Ambrosio(mu_d: mu, v0_mm_s: v0, v1_mm_s: v1)"),
    (
        "Bai",
        "Bai(mu_s: mu_s, mu_d: mu_d, v_s_mm_s: v_s, v_d_mm_s: v_d)",
    ),
    ("Dry", "Dry, with no parameters and no parentheses"),
    (
        "Lubricated",
        "Lubricated, with no parameters and no parentheses",
    ),
    ("Some", "Some(value), or None"),
];

/// When a RON error comes right after the name of a law, how that law is written.
fn variant_hint(text: &str, at: &ron::error::Position) -> Option<String> {
    // The text up to the error (line and column count characters, from 1).
    let mut prefix = String::new();
    for (i, line) in text.split('\n').enumerate() {
        if i + 1 < at.line {
            prefix.push_str(line);
            prefix.push('\n');
        } else {
            prefix.extend(line.chars().take(at.col.saturating_sub(1)));
            break;
        }
    }
    let before =
        prefix.trim_end_matches(|c: char| c.is_whitespace() || c == '(' || c == ')' || c == ',');
    let start = before
        .rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .map_or(0, |i| i + 1);
    let word = &before[start..];
    VARIANT_FORMS
        .iter()
        .find(|(name, _)| *name == word)
        .map(|(name, form)| format!("`{name}` is written {form}"))
}

/// Refuses a scalar written over a group of settings (`--set run=5`): only one of its fields
/// can be meant. A law (an enum) may be replaced by a bare name or an object, and an optional
/// group by `null`.
fn check_group(path: &str, slot: &serde_json::Value, new: &serde_json::Value) -> Result<()> {
    let Some(fields) = slot.as_object() else {
        return Ok(());
    };
    let is_enum = fields.len() == 1
        && fields
            .keys()
            .next()
            .is_some_and(|k| k.starts_with(|c: char| c.is_ascii_uppercase()));
    if is_enum || new.is_object() || new.is_null() {
        return Ok(());
    }
    let names: Vec<&str> = fields.keys().map(String::as_str).collect();
    let example = names.first().copied().unwrap_or("field");
    Err(Error::invalid(
        path,
        format!(
            "is a group of settings ({}): set one of them, e.g. `--set {path}.{example}=VALUE`",
            names.join(", ")
        ),
    ))
}

/// One step of a path into the scene's JSON: an object key or an array index.
#[derive(Clone, Debug)]
enum Step {
    Key(String),
    Index(usize),
}

/// Finds the JSON slot an override path names (see [`Scene::with_overrides`]). The first
/// segment is a top-level field, the name of a body, hinge, joint or drive, or `bodies[name]`,
/// `hinges[name]`, `joints[name]`, `drives[name]` (the form error messages use). A name that is also a
/// top-level field (a body called `run`) is taken where the rest of the path exists.
fn locate<'a>(root: &'a mut serde_json::Value, path: &str) -> Result<&'a mut serde_json::Value> {
    let unknown = |reason: String| Error::invalid(path, reason);
    let mut segments = path.split('.');
    let first = segments
        .next()
        .filter(|s| !s.is_empty())
        .ok_or_else(|| unknown("empty parameter path".into()))?;
    let rest: Vec<&str> = segments.collect();
    let obj = root
        .as_object()
        .ok_or_else(|| unknown("scene is not an object".into()))?;
    let item = |list: &str, name: &str| -> Option<Vec<Step>> {
        let items = obj.get(list)?.as_array()?;
        let i = items
            .iter()
            .position(|it| it.get("name").and_then(|n| n.as_str()) == Some(name))?;
        Some(vec![Step::Key(list.to_string()), Step::Index(i)])
    };
    let mut starts: Vec<(String, Vec<Step>)> = Vec::new();
    if let Some((list, name)) = first
        .strip_suffix(']')
        .and_then(|f| f.split_once('['))
        .filter(|(l, _)| ["bodies", "hinges", "joints", "drives"].contains(l))
    {
        let start = item(list, name).ok_or_else(|| {
            let what = match list {
                "bodies" => "body",
                "hinges" => "hinge",
                "joints" => "joint",
                _ => "drive",
            };
            unknown(format!("no {what} named `{name}`"))
        })?;
        starts.push((format!("{list}[{name}]"), start));
    } else {
        if obj.contains_key(first) {
            starts.push((
                format!("the top-level field `{first}`"),
                vec![Step::Key(first.to_string())],
            ));
        }
        for (list, what) in [
            ("bodies", "body"),
            ("hinges", "hinge"),
            ("joints", "joint"),
            ("drives", "drive"),
        ] {
            if let Some(start) = item(list, first) {
                starts.push((format!("the {what} `{first}` ({list}[{first}])"), start));
            }
        }
    }
    if starts.is_empty() {
        return Err(unknown(format!(
            "`{first}` is neither a top-level field nor the name of a body, hinge, joint or drive"
        )));
    }
    let resolved: Vec<(String, std::result::Result<Vec<Step>, String>)> = starts
        .into_iter()
        .map(|(what, start)| {
            let found = resolve(root_at(root, &start), &rest).map(|tail| {
                let mut steps = start;
                steps.extend(tail);
                steps
            });
            (what, found)
        })
        .collect();
    let ok: Vec<&(String, std::result::Result<Vec<Step>, String>)> =
        resolved.iter().filter(|(_, r)| r.is_ok()).collect();
    let steps = match ok.as_slice() {
        [(_, Ok(steps))] => steps.clone(),
        [] => {
            let (_, Err(reason)) = &resolved[0] else {
                unreachable!("no start resolved")
            };
            return Err(unknown(reason.clone()));
        }
        several => {
            return Err(unknown(format!(
                "`{first}` names {}: write `{}.{}` for the body, hinge or drive, or rename it",
                several
                    .iter()
                    .map(|(w, _)| w.as_str())
                    .collect::<Vec<_>>()
                    .join(" and "),
                several
                    .iter()
                    .find_map(|(w, _)| w.split_once('(').map(|(_, p)| p.trim_end_matches(')')))
                    .unwrap_or(first),
                rest.join(".")
            )));
        }
    };
    let mut cur = root;
    for step in &steps {
        cur = match step {
            Step::Key(k) => cur.get_mut(k.as_str()),
            Step::Index(i) => cur.get_mut(*i),
        }
        .expect("path just resolved");
    }
    Ok(cur)
}

fn root_at<'a>(root: &'a serde_json::Value, steps: &[Step]) -> &'a serde_json::Value {
    let mut cur = root;
    for step in steps {
        cur = match step {
            Step::Key(k) => &cur[k.as_str()],
            Step::Index(i) => &cur[*i],
        };
    }
    cur
}

/// The steps below `v` to the field named by `segments`, each segment a direct child or the
/// unique field of that name at any depth.
fn resolve(v: &serde_json::Value, segments: &[&str]) -> std::result::Result<Vec<Step>, String> {
    let mut steps = Vec::new();
    let mut cur = v;
    for seg in segments {
        let found = descend(cur, seg)?;
        for k in found {
            cur = &cur[k.as_str()];
            steps.push(Step::Key(k));
        }
    }
    Ok(steps)
}

/// The key path to the child `key` of `v`, or to the unique field called `key` at any depth below it.
fn descend(v: &serde_json::Value, key: &str) -> std::result::Result<Vec<String>, String> {
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
    if v.get(key).is_some() {
        return Ok(vec![key.to_string()]);
    }
    let mut found = Vec::new();
    paths(v, key, &mut Vec::new(), &mut found);
    match found.len() {
        0 => Err(format!(
            "no field `{key}` here (is the hinge ideal, or the name misspelt?)"
        )),
        1 => Ok(found.remove(0)),
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_a_scene_spec() {
        let scene = Scene::solar_panel();
        let spec = scene.hinges[0].clearance.as_ref().unwrap();
        let c = spec.clearance().unwrap();
        assert!((c.geometry.clearance() - 0.5e-3).abs() < 1e-15);
        assert_eq!(
            c.friction,
            crate::model::laws::FrictionModel::Bai(crate::model::laws::Bai::DRY)
        );
        assert_eq!(
            c.normal,
            Clearance::steel_improved_liu(0.010, 0.5e-3, 0.016)
                .unwrap()
                .normal
        );
    }
}
