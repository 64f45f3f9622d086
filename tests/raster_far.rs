//! Hard geometry against an exact referee: closed fans of thousands of slivers whose outer
//! vertices lie far off screen (3,000 px to a million), every pixel owned by exactly the
//! sliver the exact edge functions of the snapped vertices give it (integer arithmetic in
//! `i128`, the top-left rule), with no clipping plane moving an edge on the way.

use crate::raster_common;

use glam::{Vec3, Vec4};
use raster_common::vp;
use sortsim::raster::*;

/// Records, per pixel, how many fragments reached it and the last primitive that did.
struct OwnerTarget {
    rects: [ScreenRect; 1],
    count: Vec<u32>,
    owner: Vec<u32>,
}

impl OwnerTarget {
    fn new(v: Viewport) -> OwnerTarget {
        OwnerTarget {
            rects: [v.rect()],
            count: vec![0; v.pixels()],
            owner: vec![u32::MAX; v.pixels()],
        }
    }
}

impl Target for OwnerTarget {
    fn rects(&self) -> &[ScreenRect] {
        &self.rects
    }
    fn span(&mut self, _rect: usize, span: &Span<'_>, _c: &mut Counters) {
        let w = self.rects[0].width() as usize;
        for f in span.fragments() {
            let i = span.y() as usize * w + f.x as usize;
            self.count[i] += 1;
            self.owner[i] = span.prim();
        }
    }
}

/// A vertex at pixel `(x, y)` of `v` with clip w = 1 (so the front end's projection is
/// `(x_clip + 1) / 2 * width`, exactly what [`snapped`] repeats).
fn at_pixel(v: Viewport, x: f64, y: f64) -> Vertex {
    let nx = 2.0 * x / f64::from(v.width()) - 1.0;
    let ny = 1.0 - 2.0 * y / f64::from(v.height());
    Vertex {
        clip: Vec4::new(nx as f32, ny as f32, 0.5, 1.0),
        color: Vec3::ONE,
    }
}

/// The snapped screen position of a w = 1 vertex, in 1/256 pixel: the projection of the
/// module doc of `raster::fixed`, rounded half away from zero.
fn snapped(v: Viewport, p: &Vertex) -> (i128, i128) {
    let sx = (f64::from(p.clip.x) + 1.0) * 0.5 * f64::from(v.width());
    let sy = (1.0 - f64::from(p.clip.y)) * 0.5 * f64::from(v.height());
    (
        i128::from(Sub::snap(sx).unwrap().raw()),
        i128::from(Sub::snap(sy).unwrap().raw()),
    )
}

/// The exact referee: which triangle's interior (top-left rule) holds each pixel centre,
/// from the snapped vertices, with every edge function in `i128`. `None` where none does;
/// a pixel two triangles would both own fails the caller's watertightness check instead.
fn referee(v: Viewport, verts: &[Vertex], tris: &[[u32; 3]]) -> Vec<Option<u32>> {
    let (w, h) = (i128::from(v.width()), i128::from(v.height()));
    let mut owner = vec![None; v.pixels()];
    for (prim, t) in tris.iter().enumerate() {
        let mut p = t.map(|i| snapped(v, &verts[i as usize]));
        let area2 = (p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[1].1 - p[0].1) * (p[2].0 - p[0].0);
        if area2 == 0 {
            continue;
        }
        if area2 < 0 {
            p.swap(1, 2);
        }
        let edges: Vec<(i128, i128, i128, i128, i128)> = (0..3)
            .map(|i| {
                let (a, b) = (p[i], p[(i + 1) % 3]);
                let (dx, dy) = (b.0 - a.0, b.1 - a.1);
                let bias = if dy < 0 || (dy == 0 && dx > 0) { 0 } else { 1 };
                (a.0, a.1, dx, dy, bias)
            })
            .collect();
        let lo = |k: usize| {
            p.iter()
                .map(|q| if k == 0 { q.0 } else { q.1 })
                .min()
                .unwrap()
        };
        let hi = |k: usize| {
            p.iter()
                .map(|q| if k == 0 { q.0 } else { q.1 })
                .max()
                .unwrap()
        };
        let (x0, x1) = ((lo(0) / 256 - 1).max(0), (hi(0) / 256 + 1).min(w - 1));
        let (y0, y1) = ((lo(1) / 256 - 1).max(0), (hi(1) / 256 + 1).min(h - 1));
        for py in y0..=y1 {
            for px in x0..=x1 {
                let (cx, cy) = (px * 256 + 128, py * 256 + 128);
                let inside = edges
                    .iter()
                    .all(|&(ax, ay, dx, dy, bias)| dx * (cy - ay) - dy * (cx - ax) - bias >= 0);
                if inside {
                    owner[(py * w + px) as usize] = Some(prim as u32);
                }
            }
        }
    }
    owner
}

