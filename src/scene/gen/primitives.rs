//! Simple shapes: a floor plane, one big triangle, UV spheres and lattices of them.
//!
//! Owns these shapes only. Must never place or light them.

use glam::Vec3;

use crate::scene::mesh::Mesh;

/// Square [-1, 1]^2 in the xz plane facing +y: 2 triangles.
pub fn plane() -> Mesh {
    let mut m = Mesh::new();
    let v = [(-1.0, -1.0), (-1.0, 1.0), (1.0, 1.0), (1.0, -1.0)]
        .map(|(x, z)| m.vertex(Vec3::new(x, 0.0, z), 0));
    // (a, a + z, a + x) winds counter-clockwise seen from +y.
    m.tri(v[0], v[1], v[2]);
    m.tri(v[0], v[2], v[3]);
    m
}

/// One triangle in the xz plane facing +y whose inscribed square is [-1, 1]^2.
pub fn big_triangle() -> Mesh {
    let mut m = Mesh::new();
    let a = m.vertex(Vec3::new(-1.0, 0.0, -1.0), 0);
    let b = m.vertex(Vec3::new(-1.0, 0.0, 3.0), 0);
    let c = m.vertex(Vec3::new(3.0, 0.0, -1.0), 0);
    m.tri(a, b, c);
    m
}

/// UV sphere of radius 1 at the origin: poles plus (rings - 1) latitude circles of
/// `segments` vertices; 2 * segments * (rings - 1) triangles.
pub fn uv_sphere(rings: u32, segments: u32, part: u32) -> Mesh {
    uv_surface(rings, segments, part, |d| d)
}

/// A closed surface r(direction) built on the UV sphere's topology; `f` maps a unit
/// direction to a point.
pub fn uv_surface(rings: u32, segments: u32, part: u32, f: impl Fn(Vec3) -> Vec3) -> Mesh {
    let mut m = Mesh::new();
    let top = m.vertex(f(Vec3::Y), part);
    for r in 1..rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..segments {
            let phi = std::f32::consts::TAU * s as f32 / segments as f32;
            let d = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            );
            m.vertex(f(d), part);
        }
    }
    let bottom = m.vertex(f(-Vec3::Y), part);
    let ring = |r: u32, s: u32| 1 + (r - 1) * segments + (s % segments);
    for s in 0..segments {
        // phi grows counter-clockwise seen from +y (x towards -z), so (top, s, s+1) faces out.
        m.tri(top, ring(1, s), ring(1, s + 1));
        m.tri(bottom, ring(rings - 1, s + 1), ring(rings - 1, s));
    }
    for r in 1..rings - 1 {
        for s in 0..segments {
            let (a, b, c, d) = (
                ring(r, s),
                ring(r, s + 1),
                ring(r + 1, s),
                ring(r + 1, s + 1),
            );
            m.tri(a, c, d);
            m.tri(a, d, b);
        }
    }
    m
}

/// count[0] x count[1] x count[2] spheres of `radius` evenly spread in [-1, 1]^3, one part each.
pub fn sphere_lattice(count: [u32; 3], radius: f32, rings: u32, segments: u32) -> Mesh {
    let mut m = Mesh::new();
    let at = |i: u32, n: u32| {
        if n == 1 {
            0.0
        } else {
            -1.0 + 2.0 * i as f32 / (n - 1) as f32
        }
    };
    for k in 0..count[2] {
        for j in 0..count[1] {
            for i in 0..count[0] {
                let c = Vec3::new(at(i, count[0]), at(j, count[1]), at(k, count[2]));
                m.append(uv_surface(rings, segments, 0, |d| c + d * radius));
            }
        }
    }
    m
}
