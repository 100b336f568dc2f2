//! Sweep grids: axes of `--set path=v1,v2,...` values, their Cartesian product in a fixed order,
//! deterministic folder names, and shards (`--shard K/N`).

use clearance_joint::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// One swept parameter: an override path (as for `--set`) and the values it takes, in order.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Axis {
    /// Override path, e.g. `hinge.clearance_mm`.
    pub path: String,
    /// Values as written (JSON or bare words), e.g. `["0.1", "0.25"]`.
    pub values: Vec<String>,
}

impl Axis {
    /// An axis from a path and values.
    pub fn new<S: Into<String>>(
        path: impl Into<String>,
        values: impl IntoIterator<Item = S>,
    ) -> Self {
        Axis {
            path: path.into(),
            values: values.into_iter().map(Into::into).collect(),
        }
    }

    /// Parses `path=v1,v2,...`. Commas inside brackets, braces or double quotes belong to the
    /// value (`gravity=[0,0,-9.81],[0,0,0]` has two values).
    pub fn parse(arg: &str) -> Result<Axis> {
        let parse_err = |reason: &str| Error::parse(format!("sweep axis `{arg}`"), reason);
        let (path, raw) = arg
            .split_once('=')
            .ok_or_else(|| parse_err("expected `path=value1,value2,...`"))?;
        let path = path.trim();
        if path.is_empty() {
            return Err(parse_err("the path before `=` is empty"));
        }
        let values = split_top_level(raw).map_err(|r| parse_err(&r))?;
        if let Some(i) = values.iter().position(|v| v.is_empty()) {
            return Err(parse_err(&format!("value {} is empty", i + 1)));
        }
        Ok(Axis {
            path: path.to_string(),
            values,
        })
    }
}

impl Axis {
    /// Refuses a value given twice (as the scene reads it: `0.1` and `0.10` are one value):
    /// the grid would run the same point twice under two names.
    pub fn check_distinct(&self) -> Result<()> {
        let read = |v: &str| {
            serde_json::from_str::<serde_json::Value>(v)
                .unwrap_or_else(|_| serde_json::Value::String(v.to_string()))
        };
        let mut seen: Vec<(serde_json::Value, &str)> = Vec::with_capacity(self.values.len());
        for v in &self.values {
            let value = read(v);
            if let Some((_, first)) = seen.iter().find(|(s, _)| *s == value) {
                return Err(Error::invalid(
                    format!("sweep axis `{}`", self.path),
                    format!(
                        "has the value `{v}` twice (`{first}` and `{v}`): give each value once"
                    ),
                ));
            }
            seen.push((value, v));
        }
        Ok(())
    }
}

/// Splits at commas that are not inside `[]`, `{}` or a double-quoted string; trims each part.
fn split_top_level(raw: &str) -> std::result::Result<Vec<String>, String> {
    let mut parts = Vec::new();
    let mut depth: i32 = 0;
    let mut in_string = false;
    let mut escaped = false;
    let mut current = String::new();
    for ch in raw.chars() {
        if in_string {
            current.push(ch);
            if escaped {
                escaped = false;
            } else if ch == '\\' {
                escaped = true;
            } else if ch == '"' {
                in_string = false;
            }
            continue;
        }
        match ch {
            '"' => in_string = true,
            '[' | '{' => depth += 1,
            ']' | '}' => {
                depth -= 1;
                if depth < 0 {
                    return Err("unbalanced `]` or `}`".into());
                }
            }
            ',' if depth == 0 => {
                parts.push(current.trim().to_string());
                current.clear();
                continue;
            }
            _ => {}
        }
        current.push(ch);
    }
    if in_string || depth != 0 {
        return Err("unbalanced brackets or quotes".into());
    }
    parts.push(current.trim().to_string());
    Ok(parts)
}

/// The Cartesian product of axes. Point order is that of nested loops in the order the axes
/// were given: the first axis varies slowest, the last fastest. No axis: one point (the base scene).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Grid {
    /// The axes, outermost first.
    pub axes: Vec<Axis>,
}

/// One point of a grid.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Point {
    /// Position in the grid order, from 0.
    pub index: usize,
    /// `(path, value)` for every axis, in axis order.
    pub assignments: Vec<(String, String)>,
    /// The point's folder name (see [`Grid::point`]).
    pub dir: String,
}

impl Point {
    /// The point's overrides, `path=value`, in axis order.
    pub fn overrides(&self) -> Vec<String> {
        self.assignments
            .iter()
            .map(|(p, v)| format!("{p}={v}"))
            .collect()
    }
}

impl Grid {
    /// A grid of `axes`; refuses an axis without values and a path given twice.
    pub fn new(axes: Vec<Axis>) -> Result<Grid> {
        for (i, a) in axes.iter().enumerate() {
            if a.values.is_empty() {
                return Err(Error::invalid(
                    format!("sweep axis `{}`", a.path),
                    "has no values",
                ));
            }
            if axes[..i].iter().any(|b| b.path == a.path) {
                return Err(Error::invalid(
                    format!("sweep axis `{}`", a.path),
                    "is given twice: put all its values in one `--set path=v1,v2,...`",
                ));
            }
            a.check_distinct()?;
        }
        let g = Grid { axes };
        g.checked_len()?;
        Ok(g)
    }

