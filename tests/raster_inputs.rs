//! Hard inputs and interpolation: degenerate, tiny, NaN, infinite and huge vertices,
//! triangles crossing the near plane or behind the eye (never a panic, always counted), depth
//! exact at vertices and inside the triangle's range, flat colours exact.

use crate::raster_common;

use glam::{Vec3, Vec4};
use rand::Rng;
use raster_common::*;
use sortsim::raster::*;

/// Draws one triangle given in clip space into a fresh framebuffer.
fn check_one(verts: [Vertex; 3]) -> (Counters, Framebuffer) {
    let v = vp(64, 48);
    let mut fb = Framebuffer::new(v);
    let c = draw_mesh(&verts, &[[0, 1, 2]], v, &RasterOptions::default(), &mut fb);
    assert_eq!(c.triangles_in, 1);
    let outcomes = c.culled() + u64::from(c.triangles_set_up > 0);
    assert_eq!(outcomes, 1, "each triangle is culled once or set up: {c:?}");
    (c, fb)
}

fn clip(x: f32, y: f32, z: f32, w: f32) -> Vertex {
    Vertex {
        clip: Vec4::new(x, y, z, w),
        color: Vec3::ONE,
    }
}

#[test]
fn zero_area_and_colinear_triangles_draw_nothing() {
    let v = vp(64, 48);
    let colinear = [pv(v, 1.0, 1.0), pv(v, 20.0, 20.0), pv(v, 40.0, 40.0)];
    let (c, _) = check_one(colinear);
    assert_eq!((c.culled_zero_area, c.pixels_written), (1, 0));
    let point = [pv(v, 10.3, 10.3); 3];
    let (c, _) = check_one(point);
    assert_eq!((c.culled_zero_area, c.pixels_written), (1, 0));
    let two_same = [pv(v, 5.0, 5.0), pv(v, 5.0, 5.0), pv(v, 30.0, 9.0)];
    let (c, _) = check_one(two_same);
    assert_eq!((c.culled_zero_area, c.pixels_written), (1, 0));
}

#[test]
fn triangles_smaller_than_a_subpixel_snap_to_nothing() {
    let v = vp(64, 48);
    let tiny = [pv(v, 10.5, 10.5), pv(v, 10.501, 10.5), pv(v, 10.5, 10.501)];
    let (c, _) = check_one(tiny);
    assert_eq!((c.culled_zero_area, c.pixels_written), (1, 0));
}

#[test]
fn sliver_between_centres_draws_nothing_and_sliver_across_a_centre_draws_it() {
    let v = vp(64, 48);
    // A long sliver entirely between two rows of centres.
    let between = [pv(v, 1.0, 10.6), pv(v, 60.0, 10.7), pv(v, 1.0, 10.65)];
    let (c, _) = check_one(between);
    assert_eq!(c.pixels_written, 0);
    assert_eq!(c.triangles_set_up, 1);
    // A sliver 1/128 px tall straddling row 10's centres.
    let across = [pv(v, 1.0, 10.496), pv(v, 60.0, 10.496), pv(v, 1.0, 10.504)];
    let (c, fb) = check_one(across);
    assert!(c.pixels_written > 20, "{c:?}");
    assert!((0..64).all(|x| fb.color(x, 9) == Some([0, 0, 0])));
}

#[test]
fn nan_and_infinite_vertices_are_dropped_and_counted() {
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        for slot in 0..4 {
            let mut a = clip(0.0, 0.0, 0.5, 1.0);
            let mut p = a.clip.to_array();
            p[slot] = bad;
            a.clip = Vec4::from_array(p);
            let (c, _) = check_one([a, clip(0.5, 0.0, 0.5, 1.0), clip(0.0, 0.5, 0.5, 1.0)]);
            assert_eq!(
                (c.culled_invalid, c.pixels_written),
                (1, 0),
                "component {slot} = {bad}"
            );
        }
        let mut col = clip(0.0, 0.0, 0.5, 1.0);
        col.color = Vec3::new(bad, 0.0, 0.0);
        let (c, _) = check_one([col, clip(0.5, 0.0, 0.5, 1.0), clip(0.0, 0.5, 0.5, 1.0)]);
        assert_eq!(c.culled_invalid, 1, "colour {bad}");
    }
}

