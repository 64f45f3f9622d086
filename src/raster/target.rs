//! Where fragments go: the [`Target`] trait and its implementations (whole framebuffer,
//! a set of screen regions, a sparse active-pixel buffer with an optional fragment record,
//! one scanline, and an additive counting target for tests).
//!
//! Must never compute coverage, depth or colour (that is `scan`), and never know which node
//! or algorithm owns it.
//!
//! # Coordinate space
//! Every target speaks screen pixels of the viewport (see `screen`): x right, y down, origin
//! at the top-left pixel. A target announces the rectangles it accepts; the scan step only
//! generates spans inside them, one rectangle at a time, so a target never sees a fragment
//! outside its memory.
//!
//! # Depth test
//! Depth is a `u32`, smaller is nearer; a buffer is cleared to `u32::MAX`, which no fragment
//! has. Fragments are ordered by (depth, primitive id): a fragment is written when its depth
//! is strictly less than the stored one, or equal with a smaller primitive id. So a tie
//! always goes to the lower primitive id whatever the drawing order: a parallel renderer that
//! draws triangles as they arrive, or merges partial images, produces exactly the sequential
//! image; drawing a mesh twice changes nothing.
//!
//! # Anti-aliasing targets (how paper 000's adaptive supersampling plugs in)
//! Such a target returns [`Sampling::Conservative`] from [`Target::sampling`], so its spans
//! hold every pixel the triangle touches, not only covered centres. A span carries its
//! triangle ([`Span::triangle`]), which answers `fully_covers_pixel(x, y)` (an interior
//! pixel: sample once) and, for edge pixels, either `coverage_mask(x, y, samples)` (exact
//! per-sample coverage; an empty mask means the pixel was only near a corner) or the
//! bitmask table of `aa::masks`. The span's fragments give depth and colour at the pixel
//! centre, clamped to the triangle's range even where the centre lies outside it. Samples
//! obey the same top-left rule as centres, so the coverage masks of a mesh are watertight
//! too (tests/raster_coverage.rs checks this with a mask-counting target). The targets
//! themselves live in `aa/` (adaptive supersampling, k x k supersampling).

use super::counters::Counters;
use super::fixed::Depth;
use super::scan::{Sampling, Span};
use super::screen::{ScreenRect, Viewport};

/// Bytes of memory per pixel of a colour + depth buffer (24-bit colour, 32-bit depth): what
/// a node's memory pool is charged for a framebuffer, region or scanline of that size.
pub const BYTES_PER_PIXEL: u64 = 3 + 4;

/// Bytes read by one depth test (a `u32`).
const DEPTH_BYTES: u64 = 4;
/// Bytes written by one accepted fragment: depth plus 24-bit colour.
const WRITE_BYTES: u64 = 4 + 3;

/// A destination for fragments.
pub trait Target {
    /// Disjoint rectangles, in viewport pixels, that this target accepts.
    fn rects(&self) -> &[ScreenRect];

    /// Which pixels spans contain: covered centres (the default), or every touched pixel
    /// for a coverage-mask target.
    fn sampling(&self) -> Sampling {
        Sampling::Centre
    }

    /// One span inside `self.rects()[rect]`. The target consumes its fragments and adds
    /// what it did to `counters` (`pixels_tested`, `pixels_written`, `bytes_touched`).
    fn span(&mut self, rect: usize, span: &Span<'_>, counters: &mut Counters);
}

/// Whether a fragment (`z`, `prim`) is nearer than what a pixel holds: the (depth, primitive
/// id) order of the module doc.
#[inline]
pub fn nearer(z: u32, prim: u32, stored_z: u32, stored_prim: u32) -> bool {
    z < stored_z || (z == stored_z && prim < stored_prim)
}

/// Depth-tests a span into row slices that start at the span's first pixel and are exactly
/// as long as the span. Returns the number of fragments written.
#[inline]
fn depth_test_span(
    span: &Span<'_>,
    color: &mut [[u8; 3]],
    depth: &mut [u32],
    prims: &mut [u32],
) -> u64 {
    let mut written = 0;
    let prim = span.prim();
    for (f, ((c, d), p)) in span
        .fragments()
        .zip(color.iter_mut().zip(depth.iter_mut()).zip(prims.iter_mut()))
    {
        if nearer(f.z, prim, *d, *p) {
            *d = f.z;
            *p = prim;
            *c = f.rgb;
            written += 1;
        }
    }
    written
}

fn count_depth_tested(counters: &mut Counters, tested: usize, written: u64) {
    counters.pixels_tested += tested as u64;
    counters.pixels_written += written;
    counters.bytes_touched += tested as u64 * DEPTH_BYTES + written * WRITE_BYTES;
}

/// Colour and depth for a rectangle, row-major.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PixelBuffer {
    rect: ScreenRect,
    color: Vec<[u8; 3]>,
    depth: Vec<u32>,
    /// The primitive each pixel's fragment came from (`u32::MAX` when cleared): the depth
    /// test's tie-break.
    prim: Vec<u32>,
}

