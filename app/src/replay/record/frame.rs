//! One kept state of a replay: the bodies' poses and each journal in its bearing.

use serde::{Deserialize, Serialize};

/// One journal at one state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct JournalFrame {
    /// Eccentricity along the bearing's `u`, m.
    pub ecc_u_m: f64,
    /// Eccentricity along the bearing's `v`, m.
    pub ecc_v_m: f64,
    /// Contact force on the journal along `u`, N.
    pub force_u_n: f64,
    /// Contact force on the journal along `v`, N.
    pub force_v_n: f64,
    /// Contact force magnitude, N.
    pub force_n: f64,
    /// Penetration (0 when apart), m.
    pub penetration_m: f64,
    /// In contact at this state.
    pub contact: bool,
    /// A contact began at this state with an impact (approach speed above the joint's floor).
    pub impact: bool,
    /// A spatial joint's tilt, axial offset and edge and face forces (`None` for a planar
    /// joint, and then absent from the serialized frame).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spatial: Option<SpatialFrame>,
}

/// A spatial journal at one state, in the bearing's frame: `u`, `v` (as [`JournalFrame`]'s
/// eccentricity) and the axis `a`, from the bearing's centre.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SpatialFrame {
    /// The journal axis's tilt about `u` and about `v`, rad (the scene runner's
    /// `tilt_u_deg`/`tilt_v_deg` columns, in rad).
    pub tilt_rad: [f64; 2],
    /// The journal's axial offset along `a`, m.
    pub axial_m: f64,
    /// Normal resultant of the bore at its lower (`-L/2`) and upper (`+L/2`) end, N.
    pub edge_force_n: [f64; 2],
    /// Where each edge resultant acts, `[u, v, a]` from the bearing's centre, m (the centre
    /// while it carries nothing).
    pub edge_at_m: [[f64; 3]; 2],
    /// Normal resultant of the lower and upper shoulder face, N.
    pub face_force_n: [f64; 2],
    /// Where each face resultant acts, `[u, v, a]` from the bearing's centre, m.
    pub face_at_m: [[f64; 3]; 2],
}

/// One kept state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReplayFrame {
    /// Time, s.
    pub t: f64,
    /// Pose of every tracked body: position (m) and rotation quaternion, `[x, y, z, qx, qy, qz, qw]`.
    pub poses: Vec<[f64; 7]>,
    /// Every tracked journal, in tracking order.
    pub journals: Vec<JournalFrame>,
}
