//! The library's errors phrased for the command line. The library's messages name the scene's
//! fields (`run.dt_s`, `hinges[NAME].clearance.contact.eta_s`), never this program's options: it
//! carries the numbers, and this module adds what to type (`--dt`, `--set run.step=Adaptive`,
//! `--strict`, `--out`, `--max-memory`), as ripgrep's binary phrases its libraries' errors.

use clearance_joint::error::{Error, sig4};

/// `e` as the command line shows it: the library's message, then the options that act on it.
pub fn describe(e: &Error) -> String {
    let message = e.to_string();
    match e {
        Error::StepTooLarge { .. } => match e.suggested_step() {
            Some(dt) => format!(
                "{message} On the command line: `--dt {}` (or smaller), or `--set run.step=Adaptive`.",
                sig4(dt)
            ),
            None => message,
        },
        Error::Guard { .. } => format!(
            "{message} (`--strict` made these guard violations an error; without it the run is \
             written, its summary listing them)"
        ),
        _ => message,
    }
}
