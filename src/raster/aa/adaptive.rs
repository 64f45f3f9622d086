//! Paper 000's adaptive supersampling target: a 12-byte `Pixel` per pixel, sampled once
//! where a polygon covers the pixel fully, and a block of n x n 7-byte `Subpixel` cells from
//! a pool fixed in size where a polygon covers it partially (at most one block per pixel,
//! whatever the number of edges). Coverage comes from the bitmask table (`masks`), subpixel
//! depths from the pixel's depth and its dxz/dyz gradients. Reclaiming returns a block to
//! the free list when its samples agree in colour and nearly in depth; memory adaptation
//! ([`adapt`]) picks the next frame's n from this frame's demand.
//!
//! Must never grow the pool: when no block is free, an edge pixel is sampled once at its
//! centre (under the ordinary fill rule) and counted as overflowed. Must never read a clock
//! or know about nodes.
//!
//! Depth order is the module's (depth, primitive id) rule, per Pixel and per Subpixel.

use super::masks::{self, Grid};
use super::merge::{AaPixel, Sample};
use super::{box_filter, fine, sample_depth, slopes, AaStats, SUBPIXEL_BYTES};
use crate::raster::counters::Counters;
use crate::raster::fixed::Depth;
use crate::raster::scan::{Sampling, Span};
use crate::raster::screen::{ScreenRect, Viewport};
use crate::raster::target::{check_regions, nearer, Framebuffer, RegionError, RegionSet, Target};
use crate::units::Bytes;

/// Reclaiming's depth threshold in raw depth units: a super pixel whose samples all have
/// one colour is reclaimed when the samples' depths, less the offsets the Pixel's own
/// dxz/dyz predict for their positions, spread strictly less than this. Paper 000 says
/// "smaller than 1 unit" of its integer z without giving its resolution; here one unit is
/// one step of a 24-bit z-buffer (2^8 of our 32-bit raw units). Two coplanar triangles
/// sharing an edge differ by tens of raw units after snapping (measured on the letter B
/// stand-in); two faces of a tetrahedron by far more than 2^8.
pub const RECLAIM_SPREAD: u32 = 1 << 8;

/// How an adaptive target is sized and behaves for one frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AdaptiveConfig {
    /// The Subpixel pool, preallocated (paper 000: enough for 2x2 on every pixel).
    pub pool: Bytes,
    /// This frame's subpixel resolution.
    pub grid: Grid,
    /// Reclaim blocks whose samples agree (`None`: never).
    pub reclaim_spread: Option<u32>,
}

impl AdaptiveConfig {
    /// Paper 000's default pool: 2x2 Subpixels for every one of `pixels`.
    pub fn default_pool(pixels: u64) -> Bytes {
        Bytes::new(pixels * u64::from(Grid::X2.samples()) * SUBPIXEL_BYTES)
    }

    /// The paper's setup for a target of `pixels`: default pool, 4x4, reclaiming on.
    pub fn for_pixels(pixels: u64) -> AdaptiveConfig {
        AdaptiveConfig {
            pool: AdaptiveConfig::default_pool(pixels),
            grid: Grid::X4,
            reclaim_spread: Some(RECLAIM_SPREAD),
        }
    }
}

/// Memory adaptation (paper 000, section 4.1): the finest resolution whose blocks for this
/// frame's demand (`stats.demand_pixels()`) fit the pool, else 2x2.
pub fn adapt(stats: &AaStats) -> Grid {
    let demand = stats.demand_pixels();
    Grid::FINEST_FIRST
        .into_iter()
        .find(|g| demand * u64::from(g.samples()) <= stats.pool_cells)
        .unwrap_or(Grid::X2)
}

/// No Subpixel block.
const NO_BLOCK: u32 = u32::MAX;

/// The Subpixel cells: a bump region handed out in blocks of n * n, and a free list of
/// returned blocks (paper 000: "inserted to a linked-list for later use").
#[derive(Clone, Debug)]
struct Pool {
    capacity: u64,
    block: u32,
    z: Vec<u32>,
    rgb: Vec<[u8; 3]>,
    prim: Vec<u32>,
    free: Vec<u32>,
    live: u64,
    peak: u64,
}

