//! The clearance twin against the ideal twin: rate deviations, settling of the joint forces.

use super::twin::Twin;
use rapier3d_f64::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;

/// The clearance twin against the ideal twin, from every internal step (both twins built).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Comparison {
    /// Per body: deviation of its angular rate (about the reference axis) from the ideal twin's.
    pub bodies: BTreeMap<String, RateDeviation>,
    /// Per hinge: settling of the joint force.
    pub hinges: BTreeMap<String, Settling>,
}

/// Rate deviation of one body, clearance twin minus ideal twin.
#[derive(Clone, Debug, Default, Serialize)]
pub struct RateDeviation {
    /// Root-mean-square over the run (time-weighted), deg/s.
    pub rms_deg_s: f64,
    /// Largest absolute deviation, deg/s.
    pub max_deg_s: f64,
}

/// When the joint force of a hinge settles.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Settling {
    /// The last time at which the clearance joint force exceeded the ideal joint force by more
    /// than `band_n`: after it the force stays within one ideal peak of the rigid hinge's load.
    /// 0 when it never did.
    pub settling_time_s: f64,
    /// The band: the ideal twin's peak joint force on this hinge, N.
    pub band_n: f64,
}

/// Running sums behind [`Comparison`].
#[derive(Clone, Debug, Default)]
pub(super) struct ComparisonSums {
    rate_sq_time: Vec<f64>,
    rate_max: Vec<f64>,
    /// Per hinge, a stack of `(t, excess)` with decreasing excess and increasing time: for any band
    /// `b`, the last time the excess exceeded `b` is the latest entry above `b`.
    excess: Vec<Vec<(f64, f64)>>,
}

impl ComparisonSums {
    pub(super) fn record(
        &mut self,
        ideal: &Twin,
        clear: &Twin,
        bodies: &RigidBodySet,
        t: f64,
        dt: f64,
    ) {
        let n = ideal.bodies.len();
        self.rate_sq_time.resize(n, 0.0);
        self.rate_max.resize(n, 0.0);
        self.excess.resize(ideal.hinges.len(), Vec::new());
        let axis = ideal.reference_axis;
        for (i, (bi, bc)) in ideal.bodies.iter().zip(&clear.bodies).enumerate() {
            let d = (bodies[bc.handle].angvel() - bodies[bi.handle].angvel())
                .dot(axis)
                .to_degrees();
            self.rate_sq_time[i] += d * d * dt;
            self.rate_max[i] = self.rate_max[i].max(d.abs());
        }
        for (k, (hi, hc)) in ideal.hinges.iter().zip(&clear.hinges).enumerate() {
            let excess = hc.force - hi.force;
            // The band is the ideal peak at the end, at least the peak so far: an excess within
            // it can never be the answer, so it is not stored (memory stays bounded in practice).
            if excess <= hi.recorder.metrics().peak_force_n {
                continue;
            }
            let stack = &mut self.excess[k];
            while stack.last().is_some_and(|&(_, e)| e <= excess) {
                stack.pop();
            }
            stack.push((t, excess));
        }
    }

    pub(super) fn finish(&self, ideal: &Twin, duration: f64) -> Comparison {
        let mut c = Comparison::default();
        for (i, b) in ideal.bodies.iter().enumerate() {
            let rms = if duration > 0.0 {
                (self.rate_sq_time.get(i).copied().unwrap_or(0.0) / duration).sqrt()
            } else {
                0.0
            };
            c.bodies.insert(
                b.name.clone(),
                RateDeviation {
                    rms_deg_s: rms,
                    max_deg_s: self.rate_max.get(i).copied().unwrap_or(0.0),
                },
            );
        }
        for (k, h) in ideal.hinges.iter().enumerate() {
            let band = h.recorder.metrics().peak_force_n;
            let last = self
                .excess
                .get(k)
                .and_then(|s| s.iter().rev().find(|&&(_, e)| e > band))
                .map_or(0.0, |&(t, _)| t);
            c.hinges.insert(
                h.name.clone(),
                Settling {
                    settling_time_s: last,
                    band_n: band,
                },
            );
        }
        c
    }
}
