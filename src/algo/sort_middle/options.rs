//! The options of the sort-middle algorithms, one struct each: the doc comment of a field is
//! its help, its serde default the default (`sortsim run --help` and `sortsim schema
//! options` print both from here).
//!
//! Owns the option names, types and defaults. Must never check them against a machine or a
//! screen (that is `settings`, which knows both).

use crate::algo::options::{choice_option, count_option, quantity_option};
use crate::units::{Bytes, SimTime};

count_option!(
    /// Regions per processor.
    Granularity,
    min = 1,
    what = "a whole number of regions per processor, at least 1"
);

count_option!(
    /// The side of a square region in pixels.
    RegionSide,
    min = 1,
    what = "a region side in pixels, at least 1"
);

quantity_option!(
    /// A polygon buffer's size.
    BufferSize(Bytes),
    what = "a buffer size such as 4KiB"
);

quantity_option!(
    /// A time estimate.
    Estimate(SimTime),
    what = "a time such as 12us"
);

choice_option!(
    /// When the per-region counts that drive the assignment are taken (paper 002).
    CountsFrom {
        /// This frame's counts assign the next frame's regions, summed while rasterizing.
        Previous = "previous",
        /// This frame's counts assign this frame's regions: everyone waits for them.
        Current = "current",
    }
);

choice_option!(
    /// Two-step redistribution (paper 002, Figure 7).
    TwoStep {
        On = "on",
        Off = "off",
        Auto = "auto",
    }
);

/// Paper 002's polygon buffer: "The buffer size was fixed at 4 Kbytes."
pub const DEFAULT_BUFFER: Bytes = Bytes::new(4096);

fn paper_buffer() -> BufferSize {
    BufferSize(DEFAULT_BUFFER)
}
fn eight_regions() -> Granularity {
    Granularity(8)
}
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
