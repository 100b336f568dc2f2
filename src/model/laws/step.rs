//! The cubic STEP function of MSC Adams (MODEL.md §2).

/// `STEP(x, x0, h0, x1, h1)`: `h0` for `x <= x0`, `h1` for `x >= x1`, and in between the cubic
/// `h0 + (h1 - h0) s^2 (3 - 2 s)` with `s = (x - x0)/(x1 - x0)`, which has zero slope at both ends.
///
/// ```
/// use clearance_joint::model::laws::step;
/// assert_eq!(step(0.5, 0.0, 0.0, 1.0, 2.0), 1.0);
/// assert_eq!(step(-1.0, 0.0, 0.0, 1.0, 2.0), 0.0);
/// ```
#[inline]
pub fn step(x: f64, x0: f64, h0: f64, x1: f64, h1: f64) -> f64 {
    if x <= x0 {
        h0
    } else if x >= x1 {
        h1
    } else {
        let s = (x - x0) / (x1 - x0);
        h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)
    }
}

/// Derivative of [`step`] with respect to `x`.
#[inline]
pub fn step_slope(x: f64, x0: f64, h0: f64, x1: f64, h1: f64) -> f64 {
    if x <= x0 || x >= x1 {
        0.0
    } else {
        let w = x1 - x0;
        let s = (x - x0) / w;
        (h1 - h0) * 6.0 * s * (1.0 - s) / w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_hand_values() {
        // s = 0.25: s^2 (3 - 2 s) = 0.0625 * 2.5 = 0.15625
        assert!((step(0.25, 0.0, 1.0, 1.0, 3.0) - (1.0 + 2.0 * 0.15625)).abs() < 1e-15);
        assert_eq!(step(2.0, 0.0, 1.0, 1.0, 3.0), 3.0);
        // slope at the midpoint: (h1-h0) * 6 * 0.25 / w = 2 * 1.5
        assert!((step_slope(0.5, 0.0, 1.0, 1.0, 3.0) - 3.0).abs() < 1e-15);
    }

    #[test]
    fn slope_matches_finite_difference() {
        let h = 1e-7;
        for x in [0.1, 0.37, 0.8] {
            let fd =
                (step(x + h, 0.0, -2.0, 1.0, 5.0) - step(x - h, 0.0, -2.0, 1.0, 5.0)) / (2.0 * h);
            assert!((fd - step_slope(x, 0.0, -2.0, 1.0, 5.0)).abs() < 1e-6);
        }
    }
}
