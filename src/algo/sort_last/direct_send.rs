//! `sort-last/direct-send` (paper 003, section 4; the Kubota Denali scheme): node k owns the
//! interleaved scanlines y = k mod n of the screen, and every pixel goes to the node owning
//! its location. Without a local z-buffer (the default) every fragment is shipped as it is
//! generated, d*A pixels in all; with `local-zbuffer=on` a node z-buffers its share first and
//! ships only its active pixels. Owners z-merge what they receive (`composite_pixel` per
//! pixel) and finally send their rows to node 0, which holds the frame buffer.
//!
//! What the frame record counts: the merge traffic only, in shipped pixels (an address and
//! a record each, `ACTIVE_PIXEL_BYTES` without anti-aliasing), including the pixels a node
//! owns itself (delivered through its own memory, with no network message), as paper 003 and
//! trace replay count d*A. With adaptive anti-aliasing a fragment that covers its pixel
//! partly carries its coverage mask, a shipped super pixel its Subpixels, and the owner
//! merges sample by sample. Owners resolve their rows; the image gather to node 0 (rgb rows,
//! 3 bytes a pixel) crosses the network and shows in the machine's per-node statistics, but
//! not in the frame's bytes.
//!
//! With `local-zbuffer=on` and `image=rle`, a node's pixels for an owner travel as runs of
//! the owner's rows (IceT's sparse image over the owner's part): a record per active pixel
//! and an 8-byte header per run of consecutive positions instead of an address per pixel;
//! the sender scans its whole frame once to encode (`rle_pixel` per position, `rle_run` per
//! run) and the owner walks each message's runs (`rle_run`) as it merges.
//!
//! Must never depth-test before shipping unless `local-zbuffer=on`, and never let an owner
//! decide its rows before every sender's last message has arrived.

use std::rc::Rc;

use super::image::{active_runs, RUN_BYTES};
use super::options::ImageEncoding;
use super::pixel::{Px, ShippedPixel};
use super::sparse::{BucketTarget, Image, MESSAGE_PIXELS};
use super::{local, Ctx};
use crate::engine::{Filter, Node, Payload, SimError};
use crate::machine::{Counts, Op};
use crate::units::Bytes;

#[derive(Clone, Debug)]
pub(crate) enum Msg<P> {
    /// Pixels for the receiver's rows. `total` is set on the sender's last message of the
    /// frame to the number of messages it sent this receiver (messages of different sizes
    /// may overtake each other, so the flag alone would not do).
    Pixels {
        frame: u32,
        pixels: Rc<Vec<P>>,
        total: Option<u32>,
    },
    /// An owner's finished rows (resolved to colours), active pixels only on the host
    /// (charged as full rows).
    Part { frame: u32, pixels: Rc<Vec<Px>> },
}

impl<P: ShippedPixel> Payload for Msg<P> {
    fn tag(&self) -> u32 {
        match self {
            Msg::Pixels { frame, .. } => 2 * frame,
            Msg::Part { frame, .. } => 2 * frame + 1,
        }
    }
}

/// Bytes of a gathered image pixel (rgb).
const IMAGE_PIXEL_BYTES: u64 = 3;

/// The owner's part of the screen as dense slots: row y = me + k n is slot row k.
struct Part<P> {
    width: u32,
    n: u32,
    image: Image<P>,
}

impl<P: ShippedPixel> Part<P> {
    fn new(ctx: &Ctx, me: u32) -> Part<P> {
        let rows = owned_rows(ctx.viewport.height(), ctx.n, me);
        Part {
            width: ctx.viewport.width(),
            n: ctx.n,
            image: Image::new(rows as usize * ctx.viewport.width() as usize),
        }
    }

    /// Depth-merges pixels into the part (`composite_pixel` each, and the subpixel work;
    /// with rle, walking the message's runs).
    async fn merge(&mut self, node: &Node<Msg<P>>, ctx: &Ctx, pixels: &[P]) {
        let (width, n) = (self.width, self.n);
        let slot = |loc: u32| ((loc / width / n) * width + loc % width) as usize;
        if ctx.settings.image == ImageEncoding::Rle {
            node.compute(&Counts::of(Op::RleRun, runs(ctx, pixels)))
                .await;
        }
        ctx.merge_into(node, &mut self.image, slot, pixels, Op::CompositePixel)
            .await;
    }

    /// The active pixels of the part, raster order.
    fn pixels(&self, me: u32, height: u32) -> Vec<P> {
        let mut out = Vec::new();
        for k in 0..(me..height).step_by(self.n as usize).count() {
            for x in 0..self.width {
                let slot = k * self.width as usize + x as usize;
                out.extend(self.image.pixel(slot).cloned());
            }
        }
        out
    }
}

