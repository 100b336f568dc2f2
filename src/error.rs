//! Errors as values: every failure names the field or file it concerns and says why.

use std::path::PathBuf;

/// Everything that can go wrong in this crate. Nothing here panics on bad input.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A parameter is out of its domain (`field` is the path of the parameter, e.g.
    /// `hinges[hinge].clearance.clearance_mm`).
    #[error("invalid `{field}`: {reason}")]
    Invalid {
        /// Path of the offending parameter.
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
    /// message names the contact parameter that makes the contact this stiff and gives advice
    /// fitting the step mode (when the caller knows it, see [`Error::with_step_mode`]).
    #[error(
        "`{field}` = {} s is too large for the contact of hinge `{hinge}`{at}: the explicit step is \
         stable only below {} s there (penetration {} um, natural frequency {} rad/s, damping ratio {}). {}",
        sig4(*dt), sig4(*dt_max), sig4(*penetration_um), sig4(*omega), sig4(*zeta),
        step_advice(field, hinge, *law, *dt_max, *zeta, *adaptive),
        at = t.map_or(String::new(), |t| format!(" at t = {} s", sig4(t)))
    )]
    StepTooLarge {
        /// The parameter that sets the step (`run.dt_s`).
        field: String,
        /// The hinge whose contact limits the step.
        hinge: String,
        /// The step in use.
        dt: f64,
        /// The largest stable step for this contact.
        dt_max: f64,
        /// Simulated time when detected, when the caller knows it.
        t: Option<f64>,
        /// Penetration at detection, micrometres.
        penetration_um: f64,
        /// Linearised natural frequency of the contact.
        omega: f64,
        /// Linearised damping ratio of the contact.
        zeta: f64,
        /// The contact law: it tells which parameter sets the stiffness and the damping.
        law: crate::model::laws::LawKind,
        /// Whether the step was adaptive (`Some(true)`), fixed (`Some(false)`) or unknown to the
        /// code that raised the error (`None`); see [`Error::with_step_mode`].
        adaptive: Option<bool>,
    },
    /// The simulation state became non-physical (non-finite, or energy/momentum destroyed).
    #[error("simulation diverged at t = {t:.6} s: {reason}")]
    Diverged {
        /// Simulated time when detected.
        t: f64,
        /// What was detected.
        reason: String,
    },
    /// The step control could not make progress: every step it tried was rejected, or it stayed
    /// at its floor without advancing the simulated time.
    #[error("the step control stalled at t = {t:.6} s: {reason}")]
    Stalled {
        /// Simulated time when detected.
        t: f64,
        /// What was seen, with the likely cause.
        reason: String,
    },
    /// A run-time guard was violated and the step control is strict (`--strict`).
    #[error("guard violated (strict) by t = {t:.6} s: {violations}")]
    Guard {
        /// Simulated time when detected.
        t: f64,
        /// The violations in words.
        violations: String,
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
        if let Error::StepTooLarge { adaptive, .. } = &mut self {
            *adaptive = Some(is_adaptive);
        }
        self
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

/// The contact parameter that sets a contact's stiffness (or, when it is over-damped, its
/// damping), as a scene path under `hinges[<hinge>].clearance`.
fn stiff_field(hinge: &str, law: crate::model::laws::LawKind, zeta: f64) -> String {
    use crate::model::laws::LawKind as L;
    let p = format!("hinges[{hinge}].clearance");
    let damped = zeta > 1.0;
    match law {
        L::ImprovedLiu if damped => format!("`{p}.contact.eta_s` (or `d_max_n_s_per_m`)"),
        L::KelvinVoigt if damped => format!("`{p}.contact.damping`"),
        L::HuntCrossley | L::LankaraniNikravesh | L::FloresEtAl | L::GonthierEtAl if damped => {
            format!("`{p}.contact.restitution` (a lower restitution damps harder)")
        }
        L::ImprovedLiu | L::LiuEtAl => format!(
            "`{p}.bearing_material.youngs_modulus_pa`, `{p}.journal_material.youngs_modulus_pa` and \
             `{p}.width_mm` (the law's stiffness is (pi/2) E* L)"
        ),
        _ => format!(
            "`{p}.contact.stiffness` (or the materials' `youngs_modulus_pa` when the stiffness is left to the geometry)"
        ),
    }
}

/// The smallest step a run takes, s: the adaptive steps' default floor (`min_dt` of
/// [`StepControl`](crate::rapier::stepper::StepControl)); a scene's fixed step is at least
/// 1e-9 s.
const SMALLEST_STEP: f64 = 1e-10;

/// What to do about a step beyond a contact's stability limit, fitting the step mode.
fn step_advice(
    field: &str,
    hinge: &str,
    law: crate::model::laws::LawKind,
    dt_max: f64,
    zeta: f64,
    adaptive: Option<bool>,
) -> String {
    let soft = stiff_field(hinge, law, zeta);
    match adaptive {
        Some(true) => format!(
            "Adaptive stepping is on and this is already its smallest step: no step the runner takes \
             resolves this contact. It is too stiff (or too damped) for the bodies' masses: check {soft}."
        ),
        // Below the smallest step any run takes: no step resolves it.
        Some(false) if !(0.8 * dt_max >= SMALLEST_STEP) => format!(
            "No step resolves this contact (the smallest a run takes is {} s): its parameters are \
             out of reach, too stiff (or too damped) for the bodies' masses: check {soft}.",
            sig4(SMALLEST_STEP)
        ),
        Some(false) => format!(
            "Use `{field}` below {} s (`--dt`), or adaptive stepping (`--set run.step=Adaptive`), which \
             shrinks the step inside contacts; or soften the contact: {soft}.",
            sig4(0.8 * dt_max)
        ),
        None => {
            format!("Use a smaller `{field}` or adaptive stepping, or soften the contact: {soft}.")
        }
    }
}
