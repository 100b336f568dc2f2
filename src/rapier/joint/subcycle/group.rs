//! The sub-cycles of one world step: the planar sub-cycled joints of one island integrated
//! in lockstep ([`Group`]), and the delivery Rapier's pass 1 takes from them with the impulse and
//! displacement each holds to the next step ([`plan_cycles`]).

use super::SubStep;
use super::pair::{Motion, Pair12, PairStart, axpy, mul, part};
use super::steps::{Cycle, Here, SubCycle};
use crate::model::kinematics::{ForcePair, JournalState};
use crate::rapier::joint::{ClearanceJoint, ContactHistory};
use crate::rapier::pipeline::step_hooks::StepPass;
use rapier3d_f64::prelude::RigidBodySet;

/// Rounds of the continuity correction over the joints of a group (each joint's correction
/// moves the others' pairs through the mobilities between them).
const CONTINUITY_PASSES: usize = 3;

/// Sub-steps beyond which a world step is long against its contact (its sub-cycle then goes
/// on from where the last one left the pin): twice the ones the world's step control lets a
/// step span in contact (`WORLD_SUBSTEPS_IN_CONTACT`).
const LONG_STEP_SUBSTEPS: u32 = 20;

/// One joint's state inside a sub-cycle.
pub(super) struct Lane {
    pub(super) m: Motion,
    pub(super) history: ContactHistory,
    /// The state at the sub-step before, its rates at the state.
    pub(super) prev: JournalState,
    pub(super) here: Here,
    /// `Pi`: the time integral of the impulse accumulated by each sub-step's start.
    pub(super) pi: Pair12,
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
    pub(super) fn substep(&self, lanes: &[Lane], left: f64, count: u32) -> f64 {
        self.cycles
            .iter()
            .zip(lanes)
            .map(|(c, l)| c.next_substep(&l.here, &l.history, left, count))
            .fold(f64::INFINITY, f64::min)
    }

