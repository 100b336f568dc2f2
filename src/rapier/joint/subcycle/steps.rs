//! One joint's sub-steps: the contact at a position of the sub-cycle ([`Here`]), the kick
//! (the law's elastic force at the position, damping and friction implicit), the sub-step's
//! length, and what a sub-cycle hands back ([`SubCycle`]).

use super::pair::{Motion, Pair12, PairStart, axpy, dot, load, mul, part, put, rotate, row};
use super::{APPROACH_FRACTION, MAX_SUBSTEPS, STABLE_FRACTION_PER_TOLERANCE, SubStep};
use crate::model::kinematics::{BodyMotion, JournalState, journal_state};
use crate::model::laws::{FrictionLaw, NormalContact, NormalForceLaw, loaded_impact_rate};
use crate::rapier::joint::{ClearanceJoint, ContactAhead, ContactHistory};
use rapier3d_f64::math::Vector;

/// The contact at one position of the sub-cycle, linearised for the kick.
#[derive(Clone, Copy, Debug)]
pub(super) struct Here {
    pub(super) state: JournalState,
    /// The bearing's and the journal's centres, and the hinge's axis.
    pub(super) centres: [Vector; 2],
    pub(super) axis: Vector,
    /// The acceleration of the journal's centre relative to the bearing's in the plane, from the
    /// rest of the world's accelerations (with the bodies' centripetal terms), m/s².
    pub(super) centre_acceleration: Vector,
    pub(super) com: [Vector; 2],
    pub(super) tangent: Vector,
    /// Rows reading the penetration rate and the slip along `tangent`.
    pub(super) rows: [Pair12; 2],
    /// Loads of a unit normal force (pushing the journal out, along `-n`) and a unit force along
    /// `tangent`, and the pair's velocity change per unit of each.
    pub(super) loads: [Pair12; 2],
    pub(super) moves: [Pair12; 2],
    /// `w[r][c]`: the rate read by row `r` per unit of load `c`.
    pub(super) w: [[f64; 2]; 2],
}

impl Here {
    /// The state here with its rates at the pair's velocity `v`.
    pub(super) fn rates_at(&self, v: &Pair12) -> JournalState {
        let [p_i, p_j] = self.centres;
        let centre =
            |k: usize, p: Vector| part(v, 2 * k) + part(v, 2 * k + 1).cross(p - self.com[k]);
        let centres = centre(1, p_j) - centre(0, p_i);
        JournalState {
            penetration_rate: dot(&self.rows[0], v),
            slip: dot(&self.rows[1], v) * self.tangent,
            eccentricity_rate: centres - centres.dot(self.axis) * self.axis,
            ..self.state
        }
    }

    /// Effective mass along the normal, kg (infinite when nothing moves along it).
    pub(super) fn mass(&self) -> f64 {
        if self.w[0][0] < 0.0 {
            -1.0 / self.w[0][0]
        } else {
            f64::INFINITY
        }
    }
}

/// The outcome of one sub-cycle.
#[derive(Clone, Debug, Default)]
pub(crate) struct SubCycle {
    /// The contact's impulse over the step, `Gamma(h)`.
    pub(crate) impulse: Pair12,
    /// `Pi/h`: the mean over the step of the impulse accumulated by each sub-step's start.
    pub(crate) mean: Pair12,
    /// The pair's velocity at the step's end.
    pub(crate) end_velocity: Pair12,
    /// The displacement this step leaves held, `E'`, the joint's held displacement once the
    /// step finishes.
    pub(crate) shift_next: Pair12,
    pub(crate) history: ContactHistory,
    pub(crate) samples: Vec<SubStep>,
    /// The normal's effective mass at the end, kg.
    pub(crate) end_mass: f64,
    pub(crate) substeps: u32,
    /// The pair's velocity at the step's start beyond the Verlet reading of Rapier's
    /// velocities around it ([`ClearanceJoint::start_velocity_correction`]).
    pub(crate) start_correction: Pair12,
    /// The energy the damping and friction took over the step, J.
    pub(crate) dissipated: f64,
}

