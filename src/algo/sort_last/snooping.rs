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
//! node with nothing left sends one empty message to end its turn), so the frame's bytes are
//! exactly the broadcast pixels' (`ACTIVE_PIXEL_BYTES` each without anti-aliasing; with
//! adaptive anti-aliasing a super pixel carries its Subpixels, tested and written per
//! sample).
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

use super::pixel::ShippedPixel;
use super::sparse::{Image, MESSAGE_PIXELS};
use super::{local, Ctx};
use crate::engine::{Filter, Node, Payload, SimError};
use crate::machine::{Counts, Op};
use crate::units::Bytes;

/// Broadcast pixels. `total` is set on the last message of the sender's turn to the
/// number of messages of the turn (so a turn ends right even if messages overtook).
#[derive(Clone, Debug)]
pub(crate) struct Broadcast<P> {
    frame: u32,
    pixels: Rc<Vec<P>>,
    total: Option<u32>,
}

impl<P: ShippedPixel> Payload for Broadcast<P> {
    fn tag(&self) -> u32 {
        self.frame
    }
}

/// The nearest broadcast pixel per location, per frame in flight (host side): node 0's
/// frame buffer.
pub(crate) struct Shared<P> {
    fronts: RefCell<BTreeMap<u32, Image<P>>>,
}

impl<P> Default for Shared<P> {
    fn default() -> Self {
        Shared {
            fronts: RefCell::default(),
        }
    }
}

impl<P: ShippedPixel> Shared<P> {
    /// The pixels of `own` (raster order) that no earlier broadcast hides entirely (some
    /// sample is nearer); they become the front. Node 0's frame buffer holds the front, so
    /// its pool provides the blocks and the frame buffer's writes are charged to node 0.
    fn survivors(&self, ctx: &Ctx, frame: u32, own: &[P]) -> Vec<P> {
        let mut front = self
            .fronts
            .borrow_mut()
            .remove(&frame)
            .unwrap_or_else(|| Image::new(ctx.viewport.pixels()));
        let survivors = ctx.aa.with_blocks(0, |blocks| {
            let survivors: Vec<P> = own
                .iter()
                .filter(|p| front.merge(p.loc() as usize, p, blocks))
                .cloned()
                .collect();
            // Charged by what is broadcast (`charge`), not by the host's lazy front.
            blocks.take_work();
            survivors
        });
        self.fronts.borrow_mut().insert(frame, front);
        survivors
    }

    /// The frame buffer's pixels of `frame`, dropping the frame's array.
    fn take(&self, ctx: &Ctx, frame: u32) -> Vec<P> {
        let Some(front) = self.fronts.borrow_mut().remove(&frame) else {
            return Vec::new();
        };
        (0..ctx.viewport.pixels())
            .filter_map(|slot| front.pixel(slot).cloned())
            .collect()
    }
}

/// One processor: renderer, broadcaster in its turn, listener otherwise; node 0 also the
/// frame buffer.
pub(crate) async fn processor<P: ShippedPixel>(
    node: Node<Broadcast<P>>,
    ctx: Rc<Ctx>,
    shared: Rc<Shared<P>>,
) -> Result<(), SimError> {
    let me = node.id();
    let n = ctx.n;
    for frame in ctx.frames() {
        if me == 0 {
            ctx.book.begin(&node, frame);
        }
        ctx.begin_aa(&node, frame)?;
        node.phase("render");
        local::clear_full_frame(&node, &ctx).await?;
        let own: Vec<P> = local::render_own_share(&node, &ctx, frame).await?;
        if me == 0 {
            // Node 0's frame buffer is the front: its own pixels enter it in turn 0 and take
            // their blocks there.
            ctx.aa.release_render(0);
        }

        for turn in 0..n {
            if turn == me {
                node.phase("broadcast");
                let survivors = shared.survivors(&ctx, frame, &own);
                if me == 0 {
                    node.compute(&frame_buffer_writes(&survivors)).await;
                }
                if n == 1 {
                    // Nobody listens: the pixels go straight into the frame buffer.
                    let bytes = Bytes::new(survivors.iter().map(P::wire_bytes).sum());
                    ctx.record(frame, |r| r.bytes += bytes);
                    continue;
                }
                let mut chunks: Vec<&[P]> = survivors.chunks(MESSAGE_PIXELS).collect();
                if chunks.is_empty() {
                    chunks.push(&[]);
                }
                let count = chunks.len();
                for (i, c) in chunks.into_iter().enumerate() {
                    let bytes = Bytes::new(c.iter().map(P::wire_bytes).sum());
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
                    let pixels = &env.payload.pixels;
                    let samples = pixels.iter().map(P::samples).sum();
                    let mut work = Counts::of(Op::PixelTest, pixels.len() as u64);
                    work.add(Op::SubpixelTest, samples);
                    if me == 0 {
                        work += &frame_buffer_writes(pixels);
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
        ctx.end_aa(&node, frame)?;
        if me == 0 {
            let pixels = shared.take(&ctx, frame);
            ctx.show(&node, frame, &pixels).await;
            let now = node.now();
            ctx.record(frame, |r| r.end = now);
        }
    }
    Ok(())
}

/// What writing broadcast pixels into the frame buffer costs: a pixel write each, and a
/// subpixel write per sample a super pixel carries.
fn frame_buffer_writes<P: ShippedPixel>(pixels: &[P]) -> Counts {
    let mut work = Counts::of(Op::PixelWrite, pixels.len() as u64);
    work.add(Op::SubpixelWrite, pixels.iter().map(P::samples).sum());
    work
}