/// Draws `tris` with no face culled (a fan's slivers face both ways on screen).
fn draw_both_faces(
    v: Viewport,
    verts: &[Vertex],
    tris: &[[u32; 3]],
    t: &mut impl Target,
) -> Counters {
    let options = RasterOptions {
        cull: CullMode::None,
    };
    draw_mesh(verts, tris, v, &options, t)
}

/// A closed fan of `n` slivers around the screen's centre, its rim a circle of `radius` px.
fn fan(v: Viewport, n: usize, radius: f64) -> (Vec<Vertex>, Vec<[u32; 3]>) {
    let (cx, cy) = (
        f64::from(v.width()) / 2.0 + 0.37,
        f64::from(v.height()) / 2.0 - 0.21,
    );
    let mut verts = vec![at_pixel(v, cx, cy)];
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        verts.push(at_pixel(v, cx + radius * a.cos(), cy + radius * a.sin()));
    }
    let tris = (0..n as u32)
        .map(|k| [0, 1 + k, 1 + (k + 1) % n as u32])
        .collect();
    (verts, tris)
}

#[test]
fn closed_fans_with_far_rims_match_the_exact_referee() {
    let v = vp(640, 512);
    for (n, radius) in [(5_000, 3_000.0), (5_000, 10_000.0), (2_000, 1.0e6)] {
        let (verts, tris) = fan(v, n, radius);
        let mut target = OwnerTarget::new(v);
        draw_both_faces(v, &verts, &tris, &mut target);
        let twice = target.count.iter().filter(|&&c| c > 1).count();
        let holes = target.count.iter().filter(|&&c| c == 0).count();
        assert_eq!(
            (twice, holes),
            (0, 0),
            "rim at {radius} px: every pixel of the screen inside the fan exactly once"
        );
        let expected = referee(v, &verts, &tris);
        let wrong = target
            .owner
            .iter()
            .zip(&expected)
            .filter(|(got, want)| Some(**got) != **want)
            .count();
        assert_eq!(
            wrong, 0,
            "rim at {radius} px, {n} slivers: pixels whose sliver differs from the exact referee"
        );
    }
}

/// Per pixel, how many triangles covered each of its 16 samples (coverage masks, as the
/// anti-aliasing targets evaluate them on edge pixels).
struct SampleCounter {
    rects: [ScreenRect; 1],
    samples: Vec<(u8, u8)>,
    counts: Vec<[u32; 16]>,
}

impl Target for SampleCounter {
    fn rects(&self) -> &[ScreenRect] {
        &self.rects
    }
    fn sampling(&self) -> Sampling {
        Sampling::Conservative
    }
    fn span(&mut self, _rect: usize, span: &Span<'_>, _c: &mut Counters) {
        let t = span.triangle();
        let w = self.rects[0].width();
        for f in span.fragments() {
            let mask = t.coverage_mask(i64::from(f.x), i64::from(span.y()), &self.samples);
            let cell = &mut self.counts[(span.y() * w + f.x) as usize];
            for (i, c) in cell.iter_mut().enumerate() {
                *c += ((mask >> i) & 1) as u32;
            }
        }
    }
}

#[test]
fn anti_aliased_edges_shared_by_thousands_of_slivers_cover_each_sample_once() {
    // Every sample of the screen lies inside the fan; 20,000 slivers meet at its centre, so
    // the pixels there carry edges of thousands of them, and the rim is far off screen.
    let v = vp(320, 256);
    for radius in [400.0, 50_000.0] {
        let (verts, tris) = fan(v, 20_000, radius);
        let mut target = SampleCounter {
            rects: [v.rect()],
            samples: (0..16)
                .map(|i| (16 + 64 * (i % 4) as u8, 16 + 64 * (i / 4) as u8))
                .collect(),
            counts: vec![[0; 16]; v.pixels()],
        };
        draw_both_faces(v, &verts, &tris, &mut target);
        let wrong = target.counts.iter().flatten().filter(|&&c| c != 1).count();
        assert_eq!(
            wrong, 0,
            "rim at {radius} px: samples not covered exactly once"
        );
    }
}

