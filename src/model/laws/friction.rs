//! Friction laws (MODEL.md §3): a coefficient `mu(v)` of the slip speed `v = |v_t|`; the
//! friction force is `mu(v) F_N`, opposing the slip.

use super::step::step;
use crate::error::{Error, Result, in_range, sig4};

/// Physical range of a friction coefficient (0 to 2: beyond clean metals in vacuum).
pub const MU_RANGE: (f64, f64) = (0.0, 2.0);
/// Physical range of a friction law's characteristic speed, m/s (up to 100 m/s).
pub const SPEED_RANGE: (f64, f64) = (1e-12, 100.0);

fn mu(field: &str, value: f64) -> Result<f64> {
    in_range(field, value, MU_RANGE.0, MU_RANGE.1, "")
}

fn speed(field: &str, value: f64) -> Result<f64> {
    in_range(field, value, SPEED_RANGE.0, SPEED_RANGE.1, "m/s")
}

/// A friction law `mu(v)`.
pub trait FrictionLaw {
    /// Friction coefficient at slip speed `v >= 0` (m/s).
    fn coefficient(&self, slip_speed: f64) -> f64;
    /// The largest coefficient the law can return: friction never exceeds `max_coefficient F_N`.
    fn max_coefficient(&self) -> f64;
    /// The coefficient of steady sliding, `mu_d` for every law here: the law at a slip speed far
    /// above its transition speeds (1 km/s). A Coulomb constraint (stick below it, slide at it)
    /// takes this one coefficient.
    fn sliding_coefficient(&self) -> f64 {
        self.coefficient(1e3)
    }
    /// The slip speed `x >= 0` with `x + k mu(x) = target` (`target > 0`, `k > 0`: friction
    /// taken at the slip it leaves, as an implicit step takes it), where the law gives it in
    /// closed form; `None` (the default) leaves it to a numerical root.
    fn closed_form_slip(&self, _target: f64, _k: f64) -> Option<f64> {
        None
    }
}

/// Regularised Coulomb: `mu = mu_d min(1, v/v_eps)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coulomb {
    mu_d: f64,
    v_eps: f64,
}

impl Coulomb {
    /// Dynamic coefficient `mu_d >= 0`, regularisation speed `v_eps > 0` (m/s).
    pub fn new(mu_d: f64, v_eps: f64) -> Result<Self> {
        Ok(Coulomb {
            mu_d: mu("mu_d", mu_d)?,
            v_eps: speed("v_eps", v_eps)?,
        })
    }
}

impl FrictionLaw for Coulomb {
    fn coefficient(&self, v: f64) -> f64 {
        self.mu_d * (v / self.v_eps).min(1.0)
    }
    fn max_coefficient(&self) -> f64 {
        self.mu_d
    }
    /// `x + k mu_d x/v_eps = target` below `v_eps`, `x + k mu_d = target` above: the two
    /// linear pieces solved directly (a bracketed root takes several of the law's evaluations
    /// to reach the same value within its width, 1e-14 of `target`).
    fn closed_form_slip(&self, target: f64, k: f64) -> Option<f64> {
        let friction = k * self.mu_d;
        Some(if target <= self.v_eps + friction {
            target / (1.0 + friction / self.v_eps)
        } else {
            target - friction
        })
    }
}

/// Threlfall: `mu = mu_d (1 - exp(-3 v/v_0))`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Threlfall {
    mu_d: f64,
    v0: f64,
}

impl Threlfall {
    /// Dynamic coefficient `mu_d >= 0`, characteristic speed `v_0 > 0` (m/s).
    pub fn new(mu_d: f64, v0: f64) -> Result<Self> {
        Ok(Threlfall {
            mu_d: mu("mu_d", mu_d)?,
            v0: speed("v0", v0)?,
        })
    }
}

impl FrictionLaw for Threlfall {
    fn coefficient(&self, v: f64) -> f64 {
        self.mu_d * (1.0 - (-3.0 * v / self.v0).exp())
    }
    fn max_coefficient(&self) -> f64 {
        self.mu_d
    }
}

/// Ambrosio: `mu = mu_d c_d` with `c_d` ramping linearly from 0 at `v_0` to 1 at `v_1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ambrosio {
    mu_d: f64,
    v0: f64,
    v1: f64,
}

impl Ambrosio {
    /// Dynamic coefficient `mu_d >= 0`, speeds `0 <= v_0 < v_1` (m/s).
    pub fn new(mu_d: f64, v0: f64, v1: f64) -> Result<Self> {
        mu("mu_d", mu_d)?;
        in_range("v0", v0, 0.0, SPEED_RANGE.1, "m/s")?;
        speed("v1", v1)?;
        if v1 <= v0 {
            return Err(Error::invalid(
                "v1",
                format!(
                    "must be greater than v0 = {} m/s (got {} m/s)",
                    sig4(v0),
                    sig4(v1)
                ),
            ));
        }
        Ok(Ambrosio { mu_d, v0, v1 })
    }
}

impl FrictionLaw for Ambrosio {
    fn coefficient(&self, v: f64) -> f64 {
        let cd = if v <= self.v0 {
            0.0
        } else if v <= self.v1 {
            (v - self.v0) / (self.v1 - self.v0)
        } else {
            1.0
        };
        self.mu_d * cd
    }
    fn max_coefficient(&self) -> f64 {
        self.mu_d
    }
}

/// Bai / MSC Adams stiction (the paper's eq. 19): 0 at rest, `mu_s` at the stiction transition
/// speed `v_s`, falling smoothly to `mu_d` at the dynamic transition speed `v_d`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bai {
    mu_s: f64,
    mu_d: f64,
    v_s: f64,
    v_d: f64,
}

