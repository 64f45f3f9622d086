//! `sort-last/pixelflow` (paper 003, section 5; Molnar's PixelFlow): every node renders its
//! share into a full local frame, then the frames flow down the pipeline: node 0 streams its
//! whole frame (A pixels, active or not) to node 1, node i z-merges what it receives with
//! its own frame and passes the result on, and the last node's output port feeds the frame
//! buffer. Traffic is n*A pixels in total, A on every link, whatever the scene.
//!
//! Frames move in chunks of `chunk_rows` scanlines (one by default), so events grow with
//! scanlines x nodes, not with pixels. Each chunk is charged and sized as the full rows it
//! stands for (a full-frame record per pixel plus the Subpixels of its super pixels under
//! adaptive anti-aliasing, `composite_pixel` per pixel merged), but the host carries only
//! the chunk's active pixels.
//!
//! How the count agrees with trace replay's n*A: the n-1 pipeline links carry A pixels
//! each as network messages; the last node's stream into the frame buffer is the n-th link
//! (a local output port, not a network message): it is added to the frame's bytes and
//! messages without a network transfer.
//!
//! Must never skip inactive pixels in what it charges or counts, and never reorder the
//! pipeline (node i only ever receives from i-1 and sends to i+1).

use std::rc::Rc;

use super::pixel::ShippedPixel;
use super::{local, Ctx};
use crate::engine::{Filter, Node, Payload, SimError};

/// Rows `y0..y1` of a partially merged frame: only its active pixels, raster order.
#[derive(Clone, Debug)]
pub(crate) struct Rows<P> {
    frame: u32,
    y0: u32,
    pixels: Rc<Vec<P>>,
}

impl<P: ShippedPixel> Payload for Rows<P> {
    /// Frame and chunk, so a stage takes chunks in screen order even if one overtook another.
    fn tag(&self) -> u32 {
        chunk_tag(self.frame, self.y0)
    }
}

fn chunk_tag(frame: u32, y0: u32) -> u32 {
    frame.wrapping_mul(16384).wrapping_add(y0)
}

/// One pipeline stage.
pub(crate) async fn processor<P: ShippedPixel>(
    node: Node<Rows<P>>,
    ctx: Rc<Ctx>,
) -> Result<(), SimError> {
    let me = node.id();
    let n = ctx.n;
    let (w, h) = (ctx.viewport.width(), ctx.viewport.height());
    for frame in ctx.frames() {
        if me == 0 {
            ctx.book.begin(&node, frame);
        }
        ctx.begin_aa(&node, frame)?;
        node.phase("render");
        local::clear_full_frame(&node, &ctx).await?;
        let own: Vec<P> = local::render_own_share(&node, &ctx, frame).await?;

        node.phase("merge");
        let mut output: Vec<P> = Vec::new();
        let mut cursor = 0;
        let mut y0 = 0;
        while y0 < h {
            let y1 = (y0 + ctx.settings.chunk_rows).min(h);
            let chunk_pixels = ((y1 - y0) * w) as u64;
            let end = y1 * w;
            let start = cursor;
            while cursor < own.len() && own[cursor].loc() < end {
                cursor += 1;
            }
            let mine = &own[start..cursor];
            let merged = if me == 0 {
                mine.to_vec()
            } else {
                let tag = chunk_tag(frame, y0);
                let env = node.recv(Filter::tag(tag).and_source(me - 1)).await;
                ctx.merge_rows(&node, &env.payload.pixels, mine, chunk_pixels)
                    .await
            };
            let bytes = ctx.chunk_bytes(y1 - y0, &merged);
            if me + 1 < n {
                let msg = Rows {
                    frame,
                    y0,
                    pixels: Rc::new(merged),
                };
                ctx.send(&node, frame, me + 1, bytes, msg).await;
            } else {
                // The n-th link: the last stage's output port into the frame buffer.
                ctx.record(frame, |r| {
                    r.bytes += bytes;
                    r.messages += 1;
                });
                output.extend_from_slice(&merged);
            }
            y0 = y1;
        }
        local::free_full_frame(&node, &ctx)?;
        ctx.end_aa(&node, frame)?;
        if me + 1 == n {
            ctx.show(&node, frame, &output).await;
            let now = node.now();
            ctx.record(frame, |r| r.end = now);
        }
    }
    Ok(())
}
