//! The spatial joint's force evaluation: each region's contact history, forces and impact rate,
//! the penetration rates carried to the state by all regions together, and the linearised
//! contact the step control reads.

use super::*;

/// What the regions add up to at one application: wrenches, the linearised contact for the
/// step limits (each region's stiffness, damping and friction slopes through its own effective
/// mass: their sum bounds the stiffest mode, [`step_limits`]), and the dissipated power.
#[derive(Default)]
pub(super) struct Totals {
    pub(super) force: Vector,
    pub(super) normal: Vector,
    pub(super) friction: Vector,
    pub(super) torque: [Vector; 2],
    /// `sum k_r` (the laws' tangent stiffness), `sum k_r/m_r` (with the damping's slope; each
    /// region's own mass: the trace bound), `sum d_r/m_r`, `sum (friction slopes)/m_r`.
    pub(super) stiffness: f64,
    pub(super) stiffness_over_mass: f64,
    /// The loads' own mode (the accelerations `a_r = F_r/m_r` they drive together, coupled
    /// masses): `sum F_r a_r` and `sum k_r a_r^2`, its Rayleigh quotient's denominator and
    /// numerator.
    pub(super) mode_load: f64,
    pub(super) mode_stiffness: f64,
    pub(super) damping_over_mass: f64,
    pub(super) friction_over_mass: f64,
    pub(super) dissipation: f64,
}

/// One region's sums over its points at the final rates.
#[derive(Default)]
pub(super) struct RegionForces {
    pub(super) normal: f64,
    pub(super) law_force: f64,
    pub(super) moment: Vector,
    /// The law's tangent stiffness summed (the contact's own step), and the same with the
    /// damping's change with depth at the point's rate (its stability), N/m.
    pub(super) tangent: f64,
    pub(super) stiffness: f64,
    pub(super) damping: f64,
    pub(super) friction_along: f64,
    pub(super) friction_across: f64,
}

impl ClearanceJoint {
    /// The spatial joint's evaluation (the planar one is [`ClearanceJoint::evaluate`]'s own).
    ///
    /// Region by region: its deepest point moves its contact history; its points' forces take
    /// the region's impact rate (a loaded region's raised to the speed of a free impact of that
    /// region storing its energy, through its mass with every region's load acting), with the
    /// penetration rates carried to the state by all regions together
    /// ([`carried_rates`](Self::carried_rates)).
    pub(in crate::rapier::joint) fn evaluate_spatial(
        &mut self,
        bodies: &RigidBodySet,
        steps: [f64; 2],
        mechanism: &Mechanism,
    ) -> Option<(Wrench, Wrench)> {
        let (rb1, rb2) = (bodies.get(self.body1)?, bodies.get(self.body2)?);
        let (m1, m2) = (motion(rb1), motion(rb2));
        let pair = Pair([Mobility::of(rb1), Mobility::of(rb2)], mechanism);
        let transverse = *rb1.rotation() * self.spatial.as_ref()?.local_transverse1;
        let pose = self.spatial_pose(rb1, rb2, transverse);
        let mut parts = self.spatial.take()?;
        let result = self.evaluate_regions(&mut parts, &pose, [&m1, &m2], &pair, steps);
        self.spatial = Some(parts);
        result
    }

