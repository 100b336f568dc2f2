//! Figures of a run or a study, one per figure kind of the paper, as PNG and SVG (plotters):
//! - angles and rates of every movable body vs time, each case with its ideal curve
//!   (the paper's figs 3, 6, 9);
//! - joint force vs time, ideal and clearance joint, one row per case (figs 4, 7, 10);
//! - journal-centre trajectory inside the clearance circle, to scale, one panel per case
//!   (figs 5, 8, 11).
//!
//! Long series are decimated for drawing: time series keep the minimum and the maximum of
//! every pixel column ([`minmax_decimate`]), so impact peaks survive; trajectories drop points
//! closer than a fraction of a pixel to the last kept one ([`decimate_path`]). PNG text is drawn
//! with DejaVu Sans embedded in the binary (`assets/fonts/`), so nothing depends on the fonts of
//! the machine, and laid out by [`text`] (plotters' own PNG text misplaces glyphs).
//!
//! - [`legend`]: the legends, placed where they cover no curve.
//! - [`series`]: the time series of one case, read from a run's tables or a point's CSV files.
//! - [`run`]: the figures of one scene run (`run`, the default job).
//! - [`text`]: the figures' text layout and rasterisation.
//! - [`ticks`]: the axes' tick labels.

pub mod legend;
pub mod run;
pub mod series;
pub mod text;
pub mod ticks;

use crate::process::files::write_atomic;
use ab_glyph::FontRef;
use clearance_joint::error::{Error, Result};
use legend::{Entry, INSET, Legend, Mark};
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use series::CaseSeries;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use text::{Target, Typeset};
use ticks::{TICKS, TickFormat};

type DrawResult = std::result::Result<(), Box<dyn std::error::Error>>;

/// DejaVu Sans (Bitstream Vera licence, `assets/fonts/LICENSE-DejaVu.txt`).
static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
/// The family the text styles name; plotters still measures legends with the font registered
/// under it, [`text::Typeset`] draws every text in [`FONT`] whatever the family.
const FAMILY: &str = "sans-serif";

/// Case colours (Okabe-Ito, readable by colour-blind readers).
pub const PALETTE: [RGBColor; 6] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
];

/// The embedded font, registered with plotters once per process (its legends measure text
/// with it).
fn font() -> Result<FontRef<'static>> {
    static OK: OnceLock<bool> = OnceLock::new();
    let ok =
        *OK.get_or_init(|| plotters::style::register_font(FAMILY, FontStyle::Normal, FONT).is_ok());
    match FontRef::try_from_slice(FONT) {
        Ok(font) if ok => Ok(font),
        _ => Err(Error::invalid(
            "assets/fonts/DejaVuSans.ttf",
            "is not a usable TrueType font",
        )),
    }
}

/// The kinds of figure.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FigureKind {
    /// Angles and rates vs time (figs 3, 6, 9).
    AnglesRates,
    /// Joint force vs time (figs 4, 7, 10).
    Force,
    /// Journal-centre trajectory (figs 5, 8, 11).
    Trajectory,
}

impl FigureKind {
    /// All kinds, in the paper's order.
    pub const ALL: [FigureKind; 3] = [
        FigureKind::AnglesRates,
        FigureKind::Force,
        FigureKind::Trajectory,
    ];

    /// File stem: `angles_rates`, `joint_force`, `trajectory`.
    pub fn stem(self) -> &'static str {
        match self {
            FigureKind::AnglesRates => "angles_rates",
            FigureKind::Force => "joint_force",
            FigureKind::Trajectory => "trajectory",
        }
    }

    /// What the figure shows, for a title: "body angles and angular rates", "joint force",
    /// "journal-centre trajectory".
    pub fn subject(self) -> &'static str {
        match self {
            FigureKind::AnglesRates => "body angles and angular rates",
            FigureKind::Force => "joint force",
            FigureKind::Trajectory => "journal-centre trajectory",
        }
    }
}

/// A figure to draw: its kind, title and cases.
#[derive(Clone, Copy, Debug)]
pub struct Figure<'a> {
    /// What is drawn.
    pub kind: FigureKind,
    /// Title line at the top.
    pub title: &'a str,
    /// The cases, in legend order.
    pub cases: &'a [CaseSeries],
}

