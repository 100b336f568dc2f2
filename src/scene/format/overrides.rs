//! `path=value` overrides of a scene's fields, the path found in the scene's JSON form.

use super::Scene;
use crate::error::{Error, Result};

impl Scene {
    /// Applies `path=value` overrides. The first segment of `path` is a top-level field (`run`,
    /// `gravity`, ...) or the name of a body, hinge or drive; the following segments are fields,
    /// found at any depth below when unique (`hinge.clearance_mm` is
    /// `hinges[hinge].clearance.clearance_mm`). The value is JSON (`0.25`, `[0,0,-9.81]`,
    /// `{"HuntCrossley":{"restitution":0.9}}`) or else a bare word (`Lubricated`).
    ///
    /// The overrides apply in order, each path found in the scene the earlier ones left: a later
    /// override may set a field inside an earlier one's value (`hinge.contact={"ImprovedLiu":{..}}`
    /// then `hinge.exponent=1.5` is that law with exponent 1.5), and a later value holds over an
    /// earlier one of its field or of a field inside it (`hinge.exponent` then `hinge.contact`
    /// loses the exponent: [`refuse_lost_overrides`](Self::refuse_lost_overrides) refuses such
    /// a list, for overrides given together).
    ///
    /// The result is checked ([`ValidatedScene::with_overrides`](super::ValidatedScene::with_overrides)
    /// keeps what the check built).
    pub fn with_overrides<S: AsRef<str>>(&self, overrides: &[S]) -> Result<Scene> {
        if overrides.is_empty() {
            return Ok(self.clone());
        }
        let scene = self.overridden(overrides)?;
        scene.validate()?;
        Ok(scene)
    }

    /// The scene with `overrides` applied ([`with_overrides`](Self::with_overrides)), unchecked.
    pub(super) fn overridden<S: AsRef<str>>(&self, overrides: &[S]) -> Result<Scene> {
        let (value, _) = self.applied(overrides)?;
        let scene: Scene = match serde_json::from_value(value) {
            Ok(scene) => scene,
            Err(e) => return Err(self.first_unreadable(overrides, e)),
        };
        Ok(scene)
    }

    /// The scene's JSON form with `overrides` applied in order, and the field each one wrote.
    fn applied<S: AsRef<str>>(&self, overrides: &[S]) -> Result<(serde_json::Value, Vec<Written>)> {
        let mut value = self.json_form()?;
        let mut written = Vec::with_capacity(overrides.len());
        for o in overrides {
            let o = o.as_ref();
            let (path, raw) = o
                .split_once('=')
                .ok_or_else(|| Error::parse(format!("override `{o}`"), "expected `path=value`"))?;
            let new: serde_json::Value = serde_json::from_str(raw.trim())
                .unwrap_or_else(|_| serde_json::Value::String(raw.trim().to_string()));
            let path = path.trim();
            let steps = locate_steps(&value, path)?;
            // The field's text is taken now: a later override may rename what it passes through.
            let field = field_text(&value, &steps);
            let slot = slot_at(&mut value, &steps);
            check_group(path, slot, &new)?;
            *slot = new;
            written.push(Written {
                path: path.to_string(),
                steps,
                field,
            });
        }
        Ok((value, written))
    }

    /// The scene's JSON form with the defaults it leaves unwritten filled in, so paths find them.
    fn json_form(&self) -> Result<serde_json::Value> {
        let mut value =
            serde_json::to_value(self).map_err(|e| Error::invalid("scene", e.to_string()))?;
        with_skipped_defaults(&mut value);
        Ok(value)
    }

