//! `sort-last/binary-swap` (Ma, Painter, Hansen, Krogh 1994) as one node's program.
//!
//! ```text
//! render my share into my full frame
//! k = the largest power of two <= N
//! fold: node i >= k sends its whole frame to node i - k, which z-merges it; i is done
//! my piece = the whole screen (positions 0..A in raster order)
//! for round r = 0 .. log2 k:
//!   partner = i xor 2^r; split my piece into halves
//!   keep the lower half if bit r of i is 0, else the upper; send the other half to the
//!   partner, receive the partner's pixels of my half and z-merge them
//! gather: every node sends its piece (A/k positions, as merged) to node 0, which shows the
//!   image
//! ```
//!
//! Before the gather every node of the k sends and merges A (1 - 1/k) positions, in log2 k
//! messages; the fold is the usual one for N not a power of two (the N - k extra nodes hand
//! their frames to partners first, so the swap runs on k nodes).
//!
//! Must never hold full frames on the host: pieces travel as their active pixels, charged as
//! every position of the piece.

use std::rc::Rc;

use super::full_frame::{self, piece_tag, tag, Msg, PARTITION};
use super::interlace::Interlace;
use super::pixel::ShippedPixel;
use super::{image, local, request, Ctx};
use crate::engine::{Filter, Node, SimError};

pub(super) async fn processor<P: ShippedPixel>(
    node: Node<Msg<P>>,
    ctx: Rc<Ctx>,
) -> Result<(), SimError> {
    let me = node.id();
    let n = ctx.n;
    let k = 1 << n.ilog2();
    let area = ctx.viewport.width() * ctx.viewport.height();
    let interlace = Interlace::for_run(&ctx, k);
    for frame in ctx.frames() {
        let mut pixels = request::render_frame(&node, &ctx, frame).await?;
        if let Some(il) = &interlace {
            pixels = il.enter(&node, &ctx, pixels).await;
        }
        let mut piece = (0, area);
        // Round 0 is the fold; swap round r is round r + 1.
        if me >= k {
            full_frame::send_piece(&node, &ctx, (frame, 0), me - k, piece, pixels).await;
            pixels = Vec::new();
        } else {
            if me + k < n {
                pixels = receive_and_merge(&node, &ctx, (frame, 0), me + k, piece, pixels).await?;
            }
            let mut bit = 1;
            let mut round = 1;
            while bit < k {
                let (lo, hi) = piece;
                let mid = lo + (hi - lo) / 2;
                let split = pixels.partition_point(|p| p.loc() < mid);
                let upper = pixels.split_off(split);
                let (keep, give, mine, theirs) = if me & bit == 0 {
                    (pixels, upper, (lo, mid), (mid, hi))
                } else {
                    (upper, pixels, (mid, hi), (lo, mid))
                };
                let at = (frame, round);
                full_frame::send_piece(&node, &ctx, at, me ^ bit, theirs, give).await;
                pixels = receive_and_merge(&node, &ctx, at, me ^ bit, mine, keep).await?;
                piece = mine;
                bit <<= 1;
                round += 1;
            }
            if me != 0 {
                send_to_image(&node, &ctx, frame, piece, pixels).await;
                pixels = Vec::new();
            }
        }
        local::free_full_frame(&node, &ctx)?;
        ctx.end_aa(&node, frame)?;
        if me == 0 {
            let image = gather(&node, frame, k, (piece.0, pixels)).await;
            let image = match &interlace {
                Some(il) => il.leave(&node, &ctx, image).await,
                None => image,
            };
            full_frame::end_frame(&node, &ctx, frame, &image).await?;
        }
    }
    Ok(())
}

/// Receives `from`'s pixels of the positions `lo..hi` sent in round `round` and z-merges
/// them into `own` (the same range), charging what the encoding compares and walks.
pub(super) async fn receive_and_merge<P: ShippedPixel>(
    node: &Node<Msg<P>>,
    ctx: &Ctx,
    (frame, round): (u32, u32),
    from: u32,
    (lo, hi): (u32, u32),
    own: Vec<P>,
) -> Result<Vec<P>, SimError> {
    let input = crate::units::Bytes::new(u64::from(hi - lo) * ctx.record_bytes());
    node.alloc("input piece", input)?;
    let env = node
        .recv(Filter::tag(piece_tag(frame, round)).and_source(from))
        .await;
    let Msg::Piece { pixels: theirs, .. } = env.payload else {
        unreachable!("filtered by tag")
    };
    // What a compressed composite walks of its own: the runs inside the range.
    let inside = &own[own.partition_point(|p| p.loc() < lo)..own.partition_point(|p| p.loc() < hi)];
    let (compared, walked) = image::merge_work(ctx, (lo, hi), &theirs, inside);
    node.compute(&walked).await;
    let merged = ctx.merge_rows(node, &theirs, &own, compared).await;
    node.free("input piece", input)?;
    Ok(merged)
}

/// Sends a finished piece to node 0 (as a partition: a later, smaller message than a swap
/// round's may overtake it, so the two never share a tag), sized as every position of it.
pub(super) async fn send_to_image<P: ShippedPixel>(
    node: &Node<Msg<P>>,
    ctx: &Ctx,
    frame: u32,
    (lo, hi): (u32, u32),
    pixels: Vec<P>,
) {
    node.compute(&image::encode_work(ctx, (lo, hi), &pixels))
        .await;
    let bytes = image::bytes(ctx, (lo, hi), &pixels);
    let msg = Msg::Partition {
        frame,
        band: lo,
        pixels,
    };
    ctx.send(node, frame, 0, bytes, msg).await;
}

/// Node 0 collects the `k` - 1 other pieces into the image (its own, `own`, starts at
/// position `own.0`), in raster order.
pub(super) async fn gather<P: ShippedPixel>(
    node: &Node<Msg<P>>,
    frame: u32,
    k: u32,
    own: (u32, Vec<P>),
) -> Vec<P> {
    let mut pieces = vec![own];
    for _ in 1..k {
        let env = node.recv(Filter::tag(tag(PARTITION, frame))).await;
        let Msg::Partition { band, pixels, .. } = env.payload else {
            unreachable!("filtered by tag")
        };
        pieces.push((band, pixels));
    }
    pieces.sort_by_key(|(lo, _)| *lo);
    pieces.into_iter().flat_map(|(_, p)| p).collect()
}