impl Figure<'_> {
    /// Pixel size of the figure.
    pub fn size(&self) -> (u32, u32) {
        let n = self.cases.len().max(1) as u32;
        match self.kind {
            FigureKind::AnglesRates => {
                let rows = self.cases.first().map_or(1, |c| c.bodies.len().max(1)) as u32;
                (1400, 90 + 420 * rows)
            }
            FigureKind::Force => (1400, 90 + 300 * n),
            FigureKind::Trajectory => ((520 * n).max(700), 640),
        }
    }

    /// Renders the figure into a PNG image (RGB, 8 bit), in memory.
    pub fn png(&self) -> Result<Vec<u8>> {
        render_png(self)
    }

    /// Renders the figure as SVG text.
    pub fn svg(&self) -> Result<String> {
        render_svg(self)
    }

    /// Writes `<dir>/<stem>.png` and `<dir>/<stem>.svg` (each whole or not at all); returns both paths.
    pub fn write(&self, dir: &Path, stem: &str) -> Result<[PathBuf; 2]> {
        write_both(self, dir, stem)
    }

    fn error(&self, format: &str, e: Box<dyn std::error::Error>) -> Error {
        Error::invalid(
            format!("figure `{}` ({format})", self.kind.stem()),
            format!("cannot be drawn: {e}"),
        )
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE)?;
        let body = root.titled(self.title, (FAMILY, 26).into_font().color(&BLACK))?;
        if self.cases.is_empty() {
            return Ok(());
        }
        match self.kind {
            FigureKind::AnglesRates => draw_angles_rates(&body, self.cases),
            FigureKind::Force => draw_force(&body, self.cases),
            FigureKind::Trajectory => draw_trajectory(&body, self.cases),
        }
    }
}

/// What the renderers need of a figure.
trait Drawable {
    fn pixels(&self) -> (u32, u32);
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static;
    fn fail(&self, format: &str, e: Box<dyn std::error::Error>) -> Error;
}

impl Drawable for Figure<'_> {
    fn pixels(&self) -> (u32, u32) {
        self.size()
    }
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        self.draw(root)
    }
    fn fail(&self, format: &str, e: Box<dyn std::error::Error>) -> Error {
        self.error(format, e)
    }
}

fn render_png(f: &impl Drawable) -> Result<Vec<u8>> {
    let font = font()?;
    let (w, h) = f.pixels();
    let mut rgb = vec![0u8; w as usize * h as usize * 3];
    {
        let bitmap = BitMapBackend::with_buffer(&mut rgb, (w, h));
        let root = Typeset::new(bitmap, font, Target::Raster).into_drawing_area();
        f.draw_on(&root).map_err(|e| f.fail("PNG", e))?;
        root.present()
            .map_err(|e| f.fail("PNG", e.to_string().into()))?;
    }
    let mut bytes = Vec::new();
    let mut enc = png::Encoder::new(&mut bytes, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let encode =
        |enc: png::Encoder<'_, &mut Vec<u8>>| -> std::result::Result<(), png::EncodingError> {
            let mut writer = enc.write_header()?;
            writer.write_image_data(&rgb)?;
            writer.finish()
        };
    encode(enc).map_err(|e| f.fail("PNG", e.to_string().into()))?;
    Ok(bytes)
}

fn render_svg(f: &impl Drawable) -> Result<String> {
    let font = font()?;
    let mut text = String::new();
    {
        let svg = SVGBackend::with_string(&mut text, f.pixels());
        let root = Typeset::new(svg, font, Target::Vector).into_drawing_area();
        f.draw_on(&root).map_err(|e| f.fail("SVG", e))?;
        root.present()
            .map_err(|e| f.fail("SVG", e.to_string().into()))?;
    }
    Ok(text)
}

fn write_both(f: &impl Drawable, dir: &Path, stem: &str) -> Result<[PathBuf; 2]> {
    let png_path = dir.join(format!("{stem}.png"));
    let svg_path = dir.join(format!("{stem}.svg"));
    write_atomic(&png_path, &render_png(f)?)?;
    write_atomic(&svg_path, render_svg(f)?.as_bytes())?;
    Ok([png_path, svg_path])
}

/// A plain figure of curves `y` against `x` (e.g. a slider's acceleration against the crank
/// angle), each curve a label and its points in drawing order.
#[derive(Clone, Copy, Debug)]
pub struct XyFigure<'a> {
    /// Title line at the top.
    pub title: &'a str,
    /// Axis descriptions.
    pub x_label: &'a str,
    /// Axis descriptions.
    pub y_label: &'a str,
    /// The curves: label and points.
    pub curves: &'a [(String, Vec<(f64, f64)>)],
}

impl XyFigure<'_> {
    /// Writes `<dir>/<stem>.png` and `<dir>/<stem>.svg`; returns both paths.
    pub fn write(&self, dir: &Path, stem: &str) -> Result<[PathBuf; 2]> {
        write_both(self, dir, stem)
    }
}

impl Drawable for XyFigure<'_> {
    fn pixels(&self) -> (u32, u32) {
        (1200, 700)
    }
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE)?;
        let body = root.titled(self.title, (FAMILY, 26).into_font().color(&BLACK))?;
        let pts = || self.curves.iter().flat_map(|(_, p)| p.iter()).copied();
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for (x, y) in pts().filter(|(x, y)| x.is_finite() && y.is_finite()) {
            (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
        }
        if !(x1 > x0) || !(y1 >= y0) {
            return Ok(());
        }
        let pad = 0.05 * (y1 - y0).max(1e-12);
        let curves: Vec<Curve> = (self.curves.iter().enumerate())
            .map(|(i, (label, points))| {
                let color = if i == 0 { BLACK } else { case_color(i - 1) };
                (label.clone(), color, false, points.clone())
            })
            .collect();
        Panel {
            caption: "",
            descs: (self.x_label, self.y_label),
            x: (x0, x1),
            y: (y0 - pad, y1 + pad),
            curves: &curves,
            style: PanelStyle {
                caption: 0,
                margin: 15,
                label_areas: (45, 90),
                mesh: (15, 17),
                legend: 15,
            },
        }
        .draw(&body)
    }
    fn fail(&self, format: &str, e: Box<dyn std::error::Error>) -> Error {
        Error::invalid(
            format!("figure `{}` ({format})", self.title),
            format!("cannot be drawn: {e}"),
        )
    }
}

