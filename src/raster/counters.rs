//! Operation counts: what a draw did, in the units the machine's cost table charges for.
//!
//! Must never turn counts into time (that is the machine's cost model) and never read a
//! clock: a count is a pure function of the geometry and the target.

use std::ops::{Add, AddAssign};

/// Counts returned by every draw. Plain numbers; combine with `+=`.
///
/// Front end (clip, project, snap): every input triangle lands in exactly one of
/// `culled_invalid`, `culled_outside`, `culled_backface`, `culled_zero_area`, or produces
/// one or more screen triangles (`triangles_set_up`; more than one only when clipped).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Counters {
    /// Triangles handed to the front end.
    pub triangles_in: u64,
    /// Dropped for a NaN or infinite coordinate or colour, or an out-of-range vertex index.
    pub culled_invalid: u64,
    /// Dropped because no part can be visible (outside the view volume, behind the eye,
    /// clipped away, or entirely off the viewport after snapping).
    pub culled_outside: u64,
    /// Dropped by back-face culling.
    pub culled_backface: u64,
    /// Dropped because their snapped area is zero (colinear, coincident or collapsed).
    pub culled_zero_area: u64,
    /// Triangles that crossed the near or far plane or the guard band and were clipped.
    pub clipped: u64,
    /// Screen triangles produced by the front end (a clipped triangle may give several).
    pub triangles_set_up: u64,
    /// Screen triangles whose edge and plane equations were set up for scanning
    /// (per target rectangle pass counted once per triangle).
    pub triangles_scanned: u64,
    /// Non-empty spans (runs of covered pixels on one row) generated.
    pub spans: u64,
    /// Fragments generated and depth-tested (or counted, for the counting target).
    pub pixels_tested: u64,
    /// Fragments that passed the depth test and were written.
    pub pixels_written: u64,
    /// Bytes of target memory read or written by depth tests and writes.
    pub bytes_touched: u64,
    /// Scanline renderer: triangles inserted into a scanline bucket.
    pub bucket_inserts: u64,
    /// Scanline renderer: triangles moved from a bucket into the active list.
    pub active_inserts: u64,
    /// Scanline renderer: triangles removed from the active list after their last row.
    pub active_removals: u64,
    /// Scanline renderer: scanlines completed (each one cleared and emitted).
    pub scanlines: u64,
    /// Anti-aliasing: coverage masks formed for partially covered pixels (a bitmask table
    /// lookup per edge for the adaptive target; exact sample tests for supersampling).
    pub aa_coverage_masks: u64,
    /// Anti-aliasing: subpixel samples depth-tested.
    pub aa_subpixel_tests: u64,
    /// Anti-aliasing: subpixel samples written (including a block's initial copy of its
    /// pixel's sample).
    pub aa_subpixel_writes: u64,
    /// Adaptive anti-aliasing: super pixels checked for reclaiming.
    pub aa_reclaim_checks: u64,
    /// Anti-aliasing: pixels box-filtered from their samples.
    pub aa_resolved_pixels: u64,
}

impl Counters {
    /// Triangles the front end dropped for any reason.
    pub fn culled(&self) -> u64 {
        self.culled_invalid + self.culled_outside + self.culled_backface + self.culled_zero_area
    }
}

impl AddAssign for Counters {
    fn add_assign(&mut self, o: Counters) {
        self.triangles_in += o.triangles_in;
        self.culled_invalid += o.culled_invalid;
        self.culled_outside += o.culled_outside;
        self.culled_backface += o.culled_backface;
        self.culled_zero_area += o.culled_zero_area;
        self.clipped += o.clipped;
        self.triangles_set_up += o.triangles_set_up;
        self.triangles_scanned += o.triangles_scanned;
        self.spans += o.spans;
        self.pixels_tested += o.pixels_tested;
        self.pixels_written += o.pixels_written;
        self.bytes_touched += o.bytes_touched;
        self.bucket_inserts += o.bucket_inserts;
        self.active_inserts += o.active_inserts;
        self.active_removals += o.active_removals;
        self.scanlines += o.scanlines;
        self.aa_coverage_masks += o.aa_coverage_masks;
        self.aa_subpixel_tests += o.aa_subpixel_tests;
        self.aa_subpixel_writes += o.aa_subpixel_writes;
        self.aa_reclaim_checks += o.aa_reclaim_checks;
        self.aa_resolved_pixels += o.aa_resolved_pixels;
    }
}

impl Add for Counters {
    type Output = Counters;
    fn add(mut self, o: Counters) -> Counters {
        self += o;
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn add_assign_adds_every_field() {
        let one = Counters {
            triangles_in: 1,
            culled_invalid: 2,
            culled_outside: 3,
            culled_backface: 4,
            culled_zero_area: 5,
            clipped: 6,
            triangles_set_up: 7,
            triangles_scanned: 8,
            spans: 9,
            pixels_tested: 10,
            pixels_written: 11,
            bytes_touched: 12,
            bucket_inserts: 13,
            active_inserts: 14,
            active_removals: 15,
            scanlines: 16,
            aa_coverage_masks: 17,
            aa_subpixel_tests: 18,
            aa_subpixel_writes: 19,
            aa_reclaim_checks: 20,
            aa_resolved_pixels: 21,
        };
        let mut sum = one;
        sum += one;
        assert_eq!(sum.scanlines, 32);
        assert_eq!(sum.triangles_in, 2);
        assert_eq!(sum.aa_resolved_pixels, 42);
        assert_eq!(sum.aa_coverage_masks, 34);
        assert_eq!(sum, one + one);
        assert_eq!(one.culled(), 2 + 3 + 4 + 5);
    }
}
