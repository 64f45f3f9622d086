//! Different routes to the same pixels: scanline z-buffer vs z-buffer, region sets vs the
//! whole framebuffer, the sparse buffer vs the framebuffer, setup-then-scan (with a byte
//! round trip) vs direct drawing; plus property tests of the fill rule and interpolation.

use crate::raster_common;

use proptest::prelude::*;
use rand::Rng;
use raster_common::*;
use sortsim::raster::*;

fn zbuffer(v: Viewport, tris: &[ScreenTriangle]) -> (Framebuffer, Counters) {
    let mut fb = Framebuffer::new(v);
    let c = draw_screen_triangles(tris, &mut fb);
    (fb, c)
}

fn scanline(v: Viewport, tris: &[ScreenTriangle]) -> (Framebuffer, Counters) {
    let mut fb = Framebuffer::new(v);
    let c = render_scanlines_into(tris, &mut fb, [0; 3]);
    (fb, c)
}

fn soup(seed: u64, n: usize, v: Viewport) -> Vec<ScreenTriangle> {
    let mut r = rng(seed);
    let (verts, tris) = random_soup(&mut r, n);
    let mut out = Vec::new();
    setup_mesh(&verts, &tris, v, &RasterOptions::default(), &mut out);
    out
}

#[test]
fn scanline_renderer_image_equals_zbuffer_image() {
    for seed in 0..8u64 {
        let v = vp(97 + seed as u32 * 13, 61 + seed as u32 * 7);
        let tris = soup(400 + seed, 400, v);
        let (a, ca) = zbuffer(v, &tris);
        let (b, cb) = scanline(v, &tris);
        assert!(a.colors() == b.colors(), "seed {seed}: colours differ");
        assert!(a.depths() == b.depths(), "seed {seed}: depths differ");
        assert_eq!(a.hash(), b.hash());
        assert_eq!(
            (ca.spans, ca.pixels_tested, ca.pixels_written),
            (cb.spans, cb.pixels_tested, cb.pixels_written)
        );
        assert!(
            ca.pixels_written > 1000,
            "seed {seed}: the scene should draw something"
        );
        assert_eq!(cb.scanlines, u64::from(v.height()));
        assert_eq!(cb.active_inserts, cb.bucket_inserts);
        assert_eq!(
            cb.active_removals, cb.active_inserts,
            "every active triangle retires"
        );
        assert_eq!(ca.bucket_inserts, 0);
    }
}

#[test]
fn scanline_renderer_matches_on_a_closed_mesh_with_depth_ties() {
    let mut r = rng(500);
    let (pos, tris) = sphere(16, 24, |_| r.gen_range(0.8..1.0));
    let verts = to_clip(&pos, random_rotation(&mut r), 2.8, 1.0);
    let v = vp(100, 100);
    let mut out = Vec::new();
    setup_mesh(&verts, &tris, v, &RasterOptions::default(), &mut out);
    // Draw every triangle twice: ties must resolve identically (first one wins).
    let doubled: Vec<_> = out.iter().chain(out.iter()).copied().collect();
    let (a, _) = zbuffer(v, &doubled);
    let (b, _) = scanline(v, &doubled);
    assert!(a.colors() == b.colors() && a.depths() == b.depths());
}

#[test]
fn region_set_equals_the_whole_framebuffer() {
    let v = vp(100, 70);
    let tris = soup(600, 300, v);
    let (whole, cw) = zbuffer(v, &tris);
    // Irregular tiles covering the viewport.
    let xs = [0, 13, 50, 51, 100];
    let ys = [0, 7, 40, 70];
    let mut rects = Vec::new();
    for j in 0..ys.len() - 1 {
        for i in 0..xs.len() - 1 {
            rects.push(ScreenRect::new(xs[i], ys[j], xs[i + 1], ys[j + 1]).unwrap());
        }
    }
    let mut regions = RegionSet::new(v, rects).unwrap();
    let cr = draw_screen_triangles(&tris, &mut regions);
    let mut composed = Framebuffer::new(v);
    regions.copy_into(&mut composed);
    assert!(composed.colors() == whole.colors() && composed.depths() == whole.depths());
    assert_eq!(
        (cr.pixels_tested, cr.pixels_written),
        (cw.pixels_tested, cw.pixels_written)
    );
    assert!(cr.spans > cw.spans, "spans split at region borders");
}

