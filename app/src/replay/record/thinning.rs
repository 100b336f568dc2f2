//! The recorder's thinning: which states a replay keeps, and its cap on frames.

use super::recorder::{copy_into, empty_frame};
use super::*;

impl ReplayRecorder {
    /// Records one state (thinned as [`record`](Self::record) says). Where the state is held
    /// (kept or pending) it is moved out of `frame`, which is left with a spare frame's vectors
    /// to be filled again: a state costs no copy, and no allocation once the recorder has
    /// spares.
    pub(super) fn record_frame(&mut self, frame: &mut ReplayFrame) {
        let t = frame.t;
        let contact = frame.journals.iter().any(|j| j.contact);
        let onset = contact && !self.in_contact;
        if onset {
            self.onset = t;
        }
        let dense = t - self.onset <= DENSE_FRAMES * self.recording.contact_interval_s;
        let spacing = if (contact || self.in_contact) && dense {
            self.recording.contact_interval_s
        } else {
            self.recording.interval_s
        };
        let keep = onset || t - self.last_kept >= spacing * (1.0 - 1e-9);
        if onset && let Some(before) = self.pending.take() {
            self.push_after_peak(before);
        }
        self.in_contact = contact;
        if keep {
            if let Some(old) = self.pending.take() {
                self.spare.push(old);
            }
            let frame = self.take(frame);
            self.push_after_peak(frame);
        } else {
            if self.peak.as_ref().is_none_or(|p| force(frame) > force(p)) {
                let peak = self.copy(frame);
                if let Some(old) = self.peak.replace(peak) {
                    self.spare.push(old);
                }
            }
            let pending = self.take(frame);
            if let Some(old) = self.pending.replace(pending) {
                self.spare.push(old);
            }
        }
    }

    /// The state in `frame`, which is left with a spare frame's vectors (or none).
    fn take(&mut self, frame: &mut ReplayFrame) -> ReplayFrame {
        let spare = self.spare.pop().unwrap_or_else(empty_frame);
        std::mem::replace(frame, spare)
    }

    /// A copy of `frame`, in a spare frame's vectors when there is one.
    fn copy(&mut self, frame: &ReplayFrame) -> ReplayFrame {
        let Some(mut copy) = self.spare.pop() else {
            return frame.clone();
        };
        copy.t = frame.t;
        copy_into(&mut copy.poses, &frame.poses);
        copy_into(&mut copy.journals, &frame.journals);
        copy
    }

    /// Keeps `frame`, after the state of largest force skipped since the last kept one when
    /// that force exceeds both neighbours' (a peak between kept states: so the recording's
    /// largest force is the run's, whatever the thinning).
    pub(super) fn push_after_peak(&mut self, frame: ReplayFrame) {
        if let Some(peak) = self.peak.take() {
            let before = self.recording.frames.last().map_or(0.0, force);
            if peak.t < frame.t && force(&peak) > before.max(force(&frame)) {
                self.push(peak);
            } else {
                self.spare.push(peak);
            }
        }
        self.push(frame);
    }

    fn push(&mut self, frame: ReplayFrame) {
        self.last_kept = frame.t;
        self.recording.frames.push(frame);
        if self.recording.frames.len() > self.max_frames {
            self.halve();
        }
    }

    /// Halves the frames kept (see the module docs' cap): the first and last stay, each pair
    /// between keeps its frame of larger force, with the other's impact flags.
    fn halve(&mut self) {
        let frames = std::mem::take(&mut self.recording.frames);
        let n = frames.len();
        let mut kept = Vec::with_capacity(n / 2 + 2);
        let mut it = frames.into_iter();
        kept.extend(it.next());
        let last = it.next_back();
        while let Some(a) = it.next() {
            kept.push(match it.next() {
                Some(b) => merge_pair(a, b),
                None => a,
            });
        }
        kept.extend(last);
        self.recording.frames = kept;
        self.recording.interval_s *= 2.0;
        self.recording.contact_interval_s *= 2.0;
    }
}

/// The largest contact force of a frame's journals, N.
pub(super) fn force(f: &ReplayFrame) -> f64 {
    f.journals.iter().map(|j| j.force_n).fold(0.0, f64::max)
}

/// The frame of `a` and `b` with the larger contact force, carrying the other's impact flags
/// (an impact's frame dropped still shows on the timeline).
pub(super) fn merge_pair(a: ReplayFrame, b: ReplayFrame) -> ReplayFrame {
    let (mut keep, drop) = if force(&b) > force(&a) {
        (b, a)
    } else {
        (a, b)
    };
    for (k, d) in keep.journals.iter_mut().zip(&drop.journals) {
        k.impact |= d.impact;
    }
    keep
}
