//! Run summaries (`summary.json`), result files and the printed comparison table.

use crate::error::{Error, Result};
use crate::scene::output::{Render, Staging, write_set};
use crate::scene::runner::convergence::ConvergenceVerdict;
use crate::scene::runner::{HingeMetrics, Invariants, RunResult, Twin};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

/// `summary.json`: the run and, for each twin, metrics computed from every internal step.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// Scene name.
    pub scene: String,
    /// Step, s.
    pub dt_s: f64,
    /// Simulated time asked for, s.
    pub end_s: f64,
    /// Whether the run reached `end_s`. `false`: the step control stopped it (`error` says why)
    /// and every file of the set holds what was computed up to `reached_s`.
    pub complete: bool,
    /// Simulated time of the last state recorded, s (`end_s` when complete).
    pub reached_s: f64,
    /// What stopped an incomplete run (null when complete).
    pub error: Option<String>,
    /// Per twin (`ideal`, `clearance`).
    pub twins: BTreeMap<String, TwinSummary>,
    /// Clearance twin against ideal twin (null unless both ran).
    pub comparison: Option<crate::scene::runner::Comparison>,
    /// No gravity and no fixed body: total momentum must be conserved, and the drift metrics mean
    /// something (with gravity or a ground body they do not).
    pub free_floating: bool,
    /// The step control in words.
    pub stepping: String,
    /// What the run-time guards saw: rejected steps, the deepest penetration against its law's
    /// validity, steps at the floor, and violations in words (empty when the run stayed valid).
    pub guards: crate::rapier::pipeline::protocol::GuardReport,
    /// The convergence check's verdict: which metrics converged against a run at half the
    /// tolerance, which did not, and what the check cost; or why none was made
    /// ([`ConvergenceVerdict`]).
    pub convergence: ConvergenceVerdict,
}

/// Metrics of one twin.
#[derive(Clone, Debug, Serialize)]
pub struct TwinSummary {
    /// Internal steps.
    pub steps: u64,
    /// Wall time of the run, s (both twins share one world and one clock).
    pub wall_s: f64,
    /// Final angle of every body (about the reference axis) and hinge (relative), deg.
    pub final_angles_deg: BTreeMap<String, f64>,
    /// Largest joint force over all hinges, N.
    pub peak_joint_force_n: f64,
    /// [Onsets](crate::rapier::observers::metrics#onsets-impacts-and-chatter) over all hinges, chatter
    /// included.
    pub onsets: u64,
    /// Earliest contact onset, s (null without contact).
    pub first_impact_t_s: Option<f64>,
    /// Peak force of that first contact, N.
    pub first_impact_peak_n: Option<f64>,
    /// Largest penetration over all hinges, um.
    pub max_penetration_um: f64,
    /// Relative drift of total linear momentum (null when the scene is not free-floating: then
    /// momentum is not conserved and the energy balance in `invariants` is the check).
    pub linear_momentum_drift: Option<f64>,
    /// Relative drift of total angular momentum (null when not free-floating).
    pub angular_momentum_drift: Option<f64>,
    /// Energy invariants.
    pub invariants: Invariants,
    /// Per hinge.
    pub hinges: BTreeMap<String, HingeMetrics>,
}

impl TwinSummary {
    /// Summarises `twin`.
    pub fn of(twin: &Twin, steps: u64, wall_s: f64) -> TwinSummary {
        let hinges = twin.hinge_metrics();
        let first = hinges
            .values()
            .filter_map(|m| Some((m.first_impact_t_s?, m.first_impact_peak_n?)))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        TwinSummary {
            steps,
            wall_s,
            final_angles_deg: twin.final_angles_deg(),
            peak_joint_force_n: hinges.values().map(|m| m.peak_force_n).fold(0.0, f64::max),
            onsets: hinges.values().map(|m| m.onsets).sum(),
            first_impact_t_s: first.map(|f| f.0),
            first_impact_peak_n: first.map(|f| f.1),
            max_penetration_um: hinges
                .values()
                .map(|m| m.max_penetration_um)
                .fold(0.0, f64::max),
            linear_momentum_drift: twin.invariants.linear_momentum_drift,
            angular_momentum_drift: twin.invariants.angular_momentum_drift,
            invariants: twin.invariants.clone(),
            hinges,
        }
    }
}

