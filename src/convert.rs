//! Conversions between Rapier revolute joints and clearance joints (issue 5). Placeholder until built.
