//! Errors as values: every failure names the field or file it concerns and says why.

use crate::rapier::observers::stall::Stall;
use crate::rapier::pipeline::protocol::Violation;
use std::path::PathBuf;

mod divergence;
pub use divergence::Divergence;

/// Everything that can go wrong in this crate. Nothing here panics on bad input.
///
/// The messages speak to the caller of the layer that returns them: the plain API's errors name
/// the API's parameters (`dt`, [`StepControl`](crate::rapier::pipeline::stepper::StepControl)'s `max_dt`,
/// a law's `stiffness`); the ECS layer and the scene layer put their own names in
/// ([`Error::named`]: `Physics::world.rapier.integration_parameters.dt`, `run.dt_s`,
/// `hinges[NAME].clearance.contact.eta_s`). No message carries an application's command-line
/// flags: the variants carry the numbers, so an application phrases its own advice.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A parameter is out of its domain (`field` is the name or path of the parameter as the
    /// caller knows it: `clearance`, or in a scene `hinges[hinge].clearance.clearance_mm`).
    #[error("invalid `{field}`: {reason}")]
    Invalid {
        /// Name or path of the offending parameter.
        field: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A scene file or override could not be parsed.
    #[error("cannot parse {what}: {reason}")]
    Parse {
        /// What was being parsed (a file name or an override).
        what: String,
        /// The parser's message, with position where known.
        reason: String,
    },
    /// The time step is too large for the stiffness (and damping) of a contact: the explicit
    /// integration would blow up. Raised before the state is destroyed, never silently. The
    /// message names the contact parameter that makes the contact this stiff
    /// ([`ContactParameter`]) and gives advice fitting the step mode (when the code that raised
    /// it knows the mode, see [`Error::with_step_mode`]); the numbers are [`StepLimit`]'s.
    #[error("{0}")]
    StepTooLarge(Box<StepLimit>),
    /// The simulation state became non-physical: a body left the physical range, reactions that
    /// cannot be solved, a value bound for an output that is not finite. What diverged, where,
    /// and its value are [`Divergence`]'s.
    #[error("simulation diverged at t = {t:.6} s: {what}")]
    Diverged {
        /// Simulated time when detected.
        t: f64,
        /// What diverged (in words through its `Display`).
        what: Box<Divergence>,
    },
    /// The step control could not make progress: every step it tried was rejected, it stayed
    /// at its floor without advancing the simulated time, a sub-cycle stayed at its cap of
    /// sub-steps, or a sub-cycled contact asked for steps below the floor.
    #[error("the step control stalled at t = {t:.6} s: {stall}")]
    Stalled {
        /// Simulated time when detected.
        t: f64,
        /// What was seen, the contact that stopped the step control and the cause found from
        /// its numbers (in words through its `Display`).
        stall: Box<Stall>,
    },
    /// A run-time guard was violated and the step control is strict
    /// ([`StepControl::strict`](crate::rapier::pipeline::stepper::StepControl::strict), a scene's
    /// `run.strict`).
    #[error("guard violated (strict) by t = {t:.6} s: {}", in_words(violations))]
    Guard {
        /// Simulated time when detected.
        t: f64,
        /// The violations (in words: their `Display`, joined by `; `).
        violations: Vec<Violation>,
    },
    /// A convergence check found metrics that move beyond their bounds at a tighter step
    /// control ([`ConvergenceCheck::strict`](crate::scene::runner::convergence::ConvergenceCheck::strict)).
    #[error(
        "not converged at this step control: against half its tolerance (or half its fixed step) \
         {flagged} metric(s) moved beyond their bounds, the worst {worst}"
    )]
    NotConverged {
        /// How many metrics were flagged.
        flagged: usize,
        /// The worst, in words.
        worst: String,
    },
    /// A result folder cannot be used: it is not a folder, or another run is writing into it.
    /// The message calls it the output folder: an application names its own option for it.
    #[error("invalid `output folder`: {reason}")]
    OutputFolder {
        /// The folder.
        folder: PathBuf,
        /// What is wrong with it.
        reason: String,
    },
    /// A file could not be read or written.
    #[error("{action} `{path}`: {source}")]
    Io {
        /// What was being done ("cannot write", ...).
        action: &'static str,
        /// The file.
        path: PathBuf,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
}

