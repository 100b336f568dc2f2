//! What the figures read of their cases: the time span, and which ideal curves to draw.

use super::*;

pub(super) fn time_range(cases: &[CaseSeries]) -> (f64, f64) {
    let t1 = cases
        .iter()
        .filter_map(|c| c.t_s.last().copied())
        .fold(0.0, f64::max);
    (0.0, if t1 > 0.0 { t1 } else { 1.0 })
}

/// Which cases draw their own ideal curve: a case whose ideal series equals an earlier case's
/// (e.g. clearance and friction do not change the ideal twin) does not draw it again.
pub(super) fn distinct_ideals(cases: &[CaseSeries]) -> Vec<bool> {
    (0..cases.len())
        .map(|i| {
            !cases[..i].iter().any(|c| {
                c.t_s == cases[i].t_s
                    && c.force_ideal_n == cases[i].force_ideal_n
                    && c.bodies.iter().zip(&cases[i].bodies).all(|(a, b)| {
                        a.angle_ideal_deg == b.angle_ideal_deg
                            && a.rate_ideal_deg_s == b.rate_ideal_deg_s
                    })
            })
        })
        .collect()
}
