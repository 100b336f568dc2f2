//! The figures' text, laid out and rasterised here instead of by plotters' `ab_glyph` path.
//!
//! plotters 0.3.7 draws each glyph of a PNG's text at its pen position truncated to a whole
//! pixel and without the glyph's left side bearing (it adds the offset of the glyph's pixel box
//! for `y` but not for `x`), so a glyph with a wide bearing slides left onto its neighbour: "cl"
//! read as "d" and "time" as "tim e". [`Typeset`] wraps a backend and draws text itself:
//! pen positions in `f32` from the font's advances and kerning, every glyph rasterised at its
//! exact (sub-pixel) place with its bearings, the anti-aliased coverage blended onto the
//! backend. On an SVG backend it keeps plotters' `<text>` elements but gives them the same font
//! and size as the PNG, so the two files lay out alike.

use ab_glyph::{Font, FontRef, GlyphId, OutlinedGlyph, PxScale, ScaleFont, point};
use plotters::style::FontTransform;
use plotters::style::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
    FontFamily, FontStyle,
};

/// The font-family list of the SVG's text: the embedded font by name (a viewer that has it
/// draws what the PNG shows), then any sans-serif.
const SVG_FAMILY: &str = "DejaVu Sans, sans-serif";

/// plotters' text height unit: its layout boxes (and its SVG font-size) are `size / 1.24`.
const PLOTTERS_EM_RATIO: f64 = 1.24;

/// A line of text placed on its baseline: each glyph with its pen position (px from the line's
/// start), and the line's advance width.
#[derive(Clone, Debug, PartialEq)]
pub struct Line {
    /// Glyphs and their pen positions, px.
    pub glyphs: Vec<(GlyphId, f32)>,
    /// Advance width of the whole line, px.
    pub width: f32,
}

/// The pixel scale of text of plotters `size`: the height from descent to ascent is `size`
/// (as plotters' own `ab_glyph` path scales it, so the figures' text keeps its size).
pub fn scale(size: f64) -> PxScale {
    PxScale::from(size as f32)
}

/// The em of text of plotters `size`, px (the SVG's font-size).
pub fn em(font: &FontRef<'_>, size: f64) -> f32 {
    let scaled = font.as_scaled(scale(size));
    scaled.h_scale_factor() * font.units_per_em().unwrap_or(2048.0)
}

/// Lays `text` out on one line: each pen position is the previous one plus its glyph's advance
/// and the pair's kerning, kept in `f32` (no rounding, so errors never add up along the line).
pub fn layout(font: &FontRef<'_>, size: f64, text: &str) -> Line {
    let scaled = font.as_scaled(scale(size));
    let mut glyphs = Vec::with_capacity(text.len());
    let mut pen = 0.0f32;
    let mut prev: Option<GlyphId> = None;
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = prev {
            pen += scaled.kern(p, id);
        }
        glyphs.push((id, pen));
        pen += scaled.h_advance(id);
        prev = Some(id);
    }
    Line { glyphs, width: pen }
}

/// Offset of the line's start and baseline from the anchor point, px, as plotters' SVG backend
/// places text (`text-anchor`, and `dy` of 0.76 em, 0.5 ex or -0.5 ex), so PNG and SVG agree.
/// Rounded to whole pixels: a baseline on a pixel edge keeps horizontal strokes crisp, and every
/// tick label then renders its digits alike.
fn origin(
    font: &FontRef<'_>,
    size: f64,
    width: f32,
    anchor: plotters::style::text_anchor::Pos,
) -> (f32, f32) {
    let dx = match anchor.h_pos {
        HPos::Left => 0.0,
        HPos::Center => -width / 2.0,
        HPos::Right => -width,
    };
    let em = em(font, size);
    let ex = x_height(font) * em;
    let dy = match anchor.v_pos {
        VPos::Top => 0.76 * em,
        VPos::Center => 0.5 * ex,
        VPos::Bottom => -0.5 * ex,
    };
    (dx.round(), dy.round())
}

/// The font's x-height as a fraction of the em (what an SVG viewer's `ex` is).
fn x_height(font: &FontRef<'_>) -> f32 {
    let upem = font.units_per_em().unwrap_or(2048.0);
    font.outline(font.glyph_id('x'))
        .map_or(0.5, |o| o.bounds.min.y.max(o.bounds.max.y) / upem)
}

/// Anti-aliased coverage of a line of text over a pixel rectangle of the text's own frame
/// (x right, y down, the origin at the anchor point).
#[derive(Clone, Debug)]
pub struct Coverage {
    /// Top-left pixel of the rectangle.
    pub min: (i32, i32),
    /// Width and height, px.
    pub size: (usize, usize),
    /// Coverage in `[0, 1]`, row by row.
    pub alpha: Vec<f32>,
}

