//! Anti-aliasing targets (paper 000's adaptive supersampling, and plain supersampling as the
//! reference it saves memory against), with the record sizes that simulated memory is
//! charged in.
//!
//! * `cases`: paper 000's screens that decide the pool's behaviour (a shared edge inside one
//!   pixel, every pixel an edge), shared by `sortsim paper 000` and the tests;
//! * `masks`: the precomputed bitmask table (edge entry/exit -> n x n coverage);
//! * `adaptive`: [`AdaptiveTarget`], 12-byte Pixels plus a fixed pool of 7-byte Subpixel
//!   cells for edge pixels only, memory adaptation and reclaiming;
//! * `merge`: an adaptive pixel shipped to another buffer and merged there sample by
//!   sample (sort-last), with the receiver's pool;
//! * `supersample`: [`SupersampleTarget`], every pixel k x k samples.
//!
//! Both targets ask the scan step for conservative spans and resolve with a box filter into
//! a [`RegionSet`](crate::raster::RegionSet) (the image an algorithm ships and shows).
//!
//! Must never read a clock or know about nodes, and never allocate beyond its pool: a full
//! pool means "sample once and count it", not "grow".

pub mod adaptive;
pub mod cases;
pub mod masks;
pub mod merge;
pub mod supersample;

pub use adaptive::{adapt, AdaptiveConfig, AdaptiveTarget, RECLAIM_SPREAD};
pub use masks::Grid;
pub use merge::{AaPixel, Blocks, Sample};
pub use supersample::{
    downsample, for_each_sample, sample_positions, SupersampleTarget, MAX_SUPERSAMPLE_SIDE,
};

use crate::raster::fixed::{Depth, DEPTH_FRAC};
use crate::raster::setup::RasterTriangle;
use crate::units::Bytes;

/// Paper 000's `Pixel`: rgb (3), SuperPixel flag (1), z or Subpixel pointer (4), dxz (2),
/// dyz (2).
pub const PIXEL_BYTES: u64 = 3 + 1 + 4 + 2 + 2;
/// Paper 000's `Subpixel`: rgb (3), z (4). A traditional supersampling buffer stores one
/// per sample too.
pub const SUBPIXEL_BYTES: u64 = 3 + 4;

/// Which anti-aliasing an algorithm's rasterizers use (`--set aa=...`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AaMethod {
    /// Point sampling at pixel centres (the ordinary targets).
    None,
    /// Paper 000's adaptive supersampling.
    Adaptive,
    /// Every pixel `side x side` samples (paper 002 uses 16 = 4x4).
    Supersample { side: u32 },
}

impl AaMethod {
    /// The values `--set aa=` accepts, for messages.
    pub const VALID: &'static str =
        "none, adaptive, or supersample:N with N a perfect square from 4 to 256 (e.g. supersample:16)";

    /// The option value naming this method.
    pub fn name(self) -> String {
        match self {
            AaMethod::None => "none".into(),
            AaMethod::Adaptive => "adaptive".into(),
            AaMethod::Supersample { side } => format!("supersample:{}", side * side),
        }
    }

    /// Parses `none`, `adaptive` or `supersample:N`; `None` for anything else (see
    /// [`AaMethod::VALID`]).
    pub fn parse(s: &str) -> Option<AaMethod> {
        match s {
            "none" => Some(AaMethod::None),
            "adaptive" => Some(AaMethod::Adaptive),
            _ => {
                let n: u32 = s.strip_prefix("supersample:")?.parse().ok()?;
                (2..=MAX_SUPERSAMPLE_SIDE)
                    .find(|k| k * k == n)
                    .map(|side| AaMethod::Supersample { side })
            }
        }
    }
}

/// What an anti-aliasing target did in one frame (one node's target).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct AaStats {
    /// Samples per side used this frame (n of n x n; 1 when anti-aliasing is off).
    pub grid_side: u32,
    /// Pixels of the target.
    pub pixels: u64,
    /// Pixels turned into super pixels (a Subpixel block allocated), counting a pixel again
    /// if it was reclaimed and later supersampled again. For supersampling: every pixel.
    pub supersampled_pixels: u64,
    /// Super pixels whose cells went back to the free list.
    pub reclaimed_pixels: u64,
    /// Edge pixels sampled once because the pool was exhausted (each pixel counted once).
    pub overflowed_pixels: u64,
    /// Super pixels at the end of the frame (after reclaiming).
    pub live_super_pixels: u64,
    /// Most Subpixel cells in use at any moment of the frame.
    pub peak_cells: u64,
    /// Subpixel cells in use at the end of the frame.
    pub live_cells: u64,
    /// Subpixel cells the pool holds (its bytes / [`SUBPIXEL_BYTES`]).
    pub pool_cells: u64,
}

