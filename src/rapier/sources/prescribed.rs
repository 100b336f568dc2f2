//! Prescribed motion from a table: a kinematic body turned by a tabulated angle about an axis
//! through a point, or moved by a tabulated position along a direction, interpolated smoothly
//! (cubic Hermite, continuous slope: [`Table`]).
//!
//! A [`PrescribedSet`] takes part in the stepper's steps ([`StepHooks`]) but applies no force:
//! before each Rapier step the [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld) hands it the step's start and
//! length, and it sets each body's next pose at the step's end (Rapier's position-based kinematic
//! bodies then move there, their velocity being the step's mean). Poses are exact at every
//! state, whatever the step.

use crate::error::{Error, Result};
use crate::rapier::pipeline::step_hooks::{RapierStepContext, StepHooks};
use rapier3d_f64::math::{Pose, Rotation, Vector};
use rapier3d_f64::prelude::{RigidBodyHandle, RigidBodySet, RigidBodyType};

/// `v` normalised; an error naming `field` when it has no direction (zero or not finite).
fn unit(field: &str, v: Vector) -> Result<Vector> {
    let n = v.length();
    if !(n.is_finite() && n > 0.0) {
        return Err(Error::invalid(
            field,
            format!("must be a non-zero, finite vector (got {v:?}): give the axis's direction"),
        ));
    }
    Ok(v / n)
}

/// A value against time, interpolated by cubic Hermite segments with slopes from the neighbours
/// (`(v[i+1] - v[i-1]) / (t[i+1] - t[i-1])`, one-sided at the ends): the value and its rate are
/// continuous, the second derivative is piecewise linear. Outside the table the value goes on
/// along the end slope (rate constant, no acceleration).
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    t: Vec<f64>,
    v: Vec<f64>,
    m: Vec<f64>,
}

impl Table {
    /// A table of `values` at strictly increasing `times` (s); at least two finite points.
    pub fn new(times: &[f64], values: &[f64]) -> Result<Table> {
        if times.len() != values.len() {
            return Err(Error::invalid(
                "values",
                format!("{} values for {} times", values.len(), times.len()),
            ));
        }
        if times.len() < 2 {
            return Err(Error::invalid("times", "needs at least two points"));
        }
        for (i, (t, v)) in times.iter().zip(values).enumerate() {
            if !t.is_finite() {
                return Err(Error::invalid(format!("times[{i}]"), "must be finite"));
            }
            if !v.is_finite() {
                return Err(Error::invalid(format!("values[{i}]"), "must be finite"));
            }
            if i > 0 && !(times[i] > times[i - 1]) {
                return Err(Error::invalid(
                    format!("times[{i}]"),
                    "times must increase strictly",
                ));
            }
        }
        let n = times.len();
        let m: Vec<f64> = (0..n)
            .map(|i| {
                let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
                (values[b] - values[a]) / (times[b] - times[a])
            })
            .collect();
        if let Some(i) = m.iter().position(|m| !m.is_finite()) {
            return Err(Error::invalid(
                format!("values[{i}]"),
                "the rate there (the slope between its neighbours) is not finite: values or \
                 times too far apart",
            ));
        }
        Ok(Table {
            t: times.to_vec(),
            v: values.to_vec(),
            m,
        })
    }

