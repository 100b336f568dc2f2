//! The report files in Markdown: a study's `report.md` (setup, tables, figures, the paper's
//! conclusions against our numbers) and the summary of `study all`.

use super::setup::Setup;
use super::tables::{key_tables, list, num};
use super::timeline::Timeline;
use super::verdict::{ANGLE_SLIGHT, Conclusion, EQUAL_TOL, FORCE_STRONG, RATE_VISIBLE, Verdict};
use crate::figures::FigureKind;
use crate::study::case::StudyCase;
use crate::study::preset::{Study, StudyKind};
use clearance_joint::scene::runner::convergence::ConvergenceVerdict;
use std::fmt::Write as _;

/// The caption of a study's figure, citing the paper's figure for one of its studies.
fn figure_caption(study: &Study, f: FigureKind) -> String {
    let cite = |i: usize| {
        study
            .paper_figures()
            .map_or(String::new(), |n| format!(" (paper fig. {})", n[i]))
    };
    match f {
        FigureKind::AnglesRates => format!(
            "Angles and angular rates of the bodies vs time, each case with the ideal joint dashed{}.",
            cite(0)
        ),
        FigureKind::Force => format!(
            "Joint reaction force vs time: ideal joint (left, its own scale) and clearance joint (right); each column shares its scale{}. Lines keep the minimum and maximum of every pixel column, so no peak is lost.",
            cite(1)
        ),
        FigureKind::Trajectory => format!(
            "Journal-centre trajectory in the bearing frame, drawn to scale with the clearance circle |e| = c{}.",
            cite(2)
        ),
    }
}

/// Why a report judges none of the paper's conclusions.
fn not_judged(study: &Study, scene: &str) -> String {
    if study.spec.paper {
        format!(
            "Not judged: the preset is one of the paper's studies, but scene `{scene}` is not the paper's scene \
             (`assets/solar_panel.ron`: its bodies, hinges, drives, gravity and axis), and the paper's conclusions \
             (MODEL.md §5) are about that scene."
        )
    } else {
        "Not judged: the paper's conclusions (MODEL.md §5) are about its scene and its three studies (`study \
         clearance|torque|friction` on `assets/solar_panel.ron`), and this preset is not one of them."
            .to_string()
    }
}

