//! Normal contact-force laws (MODEL.md §2).

use super::step::{step, step_slope};
use crate::error::{
    ContactParameter, Error, Result, in_range, in_range_open_closed, positive, sig4,
};
use std::f64::consts::PI;

/// The state a normal law is evaluated at.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NormalContact {
    /// Penetration `delta = |e| - c`, m (contact only when > 0).
    pub penetration: f64,
    /// Penetration rate `delta_dot`, m/s (positive while the surfaces approach).
    pub penetration_rate: f64,
    /// Penetration rate when the current contact began, `delta_dot0`, m/s, already floored to a
    /// positive minimum by the joint (see `ClearanceJointBuilder::min_impact_speed`).
    pub impact_rate: f64,
}

/// A compliant normal-force law `F_N(delta, delta_dot, delta_dot0)`.
pub trait NormalForceLaw {
    /// Normal force magnitude, N. Zero without penetration and never negative: damping never
    /// pulls the surfaces together (MODEL.md §1).
    fn normal_force(&self, c: &NormalContact) -> f64 {
        if c.penetration <= 0.0 {
            return 0.0;
        }
        (self.elastic_force(c.penetration) + self.damping_coefficient(c) * c.penetration_rate)
            .max(0.0)
    }

    /// The elastic (conservative) part of the force at `penetration`, N (0 for `penetration <= 0`).
    fn elastic_force(&self, penetration: f64) -> f64;

    /// Tangent stiffness `dF_elastic/d delta` at `penetration`, N/m.
    fn tangent_stiffness(&self, penetration: f64) -> f64;

    /// The coefficient multiplying `delta_dot` in the force (`dF/d delta_dot`), N s/m.
    fn damping_coefficient(&self, c: &NormalContact) -> f64;

    /// `d D/d delta`, the change of the damping coefficient with penetration (0 by default): with
    /// [`tangent_stiffness`](Self::tangent_stiffness) it linearises the force for step limits,
    /// `dF/d delta = K_tangent + (dD/d delta) delta_dot`.
    fn damping_slope(&self, _c: &NormalContact) -> f64 {
        0.0
    }

    /// Work stored by the elastic part from 0 to `penetration`, J. The default integrates
    /// [`elastic_force`](Self::elastic_force) by 16-point Gauss-Legendre after the substitution
    /// `delta = penetration s^2`, which removes the `sqrt` behaviour at 0.
    fn elastic_energy(&self, penetration: f64) -> f64 {
        if penetration <= 0.0 {
            return 0.0;
        }
        gauss_legendre_16(|s| self.elastic_force(penetration * s * s) * 2.0 * penetration * s)
    }

    /// Whether the law reads `impact_rate` (the hysteresis laws).
    fn uses_impact_rate(&self) -> bool {
        false
    }
}

/// The penetration at which the elastic energy of `law` equals `energy`: the deepest point of an
/// undamped impact that starts with kinetic energy `energy` (`1/2 m delta_dot0^2`). Cheap enough for
/// every step: a fixed-point iteration on the local power law `F = C delta^p` through the current
/// estimate (exact for Hertz-type laws, within a few per cent for Liu's), starting from `guess`
/// (1e-6 m when it is not between 1e-15 and 1 m). 0 for an energy that is not positive (or NaN);
/// never NaN.
pub fn penetration_for_energy(law: &impl NormalForceLaw, energy: f64, guess: f64) -> f64 {
    if energy.is_nan() || energy <= 0.0 {
        return 0.0;
    }
    let mut d = if (1e-15..=1.0).contains(&guess) {
        guess
    } else {
        1e-6
    };
    for _ in 0..12 {
        let (f, k) = (law.elastic_force(d), law.tangent_stiffness(d));
        if !(f > 0.0 && k > 0.0 && f.is_finite() && k.is_finite()) {
            d *= 10.0;
            continue;
        }
        // Local power law through d: p = k d / f; energy of F = C x^p up to x is f(x) x/(p + 1).
        let p = k * d / f;
        let next = d * ((p + 1.0) * energy / (f * d)).powf(1.0 / (p + 1.0));
        // Beyond floating point (an energy of 1e300, a subnormal guess): the last estimate.
        if !(next > 0.0 && next.is_finite()) {
            break;
        }
        let converged = (next - d).abs() <= 1e-6 * d;
        d = next;
        if converged {
            break;
        }
    }
    d
}

