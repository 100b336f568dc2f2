//! A twin: its bodies, hinges, joints and drives built from the scene, tracked, and its rows.

use super::HingeMetrics;
use super::invariants::Invariants;
use crate::error::Result;
use crate::model::angle::{HingeAngle, UnwrappedAngle, twist_angle};
use crate::model::laws::NormalForceLaw;
use crate::rapier::drive::{DriveHandle, TorsionSpring};
use crate::rapier::joint::{ClearanceJointBuilder, ClearanceJointHandle};
use crate::rapier::metrics::{ContactObservation, ImpactRecorder};
use crate::rapier::prescribed::{PrescribedMotion, PrescribedPath, Table as MotionTable};
use crate::rapier::reaction::{
    IdealFixed, IdealJoint, IdealPrismatic, IdealRevolute, IdealSpherical, ReactionSolver,
    SoftMotor,
};
use crate::rapier::replay::{ReplayRecorder, in_plane_u};
use crate::rapier::stepper::StepInfo;
use crate::rapier::world::ClearanceWorld;
use crate::scene::{JointKindSpec, MotionSpec, MotorSpec, Scene};
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
    pub(super) mass: f64,
    /// Fixed or driven by a prescribed motion: outside the energy and momentum balances.
    pub(super) fixed: bool,
    /// Not a fixed body (driven bodies move).
    moves: bool,
    /// The body's tabulated motion (index in the world's prescribed set).
    table: Option<usize>,
    /// The centre of mass in the body's frame (not the origin for a spinning body), m.
    local_com: Vector,
    angle: UnwrappedAngle,
    pub(super) linvel_before: Vector,
    /// Angular velocity, centre of mass and rotation at the state before the current step.
    pub(super) angvel_before: Vector,
    pub(super) com_before: Vector,
    pub(super) rotation_before: rapier3d_f64::math::Rotation,
}

#[derive(Clone, Copy, Debug)]
enum HingeJoint {
    Ideal,
    Clearance(ClearanceJointHandle),
}

#[derive(Clone, Debug)]
pub(super) struct HingeTrack {
    pub(super) name: String,
    joint: HingeJoint,
    bearing: usize,
    journal: usize,
    local_axis1: Vector,
    local_u1: Vector,
    local_v1: Vector,
    pub(super) angle: HingeAngle,
    /// Force magnitude at the state before the current step (the clearance hook's force, or the
    /// ideal reaction once the step determined it), N.
    pub(super) force: f64,
    /// The clearance contact at the state before the current step.
    sample: ContactSample,
    pub(super) recorder: ImpactRecorder,
}

