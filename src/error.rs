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
    /// integration would blow up. Raised before the state is destroyed, never silently.
    #[error(
        "`{field}` = {dt:e} s is too large for the contact stiffness of hinge `{hinge}`{at} \
         (penetration {penetration_um:.3} um, natural frequency {omega:.4e} rad/s, damping ratio {zeta:.3}): \
         the explicit step is stable only below {dt_max:e} s; use a smaller step or adaptive stepping",
        at = t.map_or(String::new(), |t| format!(" at t = {t:.6} s"))
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
            format!("must be finite (got {value})"),
        ))
    } else if value <= 0.0 {
        Err(Error::invalid(field, format!("must be > 0 (got {value})")))
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
            format!("must be finite (got {value})"),
        ))
    } else if value < 0.0 {
        Err(Error::invalid(field, format!("must be >= 0 (got {value})")))
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
            format!("must be finite (got {value})"),
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
            format!("must be in ({lo}, {hi}] (got {value})"),
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

/// `x` with 4 significant digits, in plain or scientific notation as fits (for messages).
pub fn sig4(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let a = x.abs();
    if (1e-3..1e5).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
        let s = format!("{x:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        format!("{x:.3e}")
    }
}
