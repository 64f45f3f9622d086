//! Stand-in for paper 002's polio virus outer shell (806,640 triangles, 110 views): a
//! geodesic sphere on the icosahedron of frequency f (each of the 20 faces split into f^2
//! triangles: 20 f^2 in all) whose radius carries icosahedrally symmetric relief: knobs at
//! the 12 five-fold axes, ridges around the 20 three-fold axes, and a fine capsomere
//! ripple, all of height `bump`. With several layers, nested copies of the shell at radii
//! 1, 1 - gap, 1 - 2 gap, ...: the overdraw a capsid's folded surface gives (paper 002's
//! polio draws 806,640 triangles of 6.7 pixels on average, several times the screen).
//!
//! Owns this shape only. Must never place or light it.

use glam::Vec3;

use crate::scene::mesh::{FastMap, Mesh};

pub fn build(frequency: u32, bump: f32, layers: u32, gap: f32) -> Mesh {
    let shell = one_shell(frequency, bump);
    if layers <= 1 {
        return shell;
    }
    let mut m = Mesh::new();
    for layer in 0..layers {
        let mut copy = shell.clone();
        copy.transform(glam::Mat4::from_scale(Vec3::splat(
            1.0 - gap * layer as f32,
        )));
        m.append(copy);
    }
    m
}

fn one_shell(frequency: u32, bump: f32) -> Mesh {
    let (corners, faces) = icosahedron();
    let centres: Vec<Vec3> = faces
        .iter()
        .map(|f| (corners[f[0]] + corners[f[1]] + corners[f[2]]).normalize())
        .collect();
    let f = frequency;
    let mut m = Mesh::new();
    let mut merged: FastMap<[i32; 3], u32> = FastMap::default();
    for face in &faces {
        let [a, b, c] = face.map(|i| corners[i]);
        let mut ids = Vec::with_capacity(((f + 1) * (f + 2) / 2) as usize);
        for i in 0..=f {
            for j in 0..=f - i {
                let p = a + (b - a) * (i as f32 / f as f32) + (c - a) * (j as f32 / f as f32);
                let d = p.normalize();
                let key = (d * (1 << 20) as f32).round().to_array().map(|x| x as i32);
                let id = *merged
                    .entry(key)
                    .or_insert_with(|| m.vertex(d * radius(d, &corners, &centres, bump), 0));
                ids.push(id);
            }
        }
        // Row i of the triangular grid starts after rows 0..i of lengths f+1, f, ...
        let row_start = |i: u32| (i * (2 * f + 3 - i)) / 2;
        let id = |i: u32, j: u32| ids[(row_start(i) + j) as usize];
        for i in 0..f {
            for j in 0..f - i {
                m.tri(id(i, j), id(i + 1, j), id(i, j + 1));
                if j + 1 < f - i {
                    m.tri(id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                }
            }
        }
    }
    m
}

fn radius(d: Vec3, corners: &[Vec3], centres: &[Vec3], bump: f32) -> f32 {
    let five = corners
        .iter()
        .map(|c| d.dot(c.normalize()))
        .fold(-1.0f32, f32::max);
    let three = centres.iter().map(|c| d.dot(*c)).fold(-1.0f32, f32::max);
    let knob = (-(1.0 - five) / 0.004).exp();
    let ridge = (-((1.0 - three) - 0.02).powi(2) / 0.0002).exp();
    let ripple = 0.5 + 0.5 * ((1.0 - five) * 900.0).cos() * ((1.0 - three) * 700.0).cos();
    1.0 + bump * (0.6 * knob + 0.4 * ridge + 0.25 * ripple)
}

/// The 12 corners (0, +-1, +-phi) and cyclic permutations, and the 20 faces: the corner
/// triples at mutual distance 2, wound counter-clockwise seen from outside.
fn icosahedron() -> (Vec<Vec3>, Vec<[usize; 3]>) {
    let phi = (1.0 + 5f32.sqrt()) * 0.5;
    let mut v = Vec::new();
    for s1 in [-1.0, 1.0] {
        for s2 in [-phi, phi] {
            v.push(Vec3::new(0.0, s1, s2));
            v.push(Vec3::new(s1, s2, 0.0));
            v.push(Vec3::new(s2, 0.0, s1));
        }
    }
    let edge = |a: usize, b: usize| ((v[a] - v[b]).length() - 2.0).abs() < 1e-3;
    let mut faces = Vec::new();
    for a in 0..12 {
        for b in a + 1..12 {
            for c in b + 1..12 {
                if edge(a, b) && edge(b, c) && edge(a, c) {
                    let n = (v[b] - v[a]).cross(v[c] - v[a]);
                    faces.push(if n.dot(v[a]) > 0.0 {
                        [a, b, c]
                    } else {
                        [a, c, b]
                    });
                }
            }
        }
    }
    (v, faces)
}

#[cfg(test)]
mod layer_tests {
    use super::*;

    #[test]
    fn layers_are_nested_copies_each_a_gap_smaller() {
        let one = build(4, 0.0, 1, 0.0);
        let three = build(4, 0.0, 3, 0.1);
        assert_eq!(one.triangles.len(), 20 * 16);
        assert_eq!(three.triangles.len(), 3 * one.triangles.len());
        let n = one.positions.len();
        for (layer, scale) in [(0, 1.0f32), (1, 0.9), (2, 0.8)] {
            for (p, q) in three.positions[layer * n..(layer + 1) * n]
                .iter()
                .zip(&one.positions)
            {
                assert!((p.length() - scale * q.length()).abs() < 1e-5);
            }
        }
        // One layer is the plain shell, whatever the gap.
        assert_eq!(
            build(4, 0.06, 1, 0.3).positions,
            build(4, 0.06, 1, 0.0).positions
        );
    }
}
