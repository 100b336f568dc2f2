//! The replay of a run: one self-contained `replay.html` (data and code inside, opened from disk
//! with no network and no server) showing the bodies in 3D, the ideal and clearance twins side by
//! side or overlaid, each clearance journal magnified in its bearing with its contact force, a
//! timeline with every impact, play/pause/speed (slow motion near impacts), a scrubber, and the
//! hinge's angle, rate and force plotted under it with a cursor that follows.
//!
//! The data comes from a [`ReplayRecorder`](record::ReplayRecorder) ([`record`]: any Rapier
//! loop can feed one, the library's scene runner included; [`ReplayPage`] writes its
//! [`Recording`](record::Recording)), the plotted series from the run's tables. The viewer is a hand-written canvas-2D renderer (a few hundred lines,
//! no library, no WebGL: it draws wherever a canvas does, headless browsers included).
//!
//! **Size.** Frames: one per `end_s / FRAMES` of free flight and sustained contact, one per
//! `end_s / CONTACT_FRAMES` over the first 100 of those after each contact's onset, and every
//! onset with the state before it (the recorder's thinning rule, [`record`]); journal values with 7 significant digits, positions to 0.1 um and
//! rotations to 1e-7 (times in full).
//! Series: the table's rows cut into [`SERIES_BUCKETS`] buckets of time, each keeping its
//! smallest and largest value (so every impact's force peak stays).

//!
//! Files: [`record`] (the recorder and what it records), `series.rs` (the plotted lines),
//! `page.rs` (the page itself), `run.rs` (a scene run recorded and its page), `memory.rs` (a
//! replay's memory bound), `result_set.rs` (the replay in result sets and study reports).

mod memory;
mod page;
pub mod record;
mod result_set;
mod run;
mod series;

pub use memory::{estimate, memory_bytes};
pub use page::ReplayPage;
pub use result_set::{remove_stale, report_section};
pub use run::{run_page, run_recorded, write_run_replay};
pub use series::{Line, Series, min_max_thin};

/// File name of the replay in a result set.
pub const FILE: &str = "replay.html";
/// Free-flight frames over a run: one per `end_s / FRAMES`.
pub const FRAMES: f64 = 2000.0;
/// In-contact frame density: one per `end_s / CONTACT_FRAMES` while a journal is in contact.
pub const CONTACT_FRAMES: f64 = 100_000.0;
/// Time buckets of the plotted series (each keeps its smallest and largest value).
pub const SERIES_BUCKETS: usize = 1500;
/// Frames a replay keeps at most: beyond, the recorder halves them, keeping the largest force
/// (its cap, [`record`]); so a replay's memory does not grow with the run's length or its
/// impacts.
pub const MAX_FRAMES: usize = 20_000;
/// Numbers per journal and frame in the page's spatial array `sf`: tilt about `u` and `v`
/// (rad), axial offset (m), the two edge forces (N), their points `[u, v, a]` (m), the two face
/// forces (N) and their points.
pub const SPATIAL_NUMBERS: usize = 19;