#[test]
fn out_of_range_indices_are_dropped_and_counted() {
    let v = vp(8, 8);
    let verts = [clip(0.0, 0.0, 0.5, 1.0); 3];
    let mut fb = Framebuffer::new(v);
    let c = draw_mesh(
        &verts,
        &[[0, 1, 3], [u32::MAX, 0, 1]],
        v,
        &RasterOptions::default(),
        &mut fb,
    );
    assert_eq!((c.triangles_in, c.culled_invalid), (2, 2));
    let c = draw_subset(
        &verts,
        &[[0, 1, 2]],
        &[5],
        &mut VertexCache::new(verts.len(), v),
        &RasterOptions::default(),
        &mut fb,
    );
    assert_eq!((c.triangles_in, c.culled_invalid), (1, 1));
}

#[test]
fn huge_coordinates_1e30_must_not_panic() {
    let big = 1e30f32;
    let cases = [
        [
            clip(-big, -big, 0.5, 1.0),
            clip(big, -big, 0.5, 1.0),
            clip(0.0, big, 0.5, 1.0),
        ],
        [
            clip(big, big, 0.5, 1.0),
            clip(big, 0.0, 0.5, 1.0),
            clip(0.0, big, 0.5, 1.0),
        ],
        [
            clip(0.0, 0.0, 0.5, big),
            clip(big, 0.0, 0.5, big),
            clip(0.0, big, big, big),
        ],
        [
            clip(0.0, 0.0, 0.5, 1e-30),
            clip(1.0, 0.0, 0.5, 1e-30),
            clip(0.0, 1.0, 0.5, 1.0),
        ],
        [
            clip(-big, 0.0, -big, big),
            clip(big, 0.0, big, big),
            clip(0.0, big, 0.0, 1.0),
        ],
    ];
    for (i, t) in cases.into_iter().enumerate() {
        let (c, _) = check_one(t);
        assert_eq!(c.culled_invalid, 0, "case {i}");
    }
    // The first case covers the whole viewport after guard-band clipping.
    let (c, fb) = check_one(cases_first());
    assert_eq!(c.clipped, 1);
    assert!(fb.colors().iter().filter(|&&p| p == [255; 3]).count() > 64 * 48 / 2);
}

fn cases_first() -> [Vertex; 3] {
    let big = 1e30f32;
    [
        clip(-big, -big, 0.5, 1.0),
        clip(big, -big, 0.5, 1.0),
        clip(0.0, big, 0.5, 1.0),
    ]
}

#[test]
fn triangle_behind_the_eye_is_outside() {
    // perspective_rh puts points behind the eye at w < 0 and z < 0.
    let (c, _) = check_one([
        clip(0.0, 0.0, -1.0, -1.0),
        clip(1.0, 0.0, -1.2, -2.0),
        clip(0.0, 1.0, -1.5, -1.5),
    ]);
    assert_eq!((c.culled_outside, c.pixels_written), (1, 0));
    // Beyond the far plane.
    let (c, _) = check_one([
        clip(0.0, 0.0, 2.0, 1.0),
        clip(0.5, 0.0, 2.0, 1.0),
        clip(0.0, 0.5, 3.0, 1.0),
    ]);
    assert_eq!(c.culled_outside, 1);
    // Entirely left of the view volume.
    let (c, _) = check_one([
        clip(-3.0, 0.0, 0.5, 1.0),
        clip(-2.0, 0.0, 0.5, 1.0),
        clip(-2.0, 0.5, 0.5, 1.0),
    ]);
    assert_eq!(c.culled_outside, 1);
}

#[test]
fn triangle_crossing_the_near_plane_is_clipped_and_drawn() {
    // A floor quad from behind the eye to far away, through a real camera.
    let proj = glam::Mat4::perspective_rh(1.2, 4.0 / 3.0, 0.1, 50.0);
    let p = |x: f32, z: f32| Vertex {
        clip: proj * Vec4::new(x, -1.0, z, 1.0),
        color: Vec3::new(0.2, 0.6, 1.0),
    };
    let verts = [p(-5.0, 5.0), p(5.0, 5.0), p(5.0, -40.0), p(-5.0, -40.0)];
    let v = vp(64, 48);
    let mut counts = CountingTarget::new(v);
    let c = draw_mesh(
        &verts,
        &[[0, 1, 2], [0, 2, 3]],
        v,
        &RasterOptions::default(),
        &mut counts,
    );
    assert_eq!(c.clipped, 2, "{c:?}");
    assert!(c.triangles_set_up >= 3, "clipped pieces are fanned: {c:?}");
    assert_eq!(
        max_count(&counts),
        1,
        "the two clipped halves share their diagonal exactly"
    );
    // The floor fills the bottom rows completely.
    assert!((0..64).all(|x| counts.count(x, 47) == 1));
}

