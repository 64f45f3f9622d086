//! The options of the sort-middle algorithms, one struct each: the doc comment of a field is
//! its help, its serde default the default (`sortsim run --help` and `sortsim schema
//! options` print both from here).
//!
//! Owns the option names and defaults. Must never check them against a machine or a screen
//! (that is `image_space::settings`, which knows both).

use crate::algo::image_space::options::{
    eight_regions, paper_buffer, BufferSize, CountsFrom, Estimate, Granularity, RegionSide, TwoStep,
};

fn tiles_of_64() -> RegionSide {
    RegionSide(64)
}
fn previous_frame() -> CountsFrom {
    CountsFrom::Previous
}
fn one_step() -> TwoStep {
    TwoStep::Off
}

/// sort-middle/ellsworth (paper 002).
#[derive(Clone, Debug, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub struct EllsworthOptions {
    /// Regions per processor, the granularity ratio (paper 002 chose 8).
    #[serde(default = "eight_regions")]
    pub granularity: Granularity,
    /// Which frame's per-region polygon counts balance the regions: previous (paper 002) or
    /// current.
    #[serde(default = "previous_frame")]
    pub counts: CountsFrom,
    /// Two-step redistribution: on, off, or auto (the performance model decides).
    #[serde(default = "one_step")]
    pub two_step: TwoStep,
    /// Polygon buffer size per destination (paper 002: 4 KB).
    #[serde(default = "paper_buffer")]
    pub buffer: BufferSize,
    /// Estimated rasterization time of one polygon for load balancing; none: set-up plus 3
    /// spans plus 6 pixels at the machine's costs.
    #[serde(default)]
    pub polygon_estimate: Option<Estimate>,
}

/// sort-middle/static (paper 000: static interleaved square regions).
#[derive(Clone, Debug, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub struct StaticOptions {
    /// The side of a square region in pixels (paper 000: 64).
    #[serde(default = "tiles_of_64")]
    pub region_size: RegionSide,
    /// Polygon buffer size per destination.
    #[serde(default = "paper_buffer")]
    pub buffer: BufferSize,
}
