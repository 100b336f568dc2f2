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
        let (t, v) = (table.column_index("t_s")?, table.column_index(column)?);
        let (t, v) = if points.is_empty() {
            // Thinned straight from the rows: no copy of a column (a run's rows are
            // megabytes).
            let (at, n) = (rows_of(table), table.rows());
            min_max_thin_by(n, |i| at(i, t), |i| at(i, v), SERIES_BUCKETS)
        } else {
            let mut columns = table.columns(&["t_s", column])?;
            let (v, t) = (columns.pop()?, columns.pop()?);
            let (t, v) = crate::figures::series::merge_points(&t, &v, points);
            min_max_thin(&t, &v, SERIES_BUCKETS)
        };
        Some(Line::rounded(label, group, t, v))
    }

    /// `f` of columns `columns` of `table` per row against its `t_s`, thinned as
    /// [`from_table`](Self::from_table) (`None` when a column is missing).
    pub fn derived(
        label: &str,
        group: &str,
        table: &Table,
        columns: &[&str],
        f: impl Fn(&[f64]) -> f64,
    ) -> Option<Line> {
        let t = table.column_index("t_s")?;
        let index: Vec<usize> = columns
            .iter()
            .map(|c| table.column_index(c))
            .collect::<Option<_>>()?;
        let (at, n) = (rows_of(table), table.rows());
        let mut x = vec![0.0; index.len()];
        let v: Vec<f64> = (0..n)
            .map(|i| {
                for (x, &j) in x.iter_mut().zip(&index) {
                    *x = at(i, j);
                }
                f(&x)
            })
            .collect();
        let (t, v) = min_max_thin_by(n, |i| at(i, t), |i| v[i], SERIES_BUCKETS);
        Some(Line::rounded(label, group, t, v))
    }

    /// The line of thinned `t` and `v`, values to 7 significant digits.
    fn rounded(label: &str, group: &str, t: Vec<f64>, v: Vec<f64>) -> Line {
        Line {
            label: label.into(),
            group: group.into(),
            t,
            v: v.into_iter().map(|x| round_sig(x, 7)).collect(),
        }
    }
}

/// The value of `table` at row `i` and column `j`, read in place.
fn rows_of(table: &Table) -> impl Fn(usize, usize) -> f64 + '_ {
    let width = table.columns.len();
    move |i, j| table.values[i * width + j]
}

/// Keeps, per bucket of `buckets` equal time spans, the samples with the smallest and the
/// largest value (in time order): peaks survive any thinning.
pub fn min_max_thin(t: &[f64], v: &[f64], buckets: usize) -> (Vec<f64>, Vec<f64>) {
    let n = t.len().min(v.len());
    min_max_thin_by(n, |i| t[i], |i| v[i], buckets)
}

