//! The figures' legends. They are drawn here rather than by plotters' series labels so that
//! their box is known in pixels before anything is drawn: a figure can then place a legend
//! where it crosses no curve ([`free_corner`]), make room for it above the data
//! ([`headroom`]), or put it outside the plotting area.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{DrawResult, FAMILY};

/// The border colour of every legend box (tests find the boxes in the SVG by it).
pub const BORDER: RGBColor = RGBColor(160, 160, 160);

/// Gap between a legend and the plotting area's edge, px.
pub const INSET: i32 = 8;

/// Inner padding of the box, px.
const PAD: i32 = 6;
/// Width of a mark (line sample), px.
const MARK_W: i32 = 24;
/// Gap between a mark and its label, and between entries of a row, px.
const GAP: i32 = 8;

/// How an entry's curve is drawn, for its mark in the legend.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mark {
    /// A solid line.
    Line(RGBColor),
    /// A dashed line.
    Dashed(RGBColor),
    /// A filled dot.
    Dot(RGBColor),
}

/// One legend line: a mark and its label.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    /// The label text.
    pub label: String,
    /// The mark drawn before it.
    pub mark: Mark,
}

/// A legend: entries in a column (inside a plot) or in a row (below one).
#[derive(Clone, Debug, PartialEq)]
pub struct Legend {
    /// The entries, in drawing order.
    pub entries: Vec<Entry>,
    /// Font size of the labels, px.
    pub font_size: u32,
    /// Entries side by side instead of one under the other.
    pub row: bool,
}

impl Legend {
    /// Height of one entry's line, px.
    fn line_h(&self) -> i32 {
        self.font_size as i32 + 6
    }

    /// Width of each entry (mark, gap, label), px, as `area` measures the text.
    fn entry_widths<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Vec<i32> {
        let font = TextStyle::from((FAMILY, self.font_size).into_font());
        self.entries
            .iter()
            .map(|e| {
                let w = area.estimate_text_size(&e.label, &font).map_or(0, |s| s.0);
                MARK_W + GAP + w as i32
            })
            .collect()
    }

    /// The box's size in pixels, as drawn on `area`.
    pub fn size<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> (i32, i32) {
        let widths = self.entry_widths(area);
        let n = widths.len() as i32;
        let (w, h) = if self.row {
            let sum: i32 = widths.iter().sum();
            (sum + 2 * GAP * (n - 1).max(0), self.line_h())
        } else {
            (widths.iter().copied().max().unwrap_or(0), self.line_h() * n)
        };
        (w + 2 * PAD, h + 2 * PAD)
    }

    /// Draws the box with its top left corner at `at` (pixels of `area`).
    pub fn draw<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        at: (i32, i32),
    ) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let (w, h) = self.size(area);
        let corner = (at.0 + w, at.1 + h);
        area.draw(&Rectangle::new([at, corner], WHITE.mix(0.9).filled()))?;
        area.draw(&Rectangle::new([at, corner], BORDER.stroke_width(1)))?;
        let font = (FAMILY, self.font_size)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Left, VPos::Center));
        let (mut x, mut y) = (at.0 + PAD, at.1 + PAD + self.line_h() / 2);
        for (entry, width) in self.entries.iter().zip(self.entry_widths(area)) {
            draw_mark(area, entry.mark, (x, y))?;
            area.draw_text(&entry.label, &font, (x + MARK_W + GAP, y))?;
            if self.row {
                x += width + 2 * GAP;
            } else {
                y += self.line_h();
            }
        }
        Ok(())
    }
}

/// A mark `MARK_W` wide, its left end at `(x, y)`.
fn draw_mark<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    mark: Mark,
    (x, y): (i32, i32),
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    match mark {
        Mark::Line(c) => area.draw(&PathElement::new(
            vec![(x, y), (x + MARK_W, y)],
            c.stroke_width(2),
        ))?,
        Mark::Dashed(c) => {
            for (a, b) in [(0, 7), (10, 17), (20, MARK_W)] {
                area.draw(&PathElement::new(
                    vec![(x + a, y), (x + b, y)],
                    c.stroke_width(2),
                ))?;
            }
        }
        Mark::Dot(c) => area.draw(&Circle::new((x + MARK_W / 2, y), 4, c.filled()))?,
    }
    Ok(())
}

