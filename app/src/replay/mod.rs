//! The replay of a run: one self-contained `replay.html` (data and code inside, opened from disk
//! with no network and no server) showing the bodies in 3D, the ideal and clearance twins side by
//! side or overlaid, each clearance journal magnified in its bearing with its contact force, a
//! timeline with every impact, play/pause/speed (slow motion near impacts), a scrubber, and the
//! hinge's angle, rate and force plotted under it with a cursor that follows.
//!
//! The data comes from the library's [`ReplayRecorder`](clearance_joint::rapier::observers::replay::ReplayRecorder)
//! (any Rapier loop can feed one; [`ReplayPage`] writes its [`Recording`]), the plotted series
//! from the run's tables. The viewer is a hand-written canvas-2D renderer (a few hundred lines,
//! no library, no WebGL: it draws wherever a canvas does, headless browsers included).
//!
//! **Size.** Frames: one per `end_s / FRAMES` of free flight and sustained contact, one per
//! `end_s / CONTACT_FRAMES` over the first 100 of those after each contact's onset, and every
//! onset with the state before it (the recorder's thinning rule,
//! [`clearance_joint::rapier::observers::replay`]); journal values with 7 significant digits, positions to 0.1 um and
//! rotations to 1e-7 (times in full).
//! Series: the table's rows cut into [`SERIES_BUCKETS`] buckets of time, each keeping its
//! smallest and largest value (so every impact's force peak stays).

use crate::process::files::write_atomic;
use crate::process::memory::MemoryEstimate;
use clearance_joint::error::{Error, Result};
use clearance_joint::rapier::observers::replay::Recording;
use clearance_joint::scene::runner::{Progress, RunOptions, RunResult, Simulation, TwinKind};
use clearance_joint::scene::{Scene, ValidatedScene};
use clearance_joint::table::Table;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// File name of the replay in a result set.
pub const FILE: &str = "replay.html";
/// Free-flight frames over a run: one per `end_s / FRAMES`.
pub const FRAMES: f64 = 2000.0;
/// In-contact frame density: one per `end_s / CONTACT_FRAMES` while a journal is in contact.
pub const CONTACT_FRAMES: f64 = 100_000.0;
/// Time buckets of the plotted series (each keeps its smallest and largest value).
pub const SERIES_BUCKETS: usize = 1500;
/// Frames a replay keeps at most: beyond, the recorder halves them, keeping the largest force
/// (its cap, [`clearance_joint::rapier::observers::replay`]); so a replay's memory does not grow with the
/// run's length or its impacts.
pub const MAX_FRAMES: usize = 20_000;
/// Numbers per journal and frame in the page's spatial array `sf`: tilt about `u` and `v`
/// (rad), axial offset (m), the two edge forces (N), their points `[u, v, a]` (m), the two face
/// forces (N) and their points.
pub const SPATIAL_NUMBERS: usize = 19;
/// Characters per number in the page's JSON (7 significant digits, sign, exponent, comma).
const JSON_CHARS: u64 = 14;