/// `integral_0^1 f(s) ds` by 16-point Gauss-Legendre.
fn gauss_legendre_16(f: impl Fn(f64) -> f64) -> f64 {
    const X: [f64; 8] = [
        0.0950125098376374,
        0.2816035507792589,
        0.4580167776572274,
        0.6178762444026438,
        0.755404408355003,
        0.8656312023878318,
        0.9445750230732326,
        0.9894009349916499,
    ];
    const W: [f64; 8] = [
        0.1894506104550685,
        0.1826034150449236,
        0.1691565193950025,
        0.1495959888165767,
        0.1246289712555339,
        0.0951585116824928,
        0.0622535239386479,
        0.0271524594117541,
    ];
    let mut sum = 0.0;
    for (x, w) in X.iter().zip(W) {
        sum += w * (f(0.5 * (1.0 + x)) + f(0.5 * (1.0 - x)));
    }
    0.5 * sum
}

fn penetration_power(delta: f64, n: f64) -> f64 {
    if delta <= 0.0 { 0.0 } else { delta.powf(n) }
}

/// Physical range of a contact stiffness `K`, N/m^n: from a soft polymer pad to beyond diamond.
pub const STIFFNESS_RANGE: (f64, f64) = (1.0, 1e16);
/// Physical range of a force exponent `n`: 1 (linear, Liu) to 3 (beyond every published fit;
/// Hertz's point contact is 1.5). Below 1 the stiffness at first contact is infinite.
pub const EXPONENT_RANGE: (f64, f64) = (1.0, 3.0);
/// Physical range of a damping coefficient, N s/m.
pub const DAMPING_RANGE: (f64, f64) = (0.0, 1e12);
/// Physical range of the improved law's damping saturation depth `delta_max`, m (up to 10 mm).
pub const DELTA_MAX_RANGE: (f64, f64) = (1e-12, 1e-2);
/// Physical range of the improved law's damping time `eta`, s.
pub const ETA_RANGE: (f64, f64) = (0.0, 1.0);

/// Checks a stiffness and an exponent against their physical ranges (exponent first: an
/// invalid exponent is the cause, whatever the stiffness).
fn check_stiffness_exponent(k: f64, n: f64) -> Result<()> {
    in_range("exponent", n, EXPONENT_RANGE.0, EXPONENT_RANGE.1, "")?;
    in_range(
        "stiffness",
        k,
        STIFFNESS_RANGE.0,
        STIFFNESS_RANGE.1,
        "N/m^n",
    )?;
    Ok(())
}

/// Hertz: `F = K delta^n`, purely elastic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hertz {
    stiffness: f64,
    exponent: f64,
}

impl Hertz {
    /// `K` in N/m^n, `n >= 1`.
    pub fn new(stiffness: f64, exponent: f64) -> Result<Self> {
        check_stiffness_exponent(stiffness, exponent)?;
        Ok(Hertz {
            stiffness,
            exponent,
        })
    }
}

impl NormalForceLaw for Hertz {
    fn elastic_force(&self, delta: f64) -> f64 {
        self.stiffness * penetration_power(delta, self.exponent)
    }
    fn tangent_stiffness(&self, delta: f64) -> f64 {
        if delta <= 0.0 {
            0.0
        } else {
            self.stiffness * self.exponent * delta.powf(self.exponent - 1.0)
        }
    }
    fn damping_coefficient(&self, _: &NormalContact) -> f64 {
        0.0
    }
    fn elastic_energy(&self, delta: f64) -> f64 {
        self.stiffness * penetration_power(delta, self.exponent + 1.0) / (self.exponent + 1.0)
    }
}

/// Kelvin-Voigt: `F = K delta + D delta_dot` (linear spring and dashpot).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KelvinVoigt {
    stiffness: f64,
    damping: f64,
}

impl KelvinVoigt {
    /// `K` in N/m, `D` in N s/m (`D >= 0`).
    pub fn new(stiffness: f64, damping: f64) -> Result<Self> {
        in_range(
            "stiffness",
            stiffness,
            STIFFNESS_RANGE.0,
            STIFFNESS_RANGE.1,
            "N/m",
        )?;
        in_range(
            "damping",
            damping,
            DAMPING_RANGE.0,
            DAMPING_RANGE.1,
            "N s/m",
        )?;
        Ok(KelvinVoigt { stiffness, damping })
    }
}