impl Pool {
    fn new(bytes: Bytes, grid: Grid) -> Pool {
        // Cells are addressed by u32; a pool beyond that is capped (it could never fill).
        let capacity = (bytes.get() / SUBPIXEL_BYTES).min(u64::from(u32::MAX - 1));
        Pool {
            capacity,
            block: grid.samples(),
            z: Vec::new(),
            rgb: Vec::new(),
            prim: Vec::new(),
            free: Vec::new(),
            live: 0,
            peak: 0,
        }
    }

    /// A block's first cell, or `None` when the pool is exhausted.
    fn alloc(&mut self) -> Option<u32> {
        let start = match self.free.pop() {
            Some(b) => b,
            None => {
                let start = self.z.len() as u64;
                if start + u64::from(self.block) > self.capacity {
                    return None;
                }
                let end = start as usize + self.block as usize;
                self.z.resize(end, Depth::CLEARED);
                self.rgb.resize(end, [0; 3]);
                self.prim.resize(end, u32::MAX);
                start as u32
            }
        };
        self.live += u64::from(self.block);
        self.peak = self.peak.max(self.live);
        Some(start)
    }

    /// True when no block can be handed out.
    fn exhausted(&self) -> bool {
        self.free.is_empty() && self.z.len() as u64 + u64::from(self.block) > self.capacity
    }

    fn release(&mut self, start: u32) {
        self.free.push(start);
        self.live -= u64::from(self.block);
    }

    fn cells(&self, start: u32) -> std::ops::Range<usize> {
        start as usize..start as usize + self.block as usize
    }
}

/// One region's Pixel array.
#[derive(Clone, Debug)]
struct Plane {
    rect: ScreenRect,
    rgb: Vec<[u8; 3]>,
    z: Vec<u32>,
    prim: Vec<u32>,
    slope: Vec<[i64; 2]>,
    block: Vec<u32>,
    overflowed: Vec<bool>,
}

impl Plane {
    fn new(rect: ScreenRect, clear: [u8; 3]) -> Plane {
        let n = rect.pixels();
        Plane {
            rect,
            rgb: vec![clear; n],
            z: vec![Depth::CLEARED; n],
            prim: vec![u32::MAX; n],
            slope: vec![[0; 2]; n],
            block: vec![NO_BLOCK; n],
            overflowed: vec![false; n],
        }
    }

    fn index(&self, x: u32, y: u32) -> usize {
        let r = self.rect;
        (y - r.y0()) as usize * r.width() as usize + (x - r.x0()) as usize
    }
}

/// A fragment's values at the pixel centre, with its triangle's depth gradients.
#[derive(Clone, Copy, Debug)]
struct Frag {
    /// Depth at the centre as a fragment has it (clamped to the triangle's range).
    z: u32,
    /// The plane's unclamped depth at the centre, 1/256 units (for subpixels).
    fine: i64,
    rgb: [u8; 3],
    prim: u32,
    slope: [i64; 2],
}

/// Paper 000's adaptive supersampling buffer over one or more disjoint regions (one node's
/// regions in sort-middle, or the whole screen), sharing one Subpixel pool.
#[derive(Clone, Debug)]
pub struct AdaptiveTarget {
    rects: Vec<ScreenRect>,
    planes: Vec<Plane>,
    pool: Pool,
    config: AdaptiveConfig,
    clear: [u8; 3],
    supersampled: u64,
    reclaimed: u64,
    overflowed: u64,
}

impl AdaptiveTarget {
    /// Regions must lie in the viewport and not overlap (as for `RegionSet`); every pixel
    /// starts cleared to `clear` at the cleared depth.
    pub fn new(
        viewport: Viewport,
        rects: Vec<ScreenRect>,
        config: AdaptiveConfig,
        clear: [u8; 3],
    ) -> Result<AdaptiveTarget, RegionError> {
        check_regions(viewport, &rects)?;
        Ok(AdaptiveTarget::build(rects, config, clear))
    }