/// The memory a replay of `scene` holds at its peak, bytes, an upper bound: [`MAX_FRAMES`]
/// frames of the tracked bodies (both twins') and journals, as the recorder stores them (a pose
/// of 7 numbers per body, 6 numbers, 2 flags and room for a spatial part per journal), the page's
/// flattened copy of them,
/// and its JSON text held three times while the page is built (the JSON, its escaped copy, the
/// page). Measured: the paper's scene at 5 times its torque keeps 10,914 frames and peaks 17.5 MB
/// above its run without a replay, 1.6 kB a frame, against 2.7 kB a frame here.
pub fn memory_bytes(scene: &Scene) -> u64 {
    let bodies = 2 * scene.bodies.len() as u64;
    let journals = scene
        .hinges
        .iter()
        .filter(|h| h.clearance.is_some())
        .count() as u64;
    // A spatial scene's page carries SPATIAL_NUMBERS more per journal (`sf`).
    let spatial = if scene.hinges.iter().any(|h| h.is_spatial()) {
        SPATIAL_NUMBERS as u64 * journals
    } else {
        0
    };
    // A frame: time and two vectors' headers (8 + 48), their heap blocks (+ 32 of allocator);
    // a journal's frame holds room for the spatial part whether used or not.
    let journal =
        std::mem::size_of::<clearance_joint::rapier::observers::replay::JournalFrame>() as u64;
    let recorded = 88 + 56 * bodies + journal * journals;
    let flattened = 8 + 56 * bodies + 49 * journals + 8 * spatial;
    let numbers = 1 + 7 * bodies + 7 * journals + spatial;
    let text = 3 * JSON_CHARS * numbers;
    // The frames' vector itself may be twice its length (growth by doubling).
    let per_frame = recorded + 56 + 2 * flattened + text;
    MAX_FRAMES as u64 * per_frame + TEMPLATE.len() as u64 * 3
}

/// The memory estimate of a run of `scene` ([`MemoryEstimate::of`]) with its replay when
/// `replay` ([`memory_bytes`]).
pub fn estimate(scene: &Scene, replay: bool) -> MemoryEstimate {
    let rows = MemoryEstimate::of(scene);
    if replay {
        rows.with_replay(memory_bytes(scene))
    } else {
        rows
    }
}

const TEMPLATE: &str = include_str!("../../assets/replay/replay.html");

/// Runs `scene` (both twins) like [`Simulation::run_with_progress`], recording a replay when
/// `replay` (see the module docs for the frame rule).
pub fn run_recorded(
    scene: &ValidatedScene,
    progress: impl FnMut(&Progress),
    replay: bool,
) -> Result<(RunResult, Option<Recording>)> {
    let sim = Simulation::from_validated(scene, RunOptions::default())?;
    if !replay {
        return Ok((sim.run_keeping_partial(progress)?, None));
    }
    let end = scene.run.end_s;
    let mut recorder = sim
        .replay_recorder(end / FRAMES, end / CONTACT_FRAMES)?
        .with_max_frames(MAX_FRAMES);
    let result = sim.run_observed(progress, |s| s.record_replay(&mut recorder))?;
    Ok((result, Some(recorder.finish())))
}

/// One plotted quantity: a panel with a line per twin.
#[derive(Clone, Debug, Serialize)]
pub struct Series {
    /// Panel title (with unit).
    pub title: String,
    /// Its lines.
    pub lines: Vec<Line>,
}

/// One line of a [`Series`].
#[derive(Clone, Debug, Serialize)]
pub struct Line {
    /// Legend.
    pub label: String,
    /// Colour group (`ideal`, `clearance`, ...).
    pub group: String,
    /// Times, s.
    pub t: Vec<f64>,
    /// Values.
    pub v: Vec<f64>,
}

impl Line {
    /// Column `column` of `table` against its `t_s`, thinned to [`SERIES_BUCKETS`] buckets of
    /// time keeping each bucket's smallest and largest value (in time order).
    pub fn from_table(label: &str, group: &str, table: &Table, column: &str) -> Option<Line> {
        Self::with_points(label, group, table, column, &[])
    }

    /// As [`from_table`](Self::from_table), with `points` (`(t, v)` in time order: each
    /// contact's peak from every step) merged into the rows before thinning, so the line
    /// passes through them.
    pub fn with_points(
        label: &str,
        group: &str,
        table: &Table,
        column: &str,
        points: &[(f64, f64)],
    ) -> Option<Line> {
        let (t, v) = (table.column("t_s")?, table.column(column)?);
        let (t, v) = crate::figures::series::merge_points(&t, &v, points);
        let (t, v) = min_max_thin(&t, &v, SERIES_BUCKETS);
        Some(Line {
            label: label.into(),
            group: group.into(),
            t,
            v: v.into_iter().map(|x| round_sig(x, 7)).collect(),
        })
    }
}

