//! Study presets resolved against their scene: what each varies (a hinge's clearance, a drive's
//! torque scale, a hinge's friction law, or any field), the hinge its report shows, and whether
//! it is one of the paper's studies on the paper's scene. A scene's `studies` declare them; a
//! scene declaring none gets the paper's three, which need a hinge `hinge` and a drive `drive`.

use super::grid::{Axis, Grid};
use super::sweep::Sweep;
use clearance_joint::error::{Error, Result};
use clearance_joint::scene::{Scene, StudyKindSpec, StudySpec};

/// What a study varies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum StudyKind {
    /// A hinge's radial clearance (the paper's section 4.1: c = 0.10, 0.25, 0.50 mm; figs 3-5).
    Clearance,
    /// A drive's torque scale (section 4.2: T, 3T, 5T; figs 6-8).
    Torque,
    /// A hinge's friction law (section 4.3: dry vs lubricated; figs 9-11).
    Friction,
    /// Any other field.
    Field,
}

impl StudyKind {
    /// The paper's studies, in its order.
    pub const PAPER: [StudyKind; 3] =
        [StudyKind::Clearance, StudyKind::Torque, StudyKind::Friction];

    /// The kind of a declared preset.
    pub fn of(spec: &StudyKindSpec) -> StudyKind {
        match spec {
            StudyKindSpec::Clearance { .. } => StudyKind::Clearance,
            StudyKindSpec::Torque { .. } => StudyKind::Torque,
            StudyKindSpec::Friction { .. } => StudyKind::Friction,
            StudyKindSpec::Field { .. } => StudyKind::Field,
        }
    }

    /// `clearance`, `torque`, `friction` or `field` (the first three are the names of the
    /// paper's presets, and so their folders).
    pub fn name(self) -> &'static str {
        match self {
            StudyKind::Clearance => "clearance",
            StudyKind::Torque => "torque",
            StudyKind::Friction => "friction",
            StudyKind::Field => "field",
        }
    }

    /// What the study is about, e.g. "Influence of the clearance size".
    pub fn title(self) -> &'static str {
        match self {
            StudyKind::Clearance => "Influence of the clearance size",
            StudyKind::Torque => "Influence of the driving torque",
            StudyKind::Friction => "Influence of the friction coefficient",
            StudyKind::Field => "Influence of a parameter",
        }
    }

    /// The paper's section of its study of this kind.
    pub fn paper_section(self) -> Option<&'static str> {
        match self {
            StudyKind::Clearance => Some("4.1"),
            StudyKind::Torque => Some("4.2"),
            StudyKind::Friction => Some("4.3"),
            StudyKind::Field => None,
        }
    }

    /// The paper's figure numbers of its study of this kind: angles/rates, joint force, trajectory.
    pub fn paper_figures(self) -> Option<[u32; 3]> {
        match self {
            StudyKind::Clearance => Some([3, 4, 5]),
            StudyKind::Torque => Some([6, 7, 8]),
            StudyKind::Friction => Some([9, 10, 11]),
            StudyKind::Field => None,
        }
    }
}

/// A study preset resolved against its scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Study {
    /// The preset as declared.
    pub spec: StudySpec,
    /// What it varies.
    pub kind: StudyKind,
    /// The clearance hinge its report and figures show.
    pub hinge: String,
    /// One of the paper's studies run on the paper's scene ([`is_paper_scene`]): the report
    /// cites the paper's figures and judges the paper's conclusions against the numbers.
    pub paper: bool,
    /// Declared by the scene (`false`: the paper's presets, lent to a scene declaring none).
    pub declared: bool,
}

impl Study {
    /// The preset's name (its folder).
    pub fn name(&self) -> &str {
        &self.spec.name
    }

    /// The swept parameter and its values.
    pub fn axis(&self) -> Axis {
        Axis::new(self.spec.path(), self.spec.values.iter().cloned())
    }

    /// Legend labels of the cases, in axis order.
    pub fn labels(&self) -> Vec<String> {
        (0..self.spec.values.len())
            .map(|i| self.spec.label(i))
            .collect()
    }

    /// Title of the report: the kind's (a `Field` study names its path), with the paper's
    /// section for one of the paper's studies.
    pub fn title(&self) -> String {
        match (self.kind, self.paper) {
            (StudyKind::Field, _) => format!("Influence of `{}`", self.spec.path()),
            (k, true) => format!(
                "{} (paper section {})",
                k.title(),
                k.paper_section().unwrap_or("?")
            ),
            (k, false) => format!("{} (`{}`)", k.title(), self.spec.path()),
        }
    }

