//! The page: the viewer with a recording, its impacts and the plotted series inside, one
//! self-contained HTML file.

use super::record::{JournalFrame, Recording, ReplayBody, ReplayFrame, ReplayJournal, ReplayPin};
use super::series::{Series, round_decimals, round_sig};
use super::{FILE, SPATIAL_NUMBERS};
use crate::process::files::write_atomic_with;
use clearance_joint::error::{Error, Result};
use serde::Serialize;
use std::io::Write;
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
    t: Frames<'a>,
    poses: Frames<'a>,
    jf: Frames<'a>,
    contact: Frames<'a>,
    /// Per journal: whether it is spatial (its frames carry `sf`).
    spatial: Vec<bool>,
    /// Per frame and journal, [`SPATIAL_NUMBERS`] numbers (zeros for a planar journal); absent
    /// when no journal is spatial.
    #[serde(skip_serializing_if = "Option::is_none")]
    sf: Option<Frames<'a>>,
    impacts: Vec<Impact>,
    series: &'a [Series],
    default_speed: f64,
}

/// One of the page's per-frame arrays, serialized straight from the frames (the JSON of the
/// numbers a flattened copy would hold, without the copy).
struct Frames<'a> {
    frames: &'a [ReplayFrame],
    column: Column,
}

/// What a [`Frames`] array holds, frame after frame.
#[derive(Clone, Copy)]
enum Column {
    /// The time, in full.
    Time,
    /// Each body's pose: positions to 0.1 um and quaternions to 1e-7 (a rotation of 0.2 urad).
    Poses,
    /// Each journal's eccentricity, force, magnitude and penetration, 7 significant digits.
    Journals,
    /// Each journal's contact flag, 0 or 1.
    Contact,
    /// Each journal's [`SPATIAL_NUMBERS`], 7 significant digits.
    Spatial,
}

impl Serialize for Frames<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let frames = self.frames.iter();
        match self.column {
            Column::Time => s.collect_seq(frames.map(|f| f.t)),
            Column::Poses => s.collect_seq(
                frames.flat_map(|f| f.poses.iter().flat_map(|p| p.map(|x| round_decimals(x, 7)))),
            ),
            Column::Journals => s.collect_seq(frames.flat_map(|f| {
                f.journals.iter().flat_map(|j| {
                    [
                        j.ecc_u_m,
                        j.ecc_v_m,
                        j.force_u_n,
                        j.force_v_n,
                        j.force_n,
                        j.penetration_m,
                    ]
                    .map(|x| round_sig(x, 7))
                })
            })),
            Column::Contact => {
                s.collect_seq(frames.flat_map(|f| f.journals.iter().map(|j| j.contact as u8)))
            }
            Column::Spatial => s.collect_seq(frames.flat_map(|f| {
                f.journals
                    .iter()
                    .flat_map(|j| spatial_numbers(j).map(|x| round_sig(x, 7)))
            })),
        }
    }
}

