//! Loading a scene: from RON text or a file, the embedded paper's scene, and hints for RON errors.

use super::{Scene, ValidatedScene};
use crate::error::{Error, Result, excerpt};
use std::path::Path;

/// The paper's scene (MODEL.md §4), embedded in the binary.
pub const SOLAR_PANEL_RON: &str = include_str!("../../../assets/solar_panel.ron");

impl Scene {
    /// Parses and checks a scene from RON text; `origin` names the source in errors.
    /// [`ValidatedScene::from_ron`] keeps what the check built.
    pub fn from_ron(text: &str, origin: &str) -> Result<Scene> {
        ValidatedScene::from_ron(text, origin).map(ValidatedScene::into_scene)
    }

    /// Reads, parses and checks a scene file ([`ValidatedScene::load`] keeps what the check
    /// built).
    pub fn load(path: &Path) -> Result<Scene> {
        ValidatedScene::load(path).map(ValidatedScene::into_scene)
    }

    /// Parses a scene from RON text, unchecked; `origin` names the source in errors.
    pub(super) fn parse_ron(text: &str, origin: &str) -> Result<Scene> {
        // Editors on some systems start UTF-8 files with a byte-order mark: not RON, but harmless.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        ron::from_str(text).map_err(|e| {
            let hint = variant_hint(text, &e.span.end).map_or(String::new(), |h| format!(" ({h})"));
            Error::parse(origin, format!("{}{hint}", excerpt(&e.to_string(), 300)))
        })
    }

    /// A scene file's text.
    pub(super) fn read(path: &Path) -> Result<String> {
        std::fs::read_to_string(path).map_err(|source| Error::Io {
            action: "cannot read scene",
            path: path.into(),
            source,
        })
    }

    /// The paper's scene (MODEL.md §4).
    pub fn solar_panel() -> Scene {
        Self::from_ron(SOLAR_PANEL_RON, "assets/solar_panel.ron")
            .expect("the embedded scene is valid")
    }

    /// The scene as RON text.
    pub fn to_ron(&self) -> String {
        ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default()).unwrap_or_default()
    }
}

/// The enum variants of a scene (contact and friction laws, hinge models) and how each is
/// written, for hints when a variant is written in the wrong form (`LiuEtAl()`, a bare
/// `ImprovedLiu`, `Spatial` without its settings).
const VARIANT_FORMS: [(&str, &str); 19] = [
    (
        "Hertz",
        "Hertz(stiffness: Some(K), exponent: n), or Hertz() for n = 1.5 and the geometric stiffness",
    ),
    ("KelvinVoigt", "KelvinVoigt(stiffness: K, damping: D)"),
    (
        "HuntCrossley",
        "HuntCrossley(restitution: cr), optionally with stiffness: Some(K) and exponent: n",
    ),
    (
        "LankaraniNikravesh",
        "LankaraniNikravesh(restitution: cr), optionally with stiffness: Some(K)",
    ),
    (
        "FloresEtAl",
        "FloresEtAl(restitution: cr), optionally with stiffness: Some(K) and exponent: n",
    ),
    (
        "GonthierEtAl",
        "GonthierEtAl(restitution: cr), optionally with stiffness: Some(K) and exponent: n",
    ),
    ("LiuEtAl", "LiuEtAl, with no parameters and no parentheses"),
    (
        "ImprovedLiu",
        "ImprovedLiu(exponent: n, delta_max_mm: d, eta_s: eta), or ImprovedLiu() for the defaults",
    ),
    ("None", "None, with no parameters and no parentheses"),
    ("Coulomb", "Coulomb(mu_d: mu, v_eps_mm_s: v)"),
    ("Threlfall", "Threlfall(mu_d: mu, v0_mm_s: v)"),
    ("Ambrosio", "Ambrosio(mu_d: mu, v0_mm_s: v0, v1_mm_s: v1)"),
    (
        "Bai",
        "Bai(mu_s: mu_s, mu_d: mu_d, v_s_mm_s: v_s, v_d_mm_s: v_d)",
    ),
    ("Dry", "Dry, with no parameters and no parentheses"),
    (
        "Lubricated",
        "Lubricated, with no parameters and no parentheses",
    ),
    ("Some", "Some(value), or None"),
    (
        "Spatial",
        "Spatial((geometry: (axial_play: a, collar_radius: r))), lengths in m, optionally with \
         face: (stiffness: K, restitution: cr) after the geometry",
    ),
    (
        "Compliant",
        "Compliant, with no parameters and no parentheses",
    ),
    (
        "LargeStep",
        "LargeStep, with no parameters and no parentheses",
    ),
];

/// When a RON error comes right after the name of a law, how that law is written.
fn variant_hint(text: &str, at: &ron::error::Position) -> Option<String> {
    // The text up to the error (line and column count characters, from 1).
    let mut prefix = String::new();
    for (i, line) in text.split('\n').enumerate() {
        if i + 1 < at.line {
            prefix.push_str(line);
            prefix.push('\n');
        } else {
            prefix.extend(line.chars().take(at.col.saturating_sub(1)));
            break;
        }
    }
    let before =
        prefix.trim_end_matches(|c: char| c.is_whitespace() || c == '(' || c == ')' || c == ',');
    let start = before
        .rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .map_or(0, |i| i + 1);
    let word = &before[start..];
    variant_form(word)
}

/// How the scene's variant `word` is written, in words; `None` for a word that is no variant.
pub(super) fn variant_form(word: &str) -> Option<String> {
    VARIANT_FORMS
        .iter()
        .find(|(name, _)| *name == word)
        .map(|(name, form)| format!("`{name}` is written {form}"))
}
