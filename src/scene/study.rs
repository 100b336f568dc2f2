//! Study presets declared in a scene file (`studies`): named sweeps of one parameter (a hinge's
//! clearance, a drive's torque scale, a hinge's friction law, or any field), which the app runs
//! with `study <name>`. Plain data, validated when the scene is loaded.

use super::Scene;
use crate::error::{Error, Result};
use serde::{Deserialize, Deserializer, Serialize};

/// A study preset: every case is the scene with `set` applied, then one of `values` on the
/// parameter `kind` names. The cases run as an ideal-vs-clearance sweep, and the report shows the
/// clearance hinge of `kind`.
///
/// ```
/// use clearance_joint::scene::{Scene, StudyKindSpec};
/// let scene = Scene::solar_panel();
/// let clearance = &scene.studies[0];
/// assert_eq!(clearance.name, "clearance");
/// assert_eq!(clearance.kind, StudyKindSpec::Clearance { hinge: "hinge".into() });
/// assert_eq!(clearance.path(), "hinge.clearance_mm");
/// assert_eq!(clearance.values, ["0.10", "0.25", "0.50"]);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudySpec {
    /// Unique name: `study <name>` runs the preset, and its results go to the folder `<name>`.
    pub name: String,
    /// What the study varies, and the clearance hinge its report shows.
    pub kind: StudyKindSpec,
    /// The values of the varied parameter, one case each, as written after `--set path=`: a
    /// number (`0.25` or `"0.25"`; a string keeps its digits, e.g. `"0.10"`), a bare word
    /// (`"Lubricated"`) or JSON (`"{\"Bai\":{...}}"`).
    #[serde(deserialize_with = "values_as_written")]
    pub values: Vec<String>,
    /// Legend labels, one per value (default: `path = value`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub labels: Vec<String>,
    /// Settings common to every case, `path=value` as for `--set`, applied before the varied value
    /// (e.g. `"run.end_s=5"`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub set: Vec<String>,
    /// One of the paper's studies (its section 4: `Clearance` 4.1, `Torque` 4.2, `Friction` 4.3):
    /// on the paper's scene the report cites the paper's figures and judges the paper's
    /// conclusions against the numbers.
    #[serde(default, skip_serializing_if = "is_false")]
    pub paper: bool,
}

/// What a study varies.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum StudyKindSpec {
    /// The radial clearance of the clearance hinge `hinge`, mm (`<hinge>.clearance_mm`).
    Clearance {
        /// A hinge with clearance.
        hinge: String,
    },
    /// The torque scale of the drive `drive` (`<drive>.torque_scale`: T, 3T, ...); the report
    /// shows the clearance hinge `hinge`.
    Torque {
        /// A hinge with clearance (the one the report shows).
        hinge: String,
        /// A drive.
        drive: String,
    },
    /// The friction law of the clearance hinge `hinge` (`<hinge>.friction`): `Dry`,
    /// `Lubricated`, `None`, or a law as JSON.
    Friction {
        /// A hinge with clearance.
        hinge: String,
    },
    /// Any field, by its override path (as for `--set`, e.g. `run.end_s` or
    /// `guide.kind.limits_m`); the report shows the clearance hinge `hinge` (default: the first).
    Field {
        /// Override path.
        path: String,
        /// A hinge with clearance (the one the report shows); `None`: the scene's first.
        #[serde(default)]
        hinge: Option<String>,
    },
}

fn is_false(b: &bool) -> bool {
    !*b
}

/// Values written as strings or as numbers (a number is kept in its shortest form, `0.10` as `0.1`).
fn values_as_written<'de, D: Deserializer<'de>>(
    d: D,
) -> std::result::Result<Vec<String>, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Value {
        Text(String),
        Number(f64),
    }
    let values = Vec::<Value>::deserialize(d)?;
    Ok(values
        .into_iter()
        .map(|v| match v {
            Value::Text(s) => s,
            Value::Number(x) => x.to_string(),
        })
        .collect())
}