impl PixelBuffer {
    fn new(rect: ScreenRect, clear: [u8; 3]) -> PixelBuffer {
        PixelBuffer {
            rect,
            color: vec![clear; rect.pixels()],
            depth: vec![Depth::CLEARED; rect.pixels()],
            prim: vec![u32::MAX; rect.pixels()],
        }
    }

    pub fn rect(&self) -> ScreenRect {
        self.rect
    }

    /// Modelled memory of this buffer: pixels times [`BYTES_PER_PIXEL`].
    pub fn bytes(&self) -> u64 {
        self.rect.pixels() as u64 * BYTES_PER_PIXEL
    }

    /// Clears colour to `clear` and depth to the cleared value.
    pub fn clear(&mut self, clear: [u8; 3]) {
        self.color.fill(clear);
        self.depth.fill(Depth::CLEARED);
        self.prim.fill(u32::MAX);
    }

    fn index(&self, x: u32, y: u32) -> Option<usize> {
        let r = self.rect;
        r.contains(x, y)
            .then(|| (y - r.y0()) as usize * r.width() as usize + (x - r.x0()) as usize)
    }

    /// Colour at screen pixel `(x, y)`, `None` outside the rectangle.
    pub fn color(&self, x: u32, y: u32) -> Option<[u8; 3]> {
        self.index(x, y).map(|i| self.color[i])
    }

    /// Depth at screen pixel `(x, y)` (`u32::MAX` when never written).
    pub fn depth(&self, x: u32, y: u32) -> Option<u32> {
        self.index(x, y).map(|i| self.depth[i])
    }

    /// All colours, row-major over the rectangle.
    pub fn colors(&self) -> &[[u8; 3]] {
        &self.color
    }

    pub fn depths(&self) -> &[u32] {
        &self.depth
    }

    #[inline]
    fn depth_test(&mut self, span: &Span<'_>, counters: &mut Counters) {
        let r = self.rect;
        let start =
            (span.y() - r.y0()) as usize * r.width() as usize + (span.x0() - r.x0()) as usize;
        let end = start + span.len();
        let written = depth_test_span(
            span,
            &mut self.color[start..end],
            &mut self.depth[start..end],
            &mut self.prim[start..end],
        );
        count_depth_tested(counters, span.len(), written);
    }
}

/// The whole viewport's colour and depth buffer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Framebuffer {
    rects: [ScreenRect; 1],
    buf: PixelBuffer,
}

impl Framebuffer {
    /// Black, depth cleared.
    pub fn new(viewport: Viewport) -> Framebuffer {
        Framebuffer::with_clear(viewport, [0; 3])
    }

    pub fn with_clear(viewport: Viewport, clear: [u8; 3]) -> Framebuffer {
        Framebuffer {
            rects: [viewport.rect()],
            buf: PixelBuffer::new(viewport.rect(), clear),
        }
    }

