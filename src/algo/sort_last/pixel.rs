//! The pixel a sort-last merge moves, as one trait over the two buffers a node can render
//! into: [`Px`] from an ordinary active-pixel buffer (also on a supersampling grid, where each
//! grid pixel is one sample) and [`AaPx`] from paper 000's adaptive buffer (a plain Pixel, or
//! a super pixel carrying its n x n Subpixels). Every variant is written once over
//! [`ShippedPixel`]; which one a run uses follows `aa`.
//!
//! What a pixel costs on the wire: a sparse merge ships its address with it
//! ([`ShippedPixel::wire_bytes`]); a full-frame merge ships whole rows of records
//! (`Ctx::rows_bytes`) plus what super pixels carry beyond their record
//! ([`ShippedPixel::extra_bytes`]).
//!
//! Must never charge time or send: the variants do, through `Ctx`.

use std::fmt::Debug;

use super::Ctx;
use crate::raster::aa::{
    for_each_sample, AaPixel, AdaptiveConfig, AdaptiveTarget, Blocks, Grid, SupersampleTarget,
    PIXEL_BYTES,
};
use crate::raster::scan::{Fragment, Sampling, Span};
use crate::raster::target::nearer;
use crate::raster::{Counters, ScreenRect, SparseBuffer, Target, ACTIVE_PIXEL_BYTES};

/// One pixel as a merge ships it.
pub(crate) trait ShippedPixel: Clone + Debug + 'static {
    /// The buffer a node renders its share into.
    type Buffer: Target;

    /// An empty buffer for `frame` on node `node` (adaptive: the frame's grid and pool).
    fn buffer(ctx: &Ctx, frame: u32) -> Self::Buffer;

    /// A rendered buffer's pixels in raster order; the node's pool state is noted in `ctx`.
    fn collect(buffer: Self::Buffer, ctx: &Ctx, node: u32) -> Vec<Self>;

    /// What a node ships of a fragment without a depth test (direct send): nothing, the
    /// pixel, or with supersampling the samples it covers (`grid`: the frame's subpixel
    /// resolution).
    fn fragments(
        ctx: &Ctx,
        grid: Grid,
        span: &Span<'_>,
        f: &Fragment,
        counters: &mut Counters,
        out: &mut Vec<Self>,
    );

    /// Which pixels the buffers of this pixel type want spans to hold.
    fn sampling(ctx: &Ctx) -> Sampling;

    /// Row-major screen location.
    fn loc(&self) -> u32;

    /// Moves the pixel to another location (a composite that reorders the screen).
    fn set_loc(&mut self, loc: u32);

    /// Bytes on the wire in a sparse merge: address, record and what it carries.
    fn wire_bytes(&self) -> u64;

    /// Bytes beyond its full-frame record (a super pixel's Subpixels).
    fn extra_bytes(&self) -> u64;

    /// Subpixels carried (what a listener depth-tests beyond the pixel itself).
    fn samples(&self) -> u64;

    /// The pixel as a receiving buffer stores it where it held nothing (`None`: nothing).
    fn arrive(&self, blocks: &mut Blocks) -> Option<Self>;

    /// Depth-merges `incoming` (same location) into this stored pixel; true when any of its
    /// samples was nearer.
    fn merge(&mut self, incoming: &Self, blocks: &mut Blocks) -> bool;

    /// Colour shown and nearest depth (a super pixel's box-filtered colour).
    fn resolve(&self) -> ([u8; 3], u32);

    /// The pixel with its samples resolved: a super pixel becomes a plain one of its
    /// box-filtered colour.
    fn resolved(&self) -> Self;
}

/// One pixel of an ordinary buffer. `prim` is the host-side tie-break (not shipped).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Px {
    pub loc: u32,
    pub z: u32,
    pub prim: u32,
    pub rgb: [u8; 3],
}

/// What a node renders [`Px`]s into: an active-pixel buffer, or with `aa=supersample:N` the
/// sequential supersampling buffer (the same samples, depths and colours as sort-middle's
/// and the reference's), whose samples then travel as locations of the finer grid.
pub(crate) enum PxBuffer {
    Pixels(SparseBuffer),
    Samples(SupersampleTarget),
}

impl Target for PxBuffer {
    fn rects(&self) -> &[ScreenRect] {
        match self {
            PxBuffer::Pixels(b) => b.rects(),
            PxBuffer::Samples(b) => b.rects(),
        }
    }

    fn sampling(&self) -> Sampling {
        match self {
            PxBuffer::Pixels(b) => b.sampling(),
            PxBuffer::Samples(b) => b.sampling(),
        }
    }

    fn span(&mut self, rect: usize, span: &Span<'_>, counters: &mut Counters) {
        match self {
            PxBuffer::Pixels(b) => b.span(rect, span, counters),
            PxBuffer::Samples(b) => b.span(rect, span, counters),
        }
    }
}

impl ShippedPixel for Px {
    type Buffer = PxBuffer;

    fn buffer(ctx: &Ctx, _frame: u32) -> PxBuffer {
        match ctx.settings.side {
            1 => PxBuffer::Pixels(SparseBuffer::new(ctx.viewport)),
            side => PxBuffer::Samples(SupersampleTarget::full_screen(
                ctx.screen,
                side,
                ctx.background,
            )),
        }
    }

