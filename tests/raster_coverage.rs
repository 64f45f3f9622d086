//! Coverage: the top-left fill rule on shared edges and exact pixel centres, and
//! watertightness of fans, grids, closed meshes and huge meshes (every pixel exactly once).

use crate::raster_common;

use glam::Vec3;
use rand::Rng;
use raster_common::*;
use sortsim::raster::*;

const S: i32 = 256; // subpixel steps per pixel
const C: i32 = 128; // pixel centre offset

/// Pixels a single screen triangle covers.
fn pixels(viewport: Viewport, p: [(i32, i32); 3]) -> Vec<(u32, u32)> {
    covered(&draw_counts(viewport, &[st(p, 0).unwrap()]))
}

#[test]
fn horizontal_shared_edge_through_centres_is_owned_by_the_triangle_below() {
    let v = vp(16, 16);
    // Square [2,10]x[2,10] px split along y = 6.5 (a row of centres) into two quads' halves.
    let y = 6 * S + C;
    let top = [
        st([(2 * S, 2 * S), (10 * S, 2 * S), (10 * S, y)], 0).unwrap(),
        st([(2 * S, 2 * S), (10 * S, y), (2 * S, y)], 1).unwrap(),
    ];
    let bottom = [
        st([(2 * S, y), (10 * S, y), (10 * S, 10 * S)], 2).unwrap(),
        st([(2 * S, y), (10 * S, 10 * S), (2 * S, 10 * S)], 3).unwrap(),
    ];
    let all: Vec<_> = top.iter().chain(bottom.iter()).copied().collect();
    let t = draw_counts(v, &all);
    assert_eq!(max_count(&t), 1);
    assert_eq!(covered(&t).len(), 64);
    // Row 6 lies on the shared edge: the lower triangles own it (their top edge).
    let below = draw_counts(v, &bottom);
    assert!((2..10).all(|x| below.count(x, 6) == 1));
    let above = draw_counts(v, &top);
    assert!((2..10).all(|x| above.count(x, 6) == 0));
}

#[test]
fn vertical_shared_edge_through_centres_is_owned_by_the_triangle_to_the_right() {
    let v = vp(16, 16);
    let x = 5 * S + C;
    let left = [
        st([(S, S), (x, S), (x, 9 * S)], 0).unwrap(),
        st([(S, S), (x, 9 * S), (S, 9 * S)], 1).unwrap(),
    ];
    let right = [
        st([(x, S), (12 * S, S), (12 * S, 9 * S)], 2).unwrap(),
        st([(x, S), (12 * S, 9 * S), (x, 9 * S)], 3).unwrap(),
    ];
    let all: Vec<_> = left.iter().chain(right.iter()).copied().collect();
    let t = draw_counts(v, &all);
    assert_eq!(max_count(&t), 1);
    assert_eq!(covered(&t).len(), 11 * 8);
    let r = draw_counts(v, &right);
    assert!(
        (1..9).all(|y| r.count(5, y) == 1),
        "the left edge of the right half owns column 5"
    );
}

#[test]
fn diagonal_shared_edge_through_centres_is_drawn_once() {
    let v = vp(20, 20);
    // Diagonal from (0.5, 0.5) to (16.5, 16.5) passes through 17 centres.
    let a = (C, C);
    let b = (16 * S + C, 16 * S + C);
    let lower = st([a, b, (C, 16 * S + C)], 0).unwrap();
    let upper = st([a, (16 * S + C, C), b], 1).unwrap();
    let t = draw_counts(v, &[lower, upper]);
    assert_eq!(max_count(&t), 1);
    // The union is the square of centres 0..=16 minus its right column and bottom row
    // (right and bottom edges are not top-left): 16 x 16.
    assert_eq!(covered(&t).len(), 16 * 16);
    let on_diagonal = (0..16).filter(|&i| t.count(i, i) == 1).count();
    assert_eq!(on_diagonal, 16);
}