impl Bai {
    /// The paper's table 3, dry (no lubrication): `mu_s = 0.3, mu_d = 0.25, v_s = 0.1 mm/s, v_d = 10 mm/s`.
    pub const DRY: Bai = Bai {
        mu_s: 0.3,
        mu_d: 0.25,
        v_s: 1e-4,
        v_d: 1e-2,
    };
    /// The paper's table 3, lubricated: `mu_s = 0.08, mu_d = 0.05`, same transition speeds.
    pub const LUBRICATED: Bai = Bai {
        mu_s: 0.08,
        mu_d: 0.05,
        v_s: 1e-4,
        v_d: 1e-2,
    };

    /// Static `mu_s` and dynamic `mu_d` coefficients (`>= 0`), transition speeds `0 < v_s < v_d` (m/s).
    pub fn new(mu_s: f64, mu_d: f64, v_s: f64, v_d: f64) -> Result<Self> {
        mu("mu_s", mu_s)?;
        mu("mu_d", mu_d)?;
        speed("v_s", v_s)?;
        speed("v_d", v_d)?;
        if v_d <= v_s {
            return Err(Error::invalid(
                "v_d",
                format!(
                    "must be greater than v_s = {} m/s (got {} m/s)",
                    sig4(v_s),
                    sig4(v_d)
                ),
            ));
        }
        Ok(Bai {
            mu_s,
            mu_d,
            v_s,
            v_d,
        })
    }
}

impl FrictionLaw for Bai {
    fn coefficient(&self, v: f64) -> f64 {
        if v >= self.v_d {
            self.mu_d
        } else if v >= self.v_s {
            step(v, self.v_s, self.mu_s, self.v_d, self.mu_d)
        } else {
            step(v, -self.v_s, -self.mu_s, self.v_s, self.mu_s)
        }
    }
    fn max_coefficient(&self) -> f64 {
        self.mu_s.max(self.mu_d)
    }
}

/// No friction.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Frictionless;

impl FrictionLaw for Frictionless {
    fn coefficient(&self, _: f64) -> f64 {
        0.0
    }
    fn max_coefficient(&self) -> f64 {
        0.0
    }
}

/// A friction law chosen by name: static dispatch over every law of MODEL.md §3.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum FrictionModel {
    /// See [`Frictionless`].
    None,
    /// See [`Coulomb`].
    Coulomb(Coulomb),
    /// See [`Threlfall`].
    Threlfall(Threlfall),
    /// See [`Ambrosio`].
    Ambrosio(Ambrosio),
    /// See [`Bai`].
    Bai(Bai),
}

impl FrictionLaw for FrictionModel {
    fn coefficient(&self, v: f64) -> f64 {
        match self {
            FrictionModel::None => 0.0,
            FrictionModel::Coulomb(l) => l.coefficient(v),
            FrictionModel::Threlfall(l) => l.coefficient(v),
            FrictionModel::Ambrosio(l) => l.coefficient(v),
            FrictionModel::Bai(l) => l.coefficient(v),
        }
    }
    fn max_coefficient(&self) -> f64 {
        match self {
            FrictionModel::None => 0.0,
            FrictionModel::Coulomb(l) => l.max_coefficient(),
            FrictionModel::Threlfall(l) => l.max_coefficient(),
            FrictionModel::Ambrosio(l) => l.max_coefficient(),
            FrictionModel::Bai(l) => l.max_coefficient(),
        }
    }
    fn closed_form_slip(&self, target: f64, k: f64) -> Option<f64> {
        match self {
            FrictionModel::None => Some(target),
            FrictionModel::Coulomb(l) => l.closed_form_slip(target, k),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hand_values() {
        let c = Coulomb::new(0.2, 1e-3).unwrap();
        assert!((c.coefficient(0.5e-3) - 0.1).abs() < 1e-15);
        assert_eq!(c.coefficient(1.0), 0.2);
        let t = Threlfall::new(0.2, 1e-3).unwrap();
        assert!((t.coefficient(1e-3) - 0.2 * (1.0 - (-3.0f64).exp())).abs() < 1e-15);
        let a = Ambrosio::new(0.2, 1e-3, 3e-3).unwrap();
        assert_eq!(a.coefficient(0.5e-3), 0.0);
        assert!((a.coefficient(2e-3) - 0.1).abs() < 1e-15);
        assert_eq!(a.coefficient(1.0), 0.2);
    }

    #[test]
    fn bai_shape() {
        let b = Bai::DRY;
        assert_eq!(b.coefficient(0.0), 0.0);
        assert!((b.coefficient(1e-4) - 0.3).abs() < 1e-15);
        assert_eq!(b.coefficient(1e-2), 0.25);
        // halfway between 0 and v_s on the odd STEP: s = 0.75 -> -0.3 + 0.6 * 0.5625 * 1.5 = 0.20625
        assert!((b.coefficient(0.5e-4) - 0.20625).abs() < 1e-14);
        // halfway between v_s and v_d: 0.3 - 0.05 * 0.5 = 0.275
        assert!((b.coefficient(0.5 * (1e-4 + 1e-2)) - 0.275).abs() < 1e-14);
    }

    #[test]
    fn invalid_parameters_are_named() {
        let err = Bai::new(0.3, 0.25, 1e-2, 1e-4).unwrap_err().to_string();
        assert!(err.contains("v_d"), "{err}");
        let err = Coulomb::new(f64::NAN, 1e-3).unwrap_err().to_string();
        assert!(err.contains("mu_d") && err.contains("NaN"), "{err}");
    }
}