    pub(super) fn evaluate_regions(
        &mut self,
        parts: &mut SpatialParts,
        pose: &SpatialPose,
        motions: [&BodyMotion; 2],
        pair: &Pair,
        steps: [f64; 2],
    ) -> Option<(Wrench, Wrench)> {
        let mut report = SpatialReport {
            tilt: pose.tilt(),
            axial_offset: pose.axial_offset(),
            edge_point: [pose.bearing_center; 2],
            face_point: [pose.bearing_center; 2],
            ..SpatialReport::default()
        };
        let mut totals = Totals::default();
        let mut flight_rate = 0.0_f64;
        parts.points.clear();
        let spatial = parts.model.geometry;
        // First the regions' states, histories, points and loads; their masses take all loads.
        let mut seen: [(JournalState, std::ops::Range<usize>, f64); 4] = Default::default();
        let mut loads: [Option<Load>; 4] = Default::default();
        let mut places = std::mem::take(&mut parts.places);
        places.read(self, &spatial, pose, parts.patches.map(|p| p.region));
        for (k, view) in seen.iter_mut().enumerate() {
            let region = parts.patches[k].region;
            let place = &places.deepest[k];
            let state = place.state(motions);
            flight_rate = flight_rate.max(state.eccentricity_rate.length() / place.gap);
            let start = parts.points.len();
            places.moving(k, motions, &mut parts.points);
            let length = places.lengths[k];
            let law = region.law(&self.normal_law, &parts.face_law);
            let patch = &mut parts.patches[k];
            patch.contact.advance(
                patch.state.as_ref(),
                &state,
                self.min_impact_speed,
                self.min_separation,
            );
            patch.rate_before = patch.state.map_or(f64::NAN, |s| s.penetration_rate);
            patch.moved_before = patch.moved;
            patch.moved = match patch.state {
                Some(before) if steps[1] > 0.0 => {
                    (state.penetration - before.penetration) / steps[1]
                }
                _ => f64::NAN,
            };
            patch.state = Some(state);
            let range = start..parts.points.len();
            loads[k] = Some(Load::of(&parts.points[range.clone()], law, &state, pair));
            *view = (state, range, length);
        }
        parts.places = places;
        let loads = loads.map(|l| l.expect("every region is loaded above"));
        let masses = coupled_masses(&loads, pair);
        for (k, patch) in parts.patches.iter_mut().enumerate() {
            let law = patch.region.law(&self.normal_law, &parts.face_law);
            patch.impact_rate = if patch.contact.in_contact && law.uses_impact_rate() {
                patch
                    .contact
                    .impact_rate
                    .max(loaded_impact_rate(loads[k].energy, masses[k]))
            } else {
                patch.contact.impact_rate
            };
        }
        let carried = self.carried_rates(parts, &seen, &loads, pair, steps);
        // The deepest region: (index, state at its stored rate, impact rate, rate at the state).
        let mut deepest: Option<(usize, JournalState, f64, f64)> = None;
        for (k, (state, range, length)) in seen.into_iter().enumerate() {
            let region = parts.patches[k].region;
            let law = *region.law(&self.normal_law, &parts.face_law);
            let (load, m) = (&loads[k], masses[k]);
            let patch = &mut parts.patches[k];
            let points = &mut parts.points[range];
            let carried = carried[k];
            let forces = apply_region(
                points,
                &law,
                &self.friction_law,
                patch.impact_rate,
                carried,
                [motions[0].center_of_mass, motions[1].center_of_mass],
                &mut totals,
            );
            patch.force = forces.law_force;
            if deepest.is_none_or(|d| state.penetration > d.1.penetration) {
                deepest = Some((
                    k,
                    state,
                    patch.impact_rate,
                    state.penetration_rate + carried,
                ));
            }
            if forces.normal > 0.0 {
                report.add(region, &forces, points.len(), length);
                linearise(&mut totals, &forces, pair, load, m, &state);
            }
        }
        let (index, state, impact_rate, contact_rate) = deepest?;
        let governing = parts.patches[index].region;
        report.governed_by_face = matches!(governing, Region::Face(_));
        report.dissipation_power = totals.dissipation;
        report.bore_contact_width =
            (report.edge_length[0] + report.edge_length[1]) / self.geometry.length();
        let governing_law = governing.law(&self.normal_law, &parts.face_law);
        let m = if totals.mode_stiffness > 0.0 && totals.mode_load > 0.0 {
            // The mass that gives the regions' summed stiffness the frequency of the motion
            // their loads drive together (its Rayleigh quotient `sum k a^2 / sum F a`): the
            // planar joint's mass for an aligned journal, a rocking one for two edges.
            totals.stiffness * totals.mode_load / totals.mode_stiffness
        } else {
            pair.effective_mass(whole_centre(pose, governing, &state), state.normal)
        };
        let whole = governing_law.tangent_stiffness(state.penetration);
        parts.contact_share = if totals.stiffness > 0.0 && whole > 0.0 {
            totals.stiffness / whole
        } else {
            1.0
        };
        parts.flight_rate = flight_rate;
        parts.report = report;

        // The joint's own history follows the deepest point: its gap is the joint's gap.
        let previous = self.prepared_report().then_some(self.report.state);
        let onset = self.contact.advance(
            previous.as_ref(),
            &state,
            self.min_impact_speed,
            self.min_separation,
        );
        let mode = self.contact.mode();
        let (max_stable_dt, omega, zeta, friction_stable_dt) = step_limits(&totals);
        if self.prepared_report() {
            self.previous_rate = Some(self.report.state.penetration_rate);
        }
        self.report = ClearanceReport {
            state,
            mode,
            onset: onset.onset,
            impact: onset.impact,
            impact_rate,
            approach_speed: onset.approach_speed,
            contact_rate,
            onset_fraction: onset.fraction,
            force: ForcePair {
                on_journal: totals.force,
                point: state.contact_point,
                normal_force: totals.normal.length(),
                friction_force: totals.friction.length(),
            },
            max_stable_dt,
            friction_stable_dt,
            omega,
            zeta,
            effective_mass: m,
            spatial: Some(report),
        };
        let w1 = Wrench {
            body: self.body1,
            force: -totals.force,
            torque: totals.torque[0],
        };
        let w2 = Wrench {
            body: self.body2,
            force: totals.force,
            torque: totals.torque[1],
        };
        Some((w1, w2))
    }
}

