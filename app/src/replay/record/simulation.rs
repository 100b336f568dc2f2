//! Recording the library's scene runner: both twins' bodies and hinges, read from a
//! [`Simulation`] through its public view ([`Twin::bodies`], [`Twin::hinges`]).

use super::*;
use clearance_joint::rapier::pipeline::world::ClearanceWorld;
use clearance_joint::scene::runner::{HingeJoint, Simulation, Twin};

impl ReplayRecorder {
    /// A recorder tracking both twins of `sim` (groups `ideal` and `clearance`), keeping a state
    /// per `interval` s in free flight and per `contact_interval` s in contact; feed it with
    /// [`record_simulation`](Self::record_simulation), e.g. from
    /// [`Simulation::run_observed`].
    pub fn for_simulation(sim: &Simulation, interval: f64, contact_interval: f64) -> Result<Self> {
        let mut recorder = ReplayRecorder::new(interval, contact_interval)?;
        for twin in &sim.twins {
            recorder.track_twin(twin, &sim.world)?;
        }
        Ok(recorder)
    }

    /// Tracks a twin's bodies and hinges (group: the twin's name): clearance hinges as journals
    /// of the world's clearance set (the first set [`record`](Self::record) is given), ideal and
    /// large-step hinges as pins at their point.
    pub fn track_twin(&mut self, twin: &Twin, world: &ClearanceWorld) -> Result<()> {
        let group = twin.kind.name();
        let physics = &world.rapier;
        for (name, handle) in twin.bodies() {
            self.track_body(name, group, handle, &physics.bodies, &physics.colliders);
        }
        for h in twin.hinges() {
            match h.joint {
                HingeJoint::Clearance(c) => {
                    self.track_journal(h.name, group, 0, c, &world.clearance)?
                }
                // The replay draws journals of the compliant set only: a large-step hinge is
                // drawn as a pin (its orbit is in the rows).
                HingeJoint::Ideal | HingeJoint::LargeStep(_) => self.track_pin(
                    h.name,
                    group,
                    h.bearing,
                    h.journal,
                    h.local_anchor1,
                    h.local_axis1,
                )?,
            }
        }
        Ok(())
    }

    /// Records the current state of `sim` (tracked by [`for_simulation`](Self::for_simulation)).
    pub fn record_simulation(&mut self, sim: &Simulation) {
        self.record(
            sim.time(),
            &sim.world.rapier.bodies,
            &[&sim.world.clearance],
        );
    }
}