/// [`min_max_thin`] of the `n` samples `(t(i), v(i))`, read where they are.
fn min_max_thin_by(
    n: usize,
    t: impl Fn(usize) -> f64,
    v: impl Fn(usize) -> f64,
    buckets: usize,
) -> (Vec<f64>, Vec<f64>) {
    if n <= 2 * buckets || n < 2 {
        return ((0..n).map(&t).collect(), (0..n).map(&v).collect());
    }
    let (t0, t1) = (t(0), t(n - 1));
    let span = (t1 - t0).max(f64::MIN_POSITIVE);
    // `as usize` truncates, and takes what is below 0 (and NaN) to 0: the floor's bucket
    // without its library call.
    let bucket = |x: f64| (((x - t0) / span) * buckets as f64) as usize;
    let mut keep = Vec::with_capacity(2 * buckets + 2);
    let mut i = 0;
    while i < n {
        let b = bucket(t(i));
        let (mut lo, mut hi) = (i, i);
        let (mut v_lo, mut v_hi) = (v(i), v(i));
        let mut j = i;
        while j < n && bucket(t(j)) == b {
            let vj = v(j);
            if vj < v_lo {
                (lo, v_lo) = (j, vj);
            }
            if vj > v_hi {
                (hi, v_hi) = (j, vj);
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
        keep.iter().map(|&k| t(k)).collect(),
        keep.iter().map(|&k| v(k)).collect(),
    )
}

/// `x` rounded to `digits` significant digits (shorter JSON): the double nearest the decimal
/// `format!("{:.*e}", digits - 1, x)` writes.
pub(super) fn round_sig(x: f64, digits: usize) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let digits_i = digits as i32;
    let mut scale = digits_i - 1 - x.abs().log10().floor() as i32;
    // `log10` may put the scale a decade off next to a power of ten: one step back in.
    if let Some(p) = pow10(scale).map(|s| x.abs() * s) {
        if p < pow10(digits_i - 1).unwrap_or(f64::INFINITY) {
            scale += 1;
        } else if p >= pow10(digits_i).unwrap_or(f64::INFINITY) {
            scale -= 1;
        }
    }
    scaled_round(x, scale).unwrap_or_else(|| format!("{:.*e}", digits - 1, x).parse().unwrap_or(x))
}

/// `x` rounded to `decimals` decimal places: the double nearest the decimal
/// `format!("{x:.decimals$}")` writes.
pub(super) fn round_decimals(x: f64, decimals: usize) -> f64 {
    scaled_round(x, decimals as i32)
        .unwrap_or_else(|| format!("{x:.decimals$}").parse().unwrap_or(x))
}

/// `x` rounded to a whole number of `10^-scale`, without the text a format and a parse go
/// through (the replay rounds some 30 numbers per world step): `n = round(x 10^scale)` and
/// `n / 10^scale`, one correctly rounded division of exact numbers, which is the double nearest
/// the decimal `n e-scale` as the parse gives. `None` where that is not sure to be the
/// formatter's rounding: a power of ten not exact in `f64`, a product beyond `2^31` (its own
/// rounding then nears a unit's millionth) or within a millionth of a half (a tie, or a product
/// rounded across one).
fn scaled_round(x: f64, scale: i32) -> Option<f64> {
    let p = x * pow10(scale)?;
    let a = p.abs();
    if !(a < 2f64.powi(31)) {
        return None;
    }
    // Below 2^31 the integer conversion truncates to `floor(a)`, and `a - floor(a)` is exact:
    // `p.round()` without the two library calls the target's floating point would make.
    let whole = f64::from(a as u32);
    let frac = a - whole;
    if (frac - 0.5).abs() < 1e-6 {
        return None;
    }
    let rounded = (whole + if frac > 0.5 { 1.0 } else { 0.0 }).copysign(p);
    Some(rounded / pow10(scale)?)
}

/// `10^k` for the `k` whose power is exact in `f64` (0 to 22).
fn pow10(k: i32) -> Option<f64> {
    const POW10: [f64; 23] = [
        1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
        1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
    ];
    POW10.get(usize::try_from(k).ok()?).copied()
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

    /// The arithmetic rounding gives the formatter's double, bit for bit, over the replay's
    /// scales and next to powers of ten and halves.
    #[test]
    fn rounding_matches_the_formatted_text() {
        let by_text_sig = |x: f64| -> f64 { format!("{:.6e}", x).parse().unwrap() };
        let by_text_dec = |x: f64| -> f64 { format!("{x:.7}").parse().unwrap() };
        let mut s: u64 = 0x2545_F491_4F6C_DD1D;
        for i in 0..400_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let unit = (s >> 11) as f64 / (1u64 << 53) as f64;
            let x = match i % 4 {
                0 => (unit - 0.5) * 10f64.powi((s % 30) as i32 - 20),
                1 => 10f64.powi((s % 30) as i32 - 20) * (1.0 + (unit - 0.5) * 1e-12),
                2 => ((s >> 20) % 100_000) as f64 * 1e-7 + 0.5e-7 + (unit - 0.5) * 1e-15,
                _ => (unit - 0.5) * 4.0,
            };
            assert_eq!(round_sig(x, 7).to_bits(), by_text_sig(x).to_bits(), "{x:e}");
            assert_eq!(
                round_decimals(x, 7).to_bits(),
                by_text_dec(x).to_bits(),
                "{x:e}"
            );
        }
    }

    #[test]
    fn rounding_keeps_seven_digits() {
        assert_eq!(round_sig(0.123456789, 7), 0.1234568);
        assert_eq!(round_sig(-1.0e-5, 7), -1.0e-5);
        assert_eq!(round_sig(0.0, 7), 0.0);
    }
}
