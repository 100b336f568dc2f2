//! `report.md` of a study: setup, metrics tables, figures, and for each of the paper's
//! conclusions (MODEL.md §5) what our numbers show. The verdicts are computed from the metrics
//! with the criteria stated in the report; nothing is tuned to agree with the paper.

use super::metrics::{RunMetrics, Trend};
use super::preset::{StudyCase, StudyKind, StudyOutcome};
use super::sweep::Sweep;
use crate::figures::FigureKind;
use std::fmt::Write as _;

/// Relative tolerance below which two values count as equal in trends and comparisons.
pub const EQUAL_TOL: f64 = 0.005;
/// "Angles barely change": largest angle deviation below this fraction of the ideal deployment.
pub const ANGLE_SLIGHT: f64 = 0.02;
/// "Rates visibly change": largest rate deviation above this fraction of the mean ideal rate.
pub const RATE_VISIBLE: f64 = 0.05;
/// "Force strongly changes": clearance peak force above this multiple of the ideal peak.
pub const FORCE_STRONG: f64 = 10.0;

/// How far our numbers agree with a conclusion of the paper.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Every part of the conclusion appears in our numbers.
    Shown,
    /// Some parts appear, others do not.
    Partly,
    /// No part appears.
    NotShown,
    /// The study does not vary the parameter the conclusion is about.
    NotTested,
    /// The runs hold too few impacts to judge (a run too short): see [`MIN_IMPACTS`].
    TooLittleData,
}

/// Impacts (contact onsets) every case needs before a verdict is given: the conclusions are
/// about impacts, impact forces and the rattle they cause, and a run without them shows none.
pub const MIN_IMPACTS: u64 = 10;

impl Verdict {
    /// Short text for reports.
    pub fn text(self) -> &'static str {
        match self {
            Verdict::Shown => "reproduced",
            Verdict::Partly => "partly reproduced",
            Verdict::NotShown => "not reproduced",
            Verdict::NotTested => "not tested here",
            Verdict::TooLittleData => "too little data to judge",
        }
    }

    fn from_parts(parts: &[bool]) -> Verdict {
        if parts.iter().all(|&p| p) {
            Verdict::Shown
        } else if parts.iter().any(|&p| p) {
            Verdict::Partly
        } else {
            Verdict::NotShown
        }
    }
}

/// One of the paper's conclusions and what our numbers show.
#[derive(Clone, Debug, PartialEq)]
pub struct Conclusion {
    /// Its number in MODEL.md §5.
    pub number: u8,
    /// The paper's statement.
    pub paper: &'static str,
    /// Our verdict.
    pub verdict: Verdict,
    /// What our numbers show, with the numbers.
    pub finding: String,
}

/// The paper's conclusions (MODEL.md §5).
pub const PAPER: [&str; 4] = [
    "Clearance barely changes the angles, visibly changes the angular rates (oscillation around the ideal curve, growing with c), and strongly changes the joint force (impulsive, far above ideal).",
    "Larger clearance: more impacts, slower settling of the contact force.",
    "Higher driving torque (3T, 5T): faster deployment, stronger oscillation, more irregular trajectory.",
    "More friction (dry vs lubricated): smaller joint forces and fewer impacts, faster settling.",
];

/// The run settings and names a report states.
#[derive(Clone, Debug)]
pub struct Setup {
    /// Step, s (the largest step with adaptive stepping).
    pub dt_s: f64,
    /// The step control in words, e.g. "adaptive steps of at most 1e-3 s (tolerance 0.0075 of a contact period)".
    pub stepping: String,
    /// Interval between rows, s.
    pub output_interval_s: f64,
    /// Simulated time, s.
    pub end_s: f64,
    /// Fixed overrides of the study.
    pub overrides: Vec<String>,
    /// Swept path.
    pub axis: String,
    /// Hinge shown (first clearance hinge).
    pub hinge: String,
    /// Movable bodies, the hinge's journal body first.
    pub bodies: Vec<String>,
    /// Base scene name.
    pub scene: String,
}