#[test]
fn region_set_rejects_overlaps_and_regions_outside_the_viewport() {
    let v = vp(10, 10);
    let r = |a, b, c, d| ScreenRect::new(a, b, c, d).unwrap();
    assert_eq!(
        RegionSet::new(v, vec![r(0, 0, 5, 5), r(4, 4, 6, 6)]).unwrap_err(),
        RegionError::Overlap(0, 1)
    );
    assert_eq!(
        RegionSet::new(v, vec![r(0, 0, 11, 5)]).unwrap_err(),
        RegionError::OutsideViewport(0)
    );
    assert!(ScreenRect::new(3, 3, 3, 4).is_none());
    assert!(RegionSet::new(v, vec![r(0, 0, 5, 5), r(5, 0, 10, 5)]).is_ok());
}

#[test]
fn sparse_buffer_holds_exactly_the_framebuffers_written_pixels() {
    let v = vp(80, 60);
    let tris = soup(700, 150, v);
    let (fb, cf) = zbuffer(v, &tris);
    let mut sparse = SparseBuffer::recording(v);
    let cs = draw_screen_triangles(&tris, &mut sparse);
    assert_eq!(
        (cs.pixels_tested, cs.pixels_written),
        (cf.pixels_tested, cf.pixels_written)
    );
    let written = fb.depths().iter().filter(|&&z| z != u32::MAX).count();
    assert_eq!(sparse.active().len(), written);
    for p in sparse.active_sorted() {
        assert_eq!(fb.color(p.x, p.y), Some(p.rgb));
        assert_eq!(fb.depth(p.x, p.y), Some(p.z));
    }
    let frags = sparse.fragments().unwrap();
    assert_eq!(frags.len() as u64, cf.pixels_tested);
    // Fragments come in drawing order, so their primitive ids never decrease.
    let order: Vec<u32> = tris.iter().map(|t| t.prim()).collect();
    let pos = |p: u32| order.iter().position(|&q| q == p).unwrap();
    assert!(frags.windows(2).all(|w| pos(w[0].prim) <= pos(w[1].prim)));
}

#[test]
fn setup_then_scan_through_bytes_equals_direct_drawing() {
    let mut r = rng(800);
    let (verts, tris) = random_soup(&mut r, 300);
    let v = vp(90, 70);
    let opts = RasterOptions {
        cull: CullMode::Back,
    };
    let mut direct = Framebuffer::new(v);
    let cd = draw_mesh(&verts, &tris, v, &opts, &mut direct);
    let mut shipped = Vec::new();
    let cs = setup_mesh(&verts, &tris, v, &opts, &mut shipped);
    let received: Vec<ScreenTriangle> = shipped
        .iter()
        .map(|t| ScreenTriangle::from_bytes(&t.to_bytes()).unwrap())
        .collect();
    assert_eq!(received, shipped);
    let mut split = Framebuffer::new(v);
    let cb = draw_screen_triangles(&received, &mut split);
    assert_eq!(direct.hash(), split.hash());
    assert_eq!(
        cd,
        cs + cb,
        "front-end and back-end counts add up to a direct draw"
    );
    assert!(cs.culled_backface > 0);
    assert_eq!(ScreenTriangle::PAYLOAD_BYTES, 49);
}

#[test]
fn shared_vertex_cache_changes_nothing() {
    // draw_mesh prepares each shared vertex once; one-triangle subsets prepare vertices per
    // triangle. Both must give the same image and the same counts, clipping included.
    let mut r = rng(950);
    let (pos, tris) = sphere(12, 18, |_| r.gen_range(0.6..1.0));
    for dist in [3.0f32, 1.3, 1.25] {
        let verts = to_clip(&pos, random_rotation(&mut r), dist, 1.3);
        let v = vp(90, 70);
        let opts = RasterOptions {
            cull: CullMode::Back,
        };
        let mut whole = Framebuffer::new(v);
        let cw = draw_mesh(&verts, &tris, v, &opts, &mut whole);
        let mut single = Framebuffer::new(v);
        let mut cs = Counters::default();
        let mut cache = VertexCache::new(verts.len(), v);
        for i in 0..tris.len() as u32 {
            cs += draw_subset(&verts, &tris, &[i], &mut cache, &opts, &mut single);
        }
        assert_eq!(cw, cs, "distance {dist}");
        assert_eq!(whole.hash(), single.hash(), "distance {dist}");
        if dist < 1.5 {
            assert!(cw.clipped > 0, "the near plane cuts the mesh: {cw:?}");
        }
    }
}

