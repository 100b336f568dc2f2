//! The scene's joints in Rapier's terms: the ideal hinges' revolutes, the other joints and their
//! motors.

use super::*;
/// The ideal hinges' revolutes for the reaction solve, with the hinge index of each.
pub(super) fn ideal_hinge_joints(
    scene: &ValidatedScene,
    bodies: &[BodyTrack],
    hinges: &[HingeTrack],
) -> (Vec<IdealJoint>, Vec<usize>) {
    let (mut ideal_joints, mut ideal_hinges) = (Vec::new(), Vec::new());
    for (i, h) in hinges.iter().enumerate() {
        if let HingeJoint::Ideal = h.joint {
            let (a1, a2) = anchors(scene, scene.hinges[i].point_m, h.bearing, h.journal);
            ideal_joints.push(IdealJoint(JointModel::Revolute(IdealRevolute {
                body1: bodies[h.bearing].handle,
                body2: bodies[h.journal].handle,
                local_anchor1: a1,
                local_anchor2: a2,
                local_axis1: h.local_axis1,
            })));
            ideal_hinges.push(i);
        }
    }
    (ideal_joints, ideal_hinges)
}

/// The scene's other joints, built: what the twin keeps of them.
#[derive(Default)]
pub(super) struct SceneJoints {
    /// Each joint for the reaction solve, in scene order.
    pub(super) ideal: Vec<IdealJoint>,
    /// Each joint's name and force (zero until solved).
    pub(super) joints: Vec<(String, f64)>,
    /// Each joint's motor torque or force (zero until solved), `None` without a motor.
    pub(super) motors: Vec<Option<f64>>,
    /// The motor columns' names.
    pub(super) motor_columns: Vec<String>,
    /// The motors in Rapier, with their axis and scene joint index.
    pub(super) motor_joints: Vec<(ImpulseJointHandle, JointAxis, usize)>,
    /// The velocity motors: scene joint index, target, name, unit of the target.
    pub(super) held_motors: Vec<(usize, f64, String, &'static str)>,
}

/// The scene's joints of Rapier's other kinds in `world`, with their motors.
pub(super) fn build_joints(
    scene: &ValidatedScene,
    bodies: &[BodyTrack],
    world: &mut ClearanceWorld,
) -> SceneJoints {
    let mut out = SceneJoints::default();
    for (k, j) in scene.joints.iter().enumerate() {
        let motor = motor_of(j.motor.as_ref());
        if let Some(Motor::Held { target, .. }) = motor {
            let unit = match j.motor {
                Some(MotorSpec::LinearVelocity { .. }) => "m/s",
                _ => "rad/s",
            };
            out.held_motors.push((k, target, j.name.clone(), unit));
        }
        let (ideal, handle) = build_joint(scene, j, motor, bodies, world);
        if let (Some(_), Some(axis)) = (&j.motor, motor_axis(&j.kind)) {
            out.motor_joints.push((handle, axis, k));
        }
        out.ideal.push(ideal);
        out.joints.push((j.name.clone(), 0.0));
        out.motors.push(j.motor.as_ref().map(|_| 0.0));
        if j.motor.is_some() {
            let unit = match j.kind {
                JointKindSpec::Prismatic { .. } => "n",
                _ => "nm",
            };
            out.motor_columns.push(format!("{}_motor_{unit}", j.name));
        }
    }
    out
}

/// The axis a joint kind's motor drives (`None`: the kind takes no motor).
pub(super) fn motor_axis(kind: &JointKindSpec) -> Option<JointAxis> {
    match kind {
        JointKindSpec::Prismatic { .. } => Some(JointAxis::LinX),
        JointKindSpec::Revolute { .. } => Some(JointAxis::AngX),
        JointKindSpec::Fixed | JointKindSpec::Spherical => None,
    }
}

/// One scene joint in `world` (with its motor, `motor`), and the same joint for the reaction
/// solve.
pub(super) fn build_joint(
    scene: &ValidatedScene,
    j: &JointSpec,
    motor: Option<Motor>,
    bodies: &[BodyTrack],
    world: &mut ClearanceWorld,
) -> (IdealJoint, ImpulseJointHandle) {
    let (i1, i2) = (
        scene.body_index(&j.body1).expect("validated"),
        scene.body_index(&j.body2).expect("validated"),
    );
    let (a1, a2) = anchors(scene, j.point_m, i1, i2);
    let (b1, b2) = (bodies[i1].handle, bodies[i2].handle);
    let (rapier, ideal): (GenericJoint, IdealJoint) = match &j.kind {
        JointKindSpec::Prismatic { axis, limits_m } => prismatic(
            b1,
            b2,
            a1,
            a2,
            Vector::from(*axis).normalize(),
            *limits_m,
            motor,
        ),
        JointKindSpec::Revolute { axis } => {
            revolute(b1, b2, a1, a2, Vector::from(*axis).normalize(), motor)
        }
        JointKindSpec::Fixed => (
            FixedJointBuilder::new()
                .local_anchor1(a1)
                .local_anchor2(a2)
                .contacts_enabled(false)
                .into(),
            IdealJoint(JointModel::Fixed(IdealFixed {
                body1: b1,
                body2: b2,
                local_anchor1: a1,
                local_anchor2: a2,
            })),
        ),
        JointKindSpec::Spherical => (
            SphericalJointBuilder::new()
                .local_anchor1(a1)
                .local_anchor2(a2)
                .contacts_enabled(false)
                .into(),
            IdealJoint(JointModel::Spherical(IdealSpherical {
                body1: b1,
                body2: b2,
                local_anchor1: a1,
                local_anchor2: a2,
            })),
        ),
    };
    let handle = world.rapier.impulse_joints.insert(b1, b2, rapier, true);
    (ideal, handle)
}

/// A prismatic joint along `axis`, with its limits and motor (validated: only linear motors).
pub(super) fn prismatic(
    b1: RigidBodyHandle,
    b2: RigidBodyHandle,
    a1: Vector,
    a2: Vector,
    axis: Vector,
    limits: Option<[f64; 2]>,
    motor: Option<Motor>,
) -> (GenericJoint, IdealJoint) {
    let mut rj = PrismaticJointBuilder::new(axis)
        .local_anchor1(a1)
        .local_anchor2(a2)
        .contacts_enabled(false);
    if let Some(l) = limits {
        rj = rj.limits(l);
    }
    let ideal = IdealPrismatic {
        body1: b1,
        body2: b2,
        local_anchor1: a1,
        local_anchor2: a2,
        local_axis1: axis,
    };
    let ideal = match motor {
        Some(Motor::Held { target, factor }) => {
            rj = rj.motor_velocity(target, factor);
            IdealJoint(JointModel::MotorPrismatic(ideal))
        }
        Some(Motor::Soft(m)) => {
            rj = rj
                .set_motor(m.target_pos, m.target_vel, m.stiffness, m.damping)
                .motor_model(MotorModel::ForceBased);
            IdealJoint(JointModel::SoftMotorPrismatic(ideal, m))
        }
        None => IdealJoint(JointModel::Prismatic(ideal)),
    };
    (rj.into(), ideal)
}

/// A revolute joint about `axis`, with its motor (validated: only angular motors).
pub(super) fn revolute(
    b1: RigidBodyHandle,
    b2: RigidBodyHandle,
    a1: Vector,
    a2: Vector,
    axis: Vector,
    motor: Option<Motor>,
) -> (GenericJoint, IdealJoint) {
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
    let ideal = match motor {
        Some(Motor::Held { target, factor }) => {
            rj = rj.motor_velocity(target, factor);
            IdealJoint(JointModel::MotorRevolute(ideal))
        }
        Some(Motor::Soft(m)) => {
            rj = rj
                .motor(m.target_pos, m.target_vel, m.stiffness, m.damping)
                .motor_model(MotorModel::ForceBased);
            IdealJoint(JointModel::SoftMotorRevolute(ideal, m))
        }
        None => IdealJoint(JointModel::Revolute(ideal)),
    };
    (rj.into(), ideal)
}

/// A scene motor in Rapier's terms.
#[derive(Clone, Copy)]
pub(super) enum Motor {
    /// A velocity motor that holds its speed: target (rad/s or m/s) and damping factor (1/s).
    Held { target: f64, factor: f64 },
    /// A force-based spring-damper.
    Soft(SoftMotor),
}

pub(super) fn motor_of(spec: Option<&MotorSpec>) -> Option<Motor> {
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
