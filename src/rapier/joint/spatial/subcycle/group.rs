//! The spatial sub-cycles of one island integrated as one system ([`SpatialGroup`]): two spatial
//! pins that share a body (an arm's upper link between its shoulder and its elbow) each press
//! it stiffly, and a sub-cycle that held the other's contact out of its own would integrate
//! each stiff contact against a body the other moves by as much within the step. The
//! deliveries of the two would then add their corrections on the shared body, overshoot, and
//! the pins' rattle would grow from step to step (the SCARA arm on two spatial pins left the
//! physical range within 30 ms at every world rate). Here every pair's position and velocity
//! follow from every pair's impulse through the mobilities between the pairs, and the
//! Rosenbrock stages solve for all of them together: each contact's stiffness is implicit on
//! the shared body too. One pin alone is a group of one, integrated as before.

use super::factor::{Factor, Impulses, Slopes, through};
use super::integrator::{Eval, RegionClock, SpatialCycle};
use super::*;

/// The pairs of one island's spatial sub-cycled joints, each with its [`SpatialCycle`], and the
/// mobilities between them (`cross[a]`: `(b, P_ab)`, how pair `b`'s contact load moves pair
/// `a`).
pub(super) struct SpatialGroup<'a> {
    pub(super) cycles: Vec<SpatialCycle<'a>>,
    pub(super) cross: &'a [Vec<(usize, Square)>],
}

/// One pair's part of the group's state inside the sub-cycle.
struct Member {
    here: Eval,
    slopes: Slopes,
    /// Accepted sub-steps since its Jacobian was taken, the regions in contact there and the
    /// load there.
    age: u32,
    contacts: [bool; 4],
    taken_at: Pair12,
    history: ContactHistory,
    prev: JournalState,
}

