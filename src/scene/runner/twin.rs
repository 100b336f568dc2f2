//! A twin: its bodies, hinges, joints and drives built from the scene, tracked, and its rows.

mod build;
mod inside;
mod rows;

use super::HingeMetrics;
use super::invariants::{BodyBefore, Invariants};
use crate::error::Result;
use crate::model::angle::{HingeAngle, UnwrappedAngle, twist_angle};
use crate::model::laws::NormalForceLaw;
use crate::rapier::joint::{ClearanceJoint, ClearanceJointHandle, SpatialReport};
use crate::rapier::large_step::{LargeStepJoint, LargeStepJointHandle};
use crate::rapier::observers::metrics::{ContactObservation, ImpactRecorder};
use crate::rapier::observers::reaction::{IdealJoint, ReactionSolver};
use crate::rapier::pipeline::stepper::StepInfo;
use crate::rapier::pipeline::world::ClearanceWorld;
use crate::rapier::sources::drive::DriveHandle;
use crate::table::Table;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;

/// Which hinges a twin models with clearance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TwinKind {
    /// Every hinge is Rapier's ideal revolute joint.
    Ideal,
    /// Hinges with a clearance spec are clearance joints.
    Clearance,
}

impl TwinKind {
    /// `"ideal"` or `"clearance"`.
    pub fn name(self) -> &'static str {
        match self {
            TwinKind::Ideal => "ideal",
            TwinKind::Clearance => "clearance",
        }
    }
}

#[derive(Clone, Debug)]
pub(super) struct BodyTrack {
    pub(super) name: String,
    pub(super) handle: RigidBodyHandle,
    mass: f64,
    /// Fixed or driven by a prescribed motion: outside the energy and momentum balances.
    fixed: bool,
    /// Not a fixed body (driven bodies move).
    moves: bool,
    /// The body's tabulated motion (index in the world's prescribed set).
    table: Option<usize>,
    /// The centre of mass in the body's frame (not the origin for a spinning body), m.
    local_com: Vector,
    angle: UnwrappedAngle,
    linvel_before: Vector,
    /// Angular velocity, centre of mass and rotation at the state before the current step.
    angvel_before: Vector,
    com_before: Vector,
    rotation_before: rapier3d_f64::math::Rotation,
}

/// How a twin models one of its hinges, with the joint's handle in the world's set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HingeJoint {
    /// Rapier's ideal revolute joint (in the world's impulse joints).
    Ideal,
    /// A compliant clearance joint, in the world's [`ClearanceWorld::clearance`] set.
    Clearance(ClearanceJointHandle),
    /// A clearance hinge of the large-step model (`clearance.model: LargeStep`), in the world's
    /// [`ClearanceWorld::large_step`] set.
    LargeStep(LargeStepJointHandle),
}

#[derive(Clone, Debug)]
pub(super) struct HingeTrack {
    pub(super) name: String,
    joint: HingeJoint,
    bearing: usize,
    journal: usize,
    /// The hinge's point in the bearing body's frame, m.
    local_anchor1: Vector,
    local_axis1: Vector,
    local_u1: Vector,
    local_v1: Vector,
    pub(super) angle: HingeAngle,
    /// Force magnitude at the state before the current step (the clearance hook's force, or the
    /// ideal reaction once the step determined it), N.
    pub(super) force: f64,
    /// The clearance contact at the state before the current step.
    sample: ContactSample,
    /// The scene's hinge is spatial: its rows carry the tilt, axial offset and forces by
    /// contact kind (zero in the ideal twin).
    spatial: bool,
    /// A spatial joint at the state before the current step: its report, the wrenches it
    /// applies over the step and its elastic energy, J.
    spatial_sample: Option<SpatialSample>,
    pub(super) recorder: ImpactRecorder,
}

/// A spatial joint at the state before a step.
#[derive(Clone, Copy, Debug)]
struct SpatialSample {
    report: SpatialReport,
}

impl HingeTrack {
    /// Records the final state at time `t` into the recorder and completes its figures.
    pub(super) fn finish_recording(&mut self, t: f64) {
        if let Some(s) = &self.spatial_sample {
            self.recorder.record_spatial(0.0, &s.report);
        }
        let obs = self.observation();
        self.recorder.finish(t, &obs);
        self.recorder
            .set_final_angle_deg(self.angle.value().to_degrees());
    }