    fn checked_len(&self) -> Result<usize> {
        self.axes.iter().try_fold(1usize, |n, a| {
            n.checked_mul(a.values.len()).ok_or_else(|| {
                Error::invalid(
                    "sweep grid",
                    format!(
                        "has more points than can be counted ({}): sweep fewer values",
                        self.axes
                            .iter()
                            .map(|a| a.values.len().to_string())
                            .collect::<Vec<_>>()
                            .join(" x ")
                    ),
                )
            })
        })
    }

    /// Number of points (the product of the axis lengths).
    pub fn len(&self) -> usize {
        self.axes.iter().map(|a| a.values.len()).product()
    }

    /// True when the grid has no point (never: an empty grid has one point).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Point `index` (`index < len()`). Its folder name is the zero-padded index followed, for
    /// every axis with more than one value, by `-path=value` (characters other than letters,
    /// digits and `._=+-` replaced by `_`, long values shortened with a hash of the whole value),
    /// e.g. `004-hinge.clearance_mm=0.25-drive.torque_scale=3`. The index alone makes it unique.
    pub fn point(&self, index: usize) -> Point {
        let mut rest = index;
        let mut picks = vec![0usize; self.axes.len()];
        for (k, a) in self.axes.iter().enumerate().rev() {
            picks[k] = rest % a.values.len();
            rest /= a.values.len();
        }
        let assignments: Vec<(String, String)> = self
            .axes
            .iter()
            .zip(&picks)
            .map(|(a, &i)| (a.path.clone(), a.values[i].clone()))
            .collect();
        let width = digits(self.len().saturating_sub(1)).max(3);
        let mut dir = format!("{index:0width$}");
        for (a, (p, v)) in self.axes.iter().zip(&assignments) {
            if a.values.len() > 1 {
                dir.push('-');
                dir.push_str(&sanitize(p, 60));
                dir.push('=');
                dir.push_str(&sanitize(v, 40));
            }
        }
        Point {
            index,
            assignments,
            dir,
        }
    }

    /// Every point, in order (built one by one: a large grid is never held whole).
    pub fn points(&self) -> impl Iterator<Item = Point> + '_ {
        (0..self.len()).map(|i| self.point(i))
    }
}

fn digits(mut n: usize) -> usize {
    let mut d = 1;
    while n >= 10 {
        n /= 10;
        d += 1;
    }
    d
}

/// A file-name-safe form of `s`, at most about `max` characters (a hash keeps shortened names distinct).
fn sanitize(s: &str, max: usize) -> String {
    let clean: String = s
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "._=+-".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    if clean.len() <= max {
        clean
    } else {
        format!("{}~{:08x}", &clean[..max], fnv1a(s.as_bytes()) as u32)
    }
}

/// FNV-1a, 64 bit: a stable hash (the same on every machine and Rust version).
pub(crate) fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf29ce484222325;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x100000001b3);
    }
    h
}

/// A share of a grid: the points whose index `i` has `i % n == k` (`0 <= k < n`).
/// `--shard K/N` on N machines (a job array with tasks 0..N-1) covers every point exactly once.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// This shard, `0 <= k < n` (private: built by [`Shard::new`], which refuses `n = 0`).
    k: usize,
    n: usize,
}

impl Default for Shard {
    fn default() -> Self {
        Shard::ALL
    }
}

impl Shard {
    /// The whole grid (shard 0 of 1).
    pub const ALL: Shard = Shard { k: 0, n: 1 };

    /// Shard `k` of `n`; refuses `n = 0` and `k >= n`.
    pub fn new(k: usize, n: usize) -> Result<Shard> {
        if n == 0 {
            return Err(Error::invalid("--shard", "N must be at least 1 (K/N)"));
        }
        if k >= n {
            return Err(Error::invalid(
                "--shard",
                format!("K must be in 0..N-1 (got {k}/{n}): shards are numbered from 0"),
            ));
        }
        Ok(Shard { k, n })
    }

    /// Parses `K/N`.
    pub fn parse(s: &str) -> Result<Shard> {
        let err = |reason: String| Error::parse(format!("shard `{s}`"), reason);
        let (k, n) = s
            .split_once('/')
            .ok_or_else(|| err("expected K/N, e.g. 0/4".into()))?;
        let k: usize = k.trim().parse().map_err(|e| err(format!("K: {e}")))?;
        let n: usize = n.trim().parse().map_err(|e| err(format!("N: {e}")))?;
        Shard::new(k, n)
    }

    /// This shard's index `K`.
    pub fn index(&self) -> usize {
        self.k
    }

    /// The number of shards `N`.
    pub fn count(&self) -> usize {
        self.n
    }

    /// Whether point `index` belongs to this shard.
    pub fn contains(&self, index: usize) -> bool {
        index % self.n == self.k
    }

    /// True for the whole grid.
    pub fn is_all(&self) -> bool {
        self.n == 1
    }

    /// The indices of `grid`'s points in this shard, in grid order.
    pub fn indices(&self, grid: &Grid) -> std::iter::StepBy<std::ops::Range<usize>> {
        (self.k..grid.len().max(self.k)).step_by(self.n)
    }

    /// The number of `grid`'s points in this shard.
    pub fn len(&self, grid: &Grid) -> usize {
        grid.len().saturating_sub(self.k).div_ceil(self.n)
    }

    /// The points of `grid` in this shard, in grid order, built one by one.
    pub fn points<'g>(&self, grid: &'g Grid) -> impl Iterator<Item = Point> + 'g {
        self.indices(grid).map(|i| grid.point(i))
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}
