//! Procedural generators, one file each, re-implemented from their published descriptions
//! (Haines' Standard Procedural Databases, Newell's teapot) or written as stand-ins for the
//! papers' unavailable models. Every generator is a pure function of its parameters and seed
//! (ChaCha or a fixed hash), so the same spec gives bit-identical vertices.
//!
//! Owns geometry creation in object space. Must never place, project, light or rasterize.

mod gears;
mod head;
mod icosa_shell;
mod letter_b;
mod mountain;
mod primitives;
mod random_tetrahedra;
mod screen_scatter;
mod spd_tetra;
mod teapot;
mod teapot_data;
mod terrain;

use super::mesh::Mesh;
use crate::spec::scene::GeneratorSpec;

/// What a generator may know about the scene: only the image size (screen-space generators
/// place geometry in pixels).
#[derive(Clone, Copy, Debug)]
pub struct GenContext {
    pub width: u32,
    pub height: u32,
}

/// Builds the mesh a generator spec describes (already validated).
pub fn build(spec: &GeneratorSpec, ctx: GenContext) -> Mesh {
    match spec {
        GeneratorSpec::SpdTetra { size_factor } => spd_tetra::build(*size_factor),
        GeneratorSpec::Gears { grid, teeth } => gears::build(*grid, *teeth),
        GeneratorSpec::Mountain {
            levels,
            roughness,
            seed,
        } => mountain::build(*levels, *roughness, *seed),
        GeneratorSpec::Teapot { n } => teapot::build(*n),
        GeneratorSpec::Plane => primitives::plane(),
        GeneratorSpec::BigTriangle => primitives::big_triangle(),
        GeneratorSpec::UvSphere { rings, segments } => primitives::uv_sphere(*rings, *segments, 0),
        GeneratorSpec::Torus {
            rings,
            segments,
            minor,
        } => primitives::torus(*rings, *segments, *minor),
        GeneratorSpec::SphereLattice {
            count,
            radius,
            rings,
            segments,
        } => primitives::sphere_lattice(*count, *radius, *rings, *segments),
        GeneratorSpec::LetterB { segments, depth } => letter_b::build(*segments, *depth),
        GeneratorSpec::RandomTetrahedra { count, size, seed } => {
            random_tetrahedra::build(*count, *size, *seed)
        }
        GeneratorSpec::Head {
            rings,
            segments,
            seed,
        } => head::build(*rings, *segments, *seed),
        GeneratorSpec::IcosaShell {
            frequency,
            bump,
            layers,
            layer_gap,
        } => icosa_shell::build(*frequency, *bump, *layers, *layer_gap),
        GeneratorSpec::Terrain {
            cols,
            rows,
            relief,
            seed,
        } => terrain::build(*cols, *rows, *relief, *seed),
        GeneratorSpec::ScreenScatter {
            count,
            mean_area_px,
            sigma,
            seed,
            background_fraction,
            footprint,
        } => screen_scatter::build(
            screen_scatter::Scatter {
                count: *count,
                mean_area_px: *mean_area_px,
                sigma: *sigma,
                seed: *seed,
                background_fraction: *background_fraction,
                footprint: *footprint,
            },
            ctx,
        ),
    }
}
