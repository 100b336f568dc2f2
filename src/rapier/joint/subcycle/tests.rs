//! Hand-checked pieces of the sub-cycle: the implicit slip and the time to the wall.

use super::steps::{implicit_slip, time_to_wall};
use super::*;
use crate::model::laws::Coulomb;

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