impl RunResult {
    /// The summary of this run, its convergence not checked
    /// ([`write_checked`](Self::write_checked) records a check's verdict).
    pub fn summary(&self) -> Summary {
        Summary {
            scene: self.scene.name.clone(),
            dt_s: self.scene.run.dt_s,
            end_s: self.scene.run.end_s,
            complete: self.stopped.is_none(),
            reached_s: self.reached_s,
            error: self.stopped.as_ref().map(|e| e.to_string()),
            twins: self
                .twins
                .iter()
                .map(|t| {
                    (
                        t.kind.name().to_string(),
                        TwinSummary::of(t, self.steps, self.wall_s),
                    )
                })
                .collect(),
            comparison: self.comparison.clone(),
            free_floating: self.scene.gravity == [0.0; 3]
                && self.scene.bodies.iter().all(|b| !b.fixed),
            stepping: self.scene.run.stepping(),
            guards: self.guards.clone(),
            convergence: ConvergenceVerdict::default(),
        }
    }

    /// The twin of `kind`, if built.
    pub fn twin(&self, kind: crate::scene::runner::TwinKind) -> Option<&Twin> {
        self.twins.iter().find(|t| t.kind == kind)
    }

    /// Writes `<twin>.csv` for each twin, `<twin>_<joint>_impacts.csv` for each clearance joint
    /// (its contact list, every onset, from its
    /// [`ImpactRecorder`](crate::rapier::observers::metrics::ImpactRecorder)),
    /// `<twin>_<joint>_turns.csv` when a body spins (per-turn statistics of that list)
    /// and `summary.json` into `dir` as one set
    /// ([`write_set`]): the tables are streamed (and checked finite) into temporary files, then
    /// renamed into place, `summary.json` last. An incomplete run ([`RunResult::stopped`])
    /// writes the same files, each up to the time it reached, and says so in `summary.json`
    /// (`"complete": false`, `reached_s`, `error`). Its `convergence` says no check was run;
    /// [`write_checked`](Self::write_checked) records one.
    pub fn write(&self, dir: &Path) -> Result<Summary> {
        self.write_checked(dir, &ConvergenceVerdict::default(), &Staging::new())
    }

    /// As [`write`](Self::write), `summary.json` recording `convergence`, the verdict of the
    /// run's convergence check
    /// ([`Convergence::verdict`](crate::scene::runner::convergence::Convergence::verdict)), the
    /// temporaries recorded in `staging` while they exist (an application's, which removes them
    /// on an interrupt).
    pub fn write_checked(
        &self,
        dir: &Path,
        convergence: &ConvergenceVerdict,
        staging: &Staging,
    ) -> Result<Summary> {
        let mut summary = self.summary();
        summary.convergence = convergence.clone();
        let json = summary_json(&summary)?;
        // One contact list per clearance joint, `<twin>_<joint>_impacts.csv`.
        let mut impact_tables: Vec<(std::path::PathBuf, crate::table::Table)> = Vec::new();
        for t in &self.twins {
            let recorders = t.hinge_recorders();
            let period = self.scene.drive_period();
            // An incomplete run's turns end where it stopped.
            let end = self.reached_s;
            for h in t.clearance_hinges() {
                impact_tables.push((
                    dir.join(format!("{}_{h}_impacts.csv", t.kind.name())),
                    recorders[h].contacts_table(),
                ));
                // Per crank turn when a body spins.
                if let Some(p) = period {
                    let turns = crate::rapier::observers::metrics::per_period(
                        recorders[h].contacts(),
                        p,
                        end,
                    )
                    .map_err(|e| e.within("run.end_s"))?;
                    impact_tables.push((
                        dir.join(format!("{}_{h}_turns.csv", t.kind.name())),
                        crate::rapier::observers::metrics::per_period_table(&turns),
                    ));
                }
            }
        }
        let paths: Vec<std::path::PathBuf> = self
            .twins
            .iter()
            .map(|t| dir.join(format!("{}.csv", t.kind.name())))
            .collect();
        let mut files: Vec<(&Path, Render)> = self
            .twins
            .iter()
            .zip(&paths)
            .map(|(t, path)| {
                let render: Render = Box::new(move |w: &mut dyn std::io::Write| {
                    t.table.write_csv(w).map_err(|e| match e {
                        Error::Io { action, source, .. } => Error::Io {
                            action,
                            path: path.clone(),
                            source,
                        },
                        other => other,
                    })
                });
                (path.as_path(), render)
            })
            .collect();
        for (path, table) in &impact_tables {
            let render: Render = Box::new(move |w: &mut dyn std::io::Write| {
                table.write_csv(w).map_err(|e| match e {
                    Error::Io { action, source, .. } => Error::Io {
                        action,
                        path: path.clone(),
                        source,
                    },
                    other => other,
                })
            });
            files.push((path.as_path(), render));
        }
        let summary_path = dir.join("summary.json");
        let json_path = summary_path.clone();
        files.push((
            summary_path.as_path(),
            Box::new(move |w: &mut dyn std::io::Write| {
                w.write_all(json.as_bytes()).map_err(|source| Error::Io {
                    action: "cannot write",
                    path: json_path.clone(),
                    source,
                })
            }),
        ));
        write_set(&files, staging)?;
        Ok(summary)
    }
}

