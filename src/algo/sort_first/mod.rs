//! Sort-first rendering (Mueller 1995; the first of Molnar, Cox, Ellsworth and Fuchs's three
//! places to sort): processors own screen regions and keep the database records of the
//! primitives that fell in them last frame, so only primitives that cross into other
//! processors' regions move.
//!
//! One variant, `mueller` (the node program in `mueller.rs`). It runs on the image-space stages
//! it shares with sort-middle (`algo::image_space`: region grids, greedy assignment from summed
//! per-region counts, the frame barriers, the rasterization stage, and the host's book of who
//! holds which primitive); what is its own lives here: the options and the node program.
//!
//! Must never name a topology, and never let the host's book decide anything a processor
//! could not know: a holder of a primitive knows where it fell last frame, so it knows the
//! other holders.

pub mod mueller;
pub mod options;

use super::image_space::{self, Choice, FirstSettings, RegionChoice, DATABASE_BYTES_PER_TRIANGLE};
use super::options::parse;
use super::{RunConfig, RunError, RunResult};
pub use options::SortFirstOptions;

/// Reads sort-first's options.
fn choice(cfg: &RunConfig) -> Result<Choice, RunError> {
    let (f, aa) = parse::<SortFirstOptions>(&cfg.options, cfg.algo.id())?;
    Ok(Choice {
        regions: RegionChoice::PerProcessor(f.granularity.0),
        buffer: f.buffer.0,
        counts: image_space::options::CountsFrom::Previous,
        two_step: image_space::options::TwoStep::Off,
        polygon_estimate: None,
        aa,
        first: FirstSettings {
            regions: f.regions,
            migrate: f.migrate,
        },
        record_bytes: DATABASE_BYTES_PER_TRIANGLE,
    })
}

/// Checks sort-first's options against `cfg` without running it.
pub fn check(cfg: &RunConfig) -> Result<(), RunError> {
    image_space::check(cfg, choice(cfg)?)
}

/// Runs sort-first.
pub fn run(cfg: &RunConfig) -> Result<RunResult, RunError> {
    image_space::run(cfg, choice(cfg)?, false, mueller::processor)
}