/// A chart of `f64` against `f64`.
type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Draws `chart`'s axes, grid and tick labels (labels of `sizes.0`, descriptions of `sizes.1`),
/// every axis's labels with one number of decimals ([`TickFormat`]).
fn draw_mesh<DB: DrawingBackend>(
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

/// `[lo, hi]` of the values with 5 % padding (a unit span around a constant).
fn range_of<'a>(values: impl IntoIterator<Item = &'a f64>) -> (f64, f64) {
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

fn time_range(cases: &[CaseSeries]) -> (f64, f64) {
    let t1 = cases
        .iter()
        .filter_map(|c| c.t_s.last().copied())
        .fold(0.0, f64::max);
    (0.0, if t1 > 0.0 { t1 } else { 1.0 })
}

const DECIMATE_BINS: usize = 900;

/// Which cases draw their own ideal curve: a case whose ideal series equals an earlier case's
/// (e.g. clearance and friction do not change the ideal twin) does not draw it again.
fn distinct_ideals(cases: &[CaseSeries]) -> Vec<bool> {
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

/// A line to draw: label, colour, dashed (ideal) or solid, points.
type Curve = (String, RGBColor, bool, Vec<(f64, f64)>);

fn case_color(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Sizes of a panel's parts, px.
#[derive(Clone, Copy, Debug)]
struct PanelStyle {
    /// Caption font.
    caption: u32,
    /// Chart margin on every side.
    margin: u32,
    /// Heights of the x label area and widths of the y label area.
    label_areas: (u32, u32),
    /// Tick label and axis description fonts.
    mesh: (u32, u32),
    /// Legend font.
    legend: u32,
}

/// One panel of curves: caption, axes with their descriptions, the curves (in order, so a
/// dashed curve listed last lies over the solid ones) and a legend that crosses no curve.
struct Panel<'a> {
    caption: &'a str,
    descs: (&'a str, &'a str),
    x: (f64, f64),
    y: (f64, f64),
    curves: &'a [Curve],
    style: PanelStyle,
}

/// The width in pixels of the widest tick label of an axis over `range`, at font `size`.
fn widest_tick<DB: DrawingBackend>(
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
fn to_pixels(
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

    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult
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

fn draw_angles_rates<DB: DrawingBackend>(
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
            let pick = |b: &series::BodySeries, ideal: bool| -> Vec<f64> {
                match (is_rate, ideal) {
                    (false, false) => b.angle_deg.clone(),
                    (false, true) => b.angle_ideal_deg.clone(),
                    (true, false) => b.rate_deg_s.clone(),
                    (true, true) => b.rate_ideal_deg_s.clone(),
                }
            };
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
                    minmax_decimate(&case.t_s, &pick(b, false), t0, t1, DECIMATE_BINS),
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
                        minmax_decimate(&case.t_s, &pick(b, true), t0, t1, DECIMATE_BINS),
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

/// A force panel's caption: the joint, after the case's label when there are several cases (a
/// single case is named by the figure's title and legends).
fn force_caption(cases: usize, label: &str, joint: &str) -> String {
    if cases > 1 {
        format!("{label}: {joint}")
    } else {
        joint.to_string()
    }
}

/// What the force panels drew of the runs: the rows, thinned, and for the clearance joint
/// each contact's peak from every step.
fn force_footnote(cases: &[CaseSeries]) -> String {
    let peaks: usize = cases.iter().map(|c| c.peaks.len()).sum();
    format!(
        "Curves: the output rows, each pixel column's smallest and largest value; the clearance \
         joint's also passes through each contact's peak from every step ({peaks} contact peaks)."
    )
}

/// The top of a force axis over `series`: 5 % above their largest finite value (1 N when none
/// is positive).
fn force_top<'a>(series: impl Iterator<Item = &'a [f64]>) -> f64 {
    let m = series
        .flatten()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    if m > 0.0 { 1.05 * m } else { 1.0 }
}

fn draw_force<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, cases: &[CaseSeries]) -> DrawResult
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

/// The trajectory legend of case `i`: one row under the plot when it fits the panel's
/// `width`, else a column.
fn trajectory_legend<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, i: usize) -> Legend {
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
fn circle_points(c: f64) -> Vec<(f64, f64)> {
    (0..=720)
        .map(|k| {
            let a = k as f64 * std::f64::consts::PI / 360.0;
            (c * a.cos(), c * a.sin())
        })
        .collect()
}

fn draw_trajectory<DB: DrawingBackend>(
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
