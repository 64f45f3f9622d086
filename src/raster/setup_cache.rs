//! A frame's triangle set-ups kept for reuse: a screen triangle that touches regions of
//! several processors is set up (edge functions and interpolation planes) once per frame on
//! the host, not once by each processor that draws it.
//!
//! Owns the memo only. Must never change what is drawn or counted: a set-up is a pure
//! function of the screen triangle, and an entry serves only a triangle equal to the one it
//! was made from, so a stale or colliding entry costs a set-up, never a different pixel.

use super::setup::{RasterTriangle, ScreenTriangle};

/// No entry for this primitive.
const NONE: u32 = u32::MAX;

/// Set-ups one cache keeps at most (432 bytes each, 28 MB in all); past that a new
/// triangle is set up on every draw, as with no cache, so a frame of millions of triangles
/// does not hold a set-up for each.
const MAX_ENTRIES: usize = 1 << 16;
const _: () = assert!(std::mem::size_of::<(ScreenTriangle, RasterTriangle)>() <= 432);

/// Set-ups of one frame's screen triangles, found by primitive id. One cache serves every
/// draw of the frame (all processors of a simulated frame share one).
#[derive(Clone, Debug, Default)]
pub struct SetupCache {
    /// Per primitive id of the frame's mesh: its entry in `entries`, or `NONE`.
    slots: Vec<u32>,
    /// The triangles set up so far, each with the triangle it was made from.
    entries: Vec<(ScreenTriangle, RasterTriangle)>,
    /// Where a triangle is set up when it cannot be kept (its primitive id is past the mesh,
    /// or the cache is full).
    scratch: Option<RasterTriangle>,
    /// Set-ups made (a reused one is not counted).
    made: u64,
}

impl SetupCache {
    /// An empty cache for a mesh of `primitives` triangles.
    pub fn new(primitives: usize) -> SetupCache {
        SetupCache {
            slots: vec![NONE; primitives],
            ..SetupCache::default()
        }
    }

    /// An empty cache like [`SetupCache::new`]'s, in this one's memory.
    pub fn emptied(mut self, primitives: usize) -> SetupCache {
        self.slots.clear();
        self.slots.resize(primitives, NONE);
        self.entries.clear();
        self.scratch = None;
        self.made = 0;
        self
    }

    /// `tri` set up: the kept set-up when its primitive's entry was made from an equal
    /// triangle, else a new one (which replaces that entry: the pieces a clipped primitive
    /// was cut into share its id and take turns).
    #[inline]
    pub fn get(&mut self, tri: &ScreenTriangle) -> &RasterTriangle {
        let prim = tri.prim() as usize;
        let at = self.slots.get(prim).map_or(NONE, |&at| at) as usize;
        if at < self.entries.len() && self.entries[at].0 == *tri {
            return &self.entries[at].1;
        }
        self.made += 1;
        let set_up = RasterTriangle::new(tri);
        if at < self.entries.len() {
            self.entries[at] = (*tri, set_up);
            &self.entries[at].1
        } else if prim < self.slots.len() && self.entries.len() < MAX_ENTRIES {
            self.slots[prim] = self.entries.len() as u32;
            self.entries.push((*tri, set_up));
            &self.entries[self.entries.len() - 1].1
        } else {
            self.scratch.insert(set_up)
        }
    }

    /// Set-ups made since the cache was emptied.
    pub fn made(&self) -> u64 {
        self.made
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::setup::ScreenVertex;

    fn tri(prim: u32, dx: f64) -> ScreenTriangle {
        let v = |x: f64, y: f64| ScreenVertex::from_pixels(x, y, 0.5, [1.0, 0.5, 0.0]).unwrap();
        ScreenTriangle::new([v(dx, 0.0), v(dx + 9.0, 1.0), v(dx + 2.0, 7.5)], prim).unwrap()
    }

    fn same(a: &RasterTriangle, b: &RasterTriangle) -> bool {
        format!("{a:?}") == format!("{b:?}")
    }

    #[test]
    fn a_triangle_asked_again_is_set_up_once() {
        let mut cache = SetupCache::new(4);
        let t = tri(2, 0.0);
        let first = *cache.get(&t);
        let again = *cache.get(&t);
        assert!(same(&first, &RasterTriangle::new(&t)));
        assert!(same(&again, &first));
        assert_eq!(cache.made(), 1);
    }

    #[test]
    fn pieces_sharing_a_primitive_id_each_get_their_own_set_up() {
        let mut cache = SetupCache::new(4);
        let (a, b) = (tri(1, 0.0), tri(1, 3.25));
        for t in [a, b, a, b, b] {
            assert!(same(cache.get(&t), &RasterTriangle::new(&t)));
        }
        // a, b, a and b miss in turn; the last b finds its own entry.
        assert_eq!(cache.made(), 4);
    }

    #[test]
    fn a_primitive_id_past_the_mesh_is_set_up_every_time_and_not_kept() {
        let mut cache = SetupCache::new(2);
        let t = tri(7, 0.0);
        assert!(same(cache.get(&t), &RasterTriangle::new(&t)));
        assert!(same(cache.get(&t), &RasterTriangle::new(&t)));
        assert_eq!(cache.made(), 2);
        assert!(cache.entries.is_empty());
    }

    #[test]
    fn a_full_cache_sets_new_triangles_up_on_every_draw_and_keeps_its_entries() {
        let n = MAX_ENTRIES + 2;
        let mut cache = SetupCache::new(n);
        let t = |prim: usize| tri(prim as u32, (prim % 64) as f64);
        for prim in 0..n {
            cache.get(&t(prim));
        }
        assert_eq!(cache.entries.len(), MAX_ENTRIES);
        let made = cache.made();
        assert!(same(cache.get(&t(0)), &RasterTriangle::new(&t(0))));
        assert_eq!(cache.made(), made, "kept");
        let last = t(n - 1);
        assert!(same(cache.get(&last), &RasterTriangle::new(&last)));
        assert_eq!(cache.made(), made + 1, "set up again");
    }

    #[test]
    fn an_emptied_cache_forgets_the_last_frame() {
        let mut cache = SetupCache::new(4);
        let t = tri(3, 0.0);
        cache.get(&t);
        let mut cache = cache.emptied(4);
        assert_eq!(cache.made(), 0);
        let moved = tri(3, 1.5);
        assert!(same(cache.get(&moved), &RasterTriangle::new(&moved)));
        assert_eq!(cache.made(), 1);
    }
}