impl HingeTrack {
    /// The state before the current step, for the recorder.
    pub(super) fn observation(&self) -> ContactObservation {
        match self.joint {
            HingeJoint::Ideal => ContactObservation::ideal(self.force),
            HingeJoint::Clearance(_) => ContactObservation {
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
    pub(super) source_energy_before: f64,
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
    /// Invariants and energy over every step.
    pub invariants: Invariants,
}

impl Twin {
    pub(super) fn build(scene: &Scene, kind: TwinKind, world: &mut ClearanceWorld) -> Result<Twin> {
        let mut bodies = Vec::new();
        let prescribed = &mut world.prescribed;
        for (i, b) in scene.bodies.iter().enumerate() {
            let com = Vector::from(b.center_of_mass_m);
            let origin = Vector::from(scene.body_origin(i));
            let mut table = None;
            let rb = match &b.motion {
                // A tabulated drive: a position-based kinematic body whose next pose the
                // prescribed set gives before each step.
                Some(m @ (MotionSpec::TableAngle { .. } | MotionSpec::TablePosition { .. })) => {
                    let (path, t, v) = match m {
                        MotionSpec::TableAngle {
                            axis,
                            t_s,
                            angle_rad,
                            ..
                        } => (
                            PrescribedPath::Angle {
                                axis: Vector::from(*axis).normalize(),
                            },
                            t_s,
                            angle_rad,
                        ),
                        MotionSpec::TablePosition {
                            direction,
                            t_s,
                            position_m,
                        } => (
                            PrescribedPath::Position {
                                direction: Vector::from(*direction).normalize(),
                            },
                            t_s,
                            position_m,
                        ),
                        _ => unreachable!("matched above"),
                    };
                    let rb = RigidBodyBuilder::kinematic_position_based()
                        .translation(origin)
                        .can_sleep(false)
                        .build();
                    let start = *rb.position();
                    table = Some(prescribed.motions.len());
                    prescribed.motions.push(PrescribedMotion {
                        body: RigidBodyHandle::invalid(),
                        start,
                        path,
                        table: MotionTable::new(t, v)
                            .map_err(|e| e.within(&format!("bodies[{}].motion", b.name)))?,
                    });
                    rb
                }
                // A driven body: no mass properties, so Rapier turns it about its frame origin.
                Some(m) => {
                    let (v, w) = match m {
                        MotionSpec::Spin {
                            axis, rate_rad_s, ..
                        } => (Vector::ZERO, Vector::from(*axis).normalize() * *rate_rad_s),
                        MotionSpec::Translate { velocity_m_s } => {
                            (Vector::from(*velocity_m_s), Vector::ZERO)
                        }
                        _ => unreachable!("tables are matched above"),
                    };
                    RigidBodyBuilder::kinematic_velocity_based()
                        .translation(origin)
                        .linvel(v)
                        .angvel(w)
                        .can_sleep(false)
                        .build()
                }
                None => {
                    let builder = if b.fixed {
                        RigidBodyBuilder::fixed()
                    } else {
                        RigidBodyBuilder::dynamic()
                            .linvel(Vector::from(b.velocity_m_s))
                            .angvel(Vector::from(b.angular_velocity_rad_s))
                    };
                    builder
                        .translation(com)
                        .additional_mass_properties(MassProperties::new(
                            Vector::ZERO,
                            b.mass_kg,
                            Vector::from(b.inertia_kg_m2),
                        ))
                        .can_sleep(false)
                        .build()
                }
            };
            let handle = world.rapier.bodies.insert(rb);
            if let Some(k) = table {
                prescribed.motions[k].body = handle;
            }
            bodies.push(BodyTrack {
                table,
                name: b.name.clone(),
                handle,
                mass: b.mass_kg,
                fixed: b.fixed || b.motion.is_some(),
                moves: !b.fixed,
                local_com: com - origin,
                angle: UnwrappedAngle::default(),
                linvel_before: Vector::ZERO,
                angvel_before: Vector::ZERO,
                com_before: com,
                rotation_before: rapier3d_f64::math::Rotation::IDENTITY,
            });
        }
        let mut hinges = Vec::new();
        for h in &scene.hinges {
            let (ib, ij) = (
                scene.body_index(&h.bearing).unwrap(),
                scene.body_index(&h.journal).unwrap(),
            );
            let point = Vector::from(h.point_m);
            let axis = Vector::from(h.axis).normalize();
            // Bodies start unrotated with their frame at their origin (the centre of mass, or
            // a spinning body's axis point).
            let a1 = point - Vector::from(scene.body_origin(ib));
            let a2 = point - Vector::from(scene.body_origin(ij));
            let (b1, b2) = (bodies[ib].handle, bodies[ij].handle);
            let joint = match (&h.clearance, kind) {
                (Some(spec), TwinKind::Clearance) => {
                    let p = spec
                        .build()
                        .map_err(|e| e.within(&format!("hinges[{}].clearance", h.name)))?;
                    let mut b = ClearanceJointBuilder::new(axis, p.geometry, p.normal)
                        .local_anchor1(a1)
                        .local_anchor2(a2)
                        .friction(p.friction)
                        .min_impact_speed(p.min_impact_speed)
                        .min_separation(p.min_separation)
                        .lock(spec.lock)
                        .name(h.name.clone());
                    if let Some(depth) = p.max_valid_penetration {
                        b = b.max_valid_penetration(depth);
                    }
                    let j = b.build()?;
                    HingeJoint::Clearance(world.clearance.insert(
                        b1,
                        b2,
                        j,
                        &mut world.rapier.impulse_joints,
                    ))
                }
                _ => {
                    let j = RevoluteJointBuilder::new(axis)
                        .local_anchor1(a1)
                        .local_anchor2(a2)
                        .contacts_enabled(false);
                    {
                        world.rapier.impulse_joints.insert(b1, b2, j, true);
                        HingeJoint::Ideal
                    }
                }
            };
            let u = in_plane_u(axis);
            hinges.push(HingeTrack {
                name: h.name.clone(),
                joint,
                bearing: ib,
                journal: ij,
                local_axis1: axis,
                local_u1: u,
                local_v1: axis.cross(u),
                angle: HingeAngle::default(),
                force: 0.0,
                sample: ContactSample::default(),
                recorder: ImpactRecorder::new(),
            });
        }
        let mut drives = Vec::new();
        for d in &scene.drives {
            let hi = scene.hinge_index(&d.hinge).unwrap();
            let h = &hinges[hi];
            let per_rad = d.stiffness_nm_per_deg.to_degrees();
            let spring = TorsionSpring::new(
                bodies[h.bearing].handle,
                bodies[h.journal].handle,
                h.local_axis1,
                d.torque_scale * d.torque0_nm,
                d.torque_scale * per_rad,
            )
            .map_err(|e| e.within(&format!("drives[{}]", d.name)))?;
            drives.push(world.drives.insert(spring));
        }
        let (mut ideal_joints, mut ideal_hinges) = (Vec::new(), Vec::new());
        for (i, h) in hinges.iter().enumerate() {
            if let HingeJoint::Ideal = h.joint {
                let hs = &scene.hinges[i];
                let point = Vector::from(hs.point_m);
                let com = |k: usize| Vector::from(scene.body_origin(k));
                ideal_joints.push(IdealJoint::Revolute(IdealRevolute {
                    body1: bodies[h.bearing].handle,
                    body2: bodies[h.journal].handle,
                    local_anchor1: point - com(h.bearing),
                    local_anchor2: point - com(h.journal),
                    local_axis1: h.local_axis1,
                }));
                ideal_hinges.push(i);
            }
        }
        let (mut joints, mut motors, mut motor_columns) = (Vec::new(), Vec::new(), Vec::new());
        let mut motor_joints = Vec::new();
        let mut held_motors = Vec::new();
        for (k, j) in scene.joints.iter().enumerate() {
            if let Some(Motor::Held { target, .. }) = motor_of(j.motor.as_ref()) {
                let unit = match j.motor {
                    Some(MotorSpec::LinearVelocity { .. }) => "m/s",
                    _ => "rad/s",
                };
                held_motors.push((k, target, j.name.clone(), unit));
            }
            let (i1, i2) = (
                scene.body_index(&j.body1).unwrap(),
                scene.body_index(&j.body2).unwrap(),
            );
            let point = Vector::from(j.point_m);
            let a1 = point - Vector::from(scene.body_origin(i1));
            let a2 = point - Vector::from(scene.body_origin(i2));
            let (b1, b2) = (bodies[i1].handle, bodies[i2].handle);
            let ideal = match &j.kind {
                JointKindSpec::Prismatic { axis, limits_m } => {
                    let axis = Vector::from(*axis).normalize();
                    let mut rj = PrismaticJointBuilder::new(axis)
                        .local_anchor1(a1)
                        .local_anchor2(a2)
                        .contacts_enabled(false);
                    if let Some(l) = limits_m {
                        rj = rj.limits(*l);
                    }
                    let ideal = IdealPrismatic {
                        body1: b1,
                        body2: b2,
                        local_anchor1: a1,
                        local_anchor2: a2,
                        local_axis1: axis,
                    };
                    // Validated: only linear motors on a prismatic joint.
                    let ideal = match motor_of(j.motor.as_ref()) {
                        Some(Motor::Held { target, factor }) => {
                            rj = rj.motor_velocity(target, factor);
                            IdealJoint::MotorPrismatic(ideal)
                        }
                        Some(Motor::Soft(m)) => {
                            rj = rj
                                .set_motor(m.target_pos, m.target_vel, m.stiffness, m.damping)
                                .motor_model(MotorModel::ForceBased);
                            IdealJoint::SoftMotorPrismatic(ideal, m)
                        }
                        None => IdealJoint::Prismatic(ideal),
                    };
                    let h = world.rapier.impulse_joints.insert(b1, b2, rj, true);
                    if j.motor.is_some() {
                        motor_joints.push((h, JointAxis::LinX, k));
                    }
                    ideal
                }
                JointKindSpec::Revolute { axis } => {
                    let axis = Vector::from(*axis).normalize();
                    let mut rj = RevoluteJointBuilder::new(axis)
                        .local_anchor1(a1)
                        .local_anchor2(a2)
                        .contacts_enabled(false);
                    let ideal = IdealRevolute {
                        body1: b1,
                        body2: b2,
                        local_anchor1: a1,
                        local_anchor2: a2,
                        local_axis1: axis,
                    };
                    // Validated: only angular motors on a revolute joint.
                    let ideal = match motor_of(j.motor.as_ref()) {
                        Some(Motor::Held { target, factor }) => {
                            rj = rj.motor_velocity(target, factor);
                            IdealJoint::MotorRevolute(ideal)
                        }
                        Some(Motor::Soft(m)) => {
                            rj = rj
                                .motor(m.target_pos, m.target_vel, m.stiffness, m.damping)
                                .motor_model(MotorModel::ForceBased);
                            IdealJoint::SoftMotorRevolute(ideal, m)
                        }
                        None => IdealJoint::Revolute(ideal),
                    };
                    let h = world.rapier.impulse_joints.insert(b1, b2, rj, true);
                    if j.motor.is_some() {
                        motor_joints.push((h, JointAxis::AngX, k));
                    }
                    ideal
                }
                JointKindSpec::Fixed => {
                    let rj = FixedJointBuilder::new()
                        .local_anchor1(a1)
                        .local_anchor2(a2)
                        .contacts_enabled(false);
                    world.rapier.impulse_joints.insert(b1, b2, rj, true);
                    IdealJoint::Fixed(IdealFixed {
                        body1: b1,
                        body2: b2,
                        local_anchor1: a1,
                        local_anchor2: a2,
                    })
                }
                JointKindSpec::Spherical => {
                    let rj = SphericalJointBuilder::new()
                        .local_anchor1(a1)
                        .local_anchor2(a2)
                        .contacts_enabled(false);
                    world.rapier.impulse_joints.insert(b1, b2, rj, true);
                    IdealJoint::Spherical(IdealSpherical {
                        body1: b1,
                        body2: b2,
                        local_anchor1: a1,
                        local_anchor2: a2,
                    })
                }
            };
            ideal_joints.push(ideal);
            joints.push((j.name.clone(), 0.0));
            motors.push(j.motor.as_ref().map(|_| 0.0));
            if j.motor.is_some() {
                let unit = match j.kind {
                    JointKindSpec::Prismatic { .. } => "n",
                    _ => "nm",
                };
                motor_columns.push(format!("{}_motor_{unit}", j.name));
            }
        }
        let mut columns = vec!["t_s".to_string()];
        for b in &bodies {
            columns.push(format!("{}_angle_deg", b.name));
            columns.push(format!("{}_rate_deg_s", b.name));
        }
        let body_motion = scene.run.body_motion;
        if body_motion {
            for b in bodies.iter().filter(|b| b.moves) {
                for c in [
                    "x_m", "y_m", "z_m", "vx_m_s", "vy_m_s", "vz_m_s", "ax_m_s2", "ay_m_s2",
                    "az_m_s2",
                ] {
                    columns.push(format!("{}_{c}", b.name));
                }
            }
        }

        for h in &hinges {
            for c in [
                "angle_deg",
                "rate_deg_s",
                "force_n",
                "ecc_u_mm",
                "ecc_v_mm",
                "penetration_um",
                "contact",
            ] {
                columns.push(format!("{}_{c}", h.name));
            }
        }
        for (name, _) in &joints {
            columns.push(format!("{name}_force_n"));
        }
        columns.extend(motor_columns);
        // The rows' velocities and accelerations of every dynamic body come from the solve,
        // held by an ideal joint or not.
        let mut reactions = ReactionSolver::default();
        reactions.track = bodies
            .iter()
            .filter(|b| !b.fixed)
            .map(|b| b.handle)
            .collect();
        Ok(Twin {
            kind,
            bodies,
            hinges,
            drives,
            ideal_joints,
            ideal_hinges,
            joints,
            motors,
            body_motion,
            reactions,
            source_energy_before: 0.0,
            motor_joints,
            held_motors,
            reference_axis: Vector::from(scene.reference_axis).normalize(),
            contact_columns: columns
                .iter()
                .enumerate()
                .filter(|(_, c)| c.ends_with("_contact"))
                .map(|(i, _)| i)
                .collect(),
            table: Table::new(columns),
            row_prev: Vec::new(),
            row_cur: Vec::new(),
            invariants: Invariants::new(
                scene.gravity == [0.0; 3]
                    && scene.bodies.iter().all(|b| !b.fixed && b.motion.is_none()),
                scene.bodies.iter().any(|b| b.motion.is_some()),
            ),
        })
    }

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
            b.com_before = crate::rapier::ledger::world_center_of_mass(rb);
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
            if let HingeJoint::Clearance(c) = h.joint {
                let j = world.clearance.get(c).expect("handle of this twin");
                let r = j.report();
                let f = &r.force;
                let elastic = j.normal_law().elastic_force(r.state.penetration);
                h.force = f.on_journal.length();
                h.sample = ContactSample {
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
                };
            }
        }
        self.solve_ideal_reactions(world)?;
        self.source_energy_before = self.source_energy(world);
        if rows {
            std::mem::swap(&mut self.row_prev, &mut self.row_cur);
            self.fill_row(t, world);
        }
        Ok(())
    }

    /// Completes the step that started from the state [`before_step`](Self::before_step) read:
    /// ideal reactions (which only the step determines), metrics of that state over the step.
    pub(super) fn after_step(&mut self, world: &ClearanceWorld, info: &StepInfo) {
        let (bodies, joints) = (&world.rapier.bodies, &world.rapier.impulse_joints);
        self.update_force_metrics(info.t0, info.dt);
        self.update_invariants(bodies, world.rapier.gravity, info);
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
                let r = world
                    .clearance
                    .get(c)
                    .expect("handle of this twin")
                    .report();
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
            return Err(crate::Error::Diverged {
                t,
                reason: format!(
                    "the {} twin's ideal-joint reactions cannot be solved: its state or a \
                     body's mass is not finite",
                    self.kind.name()
                ),
            });
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
                HingeJoint::Ideal => None,
            })
            .map(|j| j.elastic_energy())
            .sum();
        drives + contacts
    }

    /// Metrics of the state before the step (its sample and force), weighted by the step.
    fn update_force_metrics(&mut self, t: f64, dt: f64) {
        for h in &mut self.hinges {
            let obs = h.observation();
            h.recorder.record(t, dt, &obs);
        }
    }

    /// The row values of the current state into `row_cur`.
    fn fill_row(&mut self, t: f64, world: &ClearanceWorld) {
        let bodies = &world.rapier.bodies;
        let axis_ref = self.reference_axis;
        let v = &mut self.row_cur;
        v.clear();
        v.push(t);
        for b in &self.bodies {
            let rb = &bodies[b.handle];
            v.push(b.angle.value().to_degrees());
            v.push(rb.angvel().dot(axis_ref).to_degrees());
        }
        if self.body_motion {
            for b in self.bodies.iter().filter(|b| b.moves) {
                let rb = &bodies[b.handle];
                let p = *rb.position() * b.local_com;
                let r = *rb.rotation() * b.local_com;
                // The centre of mass's velocity and acceleration at the state: a dynamic body's
                // from the constrained solve (`solve_ideal_reactions`); a tabulated drive's from
                // its table; a steady drive's those of its spin (its frame turns about its
                // origin, so its centre of mass moves with `w x r`).
                let (vel, acc) = match (b.table, b.fixed) {
                    (Some(k), _) => {
                        let (v0, a, w, alpha) = world.prescribed.motions[k].rates(t);
                        (v0 + w.cross(r), a + alpha.cross(r) + w.cross(w.cross(r)))
                    }
                    (None, true) => {
                        let w = rb.angvel();
                        (rb.linvel() + w.cross(r), w.cross(w.cross(r)))
                    }
                    (None, false) => {
                        let (vel, _) = self.reactions.velocity(b.handle).unwrap_or_default();
                        let (acc, _) = self.reactions.acceleration(b.handle).unwrap_or_default();
                        (vel, acc)
                    }
                };
                v.extend_from_slice(&[p.x, p.y, p.z, vel.x, vel.y, vel.z, acc.x, acc.y, acc.z]);
            }
        }
        for h in &self.hinges {
            let (r1, r2) = (
                &bodies[self.bodies[h.bearing].handle],
                &bodies[self.bodies[h.journal].handle],
            );
            let axis = *r1.rotation() * h.local_axis1;
            v.push(h.angle.value().to_degrees());
            v.push((r2.angvel() - r1.angvel()).dot(axis).to_degrees());
            v.push(h.force);
            match h.joint {
                HingeJoint::Clearance(c) => {
                    let r = world
                        .clearance
                        .get(c)
                        .expect("handle of this twin")
                        .report();
                    let e = r.state.eccentricity;
                    v.push(e.dot(*r1.rotation() * h.local_u1) * 1e3);
                    v.push(e.dot(*r1.rotation() * h.local_v1) * 1e3);
                    v.push(r.state.penetration.max(0.0) * 1e6);
                    v.push(if r.state.penetration > 0.0 { 1.0 } else { 0.0 });
                }
                HingeJoint::Ideal => v.extend_from_slice(&[0.0, 0.0, 0.0, 0.0]),
            }
        }
        for (_, f) in &self.joints {
            v.push(*f);
        }
        v.extend(self.motors.iter().flatten());
    }

    /// Appends the row at time `t`, `w` of the way from the previous state to the current one
    /// (linear; the contact flag from the nearer state).
    pub(super) fn write_row(&mut self, t: f64, w: f64) {
        let contact_cols = &self.contact_columns;
        let (prev, cur) = (&self.row_prev, &self.row_cur);
        let v = &mut self.table.values;
        v.push(t);
        for (i, &b) in cur.iter().enumerate().skip(1) {
            let a = prev.get(i).copied().unwrap_or(b);
            v.push(if w >= 1.0 {
                b
            } else if w <= 0.0 {
                a
            } else if contact_cols.contains(&i) {
                if w >= 0.5 { b } else { a }
            } else {
                a + (b - a) * w
            });
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
            .filter(|h| matches!(h.joint, HingeJoint::Clearance(_)))
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

/// A scene motor in Rapier's terms.
enum Motor {
    /// A velocity motor that holds its speed: target (rad/s or m/s) and damping factor (1/s).
    Held { target: f64, factor: f64 },
    /// A force-based spring-damper.
    Soft(SoftMotor),
}

fn motor_of(spec: Option<&MotorSpec>) -> Option<Motor> {
    Some(match spec? {
        MotorSpec::Velocity {
            target_rad_s,
            factor,
        } => Motor::Held {
            target: *target_rad_s,
            factor: *factor,
        },
        MotorSpec::LinearVelocity { target_m_s, factor } => Motor::Held {
            target: *target_m_s,
            factor: *factor,
        },
        MotorSpec::Position {
            target_rad,
            stiffness_nm_per_rad,
            damping_nm_s_per_rad,
            target_rad_s,
        } => Motor::Soft(SoftMotor::force_based(
            *target_rad,
            *target_rad_s,
            *stiffness_nm_per_rad,
            *damping_nm_s_per_rad,
        )),
        MotorSpec::LinearPosition {
            target_m,
            stiffness_n_per_m,
            damping_n_s_per_m,
            target_m_s,
        } => Motor::Soft(SoftMotor::force_based(
            *target_m,
            *target_m_s,
            *stiffness_n_per_m,
            *damping_n_s_per_m,
        )),
    })
}

impl Twin {
    /// Tracks this twin's bodies and hinges in `recorder` (group: the twin's name): clearance
    /// hinges as journals of the world's clearance set (passed first to
    /// [`ReplayRecorder::record`]), ideal hinges as pins at their scene point.
    pub fn track_replay(
        &self,
        scene: &Scene,
        world: &ClearanceWorld,
        recorder: &mut ReplayRecorder,
    ) -> Result<()> {
        let group = self.kind.name();
        let physics = &world.rapier;
        for b in &self.bodies {
            recorder.track_body(
                &b.name,
                group,
                b.handle,
                &physics.bodies,
                &physics.colliders,
            );
        }
        for (h, spec) in self.hinges.iter().zip(&scene.hinges) {
            let (b1, b2) = (self.bodies[h.bearing].handle, self.bodies[h.journal].handle);
            match h.joint {
                HingeJoint::Clearance(c) => {
                    recorder.track_journal(&h.name, group, 0, c, &world.clearance)?
                }
                HingeJoint::Ideal => {
                    let anchor =
                        Vector::from(spec.point_m) - Vector::from(scene.body_origin(h.bearing));
                    recorder.track_pin(&h.name, group, b1, b2, anchor, h.local_axis1)?
                }
            }
        }
        Ok(())
    }
}
