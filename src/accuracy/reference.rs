//! The supersampled reference image: a frame rasterized at `scale x scale` samples per pixel
//! (a regular grid of sample centres, `(i + 0.5) / scale` across each pixel) and box
//! filtered, the ground truth every anti-aliasing mode is measured against.
//!
//! How: the frame is drawn by the ordinary rasterizer on a virtual image `scale` times larger
//! in each dimension, whose pixel centres are exactly the sample centres. That image is never
//! held whole: it is cut into horizontal bands (whole pixel rows of the final image, about
//! 256 sample rows at a time, and, when wider than the rasterizer's largest viewport, into columns too). Each
//! piece is a viewport of its own, reached by a clip-space affine map of the geometry
//! ("scale the geometry", [`tile_clip_map`]), so every snapped coordinate stays inside the
//! rasterizer's guard band and fixed-point range whatever the scale and resolution. Host
//! memory is one piece's colour and depth buffer (at most `BAND_SAMPLE_ROWS` rows of
//! `MAX_VIEWPORT` samples, 11 bytes each) plus a copy of the frame's vertices and, per band,
//! the list of triangles whose rows reach it (so each band sets up only those).
//!
//! The geometry snaps to 1/256 of a *sample* spacing, finer than the 1/256 pixel of a normal
//! render; the reference is the more exact of the two.
//!
//! Must never charge simulated time, read a clock, or change the rasterizer: it only calls
//! its public entry points.

use glam::Vec4;

use crate::algo::reference::raster_options;
use crate::raster::screen::MAX_VIEWPORT;
use crate::raster::{draw_subset, Framebuffer, Vertex, VertexCache, Viewport};
use crate::scene::FrameGeometry;

/// Sample rows per band, rounded down to whole output rows (at least one): at scale 16, 16
/// output rows, about 23 MB of buffers for a 512-pixel-wide frame.
pub const BAND_SAMPLE_ROWS: u32 = 256;

/// The largest supported scale (samples per pixel side).
pub const MAX_SCALE: u32 = 64;

/// A box-filtered supersampled image: per pixel, the sum of its samples' 8-bit channels.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Reference {
    width: u32,
    height: u32,
    scale: u32,
    sums: Vec<[u32; 3]>,
}

#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ReferenceError {
    #[error("reference scale {0} is out of range (valid: 1..={MAX_SCALE})")]
    Scale(u32),
}

/// A rectangle of the virtual `scale`-times image, in its pixels: `[x0, x1) x [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Tile {
    x0: u32,
    y0: u32,
    x1: u32,
    y1: u32,
}

impl Reference {
    pub fn width(&self) -> u32 {
        self.width
    }
    pub fn height(&self) -> u32 {
        self.height
    }
    /// Samples per pixel side.
    pub fn scale(&self) -> u32 {
        self.scale
    }
    pub fn samples_per_pixel(&self) -> u32 {
        self.scale * self.scale
    }

    /// Mean channel levels (0..=255) of every pixel, row-major.
    pub fn levels(&self) -> Vec<[f64; 3]> {
        let n = f64::from(self.samples_per_pixel());
        self.sums
            .iter()
            .map(|s| s.map(|c| f64::from(c) / n))
            .collect()
    }

    /// The image rounded to 8 bits per channel (halves up), for a PNG.
    pub fn to_framebuffer(&self) -> Framebuffer {
        let vp = Viewport::new(self.width, self.height).expect("the frame's own size");
        let mut fb = Framebuffer::new(vp);
        let n = self.samples_per_pixel();
        let depth = vec![0u32; self.width as usize];
        for y in 0..self.height {
            let row = &self.sums[(y * self.width) as usize..((y + 1) * self.width) as usize];
            let rgb: Vec<[u8; 3]> = row
                .iter()
                .map(|s| s.map(|c| ((c + n / 2) / n).min(255) as u8))
                .collect();
            fb.set_row(y, &rgb, &depth);
        }
        fb
    }
}

/// Renders `frame` at `scale x scale` samples per pixel, box filtered.
pub fn render_reference(frame: &FrameGeometry, scale: u32) -> Result<Reference, ReferenceError> {
    if !(1..=MAX_SCALE).contains(&scale) {
        return Err(ReferenceError::Scale(scale));
    }
    let (width, height) = (frame.width, frame.height);
    let mut out = Reference {
        width,
        height,
        scale,
        sums: vec![[0; 3]; width as usize * height as usize],
    };
    let mut vertices = frame.vertices.clone();
    let band = band_rows(scale);
    let subsets = band_subsets(frame, band);
    for tile in tiles(width, height, scale) {
        let subset = &subsets[(tile.y0 / (band * scale)) as usize];
        let fb = draw_tile(frame, &mut vertices, subset, tile, scale);
        accumulate(&mut out, &fb, tile);
    }
    Ok(out)
}

