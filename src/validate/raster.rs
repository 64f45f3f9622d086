//! The rasterizer against Mesa's llvmpipe: the same snapped screen-space triangles drawn by
//! sortsim and by OpenGL, one flat id per triangle, compared pixel for pixel.
//!
//! Owns the cases (meshes the project generates, projected by sortsim's own front end, plus
//! random screen-space fans on a coarse subpixel grid that put many pixel centres exactly on
//! edges), the triangle file handed to OpenGL and the classification of differing pixels.
//! Must never hand OpenGL anything but sortsim's snapped vertices: the comparison is of
//! coverage, the fill rule and the depth test, not of projection.
//!
//! Conventions that make the two agree (found by running both ways, see [`Convention`]):
//! pixel centres at half-integers in both; GL's window y equals sortsim's pixel y (so GL's
//! bottom row is sortsim's top row); depth test LESS with triangles drawn in primitive order,
//! which is sortsim's tie rule (equal depth keeps the lower primitive id).

use std::ffi::OsStr;
use std::path::Path;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::python::{self, ToolError, LLVMPIPE_RASTER};
use crate::algo::reference::{raster_options, viewport};
use crate::raster::{
    draw_screen_triangles, setup_mesh, Depth, Framebuffer, RasterTriangle, ScreenTriangle,
    ScreenVertex, Sub, Viewport,
};
use crate::scene::Scene;

/// The largest depth gap, in sortsim's 32-bit depth units, at which two triangles covering a
/// pixel may be ordered differently by llvmpipe: 16 units of its 24-bit depth buffer (2^8
/// sortsim units each), for the buffer's rounding plus llvmpipe's float interpolation of z.
/// Such pixels are depth ties between intersecting or touching triangles, counted apart.
pub const DEPTH_TIE: u32 = 16 << 8;

/// Images are 512 x 512, drawn by GL at the centre of a 2048 x 2048 framebuffer: powers of
/// two keep OpenGL's viewport transform exact, so GL sees sortsim's vertices on the 1/256
/// grid unchanged, and the margin keeps triangles that cross the image's border inside GL's
/// viewport. GL clips a triangle that leaves its viewport, and the clipped polygon's float
/// vertices move its edges by about a hundredth of a subpixel: with a 512 framebuffer, one
/// teapot pixel centre 0.011 subpixel from a shared edge went to the other triangle (the
/// same two triangles moved 64 px inside the image agree). That is GL's clipper, not its
/// rasterizer, and sortsim's clipping is not what is compared here.
const SIZE: u32 = 512;
const GL_FRAMEBUFFER: u32 = 2048;

/// How GL's window coordinates map to sortsim's pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Convention {
    /// Window y = pixel y: GL's bottom-left origin is sortsim's top-left.
    WindowYIsPixelY,
    /// Window y = height - pixel y: the image upright in GL's own orientation.
    WindowYFlipped,
}

impl Convention {
    pub fn describe(self) -> &'static str {
        match self {
            Convention::WindowYIsPixelY => "GL's window y = sortsim's pixel y (y down)",
            Convention::WindowYFlipped => "GL's window y = height - sortsim's pixel y (y up)",
        }
    }

    fn script_arg(self) -> &'static str {
        match self {
            Convention::WindowYIsPixelY => "1",
            Convention::WindowYFlipped => "-1",
        }
    }
}

