//! Contact onsets per window of simulated time: when the impacts of each case happen.

use super::tables::num;
use crate::figures::series::CaseSeries;
use crate::study::metrics::{count_in_windows, onset_times};
use std::fmt::Write as _;

/// Contact onsets of every case per window of simulated time, counted from the output rows
/// (rows every step count every impact; sparser rows can merge impacts shorter than a row).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Timeline {
    /// Window length, s.
    pub window_s: f64,
    /// Per case (in case order), onsets per window.
    pub counts: Vec<Vec<u64>>,
}

impl Timeline {
    /// Windows of 1 s when the run lasts at least 2 s, else a fifth of the run.
    pub fn of(series: &[CaseSeries]) -> Timeline {
        let cases: Vec<(Vec<f64>, f64)> = series
            .iter()
            .map(|c| {
                (
                    onset_times(&c.t_s, &c.contact),
                    c.t_s.last().copied().unwrap_or(0.0),
                )
            })
            .collect();
        Self::of_onsets(&cases)
    }

    /// The same from each case's onset times and last row time (cases read in one pass, see
    /// [`crate::figures::series::CaseSeries::stream`]).
    pub fn of_onsets(cases: &[(Vec<f64>, f64)]) -> Timeline {
        let end = cases.iter().map(|c| c.1).fold(0.0, f64::max);
        let window = if end >= 2.0 {
            1.0
        } else {
            (end / 5.0).max(1e-9)
        };
        let n = ((end / window) - 1e-9).ceil().max(1.0) as usize;
        Timeline {
            window_s: window,
            counts: cases
                .iter()
                .map(|(onsets, _)| count_in_windows(onsets, window, n))
                .collect(),
        }
    }

    /// Onsets of case `i` up to the end of window `k` (inclusive).
    pub fn cumulative(&self, i: usize, k: usize) -> u64 {
        self.counts.get(i).map_or(0, |c| c.iter().take(k + 1).sum())
    }

    /// Number of windows.
    pub fn windows(&self) -> usize {
        self.counts.first().map_or(0, Vec::len)
    }

    /// Markdown table: one row per case, one column per window, and the total.
    pub fn table(&self, labels: &[String]) -> String {
        let mut s = String::from("| case |");
        let mut rule = String::from("|---|");
        for k in 0..self.windows() {
            let _ = write!(
                s,
                " {}-{} s |",
                num(k as f64 * self.window_s),
                num((k + 1) as f64 * self.window_s)
            );
            rule.push_str("---|");
        }
        let _ = writeln!(s, " total |\n{rule}---|");
        for (label, counts) in labels.iter().zip(&self.counts) {
            let _ = write!(s, "| {label} |");
            for c in counts {
                let _ = write!(s, " {c} |");
            }
            let _ = writeln!(s, " {} |", counts.iter().sum::<u64>());
        }
        s
    }
}
