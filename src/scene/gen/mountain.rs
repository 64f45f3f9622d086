//! SPD-style `mountain`: fractal subdivision. The square [-1, 1]^2 (in xz, two triangles) is
//! subdivided `levels` times, each triangle into four through its edge midpoints, and every
//! new midpoint is raised by a random amount that halves at each level (midpoint
//! displacement, Fournier-Fussell-Carpenter). 2 * 4^levels triangles, facing +y. Heights
//! depend only on the edge a midpoint splits and the seed, so shared edges never crack.
//! Paper 001's Mountain scene also has a large ground, added by the scene as its own object.
//!
//! Owns this shape only. Must never place or light it.

use glam::Vec3;

use crate::scene::mesh::{hash01, FastMap, Mesh};

pub fn build(levels: u32, roughness: f32, seed: u64) -> Mesh {
    let mut m = Mesh::new();
    let v = [(-1.0, -1.0), (-1.0, 1.0), (1.0, 1.0), (1.0, -1.0)]
        .map(|(x, z)| m.vertex(Vec3::new(x, 0.0, z), 0));
    let mut tris = vec![[v[0], v[1], v[2]], [v[0], v[2], v[3]]];
    // A peak in the middle so the mountain is a mountain and not a rough plain.
    let mut scale = roughness;
    for level in 0..levels {
        let mut mids: FastMap<(u32, u32), u32> = FastMap::default();
        let mut next = Vec::with_capacity(tris.len() * 4);
        for t in &tris {
            let [a, b, c] = *t;
            let ab = midpoint(&mut m, &mut mids, a, b, scale, seed, level);
            let bc = midpoint(&mut m, &mut mids, b, c, scale, seed, level);
            let ca = midpoint(&mut m, &mut mids, c, a, scale, seed, level);
            next.extend_from_slice(&[[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        tris = next;
        scale *= 0.5;
    }
    // Keep the rim at ground level and the base broad: fade heights towards the edge.
    for p in &mut m.positions {
        let edge = 1.0 - p.x.abs().max(p.z.abs());
        p.y = (p.y + roughness * 1.5 * edge) * edge.sqrt();
    }
    m.triangles = tris;
    m
}

fn midpoint(
    m: &mut Mesh,
    mids: &mut FastMap<(u32, u32), u32>,
    a: u32,
    b: u32,
    scale: f32,
    seed: u64,
    level: u32,
) -> u32 {
    let key = (a.min(b), a.max(b));
    if let Some(i) = mids.get(&key) {
        return *i;
    }
    let p = (m.positions[a as usize] + m.positions[b as usize]) * 0.5;
    // Sum of two uniforms: a cheap bell-shaped displacement in [-scale, scale].
    let r = hash01(seed ^ level as u64, key.0 as u64, key.1 as u64)
        + hash01(!seed, key.0 as u64, key.1 as u64)
        - 1.0;
    let i = m.vertex(p + Vec3::Y * (r * scale), 0);
    mids.insert(key, i);
    i
}
