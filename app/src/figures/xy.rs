//! A plain figure of curves `y` against `x`.

use super::*;

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
        write_both(self, dir, stem, &mut Vec::new())
    }

    /// As [`write`](Self::write), the PNG's pixels drawn in `raster` (a buffer reused from
    /// figure to figure).
    pub fn write_reusing(
        &self,
        dir: &Path,
        stem: &str,
        raster: &mut Vec<u8>,
    ) -> Result<[PathBuf; 2]> {
        write_both(self, dir, stem, raster)
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