    /// Value, rate and second derivative at `t`. A NaN `t` gives NaN for all three; an
    /// infinite `t` is beyond the table (the value infinite, or NaN for a zero end slope).
    pub fn eval(&self, t: f64) -> (f64, f64, f64) {
        if t.is_nan() {
            return (f64::NAN, f64::NAN, f64::NAN);
        }
        let n = self.t.len();
        if t <= self.t[0] {
            return (self.v[0] + self.m[0] * (t - self.t[0]), self.m[0], 0.0);
        }
        if t >= self.t[n - 1] {
            return (
                self.v[n - 1] + self.m[n - 1] * (t - self.t[n - 1]),
                self.m[n - 1],
                0.0,
            );
        }
        let i = self.t.partition_point(|&x| x <= t) - 1;
        let h = self.t[i + 1] - self.t[i];
        let s = (t - self.t[i]) / h;
        // Scaled by a power of two near the segment's largest magnitude (exact while the scaled
        // terms stay out of the subnormal range): values and slopes near f64::MAX would otherwise
        // overflow in the products (a slope times h, a basis term) and meet as inf - inf = NaN.
        let largest = [self.v[i], self.v[i + 1], self.m[i], self.m[i + 1]]
            .iter()
            .fold(0.0f64, |a, x| a.max(x.abs()));
        // 2^e with e the exponent of `largest` (`log2` rounds f64::MAX up to 1024), at least
        // 2^-1022 (a zero segment stays zero).
        let e = (((largest.to_bits() >> 52) & 0x7ff) as i32 - 1023).max(-1022);
        let scale = f64::from_bits(((e + 1023) as u64) << 52);
        let (p0, p1) = (self.v[i] / scale, self.v[i + 1] / scale);
        let (m0, m1) = (self.m[i] / scale * h, self.m[i + 1] / scale * h);
        // Hermite basis and its derivatives in s.
        let (s2, s3) = (s * s, s * s * s);
        let v = (2.0 * s3 - 3.0 * s2 + 1.0) * p0
            + (s3 - 2.0 * s2 + s) * m0
            + (-2.0 * s3 + 3.0 * s2) * p1
            + (s3 - s2) * m1;
        let d = (6.0 * s2 - 6.0 * s) * p0
            + (3.0 * s2 - 4.0 * s + 1.0) * m0
            + (-6.0 * s2 + 6.0 * s) * p1
            + (3.0 * s2 - 2.0 * s) * m1;
        let dd = (12.0 * s - 6.0) * p0
            + (6.0 * s - 4.0) * m0
            + (-12.0 * s + 6.0) * p1
            + (6.0 * s - 2.0) * m1;
        (v * scale, d / h * scale, dd / (h * h) * scale)
    }

    /// The largest magnitude of the rate over the table (the rate is constant beyond it): at the
    /// knots or where a segment's rate, a quadratic, turns.
    pub fn max_rate(&self) -> f64 {
        let mut best = self.m.iter().fold(0.0f64, |a, m| a.max(m.abs()));
        for i in 0..self.t.len() - 1 {
            // The rate in s is quadratic: 6 (s^2 - s)(p0 - p1) + (3s^2 - 4s + 1) m0 + (3s^2 - 2s) m1,
            // with m0, m1 the slopes times h; it turns where its derivative vanishes.
            let h = self.t[i + 1] - self.t[i];
            let (p0, p1, m0, m1) = (self.v[i], self.v[i + 1], self.m[i] * h, self.m[i + 1] * h);
            let a2 = 6.0 * (p0 - p1) + 3.0 * (m0 + m1);
            let a1 = -6.0 * (p0 - p1) - 4.0 * m0 - 2.0 * m1;
            if a2 != 0.0 {
                let s = -a1 / (2.0 * a2);
                if s > 0.0 && s < 1.0 {
                    best = best.max(self.eval(self.t[i] + s * h).1.abs());
                }
            }
        }
        best
    }
}

/// What a table drives.
#[derive(Clone, Debug, PartialEq)]
pub enum PrescribedPath {
    /// Rotation by the table's angle (rad, relative to its value at t = 0) about the unit `axis`
    /// through the body's frame origin.
    Angle {
        /// Unit axis, world.
        axis: Vector,
    },
    /// Translation by the table's position (m, relative to its value at t = 0) along the unit
    /// `direction`.
    Position {
        /// Unit direction, world.
        direction: Vector,
    },
}

/// One kinematic (position-based) body on a table.
#[derive(Clone, Debug, PartialEq)]
pub struct PrescribedMotion {
    /// The body.
    pub body: RigidBodyHandle,
    /// Its pose at t = 0.
    pub start: Pose,
    /// Angle or position.
    pub path: PrescribedPath,
    /// The table.
    pub table: Table,
}

