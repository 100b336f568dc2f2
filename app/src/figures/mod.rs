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
//!
//! Files: `figure.rs` (the figure kinds, [`Figure`]), `xy.rs` ([`XyFigure`]), `render.rs` (PNG,
//! SVG, the font), `tee.rs` (one drawing into both), `panel.rs` (a panel of curves), `angles_rates.rs`, `force.rs`, `trajectory.rs`
//! (each kind's drawing), `cases.rs` (what they read of the cases), `decimate.rs`.

mod angles_rates;
mod cases;
mod decimate;
mod figure;
mod force;
pub mod legend;
mod panel;
mod render;
pub mod run;
pub mod series;
mod tee;
pub mod text;
pub mod ticks;
mod trajectory;
mod xy;

pub use decimate::{decimate_path, minmax_decimate};
pub use figure::{Figure, FigureKind};
pub use xy::XyFigure;

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

// What the figure files share of one another.
use angles_rates::draw_angles_rates;
use cases::{distinct_ideals, time_range};
use decimate::DECIMATE_BINS;
use force::draw_force;
use panel::{Curve, Panel, PanelStyle, case_color, draw_mesh, range_of};
use render::{Drawable, render_png, render_svg, write_both};
use trajectory::draw_trajectory;

type DrawResult = std::result::Result<(), Box<dyn std::error::Error>>;

/// The family the text styles name; plotters still measures legends with the font registered
/// under it, [`text::Typeset`] draws every text in [`FONT`](render::FONT) whatever the family.
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
