//! Bodies and their prescribed motions, and their validation.

use super::Scene;
use super::limits::*;
use crate::error::{Error, Result, in_range, non_negative, sig4};
use serde::{Deserialize, Serialize};

/// A rigid body with principal axes along the world axes at t = 0, at rest.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Unique name (CSV column prefix).
    pub name: String,
    /// Mass, kg.
    pub mass_kg: f64,
    /// Principal moments of inertia about the centre of mass (Jx, Jy, Jz), kg m^2.
    pub inertia_kg_m2: [f64; 3],
    /// World position of the centre of mass at t = 0, m.
    pub center_of_mass_m: [f64; 3],
    /// A fixed body (ground): it does not move; mass and inertia are then ignored.
    #[serde(default)]
    pub fixed: bool,
    /// A prescribed motion: the body is kinematic (Rapier's velocity-based kinematic body) and
    /// drives the mechanism; its mass and inertia are then ignored.
    #[serde(default)]
    pub motion: Option<MotionSpec>,
    /// Initial velocity of the centre of mass, m/s (dynamic bodies only: refused on a fixed or
    /// driven body; default at rest).
    #[serde(default)]
    pub velocity_m_s: [f64; 3],
    /// Initial angular velocity, rad/s (dynamic bodies only, as `velocity_m_s`; default at
    /// rest).
    #[serde(default)]
    pub angular_velocity_rad_s: [f64; 3],
}

/// A prescribed motion of a kinematic body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum MotionSpec {
    /// Constant angular speed `rate_rad_s` about `axis` (unit, world) through `point_m` (world,
    /// m) from t = 0 (a crank).
    Spin {
        /// Rotation axis (unit vector, world).
        axis: [f64; 3],
        /// A point of the axis, m.
        point_m: [f64; 3],
        /// Angular speed, rad/s (right-hand rule about `axis`).
        rate_rad_s: f64,
    },
    /// Constant velocity `velocity_m_s` (m/s, world) without rotation.
    Translate {
        /// Velocity, m/s.
        velocity_m_s: [f64; 3],
    },
    /// A tabulated angle `angle_rad` at times `t_s` about `axis` through `point_m`, interpolated
    /// smoothly (cubic Hermite; rate continuous), relative to its value at t = 0.
    TableAngle {
        /// Rotation axis (unit vector, world).
        axis: [f64; 3],
        /// A point of the axis, m.
        point_m: [f64; 3],
        /// Times, s, strictly increasing.
        t_s: Vec<f64>,
        /// Angles at those times, rad.
        angle_rad: Vec<f64>,
    },
    /// A tabulated position `position_m` at times `t_s` along `direction`, interpolated as
    /// [`TableAngle`](Self::TableAngle), relative to its value at t = 0.
    TablePosition {
        /// Direction (unit vector, world).
        direction: [f64; 3],
        /// Times, s, strictly increasing.
        t_s: Vec<f64>,
        /// Positions at those times, m.
        position_m: Vec<f64>,
    },
}

impl Scene {
    /// The bodies' fields (names into `names`, shared with hinges, joints and drives).
    pub(super) fn validate_bodies<'a>(
        &'a self,
        names: &mut std::collections::HashSet<&'a str>,
    ) -> Result<()> {
        for b in &self.bodies {
            let p = format!("bodies[{}]", b.name);
            if !is_plain_name(&b.name) {
                return Err(Error::invalid(
                    p,
                    "name must be letters, digits, `_` and `-` (it prefixes CSV columns)",
                ));
            }
            if !names.insert(b.name.as_str()) {
                return Err(Error::invalid(p, "duplicate name"));
            }
            validate_mass(b, &p)?;
            validate_initial_state(b, &p)?;
            validate_motion(b, &p)?;
        }
        Ok(())
    }
}

/// A body's mass and inertia: ignored (0 is fine) for a ground or driven body, in range and
/// physical (the triangle inequality) otherwise.
fn validate_mass(b: &BodySpec, p: &str) -> Result<()> {
    if b.fixed || b.motion.is_some() {
        // A ground or driven body: its mass and inertia are ignored (0 is fine).
        non_negative(&format!("{p}.mass_kg"), b.mass_kg)?;
        for (i, j) in b.inertia_kg_m2.iter().enumerate() {
            non_negative(&format!("{p}.inertia_kg_m2[{i}]"), *j)?;
        }
    } else {
        let (lo, hi) = MASS_RANGE;
        in_range(&format!("{p}.mass_kg"), b.mass_kg, lo, hi, "kg")?;
        let (lo, hi) = INERTIA_RANGE;
        for (i, j) in b.inertia_kg_m2.iter().enumerate() {
            in_range(&format!("{p}.inertia_kg_m2[{i}]"), *j, lo, hi, "kg m^2")?;
        }
        let [a, bb, c] = b.inertia_kg_m2;
        if a + bb < c || bb + c < a || a + c < bb {
            return Err(Error::invalid(
                format!("{p}.inertia_kg_m2"),
                "violates the triangle inequality of principal moments",
            ));
        }
    }
    Ok(())
}