    /// The error of overrides whose result is not a scene: names the first override after which
    /// the scene no longer reads (applied in order), not the whole list.
    fn first_unreadable<S: AsRef<str>>(&self, overrides: &[S], all: serde_json::Error) -> Error {
        let Ok(mut value) = self.json_form() else {
            return Error::parse("overrides", all.to_string());
        };
        for o in overrides {
            let o = o.as_ref();
            let Some((path, raw)) = o.split_once('=') else {
                continue;
            };
            let new: serde_json::Value = serde_json::from_str(raw.trim())
                .unwrap_or_else(|_| serde_json::Value::String(raw.trim().to_string()));
            if let Ok(steps) = locate_steps(&value, path.trim()) {
                *slot_at(&mut value, &steps) = new;
            }
            if let Err(e) = serde_json::from_value::<Scene>(value.clone()) {
                let hint = super::load::variant_form(raw.trim()).map_or(String::new(), |h| {
                    format!(" ({h}; in an override, as JSON)")
                });
                return Error::parse(format!("override `{o}`"), format!("{e}{hint}"));
            }
        }
        Error::parse("overrides", all.to_string())
    }

    /// The field an override path names, written in full (`hinge.clearance_mm` is
    /// `hinges[hinge].clearance.clearance_mm`): two paths naming one field give the same text.
    /// Refused as [`Scene::with_overrides`] refuses the path.
    pub fn override_field(&self, path: &str) -> Result<String> {
        let value = self.json_form()?;
        let steps = locate_steps(&value, path.trim())?;
        Ok(field_text(&value, &steps))
    }

    /// Refuses an override of `overrides` whose field a later one of them replaces whole (it sets
    /// an object holding the field: `hinge.exponent=1.5` then `hinge.contact=..`), since its value
    /// would be lost without a word; setting a field again, or a field inside an earlier
    /// override's value, is well-defined in order and passes. The fields are found as
    /// [`with_overrides`](Self::with_overrides) applies `earlier` then `overrides`; `earlier`
    /// (settings the caller's own overrides are meant to replace, such as a study's) is not checked.
    pub fn refuse_lost_overrides<S: AsRef<str>, T: AsRef<str>>(
        &self,
        earlier: &[S],
        overrides: &[T],
    ) -> Result<()> {
        let all: Vec<&str> = earlier
            .iter()
            .map(AsRef::as_ref)
            .chain(overrides.iter().map(AsRef::as_ref))
            .collect();
        let (_, written) = self.applied(&all)?;
        refuse_lost(&written[earlier.len()..])
    }

    /// The field each of `overrides` writes, in full as [`override_field`](Self::override_field)
    /// gives it, found as [`with_overrides`](Self::with_overrides) applies them: in order, each
    /// path in the scene the earlier ones left (`hinge.exponent` after
    /// `hinge.contact={"ImprovedLiu":{..}}` is `hinges[hinge].clearance.contact.ImprovedLiu.exponent`
    /// whatever law the scene had). Refused as [`Scene::with_overrides`] refuses a path or value;
    /// the values are not checked.
    pub fn override_fields<S: AsRef<str>>(&self, overrides: &[S]) -> Result<Vec<String>> {
        let (_, written) = self.applied(overrides)?;
        Ok(written.into_iter().map(|w| w.field).collect())
    }
}

/// Whether the field `inner` lies inside the field `outer` (both as
/// [`Scene::override_field`] writes them), so that setting `outer` replaces `inner`'s value:
/// `hinges[hinge].clearance.contact.ImprovedLiu.exponent` is inside
/// `hinges[hinge].clearance.contact`, and every field of a hinge inside `hinges`.
/// A field is not inside itself.
pub fn field_within(inner: &str, outer: &str) -> bool {
    inner
        .strip_prefix(outer)
        .is_some_and(|rest| rest.starts_with(['.', '[']))
}

/// What one override wrote: its path as given, the steps to its field, and the field in full.
#[derive(Clone, Debug)]
struct Written {
    path: String,
    steps: Vec<Step>,
    field: String,
}

/// Refuses an override whose field a later override replaces whole (see
/// [`Scene::refuse_lost_overrides`]).
fn refuse_lost(written: &[Written]) -> Result<()> {
    for (i, early) in written.iter().enumerate() {
        let later = written[i + 1..]
            .iter()
            .find(|l| l.steps.len() < early.steps.len() && early.steps.starts_with(&l.steps));
        if let Some(later) = later {
            return Err(Error::invalid(
                &early.path,
                format!(
                    "its value would be lost: `{}` sets `{}`, inside `{}`, which the later \
                     override of `{}` replaces whole. Give `{}` first and `{}` after it (in \
                     order, the field is then set inside the new value), or put the field in \
                     `{}`'s value",
                    early.path,
                    early.field,
                    later.field,
                    later.path,
                    later.path,
                    early.path,
                    later.path
                ),
            ));
        }
    }
    Ok(())
}