impl Setup {
    /// The setup of `kind` from its sweep and cases.
    pub fn of(kind: StudyKind, sweep: &Sweep, cases: &[StudyCase]) -> Setup {
        let scene = cases.first().map(|c| &c.scene).unwrap_or(&sweep.base);
        let hinge = scene
            .hinges
            .iter()
            .find(|h| h.clearance.is_some())
            .or(scene.hinges.first());
        let mut bodies: Vec<String> = scene
            .bodies
            .iter()
            .filter(|b| !b.fixed)
            .map(|b| b.name.clone())
            .collect();
        if let Some(h) = hinge {
            bodies.sort_by_key(|b| *b != h.journal);
        }
        let stepping = scene.run.stepping();
        Setup {
            stepping,
            dt_s: scene.run.dt_s,
            output_interval_s: scene.run.output_interval_s,
            end_s: scene.run.end_s,
            overrides: sweep.base_overrides.clone(),
            axis: kind.axis().path,
            hinge: hinge.map(|h| h.name.clone()).unwrap_or_default(),
            bodies,
            scene: sweep.base.name.clone(),
        }
    }
}

/// A number with about four significant digits (scientific below 0.01).
pub fn num(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 {
        "0".into()
    } else if a < 0.01 {
        format!("{x:.2e}")
    } else if a < 1.0 {
        format!("{x:.4}")
    } else if a < 10.0 {
        format!("{x:.3}")
    } else if a < 100.0 {
        format!("{x:.2}")
    } else if a < 10000.0 {
        format!("{x:.1}")
    } else {
        format!("{x:.0}")
    }
}

fn hinge_of(m: &RunMetrics, hinge: &str) -> super::metrics::HingeRunMetrics {
    m.hinges.get(hinge).cloned().unwrap_or_default()
}

fn body_of(m: &RunMetrics, body: &str) -> super::metrics::BodyRunMetrics {
    m.bodies.get(body).cloned().unwrap_or_default()
}