/// One mesh to draw.
pub struct Case {
    pub name: String,
    pub what: &'static str,
    /// Snapped triangles in drawing order; triangle `i` gets id `i + 1` (0 is background).
    pub triangles: Vec<ScreenTriangle>,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CaseResult {
    pub name: String,
    pub what: &'static str,
    pub triangles: usize,
    /// Pixels sortsim covers.
    pub covered: u64,
    /// Pixels where the two differ in which triangle (or background) they show, other than
    /// depth ties: the target is 0.
    pub coverage_differences: u64,
    /// Pixels where both triangles cover the centre and their depths there differ by at most
    /// [`DEPTH_TIE`], drawn in a different order by the two.
    pub depth_ties: u64,
    /// The largest depth gap (sortsim units) among the depth ties.
    pub largest_tie_gap: u32,
    /// Triangles with a vertex outside GL's framebuffer, which GL clips: a case with any is a
    /// measurement of GL's clipper (`far-fan`), left out of the pass/fail count.
    pub gl_clipped: usize,
    /// Triangles that cross the image's border (drawn unclipped by GL thanks to the margin).
    pub crossing_border: usize,
    /// Differing pixels had GL been given the other y convention: how many pixel centres lie
    /// exactly on horizontal edges, where only the fill rule decides.
    pub other_convention_differences: u64,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RasterValidation {
    pub renderer: String,
    pub convention: Convention,
    pub depth_tie: u32,
    pub coverage_differences: u64,
    pub pass: bool,
    pub cases: Vec<CaseResult>,
}

#[derive(Clone, Debug, Serialize)]
pub struct CaseCost {
    pub name: String,
    pub triangles: usize,
    pub llvmpipe_wall_s: f64,
}

#[derive(Deserialize)]
struct GlAnswer {
    renderer: String,
    wall_s: f64,
}

/// Scenes built from the project's generators (sphere, torus, the SPD teapot) and random
/// screen-space fans; `quick` keeps the first three.
pub fn cases(quick: bool) -> Vec<Case> {
    let mut all = vec![
        scene_case(
            "uv-sphere",
            "UV sphere, 48 x 96, perspective, back faces culled",
            r#"{"kind": "uv-sphere", "rings": 48, "segments": 96}"#,
            "[0, 0.6, 2.6]",
        ),
        scene_case(
            "torus",
            "torus, 96 x 48, tilted so the far side shows through the hole",
            r#"{"kind": "torus", "rings": 96, "segments": 48, "minor": 0.35}"#,
            "[0, 1.6, 2.2]",
        ),
        fans("random-fans", 400, 12, 7),
    ];
    if !quick {
        all.push(scene_file_case(
            "spd-teapot",
            "Newell's teapot, n = 21, frame 0 of scenes/spd-teapot.json",
            include_str!("../../scenes/spd-teapot.json"),
        ));
        all.push(fans("random-fans-dense", 1500, 8, 11));
        all.push(far_fan("far-fan", 5_000, 3_000.0));
    }
    all
}

/// A closed fan of `n` slivers around the image's centre whose rim lies `radius` px out,
/// beyond GL's framebuffer: sortsim draws it with its own edges (tests/raster_far.rs holds it
/// to an exact referee), GL clips it, and the pixels its clipper moves are what this case
/// measures.
fn far_fan(name: &str, n: u32, radius: f64) -> Case {
    let centre = f64::from(SIZE) / 2.0;
    let vertex = |x: f64, y: f64, z: f64| ScreenVertex {
        x: Sub::snap(x).expect("finite"),
        y: Sub::snap(y).expect("finite"),
        z: Depth::from_unit(z).expect("a depth"),
        rgb: [0; 3],
    };
    let hub = vertex(centre + 0.37, centre - 0.21, 0.5);
    let rim: Vec<ScreenVertex> = (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * f64::from(k) / f64::from(n);
            vertex(centre + radius * a.cos(), centre + radius * a.sin(), 0.5)
        })
        .collect();
    let triangles = (0..n as usize)
        .filter_map(|k| ScreenTriangle::new([hub, rim[k], rim[(k + 1) % rim.len()]], k as u32))
        .collect();
    Case {
        name: name.to_string(),
        what: "a closed fan of 5,000 slivers whose rim lies 3,000 px out (GL clips it)",
        triangles,
    }
}

/// A generator seen through a perspective camera, set up by sortsim's front end.
fn scene_case(name: &str, what: &'static str, generator: &str, eye: &str) -> Case {
    let spec = format!(
        r#"{{"resolution": [{SIZE}, {SIZE}], "frames": 1,
            "camera": {{"kind": "perspective", "eye": {eye}, "target": [0, 0, 0],
                        "up": [0, 1, 0], "fov_deg": 45, "near": 0.05, "far": 100}},
            "geometry": [{{"generator": {generator}, "color": [0.8, 0.5, 0.3]}}]}}"#
    );
    scene_file_case(name, what, &spec)
}

/// Frame 0 of a scene spec (its resolution must be [`SIZE`] square), set up by sortsim's
/// front end.
fn scene_file_case(name: &str, what: &'static str, spec: &str) -> Case {
    let file = Path::new("validate-raster.json");
    let spec: crate::spec::scene::SceneSpec =
        crate::spec::parse_json(file, spec).expect("built-in validation scene parses");
    assert_eq!(
        spec.resolution,
        [SIZE, SIZE],
        "validation images are {SIZE} square"
    );
    let scene = Scene::from_spec(file, spec).expect("built-in validation scene is valid");
    let frame = scene.frame(0).expect("frame 0 exists");
    let mut triangles = Vec::new();
    setup_mesh(
        &frame.vertices,
        &frame.triangles,
        viewport(&frame),
        &raster_options(&frame),
        &mut triangles,
    );
    Case {
        name: name.to_string(),
        what,
        triangles,
    }
}