/// The field `steps` reach in `root`, in full (`hinges[hinge].clearance.clearance_mm`): array
/// items by their name where they have one.
fn field_text(root: &serde_json::Value, steps: &[Step]) -> String {
    let mut text = String::new();
    let mut cur = root;
    for step in steps {
        match step {
            Step::Key(k) => {
                if !text.is_empty() {
                    text.push('.');
                }
                text.push_str(k);
                cur = &cur[k.as_str()];
            }
            Step::Index(i) => {
                cur = &cur[*i];
                match cur.get("name").and_then(|n| n.as_str()) {
                    Some(name) => text.push_str(&format!("[{name}]")),
                    None => text.push_str(&format!("[{i}]")),
                }
            }
        }
    }
    text
}

/// Refuses a scalar written over a group of settings (`--set run=5`): only one of its fields
/// can be meant. A law (an enum) may be replaced by a bare name or an object, and an optional
/// group by `null`.
fn check_group(path: &str, slot: &serde_json::Value, new: &serde_json::Value) -> Result<()> {
    let Some(fields) = slot.as_object() else {
        return Ok(());
    };
    let is_enum = fields.len() == 1
        && fields
            .keys()
            .next()
            .is_some_and(|k| k.starts_with(|c: char| c.is_ascii_uppercase()));
    if is_enum || new.is_object() || new.is_null() {
        return Ok(());
    }
    let names: Vec<&str> = fields.keys().map(String::as_str).collect();
    let example = names.first().copied().unwrap_or("field");
    Err(Error::invalid(
        path,
        format!(
            "is a group of settings ({}): set one of them, e.g. `{path}.{example}=VALUE`",
            names.join(", ")
        ),
    ))
}

/// One step of a path into the scene's JSON: an object key or an array index.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Step {
    Key(String),
    Index(usize),
}

/// Writes out the clearance fields a scene leaves unwritten at their defaults (`model`,
/// `restitution`, a clearance hinge's `journal_offset_mm`: skipped so that a scene written back reads as before), so that overrides can
/// name them.
fn with_skipped_defaults(root: &mut serde_json::Value) {
    // `run.sub_cycle` is left out while all its techniques are on: written here so that an
    // override can reach its switches (`run.sub_cycle.implicit_friction=false`).
    if let Some(run) = root.get_mut("run").and_then(|r| r.as_object_mut()) {
        run.entry("sub_cycle").or_insert_with(|| {
            serde_json::to_value(crate::rapier::joint::SubCycleTechniques::default())
                .unwrap_or(serde_json::Value::Null)
        });
    }
    let Some(hinges) = root.get_mut("hinges").and_then(|h| h.as_array_mut()) else {
        return;
    };
    for h in hinges.iter_mut().filter_map(|h| h.as_object_mut()) {
        if h.get("clearance").is_some_and(|c| !c.is_null()) {
            h.entry("journal_offset_mm")
                .or_insert_with(|| serde_json::json!([0.0, 0.0, 0.0]));
        }
    }
    let clearances = hinges
        .iter_mut()
        .filter_map(|h| h.get_mut("clearance").and_then(|c| c.as_object_mut()));
    for c in clearances {
        c.entry("model").or_insert_with(|| "Compliant".into());
        c.entry("restitution").or_insert(serde_json::Value::Null);
    }
}

/// The JSON slot `steps` reach (found by [`locate_steps`] in this very value).
fn slot_at<'a>(root: &'a mut serde_json::Value, steps: &[Step]) -> &'a mut serde_json::Value {
    let mut cur = root;
    for step in steps {
        cur = match step {
            Step::Key(k) => cur.get_mut(k.as_str()),
            Step::Index(i) => cur.get_mut(*i),
        }
        .expect("path just resolved");
    }
    cur
}

