//! The screen cut into regions: a grid of `cols x rows` rectangles, as square as the count
//! allows (square regions give the smallest overlap factor, paper 002), and the regions a
//! screen triangle's bounding box touches.
//!
//! Owns region geometry only. Must never decide which processor owns a region.

use crate::raster::{ScreenRect, ScreenTriangle, Sub, Viewport};

/// A grid of regions over the viewport, indexed row-major (`r = row * cols + col`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RegionGrid {
    viewport: Viewport,
    cols: u32,
    rows: u32,
    /// Whether triangles touch regions by the pixel squares their bounds overlap (when
    /// samples lie anywhere in a pixel: anti-aliasing), not only by pixel centres.
    by_area: bool,
}

impl RegionGrid {
    /// Regions of `size x size` pixels (the last row and column may be smaller), as paper
    /// 000's renderer uses with 64.
    pub fn of_size(viewport: Viewport, size: u32) -> RegionGrid {
        let size = size.max(1);
        RegionGrid {
            viewport,
            cols: viewport.width().div_ceil(size),
            rows: viewport.height().div_ceil(size),
            by_area: false,
        }
    }

    /// The same grid, with triangles touching every region whose pixels their bounds
    /// overlap: needed when a pixel is sampled away from its centre (anti-aliasing), where
    /// a triangle can cover samples of a pixel whose centre its bounds miss.
    pub fn sampling_whole_pixels(self) -> RegionGrid {
        RegionGrid {
            by_area: true,
            ..self
        }
    }

    /// Exactly `count` regions: the factorization `cols x rows = count` whose regions are
    /// closest to square, never more columns than pixels across nor rows than pixels down.
    pub fn with_count(viewport: Viewport, count: u32) -> Option<RegionGrid> {
        let (w, h) = (viewport.width(), viewport.height());
        // A grid has at most as many columns as the screen has pixels across.
        (1..=count.min(w))
            .filter(|c| count % c == 0 && count / c <= h)
            .map(|cols| (cols, count / cols))
            .min_by(|&(c1, r1), &(c2, r2)| {
                let skew =
                    |c: u32, r: u32| ((w as f64 / c as f64) / (h as f64 / r as f64)).ln().abs();
                skew(c1, r1).total_cmp(&skew(c2, r2)).then(c1.cmp(&c2))
            })
            .map(|(cols, rows)| RegionGrid {
                viewport,
                cols,
                rows,
                by_area: false,
            })
    }

    pub fn count(&self) -> u32 {
        self.cols * self.rows
    }

    pub fn cols(&self) -> u32 {
        self.cols
    }

    pub fn rows(&self) -> u32 {
        self.rows
    }

    /// The pixels of region `r`.
    pub fn rect(&self, r: u32) -> ScreenRect {
        let (col, row) = (r % self.cols, r / self.cols);
        let x = |c: u32| (c as u64 * self.viewport.width() as u64 / self.cols as u64) as u32;
        let y = |r: u32| (r as u64 * self.viewport.height() as u64 / self.rows as u64) as u32;
        ScreenRect::new(x(col), y(row), x(col + 1), y(row + 1)).expect("grid cells are non-empty")
    }

    /// Appends the regions that `tri`'s pixel bounding box touches, in index order.
    pub fn touched_by(&self, tri: &ScreenTriangle, out: &mut Vec<u32>) {
        let bounds = if self.by_area {
            area_bounds(tri, self.viewport)
        } else {
            pixel_bounds(tri, self.viewport)
        };
        let Some((x0, y0, x1, y1)) = bounds else {
            return;
        };
        // Region c starts at floor(c * W / cols); pixel x lies in the last region starting at
        // or before it, c = floor(((x + 1) * cols - 1) / W).
        let col = |x: u32| {
            (((x as u64 + 1) * self.cols as u64 - 1) / self.viewport.width() as u64) as u32
        };
        let row = |y: u32| {
            (((y as u64 + 1) * self.rows as u64 - 1) / self.viewport.height() as u64) as u32
        };
        for r in row(y0)..=row(y1) {
            for c in col(x0)..=col(x1) {
                out.push(r * self.cols + c);
            }
        }
    }
}

/// The pixels whose centres lie in `tri`'s bounding box, clamped to the viewport:
/// (x0, y0, x1, y1) inclusive, or `None` when no pixel centre is inside the box.
pub fn pixel_bounds(tri: &ScreenTriangle, viewport: Viewport) -> Option<(u32, u32, u32, u32)> {
    bounds(
        tri,
        viewport,
        Sub::first_centre_at_or_after,
        Sub::last_centre_at_or_before,
    )
}

/// The pixels whose squares `tri`'s bounding box overlaps, clamped to the viewport: every
/// pixel with a sample the triangle can cover, wherever in the pixel its samples lie.
pub fn area_bounds(tri: &ScreenTriangle, viewport: Viewport) -> Option<(u32, u32, u32, u32)> {
    bounds(tri, viewport, Sub::pixel, Sub::pixel)
}

/// The pixel rectangle from `first` of the bounding box's low corner to `last` of its high
/// one, clamped to the viewport; `None` when empty.
fn bounds(
    tri: &ScreenTriangle,
    viewport: Viewport,
    first: fn(Sub) -> i64,
    last: fn(Sub) -> i64,
) -> Option<(u32, u32, u32, u32)> {
    let v = tri.vertices();
    let xs = v.iter().map(|p| p.x);
    let ys = v.iter().map(|p| p.y);
    let (min_x, max_x) = (xs.clone().min()?, xs.max()?);
    let (min_y, max_y) = (ys.clone().min()?, ys.max()?);
    let x0 = first(min_x).max(0);
    let y0 = first(min_y).max(0);
    let x1 = last(max_x).min(viewport.width() as i64 - 1);
    let y1 = last(max_y).min(viewport.height() as i64 - 1);
    (x0 <= x1 && y0 <= y1).then_some((x0 as u32, y0 as u32, x1 as u32, y1 as u32))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_pixel_maps_to_the_region_whose_rectangle_holds_it() {
        for (w, h, count) in [(512, 512, 24), (640, 512, 4096), (7, 5, 6), (640, 512, 40)] {
            let grid = RegionGrid::with_count(Viewport::new(w, h).unwrap(), count).unwrap();
            assert_eq!(grid.count(), count);
            let col = |x: u32| (((x as u64 + 1) * grid.cols() as u64 - 1) / w as u64) as u32;
            let row = |y: u32| (((y as u64 + 1) * grid.rows() as u64 - 1) / h as u64) as u32;
            for y in 0..h {
                for x in 0..w {
                    let r = row(y) * grid.cols() + col(x);
                    assert!(
                        grid.rect(r).contains(x, y),
                        "{w}x{h}/{count}: ({x},{y}) -> {r}"
                    );
                }
            }
        }
    }

    #[test]
    fn region_counts_are_as_square_as_possible() {
        let vp = Viewport::new(640, 512).unwrap();
        let g = RegionGrid::with_count(vp, 8 * 512).unwrap();
        assert_eq!((g.cols(), g.rows()), (64, 64));
        let g = RegionGrid::with_count(vp, 8 * 3).unwrap();
        assert_eq!((g.cols(), g.rows()), (6, 4));
        assert_eq!(
            RegionGrid::of_size(Viewport::new(512, 512).unwrap(), 64).count(),
            64
        );
        assert_eq!(
            RegionGrid::with_count(Viewport::new(4, 4).unwrap(), 17),
            None
        );
    }
}