#[test]
fn vertex_on_a_pixel_centre_is_covered_only_where_top_and_left_edges_meet() {
    let v = vp(16, 16);
    // Right triangle with its right angle at the top-left, vertices on centres.
    let p = pixels(
        v,
        [
            (2 * S + C, 2 * S + C),
            (8 * S + C, 2 * S + C),
            (2 * S + C, 8 * S + C),
        ],
    );
    assert!(
        p.contains(&(2, 2)),
        "top-left corner vertex is on a top and a left edge"
    );
    assert!(
        !p.contains(&(8, 2)),
        "right end of the top edge lies on the hypotenuse"
    );
    assert!(!p.contains(&(2, 8)), "bottom vertex lies on the hypotenuse");
    // Rows 2..=7 hold 6, 5, ..., 1 pixels (the hypotenuse itself is excluded).
    assert_eq!(p.len(), 6 + 5 + 4 + 3 + 2 + 1);
}

#[test]
fn one_subpixel_either_side_of_a_centre_decides_coverage() {
    let v = vp(8, 8);
    // Axis-aligned rectangle halves; move the left and right edges around column centres.
    let rect = |x0: i32, x1: i32| {
        let mut t = CountingTarget::new(v);
        let tris = [
            st([(x0, 0), (x1, 0), (x1, 4 * S)], 0).unwrap(),
            st([(x0, 0), (x1, 4 * S), (x0, 4 * S)], 1).unwrap(),
        ];
        draw_screen_triangles(&tris, &mut t);
        (0..8).filter(|&x| t.count(x, 1) == 1).collect::<Vec<u32>>()
    };
    let c2 = 2 * S + C; // centre of column 2
    let c5 = 5 * S + C; // centre of column 5
    assert_eq!(
        rect(c2, c5),
        vec![2, 3, 4],
        "left edge on a centre: in; right edge: out"
    );
    assert_eq!(rect(c2 + 1, c5), vec![3, 4]);
    assert_eq!(rect(c2 - 1, c5), vec![2, 3, 4]);
    assert_eq!(rect(c2, c5 + 1), vec![2, 3, 4, 5]);
    assert_eq!(rect(c2, c5 - 1), vec![2, 3, 4]);
    // Same for the top and bottom edges around row centres.
    let rows = |y0: i32, y1: i32| {
        let t = draw_counts(
            v,
            &[
                st([(0, y0), (4 * S, y0), (4 * S, y1)], 0).unwrap(),
                st([(0, y0), (4 * S, y1), (0, y1)], 1).unwrap(),
            ],
        );
        (0..8).filter(|&y| t.count(1, y) == 1).collect::<Vec<u32>>()
    };
    let r1 = S + C;
    let r4 = 4 * S + C;
    assert_eq!(rows(r1, r4), vec![1, 2, 3]);
    assert_eq!(rows(r1 + 1, r4), vec![2, 3]);
    assert_eq!(rows(r1 - 1, r4 + 1), vec![1, 2, 3, 4]);
}

/// Convex hull (Andrew's monotone chain) of points given in angular order; returns the
/// hull in the same rotational direction, strictly convex.
fn convex_hull(mut pts: Vec<(i32, i32)>) -> Vec<(i32, i32)> {
    let cross = |o: (i32, i32), a: (i32, i32), b: (i32, i32)| {
        i64::from(a.0 - o.0) * i64::from(b.1 - o.1) - i64::from(a.1 - o.1) * i64::from(b.0 - o.0)
    };
    pts.sort_unstable();
    pts.dedup();
    let mut lower: Vec<(i32, i32)> = Vec::new();
    for &p in &pts {
        while lower.len() >= 2 && cross(lower[lower.len() - 2], lower[lower.len() - 1], p) <= 0 {
            lower.pop();
        }
        lower.push(p);
    }
    let mut upper: Vec<(i32, i32)> = Vec::new();
    for &p in pts.iter().rev() {
        while upper.len() >= 2 && cross(upper[upper.len() - 2], upper[upper.len() - 1], p) <= 0 {
            upper.pop();
        }
        upper.push(p);
    }
    lower.pop();
    upper.pop();
    lower.extend(upper);
    lower
}

