//! The screen's coordinate space as validated types: the viewport and pixel rectangles.
//!
//! Pixel `(x, y)` is column `x` from the left and row `y` from the top of the viewport; it
//! covers `[x, x+1) x [y, y+1)` and is sampled at its centre. Every target, region and span
//! speaks these coordinates.
//!
//! Must never hold pixels or know about triangles.

/// Largest viewport side in pixels. With the guard band (2^20 px from the centre) this
/// bounds every snapped coordinate below `fixed::MAX_COORD_PX`.
pub const MAX_VIEWPORT: u32 = 16384;

/// A viewport of `width x height` pixels, each side in `1..=MAX_VIEWPORT`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Viewport {
    width: u32,
    height: u32,
}

impl Viewport {
    pub fn new(width: u32, height: u32) -> Option<Viewport> {
        let ok = |s: u32| (1..=MAX_VIEWPORT).contains(&s);
        (ok(width) && ok(height)).then_some(Viewport { width, height })
    }
    pub fn width(self) -> u32 {
        self.width
    }
    pub fn height(self) -> u32 {
        self.height
    }
    pub fn pixels(self) -> usize {
        self.width as usize * self.height as usize
    }
    /// The whole viewport as a rectangle.
    pub fn rect(self) -> ScreenRect {
        ScreenRect {
            x0: 0,
            y0: 0,
            x1: self.width,
            y1: self.height,
        }
    }
}

/// A non-empty half-open pixel rectangle `[x0, x1) x [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ScreenRect {
    x0: u32,
    y0: u32,
    x1: u32,
    y1: u32,
}

impl ScreenRect {
    /// `None` when empty (`x0 >= x1` or `y0 >= y1`).
    pub fn new(x0: u32, y0: u32, x1: u32, y1: u32) -> Option<ScreenRect> {
        (x0 < x1 && y0 < y1).then_some(ScreenRect { x0, y0, x1, y1 })
    }
    pub fn x0(self) -> u32 {
        self.x0
    }
    pub fn y0(self) -> u32 {
        self.y0
    }
    pub fn x1(self) -> u32 {
        self.x1
    }
    pub fn y1(self) -> u32 {
        self.y1
    }
    pub fn width(self) -> u32 {
        self.x1 - self.x0
    }
    pub fn height(self) -> u32 {
        self.y1 - self.y0
    }
    pub fn pixels(self) -> usize {
        self.width() as usize * self.height() as usize
    }
    pub fn contains(self, x: u32, y: u32) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }
    pub fn intersect(self, other: ScreenRect) -> Option<ScreenRect> {
        ScreenRect::new(
            self.x0.max(other.x0),
            self.y0.max(other.y0),
            self.x1.min(other.x1),
            self.y1.min(other.y1),
        )
    }
    /// The smallest rectangle holding both.
    pub fn union(self, other: ScreenRect) -> ScreenRect {
        ScreenRect {
            x0: self.x0.min(other.x0),
            y0: self.y0.min(other.y0),
            x1: self.x1.max(other.x1),
            y1: self.y1.max(other.y1),
        }
    }
    pub fn overlaps(self, other: ScreenRect) -> bool {
        self.intersect(other).is_some()
    }
    /// True when this rectangle lies inside the viewport.
    pub fn within(self, viewport: Viewport) -> bool {
        self.x1 <= viewport.width() && self.y1 <= viewport.height()
    }
}
