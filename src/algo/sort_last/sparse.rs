//! The host-side pixel mechanisms paper 003's three merges share: a compact shipped pixel
//! (`Px`, its screen location as one index), the one raster-order depth merge of pixel lists
//! (paper 001's full-frame merges use it too), a dense depth-merge buffer (`Image`, a node's
//! merged frame, an owner's part of the screen, or a frame buffer), a target that buckets
//! every fragment by the node owning its row before any depth test (direct send without a
//! local z-buffer), and the message size the merges batch pixels into.
//!
//! Must never charge time, send, or decide an order of its own: depth order is
//! `raster::target::nearer` only, so every merge built on it reproduces the sequential
//! z-buffer's image.

use crate::raster::target::nearer;
use crate::raster::{
    ActivePixel, Counters, Framebuffer, ScreenRect, Span, SparseBuffer, Target, Viewport,
};

/// Pixels per message when a merge batches pixels (11 KiB of active pixels).
pub const MESSAGE_PIXELS: usize = 1024;

/// One pixel as a merge ships it. `loc` is `y * width + x`; `prim` is the host-side
/// tie-break (not part of the shipped bytes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Px {
    pub loc: u32,
    pub z: u32,
    pub prim: u32,
    pub rgb: [u8; 3],
}

/// A buffer's active pixels in raster order.
pub fn sorted_active(buffer: &SparseBuffer, width: u32) -> Vec<Px> {
    buffer
        .active_sorted()
        .iter()
        .map(|p| Px {
            loc: p.y * width + p.x,
            z: p.z,
            prim: p.prim,
            rgb: p.rgb,
        })
        .collect()
}

/// A pixel a merge orders by screen location and compares by depth.
pub trait MergePixel: Copy {
    /// Raster order: row-major screen location.
    fn raster_key(&self) -> u64;
    /// (depth, primitive id), compared with `nearer`.
    fn depth(&self) -> (u32, u32);
}

impl MergePixel for Px {
    fn raster_key(&self) -> u64 {
        u64::from(self.loc)
    }
    fn depth(&self) -> (u32, u32) {
        (self.z, self.prim)
    }
}

impl MergePixel for ActivePixel {
    fn raster_key(&self) -> u64 {
        (u64::from(self.y) << 32) | u64::from(self.x)
    }
    fn depth(&self) -> (u32, u32) {
        (self.z, self.prim)
    }
}