/// A step beyond the stability limit of a contact: the numbers of [`Error::StepTooLarge`].
/// Its `Display` is the error's message.
#[derive(Clone, Debug, PartialEq)]
pub struct StepLimit {
    pub(crate) field: String,
    pub(crate) joint: String,
    pub(crate) dt: f64,
    pub(crate) dt_max: f64,
    pub(crate) t: Option<f64>,
    pub(crate) penetration_um: f64,
    pub(crate) omega: f64,
    pub(crate) zeta: f64,
    pub(crate) parameter: ContactParameter,
    pub(crate) adaptive: Option<bool>,
    pub(crate) names: Option<ParameterNames>,
}

impl StepLimit {
    /// A step `dt` (s, the plain API's `dt`) beyond the limit `dt_max` (s) of the contact of
    /// joint `joint`, linearised at a penetration of `penetration_um` (um) to a natural
    /// frequency `omega` (rad/s) and a damping ratio `zeta`; `parameter` makes it this stiff.
    pub fn new(
        joint: impl Into<String>,
        dt: f64,
        dt_max: f64,
        penetration_um: f64,
        omega: f64,
        zeta: f64,
        parameter: ContactParameter,
    ) -> StepLimit {
        StepLimit {
            field: "dt".into(),
            joint: joint.into(),
            dt,
            dt_max,
            t: None,
            penetration_um,
            omega,
            zeta,
            parameter,
            adaptive: None,
            names: None,
        }
    }

    /// The parameter that sets the step, as the caller names it: `dt` from the plain API,
    /// `Physics::world.rapier.integration_parameters.dt` from the ECS layer, `run.dt_s` from a
    /// scene.
    pub fn field(&self) -> &str {
        &self.field
    }

    /// The name of the joint whose contact limits the step.
    pub fn joint(&self) -> &str {
        &self.joint
    }

    /// The step in use, s.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The largest stable step for this contact, s.
    pub fn dt_max(&self) -> f64 {
        self.dt_max
    }

    /// Simulated time when detected, s, when the caller knows it.
    pub fn t(&self) -> Option<f64> {
        self.t
    }

    /// Penetration at detection, micrometres.
    pub fn penetration_um(&self) -> f64 {
        self.penetration_um
    }

    /// Linearised natural frequency of the contact, rad/s.
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// Linearised damping ratio of the contact.
    pub fn zeta(&self) -> f64 {
        self.zeta
    }

    /// The contact parameter that makes the contact this stiff (or this damped).
    pub fn parameter(&self) -> ContactParameter {
        self.parameter
    }

    /// Whether the step was adaptive (`Some(true)`), fixed (`Some(false)`) or unknown to the
    /// code that raised the error (`None`); see [`Error::with_step_mode`].
    pub fn adaptive(&self) -> Option<bool> {
        self.adaptive
    }

    /// The caller's names of the parameters the advice mentions, when a layer above the plain
    /// API put its own ([`Error::named`]); `None`: the plain API's names.
    pub fn names(&self) -> Option<&ParameterNames> {
        self.names.as_ref()
    }
}

impl std::fmt::Display for StepLimit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "`{}` = {} s is too large for the contact of joint `{}`{}: the explicit step is \
             stable only below {} s there (penetration {} um, natural frequency {} rad/s, damping ratio {}). {}",
            self.field,
            sig4(self.dt),
            self.joint,
            self.t
                .map_or(String::new(), |t| format!(" at t = {} s", sig4(t))),
            sig4(self.dt_max),
            sig4(self.penetration_um),
            sig4(self.omega),
            sig4(self.zeta),
            step_advice(
                &self.field,
                self.dt_max,
                self.parameter,
                self.adaptive,
                self.names.as_ref()
            ),
        )
    }
}