    fn collect(buffer: PxBuffer, ctx: &Ctx, _node: u32) -> Vec<Px> {
        let width = ctx.viewport.width();
        match buffer {
            PxBuffer::Pixels(b) => b
                .active_sorted()
                .iter()
                .map(|p| Px {
                    loc: p.y * width + p.x,
                    z: p.z,
                    prim: p.prim,
                    rgb: p.rgb,
                })
                .collect(),
            PxBuffer::Samples(b) => b
                .written_samples()
                .into_iter()
                .map(|(loc, z, prim, rgb)| Px { loc, z, prim, rgb })
                .collect(),
        }
    }

    fn fragments(
        ctx: &Ctx,
        _grid: Grid,
        span: &Span<'_>,
        f: &Fragment,
        counters: &mut Counters,
        out: &mut Vec<Px>,
    ) {
        let (side, prim) = (ctx.settings.side, span.prim());
        if side == 1 {
            out.push(Px {
                loc: span.y() * ctx.viewport.width() + f.x,
                z: f.z,
                prim,
                rgb: f.rgb,
            });
            return;
        }
        let (x0, y0) = (f.x * side, span.y() * side);
        for_each_sample(&ctx.sample_positions, span, f.x, counters, |k, z, _| {
            let (i, j) = (k as u32 % side, k as u32 / side);
            out.push(Px {
                loc: (y0 + j) * ctx.viewport.width() + x0 + i,
                z,
                prim,
                rgb: f.rgb,
            });
        });
    }

    fn sampling(ctx: &Ctx) -> Sampling {
        match ctx.settings.side {
            1 => Sampling::Centre,
            _ => Sampling::Conservative,
        }
    }

    fn loc(&self) -> u32 {
        self.loc
    }

    fn set_loc(&mut self, loc: u32) {
        self.loc = loc;
    }

    fn wire_bytes(&self) -> u64 {
        ACTIVE_PIXEL_BYTES
    }

    fn extra_bytes(&self) -> u64 {
        0
    }

    fn samples(&self) -> u64 {
        0
    }

    fn arrive(&self, _blocks: &mut Blocks) -> Option<Px> {
        Some(*self)
    }

    fn merge(&mut self, incoming: &Px, _blocks: &mut Blocks) -> bool {
        let won = nearer(incoming.z, incoming.prim, self.z, self.prim);
        if won {
            *self = *incoming;
        }
        won
    }

    fn resolve(&self) -> ([u8; 3], u32) {
        (self.rgb, self.z)
    }

    fn resolved(&self) -> Px {
        *self
    }
}

/// One pixel of an adaptive buffer at its screen location.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AaPx {
    pub loc: u32,
    pub pixel: AaPixel,
}

impl ShippedPixel for AaPx {
    type Buffer = AdaptiveTarget;

    fn buffer(ctx: &Ctx, frame: u32) -> AdaptiveTarget {
        let config = AdaptiveConfig {
            pool: ctx.aa.pool,
            grid: ctx.aa.grid(frame),
            reclaim_spread: ctx.aa.reclaim_spread(),
        };
        AdaptiveTarget::full_screen(ctx.viewport, config, ctx.background)
    }

    fn collect(buffer: AdaptiveTarget, ctx: &Ctx, node: u32) -> Vec<AaPx> {
        ctx.aa.rendered(node, buffer.stats());
        let width = ctx.viewport.width();
        buffer
            .export()
            .into_iter()
            .map(|(x, y, pixel)| AaPx {
                loc: y * width + x,
                pixel,
            })
            .collect()
    }

    fn fragments(
        ctx: &Ctx,
        grid: Grid,
        span: &Span<'_>,
        f: &Fragment,
        counters: &mut Counters,
        out: &mut Vec<AaPx>,
    ) {
        let loc = span.y() * ctx.viewport.width() + f.x;
        if let Some(pixel) = AaPixel::fragment(span, f.x, f.z, f.rgb, grid, counters) {
            out.push(AaPx { loc, pixel });
        }
    }

    fn sampling(_ctx: &Ctx) -> Sampling {
        Sampling::Conservative
    }

    fn loc(&self) -> u32 {
        self.loc
    }

    fn set_loc(&mut self, loc: u32) {
        self.loc = loc;
    }

    fn wire_bytes(&self) -> u64 {
        // x and y as u16 each, then the record.
        4 + PIXEL_BYTES + self.pixel.extra_bytes()
    }

    fn extra_bytes(&self) -> u64 {
        self.pixel.extra_bytes()
    }

    fn samples(&self) -> u64 {
        self.pixel.samples()
    }

    fn arrive(&self, blocks: &mut Blocks) -> Option<AaPx> {
        self.pixel.arrive(blocks).map(|pixel| AaPx {
            loc: self.loc,
            pixel,
        })
    }

    fn merge(&mut self, incoming: &AaPx, blocks: &mut Blocks) -> bool {
        self.pixel.merge(&incoming.pixel, blocks)
    }

    fn resolve(&self) -> ([u8; 3], u32) {
        self.pixel.resolve()
    }

    fn resolved(&self) -> AaPx {
        AaPx {
            loc: self.loc,
            pixel: self.pixel.resolved(),
        }
    }
}