impl SpatialGroup<'_> {
    /// Pair `a`'s impulses of every pair `ys`, moved through the mobilities to pair `a`.
    fn moved(&self, a: usize, ys: &[Impulses]) -> (Pair12, Pair12) {
        let p = &self.cycles[a].start.mobility;
        let (mut x, mut v) = (mul(p, &ys[a].pi), mul(p, &ys[a].gamma));
        for (b, p) in &self.cross[a] {
            axpy(&mut x, 1.0, &mul(p, &ys[*b].pi));
            axpy(&mut v, 1.0, &mul(p, &ys[*b].gamma));
        }
        (x, v)
    }

    /// Pair `a`'s position increments and velocities at `t` with the impulses `ys`.
    fn kinematics(&self, a: usize, t: f64, ys: &[Impulses]) -> (Pair12, Pair12) {
        self.cycles[a].kinematics(t, self.moved(a, ys))
    }

    /// The group's `A` and `B` over its `12 n` coordinates: each pair's slopes through the
    /// mobilities from every pair.
    fn system(&self, slopes: &[&Slopes]) -> (Vec<f64>, Vec<f64>) {
        let n = 12 * self.cycles.len();
        let (mut a, mut b) = (vec![0.0; n * n], vec![0.0; n * n]);
        let place = |m: &mut Vec<f64>, (r0, c0): (usize, usize), block: &Square| {
            for (i, x) in block.iter().enumerate() {
                m[(r0 + i / 12) * n + c0 + i % 12] = *x;
            }
        };
        for (k, s) in slopes.iter().enumerate() {
            place(&mut a, (12 * k, 12 * k), &s.a);
            place(&mut b, (12 * k, 12 * k), &s.b);
            for (other, p) in &self.cross[k] {
                place(&mut a, (12 * k, 12 * other), &through(&s.lx, p));
                place(&mut b, (12 * k, 12 * other), &through(&s.lv, p));
            }
        }
        (a, b)
    }

    /// One ROS2 sub-step of `s` from `t`, `ys` (each pair's load `f0` there): the new states
    /// and the largest scaled error of the pairs (accept at or below 1); `None` when the
    /// linear system is singular.
    fn ros2(
        &self,
        parts: &mut [SpatialParts],
        (t, ys, f0): (f64, &[Impulses], &[&Pair12]),
        slopes: &[&Slopes],
        s: f64,
        clocks: &[[RegionClock; 4]],
    ) -> Option<(Vec<Impulses>, f64)> {
        let (a, b) = self.system(slopes);
        let factor = Factor::of(a, &b, s)?;
        let gs = GAMMA * s;
        // Each load's change with time along its reference motion: dx/dt = u0 + a t, dv/dt = a.
        let ft: Vec<Pair12> = self
            .cycles
            .iter()
            .zip(slopes)
            .map(|(c, sl)| {
                let mut drift = c.u0;
                axpy(&mut drift, t, &c.accel);
                let mut ft = mul(&sl.lx, &drift);
                axpy(&mut ft, 1.0, &mul(&sl.lv, &c.accel));
                ft
            })
            .collect();
        let r1: Vec<Impulses> = (0..ys.len())
            .map(|k| {
                let mut r = Impulses {
                    pi: ys[k].gamma,
                    gamma: *f0[k],
                };
                axpy(&mut r.gamma, -1.0, &self.cycles[k].held);
                axpy(&mut r.gamma, gs, &ft[k]);
                r
            })
            .collect();
        let k1 = factor.solve(&r1);
        let y1: Vec<Impulses> = (0..ys.len())
            .map(|k| {
                let mut y = ys[k];
                axpy(&mut y.pi, s, &k1[k].pi);
                axpy(&mut y.gamma, s, &k1[k].gamma);
                y
            })
            .collect();
        let mut r2 = Vec::with_capacity(ys.len());
        for (k, part) in parts.iter_mut().enumerate() {
            let (x1, v1) = self.kinematics(k, t + s, &y1);
            let f1 = self.cycles[k].load(part, &x1, &v1, &clocks[k]);
            let mut r = Impulses {
                pi: y1[k].gamma,
                gamma: f1,
            };
            axpy(&mut r.gamma, -1.0, &self.cycles[k].held);
            axpy(&mut r.pi, -2.0, &k1[k].pi);
            axpy(&mut r.gamma, -2.0, &k1[k].gamma);
            axpy(&mut r.gamma, -gs, &ft[k]);
            r2.push(r);
        }
        let k2 = factor.solve(&r2);
        let mut next = ys.to_vec();
        let mut err = vec![Impulses::default(); ys.len()];
        for (k, (n, e)) in next.iter_mut().zip(err.iter_mut()).enumerate() {
            for (n, e, a, b) in [
                (&mut n.pi, &mut e.pi, &k1[k].pi, &k2[k].pi),
                (&mut n.gamma, &mut e.gamma, &k1[k].gamma, &k2[k].gamma),
            ] {
                axpy(n, 1.5 * s, a);
                axpy(n, 0.5 * s, b);
                axpy(e, 0.5 * s, a);
                axpy(e, 0.5 * s, b);
            }
        }
        let worst = (0..ys.len())
            .map(|k| {
                let (_, v_new) = self.kinematics(k, t + s, &next);
                let (ex, ev) = self.moved(k, &err);
                self.cycles[k].error((&ex, &ev), &v_new)
            })
            .fold(0.0, |w: f64, e| {
                // A non-finite error of any pair rejects the sub-step.
                if w.is_nan() || e.is_nan() {
                    f64::NAN
                } else {
                    w.max(e)
                }
            });
        Some((next, worst))
    }

    /// The shortest of the pairs' impact bounds at their last evaluations.
    fn impact_bound(
        &self,
        parts: &[SpatialParts],
        ys: &[Impulses],
        t: f64,
        clocks: &mut [[RegionClock; 4]],
    ) -> f64 {
        (0..self.cycles.len())
            .map(|k| {
                let (x, _) = self.kinematics(k, t, ys);
                self.cycles[k].impact_bound(&parts[k], &x, &mut clocks[k])
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Integrates the step of every pair from its joint's history and the state at the step's
    /// start (`before`) and its regions' `clocks`, with a first sub-step of `guess` (s); fills
    /// `outs` and returns the last accepted sub-step (the next step's guess).
    pub(super) fn run(
        &mut self,
        parts: &mut [SpatialParts],
        before: &[(ContactHistory, JournalState)],
        clocks: &mut [[RegionClock; 4]],
        guess: f64,
        outs: &mut [SubCycle],
    ) -> f64 {
        let n = self.cycles.len();
        let h = self.cycles[0].h;
        for out in outs.iter_mut() {
            out.samples.clear();
            out.dissipated = 0.0;
        }
        let mut ys = vec![Impulses::default(); n];
        let mut t = 0.0;
        let heres: Vec<Eval> = (0..n)
            .map(|k| {
                let (x, v) = self.kinematics(k, 0.0, &ys);
                self.cycles[k].eval(&mut parts[k], &x, &v, &clocks[k])
            })
            .collect();
        // The loads balancing each pair's free acceleration, held over the step; each moves
        // the pairs it reaches.
        for c in self.cycles.iter_mut() {
            c.held = balancing_load(&c.start.mobility, &c.accel);
        }
        let helds: Vec<Impulses> = self
            .cycles
            .iter()
            .map(|c| Impulses {
                pi: c.held,
                gamma: [0.0; 12],
            })
            .collect();
        for k in 0..n {
            let (moved, _) = self.moved(k, &helds);
            axpy(&mut self.cycles[k].accel, 1.0, &moved);
        }
        // The impacts' bound from the regions' points at the start (before the Jacobian's
        // evaluations move them).
        let mut s = if guess > 0.0 { guess.min(h) } else { h }
            .min(self.impact_bound(parts, &ys, t, clocks));
        let mut members: Vec<Member> = heres
            .into_iter()
            .enumerate()
            .map(|(k, here)| {
                let (x, v) = self.kinematics(k, 0.0, &ys);
                let slopes = self.cycles[k].slopes(&mut parts[k], (&x, &v), &here.load, &clocks[k]);
                Member {
                    contacts: contact_set(&here),
                    taken_at: here.load,
                    here,
                    slopes,
                    age: 0,
                    history: before[k].0,
                    prev: before[k].1,
                }
            })
            .collect();
        let mut count = 0u32;
        let mut accepted = s;
        while t < h {
            let left = h - t;
            // No sliver of a last sub-step.
            let step = if s >= 0.95 * left || count >= MAX_SUBSTEPS {
                left
            } else {
                s
            };
            let loads: Vec<&Pair12> = members.iter().map(|m| &m.here.load).collect();
            let slopes: Vec<&Slopes> = members.iter().map(|m| &m.slopes).collect();
            let trial = self.ros2(parts, (t, &ys, &loads), &slopes, step, clocks);
            let floor = 1e-9 * h;
            let (next, err) = match trial {
                Some((next, err)) if err.is_finite() => (next, err),
                _ if step > floor => {
                    s = 0.5 * step;
                    continue;
                }
                _ => (ys.clone(), 0.0),
            };
            if err > 1.0 && step > floor && count < MAX_SUBSTEPS {
                s = step * (0.9 / err.sqrt()).clamp(0.1, 0.9);
                // A Jacobian of an earlier state may be what failed: retake it here.
                for k in 0..n {
                    if members[k].age == 0 {
                        continue;
                    }
                    let (x, v) = self.kinematics(k, t, &ys);
                    let m = &mut members[k];
                    m.slopes =
                        self.cycles[k].slopes(&mut parts[k], (&x, &v), &m.here.load, &clocks[k]);
                    (m.age, m.taken_at) = (0, m.here.load);
                }
                continue;
            }
            let t_next = if step == left { h } else { t + step };
            let mut ats = Vec::with_capacity(n);
            let mut retry: Option<f64> = None;
            for k in 0..n {
                let (x, v) = self.kinematics(k, t_next, &next);
                let c = &self.cycles[k];
                let at = c.eval(&mut parts[k], &x, &v, &clocks[k]);
                if step > floor && count < MAX_SUBSTEPS {
                    let here = &members[k].here;
                    if let Some(shorter) =
                        c.onset_retry(&parts[k], &x, (here, &at), &clocks[k], step)
                    {
                        retry = Some(retry.map_or(shorter, |r: f64| r.min(shorter)));
                    }
                }
                ats.push(at);
            }
            if let Some(shorter) = retry {
                s = shorter;
                continue;
            }
            count += 1;
            accepted = step;
            for (k, at) in ats.into_iter().enumerate() {
                let (c, m, out) = (&self.cycles[k], &mut members[k], &mut outs[k]);
                let j = c.joint;
                out.dissipated += 0.5 * step * (m.here.dissipation + at.dissipation);
                c.advance(&mut clocks[k], &at.states, step);
                let state = at.states[at.deepest()];
                let onset =
                    m.history
                        .advance(Some(&m.prev), &state, j.min_impact_speed, j.min_separation);
                out.samples.push(SubStep {
                    t: t_next,
                    state,
                    force: at.force,
                    moment: at.moment,
                    onset: onset.onset,
                    impact: onset.impact,
                    approach_speed: onset.approach_speed,
                    onset_fraction: onset.fraction,
                });
                m.prev = state;
                m.here = at;
            }
            (t, ys) = (t_next, next);
            s = step * (0.9 / err.max(1e-12).sqrt()).clamp(0.2, 4.0);
            s = s.min(self.impact_bound(parts, &ys, t, clocks));
            for k in 0..n {
                let m = &mut members[k];
                m.age += 1;
                let touching = contact_set(&m.here);
                let moved = changed(&m.here.load, &m.taken_at);
                // With the reuse off (for comparison) the Jacobian is retaken at every sub-step.
                let max_age = if self.cycles[k].joint.techniques.jacobian_reuse {
                    JACOBIAN_AGE
                } else {
                    1
                };
                if t < h && (m.age >= max_age || touching != m.contacts || moved) {
                    let (x, v) = self.kinematics(k, t, &ys);
                    m.slopes =
                        self.cycles[k].slopes(&mut parts[k], (&x, &v), &m.here.load, &clocks[k]);
                    (m.age, m.contacts, m.taken_at) = (0, touching, m.here.load);
                }
            }
        }
        for (k, out) in outs.iter_mut().enumerate() {
            let (_, v) = self.kinematics(k, h, &ys);
            let (y, held) = (&ys[k], &self.cycles[k].held);
            out.impulse = std::array::from_fn(|i| y.gamma[i] + held[i] * h);
            out.mean = std::array::from_fn(|i| y.pi[i] / h + 0.5 * held[i] * h);
            out.end_velocity = v;
            out.history = members[k].history;
            out.substeps = count;
        }
        accepted
    }
}
