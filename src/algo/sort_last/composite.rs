//! What the compositing variants that cut the image into pieces (tree, binary swap, radix-k,
//! 2-3 swap) share around their rounds: rendering the frame (reordered when pieces are
//! interleaved), cutting a piece's pixels at part boundaries, receiving and merging a piece,
//! and the end of the frame (every piece to node 0, which shows the image).
//!
//! Must never decide who talks to whom: the rounds are each variant's.

use super::full_frame::{self, piece_tag, tag, Msg, PARTITION};
use super::interlace::Interlace;
use super::pixel::ShippedPixel;
use super::{image, local, request, Ctx};
use crate::engine::{Filter, Node, SimError};

/// This node's rendered frame for compositing, in raster order or, with `interlace`, in the
/// interlaced order.
pub(super) async fn render<P: ShippedPixel>(
    node: &Node<Msg<P>>,
    ctx: &std::rc::Rc<Ctx>,
    frame: u32,
    interlace: Option<&Interlace>,
) -> Result<Vec<P>, SimError> {
    let pixels = request::render_frame(node, ctx, frame).await?;
    Ok(match interlace {
        Some(il) => il.enter(node, ctx, pixels).await,
        None => pixels,
    })
}

/// `pixels` (ordered by position) cut before each of `ends`, ascending: the pixels below the
/// first end, then those below the second, and so on (the last part ends at the last end).
pub(super) fn cut<P: ShippedPixel>(
    mut pixels: Vec<P>,
    ends: impl Iterator<Item = u32>,
) -> Vec<Vec<P>> {
    ends.map(|end| {
        let rest = pixels.split_off(pixels.partition_point(|p| p.loc() < end));
        std::mem::replace(&mut pixels, rest)
    })
    .collect()
}

/// The end of a composited frame: a node holding a finished piece (`held`: its positions and
/// pixels; `None` when it handed its frame on) other than node 0 sends it to node 0; every
/// node frees its frame; node 0 gathers `pieces` pieces and shows the image (back in raster
/// order when interlaced).
pub(super) async fn finish<P: ShippedPixel>(
    node: &Node<Msg<P>>,
    ctx: &Ctx,
    frame: u32,
    pieces: u32,
    held: Option<((u32, u32), Vec<P>)>,
    interlace: Option<&Interlace>,
) -> Result<(), SimError> {
    let me = node.id();
    let own = match held {
        // The image stays in pieces: each node is done when its last merge is.
        Some((_, pixels)) if !ctx.settings.gather => {
            ctx.leave_piece(&pixels);
            None
        }
        Some((range, pixels)) if me != 0 => {
            send_to_image(node, ctx, frame, range, pixels).await;
            None
        }
        held => held,
    };
    local::free_full_frame(node, ctx)?;
    ctx.end_aa(node, frame)?;
    if !ctx.settings.gather {
        let now = node.now();
        ctx.record(frame, |r| r.end = r.end.max(now));
        return Ok(());
    }
    if me == 0 {
        let ((lo, _), pixels) = own.expect("node 0 holds a piece");
        let image = gather(node, frame, pieces, (lo, pixels)).await;
        let image = match interlace {
            Some(il) => il.leave(node, ctx, image).await,
            None => image,
        };
        full_frame::end_frame(node, ctx, frame, &image).await?;
    }
    Ok(())
}

/// Whose piece a receive waits for.
#[derive(Clone, Copy, Debug)]
pub(super) enum Sender {
    /// This node's.
    Node(u32),
    /// Whichever of the round's senders arrives first (the round's tag names them): a group
    /// merged as its pieces come in, as IceT's radix-k does with a wait-any.
    First,
}

/// Receives a piece of the positions `lo..hi` sent in round `round` (`from` whom) and
/// z-merges it into `own` (the same range), charging what the encoding compares and walks.
/// Merging is order-free (depth, then primitive), so arrival order changes times, not pixels.
pub(super) async fn receive_and_merge<P: ShippedPixel>(
    node: &Node<Msg<P>>,
    ctx: &Ctx,
    (frame, round): (u32, u32),
    from: Sender,
    (lo, hi): (u32, u32),
    own: Vec<P>,
) -> Result<Vec<P>, SimError> {
    let filter = Filter::tag(piece_tag(frame, round));
    let env = match from {
        Sender::Node(src) => node.recv(filter.and_source(src)).await,
        Sender::First => node.recv(filter).await,
    };
    let Msg::Piece {
        pixels: theirs,
        rect,
        ..
    } = env.payload
    else {
        unreachable!("filtered by tag")
    };
    // A buffer for every position of the range, or with bounds those inside the sender's
    // rectangle.
    let positions = ctx.positions_within(rect, (lo, hi));
    let input = crate::units::Bytes::new(positions * ctx.record_bytes());
    node.alloc("input piece", input)?;
    // What a compressed composite walks of its own: the runs inside the range.
    let inside = &own[own.partition_point(|p| p.loc() < lo)..own.partition_point(|p| p.loc() < hi)];
    let (compared, walked) = image::merge_work(ctx, (lo, hi), &theirs, inside);
    node.compute(&walked).await;
    let merged = ctx.merge_rows(node, &theirs, &own, compared).await;
    node.free("input piece", input)?;
    ctx.bounds.merge(node.id(), rect);
    Ok(merged)
}

/// Sends a finished piece to node 0 (as a partition: a later, smaller message than a swap
/// round's may overtake it, so the two never share a tag), sized as every position of it.
async fn send_to_image<P: ShippedPixel>(
    node: &Node<Msg<P>>,
    ctx: &Ctx,
    frame: u32,
    (lo, hi): (u32, u32),
    pixels: Vec<P>,
) {
    let scanned = ctx.scanned(node.id(), (lo, hi));
    node.compute(&image::encode_work(ctx, (lo, hi), scanned, &pixels))
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
async fn gather<P: ShippedPixel>(
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
