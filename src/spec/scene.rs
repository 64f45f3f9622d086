//! The scene spec file (scenes/*.json): its JSON shape and every rule a scene must satisfy,
//! each reported as a `SpecError` naming the field path and what would be valid.
//!
//! Owns deserialization and validation of scene specs. Must never build geometry, read OBJ
//! files or know about machines: `scene::Scene::load` does the building.
//!
//! Shape (all keys in snake_case, enum variants in kebab-case):
//! ```json
//! { "resolution": [640, 512], "frames": 80, "background": [0, 0, 0], "cull_backfaces": true,
//!   "camera": { "kind": "perspective", "eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0],
//!               "fov_deg": 40, "near": 0.1, "far": 100 },
//!   "animation": { "kind": "orbit", "axis": [0, 1, 0], "degrees_per_frame": 3.0 },
//!   "shading": { "kind": "gouraud", "light_dir": [1, 1, 1], "ambient": 0.2, "diffuse": 0.8 },
//!   "geometry": [ { "generator": { "kind": "teapot", "n": 13 }, "color": [0.8, 0.6, 0.3],
//!                   "transform": { "scale": [1, 1, 1], "rotate_deg": [-90, 0, 0], "translate": [0, 0, 0] },
//!                   "triangles": 11666 } ] }
//! ```

use std::path::Path;

use serde::Deserialize;

use super::{load_json, SpecError};

/// A whole scene file.
#[derive(Deserialize, Debug, Clone, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// The JSON Schema this file follows, for editors (`schemas/`); sortsim ignores it.
    #[serde(rename = "$schema", default, skip_serializing)]
    pub schema: Option<String>,
    /// Optional human description (which paper, which figure).
    #[serde(default)]
    pub description: String,
    /// Image size in pixels, [width, height].
    #[schemars(inner(range(min = 1, max = 16384)))]
    pub resolution: [u32; 2],
    /// Number of frames of the animation (at least 1).
    #[schemars(range(min = 1))]
    #[serde(default = "one")]
    pub frames: u32,
    /// Background colour, 8-bit RGB, each 0..=255.
    #[serde(default)]
    pub background: [u8; 3],
    /// Whether the rasterizer drops back faces (paper 002's terrain runs with culling off).
    #[serde(default = "yes")]
    pub cull_backfaces: bool,
    /// Keep only the triangles frame 0 draws (front-facing, on screen) before object
    /// `triangles` counts are made exact, as paper 001's pre-culled input files were.
    /// Single-frame scenes only.
    #[serde(default)]
    pub precull: bool,
    pub camera: CameraSpec,
    #[serde(default)]
    pub animation: AnimationSpec,
    #[serde(default)]
    pub shading: ShadingSpec,
    pub geometry: Vec<ObjectSpec>,
    /// The fits this scene went through (`sortsim calibrate` with a `scene`): a stand-in
    /// whose shape a paper does not give, pinned down by rows it moves. `sortsim paper`
    /// checks them against the rows' roles.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fitted_to: Vec<crate::spec::machine::FitRecord>,
}

fn one() -> u32 {
    1
}
fn yes() -> bool {
    true
}

/// Where the eye is. `screen` means the geometry is already in pixels (x right, y down,
/// depth z in [0, 1]), as in paper 001's input files.
#[derive(Deserialize, Debug, Clone, schemars::JsonSchema)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum CameraSpec {
    Perspective {
        eye: [f32; 3],
        target: [f32; 3],
        #[serde(default = "y_up")]
        up: [f32; 3],
        #[schemars(extend("exclusiveMinimum" = 0, "exclusiveMaximum" = 180))]
        /// Vertical field of view in degrees.
        fov_deg: f32,
        #[schemars(extend("exclusiveMinimum" = 0))]
        near: f32,
        far: f32,
    },
    Screen,
}

fn y_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

/// How the camera moves over the frames.
#[derive(Deserialize, Debug, Clone, Default, schemars::JsonSchema)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum AnimationSpec {
    /// The camera stays where `camera` puts it.
    #[default]
    Still,
    /// The eye orbits the target about `axis` (through the target).
    Orbit {
        #[serde(default = "y_up")]
        axis: [f32; 3],
        degrees_per_frame: f32,
    },
    /// A recorded list of viewing positions, one per frame (cycled if shorter than `frames`).
    Views { views: Vec<ViewSpec> },
}