/// The whole `report.md` of a study. `conclusions` are the paper's, judged only for one of the
/// paper's studies on its scene ([`Study::paper`]); any other report says why it has none.
pub fn study_report(
    study: &Study,
    setup: &Setup,
    cases: &[StudyCase],
    figures: &[(FigureKind, String)],
    conclusions: &[Conclusion],
    timeline: Option<&Timeline>,
) -> String {
    let cases = &escaped(cases);
    let mut s = String::new();
    let name = study.name();
    let _ = writeln!(s, "# {name} study: {}\n", study.title());
    if study.paper {
        let _ = writeln!(
            s,
            "Written by `cargo run --release -- study {name}` (or `study all`); regenerated on every run, do not edit. \
             Model: the project's specification MODEL.md (§4, the paper's scene). \
             Nothing in the model is tuned to agree with the paper.\n"
        );
    } else {
        let _ = writeln!(
            s,
            "Written by `cargo run --release -- study {name} --scene FILE` (or `study all`) for scene `{}`, from {}; \
             regenerated on every run, do not edit.\n",
            setup.scene,
            if study.declared {
                format!("the preset `{name}` its file declares")
            } else {
                format!("the paper's preset `{name}` (the scene declares none)")
            }
        );
    }
    let _ = writeln!(s, "## Setup\n");
    let _ = writeln!(
        s,
        "- Scene `{}`; swept `{}` = {}.",
        setup.scene,
        setup.axis,
        cases
            .iter()
            .map(|c| format!("{} ({})", c.value, c.label))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(
        s,
        "- Fixed overrides: {}.",
        if setup.overrides.is_empty() {
            "none".to_string()
        } else {
            setup
                .overrides
                .iter()
                .map(|o| format!("`{o}`"))
                .collect::<Vec<_>>()
                .join(", ")
        }
    );
    let _ = writeln!(
        s,
        "- The same step control for every case: {}; rows every {:e} s, {} s simulated, ideal and clearance twins in one world.",
        setup.stepping, setup.output_interval_s, setup.end_s
    );
    if study.paper && study.kind == StudyKind::Torque {
        let _ = writeln!(
            s,
            "- The paper's fixed step of 1e-4 s under-resolves the stronger impacts (`study torque --set run.step=Fixed` \
             gives their first-impact peaks against these), and it is longer than friction's limit near zero slip (a \
             guard violation). Adaptive steps shorten inside contacts as the contact requires, so the three cases run \
             with the same step control as the other studies."
        );
    }
    let _ = writeln!(
        s,
        "- Metrics (table `metrics.csv` / `metrics.json`): onsets and impacts (after a separation; the chatter is the difference), peak and RMS force, first impact, settling time, contact \
         fraction, penetration and rate deviations come from every internal step; angle deviation, force decay time, journal \
         path and contact arc from the output rows. **Settling time** (runner): the last time the clearance joint force exceeds \
         the ideal joint force by more than a band equal to the ideal twin's peak joint force. **Force decay**: the last time \
         the clearance force exceeds 10 % of its own peak. **Contact arc**: the smallest arc of the bearing holding every \
         contact position.\n"
    );
    let _ = writeln!(s, "## Results\n");
    s.push_str(&key_tables(cases, setup));
    s.push('\n');
    // Run-time guards: a case outside the model's validity says so here, not only in its files.
    let flagged: Vec<&StudyCase> = cases
        .iter()
        .filter(|c| !c.metrics.guard_violations.is_empty())
        .collect();
    if flagged.is_empty() {
        let _ = writeln!(
            s,
            "Run-time guards: every case stayed valid (no penetration beyond its law's validity, no \
             energy gained, no step at the floor); rejected and retried steps: {}.\n",
            list(cases, |c| c.metrics.rejected_steps.to_string())
        );
    } else {
        let _ = writeln!(
            s,
            "**Run-time guards violated** (see each case's `summary.json`):\n"
        );
        for c in flagged {
            let _ = writeln!(
                s,
                "- {}: {}",
                c.label,
                c.metrics.guard_violations.join("; ")
            );
        }
        s.push('\n');
    }
    s.push_str(&convergence_section(cases));
    if let Some(tl) = timeline {
        let _ = writeln!(
            s,
            "Contact onsets per {} s window, counted from the output rows:\n",
            num(tl.window_s)
        );
        let labels: Vec<String> = cases.iter().map(|c| c.label.clone()).collect();
        s.push_str(&tl.table(&labels));
        s.push('\n');
    }
    if !figures.is_empty() {
        let _ = writeln!(s, "## Figures\n");
        for (f, stem) in figures {
            let _ = writeln!(
                s,
                "![{}]({stem}.png)\n\n{} SVG: [`{stem}.svg`]({stem}.svg).\n",
                f.stem(),
                figure_caption(study, *f)
            );
        }
    }
    if !study.paper {
        let _ = writeln!(
            s,
            "## The paper's conclusions\n\n{}",
            not_judged(study, &setup.scene)
        );
        return s;
    }
    let _ = writeln!(s, "## The paper's conclusions against our numbers\n");
    let _ = writeln!(
        s,
        "Criteria (ours: the paper states none): values within {} % of each other count as equal; \"angles barely change\" \
         means a largest angle deviation below {} % of the ideal deployment; \"rates visibly change\" a largest rate deviation \
         above {} % of the mean ideal rate; \"force strongly changes\" a clearance peak above {}x the ideal peak; a trend \
         \"increases\" only if every step up the list increases.\n",
        100.0 * EQUAL_TOL,
        100.0 * ANGLE_SLIGHT,
        100.0 * RATE_VISIBLE,
        FORCE_STRONG
    );
    for c in conclusions {
        let _ = writeln!(
            s,
            "{}. **Paper:** {}\n   **Ours ({}):** {}\n",
            c.number,
            c.paper,
            c.verdict.text(),
            c.finding
        );
    }
    s
}

/// The convergence of every case, one line each: which metrics converged against the case at
/// half its tolerance, the worst of those that did not, and what the check cost; or why a case
/// was not checked.
fn convergence_section(cases: &[StudyCase]) -> String {
    let mut s = String::from(
        "Convergence (each case against itself at half the tolerance, the clearance twin only: \
         each clearance hinge's first impact and its peak, largest force and penetration, onsets, \
         impacts after a separation, contact fraction and final angle, each held to its bound; \
         `--no-check` skips it; the metrics per case in its `summary.json`):\n\n",
    );
    for c in cases {
        let v = &c.metrics.convergence;
        let _ = write!(s, "- {}: {}", c.label, md_cell(&v.describe()));
        if let ConvergenceVerdict::Checked { cost, .. } = v {
            let _ = write!(s, "; the check {}", cost.describe());
        }
        s.push('\n');
    }
    s.push('\n');
    s
}

/// What the summary of `study all` shows of one finished study.
#[derive(Clone, Copy, Debug)]
pub struct IndexEntry<'a> {
    /// Which study.
    pub study: &'a Study,
    /// Its settings.
    pub setup: &'a Setup,
    /// Its cases.
    pub cases: &'a [StudyCase],
    /// Its verdicts on the paper's conclusions (none unless [`Study::paper`]).
    pub conclusions: &'a [Conclusion],
}