/// `count` fans of `blades` triangles around random centres, every vertex on a half-pixel
/// grid (so many pixel centres lie exactly on edges) at a random depth (so fans cross each
/// other in depth), from a ChaCha8 stream seeded by `seed`.
fn fans(name: &str, count: u32, blades: u32, seed: u64) -> Case {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let half_pixels = 2 * SIZE as i32;
    let vertex = |rng: &mut ChaCha8Rng, x: i32, y: i32| ScreenVertex {
        x: Sub::from_raw(x.clamp(0, half_pixels) * 128).expect("inside the screen"),
        y: Sub::from_raw(y.clamp(0, half_pixels) * 128).expect("inside the screen"),
        z: Depth::from_unit(rng.gen_range(0.2..0.8)).expect("a depth"),
        rgb: [0; 3],
    };
    let mut triangles = Vec::new();
    for _ in 0..count {
        let (cx, cy) = (rng.gen_range(0..half_pixels), rng.gen_range(0..half_pixels));
        let radius = rng.gen_range(4..80) as f64;
        let centre = vertex(&mut rng, cx, cy);
        let rim: Vec<ScreenVertex> = (0..blades)
            .map(|k| {
                let angle =
                    std::f64::consts::TAU * (k as f64 + rng.gen_range(0.0..0.8)) / blades as f64;
                let r = radius * rng.gen_range(0.5..1.0);
                let x = cx + (r * angle.cos()).round() as i32;
                let y = cy + (r * angle.sin()).round() as i32;
                vertex(&mut rng, x, y)
            })
            .collect();
        for k in 0..blades as usize {
            let prim = triangles.len() as u32;
            if let Some(t) = ScreenTriangle::new([centre, rim[k], rim[(k + 1) % rim.len()]], prim) {
                triangles.push(t);
            }
        }
    }
    Case {
        name: name.to_string(),
        what: "random screen-space fans on the half-pixel grid at random depths",
        triangles,
    }
}

/// Each triangle flat in the colour that encodes its id (`i + 1`, 24 bits).
fn with_ids(triangles: &[ScreenTriangle]) -> Vec<ScreenTriangle> {
    triangles
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let id = (i as u32 + 1).to_le_bytes();
            let v = (*t.vertices()).map(|v| ScreenVertex {
                rgb: [id[0], id[1], id[2]],
                ..v
            });
            ScreenTriangle::new(v, t.prim()).expect("recolouring keeps the area")
        })
        .collect()
}

/// sortsim's image: the id shown at every pixel, rows from the top.
fn sortsim_ids(triangles: &[ScreenTriangle]) -> Vec<u32> {
    let vp = Viewport::new(SIZE, SIZE).expect("a valid size");
    let mut fb = Framebuffer::with_clear(vp, [0; 3]);
    draw_screen_triangles(triangles, &mut fb);
    fb.colors()
        .iter()
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], 0]))
        .collect()
}

/// The triangle file for the GL script: per vertex x, y, z as f32 and the id as u32.
fn gl_input(triangles: &[ScreenTriangle]) -> Vec<u8> {
    let mut out = Vec::with_capacity(triangles.len() * 48);
    for (i, t) in triangles.iter().enumerate() {
        for v in t.vertices() {
            let sub = |s: Sub| s.raw() as f32 / 256.0;
            let z = (f64::from(v.z.raw()) / f64::from(Depth::FAR.raw())) as f32;
            for f in [sub(v.x), sub(v.y), z] {
                out.extend_from_slice(&f.to_le_bytes());
            }
            out.extend_from_slice(&(i as u32 + 1).to_le_bytes());
        }
    }
    out
}

