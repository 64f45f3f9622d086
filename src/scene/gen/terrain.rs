//! Stand-in for paper 002's Landsat terrain: a height field on cols x rows quads over
//! [-1, 1]^2 (xz), heights from a sum of value-noise octaves (fractal Brownian motion),
//! 2 * cols * rows triangles facing +y. The paper rendered it with back-face culling off.
//!
//! Owns this shape only. Must never place or light it.

use glam::Vec3;

use crate::scene::mesh::{hash01, Mesh};

pub fn build(cols: u32, rows: u32, relief: f32, seed: u64) -> Mesh {
    let mut m = Mesh::new();
    for j in 0..=rows {
        for i in 0..=cols {
            let (x, z) = (
                -1.0 + 2.0 * i as f32 / cols as f32,
                -1.0 + 2.0 * j as f32 / rows as f32,
            );
            m.vertex(Vec3::new(x, relief * fbm(x, z, seed), z), 0);
        }
    }
    let at = |i: u32, j: u32| j * (cols + 1) + i;
    for j in 0..rows {
        for i in 0..cols {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
            // (a, a + z, a + x) faces +y.
            m.tri(a, c, d);
            m.tri(a, d, b);
        }
    }
    m
}

/// Fractal noise in about [-1, 1]: six octaves of bilinear value noise.
pub fn fbm(x: f32, z: f32, seed: u64) -> f32 {
    let mut sum = 0.0;
    let (mut freq, mut amp) = (2.0, 0.5);
    for octave in 0..6 {
        sum += amp * value_noise(x * freq, z * freq, seed.wrapping_add(octave));
        freq *= 2.0;
        amp *= 0.5;
    }
    sum
}

fn value_noise(x: f32, z: f32, seed: u64) -> f32 {
    let (xi, zi) = (x.floor(), z.floor());
    let (fx, fz) = (smooth(x - xi), smooth(z - zi));
    let corner = |dx: f32, dz: f32| {
        let (a, b) = ((xi + dx) as i64 as u64, (zi + dz) as i64 as u64);
        hash01(seed, a, b) * 2.0 - 1.0
    };
    let top = corner(0.0, 0.0) * (1.0 - fx) + corner(1.0, 0.0) * fx;
    let bottom = corner(0.0, 1.0) * (1.0 - fx) + corner(1.0, 1.0) * fx;
    top * (1.0 - fz) + bottom * fz
}

fn smooth(t: f32) -> f32 {
    t * t * (3.0 - 2.0 * t)
}
