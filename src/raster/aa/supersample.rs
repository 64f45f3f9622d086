//! Traditional supersampling, the reference adaptive supersampling saves memory against:
//! every pixel holds k x k samples (7 bytes each), each depth-tested on its own, resolved
//! with a box filter. k = 4 is paper 002's 16 samples and paper 000's 29.4 MB comparison;
//! k = 16 (256 samples) is an accuracy reference.
//!
//! Must never approximate coverage: each sample is tested against the exact edge functions
//! under the top-left rule (`RasterTriangle::covers_sample`), so a mesh covers each sample
//! exactly once. Must never read a clock or know about nodes.

use super::{box_filter, sample_depth, slopes, AaStats, SUBPIXEL_BYTES};
use crate::raster::counters::Counters;
use crate::raster::fixed::{Depth, SUBPIXEL_ONE};
use crate::raster::scan::{Sampling, Span};
use crate::raster::screen::{ScreenRect, Viewport};
use crate::raster::target::{check_regions, nearer, Framebuffer, RegionError, RegionSet, Target};

/// The largest k: 16 x 16 = 256 samples per pixel (sample positions stay on the 1/256
/// subpixel lattice exactly for k = 2, 4, 8, 16).
pub const MAX_SUPERSAMPLE_SIDE: u32 = 16;

/// One region's samples, pixel-major (pixel i's samples at `i * k * k ..`).
#[derive(Clone, Debug)]
struct Samples {
    rect: ScreenRect,
    z: Vec<u32>,
    rgb: Vec<[u8; 3]>,
    prim: Vec<u32>,
}

/// A k x k supersampling buffer over disjoint regions.
#[derive(Clone, Debug)]
pub struct SupersampleTarget {
    rects: Vec<ScreenRect>,
    regions: Vec<Samples>,
    side: u32,
    /// Sample positions in 1/256 pixel from the pixel's top-left corner, row-major.
    positions: Vec<(u8, u8)>,
    clear: [u8; 3],
}

impl SupersampleTarget {
    /// `side` is clamped to 1..=[`MAX_SUPERSAMPLE_SIDE`]. Regions as for `RegionSet`.
    pub fn new(
        viewport: Viewport,
        rects: Vec<ScreenRect>,
        side: u32,
        clear: [u8; 3],
    ) -> Result<SupersampleTarget, RegionError> {
        check_regions(viewport, &rects)?;
        let side = side.clamp(1, MAX_SUPERSAMPLE_SIDE);
        let n = (side * side) as usize;
        let regions = rects
            .iter()
            .map(|&rect| Samples {
                rect,
                z: vec![Depth::CLEARED; rect.pixels() * n],
                rgb: vec![clear; rect.pixels() * n],
                prim: vec![u32::MAX; rect.pixels() * n],
            })
            .collect();
        Ok(SupersampleTarget {
            rects,
            regions,
            side,
            positions: sample_positions(side),
            clear,
        })
    }

    /// The whole viewport.
    pub fn full_screen(viewport: Viewport, side: u32, clear: [u8; 3]) -> SupersampleTarget {
        // The viewport's own rectangle always lies in it.
        SupersampleTarget::new(viewport, vec![viewport.rect()], side, clear)
            .unwrap_or_else(|_| unreachable!("a viewport's rectangle is inside the viewport"))
    }

    pub fn side(&self) -> u32 {
        self.side
    }

    pub fn pixels(&self) -> u64 {
        self.rects.iter().map(|r| r.pixels() as u64).sum()
    }

    /// Samples per pixel times pixels.
    pub fn samples(&self) -> u64 {
        self.pixels() * u64::from(self.side * self.side)
    }

    /// What the buffer holds: every pixel supersampled, every sample a 7-byte cell.
    pub fn stats(&self) -> AaStats {
        AaStats {
            grid_side: self.side,
            pixels: self.pixels(),
            supersampled_pixels: self.pixels(),
            live_super_pixels: self.pixels(),
            peak_cells: self.samples(),
            live_cells: self.samples(),
            pool_cells: self.samples(),
            ..AaStats::default()
        }
    }

    /// Modelled memory: samples times [`SUBPIXEL_BYTES`] (no Pixel array).
    pub fn bytes(&self) -> crate::units::Bytes {
        crate::units::Bytes::new(self.samples() * SUBPIXEL_BYTES)
    }

    /// Every written sample of a full-screen target as `(location, z, prim, rgb)`, the
    /// location row-major on the grid `side` times finer in each direction (sample (i, j) of
    /// pixel (x, y) at column `x * side + i`, row `y * side + j`), in that grid's raster
    /// order: how a sort-last node hands its samples to a merge that moves them one by one.
    pub fn written_samples(&self) -> Vec<(u32, u32, u32, [u8; 3])> {
        let side = self.side as usize;
        let n = side * side;
        let mut out = Vec::new();
        for s in &self.regions {
            let (w, h) = (s.rect.width() as usize, s.rect.height() as usize);
            let fine_w = (s.rect.x0() as usize + w) * side;
            for y in 0..h * side {
                let (py, j) = (y / side, y % side);
                let fine_y = (s.rect.y0() as usize * side + y) as u32;
                for x in 0..w * side {
                    let (px, i) = (x / side, x % side);
                    let cell = (py * w + px) * n + j * side + i;
                    if s.prim[cell] != u32::MAX {
                        let fine_x = (s.rect.x0() as usize * side + x) as u32;
                        let loc = fine_y * fine_w as u32 + fine_x;
                        out.push((loc, s.z[cell], s.prim[cell], s.rgb[cell]));
                    }
                }
            }
        }
        out
    }

