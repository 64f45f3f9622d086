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

/// How many triangles the generator `spec` makes: known before a vertex is made, so that a
/// scene too large for the host is refused rather than built (`Scene::from_spec`). Exact but
/// for the teapot, whose patches lose the triangles that collapse at its poles, and the screen
/// scatter, whose background quad (when it has one) may replace a triangle: at most those.
pub fn triangles_at_most(spec: &GeneratorSpec) -> u64 {
    let sphere = |rings: u32, segments: u32| 2 * segments as u64 * (rings as u64 - 1);
    match *spec {
        GeneratorSpec::SpdTetra { size_factor } => 4u64.pow(size_factor + 1),
        GeneratorSpec::Gears { grid, teeth } => (grid as u64).pow(2) * 16 * teeth as u64,
        GeneratorSpec::Mountain { levels, .. } => 2 * 4u64.pow(levels),
        GeneratorSpec::Teapot { n } => teapot_data::PATCHES.len() as u64 * 2 * (n as u64).pow(2),
        GeneratorSpec::Plane => 2,
        GeneratorSpec::BigTriangle => 1,
        GeneratorSpec::UvSphere { rings, segments } => sphere(rings, segments),
        GeneratorSpec::Torus {
            rings, segments, ..
        } => 2 * rings as u64 * segments as u64,
        GeneratorSpec::SphereLattice {
            count,
            rings,
            segments,
            ..
        } => count.iter().map(|&c| c as u64).product::<u64>() * sphere(rings, segments),
        // Four blocks of six quads, two bowls of eight triangles a step and a quad at each end.
        GeneratorSpec::LetterB { segments, .. } => 4 * 12 + 2 * (8 * segments as u64 + 4),
        GeneratorSpec::RandomTetrahedra { count, .. } => 4 * count as u64,
        GeneratorSpec::Head {
            rings, segments, ..
        } => sphere(rings, segments),
        GeneratorSpec::IcosaShell {
            frequency, layers, ..
        } => 20 * (frequency as u64).pow(2) * layers.max(1) as u64,
        GeneratorSpec::Terrain { cols, rows, .. } => 2 * cols as u64 * rows as u64,
        GeneratorSpec::ScreenScatter { count, .. } => count as u64 + 2,
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Every generator at a few sizes: the count known beforehand is the count built (at most,
    /// for the teapot and the screen scatter, and then within a few percent).
    #[test]
    fn the_count_known_beforehand_is_the_count_built() {
        use GeneratorSpec as G;
        let ctx = GenContext {
            width: 64,
            height: 48,
        };
        let mut specs = vec![G::Plane, G::BigTriangle];
        for k in [1u32, 2, 3, 5] {
            specs.extend([
                G::SpdTetra { size_factor: k - 1 },
                G::Gears {
                    grid: k,
                    teeth: 4 + k,
                },
                G::Mountain {
                    levels: k,
                    roughness: 0.5,
                    seed: 1,
                },
                G::Teapot { n: k },
                G::UvSphere {
                    rings: k + 1,
                    segments: k + 2,
                },
                G::Torus {
                    rings: k + 2,
                    segments: k + 3,
                    minor: 0.3,
                },
                G::SphereLattice {
                    count: [k, 2, 1],
                    radius: 0.1,
                    rings: k + 1,
                    segments: 3,
                },
                G::LetterB {
                    segments: k + 1,
                    depth: 0.2,
                },
                G::RandomTetrahedra {
                    count: k,
                    size: 0.1,
                    seed: 2,
                },
                G::Head {
                    rings: 7 + k,
                    segments: 8,
                    seed: 3,
                },
                G::IcosaShell {
                    frequency: k,
                    bump: 0.1,
                    layers: k,
                    layer_gap: 0.1,
                },
                G::Terrain {
                    cols: k,
                    rows: k + 1,
                    relief: 1.0,
                    seed: 4,
                },
                G::ScreenScatter {
                    count: 10 * k,
                    mean_area_px: 20.0,
                    sigma: 0.5,
                    seed: 5,
                    background_fraction: if k > 2 { 0.3 } else { 0.0 },
                    footprint: 1.0,
                },
            ]);
        }
        for spec in &specs {
            let built = build(spec, ctx).triangles.len() as u64;
            let known = triangles_at_most(spec);
            match spec {
                G::Teapot { .. } | G::ScreenScatter { .. } => assert!(
                    built <= known && known <= built + built / 8 + 2,
                    "{spec:?}: built {built}, known {known}"
                ),
                _ => assert_eq!(built, known, "{spec:?}"),
            }
        }
    }
}