    /// The whole viewport as one region.
    pub fn full_screen(viewport: Viewport, config: AdaptiveConfig, clear: [u8; 3]) -> Self {
        AdaptiveTarget::build(vec![viewport.rect()], config, clear)
    }

    /// A target over regions already checked.
    fn build(rects: Vec<ScreenRect>, config: AdaptiveConfig, clear: [u8; 3]) -> Self {
        AdaptiveTarget {
            planes: rects.iter().map(|&r| Plane::new(r, clear)).collect(),
            rects,
            pool: Pool::new(config.pool, config.grid),
            config,
            clear,
            supersampled: 0,
            reclaimed: 0,
            overflowed: 0,
        }
    }

    pub fn config(&self) -> AdaptiveConfig {
        self.config
    }

    /// Pixels of all regions.
    pub fn pixels(&self) -> u64 {
        self.rects.iter().map(|r| r.pixels() as u64).sum()
    }

    /// What this frame did so far.
    pub fn stats(&self) -> AaStats {
        let n = u64::from(self.config.grid.samples());
        AaStats {
            grid_side: self.config.grid.side(),
            pixels: self.pixels(),
            supersampled_pixels: self.supersampled,
            reclaimed_pixels: self.reclaimed,
            overflowed_pixels: self.overflowed,
            live_super_pixels: self.pool.live / n,
            peak_cells: self.pool.peak,
            live_cells: self.pool.live,
            pool_cells: self.pool.capacity,
        }
    }

    /// True when pixel `(x, y)` holds a Subpixel block.
    pub fn is_super(&self, x: u32, y: u32) -> bool {
        self.locate(x, y)
            .is_some_and(|(r, i)| self.planes[r].block[i] != NO_BLOCK)
    }

    /// The samples of a super pixel as (depth, colour), row-major; `None` for a plain pixel.
    pub fn samples(&self, x: u32, y: u32) -> Option<Vec<(u32, [u8; 3])>> {
        let (r, i) = self.locate(x, y)?;
        let b = self.planes[r].block[i];
        (b != NO_BLOCK).then(|| {
            self.pool
                .cells(b)
                .map(|c| (self.pool.z[c], self.pool.rgb[c]))
                .collect()
        })
    }

    /// Calls `f` with every pixel a fragment reached, region by region in raster order: a
    /// plain pixel with its plane, a super pixel with its samples.
    pub(crate) fn for_each_pixel(&self, mut f: impl FnMut(u32, u32, AaPixel)) {
        for plane in &self.planes {
            let rect = plane.rect;
            for y in rect.y0()..rect.y1() {
                for x in rect.x0()..rect.x1() {
                    let i = plane.index(x, y);
                    match plane.block[i] {
                        NO_BLOCK if plane.prim[i] == u32::MAX => {}
                        NO_BLOCK => f(
                            x,
                            y,
                            AaPixel::Plain {
                                z: plane.z[i],
                                fine: fine(plane.z[i]),
                                prim: plane.prim[i],
                                rgb: plane.rgb[i],
                                slope: plane.slope[i],
                            },
                        ),
                        b => {
                            let samples = self
                                .pool
                                .cells(b)
                                .map(|c| Sample {
                                    z: self.pool.z[c],
                                    prim: self.pool.prim[c],
                                    rgb: self.pool.rgb[c],
                                })
                                .collect();
                            f(x, y, AaPixel::Super(std::rc::Rc::new(samples)));
                        }
                    }
                }
            }
        }
    }

    fn locate(&self, x: u32, y: u32) -> Option<(usize, usize)> {
        let r = self.rects.iter().position(|r| r.contains(x, y))?;
        Some((r, self.planes[r].index(x, y)))
    }

