//! The replay in result sets and study reports: a stale page removed, a report's links.

use super::FILE;
use clearance_joint::error::{Error, Result};
use std::path::Path;

/// Removes `dir/replay.html` if present: a result set written without a replay must not keep
/// an older run's.
pub fn remove_stale(dir: &Path) -> Result<()> {
    let path = dir.join(FILE);
    match std::fs::remove_file(&path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(Error::Io {
            action: "cannot remove",
            path,
            source: e,
        }),
        _ => Ok(()),
    }
}

/// The `## Replays` section of a study's report: a link per case whose folder holds a replay
/// (empty when none does).
pub fn report_section(dir: &Path, cases: &[crate::study::case::StudyCase]) -> String {
    let links: Vec<String> = cases
        .iter()
        .filter(|c| c.dir.join(FILE).is_file())
        .map(|c| {
            let rel = c.dir.strip_prefix(dir).unwrap_or(&c.dir).join(FILE);
            let size = std::fs::metadata(c.dir.join(FILE)).map_or(0, |m| m.len());
            format!(
                "- [{}]({}) ({:.1} MB)",
                c.label,
                rel.to_string_lossy().replace('\\', "/"),
                size as f64 / 1e6
            )
        })
        .collect();
    if links.is_empty() {
        return String::new();
    }
    format!(
        "\n## Replays\n\nEach case's run in 3D, ideal and clearance twins side by side, the journal \
         magnified in its bearing, every impact on the timeline (one self-contained file; open it in \
         a browser):\n\n{}\n",
        links.join("\n")
    )
}
