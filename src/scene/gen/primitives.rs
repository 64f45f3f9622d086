//! Simple shapes: a floor plane, one big triangle, UV spheres and lattices of them, a torus.
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

/// Torus around the y axis: the tube's centre circle has radius 1, the tube radius `minor`
/// (< 1). `rings` circles of the tube, `segments` vertices each; 2 * rings * segments
/// triangles, every edge shared by two of them.
pub fn torus(rings: u32, segments: u32, minor: f32) -> Mesh {
    let mut m = Mesh::new();
    for r in 0..rings {
        let phi = std::f32::consts::TAU * r as f32 / rings as f32;
        let (out, y_axis) = (Vec3::new(phi.cos(), 0.0, -phi.sin()), Vec3::Y);
        for s in 0..segments {
            let theta = std::f32::consts::TAU * s as f32 / segments as f32;
            m.vertex(
                out * (1.0 + minor * theta.cos()) + y_axis * (minor * theta.sin()),
                0,
            );
        }
    }
    let at = |r: u32, s: u32| (r % rings) * segments + (s % segments);
    for r in 0..rings {
        for s in 0..segments {
            // phi runs counter-clockwise seen from +y and theta from the outside up over the
            // top, so (a, c, d) and (a, d, b) face away from the tube's centre circle.
            let (a, b, c, d) = (at(r, s), at(r, s + 1), at(r + 1, s), at(r + 1, s + 1));
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn torus_is_closed_and_faces_out() {
        let (rings, segments, minor) = (12, 8, 0.3);
        let m = torus(rings, segments, minor);
        assert_eq!(m.triangles.len() as u32, 2 * rings * segments);
        let mut edges = std::collections::BTreeMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let centroid = (a + b + c) / 3.0;
            let ring = Vec3::new(centroid.x, 0.0, centroid.z).normalize();
            let normal = (b - a).cross(c - a);
            assert!(
                normal.dot(centroid - ring) > 0.0,
                "{t:?} faces the tube's axis"
            );
        }
        // Closed and consistently wound: every directed edge once, its reverse once.
        assert!(edges
            .keys()
            .all(|&(u, v)| edges.get(&(u, v)) == Some(&1) && edges.get(&(v, u)) == Some(&1)));
    }
}
