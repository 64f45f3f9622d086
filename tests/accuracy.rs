//! `sortsim accuracy` and its parts: the band-rendered supersampled reference (flat triangle,
//! refinement towards a finer reference), the image error of the one-sample render against
//! it, the study's guaranteed fidelity relation, and the command end to end (files written,
//! accuracy.json byte-identical across runs, modes the algorithm lacks refused with exit 2).

use crate::common;

use std::path::Path;
use std::process::{Command, Output};

use glam::{Vec3, Vec4};
use sortsim::accuracy::{image_error, render_reference, run_study, AaMode, StudyConfig};
use sortsim::algo::reference;
use sortsim::net::Fidelity;
use sortsim::raster::Vertex;
use sortsim::scene::{FrameGeometry, Scene};
use sortsim::spec::run::RunSpec;

const SIZE: u32 = 64;
/// The flat triangle's corners in pixels (clockwise on screen, y down).
const CORNERS: [(f64, f64); 3] = [(5.3, 7.1), (58.7, 12.4), (20.2, 57.9)];

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// One large flat-coloured triangle on black.
fn flat_triangle() -> FrameGeometry {
    let v = |(x, y): (f64, f64)| Vertex {
        clip: Vec4::new(
            (2.0 * x / f64::from(SIZE) - 1.0) as f32,
            (1.0 - 2.0 * y / f64::from(SIZE)) as f32,
            0.5,
            1.0,
        ),
        color: Vec3::new(0.8, 0.5, 0.3),
    };
    FrameGeometry {
        width: SIZE,
        height: SIZE,
        vertices: CORNERS.iter().map(|&c| v(c)).collect(),
        triangles: vec![[0, 1, 2]],
        cull_backfaces: false,
        background: [0, 0, 0],
    }
}

/// Distance from `p` to the segment `a`-`b`, and whether the foot of the perpendicular lies
/// on the segment at least `margin` from both ends.
fn to_segment(p: (f64, f64), a: (f64, f64), b: (f64, f64), margin: f64) -> (f64, bool) {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len = (dx * dx + dy * dy).sqrt();
    let t = ((p.0 - a.0) * dx + (p.1 - a.1) * dy) / len;
    let tc = t.clamp(0.0, len);
    let (fx, fy) = (a.0 + dx * tc / len, a.1 + dy * tc / len);
    let d = ((p.0 - fx).powi(2) + (p.1 - fy).powi(2)).sqrt();
    (d, t > margin && t < len - margin)
}

fn inside(p: (f64, f64)) -> bool {
    (0..3).all(|i| {
        let (a, b) = (CORNERS[i], CORNERS[(i + 1) % 3]);
        (b.0 - a.0) * (p.1 - a.1) - (b.1 - a.1) * (p.0 - a.0) > 0.0
    })
}

fn edges(p: (f64, f64), margin: f64) -> impl Iterator<Item = (f64, bool)> {
    (0..3).map(move |i| to_segment(p, CORNERS[i], CORNERS[(i + 1) % 3], margin))
}

#[test]
fn flat_triangle_reference_interior_exact_edges_between() {
    let frame = flat_triangle();
    let (plain, _) = reference::render(&frame);
    let colour = plain.color(30, 25).unwrap();
    assert!(colour.iter().all(|&c| c > 0), "{colour:?}");
    let r = render_reference(&frame, 16).unwrap();
    let levels = r.levels();
    let (mut interior, mut edge, mut near_edge) = (0, 0, 0);
    for y in 0..SIZE {
        for x in 0..SIZE {
            let p = (f64::from(x) + 0.5, f64::from(y) + 0.5);
            let l = levels[(y * SIZE + x) as usize];
            let nearest = edges(p, 0.0).map(|e| e.0).fold(f64::MAX, f64::min);
            if nearest < 0.72 {
                near_edge += 1;
            }
            if inside(p) && nearest > 0.75 {
                interior += 1;
                assert_eq!(l, colour.map(f64::from), "interior pixel ({x}, {y})");
            } else if edges(p, 1.0).any(|(d, on)| on && d < 0.25) {
                edge += 1;
                for k in 0..3 {
                    assert!(
                        l[k] > 0.0 && l[k] < f64::from(colour[k]),
                        "edge pixel ({x}, {y}) channel {k}: {}",
                        l[k]
                    );
                }
            } else if !inside(p) && nearest > 0.75 {
                assert_eq!(l, [0.0; 3], "outside pixel ({x}, {y})");
            }
        }
    }
    assert!(
        interior > 800 && edge > 50,
        "{interior} interior, {edge} edge"
    );
    // Only pixels an edge passes through can differ from the one-sample render.
    let e = image_error(plain.colors(), &levels).unwrap();
    let bound = near_edge as f64 / f64::from(SIZE * SIZE) * 255.0;
    assert!(
        e.mae_levels > 0.0 && e.mae_levels <= bound,
        "MAE {} against bound {bound}",
        e.mae_levels
    );
}

