//! Rendering a figure to PNG and SVG with the embedded font, and writing both.

use super::tee::Tee;
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
    encode_png(&rgb, (w, h)).map_err(|e| f.fail("PNG", e))
}

/// The PNG file of an RGB image (8 bit): each row behind the `Up` filter, deflated at the
/// fastest level of `miniz_oxide` in one stream, one `IDAT` chunk. The figures are mostly flat
/// colour and straight runs: the adaptive filter's per-row trial of all five filters buys
/// nothing over `Up` (0.29 MB for the paper's scene's three figures either way), and the
/// `png` crate's own path to the same deflate streams it through `flate2` at a quarter more
/// CPU; `fdeflate`'s preset is faster still but six times larger.
pub(super) fn encode_png(
    rgb: &[u8],
    (w, h): (u32, u32),
) -> std::result::Result<Vec<u8>, Box<dyn std::error::Error>> {
    use miniz_oxide::deflate::core::{
        CompressorOxide, TDEFLFlush, TDEFLStatus, compress_to_output,
        create_comp_flags_from_zip_params,
    };
    let stride = w as usize * 3;
    if rgb.len() != stride * h as usize {
        return Err(format!("{} bytes for a {w} x {h} RGB image", rgb.len()).into());
    }
    // Level 1 (one probe, greedy parsing) with the zlib wrapper PNG requires.
    let mut deflate = CompressorOxide::new(create_comp_flags_from_zip_params(1, 15, 0));
    let mut idat = Vec::with_capacity(rgb.len() / 16);
    let mut line = vec![0u8; stride + 1];
    // Each row's filter type: 2, `Up` (each byte less the one above it; the first row's "above"
    // is zeros).
    line[0] = 2;
    let mut prev: Option<&[u8]> = None;
    for (k, row) in rgb.chunks_exact(stride.max(1)).enumerate() {
        match prev {
            None => line[1..].copy_from_slice(row),
            Some(p) => {
                for ((o, a), b) in line[1..].iter_mut().zip(row).zip(p) {
                    *o = a.wrapping_sub(*b);
                }
            }
        }
        prev = Some(row);
        let flush = if k + 1 == h as usize {
            TDEFLFlush::Finish
        } else {
            TDEFLFlush::None
        };
        let mut input = &line[..];
        loop {
            let (status, used) = compress_to_output(&mut deflate, input, flush, |out| {
                idat.extend_from_slice(out);
                true
            });
            input = &input[used..];
            match status {
                TDEFLStatus::Done => break,
                TDEFLStatus::Okay if input.is_empty() => break,
                TDEFLStatus::Okay => {}
                other => return Err(format!("deflate failed ({other:?})").into()),
            }
        }
    }
    let mut bytes = Vec::with_capacity(idat.len() + 64);
    let mut enc = png::Encoder::new(&mut bytes, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut writer = enc.write_header()?;
    writer.write_chunk(png::chunk::IDAT, &idat)?;
    writer.finish()?;
    Ok(bytes)
}

/// The PNG and the SVG of `f` from one drawing ([`Tee`]): what [`render_png`] and
/// [`render_svg`] give, its series thinned and its axes laid out once.
/// `raster` holds the PNG's pixels while it is drawn (its memory reused from one figure to the
/// next: a fresh buffer's pages cost more to touch than to draw on).
pub(super) fn render_both(f: &impl Drawable, raster: &mut Vec<u8>) -> Result<(Vec<u8>, String)> {
    let font = font()?;
    let (w, h) = f.pixels();
    raster.clear();
    raster.resize(w as usize * h as usize * 3, 0);
    let rgb = &mut raster[..];
    let mut text = String::new();
    {
        let tee = Tee {
            first: Typeset::new(
                BitMapBackend::with_buffer(rgb, (w, h)),
                font.clone(),
                Target::Raster,
            ),
            second: Typeset::new(
                SVGBackend::with_string(&mut text, (w, h)),
                font,
                Target::Vector,
            ),
            names: ["PNG", "SVG"],
        };
        let root = tee.into_drawing_area();
        f.draw_on(&root).map_err(|e| f.fail("PNG and SVG", e))?;
        root.present()
            .map_err(|e| f.fail("PNG and SVG", e.to_string().into()))?;
    }
    let png = encode_png(raster, (w, h)).map_err(|e| f.fail("PNG", e))?;
    Ok((png, text))
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

/// Writes `<dir>/<stem>.png` and `<dir>/<stem>.svg` of `f`, drawn once for both
/// ([`render_both`], `raster` its pixels' buffer).
pub(super) fn write_both(
    f: &impl Drawable,
    dir: &Path,
    stem: &str,
    raster: &mut Vec<u8>,
) -> Result<[PathBuf; 2]> {
    let png_path = dir.join(format!("{stem}.png"));
    let svg_path = dir.join(format!("{stem}.svg"));
    let (png, svg) = render_both(f, raster)?;
    write_atomic(&png_path, &png)?;
    write_atomic(&svg_path, svg.as_bytes())?;
    Ok([png_path, svg_path])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figures::series::BodySeries;

    /// The RGB pixels of a PNG file, with its width and height.
    fn decode(png_file: &[u8]) -> (u32, u32, Vec<u8>) {
        let decoder = png::Decoder::new(std::io::Cursor::new(png_file));
        let mut reader = decoder.read_info().unwrap();
        let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut pixels).unwrap();
        assert_eq!(
            (info.color_type, info.bit_depth),
            (png::ColorType::Rgb, png::BitDepth::Eight)
        );
        pixels.truncate(info.buffer_size());
        (info.width, info.height, pixels)
    }

    #[test]
    fn the_png_file_holds_every_pixel() {
        let mut s: u32 = 0x9E37_79B9;
        // Noise (rows unlike each other), flat colour (rows alike) and a single row or column.
        for (w, h, noise) in [(37, 23, true), (64, 40, false), (1, 9, true), (50, 1, true)] {
            let rgb: Vec<u8> = (0..w * h * 3)
                .map(|k| {
                    s ^= s << 13;
                    s ^= s >> 17;
                    s ^= s << 5;
                    if noise {
                        (s >> 24) as u8
                    } else {
                        (k % 3 * 90) as u8
                    }
                })
                .collect();
            let file = encode_png(&rgb, (w, h)).unwrap();
            assert_eq!(decode(&file), (w, h, rgb));
        }
        assert!(encode_png(&[0; 5], (2, 1)).is_err());
    }

    /// A case of `n` rows: more than the figures' pixel columns (so its series are thinned),
    /// with contact peaks between the rows.
    fn case(label: &str, n: usize, phase: f64) -> CaseSeries {
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3).collect();
        let wave = |a: f64, w: f64| -> Vec<f64> {
            t.iter()
                .map(|x| a * (w * x + phase).sin() * (1.0 + (37.0 * x).sin()))
                .collect()
        };
        CaseSeries {
            label: label.into(),
            hinge: "hinge".into(),
            clearance_mm: 0.1,
            t_s: t.clone(),
            bodies: vec![
                BodySeries {
                    name: "panel".into(),
                    angle_deg: wave(10.0, 20.0),
                    rate_deg_s: wave(200.0, 20.0),
                    angle_ideal_deg: wave(9.0, 20.0),
                    rate_ideal_deg_s: wave(180.0, 20.0),
                },
                BodySeries {
                    name: "base".into(),
                    angle_deg: wave(1.0, 3.0),
                    rate_deg_s: wave(20.0, 3.0),
                    angle_ideal_deg: wave(0.9, 3.0),
                    rate_ideal_deg_s: wave(18.0, 3.0),
                },
            ],
            force_n: wave(50.0, 60.0).iter().map(|f| f.abs()).collect(),
            force_ideal_n: wave(1.0, 30.0).iter().map(|f| 1.5 + f).collect(),
            contact: vec![1.0; n],
            ecc_u_mm: t.iter().map(|x| 0.1 * (7.0 * x).cos()).collect(),
            ecc_v_mm: t.iter().map(|x| 0.1 * (11.0 * x).sin()).collect(),
            peaks: vec![(0.5005, 180.0), (1.2345, 140.0)],
        }
    }

    /// Checks that drawing `f` once for both files gives the SVG text and the PNG pixels its
    /// own drawings give.
    fn assert_one_drawing_is_both(f: &impl Drawable, raster: &mut Vec<u8>, what: &str) {
        let (png_file, svg) = render_both(f, raster).unwrap();
        assert!(svg == render_svg(f).unwrap(), "{what}: the SVGs differ");
        let (own, both) = (decode(&render_png(f).unwrap()), decode(&png_file));
        assert!(own == both, "{what}: the PNGs' pixels differ");
        assert!(
            svg.contains("<polyline") && both.2.iter().any(|&b| b < 128),
            "{what}"
        );
    }

    #[test]
    fn one_drawing_gives_each_file_what_its_own_drawing_gives() {
        let cases = [
            case("c = 0.10 mm", 5000, 0.0),
            case("c = 0.25 mm", 4000, 1.0),
        ];
        // One buffer for all, each figure a different size from the one before.
        let mut raster = Vec::new();
        for kind in FigureKind::ALL {
            for cases in [&cases[..1], &cases[..]] {
                let figure = Figure {
                    kind,
                    title: "one drawing, two files",
                    cases,
                };
                let what = format!("{kind:?} of {} cases", cases.len());
                assert_one_drawing_is_both(&figure, &mut raster, &what);
            }
        }
        let curves = [
            (
                "ideal".to_string(),
                vec![(0.0, 1.0), (90.0, -2.0), (360.0, 0.5)],
            ),
            (
                "clearance".to_string(),
                vec![(0.0, 1.2), (180.0, 3.0), (360.0, 0.4)],
            ),
        ];
        let xy = XyFigure {
            title: "xy",
            x_label: "angle (deg)",
            y_label: "acceleration (m/s^2)",
            curves: &curves,
        };
        assert_one_drawing_is_both(&xy, &mut raster, "XyFigure");
    }
}
