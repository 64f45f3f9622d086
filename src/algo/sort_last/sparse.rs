//! The host-side pixel mechanisms every sort-last merge shares, over any
//! [`ShippedPixel`]: the one raster-order depth merge of pixel lists, a dense depth-merge
//! buffer (`Image`: an owner's part of the screen, or a frame buffer), the final image, a
//! target that buckets every fragment by the node owning its row before any depth test
//! (direct send without a local z-buffer), and the message size sparse merges batch into.
//!
//! Must never charge time, send, or decide an order of its own: depth order is the pixel's
//! `merge` only (`raster::target::nearer` per pixel or per sample), so every merge built on
//! it reproduces the sequential buffer's image.

use super::pixel::ShippedPixel;
use crate::raster::aa::{Blocks, Grid};
use crate::raster::{Counters, Framebuffer, ScreenRect, Span, Target, Viewport};

/// Pixels per message when a merge batches pixels (11 KiB of active pixels).
pub const MESSAGE_PIXELS: usize = 1024;

/// Depth-merges raster-ordered `incoming` pixels into a buffer's raster-ordered `own` ones:
/// the merged pixels in raster order. A location only `incoming` has takes what the buffer
/// stores there (a super pixel needs a block from `blocks`). Every sort-last merge of pixel
/// lists goes through here.
pub fn merge_sorted<P: ShippedPixel>(incoming: &[P], own: &[P], blocks: &mut Blocks) -> Vec<P> {
    let mut out = Vec::with_capacity(incoming.len() + own.len());
    let (mut i, mut j) = (0, 0);
    while i < incoming.len() && j < own.len() {
        let (p, q) = (&incoming[i], &own[j]);
        match p.loc().cmp(&q.loc()) {
            std::cmp::Ordering::Less => {
                out.extend(p.arrive(blocks));
                i += 1;
            }
            std::cmp::Ordering::Greater => {
                out.push(q.clone());
                j += 1;
            }
            std::cmp::Ordering::Equal => {
                let mut kept = q.clone();
                kept.merge(p, blocks);
                out.push(kept);
                i += 1;
                j += 1;
            }
        }
    }
    for p in &incoming[i..] {
        out.extend(p.arrive(blocks));
    }
    out.extend_from_slice(&own[j..]);
    out
}

/// A dense depth-merge buffer over `len` slots (the caller maps locations to slots).
pub struct Image<P> {
    slots: Vec<Option<P>>,
}

impl<P: ShippedPixel> Image<P> {
    pub fn new(len: usize) -> Image<P> {
        Image {
            slots: vec![None; len],
        }
    }

    /// The depth test: merges `p` into `slot`. Returns whether any of its samples was
    /// nearer than what the slot held.
    pub fn merge(&mut self, slot: usize, p: &P, blocks: &mut Blocks) -> bool {
        match &mut self.slots[slot] {
            Some(held) => held.merge(p, blocks),
            empty => {
                *empty = p.arrive(blocks);
                empty.is_some()
            }
        }
    }

    /// The pixel in `slot`, if any fragment reached it.
    pub fn pixel(&self, slot: usize) -> Option<&P> {
        self.slots[slot].as_ref()
    }
}

/// The image resolved pixels (position, rgb, z; in any order) show on a screen cleared to
/// `background`.
pub fn framebuffer_of(
    viewport: Viewport,
    background: [u8; 3],
    pixels: impl Iterator<Item = (u32, [u8; 3], u32)>,
) -> Framebuffer {
    let w = viewport.width() as usize;
    let mut color = vec![background; viewport.pixels()];
    let mut depth = vec![u32::MAX; viewport.pixels()];
    for (loc, rgb, z) in pixels {
        color[loc as usize] = rgb;
        depth[loc as usize] = z;
    }
    let mut fb = Framebuffer::with_clear(viewport, background);
    for y in 0..viewport.height() {
        let o = y as usize * w;
        fb.set_row(y, &color[o..o + w], &depth[o..o + w]);
    }
    fb
}

/// Buckets every fragment, before any depth test, by the node owning its row (row y belongs
/// to node y mod n: interleaved scanlines), as the run's pixel type ships it. Counts no
/// depth tests: the caller charges the bucketing.
pub struct BucketTarget<'c, P> {
    ctx: &'c super::Ctx,
    /// The frame's subpixel resolution (what a partial fragment's mask is looked up in).
    grid: Grid,
    rects: [ScreenRect; 1],
    pub buckets: Vec<Vec<P>>,
    /// Fragments bucketed so far.
    pub fragments: u64,
}

impl<'c, P: ShippedPixel> BucketTarget<'c, P> {
    pub fn new(ctx: &'c super::Ctx, frame: u32) -> BucketTarget<'c, P> {
        BucketTarget {
            ctx,
            grid: ctx.aa.grid(frame),
            rects: [ctx.screen.rect()],
            buckets: vec![Vec::new(); ctx.n as usize],
            fragments: 0,
        }
    }
}

impl<P: ShippedPixel> Target for BucketTarget<'_, P> {
    fn rects(&self) -> &[ScreenRect] {
        &self.rects
    }
    fn sampling(&self) -> crate::raster::scan::Sampling {
        P::sampling(self.ctx)
    }
    fn span(&mut self, _rect: usize, span: &Span<'_>, counters: &mut Counters) {
        // A row of the merge grid belongs to node row mod n; a supersampled pixel's samples
        // lie on several.
        let width = self.ctx.viewport.width();
        let mut shipped = Vec::new();
        for f in span.fragments() {
            P::fragments(self.ctx, self.grid, span, &f, counters, &mut shipped);
            for p in shipped.drain(..) {
                self.buckets[(p.loc() / width % self.ctx.n) as usize].push(p);
                self.fragments += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::pixel::Px;
    use super::*;
    use crate::units::Bytes;

    fn px(loc: u32, z: u32, prim: u32) -> Px {
        Px {
            loc,
            z,
            prim,
            rgb: [prim as u8; 3],
        }
    }

    fn no_blocks() -> Blocks {
        Blocks::new(Grid::X2, Bytes::new(0), [0; 3])
    }

    #[test]
    fn merge_keeps_raster_order_and_the_nearer_pixel() {
        let a = [px(1, 5, 0), px(3, 7, 2), px(4, 1, 9)];
        let b = [px(0, 9, 1), px(3, 7, 1), px(4, 2, 3)];
        let m = merge_sorted(&a, &b, &mut no_blocks());
        let got: Vec<(u32, u32)> = m.iter().map(|p| (p.loc, p.prim)).collect();
        // Location 3 ties in depth: the lower primitive id wins.
        assert_eq!(got, [(0, 1), (1, 0), (3, 1), (4, 9)]);
    }

    #[test]
    fn image_depth_test() {
        let mut img = Image::new(2);
        let b = &mut no_blocks();
        assert_eq!(img.pixel(0), None);
        assert!(img.merge(0, &px(0, 4, 3), b));
        assert!(!img.merge(0, &px(0, 4, 5), b));
        assert!(img.merge(0, &px(0, 4, 2), b));
        assert_eq!(img.pixel(0).map(|p| p.prim), Some(2));
        assert_eq!(img.pixel(1), None);
    }
}
