//! Sub-cycled contact ([`ContactIntegration::SubCycled`]): inside one Rapier step the joint
//! integrates its two bodies' motion on its own clock, and Rapier's step carries the result.
//!
//! **Free motion from Rapier.** The step is first taken without the joint's force (Rapier's
//! pass 0). The velocities it ends with give every other force's acceleration of the pair over
//! the step (gravity, drives, the user's forces, the ideal joints' reactions, Rapier's own
//! integration), `a = (v_free - v_start)/kick`, held over the step.
//!
//! **The contact on its own clock.** From the pair's state at the step's start, the joint
//! integrates `dv/dt = a + P F(x, v)` over the step, `P` the pair's mobility through the
//! mechanism's ideal joints (the 12 x 12 [`Mechanism::pair_mobility`], at the step's start),
//! with sub-steps sized by the tolerance: `2 tol` of the contact's period and `10 tol` of its
//! damped stability limit in contact ([`ContactAhead::resolving_step`]), halving the time to
//! contact on approach and landing on the wall, and moving the journal by at most `tol` of the
//! clearance in free flight. A sub-step is a
//! velocity-Verlet step whose elastic force is taken at the sub-step's position and whose
//! dissipative forces (the law's damping, friction) at the velocity of the state, solved
//! implicitly (a trapezoidal rule in the velocity: stable at any sub-step, second order). The
//! friction law's steep slope near zero slip therefore sets no step.
//!
//! **Back to Rapier.** Rapier's step is then taken again (pass 1) with the constant wrench that
//! moves the bodies where the sub-steps did: with one solver iteration a force held over a step
//! moves the bodies by `h kick P Q` and changes their velocities by `kick P Q`, so
//! `Q kick = (H + Pi/h)/c_N`, `Pi` the time integral of the sub-steps' accumulated impulse,
//! `c_N = (N + 1)/(2 N)` for `N` solver iterations (Rapier's substeps) and `H` the impulse held
//! from the step before. Rapier's velocities are the mean over the step (Verlet's half-step
//! velocities), so the part of the step's impulse that is not in them, `H' = H + Gamma(h) -
//! Q kick`, is held to the next step, whose true starting velocity is Rapier's plus
//! `(c_N kick - h/2) a + P H'`. Steps without a contact and without a held impulse take pass 0
//! only.
//!
//! The sub-steps' states are the joint's [`substeps`](super::ClearanceJoint::substeps): an
//! impact that begins, peaks and ends inside one world step is reported at its sub-steps
//! (onset, peak, depth, lift-off), and the world steps at the rate of the slow motion, crossing
//! a contact in a few steps ([`ClearanceJoint::world_contact_step`]).

use super::effective_mass::Mechanism;
use super::{ClearanceJoint, ClearanceReport, ContactAhead, ContactHistory};
use crate::model::kinematics::{BodyMotion, ForcePair, JournalState, journal_state, stable_step};
use crate::model::laws::{FrictionLaw, NormalContact, NormalForceLaw, loaded_impact_rate};
use crate::rapier::pipeline::ledger::{Wrench, world_center_of_mass};
use crate::rapier::pipeline::step_hooks::StepPass;
use rapier3d_f64::math::{Rotation, Vector};
use rapier3d_f64::prelude::{RigidBody, RigidBodyHandle, RigidBodySet};
use serde::{Deserialize, Serialize};

/// How a compliant clearance joint integrates its contact and friction forces over a step
/// ([`ClearanceJointBuilder::integration`](super::ClearanceJointBuilder::integration)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum ContactIntegration {
    /// The forces are evaluated once per Rapier step at its start and held over it: the step
    /// must resolve every contact (the step control shortens it to a fraction of the contact's
    /// period and of its stability limit, and of friction's near zero slip).
    #[default]
    Explicit,
    /// The contact is integrated on the joint's own clock inside each Rapier step, its damping
    /// and friction implicitly; Rapier's step carries the result (two Rapier passes: the rest of
    /// the world's motion, then the contact's impulse; docs/sub-cycled-contact.md). The
    /// world's step is set by its slow motion: the joint adds no stability limit. Needs the
    /// [`Stepper`](crate::rapier::pipeline::stepper::Stepper) (or a world built on it); a loop of your own
    /// that calls `ClearanceJointSet::apply` gets the explicit forces.
    SubCycled,
}

/// One state inside the last Rapier step of a sub-cycled joint: where its contact was, at the
/// end of a sub-step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SubStep {
    /// Time since the step's start, s.
    pub t: f64,
    /// The journal's state, its rates at the state.
    pub state: JournalState,
    /// The contact force pair at the state.
    pub force: ForcePair,
    /// Whether a contact began at this state (an onset; see
    /// [`ClearanceReport::onset`](super::ClearanceReport::onset)).
    pub onset: bool,
    /// Whether the onset is an impact ([`ClearanceReport::impact`](super::ClearanceReport::impact)).
    pub impact: bool,
    /// At an onset, the penetration rate at the crossing of delta = 0, m/s; 0 otherwise.
    pub approach_speed: f64,
    /// At an onset, the fraction of the sub-step before this state at which delta crossed 0;
    /// 1 otherwise.
    pub onset_fraction: f64,
}

/// Sub-steps in one world step beyond which the joint stops resolving and finishes the step in
/// one sub-step (a guard: at the default tolerance an impact takes about 70).
pub(crate) const MAX_SUBSTEPS: u32 = 100_000;

/// Fraction of the predicted time to contact that one free sub-step may cover.
const APPROACH_FRACTION: f64 = 0.5;

