//! Numbers and Markdown tables of a study's report: the joint and motion tables of its cases.

use super::setup::Setup;
use crate::study::case::StudyCase;
use crate::study::metrics::{BodyRunMetrics, HingeRunMetrics, RunMetrics};
use std::fmt::Write as _;

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

pub(crate) fn hinge_of(m: &RunMetrics, hinge: &str) -> HingeRunMetrics {
    m.hinges.get(hinge).cloned().unwrap_or_default()
}

pub(crate) fn body_of(m: &RunMetrics, body: &str) -> BodyRunMetrics {
    m.bodies.get(body).cloned().unwrap_or_default()
}

pub(crate) fn list<F: Fn(&StudyCase) -> String>(cases: &[StudyCase], f: F) -> String {
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
        "| case | onsets | peak force, N (ideal) | RMS force, N (ideal) | first impact, s / peak, N | settling time, s (band, N) | force decay to 10 % of peak, s | time in contact | max penetration, um | wall, s |"
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
            m.onsets,
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
