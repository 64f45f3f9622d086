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

use super::composite::{self, cut, receive_and_merge, Sender};
use super::full_frame::{self, Msg};
use super::interlace::Interlace;
use super::pixel::ShippedPixel;
use super::Ctx;
use crate::engine::{Node, SimError};

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
        let mut pixels = composite::render(&node, &ctx, frame, interlace.as_ref()).await?;
        let mut piece = (0, area);
        // Round 0 is the fold; swap round r is round r + 1.
        if me >= k {
            full_frame::send_piece(&node, &ctx, (frame, 0), me - k, piece, pixels).await;
            composite::finish(&node, &ctx, frame, k, None, interlace.as_ref()).await?;
            continue;
        }
        if me + k < n {
            pixels =
                receive_and_merge(&node, &ctx, (frame, 0), Sender::Node(me + k), piece, pixels)
                    .await?;
        }
        let mut bit = 1;
        let mut round = 1;
        while bit < k {
            let (lo, hi) = piece;
            let mid = lo + (hi - lo) / 2;
            let [lower, upper]: [Vec<P>; 2] = cut(pixels, [mid, hi].into_iter())
                .try_into()
                .expect("two halves");
            let (keep, give, mine, theirs) = if me & bit == 0 {
                (lower, upper, (lo, mid), (mid, hi))
            } else {
                (upper, lower, (mid, hi), (lo, mid))
            };
            let at = (frame, round);
            full_frame::send_piece(&node, &ctx, at, me ^ bit, theirs, give).await;
            pixels = receive_and_merge(&node, &ctx, at, Sender::Node(me ^ bit), mine, keep).await?;
            piece = mine;
            bit <<= 1;
            round += 1;
        }
        let held = Some((piece, pixels));
        composite::finish(&node, &ctx, frame, k, held, interlace.as_ref()).await?;
    }
    Ok(())
}