fn list<F: Fn(&StudyCase) -> String>(cases: &[StudyCase], f: F) -> String {
    cases
        .iter()
        .map(|c| format!("{} {}", c.label, f(c)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The two key tables (joint, motion) of a study in Markdown.
pub fn key_tables(cases: &[StudyCase], setup: &Setup) -> String {
    let h = &setup.hinge;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| case | impacts | peak force, N (ideal) | RMS force, N (ideal) | first impact, s / peak, N | settling time, s (band, N) | force decay to 10 % of peak, s | time in contact | max penetration, um | wall, s |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|");
    for c in cases {
        let m = hinge_of(&c.metrics, h);
        let first = match (m.first_impact_t_s, m.first_impact_peak_n) {
            (Some(t), Some(p)) => format!("{} / {}", num(t), num(p)),
            _ => "-".into(),
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} ({}) | {} ({}) | {} | {} ({}) | {} | {:.2} % | {} | {:.2} |",
            c.label,
            m.impacts,
            num(m.peak_force_n),
            num(m.peak_force_ideal_n),
            num(m.rms_force_n),
            num(m.rms_force_ideal_n),
            first,
            num(m.settling_time_s),
            num(m.settling_band_n),
            num(m.force_decay_time_s),
            100.0 * m.contact_fraction,
            num(m.max_penetration_um),
            c.metrics.wall_s,
        );
    }
    s.push('\n');
    let mut head = String::from("| case | final hinge angle, deg: ideal / clearance |");
    let mut rule = String::from("|---|---|");
    for b in &setup.bodies {
        let _ = write!(
            head,
            " {b} angle: max deviation, deg | {b} rate deviation: RMS / max, deg/s (mean ideal rate) |"
        );
        rule.push_str("---|---|");
    }
    head.push_str(" journal path, mm | contact arc, deg |");
    rule.push_str("---|---|");
    let _ = writeln!(s, "{head}\n{rule}");
    for c in cases {
        let m = hinge_of(&c.metrics, h);
        let mut row = format!(
            "| {} | {} / {} |",
            c.label,
            num(m.final_angle_ideal_deg),
            num(m.final_angle_deg)
        );
        for b in &setup.bodies {
            let bm = body_of(&c.metrics, b);
            let _ = write!(
                row,
                " {} | {} / {} ({}) |",
                num(bm.angle_dev_max_deg),
                num(bm.rate_dev_rms_deg_s),
                num(bm.rate_dev_max_deg_s),
                num(bm.mean_rate_ideal_deg_s)
            );
        }
        let _ = write!(
            row,
            " {} | {} |",
            num(m.journal_path_mm),
            num(m.contact_arc_deg)
        );
        let _ = writeln!(s, "{row}");
    }
    s
}

fn trend_of<F: Fn(&StudyCase) -> f64>(cases: &[StudyCase], f: F) -> Trend {
    let v: Vec<f64> = cases.iter().map(f).collect();
    Trend::of(&v, EQUAL_TOL)
}

/// `a < b` by more than the tolerance.
fn clearly_less(a: f64, b: f64) -> bool {
    b - a > EQUAL_TOL * a.abs().max(b.abs())
}

/// "lower", "higher" or "about equal" for `a` against `b`.
fn compare(a: f64, b: f64) -> &'static str {
    if clearly_less(a, b) {
        "lower"
    } else if clearly_less(b, a) {
        "higher"
    } else {
        "about equal"
    }
}

/// A part of a conclusion: `**label: yes.** text` or `**label: no.** text`.
fn part(label: &str, ok: bool, text: String) -> String {
    format!("**{label}: {}.** {text}", if ok { "yes" } else { "no" })
}

/// Contact onsets of every case per window of simulated time, counted from the output rows
/// (rows every step count every impact; sparser rows can merge impacts shorter than a row).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Timeline {
    /// Window length, s.
    pub window_s: f64,
    /// Per case (in case order), onsets per window.
    pub counts: Vec<Vec<u64>>,
}

impl Timeline {
    /// Windows of 1 s when the run lasts at least 2 s, else a fifth of the run.
    pub fn of(series: &[crate::figures::series::CaseSeries]) -> Timeline {
        let end = series
            .iter()
            .filter_map(|c| c.t_s.last().copied())
            .fold(0.0, f64::max);
        let window = if end >= 2.0 {
            1.0
        } else {
            (end / 5.0).max(1e-9)
        };
        let n = ((end / window) - 1e-9).ceil().max(1.0) as usize;
        Timeline {
            window_s: window,
            counts: series
                .iter()
                .map(|c| count_in_windows(&onset_times(&c.t_s, &c.contact), window, n))
                .collect(),
        }
    }

    /// Onsets of case `i` up to the end of window `k` (inclusive).
    pub fn cumulative(&self, i: usize, k: usize) -> u64 {
        self.counts.get(i).map_or(0, |c| c.iter().take(k + 1).sum())
    }

    /// Number of windows.
    pub fn windows(&self) -> usize {
        self.counts.first().map_or(0, Vec::len)
    }

    /// Markdown table: one row per case, one column per window, and the total.
    pub fn table(&self, labels: &[String]) -> String {
        let mut s = String::from("| case |");
        let mut rule = String::from("|---|");
        for k in 0..self.windows() {
            let _ = write!(
                s,
                " {}-{} s |",
                num(k as f64 * self.window_s),
                num((k + 1) as f64 * self.window_s)
            );
            rule.push_str("---|");
        }
        let _ = writeln!(s, " total |\n{rule}---|");
        for (label, counts) in labels.iter().zip(&self.counts) {
            let _ = write!(s, "| {label} |");
            for c in counts {
                let _ = write!(s, " {c} |");
            }
            let _ = writeln!(s, " {} |", counts.iter().sum::<u64>());
        }
        s
    }
}

