//! Exact triangle counts: refines a mesh to exactly N triangles by bisecting the longest edge
//! of the largest triangle, together with the triangle across that edge, until the count is
//! reached. This is how stand-in scenes hit the papers' triangle counts exactly while keeping
//! their generators' natural parameters.
//!
//! Owns the refinement only. Must never move existing vertices or change the surface: new
//! vertices lie on existing edges, so areas and silhouettes are unchanged.
//!
//! Splitting both triangles of an edge keeps the mesh conforming (no T-junctions), adding 2
//! triangles; an edge on the boundary adds 1. When exactly one triangle is missing and the
//! largest triangle's edge is shared, that one triangle is split alone, leaving a single
//! T-junction (a closed surface can only have an even triangle count).

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use glam::Vec3;

use super::mesh::{FastMap, Mesh};

/// Refines `mesh` to exactly `target` triangles. Returns the mesh's own count as the error
/// when it already has more than `target`.
pub fn refine_to(mesh: &mut Mesh, target: usize) -> Result<(), usize> {
    let base = mesh.triangles.len();
    if base > target {
        return Err(base);
    }
    if base == target || base == 0 {
        return if base == target { Ok(()) } else { Err(0) };
    }
    Refiner::new(mesh).run(target);
    Ok(())
}

/// Edge key: the two endpoints' position ids (vertices at bit-identical positions share one
/// id, so faceted meshes with unshared vertices still find their neighbours).
type EdgeKey = (u32, u32);

const NONE: u32 = u32::MAX;
const MANY: u32 = u32::MAX - 1;

struct Refiner<'a> {
    mesh: &'a mut Mesh,
    pid: Vec<u32>,
    edges: FastMap<EdgeKey, [u32; 2]>,
    heap: BinaryHeap<Entry>,
}

#[derive(PartialEq)]
struct Entry {
    area: f32,
    tri: u32,
}
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Entry {
    // Largest area first; ties go to the lower index so the result is deterministic.
    fn cmp(&self, other: &Self) -> Ordering {
        self.area
            .total_cmp(&other.area)
            .then_with(|| other.tri.cmp(&self.tri))
    }
}

