//! The paper's figure kinds and a figure of a run's or a study's cases.

use super::*;

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