/// The contact parameter that makes a contact stiff (or, when it is over-damped, damped): what
/// to change when no step resolves the contact. Chosen by the code that raises
/// [`Error::StepTooLarge`] from the contact law and its damping ratio.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ContactParameter {
    /// The law's stiffness `K` (Hertz, Kelvin-Voigt, the hysteresis laws), or the materials'
    /// Young's moduli where `K` is computed from the geometry.
    Stiffness,
    /// The materials' Young's moduli and the bearing's width: the stiffness of the Liu laws is
    /// (pi/2) E* L.
    ModulusAndWidth,
    /// The Kelvin-Voigt law's damping `D` (an over-damped contact).
    Damping,
    /// The improved law's maximum damping, set by `eta` or `D_max` (an over-damped contact).
    MaxDamping,
    /// A hysteresis law's restitution (an over-damped contact: a lower restitution damps
    /// harder).
    Restitution,
}

impl ContactParameter {
    /// The plain API's names of the parameter, in the order [`ParameterNames::contact`] gives
    /// a caller's own: [`Stiffness`](Self::Stiffness): the law's `stiffness`, then the
    /// materials' modulus; [`ModulusAndWidth`](Self::ModulusAndWidth): the moduli, then the
    /// width; [`MaxDamping`](Self::MaxDamping): `eta`, then `D_max`.
    pub fn api_names(self) -> &'static [&'static str] {
        match self {
            ContactParameter::Stiffness => &["stiffness", "Material::youngs_modulus_pa"],
            ContactParameter::ModulusAndWidth => &["Material::youngs_modulus_pa", "length"],
            ContactParameter::Damping => &["damping"],
            ContactParameter::MaxDamping => &["MaxDamping::Eta", "MaxDamping::Explicit"],
            ContactParameter::Restitution => &["restitution"],
        }
    }

    /// The parameter in words, under `names` (the API's, or a caller's in the same order).
    fn describe<S: AsRef<str>>(self, names: &[S]) -> String {
        let quoted: Vec<String> = names.iter().map(|n| format!("`{}`", n.as_ref())).collect();
        let (first, rest) = match quoted.split_first() {
            Some((first, rest)) => (first.clone(), rest),
            None => return "its contact law's parameters".into(),
        };
        let list = match quoted.len() {
            1 => first.clone(),
            n => format!("{} and {}", quoted[..n - 1].join(", "), quoted[n - 1]),
        };
        match self {
            ContactParameter::Stiffness if !rest.is_empty() => format!(
                "{first} (or the materials' {} when the stiffness is left to the geometry)",
                rest.join(", ")
            ),
            ContactParameter::MaxDamping if !rest.is_empty() => {
                format!("{first} (or {})", rest.join(", "))
            }
            ContactParameter::ModulusAndWidth => {
                format!("{list} (the law's stiffness is (pi/2) E* L)")
            }
            ContactParameter::Restitution => {
                format!("{list} (a lower restitution damps harder)")
            }
            _ => list,
        }
    }
}

/// A caller's own names for the parameters a step-limit error advises on, put in by the layer
/// that knows them (the ECS layer, the scene layer) with [`Error::named`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ParameterNames {
    /// How the caller turns adaptive stepping on (e.g. `run.step = Adaptive`); empty: the plain
    /// API's [`StepControl::adaptive`](crate::rapier::pipeline::stepper::StepControl::adaptive).
    pub adaptive: String,
    /// The contact parameters, in the order of [`ContactParameter::api_names`] (e.g.
    /// `hinges[pin].clearance.contact.eta_s`, `d_max_n_s_per_m`); empty: the plain API's names.
    pub contact: Vec<String>,
}

/// Guard violations in words, as [`Error::Guard`] shows them.
fn in_words(violations: &[Violation]) -> String {
    violations
        .iter()
        .map(Violation::to_string)
        .collect::<Vec<_>>()
        .join("; ")
}

