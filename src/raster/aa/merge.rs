//! Adaptive-supersampling pixels that leave the buffer they were rendered in: how a sort-last
//! node ships a pixel of its adaptive buffer ([`AaPixel`]: a plain 12-byte Pixel, a super
//! pixel with its n x n Subpixels, or a fragment that covers the pixel partly), and how a
//! receiving buffer depth-merges it sample by sample. A plain pixel meeting a super pixel is
//! expanded to n x n samples from its depth and dxz/dyz, exactly as `promote` does inside
//! one buffer; the block it needs comes from the receiver's pool ([`Blocks`]).
//!
//! Must never grow a pool: a merge that finds no free block keeps the pixel sampled once (a
//! super pixel collapses to its box-filtered colour at its nearest depth, a partial fragment
//! falls back to the centre rule) and counts it as overflowed. Must never know about nodes or
//! messages. Depth order is (depth, primitive id) per sample, as everywhere.

use std::rc::Rc;

use super::adaptive::AdaptiveTarget;
use super::masks::{self, Grid};
use super::{box_filter, fine, sample_depth, slopes, AaStats, SUBPIXEL_BYTES};
use crate::raster::fixed::Depth;
use crate::raster::scan::Span;
use crate::raster::target::nearer;
use crate::raster::Counters;
use crate::units::Bytes;

/// One Subpixel as a merge carries it (`prim` is the host-side tie-break, not shipped).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sample {
    pub z: u32,
    pub prim: u32,
    pub rgb: [u8; 3],
}

/// One pixel of an adaptive buffer, or one fragment for one, on its way to another buffer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum AaPixel {
    /// Sampled once: paper 000's Pixel with its plane (`fine` is the depth at the centre in
    /// 1/256 units, where expansion starts from).
    Plain {
        z: u32,
        fine: i64,
        prim: u32,
        rgb: [u8; 3],
        slope: [i64; 2],
    },
    /// A super pixel's samples, row-major (n x n of the frame's grid).
    Super(Rc<Vec<Sample>>),
    /// A fragment covering the pixel partly, shipped before any depth test (direct send):
    /// its plane at the centre, the coverage mask from the bitmask table, and whether the
    /// centre is covered (what decides when the receiver has no block left).
    Partial {
        z: u32,
        fine: i64,
        prim: u32,
        rgb: [u8; 3],
        slope: [i64; 2],
        mask: u16,
        centre: bool,
    },
}

/// The Subpixel pool of a buffer receiving merged pixels, and the work the merges did (taken
/// by the caller to charge).
#[derive(Clone, Debug)]
pub struct Blocks {
    grid: Grid,
    clear: [u8; 3],
    capacity: u64,
    live: u64,
    peak: u64,
    /// Blocks merges took (pixels that became super pixels at the receiver).
    pub taken: u64,
    /// Super pixels or partial fragments kept sampled once for want of a block.
    pub overflowed: u64,
    /// Work not charged yet (`aa_subpixel_tests`, `aa_subpixel_writes`).
    work: Counters,
}

impl Blocks {
    /// A pool of `pool` bytes at resolution `grid`, cells free; cleared samples are `clear`.
    pub fn new(grid: Grid, pool: Bytes, clear: [u8; 3]) -> Blocks {
        Blocks {
            grid,
            clear,
            capacity: pool.get() / SUBPIXEL_BYTES,
            live: 0,
            peak: 0,
            taken: 0,
            overflowed: 0,
            work: Counters::default(),
        }
    }

    /// Adds a frame rendered into this pool with `stats` (its cells still in use).
    pub fn absorb(&mut self, stats: &AaStats) {
        self.peak = self.peak.max(self.live + stats.peak_cells);
        self.live += stats.live_cells;
    }

    /// Returns `cells` to the pool (a rendered frame whose pixels have been shipped).
    pub fn release(&mut self, cells: u64) {
        self.live = self.live.saturating_sub(cells);
    }

    pub fn grid(&self) -> Grid {
        self.grid
    }