    /// Box-filtered image with each pixel's nearest sample depth; one
    /// `aa_resolved_pixels` per pixel.
    /// [`resolve`](Self::resolve) straight into a framebuffer (pixels outside the regions
    /// keep what the framebuffer holds).
    pub fn resolve_into(&self, fb: &mut Framebuffer, counters: &mut Counters) {
        self.resolve(counters).copy_into(fb);
    }

    pub fn resolve(&self, counters: &mut Counters) -> RegionSet {
        let mut out = RegionSet::from_checked(self.rects.clone(), self.clear);
        let n = (self.side * self.side) as usize;
        for (r, s) in self.regions.iter().enumerate() {
            let w = s.rect.width() as usize;
            for i in 0..s.rect.pixels() {
                let cells = i * n..(i + 1) * n;
                let z = s.z[cells.clone()].iter().copied().min();
                let (x, y) = (s.rect.x0() + (i % w) as u32, s.rect.y0() + (i / w) as u32);
                out.set_pixel(
                    r,
                    x,
                    y,
                    box_filter(&s.rgb[cells]),
                    z.unwrap_or(Depth::CLEARED),
                );
                counters.aa_resolved_pixels += 1;
            }
        }
        out
    }
}

/// Resolves an image of samples drawn on a grid `side` times finer in each direction (one
/// sample per pixel of `samples`, as sort-last merges move them) with the same box filter as
/// [`SupersampleTarget::resolve`]: each output pixel is the rounded mean of its `side x side`
/// samples, its depth the nearest of them. `samples`' sides must be multiples of `side`.
pub fn downsample(samples: &Framebuffer, side: u32) -> Framebuffer {
    let (w, h) = (samples.width() / side, samples.height() / side);
    let viewport = Viewport::new(w, h).expect("a sample grid is at least one pixel per side");
    let mut out = Framebuffer::new(viewport);
    let (colors, depths) = (samples.colors(), samples.depths());
    let big_w = samples.width() as usize;
    let side = side as usize;
    let mut cell = Vec::with_capacity(side * side);
    let mut row_rgb = Vec::with_capacity(w as usize);
    let mut row_z = Vec::with_capacity(w as usize);
    for y in 0..h as usize {
        row_rgb.clear();
        row_z.clear();
        for x in 0..w as usize {
            cell.clear();
            let mut z = u32::MAX;
            for sy in y * side..(y + 1) * side {
                let start = sy * big_w + x * side;
                cell.extend_from_slice(&colors[start..start + side]);
                z = depths[start..start + side]
                    .iter()
                    .copied()
                    .fold(z, u32::min);
            }
            row_rgb.push(box_filter(&cell));
            row_z.push(z);
        }
        out.set_row(y as u32, &row_rgb, &row_z);
    }
    out
}

impl Target for SupersampleTarget {
    fn rects(&self) -> &[ScreenRect] {
        &self.rects
    }

    fn sampling(&self) -> Sampling {
        Sampling::Conservative
    }

    fn span(&mut self, rect: usize, span: &Span<'_>, c: &mut Counters) {
        let prim = span.prim();
        let n = (self.side * self.side) as usize;
        let s = &mut self.regions[rect];
        let w = s.rect.width() as usize;
        let row = (span.y() - s.rect.y0()) as usize * w;
        for f in span.fragments() {
            let base = (row + (f.x - s.rect.x0()) as usize) * n;
            for_each_sample(&self.positions, span, f.x, c, |k, z, c| {
                let cell = base + k;
                c.aa_subpixel_tests += 1;
                c.bytes_touched += 4;
                if nearer(z, prim, s.z[cell], s.prim[cell]) {
                    s.z[cell] = z;
                    s.rgb[cell] = f.rgb;
                    s.prim[cell] = prim;
                    c.aa_subpixel_writes += 1;
                    c.bytes_touched += SUBPIXEL_BYTES;
                }
            });
        }
    }
}

/// The k x k sample positions of a pixel, row-major, in 1/256 pixel from its top-left
/// corner: cell centres (2i + 1) / 2k, exact on the subpixel lattice for k = 2, 4, 8, 16.
pub fn sample_positions(side: u32) -> Vec<(u8, u8)> {
    let at = |i: u32| ((2 * i + 1) * SUBPIXEL_ONE as u32 / (2 * side)) as u8;
    (0..side * side)
        .map(|s| (at(s % side), at(s / side)))
        .collect()
}

/// Calls `visit(k, z, c)` for each sample `k` of `positions` that pixel `x` of `span`'s row
/// covers, with the triangle's depth there (its plane from the pixel centre): the one
/// definition of a supersampled fragment, for a buffer that depth-tests the samples and for
/// a sort-last node that ships them untested. Counts a coverage mask for a pixel the
/// triangle covers partly.
pub fn for_each_sample(
    positions: &[(u8, u8)],
    span: &Span<'_>,
    x: u32,
    c: &mut Counters,
    mut visit: impl FnMut(usize, u32, &mut Counters),
) {
    let tri = span.triangle();
    let slope = slopes(tri);
    let half = SUBPIXEL_ONE / 2;
    let (px, py) = (i64::from(x), i64::from(span.y()));
    let full = tri.fully_covers_pixel(px, py);
    let centre = tri.depth_fine_at(px, py);
    if !full {
        c.aa_coverage_masks += 1;
    }
    for (k, &(sx, sy)) in positions.iter().enumerate() {
        if !full && !tri.covers_sample(px, py, sx, sy) {
            continue;
        }
        let z = sample_depth(
            centre,
            slope,
            i64::from(sx) - half,
            i64::from(sy) - half,
            SUBPIXEL_ONE,
        );
        visit(k, z, c);
    }
}
