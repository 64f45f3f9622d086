//! Generators: triangle counts follow their stated formulas, output is a pure function of
//! parameters and seed, closed solids face outward, and `triangles` refinement is exact,
//! conforming and area-preserving. Also the frame pipeline: winding convention and speed.

use crate::common;

use std::collections::BTreeMap;
use std::path::Path;

use glam::Vec3;
use sortsim::scene::gen::{build, GenContext};
use sortsim::scene::mesh::Mesh;
use sortsim::scene::refine::refine_to;
use sortsim::scene::stats::geometric;
use sortsim::scene::Scene;
use sortsim::spec::scene::GeneratorSpec as G;

const CTX: GenContext = GenContext {
    width: 640,
    height: 512,
};

fn count(g: G) -> usize {
    build(&g, CTX).triangles.len()
}

#[test]
fn triangle_counts_follow_the_stated_formulas() {
    // SPD tetra: 4^SF tetrahedra of 4 triangles.
    for sf in 0..5 {
        assert_eq!(count(G::SpdTetra { size_factor: sf }), 4usize.pow(sf + 1));
    }
    assert_eq!(count(G::Gears { grid: 3, teeth: 20 }), 9 * 16 * 20);
    assert_eq!(
        count(G::Mountain {
            levels: 4,
            roughness: 0.5,
            seed: 1
        }),
        2 * 4usize.pow(4)
    );
    assert_eq!(
        count(G::UvSphere {
            rings: 10,
            segments: 12
        }),
        2 * 12 * 9
    );
    assert_eq!(
        count(G::Head {
            rings: 192,
            segments: 156,
            seed: 1
        }),
        59_592
    );
    assert_eq!(
        count(G::IcosaShell {
            frequency: 7,
            bump: 0.05,
            layers: 1,
            layer_gap: 0.0,
        }),
        20 * 49
    );
    assert_eq!(
        count(G::Terrain {
            cols: 319,
            rows: 255,
            relief: 0.2,
            seed: 5
        }),
        162_690
    );
    assert_eq!(
        count(G::LetterB {
            segments: 47,
            depth: 0.2
        }),
        56 + 16 * 47
    );
    assert_eq!(
        count(G::RandomTetrahedra {
            count: 500,
            size: 0.1,
            seed: 1
        }),
        2000
    );
    assert_eq!(
        count(G::SphereLattice {
            count: [2, 3, 1],
            radius: 0.1,
            rings: 5,
            segments: 6
        }),
        6 * 2 * 6 * 4
    );
    assert_eq!(count(G::Plane), 2);
    assert_eq!(count(G::BigTriangle), 1);
    let scatter = G::ScreenScatter {
        count: 1000,
        mean_area_px: 20.0,
        sigma: 1.0,
        seed: 3,
        background_fraction: 0.2,
        footprint: 1.0,
    };
    assert_eq!(count(scatter), 1000);
    // Teapot: 2 n^2 per patch, less the triangles collapsed at the lid knob and bottom centre
    // (8 patches with a degenerate edge, n per patch).
    for n in [4, 13] {
        assert_eq!(
            count(G::Teapot { n }),
            64 * n as usize * n as usize - 8 * n as usize,
            "n = {n}"
        );
    }
}

#[test]
fn generators_are_deterministic_per_seed_and_differ_across_seeds() {
    let seeded: Vec<fn(u64) -> G> = vec![
        |s| G::Mountain {
            levels: 4,
            roughness: 0.5,
            seed: s,
        },
        |s| G::RandomTetrahedra {
            count: 50,
            size: 0.1,
            seed: s,
        },
        |s| G::Head {
            rings: 40,
            segments: 40,
            seed: s,
        },
        |s| G::Terrain {
            cols: 20,
            rows: 10,
            relief: 0.2,
            seed: s,
        },
        |s| G::ScreenScatter {
            count: 100,
            mean_area_px: 30.0,
            sigma: 0.8,
            seed: s,
            background_fraction: 0.0,
            footprint: 1.0,
        },
    ];
    for make in seeded {
        let a = build(&make(1), CTX);
        assert_eq!(
            a,
            build(&make(1), CTX),
            "{:?}: same seed, same vertices",
            make(1)
        );
        assert_ne!(
            a.positions,
            build(&make(2), CTX).positions,
            "{:?}: another seed, other vertices",
            make(1)
        );
    }
}

#[test]
fn scenes_are_deterministic_frame_by_frame() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/p000-tetra-500.json");
    let (a, b) = (Scene::load(&file).unwrap(), Scene::load(&file).unwrap());
    for n in [0, 7, 19] {
        assert_eq!(a.frame(n).unwrap(), b.frame(n).unwrap(), "frame {n}");
    }
    assert_ne!(
        a.frame(0).unwrap().vertices,
        a.frame(1).unwrap().vertices,
        "tumbling moves the tetrahedra"
    );
}

