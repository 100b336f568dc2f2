//! One finished case of a study: its label, swept value, scene, metrics and folder.

use super::metrics::RunMetrics;
use clearance_joint::scene::Scene;
use std::path::PathBuf;

/// One case of a finished study.
#[derive(Clone, Debug)]
pub struct StudyCase {
    /// Legend label.
    pub label: String,
    /// Swept value as written.
    pub value: String,
    /// The case's scene.
    pub scene: Scene,
    /// Its metrics.
    pub metrics: RunMetrics,
    /// Its folder.
    pub dir: PathBuf,
    /// Whether it was reused from an earlier run.
    pub reused: bool,
}