/// The fraction of a contact's damped stability limit one sub-step may cover, per unit of
/// tolerance: `10 tol` (0.075 at the default 0.0075). The damping is implicit, so the limit is
/// no bound here; a heavily damped contact relaxes at about `2/limit`, and a sub-step that
/// covers a fifth of what the explicit step may (`50 tol`) resolves that relaxation to the
/// tolerance (the improved law's single impact: its depth within 1e-3 of its ODE at the
/// default, `tests/references.rs`).
const STABLE_FRACTION_PER_TOLERANCE: f64 = 10.0;

/// Sub-steps of a contact one world step may cover in or on the way into contact
/// ([`ClearanceJoint::world_contact_step`]): 10, `20 tol` of the contact's period and `100 tol`
/// of its damped stability limit. Rapier hands a step's impulse to the rest of the mechanism as
/// one constant wrench, so a world step spanning whole impacts gives the bodies beyond the pair
/// only their mean (the deployable array's window statistics: docs/sub-cycled-contact.md).
const WORLD_SUBSTEPS_IN_CONTACT: f64 = 10.0;

/// A 12-vector over the pair's coordinates: the bearing's linear and angular, then the
/// journal's.
type Pair12 = [f64; 12];

fn dot(a: &Pair12, b: &Pair12) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn axpy(y: &mut Pair12, s: f64, x: &Pair12) {
    for (y, x) in y.iter_mut().zip(x) {
        *y += s * x;
    }
}

fn mul(p: &[f64; 144], x: &Pair12) -> Pair12 {
    let mut y = [0.0; 12];
    for (r, y) in y.iter_mut().enumerate() {
        *y = dot(p[r * 12..r * 12 + 12].try_into().expect("a row"), x);
    }
    y
}

fn part(x: &Pair12, k: usize) -> Vector {
    Vector::new(x[3 * k], x[3 * k + 1], x[3 * k + 2])
}

fn put(x: &mut Pair12, k: usize, v: Vector) {
    x[3 * k..3 * k + 3].copy_from_slice(&[v.x, v.y, v.z]);
}

/// The pair's coordinates of a load at `point` on the journal (`on_journal`) and its opposite
/// on the bearing, about the centres of mass `com`.
fn load(com: &[Vector; 2], point: Vector, on_journal: Vector) -> Pair12 {
    let mut l = [0.0; 12];
    put(&mut l, 0, -on_journal);
    put(&mut l, 1, (point - com[0]).cross(-on_journal));
    put(&mut l, 2, on_journal);
    put(&mut l, 3, (point - com[1]).cross(on_journal));
    l
}

/// The row that reads the relative velocity along `dir` of the journal's point `q_j` against
/// the bearing's point `q_i`.
fn row(com: &[Vector; 2], q_i: Vector, q_j: Vector, dir: Vector) -> Pair12 {
    let mut r = [0.0; 12];
    put(&mut r, 0, -dir);
    put(&mut r, 1, -(q_i - com[0]).cross(dir));
    put(&mut r, 2, dir);
    put(&mut r, 3, (q_j - com[1]).cross(dir));
    r
}

/// The pair at the start of a step: what the sub-cycle integrates from.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PairStart {
    com: [Vector; 2],
    /// Bearing centre and journal centre, from each centre of mass.
    anchor: [Vector; 2],
    /// The hinge's axis (the bearing's).
    axis: Vector,
    /// Rapier's velocities at the start (the mean over the step before).
    velocity: Pair12,
    mobility: [f64; 144],
    /// The bodies' orientations.
    rotation: [Rotation; 2],
}

impl PairStart {
    /// The pair of `joint` at the bodies' current state, with its mobility through `mechanism`
    /// (rebuilt at this state); `None` when a body is gone.
    pub(crate) fn of(
        joint: &ClearanceJoint,
        bodies: &RigidBodySet,
        mechanism: &Mechanism,
    ) -> Option<Self> {
        let rb: [&RigidBody; 2] = [bodies.get(joint.body1)?, bodies.get(joint.body2)?];
        let com = rb.map(world_center_of_mass);
        let anchor = [
            *rb[0].position() * joint.local_anchor1 - com[0],
            *rb[1].position() * joint.local_anchor2 - com[1],
        ];
        let velocity = Self::velocity_now(joint, bodies)?;
        Some(PairStart {
            com,
            anchor,
            axis: *rb[0].rotation() * joint.local_axis1,
            velocity,
            mobility: mechanism.pair_mobility(),
            rotation: rb.map(|b| *b.rotation()),
        })
    }

    /// The pair's velocities in `bodies` now (`None` when a body is gone).
    pub(crate) fn velocity_now(joint: &ClearanceJoint, bodies: &RigidBodySet) -> Option<Pair12> {
        let mut v = [0.0; 12];
        for (k, h) in [joint.body1, joint.body2].into_iter().enumerate() {
            let b = bodies.get(h)?;
            put(&mut v, 2 * k, b.linvel());
            put(&mut v, 2 * k + 1, b.angvel());
        }
        Some(v)
    }

    /// Where Rapier's pass 0 put the bodies beyond the integration of their velocities (its
    /// joints' position stabilisation, which removes the drift of the velocity-level
    /// constraints): the shift of each centre of mass and the turn of each body (rotation
    /// vector) over the step of `h` whose velocities went from the start's to `now`, with
    /// `c_n` the share of a velocity change that Rapier's substeps turn into displacement.
    /// The sub-cycle moves the bodies by it too, spread over the step, so that they end where
    /// Rapier puts them.
    pub(crate) fn stabilisation(
        &self,
        joint: &ClearanceJoint,
        bodies: &RigidBodySet,
        now: &Pair12,
        h: f64,
        c_n: f64,
    ) -> Option<[[Vector; 2]; 2]> {
        let rb: [&RigidBody; 2] = [bodies.get(joint.body1)?, bodies.get(joint.body2)?];
        let mut out = [[Vector::ZERO; 2]; 2];
        for k in 0..2 {
            if !rb[k].is_dynamic() {
                continue;
            }
            let moved = |i: usize| {
                h * part(&self.velocity, i) + c_n * h * (part(now, i) - part(&self.velocity, i))
            };
            out[0][k] = world_center_of_mass(rb[k]) - self.com[k] - moved(2 * k);
            let turn = (*rb[k].rotation() * self.rotation[k].inverse()).to_scaled_axis();
            out[1][k] = turn - moved(2 * k + 1);
        }
        Some(out)
    }

