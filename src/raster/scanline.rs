//! The scanline z-buffer renderer (Watkins-style, as paper 001's SLMF pipeline uses it):
//! bucket-sort triangles by their first scanline, keep an active list, and for each
//! scanline depth-test the active triangles' spans into a one-scanline buffer.
//!
//! Must never evaluate coverage, depth or colour itself: it walks the same row states and
//! fragments as the z-buffer path, and keeps the active list in drawing order so depth ties
//! resolve the same way, which makes its image bit-identical to the z-buffer's. Only its
//! cost profile differs (bucket inserts, active-list operations, scanlines). Triangles are
//! set up when they become active, so host memory follows the active list, not the scene.

use super::counters::Counters;
use super::scan::{RowState, Sampling};
use super::screen::Viewport;
use super::setup::{RasterTriangle, ScreenTriangle};
use super::target::{Framebuffer, ScanlineBuffer, Target};

/// One triangle on the active list: its drawing order, where its setup lives, its walk.
#[derive(Clone, Copy, Debug)]
struct Active {
    order: usize,
    slot: usize,
    walk: RowState,
}

/// Set-up triangles of the active list, in reusable slots.
#[derive(Default)]
struct Slab {
    tris: Vec<RasterTriangle>,
    free: Vec<usize>,
}

impl Slab {
    fn insert(&mut self, t: RasterTriangle) -> usize {
        match self.free.pop() {
            Some(i) => {
                self.tris[i] = t;
                i
            }
            None => {
                self.tris.push(t);
                self.tris.len() - 1
            }
        }
    }
}

/// Renders `tris` (in drawing order) scanline by scanline, top to bottom, handing each
/// finished scanline to `emit`. Rows no triangle touches are still emitted (cleared to
/// `clear`), so the consumer sees every row of the viewport exactly once.
///
/// `triangles_scanned` counts the triangles that reach the viewport (those bucketed).
pub fn render_scanlines(
    tris: &[ScreenTriangle],
    viewport: Viewport,
    clear: [u8; 3],
    mut emit: impl FnMut(&ScanlineBuffer),
) -> Counters {
    render_scanlines_counted(tris, viewport, clear, |line, _| emit(line))
}

/// As [`render_scanlines`], also handing `emit` the counts so far (running totals, bucket
/// sort included), so a caller can charge each scanline's own work.
pub fn render_scanlines_counted(
    tris: &[ScreenTriangle],
    viewport: Viewport,
    clear: [u8; 3],
    mut emit: impl FnMut(&ScanlineBuffer, &Counters),
) -> Counters {
    let mut c = Counters::default();
    let (w, h) = (i64::from(viewport.width()), i64::from(viewport.height()));

    // Bucket sort by first scanline; buckets fill in drawing order.
    let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); h as usize];
    for (i, t) in tris.iter().enumerate() {
        let ((y0, y1), (x0, x1)) = t.centre_extent();
        if y0.max(0) <= y1.min(h - 1) && x0.max(0) <= x1.min(w - 1) {
            buckets[y0.max(0) as usize].push(i as u32);
            c.bucket_inserts += 1;
        }
    }

    let Some(mut line) = ScanlineBuffer::new(viewport, 0) else {
        return c;
    };
    let mut slab = Slab::default();
    let mut active: Vec<Active> = Vec::new();
    let mut spare: Vec<Active> = Vec::new();
    for (y, bucket) in buckets.into_iter().enumerate() {
        if !bucket.is_empty() {
            c.active_inserts += bucket.len() as u64;
            c.triangles_scanned += bucket.len() as u64;
            activate(&mut active, &mut spare, &bucket, tris, &mut slab, viewport);
        }
        line.reset(y as u32, clear);
        for a in &mut active {
            if let Some(span) = a.walk.next_row(&slab.tris[a.slot]).and_then(|row| row.span) {
                c.spans += 1;
                line.span(0, &span, &mut c);
            }
        }
        let before = active.len();
        active.retain(|a| {
            let done = a.walk.is_done();
            if done {
                slab.free.push(a.slot);
            }
            !done
        });
        c.active_removals += (before - active.len()) as u64;
        c.scanlines += 1;
        emit(&line, &c);
    }
    c
}

/// Renders into a whole framebuffer (row by row), for comparison with the z-buffer path.
pub fn render_scanlines_into(
    tris: &[ScreenTriangle],
    fb: &mut Framebuffer,
    clear: [u8; 3],
) -> Counters {
    let Some(viewport) = Viewport::new(fb.width(), fb.height()) else {
        return Counters::default();
    };
    render_scanlines(tris, viewport, clear, |line| {
        fb.set_row(line.y(), line.colors(), line.depths());
    })
}

/// Sets up the triangles starting on this scanline and merges them (ascending drawing
/// order) into the active list (also ascending), so each scanline visits triangles in
/// drawing order. `spare` is scratch space reused so merging never allocates once warm.
fn activate(
    active: &mut Vec<Active>,
    spare: &mut Vec<Active>,
    incoming: &[u32],
    tris: &[ScreenTriangle],
    slab: &mut Slab,
    viewport: Viewport,
) {
    spare.clear();
    let mut old = active.drain(..).peekable();
    for &i in incoming {
        let i = i as usize;
        while let Some(a) = old.next_if(|a| a.order < i) {
            spare.push(a);
        }
        let rt = RasterTriangle::new(&tris[i]);
        // Bucketing used the same extent, so the walk always exists.
        if let Some(walk) = RowState::new(&rt, viewport.rect(), Sampling::Centre, true) {
            let slot = slab.insert(rt);
            spare.push(Active {
                order: i,
                slot,
                walk,
            });
        }
    }
    spare.extend(old);
    std::mem::swap(active, spare);
}