    /// The box-filtered image of every region (super pixels average their samples, plain
    /// pixels keep their one sample), with each pixel's nearest depth. Counts one
    /// `aa_resolved_pixels` per super pixel.
    /// [`resolve`](Self::resolve) straight into a framebuffer (pixels outside the regions
    /// keep what the framebuffer holds).
    pub fn resolve_into(&self, fb: &mut Framebuffer, counters: &mut Counters) {
        self.resolve(counters).copy_into(fb);
    }

    pub fn resolve(&self, counters: &mut Counters) -> RegionSet {
        let mut out = RegionSet::from_checked(self.rects.clone(), self.clear);
        for (r, plane) in self.planes.iter().enumerate() {
            let rect = plane.rect;
            for y in rect.y0()..rect.y1() {
                for x in rect.x0()..rect.x1() {
                    let i = plane.index(x, y);
                    let (rgb, z) = match plane.block[i] {
                        NO_BLOCK => (plane.rgb[i], plane.z[i]),
                        b => {
                            counters.aa_resolved_pixels += 1;
                            let cells = self.pool.cells(b);
                            let z = self.pool.z[cells.clone()].iter().copied().min();
                            (
                                box_filter(&self.pool.rgb[cells]),
                                z.unwrap_or(Depth::CLEARED),
                            )
                        }
                    };
                    out.set_pixel(r, x, y, rgb, z);
                }
            }
        }
        out
    }

    /// One fragment of a conservative span. A plain pixel takes a fragment whole only when
    /// the table says every sample is covered; the centre rule decides instead once the
    /// pool is exhausted (then the pixel is sampled once, as the aliased image would be).
    /// Never the centre rule while blocks remain: a centre that the table's ties give to
    /// the neighbour would copy this polygon into every sample when the pixel is promoted.
    fn fragment(&mut self, r: usize, x: u32, y: u32, f: Frag, span: &Span<'_>, c: &mut Counters) {
        let tri = span.triangle();
        let (px, py) = (i64::from(x), i64::from(y));
        let i = self.planes[r].index(x, y);
        let full = self.config.grid.full_mask();
        if tri.fully_covers_pixel(px, py) {
            return self.cover(r, i, f, full, c);
        }
        c.aa_coverage_masks += 1;
        let mask = masks::triangle_mask(tri, px, py, self.config.grid);
        let partial = mask != 0 && mask != full;
        if self.planes[r].block[i] != NO_BLOCK {
            if mask != 0 {
                self.cover(r, i, f, mask, c);
            }
            return;
        }
        if partial && self.promote(r, i, c) {
            return self.cover(r, i, f, mask, c);
        }
        if partial {
            self.count_overflow(r, i);
        }
        let covered = if partial || self.pool.exhausted() {
            tri.covers_pixel(px, py)
        } else {
            mask == full
        };
        if covered {
            self.point(r, i, f, c);
        }
    }

    /// The fragment's samples in `mask`, into the pixel's block, or into the Pixel itself
    /// when it has none (then `mask` is full).
    fn cover(&mut self, r: usize, i: usize, f: Frag, mask: u16, c: &mut Counters) {
        match self.planes[r].block[i] {
            NO_BLOCK => self.point(r, i, f, c),
            b => {
                self.subsamples(b, f, mask, c);
                self.try_reclaim(r, i, f, c);
            }
        }
    }

    /// The ordinary z-buffer step on a Pixel.
    fn point(&mut self, r: usize, i: usize, f: Frag, c: &mut Counters) {
        let p = &mut self.planes[r];
        c.pixels_tested += 1;
        c.bytes_touched += 4;
        if nearer(f.z, f.prim, p.z[i], p.prim[i]) {
            p.z[i] = f.z;
            p.rgb[i] = f.rgb;
            p.prim[i] = f.prim;
            p.slope[i] = f.slope;
            c.pixels_written += 1;
            c.bytes_touched += super::PIXEL_BYTES;
        }
    }