use super::metrics::{count_in_windows, onset_times};

/// What our numbers show for each of the paper's four conclusions, for the cases of `kind`
/// (`timeline`: contact onsets per window, when the series were read).
pub fn conclusions(
    kind: StudyKind,
    cases: &[StudyCase],
    timeline: Option<&Timeline>,
) -> Vec<Conclusion> {
    let Some(first) = cases.first() else {
        return Vec::new();
    };
    let hinge = first
        .scene
        .hinges
        .iter()
        .find(|h| h.clearance.is_some())
        .map(|h| h.name.clone())
        .unwrap_or_default();
    let journal = first
        .scene
        .hinges
        .iter()
        .find(|h| h.name == hinge)
        .map(|h| h.journal.clone())
        .unwrap_or_default();
    let end = first.metrics.end_s;
    let hm = |c: &StudyCase| hinge_of(&c.metrics, &hinge);
    let bm = |c: &StudyCase| body_of(&c.metrics, &journal);
    let elsewhere = |n: u8, k: StudyKind| Conclusion {
        number: n,
        paper: PAPER[n as usize - 1],
        verdict: Verdict::NotTested,
        finding: format!(
            "Not varied in this study: see the {} study (`../{}/report.md`).",
            k.name(),
            k.name()
        ),
    };
    let mut out = Vec::new();

    // 1. Angles slightly, rates visibly, force strongly.
    {
        let angle_rel = |c: &StudyCase| {
            let b = bm(c);
            b.angle_dev_max_deg / b.final_angle_ideal_deg.abs().max(1e-12)
        };
        let rate_rel = |c: &StudyCase| {
            let b = bm(c);
            b.rate_dev_max_deg_s / b.mean_rate_ideal_deg_s.abs().max(1e-12)
        };
        let ratio = |c: &StudyCase| {
            let h = hm(c);
            h.peak_force_n / h.peak_force_ideal_n.max(1e-12)
        };
        let slight = cases.iter().all(|c| angle_rel(c) < ANGLE_SLIGHT);
        let visible = cases.iter().all(|c| rate_rel(c) > RATE_VISIBLE);
        let strong = cases.iter().all(|c| ratio(c) > FORCE_STRONG);
        let mut parts = vec![slight, visible, strong];
        let mut texts = vec![
            part(
                "angles barely change",
                slight,
                format!(
                    "Largest {journal}-angle deviation from the ideal twin: {}.",
                    list(cases, |c| format!(
                        "{} deg ({} % of {} deg)",
                        num(bm(c).angle_dev_max_deg),
                        num(100.0 * angle_rel(c)),
                        num(bm(c).final_angle_ideal_deg)
                    ))
                ),
            ),
            part(
                "rates visibly change",
                visible,
                format!(
                    "Largest {journal}-rate deviation: {}.",
                    list(cases, |c| format!(
                        "{} deg/s ({} % of the mean ideal rate {} deg/s)",
                        num(bm(c).rate_dev_max_deg_s),
                        num(100.0 * rate_rel(c)),
                        num(bm(c).mean_rate_ideal_deg_s)
                    ))
                ),
            ),
            part(
                "force strongly changes",
                strong,
                format!(
                    "Clearance peak over ideal peak: {}; the force is a train of impacts (see the force figure).",
                    list(cases, |c| format!(
                        "{} N / {} N = {}x",
                        num(hm(c).peak_force_n),
                        num(hm(c).peak_force_ideal_n),
                        num(ratio(c))
                    ))
                ),
            ),
        ];
        if kind == StudyKind::Clearance {
            let grow = trend_of(cases, |c| bm(c).rate_dev_rms_deg_s);
            texts.push(part(
                "rate oscillation grows with c",
                grow == Trend::Increasing,
                format!(
                    "The RMS {journal}-rate deviation {} with c: {}.",
                    grow.verb(),
                    list(cases, |c| format!(
                        "{} deg/s",
                        num(bm(c).rate_dev_rms_deg_s)
                    ))
                ),
            ));
            parts.push(grow == Trend::Increasing);
        }
        out.push(Conclusion {
            number: 1,
            paper: PAPER[0],
            verdict: Verdict::from_parts(&parts),
            finding: texts.join(" "),
        });
    }

    // 2. Clearance: impacts, settling.
    if kind == StudyKind::Clearance {
        let impacts = trend_of(cases, |c| hm(c).impacts as f64);
        let peak = trend_of(cases, |c| hm(c).peak_force_n);
        let settle = trend_of(cases, |c| hm(c).settling_time_s);
        let decay = trend_of(cases, |c| hm(c).force_decay_time_s);
        let never = cases
            .iter()
            .all(|c| hm(c).settling_time_s >= 0.99 * end - 1e-12);
        let mut more = format!(
            "Impacts over the {} s run: {} ({}). The peak joint force {} with c: {}.",
            num(end),
            list(cases, |c| hm(c).impacts.to_string()),
            impacts.verb(),
            peak.verb(),
            list(cases, |c| format!("{} N", num(hm(c).peak_force_n))),
        );
        if let Some(tl) = timeline.filter(|t| t.windows() > 1) {
            let ordered: Vec<bool> = (0..tl.windows())
                .map(|k| {
                    let v: Vec<f64> = (0..cases.len())
                        .map(|i| tl.cumulative(i, k) as f64)
                        .collect();
                    Trend::of(&v, 0.0) == Trend::Increasing
                })
                .collect();
            let first_window: Vec<String> = (0..cases.len())
                .map(|i| tl.cumulative(i, 0).to_string())
                .collect();
            let _ = write!(
                more,
                " The count depends on the time window (onsets per window from the rows, table above): after the first {} s the counts are {}",
                num(tl.window_s),
                first_window.join(", ")
            );
            match ordered.iter().rposition(|&o| !o) {
                None => {
                    let _ = write!(
                        more,
                        ", and more impacts with larger c holds at every window end."
                    );
                }
                Some(k) if k + 1 < ordered.len() => {
                    let from = if k + 2 == ordered.len() {
                        format!("only at the end of the run (t = {} s)", num(end))
                    } else {
                        format!("from t = {} s on", num((k + 2) as f64 * tl.window_s))
                    };
                    let _ = write!(
                        more,
                        ": a smaller clearance has shorter free flights and strikes more often at first; the cumulative count \
                         increases with c {from}, because the larger clearances impact more often per second later in the run \
                         (per-second counts in the last window: {}).",
                        (0..cases.len())
                            .map(|i| tl.counts[i].last().copied().unwrap_or(0).to_string())
                            .collect::<Vec<_>>()
                            .join(", ")
                    );
                }
                Some(_) => {
                    let _ = write!(
                        more,
                        "; at the end of the run the count does not increase with c."
                    );
                }
            }
        }
        let mut slow = String::new();
        if never {
            let _ = write!(
                slow,
                "Runner's settling time (last time the clearance force exceeds the ideal force by more than the ideal peak): {}, \
                 within 1 % of the end of the run in every case: impacts go on to the end, the force never settles by this \
                 definition, and it gives no ordering. ",
                list(cases, |c| format!("{} s", num(hm(c).settling_time_s))),
            );
        } else {
            let _ = write!(
                slow,
                "Runner's settling time {} with c: {}. ",
                settle.verb(),
                list(cases, |c| format!("{} s", num(hm(c).settling_time_s)))
            );
        }
        let _ = write!(
            slow,
            "The impulsive force decays to 10 % of its own peak at {} ({} with c){}.",
            list(cases, |c| format!("{} s", num(hm(c).force_decay_time_s))),
            decay.verb(),
            if decay == Trend::Decreasing {
                ": larger clearances lose their (larger) first-impact peaks sooner, the opposite of the paper"
            } else {
                ""
            }
        );
        let slower = (!never && settle == Trend::Increasing) || decay == Trend::Increasing;
        out.push(Conclusion {
            number: 2,
            paper: PAPER[1],
            verdict: Verdict::from_parts(&[impacts == Trend::Increasing, slower]),
            finding: format!(
                "{} {}",
                part("more impacts", impacts == Trend::Increasing, more),
                part("slower settling", slower, slow)
            ),
        });
    } else {
        out.push(elsewhere(2, StudyKind::Clearance));
    }

    // 3. Torque: faster deployment, stronger oscillation, irregular trajectory.
    if kind == StudyKind::Torque {
        let deploy = trend_of(cases, |c| hm(c).final_angle_ideal_deg);
        let deploy_c = trend_of(cases, |c| hm(c).final_angle_deg);
        let osc = trend_of(cases, |c| bm(c).rate_dev_rms_deg_s);
        let rel = |c: &StudyCase| {
            100.0 * bm(c).rate_dev_rms_deg_s / bm(c).mean_rate_ideal_deg_s.abs().max(1e-12)
        };
        let osc_rel = trend_of(cases, rel);
        let force = trend_of(cases, |c| hm(c).peak_force_n);
        let impacts = trend_of(cases, |c| hm(c).impacts as f64);
        let path = trend_of(cases, |c| hm(c).journal_path_mm);
        let arc = trend_of(cases, |c| hm(c).contact_arc_deg);
        let irregular = path == Trend::Increasing && arc == Trend::Increasing;
        let texts = [
            part(
                "faster deployment",
                deploy == Trend::Increasing,
                format!(
                    "Hinge angle at {} s, ideal twin: {} ({}); clearance twin: {} ({}).",
                    num(end),
                    list(cases, |c| format!(
                        "{} deg",
                        num(hm(c).final_angle_ideal_deg)
                    )),
                    deploy.verb(),
                    list(cases, |c| format!("{} deg", num(hm(c).final_angle_deg))),
                    deploy_c.verb(),
                ),
            ),
            part(
                "stronger oscillation",
                osc == Trend::Increasing,
                format!(
                    "RMS {journal}-rate deviation from the ideal twin: {} ({}); relative to the mean ideal rate {} ({}). \
                     Peak joint force: {} ({}).",
                    list(cases, |c| format!(
                        "{} deg/s",
                        num(bm(c).rate_dev_rms_deg_s)
                    )),
                    osc.verb(),
                    list(cases, |c| format!("{} %", num(rel(c)))),
                    osc_rel.verb(),
                    list(cases, |c| format!("{} N", num(hm(c).peak_force_n))),
                    force.verb(),
                ),
            ),
            part(
                "more irregular trajectory",
                irregular,
                format!(
                    "Journal path length: {} ({}); arc of the bearing touched: {} ({}). Impacts: {} ({}), with time in \
                     contact {}: at high torque the journal rides along the bearing wall (following mode) for most of the run, \
                     so separate impacts are not a measure of irregularity there.",
                    list(cases, |c| format!("{} mm", num(hm(c).journal_path_mm))),
                    path.verb(),
                    list(cases, |c| format!("{} deg", num(hm(c).contact_arc_deg))),
                    arc.verb(),
                    list(cases, |c| hm(c).impacts.to_string()),
                    impacts.verb(),
                    list(cases, |c| format!(
                        "{} %",
                        num(100.0 * hm(c).contact_fraction)
                    )),
                ),
            ),
        ];
        out.push(Conclusion {
            number: 3,
            paper: PAPER[2],
            verdict: Verdict::from_parts(&[
                deploy == Trend::Increasing,
                osc == Trend::Increasing,
                irregular,
            ]),
            finding: texts.join(" "),
        });
    } else {
        out.push(elsewhere(3, StudyKind::Torque));
    }

    // 4. Friction: dry (more friction) vs lubricated.
    if kind == StudyKind::Friction && cases.len() >= 2 {
        let (dry, lub) = (&cases[0], &cases[1]);
        let (hd, hl) = (hm(dry), hm(lub));
        let (bd, bl) = (bm(dry), bm(lub));
        let smaller_force = clearly_less(hd.peak_force_n, hl.peak_force_n)
            && clearly_less(hd.rms_force_n, hl.rms_force_n);
        let fewer = hd.impacts < hl.impacts;
        let faster = clearly_less(hd.force_decay_time_s, hl.force_decay_time_s)
            || clearly_less(hd.settling_time_s, hl.settling_time_s);
        let calmer = clearly_less(bd.rate_dev_rms_deg_s, bl.rate_dev_rms_deg_s);
        let pct = |a: f64, b: f64| num(100.0 * (a - b) / b.abs().max(1e-12));
        let texts = [
            "Dry (mu_s/mu_d = 0.3/0.25) against lubricated (0.08/0.05), values dry vs lubricated."
                .to_string(),
            part(
                "smaller joint forces",
                smaller_force,
                format!(
                    "Peak {} N vs {} N ({}, {} %); RMS {} N vs {} N ({}, {} %).{}",
                    num(hd.peak_force_n),
                    num(hl.peak_force_n),
                    compare(hd.peak_force_n, hl.peak_force_n),
                    pct(hd.peak_force_n, hl.peak_force_n),
                    num(hd.rms_force_n),
                    num(hl.rms_force_n),
                    compare(hd.rms_force_n, hl.rms_force_n),
                    pct(hd.rms_force_n, hl.rms_force_n),
                    if hd.first_impact_peak_n == Some(hd.peak_force_n)
                        && hl.first_impact_peak_n == Some(hl.peak_force_n)
                    {
                        format!(
                            " In both the peak is the first impact (at {} s), before any sliding has built up.",
                            hd.first_impact_t_s.map_or("-".into(), num)
                        )
                    } else {
                        String::new()
                    },
                ),
            ),
            part(
                "fewer impacts",
                fewer,
                format!(
                    "{} vs {} contact onsets; time in contact {} % vs {} %. Without the chatter of a journal \
                     following the wall (onsets after a free flight of at least 0.1 um): {} vs {}.",
                    hd.impacts,
                    hl.impacts,
                    num(100.0 * hd.contact_fraction),
                    num(100.0 * hl.contact_fraction),
                    hd.separated_impacts,
                    hl.separated_impacts
                ),
            ),
            part(
                "faster settling",
                faster,
                format!(
                    "Force decay to 10 % of peak {} s vs {} s ({}); runner's settling time {} s vs {} s ({}{}).",
                    num(hd.force_decay_time_s),
                    num(hl.force_decay_time_s),
                    compare(hd.force_decay_time_s, hl.force_decay_time_s),
                    num(hd.settling_time_s),
                    num(hl.settling_time_s),
                    compare(hd.settling_time_s, hl.settling_time_s),
                    if hd.settling_time_s >= 0.99 * end && hl.settling_time_s >= 0.99 * end {
                        ": neither settles by that definition"
                    } else {
                        ""
                    }
                ),
            ),
            part(
                "calmer rates when dry (the paper: lubricated shakes more)",
                calmer,
                format!(
                    "RMS {journal}-rate deviation {} vs {} deg/s ({}); largest {} vs {} deg/s.",
                    num(bd.rate_dev_rms_deg_s),
                    num(bl.rate_dev_rms_deg_s),
                    compare(bd.rate_dev_rms_deg_s, bl.rate_dev_rms_deg_s),
                    num(bd.rate_dev_max_deg_s),
                    num(bl.rate_dev_max_deg_s),
                ),
            ),
        ];
        out.push(Conclusion {
            number: 4,
            paper: PAPER[3],
            verdict: Verdict::from_parts(&[smaller_force, fewer, faster, calmer]),
            finding: texts.join(" "),
        });
    } else {
        out.push(elsewhere(4, StudyKind::Friction));
    }
    let impacts: Vec<u64> = cases.iter().map(|c| hm(c).impacts).collect();
    if impacts.iter().any(|&n| n < MIN_IMPACTS) {
        for c in out.iter_mut().filter(|c| c.verdict != Verdict::NotTested) {
            c.verdict = Verdict::TooLittleData;
            c.finding = format!(
                "**Too little data to judge.** The cases hold {} impacts in {} s; a verdict needs at least \
                 {MIN_IMPACTS} in every case (run longer: the studies' default is 5 s). The numbers, for \
                 what they are worth: {}",
                list(cases, |c| hm(c).impacts.to_string()),
                num(end),
                c.finding
            );
        }
    }
    out
}

