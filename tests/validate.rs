//! `sortsim validate` against the real reference programs: SimGrid (Debian's python3-simgrid)
//! for the `flow` network model and Mesa's llvmpipe (python3-moderngl over EGL) for the
//! rasterizer. Both are installed by the tests themselves when missing (tests/common).

use crate::common;

use std::process::{Command, Output};

use common::{assert_refused, python_module, scratch};
use serde_json::Value;

const GL_PACKAGES: &[&str] = &[
    "python3-moderngl",
    "libegl1",
    "libegl-mesa0",
    "libgl1-mesa-dri",
];

fn sortsim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .args(args)
        .output()
        .expect("sortsim runs")
}

fn report(dir: &std::path::Path, name: &str) -> Value {
    let text = std::fs::read_to_string(dir.join(name)).expect("report written");
    serde_json::from_str(&text).expect("report is JSON")
}

#[test]
fn flow_agrees_with_simgrid_on_every_message() {
    python_module("simgrid", &["python3-simgrid"]);
    let out = scratch("validate-network");
    let run = sortsim(&["validate", "network", "-o", out.to_str().unwrap()]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let v = report(&out, "network.json");
    let cases = v["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 14, "the full set of patterns ran");
    for c in cases {
        // Issue 15, part 1: every message's transfer time within 0.1% of SimGrid's (f64
        // max-min against sortsim's whole bits per second and picoseconds).
        let diff = c["max_rel_diff"].as_f64().unwrap();
        assert!(diff <= 1e-3, "{}: {diff}", c["name"]);
        // The comparison is only worth something where messages share links: in every
        // case most of them take longer than alone.
        let (contended, messages) = (
            c["contended"].as_u64().unwrap(),
            c["messages"].as_u64().unwrap(),
        );
        assert!(
            2 * contended > messages,
            "{}: {contended} of {messages} contended",
            c["name"]
        );
    }
    // Issue 32: fat-trees and dragonflies are built by SimGrid's own cluster zones, and every
    // ordered pair's route of SimGrid's rule is sortsim's, link for link, except where
    // SimGrid's is not a path (a dragonfly's route inside a group from a chassis other than
    // 0: 144 of the 3x2x3x2 dragonfly's 1,260 pairs, each counted, none on the other shapes).
    let switched: Vec<&Value> = cases
        .iter()
        .filter(|c| c["topology"] == "fat-tree" || c["topology"] == "dragonfly")
        .collect();
    assert_eq!(switched.len(), 5);
    for c in &switched {
        let n = c["dims"].as_array().unwrap();
        let hosts: u64 = match c["topology"].as_str().unwrap() {
            "fat-tree" => n[..n.len() / 3]
                .iter()
                .map(|d| d.as_u64().unwrap())
                .product(),
            _ => n.iter().map(|d| d.as_u64().unwrap()).product(),
        };
        assert_eq!(c["routes_compared"], hosts * (hosts - 1), "{}", c["name"]);
        assert_eq!(c["routes_differing"], 0, "{}", c["name"]);
        let not_paths = c["simgrid_routes_not_paths"].as_u64().unwrap();
        match c["name"].as_str().unwrap() {
            "all-to-all-dragonfly-3x2x3x2" => assert_eq!(not_paths, 144),
            name => assert_eq!(not_paths, 0, "{name}"),
        }
    }
    assert_eq!(v["routes_differing"], 0);
    assert_eq!(v["pass"], true);
    let costs = report(&out, "cost.json");
    assert_eq!(costs["network"].as_array().unwrap().len(), 14);
    let md = std::fs::read_to_string(out.join("validate.md")).unwrap();
    assert!(
        md.contains("transpose-mesh-16x16") && md.contains("agrees"),
        "{md}"
    );
}

#[test]
fn rasterizer_agrees_with_llvmpipe_pixel_for_pixel() {
    python_module("moderngl", GL_PACKAGES);
    let out = scratch("validate-raster");
    let run = sortsim(&["validate", "raster", "-o", out.to_str().unwrap()]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let v = report(&out, "raster.json");
    assert!(
        v["renderer"].as_str().unwrap().contains("llvmpipe"),
        "{}",
        v["renderer"]
    );
    let cases = v["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 6);
    // The far fan measures GL's clipper: its rim lies 3,000 px out, beyond GL's 2048 px
    // framebuffer, and the clipped polygons' float vertices move edges that sortsim keeps
    // (tests/raster_far.rs holds sortsim to an exact referee there). Measured: 165 pixels.
    let (far, cases): (Vec<&Value>, Vec<&Value>) =
        cases.iter().partition(|c| c["name"] == "far-fan");
    assert_eq!(far[0]["gl_clipped"], 5000);
    assert!(
        far[0]["coverage_differences"].as_u64().unwrap() > 0,
        "GL's clipper moved no edge: {}",
        far[0]
    );
    assert_eq!(v["pass"], true, "the unclipped cases agree");
    for c in &cases {
        let name = c["name"].as_str().unwrap();
        // Issue 15, part 2: no pixel differs except depth ties between triangles that both
        // cover the pixel centre at depths within llvmpipe's 24-bit resolution.
        assert_eq!(c["coverage_differences"], 0, "{name}");
        let covered = c["covered"].as_u64().unwrap();
        assert!(covered > 50_000, "{name}: {covered} pixels drawn");
        assert!(
            c["triangles"].as_u64().unwrap() > 2_000,
            "{name}: several thousand triangles"
        );
        assert_eq!(c["gl_clipped"], 0, "{name}: GL clipped a triangle");
        // Ties are rare: at most one pixel in ten thousand.
        assert!(
            c["depth_ties"].as_u64().unwrap() * 10_000 <= covered,
            "{name}"
        );
    }
    // The fill rule is really exercised: the fans put pixel centres exactly on horizontal
    // edges, which the other y convention gives to the other triangle.
    let fans = cases.iter().find(|c| c["name"] == "random-fans").unwrap();
    assert!(
        fans["other_convention_differences"].as_u64().unwrap() > 100,
        "{fans}"
    );
    // Triangles cross the image border and are still drawn alike.
    let torus = cases.iter().find(|c| c["name"] == "torus").unwrap();
    assert!(torus["crossing_border"].as_u64().unwrap() > 0, "{torus}");
    assert_eq!(v["pass"], true);
}

#[test]
fn a_missing_interpreter_or_module_is_named_with_what_to_install() {
    let out = scratch("validate-missing");
    let run = Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .args([
            "validate",
            "network",
            "--quick",
            "-o",
            out.to_str().unwrap(),
        ])
        .env("SORTSIM_PYTHON", "/nonexistent/python3")
        .output()
        .unwrap();
    assert_refused(&run, "no interpreter", "apt-get install python3");

    // A Python without its site packages cannot import SimGrid or moderngl.
    let python = common::installed("python3", &["python3"]);
    let bare = out.join("report");
    std::fs::create_dir_all(&out).unwrap();
    let wrapper = out.join("bare-python");
    std::fs::write(
        &wrapper,
        format!("#!/bin/sh\nexec {} -S -I \"$@\"\n", python.display()),
    )
    .unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&wrapper, std::fs::Permissions::from_mode(0o755)).unwrap();
    for (what, package) in [
        ("network", "python3-simgrid"),
        ("raster", "python3-moderngl"),
    ] {
        let run = Command::new(env!("CARGO_BIN_EXE_sortsim"))
            .args(["validate", what, "--quick", "-o", bare.to_str().unwrap()])
            .env("SORTSIM_PYTHON", &wrapper)
            .output()
            .unwrap();
        assert_refused(&run, what, package);
    }
}

#[test]
fn an_unknown_part_or_an_unwritable_folder_is_refused_before_anything_runs() {
    let run = sortsim(&["validate", "bogus"]);
    assert_refused(
        &run,
        "unknown part",
        "possible values: network, raster, all",
    );
    let dir = scratch("validate-file");
    std::fs::create_dir_all(dir.parent().unwrap()).unwrap();
    std::fs::write(&dir, "a file, not a folder").unwrap();
    let out = dir.join("report");
    let run = sortsim(&[
        "validate",
        "network",
        "--quick",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_refused(&run, "unwritable folder", "cannot write");
}