impl NormalForceLaw for KelvinVoigt {
    fn elastic_force(&self, delta: f64) -> f64 {
        self.stiffness * delta.max(0.0)
    }
    fn tangent_stiffness(&self, delta: f64) -> f64 {
        if delta <= 0.0 { 0.0 } else { self.stiffness }
    }
    fn damping_coefficient(&self, _: &NormalContact) -> f64 {
        self.damping
    }
    fn elastic_energy(&self, delta: f64) -> f64 {
        0.5 * self.stiffness * delta.max(0.0).powi(2)
    }
}

/// Shared form of the hysteresis laws: `F = K delta^n (1 + chi delta_dot/delta_dot0)`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Hysteresis {
    /// The elastic part `K delta^n`.
    elastic: Hertz,
    restitution: f64,
    chi: f64,
}

impl Hysteresis {
    fn new(
        stiffness: f64,
        exponent: f64,
        restitution: f64,
        chi: impl Fn(f64) -> f64,
    ) -> Result<Self> {
        let elastic = Hertz::new(stiffness, exponent)?;
        in_range_open_closed("restitution", restitution, 0.0, 1.0)?;
        Ok(Hysteresis {
            elastic,
            restitution,
            chi: chi(restitution),
        })
    }
    fn elastic_force(&self, delta: f64) -> f64 {
        self.elastic.elastic_force(delta)
    }
    fn tangent_stiffness(&self, delta: f64) -> f64 {
        self.elastic.tangent_stiffness(delta)
    }
    fn damping_coefficient(&self, c: &NormalContact) -> f64 {
        if c.penetration <= 0.0 || c.impact_rate <= 0.0 {
            return 0.0;
        }
        self.elastic_force(c.penetration) * self.chi / c.impact_rate
    }
    /// `d D/d delta = chi K_tangent / delta_dot0`.
    fn damping_slope(&self, c: &NormalContact) -> f64 {
        if c.penetration <= 0.0 || c.impact_rate <= 0.0 {
            return 0.0;
        }
        self.tangent_stiffness(c.penetration) * self.chi / c.impact_rate
    }
    fn elastic_energy(&self, delta: f64) -> f64 {
        self.elastic.elastic_energy(delta)
    }
}