/// Shorthand for results of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// An [`Error::Invalid`] for `field` with `reason`.
    pub fn invalid(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::Invalid {
            field: field.into(),
            reason: reason.into(),
        }
    }

    /// An [`Error::Parse`] for `what` with `reason`, each cut to [`MAX_QUOTE`] characters: a
    /// parser may quote the offending input, which can be a whole file of garbage.
    pub fn parse(what: impl AsRef<str>, reason: impl AsRef<str>) -> Self {
        Error::Parse {
            what: excerpt(what.as_ref(), MAX_QUOTE),
            reason: excerpt(reason.as_ref(), MAX_QUOTE),
        }
    }

    /// Tells an [`Error::StepTooLarge`] whether the step was adaptive, so its message gives the
    /// advice that fits the mode; other variants pass through.
    pub fn with_step_mode(mut self, is_adaptive: bool) -> Self {
        if let Error::StepTooLarge(limit) = &mut self {
            limit.adaptive = Some(is_adaptive);
        }
        self
    }

    /// Puts a caller's names into an [`Error::StepTooLarge`]: `step` for the parameter that sets
    /// the step, and the names of `names` for the rest (how the layer above the plain API calls
    /// them); other variants pass through.
    pub fn named(mut self, step: &str, names: ParameterNames) -> Self {
        if let Error::StepTooLarge(limit) = &mut self {
            limit.field = step.into();
            limit.names = Some(names);
        }
        self
    }

    /// The fixed step an [`Error::StepTooLarge`] advises, s: 80 % of the contact's stability
    /// limit, when the step was fixed and such a step can be taken (`None` otherwise, and for
    /// other variants). An application phrases it in its own options.
    pub fn suggested_step(&self) -> Option<f64> {
        match self {
            Error::StepTooLarge(limit)
                if limit.adaptive == Some(false) && 0.8 * limit.dt_max >= SMALLEST_STEP =>
            {
                Some(0.8 * limit.dt_max)
            }
            _ => None,
        }
    }

    /// Prefixes the field path of an [`Error::Invalid`] with `prefix` (`prefix.field`);
    /// other variants pass through. Used when a nested value is validated in context.
    pub fn within(self, prefix: &str) -> Self {
        match self {
            Error::Invalid { field, reason } => Error::Invalid {
                field: format!("{prefix}.{field}"),
                reason,
            },
            other => other,
        }
    }
}

/// Checks that `value` is finite and strictly positive.
pub fn positive(field: &str, value: f64) -> Result<f64> {
    if value.is_nan() {
        Err(Error::invalid(field, "is NaN"))
    } else if !value.is_finite() {
        Err(Error::invalid(
            field,
            format!("must be finite (got {})", sig4(value)),
        ))
    } else if value <= 0.0 {
        Err(Error::invalid(
            field,
            format!("must be > 0 (got {})", sig4(value)),
        ))
    } else {
        Ok(value)
    }
}

/// Checks that `value` is finite and not negative.
pub fn non_negative(field: &str, value: f64) -> Result<f64> {
    if value.is_nan() {
        Err(Error::invalid(field, "is NaN"))
    } else if !value.is_finite() {
        Err(Error::invalid(
            field,
            format!("must be finite (got {})", sig4(value)),
        ))
    } else if value < 0.0 {
        Err(Error::invalid(
            field,
            format!("must be >= 0 (got {})", sig4(value)),
        ))
    } else {
        Ok(value)
    }
}

/// Checks that `value` is finite (any sign).
pub fn finite(field: &str, value: f64) -> Result<f64> {
    if value.is_nan() {
        Err(Error::invalid(field, "is NaN"))
    } else if !value.is_finite() {
        Err(Error::invalid(
            field,
            format!("must be finite (got {})", sig4(value)),
        ))
    } else {
        Ok(value)
    }
}

/// Checks that `lo < value <= hi` (finite).
pub fn in_range_open_closed(field: &str, value: f64, lo: f64, hi: f64) -> Result<f64> {
    finite(field, value)?;
    if value <= lo || value > hi {
        Err(Error::invalid(
            field,
            format!(
                "must be in ({}, {}] (got {})",
                sig4(lo),
                sig4(hi),
                sig4(value)
            ),
        ))
    } else {
        Ok(value)
    }
}