#[test]
fn drawing_a_subset_per_node_composes_to_the_whole() {
    let mut r = rng(900);
    let (verts, tris) = random_soup(&mut r, 200);
    let v = vp(64, 64);
    let opts = RasterOptions::default();
    let mut whole = SparseBuffer::new(v);
    draw_mesh(&verts, &tris, v, &opts, &mut whole);
    let mut total = Counters::default();
    let mut nodes = Vec::new();
    // One vertex preparation shared by the three nodes, as a simulated frame shares it.
    let mut cache = VertexCache::new(verts.len(), v);
    for node in 0..3u32 {
        let mine: Vec<u32> = (0..tris.len() as u32).filter(|i| i % 3 == node).collect();
        let mut fb = Framebuffer::new(v);
        total += draw_subset(&verts, &tris, &mine, &mut cache, &opts, &mut fb);
        nodes.push(fb);
    }
    assert_eq!(total.triangles_in, tris.len() as u64);
    // Depth-composite the three nodes (sort-last): nearest wins.
    for p in whole.active() {
        let best = nodes
            .iter()
            .map(|fb| fb.depth(p.x, p.y).unwrap())
            .min()
            .unwrap();
        assert_eq!(best, p.z);
    }
}

#[test]
fn png_round_trips_and_reports_io_errors() {
    let v = vp(20, 10);
    let tris = soup(1000, 20, v);
    let (fb, _) = zbuffer(v, &tris);
    let mut bytes = Vec::new();
    encode_png(&fb, &mut bytes).unwrap();
    let dec = png::Decoder::new(std::io::Cursor::new(bytes));
    let mut reader = dec.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (20, 10));
    assert_eq!(&buf[..info.buffer_size()], fb.colors().as_flattened());
    let err = write_png(&fb, std::path::Path::new("/nonexistent-dir/x.png")).unwrap_err();
    assert!(matches!(err, PngError::Io { .. }));
    assert!(err.to_string().contains("/nonexistent-dir/x.png"));
}

/// An independent reference for coverage: exact i128 edge functions at pixel centres with
/// the top-left rule stated geometrically (interior below a horizontal edge, or to the right
/// of a non-horizontal edge, wins the tie), for either winding.
fn reference_covers(p: [(i32, i32); 3], px: i64, py: i64) -> bool {
    let (cx, cy) = (i128::from(px) * 256 + 128, i128::from(py) * 256 + 128);
    let q = p.map(|(x, y)| (i128::from(x), i128::from(y)));
    let area = (q[1].0 - q[0].0) * (q[2].1 - q[0].1) - (q[1].1 - q[0].1) * (q[2].0 - q[0].0);
    if area == 0 {
        return false;
    }
    (0..3).all(|i| {
        let (a, b) = (q[i], q[(i + 1) % 3]);
        // Oriented so that the interior is positive.
        let e = ((b.0 - a.0) * (cy - a.1) - (b.1 - a.1) * (cx - a.0)) * area.signum();
        if e != 0 {
            return e > 0;
        }
        // On the edge line: where is the interior relative to this edge?
        let third = q[(i + 2) % 3];
        if a.1 == b.1 {
            third.1 > a.1 // horizontal edge with the interior below: a top edge
        } else {
            // Interior to the right of the edge at the edge's height: a left edge.
            let x_on_edge = |y: i128| a.0 * (b.1 - y) + b.0 * (y - a.1); // times (b.1 - a.1)
            let d = b.1 - a.1;
            third.0 * d * d.signum() > x_on_edge(third.1) * d.signum()
        }
    })
}

