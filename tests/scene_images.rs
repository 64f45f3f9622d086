//! Every bundled scene, drawn two ways: the scanline z-buffer (paper 001's sequential
//! renderer) must produce the z-buffer's image bit for bit, and `sortsim render` must write
//! that image as a PNG that decodes to the same pixels.

use crate::common;

use std::path::Path;

use sortsim::algo::reference;
use sortsim::raster::{render_scanlines_into, setup_mesh, Framebuffer};
use sortsim::scene::Scene;

fn bundled_scenes() -> Vec<std::path::PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    files
}

#[test]
fn scanline_zbuffer_equals_zbuffer_on_every_bundled_scene() {
    let scenes = bundled_scenes();
    assert!(scenes.len() >= 20, "{} scenes", scenes.len());
    for path in scenes {
        let scene = Scene::load(&path).unwrap();
        let frame = scene.frame(0).unwrap();
        let (zbuffer, counts) = reference::render(&frame);
        assert!(
            counts.pixels_written > 0,
            "{}: draws something",
            path.display()
        );
        let mut tris = Vec::new();
        setup_mesh(
            &frame.vertices,
            &frame.triangles,
            reference::viewport(&frame),
            &reference::raster_options(&frame),
            &mut tris,
        );
        let mut scanline = Framebuffer::with_clear(reference::viewport(&frame), frame.background);
        render_scanlines_into(&tris, &mut scanline, frame.background);
        assert_eq!(scanline.colors(), zbuffer.colors(), "{}", path.display());
    }
}

#[test]
fn render_writes_the_reference_image() {
    let out = common::scratch("render.png");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "render",
            "scenes/p003-zinnia.json",
            "--frame",
            "0",
            "-o",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let scene = Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/p003-zinnia.json"))
        .unwrap();
    let (image, _) = reference::render(&scene.frame(0).unwrap());
    let decoder = png::Decoder::new(std::fs::File::open(&out).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (image.width(), image.height()));
    let pixels: Vec<[u8; 3]> = buf[..info.buffer_size()]
        .chunks(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    assert_eq!(pixels, image.colors());
    let stdout = String::from_utf8_lossy(&status.stdout);
    assert!(
        stdout.contains("\"pixels_written\""),
        "prints the frame's statistics: {stdout}"
    );
}