/// Six times the signed volume; positive when triangles wind counter-clockwise seen from outside.
fn volume6(m: &Mesh) -> f32 {
    m.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            a.dot(b.cross(c))
        })
        .sum()
}

#[test]
fn closed_solids_face_outward_and_height_fields_face_up() {
    for g in [
        G::SpdTetra { size_factor: 2 },
        G::Gears { grid: 2, teeth: 10 },
        G::UvSphere {
            rings: 8,
            segments: 8,
        },
        G::Head {
            rings: 30,
            segments: 30,
            seed: 1,
        },
        G::IcosaShell {
            frequency: 4,
            bump: 0.05,
            layers: 3,
            layer_gap: 0.1,
        },
        G::LetterB {
            segments: 8,
            depth: 0.2,
        },
        G::RandomTetrahedra {
            count: 20,
            size: 0.2,
            seed: 4,
        },
        G::Teapot { n: 6 },
        G::SphereLattice {
            count: [2, 2, 2],
            radius: 0.2,
            rings: 6,
            segments: 6,
        },
    ] {
        let m = build(&g, CTX);
        assert!(volume6(&m) > 0.0, "{g:?} winds inward");
        // Every part of a faceted solid is closed: its signed volume is positive too.
    }
    for g in [
        G::Plane,
        G::BigTriangle,
        G::Mountain {
            levels: 3,
            roughness: 0.3,
            seed: 1,
        },
        G::Terrain {
            cols: 8,
            rows: 8,
            relief: 0.2,
            seed: 1,
        },
    ] {
        let m = build(&g, CTX);
        let up: f32 = m
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                (b - a).cross(c - a).y
            })
            .sum();
        assert!(up > 0.0, "{g:?} faces down");
    }
}

/// Directed edges keyed by endpoint positions: in a closed conforming mesh every edge (a, b)
/// has exactly one twin (b, a).
fn unmatched_edges(m: &Mesh) -> usize {
    let key = |p: Vec3| p.to_array().map(f32::to_bits);
    let mut edges: BTreeMap<([u32; 3], [u32; 3]), i32> = BTreeMap::new();
    for t in &m.triangles {
        for k in 0..3 {
            let (a, b) = (
                key(m.positions[t[k] as usize]),
                key(m.positions[t[(k + 1) % 3] as usize]),
            );
            if a < b {
                *edges.entry((a, b)).or_default() += 1;
            } else {
                *edges.entry((b, a)).or_default() -= 1;
            }
        }
    }
    edges.values().filter(|v| **v != 0).count()
}

/// Unmatched edges with a mesh vertex at their midpoint (where refinement puts new vertices):
/// T-junctions.
fn t_junctions(m: &Mesh) -> usize {
    let key = |p: Vec3| p.to_array().map(f32::to_bits);
    let vertices: std::collections::BTreeSet<[u32; 3]> =
        m.positions.iter().map(|p| key(*p)).collect();
    let mut edges: BTreeMap<([u32; 3], [u32; 3]), (i32, Vec3)> = BTreeMap::new();
    for t in &m.triangles {
        for k in 0..3 {
            let (pa, pb) = (
                m.positions[t[k] as usize],
                m.positions[t[(k + 1) % 3] as usize],
            );
            let (a, b) = (key(pa), key(pb));
            let mid = (pa + pb) * 0.5;
            let e = edges.entry((a.min(b), a.max(b))).or_insert((0, mid));
            e.0 += if a < b { 1 } else { -1 };
        }
    }
    edges
        .values()
        .filter(|(n, mid)| *n != 0 && vertices.contains(&key(*mid)))
        .count()
}

