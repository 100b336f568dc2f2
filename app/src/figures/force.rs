//! The joint-force figure: each case's clearance and ideal joint force against time.

use super::*;

/// A force panel's caption: the joint, after the case's label when there are several cases (a
/// single case is named by the figure's title and legends).
pub(super) fn force_caption(cases: usize, label: &str, joint: &str) -> String {
    if cases > 1 {
        format!("{label}: {joint}")
    } else {
        joint.to_string()
    }
}

/// What the force panels drew of the runs: the rows, thinned, and for the clearance joint
/// each contact's peak from every step.
pub(super) fn force_footnote(cases: &[CaseSeries]) -> String {
    let peaks: usize = cases.iter().map(|c| c.peaks.len()).sum();
    format!(
        "Curves: the output rows, each pixel column's smallest and largest value; the clearance \
         joint's also passes through each contact's peak from every step ({peaks} contact peaks)."
    )
}

/// The top of a force axis over `series`: 5 % above their largest finite value (1 N when none
/// is positive).
pub(super) fn force_top<'a>(series: impl Iterator<Item = &'a [f64]>) -> f64 {
    let m = series
        .flatten()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    if m > 0.0 { 1.05 * m } else { 1.0 }
}

pub(super) fn draw_force<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    cases: &[CaseSeries],
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let (w, h) = area.dim_in_pixel();
    let (area, foot) = area.split_vertically(h.saturating_sub(26));
    foot.draw_text(
        &force_footnote(cases),
        &(FAMILY, 14).into_font().color(&RGBColor(80, 80, 80)),
        (10.min(w as i32), 4),
    )?;
    let panels = area.split_evenly((cases.len(), 2));
    let (t0, t1) = time_range(cases);
    // The clearance joint's curve passes through each contact's peak from every step (the
    // rows alone, one per output interval, miss most of an impact's top).
    let clear: Vec<(Vec<f64>, Vec<f64>)> = cases.iter().map(|c| c.force_with_peaks()).collect();
    let ideal_top = force_top(cases.iter().map(|c| &c.force_ideal_n[..]));
    let clear_top = force_top(clear.iter().map(|c| &c.1[..]));
    for (i, case) in cases.iter().enumerate() {
        let (clear_t, clear_f) = &clear[i];
        for (col, (name, times, series, y1, color)) in [
            (
                "ideal joint",
                &case.t_s,
                &case.force_ideal_n,
                ideal_top,
                BLACK,
            ),
            (
                "clearance joint",
                clear_t,
                clear_f,
                clear_top,
                case_color(i),
            ),
        ]
        .into_iter()
        .enumerate()
        {
            let points = minmax_decimate(times, series, t0, t1, DECIMATE_BINS);
            let peak = series.iter().copied().fold(0.0, f64::max);
            let curves = [(format!("{name}, peak {peak:.4} N"), color, false, points)];
            Panel {
                caption: &force_caption(cases.len(), &case.label, name),
                descs: ("time (s)", "joint force (N)"),
                x: (t0, t1),
                y: (0.0, y1),
                curves: &curves,
                style: PanelStyle {
                    caption: 20,
                    margin: 10,
                    label_areas: (45, 80),
                    mesh: (15, 17),
                    legend: 15,
                },
            }
            .draw(&panels[i * 2 + col])?;
        }
    }
    Ok(())
}
