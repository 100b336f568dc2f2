//! Hand-checked pieces of the sub-cycle: the implicit slip and the time to the wall.

use super::steps::{implicit_slip, time_to_wall};
use super::*;
use crate::model::laws::Coulomb;
use rapier3d_f64::math::Rotation;

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

/// Coulomb's slip in closed form is the root the bracket finds without it, across the stick
/// and the sliding piece and the kink between them.
#[test]
fn coulombs_closed_form_slip_is_the_bracketed_root() {
    use crate::model::laws::FrictionLaw;
    // The law without its closed form: the bracket solves it.
    struct Bracketed(Coulomb);
    impl FrictionLaw for Bracketed {
        fn coefficient(&self, v: f64) -> f64 {
            self.0.coefficient(v)
        }
        fn max_coefficient(&self) -> f64 {
            self.0.max_coefficient()
        }
    }
    let law = Coulomb::new(0.1, 1e-4).unwrap();
    assert!(law.closed_form_slip(1e-3, 0.01).is_some());
    for c0 in [1e-7, 1e-5, 9e-5, 1e-4, 1.0001e-4, 3e-4, 1e-3, 1e-2, 1.0] {
        for k in [1e-6, 1e-4, 1e-3, 1e-2, 0.1, 10.0] {
            for sign in [1.0, -1.0] {
                let x = implicit_slip(&law, sign * c0, k);
                let root = implicit_slip(&Bracketed(law), sign * c0, k);
                assert!(
                    (x - root).abs() <= 2e-14 * c0,
                    "c0 {c0} k {k}: closed form {x:e}, bracket {root:e}"
                );
                let residual = x.abs() + k * law.coefficient(x.abs()) - c0;
                assert!(residual.abs() <= 1e-15 * c0, "c0 {c0} k {k}: {residual:e}");
            }
        }
    }
}

/// The implicit slip under the paper's dry law (Bai's: steep below 0.1 mm/s, falling to `mu_d`
/// above) reaches its bracket's width in a few of the law's evaluations, from the stick region
/// to sliding: it is solved at every sub-step in contact.
#[test]
fn implicit_slip_takes_few_evaluations() {
    use crate::model::laws::{Bai, FrictionLaw};
    use std::cell::Cell;
    struct Counted(Bai, Cell<u32>);
    impl FrictionLaw for Counted {
        fn coefficient(&self, v: f64) -> f64 {
            self.1.set(self.1.get() + 1);
            self.0.coefficient(v)
        }
        fn max_coefficient(&self) -> f64 {
            self.0.max_coefficient()
        }
    }
    let law = Counted(Bai::DRY, Cell::new(0));
    // Slips before friction from 1 um/s to 1 m/s, against friction's reach of 1 um/s to 10 m/s.
    for c0 in [1e-6, 1e-5, 3e-5, 1e-4, 3e-4, 1e-3, 1e-2, 0.1, 1.0] {
        for k in [1e-6, 1e-4, 1e-3, 1e-2, 0.1, 10.0] {
            law.1.set(0);
            let x = implicit_slip(&law, c0, k);
            let calls = law.1.get();
            let residual = x + k * law.0.coefficient(x) - c0;
            assert!((0.0..=c0).contains(&x), "c0 {c0} k {k}: {x}");
            // The root to the bracket's width, or the stick at zero slip.
            assert!(
                residual.abs() <= 1e-9 * c0 || x == 0.0,
                "c0 {c0} k {k}: x {x}, residual {residual:e}"
            );
            assert!(calls <= 25, "c0 {c0} k {k}: {calls} evaluations");
        }
    }
}

/// A body's turn over a step, read back from the rotation, at every size: 1e-10 rad is a free
/// satellite's turn in a world step of 1e-6 s (glam's `to_scaled_axis` reads it as none).
#[test]
fn rotation_vector_reads_the_smallest_turns() {
    use super::pair::rotation_vector;
    let axis = Vector::new(0.36, -0.48, 0.8);
    for angle in [1e-12, 1e-10, 1e-8, 3e-8, 1e-4, 1.0, 3.0] {
        let turn = axis * angle;
        let read = rotation_vector(Rotation::from_scaled_axis(turn));
        assert!((read - turn).length() <= 1e-14 * angle, "{angle}: {read:?}");
    }
    // The shorter way round: a turn of 3.5 rad about the axis is 2 pi - 3.5 the other way.
    let read = rotation_vector(Rotation::from_scaled_axis(axis * 3.5));
    assert!(
        (read + axis * (std::f64::consts::TAU - 3.5)).length() < 1e-12,
        "{read:?}"
    );
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

/// A body spinning more than half a turn per step turns the long way round: the turn read is
/// the one its velocities expect, whole turns added or taken, and a quaternion of either sign.
#[test]
fn a_fast_turn_is_read_the_way_the_velocities_go() {
    use super::pair::turn_near;
    let axis = Vector::new(0.36, -0.48, 0.8);
    for angle in [1e-9, 0.5, 3.5, 5.0, 7.0, -4.0] {
        let turn = axis * angle;
        for q in [
            Rotation::from_scaled_axis(turn),
            -Rotation::from_scaled_axis(turn),
        ] {
            let read = turn_near(q, turn * 0.97);
            assert!(
                (read - turn).length() <= 1e-12 * angle.abs().max(1.0),
                "{angle}: {read:?}"
            );
        }
    }
}