    pub fn width(&self) -> u32 {
        self.rects[0].width()
    }
    pub fn height(&self) -> u32 {
        self.rects[0].height()
    }
    pub fn clear(&mut self, clear: [u8; 3]) {
        self.buf.clear(clear);
    }
    pub fn color(&self, x: u32, y: u32) -> Option<[u8; 3]> {
        self.buf.color(x, y)
    }
    pub fn depth(&self, x: u32, y: u32) -> Option<u32> {
        self.buf.depth(x, y)
    }
    /// Row-major 24-bit colours.
    pub fn colors(&self) -> &[[u8; 3]] {
        self.buf.colors()
    }
    pub fn depths(&self) -> &[u32] {
        self.buf.depths()
    }
    /// Copies one finished row (as from a [`ScanlineBuffer`]) into row `y`.
    pub fn set_row(&mut self, y: u32, color: &[[u8; 3]], depth: &[u32]) {
        let w = self.width() as usize;
        if y < self.height() && color.len() == w && depth.len() == w {
            let o = y as usize * w;
            self.buf.color[o..o + w].copy_from_slice(color);
            self.buf.depth[o..o + w].copy_from_slice(depth);
        }
    }
    /// Deterministic hash of size and colours (see `image::image_hash`).
    pub fn hash(&self) -> u64 {
        super::image::image_hash(self.width(), self.height(), self.colors())
    }
}

impl Target for Framebuffer {
    fn rects(&self) -> &[ScreenRect] {
        &self.rects
    }
    #[inline]
    fn span(&mut self, _rect: usize, span: &Span<'_>, counters: &mut Counters) {
        self.buf.depth_test(span, counters);
    }
}

/// Why a region set was rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RegionError {
    #[error("region {0} extends beyond the viewport")]
    OutsideViewport(usize),
    #[error("regions {0} and {1} overlap")]
    Overlap(usize, usize),
}

/// Regions must lie in the viewport and not overlap (every region target's rule).
pub(crate) fn check_regions(viewport: Viewport, rects: &[ScreenRect]) -> Result<(), RegionError> {
    for (i, r) in rects.iter().enumerate() {
        if !r.within(viewport) {
            return Err(RegionError::OutsideViewport(i));
        }
        if let Some(j) = rects[..i].iter().position(|q| q.overlaps(*r)) {
            return Err(RegionError::Overlap(j, i));
        }
    }
    Ok(())
}

/// Several disjoint screen regions, each with its own colour and depth buffer: the memory
/// of one sort-middle rasterizer node.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RegionSet {
    rects: Vec<ScreenRect>,
    bufs: Vec<PixelBuffer>,
}

impl RegionSet {
    /// Regions must lie in the viewport and not overlap; they need not cover it.
    pub fn new(viewport: Viewport, rects: Vec<ScreenRect>) -> Result<RegionSet, RegionError> {
        check_regions(viewport, &rects)?;
        let bufs = rects.iter().map(|&r| PixelBuffer::new(r, [0; 3])).collect();
        Ok(RegionSet { rects, bufs })
    }

    /// As `new`, with every region cleared to `clear` (a scene's background).
    pub fn with_clear(
        viewport: Viewport,
        rects: Vec<ScreenRect>,
        clear: [u8; 3],
    ) -> Result<RegionSet, RegionError> {
        let mut set = RegionSet::new(viewport, rects)?;
        for b in &mut set.bufs {
            b.clear(clear);
        }
        Ok(set)
    }

    /// Regions already checked by [`check_regions`], cleared to `clear`.
    pub(crate) fn from_checked(rects: Vec<ScreenRect>, clear: [u8; 3]) -> RegionSet {
        let bufs = rects.iter().map(|&r| PixelBuffer::new(r, clear)).collect();
        RegionSet { rects, bufs }
    }

    pub fn regions(&self) -> &[PixelBuffer] {
        &self.bufs
    }

    /// Stores a finished pixel of region `region` (an anti-aliasing target's resolved
    /// colour and nearest depth); pixels outside the region are ignored.
    pub(crate) fn set_pixel(&mut self, region: usize, x: u32, y: u32, rgb: [u8; 3], z: u32) {
        if let Some(b) = self.bufs.get_mut(region) {
            if let Some(i) = b.index(x, y) {
                b.color[i] = rgb;
                b.depth[i] = z;
            }
        }
    }