#[test]
fn depth_is_exact_at_vertices_on_pixel_centres() {
    let mut r = rng(7);
    for _ in 0..200 {
        let p = |r: &mut rand_chacha::ChaCha8Rng| {
            (
                r.gen_range(0..60) * 256 + 128,
                r.gen_range(0..40) * 256 + 128,
            )
        };
        let pts = [p(&mut r), p(&mut r), p(&mut r)];
        let zs = [
            r.gen_range(0..u32::MAX - 1),
            r.gen_range(0..u32::MAX - 1),
            r.gen_range(0..u32::MAX - 1),
        ];
        let verts = [0, 1, 2].map(|i| sv(pts[i].0, pts[i].1, zs[i], [0; 3]));
        let Some(t) = ScreenTriangle::new(verts, 0) else {
            continue;
        };
        let rt = RasterTriangle::new(&t);
        for (i, &(x, y)) in pts.iter().enumerate() {
            let (px, py) = (i64::from(x / 256), i64::from(y / 256));
            assert_eq!(rt.depth_at(px, py), zs[i], "vertex {i} of {t:?}");
        }
    }
}

#[test]
fn depth_is_monotone_along_edges_and_within_the_triangle_range() {
    let mut r = rng(8);
    for _ in 0..200 {
        // An edge through pixel centres: v0 + k * step for k in 0..=n.
        let (sx, sy) = (r.gen_range(-3..=3), r.gen_range(1..=3));
        let n = r.gen_range(2..12);
        let a = (
            r.gen_range(20..30) * 256 + 128,
            r.gen_range(0..4) * 256 + 128,
        );
        let b = (a.0 + sx * n * 256, a.1 + sy * n * 256);
        let c = (
            a.0 + r.gen_range(-20..20) * 256 + 77,
            a.1 + r.gen_range(-3..40) * 256 + 13,
        );
        let za: u32 = r.gen_range(0..u32::MAX - 1);
        let zb: u32 = r.gen_range(0..u32::MAX - 1);
        let zc: u32 = r.gen_range(0..u32::MAX - 1);
        let Some(t) = ScreenTriangle::new(
            [
                sv(a.0, a.1, za, [0; 3]),
                sv(b.0, b.1, zb, [0; 3]),
                sv(c.0, c.1, zc, [0; 3]),
            ],
            0,
        ) else {
            continue;
        };
        let rt = RasterTriangle::new(&t);
        let along: Vec<u32> = (0..=n)
            .map(|k| {
                let px = (a.0 + k * sx * 256).div_euclid(256);
                let py = (a.1 + k * sy * 256).div_euclid(256);
                rt.depth_at(i64::from(px), i64::from(py))
            })
            .collect();
        let (lo, hi) = (za.min(zb).min(zc), za.max(zb).max(zc));
        assert!(along.iter().all(|&z| (lo..=hi).contains(&z)));
        let up = along.windows(2).all(|w| w[0] <= w[1]);
        let down = along.windows(2).all(|w| w[0] >= w[1]);
        assert!(up || down, "not monotone: {along:?}");
        assert_eq!((along[0], along[n as usize]), (za, zb));
    }
}

#[test]
fn every_fragment_depth_and_colour_lies_within_its_triangle_range() {
    let mut r = rng(9);
    let (verts, tris) = random_soup(&mut r, 300);
    let v = vp(96, 64);
    let mut out = Vec::new();
    setup_mesh(&verts, &tris, v, &RasterOptions::default(), &mut out);
    assert!(out.len() > 200);
    for t in &out {
        let mut sparse = SparseBuffer::recording(v);
        draw_screen_triangles(std::slice::from_ref(t), &mut sparse);
        let vs = t.vertices();
        let (zlo, zhi) = (
            vs.iter().map(|v| v.z.raw()).min().unwrap(),
            vs.iter().map(|v| v.z.raw()).max().unwrap(),
        );
        for f in sparse.fragments().unwrap() {
            assert!((zlo..=zhi).contains(&f.z));
            for ch in 0..3 {
                let lo = vs.iter().map(|v| v.rgb[ch]).min().unwrap();
                let hi = vs.iter().map(|v| v.rgb[ch]).max().unwrap();
                assert!(
                    (lo..=hi).contains(&f.rgb[ch]),
                    "channel {ch} of {f:?} outside {lo}..={hi}"
                );
            }
        }
    }
}

