//! Building a twin from a validated scene, step by step: bodies, hinges, drives, the ideal
//! joints the reactions are solved for, the scene's other joints and their motors, columns.

use super::{BodyTrack, ContactSample, HingeJoint, HingeTrack, SPATIAL_COLUMNS, Twin, TwinKind};
use crate::error::Result;
use crate::model::angle::{HingeAngle, UnwrappedAngle};
use crate::model::kinematics::in_plane_u;
use crate::rapier::hinge::design::ClearanceModel;
use crate::rapier::observers::metrics::ImpactRecorder;
use crate::rapier::observers::reaction::{
    IdealFixed, IdealJoint, IdealPrismatic, IdealRevolute, IdealSpherical, JointModel,
    ReactionSolver, SoftMotor,
};
use crate::rapier::pipeline::world::ClearanceWorld;
use crate::rapier::sources::drive::{DriveHandle, TorsionSpring};
use crate::rapier::sources::prescribed::{PrescribedMotion, PrescribedPath, Table as MotionTable};
use crate::scene::runner::invariants::Invariants;
use crate::scene::{BodySpec, JointKindSpec, JointSpec, MotionSpec, MotorSpec, ValidatedScene};
use crate::table::Table;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::*;

mod joints;
use joints::*;

impl Twin {
    /// Builds the twin `kind` of `scene` into `world`: its bodies, hinges (clearance joints
    /// from the scene's [`HingeDesign`](crate::rapier::hinge::design::HingeDesign)s in a clearance twin),
    /// drives, the scene's other joints, and its table's columns.
    pub(in crate::scene::runner) fn build(
        scene: &ValidatedScene,
        kind: TwinKind,
        world: &mut ClearanceWorld,
    ) -> Result<Twin> {
        let bodies = build_bodies(scene, world)?;
        let hinges = build_hinges(scene, kind, &bodies, world)?;
        let drives = build_drives(scene, &bodies, &hinges, world)?;
        let (mut ideal_joints, ideal_hinges) = ideal_hinge_joints(scene, &bodies, &hinges);
        let other = build_joints(scene, &bodies, world);
        ideal_joints.extend(other.ideal);
        let columns = columns(scene, &bodies, &hinges, &other.joints, other.motor_columns);
        let reactions = reaction_solver(&bodies);
        Ok(Twin {
            kind,
            drives,
            ideal_joints,
            ideal_hinges,
            motors: other.motors,
            joints: other.joints,
            body_motion: scene.run.body_motion,
            reactions,
            source_energy_before: 0.0,
            motor_joints: other.motor_joints,
            held_motors: other.held_motors,
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
            inside: Default::default(),
            rows: false,
            invariants: Invariants::new(
                scene.gravity == [0.0; 3]
                    && scene.bodies.iter().all(|b| !b.fixed && b.motion.is_none()),
                scene.bodies.iter().any(|b| b.motion.is_some()),
            ),
            bodies,
            hinges,
        })
    }
}