/// A convex polygon triangulated as a fan from an interior point and as a fan from its
/// first vertex must cover exactly the same pixels, each exactly once.
#[test]
fn fans_of_thousands_of_slivers_are_watertight() {
    let v = vp(256, 256);
    for seed in 0..12u64 {
        let mut r = rng(seed);
        let n = 3000;
        let centre = (r.gen_range(100 * S..156 * S), r.gen_range(100 * S..156 * S));
        let radius = 120.0 * f64::from(S);
        let mut angles: Vec<f64> = (0..n)
            .map(|_| r.gen_range(0.0..std::f64::consts::TAU))
            .collect();
        angles.sort_by(f64::total_cmp);
        angles.dedup();
        let ring: Vec<(i32, i32)> = angles
            .iter()
            .map(|a| {
                let x = f64::from(centre.0) + radius * a.cos();
                let y = f64::from(centre.1) + radius * a.sin();
                (x.round() as i32, y.round() as i32)
            })
            .collect();
        // Rounding to subpixels can make three neighbours bend inwards; keep the convex
        // hull so that a fan from a vertex is a valid triangulation too.
        let ring = convex_hull(ring);
        let m = ring.len();
        assert!(m > 1000, "seed {seed}: the hull keeps most points ({m})");
        let fan_centre: Vec<_> = (0..m)
            .filter_map(|i| st([centre, ring[i], ring[(i + 1) % m]], i as u32))
            .collect();
        let fan_vertex: Vec<_> = (1..m - 1)
            .filter_map(|i| st([ring[0], ring[i], ring[i + 1]], i as u32))
            .collect();
        let a = draw_counts(v, &fan_centre);
        let b = draw_counts(v, &fan_vertex);
        assert_eq!(
            max_count(&a),
            1,
            "seed {seed}: a pixel drawn twice by the centre fan"
        );
        assert_eq!(
            max_count(&b),
            1,
            "seed {seed}: a pixel drawn twice by the vertex fan"
        );
        assert!(
            covered(&a) == covered(&b),
            "seed {seed}: the two triangulations differ"
        );
        // Deep inside the polygon nothing is missing.
        let r_in = 95.0;
        for (x, y) in [
            (0.0f64, 0.0f64),
            (r_in, 0.0),
            (0.0, r_in),
            (-r_in * 0.7, -r_in * 0.7),
        ] {
            let px = ((f64::from(centre.0) / f64::from(S)) + x) as u32;
            let py = ((f64::from(centre.1) / f64::from(S)) + y) as u32;
            assert_eq!(a.count(px, py), 1, "seed {seed}: hole at {px},{py}");
        }
    }
}

/// Pixels covered by `t` whose eight neighbours are covered too.
fn interior_of(t: &CountingTarget) -> impl Iterator<Item = (u32, u32)> + '_ {
    let (w, h) = (t.width(), t.height());
    (1..h - 1)
        .flat_map(move |y| (1..w - 1).map(move |x| (x, y)))
        .filter(move |&(x, y)| {
            (-1i32..=1).all(|dy| {
                (-1i32..=1).all(|dx| t.count((x as i32 + dx) as u32, (y as i32 + dy) as u32) > 0)
            })
        })
}

