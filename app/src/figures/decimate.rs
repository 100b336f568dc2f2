//! Long series thinned for drawing: time series keep every pixel column's extremes,
//! trajectories drop points closer than a fraction of a pixel.

pub(super) const DECIMATE_BINS: usize = 900;

/// Keeps, for each of `bins` equal time columns over `[t0, t1]`, the minimum and the maximum of
/// `y` (in time order), so a line through the result has the envelope of the full series and
/// every peak. Points outside `[t0, t1]` are dropped. At most `2 * bins` points.
pub fn minmax_decimate(t: &[f64], y: &[f64], t0: f64, t1: f64, bins: usize) -> Vec<(f64, f64)> {
    let n = t.len().min(y.len());
    if n <= 2 * bins || bins == 0 || t1 <= t0 {
        return (0..n)
            .filter(|&i| t[i] >= t0 && t[i] <= t1)
            .map(|i| (t[i], y[i]))
            .collect();
    }
    let mut out = Vec::with_capacity(2 * bins);
    let mut current: Option<(usize, usize, usize)> = None; // (bin, index of min, index of max)
    let flush = |out: &mut Vec<(f64, f64)>, c: Option<(usize, usize, usize)>| {
        if let Some((_, lo, hi)) = c {
            let (a, b) = if lo <= hi { (lo, hi) } else { (hi, lo) };
            out.push((t[a], y[a]));
            if b != a {
                out.push((t[b], y[b]));
            }
        }
    };
    for i in 0..n {
        if t[i] < t0 || t[i] > t1 || !y[i].is_finite() {
            continue;
        }
        let bin = (((t[i] - t0) / (t1 - t0) * bins as f64) as usize).min(bins - 1);
        match &mut current {
            Some((b, lo, hi)) if *b == bin => {
                if y[i] < y[*lo] {
                    *lo = i;
                }
                if y[i] > y[*hi] {
                    *hi = i;
                }
            }
            _ => {
                flush(&mut out, current);
                current = Some((bin, i, i));
            }
        }
    }
    flush(&mut out, current);
    out
}

/// Keeps the first point, then every point farther than `min_step` from the last kept one, and
/// the last point: a path drawn through the result differs from the full path by less than
/// `min_step`.
pub fn decimate_path(u: &[f64], v: &[f64], min_step: f64) -> Vec<(f64, f64)> {
    let n = u.len().min(v.len());
    let mut out: Vec<(f64, f64)> = Vec::new();
    for i in 0..n {
        let p = (u[i], v[i]);
        match out.last() {
            Some(&(a, b)) if (p.0 - a).hypot(p.1 - b) < min_step && i + 1 < n => {}
            _ => out.push(p),
        }
    }
    out
}
