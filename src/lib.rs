//! sortsim: a deterministic discrete-event simulator of parallel polygon-rendering machines.
//!
//! A run takes a machine spec (processors, cpu costs, network, memory), a scene and an
//! algorithm; it drives the real rasterizer on the real geometry, charges every operation and
//! message to simulated processors, links and memory pools, and reports simulated time,
//! traffic and memory. The data flow, one way:
//!
//! ```text
//! spec -> scene -> algo (node programs) -> engine (events) -> machine + net -> report
//! ```
//!
//! Everything the command line does is callable from here, so tests exercise the same code.
//!
//! ```
//! use sortsim::units::{Bandwidth, Bytes};
//! let link: Bandwidth = "17MB/s".parse().unwrap();
//! assert_eq!(link.transfer_time(Bytes::new(17_000_000)).to_string(), "1s");
//! ```

pub mod accuracy;
pub mod algo;
pub mod app;
pub mod bench;
pub mod calibrate;
pub mod engine;
pub mod host;
pub mod limits;
pub mod machine;
pub mod metrics;
pub mod net;
pub mod output;
pub mod paper;
pub mod raster;
pub mod report;
pub mod scene;
pub mod spec;
pub mod sweep;
pub mod trace;
pub mod units;
pub mod validate;
