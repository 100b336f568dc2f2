//! The memory a replay holds at its peak, for the run's memory estimate.

use super::page::TEMPLATE;
use super::record::JournalFrame;
use super::{MAX_FRAMES, SPATIAL_NUMBERS};
use crate::process::memory::MemoryEstimate;
use clearance_joint::scene::Scene;

/// Characters per number in the page's JSON (7 significant digits, sign, exponent, comma).
const JSON_CHARS: u64 = 14;

/// The memory a replay of `scene` holds at its peak, bytes, an upper bound: [`MAX_FRAMES`]
/// frames of the tracked bodies (both twins') and journals, as the recorder stores them (a pose
/// of 7 numbers per body, 6 numbers, 2 flags and room for a spatial part per journal), and room
/// for a flattened copy of them and their JSON text three times over (the page is streamed
/// from the frames into its file and holds neither: room to spare). Measured: the paper's scene
/// at 5 times its torque for 3 s keeps 10,914 frames and peaks 6.6 MB above its run without a
/// replay (both `--no-figures`; 5.4 MB with the figures), 0.6 kB a frame, against 2.7 kB a frame
/// here.
pub fn memory_bytes(scene: &Scene) -> u64 {
    let bodies = 2 * scene.bodies.len() as u64;
    let journals = scene
        .hinges
        .iter()
        .filter(|h| h.clearance.is_some())
        .count() as u64;
    // A spatial scene's page carries SPATIAL_NUMBERS more per journal (`sf`).
    let spatial = if scene.hinges.iter().any(|h| h.is_spatial()) {
        SPATIAL_NUMBERS as u64 * journals
    } else {
        0
    };
    // A frame: time and two vectors' headers (8 + 48), their heap blocks (+ 32 of allocator);
    // a journal's frame holds room for the spatial part whether used or not.
    let journal = std::mem::size_of::<JournalFrame>() as u64;
    let recorded = 88 + 56 * bodies + journal * journals;
    let flattened = 8 + 56 * bodies + 49 * journals + 8 * spatial;
    let numbers = 1 + 7 * bodies + 7 * journals + spatial;
    let text = 3 * JSON_CHARS * numbers;
    // The frames' vector itself may be twice its length (growth by doubling).
    let per_frame = recorded + 56 + 2 * flattened + text;
    MAX_FRAMES as u64 * per_frame + TEMPLATE.len() as u64 * 3
}

/// The memory estimate of a run of `scene` ([`MemoryEstimate::of`]) with its replay when
/// `replay` ([`memory_bytes`]).
pub fn estimate(scene: &Scene, replay: bool) -> MemoryEstimate {
    let rows = MemoryEstimate::of(scene);
    if replay {
        rows.with_replay(memory_bytes(scene))
    } else {
        rows
    }
}
