//! `sort-last/snooping` (paper 003, section 7; Cox and Hanrahan's distributed snooping) on a
//! broadcast bus: every node z-buffers its share locally, then the nodes take turns in
//! processor order 0..n-1. In its turn a node broadcasts its active pixels that no earlier
//! broadcast has deleted; every listener tests each broadcast pixel against its own buffer
//! (`pixel_test` per pixel received) and deletes the pixels it hides. Node 0 also holds the
//! frame buffer and keeps the last pixel broadcast at each location (`pixel_write` per
//! pixel), which is the sequential z-buffer's pixel.
//!
//! The turn passes by a bus-order rule, not a token: node k starts broadcasting when it has
//! seen all of node k-1's messages of the frame (the last one says how many there were; a
//! node with nothing left sends one empty message to end its turn), so the frame's bytes are exactly the broadcast pixels times
//! `ACTIVE_PIXEL_BYTES`.
//!
//! Host-side shortcut: listeners are charged for every test, but the host applies their
//! deletions lazily, at the listener's own turn, against one shared array holding the
//! nearest broadcast pixel per location (the frame buffer's contents). A pixel survives
//! eager deletion exactly when it is nearer than every earlier broadcast at its location,
//! and the broadcasts at a location only ever get nearer, so the result is the same; the
//! pixels broadcast equal trace replay's snooping count for the same assignment.
//!
//! Must never broadcast out of processor order or let a node read the shared array before
//! its turn.

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::rc::Rc;

use super::sparse::{self, Image, Px, MESSAGE_PIXELS};
use super::{local, Ctx};
use crate::engine::{Filter, Node, Payload, SimError};
use crate::machine::{Counts, Op};
use crate::raster::ACTIVE_PIXEL_BYTES;
use crate::units::Bytes;

/// Broadcast pixels. `total` is set on the last message of the sender's turn to the
/// number of messages of the turn (so a turn ends right even if messages overtook).
#[derive(Clone, Debug)]
pub(crate) struct Broadcast {
    frame: u32,
    pixels: Rc<Vec<Px>>,
    total: Option<u32>,
}

impl Payload for Broadcast {
    fn tag(&self) -> u32 {
        self.frame
    }
}

/// The nearest broadcast pixel per location, per frame in flight (host side).
#[derive(Default)]
pub(crate) struct Shared {
    fronts: RefCell<BTreeMap<u32, Image>>,
}

impl Shared {
    /// The pixels of `own` (raster order) that no earlier broadcast hides; they become the
    /// front.
    fn survivors(&self, ctx: &Ctx, frame: u32, own: &[Px]) -> Vec<Px> {
        let mut fronts = self.fronts.borrow_mut();
        let front = fronts
            .entry(frame)
            .or_insert_with(|| Image::new(ctx.viewport.pixels()));
        let mut out = Vec::new();
        for p in own {
            if front.merge(p.loc as usize, p) {
                out.push(*p);
            }
        }
        out
    }

    /// The frame buffer's pixels of `frame`, dropping the frame's array.
    fn take(&self, ctx: &Ctx, frame: u32) -> Vec<Px> {
        let Some(front) = self.fronts.borrow_mut().remove(&frame) else {
            return Vec::new();
        };
        (0..ctx.viewport.pixels() as u32)
            .filter_map(|loc| front.pixel(loc as usize, loc))
            .collect()
    }
}

/// One processor: renderer, broadcaster in its turn, listener otherwise; node 0 also the
/// frame buffer.
pub(crate) async fn processor(
    node: Node<Broadcast>,
    ctx: Rc<Ctx>,
    shared: Rc<Shared>,
) -> Result<(), SimError> {
    let me = node.id();
    let n = ctx.n;
    for frame in ctx.frames() {
        if me == 0 {
            let now = node.now();
            ctx.record(frame, |r| r.start = now);
        }
        node.phase("render");
        local::clear_full_frame(&node, &ctx).await?;
        let buffer = local::render_own_share(&node, &ctx, frame).await?;
        let own = sparse::sorted_active(&buffer, ctx.viewport.width());
        drop(buffer);

        for turn in 0..n {
            if turn == me {
                node.phase("broadcast");
                let survivors = shared.survivors(&ctx, frame, &own);
                if me == 0 {
                    node.compute(&Counts::of(Op::PixelWrite, survivors.len() as u64))
                        .await;
                }
                if n == 1 {
                    // Nobody listens: the pixels go straight into the frame buffer.
                    let bytes = Bytes::new(survivors.len() as u64 * ACTIVE_PIXEL_BYTES);
                    ctx.record(frame, |r| r.bytes += bytes);
                    continue;
                }
                let mut chunks: Vec<&[Px]> = survivors.chunks(MESSAGE_PIXELS).collect();
                if chunks.is_empty() {
                    chunks.push(&[]);
                }
                let count = chunks.len();
                for (i, c) in chunks.into_iter().enumerate() {
                    let bytes = Bytes::new(c.len() as u64 * ACTIVE_PIXEL_BYTES);
                    let msg = Broadcast {
                        frame,
                        pixels: Rc::new(c.to_vec()),
                        total: (i + 1 == count).then_some(count as u32),
                    };
                    ctx.broadcast(&node, frame, bytes, msg).await?;
                }
            } else {
                node.phase("snoop");
                let (mut received, mut expected) = (0, None);
                loop {
                    let env = node.recv(Filter::tag(frame).and_source(turn)).await;
                    let len = env.payload.pixels.len() as u64;
                    let mut work = Counts::of(Op::PixelTest, len);
                    if me == 0 {
                        work.add(Op::PixelWrite, len);
                    }
                    node.compute(&work).await;
                    received += 1;
                    if let Some(total) = env.payload.total {
                        expected = Some(total);
                    }
                    if expected == Some(received) {
                        break;
                    }
                }
            }
        }
        local::free_full_frame(&node, &ctx)?;
        if me == 0 {
            let now = node.now();
            ctx.record(frame, |r| r.end = now);
            let pixels = shared.take(&ctx, frame);
            if ctx.is_last(frame) {
                ctx.set_image(
                    &node,
                    sparse::framebuffer(ctx.viewport, ctx.background, &pixels),
                )
                .await;
            }
        }
    }
    Ok(())
}
