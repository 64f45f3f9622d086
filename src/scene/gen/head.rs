//! Stand-in for paper 002's PLB head (59,592 triangles) and CT head (229,208): a closed
//! head-like surface on a UV sphere's topology (2 * segments * (rings - 1) triangles): an
//! egg-shaped skull with brow, nose, chin, cheeks and ears as smooth bumps, plus a seeded
//! skin roughness. Faces +z, up +y, about 2.3 units tall with the neck.
//!
//! Owns this shape only. Must never place or light it.

use glam::Vec3;

use super::primitives::uv_surface;
use crate::scene::mesh::{hash01, Mesh};

pub fn build(rings: u32, segments: u32, seed: u64) -> Mesh {
    uv_surface(rings, segments, 0, |d| shape(d, seed))
}

fn shape(d: Vec3, seed: u64) -> Vec3 {
    // Skull: an ellipsoid narrower across than deep, with a flattened jaw below.
    let base = Vec3::new(0.78, 1.0, 0.9);
    let mut r = 1.0;
    r += 0.22 * bump(d, Vec3::new(0.0, -0.1, 1.0), 0.012); // nose
    r += 0.06 * bump(d, Vec3::new(0.0, 0.3, 1.0), 0.05); // brow
    r += 0.08 * bump(d, Vec3::new(0.0, -0.65, 0.75), 0.02); // chin
    r += 0.12 * bump(d, Vec3::new(1.0, 0.05, -0.1), 0.008); // ears
    r += 0.12 * bump(d, Vec3::new(-1.0, 0.05, -0.1), 0.008);
    r -= 0.06 * bump(d, Vec3::new(0.4, 0.15, 0.9), 0.006); // eye sockets
    r -= 0.06 * bump(d, Vec3::new(-0.4, 0.15, 0.9), 0.006);
    r += 0.06 * bump(d, Vec3::new(0.0, 0.4, -1.0), 0.2); // back of the skull
    r += 0.3 * bump(d, Vec3::new(0.0, -1.0, 0.1), 0.09); // neck
                                                         // Skin roughness: a fixed function of direction so every seed gives a closed surface.
    let cell = (
        (d.x * 40.0).floor() as i64 as u64,
        ((d.y * 40.0).floor() as i64 as u64) ^ (((d.z * 40.0).floor() as i64 as u64) << 20),
    );
    r += 0.004 * (hash01(seed, cell.0, cell.1) - 0.5);
    d * base * r
}

/// Smooth bump: 1 at direction `at`, falling off with angular width `w` (in 1 - cos units).
fn bump(d: Vec3, at: Vec3, w: f32) -> f32 {
    let c = d.dot(at.normalize());
    (-(1.0 - c) / w).exp()
}