/// Checks that `v` is finite and non-zero; returns it normalised.
pub fn unit_vector(
    field: &str,
    v: rapier3d_f64::math::Vector,
) -> Result<rapier3d_f64::math::Vector> {
    let n = v.length();
    if !n.is_finite() || n < 1e-12 {
        return Err(Error::invalid(
            field,
            format!("must be a finite, non-zero vector (got {v:?})"),
        ));
    }
    Ok(v / n)
}

/// Checks that `value` lies in its physical range `[lo, hi]` (`unit` is appended to the bounds
/// in the message). A value far outside (an exponent of 1e300) is a typo, and refusing it at
/// load beats a run that crawls at its smallest step or blames a body for leaving its range.
pub fn in_range(field: &str, value: f64, lo: f64, hi: f64, unit: &str) -> Result<f64> {
    finite(field, value)?;
    if value < lo || value > hi {
        let unit = if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        };
        return Err(Error::invalid(
            field,
            format!(
                "must be between {} and {}{unit} (got {}): outside the physical range this crate accepts",
                sig4(lo),
                sig4(hi),
                sig4(value)
            ),
        ));
    }
    Ok(value)
}

/// Most characters of quoted input an error message carries.
pub const MAX_QUOTE: usize = 500;

/// `text` cut to `max` characters, with a note of how much was left out.
pub fn excerpt(text: &str, max: usize) -> String {
    match text.char_indices().nth(max) {
        None => text.to_string(),
        Some((cut, _)) => format!(
            "{}... ({} more characters)",
            &text[..cut],
            text[cut..].chars().count()
        ),
    }
}

/// A number with 4 significant digits for messages: plain between 1e-3 and 1e5 (`0.0875`,
/// `182`), scientific otherwise (`1.312e-4`), trailing zeros dropped.
pub fn sig4(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    if !x.is_finite() {
        return format!("{x}");
    }
    let a = x.abs();
    let trim = |m: &str| -> String {
        if m.contains('.') {
            m.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            m.to_string()
        }
    };
    if (1e-3..1e5).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
        trim(&format!("{x:.decimals$}"))
    } else {
        let s = format!("{x:.3e}");
        match s.split_once('e') {
            Some((m, e)) => format!("{}e{e}", trim(m)),
            None => s,
        }
    }
}

/// The smallest step a run takes, s: the adaptive steps' default floor.
const SMALLEST_STEP: f64 = crate::rapier::pipeline::stepper::StepControl::SMALLEST_STEP;

/// What to do about a step beyond a contact's stability limit, fitting the step mode, in the
/// caller's names (`names`) or the plain API's.
fn step_advice(
    field: &str,
    dt_max: f64,
    parameter: ContactParameter,
    adaptive: Option<bool>,
    names: Option<&ParameterNames>,
) -> String {
    let soft = match names.filter(|n| !n.contact.is_empty()) {
        Some(n) => parameter.describe(&n.contact),
        None => parameter.describe(parameter.api_names()),
    };
    let switch = match names.filter(|n| !n.adaptive.is_empty()) {
        Some(n) => n.adaptive.as_str(),
        None => "StepControl::adaptive",
    };
    match adaptive {
        Some(true) => format!(
            "Adaptive stepping is on and this is already its smallest step: no step it takes \
             resolves this contact. It is too stiff (or too damped) for the bodies' masses: check {soft}."
        ),
        // Below the smallest step any run takes: no step resolves it.
        Some(false) if !(0.8 * dt_max >= SMALLEST_STEP) => format!(
            "No step resolves this contact (the smallest a run takes is {} s): its parameters are \
             out of reach, too stiff (or too damped) for the bodies' masses: check {soft}.",
            sig4(SMALLEST_STEP)
        ),
        Some(false) => format!(
            "Use `{field}` below {} s, or adaptive stepping (`{switch}`), which shrinks the step \
             inside contacts; or soften the contact: {soft}.",
            sig4(0.8 * dt_max)
        ),
        None => format!(
            "Use a smaller `{field}` or adaptive stepping (`{switch}`), or soften the contact: {soft}."
        ),
    }
}

#[cfg(test)]
mod tests;
