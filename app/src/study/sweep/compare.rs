//! Whether two sweeps or two runs are the same: the sweeps' settings and the runs' physics.

use super::*;

/// Header of a metrics table: which sweep it belongs to.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct SweepInfo {
    /// [`FORMAT_VERSION`].
    pub format: u32,
    /// Sweep name.
    pub name: String,
    /// Base scene name.
    pub scene: String,
    /// Fixed overrides.
    pub base_overrides: Vec<String>,
    /// Swept axes.
    pub axes: Vec<Axis>,
    /// Number of points of the whole grid.
    pub points: usize,
}

impl SweepInfo {
    /// What differs between this sweep and `other`, a phrase per setting (empty when equal),
    /// e.g. ``fixed settings: `run.end_s=1e0` in table 1, `run.end_s=2e0` here``.
    pub fn differences(&self, other: &SweepInfo) -> Vec<String> {
        let mut d = Vec::new();
        let mut differ = |what: &str, a: String, b: String| {
            if a != b {
                d.push(format!("{what}: {a} in table 1, {b} here"));
            }
        };
        differ("format", self.format.to_string(), other.format.to_string());
        differ(
            "name",
            format!("`{}`", self.name),
            format!("`{}`", other.name),
        );
        differ(
            "scene",
            format!("`{}`", self.scene),
            format!("`{}`", other.scene),
        );
        let only = |a: &[String], b: &[String]| -> String {
            let v: Vec<String> = a
                .iter()
                .filter(|x| !b.contains(x))
                .map(|x| format!("`{x}`"))
                .collect();
            if v.is_empty() {
                "nothing else".into()
            } else {
                v.join(", ")
            }
        };
        if self.base_overrides != other.base_overrides {
            differ(
                "fixed settings (--set, --end, --dt, ...)",
                only(&self.base_overrides, &other.base_overrides),
                only(&other.base_overrides, &self.base_overrides),
            );
        }
        let axes = |v: &[Axis]| -> Vec<String> {
            v.iter()
                .map(|a| format!("{}={}", a.path, a.values.join(",")))
                .collect()
        };
        if self.axes != other.axes {
            differ(
                "axes",
                only(&axes(&self.axes), &axes(&other.axes)),
                only(&axes(&other.axes), &axes(&self.axes)),
            );
        }
        differ("points", self.points.to_string(), other.points.to_string());
        d
    }
}

/// Two runs' metrics equal in everything but the wall times (the run's, and its check's).
pub(super) fn same_physics(a: &RunMetrics, b: &RunMetrics) -> bool {
    let mut b = b.clone();
    b.wall_s = a.wall_s;
    if let (
        ConvergenceVerdict::Checked { cost: ca, .. },
        ConvergenceVerdict::Checked { cost: cb, .. },
    ) = (&a.convergence, &mut b.convergence)
    {
        cb.wall_s = ca.wall_s;
        cb.run_wall_s = ca.run_wall_s;
    }
    *a == b
}