impl StudySpec {
    /// The override path of the varied parameter, e.g. `hinge.clearance_mm`.
    pub fn path(&self) -> String {
        match &self.kind {
            StudyKindSpec::Clearance { hinge } => format!("{hinge}.clearance_mm"),
            StudyKindSpec::Torque { drive, .. } => format!("{drive}.torque_scale"),
            StudyKindSpec::Friction { hinge } => format!("{hinge}.friction"),
            StudyKindSpec::Field { path, .. } => path.clone(),
        }
    }

    /// The clearance hinge the study shows: the one its kind names, or for a `Field` study
    /// without one, the scene's first hinge with clearance.
    pub fn hinge<'a>(&'a self, scene: &'a Scene) -> Option<&'a str> {
        match &self.kind {
            StudyKindSpec::Clearance { hinge }
            | StudyKindSpec::Torque { hinge, .. }
            | StudyKindSpec::Friction { hinge }
            | StudyKindSpec::Field {
                hinge: Some(hinge), ..
            } => Some(hinge),
            StudyKindSpec::Field { hinge: None, .. } => scene
                .hinges
                .iter()
                .find(|h| h.clearance.is_some())
                .map(|h| h.name.as_str()),
        }
    }

    /// The legend label of case `i`: the declared label, or `path = value`.
    pub fn label(&self, i: usize) -> String {
        self.labels
            .get(i)
            .cloned()
            .unwrap_or_else(|| format!("{} = {}", self.path(), self.values[i]))
    }

    /// The overrides of case `i`: `set`, then the varied value.
    pub fn case_overrides(&self, i: usize) -> Vec<String> {
        let mut o = self.set.clone();
        o.push(format!("{}={}", self.path(), self.values[i]));
        o
    }
}

