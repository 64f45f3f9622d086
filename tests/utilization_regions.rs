//! The utilization simulator's accurate region times (paper 002: "based on the number of
//! pixels in each triangle and the number of scan lines crossed") equal what rasterizing each
//! region on its own costs: the triangles classified into the region, drawn in order into a
//! target holding only that region, priced op by op.
//!
//! Must never reuse the simulator's tables for the expected side: the reference is the
//! rasterizer's own region target and counters.

use std::path::Path;

use sortsim::algo::image_space::regions::RegionGrid;
use sortsim::algo::reference::{raster_options, viewport};
use sortsim::algo::sort_middle::utilization::{FrameProfile, Prices};
use sortsim::raster::{draw_screen_triangles, setup_mesh, RegionSet};
use sortsim::scene::Scene;
use sortsim::units::SimTime;

/// Prices that are distinct primes, so that a count landing on the wrong operation shows.
fn prices() -> Prices {
    Prices {
        transform_vertex: SimTime::from_ps(0),
        setup_triangle: SimTime::from_ps(1_000_003),
        span: SimTime::from_ps(10_007),
        pixel_test: SimTime::from_ps(101),
        pixel_write: SimTime::from_ps(7),
        clear_pixel: SimTime::from_ps(3),
        byte_copy: SimTime::ZERO,
        message: SimTime::ZERO,
        per_byte: SimTime::ZERO,
        fallback: false,
    }
}

fn check(scene: &str, frame: u32, region_counts: &[u32]) {
    let scene = Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(scene)).unwrap();
    let prices = prices();
    let profile = FrameProfile::new(&scene, frame, &prices).unwrap();
    let geometry = scene.frame(frame).unwrap();
    let vp = viewport(&geometry);
    let mut tris = Vec::new();
    setup_mesh(
        &geometry.vertices,
        &geometry.triangles,
        vp,
        &raster_options(&geometry),
        &mut tris,
    );
    for &count in region_counts {
        let grid = RegionGrid::with_count(vp, count).unwrap();
        let counts = profile.counts(&grid);
        let times = profile.region_times(&grid, &counts, &prices);
        let mut touched = Vec::new();
        for r in 0..grid.count() {
            let mine: Vec<_> = tris
                .iter()
                .filter(|t| {
                    touched.clear();
                    grid.touched_by(t, &mut touched);
                    touched.contains(&r)
                })
                .copied()
                .collect();
            let rect = grid.rect(r);
            let mut target = RegionSet::new(vp, vec![rect]).unwrap();
            let c = draw_screen_triangles(&mine, &mut target);
            assert_eq!(
                counts[r as usize] as u64, c.triangles_scanned,
                "{count} regions, region {r}: polygon count"
            );
            let expected = prices.clear_pixel.times(rect.pixels() as u64)
                + prices.setup_triangle.times(c.triangles_scanned)
                + prices.span.times(c.spans)
                + prices.pixel_test.times(c.pixels_tested)
                + prices.pixel_write.times(c.pixels_written);
            assert_eq!(
                times[r as usize], expected,
                "{count} regions, region {r}: {c:?}"
            );
        }
    }
}

#[test]
fn region_times_equal_rasterizing_each_region_alone() {
    // A head seen from the side (depth complexity above 1: writes depend on order), with
    // grids whose boundaries cut many spans.
    check("scenes/plb-head-standin.json", 7, &[1, 6, 35, 128]);
}