impl ClearanceJoint {
    /// Each region's penetration rate carried from its stored rate to the state (`v - stored`,
    /// m/s; 0 out of contact, at the start, or after a step of unknown length), all regions
    /// together: the trapezoidal half step of
    /// [`StepBefore::carry`](crate::model::kinematics::StepBefore::carry) with the regions' forces acting
    /// on one another. With `c_pq = R_p . W R_q / (F_p F_q)` (the rate one region's unit load
    /// drives along another's), region `p`'s rest of the acceleration is its measured change of
    /// rate over the kick plus `sum_q c_pq F_q,before` (every region's force over the step that
    /// led here), and `(I + h/2 C D) (v - stored) = h/2 (rest - C F)`, `F` and `D` the regions'
    /// forces and dampings at their stored rates. An aligned journal's two halves then carry the
    /// planar joint's rate; a rocking pair of edges each sees the other's force change with its
    /// own.
    fn carried_rates(
        &self,
        parts: &SpatialParts,
        seen: &[(JournalState, std::ops::Range<usize>, f64); 4],
        loads: &[Load; 4],
        pair: &Pair,
        steps: [f64; 2],
    ) -> [f64; 4] {
        let mut out = [0.0; 4];
        let [before, step] = steps;
        if !(step > 0.0) {
            return out;
        }
        let kick = 0.5 * (before + step);
        // The regions that carry: in contact, with a rate before and a load to act along.
        let active: Vec<usize> = (0..4)
            .filter(|&k| {
                let (state, patch) = (&seen[k].0, &parts.patches[k]);
                state.penetration > 0.0 && patch.rate_before.is_finite() && loads[k].total > 0.0
            })
            .collect();
        let n = active.len();
        if n == 0 {
            return out;
        }
        // Each region's rates, stored and before, from the rate its positions moved at when both
        // steps' are known (the planar joint's `contact_rate`), and that rate's offset from the
        // stored one, which its points' rates take too.
        let rates = |k: usize| {
            let (patch, stored) = (&parts.patches[k], seen[k].0.penetration_rate);
            if patch.moved.is_finite() && patch.moved_before.is_finite() {
                (patch.moved, patch.moved_before, patch.moved - stored)
            } else {
                (stored, patch.rate_before, 0.0)
            }
        };
        let unit = |k: usize| loads[k].row.map(|r| r / loads[k].total);
        let rows: Vec<[f64; 12]> = active.iter().map(|&k| unit(k)).collect();
        let mut force = [0.0; 4];
        let mut damping = [0.0; 4];
        for (a, &k) in active.iter().enumerate() {
            let law = parts.patches[k]
                .region
                .law(&self.normal_law, &parts.face_law);
            let offset = rates(k).2;
            for p in &parts.points[seen[k].1.clone()] {
                let c = NormalContact {
                    penetration: p.contact.depth,
                    penetration_rate: p.penetration_rate + offset,
                    impact_rate: parts.patches[k].impact_rate,
                };
                let (f, d) = crate::model::kinematics::force_and_damping(law, &c);
                force[a] += p.contact.weight * f;
                damping[a] += p.contact.weight * d;
            }
        }
        // The system (I + h/2 C D) x = h/2 (rest - C F), row by row.
        let half = 0.5 * step;
        let mut m = [[0.0; 5]; 4];
        for a in 0..n {
            let k = active[a];
            let (stored, before, _) = rates(k);
            let mut rest = (stored - before) / kick;
            let mut pushed = 0.0;
            for b in 0..n {
                let c = pair.between(&rows[a], &rows[b]);
                rest += c * parts.patches[active[b]].force;
                pushed += c * force[b];
                m[a][b] = half * c * damping[b] + if a == b { 1.0 } else { 0.0 };
            }
            m[a][4] = half * (rest - pushed);
        }
        let solved = solve_small(&mut m, n);
        for (a, &k) in active.iter().enumerate() {
            let x = solved[a];
            out[k] = rates(k).2 + if x.is_finite() { x } else { 0.0 };
        }
        out
    }
}