impl Scene {
    /// Checks the study presets against the scene: names, the hinge and drive each acts on, the
    /// labels, and every case (the scene with `set` and each value applied must be valid). The
    /// error names the field, e.g. `studies[0].hinge`. [`Scene::load`] and [`Scene::from_ron`]
    /// call it; overrides (`--set`) do not re-check the presets, which only the app's `study`
    /// command uses.
    pub fn validate_studies(&self) -> Result<()> {
        let mut bare = self.clone();
        bare.studies.clear();
        for (i, s) in self.studies.iter().enumerate() {
            let p = format!("studies[{i}]");
            if !super::format::is_plain_name(&s.name) || s.name == "all" {
                return Err(Error::invalid(
                    format!("{p}.name"),
                    format!(
                        "`{}`: must be letters, digits, `_` and `-` (it names the output folder), and not `all` \
                         (`study all` runs every preset)",
                        s.name
                    ),
                ));
            }
            if self.studies[..i].iter().any(|o| o.name == s.name) {
                return Err(Error::invalid(
                    format!("{p}.name"),
                    format!("duplicate study name `{}`", s.name),
                ));
            }
            let clearance_hinge = |field: &str, name: &str| -> Result<()> {
                match self.hinges.iter().find(|h| h.name == name) {
                    None => Err(Error::invalid(
                        format!("{p}.{field}"),
                        format!(
                            "no hinge named `{name}` (hinges: {})",
                            names(self.hinges.iter().map(|h| h.name.as_str()))
                        ),
                    )),
                    Some(h) if h.clearance.is_none() => Err(Error::invalid(
                        format!("{p}.{field}"),
                        format!(
                            "hinge `{name}` is ideal: a study shows a hinge with clearance (hinges with clearance: {})",
                            names(
                                self.hinges
                                    .iter()
                                    .filter(|h| h.clearance.is_some())
                                    .map(|h| h.name.as_str())
                            )
                        ),
                    )),
                    Some(_) => Ok(()),
                }
            };
            match &s.kind {
                StudyKindSpec::Clearance { hinge } | StudyKindSpec::Friction { hinge } => {
                    clearance_hinge("kind.hinge", hinge)?
                }
                StudyKindSpec::Torque { hinge, drive } => {
                    clearance_hinge("kind.hinge", hinge)?;
                    if !self.drives.iter().any(|d| &d.name == drive) {
                        return Err(Error::invalid(
                            format!("{p}.kind.drive"),
                            format!(
                                "no drive named `{drive}` (drives: {})",
                                names(self.drives.iter().map(|d| d.name.as_str()))
                            ),
                        ));
                    }
                }
                StudyKindSpec::Field { path, hinge } => {
                    if path.trim().is_empty() {
                        return Err(Error::invalid(format!("{p}.kind.path"), "is empty"));
                    }
                    match hinge {
                        Some(h) => clearance_hinge("kind.hinge", h)?,
                        None if s.hinge(self).is_none() => {
                            return Err(Error::invalid(
                                format!("{p}.kind.hinge"),
                                "the scene has no hinge with clearance for the study to show",
                            ));
                        }
                        None => {}
                    }
                }
            }
            if s.paper && matches!(s.kind, StudyKindSpec::Field { .. }) {
                return Err(Error::invalid(
                    format!("{p}.paper"),
                    "the paper's studies vary the clearance, the torque or the friction: a `Field` study is none of them",
                ));
            }
            if s.values.is_empty() {
                return Err(Error::invalid(
                    format!("{p}.values"),
                    "has no values: a study needs at least one case",
                ));
            }
            if let Some(k) = s.values.iter().position(|v| v.trim().is_empty()) {
                return Err(Error::invalid(format!("{p}.values[{k}]"), "is empty"));
            }
            if !s.labels.is_empty() && s.labels.len() != s.values.len() {
                return Err(Error::invalid(
                    format!("{p}.labels"),
                    format!(
                        "{} labels for {} values: give one per value, or none",
                        s.labels.len(),
                        s.values.len()
                    ),
                ));
            }
            // Every case must be a valid scene: `set` in order, then each value.
            let mut common = bare.clone();
            for (k, o) in s.set.iter().enumerate() {
                common = common
                    .with_overrides(&[o])
                    .map_err(|e| Error::invalid(format!("{p}.set[{k}]"), format!("`{o}`: {e}")))?;
            }
            let path = s.path();
            for (k, v) in s.values.iter().enumerate() {
                let o = format!("{path}={v}");
                common.with_overrides(&[&o]).map_err(|e| {
                    Error::invalid(format!("{p}.values[{k}]"), format!("`{o}`: {e}"))
                })?;
            }
        }
        Ok(())
    }
}