fn owned_rows(height: u32, n: u32, me: u32) -> u32 {
    (height + n - 1 - me) / n
}

/// Runs of consecutive positions of the owner's part among `pixels` (all for one owner, in
/// raster order): consecutive in the part means the same row and the next x, since the
/// owner's rows follow one another in its part.
fn runs<P: ShippedPixel>(ctx: &Ctx, pixels: &[P]) -> u64 {
    let (w, n) = (ctx.viewport.width(), ctx.n);
    active_runs(pixels.iter().map(|p| (p.loc() / w / n) * w + p.loc() % w))
}

/// Bytes of a message carrying `pixels` to one owner: each with its address (dense), or a
/// full-frame record each plus a header per run (rle).
fn message_bytes<P: ShippedPixel>(ctx: &Ctx, pixels: &[P]) -> u64 {
    match ctx.settings.image {
        ImageEncoding::Dense => pixels.iter().map(P::wire_bytes).sum(),
        ImageEncoding::Rle => {
            let extra: u64 = pixels.iter().map(P::extra_bytes).sum();
            pixels.len() as u64 * ctx.record_bytes() + extra + runs(ctx, pixels) * RUN_BYTES
        }
    }
}

/// One processor: renderer, sender, owner of its scanlines; node 0 also the frame buffer.
pub(crate) async fn processor<P: ShippedPixel>(
    node: Node<Msg<P>>,
    ctx: Rc<Ctx>,
) -> Result<(), SimError> {
    let me = node.id();
    let n = ctx.n;
    let w = ctx.viewport.width();
    for frame in ctx.frames() {
        if me == 0 {
            ctx.book.begin(&node, frame);
        }
        ctx.begin_aa(&node, frame)?;
        let mut part = Part::<P>::new(&ctx, me);
        let part_bytes = ctx.rows_bytes(owned_rows(ctx.viewport.height(), n, me));
        node.alloc("owned rows", part_bytes)?;
        node.phase("render");
        let mut stream = Outgoing::new(n);
        if ctx.settings.local_zbuffer {
            local::clear_full_frame(&node, &ctx).await?;
            let rendered: Vec<P> = local::render_own_share(&node, &ctx, frame).await?;
            let mut buckets = vec![Vec::new(); n as usize];
            node.compute(&Counts::of(Op::BucketInsert, rendered.len() as u64))
                .await;
            for p in rendered {
                buckets[(p.loc() / w % n) as usize].push(p);
            }
            if ctx.settings.image == ImageEncoding::Rle {
                // One pass over the frame writes every owner's runs.
                let area = u64::from(w) * u64::from(ctx.viewport.height());
                let mut work = Counts::of(Op::RlePixel, area);
                work += &Counts::of(Op::RleRun, buckets.iter().map(|b| runs(&ctx, b)).sum());
                node.compute(&work).await;
            }
            local::free_full_frame(&node, &ctx)?;
            // The local frame is gone once bucketed: its Subpixel blocks are free again.
            ctx.aa.release_render(me);
            node.phase("send");
            stream.add(buckets);
            stream.flush(&node, &ctx, frame, &mut part, false).await;
        } else {
            // Every fragment as generated: render a batch, ship the full messages.
            let share = ctx.share(&node, frame)?;
            let mut target = BucketTarget::<P>::new(&ctx, frame);
            for batch in share.chunks(local::BATCH) {
                let before = target.fragments;
                local::render(&node, &ctx, frame, batch, &mut target).await?;
                node.compute(&Counts::of(Op::BucketInsert, target.fragments - before))
                    .await;
                stream.add(std::mem::replace(
                    &mut target.buckets,
                    vec![Vec::new(); n as usize],
                ));
                stream.flush(&node, &ctx, frame, &mut part, false).await;
            }
            local::raster_finished(&node, &ctx, frame);
            node.phase("send");
        }
        stream.flush(&node, &ctx, frame, &mut part, true).await;

        // What the node holds to the end of the frame: its rows' Pixels.
        let owned = u64::from(owned_rows(ctx.viewport.height(), n, me)) * u64::from(w);
        ctx.aa.hold_pixels(me, owned);
        node.phase("merge");
        // This node's own stream was merged as it was produced.
        let mut received = vec![0u32; n as usize];
        let mut expected: Vec<Option<u32>> = vec![None; n as usize];
        expected[me as usize] = Some(0);
        let done = |r: &[u32], e: &[Option<u32>]| r.iter().zip(e).all(|(r, e)| Some(*r) == *e);
        while !done(&received, &expected) {
            let env = node.recv(Filter::tag(2 * frame)).await;
            let src = env.src as usize;
            let Msg::Pixels { pixels, total, .. } = env.payload else {
                unreachable!("tag 2f carries pixels")
            };
            part.merge(&node, &ctx, &pixels).await;
            received[src] += 1;
            if total.is_some() {
                expected[src] = total;
            }
        }

        node.phase("gather");
        let height = ctx.viewport.height();
        let width = ctx.viewport.width() as u64;
        let mine = resolve(&node, &ctx, part.pixels(me, height)).await;
        if me == 0 {
            let mut all = mine;
            for _ in 1..n {
                let env = node.recv(Filter::tag(2 * frame + 1)).await;
                let Msg::Part { pixels, .. } = env.payload else {
                    unreachable!("tag 2f+1 carries parts")
                };
                let rows = owned_rows(height, n, env.src) as u64;
                node.compute(&Counts::of(Op::PixelWrite, rows * width))
                    .await;
                all.extend_from_slice(&pixels);
            }
            ctx.show(&node, frame, &all).await;
            let now = node.now();
            ctx.record(frame, |r| r.end = now);
        } else {
            let rows = owned_rows(height, n, me) as u64;
            let msg = Msg::Part {
                frame,
                pixels: Rc::new(mine),
            };
            node.send(0, Bytes::new(rows * width * IMAGE_PIXEL_BYTES), msg)
                .await;
        }
        node.free("owned rows", part_bytes)?;
        ctx.end_aa(&node, frame)?;
    }
    Ok(())
}