/// The scene's bodies in `world`, tracked, with the tabulated motions of the driven ones in
/// the world's prescribed set.
fn build_bodies(scene: &ValidatedScene, world: &mut ClearanceWorld) -> Result<Vec<BodyTrack>> {
    let mut bodies = Vec::with_capacity(scene.bodies.len());
    let prescribed = &mut world.prescribed;
    for (i, b) in scene.bodies.iter().enumerate() {
        let com = Vector::from(b.center_of_mass_m);
        let origin = Vector::from(scene.body_origin(i));
        let (rb, table) = match &b.motion {
            Some(m @ (MotionSpec::TableAngle { .. } | MotionSpec::TablePosition { .. })) => {
                let (rb, motion) = tabulated_body(b, m, origin)?;
                prescribed.motions.push(motion);
                (rb, Some(prescribed.motions.len() - 1))
            }
            Some(m) => (driven_body(m, origin), None),
            None => (free_or_fixed_body(b, com), None),
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
    Ok(bodies)
}

/// A tabulated drive: a position-based kinematic body whose next pose the prescribed set gives
/// before each step, and that motion (its body handle set once the body is inserted).
fn tabulated_body(
    b: &BodySpec,
    m: &MotionSpec,
    origin: Vector,
) -> Result<(RigidBody, PrescribedMotion)> {
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
        _ => unreachable!("only tables are passed here"),
    };
    let rb = RigidBodyBuilder::kinematic_position_based()
        .translation(origin)
        .can_sleep(false)
        .build();
    let motion = PrescribedMotion {
        body: RigidBodyHandle::invalid(),
        start: *rb.position(),
        path,
        table: MotionTable::new(t, v)
            .map_err(|e| e.within(&format!("bodies[{}].motion", b.name)))?,
    };
    Ok((rb, motion))
}

/// A steadily driven body: no mass properties, so Rapier turns it about its frame origin.
fn driven_body(m: &MotionSpec, origin: Vector) -> RigidBody {
    let (v, w) = match m {
        MotionSpec::Spin {
            axis, rate_rad_s, ..
        } => (Vector::ZERO, Vector::from(*axis).normalize() * *rate_rad_s),
        MotionSpec::Translate { velocity_m_s } => (Vector::from(*velocity_m_s), Vector::ZERO),
        _ => unreachable!("tables are built by `tabulated_body`"),
    };
    RigidBodyBuilder::kinematic_velocity_based()
        .translation(origin)
        .linvel(v)
        .angvel(w)
        .can_sleep(false)
        .build()
}

/// A dynamic body with its initial velocities, or a fixed one, at its centre of mass.
fn free_or_fixed_body(b: &BodySpec, com: Vector) -> RigidBody {
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

/// The scene's hinges in `world`: in a clearance twin, a hinge with clearance is a clearance
/// joint (in the world's clearance set) built by its [`HingeDesign`](crate::rapier::hinge::design::HingeDesign) (the validated scene's,
/// the one route from settings to joint); every other hinge is Rapier's revolute joint.
fn build_hinges(
    scene: &ValidatedScene,
    kind: TwinKind,
    bodies: &[BodyTrack],
    world: &mut ClearanceWorld,
) -> Result<Vec<HingeTrack>> {
    let mut hinges = Vec::with_capacity(scene.hinges.len());
    for (i, h) in scene.hinges.iter().enumerate() {
        let (ib, ij) = (
            scene.body_index(&h.bearing).expect("validated"),
            scene.body_index(&h.journal).expect("validated"),
        );
        let axis = Vector::from(h.axis).normalize();
        // Bodies start unrotated with their frame at their origin (the centre of mass, or a
        // spinning body's axis point).
        let (a1, a2) = anchors(scene, h.point_m, ib, ij);
        let (b1, b2) = (bodies[ib].handle, bodies[ij].handle);
        let joint = match (scene.clearance(i), kind) {
            (Some(settings), TwinKind::Clearance) => {
                // The journal's centre starts off the bearing's by the hinge's offset.
                let a2 = a2 + Vector::from(h.journal_offset_mm) * 1e-3;
                match settings.model {
                    ClearanceModel::Compliant => {
                        let settings = settings
                            .clone()
                            .integration(scene.run.contact_integration)
                            .sub_cycle_techniques(scene.run.sub_cycle);
                        let j = settings.joint(a1, a2, axis, axis)?;
                        HingeJoint::Clearance(world.insert_clearance(b1, b2, j)?)
                    }
                    ClearanceModel::Spatial(_) => {
                        let settings = settings
                            .clone()
                            .integration(scene.run.contact_integration)
                            .sub_cycle_techniques(scene.run.sub_cycle);
                        let j = settings.joint(a1, a2, axis, axis)?;
                        HingeJoint::Clearance(world.insert_clearance(b1, b2, j)?)
                    }
                    ClearanceModel::LargeStep => {
                        let j = settings.large_step_joint(a1, a2, axis, axis)?;
                        HingeJoint::LargeStep(world.insert_large_step(b1, b2, j)?)
                    }
                }
            }
            _ => {
                let j = RevoluteJointBuilder::new(axis)
                    .local_anchor1(a1)
                    .local_anchor2(a2)
                    .contacts_enabled(false);
                world.rapier.impulse_joints.insert(b1, b2, j, true);
                HingeJoint::Ideal
            }
        };
        let u = in_plane_u(axis);
        hinges.push(HingeTrack {
            name: h.name.clone(),
            joint,
            bearing: ib,
            journal: ij,
            local_anchor1: a1,
            local_axis1: axis,
            local_u1: u,
            local_v1: axis.cross(u),
            angle: HingeAngle::default(),
            force: 0.0,
            sample: ContactSample::default(),
            spatial: h.is_spatial(),
            spatial_sample: None,
            recorder: ImpactRecorder::new(),
        });
    }
    Ok(hinges)
}

/// The anchors of a joint at world point `point` (t = 0) in bodies `i1` and `i2`'s frames.
fn anchors(scene: &ValidatedScene, point: [f64; 3], i1: usize, i2: usize) -> (Vector, Vector) {
    let point = Vector::from(point);
    (
        point - Vector::from(scene.body_origin(i1)),
        point - Vector::from(scene.body_origin(i2)),
    )
}

/// The scene's torsion-spring drives on their hinges, in the world's drive set.
fn build_drives(
    scene: &ValidatedScene,
    bodies: &[BodyTrack],
    hinges: &[HingeTrack],
    world: &mut ClearanceWorld,
) -> Result<Vec<DriveHandle>> {
    let mut drives = Vec::with_capacity(scene.drives.len());
    for d in &scene.drives {
        let h = &hinges[scene.hinge_index(&d.hinge).expect("validated")];
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
    Ok(drives)
}

/// The table's columns: time, each body's angle and rate (and, with `run.body_motion`, each
/// moving body's position, velocity and acceleration), each hinge's, each joint's force, then
/// the motors'.
fn columns(
    scene: &ValidatedScene,
    bodies: &[BodyTrack],
    hinges: &[HingeTrack],
    joints: &[(String, f64)],
    motor_columns: Vec<String>,
) -> Vec<String> {
    let mut columns = vec!["t_s".to_string()];
    for b in bodies {
        columns.push(format!("{}_angle_deg", b.name));
        columns.push(format!("{}_rate_deg_s", b.name));
    }
    if scene.run.body_motion {
        for b in bodies.iter().filter(|b| b.moves) {
            for c in [
                "x_m", "y_m", "z_m", "vx_m_s", "vy_m_s", "vz_m_s", "ax_m_s2", "ay_m_s2", "az_m_s2",
            ] {
                columns.push(format!("{}_{c}", b.name));
            }
        }
    }
    for (i, h) in hinges.iter().enumerate() {
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
        if scene.hinges[i].is_spatial() {
            for c in SPATIAL_COLUMNS {
                columns.push(format!("{}_{c}", h.name));
            }
        }
    }
    for (name, _) in joints {
        columns.push(format!("{name}_force_n"));
    }
    columns.extend(motor_columns);
    columns
}

/// The reaction solver, tracking every dynamic body: the rows' velocities and accelerations of
/// every dynamic body come from the solve, held by an ideal joint or not.
fn reaction_solver(bodies: &[BodyTrack]) -> ReactionSolver {
    let mut reactions = ReactionSolver::default();
    reactions.track = bodies
        .iter()
        .filter(|b| !b.fixed)
        .map(|b| b.handle)
        .collect();
    reactions
}

#[cfg(test)]
mod tests;
