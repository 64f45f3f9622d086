//! Culling in advance, as paper 001's input files were made: its scenes came as screen-space
//! triangles "with backfaces culling performed", and its triangle counts (Teapot 11,666, ...)
//! count those. With `precull` a single-frame scene keeps only the triangles frame 0 would
//! draw (front-facing, with some area on screen) before `triangles` makes counts exact, so
//! every triangle handed to the rasterizer is drawn, as in the paper.
//!
//! Owns that pruning. Must never change the triangles it keeps.

use glam::Vec3;

use super::mesh::Mesh;
use super::stats::drawn_mask;
use super::{FrameGeometry, ToClip};
use crate::raster::Vertex;

/// The view frame 0 is seen from.
pub(super) struct Precull {
    pub to_clip: ToClip,
    pub width: u32,
    pub height: u32,
}

/// Drops the triangles of `mesh` (in world space) that frame 0 would not draw, and the
/// vertices no kept triangle uses.
pub(super) fn prune(mesh: &mut Mesh, view: &Precull) {
    let frame = FrameGeometry {
        width: view.width,
        height: view.height,
        vertices: mesh
            .positions
            .iter()
            .map(|p| Vertex {
                clip: view.to_clip.apply(*p),
                color: Vec3::ZERO,
            })
            .collect(),
        triangles: std::mem::take(&mut mesh.triangles),
        cull_backfaces: true,
        background: [0; 3],
    };
    let keep = drawn_mask(&frame);
    let kept: Vec<[u32; 3]> = frame
        .triangles
        .iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(t, _)| *t)
        .collect();
    mesh.triangles = kept;
    compact(mesh);
}

/// Renumbers vertices so that only used ones remain, in their original order.
fn compact(mesh: &mut Mesh) {
    let mut new_index = vec![u32::MAX; mesh.positions.len()];
    let mut order = Vec::new();
    for t in &mesh.triangles {
        for &i in t {
            if new_index[i as usize] == u32::MAX {
                new_index[i as usize] = 0; // marked; numbered below in index order
            }
        }
    }
    for (i, slot) in new_index.iter_mut().enumerate() {
        if *slot != u32::MAX {
            *slot = order.len() as u32;
            order.push(i);
        }
    }
    mesh.positions = pick(&mesh.positions, &order);
    mesh.colors = mesh.colors.as_ref().map(|c| pick(c, &order));
    mesh.normals = mesh.normals.as_ref().map(|n| pick(n, &order));
    mesh.part = order.iter().map(|&i| mesh.part[i]).collect();
    for t in &mut mesh.triangles {
        *t = t.map(|i| new_index[i as usize]);
    }
}

fn pick(values: &[Vec3], order: &[usize]) -> Vec<Vec3> {
    order.iter().map(|&i| values[i]).collect()
}
