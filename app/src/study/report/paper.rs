//! The paper's four conclusions (MODEL.md §5), each judged against a study's numbers.

use super::tables::{body_of, hinge_of, list, num};
use super::timeline::Timeline;
use super::verdict::{
    ANGLE_SLIGHT, Conclusion, FORCE_STRONG, MIN_IMPACTS, RATE_VISIBLE, Verdict, clearly_less,
    compare, part, trend_of,
};
use crate::study::case::StudyCase;
use crate::study::metrics::Trend;
use crate::study::preset::{Study, StudyKind};
use std::fmt::Write as _;

/// The paper's conclusions (MODEL.md §5).
pub const PAPER: [&str; 4] = [
    "Clearance barely changes the angles, visibly changes the angular rates (oscillation around the ideal curve, growing with c), and strongly changes the joint force (impulsive, far above ideal).",
    "Larger clearance: more impacts, slower settling of the contact force.",
    "Higher driving torque (3T, 5T): faster deployment, stronger oscillation, more irregular trajectory.",
    "More friction (dry vs lubricated): smaller joint forces and fewer impacts, faster settling.",
];

/// What our numbers show for each of the paper's four conclusions, for the cases of `study`,
/// one of the paper's studies ([`Study::paper`]: the judgement assumes the paper's scene and
/// its cases in the paper's order) (`timeline`: contact onsets per window, when the series were
/// read).
pub fn conclusions(
    study: &Study,
    cases: &[StudyCase],
    timeline: Option<&Timeline>,
) -> Vec<Conclusion> {
    let Some(first) = cases.first() else {
        return Vec::new();
    };
    let kind = study.kind;
    let hinge = &study.hinge;
    let journal = first
        .scene
        .hinges
        .iter()
        .find(|h| &h.name == hinge)
        .map(|h| h.journal.clone())
        .unwrap_or_default();
    let end = first.metrics.end_s;
    let hm = |c: &StudyCase| hinge_of(&c.metrics, hinge);
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
        let impacts = trend_of(cases, |c| hm(c).onsets as f64);
        let peak = trend_of(cases, |c| hm(c).peak_force_n);
        let settle = trend_of(cases, |c| hm(c).settling_time_s);
        let decay = trend_of(cases, |c| hm(c).force_decay_time_s);
        let never = cases
            .iter()
            .all(|c| hm(c).settling_time_s >= 0.99 * end - 1e-12);
        let mut more = format!(
            "Onsets (contacts, chatter included) over the {} s run: {} ({}). The peak joint force {} with c: {}.",
            num(end),
            list(cases, |c| hm(c).onsets.to_string()),
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
                        ", and more onsets with larger c holds at every window end."
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
        let impacts = trend_of(cases, |c| hm(c).onsets as f64);
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
                    "Journal path length: {} ({}); arc of the bearing touched: {} ({}). Onsets: {} ({}), with time in \
                     contact {}: at high torque the journal rides along the bearing wall (following mode) for most of the run, \
                     so separate impacts are not a measure of irregularity there.",
                    list(cases, |c| format!("{} mm", num(hm(c).journal_path_mm))),
                    path.verb(),
                    list(cases, |c| format!("{} deg", num(hm(c).contact_arc_deg))),
                    arc.verb(),
                    list(cases, |c| hm(c).onsets.to_string()),
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
        let fewer = hd.onsets < hl.onsets;
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
                     following the wall (impacts: onsets after a free flight of at least 0.1 um): {} vs {}.",
                    hd.onsets,
                    hl.onsets,
                    num(100.0 * hd.contact_fraction),
                    num(100.0 * hl.contact_fraction),
                    hd.impacts,
                    hl.impacts
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
    let onsets: Vec<u64> = cases.iter().map(|c| hm(c).onsets).collect();
    if onsets.iter().any(|&n| n < MIN_IMPACTS) {
        for c in out.iter_mut().filter(|c| c.verdict != Verdict::NotTested) {
            c.verdict = Verdict::TooLittleData;
            c.finding = format!(
                "**Too little data to judge.** The cases hold {} onsets in {} s; a verdict needs at least \
                 {MIN_IMPACTS} in every case (run longer: the studies' default is 5 s). The numbers, for \
                 what they are worth: {}",
                list(cases, |c| hm(c).onsets.to_string()),
                num(end),
                c.finding
            );
        }
    }
    out
}
