//! The trajectory figure: the journal's centre inside its clearance circle, to scale.

use super::*;

/// The trajectory legend of case `i`: one row under the plot when it fits the panel's
/// `width`, else a column.
pub(super) fn trajectory_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    i: usize,
) -> Legend {
    let entries = vec![
        Entry {
            label: "clearance circle |e| = c".into(),
            mark: Mark::Line(BLACK),
        },
        Entry {
            label: "journal centre".into(),
            mark: Mark::Line(case_color(i)),
        },
        Entry {
            label: "start".into(),
            mark: Mark::Dot(BLACK),
        },
    ];
    let mut legend = Legend {
        entries,
        font_size: 14,
        row: true,
    };
    legend.row = legend.size(area).0 + 2 * INSET <= area.dim_in_pixel().0 as i32;
    legend
}

/// The circle `|e| = c`, as a closed polyline.
pub(super) fn circle_points(c: f64) -> Vec<(f64, f64)> {
    (0..=720)
        .map(|k| {
            let a = k as f64 * std::f64::consts::PI / 360.0;
            (c * a.cos(), c * a.sin())
        })
        .collect()
}

pub(super) fn draw_trajectory<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    cases: &[CaseSeries],
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let panels = area.split_evenly((1, cases.len()));
    for (i, case) in cases.iter().enumerate() {
        let c = if case.clearance_mm > 0.0 {
            case.clearance_mm
        } else {
            1.0
        };
        let lim = 1.15 * c;
        // The legend goes in a strip under the plot: the orbit fills the circle, so no
        // corner of the plot is ever free of data.
        let legend = trajectory_legend(&panels[i], i);
        let (lw, lh) = legend.size(&panels[i]);
        let (w, h) = panels[i].dim_in_pixel();
        let (upper, strip) = panels[i].split_vertically(h as i32 - lh - 2 * INSET);
        // A square plotting area keeps the circle round: same span on both axes.
        let h = upper.dim_in_pixel().1;
        let side = w.min(h.saturating_sub(40));
        let pad_x = (w - side) / 2;
        let panel = upper.margin(h - side, 0, pad_x, pad_x);
        let mut chart = ChartBuilder::on(&panel)
            .caption(
                if case.label.contains("c = ") {
                    case.label.clone()
                } else {
                    format!("{} (c = {:.2} mm)", case.label, case.clearance_mm)
                },
                (FAMILY, 20),
            )
            .margin(10)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d(-lim..lim, -lim..lim)?;
        draw_mesh(
            &mut chart,
            ("eccentricity u (mm)", "eccentricity v (mm)"),
            (15, 17),
        )?;
        chart.draw_series(LineSeries::new(circle_points(c), BLACK.stroke_width(2)))?;
        // A pixel is about 2 lim / 400 here; keep steps of a quarter pixel.
        let path = decimate_path(&case.ecc_u_mm, &case.ecc_v_mm, lim / 800.0);
        chart.draw_series(LineSeries::new(path, case_color(i).stroke_width(1)))?;
        if let (Some(&u), Some(&v)) = (case.ecc_u_mm.first(), case.ecc_v_mm.first()) {
            chart.draw_series(std::iter::once(Circle::new((u, v), 4, BLACK.filled())))?;
        }
        legend.draw(&strip, ((w as i32 - lw) / 2, INSET))?;
    }
    Ok(())
}