    /// Subpixel cells in use.
    pub fn live_cells(&self) -> u64 {
        self.live
    }

    /// The most cells in use at once.
    pub fn peak_cells(&self) -> u64 {
        self.peak
    }

    /// The merges' subpixel work since the last call.
    pub fn take_work(&mut self) -> Counters {
        std::mem::take(&mut self.work)
    }

    /// `render`'s statistics with what the merges added: blocks taken count as supersampled
    /// pixels, merge overflows as overflowed ones, and the cells in use are the pool's.
    pub fn stats(&self, render: AaStats) -> AaStats {
        let n = u64::from(self.grid.samples());
        AaStats {
            grid_side: self.grid.side(),
            supersampled_pixels: render.supersampled_pixels + self.taken,
            overflowed_pixels: render.overflowed_pixels + self.overflowed,
            live_super_pixels: self.live / n,
            peak_cells: self.peak,
            live_cells: self.live,
            pool_cells: self.capacity,
            ..render
        }
    }

    /// True when no block can be taken.
    fn full(&self) -> bool {
        self.live + u64::from(self.grid.samples()) > self.capacity
    }

    fn take(&mut self) -> bool {
        let n = u64::from(self.grid.samples());
        if self.full() {
            return false;
        }
        self.live += n;
        self.peak = self.peak.max(self.live);
        self.taken += 1;
        true
    }

    /// A sample the receiver's buffer held before anything reached it.
    fn cleared(&self) -> Sample {
        Sample {
            z: Depth::CLEARED,
            prim: u32::MAX,
            rgb: self.clear,
        }
    }
}

impl AaPixel {
    /// Bytes the pixel's Subpixels (or a fragment's coverage mask) add to its 12-byte Pixel
    /// record on the wire.
    pub fn extra_bytes(&self) -> u64 {
        match self {
            AaPixel::Plain { .. } => 0,
            AaPixel::Super(s) => s.len() as u64 * SUBPIXEL_BYTES,
            AaPixel::Partial { .. } => 2,
        }
    }

    /// Subpixels carried.
    pub fn samples(&self) -> u64 {
        match self {
            AaPixel::Super(s) => s.len() as u64,
            _ => 0,
        }
    }

    pub fn is_super(&self) -> bool {
        matches!(self, AaPixel::Super(_))
    }

    /// The box-filtered colour and the nearest depth.
    pub fn resolve(&self) -> ([u8; 3], u32) {
        match self {
            AaPixel::Plain { z, rgb, .. } | AaPixel::Partial { z, rgb, .. } => (*rgb, *z),
            AaPixel::Super(s) => {
                let colors: Vec<[u8; 3]> = s.iter().map(|c| c.rgb).collect();
                let z = s.iter().map(|c| c.z).min().unwrap_or(Depth::CLEARED);
                (box_filter(&colors), z)
            }
        }
    }

    /// The pixel as the receiving buffer stores it where it held nothing, or `None` when it
    /// stores nothing (a partial fragment whose centre is uncovered, with no block free).
    pub fn arrive(&self, blocks: &mut Blocks) -> Option<AaPixel> {
        match self {
            AaPixel::Plain { .. } => Some(self.stored()),
            AaPixel::Partial { mask: 0, .. } => {
                // Near a corner only: the centre decides once blocks have run out.
                let once = if blocks.full() {
                    self.sampled_once()
                } else {
                    None
                };
                once.map(|p| p.stored())
            }
            AaPixel::Super(_) | AaPixel::Partial { .. } => {
                if !blocks.take() {
                    blocks.overflowed += 1;
                    return self.sampled_once().map(|p| p.stored());
                }
                let n = u64::from(blocks.grid.samples());
                blocks.work.aa_subpixel_writes += n;
                if let AaPixel::Super(_) = self {
                    // Copied into the new block as it is.
                    return Some(self.clone());
                }
                // Promoted from a cleared pixel, then the covered samples depth-tested.
                let mut held = vec![blocks.cleared(); n as usize];
                self.cover(&mut held, blocks);
                Some(AaPixel::Super(Rc::new(held)))
            }
        }
    }

