//! What a simulation measured, as plain serializable data: a run's summary (`run`) and the
//! machine's per-node and per-link metrics (`machine`). Sits between the simulation (`algo`,
//! `engine`) and everything that reads results (sweeps, papers, reports); never formats for
//! a person and never holds anything that depends on the host.

pub mod machine;
pub mod run;
