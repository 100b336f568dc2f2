//! The spatial sub-cycle's integrator: each region's clock, the load, the
//! linearly implicit Rosenbrock step ([`SpatialCycle`]).

use super::factor::{Factor, Impulses, Slopes};
use super::*;

/// One region's memory inside the sub-cycle.
#[derive(Clone, Copy, Debug)]
pub(super) struct RegionClock {
    pub(super) history: ContactHistory,
    pub(super) state: Option<JournalState>,
    pub(super) impact_rate: f64,
    /// The time since the onset of the region's impact (s), while its sub-steps are bounded
    /// by its period (`impact`'s [`SpatialCycle::impact_bound`]); `None` out of one.
    pub(super) impact: Option<f64>,
}

impl RegionClock {
    /// The impact rate the region's law reads at `state`: its own in contact, else the state's
    /// approach (a trial state pressing a region that has no contact yet).
    pub(super) fn rate_at(&self, state: &JournalState, floor: f64) -> f64 {
        if self.history.in_contact {
            self.impact_rate
        } else {
            state.penetration_rate.max(floor)
        }
    }
}

/// The regions at one state of the pair.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Eval {
    /// The contact's load on the pair's 12 coordinates.
    pub(super) load: Pair12,
    /// Each region's deepest point.
    pub(super) states: [JournalState; 4],
    pub(super) force: ForcePair,
    /// Power the damping and friction dissipate, W.
    pub(super) dissipation: f64,
}

impl Eval {
    pub(super) fn deepest(&self) -> usize {
        (0..4)
            .max_by(|&a, &b| {
                let (pa, pb) = (self.states[a].penetration, self.states[b].penetration);
                pa.total_cmp(&pb)
            })
            .unwrap_or(0)
    }
}

/// What the spatial sub-cycle integrates over one world step of `h` (s) from the pair's state
/// `start`, with the velocity `u0` at the state, under the rest of the world's acceleration
/// `a_free`.
///
/// **The held load.** The state is the contact's impulse beyond `held`, the load that balances
/// the free acceleration (a resting door: its weight), held over the step: `Gamma = G + held t`,
/// `Pi = Q + held t^2/2`; ROS2 integrates `(Q, G)`, whose rate is `L - held`, and `held`'s
/// impulse goes into the reference motion with the free acceleration (an exact change of
/// variables). ROS2's stage order is one: in a stiff direction it tracks its state with an
/// offset of about `0.35 s^2` times the state's curvature. On `Pi` itself that curvature would
/// be the whole load, the weight included: a resting door's contacts would sit off their balance
/// by it (its face's share of the weight 0.5 % low at the default tolerance), and the embedded
/// estimate (the first-order member failing to carry the weight) would set its sub-steps at rest. `held` follows the
/// free acceleration, not the contact, so it moves smoothly from step to step.
pub(super) struct SpatialCycle<'a> {
    pub(super) joint: &'a ClearanceJoint,
    pub(super) start: &'a SpatialStart,
    pub(super) u0: Pair12,
    /// The reference motion's acceleration: the rest of the world's (`a_free`), plus the held
    /// load's through the mobility once [`run`](SpatialCycle::run) has set it.
    pub(super) accel: Pair12,
    /// The load balancing the free acceleration, held over the step (zero until `run` sets it).
    pub(super) held: Pair12,
    pub(super) h: f64,
    pub(super) tolerance: f64,
    /// Coordinates the pair's mobility moves (the others never change).
    pub(super) moving: [bool; 12],
    /// Position scale of each coordinate (m; rad for the angular ones), against which the
    /// tolerance is applied.
    pub(super) scale: Pair12,
}

