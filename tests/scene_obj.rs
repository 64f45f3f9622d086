//! OBJ import: polygons are triangulated, missing normals and colours are tolerated, vertex
//! colours and normals are kept, and bad coordinates or indices are refused with file and
//! line. Also the `screen` camera: OBJ pixels and colours come out unchanged.

use crate::common;

use std::path::Path;

use glam::Vec3;
use sortsim::raster::{draw_mesh, fixed::channel_to_u8, Framebuffer, RasterOptions, Viewport};
use sortsim::scene::{obj, Scene, SceneError};

/// Writes `text` to a fresh temporary file, deleted when the returned path is dropped.
fn obj_file(name: &str, text: &str) -> common::Scratch {
    let path = common::scratch(name);
    std::fs::write(&*path, text).unwrap();
    path
}

fn area(m: &sortsim::scene::mesh::Mesh) -> f32 {
    m.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            (b - a).cross(c - a).length() * 0.5
        })
        .sum()
}

#[test]
fn quads_and_ngons_are_triangulated_keeping_their_area() {
    let path = obj_file(
        "poly.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 3 0 0\nv 4 0 0\nv 4.5 1 0\nv 3.5 2 0\nv 2.5 1 0\nf 1 2 3 4\nf 5 6 7 8 9\n",
    );
    let m = obj::load(&path).unwrap();
    assert_eq!(
        m.triangles.len(),
        2 + 3,
        "a quad gives 2 triangles, a pentagon 3"
    );
    // Square 1 + convex pentagon 2.5 (shoelace): triangulation keeps the area.
    assert!((area(&m) - 3.5).abs() < 1e-5, "area {}", area(&m));
}

#[test]
fn missing_normals_and_colours_are_tolerated_and_present_ones_kept() {
    let plain = obj::load(&obj_file(
        "plain.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    ))
    .unwrap();
    assert!(plain.colors.is_none() && plain.normals.is_none());
    let rich = obj::load(&obj_file(
        "rich.obj",
        "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nvn 0 0 1\nf 1//1 2//1 3//1\n",
    ))
    .unwrap();
    assert_eq!(
        rich.colors.as_deref(),
        Some(&[Vec3::X, Vec3::Y, Vec3::Z][..])
    );
    assert_eq!(rich.normals.as_ref().map(|n| n[0]), Some(Vec3::Z));
}

#[test]
fn relative_indices_resolve() {
    let m = obj::load(&obj_file(
        "relative.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n",
    ))
    .unwrap();
    assert_eq!(m.triangles.len(), 1);
}

fn refused(name: &str, text: &str) -> (usize, String) {
    match obj::load(&obj_file(name, text)) {
        Err(e @ SceneError::Obj { line, .. }) => (line, e.to_string()),
        other => panic!("{name}: expected a line-numbered OBJ error, got {other:?}"),
    }
}

#[test]
fn nan_and_infinite_coordinates_are_refused_with_file_and_line() {
    let (line, msg) = refused("nan.obj", "v 0 0 0\nv 1 0 0\nv 0 NaN 0\nf 1 2 3\n");
    assert_eq!(line, 3);
    assert!(
        msg.contains("nan.obj:3:") && msg.contains("not finite"),
        "{msg}"
    );
    let (line, msg) = refused(
        "inf.obj",
        "# comment\nv 0 0 0\nv -inf 0 0\nv 0 1 0\nf 1 2 3\n",
    );
    assert_eq!(line, 3);
    assert!(msg.contains("inf.obj:3:"), "{msg}");
    let (line, _) = refused("word.obj", "v 0 zero 0\n");
    assert_eq!(line, 1);
}

#[test]
fn out_of_range_indices_are_refused_with_file_and_line() {
    let (line, msg) = refused("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n");
    assert_eq!(line, 5);
    assert!(
        msg.contains("range.obj:5:")
            && msg.contains("face index 4 is out of range")
            && msg.contains("valid 1..=3"),
        "{msg}"
    );
    let (line, _) = refused("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
    assert_eq!(line, 4);
    let (line, _) = refused(
        "relative-out-of-range.obj",
        "v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n",
    );
    assert_eq!(line, 3);
}

/// DESIGN.md: "a triangle of one flat colour must come out in exactly that colour", and
/// screen-space input is drawn unchanged.
#[test]
fn screen_camera_draws_obj_pixels_and_colours_unchanged() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/screen-demo.json");
    let frame = Scene::load(&file).unwrap().frame(0).unwrap();
    let vp = Viewport::new(frame.width, frame.height).unwrap();
    let mut fb = Framebuffer::with_clear(vp, frame.background);
    draw_mesh(
        &frame.vertices,
        &frame.triangles,
        vp,
        &RasterOptions::default(),
        &mut fb,
    );
    let orange = [channel_to_u8(1.0), channel_to_u8(0.2), channel_to_u8(0.0)];
    let blue = [channel_to_u8(0.0), channel_to_u8(0.4), channel_to_u8(1.0)];
    assert_eq!(
        fb.color(10, 10),
        Some(orange),
        "inside the first triangle near (8, 8)"
    );
    assert_eq!(
        fb.color(30, 50),
        Some(blue),
        "inside the second, nearer triangle"
    );
    assert_eq!(fb.color(60, 4), Some([0, 0, 0]), "outside both");
    assert_eq!(fb.color(7, 30), Some([0, 0, 0]), "left of x = 8");
    // The first vertex maps to clip (2 * 8 / 64 - 1, 1 - 2 * 8 / 64, 0.5, 1).
    let v = frame.vertices[0].clip;
    assert_eq!(v.to_array(), [-0.75, 0.75, 0.5, 1.0]);
}
