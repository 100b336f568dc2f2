#![doc = include_str!("../../docs/MODEL.md")]
//!
//! # This layer in code
//!
//! Pure functions of numbers, no Rapier world: the contact and friction laws ([`laws`]), the
//! journal-bearing kinematics ([`kinematics`]) and the hinge angle from two body rotations
//! ([`angle`]). The only type borrowed from Rapier is its vector and rotation (glam's, which
//! Rapier re-exports).

pub mod angle;
pub mod kinematics;
pub mod laws;
pub mod spatial;