impl Line {
    /// `f` of columns `columns` of `table` per row against its `t_s`, thinned as
    /// [`from_table`](Self::from_table) (`None` when a column is missing).
    pub fn derived(
        label: &str,
        group: &str,
        table: &Table,
        columns: &[&str],
        f: impl Fn(&[f64]) -> f64,
    ) -> Option<Line> {
        let t = table.column("t_s")?;
        let cols = columns
            .iter()
            .map(|c| table.column(c))
            .collect::<Option<Vec<_>>>()?;
        let v: Vec<f64> = (0..t.len())
            .map(|i| f(&cols.iter().map(|c| c[i]).collect::<Vec<_>>()))
            .collect();
        let (t, v) = min_max_thin(&t, &v, SERIES_BUCKETS);
        Some(Line {
            label: label.into(),
            group: group.into(),
            t,
            v: v.into_iter().map(|x| round_sig(x, 7)).collect(),
        })
    }
}

/// Keeps, per bucket of `buckets` equal time spans, the samples with the smallest and the
/// largest value (in time order): peaks survive any thinning.
pub fn min_max_thin(t: &[f64], v: &[f64], buckets: usize) -> (Vec<f64>, Vec<f64>) {
    let n = t.len().min(v.len());
    if n <= 2 * buckets || n < 2 {
        return (t[..n].to_vec(), v[..n].to_vec());
    }
    let (t0, t1) = (t[0], t[n - 1]);
    let span = (t1 - t0).max(f64::MIN_POSITIVE);
    let mut keep = Vec::with_capacity(2 * buckets + 2);
    let mut i = 0;
    while i < n {
        let b = (((t[i] - t0) / span) * buckets as f64).floor() as usize;
        let (mut lo, mut hi) = (i, i);
        let mut j = i;
        while j < n && ((((t[j] - t0) / span) * buckets as f64).floor() as usize) == b {
            if v[j] < v[lo] {
                lo = j;
            }
            if v[j] > v[hi] {
                hi = j;
            }
            j += 1;
        }
        keep.push(lo.min(hi));
        if hi != lo {
            keep.push(lo.max(hi));
        }
        i = j;
    }
    (
        keep.iter().map(|&k| t[k]).collect(),
        keep.iter().map(|&k| v[k]).collect(),
    )
}

/// `x` rounded to `digits` significant digits (shorter JSON).
fn round_sig(x: f64, digits: usize) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    format!("{:.*e}", digits - 1, x).parse().unwrap_or(x)
}

/// `x` rounded to `decimals` decimal places.
fn round_decimals(x: f64, decimals: usize) -> f64 {
    format!("{x:.decimals$}").parse().unwrap_or(x)
}

/// A replay page: a recording, impacts, plotted series and captions.
#[derive(Clone, Debug)]
pub struct ReplayPage<'a> {
    /// Page title.
    pub title: String,
    /// Line under the title (settings).
    pub subtitle: String,
    /// Notes under the plots (thinning rule, sources).
    pub notes: String,
    /// What was recorded.
    pub recording: &'a Recording,
    /// Plotted series.
    pub series: Vec<Series>,
}

#[derive(Serialize)]
struct Impact {
    t: f64,
    journal: usize,
}

#[derive(Serialize)]
struct PageData<'a> {
    title: &'a str,
    subtitle: &'a str,
    notes: &'a str,
    bodies: &'a [clearance_joint::rapier::observers::replay::ReplayBody],
    journals: &'a [clearance_joint::rapier::observers::replay::ReplayJournal],
    pins: &'a [clearance_joint::rapier::observers::replay::ReplayPin],
    t: Vec<f64>,
    poses: Vec<f64>,
    jf: Vec<f64>,
    contact: Vec<u8>,
    /// Per journal: whether it is spatial (its frames carry `sf`).
    spatial: Vec<bool>,
    /// Per frame and journal, [`SPATIAL_NUMBERS`] numbers (zeros for a planar journal); empty
    /// when no journal is spatial.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    sf: Vec<f64>,
    impacts: Vec<Impact>,
    series: &'a [Series],
    default_speed: f64,
}

