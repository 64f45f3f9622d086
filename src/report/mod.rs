//! Reports: what a run measured, as files a person or a plot reads. summary.json holds every
//! simulated metric with its unit in the key (`_s`, `_bytes`, `_pct`) and is byte-identical for
//! identical inputs; cost.json holds what the simulation cost the host (wall time, events,
//! peak memory) and is not deterministic by nature.
//!
//! Owns formatting and writing. Must never run a simulation, and never leave a half-written
//! file: everything goes through `write_atomic`.

pub mod accuracy;
pub mod bench;
pub mod calibration;
pub mod default_job;
pub mod netsim;
pub mod paper;
pub mod run;
pub mod sweep;
pub mod trace;
pub mod utilization;
pub mod validate;
