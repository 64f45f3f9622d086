//! The options of sort-first, one struct: the doc comment of a field is its help, its serde
//! default the default.
//!
//! Owns the option names, types and defaults. Must never check them against a machine or a
//! screen (that is `image_space::settings`, which knows both).

use crate::algo::image_space::options::{
    eight_regions, paper_buffer, BufferSize, Granularity, Migrate, RegionRule,
};

fn static_regions() -> RegionRule {
    RegionRule::Static
}
fn batched() -> Migrate {
    Migrate::Batched
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