    /// The state before the current step, for the recorder.
    pub(super) fn observation(&self) -> ContactObservation {
        match self.joint {
            HingeJoint::Ideal => ContactObservation::ideal(self.force),
            HingeJoint::Clearance(_) | HingeJoint::LargeStep(_) => ContactObservation {
                force: self.force,
                onset: self.sample.onset,
                impact: self.sample.impact,
                penetration: self.sample.penetration,
                rate: self.sample.rate,
                approach_speed: self.sample.approach_speed,
                onset_fraction: self.sample.onset_fraction,
            },
        }
    }
}

/// A compliant hinge's contact at its last evaluation (the state before the step).
fn compliant_sample(j: &ClearanceJoint) -> ContactSample {
    let r = j.report();
    let f = &r.force;
    let elastic = j.normal_law().elastic_force(r.state.penetration);
    ContactSample {
        onset: r.onset,
        impact: r.impact,
        penetration: r.state.penetration,
        rate: r.state.penetration_rate,
        approach_speed: r.approach_speed,
        onset_fraction: r.onset_fraction,
        damping_force: if f.normal_force > 0.0 {
            f.normal_force - elastic
        } else {
            0.0
        },
        friction_force: f.friction_force,
    }
}

/// A large-step hinge's last step as a contact sample: the constraint model has no
/// penetration, so the sample's is the journal's excursion beyond the clearance circle,
/// `|e| - c` (negative: the gap; at least the smallest positive number while the constraint
/// is in contact, so that the recorder counts the contact).
fn large_step_sample(j: &LargeStepJoint) -> ContactSample {
    let r = j.report();
    let excursion = r.eccentricity.length() - j.clearance();
    ContactSample {
        onset: r.onset,
        // The model's impacts are its bounces (see the metrics' definitions).
        impact: r.bounce,
        penetration: if r.contact {
            excursion.max(f64::MIN_POSITIVE)
        } else {
            excursion.min(0.0)
        },
        rate: if r.onset { r.approach_speed } else { 0.0 },
        approach_speed: r.approach_speed,
        onset_fraction: 1.0,
        damping_force: 0.0,
        friction_force: 0.0,
    }
}

/// The columns a spatial hinge adds to its rows (after `contact`): the journal's tilt about the
/// `ecc_u`/`ecc_v` axes, its axial offset, the normal force of each contact kind, and where each
/// edge region's resultant acts along the axis.
pub(super) const SPATIAL_COLUMNS: [&str; 10] = [
    "tilt_u_deg",
    "tilt_v_deg",
    "axial_mm",
    "bore_force_n",
    "edge_lower_force_n",
    "edge_upper_force_n",
    "face_lower_force_n",
    "face_upper_force_n",
    "edge_lower_at_mm",
    "edge_upper_at_mm",
];

/// What a clearance hinge's hook saw at one state (read before the step it drives).
#[derive(Clone, Copy, Debug, Default)]
struct ContactSample {
    onset: bool,
    impact: bool,
    penetration: f64,
    /// Penetration rate, m/s (positive approaching).
    rate: f64,
    /// At an onset: the approach speed at the crossing, m/s, and where in the step it was.
    approach_speed: f64,
    onset_fraction: f64,
    /// The damping part of the normal force (total minus elastic), N.
    damping_force: f64,
    /// Friction force magnitude, N.
    friction_force: f64,
}

