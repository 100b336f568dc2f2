//! Tick labels of the figures' axes: one number of decimals per axis, the fewest that write
//! every tick exactly, and never "-0.0" (plotters' own labels print each tick alone, so an axis
//! read "0.2, 0.25, 0.3" and a tick a rounding error below zero read "-0.0").

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::Ranged;

/// Labelled ticks per axis (plotters' default, set explicitly so the formatter sees the same
/// ticks as the mesh).
pub const TICKS: usize = 11;

/// Decimals beyond which a tick is taken as not a short decimal at all.
const MAX_DECIMALS: usize = 12;

/// How the tick labels of one axis are written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TickFormat {
    /// Decimals of every label of the axis.
    pub decimals: usize,
}

impl TickFormat {
    /// The format of the axis over `[lo, hi]` with at most `count` labelled ticks, placed as
    /// plotters places them: the fewest decimals that write each of its ticks exactly.
    pub fn for_axis(lo: f64, hi: f64, count: usize) -> TickFormat {
        let ticks = RangedCoordf64::from(lo.min(hi)..lo.max(hi)).key_points(count);
        TickFormat::for_ticks(&ticks)
    }

    /// The fewest decimals that write each of `ticks` exactly (to a millionth of the last
    /// digit, which absorbs the binary rounding of steps like 0.1).
    pub fn for_ticks(ticks: &[f64]) -> TickFormat {
        let exact = |d: usize| {
            let m = 10f64.powi(d as i32);
            ticks.iter().all(|&t| {
                let s = t * m;
                (s - s.round()).abs() <= 1e-6 * s.abs().max(1.0)
            })
        };
        let decimals = (0..MAX_DECIMALS)
            .find(|&d| exact(d))
            .unwrap_or(MAX_DECIMALS);
        TickFormat { decimals }
    }

    /// `v` with the axis's decimals; a value that rounds to zero is "0", never "-0".
    pub fn format(&self, v: f64) -> String {
        let s = format!("{v:.*}", self.decimals);
        match s.strip_prefix('-') {
            Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_string(),
            _ => s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(lo: f64, hi: f64) -> Vec<String> {
        let f = TickFormat::for_axis(lo, hi, TICKS);
        RangedCoordf64::from(lo..hi)
            .key_points(TICKS)
            .into_iter()
            .map(|t| f.format(t))
            .collect()
    }

    fn decimals(label: &str) -> usize {
        label.split_once('.').map_or(0, |(_, d)| d.len())
    }

    #[test]
    fn no_axis_gets_a_negative_zero_or_mixed_decimals() {
        // The solar panel's axes: trajectory (+-1.15 c), force, angles, rates, time.
        let axes = [
            (-0.575, 0.575),
            (0.0, 0.344),
            (0.0, 180.3),
            (-0.7363, 0.0347),
            (-0.4354, 0.0207),
            (-2.6, 55.1),
            (0.0, 5.0),
            (-1e-17, 1.0),
            (-3.0e-5, 2.0e-5),
            (-1234.5, 98765.0),
        ];
        for (lo, hi) in axes {
            let l = labels(lo, hi);
            assert!(l.len() >= 2, "{lo}..{hi}: {l:?}");
            let negative_zero = |s: &String| s.starts_with('-') && s[1..].parse() == Ok(0.0);
            assert!(!l.iter().any(negative_zero), "{lo}..{hi}: {l:?}");
            let d = decimals(&l[0]);
            assert!(l.iter().all(|s| decimals(s) == d), "{lo}..{hi}: {l:?}");
        }
    }

    #[test]
    fn decimals_are_the_fewest_that_write_the_ticks() {
        assert_eq!(TickFormat::for_ticks(&[0.0, 0.05, 0.1, 0.15]).decimals, 2);
        assert_eq!(TickFormat::for_ticks(&[0.0, 0.1 + 0.2, 0.6]).decimals, 1);
        assert_eq!(TickFormat::for_ticks(&[0.0, 20.0, 180.0]).decimals, 0);
        let f = TickFormat::for_ticks(&[-0.5, 0.0, 0.5]);
        assert_eq!(f.format(-1e-17), "0.0");
        assert_eq!(f.format(-0.0), "0.0");
        assert_eq!(f.format(-0.5), "-0.5");
    }
}
