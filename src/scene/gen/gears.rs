//! SPD-style `gears`: a grid x grid array of meshing spur gears lying flat (axis +y), each a
//! toothed disk with trapezoidal teeth. A gear with t teeth has an outline of
//! 4t points: top and bottom faces are fans of 4t triangles each, the rim 4t quads, so
//! 16t triangles per gear (thickness 0.2 x pitch radius). Paper 001's Gears image stands
//! on a large floor; the scene adds it as a separate `plane` or `big-triangle` object,
//! because that one large primitive is what matters for its load balancing. Re-implemented
//! from the description "meshing gears", not from SPD's source: tooth shape and layout are
//! this file's own.
//!
//! Owns this shape only. Must never place or light it.

use glam::Vec3;

use crate::scene::mesh::Mesh;

/// Gears fill [-1, 1]^2 in xz; neighbours mesh because their pitch circles touch and every
/// other gear is turned by half a tooth.
pub fn build(grid: u32, teeth: u32) -> Mesh {
    let mut m = Mesh::new();
    let pitch = 1.0 / grid as f32; // radius of the pitch circle
    for j in 0..grid {
        for i in 0..grid {
            let centre = Vec3::new(
                -1.0 + pitch * (2 * i + 1) as f32,
                0.0,
                -1.0 + pitch * (2 * j + 1) as f32,
            );
            let phase = if (i + j) % 2 == 1 { 0.5 } else { 0.0 };
            gear(&mut m, centre, pitch, teeth, phase);
        }
    }
    m
}

fn gear(m: &mut Mesh, centre: Vec3, pitch: f32, teeth: u32, phase: f32) {
    let part = m.part_count();
    let depth = pitch * 2.0 * std::f32::consts::PI / teeth as f32 * 0.4; // tooth height
    let (r_root, r_tip) = (pitch - depth * 0.5, pitch + depth * 0.5);
    let half = 0.1 * pitch;
    let outline: Vec<Vec3> = (0..teeth * 4)
        .map(|k| {
            // Four points per tooth: root, tip, tip, root at quarter steps of the tooth angle.
            let a = std::f32::consts::TAU
                * ((k / 4) as f32 + phase + [0.0, 0.2, 0.5, 0.7][(k % 4) as usize])
                / teeth as f32;
            let r = if k % 4 == 1 || k % 4 == 2 {
                r_tip
            } else {
                r_root
            };
            Vec3::new(a.cos() * r, 0.0, -a.sin() * r)
        })
        .collect();
    let up = Vec3::Y * half;
    let n = outline.len();
    for k in 0..n {
        let (p, q) = (centre + outline[k], centre + outline[(k + 1) % n]);
        // Top and bottom fans from the axis; the rim quad between the two faces.
        m.facet(centre + up, p + up, q + up, centre, part);
        m.facet(centre - up, q - up, p - up, centre, part);
        m.facet_quad([p - up, q - up, q + up, p + up], centre, part);
    }
}
