//! `pieces=interleaved` for the swapping composites (binary swap, radix-k, 2-3 swap): IceT's
//! interlaced images, here by rows. Before compositing, a node reorders its image so that
//! the screen's rows run in the order (y mod K, y div K), K the number of final pieces; the
//! contiguous pieces the rounds cut are then bands of rows spread over the whole screen
//! (with K dividing the height, final piece j is exactly the rows y = j mod K), so a dense
//! cluster of geometry is shared by every piece instead of landing in one. Node 0 puts the
//! gathered image back in raster order.
//!
//! Owns the permutation of positions and the cost of applying it: one pass copying every
//! position of a dense image, or every active pixel of an rle one, priced as the rle
//! encoder's pass over a position (`rle_pixel` each: a read and a write, no depth test),
//! once at every node before compositing and once at node 0 after the gather. Must never change
//! which pixel wins a merge: merges compare pixels of one position, and a permutation keeps
//! positions apart.

use super::full_frame::Msg;
use super::options::{ImageEncoding, Pieces};
use super::pixel::ShippedPixel;
use super::Ctx;
use crate::engine::Node;
use crate::machine::{Counts, Op};

/// The row permutation for `pieces` final pieces on the run's screen.
pub struct Interlace {
    width: u32,
    /// Rank of screen row y in the interlaced order.
    rank: Vec<u32>,
    /// Screen row at each rank.
    row: Vec<u32>,
}

impl Interlace {
    /// `None` when the run keeps pieces contiguous.
    pub fn for_run(ctx: &Ctx, pieces: u32) -> Option<Interlace> {
        (ctx.settings.pieces == Pieces::Interleaved)
            .then(|| Interlace::new(ctx.viewport.width(), ctx.viewport.height(), pieces.max(1)))
    }

    pub fn new(width: u32, height: u32, pieces: u32) -> Interlace {
        let mut row: Vec<u32> = (0..height).collect();
        row.sort_by_key(|&y| (y % pieces, y / pieces));
        let mut rank = vec![0; height as usize];
        for (r, &y) in row.iter().enumerate() {
            rank[y as usize] = r as u32;
        }
        Interlace { width, rank, row }
    }

    /// The interlaced position of screen position `loc`.
    pub fn key(&self, loc: u32) -> u32 {
        self.rank[(loc / self.width) as usize] * self.width + loc % self.width
    }

    /// The screen position of interlaced position `key`.
    pub fn loc(&self, key: u32) -> u32 {
        self.row[(key / self.width) as usize] * self.width + key % self.width
    }

    /// `pixels` (raster order) moved to their interlaced positions, in that order, charging
    /// the copy.
    pub async fn enter<P: ShippedPixel>(
        &self,
        node: &Node<Msg<P>>,
        ctx: &Ctx,
        pixels: Vec<P>,
    ) -> Vec<P> {
        self.permute(node, ctx, pixels, |loc| self.key(loc)).await
    }

    /// The gathered image (interlaced order) back in raster order, charging the copy.
    pub async fn leave<P: ShippedPixel>(
        &self,
        node: &Node<Msg<P>>,
        ctx: &Ctx,
        pixels: Vec<P>,
    ) -> Vec<P> {
        self.permute(node, ctx, pixels, |key| self.loc(key)).await
    }

    async fn permute<P: ShippedPixel>(
        &self,
        node: &Node<Msg<P>>,
        ctx: &Ctx,
        mut pixels: Vec<P>,
        to: impl Fn(u32) -> u32,
    ) -> Vec<P> {
        let copied = match ctx.settings.image {
            ImageEncoding::Dense => u64::from(ctx.viewport.width() * ctx.viewport.height()),
            ImageEncoding::Rle => pixels.len() as u64,
        };
        node.compute(&Counts::of(Op::RlePixel, copied)).await;
        for p in &mut pixels {
            p.set_loc(to(p.loc()));
        }
        pixels.sort_by_key(P::loc);
        pixels
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_deal_round_robin_and_the_permutation_inverts() {
        let il = Interlace::new(4, 6, 4);
        // Rows by (y mod 4, y div 4): 0, 4, 1, 5, 2, 3.
        assert_eq!(il.row, [0, 4, 1, 5, 2, 3]);
        for loc in 0..24 {
            assert_eq!(il.loc(il.key(loc)), loc);
        }
        // With K dividing the height, final piece j holds exactly rows y = j mod K.
        let il = Interlace::new(8, 16, 4);
        for j in 0..4u32 {
            let piece = (j * 32)..((j + 1) * 32);
            let rows: Vec<u32> = piece.step_by(8).map(|key| il.loc(key) / 8).collect();
            assert_eq!(rows, [j, j + 4, j + 8, j + 12]);
        }
    }
}