impl ReplayPage<'_> {
    /// The page's HTML: the viewer with the data inside (no external resource).
    pub fn html(&self) -> Result<String> {
        let r = self.recording;
        non_empty(r)?;
        // The numbers' text is at most about 24 bytes each; capacity never written is never
        // touched.
        let per_frame = 1 + r.bodies.len() * 7 + r.journals.len() * (7 + SPATIAL_NUMBERS);
        let mut page = Vec::with_capacity(TEMPLATE.len() + 24 * per_frame * r.frames.len());
        self.write_html(&mut page)
            .map_err(|e| Error::invalid("replay", e.to_string()))?;
        String::from_utf8(page).map_err(|e| Error::invalid("replay", e.to_string()))
    }

    /// Writes the page's HTML into `w` (a recording with frames), the data serialized straight
    /// from the recording: no copy of its frames or of the page's text is held.
    fn write_html(&self, w: &mut dyn Write) -> std::io::Result<()> {
        let r = self.recording;
        let column = |column| Frames {
            frames: &r.frames,
            column,
        };
        let spatial = spatial_journals(r);
        let sf = spatial.iter().any(|&b| b).then(|| column(Column::Spatial));
        let impacts = r
            .frames
            .iter()
            .flat_map(|f| {
                f.journals
                    .iter()
                    .enumerate()
                    .filter(|(_, j)| j.impact)
                    .map(|(journal, _)| Impact { t: f.t, journal })
            })
            .collect();
        // Speed: the whole run in about 20 s of wall time (a preset of the menu).
        let span = r.frames[r.frames.len() - 1].t - r.frames[0].t;
        let default_speed = [
            0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0,
        ]
        .into_iter()
        .find(|&s| span / s <= 25.0)
        .unwrap_or(2.0);
        let data = PageData {
            title: &self.title,
            subtitle: &self.subtitle,
            notes: &self.notes,
            bodies: &r.bodies,
            journals: &r.journals,
            pins: &r.pins,
            t: column(Column::Time),
            poses: column(Column::Poses),
            jf: column(Column::Journals),
            contact: column(Column::Contact),
            spatial,
            sf,
            impacts,
            series: &self.series,
            default_speed,
        };
        // The data (megabytes) is serialized into the page as it goes, after the head; no pass
        // searches it for `</` (only its strings can hold one, and [`ScriptSafe`] escapes it
        // there).
        let (head, rest) = TEMPLATE.split_once("__TITLE__").unwrap_or((TEMPLATE, ""));
        let (middle, tail) = rest.split_once("__DATA__").unwrap_or((rest, ""));
        // The serializer's many small writes go to a buffer of its own, passed on in large
        // blocks (a `dyn` writer's call per number would cost more than the number).
        let mut w = std::io::BufWriter::with_capacity(1 << 16, w);
        w.write_all(head.as_bytes())?;
        w.write_all(escape_html(&self.title).as_bytes())?;
        w.write_all(middle.as_bytes())?;
        data.serialize(&mut serde_json::Serializer::with_formatter(
            &mut w, ScriptSafe,
        ))?;
        w.write_all(tail.as_bytes())?;
        w.flush()
    }

    /// Writes the page to `dir/replay.html` (atomically, streamed into the file) and returns
    /// its path.
    pub fn write(&self, dir: &Path) -> Result<PathBuf> {
        let path = dir.join(FILE);
        non_empty(self.recording)?;
        write_atomic_with(&path, |w| {
            self.write_html(w).map_err(|source| Error::Io {
                action: "cannot write",
                path: path.clone(),
                source,
            })
        })?;
        Ok(path)
    }
}

