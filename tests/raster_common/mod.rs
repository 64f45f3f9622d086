//! Shared helpers for the raster integration tests: building vertices from pixel
//! coordinates, exact screen triangles from subpixel integers, random meshes from seeded
//! ChaCha streams, and the one `draw_counts` boundary most coverage checks go through.
//!
//! Must never depend on rasterizer internals: only the public `sortsim::raster` API.
#![allow(dead_code)]

use glam::{Mat4, Vec3, Vec4};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sortsim::raster::*;

pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

pub fn vp(w: u32, h: u32) -> Viewport {
    Viewport::new(w, h).unwrap()
}

/// A vertex at pixel `(x, y)` (y down) with depth `z` in 0..=1 and clip w = `w`.
pub fn pv_w(viewport: Viewport, x: f64, y: f64, z: f64, w: f64, rgb: [f32; 3]) -> Vertex {
    let nx = 2.0 * x / f64::from(viewport.width()) - 1.0;
    let ny = 1.0 - 2.0 * y / f64::from(viewport.height());
    Vertex {
        clip: Vec4::new((nx * w) as f32, (ny * w) as f32, (z * w) as f32, w as f32),
        color: Vec3::from_array(rgb),
    }
}

pub fn pv(viewport: Viewport, x: f64, y: f64) -> Vertex {
    pv_w(viewport, x, y, 0.5, 1.0, [1.0, 1.0, 1.0])
}

/// A screen vertex at raw subpixel coordinates.
pub fn sv(x: i32, y: i32, z: u32, rgb: [u8; 3]) -> ScreenVertex {
    ScreenVertex {
        x: Sub::from_raw(x).unwrap(),
        y: Sub::from_raw(y).unwrap(),
        z: Depth::from_raw(z).unwrap(),
        rgb,
    }
}

/// A screen triangle from subpixel coordinates (flat white, depth 0), `None` if zero area.
pub fn st(p: [(i32, i32); 3], prim: u32) -> Option<ScreenTriangle> {
    ScreenTriangle::new(p.map(|(x, y)| sv(x, y, 0, [255; 3])), prim)
}

/// Fragments per pixel when drawing `tris` (additive, no depth test).
pub fn draw_counts(viewport: Viewport, tris: &[ScreenTriangle]) -> CountingTarget {
    let mut t = CountingTarget::new(viewport);
    draw_screen_triangles(tris, &mut t);
    t
}

/// Fragments per pixel when drawing a mesh through the whole float front end.
pub fn mesh_counts(
    viewport: Viewport,
    verts: &[Vertex],
    tris: &[[u32; 3]],
    cull: CullMode,
) -> (CountingTarget, Counters) {
    let mut t = CountingTarget::new(viewport);
    let c = draw_mesh(verts, tris, viewport, &RasterOptions { cull }, &mut t);
    (t, c)
}

/// Pixels with a non-zero count, in raster order.
pub fn covered(t: &CountingTarget) -> Vec<(u32, u32)> {
    let w = t.width();
    t.counts()
        .iter()
        .enumerate()
        .filter(|(_, &c)| c > 0)
        .map(|(i, _)| (i as u32 % w, i as u32 / w))
        .collect()
}

pub fn max_count(t: &CountingTarget) -> u32 {
    t.counts().iter().copied().max().unwrap_or(0)
}

/// A UV sphere of `rings x segments` with each vertex's radius scaled by `radius(i)`:
/// a closed, consistently wound (counter-clockwise seen from outside) mesh.
pub fn sphere(
    rings: u32,
    segments: u32,
    mut radius: impl FnMut(usize) -> f32,
) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut pos = vec![Vec3::Y * radius(0)];
    for r in 1..rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..segments {
            let phi = std::f32::consts::TAU * s as f32 / segments as f32;
            let dir = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            let i = pos.len();
            pos.push(dir * radius(i));
        }
    }
    let bottom = pos.len() as u32;
    pos.push(-Vec3::Y * radius(bottom as usize));
    let ring = |r: u32, s: u32| 1 + (r - 1) * segments + (s % segments);
    let mut tris = Vec::new();
    for s in 0..segments {
        tris.push([0, ring(1, s + 1), ring(1, s)]);
        for r in 1..rings - 1 {
            let (a, b, c, d) = (
                ring(r, s),
                ring(r, s + 1),
                ring(r + 1, s),
                ring(r + 1, s + 1),
            );
            tris.push([a, b, d]);
            tris.push([a, d, c]);
        }
        tris.push([bottom, ring(rings - 1, s), ring(rings - 1, s + 1)]);
    }
    (pos, tris)
}

/// Transforms model-space positions to clip space with a camera at distance `dist` looking
/// at the origin, after a rotation; per-vertex colours from the position.
pub fn to_clip(pos: &[Vec3], rot: glam::Quat, dist: f32, aspect: f32) -> Vec<Vertex> {
    let proj = Mat4::perspective_rh(0.9, aspect, 0.5, 100.0);
    let view = Mat4::from_translation(Vec3::new(0.0, 0.0, -dist)) * Mat4::from_quat(rot);
    let m = proj * view;
    pos.iter()
        .map(|&p| Vertex {
            clip: m * p.extend(1.0),
            color: (p.normalize_or_zero() * 0.5 + Vec3::splat(0.5)).clamp(Vec3::ZERO, Vec3::ONE),
        })
        .collect()
}

pub fn random_rotation(r: &mut ChaCha8Rng) -> glam::Quat {
    let axis = Vec3::new(
        r.gen_range(-1.0..1.0),
        r.gen_range(-1.0..1.0),
        r.gen_range(-1.0..1.0),
    );
    glam::Quat::from_axis_angle(
        axis.try_normalize().unwrap_or(Vec3::X),
        r.gen_range(0.0..6.3),
    )
}

/// Random triangles in clip space with overlapping, interpenetrating depths and random
/// colours, all inside the view volume or crossing its sides.
pub fn random_soup(r: &mut ChaCha8Rng, n: usize) -> (Vec<Vertex>, Vec<[u32; 3]>) {
    let mut verts = Vec::new();
    let mut tris = Vec::new();
    for i in 0..n {
        let cx: f32 = r.gen_range(-1.0..1.0);
        let cy: f32 = r.gen_range(-1.0..1.0);
        let size: f32 = r.gen_range(0.01..0.6);
        for _ in 0..3 {
            let w: f32 = r.gen_range(0.5..3.0);
            let x = cx + r.gen_range(-size..size);
            let y = cy + r.gen_range(-size..size);
            let z: f32 = r.gen_range(0.0..1.0);
            verts.push(Vertex {
                clip: Vec4::new(x * w, y * w, z * w, w),
                color: Vec3::new(r.gen(), r.gen(), r.gen()),
            });
        }
        let b = 3 * i as u32;
        tris.push([b, b + 1, b + 2]);
    }
    (verts, tris)
}