impl Coverage {
    /// Coverage at a pixel of the text's frame (0 outside).
    pub fn at(&self, x: i32, y: i32) -> f32 {
        let (i, j) = (x - self.min.0, y - self.min.1);
        if i < 0 || j < 0 || i as usize >= self.size.0 || j as usize >= self.size.1 {
            return 0.0;
        }
        self.alpha[j as usize * self.size.0 + i as usize]
    }
}

/// Rasterises `line` with its start and baseline at `(x, y)` of the text's frame: each glyph at
/// its exact pen position, its outline keeping its side bearings; overlapping coverage adds up
/// to at most 1.
pub fn rasterize(font: &FontRef<'_>, size: f64, line: &Line, (x, y): (f32, f32)) -> Coverage {
    let outlines: Vec<OutlinedGlyph> = line
        .glyphs
        .iter()
        .filter_map(|&(id, pen)| {
            font.outline_glyph(id.with_scale_and_position(scale(size), point(x + pen, y)))
        })
        .collect();
    let (mut lo, mut hi) = ((i32::MAX, i32::MAX), (i32::MIN, i32::MIN));
    for g in &outlines {
        let b = g.px_bounds();
        lo = (lo.0.min(b.min.x as i32), lo.1.min(b.min.y as i32));
        hi = (hi.0.max(b.max.x as i32), hi.1.max(b.max.y as i32));
    }
    if outlines.is_empty() {
        return Coverage {
            min: (0, 0),
            size: (0, 0),
            alpha: Vec::new(),
        };
    }
    let size = ((hi.0 - lo.0) as usize, (hi.1 - lo.1) as usize);
    let mut alpha = vec![0.0f32; size.0 * size.1];
    for g in &outlines {
        let b = g.px_bounds();
        let (ox, oy) = (b.min.x as i32 - lo.0, b.min.y as i32 - lo.1);
        g.draw(|gx, gy, c| {
            let k = (oy + gy as i32) as usize * size.0 + (ox + gx as i32) as usize;
            alpha[k] = (alpha[k] + c).min(1.0);
        });
    }
    Coverage {
        min: lo,
        size,
        alpha,
    }
}

/// Where pixel `(x, y)` of the text's frame lands after plotters' rotation: the rotation maps
/// points, and a pixel is the unit square right of and below its index, hence the `- 1`s.
fn rotate(t: &FontTransform, (x, y): (i32, i32)) -> (i32, i32) {
    match t {
        FontTransform::None => (x, y),
        FontTransform::Rotate90 => (-y - 1, x),
        FontTransform::Rotate180 => (-x - 1, -y - 1),
        FontTransform::Rotate270 => (y, -x - 1),
    }
}

/// What a [`Typeset`] backend makes of text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// Pixels: the text is rasterised here and blended onto the backend.
    Raster,
    /// Vector text (SVG): plotters' `<text>` elements, in the figures' font and size.
    Vector,
}

/// A drawing backend whose text is laid out (and, for [`Target::Raster`], drawn) with the
/// figures' font by this module; everything else goes to the wrapped backend unchanged.
pub struct Typeset<B> {
    inner: B,
    font: FontRef<'static>,
    target: Target,
}

impl<B: DrawingBackend> Typeset<B> {
    /// Wraps `inner`, setting all its text in `font`.
    pub fn new(inner: B, font: FontRef<'static>, target: Target) -> Self {
        Typeset {
            inner,
            font,
            target,
        }
    }

    fn draw_raster<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        let line = layout(&self.font, style.size(), text);
        let start = origin(&self.font, style.size(), line.width, style.anchor());
        let cover = rasterize(&self.font, style.size(), &line, start);
        let (color, turn) = (style.color(), style.transform());
        for j in 0..cover.size.1 as i32 {
            for i in 0..cover.size.0 as i32 {
                let (x, y) = (cover.min.0 + i, cover.min.1 + j);
                let a = cover.at(x, y);
                if a <= 0.0 {
                    continue;
                }
                let (dx, dy) = rotate(&turn, (x, y));
                let pixel = BackendColor {
                    alpha: color.alpha * f64::from(a),
                    rgb: color.rgb,
                };
                self.inner.draw_pixel((pos.0 + dx, pos.1 + dy), pixel)?;
            }
        }
        Ok(())
    }
}

/// A text style as the SVG backend should write it: the figures' font family and the em of
/// the PNG's text as its font-size (the backend writes `size / 1.24`).
struct SvgStyle<'a, S> {
    inner: &'a S,
    size: f64,
}