/// Whether the segment `a`–`b` meets the rectangle `[x0, x1] x [y0, y1]` (Liang-Barsky
/// clipping: the part of the segment inside each slab, intersected).
pub fn segment_meets_rect(
    a: (f64, f64),
    b: (f64, f64),
    (x0, y0, x1, y1): (f64, f64, f64, f64),
) -> bool {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-dx, a.0 - x0),
        (dx, x1 - a.0),
        (-dy, a.1 - y0),
        (dy, y1 - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return false;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    t0 <= t1
}

/// Pixels around a legend box that a curve must also keep clear of (rounding of plotters'
/// coordinate mapping and line width).
const CLEAR: f64 = 4.0;

/// The top left corner of the first of the plotting area's corners (upper left, upper right,
/// lower left, lower right; `INSET` from the edges) where a legend of `size` crosses none of
/// the polylines `paths` (pixels of a plotting area of `plot`), or `None` if each one does.
pub fn free_corner(
    paths: &[Vec<(f64, f64)>],
    plot: (i32, i32),
    size: (i32, i32),
) -> Option<(i32, i32)> {
    let (left, top) = (INSET, INSET);
    let (right, bottom) = (plot.0 - INSET - size.0, plot.1 - INSET - size.1);
    if right < left || bottom < top {
        return None;
    }
    [(left, top), (right, top), (left, bottom), (right, bottom)]
        .into_iter()
        .find(|&(x, y)| {
            let r = (
                f64::from(x) - CLEAR,
                f64::from(y) - CLEAR,
                f64::from(x + size.0) + CLEAR,
                f64::from(y + size.1) + CLEAR,
            );
            !paths
                .iter()
                .any(|p| p.windows(2).any(|s| segment_meets_rect(s[0], s[1], r)))
        })
}

/// The top of a y axis over `[y0, ..]` that leaves the upper `need` pixels of a plotting area
/// `height` pixels high free of data reaching `y_max`; `None` if that would leave the data
/// less than half the height.
pub fn headroom(y0: f64, y_max: f64, need: i32, height: i32) -> Option<f64> {
    let f = f64::from(need) / f64::from(height.max(1));
    (f <= 0.5).then(|| (y_max - f * y0) / (1.0 - f))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_meet_rectangles_only_when_they_cross_them() {
        let r = (10.0, 10.0, 20.0, 20.0);
        assert!(segment_meets_rect((0.0, 15.0), (30.0, 15.0), r));
        assert!(segment_meets_rect((12.0, 12.0), (13.0, 13.0), r));
        assert!(segment_meets_rect((0.0, 0.0), (30.0, 30.0), r));
        assert!(!segment_meets_rect((0.0, 0.0), (30.0, 0.0), r));
        assert!(!segment_meets_rect((0.0, 25.0), (25.0, 50.0), r));
        // Both ends outside the box's corners, the segment passing beside it.
        assert!(!segment_meets_rect((0.0, 9.0), (9.0, 0.0), r));
    }

    #[test]
    fn a_corner_is_free_only_if_no_segment_crosses_it() {
        // A diagonal from the lower left to the upper right of a 400 x 300 plot.
        let diagonal = vec![vec![(0.0, 300.0), (400.0, 0.0)]];
        assert_eq!(
            free_corner(&diagonal, (400, 300), (100, 50)),
            Some((INSET, INSET))
        );
        // A horizontal line across the top and one across the bottom: no corner is free.
        let both = vec![
            vec![(0.0, 20.0), (400.0, 20.0)],
            vec![(0.0, 280.0), (400.0, 280.0)],
        ];
        assert_eq!(free_corner(&both, (400, 300), (100, 50)), None);
        // A box wider than the plot fits nowhere.
        assert_eq!(free_corner(&[], (100, 300), (120, 50)), None);
    }

    #[test]
    fn headroom_keeps_the_data_below_the_legend() {
        let y1 = headroom(0.0, 10.0, 100, 400).unwrap();
        // Data at 10 sits at pixel 400 * (1 - 10 / y1) from the top: 100.
        assert!((400.0 * (1.0 - 10.0 / y1) - 100.0).abs() < 1e-9);
        assert_eq!(headroom(0.0, 10.0, 300, 400), None);
    }
}
