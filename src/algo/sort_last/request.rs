//! The rendering phase of paper 001's SLML-full algorithms (DF and PC), with or without its
//! request-based dynamic load balancing (section 4.1).
//!
//! ```text
//! scatter primitives; render my queue
//! when my queue is empty: send a work request to node (i+1) mod N
//!   a busy node splits its queue by `split` and answers with a packet (if it holds at least
//!   `min-packet` primitives), else forwards the request; idle nodes forward
//!   a packet arrives: render it and ask again
//!   my own request comes back: local termination
//! ```
//!
//! The balancer is a helper program on each node answering requests between batches (the
//! cpu serves it first come, first served; on a time-sliced cpu, such as the MultiCluster's
//! transputers, it waits at most a slice behind the renderer, as the paper's balancer runs
//! "concurrently with the main task"). A work packet carries its primitives as the nodes
//! hold them, screen-space triangles (paper 001 renders screen-space input):
//! `ScreenTriangle::PAYLOAD_BYTES` each, plus a small header.
//!
//! Must never merge: it returns the node's rendered frame and records when rasterization
//! finished.

use std::cell::RefCell;
use std::collections::VecDeque;
use std::rc::Rc;

use super::full_frame::{self, tag, Msg, CONTROL_BYTES, WORK_PACKET, WORK_REQUEST};
use super::pixel::ShippedPixel;
use super::{local, Assignment, Ctx};
use crate::engine::{Filter, Node, SimError};
use crate::raster::ScreenTriangle;
use crate::units::{Bytes, SimTime};

/// What a work packet carries per primitive: the screen-space triangle its donor holds.
const WORK_PACKET_BYTES_PER_PRIMITIVE: u64 = ScreenTriangle::PAYLOAD_BYTES as u64;

/// The rendering phase of a frame for the variants that merge after rendering: waits for
/// the frame to start, clears this node's full frame, renders its share (balancing on
/// request when the run says so) and enters the merge phase; the rendered pixels in raster
/// order.
pub(crate) async fn render_frame<P: ShippedPixel>(
    node: &Node<Msg<P>>,
    ctx: &Rc<Ctx>,
    frame: u32,
) -> Result<Vec<P>, SimError> {
    full_frame::start_frame(node, ctx, frame).await?;
    node.phase("clear");
    let pixels = if ctx.settings.bounds {
        local::render_bounded(node, ctx, frame).await?
    } else {
        local::clear_full_frame(node, ctx).await?;
        node.phase("render");
        render_share(node, ctx, frame).await?
    };
    node.phase("merge");
    Ok(pixels)
}

/// Renders this node's share of `frame` into the run's buffer (charged as a full frame by
/// the caller), balancing on request when the run says so; returns the rendered pixels in
/// raster order.
pub(crate) async fn render_share<P: ShippedPixel>(
    node: &Node<Msg<P>>,
    ctx: &Rc<Ctx>,
    frame: u32,
) -> Result<Vec<P>, SimError> {
    let Assignment::Request { split, min_packet } = ctx.settings.assignment else {
        return local::render_own_share(node, ctx, frame).await;
    };
    if ctx.n == 1 {
        // Nobody to ask: the scatter is the whole share.
        return local::render_own_share(node, ctx, frame).await;
    }
    let mut target = P::buffer(ctx, frame);
    let share = ctx.share(node, frame)?;
    let queue = Rc::new(RefCell::new(VecDeque::from(share)));
    node.spawn_daemon(
        format!("load balancer {}", node.id()),
        balancer(
            node.clone(),
            ctx.clone(),
            frame,
            queue.clone(),
            split,
            min_packet,
        ),
    );
    let mut finished = node.now();
    loop {
        loop {
            let batch: Vec<u32> = {
                let mut q = queue.borrow_mut();
                let k = q.len().min(local::BATCH);
                q.drain(..k).collect()
            };
            if batch.is_empty() {
                break;
            }
            local::render(node, ctx, frame, &batch, &mut target).await?;
            finished = node.now();
        }
        let next = (node.id() + 1) % ctx.n;
        let request = Msg::WorkRequest {
            frame,
            origin: node.id(),
        };
        ctx.send(node, frame, next, Bytes::new(CONTROL_BYTES), request)
            .await;
        let env = node.recv(Filter::tag(tag(WORK_PACKET, frame))).await;
        let Msg::WorkPacket { prims, .. } = env.payload else {
            unreachable!("filtered by tag")
        };
        if prims.is_empty() {
            break; // my request came back unanswered: local termination
        }
        queue.borrow_mut().extend(prims);
    }
    let me = node.id() as usize;
    ctx.record(frame, |r| r.raster_finish[me] = finished);
    Ok(P::collect(target, ctx, node.id()))
}

/// Answers work requests for `frame` between the renderer's batches.
async fn balancer<P: ShippedPixel>(
    node: Node<Msg<P>>,
    ctx: Rc<Ctx>,
    frame: u32,
    queue: Rc<RefCell<VecDeque<u32>>>,
    split: u32,
    min_packet: u32,
) -> Result<(), SimError> {
    let me = node.id();
    let next = (me + 1) % ctx.n;
    loop {
        let env = node.recv(Filter::tag(tag(WORK_REQUEST, frame))).await;
        let Msg::WorkRequest { origin, .. } = env.payload else {
            unreachable!("filtered by tag")
        };
        if origin == me {
            let done = Msg::WorkPacket {
                frame,
                prims: Vec::new(),
            };
            node.post(me, SimTime::ZERO, done);
            continue;
        }
        let packet = {
            let mut q = queue.borrow_mut();
            let give = q.len() / split as usize;
            (give >= min_packet as usize && give > 0).then(|| {
                let keep = q.len() - give;
                q.split_off(keep)
            })
        };
        match packet {
            Some(prims) => {
                let bytes = CONTROL_BYTES + prims.len() as u64 * WORK_PACKET_BYTES_PER_PRIMITIVE;
                let prims: Vec<u32> = prims.into();
                let msg = Msg::WorkPacket { frame, prims };
                ctx.send(&node, frame, origin, Bytes::new(bytes), msg).await;
            }
            None => {
                let msg = Msg::WorkRequest { frame, origin };
                ctx.send(&node, frame, next, Bytes::new(CONTROL_BYTES), msg)
                    .await;
            }
        }
    }
}
