//! Normal contact-force laws (MODEL.md §2).

use super::step::{step, step_slope};
use crate::error::{
    ContactParameter, Error, Result, in_range, in_range_open_closed, positive, sig4,
};
use std::f64::consts::PI;

mod model;
pub use model::{LawKind, NormalModel};

#[cfg(test)]
mod tests;

/// The state a normal law is evaluated at.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NormalContact {
    /// Penetration `delta = |e| - c`, m (contact only when > 0).
    pub penetration: f64,
    /// Penetration rate `delta_dot`, m/s (positive while the surfaces approach).
    pub penetration_rate: f64,
    /// Penetration rate when the current contact began, `delta_dot0`, m/s, already floored to a
    /// positive minimum by the joint (see `HingeDesign::min_impact_speed`).
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
    if delta <= 0.0 { 0.0 } else { power(delta, n) }
}

/// `x^n`, exact and without the library's `pow` for the exponents 1 and 0 (the linear laws and
/// their stiffness): `pow` was a tenth of a spatial joint's cost on the improved law with
/// `n = 1`.
fn power(x: f64, n: f64) -> f64 {
    if n == 1.0 {
        x
    } else if n == 0.0 {
        1.0
    } else {
        general_power(x, n)
    }
}

/// `x^n` by the library's `pow`, behind a call the optimiser keeps on its branch: `powf` is a
/// side-effect-free intrinsic, and inlined into the laws the branches above became a select
/// of `pow`'s result, called for every exponent (a twentieth of the paper's sub-cycled run's
/// CPU, with `n = 1`).
#[inline(never)]
fn general_power(x: f64, n: f64) -> f64 {
    x.powf(n)
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
            self.stiffness * self.exponent * power(delta, self.exponent - 1.0)
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
        self.scale * liu_factor(delta, self.clearance).0 * power(delta, self.exponent)
    }
    /// `K_N = dF_K/d delta` (eq. 17).
    fn tangent_stiffness(&self, delta: f64) -> f64 {
        if delta <= 0.0 {
            return 0.0;
        }
        let (g, dg) = liu_factor(delta, self.clearance);
        let n = self.exponent;
        self.scale * (n * power(delta, n - 1.0) * g + power(delta, n) * dg)
    }
    /// `d D_imp / d delta`: the slope of the STEP ramp.
    fn damping_slope(&self, c: &NormalContact) -> f64 {
        step_slope(c.penetration, 0.0, 0.0, self.delta_max, self.d_max)
    }
    fn damping_coefficient(&self, c: &NormalContact) -> f64 {
        step(c.penetration, 0.0, 0.0, self.delta_max, self.d_max)
    }
}