impl SpatialCycle<'_> {
    pub(super) fn new<'a>(
        joint: &'a ClearanceJoint,
        start: &'a SpatialStart,
        (u0, a_free): (Pair12, Pair12),
        h: f64,
        tolerance: f64,
    ) -> SpatialCycle<'a> {
        let g = &joint.geometry;
        let lever = (0.5 * g.length()).max(g.journal_radius());
        let length = POSITION_SCALE * g.clearance();
        let moving = std::array::from_fn(|r| (0..12).any(|c| start.mobility[r * 12 + c] != 0.0));
        let scale = std::array::from_fn(|i| {
            if (i / 3) % 2 == 0 {
                length
            } else {
                length / lever
            }
        });
        SpatialCycle {
            joint,
            start,
            u0,
            accel: a_free,
            held: [0.0; 12],
            h,
            tolerance,
            moving,
            scale,
        }
    }

    /// The pair's position increments and velocities at `t` with the impulses `y`.
    pub(super) fn kinematics(&self, t: f64, y: &Impulses) -> (Pair12, Pair12) {
        let p = &self.start.mobility;
        let mut x = mul(p, &y.pi);
        axpy(&mut x, t, &self.u0);
        axpy(&mut x, 0.5 * t * t, &self.accel);
        let mut v = mul(p, &y.gamma);
        axpy(&mut v, 1.0, &self.u0);
        axpy(&mut v, t, &self.accel);
        (x, v)
    }

    /// The pose at position increments `x`.
    pub(super) fn pose(&self, x: &Pair12) -> SpatialPose {
        let s = self.start;
        let com = self.centres(x);
        let (turn_i, turn_j) = (part(x, 1), part(x, 3));
        SpatialPose {
            bearing_center: com[0] + rotate(turn_i, s.anchor[0]),
            bearing_axis: rotate(turn_i, s.bearing_axis),
            bearing_transverse: rotate(turn_i, s.transverse),
            journal_center: com[1] + rotate(turn_j, s.anchor[1]),
            journal_axis: rotate(turn_j, s.journal_axis),
        }
    }

    /// The bodies' centres of mass at position increments `x`.
    fn centres(&self, x: &Pair12) -> [Vector; 2] {
        [
            self.start.com[0] + part(x, 0),
            self.start.com[1] + part(x, 2),
        ]
    }

    /// The bodies' motions at position increments `x` and velocities `v` (no rotation: a
    /// velocity step of the Jacobian reads only these).
    fn motions(&self, x: &Pair12, v: &Pair12) -> [BodyMotion; 2] {
        let com = self.centres(x);
        std::array::from_fn(|k| BodyMotion {
            center_of_mass: com[k],
            linvel: part(v, 2 * k),
            angvel: part(v, 2 * k + 1),
        })
    }

    /// The regions' load, states and dissipation at `x`, `v`.
    pub(super) fn eval(
        &self,
        parts: &mut SpatialParts,
        x: &Pair12,
        v: &Pair12,
        clocks: &[RegionClock; 4],
    ) -> Eval {
        self.eval_with(parts, (x, v), clocks, true)
    }

    /// The regions' load alone at `x`, `v`.
    pub(super) fn load(
        &self,
        parts: &mut SpatialParts,
        x: &Pair12,
        v: &Pair12,
        clocks: &[RegionClock; 4],
    ) -> Pair12 {
        self.eval_with(parts, (x, v), clocks, false).load
    }

    fn eval_with(
        &self,
        parts: &mut SpatialParts,
        (x, v): (&Pair12, &Pair12),
        clocks: &[RegionClock; 4],
        dissipation: bool,
    ) -> Eval {
        let mut places = std::mem::take(&mut parts.places);
        self.read_places(parts, &mut places, x);
        let out = self.eval_at(parts, (&places, x, v), clocks, dissipation);
        parts.places = places;
        out
    }

    /// Where the pose at `x` puts the regions' contacts, into `places`.
    fn read_places(&self, parts: &SpatialParts, places: &mut Places, x: &Pair12) {
        let pose = self.pose(x);
        let regions = parts.patches.map(|p| p.region);
        places.read(self.joint, &parts.model.geometry, &pose, regions);
    }

    /// The regions' load and states at `x`, `v`, the contacts at `places` (read at `x`), and
    /// their dissipation when asked.
    fn eval_at(
        &self,
        parts: &mut SpatialParts,
        (places, x, v): (&Places, &Pair12, &Pair12),
        clocks: &[RegionClock; 4],
        dissipation: bool,
    ) -> Eval {
        let j = self.joint;
        let motions = self.motions(x, v);
        let bodies = [&motions[0], &motions[1]];
        let centres = [motions[0].center_of_mass, motions[1].center_of_mass];
        let mut totals = Totals::default();
        let mut out = Eval::default();
        parts.points.clear();
        for (k, clock) in clocks.iter().enumerate() {
            let region = parts.patches[k].region;
            let state = places.deepest[k].state(bodies);
            let first = parts.points.len();
            places.moving(k, bodies, &mut parts.points);
            let law = *region.law(&j.normal_law, &parts.face_law);
            let rate = clock.rate_at(&state, j.min_impact_speed);
            let points = &mut parts.points[first..];
            let laws = (&law, &j.friction_law);
            load_region(points, laws, rate, centres, dissipation, &mut totals);
            out.states[k] = state;
        }
        put(&mut out.load, 0, -totals.force);
        put(&mut out.load, 1, totals.torque[0]);
        put(&mut out.load, 2, totals.force);
        put(&mut out.load, 3, totals.torque[1]);
        let deepest = &out.states[out.deepest()];
        out.force = ForcePair {
            on_journal: totals.force,
            point: deepest.contact_point,
            normal_force: totals.normal.length(),
            friction_force: totals.friction.length(),
        };
        out.dissipation = totals.dissipation;
        out
    }

    /// The load's Jacobian at `x`, `v` (whose load is `base`), by forward differences along the
    /// coordinates the pair moves: steps of 1e-6 of the position scale (the contacts' depths
    /// resolve it) and 1e-3 of it per second for velocities (well inside friction's linear
    /// range near zero slip).
    pub(super) fn slopes(
        &self,
        parts: &mut SpatialParts,
        (x, v): (&Pair12, &Pair12),
        base: &Pair12,
        clocks: &[RegionClock; 4],
    ) -> Slopes {
        let mut lx = [0.0; 144];
        let mut lv = [0.0; 144];
        if !self.joint.techniques.implicit_spatial {
            // A zero Jacobian (for comparison): ROS2 is then explicit.
            return Slopes {
                lx,
                lv,
                a: lx,
                b: lv,
            };
        }
        // A velocity's step leaves the contacts where they are: read them once.
        let mut base_places = std::mem::take(&mut parts.base_places);
        self.read_places(parts, &mut base_places, x);
        for c in (0..12).filter(|&c| self.moving[c]) {
            for (jac, dv, e) in [(&mut lx, false, 1e-6), (&mut lv, true, 1e-3)] {
                let step = e * self.scale[c];
                let (mut xp, mut vp) = (*x, *v);
                if dv {
                    vp[c] += step;
                } else {
                    xp[c] += step;
                }
                let load = if dv {
                    let at = (&base_places, &xp, &vp);
                    self.eval_at(parts, at, clocks, false).load
                } else {
                    self.load(parts, &xp, &vp, clocks)
                };
                for r in 0..12 {
                    jac[r * 12 + c] = (load[r] - base[r]) / step;
                }
            }
        }
        parts.base_places = base_places;
        let p = &self.start.mobility;
        let through = |l: &Square| -> Square {
            std::array::from_fn(|i| {
                let (r, c) = (i / 12, i % 12);
                (0..12).map(|k| l[r * 12 + k] * p[k * 12 + c]).sum()
            })
        };
        Slopes {
            a: through(&lx),
            b: through(&lv),
            lx,
            lv,
        }
    }

    /// One ROS2 sub-step of `s` from `t`, `y` (load `f0` there): the new state, the load at its
    /// second stage's point is not kept. Returns the state and its scaled error (accept at or
    /// below 1); `None` when the linear system is singular.
    pub(super) fn ros2(
        &self,
        parts: &mut SpatialParts,
        (t, y, f0): (f64, &Impulses, &Pair12),
        slopes: &Slopes,
        s: f64,
        clocks: &[RegionClock; 4],
    ) -> Option<(Impulses, f64)> {
        let factor = Factor::of(slopes, s)?;
        // The load's change with time along the reference motion: dx/dt = u0 + a t, dv/dt = a.
        let mut drift = self.u0;
        axpy(&mut drift, t, &self.accel);
        let mut ft = mul(&slopes.lx, &drift);
        axpy(&mut ft, 1.0, &mul(&slopes.lv, &self.accel));
        let gs = GAMMA * s;
        let mut r1 = Impulses {
            pi: y.gamma,
            gamma: *f0,
        };
        axpy(&mut r1.gamma, -1.0, &self.held);
        axpy(&mut r1.gamma, gs, &ft);
        let k1 = factor.solve(slopes, &r1);
        let mut y1 = *y;
        axpy(&mut y1.pi, s, &k1.pi);
        axpy(&mut y1.gamma, s, &k1.gamma);
        let (x1, v1) = self.kinematics(t + s, &y1);
        let f1 = self.load(parts, &x1, &v1, clocks);
        let mut r2 = Impulses {
            pi: y1.gamma,
            gamma: f1,
        };
        axpy(&mut r2.gamma, -1.0, &self.held);
        axpy(&mut r2.pi, -2.0, &k1.pi);
        axpy(&mut r2.gamma, -2.0, &k1.gamma);
        axpy(&mut r2.gamma, -gs, &ft);
        let k2 = factor.solve(slopes, &r2);
        let mut next = *y;
        let mut err = Impulses::default();
        for (n, e, a, b) in [
            (&mut next.pi, &mut err.pi, &k1.pi, &k2.pi),
            (&mut next.gamma, &mut err.gamma, &k1.gamma, &k2.gamma),
        ] {
            axpy(n, 1.5 * s, a);
            axpy(n, 0.5 * s, b);
            axpy(e, 0.5 * s, a);
            axpy(e, 0.5 * s, b);
        }
        let (_, v_new) = self.kinematics(t + s, &next);
        Some((next, self.error(&err, &v_new)))
    }

    /// The largest error against the tolerance, body by body: displacements (of the centre of
    /// mass and of the bearing's or journal's centre, where the contacts are: a door's centre of
    /// mass is 0.2 m off its pin, and a rotation's error adds over that lever) and rotations
    /// across the axis against their scale (the edges' and faces' depths follow them), rotations
    /// about the axis against the clearance over the journal's radius (they slide the journal
    /// along its wall), velocities against themselves plus [`VELOCITY_SCALE`] of their scale.
    pub(super) fn error(&self, err: &Impulses, v: &Pair12) -> f64 {
        let p = &self.start.mobility;
        let (ex, ev) = (mul(p, &err.pi), mul(p, &err.gamma));
        let g = &self.joint.geometry;
        let axis = self.start.bearing_axis;
        let floor = VELOCITY_SCALE / POSITION_SCALE;
        let tol = self.tolerance;
        let mut worst = 0.0_f64;
        for k in 0..4 {
            let (e, de, u) = (part(&ex, k), part(&ev, k), part(v, k));
            if k % 2 == 0 {
                // The contacts follow the bearing's or journal's centre, `anchor` off the centre
                // of mass: its displacement is judged too.
                let at_centre = e + part(&ex, k + 1).cross(self.start.anchor[k / 2]);
                worst = worst.max(at_centre.length() / (tol * self.scale[3 * k]));
            }
            let scales = if k % 2 == 0 {
                vec![(e, de, u, self.scale[3 * k])]
            } else {
                let along = |x: Vector| x.dot(axis) * axis;
                vec![
                    (
                        e - along(e),
                        de - along(de),
                        u - along(u),
                        self.scale[3 * k],
                    ),
                    (
                        along(e),
                        along(de),
                        along(u),
                        g.clearance() / g.journal_radius(),
                    ),
                ]
            };
            for (e, de, u, scale) in scales {
                let position = e.length() / (tol * scale);
                let velocity = de.length() / (tol * (u.length() + floor * scale));
                worst = worst.max(position).max(velocity);
            }
        }
        worst
    }

    /// Integrates the step from the joint's `history` and `before` (the state at the step's
    /// start) and the regions' `clocks`, with a first sub-step of `guess` (s); fills `out` and
    /// returns the last accepted sub-step (the next step's guess).
    pub(super) fn run(
        &mut self,
        parts: &mut SpatialParts,
        (history, before): (ContactHistory, &JournalState),
        clocks: &mut [RegionClock; 4],
        guess: f64,
        out: &mut SubCycle,
    ) -> f64 {
        let j = self.joint;
        out.samples.clear();
        out.dissipated = 0.0;
        let mut hist = history;
        let mut prev = *before;
        let mut y = Impulses::default();
        let mut t = 0.0;
        let (x, v) = self.kinematics(0.0, &y);
        let mut here = self.eval(parts, &x, &v, clocks);
        // The load balancing the free acceleration held over the step.
        self.held = balancing_load(&self.start.mobility, &self.accel);
        axpy(&mut self.accel, 1.0, &mul(&self.start.mobility, &self.held));
        let mut s = if guess > 0.0 {
            guess.min(self.h)
        } else {
            self.h
        }
        .min(self.impact_bound(parts, &x, clocks));
        let mut slopes = self.slopes(parts, (&x, &v), &here.load, clocks);
        let mut count = 0u32;
        let mut accepted = s;
        // Accepted sub-steps since the Jacobian was taken, and the regions in contact there.
        let (mut age, mut contacts, mut taken_at) = (0u32, contact_set(&here), here.load);
        while t < self.h {
            let left = self.h - t;
            // No sliver of a last sub-step.
            let step = if s >= 0.95 * left || count >= MAX_SUBSTEPS {
                left
            } else {
                s
            };
            let trial = self.ros2(parts, (t, &y, &here.load), &slopes, step, clocks);
            let floor = 1e-9 * self.h;
            let (next, err) = match trial {
                Some((next, err)) if err.is_finite() => (next, err),
                _ if step > floor => {
                    s = 0.5 * step;
                    continue;
                }
                _ => (y, 0.0),
            };
            if err > 1.0 && step > floor && count < MAX_SUBSTEPS {
                s = step * (0.9 / err.sqrt()).clamp(0.1, 0.9);
                if age > 0 {
                    // A Jacobian of an earlier state may be what failed: retake it here.
                    let (x, v) = self.kinematics(t, &y);
                    slopes = self.slopes(parts, (&x, &v), &here.load, clocks);
                    (age, taken_at) = (0, here.load);
                }
                continue;
            }
            let t_next = if step == left { self.h } else { t + step };
            let (x, v) = self.kinematics(t_next, &next);
            let at = self.eval(parts, &x, &v, clocks);
            if step > floor
                && count < MAX_SUBSTEPS
                && let Some(shorter) = self.onset_retry(parts, &x, (&here, &at), clocks, step)
            {
                s = shorter;
                continue;
            }
            count += 1;
            accepted = step;
            out.dissipated += 0.5 * step * (here.dissipation + at.dissipation);
            self.advance(clocks, &at.states, step);
            let state = at.states[at.deepest()];
            let onset = hist.advance(Some(&prev), &state, j.min_impact_speed, j.min_separation);
            out.samples.push(SubStep {
                t: t_next,
                state,
                force: at.force,
                onset: onset.onset,
                impact: onset.impact,
                approach_speed: onset.approach_speed,
                onset_fraction: onset.fraction,
            });
            prev = state;
            (t, y, here) = (t_next, next, at);
            s = step * (0.9 / err.max(1e-12).sqrt()).clamp(0.2, 4.0);
            s = s.min(self.impact_bound(parts, &x, clocks));
            age += 1;
            let touching = contact_set(&here);
            let moved = changed(&here.load, &taken_at);
            // With the reuse off (for comparison) the Jacobian is retaken at every sub-step.
            let max_age = if j.techniques.jacobian_reuse {
                JACOBIAN_AGE
            } else {
                1
            };
            if t < self.h && (age >= max_age || touching != contacts || moved) {
                slopes = self.slopes(parts, (&x, &v), &here.load, clocks);
                (age, contacts, taken_at) = (0, touching, here.load);
            }
        }
        let (_, v) = self.kinematics(self.h, &y);
        let h = self.h;
        out.impulse = std::array::from_fn(|i| y.gamma[i] + self.held[i] * h);
        out.mean = std::array::from_fn(|i| y.pi[i] / h + 0.5 * self.held[i] * h);
        out.end_velocity = v;
        out.history = hist;
        out.substeps = count;
        accepted
    }

    /// Each region's history moved to the accepted `states` after a sub-step of `step` (s); a
    /// region whose contact began takes its approach at the crossing as its impact rate, and
    /// starts an impact's clock.
    pub(super) fn advance(
        &self,
        clocks: &mut [RegionClock; 4],
        states: &[JournalState; 4],
        step: f64,
    ) {
        let j = self.joint;
        for (clock, state) in clocks.iter_mut().zip(states) {
            let was = clock.history.in_contact;
            let before = clock.state.as_ref();
            clock
                .history
                .advance(before, state, j.min_impact_speed, j.min_separation);
            clock.impact = match clock.impact {
                _ if !clock.history.in_contact => None,
                _ if !was => Some(0.0),
                elapsed => elapsed.map(|t| t + step),
            };
            if !was && clock.history.in_contact {
                clock.impact_rate = clock.history.impact_rate;
            }
            clock.state = Some(*state);
        }
    }
}
