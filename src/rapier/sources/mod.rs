//! Force sources and motions beside the joints: [`drive`] (torsion springs and torques) and
//! [`prescribed`] (tabulated motions of kinematic bodies).

pub mod drive;
pub mod prescribed;