/// What a sub-cycle integrates over one world step of `h` (s), from the pair's state `start`
/// with the velocity `u0` at the state, under the rest of the world's acceleration `a_free`.
pub(crate) struct Cycle<'a> {
    pub(crate) joint: &'a ClearanceJoint,
    pub(crate) start: &'a PairStart,
    pub(crate) u0: Pair12,
    /// Where the pair stands beyond Rapier's poses at the start (the held displacement moved
    /// through the mobilities): shifts, then turns, as [`Pair12`].
    pub(crate) offset: Pair12,
    pub(crate) a_free: Pair12,
    /// [`PairStart::stabilisation`]: shifts, then turns.
    pub(crate) stabilisation: [[Vector; 2]; 2],
    pub(crate) h: f64,
    pub(crate) tolerance: f64,
}

impl Cycle<'_> {
    /// The velocity at which the stabilisation moves the pair, spread evenly over the step
    /// (`stabilisation / h`, as [`Pair12`]): the bodies' positions move at `v` plus it, so the
    /// contact's rates are read at `v` plus it. Rapier stores its velocities without it, and it
    /// is of the order of the ideal joints' accelerations times `h/2` (a rate of order `h` that
    /// a heavily damped contact would integrate into its depth: docs/sub-cycled-contact.md).
    pub(super) fn drift(&self) -> Pair12 {
        let mut d = [0.0; 12];
        if self.h > 0.0 {
            for k in 0..2 {
                put(&mut d, 2 * k, self.stabilisation[0][k] / self.h);
                put(&mut d, 2 * k + 1, self.stabilisation[1][k] / self.h);
            }
        }
        d
    }

    /// The velocity the contact's rates are read at when the pair's is `v`: `v` plus the
    /// stabilisation's [`drift`](Self::drift).
    pub(super) fn moving(&self, v: &Pair12) -> Pair12 {
        let mut m = *v;
        axpy(&mut m, 1.0, &self.drift());
        m
    }

    pub(super) fn here(&self, m: &Motion) -> Here {
        let s = self.start;
        let com = [s.com[0] + m.shift[0], s.com[1] + m.shift[1]];
        let p_i = com[0] + rotate(m.turn[0], s.anchor[0]);
        let p_j = com[1] + rotate(m.turn[1], s.anchor[1]);
        let axis = rotate(m.turn[0], s.axis);
        let motion = |k: usize| BodyMotion {
            center_of_mass: com[k],
            linvel: part(&m.v, 2 * k),
            angvel: part(&m.v, 2 * k + 1),
        };
        let g = &self.joint.geometry;
        let state = journal_state(g, p_i, p_j, axis, &motion(0), &motion(1));
        let n = state.normal;
        let tangent = axis.cross(n);
        let q_i = p_i + g.bearing_radius() * n;
        let q_j = p_j + g.journal_radius() * n;
        let rows = [row(&com, q_i, q_j, n), row(&com, q_i, q_j, tangent)];
        let loads = [
            load(&com, state.contact_point, -n),
            load(&com, state.contact_point, tangent),
        ];
        let moves = loads.map(|l| mul(&s.mobility, &l));
        let w = [0, 1].map(|r| [0, 1].map(|c| dot(&rows[r], &moves[c])));
        let point_acceleration = |k: usize, p: Vector| {
            let (w, r) = (part(&m.v, 2 * k + 1), p - com[k]);
            part(&self.a_free, 2 * k) + part(&self.a_free, 2 * k + 1).cross(r) + w.cross(w.cross(r))
        };
        let relative = point_acceleration(1, p_j) - point_acceleration(0, p_i);
        Here {
            state,
            centres: [p_i, p_j],
            axis,
            centre_acceleration: relative - relative.dot(axis) * axis,
            com,
            tangent,
            rows,
            loads,
            moves,
            w,
        }
    }

    /// Where the pair stands at the step's start: Rapier's poses moved by the held displacement,
    /// at the state's velocity.
    pub(super) fn at_start(&self) -> Here {
        self.here(&Motion {
            shift: [part(&self.offset, 0), part(&self.offset, 2)],
            turn: [part(&self.offset, 1), part(&self.offset, 3)],
            v: self.u0,
        })
    }

    /// The displacement (`E`, impulse times time) and the impulse across the pin, as loads at
    /// the centres along the normal and the tangent, that bring the pair's eccentricity at the
    /// step's start onto `eccentricity` and its rate onto `rate`; `None` when the pair cannot
    /// move across the pin.
    pub(super) fn continuity(
        &self,
        eccentricity: Vector,
        rate: Vector,
    ) -> Option<(Pair12, Pair12)> {
        let here = self.at_start();
        let [p_i, p_j] = here.centres;
        let n = here.state.normal;
        let t = here.axis.cross(n);
        let mid = 0.5 * (p_i + p_j);
        let rows = [row(&here.com, p_i, p_j, n), row(&here.com, p_i, p_j, t)];
        let loads = [load(&here.com, mid, n), load(&here.com, mid, t)];
        let moves = loads.map(|l| mul(&self.start.mobility, &l));
        let w = [0, 1].map(|r| [0, 1].map(|c| dot(&rows[r], &moves[c])));
        let det = w[0][0] * w[1][1] - w[0][1] * w[1][0];
        if !(det.abs() > 1e-12 * (w[0][0] * w[1][1]).abs()) || !det.is_finite() {
            return None;
        }
        let solve = |d: Vector| {
            let (x, y) = (d.dot(n), d.dot(t));
            let l = [
                (w[1][1] * x - w[0][1] * y) / det,
                (w[0][0] * y - w[1][0] * x) / det,
            ];
            let mut out = [0.0; 12];
            axpy(&mut out, l[0], &loads[0]);
            axpy(&mut out, l[1], &loads[1]);
            out
        };
        Some((
            solve(eccentricity - here.state.eccentricity),
            solve(rate - here.state.eccentricity_rate),
        ))
    }

    /// `delta_dot0` for the law in the contact of `history` at `here` (as the explicit joint's).
    pub(super) fn impact_rate(&self, history: &ContactHistory, here: &Here) -> f64 {
        let law = &self.joint.normal_law;
        if history.in_contact && law.uses_impact_rate() {
            let elastic = law.elastic_energy(here.state.penetration);
            history
                .impact_rate
                .max(loaded_impact_rate(elastic, here.mass()))
        } else {
            history.impact_rate
        }
    }

    /// The next sub-step from `here` (velocity `v` read there), at most `left` (s).
    pub(super) fn substep(&self, here: &Here, history: &ContactHistory, left: f64) -> f64 {
        let j = self.joint;
        let st = &here.state;
        let mass = here.mass();
        let ahead = |speed: f64, depth: f64| {
            let contact = ContactAhead {
                mass,
                approach_speed: speed,
                depth,
                impact_rate: history.in_contact.then_some(history.impact_rate),
                min_impact_speed: j.min_impact_speed,
            };
            let elastic = j.normal_law.elastic_energy(depth);
            // Capped as the explicit step's is, at 0.8 of the damped limit (the sub-cycle's
            // tolerance, at most `MAX_CONTACT_TOLERANCE`, keeps `10 tol` below it).
            let stable = (STABLE_FRACTION_PER_TOLERANCE * self.tolerance)
                .min(super::super::step_policy::STABILITY_SAFETY);
            contact.resolving_step(&j.normal_law, elastic, self.tolerance, stable)
        };
        let s = if st.penetration > 0.0 {
            ahead(st.penetration_rate.abs(), st.penetration)
        } else {
            let c = j.geometry.clearance();
            let (e, v, a) = (
                st.eccentricity,
                st.eccentricity_rate,
                here.centre_acceleration,
            );
            // The wall is predicted from the centre's path as a parabola: a free sub-step
            // moves it by at most `tolerance` of the clearance (the world step's own journal
            // path bound), so a turning body's path meets the wall where the parabola says.
            let path = crate::rapier::joint::flight_step(self.tolerance, c, v.length());
            match time_to_wall(e, v, a, c, left.min(path)) {
                None => left.min(path),
                Some(t) => {
                    let n = (e + v * t + 0.5 * a * t * t).normalize_or_zero();
                    let speed = (v + a * t).dot(n).max(0.0);
                    let own = ahead(speed, 0.0);
                    if t <= own {
                        // Onto the wall: the contact begins at a sub-step's end, where a law
                        // whose force jumps at the onset (Kelvin-Voigt's damping) starts whole.
                        t * (1.0 + 1e-9) + 1e-15 * self.h
                    } else {
                        (APPROACH_FRACTION * t).max(own)
                    }
                }
            }
        };
        let s = if j.techniques.implicit_friction {
            s
        } else {
            s.min(self.explicit_friction_step(here, history))
        };
        let s = s.max(1e-9 * self.h);
        // No sliver of a last sub-step.
        if s >= 0.95 * left { left } else { s }
    }

    /// With friction explicit ([`SubCycleTechniques::implicit_friction`] off): the sub-step
    /// within friction's stability limit near the slip at `here`, as the explicit joint's step
    /// (`STABILITY_SAFETY x 2/(w_t F_N dmu/dv)`, 0.8 of the limit, `w_t` the slip's rate per unit of tangential load, `F_N`
    /// the law's force at the state); unbounded out of contact.
    ///
    /// [`SubCycleTechniques::implicit_friction`]: super::SubCycleTechniques::implicit_friction
    fn explicit_friction_step(&self, here: &Here, history: &ContactHistory) -> f64 {
        let j = self.joint;
        let st = &here.state;
        if st.penetration <= 0.0 {
            return f64::INFINITY;
        }
        let contact = NormalContact {
            penetration: st.penetration,
            penetration_rate: st.penetration_rate,
            impact_rate: self.impact_rate(history, here).max(j.min_impact_speed),
        };
        let f_n = j.normal_law.normal_force(&contact).max(0.0);
        let slope = super::super::friction_slope(&j.friction_law, st.slip.length());
        let w_t = here.w[1][1].abs();
        if f_n > 0.0 && slope > 0.0 && w_t > 0.0 {
            super::super::step_policy::STABILITY_SAFETY * 2.0 / (w_t * f_n * slope)
        } else {
            f64::INFINITY
        }
    }

    /// The sub-step after one of `s` that left `left` (s) of the step, from `here`: 0 when that
    /// was the last, the rest of the step beyond [`MAX_SUBSTEPS`].
    pub(super) fn next_substep(
        &self,
        here: &Here,
        history: &ContactHistory,
        left: f64,
        count: u32,
    ) -> f64 {
        if left <= 0.0 {
            0.0
        } else if count >= MAX_SUBSTEPS {
            left
        } else {
            self.substep(here, history, left)
        }
    }

    /// A kick at `here`: `v += sigma a + sigma_c P F`, the rest of the world acting over `sigma`
    /// (s) and the contact over `sigma_c` (s; shorter at an onset, where it acts from the
    /// crossing on), its force taken at the state's velocity `(1 - beta) v_before + beta v_after`
    /// (implicit for `beta > 0`). Returns the force (normal, along the tangent), the impulse and
    /// the energy the damping and friction took over the span (J).
    pub(super) fn kick(
        &self,
        here: &Here,
        v: &mut Pair12,
        (sigma, sigma_c): (f64, f64),
        beta: f64,
        impact_rate: f64,
    ) -> ([f64; 2], Pair12, f64) {
        let moving = self.moving(v);
        let c_a = [dot(&here.rows[0], &moving), dot(&here.rows[1], &moving)];
        // The rates the rest of the world brings over the span.
        let a = [
            sigma * dot(&here.rows[0], &self.a_free),
            sigma * dot(&here.rows[1], &self.a_free),
        ];
        let delta = here.state.penetration;
        let mut f = [0.0, 0.0];
        let mut dissipated = 0.0;
        if delta > 0.0 {
            let law = &self.joint.normal_law;
            let contact = NormalContact {
                penetration: delta,
                penetration_rate: 0.0,
                impact_rate,
            };
            let elastic = law.elastic_force(delta);
            let damping = law.damping_coefficient(&contact);
            let w = &here.w;
            let bs = beta * sigma_c;
            let t = &self.joint.techniques;
            for _ in 0..50 {
                // The normal force is affine in the rate (every law here): solved exactly.
                let c0n = c_a[0] + beta * a[0] + bs * w[0][1] * f[1];
                let f_n = if t.implicit_damping {
                    ((elastic + damping * c0n) / (1.0 - damping * bs * w[0][0])).max(0.0)
                } else {
                    // Explicit (for comparison): at the rate before the kick.
                    (elastic + damping * c_a[0]).max(0.0)
                };
                let c0t = c_a[1] + beta * a[1] + bs * w[1][0] * f_n;
                let k = bs * w[1][1] * f_n;
                let slip = if t.implicit_friction {
                    implicit_slip(&self.joint.friction_law, c0t, k)
                } else {
                    // Explicit (for comparison): at the slip before the kick.
                    c_a[1]
                };
                let f_t = -self.joint.friction_law.coefficient(slip.abs()) * f_n * slip.signum();
                let change = (f_n - f[0]).abs() + (f_t - f[1]).abs();
                f = [f_n, if slip == 0.0 { 0.0 } else { f_t }];
                if change <= 1e-13 * (f_n + 1e-300) {
                    break;
                }
            }
            // The rates at the state, with the force found: the damping's share of the normal
            // force and the friction work against them.
            let c_m = [0, 1].map(|r| c_a[r] + beta * a[r] + bs * (w[r][0] * f[0] + w[r][1] * f[1]));
            if f[0] > 0.0 {
                dissipated = sigma_c * ((f[0] - elastic) * c_m[0] - f[1] * c_m[1]);
            }
        }
        axpy(v, sigma, &self.a_free);
        axpy(v, sigma_c * f[0], &here.moves[0]);
        axpy(v, sigma_c * f[1], &here.moves[1]);
        let mut impulse = [0.0; 12];
        axpy(&mut impulse, sigma_c * f[0], &here.loads[0]);
        axpy(&mut impulse, sigma_c * f[1], &here.loads[1]);
        (f, impulse, dissipated)
    }
}