/// One recorded viewing position.
#[derive(Deserialize, Debug, Clone, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ViewSpec {
    pub eye: [f32; 3],
    pub target: [f32; 3],
    #[serde(default = "y_up")]
    pub up: [f32; 3],
}

/// Per-vertex colour computation.
#[derive(Deserialize, Debug, Clone, Default, schemars::JsonSchema)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum ShadingSpec {
    /// Each vertex keeps its colour (object colour or OBJ vertex colour).
    #[default]
    Flat,
    /// Lambert lighting per vertex, interpolated by the rasterizer: colour * (ambient +
    /// diffuse * max(0, n . l)), with `light_dir` pointing from the surface towards the light.
    Gouraud {
        light_dir: [f32; 3],
        #[schemars(range(min = 0.0, max = 1.0))]
        #[serde(default = "ambient")]
        ambient: f32,
        #[schemars(range(min = 0.0, max = 1.0))]
        #[serde(default = "diffuse")]
        diffuse: f32,
    },
}

fn ambient() -> f32 {
    0.2
}
fn diffuse() -> f32 {
    0.8
}

/// One object: a generator or an OBJ file, placed by a transform, optionally moving.
#[derive(Deserialize, Debug, Clone, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ObjectSpec {
    #[serde(default)]
    pub generator: Option<GeneratorSpec>,
    /// OBJ file, relative to the scene file.
    #[serde(default)]
    pub obj: Option<String>,
    #[serde(default)]
    pub transform: TransformSpec,
    /// Linear RGB in 0..=1, used where the mesh has no vertex colours.
    #[schemars(inner(range(min = 0.0, max = 1.0)))]
    #[serde(default = "grey")]
    pub color: [f32; 3],
    /// Exact triangle count wanted: the mesh is refined (largest triangles bisected first)
    /// until it has exactly this many. Must be at least the generator's own count.
    #[serde(default)]
    pub triangles: Option<u32>,
    #[serde(default)]
    pub motion: MotionSpec,
}

fn grey() -> [f32; 3] {
    [0.8, 0.8, 0.8]
}

/// Static placement: scale, then rotate (x, then y, then z, degrees), then translate.
#[derive(Deserialize, Debug, Clone, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TransformSpec {
    #[serde(default = "unit_scale")]
    pub scale: [f32; 3],
    #[serde(default)]
    pub rotate_deg: [f32; 3],
    #[serde(default)]
    pub translate: [f32; 3],
}

fn unit_scale() -> [f32; 3] {
    [1.0, 1.0, 1.0]
}

impl Default for TransformSpec {
    fn default() -> Self {
        TransformSpec {
            scale: unit_scale(),
            rotate_deg: [0.0; 3],
            translate: [0.0; 3],
        }
    }
}

/// How an object moves from frame to frame.
#[derive(Deserialize, Debug, Clone, Default, schemars::JsonSchema)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum MotionSpec {
    #[default]
    Still,
    /// Turns about `axis` through the centre of its bounding box (paper 002's PLB head turns
    /// 4.5 degrees left per frame).
    Spin {
        axis: [f32; 3],
        degrees_per_frame: f32,
    },
    /// Every connected part (each tetrahedron of a random-tetrahedra cloud, or the whole
    /// letter B) turns about its own centroid, about a random axis at a random speed in
    /// [0.5, 1] x `degrees_per_frame` (paper 000's objects "rotate randomly").
    Tumble { seed: u64, degrees_per_frame: f32 },
}

