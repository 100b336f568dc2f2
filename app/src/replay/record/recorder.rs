//! The recorder: what it tracks, and each state it reads from the world.

use super::journal::{journal_frame, substep_frame};
use super::shapes::body_shapes;
use super::*;
use clearance_joint::model::kinematics::in_plane_u;

impl ReplayRecorder {
    /// A recorder keeping a state per `interval` s in free flight and per `contact_interval`
    /// s while a journal is in contact (`0 < contact_interval <= interval`).
    pub fn new(interval: f64, contact_interval: f64) -> Result<Self> {
        if !(interval.is_finite() && interval > 0.0) {
            return Err(Error::invalid("interval", "must be a positive time, s"));
        }
        if !(contact_interval.is_finite() && contact_interval > 0.0 && contact_interval <= interval)
        {
            return Err(Error::invalid(
                "contact_interval",
                "must be a positive time no longer than `interval`, s",
            ));
        }
        Ok(ReplayRecorder {
            recording: Recording {
                interval_s: interval,
                contact_interval_s: contact_interval,
                ..Recording::default()
            },
            handles: Vec::new(),
            joints: Vec::new(),
            pending: None,
            peak: None,
            in_contact: false,
            onset: f64::NEG_INFINITY,
            last_kept: f64::NEG_INFINITY,
            max_frames: usize::MAX,
            spare: Vec::new(),
            scratch: [empty_frame(), empty_frame()],
            times: Vec::new(),
        })
    }

    /// The recorder keeping at most `max_frames` frames (at least 4), halving its frames and
    /// doubling its intervals whenever it reaches them (see the module docs' cap).
    pub fn with_max_frames(mut self, max_frames: usize) -> Self {
        self.max_frames = max_frames.max(4);
        self
    }

    /// Tracks a body (in group `group`), its shapes from its colliders or its mass properties
    /// (see [`ReplayBody::shapes`]; call after the mass properties are known: Rapier computes
    /// them in the first step,
    /// [`prepare_mass_properties`](clearance_joint::rapier::observers::reaction::prepare_mass_properties) before it).
    /// Returns its index.
    pub fn track_body(
        &mut self,
        name: &str,
        group: &str,
        handle: RigidBodyHandle,
        bodies: &RigidBodySet,
        colliders: &ColliderSet,
    ) -> usize {
        let shapes = bodies
            .get(handle)
            .map(|rb| body_shapes(rb, colliders))
            .unwrap_or_default();
        self.recording.bodies.push(ReplayBody {
            name: name.into(),
            group: group.into(),
            shapes,
        });
        self.handles.push(handle);
        self.handles.len() - 1
    }

    /// The index of a tracked body, by handle.
    fn body_index(&self, handle: RigidBodyHandle, field: &str) -> Result<usize> {
        self.handles
            .iter()
            .position(|&h| h == handle)
            .ok_or_else(|| Error::invalid(field, "its body is not tracked: track it first"))
    }

    /// Tracks clearance joint `handle` of `set`, the set passed `set_index`-th to
    /// [`record`](Self::record). Its two bodies must be tracked already.
    pub fn track_journal(
        &mut self,
        name: &str,
        group: &str,
        set_index: usize,
        handle: ClearanceJointHandle,
        set: &ClearanceJointSet,
    ) -> Result<()> {
        let joint = set
            .get(handle)
            .ok_or_else(|| Error::invalid(name, "no such clearance joint in this set"))?;
        let g = joint.geometry();
        let axis1 = joint.local_axis1();
        let u1 = in_plane_u(axis1);
        self.recording.journals.push(ReplayJournal {
            name: name.into(),
            group: group.into(),
            bearing: self.body_index(joint.body1(), name)?,
            journal: self.body_index(joint.body2(), name)?,
            anchor1_m: joint.local_anchor1().to_array(),
            anchor2_m: joint.local_anchor2().to_array(),
            axis1: axis1.to_array(),
            u1: u1.to_array(),
            clearance_m: g.clearance(),
            bearing_radius_m: g.bearing_radius(),
            width_m: g.length(),
            axial_play_m: joint.spatial_model().map(|m| m.geometry.axial_play),
        });
        self.joints.push((set_index, handle));
        Ok(())
    }

    /// Tracks an ideal hinge between two tracked bodies, drawn as a pin.
    pub fn track_pin(
        &mut self,
        name: &str,
        group: &str,
        body1: RigidBodyHandle,
        body2: RigidBodyHandle,
        anchor1: Vector,
        axis1: Vector,
    ) -> Result<()> {
        let pin = ReplayPin {
            name: name.into(),
            group: group.into(),
            body1: self.body_index(body1, name)?,
            body2: self.body_index(body2, name)?,
            anchor1_m: anchor1.to_array(),
            axis1: axis1.normalize_or_zero().to_array(),
        };
        self.recording.pins.push(pin);
        Ok(())
    }