#[test]
fn grid_of_rotated_jittered_quads_is_watertight() {
    let v = vp(200, 200);
    for seed in 0..8u64 {
        let mut r = rng(100 + seed);
        let n = 40usize;
        let angle: f64 = r.gen_range(0.0..1.5);
        let (sin, cos) = angle.sin_cos();
        let cell = 3.7 * f64::from(S);
        let half = n as f64 * cell / 2.0;
        let mut grid = vec![(0i32, 0i32); (n + 1) * (n + 1)];
        for j in 0..=n {
            for i in 0..=n {
                let interior = i > 0 && j > 0 && i < n && j < n;
                let jit = if interior { 0.2 * cell } else { 0.0 };
                let x = i as f64 * cell - half + r.gen_range(-jit..=jit);
                let y = j as f64 * cell - half + r.gen_range(-jit..=jit);
                let (rx, ry) = (x * cos - y * sin, x * sin + y * cos);
                let o = 100.3 * f64::from(S);
                grid[j * (n + 1) + i] = ((rx + o).round() as i32, (ry + o).round() as i32);
            }
        }
        let g = |i: usize, j: usize| grid[j * (n + 1) + i];
        let mut tris = Vec::new();
        for j in 0..n {
            for i in 0..n {
                // Alternate the diagonal so both directions are exercised.
                let (a, b, c, d) = (g(i, j), g(i + 1, j), g(i + 1, j + 1), g(i, j + 1));
                if (i + j) % 2 == 0 {
                    tris.extend(st([a, b, c], 0));
                    tris.extend(st([a, c, d], 0));
                } else {
                    tris.extend(st([a, b, d], 0));
                    tris.extend(st([b, c, d], 0));
                }
            }
        }
        let t = draw_counts(v, &tris);
        let corners = [g(0, 0), g(n, 0), g(n, n), g(0, n)];
        let hull = draw_counts(
            v,
            &[
                st([corners[0], corners[1], corners[2]], 0).unwrap(),
                st([corners[0], corners[2], corners[3]], 0).unwrap(),
            ],
        );
        assert_eq!(max_count(&t), 1, "seed {seed}");
        // The outline's vertices were rounded independently, so its sides are not exactly
        // straight: compare away from the outline only.
        let holes = interior_of(&hull)
            .filter(|&(x, y)| t.count(x, y) != 1)
            .count();
        assert_eq!(holes, 0, "seed {seed}: holes inside the grid");
        assert!(covered(&t).len() * 10 > covered(&hull).len() * 9);
    }
}

/// A closed mesh seen from outside: every ray through a pixel centre enters as often as it
/// leaves, so front faces and back faces cover each pixel equally often; a convex one
/// covers its silhouette exactly once from each side.
#[test]
fn random_closed_meshes_cover_each_pixel_equally_from_front_and_back() {
    let v = vp(160, 120);
    for seed in 0..8u64 {
        let mut r = rng(200 + seed);
        let convex = seed == 0;
        let (pos, tris) = sphere(14, 23, |_| if convex { 1.0 } else { r.gen_range(0.6..1.0) });
        let rot = random_rotation(&mut r);
        let verts = to_clip(&pos, rot, r.gen_range(2.5..4.0), 160.0 / 120.0);
        let (front, cf) = mesh_counts(v, &verts, &tris, CullMode::Back);
        let flipped: Vec<[u32; 3]> = tris.iter().map(|t| [t[0], t[2], t[1]]).collect();
        let (back, _) = mesh_counts(v, &verts, &flipped, CullMode::Back);
        let (both, _) = mesh_counts(v, &verts, &tris, CullMode::None);
        assert!(
            cf.culled_backface > 0,
            "seed {seed}: nothing was back-facing"
        );
        if convex {
            assert_eq!(max_count(&front), 1, "seed {seed}");
            assert!(
                both.counts().iter().all(|&c| c == 0 || c == 2),
                "seed {seed}: a hole or overlap"
            );
        }
        assert_eq!(
            front.counts(),
            back.counts(),
            "seed {seed}: front and back coverage differ"
        );
        assert!(
            both.counts().iter().all(|&c| c % 2 == 0),
            "seed {seed}: odd coverage is a hole"
        );
        assert!(
            covered(&front).len() > 1000,
            "seed {seed}: the mesh should be on screen"
        );
    }
}

