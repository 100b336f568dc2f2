//! A scene run recorded for its replay, and the run's page: the recording with each clearance
//! hinge's angle, rate and force, ideal against clearance.

use super::record::{DENSE_FRAMES, Recording, ReplayRecorder};
use super::series::{Line, Series};
use super::{CONTACT_FRAMES, FRAMES, MAX_FRAMES, ReplayPage, SERIES_BUCKETS};
use clearance_joint::error::Result;
use clearance_joint::scene::runner::{Progress, RunOptions, RunResult, Simulation, TwinKind};
use clearance_joint::scene::{Scene, ValidatedScene};
use clearance_joint::table::Table;
use std::path::{Path, PathBuf};

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
    let mut recorder = ReplayRecorder::for_simulation(&sim, end / FRAMES, end / CONTACT_FRAMES)?
        .with_max_frames(MAX_FRAMES);
    let result = sim.run_observed(progress, |s| recorder.record_simulation(s))?;
    Ok((result, Some(recorder.finish())))
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
            clearance_joint::error::sig4(DENSE_FRAMES * recording.contact_interval_s),
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