    /// Copies every region into a framebuffer (colour and depth).
    pub fn copy_into(&self, fb: &mut Framebuffer) {
        for b in &self.bufs {
            let r = b.rect();
            let w = r.width() as usize;
            for (row, y) in (r.y0()..r.y1()).enumerate() {
                let src = row * w..(row + 1) * w;
                if let Some(dst) = fb.buf.index(r.x0(), y) {
                    fb.buf.color[dst..dst + w].copy_from_slice(&b.color[src.clone()]);
                    fb.buf.depth[dst..dst + w].copy_from_slice(&b.depth[src.clone()]);
                    fb.buf.prim[dst..dst + w].copy_from_slice(&b.prim[src]);
                }
            }
        }
    }
}

impl Target for RegionSet {
    fn rects(&self) -> &[ScreenRect] {
        &self.rects
    }
    #[inline]
    fn span(&mut self, rect: usize, span: &Span<'_>, counters: &mut Counters) {
        self.bufs[rect].depth_test(span, counters);
    }
}

/// A fragment as generated, before any depth test: for pixel traces.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FragmentRecord {
    pub x: u32,
    pub y: u32,
    pub z: u32,
    pub rgb: [u8; 3],
    pub prim: u32,
}

/// A pixel that at least one fragment reached, with the nearest fragment's values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ActivePixel {
    pub x: u32,
    pub y: u32,
    pub z: u32,
    pub rgb: [u8; 3],
    /// The primitive of the nearest fragment (host-side tie-break; not part of
    /// `ACTIVE_PIXEL_BYTES`).
    pub prim: u32,
}

/// Bytes of one active pixel as sort-last sparse merging ships it: x, y (u16 each), z (u32),
/// rgb (3 bytes).
pub const ACTIVE_PIXEL_BYTES: u64 = 2 + 2 + 4 + 3;

/// Stores only the pixels fragments reached (sort-last sparse), in first-touch order, and
/// optionally every fragment before the depth test (pixel traces, paper 003).
///
/// The simulated memory is `active().len() * ACTIVE_PIXEL_BYTES`; the index that finds a
/// pixel's entry is a host-side lookup structure, not part of the modelled memory. It holds
/// a row only once a fragment falls in it: a node of a 32,768-process run draws into a few
/// rows of a 64-megapixel screen, and a whole-screen index would be 256 MB to clear.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SparseBuffer {
    rects: [ScreenRect; 1],
    /// Per row, once touched: each pixel's entry in `active`, or `u32::MAX`.
    index: Vec<Option<Box<[u32]>>>,
    active: Vec<ActivePixel>,
    record: Option<Vec<FragmentRecord>>,
}

impl SparseBuffer {
    pub fn new(viewport: Viewport) -> SparseBuffer {
        SparseBuffer {
            rects: [viewport.rect()],
            index: vec![None; viewport.height() as usize],
            active: Vec::new(),
            record: None,
        }
    }

    /// Also records every fragment, in generation order, before the depth test.
    pub fn recording(viewport: Viewport) -> SparseBuffer {
        SparseBuffer {
            record: Some(Vec::new()),
            ..SparseBuffer::new(viewport)
        }
    }

    /// Active pixels in first-touch order.
    pub fn active(&self) -> &[ActivePixel] {
        &self.active
    }

    /// Active pixels in raster order (row by row, left to right).
    pub fn active_sorted(&self) -> Vec<ActivePixel> {
        let mut v = self.active.clone();
        v.sort_by_key(|p| (p.y, p.x));
        v
    }

    /// Every fragment generated, when built with [`SparseBuffer::recording`].
    pub fn fragments(&self) -> Option<&[FragmentRecord]> {
        self.record.as_deref()
    }
}