/// Error of one reference (rounded to 8 bits) against a finer one.
fn mae_against(coarse: u32, fine: &[[f64; 3]], frame: &FrameGeometry) -> f64 {
    let r = render_reference(frame, coarse).unwrap().to_framebuffer();
    image_error(r.colors(), fine).unwrap().mae_levels
}

#[test]
fn a_finer_reference_is_closer_to_a_32x_one() {
    let demo = Scene::load(&root().join("scenes/screen-demo.json"))
        .unwrap()
        .frame(0)
        .unwrap();
    for frame in [flat_triangle(), demo] {
        let fine = render_reference(&frame, 32).unwrap().levels();
        let (m4, m16) = (
            mae_against(4, &fine, &frame),
            mae_against(16, &fine, &frame),
        );
        assert!(m16 <= m4, "16x: {m16}, 4x: {m4}");
        assert!(m4 > 0.0, "a 4x reference differs from a 32x one somewhere");
    }
}

#[test]
fn reference_is_independent_of_banding_and_columns() {
    // 1100 * 16 samples exceed the rasterizer's largest viewport, so the reference is drawn
    // in two columns per band; a flat rectangle spanning the seam must show no seam.
    let (w, h) = (1100u32, 8u32);
    let v = |x: f32, y: f32| Vertex {
        clip: Vec4::new(x, y, 0.5, 1.0),
        color: Vec3::new(1.0, 1.0, 1.0),
    };
    let frame = FrameGeometry {
        width: w,
        height: h,
        vertices: vec![v(-0.9, 0.9), v(0.9, 0.9), v(0.9, -0.9), v(-0.9, -0.9)],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        cull_backfaces: false,
        background: [0, 0, 0],
    };
    let r = render_reference(&frame, 16).unwrap();
    let levels = r.levels();
    for x in 100..1000 {
        for y in 2..6 {
            assert_eq!(levels[(y * w + x) as usize], [255.0; 3], "({x}, {y})");
        }
    }
}

fn study(machine: &str, fidelities: Vec<Fidelity>) -> sortsim::accuracy::Study {
    study_with(machine, fidelities, Default::default())
}

fn study_with(
    machine: &str,
    fidelities: Vec<Fidelity>,
    set: std::collections::BTreeMap<String, String>,
) -> sortsim::accuracy::Study {
    let cfg = StudyConfig {
        run: RunSpec {
            schema: None,
            machine: root().join(machine),
            scene: root().join("scenes/screen-demo.json"),
            algo: "sort-middle/static".into(),
            procs: 4,
            frames: None,
            seed: 1,
            set,
        },
        modes: vec![AaMode::None],
        fidelities,
        reference_scale: 8,
    };
    run_study(&cfg, &mut |_| {}).unwrap()
}

#[test]
fn ideal_equals_hops_under_wormhole_switching() {
    // Under wormhole switching `ideal` and `hops` charge every message the same formula
    // (net/transport/contention_free.rs), so the runs are identical; no other order between
    // levels is guaranteed for a whole frame of an algorithm.
    let s = study("machines/delta.json", Fidelity::ALL.to_vec());
    let t: Vec<_> = s.fidelities.iter().map(|f| f.measure.clone()).collect();
    assert_eq!(s.fidelities[0].fidelity, Fidelity::Ideal);
    assert_eq!(s.fidelities[1].fidelity, Fidelity::Hops);
    assert_eq!(t[0], t[1]);
    assert!(t
        .iter()
        .all(|m| m.mean_frame > sortsim::units::SimTime::ZERO));
    let none = &s.modes[0];
    assert!(none.error.mae_levels > 0.0);
    assert!(none.measure.memory_max >= none.measure.memory_mean);
    assert!(none.measure.memory_max.get() > 0);
}

#[test]
fn mode_none_and_the_fidelity_runs_drop_a_user_aa_option() {
    // `none` means no option at all, whatever --set says; the runs then succeed whether or
    // not the algorithm knows `aa`.
    let set = [("aa".to_string(), "supersample:16".to_string())].into();
    let s = study_with("machines/delta.json", vec![Fidelity::Hops], set);
    assert!(s.base.options.pairs().any(|(k, _)| k == "aa"));
    assert_eq!(s.modes.len(), 1);
    assert_eq!(s.fidelities.len(), 1);
    let plain = study("machines/delta.json", vec![Fidelity::Hops]);
    assert_eq!(s.modes[0].measure, plain.modes[0].measure);
    assert_eq!(s.modes[0].image, plain.modes[0].image);
}

