//! Paper 000's test scenes: N regular tetrahedra scattered at random in the cube [-1, 1]^3,
//! each randomly oriented (500 and 3000 of them, rotating randomly on a 512x512 screen).
//! 4 triangles per tetrahedron, one part each so `tumble` turns them individually.
//!
//! Owns this shape only. Must never place or light it.

use glam::{Quat, Vec3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::spd_tetra::tetrahedron;
use crate::scene::mesh::Mesh;

pub fn build(count: u32, size: f32, seed: u64) -> Mesh {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut m = Mesh::new();
    // Regular tetrahedron with edge `size`: alternate cube corners scaled by size / (2 sqrt 2).
    let k = size / (2.0 * std::f32::consts::SQRT_2);
    let unit = [
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(-1.0, -1.0, 1.0),
        Vec3::new(-1.0, 1.0, -1.0),
        Vec3::new(1.0, -1.0, -1.0),
    ];
    for _ in 0..count {
        let centre = Vec3::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        );
        let rot = random_rotation(&mut rng);
        tetrahedron(&mut m, unit.map(|p| centre + rot * (p * k)));
    }
    m
}

/// A uniformly distributed rotation (Shoemake's method from three uniforms).
pub fn random_rotation(rng: &mut impl Rng) -> Quat {
    let (u1, u2, u3): (f32, f32, f32) = (rng.gen(), rng.gen(), rng.gen());
    let tau = std::f32::consts::TAU;
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    Quat::from_xyzw(
        a * (tau * u2).sin(),
        a * (tau * u2).cos(),
        b * (tau * u3).sin(),
        b * (tau * u3).cos(),
    )
    .normalize()
}