    /// Depth-merges `incoming` (same location) into this stored pixel, sample by sample when
    /// either is a super pixel. True when any of `incoming`'s samples was nearer.
    pub fn merge(&mut self, incoming: &AaPixel, blocks: &mut Blocks) -> bool {
        if let AaPixel::Super(held) = self {
            return incoming.cover(Rc::make_mut(held).as_mut_slice(), blocks);
        }
        let wants_block = !matches!(
            incoming,
            AaPixel::Plain { .. } | AaPixel::Partial { mask: 0, .. }
        );
        if matches!(incoming, AaPixel::Partial { mask: 0, .. }) && !blocks.full() {
            return false;
        }
        if wants_block && blocks.take() {
            let mut held = self.expand(blocks.grid);
            blocks.work.aa_subpixel_writes += held.len() as u64;
            let won = incoming.cover(&mut held, blocks);
            *self = AaPixel::Super(Rc::new(held));
            return won;
        }
        if wants_block {
            blocks.overflowed += 1;
        }
        let Some(once) = incoming.sampled_once() else {
            return false;
        };
        let (
            AaPixel::Plain { z, prim, .. },
            AaPixel::Plain {
                z: iz, prim: ip, ..
            },
        ) = (&*self, &once)
        else {
            unreachable!("a stored pixel without a block and a once-sampled one are plain")
        };
        let won = nearer(*iz, *ip, *z, *prim);
        if won {
            *self = once.stored();
        }
        won
    }

    /// Depth-tests this pixel's samples (all of them, or a partial fragment's masked ones)
    /// against the block `held`, writing the nearer ones. True if any was written.
    fn cover(&self, held: &mut [Sample], blocks: &mut Blocks) -> bool {
        let grid = blocks.grid;
        let mut won = false;
        let mut test = |s: usize, sample: Sample, work: &mut Counters| {
            work.aa_subpixel_tests += 1;
            let cell = &mut held[s];
            if nearer(sample.z, sample.prim, cell.z, cell.prim) {
                *cell = sample;
                work.aa_subpixel_writes += 1;
                won = true;
            }
        };
        match self {
            AaPixel::Super(samples) => {
                for (s, &sample) in samples.iter().enumerate() {
                    test(s, sample, &mut blocks.work);
                }
            }
            AaPixel::Plain {
                fine,
                prim,
                rgb,
                slope,
                ..
            } => {
                for s in 0..grid.samples() {
                    let z = at_sample(*fine, *slope, grid, s);
                    let sample = Sample {
                        z,
                        prim: *prim,
                        rgb: *rgb,
                    };
                    test(s as usize, sample, &mut blocks.work);
                }
            }
            AaPixel::Partial {
                fine,
                prim,
                rgb,
                slope,
                mask,
                ..
            } => {
                for s in (0..grid.samples()).filter(|s| mask & (1 << s) != 0) {
                    let z = at_sample(*fine, *slope, grid, s);
                    let sample = Sample {
                        z,
                        prim: *prim,
                        rgb: *rgb,
                    };
                    test(s as usize, sample, &mut blocks.work);
                }
            }
        }
        won
    }

    /// The pixel as one sample: a super pixel's box-filtered colour at its nearest depth
    /// (a flat plane); a plain pixel as it is.
    pub fn resolved(&self) -> AaPixel {
        match self {
            AaPixel::Super(_) => self.sampled_once().unwrap_or_else(|| self.clone()),
            _ => self.clone(),
        }
    }

    /// A stored plain pixel's n x n samples, depths from its plane (as `promote` does).
    fn expand(&self, grid: Grid) -> Vec<Sample> {
        let AaPixel::Plain {
            z,
            fine,
            prim,
            rgb,
            slope,
        } = self
        else {
            unreachable!("only a plain pixel is expanded")
        };
        (0..grid.samples())
            .map(|s| Sample {
                z: if *z == Depth::CLEARED {
                    Depth::CLEARED
                } else {
                    at_sample(*fine, *slope, grid, s)
                },
                prim: *prim,
                rgb: *rgb,
            })
            .collect()
    }

