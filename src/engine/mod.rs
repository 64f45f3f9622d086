//! The deterministic discrete-event engine: a clock, an event queue and a single-threaded
//! executor that runs one async program per simulated node, plus helper programs (message
//! handlers, send threads).
//!
//! # Ordering contract
//! - Events are processed in (time, insertion sequence) order: FIFO on ties.
//! - An event is processed in full, including every program it wakes, in the order they were
//!   woken, before the next event; programs spawned at the same instant start in spawn order.
//! - Each node's cpu serves `compute` requests first come, first served (no preemption).
//! - Randomness comes only from named ChaCha streams derived from the run's seed
//!   (`Node::rng`); no wall-clock time, OS randomness or hash-map order reaches a result.
//!
//! Programs see only their `Node` handle: they compute, send, receive, broadcast, sleep and
//! allocate through it. This module knows nothing about triangles, pixels or algorithms, and
//! never looks inside a payload except through `Payload::tag`.

mod executor;
mod node;
mod queue;
mod rng;
mod slices;
mod stats;
mod wakes;

pub use executor::{ProgramId, Sim, SimError, WaitingProgram};
pub use node::{Envelope, Filter, Node, Payload};
pub use queue::EventQueue;
pub use rng::rng_stream;
pub use stats::{CpuSpan, NodeStats, RunStats};