    fn subsamples(&mut self, block: u32, f: Frag, mask: u16, c: &mut Counters) {
        let grid = self.config.grid;
        let half = masks::STEPS / 2;
        for s in 0..grid.samples() {
            if mask & (1 << s) == 0 {
                continue;
            }
            let (sx, sy) = grid.sample(s);
            let z = sample_depth(f.fine, f.slope, sx - half, sy - half, masks::STEPS);
            let cell = block as usize + s as usize;
            c.aa_subpixel_tests += 1;
            c.bytes_touched += 4;
            if nearer(z, f.prim, self.pool.z[cell], self.pool.prim[cell]) {
                self.pool.z[cell] = z;
                self.pool.rgb[cell] = f.rgb;
                self.pool.prim[cell] = f.prim;
                c.aa_subpixel_writes += 1;
                c.bytes_touched += SUBPIXEL_BYTES;
            }
        }
    }

    /// Gives pixel `i` a block whose samples start as its one sample (depths from its
    /// dxz/dyz). False when the pool is exhausted.
    fn promote(&mut self, r: usize, i: usize, c: &mut Counters) -> bool {
        let Some(b) = self.pool.alloc() else {
            return false;
        };
        let grid = self.config.grid;
        let half = masks::STEPS / 2;
        let p = &mut self.planes[r];
        for s in 0..grid.samples() {
            let (sx, sy) = grid.sample(s);
            let cell = b as usize + s as usize;
            self.pool.z[cell] = if p.z[i] == Depth::CLEARED {
                Depth::CLEARED
            } else {
                sample_depth(fine(p.z[i]), p.slope[i], sx - half, sy - half, masks::STEPS)
            };
            self.pool.rgb[cell] = p.rgb[i];
            self.pool.prim[cell] = p.prim[i];
        }
        p.block[i] = b;
        c.aa_subpixel_writes += u64::from(grid.samples());
        c.bytes_touched += u64::from(grid.samples()) * SUBPIXEL_BYTES;
        self.supersampled += 1;
        true
    }

    fn count_overflow(&mut self, r: usize, i: usize) {
        let flag = &mut self.planes[r].overflowed[i];
        if !*flag {
            *flag = true;
            self.overflowed += 1;
        }
    }

    /// Paper 000, section 4.2: one colour and similar depths make the block unnecessary.
    /// "Similar" is measured against the plane the Pixel will keep (the reclaiming
    /// fragment's dxz/dyz): the samples' depths less that plane's offsets must spread
    /// strictly less than the threshold. A raw max - min would also count a single plane's
    /// own slope across the pixel (thousands of raw units on a tilted polygon), which is not
    /// what makes two polygons differ.
    fn try_reclaim(&mut self, r: usize, i: usize, f: Frag, c: &mut Counters) {
        let Some(spread) = self.config.reclaim_spread else {
            return;
        };
        c.aa_reclaim_checks += 1;
        let b = self.planes[r].block[i];
        let cells = self.pool.cells(b);
        let rgb = self.pool.rgb[cells.start];
        if self.pool.rgb[cells.clone()].iter().any(|&x| x != rgb) {
            return;
        }
        let Some((lo, hi)) = self.residual_range(b, f.slope) else {
            return;
        };
        if hi - lo >= i64::from(spread) {
            return;
        }
        let prim = self.pool.prim[cells]
            .iter()
            .copied()
            .min()
            .unwrap_or(f.prim);
        let centre = (lo + hi)
            .div_euclid(2)
            .clamp(0, i64::from(Depth::FAR.raw())) as u32;
        let p = &mut self.planes[r];
        p.rgb[i] = rgb;
        p.z[i] = centre;
        p.prim[i] = prim;
        p.slope[i] = f.slope;
        p.block[i] = NO_BLOCK;
        self.pool.release(b);
        self.reclaimed += 1;
    }

    /// Min and max over a block's samples of (depth - the offset `slope` predicts for the
    /// sample's position): the depth at the pixel centre each sample implies. `None` if a
    /// sample still holds the cleared depth (background never merges with a polygon).
    fn residual_range(&self, block: u32, slope: [i64; 2]) -> Option<(i64, i64)> {
        let grid = self.config.grid;
        let half = masks::STEPS / 2;
        let mut range: Option<(i64, i64)> = None;
        for s in 0..grid.samples() {
            let z = self.pool.z[block as usize + s as usize];
            if z == Depth::CLEARED {
                return None;
            }
            let (sx, sy) = grid.sample(s);
            let predicted = offset_of(slope, sx - half, sy - half);
            let v = i64::from(z) - predicted;
            range = Some(range.map_or((v, v), |(lo, hi)| (lo.min(v), hi.max(v))));
        }
        range
    }
}