macro_rules! hysteresis_law {
    ($(#[$doc:meta])* $name:ident, $chi:expr) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct $name(Hysteresis);

        impl $name {
            /// Stiffness `K` (N/m^n), exponent `n >= 1`, restitution coefficient `cr` in (0, 1].
            pub fn new(stiffness: f64, exponent: f64, restitution: f64) -> Result<Self> {
                Hysteresis::new(stiffness, exponent, restitution, $chi).map($name)
            }
            /// The restitution coefficient `cr`.
            pub fn restitution(&self) -> f64 {
                self.0.restitution
            }
            /// The hysteresis factor `chi` in `1 + chi delta_dot/delta_dot0`.
            pub fn hysteresis_factor(&self) -> f64 {
                self.0.chi
            }
        }

        impl NormalForceLaw for $name {
            fn elastic_force(&self, delta: f64) -> f64 {
                self.0.elastic_force(delta)
            }
            fn tangent_stiffness(&self, delta: f64) -> f64 {
                self.0.tangent_stiffness(delta)
            }
            fn damping_coefficient(&self, c: &NormalContact) -> f64 {
                self.0.damping_coefficient(c)
            }
            fn damping_slope(&self, c: &NormalContact) -> f64 {
                self.0.damping_slope(c)
            }
            fn elastic_energy(&self, delta: f64) -> f64 {
                self.0.elastic_energy(delta)
            }
            fn uses_impact_rate(&self) -> bool {
                true
            }
        }
    };
}

hysteresis_law!(
    /// Hunt-Crossley: `F = K delta^n (1 + 3(1-cr)/2 * delta_dot/delta_dot0)`.
    HuntCrossley,
    |cr| 1.5 * (1.0 - cr)
);
hysteresis_law!(
    /// Lankarani-Nikravesh: `F = K delta^n (1 + 3(1-cr^2)/4 * delta_dot/delta_dot0)`, usually with
    /// `n = 1.5` and `K` from [`LankaraniNikravesh::stiffness_from_geometry`].
    LankaraniNikravesh,
    |cr| 0.75 * (1.0 - cr * cr)
);
hysteresis_law!(
    /// Flores et al. 2011: `F = K delta^n (1 + 8(1-cr)/(5 cr) * delta_dot/delta_dot0)`.
    FloresEtAl,
    |cr| 8.0 * (1.0 - cr) / (5.0 * cr)
);
hysteresis_law!(
    /// Gonthier et al. 2004: `F = K delta^n (1 + (1-cr^2)/cr * delta_dot/delta_dot0)`.
    GonthierEtAl,
    |cr| (1.0 - cr * cr) / cr
);

impl LankaraniNikravesh {
    /// Hertz exponent of the Lankarani-Nikravesh law.
    pub const EXPONENT: f64 = 1.5;

    /// `K = 4/(3(sigma_i + sigma_j)) * sqrt(R_b R_j/(R_b - R_j))` (MODEL.md §2), N/m^1.5.
    pub fn stiffness_from_geometry(
        geometry: &super::BearingGeometry,
        bearing: &super::Material,
        journal: &super::Material,
    ) -> f64 {
        let (rb, rj) = (geometry.bearing_radius(), geometry.journal_radius());
        4.0 / (3.0 * (bearing.sigma() + journal.sigma())) * (rb * rj / (rb - rj)).sqrt()
    }
}

/// `sqrt(delta/(2(c+delta)))` and its derivative in `delta`.
fn liu_factor(delta: f64, clearance: f64) -> (f64, f64) {
    let g = (delta / (2.0 * (clearance + delta))).sqrt();
    let slope = if g > 0.0 {
        clearance / (4.0 * (clearance + delta).powi(2) * g)
    } else {
        f64::INFINITY
    };
    (g, slope)
}

/// Liu et al. 2007, cylindrical contact with clearance: `F = (pi/2) E* L delta sqrt(delta/(2(c+delta)))`,
/// the paper's improved law with `n = 1` and no damping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LiuEtAl(ImprovedLiu);

impl LiuEtAl {
    /// Composite modulus `E*` (Pa), axial length `L` (m), radial clearance `c` (m).
    pub fn new(effective_modulus: f64, length: f64, clearance: f64) -> Result<Self> {
        let undamped = MaxDamping::Explicit(0.0);
        ImprovedLiu::new(
            effective_modulus,
            length,
            clearance,
            1.0,
            ImprovedLiu::DEFAULT_DELTA_MAX,
            undamped,
        )
        .map(LiuEtAl)
    }
}

impl LiuEtAl {
    /// The radial clearance `c` of the law, m.
    pub fn clearance(&self) -> f64 {
        self.0.clearance()
    }
}

impl NormalForceLaw for LiuEtAl {
    fn elastic_force(&self, delta: f64) -> f64 {
        self.0.elastic_force(delta)
    }
    fn tangent_stiffness(&self, delta: f64) -> f64 {
        self.0.tangent_stiffness(delta)
    }
    fn damping_coefficient(&self, _: &NormalContact) -> f64 {
        0.0
    }
}

/// How the improved law's maximum damping `D_max` is set (MODEL.md §2, eq. 16).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaxDamping {
    /// `D_max = eta K_N(delta_max)`, `eta` in seconds (the paper's "1 %" is `eta = 0.01`).
    Eta(f64),
    /// An explicit `D_max`, N s/m.
    Explicit(f64),
}

/// The paper's improved law (eqs. 14-17): `F = F_K + D_imp delta_dot` with
/// `F_K = (pi/2) E* L sqrt(delta/(2(c+delta))) delta^n` and
/// `D_imp = STEP(delta, 0, 0, delta_max, D_max)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImprovedLiu {
    scale: f64,
    clearance: f64,
    exponent: f64,
    delta_max: f64,
    d_max: f64,
}

impl ImprovedLiu {
    /// The paper's damping saturation depth `delta_max` = 0.1 mm.
    pub const DEFAULT_DELTA_MAX: f64 = 1e-4;
    /// The paper's `eta` = 1 % read as 0.01 s (MODEL.md §2 interpretation).
    pub const DEFAULT_ETA: f64 = 0.01;

    /// Composite modulus `E*` (Pa), length `L` (m), clearance `c` (m), exponent `n >= 1`,
    /// damping saturation depth `delta_max` (m) and the maximum damping.
    pub fn new(
        effective_modulus: f64,
        length: f64,
        clearance: f64,
        exponent: f64,
        delta_max: f64,
        damping: MaxDamping,
    ) -> Result<Self> {
        positive("effective_modulus", effective_modulus)?;
        positive("length", length)?;
        positive("clearance", clearance)?;
        in_range("exponent", exponent, EXPONENT_RANGE.0, EXPONENT_RANGE.1, "")?;
        in_range(
            "delta_max",
            delta_max,
            DELTA_MAX_RANGE.0,
            DELTA_MAX_RANGE.1,
            "m",
        )?;
        let mut law = ImprovedLiu {
            scale: 0.5 * PI * effective_modulus * length,
            clearance,
            exponent,
            delta_max,
            d_max: 0.0,
        };
        law.d_max = match damping {
            MaxDamping::Eta(eta) => {
                in_range("eta_s", eta, ETA_RANGE.0, ETA_RANGE.1, "s")?
                    * law.tangent_stiffness(delta_max)
            }
            MaxDamping::Explicit(d) => {
                in_range("d_max", d, DAMPING_RANGE.0, DAMPING_RANGE.1, "N s/m")?
            }
        };
        Ok(law)
    }