impl ReplayPage<'_> {
    /// The page's HTML: the viewer with the data inside (no external resource).
    pub fn html(&self) -> Result<String> {
        let r = self.recording;
        if r.frames.is_empty() {
            return Err(Error::invalid("replay", "the recording holds no frame"));
        }
        let mut data = PageData {
            title: &self.title,
            subtitle: &self.subtitle,
            notes: &self.notes,
            bodies: &r.bodies,
            journals: &r.journals,
            pins: &r.pins,
            t: Vec::with_capacity(r.frames.len()),
            poses: Vec::new(),
            jf: Vec::new(),
            contact: Vec::new(),
            spatial: spatial_journals(r),
            sf: Vec::new(),
            impacts: Vec::new(),
            series: &self.series,
            default_speed: 0.0,
        };
        for f in &r.frames {
            data.t.push(f.t);
            // Positions to 0.1 um and quaternions to 1e-7 (a rotation of 0.2 urad).
            for p in &f.poses {
                data.poses.extend(p.iter().map(|&x| round_decimals(x, 7)));
            }
            for (k, j) in f.journals.iter().enumerate() {
                data.jf.extend(
                    [
                        j.ecc_u_m,
                        j.ecc_v_m,
                        j.force_u_n,
                        j.force_v_n,
                        j.force_n,
                        j.penetration_m,
                    ]
                    .map(|x| round_sig(x, 7)),
                );
                data.contact.push(j.contact as u8);
                if data.spatial.iter().any(|&b| b) {
                    data.sf.extend(spatial_numbers(j).map(|x| round_sig(x, 7)));
                }
                if j.impact {
                    data.impacts.push(Impact { t: f.t, journal: k });
                }
            }
        }
        // Speed: the whole run in about 20 s of wall time (a preset of the menu).
        let span = r.frames[r.frames.len() - 1].t - r.frames[0].t;
        data.default_speed = [
            0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0,
        ]
        .into_iter()
        .find(|&s| span / s <= 25.0)
        .unwrap_or(2.0);
        let json =
            serde_json::to_string(&data).map_err(|e| Error::invalid("replay", e.to_string()))?;
        // Inside <script>, `</` must not appear (JSON allows `<\/`).
        let json = json.replace("</", "<\\/");
        Ok(TEMPLATE
            .replacen("__TITLE__", &escape_html(&self.title), 1)
            .replacen("__DATA__", &json, 1))
    }

    /// Writes the page to `dir/replay.html` (atomically) and returns its path.
    pub fn write(&self, dir: &Path) -> Result<PathBuf> {
        let path = dir.join(FILE);
        write_atomic(&path, self.html()?.as_bytes())?;
        Ok(path)
    }
}

/// Per journal of `r`: whether any frame carries its spatial part.
fn spatial_journals(r: &Recording) -> Vec<bool> {
    (0..r.journals.len())
        .map(|k| {
            r.frames
                .iter()
                .any(|f| f.journals.get(k).is_some_and(|j| j.spatial.is_some()))
        })
        .collect()
}

/// A journal frame's spatial numbers in the page's order ([`SPATIAL_NUMBERS`]; zeros for a
/// planar journal).
fn spatial_numbers(
    j: &clearance_joint::rapier::observers::replay::JournalFrame,
) -> [f64; SPATIAL_NUMBERS] {
    let s = j.spatial.unwrap_or_default();
    let [e0, e1] = s.edge_at_m;
    let [f0, f1] = s.face_at_m;
    [
        s.tilt_rad[0],
        s.tilt_rad[1],
        s.axial_m,
        s.edge_force_n[0],
        s.edge_force_n[1],
        e0[0],
        e0[1],
        e0[2],
        e1[0],
        e1[1],
        e1[2],
        s.face_force_n[0],
        s.face_force_n[1],
        f0[0],
        f0[1],
        f0[2],
        f1[0],
        f1[1],
        f1[2],
    ]
}

