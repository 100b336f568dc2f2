//! Revolute hinges with radial clearance for the Rapier physics engine (`rapier3d-f64`).
pub mod error;
pub mod laws;
pub use error::{Error, Result};