    /// The radial clearance `c` of eq. 14, m.
    pub fn clearance(&self) -> f64 {
        self.clearance
    }

    /// The maximum damping coefficient `D_max`, N s/m.
    pub fn max_damping(&self) -> f64 {
        self.d_max
    }
}

impl NormalForceLaw for ImprovedLiu {
    fn elastic_force(&self, delta: f64) -> f64 {
        if delta <= 0.0 {
            return 0.0;
        }
        self.scale * liu_factor(delta, self.clearance).0 * delta.powf(self.exponent)
    }
    /// `K_N = dF_K/d delta` (eq. 17).
    fn tangent_stiffness(&self, delta: f64) -> f64 {
        if delta <= 0.0 {
            return 0.0;
        }
        let (g, dg) = liu_factor(delta, self.clearance);
        let n = self.exponent;
        self.scale * (n * delta.powf(n - 1.0) * g + delta.powf(n) * dg)
    }
    /// `d D_imp / d delta`: the slope of the STEP ramp.
    fn damping_slope(&self, c: &NormalContact) -> f64 {
        step_slope(c.penetration, 0.0, 0.0, self.delta_max, self.d_max)
    }
    fn damping_coefficient(&self, c: &NormalContact) -> f64 {
        step(c.penetration, 0.0, 0.0, self.delta_max, self.d_max)
    }
}

/// A normal law chosen by name: static dispatch over every law of MODEL.md §2.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum NormalModel {
    /// See [`Hertz`].
    Hertz(Hertz),
    /// See [`KelvinVoigt`].
    KelvinVoigt(KelvinVoigt),
    /// See [`HuntCrossley`].
    HuntCrossley(HuntCrossley),
    /// See [`LankaraniNikravesh`].
    LankaraniNikravesh(LankaraniNikravesh),
    /// See [`FloresEtAl`].
    FloresEtAl(FloresEtAl),
    /// See [`GonthierEtAl`].
    GonthierEtAl(GonthierEtAl),
    /// See [`LiuEtAl`].
    LiuEtAl(LiuEtAl),
    /// See [`ImprovedLiu`].
    ImprovedLiu(ImprovedLiu),
}

macro_rules! dispatch_normal {
    ($self:ident, $law:ident => $e:expr) => {
        match $self {
            NormalModel::Hertz($law) => $e,
            NormalModel::KelvinVoigt($law) => $e,
            NormalModel::HuntCrossley($law) => $e,
            NormalModel::LankaraniNikravesh($law) => $e,
            NormalModel::FloresEtAl($law) => $e,
            NormalModel::GonthierEtAl($law) => $e,
            NormalModel::LiuEtAl($law) => $e,
            NormalModel::ImprovedLiu($law) => $e,
        }
    };
}

impl NormalForceLaw for NormalModel {
    fn normal_force(&self, c: &NormalContact) -> f64 {
        dispatch_normal!(self, l => l.normal_force(c))
    }
    fn elastic_force(&self, delta: f64) -> f64 {
        dispatch_normal!(self, l => l.elastic_force(delta))
    }
    fn tangent_stiffness(&self, delta: f64) -> f64 {
        dispatch_normal!(self, l => l.tangent_stiffness(delta))
    }
    fn damping_coefficient(&self, c: &NormalContact) -> f64 {
        dispatch_normal!(self, l => l.damping_coefficient(c))
    }
    fn damping_slope(&self, c: &NormalContact) -> f64 {
        dispatch_normal!(self, l => l.damping_slope(c))
    }
    fn elastic_energy(&self, delta: f64) -> f64 {
        dispatch_normal!(self, l => l.elastic_energy(delta))
    }
    fn uses_impact_rate(&self) -> bool {
        dispatch_normal!(self, l => l.uses_impact_rate())
    }
}