/// Pretty JSON of a summary; refuses non-finite numbers (JSON has none).
pub fn summary_json(summary: &Summary) -> Result<String> {
    let value =
        serde_json::to_value(summary).map_err(|e| Error::invalid("summary", e.to_string()))?;
    // serde_json writes a non-finite float as null: a null is allowed only where a metric is
    // legitimately absent (no impact yet, only one twin), so a NaN anywhere else is caught here.
    const MAY_BE_NULL: [&str; 10] = [
        "error",
        "worst",
        "first_impact_t_s",
        "first_impact_peak_n",
        "comparison",
        "linear_momentum_drift",
        "angular_momentum_drift",
        "energy_growth",
        "energy_error",
        "motor_speed_error",
    ];
    fn check(v: &serde_json::Value, key: &str, path: &str, end: f64) -> Result<()> {
        match v {
            serde_json::Value::Null if !MAY_BE_NULL.contains(&key) => Err(Error::diverged(
                end,
                crate::error::Divergence::NonFinite {
                    name: path.to_string(),
                    place: "in the summary".into(),
                    value: None,
                },
            )),
            serde_json::Value::Object(o) => o
                .iter()
                .try_for_each(|(k, c)| check(c, k, &format!("{path}.{k}"), end)),
            serde_json::Value::Array(a) => a
                .iter()
                .enumerate()
                .try_for_each(|(i, c)| check(c, key, &format!("{path}[{i}]"), end)),
            _ => Ok(()),
        }
    }
    check(&value, "summary", "summary", summary.end_s)?;
    serde_json::to_string_pretty(&value).map_err(|e| Error::invalid("summary", e.to_string()))
}

/// The comparison table's rows of each spatial hinge (a planar scene has none): its largest
/// tilt and the peaks of its edge and face forces (lower / upper); `-` in a twin where the hinge
/// is ideal.
fn spatial_rows(twins: &[(&String, &TwinSummary)], rows: &mut Vec<(String, Vec<String>)>) {
    let names: std::collections::BTreeSet<&String> = twins
        .iter()
        .flat_map(|(_, t)| t.hinges.iter())
        .filter(|(_, m)| m.spatial.is_some())
        .map(|(name, _)| name)
        .collect();
    type Cell = fn(&crate::rapier::observers::metrics::SpatialMetrics) -> String;
    let cells: [(&str, Cell); 3] = [
        ("max tilt (deg)", |m| format!("{:.4}", m.max_tilt_deg)),
        ("peak edge forces (N)", |m| {
            format!(
                "{:.1}/{:.1}",
                m.peak_edge_force_n[0], m.peak_edge_force_n[1]
            )
        }),
        ("peak face forces (N)", |m| {
            format!(
                "{:.1}/{:.1}",
                m.peak_face_force_n[0], m.peak_face_force_n[1]
            )
        }),
    ];
    for name in names {
        for (label, cell) in cells {
            rows.push((
                format!("{name} {label}"),
                twins
                    .iter()
                    .map(|(_, t)| {
                        t.hinges
                            .get(name)
                            .and_then(|m| m.spatial.as_ref())
                            .map_or("-".to_string(), cell)
                    })
                    .collect(),
            ));
        }
    }
}

