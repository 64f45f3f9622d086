//! The option types the image-space algorithms share (sort-middle's and sort-first's option
//! structs are built from them): granularity, region side, buffer size, estimates, counts,
//! two-step, sort-first's region rule and record migration, with their defaults.
//!
//! Owns the option value types and shared defaults. Must never check them against a machine
//! or a screen (that is `settings`, which knows both).

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

/// Paper 002's buffer, the default of every image-space algorithm's buffer option.
pub fn paper_buffer() -> BufferSize {
    BufferSize(DEFAULT_BUFFER)
}

/// Paper 002's granularity ratio.
pub fn eight_regions() -> Granularity {
    Granularity(8)
}

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