/// The steps from the root to the slot an override path names (see [`Scene::with_overrides`]).
/// The first segment is a top-level field, the name of a body, hinge, joint or drive, or
/// `bodies[name]`, `hinges[name]`, `joints[name]`, `drives[name]` (the form error messages use).
/// A name that is also a top-level field (a body called `run`) is taken where the rest of the
/// path exists.
fn locate_steps(root: &serde_json::Value, path: &str) -> Result<Vec<Step>> {
    let unknown = |reason: String| Error::invalid(path, reason);
    let mut segments = path.split('.');
    let first = segments
        .next()
        .filter(|s| !s.is_empty())
        .ok_or_else(|| unknown("empty parameter path".into()))?;
    let rest: Vec<&str> = segments.collect();
    let obj = root
        .as_object()
        .ok_or_else(|| unknown("scene is not an object".into()))?;
    let item = |list: &str, name: &str| -> Option<Vec<Step>> {
        let items = obj.get(list)?.as_array()?;
        let i = items
            .iter()
            .position(|it| it.get("name").and_then(|n| n.as_str()) == Some(name))?;
        Some(vec![Step::Key(list.to_string()), Step::Index(i)])
    };
    let mut starts: Vec<(String, Vec<Step>)> = Vec::new();
    if let Some((list, name)) = first
        .strip_suffix(']')
        .and_then(|f| f.split_once('['))
        .filter(|(l, _)| ["bodies", "hinges", "joints", "drives"].contains(l))
    {
        let start = item(list, name).ok_or_else(|| {
            let what = match list {
                "bodies" => "body",
                "hinges" => "hinge",
                "joints" => "joint",
                _ => "drive",
            };
            unknown(format!("no {what} named `{name}`"))
        })?;
        starts.push((format!("{list}[{name}]"), start));
    } else {
        if obj.contains_key(first) {
            starts.push((
                format!("the top-level field `{first}`"),
                vec![Step::Key(first.to_string())],
            ));
        }
        for (list, what) in [
            ("bodies", "body"),
            ("hinges", "hinge"),
            ("joints", "joint"),
            ("drives", "drive"),
        ] {
            if let Some(start) = item(list, first) {
                starts.push((format!("the {what} `{first}` ({list}[{first}])"), start));
            }
        }
    }
    if starts.is_empty() {
        return Err(unknown(format!(
            "`{first}` is neither a top-level field nor the name of a body, hinge, joint or drive"
        )));
    }
    let resolved: Vec<(String, std::result::Result<Vec<Step>, String>)> = starts
        .into_iter()
        .map(|(what, start)| {
            let found = resolve(root_at(root, &start), &rest).map(|tail| {
                let mut steps = start;
                steps.extend(tail);
                steps
            });
            (what, found)
        })
        .collect();
    let ok: Vec<&(String, std::result::Result<Vec<Step>, String>)> =
        resolved.iter().filter(|(_, r)| r.is_ok()).collect();
    let steps = match ok.as_slice() {
        [(_, Ok(steps))] => steps.clone(),
        [] => {
            let (_, Err(reason)) = &resolved[0] else {
                unreachable!("no start resolved")
            };
            return Err(unknown(reason.clone()));
        }
        several => {
            return Err(unknown(format!(
                "`{first}` names {}: write `{}.{}` for the body, hinge or drive, or rename it",
                several
                    .iter()
                    .map(|(w, _)| w.as_str())
                    .collect::<Vec<_>>()
                    .join(" and "),
                several
                    .iter()
                    .find_map(|(w, _)| w.split_once('(').map(|(_, p)| p.trim_end_matches(')')))
                    .unwrap_or(first),
                rest.join(".")
            )));
        }
    };
    Ok(steps)
}

fn root_at<'a>(root: &'a serde_json::Value, steps: &[Step]) -> &'a serde_json::Value {
    let mut cur = root;
    for step in steps {
        cur = match step {
            Step::Key(k) => &cur[k.as_str()],
            Step::Index(i) => &cur[*i],
        };
    }
    cur
}

