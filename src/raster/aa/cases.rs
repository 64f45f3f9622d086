//! Paper 000's two screens that decide how the pool behaves: Figure 3's pair of flat polygons
//! meeting inside one pixel (the reclaim rule) and a screen on which every pixel is cut by
//! edges (what the pool can hold). `sortsim paper 000` measures its rows on them and the
//! tests check the targets on them, so both look at the same pixels.
//!
//! Owns the screen-space geometry only. Must never draw or decide a verdict.

use crate::raster::{Depth, ScreenTriangle, ScreenVertex, Sub, Viewport};

/// The raw depth of the left polygon of [`shared_edge_in_one_pixel`].
const BASE_DEPTH: u32 = 1_000_000;

/// A 4 x 4 screen covered by two tall flat rectangles meeting on x = 1.5, inside pixel
/// (1, 1) (their diagonals stay out of it): the left one `left` at a fixed raw depth
/// (primitives 0 and 1), the right one `right` and `depth_gap` raw steps behind (2 and 3).
pub fn shared_edge_in_one_pixel(
    depth_gap: u32,
    left: [u8; 3],
    right: [u8; 3],
) -> (Viewport, Vec<ScreenTriangle>) {
    let vp = Viewport::new(4, 4).expect("a 4 x 4 viewport");
    let mut tris = flat_rect([0.0, -10.0, 1.5, 14.0], BASE_DEPTH, left, 0);
    tris.extend(flat_rect(
        [1.5, -10.0, 4.0, 14.0],
        BASE_DEPTH + depth_gap,
        right,
        2,
    ));
    (vp, tris)
}

/// The rectangle `[x0, y0, x1, y1]` (pixel coordinates on the subpixel grid) as two triangles
/// `prim` and `prim + 1` at one raw depth.
pub fn flat_rect(corners: [f64; 4], z: u32, rgb: [u8; 3], prim: u32) -> Vec<ScreenTriangle> {
    let [x0, y0, x1, y1] = corners;
    let v = |x: f64, y: f64| ScreenVertex {
        x: Sub::snap(x).expect("x on the subpixel grid"),
        y: Sub::snap(y).expect("y on the subpixel grid"),
        z: Depth::from_raw(z).expect("a raw depth in range"),
        rgb,
    };
    let (a, b, c, d) = (v(x0, y0), v(x1, y0), v(x1, y1), v(x0, y1));
    [
        ScreenTriangle::new([a, b, c], prim),
        ScreenTriangle::new([a, c, d], prim + 1),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// A `side` x `side` mesh of one-pixel squares whose corners sit on pixel centres, coloured by
/// the parity of x and y, so every pixel's four quarters differ: every pixel wants a Subpixel
/// block and none can be reclaimed.
pub fn every_pixel_an_edge(side: u32) -> (Viewport, Vec<ScreenTriangle>) {
    let vp = Viewport::new(side, side).expect("a non-empty square viewport");
    let mut tris = Vec::with_capacity(2 * side as usize * side as usize);
    let v = |x: u32, y: u32, rgb: [f64; 3]| {
        ScreenVertex::from_pixels(x as f64 + 0.5, y as f64 + 0.5, 0.5, rgb)
            .expect("pixel centres are on the subpixel grid")
    };
    for y in 0..side {
        for x in 0..side {
            let rgb = [(x % 2) as f64, (y % 2) as f64, 0.5];
            let (a, b, c, d) = (
                v(x, y, rgb),
                v(x + 1, y, rgb),
                v(x + 1, y + 1, rgb),
                v(x, y + 1, rgb),
            );
            let prim = 2 * (y * side + x);
            tris.extend(ScreenTriangle::new([a, b, c], prim));
            tris.extend(ScreenTriangle::new([a, c, d], prim + 1));
        }
    }
    (vp, tris)
}
