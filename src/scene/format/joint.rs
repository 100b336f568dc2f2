//! Ideal joints other than hinges (prismatic, fixed, spherical, motorised revolute), their
//! motors, and their validation.

use super::Scene;
use super::limits::*;
use crate::error::{Error, Result, in_range};
use serde::{Deserialize, Serialize};

/// An ideal joint that is not a revolute (revolutes are `hinges`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointSpec {
    /// Unique name (CSV column prefix).
    pub name: String,
    /// First body (the guide of a prismatic joint).
    pub body1: String,
    /// Second body (the slider): the joint force reported is the force on it.
    pub body2: String,
    /// World position of the joint point at t = 0, m (the slider's point of a prismatic joint).
    pub point_m: [f64; 3],
    /// Which joint.
    pub kind: JointKindSpec,
    /// A motor on the joint's free axis: `Velocity` or `Position` on a `Revolute` joint,
    /// `LinearVelocity` or `LinearPosition` on a `Prismatic` joint without `limits_m`.
    #[serde(default)]
    pub motor: Option<MotorSpec>,
}

/// A joint motor, Rapier's (`set_motor_velocity`, `set_motor`). Its torque or force is written
/// as `<joint>_motor_nm` (revolute) or `<joint>_motor_n` (prismatic), the torque or force on
/// body 2 about or along the axis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum MotorSpec {
    /// Holds the relative angular speed at `target_rad_s` (revolute), Rapier's velocity motor
    /// (acceleration-based) with damping `factor` (1/s; high: a stiff motor). The joint forces
    /// and the motor torque reported are those of a motor that holds its speed exactly.
    Velocity {
        /// Target relative angular speed of body 2 about the axis, rad/s.
        target_rad_s: f64,
        /// Rapier's motor damping factor, 1/s.
        factor: f64,
    },
    /// A torsional spring and damper towards an angle (revolute), Rapier's force-based motor:
    /// torque `stiffness (target_rad - angle) + damping (target_rad_s - rate)` on body 2, the
    /// angle of body 2 relative to body 1 about the axis from the start (in `[-pi, pi]`, the
    /// error taken the shorter way round). With no stiffness and a `target_rad_s` it is a soft
    /// velocity motor (a torque falling linearly with speed). Reported exactly: the torque is
    /// a function of the state.
    Position {
        /// Target angle, rad, in `[-pi, pi]`.
        target_rad: f64,
        /// Stiffness, N m/rad.
        stiffness_nm_per_rad: f64,
        /// Damping, N m s/rad.
        damping_nm_s_per_rad: f64,
        /// Target relative angular speed of the damping term, rad/s (default 0: the damping
        /// resists any motion).
        #[serde(default)]
        target_rad_s: f64,
    },
    /// Holds the relative speed along the axis at `target_m_s` (prismatic), as
    /// [`Velocity`](Self::Velocity).
    LinearVelocity {
        /// Target speed of body 2 along the axis, m/s.
        target_m_s: f64,
        /// Rapier's motor damping factor, 1/s.
        factor: f64,
    },
    /// A linear spring and damper towards a displacement (prismatic), Rapier's force-based
    /// motor: force `stiffness (target_m - x) + damping (target_m_s - speed)` on body 2 along the
    /// axis, `x` its displacement from the start.
    LinearPosition {
        /// Target displacement along the axis from the start, m.
        target_m: f64,
        /// Stiffness, N/m.
        stiffness_n_per_m: f64,
        /// Damping, N s/m.
        damping_n_s_per_m: f64,
        /// Target speed of the damping term, m/s (default 0).
        #[serde(default)]
        target_m_s: f64,
    },
}

impl MotorSpec {
    /// The variant's name as written in a scene.
    pub fn name(&self) -> &'static str {
        match self {
            MotorSpec::Velocity { .. } => "Velocity",
            MotorSpec::Position { .. } => "Position",
            MotorSpec::LinearVelocity { .. } => "LinearVelocity",
            MotorSpec::LinearPosition { .. } => "LinearPosition",
        }
    }
}

/// The kinds of [`JointSpec`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum JointKindSpec {
    /// Body 2 slides along `axis` (unit, world at t = 0) without turning relative to body 1,
    /// optionally between `limits_m` (displacement from the start, m).
    Prismatic {
        /// Slide axis (unit vector, world, t = 0).
        axis: [f64; 3],
        /// Travel limits `[min, max]` along the axis from the start position, m.
        #[serde(default)]
        limits_m: Option<[f64; 2]>,
    },
    /// An ideal revolute about `axis` (unit, world at t = 0) that may carry a `motor` (a
    /// revolute without motor is better written as a hinge, which may also take a clearance).
    Revolute {
        /// Hinge axis (unit vector, world, t = 0).
        axis: [f64; 3],
    },
    /// The bodies move as one.
    Fixed,
    /// A ball joint: the joint points coincide, rotation is free.
    Spherical,
}

