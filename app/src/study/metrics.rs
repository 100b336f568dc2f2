//! Per-run metrics of a sweep point: the runner's every-step metrics (onsets and impacts, peak and RMS
//! force, settling, rate deviation, contact fraction) plus a few computed here from the output
//! rows (angle deviation, force decay time, journal path length, contact arc), as pure functions
//! of series so they can be tested on hand-made data.

use clearance_joint::error::{Divergence, Error, Result};
use clearance_joint::scene::Scene;
use clearance_joint::scene::report::Summary;
use clearance_joint::scene::runner::RunResult;
use clearance_joint::scene::runner::convergence::ConvergenceVerdict;
use clearance_joint::table::Table;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Fraction of its own peak below which the clearance joint force counts as decayed
/// ([`HingeRunMetrics::force_decay_time_s`]).
pub const FORCE_DECAY_FRACTION: f64 = 0.1;

/// Metrics of one ideal-vs-clearance run.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RunMetrics {
    /// Step, s.
    pub dt_s: f64,
    /// Simulated time, s.
    pub end_s: f64,
    /// Internal steps.
    pub steps: u64,
    /// Wall time of the run (both twins in one world), s.
    pub wall_s: f64,
    /// Per movable body (fixed bodies are left out).
    pub bodies: BTreeMap<String, BodyRunMetrics>,
    /// Per hinge.
    pub hinges: BTreeMap<String, HingeRunMetrics>,
    /// Steps the step control rejected and retried shorter.
    #[serde(default)]
    pub rejected_steps: u64,
    /// Run-time guard violations in words (empty when the run stayed within the model's
    /// validity; see `summary.json`'s `guards`).
    #[serde(default)]
    pub guard_violations: Vec<String>,
    /// The convergence check's verdict (`summary.json`'s `convergence`): which metrics
    /// converged against the point at half its tolerance, or why none was checked.
    #[serde(default)]
    pub convergence: ConvergenceVerdict,
}

/// Metrics of one body: the clearance twin against the ideal twin, about the scene's reference axis.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BodyRunMetrics {
    /// Final angle, clearance twin, deg.
    pub final_angle_deg: f64,
    /// Final angle, ideal twin, deg.
    pub final_angle_ideal_deg: f64,
    /// Largest `|angle - ideal angle|` over the output rows, deg.
    pub angle_dev_max_deg: f64,
    /// RMS of `rate - ideal rate` over every internal step (time-weighted), deg/s.
    pub rate_dev_rms_deg_s: f64,
    /// Largest `|rate - ideal rate|` over every internal step, deg/s.
    pub rate_dev_max_deg_s: f64,
    /// Mean angular rate of the ideal twin, `final_angle_ideal_deg / end_s`, deg/s: the scale
    /// against which the rate deviations are judged.
    pub mean_rate_ideal_deg_s: f64,
}

/// Metrics of one hinge. Every-step values come from the runner (`clearance_joint::scene::runner`); "rows" values are
/// computed here from the output rows (one per output interval).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HingeRunMetrics {
    /// Radial clearance of the clearance twin, mm (0 for an ideal hinge).
    pub clearance_mm: f64,
    /// Contact [onsets](clearance_joint::rapier::observers::metrics#onsets-impacts-and-chatter), chatter
    /// included (every step). JSON key `onsets`; a point written with the key `impacts` reads
    /// back here.
    #[serde(alias = "impacts")]
    pub onsets: u64,
    /// [Impacts](clearance_joint::rapier::observers::metrics#onsets-impacts-and-chatter): onsets after a
    /// free flight that opened at least the joint's minimum separation (0.1 um by default), the
    /// onsets without the chatter of a journal following the wall. JSON key `separated_impacts`.
    #[serde(default, rename = "separated_impacts")]
    pub impacts: u64,
    /// Peak joint force, clearance twin (every step), N.
    pub peak_force_n: f64,
    /// Peak joint force, ideal twin (every step), N.
    pub peak_force_ideal_n: f64,
    /// RMS joint force over the run, clearance twin (every step), N.
    pub rms_force_n: f64,
    /// RMS joint force over the run, ideal twin (every step), N.
    pub rms_force_ideal_n: f64,
    /// Time of the first contact onset, s (every step; none without contact).
    pub first_impact_t_s: Option<f64>,
    /// Peak force of the first contact, N (every step).
    pub first_impact_peak_n: Option<f64>,
    /// Settling time of the runner (every step): the last time the clearance joint force exceeded
    /// the ideal joint force by more than `settling_band_n`, s; 0 if never.
    pub settling_time_s: f64,
    /// The band of `settling_time_s`: the ideal twin's peak joint force, N.
    pub settling_band_n: f64,
    /// Decay time of the impulsive force (rows): the last time the clearance joint force exceeded
    /// [`FORCE_DECAY_FRACTION`] of its own peak, s; 0 if never.
    pub force_decay_time_s: f64,
    /// Fraction of simulated time in contact (every step).
    pub contact_fraction: f64,
    /// Largest penetration (every step), um.
    pub max_penetration_um: f64,
    /// Length of the journal-centre path inside the bearing (rows), mm.
    pub journal_path_mm: f64,
    /// Smallest arc of the bearing circle holding every contact position (rows), deg:
    /// 0 when all contacts are at one spot, 360 when they surround the journal.
    pub contact_arc_deg: f64,
    /// Final relative angle, clearance twin, deg.
    pub final_angle_deg: f64,
    /// Final relative angle, ideal twin, deg.
    pub final_angle_ideal_deg: f64,
    /// Largest `|angle - ideal angle|` over the rows, deg.
    pub angle_dev_max_deg: f64,
}