impl NormalModel {
    /// The radial clearance the law was built with, m, for the laws that hold one (Liu's and
    /// the improved law, eq. 14); `None` for the others.
    pub fn clearance(&self) -> Option<f64> {
        match self {
            NormalModel::LiuEtAl(l) => Some(l.clearance()),
            NormalModel::ImprovedLiu(l) => Some(l.clearance()),
            _ => None,
        }
    }

    /// Checks that the law's clearance, if it holds one, is the bearing's `clearance` (m) within
    /// a relative 1e-9 (the geometry's `R_b - R_j` may differ in the last bits from the `c` the
    /// law was given); the error names `field`.
    pub fn check_clearance(&self, field: &str, clearance: f64) -> Result<()> {
        match self.clearance() {
            Some(c) if (c - clearance).abs() > 1e-9 * clearance.abs() => Err(Error::invalid(
                field,
                format!(
                    "the {} law was built for a clearance of {} m, but the bearing's is {} m: \
                     build the law with the bearing's clearance",
                    self.name(),
                    sig4(c),
                    sig4(clearance)
                ),
            )),
            _ => Ok(()),
        }
    }

    /// The law's name as written in scene files.
    pub fn name(&self) -> &'static str {
        self.kind().name()
    }

    /// Which law this is, without its parameters.
    pub fn kind(&self) -> LawKind {
        match self {
            NormalModel::Hertz(_) => LawKind::Hertz,
            NormalModel::KelvinVoigt(_) => LawKind::KelvinVoigt,
            NormalModel::HuntCrossley(_) => LawKind::HuntCrossley,
            NormalModel::LankaraniNikravesh(_) => LawKind::LankaraniNikravesh,
            NormalModel::FloresEtAl(_) => LawKind::FloresEtAl,
            NormalModel::GonthierEtAl(_) => LawKind::GonthierEtAl,
            NormalModel::LiuEtAl(_) => LawKind::LiuEtAl,
            NormalModel::ImprovedLiu(_) => LawKind::ImprovedLiu,
        }
    }
}

/// A normal law's kind, without parameters (one byte: it travels in errors).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LawKind {
    /// [`Hertz`].
    Hertz,
    /// [`KelvinVoigt`].
    KelvinVoigt,
    /// [`HuntCrossley`].
    HuntCrossley,
    /// [`LankaraniNikravesh`].
    LankaraniNikravesh,
    /// [`FloresEtAl`].
    FloresEtAl,
    /// [`GonthierEtAl`].
    GonthierEtAl,
    /// [`LiuEtAl`].
    LiuEtAl,
    /// [`ImprovedLiu`].
    ImprovedLiu,
}

