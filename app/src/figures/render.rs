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
    encode_png(&rgb, w, h).map_err(|e| f.fail("PNG", e.to_string().into()))
}

/// An 8-bit RGB image of `w` by `h` pixels as PNG: the `png` crate's header and end, the image
/// data compressed here ([`idat`]) as one IDAT chunk.
fn encode_png(rgb: &[u8], w: u32, h: u32) -> std::result::Result<Vec<u8>, png::EncodingError> {
    let idat = idat(rgb, w as usize * 3)?;
    let mut bytes = Vec::with_capacity(idat.len() + 128);
    let mut enc = png::Encoder::new(&mut bytes, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    // The image data goes in as a chunk of our own, not through `write_image_data`: the encoder
    // does not count it as an image.
    enc.validate_sequence(false);
    let mut writer = enc.write_header()?;
    writer.write_chunk(png::chunk::IDAT, &idat)?;
    writer.finish()?;
    Ok(bytes)
}

/// The zlib stream of an 8-bit RGB image's rows (`row` bytes each), each behind the `Up` filter:
/// the bytes `png`'s `write_image_data` writes with `Filter::Up` and deflate's level 1. Deflate's
/// fastest level behind the `Up` filter on every row: the figures are mostly flat colour and
/// straight runs, so the adaptive filter's per-row trial of all five filters buys nothing (0.29
/// MB for the paper's scene's three figures either way) and costs about 4 % of its sub-cycled
/// run's CPU; `fdeflate`'s preset is faster still but six times larger. The filtered rows go to
/// the compressor in writes of at least 256 KiB: `png` hands it each row in two writes, and
/// `flate2` zeroes its 32 KiB output buffer at every write (0.13 GB for the paper's scene's
/// three figures). Deflate's output does not depend on how its input is split.
fn idat(rgb: &[u8], row: usize) -> std::io::Result<Vec<u8>> {
    use std::io::Write as _;
    const CHUNK: usize = 1 << 18;
    let row = row.max(1);
    let mut zlib = flate2::write::ZlibEncoder::new(
        Vec::with_capacity(rgb.len() / 16),
        flate2::Compression::new(1),
    );
    let mut filtered = Vec::with_capacity(CHUNK + row + 1);
    let mut above: &[u8] = &[];
    for line in rgb.chunks(row) {
        // The `Up` filter (type 2): each byte less the byte above it (the first row's: zero).
        filtered.push(2);
        if above.is_empty() {
            filtered.extend_from_slice(line);
        } else {
            filtered.extend(line.iter().zip(above).map(|(b, a)| b.wrapping_sub(*a)));
        }
        above = line;
        if filtered.len() >= CHUNK {
            zlib.write_all(&filtered)?;
            filtered.clear();
        }
    }
    zlib.write_all(&filtered)?;
    zlib.finish()
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

#[cfg(test)]
mod tests {
    use super::encode_png;

    /// `png`'s own encoding of `rgb` with the settings [`encode_png`] stands for.
    fn by_png(rgb: &[u8], w: u32, h: u32) -> Vec<u8> {
        let mut bytes = Vec::new();
        let mut enc = png::Encoder::new(&mut bytes, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_deflate_compression(png::DeflateCompression::Level(1));
        enc.set_filter(png::Filter::Up);
        let mut writer = enc.write_header().unwrap();
        writer.write_image_data(rgb).unwrap();
        writer.finish().unwrap();
        bytes
    }

    /// The PNG is byte for byte the one `png` writes with the `Up` filter and deflate's level 1,
    /// on images smaller and larger than one write to the compressor (a white page with lines
    /// and noise, as a figure's), and it decodes to the image.
    #[test]
    fn the_png_is_pngs_own_with_the_up_filter_at_level_1() {
        let mut x: u32 = 12345;
        for (w, h) in [(1, 1), (7, 3), (300, 200), (1400, 930)] {
            let mut rgb = vec![255u8; (w * h * 3) as usize];
            for (i, p) in rgb.iter_mut().enumerate() {
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                let (col, row) = ((i / 3) as u32 % w, (i / 3) as u32 / w);
                if col.is_multiple_of(97) || row.is_multiple_of(41) || x.is_multiple_of(50) {
                    *p = (x >> 8) as u8;
                }
            }
            let ours = encode_png(&rgb, w, h).unwrap();
            assert!(ours == by_png(&rgb, w, h), "{w} x {h}");
            let mut reader = png::Decoder::new(std::io::Cursor::new(&ours))
                .read_info()
                .unwrap();
            let mut back = vec![0; reader.output_buffer_size().unwrap()];
            reader.next_frame(&mut back).unwrap();
            assert!(back == rgb, "{w} x {h}");
        }
    }
}
