//! The figures of one scene run (`run`, the default job): angles and rates, joint force and
//! journal orbit of the first clearance hinge, and for driven mechanisms each moving body's
//! acceleration over the driver's last turn, ideal against clearance.

use super::series::CaseSeries;
use super::{Figure, FigureKind, XyFigure};
use clearance_joint::error::{Error, Result};
use clearance_joint::scene::runner::{RunResult, TwinKind};
use clearance_joint::scene::{MotionSpec, Scene};
use clearance_joint::table::Table;
use std::path::Path;

/// Whether `scene`'s runs can have figures (a clearance hinge to plot): the reason if not.
pub fn can_draw(scene: &Scene) -> Result<()> {
    if scene.hinges.iter().any(|h| h.clearance.is_some()) {
        Ok(())
    } else {
        Err(Error::invalid(
            "--figures",
            "the scene has no hinge with clearance: nothing to plot (the figures show a clearance hinge)",
        ))
    }
}

/// Draws the figures of `result` (a run of `scene`) into `out`, PNG and SVG, calling `written`
/// with each file as soon as it is written. Fails when the run lacks a twin or the scene has no
/// clearance hinge to plot.
pub fn draw_run_figures(
    scene: &Scene,
    result: &RunResult,
    out: &Path,
    mut written: impl FnMut(&Path),
) -> Result<()> {
    let (Some(ideal), Some(clear)) = (
        result.twin(TwinKind::Ideal),
        result.twin(TwinKind::Clearance),
    ) else {
        return Err(Error::invalid("--figures", "needs both twins"));
    };
    can_draw(scene)?;
    let case = CaseSeries::from_tables(case_label(scene), scene, &ideal.table, &clear.table)?;
    let contacts = clear.hinge_recorders();
    let series = [match contacts.get(&case.hinge) {
        Some(r) => case.with_contacts(r.contacts()),
        None => case,
    }];
    // One pixel buffer for every figure's PNG.
    let mut raster = Vec::new();
    // Driven mechanisms: each moving body's x acceleration against the driver's angle over
    // the last turn, ideal against clearance.
    if let (Some(period), true) = (scene.drive_period(), scene.run.body_motion) {
        let driver = scene
            .bodies
            .iter()
            .find(|b| matches!(b.motion, Some(MotionSpec::Spin { .. })))
            .map(|b| b.name.clone())
            .or_else(|| {
                scene
                    .joints
                    .iter()
                    .find(|j| j.motor.is_some())
                    .map(|j| j.body2.clone())
            });
        let end = scene.run.end_s;
        for b in scene
            .bodies
            .iter()
            .filter(|b| !b.fixed && b.motion.is_none())
        {
            let (Some(driver), true) = (&driver, end >= period * (1.0 - 1e-9)) else {
                continue;
            };
            let column = format!("{}_ax_m_s2", b.name);
            let curve = |label: &str, t: &Table| {
                let (Some(ts), Some(angle), Some(a)) = (
                    t.column("t_s"),
                    t.column(&format!("{driver}_angle_deg")),
                    t.column(&column),
                ) else {
                    return None;
                };
                let first = ts.iter().position(|&x| x >= end - period)?;
                let points = (first..ts.len())
                    .map(|i| (angle[i] - angle[first], a[i]))
                    .collect();
                Some((label.to_string(), points))
            };
            let curves: Vec<(String, Vec<(f64, f64)>)> = [
                curve("ideal", &ideal.table),
                curve("clearance", &clear.table),
            ]
            .into_iter()
            .flatten()
            .collect();
            if curves.is_empty() {
                continue;
            }
            let title = format!(
                "{}: {} acceleration along x over the last turn of {driver}",
                scene.name, b.name
            );
            let x_label = format!("{driver} angle from the turn's start (deg)");
            let paths = XyFigure {
                title: &title,
                x_label: &x_label,
                y_label: "acceleration along x (m/s^2)",
                curves: &curves,
            }
            .write_reusing(out, &format!("{}_acceleration", b.name), &mut raster)?;
            for p in paths {
                written(&p);
            }
        }
    }
    for kind in FigureKind::ALL {
        let title = format!("{}: {}", scene.name, kind.subject());
        let paths = Figure {
            kind,
            title: &title,
            cases: &series,
        }
        .write_reusing(out, kind.stem(), &mut raster)?;
        for p in paths {
            written(&p);
        }
    }
    Ok(())
}

/// The legend label of a run's clearance curves: "clearance joint" and its clearance, with the
/// hinge's name when the scene has several clearance hinges (the figures draw the first). The
/// ideal curves are "ideal joint"; the scene's name is in the title.
fn case_label(scene: &Scene) -> String {
    let hinges: Vec<_> = scene
        .hinges
        .iter()
        .filter(|h| h.clearance.is_some())
        .collect();
    let Some(h) = hinges.first() else {
        return "clearance joint".to_string();
    };
    let c = h.clearance.as_ref().map_or(0.0, |c| c.clearance_mm);
    if hinges.len() > 1 {
        format!("clearance joint {} (c = {c:.2} mm)", h.name)
    } else {
        format!("clearance joint (c = {c:.2} mm)")
    }
}
