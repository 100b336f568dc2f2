use super::flight_step;

#[test]
fn flight_step_by_hand() {
    // 0.0075 of a 0.5 mm gap is 3.75 um: 3.75 us at 1 m/s, 0.9375 us at 4 m/s.
    assert!((flight_step(0.0075, 0.5e-3, 1.0) - 3.75e-6).abs() < 1e-18);
    assert!((flight_step(0.0075, 0.5e-3, 4.0) - 0.9375e-6).abs() < 1e-18);
    assert_eq!(flight_step(0.0075, 0.5e-3, 0.0), f64::INFINITY);
}