fn escape_html(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The replay page of a scene run: the recording, and for each clearance hinge its angle, rate
/// and force, ideal against clearance, from the run's tables.
pub fn run_page<'a>(scene: &Scene, result: &RunResult, recording: &'a Recording) -> ReplayPage<'a> {
    let twins: Vec<(&str, &Table)> = result
        .twins
        .iter()
        .map(|t| (t.kind.name(), &t.table))
        .collect();
    let hinges: Vec<String> = result
        .twin(TwinKind::Clearance)
        .map(|t| t.clearance_hinges().iter().map(|h| h.to_string()).collect())
        .unwrap_or_default();
    // Each contact's peak from every step, for the clearance twin's force line.
    let recorders = result
        .twin(TwinKind::Clearance)
        .map(|t| t.hinge_recorders())
        .unwrap_or_default();
    let mut series = Vec::new();
    for h in &hinges {
        let peaks = recorders.get(h).map_or(Vec::new(), |r| {
            crate::figures::series::peaks_of(r.contacts())
        });
        for (what, column) in [
            ("angle (deg)", "angle_deg"),
            ("relative rate (deg/s)", "rate_deg_s"),
            ("joint force (N)", "force_n"),
        ] {
            let lines: Vec<Line> = twins
                .iter()
                .filter_map(|(name, table)| {
                    let clear_force = column == "force_n" && *name == TwinKind::Clearance.name();
                    let points = if clear_force { &peaks[..] } else { &[] };
                    Line::with_points(name, name, table, &format!("{h}_{column}"), points)
                })
                .collect();
            if !lines.is_empty() {
                series.push(Series {
                    title: format!("hinge `{h}`: {what}"),
                    lines,
                });
            }
        }
    }
    for h in &hinges {
        series.extend(spatial_series(h, &twins));
    }
    let run = &scene.run;
    ReplayPage {
        title: format!("{}: replay", scene.name),
        subtitle: format!(
            "{} s simulated \u{b7} {} \u{b7} ideal and clearance twins",
            clearance_joint::error::sig4(run.end_s),
            stepping_short(run)
        ),
        notes: format!(
            "Frames: {} kept of the run's states: one per {} s, one per {} s over the first {} s of \
             each contact, every contact onset with the state before it, and between kept frames \
             the state of largest force; in between, positions and journal values are interpolated \
             linearly. Plots: the CSV rows (the clearance force also each contact's peak from every \
             step), thinned to {SERIES_BUCKETS} time buckets keeping each bucket's smallest and \
             largest value. Bodies: \
             their colliders, else the uniform box with their mass and inertia; grey: a fixed body, \
             drawn around its joint points. Open at a time with #t=SECONDS.",
            recording.frames.len(),
            clearance_joint::error::sig4(recording.interval_s),
            clearance_joint::error::sig4(recording.contact_interval_s),
            clearance_joint::error::sig4(
                clearance_joint::rapier::observers::replay::DENSE_FRAMES
                    * recording.contact_interval_s
            ),
        ),
        recording,
        series,
    }
}

/// A spatial hinge's tilt magnitude (mrad) and axial offset (mm) panels, from the twins whose
/// rows carry them (none for a planar hinge).
fn spatial_series(h: &str, twins: &[(&str, &Table)]) -> Vec<Series> {
    let (tu, tv, ax) = (
        format!("{h}_tilt_u_deg"),
        format!("{h}_tilt_v_deg"),
        format!("{h}_axial_mm"),
    );
    // The ideal twin's hinge has no play: its zeros would only hide the axis.
    let twins: Vec<&(&str, &Table)> = twins
        .iter()
        .filter(|(name, _)| *name != TwinKind::Ideal.name())
        .collect();
    let tilt: Vec<Line> = twins
        .iter()
        .filter_map(|(name, table)| {
            Line::derived(name, name, table, &[&tu, &tv], |x| {
                x[0].hypot(x[1]).to_radians() * 1e3
            })
        })
        .collect();
    let axial: Vec<Line> = twins
        .iter()
        .filter_map(|(name, table)| Line::from_table(name, name, table, &ax))
        .collect();
    [("tilt |tilt| (mrad)", tilt), ("axial offset (mm)", axial)]
        .into_iter()
        .filter(|(_, lines)| !lines.is_empty())
        .map(|(what, lines)| Series {
            title: format!("hinge `{h}`: {what}"),
            lines,
        })
        .collect()
}