/// A body's position and initial velocities (none for a fixed or driven body: it would be
/// ignored).
fn validate_initial_state(b: &BodySpec, p: &str) -> Result<()> {
    for (i, x) in b.center_of_mass_m.iter().enumerate() {
        position(&format!("{p}.center_of_mass_m[{i}]"), *x)?;
    }
    speed(&format!("{p}.velocity_m_s"), &b.velocity_m_s)?;
    for (i, w) in b.angular_velocity_rad_s.iter().enumerate() {
        in_range(
            &format!("{p}.angular_velocity_rad_s[{i}]"),
            *w,
            -RATE_MAX,
            RATE_MAX,
            "rad/s",
        )?;
    }
    // A fixed or driven body's velocity is not its own: one given would be ignored.
    if b.fixed || b.motion.is_some() {
        let what = if b.fixed {
            "a fixed body does not move"
        } else {
            "a body with a prescribed motion moves as its `motion` says"
        };
        for (field, v) in [
            ("velocity_m_s", b.velocity_m_s),
            ("angular_velocity_rad_s", b.angular_velocity_rad_s),
        ] {
            if v != [0.0; 3] {
                return Err(Error::invalid(
                    format!("{p}.{field}"),
                    format!("{what}: an initial velocity would be ignored; remove it"),
                ));
            }
        }
    }
    Ok(())
}

/// A body's prescribed motion.
fn validate_motion(b: &BodySpec, p: &str) -> Result<()> {
    match &b.motion {
        Some(_) if b.fixed => {
            return Err(Error::invalid(
                format!("{p}.motion"),
                "a fixed body cannot also have a prescribed motion: remove `fixed: true` or the motion",
            ));
        }
        Some(MotionSpec::Spin {
            axis,
            point_m,
            rate_rad_s,
        }) => {
            unit(axis, &format!("{p}.motion.axis"))?;
            for (i, x) in point_m.iter().enumerate() {
                position(&format!("{p}.motion.point_m[{i}]"), *x)?;
            }
            in_range(
                &format!("{p}.motion.rate_rad_s"),
                *rate_rad_s,
                -RATE_MAX,
                RATE_MAX,
                "rad/s",
            )?;
            turning_speed(
                &format!("{p}.motion.rate_rad_s"),
                rate_rad_s.abs(),
                point_m,
                &b.center_of_mass_m,
            )?;
        }
        Some(MotionSpec::TableAngle {
            axis,
            point_m,
            t_s,
            angle_rad,
        }) => {
            unit(axis, &format!("{p}.motion.axis"))?;
            for (i, x) in point_m.iter().enumerate() {
                position(&format!("{p}.motion.point_m[{i}]"), *x)?;
            }
            let table = crate::rapier::sources::prescribed::Table::new(t_s, angle_rad)
                .map_err(|e| table_error(e, p, "angle_rad"))?;
            let field = format!("{p}.motion.angle_rad");
            let rate = table.max_rate();
            if rate > RATE_MAX {
                return Err(Error::invalid(
                    field,
                    format!(
                        "turns at up to {} rad/s between its points, more than {} rad/s",
                        sig4(rate),
                        sig4(RATE_MAX)
                    ),
                ));
            }
            turning_speed(&field, rate, point_m, &b.center_of_mass_m)?;
        }
        Some(MotionSpec::TablePosition {
            direction,
            t_s,
            position_m,
        }) => {
            unit(direction, &format!("{p}.motion.direction"))?;
            let table = crate::rapier::sources::prescribed::Table::new(t_s, position_m)
                .map_err(|e| table_error(e, p, "position_m"))?;
            let rate = table.max_rate();
            if rate > SPEED_MAX {
                return Err(Error::invalid(
                    format!("{p}.motion.position_m"),
                    format!(
                        "moves at up to {} m/s between its points, more than {} m/s",
                        sig4(rate),
                        sig4(SPEED_MAX)
                    ),
                ));
            }
        }
        Some(MotionSpec::Translate { velocity_m_s }) => {
            speed(&format!("{p}.motion.velocity_m_s"), velocity_m_s)?;
        }
        None => {}
    }
    Ok(())
}

/// A velocity: finite components and a speed of at most [`SPEED_MAX`].
fn speed(field: &str, v: &[f64; 3]) -> Result<()> {
    for (i, x) in v.iter().enumerate() {
        in_range(&format!("{field}[{i}]"), *x, -SPEED_MAX, SPEED_MAX, "m/s")?;
    }
    let s = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if s > SPEED_MAX {
        return Err(Error::invalid(
            field,
            format!(
                "a speed of {} m/s, more than {} m/s",
                sig4(s),
                sig4(SPEED_MAX)
            ),
        ));
    }
    Ok(())
}

/// The speed of the centre of mass `com` turning at `rate` (rad/s) about an axis through
/// `point`: at most `rate |com - point|`, which must not pass [`SPEED_MAX`].
fn turning_speed(field: &str, rate: f64, point: &[f64; 3], com: &[f64; 3]) -> Result<()> {
    let r = (0..3)
        .map(|i| (com[i] - point[i]).powi(2))
        .sum::<f64>()
        .sqrt();
    let s = rate * r;
    if s > SPEED_MAX {
        return Err(Error::invalid(
            field,
            format!(
                "turns the centre of mass, {} m from the axis, at up to {} m/s, more than {} m/s",
                sig4(r),
                sig4(s),
                sig4(SPEED_MAX)
            ),
        ));
    }
    Ok(())
}

/// A table's error with the scene's field names (`t_s` and the value list's name).
fn table_error(e: Error, body: &str, values: &str) -> Error {
    match e {
        Error::Invalid { field, reason } => Error::invalid(
            format!(
                "{body}.motion.{}",
                field
                    .replacen("values", values, 1)
                    .replacen("times", "t_s", 1)
            ),
            reason,
        ),
        other => other,
    }
}
