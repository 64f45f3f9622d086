//! `sort-last/radix-k` (Peterka, Goodell, Ross, Shen, Thakur 2009) as one node's program.
//!
//! ```text
//! render my share into my full frame
//! N = k1 x k2 x ... ; my id in that mixed radix has one digit per round
//! my piece = the whole screen (positions 0..A in raster order)
//! for round r: my group = the k_r nodes whose ids differ from mine in digit r only
//!   cut my piece into k_r parts; part j belongs to the member whose digit r is j
//!   send every other member its part (a direct send within the group)
//!   receive the k_r - 1 members' pixels of my part, z-merging each as it arrives
//! gather: every node sends its piece (A/N positions, rgb and z as merged) to node 0
//! ```
//!
//! Before the gather every node sends A (1 - 1/N) positions in sum(k_r - 1) messages. With
//! k = 2, 2, ... it is binary swap without the fold; with one round of N it is direct send
//! of contiguous parts.
//!
//! Must never hold full frames on the host: parts travel as their active pixels, charged as
//! every position of the part.

use std::rc::Rc;

use super::composite::{self, cut, receive_and_merge, Sender};
use super::full_frame::{self, Msg};
use super::interlace::Interlace;
use super::pixel::ShippedPixel;
use super::Ctx;
use crate::engine::{Node, SimError};

/// The group sizes `auto` picks for `n` processors: 8 while 8 divides what is left (IceT's
/// default radix), then the largest divisor of the rest up to 8, and a prime above 8 as one
/// round of its own. Empty for one processor.
pub fn default_radices(n: u32) -> Vec<u32> {
    let mut left = n;
    let mut radices = Vec::new();
    while left > 1 {
        let k = (2..=8.min(left))
            .rev()
            .find(|k| left % k == 0)
            .unwrap_or(left);
        radices.push(k);
        left /= k;
    }
    radices
}

/// The ids of the members of `me`'s round-`round` group, in digit order (`me` among them).
pub fn group(me: u32, radices: &[u32], round: usize) -> Vec<u32> {
    let stride: u32 = radices[..round].iter().product();
    let k = radices[round];
    let digit = me / stride % k;
    let base = me - digit * stride;
    (0..k).map(|j| base + j * stride).collect()
}

/// Part `j` of `k` of the positions `lo..hi`.
fn part((lo, hi): (u32, u32), k: u32, j: u32) -> (u32, u32) {
    let cut = |j: u32| lo + ((u64::from(hi - lo) * u64::from(j)) / u64::from(k)) as u32;
    (cut(j), cut(j + 1))
}

pub(super) async fn processor<P: ShippedPixel>(
    node: Node<Msg<P>>,
    ctx: Rc<Ctx>,
) -> Result<(), SimError> {
    let me = node.id();
    let radices = ctx.settings.radices.clone();
    let area = ctx.viewport.width() * ctx.viewport.height();
    let interlace = Interlace::for_run(&ctx, ctx.n);
    for frame in ctx.frames() {
        let mut pixels = composite::render(&node, &ctx, frame, interlace.as_ref()).await?;
        let mut piece = (0, area);
        for (round, &k) in radices.iter().enumerate() {
            let members = group(me, &radices, round);
            let mine = members.iter().position(|&m| m == me).expect("in my group") as u32;
            let parts = cut(pixels, (0..k).map(|j| part(piece, k, j).1));
            let mut keep = Vec::new();
            for (j, (&member, pixels)) in members.iter().zip(parts).enumerate() {
                if member == me {
                    keep = pixels;
                } else {
                    let range = part(piece, k, j as u32);
                    let at = (frame, round as u32);
                    full_frame::send_piece(&node, &ctx, at, member, range, pixels).await;
                }
            }
            piece = part(piece, k, mine);
            for _ in 1..k {
                let at = (frame, round as u32);
                keep = receive_and_merge(&node, &ctx, at, Sender::First, piece, keep).await?;
            }
            pixels = keep;
        }
        let held = Some((piece, pixels));
        composite::finish(&node, &ctx, frame, ctx.n, held, interlace.as_ref()).await?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_takes_rounds_of_eight_then_the_largest_divisor() {
        assert_eq!(default_radices(1), Vec::<u32>::new());
        assert_eq!(default_radices(512), [8, 8, 8]);
        assert_eq!(default_radices(128), [8, 8, 2]);
        assert_eq!(default_radices(12), [6, 2]);
        assert_eq!(default_radices(13), [13]);
        assert_eq!(default_radices(26), [2, 13]);
    }

    #[test]
    fn groups_differ_in_one_digit() {
        let radices = [4, 2, 3];
        assert_eq!(group(0, &radices, 0), [0, 1, 2, 3]);
        assert_eq!(group(5, &radices, 1), [1, 5]);
        assert_eq!(group(5, &radices, 2), [5, 13, 21]);
        assert_eq!(part((0, 10), 3, 0), (0, 3));
        assert_eq!(part((0, 10), 3, 2), (6, 10));
    }
}
