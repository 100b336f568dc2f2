//! [`Divergence`]: what became non-physical, the data of [`Error::Diverged`](super::Error::Diverged).

use super::{Error, sig4};

/// What became non-physical: the data of [`Error::Diverged`]. Its `Display` is the error's
/// reason.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Divergence {
    /// A body left the physical range: disabled by Rapier's quarantine, a state that is not
    /// finite, or faster than the speed guard.
    Body {
        /// The body: its handle's raw parts from the plain API (`(1, 0)`), its name and twin
        /// from the scene runner (`` `stone` of the clearance twin ``).
        body: String,
        /// What joins it, in words (Rapier's impulse joints, clearance joints); empty: nothing
        /// known.
        joined: Vec<String>,
        /// What is out of range in its state, in words: `speed 300 m/s`, a position or a
        /// velocity that is not finite, Rapier's quarantine, a body no longer in the world.
        state: String,
        /// The speed guard, m/s: half Rapier's `max_linear_velocity`.
        guard: f64,
        /// The likely cause, in words.
        cause: String,
    },
    /// The ideal joints' reactions cannot be solved: the state or a body's mass is not finite.
    Reactions {
        /// The twin whose reactions failed, from the scene runner (`clearance`); `None` from the
        /// ECS layer (its ideal hinges).
        twin: Option<String>,
    },
    /// A value bound for an output is not finite.
    NonFinite {
        /// The value, as the output names it: a summary's path, a table's column, a metric.
        name: String,
        /// Where it is, in words: `in the summary`, `in output row 12`.
        place: String,
        /// The value; `None` where the output holds only a null.
        value: Option<f64>,
    },
}

impl std::fmt::Display for Divergence {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Divergence::Body {
                body,
                joined,
                state,
                guard,
                cause,
            } => {
                let joined = if joined.is_empty() {
                    String::new()
                } else {
                    format!(", joined by {}", joined.join(", "))
                };
                write!(
                    f,
                    "body {body}{joined} left the physical range ({state}, the guard being {} \
                     m/s); likely cause: {cause}",
                    sig4(*guard)
                )
            }
            Divergence::Reactions { twin: None } => write!(
                f,
                "the ideal hinges' reactions cannot be solved: the state or a body's mass is not \
                 finite"
            ),
            Divergence::Reactions { twin: Some(twin) } => write!(
                f,
                "the {twin} twin's ideal-joint reactions cannot be solved: its state or a body's \
                 mass is not finite"
            ),
            Divergence::NonFinite { name, place, value } => {
                write!(f, "non-finite `{name}` {place}")?;
                match value {
                    Some(v) => write!(f, " ({v})"),
                    None => Ok(()),
                }
            }
        }
    }
}

impl Error {
    /// An [`Error::Diverged`] at `t` (s) of `what`.
    pub(crate) fn diverged(t: f64, what: Divergence) -> Self {
        Error::Diverged {
            t,
            what: Box::new(what),
        }
    }
}
