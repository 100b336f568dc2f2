//! One drawing into two backends: a figure's PNG and SVG from a single pass of its drawing code,
//! so its series are thinned and its axes laid out once for both files.

use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
};

/// A backend passing every call to both `first` and `second`, each drawing it with its own
/// implementation of that call: each receives the calls a drawing of its own would give it, so
/// draws what it would alone. Size and text measures are `first`'s (the figures' backends,
/// [`Typeset`](super::text::Typeset) on a bitmap and on an SVG, measure text alike).
pub(super) struct Tee<A, B> {
    pub first: A,
    pub second: B,
    /// What each backend makes, for its errors (`PNG`, `SVG`).
    pub names: [&'static str; 2],
}

/// A backend's error, named by the file it was drawing.
#[derive(Debug)]
pub(super) struct TeeError(String);

impl std::fmt::Display for TeeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for TeeError {}

type Drawn = Result<(), DrawingErrorKind<TeeError>>;

/// `e` of the backend drawing `name`.
fn named<E: std::error::Error + Send + Sync>(
    name: &str,
    e: DrawingErrorKind<E>,
) -> DrawingErrorKind<TeeError> {
    match e {
        DrawingErrorKind::DrawingError(e) => {
            DrawingErrorKind::DrawingError(TeeError(format!("{name}: {e}")))
        }
        DrawingErrorKind::FontError(e) => DrawingErrorKind::FontError(e),
    }
}

impl<A: DrawingBackend, B: DrawingBackend> Tee<A, B> {
    /// Runs `a` on the first backend, then `b` on the second.
    fn both(
        &mut self,
        a: impl FnOnce(&mut A) -> Result<(), DrawingErrorKind<A::ErrorType>>,
        b: impl FnOnce(&mut B) -> Result<(), DrawingErrorKind<B::ErrorType>>,
    ) -> Drawn {
        a(&mut self.first).map_err(|e| named(self.names[0], e))?;
        b(&mut self.second).map_err(|e| named(self.names[1], e))
    }
}

impl<A: DrawingBackend, B: DrawingBackend> DrawingBackend for Tee<A, B> {
    type ErrorType = TeeError;

    fn get_size(&self) -> (u32, u32) {
        self.first.get_size()
    }
    fn ensure_prepared(&mut self) -> Drawn {
        self.both(|a| a.ensure_prepared(), |b| b.ensure_prepared())
    }
    fn present(&mut self) -> Drawn {
        self.both(|a| a.present(), |b| b.present())
    }
    fn draw_pixel(&mut self, point: BackendCoord, color: BackendColor) -> Drawn {
        self.both(
            |a| a.draw_pixel(point, color),
            |b| b.draw_pixel(point, color),
        )
    }
    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Drawn {
        self.both(
            |a| a.draw_line(from, to, style),
            |b| b.draw_line(from, to, style),
        )
    }
    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Drawn {
        self.both(
            |a| a.draw_rect(upper_left, bottom_right, style, fill),
            |b| b.draw_rect(upper_left, bottom_right, style, fill),
        )
    }
    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Drawn {
        let path: Vec<BackendCoord> = path.into_iter().collect();
        self.both(
            |a| a.draw_path(path.iter().copied(), style),
            |b| b.draw_path(path.iter().copied(), style),
        )
    }
    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Drawn {
        self.both(
            |a| a.draw_circle(center, radius, style, fill),
            |b| b.draw_circle(center, radius, style, fill),
        )
    }
    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Drawn {
        let vert: Vec<BackendCoord> = vert.into_iter().collect();
        self.both(
            |a| a.fill_polygon(vert.iter().copied(), style),
            |b| b.fill_polygon(vert.iter().copied(), style),
        )
    }
    fn blit_bitmap(&mut self, pos: BackendCoord, size: (u32, u32), src: &[u8]) -> Drawn {
        self.both(
            |a| a.blit_bitmap(pos, size, src),
            |b| b.blit_bitmap(pos, size, src),
        )
    }
    fn draw_text<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> Drawn {
        self.both(
            |a| a.draw_text(text, style, pos),
            |b| b.draw_text(text, style, pos),
        )
    }
    fn estimate_text_size<S: BackendTextStyle>(
        &self,
        text: &str,
        style: &S,
    ) -> Result<(u32, u32), DrawingErrorKind<TeeError>> {
        self.first
            .estimate_text_size(text, style)
            .map_err(|e| named(self.names[0], e))
    }
}