    /// The pair's mobility applied to `impulse`.
    pub(crate) fn moved_by(&self, impulse: &Pair12) -> Pair12 {
        mul(&self.mobility, impulse)
    }

    /// Rapier's velocities at the start.
    pub(crate) fn velocity(&self) -> &Pair12 {
        &self.velocity
    }
}

/// Where the pair is inside the sub-cycle: displacements of the centres of mass, rotation
/// vectors, and velocities.
#[derive(Clone, Copy, Debug, Default)]
struct Motion {
    shift: [Vector; 2],
    turn: [Vector; 2],
    v: Pair12,
}

fn rotate(turn: Vector, r: Vector) -> Vector {
    if turn == Vector::ZERO {
        r
    } else {
        Rotation::from_scaled_axis(turn) * r
    }
}

/// The contact at one position of the sub-cycle, linearised for the kick.
#[derive(Clone, Copy, Debug)]
struct Here {
    state: JournalState,
    /// The bearing's and the journal's centres, and the hinge's axis.
    centres: [Vector; 2],
    axis: Vector,
    /// The acceleration of the journal's centre relative to the bearing's in the plane, from the
    /// rest of the world's accelerations (with the bodies' centripetal terms), m/s².
    centre_acceleration: Vector,
    com: [Vector; 2],
    tangent: Vector,
    /// Rows reading the penetration rate and the slip along `tangent`.
    rows: [Pair12; 2],
    /// Loads of a unit normal force (pushing the journal out, along `-n`) and a unit force along
    /// `tangent`, and the pair's velocity change per unit of each.
    loads: [Pair12; 2],
    moves: [Pair12; 2],
    /// `w[r][c]`: the rate read by row `r` per unit of load `c`.
    w: [[f64; 2]; 2],
}