/// The procedural generators, one per file under `scene/gen/`.
#[derive(Deserialize, Debug, Clone, schemars::JsonSchema)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum GeneratorSpec {
    /// SPD `tetra`: Sierpinski tetrahedron, 4^size_factor tetrahedra, 4^(size_factor+1) triangles.
    SpdTetra {
        #[schemars(range(max = 9))]
        size_factor: u32,
    },
    /// SPD-style `gears`: a grid x grid array of meshing spur gears, 16 * teeth triangles each.
    Gears {
        #[schemars(range(min = 1, max = 64))]
        grid: u32,
        #[schemars(range(min = 4, max = 1000))]
        teeth: u32,
    },
    /// SPD-style `mountain`: a square recursively subdivided `levels` times with random
    /// midpoint displacement, 2 * 4^levels triangles.
    Mountain {
        #[schemars(range(max = 10))]
        levels: u32,
        #[schemars(range(min = 0.0, max = 2.0))]
        roughness: f32,
        seed: u64,
    },
    /// Newell's teapot, 32 bicubic Bezier patches tessellated n x n (2 n^2 triangles per
    /// patch, minus those that collapse at the lid and bottom poles).
    Teapot {
        #[schemars(range(min = 1, max = 200))]
        n: u32,
    },
    /// A flat square in the xz plane, side 2, facing +y: 2 triangles (a floor or ground).
    Plane,
    /// One triangle in the xz plane covering the square of side 2, facing +y.
    BigTriangle,
    /// UV sphere of radius 1: 2 * segments * (rings - 1) triangles.
    UvSphere {
        #[schemars(range(min = 2, max = 4096))]
        rings: u32,
        #[schemars(range(min = 3, max = 4096))]
        segments: u32,
    },
    /// Torus around the y axis, tube centre at radius 1, tube radius `minor`: `rings` tube
    /// circles of `segments` vertices, 2 * rings * segments triangles.
    Torus {
        #[schemars(range(min = 3, max = 4096))]
        rings: u32,
        #[schemars(range(min = 3, max = 4096))]
        segments: u32,
        #[schemars(range(min = 1e-6, max = 0.999))]
        minor: f32,
    },
    /// A count_x x count_y x count_z lattice of UV spheres of radius `radius` in the cube
    /// [-1, 1]^3.
    SphereLattice {
        #[schemars(inner(range(min = 1, max = 256)))]
        count: [u32; 3],
        #[schemars(range(min = 1e-6, max = 1.0))]
        radius: f32,
        #[schemars(range(min = 2, max = 4096))]
        rings: u32,
        #[schemars(range(min = 3, max = 4096))]
        segments: u32,
    },
    /// Letter "B" extruded: a stem, three bars and two bowls of `segments` steps each.
    LetterB {
        #[schemars(range(min = 2, max = 10_000))]
        segments: u32,
        #[schemars(range(min = 1e-6, max = 100.0))]
        depth: f32,
    },
    /// `count` regular tetrahedra of edge `size` placed uniformly in the cube [-1, 1]^3 with
    /// random orientation; 4 triangles each.
    RandomTetrahedra {
        #[schemars(range(min = 1, max = 10_000_000))]
        count: u32,
        #[schemars(range(min = 1e-6, max = 2.0))]
        size: f32,
        seed: u64,
    },
    /// A head-like closed surface (skull, nose, ears, chin by smooth displacement of a UV
    /// sphere): 2 * segments * (rings - 1) triangles.
    Head {
        #[schemars(range(min = 8, max = 4096))]
        rings: u32,
        #[schemars(range(min = 8, max = 4096))]
        segments: u32,
        seed: u64,
    },
    /// An icosahedral virus-like shell: geodesic sphere of frequency f (20 f^2 triangles)
    /// with icosahedrally symmetric bumps; with `layers` > 1, that many nested copies, each
    /// `layer_gap` smaller in radius than the one around it (a capsid's depth complexity
    /// without its atoms: 20 f^2 * layers triangles).
    IcosaShell {
        #[schemars(range(min = 1, max = 2048))]
        frequency: u32,
        #[schemars(range(min = 0.0, max = 0.5))]
        bump: f32,
        #[serde(default = "one_layer")]
        #[schemars(range(min = 1, max = 64))]
        layers: u32,
        /// At most 0.9 / (layers - 1), so the innermost layer keeps a positive radius.
        #[serde(default)]
        #[schemars(range(min = 0.0, max = 0.9))]
        layer_gap: f32,
    },
    /// A fractal height field on cols x rows quads of the square [-1, 1]^2: 2 * cols * rows
    /// triangles.
    Terrain {
        #[schemars(range(min = 1, max = 8192))]
        cols: u32,
        #[schemars(range(min = 1, max = 8192))]
        rows: u32,
        #[schemars(range(min = 0.0, max = 10.0))]
        relief: f32,
        seed: u64,
    },
    /// Screen-space scatter for paper 003 stand-ins (use with the `screen` camera): `count`
    /// triangles with log-normal areas rescaled to a mean of exactly `mean_area_px`, placed
    /// uniformly inside the screen at random depths; optionally a first large "background"
    /// quad covering `background_fraction` of the screen (paper 003's Zinnia). With
    /// `footprint` below 1 the triangles fall inside a centred rectangle of that share of the
    /// screen (the screen's aspect), so depth piles up to `count * mean / (footprint * A)`
    /// there and the rest of the screen stays empty.
    ScreenScatter {
        #[schemars(range(min = 1, max = 50_000_000))]
        count: u32,
        #[schemars(range(min = 0.01, max = 1e7))]
        mean_area_px: f64,
        #[serde(default = "sigma")]
        #[schemars(range(min = 0.0, max = 3.0))]
        sigma: f64,
        seed: u64,
        #[serde(default)]
        #[schemars(range(min = 0.0, max = 1.0))]
        background_fraction: f64,
        #[serde(default = "whole_screen")]
        #[schemars(range(min = 0.001, max = 1.0))]
        footprint: f64,
    },
}

