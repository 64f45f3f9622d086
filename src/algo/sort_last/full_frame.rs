//! What paper 001's three full-frame algorithms (DF, PC, ScanlineFlow) share: their message
//! kinds, the frame barrier, and the host-side form of a node's frame.
//!
//! A node's frame is charged as a full frame (every pixel is moved and depth-compared), but
//! the host keeps only its active pixels in raster order ([`Rows`]), and merges them with
//! [`crate::raster::target::nearer`], so the merged image is the sequential z-buffer's.
//!
//! Must never charge time or decide anything for a variant: it only carries and merges
//! pixels and synchronizes frames.

use std::rc::Rc;

use super::pixel::ShippedPixel;
use super::{image, Ctx};
use crate::engine::{Filter, Node, Payload, SimError};
use crate::raster::ScreenRect;
use crate::units::Bytes;

/// Bytes of a control message (a request, a credit, a frame start).
pub const CONTROL_BYTES: u64 = 16;

/// The messages of the full-frame algorithms. Tags carry the frame (see [`tag`]).
#[derive(Clone, Debug)]
pub enum Msg<P> {
    /// The holder of the previous frame's image lets everyone start `frame`.
    Start { frame: u32 },
    /// Request balancing: `origin` asks around the ring for work.
    WorkRequest { frame: u32, origin: u32 },
    /// Request balancing: a packet of primitives for the node that asked (empty: the
    /// asking node's own request came back unanswered, local termination).
    WorkPacket { frame: u32, prims: Vec<u32> },
    /// DF: the owner of band `band` asks for that part of a node's frame.
    BandRequest { frame: u32, band: u32 },
    /// DF: one node's part of band `band` (a full band is charged).
    BandReply { frame: u32, pixels: Rc<Vec<P>> },
    /// DF: a merged partition on its way to the controller.
    Partition {
        frame: u32,
        band: u32,
        pixels: Vec<P>,
    },
    /// PC and ScanlineFlow: rows `y0..y1` merged so far (every pixel of them charged). The
    /// rows travel with the chunk: chunks of different sizes may overtake each other.
    Chunk {
        frame: u32,
        y0: u32,
        y1: u32,
        pixels: Vec<P>,
    },
    /// PC and ScanlineFlow: an input buffer was freed (a credit for the sender).
    Credit { frame: u32 },
    /// A hand-off between two programs of one node (a semaphore), never on the network.
    Local { frame: u32 },
    /// Tree, binary swap, radix-k, 2-3 swap: a range of screen positions the receiver knows
    /// (raster order), sized by the run's image encoding (`image.rs`), sent in compositing
    /// round `round` (a later round's piece from the same sender may overtake it).
    Piece {
        frame: u32,
        round: u32,
        pixels: Vec<P>,
        /// With `bounds=on`, the sender's rectangle (where its pixels can be).
        rect: Option<ScreenRect>,
    },
}

/// Message kinds, the low bits of a tag.
pub const START: u32 = 0;
pub const WORK_REQUEST: u32 = 1;
pub const WORK_PACKET: u32 = 2;
pub const BAND_REQUEST: u32 = 4;
pub const BAND_REPLY: u32 = 5;
pub const PARTITION: u32 = 6;
pub const CHUNK: u32 = 7;
pub const CREDIT: u32 = 8;
pub const LOCAL: u32 = 9;
/// Pieces of compositing round r have kind `PIECE + r`.
pub const PIECE: u32 = 16;
/// Rounds a compositing variant may take (2^20 nodes, the most a machine may have, take 20).
pub const MAX_ROUNDS: u32 = 256 - PIECE;

/// The tag of a message of `kind` in `frame`: frames never mix in a mailbox.
pub fn tag(kind: u32, frame: u32) -> u32 {
    debug_assert!(kind < 256);
    (frame << 8) | kind
}

/// The tag of a piece of compositing round `round` in `frame`.
pub fn piece_tag(frame: u32, round: u32) -> u32 {
    debug_assert!(round < MAX_ROUNDS);
    tag(PIECE + round, frame)
}