impl PrescribedMotion {
    /// `body` turned by `table`'s angle (rad) about `axis` (world, normalised here) through its
    /// frame origin, from `start`; refuses a zero or non-finite axis, naming `axis`.
    pub fn angle(body: RigidBodyHandle, start: Pose, axis: Vector, table: Table) -> Result<Self> {
        let axis = unit("axis", axis)?;
        let path = PrescribedPath::Angle { axis };
        Ok(PrescribedMotion {
            body,
            start,
            path,
            table,
        })
    }

    /// `body` moved by `table`'s position (m) along `direction` (world, normalised here) from
    /// `start`; refuses a zero or non-finite direction, naming `direction`.
    pub fn position(
        body: RigidBodyHandle,
        start: Pose,
        direction: Vector,
        table: Table,
    ) -> Result<Self> {
        let direction = unit("direction", direction)?;
        let path = PrescribedPath::Position { direction };
        Ok(PrescribedMotion {
            body,
            start,
            path,
            table,
        })
    }

    /// Whether this motion can be honoured in `bodies`: its body is there and kinematic
    /// position-based (Rapier moves no other kind to a pose), its axis or direction a unit vector
    /// (else the pose's rotation is not one). Errors name `motions[index]` and the field.
    pub(crate) fn check(&self, index: usize, bodies: &RigidBodySet) -> Result<()> {
        let at = |field: &str| format!("motions[{index}].{field}");
        let Some(rb) = bodies.get(self.body) else {
            return Err(Error::invalid(
                at("body"),
                "is not in the world's bodies (removed, invalid or of another world): prescribe \
                 the motion of a body of this world",
            ));
        };
        if rb.body_type() != RigidBodyType::KinematicPositionBased {
            return Err(Error::invalid(
                at("body"),
                format!(
                    "is a {:?} body, which Rapier does not move to a prescribed pose: build it \
                     with `RigidBodyBuilder::kinematic_position_based()`",
                    rb.body_type()
                ),
            ));
        }
        let (field, v) = match self.path {
            PrescribedPath::Angle { axis } => ("path.axis", axis),
            PrescribedPath::Position { direction } => ("path.direction", direction),
        };
        if !v.is_finite() || (v.length() - 1.0).abs() > 1e-9 {
            return Err(Error::invalid(
                at(field),
                format!(
                    "must be a unit vector (got length {}): give a unit vector, or build the \
                     motion with `PrescribedMotion::angle` or `::position`, which normalise it",
                    crate::error::sig4(v.length())
                ),
            ));
        }
        Ok(())
    }

    /// The body's pose at `t`.
    pub fn pose(&self, t: f64) -> Pose {
        let (x, _, _) = self.table.eval(t);
        let x0 = self.table.eval(0.0).0;
        match self.path {
            PrescribedPath::Angle { axis } => {
                let r = Rotation::from_axis_angle(axis, x - x0);
                Pose::from_parts(self.start.translation, r * self.start.rotation)
            }
            PrescribedPath::Position { direction } => Pose::from_parts(
                self.start.translation + direction * (x - x0),
                self.start.rotation,
            ),
        }
    }

    /// Velocity and acceleration of the frame origin and angular velocity and acceleration at
    /// `t`: `(v, a, w, alpha)`.
    pub fn rates(&self, t: f64) -> (Vector, Vector, Vector, Vector) {
        let (_, d, dd) = self.table.eval(t);
        match self.path {
            PrescribedPath::Angle { axis } => (Vector::ZERO, Vector::ZERO, axis * d, axis * dd),
            PrescribedPath::Position { direction } => {
                (direction * d, direction * dd, Vector::ZERO, Vector::ZERO)
            }
        }
    }
}

/// The tabulated motions of a world, a participant in the stepper's steps (it sets poses, not
/// forces).
#[derive(Clone, Debug, Default)]
pub struct PrescribedSet {
    /// The motions.
    pub motions: Vec<PrescribedMotion>,
}