impl Here {
    /// The state here with its rates at the pair's velocity `v`.
    fn rates_at(&self, v: &Pair12) -> JournalState {
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
    fn mass(&self) -> f64 {
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
    /// The displacement held by the last finished step, `E` (impulse times time: the pair
    /// stands at Rapier's poses moved by `P E`), with the impulse held beside it, by which a
    /// step retaken from a restored state finds it ([`SubCycle::held_shift`]).
    pub(crate) shift: HeldShift,
    /// The displacement this step leaves held, `E'`, taken as `shift` when the step finishes.
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

/// The displacements held by the last two finished steps, each with the impulse held beside it
/// (newest first): a step the stepper rejects restores the impulse held before it, and with
/// it the displacement held before it.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct HeldShift {
    last: [(Pair12, Pair12); 2],
}

impl SubCycle {
    /// The displacement held with the impulse `held` (zero when neither of the last two
    /// finished steps held that impulse: a first step, or a state restored from further back).
    fn held_shift(&self, held: &Pair12) -> Pair12 {
        self.shift
            .last
            .iter()
            .find(|(h, _)| h == held)
            .map_or([0.0; 12], |(_, e)| *e)
    }
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
    fn here(&self, m: &Motion) -> Here {
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

    /// `delta_dot0` for the law in the contact of `history` at `here` (as the explicit joint's).
    fn impact_rate(&self, history: &ContactHistory, here: &Here) -> f64 {
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
    fn substep(&self, here: &Here, history: &ContactHistory, left: f64) -> f64 {
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
            let stable = STABLE_FRACTION_PER_TOLERANCE * self.tolerance;
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
            let path = super::flight_step(self.tolerance, c, v.length());
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
        let s = s.max(1e-9 * self.h);
        // No sliver of a last sub-step.
        if s >= 0.95 * left { left } else { s }
    }

    /// The sub-step after one of `s` that left `left` (s) of the step, from `here`: 0 when that
    /// was the last, the rest of the step beyond [`MAX_SUBSTEPS`].
    fn next_substep(&self, here: &Here, history: &ContactHistory, left: f64, count: u32) -> f64 {
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
    fn kick(
        &self,
        here: &Here,
        v: &mut Pair12,
        (sigma, sigma_c): (f64, f64),
        beta: f64,
        impact_rate: f64,
    ) -> ([f64; 2], Pair12, f64) {
        let c_a = [dot(&here.rows[0], v), dot(&here.rows[1], v)];
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
            for _ in 0..50 {
                // The normal force is affine in the rate (every law here): solved exactly.
                let c0n = c_a[0] + beta * a[0] + bs * w[0][1] * f[1];
                let f_n = ((elastic + damping * c0n) / (1.0 - damping * bs * w[0][0])).max(0.0);
                let c0t = c_a[1] + beta * a[1] + bs * w[1][0] * f_n;
                let k = bs * w[1][1] * f_n;
                let slip = implicit_slip(&self.joint.friction_law, c0t, k);
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

/// One joint's state inside a sub-cycle.
struct Lane {
    m: Motion,
    history: ContactHistory,
    /// The state at the sub-step before, its rates at the state.
    prev: JournalState,
    here: Here,
    /// `Pi`: the time integral of the impulse accumulated by each sub-step's start.
    pi: Pair12,
}

/// What the sub-steps of one world step integrate: the coupled joints of one island, each with
/// its [`Cycle`], the mobilities between their pairs (`cross[i]`: `(k, P_ik)`, how joint `k`'s
/// contact moves joint `i`'s pair) and each contact's memory at the step's start (history, and
/// the state with its rates at the state).
pub(crate) struct Group<'a> {
    pub(crate) cycles: Vec<Cycle<'a>>,
    pub(crate) cross: &'a [Vec<(usize, [f64; 144])>],
    pub(crate) memory: Vec<(ContactHistory, JournalState)>,
}

impl Group<'_> {
    /// The sub-step all joints can take from their lanes, at most `left` (s); 0 after the last.
    fn substep(&self, lanes: &[Lane], left: f64, count: u32) -> f64 {
        self.cycles
            .iter()
            .zip(lanes)
            .map(|(c, l)| c.next_substep(&l.here, &l.history, left, count))
            .fold(f64::INFINITY, f64::min)
    }

    /// Joint `k`'s contact impulse `dg` moves the other joints' pairs.
    fn spread(&self, lanes: &mut [Lane], k: usize, dg: &Pair12) {
        if dg.iter().all(|x| *x == 0.0) {
            return;
        }
        for (lane, cross) in lanes.iter_mut().zip(self.cross) {
            for (_, p) in cross.iter().filter(|(from, _)| *from == k) {
                axpy(&mut lane.m.v, 1.0, &mul(p, dg));
            }
        }
    }

    /// Integrates the step of every joint in lockstep (the contacts of one sub-step kicked in
    /// turn, each seeing the ones before: Gauss-Seidel across joints); `outs[k]` receives joint
    /// `k`'s sub-cycle and keeps its buffers.
    pub(crate) fn run(&self, outs: &mut [SubCycle]) {
        let h = self.cycles[0].h;
        let mut lanes: Vec<Lane> = self
            .cycles
            .iter()
            .zip(&self.memory)
            .map(|(c, (history, before))| {
                let m = Motion {
                    shift: [part(&c.offset, 0), part(&c.offset, 2)],
                    turn: [part(&c.offset, 1), part(&c.offset, 3)],
                    v: c.u0,
                };
                let here = c.here(&m);
                Lane {
                    here,
                    m,
                    history: *history,
                    prev: *before,
                    pi: [0.0; 12],
                }
            })
            .collect();
        for out in outs.iter_mut() {
            out.samples.clear();
            out.impulse = [0.0; 12];
            out.dissipated = 0.0;
        }
        // The first half kicks, from the states' own velocities.
        let mut rest = h;
        let mut s = self.substep(&lanes, rest, 0);
        for k in 0..lanes.len() {
            let c = &self.cycles[k];
            let rate = c.impact_rate(&lanes[k].history, &lanes[k].here);
            let lane = &mut lanes[k];
            let (_, dg, loss) = c.kick(&lane.here, &mut lane.m.v, (0.5 * s, 0.5 * s), 0.0, rate);
            self.spread(&mut lanes, k, &dg);
            axpy(&mut outs[k].impulse, 1.0, &dg);
            outs[k].dissipated += loss;
        }
        let (mut tau, mut count) = (0.0, 0u32);
        let mut onsets = Vec::with_capacity(lanes.len());
        let mut v_before = Vec::with_capacity(lanes.len());
        let mut forces = Vec::with_capacity(lanes.len());
        loop {
            count += 1;
            for ((lane, out), c) in lanes.iter_mut().zip(outs.iter()).zip(&self.cycles) {
                let share = s / h;
                for k in 0..2 {
                    lane.m.shift[k] += s * part(&lane.m.v, 2 * k) + share * c.stabilisation[0][k];
                    lane.m.turn[k] +=
                        s * part(&lane.m.v, 2 * k + 1) + share * c.stabilisation[1][k];
                }
                axpy(&mut lane.pi, s, &out.impulse);
            }
            // A sub-step chosen as the rest of the step ends it exactly.
            let left = if s == rest { 0.0 } else { rest - s };
            rest = left;
            let last = left <= 0.0;
            tau = if last { h } else { tau + s };
            onsets.clear();
            for (c, lane) in self.cycles.iter().zip(lanes.iter_mut()) {
                let j = c.joint;
                lane.here = c.here(&lane.m);
                let onset = lane.history.advance(
                    Some(&lane.prev),
                    &lane.here.state,
                    j.min_impact_speed,
                    j.min_separation,
                );
                onsets.push(onset);
            }
            let next = self.substep(&lanes, left, count);
            let (alpha, beta) = (next / (s + next), s / (s + next));
            v_before.clear();
            v_before.extend(lanes.iter().map(|l| l.m.v));
            forces.clear();
            for k in 0..lanes.len() {
                let c = &self.cycles[k];
                // A contact that began inside the sub-step before acts from its crossing on:
                // for a law whose force jumps at the onset (Kelvin-Voigt's damping) the kick's
                // half over that sub-step is the part after the crossing.
                let before = if onsets[k].onset {
                    s * (1.0 - onsets[k].fraction.clamp(0.0, 1.0))
                } else {
                    s
                };
                let spans = (0.5 * (s + next), 0.5 * (before + next));
                let rate = c.impact_rate(&lanes[k].history, &lanes[k].here);
                let lane = &mut lanes[k];
                let (f, dg, loss) = c.kick(&lane.here, &mut lane.m.v, spans, beta, rate);
                self.spread(&mut lanes, k, &dg);
                axpy(&mut outs[k].impulse, 1.0, &dg);
                outs[k].dissipated += loss;
                forces.push(f);
            }
            for k in 0..lanes.len() {
                let (lane, onset, f) = (&mut lanes[k], &onsets[k], forces[k]);
                // The state: its velocity between the half steps around it.
                let mut at_state = lane.m.v;
                for (x, b) in at_state.iter_mut().zip(v_before[k]) {
                    *x = alpha * b + beta * *x;
                }
                let state = lane.here.rates_at(&at_state);
                let n = lane.here.state.normal;
                let force = ForcePair {
                    on_journal: -f[0] * n + f[1] * lane.here.tangent,
                    point: lane.here.state.contact_point,
                    normal_force: f[0],
                    friction_force: f[1].abs(),
                };
                outs[k].samples.push(SubStep {
                    t: tau,
                    state,
                    force,
                    onset: onset.onset,
                    impact: onset.impact,
                    approach_speed: onset.approach_speed,
                    onset_fraction: onset.fraction,
                });
                lane.prev = state;
            }
            if last {
                break;
            }
            s = next;
        }
        for (lane, out) in lanes.iter().zip(outs.iter_mut()) {
            out.end_mass = lane.here.mass();
            out.end_velocity = lane.m.v;
            for (mean, p) in out.mean.iter_mut().zip(lane.pi) {
                *mean = p / h;
            }
            out.history = lane.history;
            out.substeps = count;
        }
    }
}

/// After Rapier's pass 0 of a step (`pass`), with `iterations` solver iterations: runs the
/// sub-cycle of every sub-cycled joint of `joints` that has a start, the joints of one island
/// together ([`Group`]), and returns the impulse Rapier's pass 1 must deliver for each, `Q kick`
/// (`None`: nothing to deliver). Each keeps the impulse left held for the evaluation at the
/// step's end.
pub(crate) fn plan_cycles(
    joints: &mut [&mut ClearanceJoint],
    bodies: &RigidBodySet,
    pass: &StepPass,
    iterations: usize,
) -> Vec<Option<Pair12>> {
    let mut deliveries = vec![None; joints.len()];
    let planned: Vec<usize> = (0..joints.len())
        .filter(|&i| {
            joints[i].cycle.start.is_some() && PairStart::velocity_now(joints[i], bodies).is_some()
        })
        .collect();
    for group in islands(joints, &planned) {
        plan_group(joints, &group, bodies, pass, iterations, &mut deliveries);
    }
    deliveries
}

/// The members of `planned` in groups whose pairs move each other (a block of
/// `cycle.coupled`), each in the set's order.
fn islands(joints: &[&mut ClearanceJoint], planned: &[usize]) -> Vec<Vec<usize>> {
    let mut group: Vec<usize> = (0..planned.len()).collect();
    fn root(group: &mut [usize], mut i: usize) -> usize {
        while group[i] != i {
            group[i] = group[group[i]];
            i = group[i];
        }
        i
    }
    for (a, &i) in planned.iter().enumerate() {
        for (b, &j) in planned.iter().enumerate().skip(a + 1) {
            if joints[i].coupling_to(joints[j]).is_some() {
                let (ra, rb) = (root(&mut group, a), root(&mut group, b));
                group[ra.max(rb)] = ra.min(rb);
            }
        }
    }
    let roots: Vec<usize> = (0..planned.len()).map(|a| root(&mut group, a)).collect();
    let mut out: Vec<(usize, Vec<usize>)> = Vec::new();
    for (a, r) in roots.into_iter().enumerate() {
        match out.iter_mut().find(|(root, _)| *root == r) {
            Some((_, g)) => g.push(planned[a]),
            None => out.push((r, vec![planned[a]])),
        }
    }
    out.into_iter().map(|(_, g)| g).collect()
}

/// Runs the sub-cycle of the joints `group` (indices into `joints`, one island) and fills
/// their `deliveries`.
fn plan_group(
    joints: &mut [&mut ClearanceJoint],
    group: &[usize],
    bodies: &RigidBodySet,
    pass: &StepPass,
    iterations: usize,
    deliveries: &mut [Option<Pair12>],
) {
    let (h, kick) = (pass.dt, pass.kick);
    let c_n = (iterations as f64 + 1.0) / (2.0 * iterations.max(1) as f64);
    let mut runs: Vec<SubCycle> = group
        .iter()
        .map(|&i| std::mem::take(&mut joints[i].cycle.run))
        .collect();
    let shared: &[&mut ClearanceJoint] = joints;
    let members: Vec<&ClearanceJoint> = group.iter().map(|&i| &*shared[i]).collect();
    let starts: Vec<PairStart> = members
        .iter()
        .map(|j| j.cycle.start.expect("a planned joint has a start"))
        .collect();
    let held: Vec<Pair12> = members.iter().map(|j| j.cycle.held).collect();
    let shift: Vec<Pair12> = (0..group.len())
        .map(|a| runs[a].held_shift(&held[a]))
        .collect();
    let cross: Vec<Vec<(usize, [f64; 144])>> = members
        .iter()
        .enumerate()
        .map(|(a, j)| {
            let others = members.iter().enumerate().filter(|(b, _)| *b != a);
            others
                .filter_map(|(b, other)| j.coupling_to(other).map(|p| (b, p)))
                .collect()
        })
        .collect();
    // The velocity change of each pair from impulses on every pair of the group.
    let moved = |a: usize, impulses: &[Pair12]| {
        let mut v = starts[a].moved_by(&impulses[a]);
        for (b, p) in &cross[a] {
            axpy(&mut v, 1.0, &mul(p, &impulses[*b]));
        }
        v
    };
    let cycles = members
        .iter()
        .enumerate()
        .map(|(a, &joint)| {
            let now = PairStart::velocity_now(joint, bodies).expect("a planned joint's bodies");
            let mut a_free = [0.0; 12];
            for ((x, n), v) in a_free.iter_mut().zip(now).zip(starts[a].velocity()) {
                *x = (n - v) / kick;
            }
            let mut u0 = *starts[a].velocity();
            axpy(&mut u0, c_n * kick - 0.5 * h, &a_free);
            axpy(&mut u0, 1.0, &moved(a, &held));
            let stabilisation = starts[a]
                .stabilisation(joint, bodies, &now, h, c_n)
                .unwrap_or_default();
            Cycle {
                joint,
                start: &starts[a],
                u0,
                offset: moved(a, &shift),
                a_free,
                stabilisation,
                h,
                tolerance: pass.tolerance,
            }
        })
        .collect();
    let memory = members
        .iter()
        .map(|j| (j.contact, j.report.state))
        .collect();
    Group {
        cycles,
        cross: &cross,
        memory,
    }
    .run(&mut runs);
    let deliver: Vec<Pair12> = (0..group.len())
        .map(|a| {
            let (d, shift_next) = delivery_plan(&held[a], &shift[a], &runs[a], h, c_n);
            runs[a].shift_next = shift_next;
            d
        })
        .collect();
    // The state's velocity beyond the Verlet reading of Rapier's velocities around it,
    // `u_before + w (u_after - u_before)`, `w = h_prev/(h_prev + h)`: `P (H - w Q kick)`.
    let w = (2.0 * kick - h) / (2.0 * kick);
    let beyond: Vec<Pair12> = (0..group.len())
        .map(|a| {
            let mut b = held[a];
            axpy(&mut b, -w, &deliver[a]);
            b
        })
        .collect();
    for (a, run) in runs.iter_mut().enumerate() {
        run.start_correction = moved(a, &beyond);
    }
    for ((a, &i), mut run) in group.iter().enumerate().zip(runs) {
        let mut left = held[a];
        axpy(&mut left, 1.0, &run.impulse);
        axpy(&mut left, -1.0, &deliver[a]);
        let joint = &mut *joints[i];
        std::mem::swap(&mut joint.cycle.run, &mut run);
        joint.cycle.pending = Some(left);
        deliveries[i] = deliver[a].iter().any(|q| *q != 0.0).then_some(deliver[a]);
    }
}

/// The impulse Rapier's pass 1 delivers over a step of `h` (`Q kick`, as a constant wrench
/// through `N` substeps: `c_n = (N + 1)/(2 N)`), after a sub-cycle `run` that began with the
/// impulse `held` and the displacement `shift` held, and the displacement it leaves held.
///
/// A constant wrench through Rapier's substeps moves the pair by `c_n h P Q kick` and changes
/// its velocity by `P Q kick`; the sub-cycle moved it by `P (h H + Pi)` and changed its velocity
/// by `P Gamma` beyond the held `H`. With one substep (`c_n = 1`) the move is met exactly,
/// `Q kick = H + Pi/h`, and the rest of the impulse, `H + Gamma - Q kick` (between 0 and
/// `Gamma`), is held to the next step. With more, meeting the move every step holds
/// `H' = (1 - 1/c_n) H + ...`: an impulse that changes sign at every step (-0.6 of itself at four
/// substeps), in Rapier's velocities between the steps, where every velocity-dependent force
/// of the world (a controller's damping, a motor) reads it: the SCARA arm's shoulder fed it back
/// through its PD controller into impacts 4 times the reference's. Here instead the move and
/// the impulse are met over two steps, without sign changes: `E0 = E + h H + Pi - c_n h (H +
/// Gamma)` is what the velocity-matching delivery `H + Gamma` leaves of the move, the delivery
/// is `H + Gamma + E0/h`, and the step leaves `H' = -E0/h` held and `E' = (1 - c_n) E0` in
/// place (the pair stands at Rapier's poses moved by `P E'`, where the next sub-cycle starts);
/// a step without contact after it delivers both exactly (`E0' = 0`).
fn delivery_plan(
    held: &Pair12,
    shift: &Pair12,
    run: &SubCycle,
    h: f64,
    c_n: f64,
) -> (Pair12, Pair12) {
    let mut d = *held;
    if c_n == 1.0 {
        axpy(&mut d, 1.0, &run.mean);
        return (d, [0.0; 12]);
    }
    // `E0/h`, with the velocity-matching delivery `H + Gamma` in `d`.
    let mut e0 = *shift;
    e0.iter_mut().for_each(|e| *e /= h);
    axpy(&mut e0, 1.0 - c_n, held);
    axpy(&mut e0, 1.0, &run.mean);
    axpy(&mut e0, -c_n, &run.impulse);
    axpy(&mut d, 1.0, &run.impulse);
    axpy(&mut d, 1.0, &e0);
    (d, e0.map(|e| (1.0 - c_n) * h * e))
}

impl super::CycleState {
    /// Takes the step's sub-cycle as the last step's: the impulse left `held`, and what the
    /// step did (its velocity correction, dissipation, impulse and sub-steps), for the readers.
    pub(crate) fn adopt_run(&mut self, held: Pair12) {
        let run = &mut self.run;
        run.shift.last = [(held, run.shift_next), run.shift.last[0]];
        self.held = held;
        self.start_correction = self.run.start_correction;
        self.dissipated = self.run.dissipated;
        self.impulse = self.run.impulse;
        self.substep_count = self.run.substeps;
        std::mem::swap(&mut self.substeps, &mut self.run.samples);
    }
}

impl ClearanceJoint {
    /// The world step a sub-cycled joint allows near contact, from its state at the last step's
    /// end: in contact, [`WORLD_SUBSTEPS_IN_CONTACT`] of the sub-steps the contact needs there
    /// (`ContactAhead::resolving_step` at `10 tol` of the tolerance); approaching the wall at
    /// the penetration rate, at most half the time to it and no less than that step at its
    /// arrival speed; otherwise no bound (s).
    pub(crate) fn world_contact_step(&self, tolerance: f64) -> f64 {
        let st = &self.report.state;
        let (depth, rate) = (st.penetration, st.penetration_rate);
        let step = |speed: f64, depth: f64| {
            let contact = ContactAhead {
                mass: self.report.effective_mass,
                approach_speed: speed,
                depth,
                impact_rate: self.contact.in_contact.then_some(self.contact.impact_rate),
                min_impact_speed: self.min_impact_speed,
            };
            let elastic = self.normal_law.elastic_energy(depth.max(0.0));
            let k = WORLD_SUBSTEPS_IN_CONTACT;
            let stable = k * STABLE_FRACTION_PER_TOLERANCE * tolerance;
            contact.resolving_step(&self.normal_law, elastic, k * tolerance, stable)
        };
        if depth > 0.0 {
            step(rate.abs(), depth)
        } else if rate > 0.0 {
            (APPROACH_FRACTION * -depth / rate).max(step(rate, 0.0))
        } else {
            f64::INFINITY
        }
    }

    /// The mobility from `other`'s contact loads to this joint's pair, when the two are
    /// sub-cycled in one island (taken with the start, [`ClearanceJoint::take_coupling`]).
    fn coupling_to(&self, other: &ClearanceJoint) -> Option<[f64; 144]> {
        let pair = [other.body1, other.body2];
        self.cycle
            .coupled
            .iter()
            .find(|(p, _)| *p == pair)
            .map(|(_, m)| *m)
    }

    /// Takes the mobilities from the contact loads of the other sub-cycled joints' pairs
    /// (`partners`: their bearing and journal bodies) to this pair through `mechanism`, rebuilt
    /// for this joint at the state: the pairs whose contacts move this one within a step.
    pub(crate) fn take_coupling(
        &mut self,
        mechanism: &Mechanism,
        partners: impl Iterator<Item = [RigidBodyHandle; 2]>,
    ) {
        self.cycle.coupled.clear();
        if self.cycle.start.is_none() {
            return;
        }
        for pair in partners {
            if self.cycle.coupled.iter().any(|(p, _)| *p == pair) {
                continue;
            }
            if let Some(p) = mechanism.cross_mobility(pair) {
                self.cycle.coupled.push((pair, p));
            }
        }
    }

    /// At the evaluation after a sub-cycled step: the report from the sub-cycle's end, the
    /// states inside the step, the impulse left held. `None` when no step was planned (the
    /// joint is then evaluated as an explicit one) or a body is gone.
    pub(crate) fn finish_cycle(&mut self, bodies: &RigidBodySet) -> Option<(Wrench, Wrench)> {
        let held = self.cycle.pending.take()?;
        let end = *self.cycle.run.samples.last()?;
        let (rb1, rb2) = (bodies.get(self.body1)?, bodies.get(self.body2)?);
        let history = self.cycle.run.history;
        let mass = self.cycle.run.end_mass;
        let law = &self.normal_law;
        let delta = end.state.penetration;
        let impact_rate = if history.in_contact && law.uses_impact_rate() {
            history
                .impact_rate
                .max(loaded_impact_rate(law.elastic_energy(delta), mass))
        } else {
            history.impact_rate
        };
        let (omega, zeta) = if delta > 0.0 {
            let c = NormalContact {
                penetration: delta,
                penetration_rate: end.state.penetration_rate,
                impact_rate,
            };
            let k = law.tangent_stiffness(delta);
            let (_, omega, zeta) = stable_step(k, law.damping_coefficient(&c), mass);
            (omega, zeta)
        } else {
            (0.0, 0.0)
        };
        self.contact = history;
        self.report = ClearanceReport {
            state: end.state,
            mode: history.mode(),
            onset: end.onset,
            impact: end.impact,
            impact_rate,
            approach_speed: end.approach_speed,
            contact_rate: end.state.penetration_rate,
            onset_fraction: end.onset_fraction,
            force: end.force,
            max_stable_dt: f64::INFINITY,
            friction_stable_dt: f64::INFINITY,
            omega,
            zeta,
            effective_mass: mass,
            spatial: None,
        };
        self.elastic = std::sync::OnceLock::new();
        self.previous_rate = None;
        self.cycle.adopt_run(held);
        let f = end.force.on_journal;
        let p = end.force.point;
        let (c1, c2) = (world_center_of_mass(rb1), world_center_of_mass(rb2));
        Some((
            Wrench {
                body: self.body1,
                force: -f,
                torque: (p - c1).cross(-f),
            },
            Wrench {
                body: self.body2,
                force: f,
                torque: (p - c2).cross(f),
            },
        ))
    }

    /// The wrenches that deliver the impulse `deliver` (`Q kick`) over a step whose kick is
    /// `kick` (s): a force and torque on each body, held over the step.
    pub(crate) fn delivery(&self, deliver: &Pair12, kick: f64) -> [Wrench; 2] {
        [(self.body1, 0), (self.body2, 2)].map(|(body, k)| Wrench {
            body,
            force: part(deliver, k) / kick,
            torque: part(deliver, k + 1) / kick,
        })
    }

    /// Takes the pair's state before the next step (at each evaluation; `None` for a joint that
    /// is not sub-cycled or whose body is gone).
    pub(crate) fn take_start(&mut self, bodies: &RigidBodySet, mechanism: &Mechanism) {
        // A spatial joint takes its own start (`take_spatial_start`).
        self.cycle.start = if self.sub_cycled() && self.spatial.is_none() {
            PairStart::of(self, bodies, mechanism)
        } else {
            None
        };
    }

    /// The velocity (linear, angular) of the bearing's body and of the journal's at the state
    /// the last step began from, beyond the Verlet reading of Rapier's velocities around that
    /// state (`(h v_before + h_prev v_after)/(h_prev + h)`, `v_before` the velocity stored
    /// before the step, `v_after` after it, `h_prev` and `h` the steps before and after the
    /// state): the part of a sub-cycled contact's impulse inside the steps that Rapier's mean
    /// velocities spread over them. Zero for an explicit joint and for steps without contact.
    /// Add it to read the bodies' momentum or energy at that state.
    pub fn start_velocity_correction(&self) -> [(RigidBodyHandle, Vector, Vector); 2] {
        let c = &self.cycle.start_correction;
        [(self.body1, 0), (self.body2, 2)].map(|(b, k)| (b, part(c, k), part(c, k + 1)))
    }

    /// The contact's impulse on the journal over the last step, N s, summed over a sub-cycled
    /// joint's sub-steps (`None` for an explicit joint, and before the first sub-cycled step):
    /// with [`substeps`](Self::substeps), what the step's contacts did when the step is longer
    /// than they are.
    pub fn step_impulse(&self) -> Option<Vector> {
        (self.sub_cycled() && !self.cycle.substeps.is_empty()).then(|| part(&self.cycle.impulse, 2))
    }

    /// The energy the contact's damping and friction took over the last step, J, integrated over
    /// a sub-cycled joint's sub-steps (`None` for an explicit joint, and before the first
    /// sub-cycled step).
    pub fn step_dissipation(&self) -> Option<f64> {
        (self.sub_cycled() && !self.cycle.substeps.is_empty()).then_some(self.cycle.dissipated)
    }

    /// Sub-steps the last step took, when it reached [`MAX_SUBSTEPS`] (its rest then went in
    /// one sub-step).
    pub(crate) fn substeps_beyond_cap(&self) -> Option<u32> {
        (self.cycle.substep_count > MAX_SUBSTEPS).then_some(self.cycle.substep_count)
    }

    /// The deepest penetration of the last step, m: over its sub-steps for a sub-cycled joint,
    /// at its end for an explicit one.
    pub(crate) fn deepest_in_step(&self) -> f64 {
        self.cycle
            .substeps
            .iter()
            .map(|s| s.state.penetration)
            .fold(self.report.state.penetration, f64::max)
    }
}

/// The first time within `left` (s) at which the eccentricity `e + v t + a t^2/2` (m, m/s,
/// m/s²) can reach the clearance `c` (m), `None` when it stays inside. Marched by safe steps:
/// from each point the gap cannot close faster than the path's speed and acceleration allow,
/// so no contact is stepped over, and a path straight at the wall lands on it in one step.
fn time_to_wall(e: Vector, v: Vector, a: Vector, c: f64, left: f64) -> Option<f64> {
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
/// bracketed by bisection with a secant guess, as the law may fall with speed (Stribeck).
fn implicit_slip(law: &impl FrictionLaw, c0: f64, k: f64) -> f64 {
    if c0 == 0.0 || !(k > 0.0) {
        return c0;
    }
    let sign = c0.signum();
    let target = c0.abs();
    // g(x) = x + k mu(x) - target over [0, target]: g(0) <= 0 <= g(target).
    let g = |x: f64| x + k * law.coefficient(x) - target;
    let (mut lo, mut hi) = (0.0, target);
    let (mut g_lo, mut g_hi) = (g(lo), g(hi));
    if g_lo >= 0.0 {
        return 0.0;
    }
    for _ in 0..200 {
        let secant = lo - g_lo * (hi - lo) / (g_hi - g_lo);
        let mid = 0.5 * (lo + hi);
        // The secant when it falls well inside the bracket, else the midpoint.
        let x = if secant > lo + 0.01 * (hi - lo) && secant < hi - 0.01 * (hi - lo) {
            secant
        } else {
            mid
        };
        let gx = g(x);
        if gx <= 0.0 {
            lo = x;
            g_lo = gx;
        } else {
            hi = x;
            g_hi = gx;
        }
        if hi - lo <= 1e-14 * target + 1e-300 {
            break;
        }
    }
    sign * 0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::laws::Coulomb;

    #[test]
    fn implicit_slip_by_hand() {
        // mu = 0.2 min(1, v/0.01): with k = 0.5 and c0 = 0.003 the root is in the linear part,
        // x + 0.5 * 20 x = 0.003 -> x = 0.003/11.
        let law = Coulomb::new(0.2, 0.01).unwrap();
        let x = implicit_slip(&law, 0.003, 0.5);
        assert!((x - 0.003 / 11.0).abs() < 1e-15, "{x}");
        let x = implicit_slip(&law, -0.003, 0.5);
        assert!((x + 0.003 / 11.0).abs() < 1e-15, "{x}");
        // Sliding: x + 0.5 * 0.2 = 1 -> x = 0.9.
        assert!((implicit_slip(&law, 1.0, 0.5) - 0.9).abs() < 1e-13);
        assert_eq!(implicit_slip(&law, 0.0, 0.5), 0.0);
    }

    #[test]
    fn time_to_wall_by_hand() {
        let (x, y) = (Vector::X, Vector::Y);
        // From the centre at 2 m/s across a gap of 1 m: 0.5 s.
        let t = time_to_wall(Vector::ZERO, 2.0 * x, Vector::ZERO, 1.0, 2.0).unwrap();
        assert!((t - 0.5).abs() < 1e-12, "{t}");
        // From rest under 2 m/s²: 1 = t^2 -> 1 s.
        let t = time_to_wall(Vector::ZERO, Vector::ZERO, 2.0 * y, 1.0, 3.0).unwrap();
        assert!((t - 1.0).abs() < 1e-12, "{t}");
        // Sliding along the wall 1e-6 inside it at 1 m/s, pulled to it at 2 m/s²: it reaches
        // the wall after 1e-3 s, and the march stays below that.
        let t = time_to_wall((1.0 - 1e-6) * x, y, 2.0 * x, 1.0, 1.0).unwrap();
        assert!(t <= 1.0e-3 + 1e-9, "{t}");
        // Not within the time left.
        assert_eq!(time_to_wall(Vector::ZERO, x, Vector::ZERO, 1.0, 0.5), None);
        // Moving away from a wall it is near.
        assert_eq!(time_to_wall(0.9 * x, -x, Vector::ZERO, 1.0, 0.5), None);
    }
}
