//! The hinge's specification, shared by both joint models, and the conversions between Rapier's
//! revolute joint and a clearance joint ([`convert`]).

pub mod convert;
