//! The target one sort-middle processor rasterizes its regions into, under the run's
//! anti-aliasing setting (`--set aa=none|adaptive|supersample:N`), with the memory it is
//! charged for and the resolve that turns it into the regional image the root collects.
//!
//! Must never decide which regions a processor owns or when it rasterizes: it is handed the
//! rectangles and returns the image, the counts to charge and the frame's statistics.

use crate::engine::{Node, SimError};
use crate::raster::aa::{AaMethod, AaStats, AdaptiveConfig, AdaptiveTarget, Grid};
use crate::raster::aa::{SupersampleTarget, PIXEL_BYTES};
use crate::raster::{Counters, RegionSet, ScreenRect, Target, Viewport, BYTES_PER_PIXEL};
use crate::units::Bytes;

use super::Msg;
use crate::algo::aa::AaSettings;

/// One frame's target on one processor.
pub(crate) enum Canvas {
    Plain(RegionSet),
    Adaptive(AdaptiveTarget),
    Supersample(SupersampleTarget),
}

/// Memory a canvas holds, by the tag the node's pool records it under.
pub(crate) type Charges = Vec<(&'static str, Bytes)>;

impl Canvas {
    /// The canvas for `rects` with this frame's resolution `grid` (adaptive only).
    pub(crate) fn new(
        node: &Node<Msg>,
        aa: &AaSettings,
        grid: Grid,
        viewport: Viewport,
        rects: Vec<ScreenRect>,
        clear: [u8; 3],
    ) -> Result<Canvas, SimError> {
        let pixels: u64 = rects.iter().map(|r| r.pixels() as u64).sum();
        let canvas = match aa.method {
            AaMethod::None => RegionSet::with_clear(viewport, rects, clear).map(Canvas::Plain),
            AaMethod::Adaptive => {
                let config = AdaptiveConfig {
                    pool: aa.pool.unwrap_or(AdaptiveConfig::default_pool(pixels)),
                    grid,
                    reclaim_spread: aa.reclaim.then_some(crate::raster::aa::RECLAIM_SPREAD),
                };
                AdaptiveTarget::new(viewport, rects, config, clear).map(Canvas::Adaptive)
            }
            AaMethod::Supersample { side } => {
                SupersampleTarget::new(viewport, rects, side, clear).map(Canvas::Supersample)
            }
        };
        canvas.map_err(|e| node.error(e.to_string()))
    }

    /// What this canvas occupies in the node's memory, by tag.
    pub(crate) fn charges(&self) -> Charges {
        match self {
            Canvas::Plain(r) => vec![("framebuffer", Bytes::new(pixels(r) * BYTES_PER_PIXEL))],
            Canvas::Adaptive(t) => vec![
                ("pixel array", Bytes::new(t.pixels() * PIXEL_BYTES)),
                ("subpixel pool", t.config().pool),
            ],
            Canvas::Supersample(t) => vec![("sample buffer", t.bytes())],
        }
    }

    /// Samples to clear before drawing (the pool needs none: its free list is reset).
    pub(crate) fn clear_count(&self) -> u64 {
        match self {
            Canvas::Plain(r) => pixels(r),
            Canvas::Adaptive(t) => t.pixels(),
            Canvas::Supersample(t) => t.samples(),
        }
    }

    pub(crate) fn target(&mut self) -> &mut dyn Target {
        match self {
            Canvas::Plain(r) => r,
            Canvas::Adaptive(t) => t,
            Canvas::Supersample(t) => t,
        }
    }

    /// The regional image (box-filtered when anti-aliased), the resolve's counts, and the
    /// frame's anti-aliasing statistics (`None` without anti-aliasing).
    pub(crate) fn finish(self) -> (RegionSet, Counters, Option<AaStats>) {
        let mut c = Counters::default();
        match self {
            Canvas::Plain(r) => (r, c, None),
            Canvas::Adaptive(t) => {
                let image = t.resolve(&mut c);
                (image, c, Some(t.stats()))
            }
            Canvas::Supersample(t) => {
                let image = t.resolve(&mut c);
                (image, c, Some(t.stats()))
            }
        }
    }
}

fn pixels(r: &RegionSet) -> u64 {
    r.regions().iter().map(|b| b.rect().pixels() as u64).sum()
}
