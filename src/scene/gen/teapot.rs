//! Newell's teapot (SPD `teapot`): 32 bicubic Bezier patches, each evaluated on an
//! (n + 1) x (n + 1) grid and split into 2 n^2 triangles. Triangles that collapse where a
//! patch edge degenerates to a point (the lid knob and the bottom centre) are dropped, and
//! vertices at the same position on patch seams are merged, so the surface is one mesh.
//! z is up in the data; scenes rotate it.
//!
//! Owns this shape only. Must never place or light it.

use glam::Vec3;

use super::teapot_data::{PATCHES, POINTS};
use crate::scene::mesh::{FastMap, Mesh};

pub fn build(n: u32) -> Mesh {
    let mut m = Mesh::new();
    let mut merged: FastMap<[i32; 3], u32> = FastMap::default();
    for patch in &PATCHES {
        let cp: Vec<Vec3> = patch
            .iter()
            .map(|&i| Vec3::from(POINTS[i as usize - 1]))
            .collect();
        let mut grid = Vec::with_capacity(((n + 1) * (n + 1)) as usize);
        for i in 0..=n {
            for j in 0..=n {
                let p = bezier(&cp, i as f32 / n as f32, j as f32 / n as f32);
                grid.push(weld(&mut m, &mut merged, p));
            }
        }
        let at = |i: u32, j: u32| grid[(i * (n + 1) + j) as usize];
        for i in 0..n {
            for j in 0..n {
                let (a, b, c, d) = (at(i, j), at(i, j + 1), at(i + 1, j), at(i + 1, j + 1));
                push_unless_degenerate(&mut m, [a, c, d]);
                push_unless_degenerate(&mut m, [a, d, b]);
            }
        }
    }
    orient_outward(&mut m);
    m
}

/// Bicubic Bezier surface point; `cp` holds 16 control points row by row (row = u).
fn bezier(cp: &[Vec3], u: f32, v: f32) -> Vec3 {
    let bu = bernstein(u);
    let bv = bernstein(v);
    let mut p = Vec3::ZERO;
    for (i, wu) in bu.iter().enumerate() {
        for (j, wv) in bv.iter().enumerate() {
            p += cp[i * 4 + j] * (wu * wv);
        }
    }
    p
}

fn bernstein(t: f32) -> [f32; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t]
}

/// One vertex per position (to 1e-5), so seams between patches share vertices.
fn weld(m: &mut Mesh, merged: &mut FastMap<[i32; 3], u32>, p: Vec3) -> u32 {
    let key = (p * 1e5).round().to_array().map(|x| x as i32);
    *merged.entry(key).or_insert_with(|| m.vertex(p, 0))
}

fn push_unless_degenerate(m: &mut Mesh, t: [u32; 3]) {
    if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
        m.tri(t[0], t[1], t[2]);
    }
}

/// The patches' parameter directions do not say which side is out; the sign of the enclosed
/// volume does (the teapot is closed but for the spout's and handle's seams).
fn orient_outward(m: &mut Mesh) {
    let volume: f32 = m
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            a.dot(b.cross(c))
        })
        .sum();
    if volume < 0.0 {
        for t in &mut m.triangles {
            t.swap(1, 2);
        }
    }
}
