//! The one thing every sort-last node does before (or while) merging: render whole
//! primitives of its share into a local target, charged batch by batch as the machine would
//! be, and the full frame it would hold.
//!
//! Must never merge or send: merging is each variant's business.

use super::pixel::ShippedPixel;
use super::Ctx;
use crate::algo::charge;
use crate::engine::{Node, Payload, SimError};
use crate::machine::{Counts, Op};
use crate::raster::{draw_subset, Counters, Target};

/// Primitives per compute charge: events grow with batches, not with pixels, and a request
/// for work waits at most one batch before the renderer looks at it.
pub const BATCH: usize = 64;

/// Renders `prims` (database indices of `frame`) into `target` one batch at a time, charging
/// each batch's front and back end. Returns the counts of the whole call.
pub(crate) async fn render<M: Payload, T: Target>(
    node: &Node<M>,
    ctx: &Ctx,
    frame: u32,
    prims: &[u32],
    target: &mut T,
) -> Result<Counters, SimError> {
    let geometry = ctx.geometry(node, frame)?;
    let mut total = Counters::default();
    for batch in prims.chunks(BATCH) {
        let c = draw_subset(
            &geometry.vertices,
            &geometry.triangles,
            batch,
            ctx.viewport,
            &ctx.raster,
            target,
        );
        let mut work = charge::front_end(&c);
        work += &charge::back_end(&c);
        node.compute(&work).await;
        total += c;
    }
    ctx.record(frame, |r| {
        r.triangles_in_view += total.triangles_in - total.culled_outside - total.culled_invalid
    });
    Ok(total)
}

/// Renders this node's static share of `frame` into the run's buffer, records when
/// rasterization finished, and returns the rendered pixels in raster order.
pub(crate) async fn render_own_share<P: ShippedPixel, M: Payload>(
    node: &Node<M>,
    ctx: &Ctx,
    frame: u32,
) -> Result<Vec<P>, SimError> {
    let share = ctx.share(node, frame)?;
    let mut buffer = P::buffer(ctx, frame);
    render(node, ctx, frame, &share, &mut buffer).await?;
    raster_finished(node, ctx, frame);
    Ok(P::collect(buffer, ctx, node.id()))
}

/// Records when this node finished rasterizing `frame` (paper 001's load imbalance).
pub(crate) fn raster_finished<M: Payload>(node: &Node<M>, ctx: &Ctx, frame: u32) {
    let (me, now) = (node.id() as usize, node.now());
    ctx.record(frame, |r| r.raster_finish[me] = now);
}

/// Allocates a full frame (colour and z, or paper 000's Pixels) in the node's memory pool and
/// charges clearing it (a Subpixel pool needs no clearing: its free list is reset).
pub(crate) async fn clear_full_frame<M: Payload>(
    node: &Node<M>,
    ctx: &Ctx,
) -> Result<(), SimError> {
    node.alloc("frame buffer", ctx.full_frame_bytes())?;
    let pixels = ctx.viewport.pixels() as u64;
    node.compute(&Counts::of(Op::ClearPixel, pixels)).await;
    Ok(())
}

/// Returns the full frame to the memory pool.
pub(crate) fn free_full_frame<M: Payload>(node: &Node<M>, ctx: &Ctx) -> Result<(), SimError> {
    node.free("frame buffer", ctx.full_frame_bytes())
}