/// Depth-merges two raster-ordered pixel lists into one (the nearer pixel wins a shared
/// location). Every sort-last merge of pixel lists goes through here.
pub fn merge_sorted<P: MergePixel>(a: &[P], b: &[P]) -> Vec<P> {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        let (p, q) = (a[i], b[j]);
        match p.raster_key().cmp(&q.raster_key()) {
            std::cmp::Ordering::Less => {
                out.push(p);
                i += 1;
            }
            std::cmp::Ordering::Greater => {
                out.push(q);
                j += 1;
            }
            std::cmp::Ordering::Equal => {
                let ((pz, pp), (qz, qp)) = (p.depth(), q.depth());
                out.push(if nearer(qz, qp, pz, pp) { q } else { p });
                i += 1;
                j += 1;
            }
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
    out
}

/// A dense depth buffer over `len` slots (the caller maps locations to slots).
pub struct Image {
    z: Vec<u32>,
    prim: Vec<u32>,
    rgb: Vec<[u8; 3]>,
}

impl Image {
    pub fn new(len: usize) -> Image {
        Image {
            z: vec![u32::MAX; len],
            prim: vec![u32::MAX; len],
            rgb: vec![[0; 3]; len],
        }
    }

    /// Whether `p` is nearer than what slot `slot` holds.
    #[inline]
    pub fn hides(&self, slot: usize, p: &Px) -> bool {
        nearer(p.z, p.prim, self.z[slot], self.prim[slot])
    }

    /// Stores `p` in `slot` unconditionally (the last broadcast pixel wins).
    #[inline]
    pub fn put(&mut self, slot: usize, p: &Px) {
        self.z[slot] = p.z;
        self.prim[slot] = p.prim;
        self.rgb[slot] = p.rgb;
    }

    /// The depth test: stores `p` if it is nearer. Returns whether it did.
    #[inline]
    pub fn merge(&mut self, slot: usize, p: &Px) -> bool {
        let nearer = self.hides(slot, p);
        if nearer {
            self.put(slot, p);
        }
        nearer
    }

    /// The pixel in `slot` with location `loc`, if any fragment reached it.
    pub fn pixel(&self, slot: usize, loc: u32) -> Option<Px> {
        (self.prim[slot] != u32::MAX).then(|| Px {
            loc,
            z: self.z[slot],
            prim: self.prim[slot],
            rgb: self.rgb[slot],
        })
    }
}

/// Writes raster-ordered (or any-order) pixels into a framebuffer cleared to `background`.
pub fn framebuffer(viewport: Viewport, background: [u8; 3], pixels: &[Px]) -> Framebuffer {
    let w = viewport.width() as usize;
    let mut color = vec![background; viewport.pixels()];
    let mut depth = vec![u32::MAX; viewport.pixels()];
    for p in pixels {
        color[p.loc as usize] = p.rgb;
        depth[p.loc as usize] = p.z;
    }
    let mut fb = Framebuffer::with_clear(viewport, background);
    for y in 0..viewport.height() {
        let o = y as usize * w;
        fb.set_row(y, &color[o..o + w], &depth[o..o + w]);
    }
    fb
}

/// Buckets every fragment, before any depth test, by the node owning its row (row y belongs
/// to node y mod n: interleaved scanlines). Counts no depth tests: the caller charges the
/// bucketing.
pub struct BucketTarget {
    rects: [ScreenRect; 1],
    width: u32,
    n: u32,
    pub buckets: Vec<Vec<Px>>,
    /// Fragments bucketed so far.
    pub fragments: u64,
}

impl BucketTarget {
    pub fn new(viewport: Viewport, n: u32) -> BucketTarget {
        BucketTarget {
            rects: [viewport.rect()],
            width: viewport.width(),
            n,
            buckets: vec![Vec::new(); n as usize],
            fragments: 0,
        }
    }
}

impl Target for BucketTarget {
    fn rects(&self) -> &[ScreenRect] {
        &self.rects
    }
    fn span(&mut self, _rect: usize, span: &Span<'_>, _counters: &mut Counters) {
        let y = span.y();
        let prim = span.prim();
        let row = y * self.width;
        let bucket = &mut self.buckets[(y % self.n) as usize];
        for f in span.fragments() {
            bucket.push(Px {
                loc: row + f.x,
                z: f.z,
                prim,
                rgb: f.rgb,
            });
        }
        self.fragments += span.len() as u64;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn px(loc: u32, z: u32, prim: u32) -> Px {
        Px {
            loc,
            z,
            prim,
            rgb: [prim as u8; 3],
        }
    }

    #[test]
    fn merge_keeps_raster_order_and_the_nearer_pixel() {
        let a = [px(1, 5, 0), px(3, 7, 2), px(4, 1, 9)];
        let b = [px(0, 9, 1), px(3, 7, 1), px(4, 2, 3)];
        let m = merge_sorted(&a, &b);
        let got: Vec<(u32, u32)> = m.iter().map(|p| (p.loc, p.prim)).collect();
        // Location 3 ties in depth: the lower primitive id wins.
        assert_eq!(got, [(0, 1), (1, 0), (3, 1), (4, 9)]);
    }

    #[test]
    fn image_depth_test_and_unconditional_put() {
        let mut img = Image::new(2);
        assert_eq!(img.pixel(0, 0), None);
        assert!(img.merge(0, &px(0, 4, 3)));
        assert!(!img.merge(0, &px(0, 4, 5)));
        assert!(img.merge(0, &px(0, 4, 2)));
        img.put(1, &px(1, 9, 9));
        assert_eq!(img.pixel(0, 0).map(|p| p.prim), Some(2));
        assert_eq!(img.pixel(1, 1).map(|p| p.z), Some(9));
    }
}
