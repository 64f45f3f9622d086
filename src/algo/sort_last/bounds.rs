//! IceT's bounding boxes for the compositing variants (`bounds=on`, with run-length images):
//! each node knows a rectangle of the screen outside which it holds nothing, so it clears and
//! keeps a frame buffer of that rectangle only, and encoding a piece scans only the piece's
//! positions inside it (the rest is one inactive run, never looked at). The rectangle starts
//! as the one around the pixels the node drew (IceT projects the bounds of the node's
//! geometry, which contain them) and, as pieces are merged in, grows to the rectangle around
//! the node's and each sender's.
//!
//! Owns the rectangles and the arithmetic of positions inside them. Must never change which
//! pixels a node holds or sends: bounds only change what is charged and allocated.

use std::cell::RefCell;

use super::pixel::ShippedPixel;
use crate::raster::{ScreenRect, Viewport};
use crate::units::Bytes;

/// Every node's rectangle and frame buffer for the frame in progress.
pub(crate) struct Bounds {
    rects: RefCell<Vec<Option<ScreenRect>>>,
    buffers: RefCell<Vec<Bytes>>,
}

impl Bounds {
    pub fn new(nodes: u32) -> Bounds {
        Bounds {
            rects: RefCell::new(vec![None; nodes as usize]),
            buffers: RefCell::new(vec![Bytes::ZERO; nodes as usize]),
        }
    }

    /// Starts `node`'s frame with the rectangle around its drawn `pixels` and a frame buffer
    /// of `buffer` bytes for it.
    pub fn start(&self, node: u32, rect: Option<ScreenRect>, buffer: Bytes) {
        self.rects.borrow_mut()[node as usize] = rect;
        self.buffers.borrow_mut()[node as usize] = buffer;
    }

    /// The rectangle outside which `node` holds nothing (`None`: it holds nothing).
    pub fn rect(&self, node: u32) -> Option<ScreenRect> {
        self.rects.borrow()[node as usize]
    }

    /// Grows `node`'s rectangle to take in a merged piece's sender's, `theirs`.
    pub fn merge(&self, node: u32, theirs: Option<ScreenRect>) {
        let mut rects = self.rects.borrow_mut();
        let mine = &mut rects[node as usize];
        *mine = match (*mine, theirs) {
            (Some(a), Some(b)) => Some(a.union(b)),
            (a, b) => a.or(b),
        };
    }

    /// The frame buffer `node` allocated for the frame in progress.
    pub fn buffer(&self, node: u32) -> Bytes {
        self.buffers.borrow()[node as usize]
    }
}

/// The rectangle around `pixels` (positions on a grid `grid` wide), `None` when there are none.
pub(super) fn around<P: ShippedPixel>(pixels: &[P], grid: Viewport) -> Option<ScreenRect> {
    let width = grid.width();
    let (first, last) = (pixels.first()?.loc(), pixels.last()?.loc());
    // Raster order: the first and last pixels give the rows; the columns need a pass.
    let (x0, x1) = pixels.iter().fold((u32::MAX, 0), |(lo, hi), p| {
        let x = p.loc() % width;
        (lo.min(x), hi.max(x + 1))
    });
    ScreenRect::new(x0, first / width, x1, last / width + 1)
}

/// Positions of the raster-order range `lo..hi` (of a grid `width` wide) inside `rect`.
pub(super) fn positions_inside(rect: ScreenRect, (lo, hi): (u32, u32), width: u32) -> u64 {
    before(rect, hi, width) - before(rect, lo, width)
}

/// Positions of `rect` before raster position `p`.
fn before(rect: ScreenRect, p: u32, width: u32) -> u64 {
    let (y, x) = (p / width, p % width);
    let full_rows = y.clamp(rect.y0(), rect.y1()) - rect.y0();
    let in_row = if (rect.y0()..rect.y1()).contains(&y) {
        x.clamp(rect.x0(), rect.x1()) - rect.x0()
    } else {
        0
    };
    u64::from(full_rows) * u64::from(rect.width()) + u64::from(in_row)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Counting by rows equals looking at every position of the range.
        #[test]
        fn positions_inside_match_a_walk(
            (width, height) in (1u32..20, 1u32..20),
            corners in (0u32..20, 0u32..20, 0u32..20, 0u32..20),
            ends in (0u32..400, 0u32..400),
        ) {
            let span = |a: u32, b: u32, side: u32| ((a % side).min(b % side), (a % side).max(b % side) + 1);
            let (x0, x1) = span(corners.0, corners.1, width);
            let (y0, y1) = span(corners.2, corners.3, height);
            let rect = ScreenRect::new(x0, y0, x1, y1).unwrap();
            let area = width * height;
            let (a, b) = (ends.0 % (area + 1), ends.1 % (area + 1));
            let (lo, hi) = (a.min(b), a.max(b));
            let walked = (lo..hi).filter(|&p| rect.contains(p % width, p / width)).count();
            prop_assert_eq!(positions_inside(rect, (lo, hi), width), walked as u64);
        }
    }
}
