//! This process's plumbing: its files in flight (removed on an interrupt), the folders it
//! claims, and the memory it may use.
//!
//! - [`files`]: result files written through this process's [`Staging`](clearance_joint::scene::output::Staging)
//!   ([`files::write_atomic`]), removed by the interrupt handler ([`files::remove_inflight`]);
//!   temporaries of dead processes removed by the next write into their folder.
//! - [`lock`]: a result folder claimed for one process ([`lock::DirLock`]).
//! - [`memory`]: a run's memory estimate, the machine's available memory, sizes as text.

pub mod files;
pub mod lock;
pub mod memory;