#[test]
fn refinement_is_exact_conforming_and_keeps_area() {
    let area = |m: &Mesh| -> f64 {
        m.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                (b - a).cross(c - a).length() as f64 * 0.5
            })
            .sum()
    };
    for g in [
        G::UvSphere {
            rings: 12,
            segments: 16,
        },
        G::SpdTetra { size_factor: 2 },
        G::Head {
            rings: 20,
            segments: 24,
            seed: 3,
        },
    ] {
        let base = build(&g, CTX);
        assert_eq!(unmatched_edges(&base), 0, "{g:?} is closed");
        for extra in [2, 100, 2 * base.triangles.len()] {
            let mut m = base.clone();
            refine_to(&mut m, base.triangles.len() + extra).unwrap();
            assert_eq!(m.triangles.len(), base.triangles.len() + extra);
            assert_eq!(
                unmatched_edges(&m),
                0,
                "{g:?} + {extra}: no T-junctions for an even count"
            );
            assert!(
                (area(&m) - area(&base)).abs() < 1e-4 * area(&base),
                "{g:?}: area kept"
            );
            assert!(volume6(&m) > 0.0, "{g:?}: still faces outward");
        }
        // An odd count on a closed surface leaves exactly one T-junction.
        let mut m = base.clone();
        refine_to(&mut m, base.triangles.len() + 1).unwrap();
        assert_eq!(m.triangles.len(), base.triangles.len() + 1);
        assert_eq!(t_junctions(&m), 1, "{g:?}");
        let mut m = base.clone();
        assert_eq!(
            refine_to(&mut m, base.triangles.len() - 1),
            Err(base.triangles.len())
        );
    }
    // Open meshes take odd counts without T-junctions: a boundary edge is split alone, which
    // adds exactly one unmatched (boundary) edge and nothing else.
    for g in [
        G::Plane,
        G::Terrain {
            cols: 6,
            rows: 5,
            relief: 0.2,
            seed: 2,
        },
        G::Mountain {
            levels: 2,
            roughness: 0.3,
            seed: 4,
        },
    ] {
        let base = build(&g, CTX);
        let open = unmatched_edges(&base);
        for extra in [1, 5, 37] {
            let mut m = base.clone();
            refine_to(&mut m, base.triangles.len() + extra).unwrap();
            assert_eq!(m.triangles.len(), base.triangles.len() + extra);
            assert!(
                (area(&m) - area(&base)).abs() < 1e-4 * area(&base),
                "{g:?}: area kept"
            );
            let boundary_splits = unmatched_edges(&m) - open;
            assert!(
                boundary_splits <= extra,
                "{g:?} + {extra}: {boundary_splits} new unmatched edges"
            );
            assert_eq!(
                boundary_splits % 2,
                extra % 2,
                "{g:?} + {extra}: a T-junction would add 3"
            );
        }
    }
}

/// The winding convention of `FrameGeometry`: outward faces of a sphere in front of the
/// camera are front-facing, about half of all from far away, and none seen from inside.
#[test]
fn outward_faces_are_front_facing_under_perspective() {
    let spec = r#"{ "resolution": [200, 200], "camera": { "kind": "perspective", "eye": [0, 0, 40], "target": [0, 0, 0], "fov_deg": 4, "near": 0.1, "far": 100 },
                   "geometry": [ { "generator": { "kind": "uv-sphere", "rings": 20, "segments": 20 } } ] }"#;
    let path = common::scratch("winding.json");
    std::fs::write(&path, spec).unwrap();
    let frame = Scene::load(&path).unwrap().frame(0).unwrap();
    let s = geometric(&frame);
    let half = s.triangles_in as f64 / 2.0;
    assert!((s.front_facing as f64 - half).abs() < 0.15 * half, "{s:?}");
    assert_eq!(
        s.on_screen, s.front_facing,
        "culling on: only front faces are drawn"
    );
    std::fs::write(
        &path,
        spec.replace("[0, 0, 40]", "[0, 0, 0.5]")
            .replace("\"fov_deg\": 4,", "\"fov_deg\": 60,"),
    )
    .unwrap();
    let inside = geometric(&Scene::load(&path).unwrap().frame(0).unwrap());
    assert_eq!(
        inside.front_facing, 0,
        "from inside every face is a back face: {inside:?}"
    );
}

/// The largest stand-in (paper 002's polio shell) has the paper's 806,640 triangles in every
/// frame. (How long building it takes is measured in benches/scene.rs, not here.)
#[test]
fn polio_shell_has_the_papers_triangle_count() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/polio-standin.json");
    let scene = Scene::load(&file).unwrap();
    assert_eq!(scene.frame(37).unwrap().triangles.len(), 806_640);
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]

        /// Any even number of extra triangles on a closed UV sphere: exact, conforming,
        /// outward; any number on an open height field: exact, no T-junction.
        #[test]
        fn refinement_hits_any_count(rings in 3u32..12, segments in 3u32..12, extra in 0usize..400, seed in 0u64..1000) {
            let sphere = build(&G::UvSphere { rings, segments }, CTX);
            let mut m = sphere.clone();
            let target = sphere.triangles.len() + 2 * extra;
            refine_to(&mut m, target).unwrap();
            prop_assert_eq!(m.triangles.len(), target);
            prop_assert_eq!(unmatched_edges(&m), 0);
            prop_assert!(volume6(&m) > 0.0);

            let field = build(&G::Terrain { cols: rings, rows: segments, relief: 0.3, seed }, CTX);
            let mut m = field.clone();
            let target = field.triangles.len() + extra;
            refine_to(&mut m, target).unwrap();
            prop_assert_eq!(m.triangles.len(), target);
            prop_assert_eq!(t_junctions(&m), 0);
        }
    }
}