/// A page needs a frame at least.
fn non_empty(r: &Recording) -> Result<()> {
    if r.frames.is_empty() {
        return Err(Error::invalid("replay", "the recording holds no frame"));
    }
    Ok(())
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
    use super::*;
    use crate::replay::record::SpatialFrame;

    /// The page's data as a plain structure of flattened arrays: what the page's JSON must be.
    #[derive(Serialize)]
    struct Flat<'a> {
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
        spatial: Vec<bool>,
        #[serde(skip_serializing_if = "Vec::is_empty")]
        sf: Vec<f64>,
        impacts: Vec<Impact>,
        series: &'a [Series],
        default_speed: f64,
    }

    fn flat<'a>(page: &'a ReplayPage<'_>, default_speed: f64) -> Flat<'a> {
        let r = page.recording;
        let spatial = spatial_journals(r);
        let any = spatial.iter().any(|&b| b);
        let mut flat = Flat {
            title: &page.title,
            subtitle: &page.subtitle,
            notes: &page.notes,
            bodies: &r.bodies,
            journals: &r.journals,
            pins: &r.pins,
            t: Vec::new(),
            poses: Vec::new(),
            jf: Vec::new(),
            contact: Vec::new(),
            spatial,
            sf: Vec::new(),
            impacts: Vec::new(),
            series: &page.series,
            default_speed,
        };
        for f in &r.frames {
            flat.t.push(f.t);
            for p in &f.poses {
                flat.poses.extend(p.map(|x| round_decimals(x, 7)));
            }
            for (k, j) in f.journals.iter().enumerate() {
                let values = [
                    j.ecc_u_m,
                    j.ecc_v_m,
                    j.force_u_n,
                    j.force_v_n,
                    j.force_n,
                    j.penetration_m,
                ];
                flat.jf.extend(values.map(|x| round_sig(x, 7)));
                flat.contact.push(j.contact as u8);
                if any {
                    flat.sf.extend(spatial_numbers(j).map(|x| round_sig(x, 7)));
                }
                if j.impact {
                    flat.impacts.push(Impact { t: f.t, journal: k });
                }
            }
        }
        flat
    }

    /// The page's data, streamed from the frames, is the JSON of its flattened arrays (planar
    /// and spatial journals, impacts, a non-finite value and a string closing its tag).
    #[test]
    fn the_streamed_data_is_the_json_of_the_flattened_frames() {
        let journal = |k: f64, spatial: bool| JournalFrame {
            ecc_u_m: 1.234_567_89e-4 * k,
            ecc_v_m: -2.5e-5 * k,
            force_u_n: 12.345_678_9 * k,
            force_v_n: f64::NAN,
            force_n: 123.456_789 * k,
            penetration_m: 1e-7 * k,
            contact: k > 1.0,
            impact: k == 2.0,
            spatial: spatial.then(|| SpatialFrame {
                tilt_rad: [1e-3 * k, -2e-3],
                axial_m: 3e-5,
                edge_force_n: [4.0 * k, 0.0],
                edge_at_m: [[1e-3, 2e-3, -5e-3], [0.0, 0.0, 5e-3]],
                face_force_n: [0.0, 7.5],
                face_at_m: [[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]],
            }),
        };
        let frames: Vec<ReplayFrame> = (0..5)
            .map(|k| ReplayFrame {
                t: k as f64 * 0.012_345_678_9,
                poses: vec![
                    [
                        0.1 * k as f64,
                        -0.333_333_333_3,
                        2.0,
                        0.0,
                        0.0,
                        std::f64::consts::FRAC_1_SQRT_2,
                        std::f64::consts::FRAC_1_SQRT_2,
                    ],
                    [1e-9, 0.0, -0.0, 1.0, 0.0, 0.0, 0.0],
                ],
                journals: vec![journal(k as f64, false), journal(k as f64, k % 2 == 0)],
            })
            .collect();
        let track = |name: &str, axial_play_m| ReplayJournal {
            name: name.into(),
            group: "clearance".into(),
            bearing: 0,
            journal: 1,
            anchor1_m: [0.0; 3],
            anchor2_m: [0.0, 0.3, 0.0],
            axis1: [0.0, 0.0, 1.0],
            u1: [1.0, 0.0, 0.0],
            clearance_m: 1e-4,
            bearing_radius_m: 0.01,
            width_m: 0.02,
            axial_play_m,
        };
        let recording = Recording {
            bodies: ["base", "arm"]
                .map(|name| ReplayBody {
                    name: name.into(),
                    group: "clearance".into(),
                    shapes: Vec::new(),
                })
                .into(),
            journals: vec![track("planar", None), track("spatial", Some(2e-4))],
            frames,
            interval_s: 1e-3,
            contact_interval_s: 1e-5,
            ..Recording::default()
        };
        let page = ReplayPage {
            title: "a <b> & </script> title".into(),
            subtitle: "sub".into(),
            notes: "notes </script>".into(),
            recording: &recording,
            series: vec![Series {
                title: "s".into(),
                lines: vec![],
            }],
        };
        let html = page.html().unwrap();
        let json = html
            .split_once("type=\"application/json\">")
            .and_then(|(_, rest)| rest.split_once("</script>"))
            .map(|(json, _)| json)
            .unwrap();
        let span = 4.0 * 0.012_345_678_9;
        let speed = [0.001, 0.002, 0.005, 0.01]
            .into_iter()
            .find(|&s| span / s <= 25.0)
            .unwrap();
        let mut want = Vec::new();
        flat(&page, speed)
            .serialize(&mut serde_json::Serializer::with_formatter(
                &mut want, ScriptSafe,
            ))
            .unwrap();
        assert_eq!(json, String::from_utf8(want).unwrap());
        assert!(
            json.contains("\"sf\":[") && json.contains("\"impacts\":[{"),
            "{json}"
        );
        assert!(html.contains("<title>a &lt;b&gt; &amp; &lt;/script&gt; title</title>"));
        // With no spatial journal there is no `sf`.
        let mut planar = recording.clone();
        for f in &mut planar.frames {
            for j in &mut f.journals {
                j.spatial = None;
            }
        }
        let html = ReplayPage {
            recording: &planar,
            ..page.clone()
        }
        .html()
        .unwrap();
        assert!(!html.contains("\"sf\"") && html.contains("\"spatial\":[false,false]"));
    }

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
