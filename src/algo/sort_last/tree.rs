//! `sort-last/tree` (IceT's reduce tree): after rendering, nodes merge whole frames in pairs
//! up a binary tree, and node 0 ends with the image.
//!
//! ```text
//! render my share into my full frame
//! for stride s = 1, 2, 4, ... while s < N:
//!   if my id is an odd multiple of s: send my frame to node id - s; done
//!   if node id + s exists: receive its frame and z-merge it into mine
//! node 0 holds the image
//! ```
//!
//! Any N works: a node whose partner id + s does not exist just waits for the next round.
//! Every merge moves and depth-compares a full frame (A positions dense; with `image=rle` its
//! active pixels and runs), so a frame costs N - 1 frame messages and log2 N rounds on the
//! critical path; the sender's frame travels as one message.
//!
//! Must never hold full frames on the host: frames travel as their active pixels, charged
//! as full frames.

use std::rc::Rc;

use super::composite::{receive_and_merge, Sender};
use super::full_frame::{self, Msg};
use super::pixel::ShippedPixel;
use super::{local, request, Ctx};
use crate::engine::{Node, SimError};

pub(super) async fn processor<P: ShippedPixel>(
    node: Node<Msg<P>>,
    ctx: Rc<Ctx>,
) -> Result<(), SimError> {
    let me = node.id();
    let n = ctx.n;
    let screen = (0, ctx.viewport.width() * ctx.viewport.height());
    for frame in ctx.frames() {
        let mut pixels = request::render_frame(&node, &ctx, frame).await?;
        let mut stride = 1;
        let mut round = 0;
        while stride < n {
            let at = (frame, round);
            if me % (2 * stride) == stride {
                full_frame::send_piece(&node, &ctx, at, me - stride, screen, pixels).await;
                pixels = Vec::new();
                break;
            }
            if me + stride < n {
                pixels =
                    receive_and_merge(&node, &ctx, at, Sender::Node(me + stride), screen, pixels)
                        .await?;
            }
            stride *= 2;
            round += 1;
        }
        local::free_full_frame(&node, &ctx)?;
        ctx.end_aa(&node, frame)?;
        if me == 0 {
            full_frame::end_frame(&node, &ctx, frame, &pixels).await?;
        }
    }
    Ok(())
}
