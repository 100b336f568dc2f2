//! `summary.json` as the app writes it: the library's summary of a run
//! ([`RunResult::write_checked`]) with the scene the run used, every `--set` override applied
//! and every default filled in, under [`EFFECTIVE_SCENE`].

use crate::process::files::write_atomic;
use clearance_joint::error::{Error, Result};
use clearance_joint::scene::report::{Summary, summary_json};
use clearance_joint::scene::runner::RunResult;
use clearance_joint::scene::runner::convergence::ConvergenceVerdict;
use clearance_joint::scene::{Scene, ValidatedScene};
use serde::Deserialize;
use std::path::Path;

/// The key of `summary.json` that holds the effective scene: the whole [`Scene`] as the run used
/// it, in the scene file's fields (JSON).
pub const EFFECTIVE_SCENE: &str = "effective_scene";

/// Writes `result`'s set into `dir` as [`RunResult::write_checked`] does (recording
/// `convergence`), then replaces its `summary.json` (atomically) by
/// [`summary_with_scene`]'s: the same summary with the effective scene.
pub fn write_run(
    result: &RunResult,
    dir: &Path,
    convergence: &ConvergenceVerdict,
) -> Result<Summary> {
    let summary = result.write_checked(dir, convergence, &crate::process::files::STAGING)?;
    let text = summary_with_scene(&summary, &result.scene)?;
    write_atomic(&dir.join("summary.json"), text.as_bytes())?;
    Ok(summary)
}

/// The text of `summary.json`: `summary` as the library writes it ([`summary_json`]: refusing
/// a non-finite metric), with `scene` whole under [`EFFECTIVE_SCENE`].
pub fn summary_with_scene(summary: &Summary, scene: &Scene) -> Result<String> {
    let invalid = |e: serde_json::Error| Error::invalid("summary", e.to_string());
    let mut value: serde_json::Value =
        serde_json::from_str(&summary_json(summary)?).map_err(invalid)?;
    let scene = effective_scene_json(scene)?;
    let object = value
        .as_object_mut()
        .ok_or_else(|| Error::invalid("summary", "is not a JSON object"))?;
    object.insert(EFFECTIVE_SCENE.into(), scene);
    serde_json::to_string_pretty(&value).map_err(invalid)
}

/// `scene` as JSON, every hinge setting written: the scene format leaves a hinge's
/// `journal_offset_mm` and a clearance's `model` and `restitution` out at their defaults
/// (centred, `Compliant`, none), and here they are given. A spatial hinge's `face` is left out
/// when it takes the flat punch of its collar (its law is built from the materials).
pub fn effective_scene_json(scene: &Scene) -> Result<serde_json::Value> {
    let json = |v: serde_json::Result<serde_json::Value>| {
        v.map_err(|e| Error::invalid("summary.effective_scene", e.to_string()))
    };
    let mut value = json(serde_json::to_value(scene))?;
    let hinges = value
        .get_mut("hinges")
        .and_then(serde_json::Value::as_array_mut);
    for (h, v) in scene.hinges.iter().zip(hinges.into_iter().flatten()) {
        v["journal_offset_mm"] = json(serde_json::to_value(h.journal_offset_mm))?;
        if let Some(c) = &h.clearance {
            v["clearance"]["model"] = json(serde_json::to_value(c.model))?;
            v["clearance"]["restitution"] = json(serde_json::to_value(c.restitution))?;
        }
    }
    Ok(value)
}

/// The effective scene that a `summary.json`'s text records ([`EFFECTIVE_SCENE`]), checked as
/// the run checked it (fields, not study presets): run it for the same run again. `origin`
/// names the summary in errors.
pub fn recorded_scene(summary_json: &str, origin: &str) -> Result<ValidatedScene> {
    let what = format!("{origin} (`{EFFECTIVE_SCENE}`)");
    let value: serde_json::Value =
        serde_json::from_str(summary_json).map_err(|e| Error::parse(&what, e.to_string()))?;
    let scene = value
        .get(EFFECTIVE_SCENE)
        .ok_or_else(|| Error::parse(&what, "the summary records no scene"))?;
    Scene::deserialize(scene)
        .map_err(|e| Error::parse(&what, e.to_string()))?
        .validated()
}