/// The first time within `left` (s) at which the eccentricity `e + v t + a t^2/2` (m, m/s,
/// m/s²) can reach the clearance `c` (m), `None` when it stays inside. Marched by safe steps:
/// from each point the gap cannot close faster than the path's speed and acceleration allow,
/// so no contact is stepped over, and a path straight at the wall lands on it in one step.
pub(super) fn time_to_wall(e: Vector, v: Vector, a: Vector, c: f64, left: f64) -> Option<f64> {
    let acc = a.length();
    let mut t = 0.0;
    for _ in 0..200 {
        let gap = c - (e + v * t + 0.5 * a * t * t).length();
        if gap <= 0.0 {
            return Some(t);
        }
        let speed = (v + a * t).length();
        // The earliest the gap can close: speed dt + acc dt^2/2 = gap.
        let dt = if acc > 0.0 {
            2.0 * gap / (speed + (speed * speed + 2.0 * acc * gap).sqrt())
        } else if speed > 0.0 {
            gap / speed
        } else {
            return None;
        };
        t += dt;
        if t >= left {
            return None;
        }
        if dt <= 1e-12 * t {
            return Some(t);
        }
    }
    Some(t)
}

/// The slip `x` at the state with friction taken there: `x = c0 - k mu(|x|) sign(x)`, `c0` the
/// slip without this sub-step's friction, `k >= 0` the slip friction's full coefficient removes.
/// A root lies between 0 and `c0` (friction opposes the slip and never reverses it alone);
/// bracketed, as the law may fall with speed (Stribeck), and found by false position with the
/// Illinois rule (the value at an end kept twice in a row is halved: the bracket closes from
/// both sides, in about a tenth of the law's evaluations plain false position takes to the
/// same width), a bisection where the secant leaves the bracket.
pub(super) fn implicit_slip(law: &impl FrictionLaw, c0: f64, k: f64) -> f64 {
    if c0 == 0.0 || !(k > 0.0) {
        return c0;
    }
    let sign = c0.signum();
    let target = c0.abs();
    // A law linear in pieces (Coulomb's) gives the root directly: the bracket below was most
    // of a kick's cost on the SCARA arm's pins.
    if let Some(x) = law.closed_form_slip(target, k) {
        return sign * x;
    }
    // g(x) = x + k mu(x) - target over [0, target]: g(0) <= 0 <= g(target).
    let g = |x: f64| x + k * law.coefficient(x) - target;
    let (mut lo, mut hi) = (0.0, target);
    let (mut g_lo, mut g_hi) = (g(lo), g(hi));
    if g_lo >= 0.0 {
        return 0.0;
    }
    // Which end the last iterate moved: -1 the lower, +1 the upper.
    let mut moved = 0;
    for _ in 0..200 {
        let secant = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
        let x = if secant > lo && secant < hi {
            secant
        } else {
            0.5 * (lo + hi)
        };
        let gx = g(x);
        if gx == 0.0 {
            return sign * x;
        }
        if gx < 0.0 {
            lo = x;
            g_lo = gx;
            if moved == -1 {
                g_hi *= 0.5;
            }
            moved = -1;
        } else {
            hi = x;
            g_hi = gx;
            if moved == 1 {
                g_lo *= 0.5;
            }
            moved = 1;
        }
        if hi - lo <= 1e-14 * target + 1e-300 {
            break;
        }
    }
    sign * 0.5 * (lo + hi)
}