impl LawKind {
    /// The name as written in scene files.
    pub fn name(self) -> &'static str {
        match self {
            LawKind::Hertz => "Hertz",
            LawKind::KelvinVoigt => "KelvinVoigt",
            LawKind::HuntCrossley => "HuntCrossley",
            LawKind::LankaraniNikravesh => "LankaraniNikravesh",
            LawKind::FloresEtAl => "FloresEtAl",
            LawKind::GonthierEtAl => "GonthierEtAl",
            LawKind::LiuEtAl => "LiuEtAl",
            LawKind::ImprovedLiu => "ImprovedLiu",
        }
    }

    /// The parameter that limits a contact's stable step under this law: its damping when the
    /// contact is over-damped (damping ratio `zeta > 1`) and the law has a damping parameter,
    /// else what sets its stiffness.
    pub fn stiff_parameter(self, zeta: f64) -> ContactParameter {
        use ContactParameter as P;
        let damped = zeta > 1.0;
        match self {
            LawKind::ImprovedLiu if damped => P::MaxDamping,
            LawKind::KelvinVoigt if damped => P::Damping,
            LawKind::HuntCrossley
            | LawKind::LankaraniNikravesh
            | LawKind::FloresEtAl
            | LawKind::GonthierEtAl
                if damped =>
            {
                P::Restitution
            }
            LawKind::ImprovedLiu | LawKind::LiuEtAl => P::ModulusAndWidth,
            _ => P::Stiffness,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_laws_clearance_must_be_the_bearings() {
        let law = NormalModel::ImprovedLiu(
            ImprovedLiu::new(1.137e11, 0.016, 0.5e-3, 1.0, 1e-4, MaxDamping::Eta(0.01)).unwrap(),
        );
        assert_eq!(law.clearance(), Some(0.5e-3));
        // The geometry's R_b - (R_b - c) differs from c in the last bits: accepted.
        let c = 0.010 - (0.010 - 0.5e-3);
        law.check_clearance("normal", c).unwrap();
        let e = law
            .check_clearance("normal", 0.2e-3)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`normal`") && e.contains("5e-4") && e.contains("2e-4"),
            "{e}"
        );
        let liu = NormalModel::LiuEtAl(LiuEtAl::new(1.137e11, 0.016, 0.3e-3).unwrap());
        assert!(liu.check_clearance("normal", 0.5e-3).is_err());
        // A law without a clearance agrees with any bearing.
        let hertz = NormalModel::Hertz(Hertz::new(1e10, 1.5).unwrap());
        assert_eq!(hertz.clearance(), None);
        hertz.check_clearance("normal", 0.5e-3).unwrap();
    }

    fn contact(delta: f64, rate: f64, rate0: f64) -> NormalContact {
        NormalContact {
            penetration: delta,
            penetration_rate: rate,
            impact_rate: rate0,
        }
    }

    #[test]
    fn hertz_hand_values() {
        let h = Hertz::new(1e10, 1.5).unwrap();
        // 1e10 * (1e-6)^1.5 = 1e10 * 1e-9 = 10 N
        assert!((h.normal_force(&contact(1e-6, 1.0, 1.0)) - 10.0).abs() < 1e-9);
        assert!((h.tangent_stiffness(1e-6) - 1.5e7).abs() < 1e-3);
        assert!((h.elastic_energy(1e-6) - 10.0 * 1e-6 / 2.5).abs() < 1e-18);
        assert_eq!(h.normal_force(&contact(-1e-6, 1.0, 1.0)), 0.0);
    }

    #[test]
    fn hysteresis_factors_hand_values() {
        let cr = 0.8;
        assert!((HuntCrossley::new(1.0, 1.5, cr).unwrap().hysteresis_factor() - 0.3).abs() < 1e-15);
        assert!(
            (LankaraniNikravesh::new(1.0, 1.5, cr)
                .unwrap()
                .hysteresis_factor()
                - 0.27)
                .abs()
                < 1e-15
        );
        assert!((FloresEtAl::new(1.0, 1.5, cr).unwrap().hysteresis_factor() - 0.4).abs() < 1e-15);
        assert!(
            (GonthierEtAl::new(1.0, 1.5, cr).unwrap().hysteresis_factor() - 0.45).abs() < 1e-15
        );
        // LN at delta = 1e-6, K = 1e10: elastic 10 N; delta_dot/delta_dot0 = 0.5 -> 10 (1 + 0.135)
        let ln = LankaraniNikravesh::new(1e10, 1.5, cr).unwrap();
        assert!((ln.normal_force(&contact(1e-6, 0.5, 1.0)) - 11.35).abs() < 1e-9);
        // restitution phase with a large rate: clamped at 0, never pulling
        assert_eq!(ln.normal_force(&contact(1e-6, -10.0, 1.0)), 0.0);
    }

    #[test]
    fn ln_stiffness_from_geometry_hand_value() {
        let g = super::super::BearingGeometry::new(0.01, 0.0095, 0.016).unwrap();
        let s = super::super::Material::STEEL;
        // sigma = 0.91/207e9 = 4.3961e-12; K = 4/(3*8.7923e-12) * sqrt(0.01*0.0095/0.0005) = 1.5165e11 * 0.43589
        let k = LankaraniNikravesh::stiffness_from_geometry(&g, &s, &s);
        let expected = 4.0 / (3.0 * 2.0 * 0.91 / 207e9) * (0.01f64 * 0.0095 / 0.0005).sqrt();
        assert!((k - expected).abs() / expected < 1e-14);
        assert!((k - 6.6104e10).abs() / 6.6104e10 < 1e-4, "{k}");
    }

    #[test]
    fn liu_and_improved_hand_values() {
        // E* = 1e11, L = 0.01 -> scale = pi/2 * 1e9; c = 1e-4, delta = 1e-4:
        // sqrt(1e-4/(2*2e-4)) = 0.5; Liu F = scale * 1e-4 * 0.5
        let liu = LiuEtAl::new(1e11, 0.01, 1e-4).unwrap();
        let scale = 0.5 * PI * 1e9;
        assert!((liu.elastic_force(1e-4) - scale * 0.5e-4).abs() < 1e-6);
        // improved with n = 1 and no damping equals Liu
        let imp = ImprovedLiu::new(1e11, 0.01, 1e-4, 1.0, 1e-4, MaxDamping::Eta(0.0)).unwrap();
        assert!((imp.elastic_force(3e-6) - liu.elastic_force(3e-6)).abs() < 1e-9);
        assert!((imp.tangent_stiffness(3e-6) - liu.tangent_stiffness(3e-6)).abs() < 1e-3);
        // K_N at delta = c = 1e-4 with n = 1: g = 0.5, g' = c/(4 (2c)^2 g) = 1/(8c) = 1250;
        // K_N = scale (0.5 + 1e-4 * 1250) = scale * 0.625
        assert!((imp.tangent_stiffness(1e-4) - scale * 0.625).abs() < 1e-3);
        // eta = 0.01 s -> D_max = 0.01 * K_N(delta_max)
        let imp = ImprovedLiu::new(1e11, 0.01, 1e-4, 1.0, 1e-4, MaxDamping::Eta(0.01)).unwrap();
        assert!((imp.max_damping() - 0.01 * scale * 0.625).abs() < 1e-6);
        // D_imp at delta_max/2 = D_max/2 (STEP midpoint); force = F_K + D delta_dot
        let c = contact(0.5e-4, 0.001, 1.0);
        let expected = imp.elastic_force(0.5e-4) + 0.5 * imp.max_damping() * 0.001;
        assert!((imp.normal_force(&c) - expected).abs() < 1e-6 * expected);
    }

    #[test]
    fn tangent_stiffness_matches_finite_difference() {
        let laws = [
            NormalModel::ImprovedLiu(
                ImprovedLiu::new(1.1e11, 0.016, 5e-4, 1.5, 1e-4, MaxDamping::Eta(0.01)).unwrap(),
            ),
            NormalModel::LiuEtAl(LiuEtAl::new(1.1e11, 0.016, 5e-4).unwrap()),
            NormalModel::Hertz(Hertz::new(1e10, 1.5).unwrap()),
        ];
        for law in laws {
            for d in [1e-7, 2e-6, 5e-5] {
                let h = d * 1e-6;
                let fd = (law.elastic_force(d + h) - law.elastic_force(d - h)) / (2.0 * h);
                assert!(
                    (fd - law.tangent_stiffness(d)).abs() < 1e-6 * fd.abs(),
                    "{} at {d}",
                    law.name()
                );
            }
        }
    }

    #[test]
    fn numeric_energy_matches_closed_form() {
        // Liu with c >> delta behaves like delta^1.5 / sqrt(2c); compare default quadrature
        // against Hertz's closed form through a law that uses the default.
        let liu = LiuEtAl::new(1e11, 0.01, 1e-4).unwrap();
        let d = 2e-6;
        // trapezoid with many points as reference
        let n = 200_000;
        let mut e = 0.0;
        for i in 0..n {
            let a = d * i as f64 / n as f64;
            let b = d * (i + 1) as f64 / n as f64;
            e += 0.5 * (liu.elastic_force(a) + liu.elastic_force(b)) * (b - a);
        }
        assert!((liu.elastic_energy(d) - e).abs() < 1e-7 * e);
    }

    #[test]
    fn penetration_for_energy_inverts_the_elastic_energy() {
        let hertz = Hertz::new(1e10, 1.5).unwrap();
        let d = penetration_for_energy(&hertz, hertz.elastic_energy(3e-6), 1e-9);
        assert!((d - 3e-6).abs() < 1e-12, "{d}");
        let liu = LiuEtAl::new(1.137e11, 0.016, 5e-4).unwrap();
        for target in [1e-7, 2e-6, 4e-5] {
            let d = penetration_for_energy(&liu, liu.elastic_energy(target), 1e-6);
            assert!((d - target).abs() < 0.03 * target, "{target} -> {d}");
        }
        assert_eq!(penetration_for_energy(&liu, 0.0, 1e-6), 0.0);
    }

    #[test]
    fn invalid_parameters_are_named() {
        let err = Hertz::new(-1.0, 1.5).unwrap_err().to_string();
        assert!(
            err.contains("stiffness") && err.contains("between 1 and 1e16"),
            "{err}"
        );
        let err = HuntCrossley::new(1.0, 1.5, 1.5).unwrap_err().to_string();
        assert!(err.contains("restitution"), "{err}");
        let err = ImprovedLiu::new(1e11, 0.01, f64::NAN, 1.0, 1e-4, MaxDamping::Eta(0.01))
            .unwrap_err()
            .to_string();
        assert!(err.contains("clearance") && err.contains("NaN"), "{err}");
    }
}
