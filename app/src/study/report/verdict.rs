//! The verdict machinery: how far a study's numbers agree with a statement, the criteria that
//! decide it (stated in every report), and the parts a finding is assembled from.

use crate::study::case::StudyCase;
use crate::study::metrics::Trend;

/// Relative tolerance below which two values count as equal in trends and comparisons.
pub const EQUAL_TOL: f64 = 0.005;
/// "Angles barely change": largest angle deviation below this fraction of the ideal deployment.
pub const ANGLE_SLIGHT: f64 = 0.02;
/// "Rates visibly change": largest rate deviation above this fraction of the mean ideal rate.
pub const RATE_VISIBLE: f64 = 0.05;
/// "Force strongly changes": clearance peak force above this multiple of the ideal peak.
pub const FORCE_STRONG: f64 = 10.0;

/// How far our numbers agree with a conclusion of the paper.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Every part of the conclusion appears in our numbers.
    Shown,
    /// Some parts appear, others do not.
    Partly,
    /// No part appears.
    NotShown,
    /// The study does not vary the parameter the conclusion is about.
    NotTested,
    /// The runs hold too few onsets to judge (a run too short): see [`MIN_IMPACTS`].
    TooLittleData,
}

/// [Onsets](clearance_joint::rapier::observers::metrics#onsets-impacts-and-chatter) (contacts, chatter
/// included) every case needs before a verdict is given: the conclusions are about impacts,
/// impact forces and the rattle they cause, and a run without contacts shows none.
pub const MIN_IMPACTS: u64 = 10;

impl Verdict {
    /// Short text for reports.
    pub fn text(self) -> &'static str {
        match self {
            Verdict::Shown => "reproduced",
            Verdict::Partly => "partly reproduced",
            Verdict::NotShown => "not reproduced",
            Verdict::NotTested => "not tested here",
            Verdict::TooLittleData => "too little data to judge",
        }
    }

    pub(crate) fn from_parts(parts: &[bool]) -> Verdict {
        if parts.iter().all(|&p| p) {
            Verdict::Shown
        } else if parts.iter().any(|&p| p) {
            Verdict::Partly
        } else {
            Verdict::NotShown
        }
    }
}

/// One of the paper's conclusions and what our numbers show.
#[derive(Clone, Debug, PartialEq)]
pub struct Conclusion {
    /// Its number in MODEL.md §5.
    pub number: u8,
    /// The paper's statement.
    pub paper: &'static str,
    /// Our verdict.
    pub verdict: Verdict,
    /// What our numbers show, with the numbers.
    pub finding: String,
}

pub(crate) fn trend_of<F: Fn(&StudyCase) -> f64>(cases: &[StudyCase], f: F) -> Trend {
    let v: Vec<f64> = cases.iter().map(f).collect();
    Trend::of(&v, EQUAL_TOL)
}

/// `a < b` by more than the tolerance.
pub(crate) fn clearly_less(a: f64, b: f64) -> bool {
    b - a > EQUAL_TOL * a.abs().max(b.abs())
}

/// "lower", "higher" or "about equal" for `a` against `b`.
pub(crate) fn compare(a: f64, b: f64) -> &'static str {
    if clearly_less(a, b) {
        "lower"
    } else if clearly_less(b, a) {
        "higher"
    } else {
        "about equal"
    }
}

/// A part of a conclusion: `**label: yes.** text` or `**label: no.** text`.
pub(crate) fn part(label: &str, ok: bool, text: String) -> String {
    format!("**{label}: {}.** {text}", if ok { "yes" } else { "no" })
}