impl AaStats {
    /// Paper 000's memory figure: the Pixel array plus the Subpixel cells in use at the end
    /// of the frame (for supersampling: every sample).
    pub fn memory_used(&self) -> Bytes {
        Bytes::new(self.pixels * PIXEL_BYTES + self.live_cells * SUBPIXEL_BYTES)
    }

    /// The Pixel array plus the most cells in use at once.
    pub fn memory_peak(&self) -> Bytes {
        Bytes::new(self.pixels * PIXEL_BYTES + self.peak_cells * SUBPIXEL_BYTES)
    }

    /// Edge pixels this frame wanted blocks for beyond those it reused: what memory
    /// adaptation sizes the next frame by.
    pub fn demand_pixels(&self) -> u64 {
        self.peak_cells / u64::from(self.grid_side.max(1).pow(2)) + self.overflowed_pixels
    }
}

/// A triangle's depth gradient per pixel in 1/256 depth units (paper 000's dxz, dyz; the
/// paper stores them in 2 bytes each, which only the modelled memory follows).
pub(crate) fn slopes(tri: &RasterTriangle) -> [i64; 2] {
    let shift = DEPTH_FRAC - 8;
    let cap = |g: i128| (g >> shift).clamp(-(1 << 60), 1 << 60) as i64;
    [cap(tri.depth.step_x()), cap(tri.depth.step_y())]
}

/// Depth at an offset `(ox, oy)` (in 1/`denom` pixel) from a pixel centre of depth `fine`
/// (in 1/256 depth units, rounding half included, as [`fine`] and the depth planes give
/// it), from the per-pixel gradients: how a Subpixel's z is derived. Clamped to the depths
/// a fragment may have.
pub(crate) fn sample_depth(fine: i64, slope: [i64; 2], ox: i64, oy: i64, denom: i64) -> u32 {
    let d = i128::from(denom);
    let num = i128::from(fine) * d
        + i128::from(slope[0]) * i128::from(ox)
        + i128::from(slope[1]) * i128::from(oy);
    num.div_euclid(256 * d)
        .clamp(0, i128::from(Depth::FAR.raw())) as u32
}

/// A stored depth in the 1/256 units [`sample_depth`] starts from (with the half that makes
/// its floor round to nearest).
pub(crate) fn fine(z: u32) -> i64 {
    i64::from(z) * 256 + 128
}

/// Box filter: the rounded mean of the samples' colours.
pub(crate) fn box_filter(colors: &[[u8; 3]]) -> [u8; 3] {
    let n = colors.len().max(1) as u32;
    let mut sum = [0u32; 3];
    for c in colors {
        for ch in 0..3 {
            sum[ch] += u32::from(c[ch]);
        }
    }
    sum.map(|s| ((s + n / 2) / n) as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn record_sizes_are_the_papers() {
        // Paper 000, section 3: Pixel 12 bytes, Subpixel 7 bytes.
        assert_eq!(PIXEL_BYTES, 12);
        assert_eq!(SUBPIXEL_BYTES, 7);
    }

    #[test]
    fn methods_parse_and_bad_ones_are_refused() {
        assert_eq!(AaMethod::parse("none"), Some(AaMethod::None));
        assert_eq!(AaMethod::parse("adaptive"), Some(AaMethod::Adaptive));
        assert_eq!(
            AaMethod::parse("supersample:16"),
            Some(AaMethod::Supersample { side: 4 })
        );
        assert_eq!(
            AaMethod::parse("supersample:256"),
            Some(AaMethod::Supersample { side: 16 })
        );
        for bad in [
            "supersample:15",
            "supersample:1",
            "supersample:1024",
            "fxaa",
            "",
        ] {
            assert_eq!(AaMethod::parse(bad), None, "{bad}");
        }
        assert!(AaMethod::VALID.contains("perfect square"));
    }

    #[test]
    fn box_filter_rounds_the_mean() {
        assert_eq!(box_filter(&[[0, 0, 0], [255, 255, 1]]), [128, 128, 1]);
        assert_eq!(box_filter(&[[10, 20, 30]; 16]), [10, 20, 30]);
    }
}