/// `report.md` of `study all`: each study's key tables and verdicts, with links.
pub fn index_report(entries: &[IndexEntry]) -> String {
    let mut s = if entries.iter().all(|e| e.study.paper) {
        String::from(
            "# The paper's studies: summary\n\nWritten by `cargo run --release -- study all`; each study's own report has its figures and full findings.\n\n",
        )
    } else {
        format!(
            "# Studies of scene `{}`: summary\n\nWritten by `cargo run --release -- study all --scene FILE`; each study's own report has its figures and full findings.\n\n",
            entries.first().map_or("", |e| e.setup.scene.as_str())
        )
    };
    for o in entries {
        let name = o.study.name();
        let _ = writeln!(
            s,
            "## {} study: [{name}/report.md]({name}/report.md)\n",
            name
        );
        let _ = writeln!(s, "{}, {} s simulated.\n", o.setup.stepping, o.setup.end_s);
        s.push_str(&key_tables(&escaped(o.cases), o.setup));
        s.push('\n');
        let _ = writeln!(
            s,
            "Convergence: {}.\n",
            o.cases
                .iter()
                .map(|c| format!(
                    "{} {}",
                    md_cell(&c.label),
                    md_cell(&c.metrics.convergence.describe())
                ))
                .collect::<Vec<_>>()
                .join("; ")
        );
        for c in o
            .conclusions
            .iter()
            .filter(|c| c.verdict != Verdict::NotTested)
        {
            let _ = writeln!(
                s,
                "- Conclusion {} ({}): {}",
                c.number,
                c.verdict.text(),
                c.finding
            );
        }
        s.push('\n');
    }
    s
}

/// Text safe in a Markdown table cell or list item: `|` escaped, line breaks as spaces.
pub fn md_cell(text: &str) -> String {
    text.replace("\r\n", " ")
        .replace(['\n', '\r'], " ")
        .replace('|', "\\|")
}

/// The cases with labels and values safe in the report's tables ([`md_cell`]).
fn escaped(cases: &[StudyCase]) -> Vec<StudyCase> {
    cases
        .iter()
        .map(|c| StudyCase {
            label: md_cell(&c.label),
            value: md_cell(&c.value),
            ..c.clone()
        })
        .collect()
}
