//! The paper's three studies (its section 4) as named sweeps: what each varies, what it fixes,
//! its labels, and the scene names they need.

use super::grid::{Axis, Grid};
use super::sweep::Sweep;
use clearance_joint::error::{Error, Result};
use clearance_joint::scene::Scene;

/// One of the paper's studies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum StudyKind {
    /// Clearance size c = 0.10, 0.25, 0.50 mm (torque T, dry): figs 3-5.
    Clearance,
    /// Driving torque T, 3T, 5T (c = 0.5 mm, dry): figs 6-8.
    Torque,
    /// Dry vs lubricated (c = 0.5 mm, torque T, 5 s): figs 9-11.
    Friction,
}

impl StudyKind {
    /// All studies, in the paper's order.
    pub const ALL: [StudyKind; 3] = [StudyKind::Clearance, StudyKind::Torque, StudyKind::Friction];

    /// `clearance`, `torque` or `friction` (the CLI name and the folder name).
    pub fn name(self) -> &'static str {
        match self {
            StudyKind::Clearance => "clearance",
            StudyKind::Torque => "torque",
            StudyKind::Friction => "friction",
        }
    }

    /// Parses a study name (`all` is handled by the caller).
    pub fn parse(s: &str) -> Result<StudyKind> {
        StudyKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                Error::invalid(
                    "study",
                    format!("unknown study `{s}`: expected clearance, torque, friction or all"),
                )
            })
    }

    /// Title of the study (the paper's section heading).
    pub fn title(self) -> &'static str {
        match self {
            StudyKind::Clearance => "Influence of the clearance size (paper section 4.1)",
            StudyKind::Torque => "Influence of the driving torque (paper section 4.2)",
            StudyKind::Friction => "Influence of the friction coefficient (paper section 4.3)",
        }
    }

    /// The paper's figure numbers for angles/rates, joint force and trajectory.
    pub fn paper_figures(self) -> [u32; 3] {
        match self {
            StudyKind::Clearance => [3, 4, 5],
            StudyKind::Torque => [6, 7, 8],
            StudyKind::Friction => [9, 10, 11],
        }
    }

    /// Overrides common to every case, applied to the base scene before the swept value.
    /// Every study runs with the same step control for all its cases, so they are comparable: the
    /// crate's default adaptive steps (at most 1e-3 s, 0.75 % of a contact period inside
    /// contacts), which agree with a converged fixed-step run to 1 % in the first-impact peak and
    /// 3 % in onsets (README, work-precision); the paper's fixed 1e-4 s overstates the first-impact
    /// peak by 13 % (203.2 N against 179.4 N). Rows every 0.1 ms.
    pub fn base_overrides(self) -> Vec<String> {
        let v: &[&str] = match self {
            StudyKind::Clearance => &[
                "run.step=Adaptive",
                "run.output_interval_s=1e-4",
                "run.end_s=5",
                "drive.torque_scale=1",
                "hinge.friction=Dry",
            ],
            StudyKind::Torque => &[
                "run.step=Adaptive",
                "run.output_interval_s=1e-4",
                "run.end_s=5",
                "hinge.clearance_mm=0.5",
                "hinge.friction=Dry",
            ],
            StudyKind::Friction => &[
                "run.step=Adaptive",
                "run.output_interval_s=1e-4",
                "run.end_s=5",
                "hinge.clearance_mm=0.5",
                "drive.torque_scale=1",
            ],
        };
        v.iter().map(|s| s.to_string()).collect()
    }

    /// The swept parameter and its values.
    pub fn axis(self) -> Axis {
        match self {
            StudyKind::Clearance => Axis::new("hinge.clearance_mm", ["0.10", "0.25", "0.50"]),
            StudyKind::Torque => Axis::new("drive.torque_scale", ["1", "3", "5"]),
            StudyKind::Friction => Axis::new("hinge.friction", ["Dry", "Lubricated"]),
        }
    }

    /// Legend labels of the cases, in axis order.
    pub fn labels(self) -> Vec<String> {
        let v: &[&str] = match self {
            StudyKind::Clearance => &["c = 0.10 mm", "c = 0.25 mm", "c = 0.50 mm"],
            StudyKind::Torque => &["T", "3T", "5T"],
            StudyKind::Friction => &["dry (no lubrication)", "lubricated"],
        };
        v.iter().map(|s| s.to_string()).collect()
    }

    /// The study as a sweep over `base`, with `extra` overrides after the study's own.
    pub fn sweep(self, base: &Scene, extra: &[String]) -> Sweep {
        let mut overrides = self.base_overrides();
        overrides.extend(extra.iter().cloned());
        Sweep::new(
            self.name(),
            base.clone(),
            overrides,
            Grid {
                axes: vec![self.axis()],
            },
        )
    }
}

/// The presets set `hinge.clearance_mm`, `hinge.friction` and `drive.torque_scale`: the scene
/// must have a clearance hinge named `hinge` and a drive named `drive`. Says so, and what the
/// scene has, before anything runs.
pub fn check_names(base: &Scene) -> Result<()> {
    let hinge_ok = base
        .hinges
        .iter()
        .any(|h| h.name == "hinge" && h.clearance.is_some());
    let drive_ok = base.drives.iter().any(|d| d.name == "drive");
    if hinge_ok && drive_ok {
        return Ok(());
    }
    let names = |v: Vec<&str>| {
        if v.is_empty() {
            "none".to_string()
        } else {
            v.iter()
                .map(|n| format!("`{n}`"))
                .collect::<Vec<_>>()
                .join(", ")
        }
    };
    Err(Error::invalid(
        format!("study --scene ({})", base.name),
        format!(
            "the studies need a clearance hinge named `hinge` and a drive named `drive` (they set \
             hinge.clearance_mm, hinge.friction and drive.torque_scale); this scene has clearance hinges {} \
             and drives {}: rename them in the scene file, or run your own grid with `sweep --set ...`",
            names(
                base.hinges
                    .iter()
                    .filter(|h| h.clearance.is_some())
                    .map(|h| h.name.as_str())
                    .collect()
            ),
            names(base.drives.iter().map(|d| d.name.as_str()).collect()),
        ),
    ))
}