/// The depth change `slope` predicts from the pixel centre to an offset `(ox, oy)` in 1/24
/// pixel, rounded to nearest raw unit.
fn offset_of(slope: [i64; 2], ox: i64, oy: i64) -> i64 {
    let d = i128::from(masks::STEPS);
    let num = i128::from(slope[0]) * i128::from(ox) + i128::from(slope[1]) * i128::from(oy);
    (num + 128 * d)
        .div_euclid(256 * d)
        .clamp(i128::from(i64::MIN / 2), i128::from(i64::MAX / 2)) as i64
}

impl Target for AdaptiveTarget {
    fn rects(&self) -> &[ScreenRect] {
        &self.rects
    }

    fn sampling(&self) -> Sampling {
        Sampling::Conservative
    }

    fn span(&mut self, rect: usize, span: &Span<'_>, counters: &mut Counters) {
        let tri = span.triangle();
        let slope = slopes(tri);
        let prim = span.prim();
        let y = span.y();
        for frag in span.fragments() {
            let f = Frag {
                z: frag.z,
                fine: tri.depth_fine_at(i64::from(frag.x), i64::from(y)),
                rgb: frag.rgb,
                prim,
                slope,
            };
            self.fragment(rect, frag.x, y, f, span, counters);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn demand(peak_cells: u64, grid_side: u32, overflowed: u64, pool_cells: u64) -> AaStats {
        AaStats {
            grid_side,
            peak_cells,
            overflowed_pixels: overflowed,
            pool_cells,
            ..AaStats::default()
        }
    }

    /// Paper 000, section 4.1: a pool of 4 cells per pixel holds 4x4 blocks for 25% of the
    /// pixels, 3x3 for 44%, 2x2 for all of them.
    #[test]
    fn adaptation_picks_the_finest_grid_the_demand_fits() {
        let pixels = 1000;
        let pool = 4 * pixels;
        // 250 edge pixels at 4x4 fill the pool exactly: keep 4x4.
        assert_eq!(adapt(&demand(250 * 16, 4, 0, pool)), Grid::X4);
        // One more (overflowed) pixel: 3x3 (251 * 9 <= 4000).
        assert_eq!(adapt(&demand(250 * 16, 4, 1, pool)), Grid::X3);
        // 444 at 3x3 still fit 3x3; 445 need 2x2.
        assert_eq!(adapt(&demand(444 * 9, 3, 0, pool)), Grid::X3);
        assert_eq!(adapt(&demand(445 * 9, 3, 0, pool)), Grid::X2);
        // Few edges again: back to 4x4.
        assert_eq!(adapt(&demand(100 * 4, 2, 0, pool)), Grid::X4);
        // More than the pool holds even at 2x2: 2x2 is the floor.
        assert_eq!(adapt(&demand(4000, 2, 500, pool)), Grid::X2);
        // An empty pool: 2x2, nothing fits anyway.
        assert_eq!(adapt(&demand(0, 4, 10, 0)), Grid::X2);
    }

    #[test]
    fn a_block_goes_back_on_the_free_list_and_is_reused() {
        let mut pool = Pool::new(Bytes::new(2 * 16 * SUBPIXEL_BYTES), Grid::X4);
        let a = pool.alloc().unwrap();
        let b = pool.alloc().unwrap();
        assert!(pool.alloc().is_none() && pool.exhausted());
        pool.release(a);
        assert_eq!(pool.live, 16);
        assert_eq!(pool.alloc(), Some(a));
        assert_eq!((pool.live, pool.peak), (32, 32));
        assert_ne!(a, b);
    }
}