/// One twin: its bodies, joints, drives and records.
#[derive(Debug)]
pub struct Twin {
    /// Ideal or clearance.
    pub kind: TwinKind,
    pub(super) bodies: Vec<BodyTrack>,
    pub(super) hinges: Vec<HingeTrack>,
    /// This twin's drives in the world's drive set.
    drives: Vec<DriveHandle>,
    /// The ideal joints: the ideal hinges' revolutes (with the hinge index of each), then the
    /// scene's other joints.
    ideal_joints: Vec<IdealJoint>,
    ideal_hinges: Vec<usize>,
    /// The scene's other joints: name and force on body 2 at the current state, N.
    joints: Vec<(String, f64)>,
    /// Per scene joint: its motor's torque (N m) or force (N) at the current state, `None`
    /// for a joint without motor (no column).
    motors: Vec<Option<f64>>,
    body_motion: bool,
    reactions: ReactionSolver,
    /// Spring and contact elastic energy at the state before the current step, J.
    source_energy_before: f64,
    /// The joint motors in Rapier, with the index of their scene joint: their impulses over each
    /// step give their work.
    motor_joints: Vec<(ImpulseJointHandle, JointAxis, usize)>,
    /// The velocity motors (reported as holding their speed): motor index, target, joint name,
    /// unit of the target.
    held_motors: Vec<(usize, f64, String, &'static str)>,
    pub(super) reference_axis: Vector,
    /// Output rows.
    pub table: Table,
    /// Row values at the previous and the current state.
    row_prev: Vec<f64>,
    row_cur: Vec<f64>,
    /// Columns holding a contact flag (taken from the nearer state, not interpolated).
    contact_columns: Vec<usize>,
    /// What the rows inside a sub-cycled step read from its sub-steps.
    inside: inside::InsideRows,
    /// Rows are kept (the last state read said so): the steps' sub-steps are then recorded.
    rows: bool,
    /// Invariants and energy over every step.
    pub invariants: Invariants,
}

impl Twin {
    /// Reads the state before a step (from the sources' evaluation at it): invariants, the
    /// clearance samples and forces, the angles, and (with `rows`) the row values of the state.
    pub(super) fn before_step(&mut self, world: &mut ClearanceWorld, rows: bool) -> Result<()> {
        let t = world.time();
        let bodies = &world.rapier.bodies;
        let axis_ref = self.reference_axis;
        for b in &mut self.bodies {
            let rb = &bodies[b.handle];
            b.linvel_before = rb.linvel();
            b.angvel_before = rb.angvel();
            b.com_before = crate::rapier::pipeline::ledger::world_center_of_mass(rb);
            b.rotation_before = *rb.rotation();
            // Bodies start unrotated: the body's rotation is its rotation since t = 0.
            b.angle.update(twist_angle(rb.rotation(), axis_ref));
        }
        for h in &mut self.hinges {
            let (r1, r2) = (
                &bodies[self.bodies[h.bearing].handle],
                &bodies[self.bodies[h.journal].handle],
            );
            // Every state, so the unwrapped angle never aliases whatever the output interval.
            h.angle.update(r1.rotation(), r2.rotation(), h.local_axis1);
            match h.joint {
                HingeJoint::Clearance(c) => {
                    let j = world.clearance.get(c).expect("handle of this twin");
                    h.force = j.report().force.on_journal.length();
                    h.sample = compliant_sample(j);
                    h.spatial_sample = j.report().spatial.map(|report| SpatialSample { report });
                }
                HingeJoint::LargeStep(k) => {
                    let j = world.large_step.get(k).expect("handle of this twin");
                    h.force = j.report().normal_force;
                    h.sample = large_step_sample(j);
                }
                HingeJoint::Ideal => {}
            }
        }
        self.solve_ideal_reactions(world)?;
        self.source_energy_before = self.source_energy(world);
        self.rows = rows;
        if rows {
            std::mem::swap(&mut self.row_prev, &mut self.row_cur);
            self.fill_row(t, world);
            self.inside.advance();
        }
        Ok(())
    }