impl RunMetrics {
    /// Metrics of a finished run with both twins and output rows.
    pub fn of(result: &RunResult) -> Result<RunMetrics> {
        let summary = result.summary();
        let [ideal, clear] = result.twins.as_slice() else {
            return Err(Error::invalid(
                "run",
                "study metrics need both the ideal and the clearance twin",
            ));
        };
        Self::from_parts(&result.scene, &summary, &ideal.table, &clear.table)
    }

    /// Metrics from a run's summary and the two twins' output tables (as written to
    /// `ideal.csv` and `clearance.csv`).
    pub fn from_parts(
        scene: &Scene,
        summary: &Summary,
        ideal: &Table,
        clear: &Table,
    ) -> Result<RunMetrics> {
        let twin = |name: &str| {
            summary
                .twins
                .get(name)
                .ok_or_else(|| Error::invalid("summary", format!("has no `{name}` twin")))
        };
        let (si, sc) = (twin("ideal")?, twin("clearance")?);
        let comparison = summary.comparison.clone().unwrap_or_default();
        let col = |t: &Table, name: &str| {
            t.column(name)
                .ok_or_else(|| Error::invalid("output table", format!("has no column `{name}`")))
        };
        let end = summary.end_s;
        let mut m = RunMetrics {
            dt_s: summary.dt_s,
            end_s: end,
            steps: sc.steps,
            wall_s: sc.wall_s,
            rejected_steps: summary.guards.rejected_steps,
            guard_violations: summary.guards.messages(),
            convergence: summary.convergence.clone(),
            ..Default::default()
        };
        for b in scene.bodies.iter().filter(|b| !b.fixed) {
            let name = &b.name;
            let (ai, ac) = (
                col(ideal, &format!("{name}_angle_deg"))?,
                col(clear, &format!("{name}_angle_deg"))?,
            );
            let dev = comparison.bodies.get(name).cloned().unwrap_or_default();
            let final_ideal = si.final_angles_deg.get(name).copied().unwrap_or(0.0);
            m.bodies.insert(
                name.clone(),
                BodyRunMetrics {
                    final_angle_deg: sc.final_angles_deg.get(name).copied().unwrap_or(0.0),
                    final_angle_ideal_deg: final_ideal,
                    angle_dev_max_deg: max_abs_difference(&ac, &ai),
                    rate_dev_rms_deg_s: dev.rms_deg_s,
                    rate_dev_max_deg_s: dev.max_deg_s,
                    mean_rate_ideal_deg_s: if end > 0.0 { final_ideal / end } else { 0.0 },
                },
            );
        }
        let t = col(clear, "t_s")?;
        for h in &scene.hinges {
            let name = &h.name;
            let (hi, hc) = match (si.hinges.get(name), sc.hinges.get(name)) {
                (Some(a), Some(b)) => (a, b),
                _ => {
                    return Err(Error::invalid(
                        "summary",
                        format!("has no metrics for hinge `{name}`"),
                    ));
                }
            };
            let c = |s: &str| format!("{name}_{s}");
            let force = col(clear, &c("force_n"))?;
            let (u, v) = (col(clear, &c("ecc_u_mm"))?, col(clear, &c("ecc_v_mm"))?);
            let contact = col(clear, &c("contact"))?;
            let (ai, ac) = (col(ideal, &c("angle_deg"))?, col(clear, &c("angle_deg"))?);
            let settling = comparison.hinges.get(name).cloned().unwrap_or_default();
            m.hinges.insert(
                name.clone(),
                HingeRunMetrics {
                    clearance_mm: h.clearance.as_ref().map_or(0.0, |s| s.clearance_mm),
                    onsets: hc.onsets,
                    impacts: hc.impacts,
                    peak_force_n: hc.peak_force_n,
                    peak_force_ideal_n: hi.peak_force_n,
                    rms_force_n: hc.rms_force_n,
                    rms_force_ideal_n: hi.rms_force_n,
                    first_impact_t_s: hc.first_impact_t_s,
                    first_impact_peak_n: hc.first_impact_peak_n,
                    settling_time_s: settling.settling_time_s,
                    settling_band_n: settling.band_n,
                    force_decay_time_s: last_time_above(
                        &t,
                        &force,
                        FORCE_DECAY_FRACTION * hc.peak_force_n,
                    ),
                    contact_fraction: hc.contact_fraction,
                    max_penetration_um: hc.max_penetration_um,
                    journal_path_mm: path_length(&u, &v),
                    contact_arc_deg: contact_arc_deg(&u, &v, &contact),
                    final_angle_deg: hc.final_angle_deg,
                    final_angle_ideal_deg: hi.final_angle_deg,
                    angle_dev_max_deg: max_abs_difference(&ac, &ai),
                },
            );
        }
        m.check_finite()?;
        Ok(m)
    }