/// An owner's rows as the image shows them (super pixels resolved, `resolve_pixel` each),
/// as the colours the gather ships.
async fn resolve<P: ShippedPixel>(node: &Node<Msg<P>>, ctx: &Ctx, pixels: Vec<P>) -> Vec<Px> {
    let resolved = ctx.resolve_rows(node, pixels).await;
    resolved
        .iter()
        .map(|p| {
            let (rgb, z) = p.resolve();
            Px {
                loc: p.loc(),
                z,
                prim: 0,
                rgb,
            }
        })
        .collect()
}

/// A sender's pixels waiting per owner.
struct Outgoing<P> {
    pending: Vec<Vec<P>>,
    /// Messages sent to each node so far this frame.
    sent: Vec<u32>,
}

impl<P: ShippedPixel> Outgoing<P> {
    fn new(n: u32) -> Outgoing<P> {
        Outgoing {
            pending: vec![Vec::new(); n as usize],
            sent: vec![0; n as usize],
        }
    }

    fn add(&mut self, buckets: Vec<Vec<P>>) {
        for (pending, mut b) in self.pending.iter_mut().zip(buckets) {
            if pending.is_empty() {
                *pending = b;
            } else {
                pending.append(&mut b);
            }
        }
    }

    /// Ships every full message (and, when `last`, the remainders with the end flag, one
    /// message per owner even if empty). Owners are visited starting after this node, so
    /// senders do not all hit node 0 first. The node's own pixels merge locally.
    async fn flush(
        &mut self,
        node: &Node<Msg<P>>,
        ctx: &Ctx,
        frame: u32,
        part: &mut Part<P>,
        last: bool,
    ) {
        let me = node.id();
        let n = ctx.n;
        for k in 1..=n {
            let dst = (me + k) % n;
            let pending = std::mem::take(&mut self.pending[dst as usize]);
            let mut chunks: Vec<&[P]> = pending.chunks(MESSAGE_PIXELS).collect();
            let keep = if !last && chunks.last().is_some_and(|c| c.len() < MESSAGE_PIXELS) {
                chunks.pop()
            } else {
                None
            };
            if dst == me {
                let bytes: u64 = chunks.iter().map(|c| message_bytes(ctx, c)).sum();
                for c in &chunks {
                    part.merge(node, ctx, c).await;
                }
                ctx.record(frame, |r| r.bytes += Bytes::new(bytes));
            } else {
                if last && chunks.is_empty() {
                    chunks.push(&[]);
                }
                let count = chunks.len();
                for (i, c) in chunks.into_iter().enumerate() {
                    let bytes = Bytes::new(message_bytes(ctx, c));
                    self.sent[dst as usize] += 1;
                    let total = self.sent[dst as usize];
                    let msg = Msg::Pixels {
                        frame,
                        pixels: Rc::new(c.to_vec()),
                        total: (last && i + 1 == count).then_some(total),
                    };
                    ctx.send(node, frame, dst, bytes, msg).await;
                }
            }
            if let Some(rest) = keep {
                self.pending[dst as usize] = rest.to_vec();
            }
        }
    }
}
