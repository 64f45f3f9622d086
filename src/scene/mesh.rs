//! `Mesh`: an indexed triangle list in object space with optional per-vertex colours and
//! normals and a part id per vertex (what `tumble` rotates as one body).
//!
//! Owns mesh assembly helpers (appending, orienting, smooth normals, static transforms).
//! Must never project, light or rasterize: that happens per frame in `scene::frame`.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use glam::{Mat4, Vec3};

/// Triangles in object space. Invariant: every index is < `positions.len()`, and
/// `colors`, `normals` (when present) and `part` have one entry per position.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub colors: Option<Vec<Vec3>>,
    pub normals: Option<Vec<Vec3>>,
    /// Connected body each vertex belongs to (0-based, dense).
    pub part: Vec<u32>,
    /// Counter-clockwise as seen from outside: (b - a) x (c - a) points outward.
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    pub fn new() -> Mesh {
        Mesh::default()
    }

    /// Number of parts (bodies); 0 for an empty mesh.
    pub fn part_count(&self) -> u32 {
        self.part.iter().max().map_or(0, |p| p + 1)
    }

    /// Adds a vertex to part `part` and returns its index.
    pub fn vertex(&mut self, p: Vec3, part: u32) -> u32 {
        self.positions.push(p);
        self.part.push(part);
        (self.positions.len() - 1) as u32
    }

    pub fn tri(&mut self, a: u32, b: u32, c: u32) {
        self.triangles.push([a, b, c]);
    }

    /// Adds a triangle with its own three vertices, wound so that its normal points away
    /// from `inside` (faceted solids: each face keeps its own normal).
    pub fn facet(&mut self, a: Vec3, b: Vec3, c: Vec3, inside: Vec3, part: u32) {
        let n = (b - a).cross(c - a);
        let (b, c) = if n.dot(a - inside) >= 0.0 {
            (b, c)
        } else {
            (c, b)
        };
        let i = self.vertex(a, part);
        let j = self.vertex(b, part);
        let k = self.vertex(c, part);
        self.tri(i, j, k);
    }

    /// Adds a quad a b c d (in order around it) as two facets facing away from `inside`.
    pub fn facet_quad(&mut self, q: [Vec3; 4], inside: Vec3, part: u32) {
        self.facet(q[0], q[1], q[2], inside, part);
        self.facet(q[0], q[2], q[3], inside, part);
    }

    /// Appends `other`, renumbering its parts after ours.
    pub fn append(&mut self, other: Mesh) {
        let base = self.positions.len() as u32;
        let parts = self.part_count();
        let n_self = self.positions.len();
        let n_other = other.positions.len();
        self.colors = merge_attr(self.colors.take(), n_self, other.colors, n_other, Vec3::ONE);
        self.normals = merge_attr(self.normals.take(), n_self, other.normals, n_other, Vec3::Y);
        self.positions.extend(other.positions);
        self.part.extend(other.part.iter().map(|p| p + parts));
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + base)));
    }

    /// Applies a static transform: positions by `m`, normals by its inverse transpose.
    pub fn transform(&mut self, m: Mat4) {
        for p in &mut self.positions {
            *p = m.transform_point3(*p);
        }
        if let Some(normals) = &mut self.normals {
            let nm = m.inverse().transpose();
            for n in normals.iter_mut() {
                *n = nm.transform_vector3(*n).normalize_or_zero();
            }
        }
        // A mirroring transform turns the winding inside out; keep triangles facing outward.
        if m.determinant() < 0.0 {
            for t in &mut self.triangles {
                t.swap(1, 2);
            }
        }
    }

    /// Area-weighted average of the face normals at each vertex (what Gouraud shading uses
    /// when the source gave no normals).
    pub fn smooth_normals(&self) -> Vec<Vec3> {
        let mut acc = vec![Vec3::ZERO; self.positions.len()];
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| self.positions[i as usize]);
            let n = (b - a).cross(c - a);
            for i in t {
                acc[*i as usize] += n;
            }
        }
        acc.into_iter().map(|n| n.normalize_or(Vec3::Y)).collect()
    }

    /// Axis-aligned bounding box, or None for a mesh without vertices.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let first = *self.positions.first()?;
        Some(
            self.positions
                .iter()
                .fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))),
        )
    }
}

fn merge_attr(
    a: Option<Vec<Vec3>>,
    na: usize,
    b: Option<Vec<Vec3>>,
    nb: usize,
    fill: Vec3,
) -> Option<Vec<Vec3>> {
    match (a, b) {
        (None, None) => None,
        (a, b) => {
            let mut v = a.unwrap_or_else(|| vec![fill; na]);
            v.extend(b.unwrap_or_else(|| vec![fill; nb]));
            Some(v)
        }
    }
}

/// Deterministic hash of a seed and two integers to a uniform number in [0, 1); used where a
/// value must depend only on *which* edge or cell it belongs to, not on visiting order.
pub fn hash01(seed: u64, a: u64, b: u64) -> f32 {
    let mut x =
        seed ^ a.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ b.wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    // splitmix64 finalizer
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^= x >> 31;
    (x >> 40) as f32 / (1u64 << 24) as f32
}

/// Multiplicative hashing for integer keys: the scene's maps (vertex welding, edge midpoints,
/// refinement adjacency) hold millions of small keys and are only looked up, never iterated
/// into an output, so a fast fixed hash is safe; it keeps the 806,640-triangle shell quick.
#[derive(Default)]
pub struct IntHasher(u64);

impl Hasher for IntHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.write_u64(*b as u64);
        }
    }
    fn write_u32(&mut self, x: u32) {
        self.write_u64(x as u64);
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7C_C1_B7_27_22_0A_95);
    }
}

pub type FastMap<K, V> = HashMap<K, V, BuildHasherDefault<IntHasher>>;
