//! Rendering a figure to PNG and SVG with the embedded font, and writing both.

use super::*;

/// DejaVu Sans (Bitstream Vera licence, `assets/fonts/LICENSE-DejaVu.txt`).
pub(super) static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// The embedded font, registered with plotters once per process (its legends measure text
/// with it).
pub(super) fn font() -> Result<FontRef<'static>> {
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

/// What the renderers need of a figure.
pub(super) trait Drawable {
    fn pixels(&self) -> (u32, u32);
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static;
    fn fail(&self, format: &str, e: Box<dyn std::error::Error>) -> Error;
}

pub(super) fn render_png(f: &impl Drawable) -> Result<Vec<u8>> {
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
    // Deflate's fastest level behind the `Up` filter on every row: the figures are mostly flat
    // colour and straight runs, so the adaptive filter's per-row trial of all five filters
    // buys nothing (0.29 MB for the paper's scene's three figures either way) and costs about
    // 4 % of its sub-cycled run's CPU. `fdeflate`'s preset is faster still but six times larger.
    enc.set_deflate_compression(png::DeflateCompression::Level(1));
    enc.set_filter(png::Filter::Up);
    let encode =
        |enc: png::Encoder<'_, &mut Vec<u8>>| -> std::result::Result<(), png::EncodingError> {
            let mut writer = enc.write_header()?;
            writer.write_image_data(&rgb)?;
            writer.finish()
        };
    encode(enc).map_err(|e| f.fail("PNG", e.to_string().into()))?;
    Ok(bytes)
}

pub(super) fn render_svg(f: &impl Drawable) -> Result<String> {
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

pub(super) fn write_both(f: &impl Drawable, dir: &Path, stem: &str) -> Result<[PathBuf; 2]> {
    let png_path = dir.join(format!("{stem}.png"));
    let svg_path = dir.join(format!("{stem}.svg"));
    write_atomic(&png_path, &render_png(f)?)?;
    write_atomic(&svg_path, render_svg(f)?.as_bytes())?;
    Ok([png_path, svg_path])
}