fn whole_screen() -> f64 {
    1.0
}

fn sigma() -> f64 {
    0.8
}

/// Every generator kind as written in JSON, for messages.
pub const GENERATOR_KINDS: &str = "spd-tetra, gears, mountain, teapot, plane, big-triangle, uv-sphere, sphere-lattice, letter-b, random-tetrahedra, head, icosa-shell, terrain, screen-scatter";

/// Loads a scene spec and checks every rule; the error names the field path.
pub fn load(path: &Path) -> Result<SceneSpec, SpecError> {
    let spec: SceneSpec = load_json(path)?;
    spec.validate(path)?;
    Ok(spec)
}

impl SceneSpec {
    /// Checks the rules serde cannot express; `file` is only used in messages.
    pub fn validate(&self, file: &Path) -> Result<(), SpecError> {
        let bad = |field: &str, msg: String| Err(SpecError::invalid(file, field, msg));
        let [w, h] = self.resolution;
        if w == 0 || h == 0 || w > 16384 || h > 16384 {
            return bad(
                "resolution",
                format!("must be [width, height] with each in 1..=16384 pixels, got [{w}, {h}]"),
            );
        }
        if self.frames == 0 {
            return bad("frames", "must be at least 1".into());
        }
        if self.precull && self.frames != 1 {
            return bad(
                "precull",
                format!("only a single-frame scene can be culled in advance (frame 0's view); `frames` is {}", self.frames),
            );
        }
        self.validate_camera(file)?;
        self.validate_animation(file)?;
        if let ShadingSpec::Gouraud {
            light_dir,
            ambient,
            diffuse,
        } = &self.shading
        {
            check_dir(file, "shading.light_dir", *light_dir)?;
            check_range(file, "shading.ambient", *ambient, 0.0, 1.0)?;
            check_range(file, "shading.diffuse", *diffuse, 0.0, 1.0)?;
        }
        if self.geometry.is_empty() {
            return bad(
                "geometry",
                "must list at least one object (a `generator` or an `obj` file)".into(),
            );
        }
        for (i, object) in self.geometry.iter().enumerate() {
            object.validate(file, &format!("geometry[{i}]"))?;
        }
        Ok(())
    }

    fn validate_camera(&self, file: &Path) -> Result<(), SpecError> {
        if let CameraSpec::Perspective {
            eye,
            target,
            up,
            fov_deg,
            near,
            far,
        } = &self.camera
        {
            check_finite(file, "camera.eye", eye)?;
            check_finite(file, "camera.target", target)?;
            check_dir(file, "camera.up", *up)?;
            check_view(file, "camera", *eye, *target, *up)?;
            if !(*fov_deg > 0.0 && *fov_deg < 180.0) {
                return Err(SpecError::invalid(
                    file,
                    "camera.fov_deg",
                    format!("must be in (0, 180) degrees, got {fov_deg}"),
                ));
            }
            if !(*near > 0.0 && near.is_finite()) {
                return Err(SpecError::invalid(
                    file,
                    "camera.near",
                    format!("must be a positive distance, got {near}"),
                ));
            }
            if !(*far > *near && far.is_finite()) {
                return Err(SpecError::invalid(
                    file,
                    "camera.far",
                    format!("must be finite and greater than near ({near}), got {far}"),
                ));
            }
        }
        Ok(())
    }

