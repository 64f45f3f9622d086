//! What the rasterizer's operation counts cost on a machine: the one mapping from
//! `raster::Counters` to the cpu's `Op`s, for the front end (transform, clip, classify) and
//! the back end (set up, spans, depth tests, writes).
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
        .add(Op::PixelWrite, c.pixels_written);
    counts
}