/// llvmpipe's image under `convention`, and what the script reported.
fn llvmpipe_ids(
    input: &Path,
    work: &Path,
    convention: Convention,
) -> Result<(Vec<u32>, GlAnswer), ToolError> {
    let out = work.join("ids.bin");
    let size = SIZE.to_string();
    let framebuffer = GL_FRAMEBUFFER.to_string();
    let args = [
        OsStr::new(&size),
        OsStr::new(&size),
        OsStr::new(&framebuffer),
        input.as_os_str(),
        out.as_os_str(),
        OsStr::new(convention.script_arg()),
    ];
    let answer: GlAnswer = python::parse(
        &LLVMPIPE_RASTER,
        &python::run(&LLVMPIPE_RASTER, work, &args)?,
    )?;
    let bytes = std::fs::read(&out).map_err(|source| ToolError::Io {
        path: out.clone(),
        source,
    })?;
    if bytes.len() != (SIZE * SIZE * 4) as usize {
        return Err(ToolError::Failed {
            script: LLVMPIPE_RASTER.name,
            detail: format!("{} bytes of ids for a {SIZE}x{SIZE} image", bytes.len()),
        });
    }
    let ids = bytes
        .chunks_exact(4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    Ok((ids, answer))
}

/// Differing pixels, split into (coverage differences, depth ties, largest tie gap).
fn classify(triangles: &[ScreenTriangle], ours: &[u32], theirs: &[u32]) -> (u64, u64, u32) {
    let raster: Vec<RasterTriangle> = triangles.iter().map(RasterTriangle::new).collect();
    let (mut coverage, mut ties, mut gap) = (0, 0, 0);
    for (p, (&a, &b)) in ours.iter().zip(theirs).enumerate() {
        if a == b {
            continue;
        }
        let (px, py) = ((p as u32 % SIZE) as i64, (p as u32 / SIZE) as i64);
        let tri = |id: u32| (id != 0).then(|| raster.get(id as usize - 1)).flatten();
        match (tri(a), tri(b)) {
            (Some(ta), Some(tb)) if ta.covers_pixel(px, py) && tb.covers_pixel(px, py) => {
                let d = ta.depth_at(px, py).abs_diff(tb.depth_at(px, py));
                if d <= DEPTH_TIE {
                    ties += 1;
                    gap = gap.max(d);
                } else {
                    coverage += 1;
                }
            }
            _ => coverage += 1,
        }
    }
    (coverage, ties, gap)
}

/// Triangles with a vertex outside a `side`-pixel square centred on the image.
fn count_outside(triangles: &[ScreenTriangle], side: u32) -> usize {
    let margin = i64::from(side - SIZE) / 2 * 256;
    let (lo, hi) = (-margin, i64::from(SIZE) * 256 + margin);
    triangles
        .iter()
        .filter(|t| {
            t.vertices().iter().any(|v| {
                [v.x.raw(), v.y.raw()]
                    .iter()
                    .any(|&c| !(lo..=hi).contains(&i64::from(c)))
            })
        })
        .count()
}

/// Draws every case with both renderers and compares.
pub fn validate(
    cases: &[Case],
    work: &Path,
) -> Result<(RasterValidation, Vec<CaseCost>), ToolError> {
    let convention = Convention::WindowYIsPixelY;
    let mut results = Vec::new();
    let mut costs = Vec::new();
    let mut renderer = String::new();
    for case in cases {
        let triangles = with_ids(&case.triangles);
        let ours = sortsim_ids(&triangles);
        let input = work.join(format!("{}.tri", case.name));
        std::fs::write(&input, gl_input(&triangles)).map_err(|source| ToolError::Io {
            path: input.clone(),
            source,
        })?;
        let (theirs, answer) = llvmpipe_ids(&input, work, convention)?;
        let (flipped, _) = llvmpipe_ids(&input, work, Convention::WindowYFlipped)?;
        let (coverage_differences, depth_ties, largest_tie_gap) =
            classify(&triangles, &ours, &theirs);
        let (other, other_ties, _) = classify(&triangles, &ours, &flipped);
        results.push(CaseResult {
            name: case.name.clone(),
            what: case.what,
            triangles: triangles.len(),
            covered: ours.iter().filter(|&&id| id != 0).count() as u64,
            coverage_differences,
            depth_ties,
            largest_tie_gap,
            other_convention_differences: other + other_ties,
            gl_clipped: count_outside(&triangles, GL_FRAMEBUFFER),
            crossing_border: count_outside(&triangles, SIZE),
        });
        costs.push(CaseCost {
            name: case.name.clone(),
            triangles: triangles.len(),
            llvmpipe_wall_s: answer.wall_s,
        });
        renderer = answer.renderer;
    }
    // A case GL has to clip measures GL's clipper, not the rasterizers: reported, not counted.
    let coverage_differences = results
        .iter()
        .filter(|r| r.gl_clipped == 0)
        .map(|r| r.coverage_differences)
        .sum();
    Ok((
        RasterValidation {
            renderer,
            convention,
            depth_tie: DEPTH_TIE,
            coverage_differences,
            pass: coverage_differences == 0,
            cases: results,
        },
        costs,
    ))
}