    /// The paper's figure numbers, for one of the paper's studies.
    pub fn paper_figures(&self) -> Option<[u32; 3]> {
        self.kind.paper_figures().filter(|_| self.paper)
    }

    /// The study as a sweep over `base`, with `extra` overrides after the preset's own `set`.
    pub fn sweep(&self, base: &Scene, extra: &[String]) -> Sweep {
        let mut overrides = self.spec.set.clone();
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

/// The presets of `scene`: those its `studies` declare, or for a scene declaring none the
/// paper's three (from `assets/solar_panel.ron`), refused with what to declare when the scene
/// lacks the clearance hinge `hinge` or the drive `drive` they act on.
pub fn presets(scene: &Scene) -> Result<Vec<Study>> {
    if !scene.studies.is_empty() {
        scene.validate_studies()?;
        return Ok(resolve(scene, true));
    }
    check_names(scene)?;
    let mut lent = scene.clone();
    lent.studies = Scene::solar_panel().studies;
    lent.validate_studies().map_err(|e| {
        Error::invalid(
            format!("study --scene ({})", scene.name),
            format!(
                "declares no study presets, and the paper's do not fit it ({e}): declare `studies` in the scene file"
            ),
        )
    })?;
    Ok(resolve(&lent, false))
}

fn resolve(scene: &Scene, declared: bool) -> Vec<Study> {
    let paper_scene = is_paper_scene(scene);
    scene
        .studies
        .iter()
        .map(|spec| Study {
            kind: StudyKind::of(&spec.kind),
            hinge: spec.hinge(scene).unwrap_or_default().to_string(),
            paper: spec.paper && paper_scene,
            declared,
            spec: spec.clone(),
        })
        .collect()
}

/// The presets of `scene` that `name` selects: the one so named, or every one for `all`.
pub fn select(scene: &Scene, name: &str) -> Result<Vec<Study>> {
    let all = presets(scene)?;
    if name == "all" {
        return Ok(all);
    }
    if let Some(s) = all.iter().find(|s| s.name() == name) {
        return Ok(vec![s.clone()]);
    }
    let names: Vec<String> = all.iter().map(|s| format!("`{}`", s.name())).collect();
    Err(Error::invalid(
        "study",
        format!(
            "unknown study `{name}`: scene `{}` {} {}, or `all` for every one",
            scene.name,
            if all.first().is_some_and(|s| s.declared) {
                "declares"
            } else {
                "has the paper's"
            },
            names.join(", ")
        ),
    ))
}

/// Whether `scene` is the paper's scene: its bodies, hinges, joints, drives, gravity and
/// reference axis those of `assets/solar_panel.ron` (its name, run settings and presets may
/// differ). The paper's conclusions are about that scene only.
pub fn is_paper_scene(scene: &Scene) -> bool {
    let mechanism = |s: &Scene| {
        let mut s = s.clone();
        s.name.clear();
        s.run = Default::default();
        s.studies.clear();
        s
    };
    mechanism(scene) == mechanism(&Scene::solar_panel())
}

/// A scene declaring no presets gets the paper's, which set `hinge.clearance_mm`,
/// `hinge.friction` and `drive.torque_scale`: it must have a clearance hinge named `hinge` and a
/// drive named `drive`. Says so, what the scene has and what to declare instead, before anything
/// runs.
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
    let clearance_hinges: Vec<&str> = base
        .hinges
        .iter()
        .filter(|h| h.clearance.is_some())
        .map(|h| h.name.as_str())
        .collect();
    let example = clearance_hinges.first().copied().unwrap_or("HINGE");
    Err(Error::invalid(
        format!("study --scene ({})", base.name),
        format!(
            "the scene declares no study presets (`studies`), and the paper's presets need a clearance hinge named \
             `hinge` and a drive named `drive` (they set hinge.clearance_mm, hinge.friction and drive.torque_scale); \
             this scene has clearance hinges {} and drives {}: declare its studies in the scene file, e.g. \
             `studies: [(name: \"clearance\", kind: Clearance(hinge: \"{example}\"), values: [\"0.1\", \"0.25\", \"0.5\"])]` \
             (kinds: Clearance(hinge), Torque(hinge, drive), Friction(hinge), Field(path)), or run your own grid with \
             `sweep --set ...`",
            names(clearance_hinges.clone()),
            names(base.drives.iter().map(|d| d.name.as_str()).collect()),
        ),
    ))
}
