//! Distributed Frame buffer (paper 001, section 4.1, SLML-full) as one node's program.
//!
//! ```text
//! clear my full frame; render my share (request balancing optional)
//! I own band i of the screen (horizontal bands); ask each of the other N-1 nodes for it
//! z-merge every reply into my band (every pixel, active or not, is moved and compared)
//! resolve my band's super pixels (anti-aliasing) and send it to the controller (node 0),
//! which copies the bands into the final image
//! ```
//!
//! A band server on each node answers the other owners' requests once its own frame is
//! rendered. Must never hold full frames on the host: replies carry active pixels only.

use std::rc::Rc;

use super::full_frame::{self, tag, Msg, Rows, BAND_REPLY, BAND_REQUEST, CONTROL_BYTES, PARTITION};
use super::pixel::ShippedPixel;
use super::{local, request, Ctx};
use crate::engine::{Filter, Node, SimError};
use crate::machine::{Counts, Op};
use crate::units::Bytes;

/// Rows `y0..y1` of band `b` of `n`.
fn band(ctx: &Ctx, b: u32) -> (u32, u32) {
    let h = ctx.viewport.height() as u64;
    let n = ctx.n as u64;
    let at = |k: u64| (h * k / n) as u32;
    (at(b as u64), at(b as u64 + 1))
}

fn band_pixels(ctx: &Ctx, b: u32) -> u64 {
    let (y0, y1) = band(ctx, b);
    (y1 - y0) as u64 * ctx.viewport.width() as u64
}

pub(super) async fn processor<P: ShippedPixel>(
    node: Node<Msg<P>>,
    ctx: Rc<Ctx>,
) -> Result<(), SimError> {
    let me = node.id();
    let n = ctx.n;
    let (w, h) = (ctx.viewport.width(), ctx.viewport.height());
    for frame in ctx.frames() {
        let rendered = request::render_frame(&node, &ctx, frame).await?;
        let rows = Rc::new(Rows::new(rendered, w, h));

        node.spawn(
            format!("band server {me}"),
            serve(node.clone(), ctx.clone(), frame, rows.clone()),
        );
        for k in 1..n {
            let msg = Msg::BandRequest { frame, band: me };
            ctx.send(&node, frame, (me + k) % n, Bytes::new(CONTROL_BYTES), msg)
                .await;
        }
        let (y0, y1) = band(&ctx, me);
        let mut merged = rows.rows(y0, y1).to_vec();
        let band_bytes = ctx.rows_bytes(y1 - y0);
        node.alloc("band buffer", band_bytes)?;
        for _ in 1..n {
            let env = node.recv(Filter::tag(tag(BAND_REPLY, frame))).await;
            let Msg::BandReply { pixels, .. } = env.payload else {
                unreachable!("filtered by tag")
            };
            merged = ctx
                .merge_rows(&node, &pixels, &merged, band_pixels(&ctx, me))
                .await;
        }
        node.free("band buffer", band_bytes)?;

        if me == 0 {
            node.phase("assemble");
            let mut image = merged;
            for _ in 1..n {
                let env = node.recv(Filter::tag(tag(PARTITION, frame))).await;
                let Msg::Partition {
                    band: b, pixels, ..
                } = env.payload
                else {
                    unreachable!("filtered by tag")
                };
                let (b0, b1) = band(&ctx, b);
                let bytes = ctx.chunk_bytes(b1 - b0, &pixels);
                node.compute(&Counts::of(Op::ByteCopy, bytes.get())).await;
                image.extend(pixels);
            }
            local::free_full_frame(&node, &ctx)?;
            ctx.end_aa(&node, frame)?;
            full_frame::end_frame(&node, &ctx, frame, &image).await?;
        } else {
            // The controller shows colours: a band's super pixels are resolved here.
            let merged = ctx.resolve_rows(&node, merged).await;
            let bytes = ctx.chunk_bytes(y1 - y0, &merged);
            let msg = Msg::Partition {
                frame,
                band: me,
                pixels: merged,
            };
            ctx.send(&node, frame, 0, bytes, msg).await;
            local::free_full_frame(&node, &ctx)?;
            ctx.end_aa(&node, frame)?;
        }
    }
    Ok(())
}

/// Answers the N-1 band requests for this node's rendered frame.
async fn serve<P: ShippedPixel>(
    node: Node<Msg<P>>,
    ctx: Rc<Ctx>,
    frame: u32,
    rows: Rc<Rows<P>>,
) -> Result<(), SimError> {
    for _ in 1..ctx.n {
        let env = node.recv(Filter::tag(tag(BAND_REQUEST, frame))).await;
        let Msg::BandRequest { band: b, .. } = env.payload else {
            unreachable!("filtered by tag")
        };
        let (y0, y1) = band(&ctx, b);
        let pixels = Rc::new(rows.rows(y0, y1).to_vec());
        let bytes = ctx.chunk_bytes(y1 - y0, &pixels);
        let msg = Msg::BandReply { frame, pixels };
        ctx.send(&node, frame, env.src, bytes, msg).await;
    }
    Ok(())
}
