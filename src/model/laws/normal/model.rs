//! [`NormalModel`]: a normal law chosen by name, and [`LawKind`], its kind without parameters.

use super::*;

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
