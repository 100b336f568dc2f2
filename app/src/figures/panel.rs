//! One panel of curves: axes, ticks, curves and a legend that crosses none of them.

use super::*;

/// A chart of `f64` against `f64`.
pub(super) type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Draws `chart`'s axes, grid and tick labels (labels of `sizes.0`, descriptions of `sizes.1`),
/// every axis's labels with one number of decimals ([`TickFormat`]).
pub(super) fn draw_mesh<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    (x_desc, y_desc): (&str, &str),
    sizes: (u32, u32),
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let (x, y) = (chart.x_range(), chart.y_range());
    let xf = TickFormat::for_axis(x.start, x.end, TICKS);
    let yf = TickFormat::for_axis(y.start, y.end, TICKS);
    chart
        .configure_mesh()
        .x_labels(TICKS)
        .y_labels(TICKS)
        .x_label_formatter(&|v| xf.format(*v))
        .y_label_formatter(&|v| yf.format(*v))
        .x_desc(x_desc)
        .y_desc(y_desc)
        .label_style((FAMILY, sizes.0))
        .axis_desc_style((FAMILY, sizes.1))
        .light_line_style(RGBColor(246, 246, 246))
        .draw()?;
    Ok(())
}

/// `[lo, hi]` of the values with 5 % padding (a unit span around a constant).
pub(super) fn range_of<'a>(values: impl IntoIterator<Item = &'a f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &v in values {
        if v.is_finite() {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if hi - lo < 1e-12 * hi.abs().max(1.0) {
        return (lo - 0.5, hi + 0.5);
    }
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

/// A line to draw: label, colour, dashed (ideal) or solid, points.
pub(super) type Curve = (String, RGBColor, bool, Vec<(f64, f64)>);

pub(super) fn case_color(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Sizes of a panel's parts, px.
#[derive(Clone, Copy, Debug)]
pub(super) struct PanelStyle {
    /// Caption font.
    pub(super) caption: u32,
    /// Chart margin on every side.
    pub(super) margin: u32,
    /// Heights of the x label area and widths of the y label area.
    pub(super) label_areas: (u32, u32),
    /// Tick label and axis description fonts.
    pub(super) mesh: (u32, u32),
    /// Legend font.
    pub(super) legend: u32,
}

/// One panel of curves: caption, axes with their descriptions, the curves (in order, so a
/// dashed curve listed last lies over the solid ones) and a legend that crosses no curve.
pub(super) struct Panel<'a> {
    pub(super) caption: &'a str,
    pub(super) descs: (&'a str, &'a str),
    pub(super) x: (f64, f64),
    pub(super) y: (f64, f64),
    pub(super) curves: &'a [Curve],
    pub(super) style: PanelStyle,
}

/// The width in pixels of the widest tick label of an axis over `range`, at font `size`.
pub(super) fn widest_tick<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    range: (f64, f64),
    size: u32,
) -> u32 {
    let format = TickFormat::for_axis(range.0, range.1, TICKS);
    let font = TextStyle::from((FAMILY, size).into_font());
    let ticks = RangedCoordf64::from(range.0.min(range.1)..range.0.max(range.1)).key_points(TICKS);
    let width = |t: f64| {
        area.estimate_text_size(&format.format(t), &font)
            .map_or(0, |s| s.0)
    };
    ticks.into_iter().map(width).max().unwrap_or(0)
}

/// `points` in pixels of a plotting area of `plot` pixels showing `x` by `y`.
pub(super) fn to_pixels(
    points: &[(f64, f64)],
    x: (f64, f64),
    y: (f64, f64),
    plot: (i32, i32),
) -> Vec<(f64, f64)> {
    let (w, h) = (f64::from(plot.0), f64::from(plot.1));
    let (sx, sy) = ((x.1 - x.0).max(1e-300), (y.1 - y.0).max(1e-300));
    points
        .iter()
        .map(|&(u, v)| ((u - x.0) / sx * w, (y.1 - v) / sy * h))
        .collect()
}

impl Panel<'_> {
    fn legend(&self) -> Legend {
        let entries = self.curves.iter().map(|(label, color, dashed, _)| Entry {
            label: label.clone(),
            mark: if *dashed {
                Mark::Dashed(*color)
            } else {
                Mark::Line(*color)
            },
        });
        Legend {
            entries: entries.collect(),
            font_size: self.style.legend,
            row: false,
        }
    }

    fn pixel_paths(&self, y: (f64, f64), plot: (i32, i32)) -> Vec<Vec<(f64, f64)>> {
        self.curves
            .iter()
            .map(|c| to_pixels(&c.3, self.x, y, plot))
            .collect()
    }

    /// The y range to draw: the panel's, or raised so the legend fits above the data when no
    /// corner of the plot is free of curves.
    fn y_range(&self, plot: (i32, i32), legend: (i32, i32)) -> (f64, f64) {
        if legend::free_corner(&self.pixel_paths(self.y, plot), plot, legend).is_some() {
            return self.y;
        }
        let top = self.curves.iter().flat_map(|c| c.3.iter().map(|p| p.1));
        let y_max = top.filter(|v| v.is_finite()).fold(self.y.0, f64::max);
        let need = 2 * INSET + legend.1;
        match legend::headroom(self.y.0, y_max, need, plot.1) {
            Some(y1) => (self.y.0, y1.max(self.y.1)),
            None => self.y,
        }
    }

    pub(super) fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let st = self.style;
        let area = if self.caption.is_empty() {
            area.clone()
        } else {
            area.titled(self.caption, (FAMILY, st.caption).into_font().color(&BLACK))?
        };
        // The plotting area ChartBuilder leaves, known before building so the y range can
        // make room for the legend; the y label area is as wide as the y range's tick labels
        // need, which the legend's headroom may change, hence the second pass.
        let (w, h) = area.dim_in_pixel();
        let right = st.margin.max(widest_tick(&area, self.x, st.mesh.0) / 2 + 4);
        let y_area = |y: (f64, f64)| {
            let need = widest_tick(&area, y, st.mesh.0) + st.mesh.1 + 30;
            st.label_areas.1.max(need)
        };
        let plot = |y_area: u32| {
            let used_w = st.margin + right + y_area;
            let used_h = 2 * st.margin + st.label_areas.0;
            (w as i32 - used_w as i32, h as i32 - used_h as i32)
        };
        let legend = self.legend();
        let size = legend.size(&area);
        let mut y_width = y_area(self.y);
        let mut y = self.y_range(plot(y_width), size);
        if y_area(y) > y_width {
            y_width = y_area(y);
            y = self.y_range(plot(y_width), size);
        }
        let mut chart = ChartBuilder::on(&area)
            .margin(st.margin)
            .margin_right(right)
            .x_label_area_size(st.label_areas.0)
            .y_label_area_size(y_width)
            .build_cartesian_2d(self.x.0..self.x.1, y.0..y.1)?;
        draw_mesh(&mut chart, self.descs, st.mesh)?;
        for (_, color, dashed, points) in self.curves {
            let style = color.stroke_width(if *dashed { 2 } else { 1 });
            if *dashed {
                chart.draw_series(DashedLineSeries::new(points.iter().copied(), 8, 5, style))?;
            } else {
                chart.draw_series(LineSeries::new(points.iter().copied(), style))?;
            }
        }
        let plotting = chart.plotting_area().strip_coord_spec();
        let (pw, ph) = plotting.dim_in_pixel();
        let actual = (pw as i32, ph as i32);
        let at = legend::free_corner(&self.pixel_paths(y, actual), actual, size);
        legend.draw(&plotting, at.unwrap_or((INSET, INSET)))
    }
}
