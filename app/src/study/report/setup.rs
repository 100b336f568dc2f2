//! The run settings and names a study's report states.

use crate::study::case::StudyCase;
use crate::study::preset::Study;
use crate::study::sweep::Sweep;

/// The run settings and names a report states.
#[derive(Clone, Debug)]
pub struct Setup {
    /// Step, s (the largest step with adaptive stepping).
    pub dt_s: f64,
    /// The step control in words, e.g. "adaptive steps of at most 1e-3 s (tolerance 0.0075:
    /// twice it of a contact period, an eighth of it in rad of a body's turn)".
    pub stepping: String,
    /// Interval between rows, s.
    pub output_interval_s: f64,
    /// Simulated time, s.
    pub end_s: f64,
    /// Fixed overrides of the study.
    pub overrides: Vec<String>,
    /// Swept path.
    pub axis: String,
    /// Hinge shown (the study's clearance hinge).
    pub hinge: String,
    /// Movable bodies, the hinge's journal body first.
    pub bodies: Vec<String>,
    /// Base scene name.
    pub scene: String,
}

impl Setup {
    /// The setup of `study` from its sweep and cases.
    pub fn of(study: &Study, sweep: &Sweep, cases: &[StudyCase]) -> Setup {
        let scene = cases.first().map(|c| &c.scene).unwrap_or(&sweep.base);
        let hinge = scene.hinges.iter().find(|h| h.name == study.hinge);
        let mut bodies: Vec<String> = scene
            .bodies
            .iter()
            .filter(|b| !b.fixed)
            .map(|b| b.name.clone())
            .collect();
        if let Some(h) = hinge {
            bodies.sort_by_key(|b| *b != h.journal);
        }
        let stepping = scene.run.stepping();
        Setup {
            stepping,
            dt_s: scene.run.dt_s,
            output_interval_s: scene.run.output_interval_s,
            end_s: scene.run.end_s,
            overrides: sweep.base_overrides.clone(),
            axis: study.axis().path,
            hinge: study.hinge.clone(),
            bodies,
            scene: sweep.base.name.clone(),
        }
    }
}