    /// Joint `k`'s contact impulse `dg` moves the other joints' pairs.
    pub(super) fn spread(&self, lanes: &mut [Lane], k: usize, dg: &Pair12) {
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
                let onset = lane.history.advance_sub_step(
                    &lane.prev,
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
                    moment: force.point.cross(force.on_journal),
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
pub(crate) fn islands(joints: &[&mut ClearanceJoint], planned: &[usize]) -> Vec<Vec<usize>> {
    let mut group: Vec<usize> = (0..planned.len()).collect();
    pub(super) fn root(group: &mut [usize], mut i: usize) -> usize {
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
pub(super) fn plan_group(
    joints: &mut [&mut ClearanceJoint],
    group: &[usize],
    bodies: &RigidBodySet,
    pass: &StepPass,
    iterations: usize,
    deliveries: &mut [Option<Pair12>],
) {
    let (h, kick) = (pass.dt, pass.kick);
    let c_n = crate::rapier::pipeline::stepper::substep_share(iterations);
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
    let mut held: Vec<Pair12> = members.iter().map(|j| j.cycle.held).collect();
    let mut shift: Vec<Pair12> = members.iter().map(|j| j.cycle.shift).collect();
    let cross = cross_mobilities(&members);
    // The velocity change of each pair from impulses on every pair of the group.
    let moved = |a: usize, impulses: &[Pair12]| {
        let mut v = starts[a].moved_by(&impulses[a]);
        for (b, p) in &cross[a] {
            axpy(&mut v, 1.0, &mul(p, &impulses[*b]));
        }
        v
    };
    // What pass 0 says of each pair: the rest of the world's acceleration over the step and
    // Rapier's stabilisation. It does not change with the impulse and displacement held, which
    // the continuity passes below move, so it is read once.
    let free: Vec<(Pair12, _)> = members
        .iter()
        .zip(&starts)
        .map(|(&joint, start)| {
            let now = PairStart::velocity_now(joint, bodies).expect("a planned joint's bodies");
            let mut a_free = [0.0; 12];
            for ((x, n), v) in a_free.iter_mut().zip(now).zip(start.velocity()) {
                *x = (n - v) / kick;
            }
            let stabilisation = if joint.techniques.stabilisation {
                start
                    .stabilisation(joint, bodies, &now, h, c_n)
                    .unwrap_or_default()
            } else {
                Default::default()
            };
            (a_free, stabilisation)
        })
        .collect();
    let cycle = |a: usize, held: &[Pair12], shift: &[Pair12]| {
        let (a_free, stabilisation) = free[a];
        let mut u0 = *starts[a].velocity();
        axpy(&mut u0, c_n * kick - 0.5 * h, &a_free);
        axpy(&mut u0, 1.0, &moved(a, held));
        Cycle {
            joint: members[a],
            start: &starts[a],
            u0,
            offset: moved(a, shift),
            a_free,
            stabilisation,
            h,
            tolerance: crate::rapier::joint::step_policy::contact_tolerance(pass.tolerance),
        }
    };
    // After a step long against its contact (more than `LONG_STEP_SUBSTEPS` sub-steps), each
    // contact goes on from where its last sub-cycle left it: what Rapier's pass 1 made of the
    // step's wrench beyond the pair's mobility at the step's start (the bearing's body turning
    // on its ideal joints while the contact moves it) is held to the next step as a
    // displacement and an impulse across the pin. A step the world's step control sized to its
    // contact starts from Rapier's state: the difference is of the order of the start's own
    // reading of its rate (Rapier's velocities carried to the state by this step's
    // acceleration), and a displacement held between the steps is a lever the contact's force
    // acts through beside Rapier's bodies.
    let continuing: Vec<bool> = members
        .iter()
        .map(|j| {
            j.techniques.continuation
                && j.cycle.substep_count > LONG_STEP_SUBSTEPS
                && j.cycle.impulse.iter().any(|x| *x != 0.0)
        })
        .collect();
    let rounds = if members.iter().all(|j| j.techniques.continuity_rounds) {
        CONTINUITY_PASSES
    } else {
        1
    };
    for _ in 0..rounds {
        for a in (0..group.len()).filter(|&a| continuing[a]) {
            let c = cycle(a, &held, &shift);
            let end = &members[a].report.state;
            if let Some((e, v)) = c.continuity(end.eccentricity, end.eccentricity_rate) {
                axpy(&mut shift[a], 1.0, &e);
                axpy(&mut held[a], 1.0, &v);
            }
        }
    }
    let cycles: Vec<Cycle> = (0..group.len()).map(|a| cycle(a, &held, &shift)).collect();
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
    let beyond = beyond_verlet(&held, &deliver, kick, h);
    for (a, run) in runs.iter_mut().enumerate() {
        let own = starts[a].moved_by(&beyond[a]);
        run.start_correction = attributed(a, &members, own, &cross, &beyond);
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

/// For each member of a group, the other members whose pairs move its pair: `(b, P_ab)`, how
/// member `b`'s impulse moves member `a`'s pair (`ClearanceJoint::coupling_to`).
pub(crate) fn cross_mobilities(members: &[&ClearanceJoint]) -> Vec<Vec<(usize, [f64; 144])>> {
    members
        .iter()
        .enumerate()
        .map(|(a, j)| {
            let others = members.iter().enumerate().filter(|(b, _)| *b != a);
            others
                .filter_map(|(b, other)| j.coupling_to(other).map(|p| (b, p)))
                .collect()
        })
        .collect()
}

/// Each member's impulse beyond the Verlet reading of Rapier's velocities around the state,
/// `u_before + w (u_after - u_before)`, `w = h_prev/(h_prev + h)`: `H - w Q kick`, from the
/// impulses `held` at the step's start and the deliveries `deliver` over a step `h` whose
/// kick is `kick` (the state's velocity is this moved through the pair's mobility).
pub(crate) fn beyond_verlet(held: &[Pair12], deliver: &[Pair12], kick: f64, h: f64) -> Vec<Pair12> {
    let w = (2.0 * kick - h) / (2.0 * kick);
    held.iter()
        .zip(deliver)
        .map(|(held, deliver)| {
            let mut b = *held;
            axpy(&mut b, -w, deliver);
            b
        })
        .collect()
}

/// Member `a`'s share of the velocity correction its pair's bodies have from the impulses
/// `beyond` of the group's `members` (`own`: its own impulse moved through its pair's mobility) (`cross`: each member's mobilities from the others'
/// impulses): its own impulse on its pair, and another member's impulse on a body of `a`'s pair
/// only where that body is in neither the other member's pair nor the pair of an earlier member
/// that the impulse moves too. Readers add the corrections of all joints per body
/// ([`ClearanceJoint::start_velocity_correction`]); a body two pairs share (the yoke between a
/// deployable array's root and its next hinge) would otherwise have every impulse's velocity
/// twice: `moved` gives each pair the whole correction of its bodies.
pub(crate) fn attributed(
    a: usize,
    members: &[&ClearanceJoint],
    own: Pair12,
    cross: &[Vec<(usize, [f64; 144])>],
    beyond: &[Pair12],
) -> Pair12 {
    let mut v = own;
    let pair = |m: &ClearanceJoint| [m.body1, m.body2];
    let moves = |e: usize, b: usize| cross[e].iter().any(|(x, _)| *x == b);
    for (b, p) in &cross[a] {
        let from_b = mul(p, &beyond[*b]);
        for (slot, body) in pair(members[a]).into_iter().enumerate() {
            let own = pair(members[*b]).contains(&body);
            let earlier = members[..a]
                .iter()
                .enumerate()
                .any(|(e, m)| e != *b && moves(e, *b) && pair(m).contains(&body));
            if !own && !earlier {
                for q in 6 * slot..6 * slot + 6 {
                    v[q] += from_b[q];
                }
            }
        }
    }
    v
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
pub(super) fn delivery_plan(
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

impl crate::rapier::joint::CycleState {
    /// Takes the step's sub-cycle as the last step's: the impulse left `held`, and what the
    /// step did (its velocity correction, dissipation, impulse and sub-steps), for the readers.
    pub(crate) fn adopt_run(&mut self, held: Pair12) {
        self.held = held;
        self.shift = self.run.shift_next;
        self.start_correction = self.run.start_correction;
        self.end_velocity = Some(self.run.end_velocity);
        self.dissipated = self.run.dissipated;
        self.impulse = self.run.impulse;
        self.substep_count = self.run.substeps;
        std::mem::swap(&mut self.substeps, &mut self.run.samples);
    }
}