    /// Completes the step that started from the state [`before_step`](Self::before_step) read:
    /// ideal reactions (which only the step determines), metrics of that state over the step.
    pub(super) fn after_step(&mut self, world: &ClearanceWorld, info: &StepInfo) {
        let joints = &world.rapier.impulse_joints;
        self.update_force_metrics(world, info.t0, info.dt);
        if self.rows {
            self.record_inside(world, (info.t0, info.dt));
        }
        self.update_invariants(world, info);
        // The motors' work over the step: the angular or linear impulse Rapier's motor row
        // applied to body 2 (minus its stored impulse) times the joint's speed at the state the
        // step started from (the solve's synchronous one), what a kick does to kinetic energy.
        let n = self.ideal_hinges.len();
        for &(h, axis, k) in &self.motor_joints {
            if let (Some(j), Some(rate)) = (joints.get(h), self.reactions.motor_rate(n + k)) {
                self.invariants.motor_work_j -= j.data.motors[axis as usize].impulse * rate;
            }
        }
        // How far the velocity motors hold their speed, at the state the step started from.
        for (k, target, name, unit) in &self.held_motors {
            if let Some(rate) = self.reactions.motor_rate(n + k) {
                let miss = (rate - target).abs();
                let e = miss / target.abs().max(1e-3);
                let inv = &mut self.invariants;
                if e > super::MOTOR_SPEED_ERROR_LIMIT {
                    inv.motor_speed_violations += 1;
                    inv.motor_speed_first_violation_at.get_or_insert(info.t0);
                }
                if info.t0 == 0.0
                    && e > super::MOTOR_SPEED_ERROR_LIMIT
                    && inv.motor_start_mismatch.is_none()
                {
                    inv.motor_start_mismatch = Some((name.clone(), rate, *target, unit));
                }
                if inv.motor_speed_error.is_none_or(|w| e > w) {
                    inv.motor_speed_error = Some(e);
                    inv.motor_speed_error_at = Some((name.clone(), info.t0));
                    inv.motor_speed_miss = Some((miss, *target, unit));
                }
            }
        }
        // Work of the step's damping and friction forces over the step's motion: the
        // penetration change, and the slip at the step's velocity.
        for h in &self.hinges {
            if let HingeJoint::Clearance(c) = h.joint {
                let j = world.clearance.get(c).expect("handle of this twin");
                if let Some(loss) = j.step_dissipation() {
                    // Sub-cycled, planar or spatial: integrated over the sub-steps (the power
                    // at the step's start held over a step that spans the contact's motion is
                    // not the work the sub-steps' forces did).
                    self.invariants.dissipated_j += loss;
                    continue;
                }
                if let Some(s) = &h.spatial_sample {
                    // The power of every contact point's damping and friction at the state
                    // before the step, as the planar joint's force at that state.
                    self.invariants.dissipated_j += s.report.dissipation_power * info.dt;
                    continue;
                }
                let r = j.report();
                let sample = &h.sample;
                if sample.penetration > 0.0 {
                    self.invariants.dissipated_j += sample.damping_force
                        * (r.state.penetration - sample.penetration)
                        + sample.friction_force * r.state.slip.length() * info.dt;
                }
            }
        }
    }

    /// Ideal-joint reactions, motor torques and the bodies' velocities and accelerations at the
    /// current state, exact: the constrained rigid-body equations solved for the joint forces
    /// ([`ClearanceWorld::solve_reactions`]), whatever the step control.
    /// A solve that fails (a non-finite state) is an error: never reactions left at zero.
    fn solve_ideal_reactions(&mut self, world: &mut ClearanceWorld) -> Result<()> {
        if self.ideal_joints.is_empty() && !self.body_motion {
            return Ok(());
        }
        let t = world.time();
        let Some(forces) = world.solve_reactions(&mut self.reactions, &self.ideal_joints) else {
            return Err(crate::Error::diverged(
                t,
                crate::error::Divergence::Reactions {
                    twin: Some(self.kind.name().to_string()),
                },
            ));
        };
        {
            let n = self.ideal_hinges.len();
            for (&hi, f) in self.ideal_hinges.iter().zip(forces) {
                self.hinges[hi].force = f.length();
            }
            for (j, f) in self.joints.iter_mut().zip(&forces[n..]) {
                j.1 = f.length();
            }
            for (k, m) in self.motors.iter_mut().enumerate() {
                if let Some(m) = m {
                    *m = self.reactions.motor(n + k).unwrap_or(0.0);
                }
            }
        }
        Ok(())
    }

    /// The elastic energy of this twin's drives and clearance contacts at the current state, J.
    fn source_energy(&self, world: &ClearanceWorld) -> f64 {
        let drives: f64 = self
            .drives
            .iter()
            .filter_map(|&d| world.drives.get(d))
            .map(|d| d.potential_energy(d.angle()))
            .sum();
        let contacts: f64 = self
            .hinges
            .iter()
            .filter_map(|h| match h.joint {
                HingeJoint::Clearance(c) => world.clearance.get(c),
                // The constraint model stores no elastic energy.
                HingeJoint::Ideal | HingeJoint::LargeStep(_) => None,
            })
            .map(|j| j.elastic_energy())
            .sum();
        drives + contacts
    }