impl<S: BackendTextStyle> BackendTextStyle for SvgStyle<'_, S> {
    type FontError = S::FontError;
    fn color(&self) -> BackendColor {
        self.inner.color()
    }
    fn size(&self) -> f64 {
        self.size
    }
    fn transform(&self) -> FontTransform {
        self.inner.transform()
    }
    fn style(&self) -> FontStyle {
        self.inner.style()
    }
    fn anchor(&self) -> plotters::style::text_anchor::Pos {
        self.inner.anchor()
    }
    fn family(&self) -> FontFamily<'_> {
        FontFamily::Name(SVG_FAMILY)
    }
    fn layout_box(&self, text: &str) -> Result<((i32, i32), (i32, i32)), Self::FontError> {
        self.inner.layout_box(text)
    }
    fn draw<E, F: FnMut(i32, i32, BackendColor) -> Result<(), E>>(
        &self,
        text: &str,
        pos: BackendCoord,
        draw: F,
    ) -> Result<Result<(), E>, Self::FontError> {
        self.inner.draw(text, pos, draw)
    }
}

impl<B: DrawingBackend> DrawingBackend for Typeset<B> {
    type ErrorType = B::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }
    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        self.inner.ensure_prepared()
    }
    fn present(&mut self) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        self.inner.present()
    }
    fn draw_pixel(
        &mut self,
        point: BackendCoord,
        color: BackendColor,
    ) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        self.inner.draw_pixel(point, color)
    }
    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        self.inner.draw_line(from, to, style)
    }
    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        self.inner.draw_rect(upper_left, bottom_right, style, fill)
    }
    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        self.inner.draw_path(path, style)
    }
    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        self.inner.draw_circle(center, radius, style, fill)
    }
    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        self.inner.fill_polygon(vert, style)
    }
    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        self.inner.blit_bitmap(pos, size, src)
    }

    fn draw_text<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        if style.color().alpha == 0.0 {
            return Ok(());
        }
        match self.target {
            Target::Raster => self.draw_raster(text, style, pos),
            Target::Vector => {
                let size = f64::from(em(&self.font, style.size())) * PLOTTERS_EM_RATIO;
                self.inner
                    .draw_text(text, &SvgStyle { inner: style, size }, pos)
            }
        }
    }

    /// The exact advance width (rounded up) and plotters' box height (`size / 1.24`, which its
    /// legends also use), the same for PNG and SVG.
    fn estimate_text_size<S: BackendTextStyle>(
        &self,
        text: &str,
        style: &S,
    ) -> Result<(u32, u32), DrawingErrorKind<B::ErrorType>> {
        let width = layout(&self.font, style.size(), text).width;
        Ok((
            width.ceil() as u32,
            (style.size() / PLOTTERS_EM_RATIO) as u32,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::prelude::*;

    const W: u32 = 420;
    const H: u32 = 420;
    /// Where the test text is anchored.
    const AT: (i32, i32) = (10, 10);

    fn font() -> FontRef<'static> {
        super::super::render::font().unwrap()
    }

    /// Darkness (0 white to 1 black), row by row, of `text` drawn in black at `at` (top left
    /// anchor) through the figures' PNG backend.
    fn render(text: &str, size: u32, turn: FontTransform, at: (i32, i32)) -> Vec<f32> {
        let mut rgb = vec![0u8; (W * H * 3) as usize];
        {
            let bitmap = BitMapBackend::with_buffer(&mut rgb, (W, H));
            let root = Typeset::new(bitmap, font(), Target::Raster).into_drawing_area();
            root.fill(&WHITE).unwrap();
            let style = ("sans-serif", size)
                .into_font()
                .transform(turn)
                .color(&BLACK);
            root.draw_text(text, &style, at).unwrap();
            root.present().unwrap();
        }
        rgb.chunks(3)
            .map(|p| 1.0 - f32::from(p[0]) / 255.0)
            .collect()
    }

    /// Per pixel column, the summed darkness.
    fn columns(image: &[f32]) -> Vec<f32> {
        (0..W as usize)
            .map(|x| (0..H as usize).map(|y| image[y * W as usize + x]).sum())
            .collect()
    }

    /// The column profile of `text` as ab_glyph's exact layout has it, computed here from
    /// advances and kerning alone: each glyph outline at its `f32` pen position from [`AT`].
    fn exact_columns(text: &str, size: u32) -> Vec<f32> {
        let font = font();
        let scaled = font.as_scaled(PxScale::from(size as f32));
        let mut out = vec![0.0f32; W as usize];
        let (mut pen, mut prev) = (AT.0 as f32, None);
        for c in text.chars() {
            let id = scaled.glyph_id(c);
            pen += prev.map_or(0.0, |p| scaled.kern(p, id));
            let glyph = id.with_scale_and_position(scaled.scale(), point(pen, 100.0));
            if let Some(g) = font.outline_glyph(glyph) {
                let x0 = g.px_bounds().min.x as i32;
                g.draw(|x, _, a| out[(x0 + x as i32) as usize] += a);
            }
            pen += scaled.h_advance(id);
            prev = Some(id);
        }
        out
    }

    #[test]
    fn every_glyph_sits_where_the_exact_layout_puts_it() {
        let texts = [
            "clearance circle",
            "time (s)",
            "peak 0.3275 N",
            "-0.05",
            "journal centre",
        ];
        for size in [14, 15, 16, 17, 18, 20, 22, 26] {
            for text in texts {
                let got = columns(&render(text, size, FontTransform::None, AT));
                let want = exact_columns(text, size);
                let worst = got
                    .iter()
                    .zip(&want)
                    .map(|(g, w)| (g - w).abs())
                    .fold(0.0, f32::max);
                // Blending to 8 bits rounds each pixel by under 1/255: far below a glyph moved
                // by a pixel, which shifts a whole stem's darkness (several px) to a neighbour.
                assert!(
                    worst < 0.25,
                    "`{text}` at {size}: a column differs by {worst} px of ink"
                );
            }
        }
    }

    /// Runs of consecutive columns holding ink darker than `min` somewhere.
    fn ink_runs(image: &[f32], min: f32) -> usize {
        let inked: Vec<bool> = (0..W as usize)
            .map(|x| (0..H as usize).any(|y| image[y * W as usize + x] > min))
            .collect();
        inked.windows(2).filter(|w| w[1] && !w[0]).count() + usize::from(inked[0])
    }

    #[test]
    fn c_and_l_stay_two_letters() {
        // The gap between 'c' and 'l' is 0.15 em: always a column with no ink at these sizes.
        for size in [14, 15, 16, 17, 18, 20, 22, 26] {
            let image = render("cl", size, FontTransform::None, AT);
            assert_eq!(ink_runs(&image, 0.15), 2, "\"cl\" at {size} runs together");
        }
    }

    #[test]
    fn turned_text_is_the_same_pixels_turned() {
        let text = "eccentricity v (mm)";
        let flat = render(text, 17, FontTransform::None, AT);
        let low = (AT.0, H as i32 - 10);
        let turned = render(text, 17, FontTransform::Rotate270, low);
        let at = |img: &[f32], (x, y): (i32, i32)| img[(y * W as i32 + x) as usize];
        let mut ink = 0.0;
        for y in -5..40 {
            for x in 0..W as i32 - 2 * AT.0 {
                // Rotate270 takes pixel (x, y) of the text's frame to (y, -x - 1).
                let want = at(&flat, (AT.0 + x, AT.1 + y));
                let got = at(&turned, (low.0 + y, low.1 - x - 1));
                assert_eq!(got, want, "pixel ({x}, {y}) of the text");
                ink += want;
            }
        }
        assert!(ink > 50.0, "the text was drawn ({ink} px of ink)");
    }

    #[test]
    fn measured_width_is_the_exact_layout_width_and_plotters_legend_width() {
        let font = font();
        let mut out = String::new();
        let svg = SVGBackend::with_string(&mut out, (10, 10));
        let backend = Typeset::new(svg, font.clone(), Target::Vector);
        for size in [14, 15, 20, 26] {
            let style = ("sans-serif", size).into_font();
            for text in ["clearance circle |e| = c", "ideal joint, peak 0.3275 N"] {
                let (w, _) = backend
                    .estimate_text_size(text, &TextStyle::from(style.clone()))
                    .unwrap();
                let exact = layout(&font, f64::from(size), text).width;
                assert_eq!(w, exact.ceil() as u32, "`{text}` at {size}");
                // Legends measure their text with plotters' own estimate; it must agree.
                let (legend, _) = style.box_size(text).unwrap();
                assert!(
                    w.abs_diff(legend) <= 1,
                    "`{text}` at {size}: {w} vs legend {legend}"
                );
            }
        }
    }

    #[test]
    fn svg_text_has_the_png_font_and_em() {
        let mut out = String::new();
        {
            let svg = SVGBackend::with_string(&mut out, (200, 50));
            let root = Typeset::new(svg, font(), Target::Vector).into_drawing_area();
            let style = ("sans-serif", 26).into_font().color(&BLACK);
            root.draw_text("time (s)", &style, (5, 5)).unwrap();
            root.present().unwrap();
        }
        let size: f32 = out
            .split("font-size=\"")
            .nth(1)
            .and_then(|s| s.split('"').next())
            .and_then(|s| s.parse().ok())
            .unwrap();
        assert!((size - em(&font(), 26.0)).abs() < 1e-3, "font-size {size}");
        assert!(
            out.contains(&format!("font-family=\"{SVG_FAMILY}\"")),
            "{out}"
        );
    }
}