/// Solves the `n` by `n` system whose augmented rows are `m` (the right-hand side in column 4)
/// by Gaussian elimination with partial pivoting; NaN where it is singular.
fn solve_small(m: &mut [[f64; 5]; 4], n: usize) -> [f64; 4] {
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))
            .unwrap_or(col);
        m.swap(col, pivot);
        let d = m[col][col];
        if d == 0.0 {
            return [f64::NAN; 4];
        }
        let top = m[col];
        for row in m.iter_mut().take(n).skip(col + 1) {
            let f = row[col] / d;
            for (x, t) in row.iter_mut().zip(top).skip(col) {
                *x -= f * t;
            }
        }
    }
    let mut x = [0.0; 4];
    for row in (0..n).rev() {
        let tail: f64 = (row + 1..n).map(|c| m[row][c] * x[c]).sum();
        x[row] = (m[row][4] - tail) / m[row][row];
    }
    x
}

/// The region's points' forces at their rates carried by `carried` (m/s), into `totals`
/// ([`load_point`]), and what the explicit joint's step bounds read of them: the region's
/// stiffness, damping and friction slopes.
fn apply_region(
    points: &mut [SpatialPoint],
    law: &NormalModel,
    friction: &impl FrictionLaw,
    impact_rate: f64,
    carried: f64,
    centres: [Vector; 2],
    totals: &mut Totals,
) -> RegionForces {
    let mut sums = RegionForces::default();
    for p in points.iter_mut() {
        let at = (carried, centres);
        let Some(k) = load_point(p, law, friction, impact_rate, at, true, totals) else {
            continue;
        };
        let c = &k.contact;
        sums.normal += p.normal_force;
        sums.law_force += k.law_force;
        sums.moment += p.normal_force * p.contact.point;
        let tangent = law.tangent_stiffness(c.penetration);
        sums.tangent += k.weight * tangent * k.gradient2;
        sums.stiffness +=
            k.weight * (tangent + law.damping_slope(c) * c.penetration_rate) * k.gradient2;
        sums.damping += k.weight * law.damping_coefficient(c) * k.gradient2;
        let slope = friction_slope(friction, k.speed);
        let across = if k.speed > 0.0 { k.mu / k.speed } else { slope };
        sums.friction_along += p.normal_force * slope.max(0.0);
        sums.friction_across += p.normal_force * across.max(0.0);
    }
    sums
}

/// The region's points' forces into `totals` ([`load_point`]), no more: the sub-cycle's load,
/// evaluated twice per sub-step and twice per coordinate for its Jacobian (without the
/// `dissipation` where only the load is wanted: an accepted state's power needs it).
pub(super) fn load_region(
    points: &mut [SpatialPoint],
    (law, friction): (&NormalModel, &impl FrictionLaw),
    impact_rate: f64,
    centres: [Vector; 2],
    dissipation: bool,
    totals: &mut Totals,
) {
    for p in points.iter_mut() {
        let at = (0.0, centres);
        load_point(p, law, friction, impact_rate, at, dissipation, totals);
    }
}

/// What [`apply_region`]'s sums read of a loaded point besides its forces.
struct LoadedPoint {
    contact: NormalContact,
    /// The law's force times the point's weight, N.
    law_force: f64,
    weight: f64,
    /// The gradient's squared length.
    gradient2: f64,
    speed: f64,
    mu: f64,
}