    /// The metrics as named columns (`None` for a missing optional value), in a fixed order:
    /// run columns, then `<body>_<metric>` per body, then `<hinge>_<metric>` per hinge.
    pub fn columns(&self) -> Vec<(String, Option<f64>)> {
        let mut cols: Vec<(String, Option<f64>)> = vec![
            ("dt_s".into(), Some(self.dt_s)),
            ("end_s".into(), Some(self.end_s)),
            ("steps".into(), Some(self.steps as f64)),
            ("wall_s".into(), Some(self.wall_s)),
            // A point outside the model's validity says so in the table too.
            ("rejected_steps".into(), Some(self.rejected_steps as f64)),
            (
                "guard_violations".into(),
                Some(self.guard_violations.len() as f64),
            ),
            // The metrics the convergence check flagged (empty when it compared none).
            (
                "not_converged".into(),
                self.convergence
                    .is_checked()
                    .then(|| self.convergence.not_converged().len() as f64),
            ),
        ];
        for (name, b) in &self.bodies {
            for (k, v) in [
                ("final_angle_deg", b.final_angle_deg),
                ("final_angle_ideal_deg", b.final_angle_ideal_deg),
                ("angle_dev_max_deg", b.angle_dev_max_deg),
                ("rate_dev_rms_deg_s", b.rate_dev_rms_deg_s),
                ("rate_dev_max_deg_s", b.rate_dev_max_deg_s),
                ("mean_rate_ideal_deg_s", b.mean_rate_ideal_deg_s),
            ] {
                cols.push((format!("{name}_{k}"), Some(v)));
            }
        }
        for (name, h) in &self.hinges {
            for (k, v) in [
                ("clearance_mm", Some(h.clearance_mm)),
                ("onsets", Some(h.onsets as f64)),
                ("separated_impacts", Some(h.impacts as f64)),
                ("peak_force_n", Some(h.peak_force_n)),
                ("peak_force_ideal_n", Some(h.peak_force_ideal_n)),
                ("rms_force_n", Some(h.rms_force_n)),
                ("rms_force_ideal_n", Some(h.rms_force_ideal_n)),
                ("first_impact_t_s", h.first_impact_t_s),
                ("first_impact_peak_n", h.first_impact_peak_n),
                ("settling_time_s", Some(h.settling_time_s)),
                ("settling_band_n", Some(h.settling_band_n)),
                ("force_decay_time_s", Some(h.force_decay_time_s)),
                ("contact_fraction", Some(h.contact_fraction)),
                ("max_penetration_um", Some(h.max_penetration_um)),
                ("journal_path_mm", Some(h.journal_path_mm)),
                ("contact_arc_deg", Some(h.contact_arc_deg)),
                ("final_angle_deg", Some(h.final_angle_deg)),
                ("final_angle_ideal_deg", Some(h.final_angle_ideal_deg)),
                ("angle_dev_max_deg", Some(h.angle_dev_max_deg)),
            ] {
                cols.push((format!("{name}_{k}"), v));
            }
        }
        cols
    }