/// A short side-by-side table of the twins for the terminal.
pub fn comparison_table(summary: &Summary) -> String {
    let twins: Vec<(&String, &TwinSummary)> = summary.twins.iter().rev().collect(); // ideal, clearance
    let mut rows: Vec<(String, Vec<String>)> = Vec::new();
    if let Some((_, first)) = twins.first() {
        for name in first.final_angles_deg.keys() {
            rows.push((
                format!("final {name} angle (deg)"),
                twins
                    .iter()
                    .map(|(_, t)| format!("{:.4}", t.final_angles_deg[name]))
                    .collect(),
            ));
        }
    }
    let opt = |x: Option<f64>, p: usize| x.map_or("-".to_string(), |v| format!("{v:.p$}"));
    rows.push((
        "peak joint force (N)".into(),
        twins
            .iter()
            .map(|(_, t)| format!("{:.4}", t.peak_joint_force_n))
            .collect(),
    ));
    rows.push((
        "onsets".into(),
        twins.iter().map(|(_, t)| t.onsets.to_string()).collect(),
    ));
    rows.push((
        "first impact (s)".into(),
        twins
            .iter()
            .map(|(_, t)| opt(t.first_impact_t_s, 4))
            .collect(),
    ));
    rows.push((
        "first impact peak (N)".into(),
        twins
            .iter()
            .map(|(_, t)| opt(t.first_impact_peak_n, 3))
            .collect(),
    ));
    rows.push((
        "max penetration (um)".into(),
        twins
            .iter()
            .map(|(_, t)| format!("{:.3}", t.max_penetration_um))
            .collect(),
    ));
    spatial_rows(&twins, &mut rows);
    rows.push((
        "momentum drift lin/ang".into(),
        twins
            .iter()
            .map(
                |(_, t)| match (t.linear_momentum_drift, t.angular_momentum_drift) {
                    (Some(l), Some(a)) => format!("{l:.1e}/{a:.1e}"),
                    _ => "n/a (not free-floating)".to_string(),
                },
            )
            .collect(),
    ));
    rows.push((
        "energy balance growth".into(),
        twins
            .iter()
            .map(|(_, t)| {
                let none = if t.invariants.driven {
                    "n/a (driven)"
                } else {
                    "n/a (at rest)"
                };
                t.invariants
                    .energy_growth
                    .map_or(none.to_string(), |g| format!("{g:.1e}"))
            })
            .collect(),
    ));
    let w0 = rows.iter().map(|r| r.0.len()).max().unwrap_or(0);
    let mut s = format!("{:w0$}", "");
    for (name, _) in &twins {
        s.push_str(&format!("  {name:>16}"));
    }
    s.push('\n');
    for (label, vals) in rows {
        s.push_str(&format!("{label:w0$}"));
        for v in vals {
            s.push_str(&format!("  {v:>16}"));
        }
        s.push('\n');
    }
    if summary.guards.is_clean() {
        s.push_str(&format!(
            "guards: clean ({} rejected steps, deepest penetration {:.3} of its law's validity)\n",
            summary.guards.rejected_steps, summary.guards.worst_penetration_ratio
        ));
    } else {
        for v in summary.guards.messages() {
            s.push_str(&format!("WARNING: {v}\n"));
        }
    }
    if let Some(e) = &summary.error {
        s.push_str(&format!(
            "INCOMPLETE: the run stopped at t = {} s of {} s; every file holds what was computed \
             up to it (summary.json: \"complete\": false): {e}\n",
            crate::error::sig4(summary.reached_s),
            crate::error::sig4(summary.end_s)
        ));
    }
    s
}