/// Huge meshes (vertices up to 1e7 px away, clip w varying) go through guard-band
/// clipping (the band lies a million pixels out); the visible part must still cover every
/// viewport pixel exactly once.
#[test]
fn meshes_at_coordinates_up_to_1e7_px_are_watertight() {
    let v = vp(128, 96);
    for seed in 0..8u64 {
        let mut r = rng(300 + seed);
        let n = 12usize;
        let span = 2.0e7;
        let mut verts = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let interior = i > 0 && j > 0 && i < n && j < n;
                let jit = if interior { 0.3 * span / n as f64 } else { 0.0 };
                let x = -1.0e7 + i as f64 * span / n as f64 + r.gen_range(-jit..=jit);
                let y = -1.0e7 + j as f64 * span / n as f64 + r.gen_range(-jit..=jit);
                let w = if seed % 2 == 0 {
                    1.0
                } else {
                    r.gen_range(0.2..50.0)
                };
                verts.push(pv_w(v, x, y, 0.5, w, [1.0; 3]));
            }
        }
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mut tris = Vec::new();
        for j in 0..n {
            for i in 0..n {
                tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let (t, c) = mesh_counts(v, &verts, &tris, CullMode::None);
        assert!(
            c.clipped > 0,
            "seed {seed}: the guard band should have clipped"
        );
        assert!(
            t.counts().iter().all(|&k| k == 1),
            "seed {seed}: every viewport pixel exactly once, got max {} and {} holes",
            max_count(&t),
            t.counts().iter().filter(|&&k| k == 0).count()
        );
    }
}

#[test]
fn counter_clockwise_on_screen_is_front_facing() {
    let v = vp(32, 32);
    // (2,2) -> (2,20) -> (20,2): down the left side, then up-right: counter-clockwise.
    let ccw = [pv(v, 2.0, 2.0), pv(v, 2.0, 20.0), pv(v, 20.0, 2.0)];
    let (t, c) = mesh_counts(v, &ccw, &[[0, 1, 2]], CullMode::Back);
    assert_eq!(c.culled_backface, 0);
    assert!(c.pixels_written > 100);
    assert!(!covered(&t).is_empty());
    let (_, c) = mesh_counts(v, &ccw, &[[0, 2, 1]], CullMode::Back);
    assert_eq!(c.culled_backface, 1);
    assert_eq!(c.pixels_written, 0);
    // Without culling both windings give the same pixels.
    let (a, _) = mesh_counts(v, &ccw, &[[0, 1, 2]], CullMode::None);
    let (b, _) = mesh_counts(v, &ccw, &[[0, 2, 1]], CullMode::None);
    assert_eq!(a.counts(), b.counts());
}

#[test]
fn sphere_fixture_is_wound_counter_clockwise_from_outside() {
    // Guards the fixture the closed-mesh test relies on: seen from the front, the faces
    // toward the camera survive back-face culling.
    let v = vp(64, 64);
    let (pos, tris) = sphere(8, 12, |_| 1.0);
    let verts = to_clip(&pos, glam::Quat::IDENTITY, 3.0, 1.0);
    let (_, c) = mesh_counts(v, &verts, &tris, CullMode::Back);
    assert!(c.culled_backface > 0 && c.triangles_set_up > 0);
    let centre_tri_drawn = {
        let (t, _) = mesh_counts(v, &verts, &tris, CullMode::Back);
        t.count(32, 32) == 1
    };
    assert!(centre_tri_drawn);
    let _ = Vec3::ZERO;
}

/// The shape of paper 000's adaptive supersampling buffer, reduced to counting: with
/// conservative sampling, per pixel and per sample of a 4x4 grid, how many triangles cover
/// the sample; fully covered pixels must have full masks.
struct MaskCounter {
    rects: [ScreenRect; 1],
    samples: Vec<(u8, u8)>,
    counts: Vec<[u32; 16]>,
    full_pixels: u64,
    edge_pixels: u64,
}

