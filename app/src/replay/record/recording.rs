//! What a replay holds: the tracked bodies, journals and pins, and the kept frames.

use super::ReplayFrame;
use serde::{Deserialize, Serialize};

/// A shape drawn for a body, in the body's frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ReplayShape {
    /// A box.
    Box {
        /// Half extents along the box's axes, m.
        half_extents_m: [f64; 3],
        /// Centre in the body's frame, m.
        center_m: [f64; 3],
        /// Rotation from the box's axes to the body's frame (quaternion x, y, z, w).
        rotation: [f64; 4],
    },
    /// A cylinder along its own y axis.
    Cylinder {
        /// Radius, m.
        radius_m: f64,
        /// Half height, m.
        half_height_m: f64,
        /// Centre in the body's frame, m.
        center_m: [f64; 3],
        /// Rotation from the cylinder's axes to the body's frame (quaternion x, y, z, w).
        rotation: [f64; 4],
    },
    /// A ball.
    Ball {
        /// Radius, m.
        radius_m: f64,
        /// Centre in the body's frame, m.
        center_m: [f64; 3],
    },
}

/// A tracked body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReplayBody {
    /// Name shown.
    pub name: String,
    /// Group (e.g. the twin: `ideal`, `clearance`); groups are drawn side by side.
    pub group: String,
    /// Its shapes: its colliders' (boxes, cylinders, balls), else the box with its mass and
    /// principal inertia (a uniform box's `a_x^2 = 6 (J_y + J_z - J_x) / m`), else none (a fixed
    /// body without colliders: the viewer sizes it from the joint points).
    pub shapes: Vec<ReplayShape>,
}

/// A tracked clearance joint: where its bearing and journal are on their bodies.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReplayJournal {
    /// Name shown.
    pub name: String,
    /// Group, as the bodies'.
    pub group: String,
    /// Index (in [`Recording::bodies`]) of the body carrying the bearing.
    pub bearing: usize,
    /// Index of the body carrying the journal.
    pub journal: usize,
    /// Bearing centre in the bearing body's frame, m.
    pub anchor1_m: [f64; 3],
    /// Journal centre in the journal body's frame, m.
    pub anchor2_m: [f64; 3],
    /// Axis in the bearing body's frame (unit).
    pub axis1: [f64; 3],
    /// In-plane direction `u` of the inset (bearing frame, unit; `v = axis x u`).
    pub u1: [f64; 3],
    /// Radial clearance `c`, m.
    pub clearance_m: f64,
    /// Bearing radius, m.
    pub bearing_radius_m: f64,
    /// Bearing width, m.
    pub width_m: f64,
    /// A spatial joint's axial play (its journal's free axial travel when centred), m; `None`
    /// (and absent from the serialized journal) for a planar joint.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axial_play_m: Option<f64>,
}

/// An ideal hinge drawn as a pin (not sampled: its bodies' poses say all).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReplayPin {
    /// Name shown.
    pub name: String,
    /// Group, as the bodies'.
    pub group: String,
    /// Index of the first body.
    pub body1: usize,
    /// Index of the second body.
    pub body2: usize,
    /// Pin centre in the first body's frame, m.
    pub anchor1_m: [f64; 3],
    /// Axis in the first body's frame (unit).
    pub axis1: [f64; 3],
}

/// What a [`ReplayRecorder`](super::ReplayRecorder) recorded.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Recording {
    /// Tracked bodies.
    pub bodies: Vec<ReplayBody>,
    /// Tracked clearance joints.
    pub journals: Vec<ReplayJournal>,
    /// Ideal hinges drawn as pins.
    pub pins: Vec<ReplayPin>,
    /// Kept states, in time order.
    pub frames: Vec<ReplayFrame>,
    /// Free-flight frame interval, s.
    pub interval_s: f64,
    /// In-contact frame interval, s.
    pub contact_interval_s: f64,
}