/// The tabulated motions take part in the stepper's steps: each Rapier step (a retried one
/// included) gets the bodies' poses at its end time ([`crate::rapier::pipeline::step_hooks`]).
impl StepHooks for PrescribedSet {
    fn check_bodies(&self, bodies: &RigidBodySet) -> Result<()> {
        for (i, m) in self.motions.iter().enumerate() {
            m.check(i, bodies)?;
        }
        Ok(())
    }

    fn before_rapier_step(&mut self, context: RapierStepContext<'_>) {
        for m in &self.motions {
            if let Some(rb) = context.world.bodies.get_mut(m.body) {
                rb.set_next_kinematic_position(m.pose(context.t0 + context.dt));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_near_the_largest_float_give_no_nan() {
        // Found by tests/numeric_inputs.rs: a slope times the segment's length overflowed, and
        // the Hermite sum met inf - inf.
        let table = Table::new(
            &[-1.3250567694746097e-14, 85212.86925059001],
            &[f64::MAX, 0.0],
        )
        .unwrap();
        let (v, d, dd) = table.eval(0.0);
        assert!(
            v.is_finite() && d.is_finite() && dd.is_finite(),
            "{v} {d} {dd}"
        );
        // The segment is a straight line (both end slopes are the secant's): v, the secant.
        let secant = -f64::MAX / (85212.86925059001 + 1.3250567694746097e-14);
        assert!((d / secant - 1.0).abs() < 1e-12, "{d} against {secant}");
        assert!((v / f64::MAX - 1.0).abs() < 1e-12, "{v}");
        let all_zero = Table::new(&[0.0, 1.0], &[0.0, 0.0]).unwrap();
        assert_eq!(all_zero.eval(0.5), (0.0, 0.0, 0.0));
    }

    #[test]
    fn hermite_table_by_hand() {
        // A parabola sampled at 0, 1, 2, 3: v = t^2. Interior slopes are the central
        // differences 2, 4 (exact for a parabola); the ends are one-sided, 1 and 5.
        let t = Table::new(&[0.0, 1.0, 2.0, 3.0], &[0.0, 1.0, 4.0, 9.0]).unwrap();
        let (v, d, dd) = t.eval(1.5);
        // Between exact slopes 2 and 4 the Hermite cubic is the parabola itself.
        assert!((v - 2.25).abs() < 1e-12 && (d - 3.0).abs() < 1e-12 && (dd - 2.0).abs() < 1e-12);
        // Knots are hit exactly, with continuous slope.
        let (v, d, _) = t.eval(2.0);
        assert!((v - 4.0).abs() < 1e-12 && (d - 4.0).abs() < 1e-12);
        // Beyond the end: along the end slope (5), no acceleration.
        assert_eq!(t.eval(4.0), (14.0, 5.0, 0.0));
        assert!(Table::new(&[0.0, 0.0], &[1.0, 2.0]).is_err());
        // In the last segment (knot slopes 4 and 5, one-sided at the end) the rate is
        // -3 s^2 + 4 s + 4, largest at s = 2/3: 16/3, above both knots'.
        assert!(
            (t.max_rate() - 16.0 / 3.0).abs() < 1e-12,
            "{}",
            t.max_rate()
        );
        // 0, 1, 0: slopes 1, 0, -1; the first segment's rate -3 s^2 + 2 s + 1 peaks at 4/3.
        let hump = Table::new(&[0.0, 1.0, 2.0], &[0.0, 1.0, 0.0]).unwrap();
        assert!((hump.max_rate() - 4.0 / 3.0).abs() < 1e-12);
        assert!(t.eval(f64::NAN).0.is_nan());
        assert!(Table::new(&[0.0, 1.0], &[-1e308, 1e308]).is_err());
        assert!(Table::new(&[0.0], &[1.0]).is_err());
        assert!(Table::new(&[0.0, 1.0], &[1.0]).is_err());
    }
}