impl MaskCounter {
    fn new(v: Viewport) -> MaskCounter {
        let samples = (0..16)
            .map(|i| (32 + 64 * (i % 4) as u8, 32 + 64 * (i / 4) as u8))
            .collect();
        MaskCounter {
            rects: [v.rect()],
            samples,
            counts: vec![[0; 16]; v.pixels()],
            full_pixels: 0,
            edge_pixels: 0,
        }
    }
}

impl Target for MaskCounter {
    fn rects(&self) -> &[ScreenRect] {
        &self.rects
    }
    fn sampling(&self) -> Sampling {
        Sampling::Conservative
    }
    fn span(&mut self, _rect: usize, span: &Span<'_>, counters: &mut Counters) {
        let t = span.triangle();
        let y = span.y();
        for f in span.fragments() {
            let (px, py) = (i64::from(f.x), i64::from(y));
            let mask = t.coverage_mask(px, py, &self.samples);
            if t.fully_covers_pixel(px, py) {
                assert_eq!(mask, 0xffff, "a fully covered pixel has every sample");
                self.full_pixels += 1;
            } else if mask != 0 {
                self.edge_pixels += 1;
            }
            let cell = &mut self.counts[(y * self.rects[0].width() + f.x) as usize];
            for (i, c) in cell.iter_mut().enumerate() {
                *c += ((mask >> i) & 1) as u32;
            }
        }
        counters.pixels_tested += span.len() as u64;
    }
}

#[test]
fn coverage_masks_of_a_mesh_are_watertight_and_complete() {
    let v = vp(48, 48);
    let mut r = rng(400);
    let n = 9usize;
    let cell = 5.1 * f64::from(S);
    let mut grid = vec![(0i32, 0i32); (n + 1) * (n + 1)];
    for j in 0..=n {
        for i in 0..=n {
            let interior = i > 0 && j > 0 && i < n && j < n;
            let jit = if interior { 0.2 * cell } else { 0.0 };
            let x = 1.7 * f64::from(S) + i as f64 * cell + r.gen_range(-jit..=jit);
            let y = 0.9 * f64::from(S) + j as f64 * cell + r.gen_range(-jit..=jit);
            grid[j * (n + 1) + i] = (x.round() as i32, y.round() as i32);
        }
    }
    let g = |i: usize, j: usize| grid[j * (n + 1) + i];
    let mut tris = Vec::new();
    for j in 0..n {
        for i in 0..n {
            tris.extend(st([g(i, j), g(i + 1, j), g(i + 1, j + 1)], 0));
            tris.extend(st([g(i, j), g(i + 1, j + 1), g(i, j + 1)], 0));
        }
    }
    let mut masks = MaskCounter::new(v);
    draw_screen_triangles(&tris, &mut masks);
    assert!(masks.full_pixels > 500 && masks.edge_pixels > 200);
    // Every sample is covered at most once, and exactly as often as brute force says: no
    // touched pixel was left out of the conservative spans.
    let mut brute = vec![[0u32; 16]; v.pixels()];
    for t in &tris {
        let rt = RasterTriangle::new(t);
        for py in 0..48 {
            for px in 0..48 {
                let m = rt.coverage_mask(px, py, &masks.samples);
                for (i, c) in brute[(py * 48 + px) as usize].iter_mut().enumerate() {
                    *c += ((m >> i) & 1) as u32;
                }
            }
        }
    }
    assert!(
        masks.counts == brute,
        "conservative spans missed a touched pixel"
    );
    assert!(
        masks.counts.iter().flatten().all(|&c| c <= 1),
        "a sample covered twice"
    );
    // Samples well inside the grid are all covered.
    let inside = (10..40).flat_map(|y| (10..40).map(move |x| (x, y)));
    assert!(inside
        .into_iter()
        .all(|(x, y)| masks.counts[y * 48 + x].iter().all(|&c| c == 1)));
}
