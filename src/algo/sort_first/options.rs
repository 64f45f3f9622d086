//! The options of sort-first, one struct: the doc comment of a field is its help, its serde
//! default the default.
//!
//! Owns the option names, types and defaults. Must never check them against a machine or a
//! screen (that is sort-middle's `settings`, which knows both).

use crate::algo::options::choice_option;
use crate::algo::sort_middle::options::{BufferSize, Granularity};

choice_option!(
    /// How screen regions are assigned to processors.
    RegionRule {
        /// Interleaved, fixed for the whole run.
        Static = "static",
        /// Each frame by greedy bin packing on the previous frame's per-region counts
        /// (sort-middle/ellsworth's balancing).
        Adaptive = "adaptive",
    }
);

choice_option!(
    /// How the records of migrating primitives travel.
    Migrate {
        /// In buffers of `buffer` bytes per destination, sent when full and at the end of
        /// the transformation.
        Batched = "batched",
        /// After each transformed batch, whatever is waiting for each destination.
        Immediate = "immediate",
    }
);

fn eight_regions() -> Granularity {
    Granularity(8)
}
fn static_regions() -> RegionRule {
    RegionRule::Static
}
fn batched() -> Migrate {
    Migrate::Batched
}
fn paper_buffer() -> BufferSize {
    BufferSize(crate::algo::sort_middle::DEFAULT_BUFFER)
}

/// sort-first/mueller (Mueller 1995).
#[derive(Clone, Debug, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub struct SortFirstOptions {
    /// Regions per processor.
    #[serde(default = "eight_regions")]
    pub granularity: Granularity,
    /// Region assignment: static (interleaved) or adaptive (previous frame's counts).
    #[serde(default = "static_regions")]
    pub regions: RegionRule,
    /// How migrating primitives' records travel: batched (full buffers) or immediate.
    #[serde(default = "batched")]
    pub migrate: Migrate,
    /// Record buffer size per destination (as sort-middle's polygon buffers: 4 KB).
    #[serde(default = "paper_buffer")]
    pub buffer: BufferSize,
}
