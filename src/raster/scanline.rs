//! The scanline z-buffer renderer (Watkins-style, as paper 001's SLMF pipeline uses it):
//! bucket-sort triangles by their first scanline, keep an active list, and for each
//! scanline depth-test the active triangles' spans into a one-scanline buffer.
//!
//! Must never evaluate coverage, depth or colour itself: it walks the same `RowWalker`s and
//! fragments as the z-buffer path, and keeps the active list in drawing order so depth ties
//! resolve the same way, which makes its image bit-identical to the z-buffer's. Only its
//! cost profile differs (bucket inserts, active-list operations, scanlines).

use super::counters::Counters;
use super::scan::RowWalker;
use super::screen::Viewport;
use super::setup::{RasterTriangle, ScreenTriangle};
use super::target::{Framebuffer, ScanlineBuffer, Target};

/// Renders `tris` (in drawing order) scanline by scanline, top to bottom, handing each
/// finished scanline to `emit`. Rows no triangle touches are still emitted (cleared to
/// `clear`), so the consumer sees every row of the viewport exactly once.
pub fn render_scanlines(
    tris: &[ScreenTriangle],
    viewport: Viewport,
    clear: [u8; 3],
    mut emit: impl FnMut(&ScanlineBuffer),
) -> Counters {
    let mut c = Counters::default();
    let setups: Vec<RasterTriangle> = tris.iter().map(RasterTriangle::new).collect();
    c.triangles_scanned += setups.len() as u64;

    // Bucket sort by first scanline; buckets fill in drawing order.
    let mut buckets: Vec<Vec<usize>> = vec![Vec::new(); viewport.height() as usize];
    for (i, t) in setups.iter().enumerate() {
        if let Some(w) = RowWalker::new(t, viewport.rect()) {
            buckets[w.next_y() as usize].push(i);
            c.bucket_inserts += 1;
        }
    }

    let mut active: Vec<(usize, RowWalker<'_>)> = Vec::new();
    let mut spare: Vec<(usize, RowWalker<'_>)> = Vec::new();
    let Some(mut line) = ScanlineBuffer::new(viewport, 0) else {
        return c;
    };
    for (y, bucket) in buckets.into_iter().enumerate() {
        if !bucket.is_empty() {
            c.active_inserts += bucket.len() as u64;
            merge_in_order(&mut active, &mut spare, &bucket, &setups, viewport);
        }
        line.reset(y as u32, clear);
        for (_, walker) in &mut active {
            if let Some(span) = walker.next_row().and_then(|row| row.span) {
                c.spans += 1;
                line.span(0, &span, &mut c);
            }
        }
        let before = active.len();
        active.retain(|(_, w)| w.next_y() <= w.last_y());
        c.active_removals += (before - active.len()) as u64;
        c.scanlines += 1;
        emit(&line);
    }
    c
}

/// Renders into a whole framebuffer (row by row), for comparison with the z-buffer path.
pub fn render_scanlines_into(tris: &[ScreenTriangle], fb: &mut Framebuffer, clear: [u8; 3]) -> Counters {
    let Some(viewport) = Viewport::new(fb.width(), fb.height()) else {
        return Counters::default();
    };
    render_scanlines(tris, viewport, clear, |line| {
        fb.set_row(line.y(), line.colors(), line.depths());
    })
}

/// Merges newly active triangles (ascending drawing order) into the active list (also
/// ascending), so each scanline visits triangles in drawing order.
/// `spare` is scratch space reused across scanlines so merging never allocates once warm.
fn merge_in_order<'a>(
    active: &mut Vec<(usize, RowWalker<'a>)>,
    spare: &mut Vec<(usize, RowWalker<'a>)>,
    incoming: &[usize],
    setups: &'a [RasterTriangle],
    viewport: Viewport,
) {
    spare.clear();
    let mut old = active.drain(..).peekable();
    for &i in incoming {
        while let Some(a) = old.next_if(|(j, _)| *j < i) {
            spare.push(a);
        }
        if let Some(w) = RowWalker::new(&setups[i], viewport.rect()) {
            spare.push((i, w));
        }
    }
    spare.extend(old);
    std::mem::swap(active, spare);
}
