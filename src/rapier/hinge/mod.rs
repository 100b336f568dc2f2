//! The hinge's design, shared by both joint models ([`design`]), and the conversions between
//! Rapier's revolute joint and a clearance joint ([`convert`]).

pub mod convert;
pub mod design;

#[cfg(test)]
mod tests;
