//! What the rasterizer's operation counts cost on a machine: the one mapping from
//! `raster::Counters` to the cpu's `Op`s, for the front end (transform, clip, classify) and
//! the back end (set up, spans, depth tests, writes, and anti-aliasing's masks, subpixel
//! tests and writes, reclaim checks and resolves).
//!
//! Must never time anything itself: it only builds `Counts` for `Node::compute`.

use crate::machine::{Counts, Op};
use crate::raster::Counters;

/// Transforming and clipping triangles: three vertices per triangle handed in (immediate
/// mode, as the papers' renderers transform polygons, not shared vertex arrays).
pub fn front_end(c: &Counters) -> Counts {
    let mut counts = Counts::new();
    counts
        .add(Op::TransformVertex, 3 * c.triangles_in)
        .add(Op::ClipTriangle, c.clipped);
    counts
}

/// Scan-converting screen triangles into a target.
pub fn back_end(c: &Counters) -> Counts {
    let mut counts = Counts::new();
    counts
        .add(Op::SetupTriangle, c.triangles_scanned)
        .add(Op::Span, c.spans)
        .add(Op::PixelTest, c.pixels_tested)
        .add(Op::PixelWrite, c.pixels_written)
        .add(Op::CoverageMask, c.aa_coverage_masks)
        .add(Op::SubpixelTest, c.aa_subpixel_tests)
        .add(Op::SubpixelWrite, c.aa_subpixel_writes)
        .add(Op::ReclaimCheck, c.aa_reclaim_checks)
        .add(Op::ResolvePixel, c.aa_resolved_pixels);
    counts
}