#[test]
fn drawing_the_same_mesh_twice_changes_nothing() {
    let mut r = rng(10);
    let (pos, tris) = sphere(12, 20, |_| r.gen_range(0.7..1.0));
    let verts = to_clip(&pos, random_rotation(&mut r), 3.0, 1.5);
    let v = vp(120, 80);
    let mut fb = Framebuffer::new(v);
    let first = draw_mesh(&verts, &tris, v, &RasterOptions::default(), &mut fb);
    let (colors, depths) = (fb.colors().to_vec(), fb.depths().to_vec());
    let second = draw_mesh(&verts, &tris, v, &RasterOptions::default(), &mut fb);
    assert!(first.pixels_written > 1000);
    assert_eq!(
        second.pixels_written, 0,
        "no fragment of the same mesh beats itself"
    );
    assert_eq!(second.pixels_tested, first.pixels_tested);
    assert!(fb.colors() == colors.as_slice() && fb.depths() == depths.as_slice());
}

#[test]
fn flat_colour_triangles_come_out_exactly_in_their_colour() {
    let mut r = rng(11);
    let v = vp(64, 64);
    for _ in 0..300 {
        let rgb: [f32; 3] = [r.gen(), r.gen(), r.gen()];
        let expect = rgb.map(|c| (c * 255.0).round() as u8);
        let p = |r: &mut rand_chacha::ChaCha8Rng| {
            pv_w(
                v,
                r.gen_range(-20.0..84.0),
                r.gen_range(-20.0..84.0),
                r.gen_range(0.0..1.0),
                r.gen_range(0.3..4.0),
                rgb,
            )
        };
        let verts = [p(&mut r), p(&mut r), p(&mut r)];
        let mut fb = Framebuffer::with_clear(v, [1, 2, 3]);
        let c = draw_mesh(&verts, &[[0, 1, 2]], v, &RasterOptions::default(), &mut fb);
        let drawn = fb.colors().iter().filter(|&&p| p != [1, 2, 3]).count() as u64;
        assert_eq!(drawn, c.pixels_written);
        assert!(
            fb.colors().iter().all(|&p| p == [1, 2, 3] || p == expect),
            "colour {expect:?}"
        );
    }
}

#[test]
fn screen_space_vertices_snap_exactly_and_flat_colour_is_exact() {
    let v = vp(50, 30);
    let p = |x: f64, y: f64| ScreenVertex::from_pixels(x, y, 0.25, [0.2, 0.4, 0.6]).unwrap();
    let a = p(10.5, 3.0);
    assert_eq!((a.x.raw(), a.y.raw()), (10 * 256 + 128, 3 * 256));
    let t = ScreenTriangle::new([p(1.0, 1.0), p(40.0, 2.0), p(5.0, 28.0)], 0).unwrap();
    let mut fb = Framebuffer::with_clear(v, [9, 9, 9]);
    let c = draw_screen_triangles(&[t], &mut fb);
    assert!(c.pixels_written > 300);
    let expect = [51, 102, 153];
    assert!(fb.colors().iter().all(|&p| p == [9, 9, 9] || p == expect));
    assert!(ScreenVertex::from_pixels(f64::NAN, 0.0, 0.0, [0.0; 3]).is_none());
    assert!(ScreenVertex::from_pixels(0.0, 0.0, 0.0, [f64::NAN; 3]).is_none());
}