    /// The pixel sampled once: a super pixel's box-filtered colour at its nearest sample's
    /// depth (a flat plane), a partial fragment only if it covers the centre.
    fn sampled_once(&self) -> Option<AaPixel> {
        match self {
            AaPixel::Plain { .. } => Some(self.clone()),
            AaPixel::Super(samples) => {
                let (rgb, _) = self.resolve();
                let nearest = samples
                    .iter()
                    .min_by(|a, b| (a.z, a.prim).cmp(&(b.z, b.prim)))
                    .copied()
                    .unwrap_or(Sample {
                        z: Depth::CLEARED,
                        prim: u32::MAX,
                        rgb,
                    });
                Some(AaPixel::Plain {
                    z: nearest.z,
                    fine: fine(nearest.z),
                    prim: nearest.prim,
                    rgb,
                    slope: [0, 0],
                })
            }
            AaPixel::Partial {
                z,
                fine,
                prim,
                rgb,
                slope,
                centre,
                ..
            } => centre.then_some(AaPixel::Plain {
                z: *z,
                fine: *fine,
                prim: *prim,
                rgb: *rgb,
                slope: *slope,
            }),
        }
    }

    /// The form a buffer keeps a plain pixel in: its Pixel record holds z, not the plane's
    /// exact centre, so a later expansion starts from z (as inside one buffer).
    fn stored(&self) -> AaPixel {
        match self {
            AaPixel::Plain {
                z,
                prim,
                rgb,
                slope,
                ..
            } => AaPixel::Plain {
                z: *z,
                fine: fine(*z),
                prim: *prim,
                rgb: *rgb,
                slope: *slope,
            },
            other => other.clone(),
        }
    }

    /// A fragment of `span` at pixel `x` as a buffer without a depth test ships it (the
    /// classification [`AdaptiveTarget`] makes): a plain pixel where the triangle covers
    /// every sample, a partial fragment where it covers some (or only the centre), nothing
    /// otherwise. Counts the coverage masks it looks up.
    pub fn fragment(
        span: &Span<'_>,
        x: u32,
        z: u32,
        rgb: [u8; 3],
        grid: Grid,
        counters: &mut Counters,
    ) -> Option<AaPixel> {
        let tri = span.triangle();
        let (px, py) = (i64::from(x), i64::from(span.y()));
        let (fine, slope, prim) = (tri.depth_fine_at(px, py), slopes(tri), span.prim());
        let plain = AaPixel::Plain {
            z,
            fine,
            prim,
            rgb,
            slope,
        };
        if tri.fully_covers_pixel(px, py) {
            return Some(plain);
        }
        counters.aa_coverage_masks += 1;
        let mask = masks::triangle_mask(tri, px, py, grid);
        let centre = tri.covers_pixel(px, py);
        if mask == grid.full_mask() {
            Some(plain)
        } else if mask != 0 || centre {
            Some(AaPixel::Partial {
                z,
                fine,
                prim,
                rgb,
                slope,
                mask,
                centre,
            })
        } else {
            None
        }
    }
}

/// Depth of sample `s` of `grid` from a plane with centre depth `fine` (1/256 units).
fn at_sample(fine: i64, slope: [i64; 2], grid: Grid, s: u32) -> u32 {
    let half = masks::STEPS / 2;
    let (sx, sy) = grid.sample(s);
    sample_depth(fine, slope, sx - half, sy - half, masks::STEPS)
}