    /// The invariants at the state before the step just taken, from this twin's moving bodies
    /// and its sources' elastic energy there.
    fn update_invariants(&mut self, world: &ClearanceWorld, info: &StepInfo) {
        let bodies = &world.rapier.bodies;
        let beyond = |body: RigidBodyHandle| {
            world
                .clearance
                .iter()
                .flat_map(|(_, j)| j.start_velocity_correction())
                .filter(|c| c.0 == body)
                .fold((Vector::ZERO, Vector::ZERO), |(v, w), c| (v + c.1, w + c.2))
        };
        let moving = self.bodies.iter().filter(|b| !b.fixed).map(|b| BodyBefore {
            mass: b.mass,
            com: b.com_before,
            rotation: b.rotation_before,
            linvel: b.linvel_before,
            angvel: b.angvel_before,
            after: &bodies[b.handle],
            beyond: beyond(b.handle),
        });
        self.invariants.update(
            moving,
            self.source_energy_before,
            world.rapier.gravity,
            info,
        );
    }

    /// Metrics of the state before the step (its sample and force), weighted by the step.
    /// A sub-cycled joint's states inside the step are recorded too.
    fn update_force_metrics(&mut self, world: &ClearanceWorld, t: f64, dt: f64) {
        for h in &mut self.hinges {
            let obs = h.observation();
            let substeps = match h.joint {
                HingeJoint::Clearance(c) => {
                    world.clearance.get(c).map_or(&[][..], |j| j.substeps())
                }
                HingeJoint::Ideal | HingeJoint::LargeStep(_) => &[],
            };
            h.recorder.record_step(t, dt, &obs, substeps);
            if let Some(s) = &h.spatial_sample {
                h.recorder.record_spatial(dt, &s.report);
            }
        }
    }

    /// Per-hinge metrics by hinge name.
    pub fn hinge_metrics(&self) -> BTreeMap<String, HingeMetrics> {
        self.hinges
            .iter()
            .map(|h| (h.name.clone(), h.recorder.metrics().clone()))
            .collect()
    }

    /// The impact recorder of every hinge, by hinge name (ideal hinges record no impacts).
    pub fn hinge_recorders(&self) -> BTreeMap<String, &ImpactRecorder> {
        self.hinges
            .iter()
            .map(|h| (h.name.clone(), &h.recorder))
            .collect()
    }

    /// Names of the hinges that are clearance joints in this twin, in scene order.
    pub fn clearance_hinges(&self) -> Vec<&str> {
        self.hinges
            .iter()
            .filter(|h| matches!(h.joint, HingeJoint::Clearance(_) | HingeJoint::LargeStep(_)))
            .map(|h| h.name.as_str())
            .collect()
    }

    /// Final angles (deg) of every body and hinge, by name.
    pub fn final_angles_deg(&self) -> BTreeMap<String, f64> {
        let mut m = BTreeMap::new();
        for b in &self.bodies {
            m.insert(b.name.clone(), b.angle.value().to_degrees());
        }
        for h in &self.hinges {
            m.insert(h.name.clone(), h.angle.value().to_degrees());
        }
        m
    }
}

impl Twin {
    /// This twin's bodies, in scene order: each one's name and its handle in the world's
    /// bodies.
    pub fn bodies(&self) -> impl Iterator<Item = (&str, RigidBodyHandle)> {
        self.bodies.iter().map(|b| (b.name.as_str(), b.handle))
    }

    /// This twin's hinges, in scene order: what each one is in the world (see [`TwinHinge`]).
    pub fn hinges(&self) -> impl Iterator<Item = TwinHinge<'_>> {
        self.hinges.iter().map(|h| TwinHinge {
            name: &h.name,
            bearing: self.bodies[h.bearing].handle,
            journal: self.bodies[h.journal].handle,
            joint: h.joint,
            local_anchor1: h.local_anchor1,
            local_axis1: h.local_axis1,
        })
    }
}

/// One hinge of a [`Twin`], read from [`Twin::hinges`]: enough to find it in the world and to
/// draw it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwinHinge<'a> {
    /// The scene's name of the hinge.
    pub name: &'a str,
    /// The body carrying the bearing.
    pub bearing: RigidBodyHandle,
    /// The body carrying the journal.
    pub journal: RigidBodyHandle,
    /// Ideal or clearance, with the joint's handle.
    pub joint: HingeJoint,
    /// The hinge's point in the bearing body's frame, m.
    pub local_anchor1: Vector,
    /// The hinge's axis in the bearing body's frame (unit).
    pub local_axis1: Vector,
}