#[test]
fn a_million_slivers_and_slivers_thinner_than_a_subpixel_are_watertight() {
    // A closed fan of a million slivers (each thinner than 1/256 px within 40 px of the
    // centre) on a 640 x 512 screen: every pixel exactly once.
    let v = vp(640, 512);
    let (verts, tris) = fan(v, 1_000_000, 2_000.0);
    let mut target = OwnerTarget::new(v);
    let c = draw_both_faces(v, &verts, &tris, &mut target);
    assert!(c.triangles_set_up > 900_000, "{c:?}");
    let bad = target.count.iter().filter(|&&k| k != 1).count();
    assert_eq!(bad, 0, "pixels not covered exactly once");
}

#[test]
fn depths_from_1e_minus_7_to_1e7_and_a_ground_behind_the_eye_stay_watertight() {
    // A ground plane of radius 1e6 under an eye 1 unit above it, near 1e-7 and far 1e7: the
    // part behind the eye is cut by the near plane, the horizon is 1e6 units away, and clip
    // w spans 13 decades. No pixel twice; every pixel below the horizon's band covered.
    let v = vp(320, 240);
    let proj = glam::Mat4::perspective_rh(1.0, 320.0 / 240.0, 1e-7, 1e7);
    let n = 400usize;
    let mut verts = vec![Vertex {
        clip: proj * glam::Vec4::new(0.0, -1.0, 0.0, 1.0),
        color: Vec3::ONE,
    }];
    for k in 0..n {
        let a = std::f32::consts::TAU * k as f32 / n as f32;
        verts.push(Vertex {
            clip: proj * glam::Vec4::new(1e6 * a.cos(), -1.0, 1e6 * a.sin(), 1.0),
            color: Vec3::ONE,
        });
    }
    let tris: Vec<[u32; 3]> = (0..n as u32)
        .map(|k| [0, 1 + k, 1 + (k + 1) % n as u32])
        .collect();
    let mut target = OwnerTarget::new(v);
    let c = draw_both_faces(v, &verts, &tris, &mut target);
    assert!(c.clipped > 0, "the ground behind the eye is clipped: {c:?}");
    assert!(target.count.iter().all(|&k| k <= 1), "a pixel drawn twice");
    let w = v.width() as usize;
    let lower_third = &target.count[w * 160..];
    assert!(
        lower_third.iter().all(|&k| k == 1),
        "a hole in the ground below the horizon"
    );
}

#[test]
fn a_fan_reaching_far_off_screen_is_one_image_at_every_processor_count() {
    // 3,000 coloured slivers whose rim projects about 700,000 px out: every algorithm, at
    // 1, 3 and 7 processors, draws the sequential renderer's image.
    let dir = tempfile::tempdir().unwrap();
    let n = 3_000;
    let mut obj = String::from("v 0.013 -0.007 0 1 1 1\n");
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        let (r, g, b) = (
            (k % 7) as f64 / 6.0,
            (k % 5) as f64 / 4.0,
            (k % 3) as f64 / 2.0,
        );
        obj += &format!("v {} {} 0 {r} {g} {b}\n", 1e3 * a.cos(), 1e3 * a.sin());
    }
    for k in 0..n {
        obj += &format!("f 1 {} {}\n", 2 + k, 2 + (k + 1) % n);
    }
    std::fs::write(dir.path().join("fan.obj"), obj).unwrap();
    let scene_file = dir.path().join("fan.json");
    std::fs::write(
        &scene_file,
        r#"{"resolution": [320, 240], "frames": 1, "cull_backfaces": false,
            "camera": {"kind": "perspective", "eye": [0, 0, 1], "target": [0, 0, 0],
                       "fov_deg": 40, "near": 0.1, "far": 10},
            "geometry": [{"obj": "fan.obj"}]}"#,
    )
    .unwrap();
    let scene = std::sync::Arc::new(sortsim::scene::Scene::load(&scene_file).unwrap());
    let expected = sortsim::algo::reference::render(&scene.frame(0).unwrap()).0;
    for algo in [
        "sort-middle/static",
        "sort-middle/ellsworth",
        "sort-first/mueller",
        "sort-last/direct-send",
        "sort-last/binary-swap",
    ] {
        for procs in [1, 3, 7] {
            let spec = sortsim::spec::run::RunSpec {
                schema: None,
                machine: std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                    .join("machines/delta.json"),
                scene: scene_file.clone(),
                algo: algo.into(),
                procs,
                frames: Some("0".into()),
                seed: 1,
                set: Default::default(),
            };
            let r = sortsim::algo::run(&spec.resolve(Some(scene.clone())).unwrap()).unwrap();
            assert_eq!(
                r.image.hash(),
                expected.hash(),
                "{algo} on {procs} processors differs from the sequential render"
            );
        }
    }
}