/// `` `a`, `b` `` or `none`.
fn names<'a>(it: impl Iterator<Item = &'a str>) -> String {
    let v: Vec<String> = it.map(|n| format!("`{n}`")).collect();
    if v.is_empty() {
        "none".into()
    } else {
        v.join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's scene with `studies` replaced by `studies` (RON).
    fn with_studies(studies: &str) -> Result<Scene> {
        let text = crate::scene::SOLAR_PANEL_RON;
        let start = text
            .find("    studies:")
            .expect("the paper's scene declares studies");
        let end = start + text[start..].find("\n    ],\n").expect("end of studies") + 8;
        Scene::from_ron(
            &format!(
                "{}    studies: {studies},\n{}",
                &text[..start],
                &text[end..]
            ),
            "test.ron",
        )
    }

    fn error(studies: &str) -> String {
        with_studies(studies).expect_err("refused").to_string()
    }

    #[test]
    fn the_papers_scene_declares_its_three_studies() {
        let s = Scene::solar_panel();
        let names: Vec<&str> = s.studies.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names, ["clearance", "torque", "friction"]);
        assert!(s.studies.iter().all(|s| s.paper));
        let torque = &s.studies[1];
        assert_eq!(torque.path(), "drive.torque_scale");
        assert_eq!(torque.hinge(&s), Some("hinge"));
        assert_eq!(torque.label(2), "5T");
        assert_eq!(
            torque.case_overrides(1).last().map(String::as_str),
            Some("drive.torque_scale=3")
        );
    }

    #[test]
    fn values_may_be_numbers_and_labels_default_to_the_assignment() {
        let s = with_studies(
            r#"[(name: "c", kind: Clearance(hinge: "hinge"), values: [0.10, "0.20", 1])]"#,
        )
        .unwrap();
        assert_eq!(s.studies[0].values, ["0.1", "0.20", "1"]);
        assert_eq!(s.studies[0].label(1), "hinge.clearance_mm = 0.20");
        // A general study defaults to the first clearance hinge, and survives a round trip.
        let s = with_studies(
            r#"[(name: "end", kind: Field(path: "run.end_s"), values: ["1", "2"], labels: ["short", "long"])]"#,
        )
        .unwrap();
        assert_eq!(s.studies[0].hinge(&s), Some("hinge"));
        assert_eq!(Scene::from_ron(&s.to_ron(), "round trip").unwrap(), s);
    }

    #[test]
    fn errors_name_the_field() {
        for (studies, field, words) in [
            (
                r#"[(name: "c", kind: Clearance(hinge: "pin"), values: ["0.1"])]"#,
                "studies[0].kind.hinge",
                "no hinge named `pin` (hinges: `hinge`)",
            ),
            (
                r#"[(name: "t", kind: Torque(hinge: "hinge", drive: "motor"), values: ["2"])]"#,
                "studies[0].kind.drive",
                "no drive named `motor` (drives: `drive`)",
            ),
            (
                r#"[(name: "a", kind: Friction(hinge: "hinge"), values: ["Dry"]), (name: "a", kind: Friction(hinge: "hinge"), values: ["Dry"])]"#,
                "studies[1].name",
                "duplicate",
            ),
            (
                r#"[(name: "all", kind: Friction(hinge: "hinge"), values: ["Dry"])]"#,
                "studies[0].name",
                "not `all`",
            ),
            (
                r#"[(name: "c", kind: Clearance(hinge: "hinge"), values: [])]"#,
                "studies[0].values",
                "no values",
            ),
            (
                r#"[(name: "c", kind: Clearance(hinge: "hinge"), values: ["0.1", "0.2"], labels: ["one"])]"#,
                "studies[0].labels",
                "1 labels for 2 values",
            ),
            (
                r#"[(name: "c", kind: Clearance(hinge: "hinge"), values: ["0.1", "-2"])]"#,
                "studies[0].values[1]",
                "hinges[hinge].clearance.clearance_mm",
            ),
            (
                r#"[(name: "c", kind: Clearance(hinge: "hinge"), values: ["0.1"], set: ["run.end_s=0"])]"#,
                "studies[0].set[0]",
                "run.end_s",
            ),
            (
                r#"[(name: "f", kind: Field(path: "hinge.no_such_field"), values: ["1"])]"#,
                "studies[0].values[0]",
                "no_such_field",
            ),
            (
                r#"[(name: "f", kind: Field(path: "run.end_s"), values: ["1"], paper: true)]"#,
                "studies[0].paper",
                "none of them",
            ),
            (
                r#"[(name: "f", kind: Friction(hinge: "hinge"), values: ["Sticky"])]"#,
                "studies[0].values[0]",
                "Sticky",
            ),
        ] {
            let e = error(studies);
            assert!(
                e.contains(&format!("`{field}`")) && e.contains(words),
                "{studies}: {e}"
            );
        }
        // A field the format does not know is a parse error naming it.
        let e =
            error(r#"[(name: "c", kind: Clearance(hinge: "hinge"), values: ["0.1"], hinge: "x")]"#);
        assert!(e.contains("hinge") && e.contains("test.ron"), "{e}");
    }

    #[test]
    fn an_ideal_hinge_cannot_be_studied() {
        let mut s = Scene::solar_panel();
        s.hinges[0].clearance = None;
        let e = s.validate_studies().unwrap_err().to_string();
        assert!(
            e.contains("`studies[0].kind.hinge`") && e.contains("hinge `hinge` is ideal"),
            "{e}"
        );
    }
}
