//! The one thing every sort-last node does before (or while) merging: render whole
//! primitives of its share into a local target, charged batch by batch as the machine would
//! be, and the full frame it would hold.
//!
//! Must never merge or send: merging is each variant's business.

use super::bounds;
use super::pixel::ShippedPixel;
use super::Ctx;
use crate::algo::charge;
use crate::engine::{Node, Payload, SimError};
use crate::machine::{Counts, Op};
use crate::raster::{draw_subset, Counters, Target};
use crate::units::Bytes;

/// Primitives per compute charge: events grow with batches, not with pixels, and a request
/// for work waits at most one batch before the renderer looks at it.
pub const BATCH: usize = 64;

/// Renders `prims` (database indices of `frame`) into `target` one batch at a time, charging
/// each batch's front and back end as it is drawn (so a program beside the renderer sees the
/// target between batches).
pub(crate) async fn render<M: Payload, T: Target>(
    node: &Node<M>,
    ctx: &Ctx,
    frame: u32,
    prims: &[u32],
    target: &mut T,
) -> Result<(), SimError> {
    for batch in prims.chunks(BATCH) {
        let drawn = draw(node, ctx, frame, batch, target)?;
        charge_batches(node, ctx, frame, &drawn).await;
    }
    Ok(())
}

/// Draws `prims` into `target` on the host, batch by batch, without charging: the counts
/// of each batch.
fn draw<M: Payload, T: Target>(
    node: &Node<M>,
    ctx: &Ctx,
    frame: u32,
    prims: &[u32],
    target: &mut T,
) -> Result<Vec<Counters>, SimError> {
    let geometry = ctx.geometry(node, frame)?;
    let vertices = ctx.vertices(node, frame)?;
    let mut vertices = vertices.borrow_mut();
    Ok(prims
        .chunks(BATCH)
        .map(|batch| {
            draw_subset(
                &geometry.vertices,
                &geometry.triangles,
                batch,
                &mut vertices,
                &ctx.raster,
                target,
            )
        })
        .collect())
}

/// Charges drawn batches one compute each (front and back end), and counts the triangles
/// they found in view.
async fn charge_batches<M: Payload>(node: &Node<M>, ctx: &Ctx, frame: u32, batches: &[Counters]) {
    for c in batches {
        let mut work = charge::front_end(c);
        work += &charge::back_end(c);
        node.compute(&work).await;
        ctx.record(frame, |r| {
            r.triangles_in_view += c.triangles_in - c.culled_outside - c.culled_invalid
        });
    }
}

/// Renders this node's static share of `frame` into the run's buffer, records when
/// rasterization finished, and returns the rendered pixels in raster order. Nothing else
/// looks at the buffer while it is drawn, so the host draws the whole share at once and
/// drops the buffer before charging the batches: one node's dense buffer is alive at a
/// time, not every node's.
pub(crate) async fn render_own_share<P: ShippedPixel, M: Payload>(
    node: &Node<M>,
    ctx: &Ctx,
    frame: u32,
) -> Result<Vec<P>, SimError> {
    let (pixels, batches) = draw_share(node, ctx, frame)?;
    charge_batches(node, ctx, frame, &batches).await;
    raster_finished(node, ctx, frame);
    Ok(pixels)
}

/// Draws this node's static share of `frame` on the host, uncharged: its pixels in raster
/// order and the counts of each batch.
fn draw_share<P: ShippedPixel, M: Payload>(
    node: &Node<M>,
    ctx: &Ctx,
    frame: u32,
) -> Result<(Vec<P>, Vec<Counters>), SimError> {
    let share = ctx.share(node, frame)?;
    let mut buffer = P::buffer(ctx, frame);
    let batches = draw(node, ctx, frame, &share, &mut buffer)?;
    Ok((P::collect(buffer, ctx, node.id()), batches))
}

/// [`render_own_share`] with `bounds=on`: the host draws the share first, so that the node
/// allocates and clears a frame buffer of only the rectangle around what it drew (charged
/// before its batches, as IceT clears before rendering) and starts the frame's bounds with it.
pub(crate) async fn render_bounded<P: ShippedPixel, M: Payload>(
    node: &Node<M>,
    ctx: &Ctx,
    frame: u32,
) -> Result<Vec<P>, SimError> {
    let (pixels, batches) = draw_share::<P, M>(node, ctx, frame)?;
    let rect = bounds::around(&pixels, ctx.viewport);
    let area = rect.map_or(0, |r| r.pixels() as u64);
    let bytes = Bytes::new(area * ctx.record_bytes());
    ctx.bounds.start(node.id(), rect, bytes);
    node.alloc("frame buffer", bytes)?;
    node.compute(&Counts::of(Op::ClearPixel, area)).await;
    node.phase("render");
    charge_batches(node, ctx, frame, &batches).await;
    raster_finished(node, ctx, frame);
    Ok(pixels)
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

/// Returns the full frame (with `bounds=on`, the node's rectangle of it) to the memory pool.
pub(crate) fn free_full_frame<M: Payload>(node: &Node<M>, ctx: &Ctx) -> Result<(), SimError> {
    let bytes = if ctx.settings.bounds {
        ctx.bounds.buffer(node.id())
    } else {
        ctx.full_frame_bytes()
    };
    node.free("frame buffer", bytes)
}
