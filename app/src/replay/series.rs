//! The page's plotted series: a table's columns thinned to time buckets, peaks kept.

use super::SERIES_BUCKETS;
use clearance_joint::table::Table;
use serde::Serialize;

/// One plotted quantity: a panel with a line per twin.
#[derive(Clone, Debug, Serialize)]
pub struct Series {
    /// Panel title (with unit).
    pub title: String,
    /// Its lines.
    pub lines: Vec<Line>,
}

/// One line of a [`Series`].
#[derive(Clone, Debug, Serialize)]
pub struct Line {
    /// Legend.
    pub label: String,
    /// Colour group (`ideal`, `clearance`, ...).
    pub group: String,
    /// Times, s.
    pub t: Vec<f64>,
    /// Values.
    pub v: Vec<f64>,
}

impl Line {
    /// Column `column` of `table` against its `t_s`, thinned to [`SERIES_BUCKETS`] buckets of
    /// time keeping each bucket's smallest and largest value (in time order).
    pub fn from_table(label: &str, group: &str, table: &Table, column: &str) -> Option<Line> {
        Self::with_points(label, group, table, column, &[])
    }

    /// As [`from_table`](Self::from_table), with `points` (`(t, v)` in time order: each
    /// contact's peak from every step) merged into the rows before thinning, so the line
    /// passes through them.
    pub fn with_points(
        label: &str,
        group: &str,
        table: &Table,
        column: &str,
        points: &[(f64, f64)],
    ) -> Option<Line> {
        let (t, v) = (table.column("t_s")?, table.column(column)?);
        let (t, v) = crate::figures::series::merge_points(&t, &v, points);
        let (t, v) = min_max_thin(&t, &v, SERIES_BUCKETS);
        Some(Line {
            label: label.into(),
            group: group.into(),
            t,
            v: v.into_iter().map(|x| round_sig(x, 7)).collect(),
        })
    }
}

impl Line {
    /// `f` of columns `columns` of `table` per row against its `t_s`, thinned as
    /// [`from_table`](Self::from_table) (`None` when a column is missing).
    pub fn derived(
        label: &str,
        group: &str,
        table: &Table,
        columns: &[&str],
        f: impl Fn(&[f64]) -> f64,
    ) -> Option<Line> {
        let t = table.column("t_s")?;
        let cols = columns
            .iter()
            .map(|c| table.column(c))
            .collect::<Option<Vec<_>>>()?;
        let v: Vec<f64> = (0..t.len())
            .map(|i| f(&cols.iter().map(|c| c[i]).collect::<Vec<_>>()))
            .collect();
        let (t, v) = min_max_thin(&t, &v, SERIES_BUCKETS);
        Some(Line {
            label: label.into(),
            group: group.into(),
            t,
            v: v.into_iter().map(|x| round_sig(x, 7)).collect(),
        })
    }
}

/// Keeps, per bucket of `buckets` equal time spans, the samples with the smallest and the
/// largest value (in time order): peaks survive any thinning.
pub fn min_max_thin(t: &[f64], v: &[f64], buckets: usize) -> (Vec<f64>, Vec<f64>) {
    let n = t.len().min(v.len());
    if n <= 2 * buckets || n < 2 {
        return (t[..n].to_vec(), v[..n].to_vec());
    }
    let (t0, t1) = (t[0], t[n - 1]);
    let span = (t1 - t0).max(f64::MIN_POSITIVE);
    let mut keep = Vec::with_capacity(2 * buckets + 2);
    let mut i = 0;
    while i < n {
        let b = (((t[i] - t0) / span) * buckets as f64).floor() as usize;
        let (mut lo, mut hi) = (i, i);
        let mut j = i;
        while j < n && ((((t[j] - t0) / span) * buckets as f64).floor() as usize) == b {
            if v[j] < v[lo] {
                lo = j;
            }
            if v[j] > v[hi] {
                hi = j;
            }
            j += 1;
        }
        keep.push(lo.min(hi));
        if hi != lo {
            keep.push(lo.max(hi));
        }
        i = j;
    }
    (
        keep.iter().map(|&k| t[k]).collect(),
        keep.iter().map(|&k| v[k]).collect(),
    )
}

/// `x` rounded to `digits` significant digits (shorter JSON).
pub(super) fn round_sig(x: f64, digits: usize) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    format!("{:.*e}", digits - 1, x).parse().unwrap_or(x)
}

/// `x` rounded to `decimals` decimal places.
pub(super) fn round_decimals(x: f64, decimals: usize) -> f64 {
    format!("{x:.decimals$}").parse().unwrap_or(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn min_max_thinning_keeps_the_peak() {
        let t: Vec<f64> = (0..10_000).map(|i| i as f64 * 1e-3).collect();
        let mut v = vec![0.0; 10_000];
        v[4321] = 7.0;
        v[8000] = -3.0;
        let (tt, vv) = min_max_thin(&t, &v, 100);
        assert!(tt.len() <= 200, "{}", tt.len());
        assert!(vv.contains(&7.0) && vv.contains(&-3.0));
        assert!(tt.windows(2).all(|w| w[0] < w[1]));
    }

    #[test]
    fn rounding_keeps_seven_digits() {
        assert_eq!(round_sig(0.123456789, 7), 0.1234568);
        assert_eq!(round_sig(-1.0e-5, 7), -1.0e-5);
        assert_eq!(round_sig(0.0, 7), 0.0);
    }
}