/// Output rows per band: about `BAND_SAMPLE_ROWS` sample rows, at least one output row.
fn band_rows(scale: u32) -> u32 {
    (BAND_SAMPLE_ROWS / scale).max(1)
}

/// For each band of `band` output rows, the triangles (in scene order) whose projected
/// vertices' rows reach it, with a pixel of margin. A triangle with a vertex at or behind
/// the eye (w <= 0), not finite or missing goes to every band: its projected extent is not
/// its vertices' (the rasterizer culls what is invalid). Only a cost saving: a triangle left out would have drawn nothing in the band.
fn band_subsets(frame: &FrameGeometry, band: u32) -> Vec<Vec<u32>> {
    let bands = frame.height.div_ceil(band) as usize;
    let mut out = vec![Vec::new(); bands];
    let row = |v: &Vertex| {
        let (y, w) = (f64::from(v.clip.y), f64::from(v.clip.w));
        (w > 0.0 && (y / w).is_finite()).then(|| (1.0 - y / w) * 0.5 * f64::from(frame.height))
    };
    for (i, tri) in frame.triangles.iter().enumerate() {
        let rows: Option<Vec<f64>> = tri
            .iter()
            .map(|&k| frame.vertices.get(k as usize).and_then(row))
            .collect();
        let range = match rows {
            Some(r) => {
                let lo = r.iter().copied().fold(f64::INFINITY, f64::min) - 1.0;
                let hi = r.iter().copied().fold(f64::NEG_INFINITY, f64::max) + 1.0;
                let last = bands as f64 - 1.0;
                let first_band = (lo / f64::from(band)).floor().max(0.0);
                let last_band = (hi / f64::from(band)).floor().min(last);
                first_band as usize..=last_band as usize
            }
            None => 0..=bands - 1,
        };
        for subset in out.get_mut(range).into_iter().flatten() {
            subset.push(i as u32);
        }
    }
    out
}

/// Pieces of the virtual image, band by band, top to bottom and left to right. Every piece
/// is whole pixels of the output and at most `MAX_VIEWPORT` samples on a side.
fn tiles(width: u32, height: u32, scale: u32) -> Vec<Tile> {
    let (big_w, big_h) = (width * scale, height * scale);
    let band = band_rows(scale) * scale;
    let column = (MAX_VIEWPORT / scale) * scale;
    let mut out = Vec::new();
    for y0 in (0..big_h).step_by(band as usize) {
        for x0 in (0..big_w).step_by(column as usize) {
            out.push(Tile {
                x0,
                y0,
                x1: (x0 + column).min(big_w),
                y1: (y0 + band).min(big_h),
            });
        }
    }
    out
}

/// Draws the piece `tile` of the virtual image into a framebuffer of its own size.
fn draw_tile(
    frame: &FrameGeometry,
    scratch: &mut [Vertex],
    subset: &[u32],
    tile: Tile,
    scale: u32,
) -> Framebuffer {
    let vp = Viewport::new(tile.x1 - tile.x0, tile.y1 - tile.y0).expect("tiles are small");
    let map = tile_clip_map(frame.width * scale, frame.height * scale, tile);
    for (dst, src) in scratch.iter_mut().zip(&frame.vertices) {
        dst.clip = map.apply(src.clip);
    }
    let mut fb = Framebuffer::with_clear(vp, frame.background);
    draw_subset(
        scratch,
        &frame.triangles,
        subset,
        &mut VertexCache::new(scratch.len(), vp),
        &raster_options(frame),
        &mut fb,
    );
    fb
}

/// A clip-space affine map `x' = ax * x + bx * w`, `y' = ay * y + by * w` (z, w unchanged).
#[derive(Clone, Copy, Debug, PartialEq)]
struct ClipMap {
    ax: f64,
    bx: f64,
    ay: f64,
    by: f64,
}

impl ClipMap {
    fn apply(&self, p: Vec4) -> Vec4 {
        let (x, y, w) = (f64::from(p.x), f64::from(p.y), f64::from(p.w));
        Vec4::new(
            (self.ax * x + self.bx * w) as f32,
            (self.ay * y + self.by * w) as f32,
            p.z,
            p.w,
        )
    }
}

/// The map that makes a `big_w x big_h` viewport's piece `tile` fill a viewport of the
/// tile's size: the rasterizer puts NDC x at `(x/w + 1) / 2 * W` and y at
/// `(1 - y/w) / 2 * H`, so shifting by the tile's origin and rescaling is affine in (x, w)
/// and (y, w), and projective-correct: depth and colour are untouched.
fn tile_clip_map(big_w: u32, big_h: u32, tile: Tile) -> ClipMap {
    let (tw, th) = (f64::from(tile.x1 - tile.x0), f64::from(tile.y1 - tile.y0));
    let (sx, sy) = (f64::from(big_w) / tw, f64::from(big_h) / th);
    ClipMap {
        ax: sx,
        bx: sx - 2.0 * f64::from(tile.x0) / tw - 1.0,
        ay: sy,
        by: 1.0 - sy + 2.0 * f64::from(tile.y0) / th,
    }
}