impl Target for SparseBuffer {
    fn rects(&self) -> &[ScreenRect] {
        &self.rects
    }
    fn span(&mut self, _rect: usize, span: &Span<'_>, counters: &mut Counters) {
        let w = self.rects[0].width() as usize;
        let y = span.y();
        let row = self.index[y as usize].get_or_insert_with(|| vec![u32::MAX; w].into());
        let mut written = 0;
        for f in span.fragments() {
            if let Some(rec) = &mut self.record {
                rec.push(FragmentRecord {
                    x: f.x,
                    y,
                    z: f.z,
                    rgb: f.rgb,
                    prim: span.prim(),
                });
            }
            let slot = &mut row[f.x as usize];
            if *slot == u32::MAX {
                *slot = self.active.len() as u32;
                self.active.push(ActivePixel {
                    x: f.x,
                    y,
                    z: f.z,
                    rgb: f.rgb,
                    prim: span.prim(),
                });
                written += 1;
            } else {
                let p = &mut self.active[*slot as usize];
                if nearer(f.z, span.prim(), p.z, p.prim) {
                    p.z = f.z;
                    p.rgb = f.rgb;
                    p.prim = span.prim();
                    written += 1;
                }
            }
        }
        count_depth_tested(counters, span.len(), written);
    }
}

/// One scanline's colour and depth: the scanline renderer's only pixel memory. Its
/// rectangle is row `y` of the viewport.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ScanlineBuffer {
    rects: [ScreenRect; 1],
    buf: PixelBuffer,
}

impl ScanlineBuffer {
    /// Row `y` of `viewport`; `None` when the row is outside it.
    pub fn new(viewport: Viewport, y: u32) -> Option<ScanlineBuffer> {
        let r = ScreenRect::new(0, y, viewport.width(), y + 1)?.intersect(viewport.rect())?;
        Some(ScanlineBuffer {
            rects: [r],
            buf: PixelBuffer::new(r, [0; 3]),
        })
    }

    pub fn y(&self) -> u32 {
        self.rects[0].y0()
    }

    /// Moves to row `y` (which must be inside the viewport the buffer was made for) and
    /// clears colour to `clear` and depth.
    pub fn reset(&mut self, y: u32, clear: [u8; 3]) {
        let r = self.rects[0];
        if let Some(moved) = ScreenRect::new(r.x0(), y, r.x1(), y + 1) {
            self.rects[0] = moved;
            self.buf.rect = moved;
        }
        self.buf.clear(clear);
    }

    pub fn colors(&self) -> &[[u8; 3]] {
        self.buf.colors()
    }
    pub fn depths(&self) -> &[u32] {
        self.buf.depths()
    }
    /// The primitive each pixel's fragment came from (`u32::MAX` where none reached it):
    /// what a sort-last merge of scanlines needs for the depth test's tie-break.
    pub fn prims(&self) -> &[u32] {
        &self.buf.prim
    }
}

impl Target for ScanlineBuffer {
    fn rects(&self) -> &[ScreenRect] {
        &self.rects
    }
    #[inline]
    fn span(&mut self, _rect: usize, span: &Span<'_>, counters: &mut Counters) {
        self.buf.depth_test(span, counters);
    }
}

/// Counts how many fragments reach each pixel, with no depth test: the watertightness
/// oracle of the tests.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CountingTarget {
    rects: [ScreenRect; 1],
    counts: Vec<u32>,
}

impl CountingTarget {
    pub fn new(viewport: Viewport) -> CountingTarget {
        CountingTarget {
            rects: [viewport.rect()],
            counts: vec![0; viewport.pixels()],
        }
    }
    pub fn width(&self) -> u32 {
        self.rects[0].width()
    }
    pub fn height(&self) -> u32 {
        self.rects[0].height()
    }
    /// Fragments that reached `(x, y)`; 0 outside the viewport.
    pub fn count(&self, x: u32, y: u32) -> u32 {
        if self.rects[0].contains(x, y) {
            self.counts[y as usize * self.width() as usize + x as usize]
        } else {
            0
        }
    }
    /// Row-major counts.
    pub fn counts(&self) -> &[u32] {
        &self.counts
    }
}

impl Target for CountingTarget {
    fn rects(&self) -> &[ScreenRect] {
        &self.rects
    }
    fn span(&mut self, _rect: usize, span: &Span<'_>, counters: &mut Counters) {
        let o = span.y() as usize * self.width() as usize;
        for c in &mut self.counts[o + span.x0() as usize..o + span.x1() as usize] {
            *c += 1;
        }
        counters.pixels_tested += span.len() as u64;
        counters.pixels_written += span.len() as u64;
        counters.bytes_touched += span.len() as u64 * 8;
    }
}
