//! The library's errors phrased for the command line. The library's messages name the scene's
//! fields (`run.dt_s`, `hinges[NAME].clearance.contact.eta_s`), never this program's options: it
//! carries the numbers, and this module adds what to type (`--dt`, `--set run.step=Adaptive`,
//! `--strict`, `--out`, `--max-memory`), as ripgrep's binary phrases its libraries' errors.

use crate::process::memory::MemoryEstimate;
use clearance_joint::error::{Error, sig4};
use clearance_joint::scene::Scene;

/// `e` as the command line shows it: the library's message, then the options that act on it.
pub fn describe(e: &Error) -> String {
    let message = e.to_string();
    match e {
        Error::StepTooLarge(_) => match e.suggested_step() {
            Some(dt) => format!(
                "{message} On the command line: `--dt {}` (or smaller), or `--set run.step=Adaptive`.",
                sig4(dt)
            ),
            None => message,
        },
        // The library's result folder is this program's `--out`.
        Error::OutputFolder { reason, .. } => {
            format!("invalid `--out`: {reason}")
        }
        Error::Guard { .. } => format!(
            "{message} (`--strict` made these guard violations an error; without it the run is \
             written, its summary listing them)"
        ),
        Error::NotConverged { .. } => format!(
            "{message} (`--strict` made the convergence check an error; the run is written, \
             `convergence.json` listing every metric; a smaller `--set run.tolerance=...` or \
             `--dt` is what converges them)"
        ),
        _ => message,
    }
}

/// A memory refusal of [`MemoryEstimate::check`] with the options that act on it: the output
/// interval that fits (`--output-interval`), the budget (`--max-memory`) and the runs in
/// parallel (`--jobs`). Other errors pass through.
pub fn memory_options(
    e: Error,
    estimate: &MemoryEstimate,
    scene: &Scene,
    concurrent: u64,
    budget: u64,
) -> Error {
    let Error::Invalid { field, reason } = e else {
        return e;
    };
    let parallel = if concurrent > 1 {
        " (`--jobs` runs them in parallel)"
    } else {
        ""
    };
    let options = match estimate.fitting_interval(scene, concurrent, budget) {
        Some(interval) => format!(
            "`--output-interval {}` or larger (or a shorter `--end`; `--max-memory` sets the \
             budget){parallel}",
            sig4(interval)
        ),
        None if concurrent > 1 => "raise `--max-memory` or lower `--jobs`".into(),
        None => "raise `--max-memory`".into(),
    };
    // The replay's share does not shrink with the rows (its frames are capped): say how to
    // drop it first.
    let options = if estimate.replay_bytes > 0 {
        format!(
            "`--no-replay` drops the replay (`replay.html`, about {}), or {options}",
            crate::process::memory::bytes_text(estimate.replay_bytes)
        )
    } else {
        options
    };
    Error::Invalid {
        field,
        reason: format!("{reason}. On the command line: {options}"),
    }
}

/// An error about a value the command line gave in `option` (`--max-memory`), named by it.
pub fn from_option(e: Error, option: &str) -> Error {
    match e {
        Error::Invalid { reason, .. } => Error::Invalid {
            field: option.into(),
            reason,
        },
        other => other,
    }
}
