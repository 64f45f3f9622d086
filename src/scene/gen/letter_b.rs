//! Stand-in for paper 000's letter "B" ("about 800 very large polygons", 512x512): a block
//! letter in the xy plane (height 1, facing +z) extruded by `depth`: a stem, three bars
//! and two bowls (half annuli of `segments` steps). Boxes have 12 triangles, a bowl
//! 8 * segments + 4, so 56 + 16 * segments triangles (segments = 47 gives 808). One part.
//!
//! Owns this shape only. Must never place or light it.

use glam::Vec3;

use crate::scene::mesh::Mesh;

pub fn build(segments: u32, depth: f32) -> Mesh {
    let mut m = Mesh::new();
    let z = depth * 0.5;
    block(&mut m, [-0.35, -0.5], [-0.15, 0.5], z); // stem
    block(&mut m, [-0.15, 0.38], [0.05, 0.5], z); // top bar
    block(&mut m, [-0.15, -0.06], [0.05, 0.06], z); // middle bar
    block(&mut m, [-0.15, -0.5], [0.05, -0.38], z); // bottom bar
    bowl(&mut m, [0.05, 0.22], 0.28, 0.16, segments, z);
    bowl(&mut m, [0.05, -0.22], 0.28, 0.16, segments, z);
    m
}

fn block(m: &mut Mesh, lo: [f32; 2], hi: [f32; 2], z: f32) {
    let c = Vec3::new((lo[0] + hi[0]) * 0.5, (lo[1] + hi[1]) * 0.5, 0.0);
    let p = |x: usize, y: usize, s: f32| Vec3::new([lo[0], hi[0]][x], [lo[1], hi[1]][y], s * z);
    let faces = [
        [p(0, 0, 1.0), p(1, 0, 1.0), p(1, 1, 1.0), p(0, 1, 1.0)],
        [p(0, 0, -1.0), p(0, 1, -1.0), p(1, 1, -1.0), p(1, 0, -1.0)],
        [p(0, 0, -1.0), p(1, 0, -1.0), p(1, 0, 1.0), p(0, 0, 1.0)],
        [p(0, 1, -1.0), p(0, 1, 1.0), p(1, 1, 1.0), p(1, 1, -1.0)],
        [p(0, 0, -1.0), p(0, 0, 1.0), p(0, 1, 1.0), p(0, 1, -1.0)],
        [p(1, 0, -1.0), p(1, 1, -1.0), p(1, 1, 1.0), p(1, 0, 1.0)],
    ];
    for f in faces {
        m.facet_quad(f, c, 0);
    }
}

/// Right half annulus centred at `c` from -90 to +90 degrees.
fn bowl(m: &mut Mesh, c: [f32; 2], r_out: f32, r_in: f32, segments: u32, z: f32) {
    let centre = Vec3::new(c[0], c[1], 0.0);
    let at = |r: f32, k: u32, s: f32| {
        let a = -std::f32::consts::FRAC_PI_2 + std::f32::consts::PI * k as f32 / segments as f32;
        centre + Vec3::new(a.cos() * r, a.sin() * r, s * z)
    };
    let r_mid = (r_out + r_in) * 0.5;
    for k in 0..segments {
        // A point inside this step of the bowl tells each facet which way is out.
        let a = -std::f32::consts::FRAC_PI_2
            + std::f32::consts::PI * (k as f32 + 0.5) / segments as f32;
        let inside = centre + Vec3::new(a.cos() * r_mid, a.sin() * r_mid, 0.0);
        for s in [1.0, -1.0] {
            m.facet_quad(
                [
                    at(r_in, k, s),
                    at(r_out, k, s),
                    at(r_out, k + 1, s),
                    at(r_in, k + 1, s),
                ],
                inside,
                0,
            );
        }
        for r in [r_out, r_in] {
            m.facet_quad(
                [
                    at(r, k, -1.0),
                    at(r, k + 1, -1.0),
                    at(r, k + 1, 1.0),
                    at(r, k, 1.0),
                ],
                inside,
                0,
            );
        }
        if k == 0 || k == segments - 1 {
            let e = if k == 0 { 0 } else { segments };
            m.facet_quad(
                [
                    at(r_in, e, -1.0),
                    at(r_out, e, -1.0),
                    at(r_out, e, 1.0),
                    at(r_in, e, 1.0),
                ],
                inside,
                0,
            );
        }
    }
}