fn sortsim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("sortsim runs")
}

fn temp_dir(name: &str) -> common::Scratch {
    common::scratch(name)
}

fn accuracy_args<'a>(modes: &'a str, out: &'a str) -> Vec<&'a str> {
    vec![
        "accuracy",
        "scenes/screen-demo.json",
        "--machine",
        "machines/delta.json",
        "--algo",
        "sort-middle/static",
        "--procs",
        "4",
        "--modes",
        modes,
        "--fidelities",
        "ideal,flow",
        "-o",
        out,
    ]
}

#[test]
fn accuracy_command_writes_a_deterministic_report() {
    let (a, b) = (temp_dir("a"), temp_dir("b"));
    for dir in [&a, &b] {
        let out = sortsim(&accuracy_args("none", dir.to_str().unwrap()));
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    for name in [
        "accuracy.json",
        "accuracy.md",
        "cost.json",
        "fidelity.txt",
        "reference.png",
        "frame-none.png",
        "error-vs-frame-time.svg",
        "error-vs-frame-time.png",
        "error-vs-memory.svg",
        "error-vs-memory.png",
        "fidelity-vs-wall.svg",
    ] {
        assert!(a.join(name).is_file(), "{name} missing");
    }
    let json = std::fs::read(a.join("accuracy.json")).unwrap();
    assert_eq!(json, std::fs::read(b.join("accuracy.json")).unwrap());
    assert_eq!(
        std::fs::read(a.join("error-vs-memory.svg")).unwrap(),
        std::fs::read(b.join("error-vs-memory.svg")).unwrap()
    );
    let v: serde_json::Value = serde_json::from_slice(&json).unwrap();
    assert_eq!(v["reference"]["samples_per_pixel"], 256);
    assert_eq!(v["modes"][0]["mode"], "none");
    assert!(v["modes"][0]["mae_levels"].as_f64().unwrap() > 0.0);
    assert_eq!(v["fidelities"].as_array().unwrap().len(), 2);
    assert!(!String::from_utf8_lossy(&json).contains("wall"));
}

#[test]
fn a_mode_the_machine_cannot_price_is_refused_before_anything_runs() {
    // With every anti-aliasing operation priced at zero, adaptive supersampling would cost
    // nothing: the study must refuse it (exit 2, naming the operations) and write nothing.
    let dir = temp_dir("unpriced");
    let mut args = accuracy_args("none,adaptive", dir.to_str().unwrap());
    let free = [
        "machine.cpu.costs.coverage_mask=0ns",
        "machine.cpu.costs.subpixel_test=0ns",
        "machine.cpu.costs.subpixel_write=0ns",
        "machine.cpu.costs.reclaim_check=0ns",
        "machine.cpu.costs.resolve_pixel=0ns",
    ];
    for f in &free {
        args.extend(["--set", f]);
    }
    let out = sortsim(&args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("prices none of the anti-aliasing operations")
            && stderr.contains("coverage_mask"),
        "{stderr}"
    );
    assert!(!dir.exists(), "a refused study wrote output");
}

/// Sort-last algorithms take every mode: adaptive supersampling lowers PixelFlow's image
/// error against the reference at a price in frame time and memory.
#[test]
fn a_sort_last_study_prices_adaptive_supersampling() {
    let dir = temp_dir("sort-last");
    let out = sortsim(&[
        "accuracy",
        "scenes/spd-teapot.json",
        "--machine",
        "machines/pixelflow-pipeline.json",
        "--algo",
        "sort-last/pixelflow",
        "--procs",
        "4",
        "--modes",
        "none,adaptive",
        "--fidelities",
        "ideal",
        "-o",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("accuracy.json")).unwrap()).unwrap();
    let modes = json["modes"].as_array().expect("modes");
    let field = |i: usize, k: &str| {
        modes[i][k]
            .as_f64()
            .unwrap_or_else(|| panic!("{k}: {json}"))
    };
    assert_eq!(modes[1]["mode"], "adaptive");
    // Measured: MAE 0.172 -> 0.077 levels at 8 stages; asked: at least a third less.
    assert!(
        field(1, "mae_levels") < 0.67 * field(0, "mae_levels"),
        "{json}"
    );
    assert!(
        field(1, "mean_frame_s") > field(0, "mean_frame_s"),
        "{json}"
    );
}
