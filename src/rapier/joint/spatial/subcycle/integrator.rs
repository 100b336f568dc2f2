//! The spatial sub-cycle's integrator: each region's clock, the load, the
//! linearly implicit Rosenbrock step ([`SpatialCycle`]).

use super::factor::{Slopes, through};
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
    /// The load's moment on the journal about the world's origin, N m.
    pub(super) moment: Vector,
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

    /// The pair's position increments and velocities at `t` with the impulses moved through
    /// the mobilities from every pair of the group, `moved` (`sum_b P_ab Pi_b`, then the same of
    /// `Gamma`).
    pub(super) fn kinematics(&self, t: f64, moved: (Pair12, Pair12)) -> (Pair12, Pair12) {
        let (mut x, mut v) = moved;
        axpy(&mut x, t, &self.u0);
        axpy(&mut x, 0.5 * t * t, &self.accel);
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
        out.moment = totals.torque[1] + centres[1].cross(totals.force);
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
        Slopes {
            a: through(&lx, p),
            b: through(&lv, p),
            lx,
            lv,
        }
    }

    /// The largest error against the tolerance, body by body: displacements (of the centre of
    /// mass and of the bearing's or journal's centre, where the contacts are: a door's centre of
    /// mass is 0.2 m off its pin, and a rotation's error adds over that lever) and rotations
    /// across the axis against their scale (the edges' and faces' depths follow them), rotations
    /// about the axis against the clearance over the journal's radius (they slide the journal
    /// along its wall), velocities against themselves plus [`VELOCITY_SCALE`] of their scale.
    ///
    /// `err` is the pair's error, moved through the mobilities from every pair of the group:
    /// its positions, then velocities.
    pub(super) fn error(&self, (ex, ev): (&Pair12, &Pair12), v: &Pair12) -> f64 {
        let g = &self.joint.geometry;
        let axis = self.start.bearing_axis;
        let floor = VELOCITY_SCALE / POSITION_SCALE;
        let tol = self.tolerance;
        let mut worst = 0.0_f64;
        for k in 0..4 {
            let (e, de, u) = (part(ex, k), part(ev, k), part(v, k));
            if k % 2 == 0 {
                // The contacts follow the bearing's or journal's centre, `anchor` off the centre
                // of mass: its displacement is judged too.
                let at_centre = e + part(ex, k + 1).cross(self.start.anchor[k / 2]);
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