impl AdaptiveTarget {
    /// Every pixel a fragment reached, in raster order of its regions, as it would be
    /// shipped: plain pixels with their plane, super pixels with their samples.
    pub fn export(&self) -> Vec<(u32, u32, AaPixel)> {
        let mut out = Vec::new();
        self.for_each_pixel(|x, y, p| out.push((x, y, p)));
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plain(z: u32, prim: u32, rgb: u8) -> AaPixel {
        AaPixel::Plain {
            z,
            fine: fine(z),
            prim,
            rgb: [rgb; 3],
            slope: [0, 0],
        }
    }

    fn blocks(cells: u64) -> Blocks {
        Blocks::new(Grid::X2, Bytes::new(cells * SUBPIXEL_BYTES), [0; 3])
    }

    fn partial(z: u32, prim: u32, mask: u16, centre: bool) -> AaPixel {
        AaPixel::Partial {
            z,
            fine: fine(z),
            prim,
            rgb: [200; 3],
            slope: [0, 0],
            mask,
            centre,
        }
    }

    #[test]
    fn plain_pixels_merge_by_depth_without_a_block() {
        let mut b = blocks(4);
        let mut p = plain(10, 1, 50).arrive(&mut b).unwrap();
        assert!(!p.merge(&plain(20, 2, 90), &mut b));
        assert!(p.merge(&plain(5, 3, 70), &mut b));
        assert_eq!(p.resolve(), ([70; 3], 5));
        assert_eq!((b.live_cells(), b.taken, b.overflowed), (0, 0, 0));
    }

    #[test]
    fn a_partial_fragment_expands_a_plain_pixel_into_a_block() {
        let mut b = blocks(4);
        let mut p = plain(10, 1, 40).arrive(&mut b).unwrap();
        // Nearer, on the two top samples of 2x2.
        assert!(p.merge(&partial(5, 2, 0b0011, false), &mut b));
        assert!(p.is_super());
        assert_eq!(p.resolve(), ([120; 3], 5));
        assert_eq!((b.live_cells(), b.taken), (4, 1));
        let work = b.take_work();
        // Expansion writes 4; the fragment tests 2 and writes 2.
        assert_eq!((work.aa_subpixel_tests, work.aa_subpixel_writes), (2, 6));
    }

    #[test]
    fn without_a_block_a_partial_fragment_falls_back_to_its_centre() {
        let mut b = blocks(0);
        let mut p = plain(10, 1, 40).arrive(&mut b).unwrap();
        assert!(!p.merge(&partial(5, 2, 0b0011, false), &mut b));
        assert!(p.merge(&partial(5, 2, 0b0111, true), &mut b));
        assert_eq!(p.resolve(), ([200; 3], 5));
        assert!(partial(5, 2, 0b0001, false).arrive(&mut b).is_none());
        assert_eq!((b.overflowed, b.live_cells()), (3, 0));
    }

    #[test]
    fn a_super_pixel_without_a_block_collapses_to_its_filtered_colour() {
        let s = |z, rgb| Sample {
            z,
            prim: 7,
            rgb: [rgb; 3],
        };
        let sp = AaPixel::Super(Rc::new(vec![s(9, 0), s(3, 100), s(9, 0), s(9, 100)]));
        let mut b = blocks(0);
        let got = sp.arrive(&mut b).unwrap();
        assert_eq!(got.resolve(), ([50; 3], 3));
        assert!(!got.is_super());
        assert_eq!(b.overflowed, 1);
    }

    #[test]
    fn super_pixels_merge_sample_by_sample_and_the_order_does_not_matter() {
        let s = |z, prim| Sample {
            z,
            prim,
            rgb: [prim as u8 * 10; 3],
        };
        let a = AaPixel::Super(Rc::new(vec![s(1, 1), s(9, 1), s(5, 1), s(5, 1)]));
        let c = AaPixel::Super(Rc::new(vec![s(2, 2), s(3, 2), s(5, 2), s(7, 2)]));
        let mut b1 = blocks(8);
        let mut x = a.arrive(&mut b1).unwrap();
        x.merge(&c, &mut b1);
        let mut b2 = blocks(8);
        let mut y = c.arrive(&mut b2).unwrap();
        y.merge(&a, &mut b2);
        assert_eq!(x, y);
        let AaPixel::Super(got) = x else {
            panic!("still a super pixel")
        };
        let prims: Vec<u32> = got.iter().map(|c| c.prim).collect();
        // Sample 2 ties in depth: the lower primitive id wins.
        assert_eq!(prims, [1, 2, 1, 1]);
    }
}
