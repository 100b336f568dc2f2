//! The memory a run will hold, estimated before it starts, against the memory this machine
//! has ([`available_memory`]) or a budget given as a size ([`parse_bytes`]).

use clearance_joint::error::{Error, Result, sig4};

/// The memory a run will hold for its output rows, estimated from the scene before it starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MemoryEstimate {
    /// Output rows per twin.
    pub rows: u64,
    /// Values per row, over both twins.
    pub values_per_row: u64,
    /// Bytes: the rows' values (8 bytes each) held twice, for a table's growth by doubling,
    /// plus a fixed allowance for the world and the program, plus [`replay_bytes`](Self::replay_bytes).
    pub bytes: u64,
    /// Bytes of the run's replay, when one is recorded (0 otherwise): what its recorder and
    /// page hold at their peak, as the application that builds them states
    /// ([`with_replay`](Self::with_replay)).
    pub replay_bytes: u64,
}

/// Fixed allowance of a run beyond its rows (program, Rapier world, buffers), bytes.
const BASE_BYTES: u64 = 64 << 20;

impl MemoryEstimate {
    /// The estimate for one run of `scene` with both twins: rows from `run.end_s` and
    /// `run.output_interval_s` (fixed steps: the interval rounded to whole steps), one time
    /// column, two per body and seven per hinge, per twin.
    pub fn of(scene: &clearance_joint::scene::Scene) -> MemoryEstimate {
        let r = &scene.run;
        let rows = match r.step {
            clearance_joint::scene::StepMode::Fixed => {
                let steps = (r.end_s / r.dt_s).round().max(1.0);
                let stride = (r.output_interval_s / r.dt_s).round().max(1.0);
                (steps / stride + 1e-9).floor() + 2.0
            }
            // Adaptive, and any mode to come: one row per output interval.
            _ => (r.end_s / r.output_interval_s + 1e-9).floor() + 2.0,
        };
        let rows = if rows.is_finite() {
            rows.min(u64::MAX as f64 / 1e3) as u64
        } else {
            u64::MAX / 1000
        };
        let motion = if scene.run.body_motion { 9 } else { 0 };
        let per_twin = 1
            + (2 + motion) * scene.bodies.len() as u64
            + 7 * scene.hinges.len() as u64
            + scene.joints.len() as u64;
        let values_per_row = 2 * per_twin;
        let bytes = rows
            .saturating_mul(values_per_row)
            .saturating_mul(16)
            .saturating_add(BASE_BYTES);
        MemoryEstimate {
            rows,
            values_per_row,
            bytes,
            replay_bytes: 0,
        }
    }

    /// The estimate with a replay of `replay_bytes` recorded beside the rows (replacing any
    /// replay counted before).
    pub fn with_replay(self, replay_bytes: u64) -> MemoryEstimate {
        MemoryEstimate {
            bytes: self
                .bytes
                .saturating_sub(self.replay_bytes)
                .saturating_add(replay_bytes),
            replay_bytes,
            ..self
        }
    }

    /// Refuses the run when `concurrent` such runs would need more than `budget` bytes, with the
    /// numbers and the fields to change (a larger `run.output_interval_s`, the smallest that
    /// fits: [`fitting_interval`](Self::fitting_interval)).
    pub fn check(
        &self,
        scene: &clearance_joint::scene::Scene,
        concurrent: u64,
        budget: u64,
    ) -> Result<()> {
        let need = self.bytes.saturating_mul(concurrent.max(1));
        if need <= budget {
            return Ok(());
        }
        let advice = match self.fitting_interval(scene, concurrent, budget) {
            Some(interval) => format!(
                "use `run.output_interval_s` = {} or larger (or a shorter `run.end_s`, or a larger \
                 memory budget)",
                sig4(interval)
            ),
            None => format!(
                "that is less than the {} a run needs beyond its rows: raise the memory budget{}",
                bytes_text(BASE_BYTES.saturating_add(self.replay_bytes)),
                if concurrent > 1 {
                    " or run fewer in parallel"
                } else {
                    ""
                }
            ),
        };
        Err(Error::invalid(
            "run.output_interval_s",
            format!(
                "{} rows of {} values{}{} would need about {} of memory, more than the {} available: {advice}",
                sig4(self.rows as f64),
                self.values_per_row,
                if self.replay_bytes > 0 {
                    format!(" and the replay (about {})", bytes_text(self.replay_bytes))
                } else {
                    String::new()
                },
                if concurrent > 1 {
                    format!(" in each of {concurrent} parallel runs")
                } else {
                    String::new()
                },
                bytes_text(need),
                bytes_text(budget),
            ),
        ))
    }