impl<'a> Refiner<'a> {
    fn new(mesh: &'a mut Mesh) -> Refiner<'a> {
        let n = mesh.positions.len();
        let mut first: FastMap<[u32; 3], u32> =
            FastMap::with_capacity_and_hasher(n, Default::default());
        let pid = mesh
            .positions
            .iter()
            .enumerate()
            .map(|(i, p)| {
                *first
                    .entry(p.to_array().map(f32::to_bits))
                    .or_insert(i as u32)
            })
            .collect();
        let tris = mesh.triangles.len();
        let edges = FastMap::with_capacity_and_hasher(tris * 3 / 2 + 16, Default::default());
        let mut r = Refiner {
            mesh,
            pid,
            edges,
            heap: BinaryHeap::new(),
        };
        let mut entries = Vec::with_capacity(tris);
        for t in 0..tris as u32 {
            let tri = r.mesh.triangles[t as usize];
            for k in 0..3 {
                r.link(tri[k], tri[(k + 1) % 3], t);
            }
            entries.push(Entry {
                area: r.area(t),
                tri: t,
            });
        }
        // Heapify in O(n) rather than n pushes.
        r.heap = BinaryHeap::from(entries);
        r
    }

    fn key(&self, a: u32, b: u32) -> EdgeKey {
        let (x, y) = (self.pid[a as usize], self.pid[b as usize]);
        (x.min(y), x.max(y))
    }

    fn link(&mut self, a: u32, b: u32, t: u32) {
        let k = self.key(a, b);
        let slot = self.edges.entry(k).or_insert([NONE, NONE]);
        if slot[0] == NONE {
            slot[0] = t;
        } else if slot[1] == NONE {
            slot[1] = t;
        } else {
            slot[1] = MANY; // non-manifold: never split across it
        }
    }

    fn relink(&mut self, a: u32, b: u32, old: u32, new: u32) {
        let k = self.key(a, b);
        if let Some(slot) = self.edges.get_mut(&k) {
            for s in slot.iter_mut() {
                if *s == old {
                    *s = new;
                    return;
                }
            }
        }
    }

    fn unlink(&mut self, a: u32, b: u32) {
        let k = self.key(a, b);
        self.edges.remove(&k);
    }

    fn area(&self, t: u32) -> f32 {
        let [a, b, c] = self.mesh.triangles[t as usize].map(|i| self.mesh.positions[i as usize]);
        (b - a).cross(c - a).length()
    }

    fn push(&mut self, t: u32) {
        let area = self.area(t);
        self.heap.push(Entry { area, tri: t });
    }

    fn run(&mut self, target: usize) {
        while self.mesh.triangles.len() < target {
            let Some(Entry { area, tri }) = self.heap.pop() else {
                return;
            };
            if area != self.area(tri) {
                continue; // stale: this triangle was split since
            }
            let remaining = target - self.mesh.triangles.len();
            let (a, b) = self.longest_edge(tri);
            match self.neighbour(a, b, tri) {
                None => self.split_one(tri, a, b),
                Some(u) if remaining >= 2 => self.split_pair(tri, u, a, b),
                // One triangle short across a shared edge: split a boundary edge instead if
                // the mesh has one, so that only a closed surface ever gets the T-junction.
                Some(_) => match self.largest_boundary_edge() {
                    Some((t, a, b)) => self.split_one(t, a, b),
                    None => self.split_one(tri, a, b),
                },
            }
        }
    }

    /// The boundary edge (used by one triangle only) of the largest triangle that has one.
    fn largest_boundary_edge(&self) -> Option<(u32, u32, u32)> {
        let mut best: Option<(f32, u32, u32, u32)> = None;
        for t in 0..self.mesh.triangles.len() as u32 {
            let v = self.mesh.triangles[t as usize];
            for k in 0..3 {
                let (a, b) = (v[k], v[(k + 1) % 3]);
                let open = self
                    .edges
                    .get(&self.key(a, b))
                    .is_some_and(|slot| slot[1] == NONE);
                let area = self.area(t);
                if open && best.is_none_or(|(best_area, ..)| area > best_area) {
                    best = Some((area, t, a, b));
                }
            }
        }
        best.map(|(_, t, a, b)| (t, a, b))
    }

    /// The longest edge of `t` as a directed edge (a, b) in `t`'s winding.
    fn longest_edge(&self, t: u32) -> (u32, u32) {
        let v = self.mesh.triangles[t as usize];
        let p = |i: usize| self.mesh.positions[v[i] as usize];
        let mut best = 0;
        let mut len = -1.0;
        for k in 0..3 {
            let l = (p((k + 1) % 3) - p(k)).length_squared();
            if l > len {
                len = l;
                best = k;
            }
        }
        (v[best], v[(best + 1) % 3])
    }

    fn neighbour(&self, a: u32, b: u32, t: u32) -> Option<u32> {
        let slot = self.edges.get(&self.key(a, b))?;
        if slot[1] == MANY {
            return None;
        }
        let u = if slot[0] == t { slot[1] } else { slot[0] };
        (u != NONE && u != t).then_some(u)
    }

    /// A new vertex halfway between `a` and `b`, with interpolated attributes. The position is
    /// computed symmetrically so both sides of a shared edge get bit-identical midpoints.
    fn midpoint(&mut self, a: u32, b: u32, pid: Option<u32>) -> u32 {
        let m = &mut *self.mesh;
        let (pa, pb) = (m.positions[a as usize], m.positions[b as usize]);
        m.positions.push((pa + pb) * 0.5);
        let part = m.part[a as usize];
        m.part.push(part);
        if let Some(c) = &mut m.colors {
            c.push((c[a as usize] + c[b as usize]) * 0.5);
        }
        if let Some(n) = &mut m.normals {
            n.push((n[a as usize] + n[b as usize]).normalize_or(Vec3::Y));
        }
        let i = (m.positions.len() - 1) as u32;
        self.pid.push(pid.unwrap_or(i));
        i
    }

    /// Splits triangle `t` at the midpoint m of its edge whose endpoints sit at the positions
    /// of `a` and `b`; with that edge read in `t`'s own winding as (x, y) and apex c, `t`
    /// becomes (x, m, c) and a new triangle (m, y, c), so orientation is kept. Returns m.
    fn split_half(&mut self, t: u32, a: u32, b: u32, m_pid: Option<u32>) -> u32 {
        let (pa, pb) = (self.pid[a as usize], self.pid[b as usize]);
        let v = self.mesh.triangles[t as usize];
        let k = (0..3)
            .find(|&k| {
                let (x, y) = (self.pid[v[k] as usize], self.pid[v[(k + 1) % 3] as usize]);
                (x == pa && y == pb) || (x == pb && y == pa)
            })
            .unwrap_or(0);
        let (x, y, c) = (v[k], v[(k + 1) % 3], v[(k + 2) % 3]);
        let m = self.midpoint(x, y, m_pid);
        let new = self.mesh.triangles.len() as u32;
        self.mesh.triangles[t as usize] = [x, m, c];
        self.mesh.triangles.push([m, y, c]);
        self.relink(y, c, t, new);
        self.link(x, m, t);
        self.link(m, y, new);
        self.link(m, c, t);
        self.link(m, c, new);
        self.push(t);
        self.push(new);
        m
    }

    fn split_one(&mut self, t: u32, a: u32, b: u32) {
        let other = self.neighbour(a, b, t);
        self.unlink(a, b);
        self.split_half(t, a, b, None);
        if let Some(u) = other {
            // The neighbour keeps the long edge (the one T-junction); it stays findable.
            self.link(a, b, u);
        }
    }

    fn split_pair(&mut self, t: u32, u: u32, a: u32, b: u32) {
        self.unlink(a, b);
        let m = self.split_half(t, a, b, None);
        let mpid = self.pid[m as usize];
        self.split_half(u, a, b, Some(mpid));
    }
}
