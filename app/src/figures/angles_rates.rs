//! The angles-and-rates figure: every movable body's angle and rate against time.

use super::*;

pub(super) fn draw_angles_rates<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    cases: &[CaseSeries],
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let rows = cases[0].bodies.len().max(1);
    let panels = area.split_evenly((rows, 2));
    let (t0, t1) = time_range(cases);
    let own_ideal = distinct_ideals(cases);
    let single_ideal = own_ideal.iter().filter(|&&b| b).count() == 1;
    for (r, body) in cases[0].bodies.iter().enumerate() {
        for (c, is_rate) in [(0, false), (1, true)] {
            let mut curves: Vec<Curve> = Vec::new();
            // The clearance curves first, the ideal ones dashed over them: the two nearly
            // coincide, and a dashed line on top leaves both visible.
            for (i, case) in cases.iter().enumerate() {
                let Some(b) = case.bodies.iter().find(|b| b.name == body.name) else {
                    continue;
                };
                curves.push((
                    case.label.clone(),
                    case_color(i),
                    false,
                    minmax_decimate(&case.t_s, pick(b, is_rate, false), t0, t1, DECIMATE_BINS),
                ));
            }
            for (i, case) in cases.iter().enumerate() {
                let Some(b) = case.bodies.iter().find(|b| b.name == body.name) else {
                    continue;
                };
                if own_ideal[i] {
                    let (label, color) = if single_ideal {
                        ("ideal joint (dashed)".to_string(), BLACK)
                    } else {
                        (format!("ideal, {} (dashed)", case.label), case_color(i))
                    };
                    curves.push((
                        label,
                        color,
                        true,
                        minmax_decimate(&case.t_s, pick(b, is_rate, true), t0, t1, DECIMATE_BINS),
                    ));
                }
            }
            let (what, unit) = if is_rate {
                ("angular rate", "deg/s")
            } else {
                ("angle", "deg")
            };
            let caption = format!("{} {what}", body.name);
            let y_desc = format!("{caption} ({unit})");
            Panel {
                caption: &caption,
                descs: ("time (s)", &y_desc),
                x: (t0, t1),
                y: range_of(curves.iter().flat_map(|c| c.3.iter().map(|p| &p.1))),
                curves: &curves,
                style: PanelStyle {
                    caption: 22,
                    margin: 12,
                    label_areas: (50, 80),
                    mesh: (16, 18),
                    legend: 16,
                },
            }
            .draw(&panels[r * 2 + c])?;
        }
    }
    Ok(())
}

/// A body's series: its angle or rate (`is_rate`), of the clearance or the ideal twin. Borrowed:
/// a series is a run's rows (50,001 numbers for the paper's scene), and the figure is drawn once
/// per format.
fn pick(b: &series::BodySeries, is_rate: bool, ideal: bool) -> &[f64] {
    match (is_rate, ideal) {
        (false, false) => &b.angle_deg,
        (false, true) => &b.angle_ideal_deg,
        (true, false) => &b.rate_deg_s,
        (true, true) => &b.rate_ideal_deg_s,
    }
}
