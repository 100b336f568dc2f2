//! The page: the viewer with a recording, its impacts and the plotted series inside, one
//! self-contained HTML file.

use super::record::{JournalFrame, Recording, ReplayBody, ReplayJournal, ReplayPin};
use super::series::{Series, round_decimals, round_sig};
use super::{FILE, SPATIAL_NUMBERS};
use crate::process::files::write_atomic;
use clearance_joint::error::{Error, Result};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The viewer: the page's HTML with `__TITLE__` and `__DATA__` to fill.
pub(super) const TEMPLATE: &str = include_str!("../../assets/replay/replay.html");

/// A replay page: a recording, impacts, plotted series and captions.
#[derive(Clone, Debug)]
pub struct ReplayPage<'a> {
    /// Page title.
    pub title: String,
    /// Line under the title (settings).
    pub subtitle: String,
    /// Notes under the plots (thinning rule, sources).
    pub notes: String,
    /// What was recorded.
    pub recording: &'a Recording,
    /// Plotted series.
    pub series: Vec<Series>,
}

#[derive(Serialize)]
struct Impact {
    t: f64,
    journal: usize,
}

#[derive(Serialize)]
struct PageData<'a> {
    title: &'a str,
    subtitle: &'a str,
    notes: &'a str,
    bodies: &'a [ReplayBody],
    journals: &'a [ReplayJournal],
    pins: &'a [ReplayPin],
    t: Vec<f64>,
    poses: Vec<f64>,
    jf: Vec<f64>,
    contact: Vec<u8>,
    /// Per journal: whether it is spatial (its frames carry `sf`).
    spatial: Vec<bool>,
    /// Per frame and journal, [`SPATIAL_NUMBERS`] numbers (zeros for a planar journal); empty
    /// when no journal is spatial.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    sf: Vec<f64>,
    impacts: Vec<Impact>,
    series: &'a [Series],
    default_speed: f64,
}

impl ReplayPage<'_> {
    /// The page's HTML: the viewer with the data inside (no external resource).
    pub fn html(&self) -> Result<String> {
        String::from_utf8(self.html_bytes()?).map_err(|e| Error::invalid("replay", e.to_string()))
    }

    /// [`html`](Self::html) as bytes: the data serialized straight into the page.
    fn html_bytes(&self) -> Result<Vec<u8>> {
        let r = self.recording;
        if r.frames.is_empty() {
            return Err(Error::invalid("replay", "the recording holds no frame"));
        }
        let mut data = PageData {
            title: &self.title,
            subtitle: &self.subtitle,
            notes: &self.notes,
            bodies: &r.bodies,
            journals: &r.journals,
            pins: &r.pins,
            t: Vec::with_capacity(r.frames.len()),
            poses: Vec::new(),
            jf: Vec::new(),
            contact: Vec::new(),
            spatial: spatial_journals(r),
            sf: Vec::new(),
            impacts: Vec::new(),
            series: &self.series,
            default_speed: 0.0,
        };
        for f in &r.frames {
            data.t.push(f.t);
            // Positions to 0.1 um and quaternions to 1e-7 (a rotation of 0.2 urad).
            for p in &f.poses {
                data.poses.extend(p.iter().map(|&x| round_decimals(x, 7)));
            }
            for (k, j) in f.journals.iter().enumerate() {
                data.jf.extend(
                    [
                        j.ecc_u_m,
                        j.ecc_v_m,
                        j.force_u_n,
                        j.force_v_n,
                        j.force_n,
                        j.penetration_m,
                    ]
                    .map(|x| round_sig(x, 7)),
                );
                data.contact.push(j.contact as u8);
                if data.spatial.iter().any(|&b| b) {
                    data.sf.extend(spatial_numbers(j).map(|x| round_sig(x, 7)));
                }
                if j.impact {
                    data.impacts.push(Impact { t: f.t, journal: k });
                }
            }
        }
        // Speed: the whole run in about 20 s of wall time (a preset of the menu).
        let span = r.frames[r.frames.len() - 1].t - r.frames[0].t;
        data.default_speed = [
            0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0,
        ]
        .into_iter()
        .find(|&s| span / s <= 25.0)
        .unwrap_or(2.0);
        // The data (megabytes) is serialized into the page's own buffer, after the head: no
        // copy of it is held, and no pass searches it for `</` (only its strings can hold one,
        // and [`ScriptSafe`] escapes it there).
        let (head, rest) = TEMPLATE.split_once("__TITLE__").unwrap_or((TEMPLATE, ""));
        let (middle, tail) = rest.split_once("__DATA__").unwrap_or((rest, ""));
        let title = escape_html(&self.title);
        // The numbers' text is at most about 24 bytes each; capacity never written is never
        // touched.
        let numbers = data.t.len() + data.poses.len() + data.jf.len() + data.sf.len();
        let mut page = Vec::with_capacity(TEMPLATE.len() + title.len() + 24 * numbers + 64);
        page.extend_from_slice(head.as_bytes());
        page.extend_from_slice(title.as_bytes());
        page.extend_from_slice(middle.as_bytes());
        data.serialize(&mut serde_json::Serializer::with_formatter(
            &mut page, ScriptSafe,
        ))
        .map_err(|e| Error::invalid("replay", e.to_string()))?;
        page.extend_from_slice(tail.as_bytes());
        Ok(page)
    }

    /// Writes the page to `dir/replay.html` (atomically) and returns its path.
    pub fn write(&self, dir: &Path) -> Result<PathBuf> {
        let path = dir.join(FILE);
        write_atomic(&path, &self.html_bytes()?)?;
        Ok(path)
    }
}