/// The steps below `v` to the field named by `segments`, each segment a direct child or the
/// unique field of that name at any depth.
fn resolve(v: &serde_json::Value, segments: &[&str]) -> std::result::Result<Vec<Step>, String> {
    let mut steps = Vec::new();
    let mut cur = v;
    for seg in segments {
        let found = descend(cur, seg)?;
        for k in found {
            cur = &cur[k.as_str()];
            steps.push(Step::Key(k));
        }
    }
    Ok(steps)
}

/// The key path to the child `key` of `v`, or to the unique field called `key` at any depth below it.
fn descend(v: &serde_json::Value, key: &str) -> std::result::Result<Vec<String>, String> {
    fn paths(
        v: &serde_json::Value,
        key: &str,
        prefix: &mut Vec<String>,
        out: &mut Vec<Vec<String>>,
    ) {
        if let Some(o) = v.as_object() {
            for (k, child) in o {
                prefix.push(k.clone());
                if k == key {
                    out.push(prefix.clone());
                }
                paths(child, key, prefix, out);
                prefix.pop();
            }
        }
    }
    if v.get(key).is_some() {
        return Ok(vec![key.to_string()]);
    }
    let mut found = Vec::new();
    paths(v, key, &mut Vec::new(), &mut found);
    match found.len() {
        0 => Err(format!(
            "no field `{key}` here (is the hinge ideal, or the name misspelt?)"
        )),
        1 => Ok(found.remove(0)),
        _ => Err(format!(
            "`{key}` is ambiguous: {}",
            found
                .iter()
                .map(|p| p.join("."))
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LAW: &str =
        r#"hinge.contact={"ImprovedLiu":{"exponent":1.0,"delta_max_mm":0.1,"eta_s":0.01}}"#;

    fn exponent(scene: &Scene) -> String {
        let c = serde_json::to_value(&scene.hinges[0].clearance).unwrap();
        c["contact"]["ImprovedLiu"]["exponent"].to_string()
    }

    /// A law and then a field inside it: applied in order, the field set inside the new law.
    #[test]
    fn a_field_after_its_law_is_set_inside_it() {
        let s = Scene::solar_panel()
            .with_overrides(&[LAW, "hinge.exponent=1.5"])
            .unwrap();
        assert_eq!(exponent(&s), "1.5");
    }

    /// A field and then the law holding it: the field's value would be lost, so both are named.
    #[test]
    fn a_field_before_its_law_is_refused_naming_both() {
        let e = Scene::solar_panel()
            .refuse_lost_overrides::<&str, _>(&[], &["hinge.exponent=1.5", LAW])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`hinge.exponent`")
                && e.contains("`hinge.contact`")
                && e.contains("hinges[hinge].clearance.contact.ImprovedLiu.exponent")
                && e.contains("lost"),
            "{e}"
        );
        // An earlier list (a study's settings) may be replaced; the same field twice is fine.
        Scene::solar_panel()
            .refuse_lost_overrides(&["hinge.exponent=1.5"], &[LAW])
            .unwrap();
        Scene::solar_panel()
            .refuse_lost_overrides::<&str, _>(&[], &[LAW, "hinge.exponent=2"])
            .unwrap();
        // The same field twice: the later value holds.
        let s = Scene::solar_panel()
            .with_overrides(&["hinge.exponent=1.5", "hinge.exponent=2"])
            .unwrap();
        assert_eq!(exponent(&s), "2.0");
    }

    /// Each override's field is found where the earlier ones left the scene.
    #[test]
    fn fields_are_found_in_order() {
        let fields = Scene::solar_panel()
            .override_fields(&[LAW, "hinge.exponent=2"])
            .unwrap();
        assert_eq!(
            fields,
            [
                "hinges[hinge].clearance.contact",
                "hinges[hinge].clearance.contact.ImprovedLiu.exponent"
            ]
        );
        assert!(field_within(&fields[1], &fields[0]));
        assert!(!field_within(&fields[0], &fields[1]));
        assert!(!field_within(&fields[0], &fields[0]));
        assert!(field_within("hinges[hinge].point_m", "hinges"));
        assert!(!field_within("hinges[hinge2].point_m", "hinges[hinge]"));
    }
}