fn arb_vertex() -> impl Strategy<Value = (i32, i32, u32, [u8; 3])> {
    (
        -2000i32..12000,
        -2000i32..12000,
        0u32..u32::MAX - 1,
        any::<[u8; 3]>(),
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2048, ..ProptestConfig::default() })]

    /// Splitting a triangle at a point of one of its edges gives two triangles that cover
    /// exactly the original pixels, each once.
    #[test]
    fn split_along_an_edge_covers_the_same_pixels_once(
        a in arb_vertex(), b in arb_vertex(), d in (-1500i32..1500, -1500i32..1500), k in 1i32..8
    ) {
        let v = vp(40, 40);
        let p = |q: (i32, i32, u32, [u8; 3])| sv(q.0, q.1, q.2, q.3);
        // c = b + 8 d, so b + d k lies exactly on edge b-c.
        let c = (b.0 + 8 * d.0, b.1 + 8 * d.1, a.2, a.3);
        let Some(whole) = ScreenTriangle::new([p(a), p(b), p(c)], 0) else { return Ok(()) };
        let m = (b.0 + d.0 * k, b.1 + d.1 * k, b.2, b.3);
        let parts: Vec<_> = [ScreenTriangle::new([p(a), p(b), p(m)], 1), ScreenTriangle::new([p(a), p(m), p(c)], 2)]
            .into_iter().flatten().collect();
        let one = draw_counts(v, &[whole]);
        let two = draw_counts(v, &parts);
        prop_assert!(max_count(&two) <= 1);
        prop_assert!(one.counts() == two.counts());
    }

    /// Every fragment lies within the triangle's depth and colour ranges, its pixel centre
    /// is covered, and flat colours are exact.
    #[test]
    fn fragments_stay_within_vertex_ranges(a in arb_vertex(), b in arb_vertex(), c in arb_vertex(), flat in any::<bool>()) {
        let v = vp(48, 48);
        let p = |q: (i32, i32, u32, [u8; 3])| sv(q.0, q.1, q.2, if flat { a.3 } else { q.3 });
        let Some(t) = ScreenTriangle::new([p(a), p(b), p(c)], 0) else { return Ok(()) };
        let rt = RasterTriangle::new(&t);
        let mut s = SparseBuffer::recording(v);
        draw_screen_triangles(&[t], &mut s);
        let zs = [a.2, b.2, c.2];
        for f in s.fragments().unwrap() {
            prop_assert!(rt.covers_pixel(i64::from(f.x), i64::from(f.y)));
            prop_assert!(f.z >= *zs.iter().min().unwrap() && f.z <= *zs.iter().max().unwrap());
            if flat {
                prop_assert_eq!(f.rgb, a.3);
            }
            prop_assert_eq!(f.z, rt.depth_at(i64::from(f.x), i64::from(f.y)));
        }
        // And nothing covered was missed.
        let covered_centres = (0..48i64).flat_map(|y| (0..48i64).map(move |x| (x, y)))
            .filter(|&(x, y)| rt.covers_pixel(x, y)).count();
        prop_assert_eq!(covered_centres, s.fragments().unwrap().len());
    }

    /// Coverage equals the independent reference on random triangles and slivers.
    #[test]
    fn coverage_matches_an_independent_reference(
        a in (-800i32..9000, -800i32..9000),
        b in (-800i32..9000, -800i32..9000),
        t in -0.2f64..1.2,
        off in -600i32..600,
        sliver in any::<bool>(),
        coarse in any::<bool>(),
    ) {
        // A sliver's third vertex lies within a few subpixels of the line through a and b.
        let c = if sliver {
            let x = f64::from(a.0) + t * f64::from(b.0 - a.0);
            let y = f64::from(a.1) + t * f64::from(b.1 - a.1);
            (x.round() as i32 + off / 100, y.round() as i32 - off / 150)
        } else {
            (a.0 + off * 7, b.1 - off * 5)
        };
        let v = vp(36, 36);
        // On a 128-subpixel grid, edges run through pixel centres all the time: ties.
        let snap = |p: (i32, i32)| if coarse { (p.0 / 128 * 128, p.1 / 128 * 128) } else { p };
        let pts = [snap(a), snap(b), snap(c)];
        let counts = match st(pts, 0) {
            Some(tri) => draw_counts(v, &[tri]),
            None => CountingTarget::new(v),
        };
        for py in 0..36u32 {
            for px in 0..36u32 {
                let want = reference_covers(pts, i64::from(px), i64::from(py));
                prop_assert_eq!(counts.count(px, py) == 1, want, "pixel {},{} of {:?}", px, py, pts);
            }
        }
    }

    #[test]
    fn screen_triangle_bytes_round_trip(a in arb_vertex(), b in arb_vertex(), c in arb_vertex(), prim in any::<u32>()) {
        let p = |q: (i32, i32, u32, [u8; 3])| sv(q.0, q.1, q.2, q.3);
        if let Some(t) = ScreenTriangle::new([p(a), p(b), p(c)], prim) {
            prop_assert_eq!(ScreenTriangle::from_bytes(&t.to_bytes()), Some(t));
        }
    }

    /// Random soups: the scanline renderer equals the z-buffer.
    #[test]
    fn scanline_equals_zbuffer_on_random_soups(seed in any::<u64>(), n in 1usize..60) {
        let v = vp(33, 29);
        let tris = soup(seed, n, v);
        let (a, _) = zbuffer(v, &tris);
        let (b, _) = scanline(v, &tris);
        prop_assert!(a.colors() == b.colors() && a.depths() == b.depths());
    }
}
