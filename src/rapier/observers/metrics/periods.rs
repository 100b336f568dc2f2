//! The per-turn statistics of a contact list (a crank turn of a driven mechanism), as the
//! scene's result set writes them (`<twin>_<joint>_turns.csv`).

use super::Impact;
use crate::error::{Error, Result, sig4};
use crate::table::Table;
use serde::Serialize;

/// One period (a crank turn) of a driven mechanism's clearance joint.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub(crate) struct PeriodStats {
    /// Start of the period, s.
    pub start_s: f64,
    /// Its length, s (the last period may be cut short by the end of the run).
    pub length_s: f64,
    /// [Onsets](crate::rapier::observers::metrics#onsets-impacts-and-chatter) in it: contacts that began in it, chatter
    /// included.
    pub onsets: u64,
    /// [Impacts](crate::rapier::observers::metrics#onsets-impacts-and-chatter) in it: its onsets after a
    /// separation. JSON key `separated_impacts`.
    #[serde(rename = "separated_impacts")]
    pub impacts: u64,
    /// Largest peak force of the contacts that began in it, N (0 without one).
    pub peak_force_n: f64,
    /// Time in contact within it, s (contacts are split at the period's bounds).
    pub contact_s: f64,
}

/// Per-period statistics of a contact list over `[0, end)` in periods of `period` (s): onsets,
/// impacts, peak force and time in contact per crank turn. A contact's duration is the contiguous span
/// from its onset, so the time in contact is split exactly at the bounds; its peak counts in the
/// period of its onset. Empty for a period or end that is not positive (or NaN); an error when
/// `end / period` is more than [`MAX_PERIODS`] (or infinite): the table would not fit in
/// memory.
pub(crate) fn per_period(impacts: &[Impact], period: f64, end: f64) -> Result<Vec<PeriodStats>> {
    if !(period > 0.0) || !(end > 0.0) {
        return Ok(Vec::new());
    }
    let count = (end / period).ceil().max(1.0);
    if !(count <= MAX_PERIODS as f64) {
        return Err(Error::invalid(
            "period",
            format!(
                "{} s over {} s is {} periods, more than {MAX_PERIODS}",
                sig4(period),
                sig4(end),
                sig4(count)
            ),
        ));
    }
    let n = count as usize;
    let mut out: Vec<PeriodStats> = (0..n)
        .map(|k| {
            let start = k as f64 * period;
            PeriodStats {
                start_s: start,
                length_s: ((k + 1) as f64 * period).min(end) - start,
                ..Default::default()
            }
        })
        .collect();
    for i in impacts {
        let k = ((i.onset_t_s / period) as usize).min(n - 1);
        let p = &mut out[k];
        p.onsets += 1;
        p.impacts += u64::from(i.separated);
        p.peak_force_n = p.peak_force_n.max(i.peak_force_n);
        let (a, b) = (i.onset_t_s, i.onset_t_s + i.duration_s);
        for p in out.iter_mut().skip(k) {
            let (lo, hi) = (p.start_s, p.start_s + p.length_s);
            if lo >= b {
                break;
            }
            p.contact_s += (b.min(hi) - a.max(lo)).max(0.0);
        }
    }
    Ok(out)
}

/// Most periods [`per_period`] tabulates (a table of about 50 MB).
pub(crate) const MAX_PERIODS: usize = 1_000_000;

/// The per-period statistics as a table: `turn, start_s, onsets, separated_impacts,
/// peak_force_n, contact_fraction` (`separated_impacts`: the [impacts](crate::rapier::observers::metrics#onsets-impacts-and-chatter)).
pub(crate) fn per_period_table(periods: &[PeriodStats]) -> Table {
    let mut t = Table::new(
        [
            "turn",
            "start_s",
            "onsets",
            "separated_impacts",
            "peak_force_n",
            "contact_fraction",
        ]
        .map(String::from)
        .to_vec(),
    );
    for (k, p) in periods.iter().enumerate() {
        t.values.extend_from_slice(&[
            k as f64,
            p.start_s,
            p.onsets as f64,
            p.impacts as f64,
            p.peak_force_n,
            if p.length_s > 0.0 {
                p.contact_s / p.length_s
            } else {
                0.0
            },
        ]);
    }
    t
}