/// The header's short line on the stepping: `adaptive steps <= 1 ms, tolerance 0.0075` or
/// `fixed step 10 us`.
fn stepping_short(run: &clearance_joint::scene::RunSettings) -> String {
    use clearance_joint::scene::StepMode;
    let time = |s: f64| {
        if s >= 1e-3 {
            format!("{} ms", clearance_joint::error::sig4(s * 1e3))
        } else {
            format!("{} \u{b5}s", clearance_joint::error::sig4(s * 1e6))
        }
    };
    match run.step {
        StepMode::Fixed => format!("fixed step {}", time(run.dt_s)),
        StepMode::Adaptive => format!(
            "adaptive steps \u{2264} {}, tolerance {}",
            time(run.max_dt_s),
            run.tolerance
        ),
        other => format!("{other:?} steps"),
    }
}

/// Writes the replay of a scene run into `dir` (see [`run_page`]); returns its path.
pub fn write_run_replay(
    scene: &Scene,
    result: &RunResult,
    recording: &Recording,
    dir: &Path,
) -> Result<PathBuf> {
    run_page(scene, result, recording).write(dir)
}

/// Removes `dir/replay.html` if present: a result set written without a replay must not keep
/// an older run's.
pub fn remove_stale(dir: &Path) -> Result<()> {
    let path = dir.join(FILE);
    match std::fs::remove_file(&path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(Error::Io {
            action: "cannot remove",
            path,
            source: e,
        }),
        _ => Ok(()),
    }
}

/// The `## Replays` section of a study's report: a link per case whose folder holds a replay
/// (empty when none does).
pub fn report_section(dir: &Path, cases: &[crate::study::case::StudyCase]) -> String {
    let links: Vec<String> = cases
        .iter()
        .filter(|c| c.dir.join(FILE).is_file())
        .map(|c| {
            let rel = c.dir.strip_prefix(dir).unwrap_or(&c.dir).join(FILE);
            let size = std::fs::metadata(c.dir.join(FILE)).map_or(0, |m| m.len());
            format!(
                "- [{}]({}) ({:.1} MB)",
                c.label,
                rel.to_string_lossy().replace('\\', "/"),
                size as f64 / 1e6
            )
        })
        .collect();
    if links.is_empty() {
        return String::new();
    }
    format!(
        "\n## Replays\n\nEach case's run in 3D, ideal and clearance twins side by side, the journal \
         magnified in its bearing, every impact on the timeline (one self-contained file; open it in \
         a browser):\n\n{}\n",
        links.join("\n")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn min_max_thinning_keeps_the_peak() {
        let t: Vec<f64> = (0..10_000).map(|i| i as f64 * 1e-3).collect();
        let mut v = vec![0.0; 10_000];
        v[4321] = 7.0;
        v[8000] = -3.0;
        let (tt, vv) = min_max_thin(&t, &v, 100);
        assert!(tt.len() <= 200, "{}", tt.len());
        assert!(vv.contains(&7.0) && vv.contains(&-3.0));
        assert!(tt.windows(2).all(|w| w[0] < w[1]));
    }

    #[test]
    fn rounding_keeps_seven_digits() {
        assert_eq!(round_sig(0.123456789, 7), 0.1234568);
        assert_eq!(round_sig(-1.0e-5, 7), -1.0e-5);
        assert_eq!(round_sig(0.0, 7), 0.0);
    }
}