    /// Refuses a non-finite metric, naming it (output files hold no NaN).
    pub fn check_finite(&self) -> Result<()> {
        for (name, v) in self.columns() {
            if let Some(x) = v
                && !x.is_finite()
            {
                return Err(Error::Diverged {
                    t: self.end_s,
                    what: Box::new(Divergence::NonFinite {
                        name,
                        place: "among the run's metrics".into(),
                        value: Some(x),
                    }),
                });
            }
        }
        Ok(())
    }
}

/// The last time `t[i]` at which `x[i] > threshold`; 0 when `x` never exceeds it.
pub fn last_time_above(t: &[f64], x: &[f64], threshold: f64) -> f64 {
    t.iter()
        .zip(x)
        .rev()
        .find(|&(_, &v)| v > threshold)
        .map_or(0.0, |(&ti, _)| ti)
}

/// Largest `|a[i] - b[i]|` over the common length; 0 for empty series.
pub fn max_abs_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Length of the polyline through `(u[i], v[i])`.
pub fn path_length(u: &[f64], v: &[f64]) -> f64 {
    let n = u.len().min(v.len());
    (1..n)
        .map(|i| (u[i] - u[i - 1]).hypot(v[i] - v[i - 1]))
        .sum()
}

/// Smallest arc of the circle, in degrees, that holds the directions `atan2(v, u)` of every
/// point with `contact[i] > 0.5`: 360 minus the largest gap between successive contact
/// directions. 0 without contact or with a single direction.
pub fn contact_arc_deg(u: &[f64], v: &[f64], contact: &[f64]) -> f64 {
    let mut angles: Vec<f64> = u
        .iter()
        .zip(v)
        .zip(contact)
        .filter(|&(_, &c)| c > 0.5)
        .map(|((&a, &b), _)| b.atan2(a).to_degrees())
        .collect();
    if angles.len() < 2 {
        return 0.0;
    }
    angles.sort_by(f64::total_cmp);
    let wrap_gap = angles[0] + 360.0 - angles[angles.len() - 1];
    let largest_gap = angles
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(wrap_gap, f64::max);
    (360.0 - largest_gap).clamp(0.0, 360.0)
}

/// Times `t[i]` at which `contact` turns on (`contact[i] > 0.5` after `contact[i-1] <= 0.5`;
/// contact at the first sample counts as an onset).
pub fn onset_times(t: &[f64], contact: &[f64]) -> Vec<f64> {
    let mut out = Vec::new();
    let mut before = false;
    for (&ti, &c) in t.iter().zip(contact) {
        let now = c > 0.5;
        if now && !before {
            out.push(ti);
        }
        before = now;
    }
    out
}

/// Counts of `times` in `n` windows `[k w, (k+1) w)`; times beyond the last window count in it.
pub fn count_in_windows(times: &[f64], window: f64, n: usize) -> Vec<u64> {
    let mut counts = vec![0u64; n.max(1)];
    for &t in times {
        let k = if window > 0.0 && t > 0.0 {
            ((t / window) as usize).min(counts.len() - 1)
        } else {
            0
        };
        counts[k] += 1;
    }
    counts
}

/// The direction of change of a sequence of values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Trend {
    /// Every value above the previous one by more than the tolerance.
    Increasing,
    /// Every value below the previous one by more than the tolerance.
    Decreasing,
    /// All values within the tolerance of each other.
    Flat,
    /// Anything else.
    Mixed,
}

impl Trend {
    /// The trend of `values`: successive values closer than `rel_tol` times the largest
    /// magnitude count as equal.
    pub fn of(values: &[f64], rel_tol: f64) -> Trend {
        let scale = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let tol = rel_tol * scale;
        let steps: Vec<f64> = values.windows(2).map(|w| w[1] - w[0]).collect();
        if steps.iter().all(|d| d.abs() <= tol) {
            Trend::Flat
        } else if steps.iter().all(|&d| d > tol) {
            Trend::Increasing
        } else if steps.iter().all(|&d| d < -tol) {
            Trend::Decreasing
        } else {
            Trend::Mixed
        }
    }

    /// `"increases"`, `"decreases"`, `"stays flat"` or `"is not monotonic"`.
    pub fn verb(self) -> &'static str {
        match self {
            Trend::Increasing => "increases",
            Trend::Decreasing => "decreases",
            Trend::Flat => "stays flat",
            Trend::Mixed => "is not monotonic",
        }
    }
}