fn figure_caption(kind: StudyKind, f: FigureKind) -> String {
    let [a, b, c] = kind.paper_figures();
    match f {
        FigureKind::AnglesRates => format!(
            "Angles and angular rates of the bodies vs time, each case with the ideal joint dashed (paper fig. {a})."
        ),
        FigureKind::Force => format!(
            "Joint reaction force vs time: ideal joint (left, its own scale) and clearance joint (right); each column shares its scale (paper fig. {b}). Lines keep the minimum and maximum of every pixel column, so no peak is lost."
        ),
        FigureKind::Trajectory => format!(
            "Journal-centre trajectory in the bearing frame, drawn to scale with the clearance circle |e| = c (paper fig. {c})."
        ),
    }
}

/// The whole `report.md` of a study.
pub fn study_report(
    kind: StudyKind,
    setup: &Setup,
    cases: &[StudyCase],
    figures: &[(FigureKind, String)],
    conclusions: &[Conclusion],
    timeline: Option<&Timeline>,
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# {} study: {}\n", kind.name(), kind.title());
    let _ = writeln!(
        s,
        "Written by `cargo run --release -- study {}` (or `study all`); regenerated on every run, do not edit. \
         Model: the project's specification MODEL.md (§4, the paper's scene). \
         Nothing in the model is tuned to agree with the paper.\n",
        kind.name()
    );
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
    if kind == StudyKind::Torque {
        let _ = writeln!(
            s,
            "- The paper's fixed step of 1e-4 s under-resolves the stronger impacts: at 3T and 5T it gives first-impact peaks \
             of 327 N and 437 N against 358 N and 503 N with the default adaptive steps, and it is longer than friction's \
             limit near zero slip (a guard violation). Adaptive steps shorten inside contacts as the contact requires, so \
             the three cases run with the same step control as the other studies."
        );
    }
    let _ = writeln!(
        s,
        "- Metrics (table `metrics.csv` / `metrics.json`): impacts, peak and RMS force, first impact, settling time, contact \
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
                figure_caption(kind, *f)
            );
        }
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

/// `report.md` of `study all`: each study's key tables and verdicts, with links.
pub fn index_report(outcomes: &[StudyOutcome]) -> String {
    let mut s = String::from(
        "# The paper's studies: summary\n\nWritten by `cargo run --release -- study all`; each study's own report has its figures and full findings.\n\n",
    );
    for o in outcomes {
        let name = o.kind.name();
        let _ = writeln!(
            s,
            "## {} study: [{name}/report.md]({name}/report.md)\n",
            name
        );
        let _ = writeln!(s, "{}, {} s simulated.\n", o.setup.stepping, o.setup.end_s);
        s.push_str(&key_tables(&o.cases, &o.setup));
        s.push('\n');
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