/// Per journal of `r`: whether any frame carries its spatial part.
fn spatial_journals(r: &Recording) -> Vec<bool> {
    (0..r.journals.len())
        .map(|k| {
            r.frames
                .iter()
                .any(|f| f.journals.get(k).is_some_and(|j| j.spatial.is_some()))
        })
        .collect()
}

/// A journal frame's spatial numbers in the page's order ([`SPATIAL_NUMBERS`]; zeros for a
/// planar journal).
fn spatial_numbers(j: &JournalFrame) -> [f64; SPATIAL_NUMBERS] {
    let s = j.spatial.unwrap_or_default();
    let [e0, e1] = s.edge_at_m;
    let [f0, f1] = s.face_at_m;
    [
        s.tilt_rad[0],
        s.tilt_rad[1],
        s.axial_m,
        s.edge_force_n[0],
        s.edge_force_n[1],
        e0[0],
        e0[1],
        e0[2],
        e1[0],
        e1[1],
        e1[2],
        s.face_force_n[0],
        s.face_force_n[1],
        f0[0],
        f0[1],
        f0[2],
        f1[0],
        f1[1],
        f1[2],
    ]
}

/// JSON as `serde_json::to_string` writes it, but `</` inside strings written `<\/` (the same
/// string to a JSON reader): inside `<script>` the sequence must not appear. Outside strings
/// JSON has no `<`, and `serde_json` escapes neither `<` nor `/`, so a string's `</` is never
/// split between two fragments.
struct ScriptSafe;

impl serde_json::ser::Formatter for ScriptSafe {
    fn write_string_fragment<W: ?Sized + std::io::Write>(
        &mut self,
        writer: &mut W,
        fragment: &str,
    ) -> std::io::Result<()> {
        for (k, part) in fragment.split("</").enumerate() {
            if k > 0 {
                writer.write_all(b"<\\/")?;
            }
            writer.write_all(part.as_bytes())?;
        }
        Ok(())
    }
}

fn escape_html(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::ScriptSafe;
    use serde::Serialize;

    #[test]
    fn script_safe_json_is_serde_json_with_only_strings_closing_tags_escaped() {
        // A `</` right after an escaped quote (a fragment's start), at a string's end, twice
        // in a row, and in a key; numbers beside them.
        let value = serde_json::json!({
            "title": "a</script>b\"</",
            "n": "<</</",
            "x</": [1.5, -0.0, 1e-7, 123456.789],
        });
        let mut out = Vec::new();
        value
            .serialize(&mut serde_json::Serializer::with_formatter(
                &mut out, ScriptSafe,
            ))
            .unwrap();
        let text = String::from_utf8(out).unwrap();
        let plain = serde_json::to_string(&value).unwrap();
        assert!(plain.contains("</"));
        assert_eq!(text, plain.replace("</", "<\\/"));
        let back: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(back, value);
    }
}