impl<P: ShippedPixel> Payload for Msg<P> {
    fn tag(&self) -> u32 {
        match self {
            Msg::Start { frame } => tag(START, *frame),
            Msg::WorkRequest { frame, .. } => tag(WORK_REQUEST, *frame),
            Msg::WorkPacket { frame, .. } => tag(WORK_PACKET, *frame),
            Msg::BandRequest { frame, .. } => tag(BAND_REQUEST, *frame),
            Msg::BandReply { frame, .. } => tag(BAND_REPLY, *frame),
            Msg::Partition { frame, .. } => tag(PARTITION, *frame),
            Msg::Chunk { frame, .. } => tag(CHUNK, *frame),
            Msg::Credit { frame } => tag(CREDIT, *frame),
            Msg::Local { frame, .. } => tag(LOCAL, *frame),
            Msg::Piece { frame, round, .. } => piece_tag(*frame, *round),
        }
    }
}

/// A node's frame on the host: active pixels in raster order, and where each row starts.
pub struct Rows<P> {
    pixels: Vec<P>,
    starts: Vec<usize>,
}

impl<P: ShippedPixel> Rows<P> {
    /// From active pixels in raster order, for a viewport of `width` x `height`.
    pub fn new(pixels: Vec<P>, width: u32, height: u32) -> Rows<P> {
        let mut starts = Vec::with_capacity(height as usize + 1);
        let mut i = 0;
        for y in 0..=height {
            while i < pixels.len() && pixels[i].loc() / width < y {
                i += 1;
            }
            starts.push(i);
        }
        Rows { pixels, starts }
    }

    /// The active pixels of rows `y0..y1`.
    pub fn rows(&self, y0: u32, y1: u32) -> &[P] {
        &self.pixels[self.starts[y0 as usize]..self.starts[y1 as usize]]
    }
}

/// Starts `frame` on this node: the first frame starts at once; a later one when the holder
/// of the previous frame's image says so. Node 0 records the frame's start; every node
/// takes its Subpixel pool (adaptive anti-aliasing).
pub async fn start_frame<P: ShippedPixel>(
    node: &Node<Msg<P>>,
    ctx: &Ctx,
    frame: u32,
) -> Result<(), SimError> {
    if frame != ctx.cfg.frames.start {
        node.recv(Filter::tag(tag(START, frame))).await;
    }
    if node.id() == 0 {
        ctx.book.begin(node, frame);
    }
    ctx.begin_aa(node, frame)
}

/// Sends rows `y0..y1` (`pixels` active in them) to `dst`, sized as the full rows.
pub async fn send_chunk<P: ShippedPixel>(
    node: &Node<Msg<P>>,
    ctx: &Ctx,
    frame: u32,
    dst: u32,
    (y0, y1): (u32, u32),
    pixels: Vec<P>,
) {
    let bytes = ctx.chunk_bytes(y1 - y0, &pixels);
    let msg = Msg::Chunk {
        frame,
        y0,
        y1,
        pixels,
    };
    ctx.send(node, frame, dst, bytes, msg).await;
}

/// Sends the screen positions `lo..hi` (`pixels` active among them) to `dst`, encoded as
/// the run asks (`image`: dense, every position; rle, the active ones and their runs), after
/// charging the encoding.
pub async fn send_piece<P: ShippedPixel>(
    node: &Node<Msg<P>>,
    ctx: &Ctx,
    (frame, round): (u32, u32),
    dst: u32,
    range: (u32, u32),
    pixels: Vec<P>,
) {
    let scanned = ctx.scanned(node.id(), range);
    node.compute(&image::encode_work(ctx, range, scanned, &pixels))
        .await;
    let bytes = image::bytes(ctx, range, &pixels);
    let msg = Msg::Piece {
        frame,
        round,
        pixels,
        rect: ctx.bounds.rect(node.id()),
    };
    ctx.send(node, frame, dst, bytes, msg).await;
}

/// Ends `frame` at the node holding its image (`image`, the merged pixels): shows it
/// (resolving anti-aliased pixels), records the end and lets every other node start the
/// next frame. (The holder itself starts the next frame when this returns.)
pub async fn end_frame<P: ShippedPixel>(
    node: &Node<Msg<P>>,
    ctx: &Ctx,
    frame: u32,
    image: &[P],
) -> Result<(), SimError> {
    ctx.show(node, frame, image).await;
    let now = node.now();
    ctx.record(frame, |r| r.end = now);
    if !ctx.is_last(frame) {
        let me = node.id();
        for p in (0..ctx.n).filter(|&p| p != me) {
            ctx.send(
                node,
                frame + 1,
                p,
                Bytes::new(CONTROL_BYTES),
                Msg::Start { frame: frame + 1 },
            )
            .await;
        }
        node.post(
            me,
            crate::units::SimTime::ZERO,
            Msg::Start { frame: frame + 1 },
        );
    }
    Ok(())
}