/// Adds every sample of `fb` (the piece `tile`) to its output pixel's sums.
fn accumulate(out: &mut Reference, fb: &Framebuffer, tile: Tile) {
    let s = out.scale;
    let tw = (tile.x1 - tile.x0) as usize;
    for (row, sy) in (tile.y0..tile.y1).enumerate() {
        let colours = &fb.colors()[row * tw..(row + 1) * tw];
        let py = (sy / s) as usize;
        for (col, c) in colours.iter().enumerate() {
            let px = ((tile.x0 as usize) + col) / s as usize;
            let sum = &mut out.sums[py * out.width as usize + px];
            for k in 0..3 {
                sum[k] += u32::from(c[k]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_virtual_image_once_in_whole_pixels() {
        for (w, h, s) in [(64, 64, 16), (1536, 20, 16), (7, 5, 3), (1024, 17, 16)] {
            let mut count = vec![0u8; (w * s * h * s) as usize];
            for t in tiles(w, h, s) {
                assert!(t.x1 - t.x0 <= MAX_VIEWPORT && t.y1 - t.y0 <= MAX_VIEWPORT);
                assert!(t.x0 % s == 0 && t.y0 % s == 0 && t.x1 % s == 0 && t.y1 % s == 0);
                for y in t.y0..t.y1 {
                    for x in t.x0..t.x1 {
                        count[(y * w * s + x) as usize] += 1;
                    }
                }
            }
            assert!(count.iter().all(|&c| c == 1), "{w}x{h} at {s}");
        }
    }

    #[test]
    fn the_clip_map_sends_tile_corners_to_ndc_corners() {
        let tile = Tile {
            x0: 256,
            y0: 512,
            x1: 512,
            y1: 768,
        };
        let m = tile_clip_map(1024, 1024, tile);
        // NDC of the big image's pixel (256, 512): x = 256/512 - 1 = -0.5, y = 1 - 512/512 = 0.
        let p = m.apply(Vec4::new(-0.5, 0.0, 0.3, 1.0));
        assert!((p.x + 1.0).abs() < 1e-6 && (p.y - 1.0).abs() < 1e-6, "{p}");
        // ... and (512, 768) to the tile's bottom-right corner, at any w.
        let p = m.apply(Vec4::new(0.0, -0.5, 0.3, 1.0) * 2.0);
        assert!((p.x / p.w - 1.0).abs() < 1e-6 && (p.y / p.w + 1.0).abs() < 1e-6);
        assert_eq!(p.z, 0.6);
    }

    #[test]
    fn band_subsets_keep_every_triangle_that_can_reach_a_band() {
        let v = |y: f32, w: f32| Vertex {
            clip: Vec4::new(0.0, y, 0.5, w),
            color: glam::Vec3::ONE,
        };
        // Rows: NDC y = 1 - 2 * row / 64. Vertex 0..3 span rows 2..6; vertex 3 is behind the
        // eye; vertex 4 sits on row 33, in band 2; triangle 3 has a missing vertex.
        let frame = FrameGeometry {
            width: 64,
            height: 64,
            vertices: vec![
                v(1.0 - 4.0 / 64.0, 1.0),
                v(1.0 - 12.0 / 64.0, 1.0),
                v(1.0 - 8.0 / 64.0, 1.0),
                v(0.0, -1.0),
                v(1.0 - 66.0 / 64.0, 1.0),
            ],
            triangles: vec![[0, 1, 2], [0, 1, 3], [0, 4, 2], [0, 1, 99]],
            cull_backfaces: false,
            background: [0; 3],
        };
        let subsets = band_subsets(&frame, 16);
        assert_eq!(
            subsets,
            vec![vec![0, 1, 2, 3], vec![1, 2, 3], vec![1, 2, 3], vec![1, 3]]
        );
    }

    #[test]
    fn scale_out_of_range_is_an_error() {
        let frame = FrameGeometry {
            width: 4,
            height: 4,
            vertices: vec![],
            triangles: vec![],
            cull_backfaces: false,
            background: [1, 2, 3],
        };
        assert_eq!(
            render_reference(&frame, 0).unwrap_err(),
            ReferenceError::Scale(0)
        );
        let r = render_reference(&frame, 2).unwrap();
        assert!(r.levels().iter().all(|l| *l == [1.0, 2.0, 3.0]));
    }
}