/// One point's force pair at its rate carried by `carried` (m/s), into `totals` (the bodies'
/// centres of mass at `centres`; the power the damping and friction take when `dissipation`),
/// and its normal and friction forces onto the point: it acts at the surface point along the
/// gradient (the elastic part is the gradient of the region's elastic energy), friction against
/// the slip. `None` where the law pushes nothing.
fn load_point(
    p: &mut SpatialPoint,
    law: &NormalModel,
    friction: &impl FrictionLaw,
    impact_rate: f64,
    (carried, centres): (f64, [Vector; 2]),
    dissipation: bool,
    totals: &mut Totals,
) -> Option<LoadedPoint> {
    let (w, g) = (p.contact.weight, p.contact.gradient);
    let c = NormalContact {
        penetration: p.contact.depth,
        penetration_rate: p.penetration_rate + carried,
        impact_rate,
    };
    p.penetration_rate = c.penetration_rate;
    let f = w * law.normal_force(&c);
    if !(f > 0.0) {
        return None;
    }
    let g2 = g.length_squared();
    let normal = f * g2.sqrt();
    let (slip, speed) = (p.slip, p.slip.length());
    let mu = if speed > 0.0 {
        friction.coefficient(speed)
    } else {
        0.0
    };
    let friction_force = mu * normal;
    let friction_vector = if speed > 0.0 {
        -friction_force / speed * slip
    } else {
        Vector::ZERO
    };
    let on_journal = -f * g + friction_vector;
    totals.force += on_journal;
    totals.normal -= f * g;
    totals.friction += friction_vector;
    totals.torque[1] += (p.contact.point - centres[1]).cross(on_journal);
    totals.torque[0] += (p.contact.point - centres[0]).cross(-on_journal);
    if dissipation {
        let elastic = w * law.elastic_force(p.contact.depth);
        totals.dissipation += (f - elastic) * c.penetration_rate + friction_force * speed;
    }
    p.normal_force = normal;
    p.friction_force = friction_force;
    Some(LoadedPoint {
        contact: c,
        law_force: f,
        weight: w,
        gradient2: g2,
        speed,
        mu,
    })
}

/// Adds a region in contact to the linearised sums, through its effective mass at its load's
/// centre (along its load, and along and across its deepest point's slip for friction).
fn linearise(
    totals: &mut Totals,
    forces: &RegionForces,
    pair: &Pair,
    load: &Load,
    coupled_mass: f64,
    deepest: &JournalState,
) {
    // The region's own inverse mass: its load row's, per unit load.
    let inv_m = if load.total > 0.0 {
        pair.between(&load.row, &load.row) / (load.total * load.total)
    } else {
        pair.inverse_mass(load.centre, load.direction)
    };
    totals.stiffness += forces.tangent;
    totals.stiffness_over_mass += forces.stiffness.max(0.0) * inv_m;
    if load.total > 0.0 {
        let a = load.total / coupled_mass;
        totals.mode_load += load.total * a;
        totals.mode_stiffness += forces.tangent.max(0.0) * a * a;
    }
    totals.damping_over_mass += forces.damping.max(0.0) * inv_m;
    if forces.friction_along > 0.0 || forces.friction_across > 0.0 {
        let t = friction_direction(deepest, load.direction);
        let across = load.direction.cross(t);
        // Along and across the slip are two directions at one point: the larger rate of the
        // two bounds the region's own friction mode.
        totals.friction_over_mass += (forces.friction_along * pair.inverse_mass(load.centre, t))
            .max(forces.friction_across * pair.inverse_mass(load.centre, across));
    }
}

/// The joint's stability and friction limits: `(max_stable_dt, omega, zeta,
/// friction_stable_dt)`. The regions act in parallel on the same two bodies; the sum of each
/// one's `k/m` bounds the squared frequency of the stiffest mode they make together (the trace
/// of `M^-1 K`: a journal on both edges rocks faster than either edge alone), and likewise for
/// their damping and friction's tangential dampers.
fn step_limits(totals: &Totals) -> (f64, f64, f64, f64) {
    let (max_stable_dt, omega, zeta) =
        if totals.stiffness_over_mass > 0.0 || totals.damping_over_mass > 0.0 {
            stable_step(totals.stiffness_over_mass, totals.damping_over_mass, 1.0)
        } else {
            (f64::INFINITY, 0.0, 0.0)
        };
    let friction_stable_dt = if totals.friction_over_mass > 0.0 {
        2.0 / totals.friction_over_mass
    } else {
        f64::INFINITY
    };
    (max_stable_dt, omega, zeta, friction_stable_dt)
}

/// The point where the whole contact would act were it at this region: on the bearing's
/// mid-plane for the bore (where the planar joint's contact sits), on the axis for a face (an
/// axial knock's). Its effective mass is the whole contact's.
fn whole_centre(pose: &SpatialPose, region: Region, state: &JournalState) -> Vector {
    let r = state.contact_point - pose.bearing_center;
    let along = r.dot(pose.bearing_axis) * pose.bearing_axis;
    match region {
        Region::Bore(_) => state.contact_point - along,
        Region::Face(_) => pose.bearing_center + along,
    }
}

/// The slip direction, or a tangent when the point does not slip.
fn friction_direction(state: &JournalState, normal: Vector) -> Vector {
    let v = state.slip.length();
    if v > 0.0 {
        state.slip / v
    } else {
        normal.any_orthonormal_vector()
    }
}
