//! Cameras and animation: orbit, recorded views, per-object spin and tumble move the
//! geometry as specified, and a static transform places it.

use crate::common;

use sortsim::scene::{FrameGeometry, Scene};

fn scene(name: &str, json: &str) -> Scene {
    let path = common::scratch(&format!("{name}.json"));
    std::fs::write(&*path, json).unwrap();
    Scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

const CAMERA: &str = r#""camera": { "kind": "perspective", "eye": [0, 0, 5], "target": [0, 0, 0], "fov_deg": 40, "near": 0.1, "far": 20 }"#;
const SHAPE: &str = r#"{ "generator": { "kind": "letter-b", "segments": 6, "depth": 0.2 }"#;

fn max_diff(a: &FrameGeometry, b: &FrameGeometry) -> f32 {
    a.vertices
        .iter()
        .zip(&b.vertices)
        .map(|(u, v)| (u.clip - v.clip).abs().max_element())
        .fold(0.0, f32::max)
}

#[test]
fn orbit_returns_after_a_full_turn() {
    let s = scene(
        "orbit",
        &format!(
            r#"{{ "resolution": [64, 64], "frames": 5, {CAMERA}, "animation": {{ "kind": "orbit", "degrees_per_frame": 90 }}, "geometry": [ {SHAPE} }} ] }}"#
        ),
    );
    let (f0, f1, f4) = (
        s.frame(0).unwrap(),
        s.frame(1).unwrap(),
        s.frame(4).unwrap(),
    );
    assert!(
        max_diff(&f0, &f4) < 1e-4,
        "360 degrees later the view is the same"
    );
    assert!(max_diff(&f0, &f1) > 0.1, "90 degrees later it is not");
}

#[test]
fn recorded_views_are_used_in_order_and_cycle() {
    let s = scene(
        "views",
        &format!(
            r#"{{ "resolution": [64, 64], "frames": 3, {CAMERA},
                 "animation": {{ "kind": "views", "views": [ {{ "eye": [0, 0, 5], "target": [0, 0, 0] }}, {{ "eye": [5, 0, 0], "target": [0, 0, 0] }} ] }},
                 "geometry": [ {SHAPE} }} ] }}"#
        ),
    );
    let (f0, f1, f2) = (
        s.frame(0).unwrap(),
        s.frame(1).unwrap(),
        s.frame(2).unwrap(),
    );
    assert_eq!(f0, f2, "two views cycle");
    assert!(max_diff(&f0, &f1) > 0.1);
    let still = scene(
        "still",
        &format!(r#"{{ "resolution": [64, 64], {CAMERA}, "geometry": [ {SHAPE} }} ] }}"#),
    );
    assert_eq!(
        still.frame(0).unwrap(),
        f0,
        "the first view is the camera's own"
    );
}

#[test]
fn spin_turns_about_the_object_centre() {
    // Paper 002's PLB head turns 4.5 degrees per frame: 80 frames make a full turn.
    let s = scene(
        "spin",
        &format!(
            r#"{{ "resolution": [64, 64], "frames": 81, {CAMERA},
                 "geometry": [ {SHAPE}, "transform": {{ "translate": [0.5, 0, 0] }}, "motion": {{ "kind": "spin", "axis": [0, 1, 0], "degrees_per_frame": 4.5 }} }} ] }}"#
        ),
    );
    let (f0, f40, f80) = (
        s.frame(0).unwrap(),
        s.frame(40).unwrap(),
        s.frame(80).unwrap(),
    );
    assert!(max_diff(&f0, &f80) < 1e-3, "a full turn after 80 frames");
    assert!(max_diff(&f0, &f40) > 0.05, "half a turn after 40");
    // Turning about the centre of its bounding box, the box stays where it is on screen.
    let centre_x = |f: &FrameGeometry| {
        let xs = f.vertices.iter().map(|v| v.clip.x / v.clip.w);
        let (lo, hi) = xs.fold((f32::MAX, f32::MIN), |(lo, hi), x| (lo.min(x), hi.max(x)));
        (lo + hi) * 0.5
    };
    assert!(
        (centre_x(&f0) - centre_x(&f40)).abs() < 0.02,
        "{} vs {}",
        centre_x(&f0),
        centre_x(&f40)
    );
}

#[test]
fn tumble_turns_each_part_about_its_own_centroid() {
    let s = scene(
        "tumble",
        &format!(
            r#"{{ "resolution": [64, 64], "frames": 10, {CAMERA},
                 "geometry": [ {{ "generator": {{ "kind": "random-tetrahedra", "count": 30, "size": 0.2, "seed": 9 }}, "motion": {{ "kind": "tumble", "seed": 1, "degrees_per_frame": 20 }} }} ] }}"#
        ),
    );
    let (f0, f5) = (s.frame(0).unwrap(), s.frame(5).unwrap());
    assert!(max_diff(&f0, &f5) > 1e-3, "the tetrahedra turn");
    // Each tetrahedron's 12 vertices keep their centroid (rotation about it).
    for t in 0..30 {
        let c = |f: &FrameGeometry| {
            f.vertices[t * 12..t * 12 + 12]
                .iter()
                .map(|v| v.clip)
                .sum::<glam::Vec4>()
                / 12.0
        };
        assert!(
            (c(&f0) - c(&f5)).abs().max_element() < 1e-3,
            "tetrahedron {t} moved"
        );
    }
}

#[test]
fn describe_names_size_frames_and_triangles() {
    let s = scene(
        "describe",
        &format!(
            r#"{{ "resolution": [64, 48], "frames": 3, {CAMERA}, "geometry": [ {SHAPE} }} ] }}"#
        ),
    );
    assert_eq!(
        s.describe(),
        "scene: 64x48, 3 frames, 1 object, 152 triangles per frame, perspective camera, back-face culling on"
    );
}

/// A frame built in an earlier frame's memory (as a run does, to spare the kernel zeroing
/// fresh pages every frame) is the frame built afresh, vertex for vertex; a larger earlier
/// frame's leftovers do not survive into it.
#[test]
fn a_frame_built_in_reused_memory_equals_a_fresh_one() {
    let s = Scene::load(&common::root().join("scenes/p000-letter-b.json")).unwrap();
    let frames = s.frame_count().min(4);
    assert!(frames >= 2, "the letter B animates over several frames");
    for n in 1..frames {
        let fresh = s.frame(n).unwrap();
        let reused = s.frame_reusing(n, Some(s.frame(n - 1).unwrap())).unwrap();
        assert_ne!(
            s.frame(n - 1).unwrap().vertices,
            fresh.vertices,
            "frames {} and {n} differ, so reuse is tested",
            n - 1
        );
        assert_eq!(reused.vertices, fresh.vertices, "frame {n}");
        assert_eq!(reused.triangles, fresh.triangles, "frame {n}");
    }
    let mut big = s.frame(0).unwrap();
    big.vertices.extend_from_within(..);
    big.triangles.extend_from_within(..);
    let reused = s.frame_reusing(1, Some(big)).unwrap();
    assert_eq!(reused.vertices, s.frame(1).unwrap().vertices);
    assert_eq!(reused.triangles, s.frame(1).unwrap().triangles);
}