    fn validate_animation(&self, file: &Path) -> Result<(), SpecError> {
        match &self.animation {
            AnimationSpec::Still => Ok(()),
            AnimationSpec::Orbit {
                axis,
                degrees_per_frame,
            } => {
                if matches!(self.camera, CameraSpec::Screen) {
                    return Err(SpecError::invalid(
                        file,
                        "animation",
                        "a `screen` camera cannot orbit; use `still`",
                    ));
                }
                check_dir(file, "animation.axis", *axis)?;
                check_finite(file, "animation.degrees_per_frame", &[*degrees_per_frame])
            }
            AnimationSpec::Views { views } => {
                if matches!(self.camera, CameraSpec::Screen) {
                    return Err(SpecError::invalid(
                        file,
                        "animation",
                        "a `screen` camera has no views; use `still`",
                    ));
                }
                if views.is_empty() {
                    return Err(SpecError::invalid(
                        file,
                        "animation.views",
                        "must list at least one view",
                    ));
                }
                for (i, v) in views.iter().enumerate() {
                    let at = format!("animation.views[{i}]");
                    check_finite(file, &format!("{at}.eye"), &v.eye)?;
                    check_finite(file, &format!("{at}.target"), &v.target)?;
                    check_dir(file, &format!("{at}.up"), v.up)?;
                    check_view(file, &at, v.eye, v.target, v.up)?;
                }
                Ok(())
            }
        }
    }
}

impl ObjectSpec {
    fn validate(&self, file: &Path, at: &str) -> Result<(), SpecError> {
        match (&self.generator, &self.obj) {
            (Some(g), None) => g.validate(file, &format!("{at}.generator"))?,
            (None, Some(path)) => {
                if path.is_empty() {
                    return Err(SpecError::invalid(file, format!("{at}.obj"), "must be a path to an OBJ file, relative to the scene file"));
                }
            }
            _ => {
                return Err(SpecError::invalid(
                    file,
                    at,
                    format!("needs exactly one of `generator` (one of: {GENERATOR_KINDS}) or `obj` (a file path)"),
                ))
            }
        }
        let t = &self.transform;
        check_finite(file, &format!("{at}.transform.scale"), &t.scale)?;
        if t.scale.contains(&0.0) {
            return Err(SpecError::invalid(
                file,
                format!("{at}.transform.scale"),
                "must be non-zero on every axis",
            ));
        }
        check_finite(file, &format!("{at}.transform.rotate_deg"), &t.rotate_deg)?;
        check_finite(file, &format!("{at}.transform.translate"), &t.translate)?;
        for (k, c) in self.color.iter().enumerate() {
            check_range(file, &format!("{at}.color[{k}]"), *c, 0.0, 1.0)?;
        }
        if self.triangles == Some(0) {
            return Err(SpecError::invalid(
                file,
                format!("{at}.triangles"),
                "must be at least 1 (or left out)",
            ));
        }
        match &self.motion {
            MotionSpec::Still => Ok(()),
            MotionSpec::Spin {
                axis,
                degrees_per_frame,
            } => {
                check_dir(file, &format!("{at}.motion.axis"), *axis)?;
                check_finite(
                    file,
                    &format!("{at}.motion.degrees_per_frame"),
                    &[*degrees_per_frame],
                )
            }
            MotionSpec::Tumble {
                degrees_per_frame, ..
            } => check_finite(
                file,
                &format!("{at}.motion.degrees_per_frame"),
                &[*degrees_per_frame],
            ),
        }
    }
}

