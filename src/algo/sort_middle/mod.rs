//! Sort-middle rendering: every processor transforms an even share of the polygons, sends the
//! screen-space triangles to the processors that own the screen regions they touch, and
//! rasterizes its own regions.
//!
//! Two variants: `static` (paper 000: 64x64 regions in a fixed interleaved pattern, a root
//! collects the regional images) and `ellsworth` (paper 002: regions = granularity x N,
//! assigned for the next frame by greedy bin packing on this frame's per-region counts summed
//! up a tree, optional two-step redistribution). The node programs are in `ellsworth.rs` and
//! `static_regions.rs`; the stages they share with sort-first (regions, trees, buffers,
//! redistribution, rasterization) are in `algo::image_space`. `utilization.rs` is paper 002's
//! utilization simulator and performance model.
//!
//! Must never name a topology: groups and trees are over processor ids.

mod ellsworth;
pub mod options;
mod static_regions;
pub mod utilization;

pub use options::{EllsworthOptions, StaticOptions};

use super::image_space::buffers::ROUTED_TRIANGLE_BYTES;
use super::image_space::options::{CountsFrom, TwoStep};
use super::image_space::{self, Choice, FirstSettings, RegionChoice};
use super::options::parse;
use super::{RunConfig, RunError, RunResult};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    Static,
    Ellsworth,
}

/// Reads `variant`'s options.
fn choice(cfg: &RunConfig, variant: Variant) -> Result<Choice, RunError> {
    let (o, algo) = (&cfg.options, cfg.algo.id());
    let choice = match variant {
        Variant::Static => {
            let (s, aa) = parse::<StaticOptions>(o, algo)?;
            Choice {
                regions: RegionChoice::Side(s.region_size.0),
                buffer: s.buffer.0,
                counts: CountsFrom::Previous,
                two_step: TwoStep::Off,
                polygon_estimate: None,
                aa,
                first: FirstSettings::default(),
                record_bytes: ROUTED_TRIANGLE_BYTES,
            }
        }
        Variant::Ellsworth => {
            let (e, aa) = parse::<EllsworthOptions>(o, algo)?;
            Choice {
                regions: RegionChoice::PerProcessor(e.granularity.0),
                buffer: e.buffer.0,
                counts: e.counts,
                two_step: e.two_step,
                polygon_estimate: e.polygon_estimate.map(|t| t.0),
                aa,
                first: FirstSettings::default(),
                record_bytes: ROUTED_TRIANGLE_BYTES,
            }
        }
    };
    Ok(choice)
}

/// Checks a variant's options against `cfg` without running it.
pub fn check(cfg: &RunConfig, variant: Variant) -> Result<(), RunError> {
    image_space::check(cfg, choice(cfg, variant)?)
}

/// Runs a sort-middle variant.
pub fn run(cfg: &RunConfig, variant: Variant) -> Result<RunResult, RunError> {
    let choice = choice(cfg, variant)?;
    match variant {
        Variant::Static => image_space::run(cfg, choice, true, static_regions::processor),
        Variant::Ellsworth => image_space::run(cfg, choice, true, ellsworth::processor),
    }
}
