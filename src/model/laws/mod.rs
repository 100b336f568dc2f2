//! Contact and friction laws of MODEL.md §2-§3: pure functions of numbers, no Rapier.
//!
//! Each law is its own type implementing one trait per family ([`NormalForceLaw`],
//! [`FrictionLaw`]); the enums [`NormalModel`] and [`FrictionModel`] choose one by name and
//! dispatch statically. Constructors validate every parameter and return an [`Error`](crate::Error)
//! naming it.

mod friction;
mod impact;
mod material;
mod normal;
mod step;

pub use friction::*;
pub use impact::{
    contact_period, crossing_fraction, impact_restitution, loaded_impact_rate, speed_at_crossing,
    speed_at_crossing_in_substep,
};
pub use material::*;
pub use normal::*;
pub use step::step;