impl GeneratorSpec {
    fn validate(&self, file: &Path, at: &str) -> Result<(), SpecError> {
        let count = |field: &str, v: u32, lo: u32, hi: u32| -> Result<(), SpecError> {
            if v < lo || v > hi {
                Err(SpecError::invalid(
                    file,
                    format!("{at}.{field}"),
                    format!("must be in {lo}..={hi}, got {v}"),
                ))
            } else {
                Ok(())
            }
        };
        let real = |field: &str, v: f64, lo: f64, hi: f64| {
            check_range(file, &format!("{at}.{field}"), v, lo, hi)
        };
        match self {
            GeneratorSpec::SpdTetra { size_factor } => count("size_factor", *size_factor, 0, 9),
            GeneratorSpec::Gears { grid, teeth } => {
                count("grid", *grid, 1, 64)?;
                count("teeth", *teeth, 4, 1000)
            }
            GeneratorSpec::Mountain {
                levels, roughness, ..
            } => {
                count("levels", *levels, 0, 10)?;
                real("roughness", *roughness as f64, 0.0, 2.0)
            }
            GeneratorSpec::Teapot { n } => count("n", *n, 1, 200),
            GeneratorSpec::Plane | GeneratorSpec::BigTriangle => Ok(()),
            GeneratorSpec::UvSphere { rings, segments } => {
                count("rings", *rings, 2, 4096)?;
                count("segments", *segments, 3, 4096)
            }
            GeneratorSpec::Torus {
                rings,
                segments,
                minor,
            } => {
                count("rings", *rings, 3, 4096)?;
                count("segments", *segments, 3, 4096)?;
                real("minor", *minor as f64, 1e-6, 0.999)
            }
            GeneratorSpec::SphereLattice {
                count: c,
                radius,
                rings,
                segments,
            } => {
                for (k, n) in c.iter().enumerate() {
                    count(&format!("count[{k}]"), *n, 1, 256)?;
                }
                real("radius", *radius as f64, 1e-6, 1.0)?;
                count("rings", *rings, 2, 4096)?;
                count("segments", *segments, 3, 4096)
            }
            GeneratorSpec::LetterB { segments, depth } => {
                count("segments", *segments, 2, 10_000)?;
                real("depth", *depth as f64, 1e-6, 100.0)
            }
            GeneratorSpec::RandomTetrahedra { count: c, size, .. } => {
                count("count", *c, 1, 10_000_000)?;
                real("size", *size as f64, 1e-6, 2.0)
            }
            GeneratorSpec::Head {
                rings, segments, ..
            } => {
                count("rings", *rings, 8, 4096)?;
                count("segments", *segments, 8, 4096)
            }
            GeneratorSpec::IcosaShell {
                frequency,
                bump,
                layers,
                layer_gap,
            } => {
                count("frequency", *frequency, 1, 2048)?;
                count("layers", *layers, 1, 64)?;
                real("bump", *bump as f64, 0.0, 0.5)?;
                // The innermost layer keeps a positive radius.
                real(
                    "layer_gap",
                    *layer_gap as f64,
                    0.0,
                    0.9 / (*layers as f64 - 1.0).max(1.0),
                )
            }
            GeneratorSpec::Terrain {
                cols, rows, relief, ..
            } => {
                count("cols", *cols, 1, 8192)?;
                count("rows", *rows, 1, 8192)?;
                real("relief", *relief as f64, 0.0, 10.0)
            }
            GeneratorSpec::ScreenScatter {
                count: c,
                mean_area_px,
                sigma,
                background_fraction,
                footprint,
                ..
            } => {
                count("count", *c, 1, 50_000_000)?;
                real("mean_area_px", *mean_area_px, 0.01, 1e7)?;
                real("sigma", *sigma, 0.0, 3.0)?;
                real("background_fraction", *background_fraction, 0.0, 1.0)?;
                real("footprint", *footprint, 0.001, 1.0)
            }
        }
    }
}

fn check_finite(file: &Path, field: &str, v: &[f32]) -> Result<(), SpecError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(SpecError::invalid(
            file,
            field,
            format!("must be finite numbers, got {v:?}"),
        ))
    }
}

fn check_dir(file: &Path, field: &str, v: [f32; 3]) -> Result<(), SpecError> {
    check_finite(file, field, &v)?;
    if v.iter().all(|x| *x == 0.0) {
        return Err(SpecError::invalid(
            file,
            field,
            "must be a non-zero direction",
        ));
    }
    Ok(())
}

fn check_view(
    file: &Path,
    at: &str,
    eye: [f32; 3],
    target: [f32; 3],
    up: [f32; 3],
) -> Result<(), SpecError> {
    let d = glam::Vec3::from(target) - glam::Vec3::from(eye);
    if d.length_squared() == 0.0 {
        return Err(SpecError::invalid(
            file,
            format!("{at}.target"),
            "must differ from the eye",
        ));
    }
    if d.normalize()
        .cross(glam::Vec3::from(up).normalize())
        .length()
        < 1e-4
    {
        return Err(SpecError::invalid(
            file,
            format!("{at}.up"),
            "must not be parallel to the viewing direction",
        ));
    }
    Ok(())
}

fn check_range(
    file: &Path,
    field: &str,
    v: impl Into<f64>,
    lo: f64,
    hi: f64,
) -> Result<(), SpecError> {
    let v = v.into();
    if v.is_finite() && v >= lo && v <= hi {
        Ok(())
    } else {
        Err(SpecError::invalid(
            file,
            field,
            format!("must be in [{lo}, {hi}], got {v}"),
        ))
    }
}

fn one_layer() -> u32 {
    1
}
