//! A scene checked once, carrying what the check built: each clearance hinge's [`HingeDesign`].

use super::Scene;
use crate::error::Result;
use crate::rapier::hinge::design::HingeDesign;
use std::path::Path;

/// A [`Scene`] whose every field was checked, with each clearance hinge's settings built into a
/// [`HingeDesign`] (named after its hinge): the one route from a hinge's
/// [`ClearanceSpec`](super::ClearanceSpec) to its joint ([`HingeDesign::joint`]).
///
/// Built by [`Scene::validated`] (or loaded checked, [`ValidatedScene::load`]); read-only (it
/// derefs to its [`Scene`]): a changed scene is a new [`Scene`], checked again.
///
/// ```
/// use clearance_joint::scene::Scene;
/// let scene = Scene::solar_panel().validated()?;
/// let hinge = &scene.hinges[0];
/// let clearance = scene.clearance(0).expect("the paper's hinge has clearance");
/// assert_eq!(clearance.name.as_deref(), Some(hinge.name.as_str()));
/// assert!((clearance.geometry.clearance() - 0.5e-3).abs() < 1e-15);
/// # Ok::<(), clearance_joint::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct ValidatedScene {
    scene: Scene,
    /// Per hinge, in scene order: its clearance settings, `None` for an ideal hinge.
    clearances: Vec<Option<HingeDesign>>,
}

impl ValidatedScene {
    /// Only [`Scene::validated`] builds one: `clearances` are what its check built.
    pub(super) fn new(scene: Scene, clearances: Vec<Option<HingeDesign>>) -> Self {
        ValidatedScene { scene, clearances }
    }

    /// Parses and checks a scene from RON text (its study presets too); `origin` names the
    /// source in errors.
    pub fn from_ron(text: &str, origin: &str) -> Result<ValidatedScene> {
        let scene = Scene::parse_ron(text, origin)?;
        let validated = scene.validated()?;
        scene.validate_studies()?;
        Ok(validated)
    }

    /// Reads, parses and checks a scene file.
    pub fn load(path: &Path) -> Result<ValidatedScene> {
        let text = Scene::read(path)?;
        Self::from_ron(&text, &path.display().to_string())
    }

    /// The scene with `path=value` overrides applied ([`Scene::with_overrides`]), checked once.
    pub fn with_overrides<S: AsRef<str>>(&self, overrides: &[S]) -> Result<ValidatedScene> {
        if overrides.is_empty() {
            return Ok(self.clone());
        }
        self.scene.overridden(overrides)?.validated()
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The scene, to change (and check again).
    pub fn into_scene(self) -> Scene {
        self.scene
    }

    /// The clearance settings of hinge `hinge` (index in [`Scene::hinges`]), `None` for an ideal
    /// hinge or an index past the last.
    pub fn clearance(&self, hinge: usize) -> Option<&HingeDesign> {
        self.clearances.get(hinge)?.as_ref()
    }
}

impl std::ops::Deref for ValidatedScene {
    type Target = Scene;
    fn deref(&self) -> &Scene {
        &self.scene
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn carries_each_hinges_clearance_with_its_name() {
        let scene = Scene::solar_panel();
        let v = scene.validated().unwrap();
        for (i, h) in scene.hinges.iter().enumerate() {
            match (&h.clearance, v.clearance(i)) {
                (Some(spec), Some(c)) => {
                    assert_eq!(c.name.as_deref(), Some(h.name.as_str()));
                    assert_eq!(
                        c,
                        &spec.clearance().unwrap().name(h.name.clone()),
                        "the spec's own route"
                    );
                }
                (None, None) => {}
                other => panic!("hinge {}: {other:?}", h.name),
            }
        }
        assert!(v.clearance(scene.hinges.len()).is_none());
    }

    #[test]
    fn overrides_are_checked_and_carried() {
        let v = Scene::solar_panel().validated().unwrap();
        let name = v.hinges[0].name.clone();
        let o = v
            .with_overrides(&[format!("{name}.clearance_mm=0.25")])
            .unwrap();
        let c = o.clearance(0).unwrap();
        assert!((c.geometry.clearance() - 0.25e-3).abs() < 1e-15);
        let e = v
            .with_overrides(&[format!("{name}.clearance_mm=-1")])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("hinges[{name}].clearance.clearance_mm")),
            "{e}"
        );
        // No override: the same checked scene.
        let same = v.with_overrides::<&str>(&[]).unwrap();
        assert_eq!(same.scene(), v.scene());
    }
}