impl Scene {
    /// The joints' fields and motors (names into `names`).
    pub(super) fn validate_joints<'a>(
        &'a self,
        names: &mut std::collections::HashSet<&'a str>,
    ) -> Result<()> {
        for j in &self.joints {
            let p = format!("joints[{}]", j.name);
            if !is_plain_name(&j.name) {
                return Err(Error::invalid(
                    p,
                    "name must be letters, digits, `_` and `-` (it prefixes CSV columns)",
                ));
            }
            if !names.insert(j.name.as_str()) {
                return Err(Error::invalid(
                    p,
                    "duplicate name (bodies, hinges, joints and drives share one namespace)",
                ));
            }
            for (field, body) in [("body1", &j.body1), ("body2", &j.body2)] {
                if self.body_index(body).is_none() {
                    return Err(Error::invalid(
                        format!("{p}.{field}"),
                        format!("no body named `{body}`"),
                    ));
                }
            }
            if j.body1 == j.body2 {
                return Err(Error::invalid(
                    format!("{p}.body2"),
                    "must differ from body1",
                ));
            }
            for (i, x) in j.point_m.iter().enumerate() {
                position(&format!("{p}.point_m[{i}]"), *x)?;
            }
            if let JointKindSpec::Revolute { axis } = &j.kind {
                unit(axis, &format!("{p}.kind.axis"))?;
            }
            if let Some(m) = &j.motor {
                validate_motor(m, &j.kind, &format!("{p}.motor"))?;
            }
            if let JointKindSpec::Prismatic { axis, limits_m } = &j.kind {
                unit(axis, &format!("{p}.kind.axis"))?;
                if let Some([lo, hi]) = limits_m {
                    position(&format!("{p}.kind.limits_m[0]"), *lo)?;
                    position(&format!("{p}.kind.limits_m[1]"), *hi)?;
                    if !(lo < hi) || *lo > 0.0 || *hi < 0.0 {
                        return Err(Error::invalid(
                            format!("{p}.kind.limits_m"),
                            format!(
                                "must be [min, max] with min <= 0 <= max and min < max (the start is 0; got [{lo}, {hi}])"
                            ),
                        ));
                    }
                }
            }
        }
        Ok(())
    }
}

/// A joint's motor (at `p`, e.g. `joints[motor].motor`) against the joint's kind and the
/// physical ranges of its fields.
fn validate_motor(m: &MotorSpec, kind: &JointKindSpec, p: &str) -> Result<()> {
    let (revolute, prismatic) = (
        matches!(kind, JointKindSpec::Revolute { .. }),
        matches!(kind, JointKindSpec::Prismatic { .. }),
    );
    let wrong = |needs: &str, other: &str| {
        Err(Error::invalid(
            p,
            format!("a `{}` motor needs a `{needs}` joint{other}", m.name()),
        ))
    };
    let factor = |f: f64| {
        in_range(
            &format!("{p}.factor"),
            f,
            MOTOR_FACTOR_RANGE.0,
            MOTOR_FACTOR_RANGE.1,
            "1/s",
        )
    };
    let spring = |k: (&str, f64, &str), c: (&str, f64, &str)| -> Result<()> {
        in_range(&format!("{p}.{}", k.0), k.1, 0.0, MOTOR_STIFFNESS_MAX, k.2)?;
        in_range(&format!("{p}.{}", c.0), c.1, 0.0, MOTOR_DAMPING_MAX, c.2)?;
        if k.1 == 0.0 && c.1 == 0.0 {
            return Err(Error::invalid(
                p,
                format!("`{}` and `{}` are both 0: the motor does nothing", k.0, c.0),
            ));
        }
        Ok(())
    };
    let rate =
        |field: &str, v: f64| in_range(&format!("{p}.{field}"), v, -RATE_MAX, RATE_MAX, "rad/s");
    let speed =
        |field: &str, v: f64| in_range(&format!("{p}.{field}"), v, -SPEED_MAX, SPEED_MAX, "m/s");
    match m {
        MotorSpec::Velocity {
            target_rad_s,
            factor: f,
        } => {
            if !revolute {
                return wrong("Revolute", " (on a `Prismatic` joint: `LinearVelocity`)");
            }
            rate("target_rad_s", *target_rad_s)?;
            factor(*f)?;
        }
        MotorSpec::Position {
            target_rad,
            stiffness_nm_per_rad,
            damping_nm_s_per_rad,
            target_rad_s,
        } => {
            if !revolute {
                return wrong("Revolute", " (on a `Prismatic` joint: `LinearPosition`)");
            }
            // Rapier measures the angle in [-pi, pi]: a target beyond is never reached.
            let pi = std::f64::consts::PI;
            in_range(&format!("{p}.target_rad"), *target_rad, -pi, pi, "rad")?;
            spring(
                ("stiffness_nm_per_rad", *stiffness_nm_per_rad, "N m/rad"),
                ("damping_nm_s_per_rad", *damping_nm_s_per_rad, "N m s/rad"),
            )?;
            rate("target_rad_s", *target_rad_s)?;
        }
        MotorSpec::LinearVelocity {
            target_m_s,
            factor: f,
        } => {
            if !prismatic {
                return wrong("Prismatic", " (on a `Revolute` joint: `Velocity`)");
            }
            speed("target_m_s", *target_m_s)?;
            factor(*f)?;
        }
        MotorSpec::LinearPosition {
            target_m,
            stiffness_n_per_m,
            damping_n_s_per_m,
            target_m_s,
        } => {
            if !prismatic {
                return wrong("Prismatic", " (on a `Revolute` joint: `Position`)");
            }
            position(&format!("{p}.target_m"), *target_m)?;
            spring(
                ("stiffness_n_per_m", *stiffness_n_per_m, "N/m"),
                ("damping_n_s_per_m", *damping_n_s_per_m, "N s/m"),
            )?;
            speed("target_m_s", *target_m_s)?;
        }
    }
    if let JointKindSpec::Prismatic {
        limits_m: Some(_), ..
    } = kind
    {
        return Err(Error::invalid(
            p,
            "a motor on a prismatic joint with `limits_m` is not supported: the reported \
             reactions would not know when the limit, not the motor, holds the slider",
        ));
    }
    Ok(())
}