    /// Records the state at time `t` (call after each step; `sets` as given to
    /// [`track_journal`](Self::track_journal)). Keeps it or not by the thinning rule.
    pub fn record(&mut self, t: f64, bodies: &RigidBodySet, sets: &[&ClearanceJointSet]) {
        // The states are built in the recorder's scratch frames, which the thinning keeps or
        // trades for spare ones: a step's states allocate nothing once it has spares.
        let [mut end, mut inside] =
            std::mem::replace(&mut self.scratch, [empty_frame(), empty_frame()]);
        self.fill_frame(&mut end, t, bodies, sets);
        self.record_inside(&end, &mut inside, bodies, sets);
        self.record_frame(&mut end);
        self.scratch = [end, inside];
    }

    /// Sets `frame` to the state at time `t`.
    fn fill_frame(
        &self,
        frame: &mut ReplayFrame,
        t: f64,
        bodies: &RigidBodySet,
        sets: &[&ClearanceJointSet],
    ) {
        frame.t = t;
        // Exact capacities: a kept frame keeps its vectors (`extend` into an empty vector
        // would reserve room for 4 journals where there is 1).
        frame.poses.clear();
        frame.poses.reserve_exact(self.handles.len());
        frame
            .poses
            .extend(self.handles.iter().map(|&h| match bodies.get(h) {
                Some(rb) => {
                    let (p, q) = (rb.translation(), *rb.rotation());
                    [p.x, p.y, p.z, q.x, q.y, q.z, q.w]
                }
                None => [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
            }));
        frame.journals.clear();
        frame.journals.reserve_exact(self.joints.len());
        frame
            .journals
            .extend(
                self.joints
                    .iter()
                    .zip(&self.recording.journals)
                    .map(|(&(set, h), track)| {
                        let Some(joint) = sets.get(set).and_then(|s| s.get(h)) else {
                            return JournalFrame::default();
                        };
                        journal_frame(joint, bodies, track)
                    }),
            );
    }

    /// Records the states inside the step that led to `end` of the sub-cycled joints
    /// ([`ClearanceJoint::substeps`]), in time order (each built in `inside`): each such joint
    /// at its sub-step, the other journals as at the step's end (or at their own latest
    /// sub-step before), the bodies drawn at the step's end (they move little within a step
    /// against the journal in its play).
    fn record_inside(
        &mut self,
        end: &ReplayFrame,
        inside: &mut ReplayFrame,
        bodies: &RigidBodySet,
        sets: &[&ClearanceJointSet],
    ) {
        let joint = |&(set, h): &(usize, ClearanceJointHandle)| sets.get(set)?.get(h);
        let mut times = std::mem::take(&mut self.times);
        times.clear();
        for j in self.joints.iter().filter_map(joint) {
            if let Some((last, within)) = j.substeps().split_last() {
                let start = end.t - last.t;
                times.extend(within.iter().map(|s| start + s.t));
            }
        }
        if !times.is_empty() {
            times.sort_by(f64::total_cmp);
            times.dedup();
            for &t in &times {
                inside.t = t;
                copy_into(&mut inside.poses, &end.poses);
                copy_into(&mut inside.journals, &end.journals);
                for ((k, id), track) in self.joints.iter().enumerate().zip(&self.recording.journals)
                {
                    let Some(j) = joint(id) else { continue };
                    let Some(last) = j.substeps().last() else {
                        continue;
                    };
                    let start = end.t - last.t;
                    if let Some(s) = j.substeps().iter().rev().find(|s| start + s.t <= t) {
                        let rotation: Rotation = bodies
                            .get(j.body1())
                            .map(|rb| *rb.rotation())
                            .unwrap_or_default();
                        inside.journals[k] = substep_frame(s, rotation, track);
                    }
                }
                self.record_frame(inside);
            }
        }
        self.times = times;
    }

    /// The frames kept so far.
    pub fn frames(&self) -> &[ReplayFrame] {
        &self.recording.frames
    }

    /// The recording, with the last state recorded kept.
    pub fn finish(mut self) -> Recording {
        if let Some(last) = self.pending.take() {
            self.push_after_peak(last);
        }
        self.recording
    }
}

/// A frame of no state, whose vectors a recorded state fills.
pub(super) fn empty_frame() -> ReplayFrame {
    ReplayFrame {
        t: 0.0,
        poses: Vec::new(),
        journals: Vec::new(),
    }
}

/// Sets `to` to `from`, in `to`'s memory when it is large enough, else in memory of exactly
/// `from`'s length (a kept frame's vectors hold no spare room).
pub(super) fn copy_into<T: Copy>(to: &mut Vec<T>, from: &[T]) {
    to.clear();
    to.reserve_exact(from.len());
    to.extend_from_slice(from);
}
