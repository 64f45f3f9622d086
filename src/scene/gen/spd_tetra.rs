//! SPD `tetra` (Haines, Standard Procedural Databases): the Sierpinski tetrahedron. A regular
//! tetrahedron is replaced by four half-size copies at its corners, `size_factor` times,
//! giving 4^size_factor tetrahedra and 4^(size_factor + 1) triangles (4 faces each, each
//! face its own triangle). Paper 001's Tetra file had 34,017 triangles *after* back-face
//! culling (its inputs were culled screen-space files); the stand-in scene pre-culls size
//! factor 7 (65,536 triangles, about 26,400 facing its camera) and refines that to exactly
//! 34,017.
//!
//! Owns this shape only. Must never place or light it.

use glam::Vec3;

use crate::scene::mesh::Mesh;

pub fn build(size_factor: u32) -> Mesh {
    let mut m = Mesh::new();
    let corners = [
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(-1.0, -1.0, 1.0),
        Vec3::new(-1.0, 1.0, -1.0),
        Vec3::new(1.0, -1.0, -1.0),
    ];
    recurse(&mut m, corners, size_factor);
    m
}

fn recurse(m: &mut Mesh, c: [Vec3; 4], depth: u32) {
    if depth == 0 {
        tetrahedron(m, c);
        return;
    }
    for i in 0..4 {
        // The copy at corner i: every corner pulled halfway towards corner i.
        recurse(m, c.map(|p| (p + c[i]) * 0.5), depth - 1);
    }
}

/// Four outward facets, one part per tetrahedron.
pub fn tetrahedron(m: &mut Mesh, c: [Vec3; 4]) {
    let part = m.part_count();
    let centre = (c[0] + c[1] + c[2] + c[3]) * 0.25;
    for skip in 0..4 {
        let f: Vec<Vec3> = (0..4).filter(|&k| k != skip).map(|k| c[k]).collect();
        m.facet(f[0], f[1], f[2], centre, part);
    }
}