#[test]
fn gouraud_colour_reaches_vertex_colours_at_vertex_centres() {
    // Red, green, blue corners on pixel centres: interpolation is exact at the anchor vertex
    // and within one step elsewhere.
    let t = ScreenTriangle::new(
        [
            sv(128, 128, 0, [255, 0, 0]),
            sv(40 * 256 + 128, 128, 0, [0, 255, 0]),
            sv(128, 40 * 256 + 128, 0, [0, 0, 255]),
        ],
        0,
    )
    .unwrap();
    let rt = RasterTriangle::new(&t);
    assert_eq!(rt.color_at(0, 0), [255, 0, 0]);
    let g = rt.color_at(40, 0);
    let b = rt.color_at(0, 40);
    assert!(g[1] >= 254 && g[0] <= 1 && g[2] <= 1, "{g:?}");
    assert!(b[2] >= 254 && b[0] <= 1 && b[1] <= 1, "{b:?}");
    let mid = rt.color_at(20, 0);
    assert!(
        (126..=129).contains(&mid[0]) && (126..=129).contains(&mid[1]),
        "{mid:?}"
    );
}

/// Guard for the one division in projection: a vertex at w == 0 (the eye itself) passes
/// both depth planes and would divide by zero. Must not panic.
#[test]
fn regression_vertex_at_the_eye_must_not_panic() {
    let (c, _) = check_one([
        clip(0.0, 0.0, 0.0, 0.0),
        clip(1.0, 0.0, 0.5, 1.0),
        clip(0.0, 1.0, 0.5, 1.0),
    ]);
    assert_eq!(c.culled_invalid, 0);
    let (c, _) = check_one([clip(0.0, 0.0, 0.0, 0.0); 3]);
    assert_eq!(c.pixels_written, 0);
}

/// Guard for gradient overflow: a sliver with an area of one square subpixel and long
/// edges has colour gradients beyond i64 unless they saturate. Must not panic.
#[test]
fn regression_extreme_sliver_gradients_must_not_panic() {
    let long = 60 * 256;
    let t = ScreenTriangle::new(
        [
            sv(0, 0, 0, [0, 0, 0]),
            sv(long, 1, u32::MAX - 1, [255, 255, 255]),
            sv(2 * long, 3, 7, [255, 0, 255]),
        ],
        0,
    )
    .unwrap();
    let mut fb = Framebuffer::new(vp(128, 4));
    let c = draw_screen_triangles(&[t], &mut fb);
    assert_eq!(c.triangles_scanned, 1);
}

/// Guard for span arithmetic at the edge of the fixed-point range: vertices exactly on the
/// guard band. Must not panic.
#[test]
fn regression_guard_band_corners_must_not_panic() {
    let g = 8.0f32;
    let (c, fb) = check_one([
        clip(-g, -g, 0.5, 1.0),
        clip(g, -g, 0.5, 1.0),
        clip(0.0, g, 0.5, 1.0),
    ]);
    assert_eq!(c.clipped, 0, "exactly on the guard band is inside it");
    assert!(fb.colors().iter().all(|&p| p == [255; 3]));
}

mod arbitrary_floats {
    use super::*;
    use proptest::prelude::*;

    fn coord() -> impl Strategy<Value = f32> {
        prop_oneof![
            -3.0f32..3.0,
            any::<f32>(),
            Just(0.0f32),
            Just(-0.0f32),
            Just(f32::MAX),
            Just(f32::MIN_POSITIVE),
            Just(1e30f32),
            Just(-1e30f32),
        ]
    }

    fn vertex() -> impl Strategy<Value = Vertex> {
        (coord(), coord(), coord(), coord(), any::<[f32; 3]>()).prop_map(|(x, y, z, w, c)| Vertex {
            clip: Vec4::new(x, y, z, w),
            color: Vec3::from_array(c),
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 2048, ..ProptestConfig::default() })]

        /// Any floats at all: never a panic, every triangle accounted for exactly once,
        /// and culling or clipping never produces a fragment outside the triangle's
        /// depth range or the viewport.
        #[test]
        fn any_vertices_are_accounted_for_and_never_panic(a in vertex(), b in vertex(), c in vertex(), cull in any::<bool>()) {
            let v = vp(32, 24);
            let cull = if cull { CullMode::Back } else { CullMode::None };
            let mut s = SparseBuffer::recording(v);
            let k = draw_mesh(&[a, b, c], &[[0, 1, 2]], v, &RasterOptions { cull }, &mut s);
            prop_assert_eq!(k.triangles_in, 1);
            prop_assert_eq!(k.culled() + u64::from(k.triangles_set_up > 0), 1);
            prop_assert_eq!(k.pixels_tested, s.fragments().unwrap().len() as u64);
            prop_assert!(s.fragments().unwrap().iter().all(|f| f.x < 32 && f.y < 24 && f.z != u32::MAX));
        }
    }
}