    /// The smallest output interval, s (2 significant digits, rounded up), at which
    /// `concurrent` runs of `scene` fit `budget` bytes; `None` when no interval does (the budget
    /// is below what a run needs beyond its rows).
    pub fn fitting_interval(
        &self,
        scene: &clearance_joint::scene::Scene,
        concurrent: u64,
        budget: u64,
    ) -> Option<f64> {
        let per_run = budget / concurrent.max(1);
        let fixed = BASE_BYTES.saturating_add(self.replay_bytes);
        let fit_rows = per_run.saturating_sub(fixed) / (16 * self.values_per_row.max(1));
        (fit_rows > 2).then(|| round_up_sig(scene.run.end_s / (fit_rows - 2) as f64))
    }
}

/// `x` rounded up to 2 significant digits (a suggested option value).
fn round_up_sig(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return x;
    }
    let p = 10f64.powf(x.log10().floor() - 1.0);
    (x / p).ceil() * p
}

/// Bytes as `1.23 GB` (powers of 1000).
pub fn bytes_text(bytes: u64) -> String {
    let b = bytes as f64;
    for (unit, scale) in [("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)] {
        if b >= scale {
            return format!("{} {unit}", sig4(b / scale));
        }
    }
    format!("{bytes} B")
}

/// Parses a memory size: bytes, or a number with `k`, `M`, `G` or `T` (powers of 1024 with
/// `KiB`..`TiB`, of 1000 with `kB`..`TB` or the bare letter).
pub fn parse_bytes(text: &str) -> Result<u64> {
    let t = text.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == 'e' || c == 'E'))
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let scale = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 1.0,
        "k" | "kb" => 1e3,
        "m" | "mb" => 1e6,
        "g" | "gb" => 1e9,
        "t" | "tb" => 1e12,
        "kib" => 1024.0,
        "mib" => 1024.0 * 1024.0,
        "gib" => 1024.0 * 1024.0 * 1024.0,
        "tib" => 1024.0f64.powi(4),
        _ => f64::NAN,
    };
    let v: f64 = num.parse().unwrap_or(f64::NAN) * scale;
    if v.is_finite() && v > 0.0 {
        Ok(v as u64)
    } else {
        Err(Error::invalid(
            "size",
            format!(
                "expected a size such as 4G, 512M or 2GiB (got `{}`)",
                clearance_joint::error::excerpt(text, 40)
            ),
        ))
    }
}

/// Memory this process may use: 80 % of what the system reports available (Linux
/// `MemAvailable`, and a cgroup limit when there is one); `None` when unknown.
pub fn available_memory() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let avail_kb: u64 = meminfo
        .lines()
        .find_map(|l| l.strip_prefix("MemAvailable:"))?
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    let mut avail = avail_kb.saturating_mul(1024);
    for (limit, usage) in [
        ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
        (
            "/sys/fs/cgroup/memory/memory.limit_in_bytes",
            "/sys/fs/cgroup/memory/memory.usage_in_bytes",
        ),
    ] {
        let read =
            |p: &str| -> Option<u64> { std::fs::read_to_string(p).ok()?.trim().parse().ok() };
        if let (Some(l), Some(u)) = (read(limit), read(usage)) {
            avail = avail.min(l.saturating_sub(u));
        }
    }
    Some(avail / 5 * 4)
}
