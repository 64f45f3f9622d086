//! Pipeline Composition (paper 001, section 4.1, SLML-full; after PixelFlow) as one node's
//! program.
//!
//! ```text
//! clear my full frame; render my share (request balancing optional)
//! node 0:   send my frame down the pipeline, chunk by chunk (`chunk-rows` scanlines)
//! node i:   read thread: receive chunk c from node i-1 into the input double buffer
//!           z-buffer thread: merge chunk c with my rows, free the input buffer (a credit)
//!           send thread: pass the merged chunk to node i+1
//! node N-1: read and merge only; its frame is the image
//! ```
//!
//! The double buffer is a credit scheme: a sender sends chunk c only once chunk c-2 has been
//! merged downstream, so at most two chunks wait in a node's mailbox. A chunk's pixels are
//! charged in one compute, so events grow with chunks times nodes, not with pixels.
//!
//! Must never hold full frames on the host: chunks carry active pixels only.

use std::cell::RefCell;
use std::collections::VecDeque;
use std::rc::Rc;

use super::full_frame::{self, tag, Msg, Rows, CHUNK, CONTROL_BYTES, CREDIT, LOCAL};
use super::pixel::ShippedPixel;
use super::{local, request, Ctx};
use crate::engine::{Filter, Node, SimError};
use crate::units::{Bytes, SimTime};

/// Input buffers per node (paper 001: a double buffer).
pub const INPUT_BUFFERS: u32 = 2;

pub(super) async fn processor<P: ShippedPixel>(
    node: Node<Msg<P>>,
    ctx: Rc<Ctx>,
) -> Result<(), SimError> {
    let me = node.id();
    let n = ctx.n;
    let (w, h) = (ctx.viewport.width(), ctx.viewport.height());
    let rows_per = ctx.settings.chunk_rows.min(h);
    let chunks = h.div_ceil(rows_per);
    let extent = |c: u32| (c * rows_per, ((c + 1) * rows_per).min(h));
    for frame in ctx.frames() {
        let rendered = request::render_frame(&node, &ctx, frame).await?;
        let rows = Rows::new(rendered, w, h);

        let mut image: Option<Vec<P>> = (me == n - 1).then(Vec::new);
        if n == 1 {
            if let Some(image) = &mut image {
                image.extend_from_slice(rows.rows(0, h));
            }
        } else if me == 0 {
            for c in 0..chunks {
                if c >= INPUT_BUFFERS {
                    node.recv(Filter::tag(tag(CREDIT, frame)).and_source(1))
                        .await;
                }
                let (y0, y1) = extent(c);
                let pixels = rows.rows(y0, y1).to_vec();
                full_frame::send_chunk(&node, &ctx, frame, 1, (y0, y1), pixels).await;
            }
        } else {
            let buffers = Bytes::new(INPUT_BUFFERS as u64 * ctx.rows_bytes(rows_per).get());
            node.alloc("input double buffer", buffers)?;
            let outbox = Rc::new(RefCell::new(VecDeque::new()));
            if me < n - 1 {
                node.spawn(
                    format!("send thread {me}"),
                    send_thread(node.clone(), ctx.clone(), frame, chunks, outbox.clone()),
                );
            }
            for _ in 0..chunks {
                let env = node
                    .recv(Filter::tag(tag(CHUNK, frame)).and_source(me - 1))
                    .await;
                let Msg::Chunk { y0, y1, pixels, .. } = env.payload else {
                    unreachable!("filtered by tag")
                };
                let charged = u64::from(y1 - y0) * u64::from(w);
                let merged = ctx
                    .merge_rows(&node, &pixels, rows.rows(y0, y1), charged)
                    .await;
                ctx.send(
                    &node,
                    frame,
                    me - 1,
                    Bytes::new(CONTROL_BYTES),
                    Msg::Credit { frame },
                )
                .await;
                match &mut image {
                    Some(image) => image.extend(merged),
                    None => {
                        outbox.borrow_mut().push_back((y0, y1, merged));
                        node.post(me, SimTime::ZERO, Msg::Local { frame });
                    }
                }
            }
            node.free("input double buffer", buffers)?;
        }
        local::free_full_frame(&node, &ctx)?;
        ctx.end_aa(&node, frame)?;
        if let Some(image) = image {
            full_frame::end_frame(&node, &ctx, frame, &image).await?;
        }
    }
    Ok(())
}

/// Merged chunks (rows `y0..y1` and their pixels) waiting for the send thread.
type Outbox<P> = Rc<RefCell<VecDeque<(u32, u32, Vec<P>)>>>;

/// Passes merged chunks to node i+1 as its input buffers free up.
async fn send_thread<P: ShippedPixel>(
    node: Node<Msg<P>>,
    ctx: Rc<Ctx>,
    frame: u32,
    chunks: u32,
    outbox: Outbox<P>,
) -> Result<(), SimError> {
    let me = node.id();
    for c in 0..chunks {
        node.recv(Filter::tag(tag(LOCAL, frame)).and_source(me))
            .await;
        if c >= INPUT_BUFFERS {
            node.recv(Filter::tag(tag(CREDIT, frame)).and_source(me + 1))
                .await;
        }
        let Some((y0, y1, pixels)) = outbox.borrow_mut().pop_front() else {
            unreachable!("a merged chunk is queued before its hand-off")
        };
        full_frame::send_chunk(&node, &ctx, frame, me + 1, (y0, y1), pixels).await;
    }
    Ok(())
}
