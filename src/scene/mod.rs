//! Scenes: geometry (generators, OBJ files), cameras and animation, per-vertex lighting; one
//! frame's clip-space vertices at a time, handed to the rasterizer as `FrameGeometry`.
//!
//! Must never rasterize (only `stats` calls into `raster` to measure) and never know about
//! simulated machines, nodes or time.
//!
//! ```no_run
//! use sortsim::scene::Scene;
//! let scene = Scene::load("scenes/spd-teapot.json".as_ref()).unwrap();
//! let frame = scene.frame(0).unwrap();
//! let stats = sortsim::scene::stats::geometric(&frame);
//! println!("{} triangles, mean {:.1} px", stats.triangles_in, stats.mean_area_px);
//! ```

pub mod gen;
pub mod mesh;
pub mod obj;
pub mod paper;
pub mod planes;
mod precull;
pub mod refine;
pub mod stats;
pub mod summary;

use crate::units::count;
use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec3, Vec4};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::limits::MAX_SCENE_TRIANGLES;
use crate::raster::Vertex;
use crate::spec::scene::{
    AnimationSpec, CameraSpec, MotionSpec, ObjectSpec, SceneSpec, ShadingSpec,
};
use crate::spec::SpecError;
use mesh::Mesh;
use precull::Precull;

/// One frame's geometry as the rasterizer takes it.
///
/// Winding convention: a triangle is **front-facing** when its screen-space signed area,
/// computed with x right and y pointing *down* (pixel coordinates) as
/// `((x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)) / 2`, is **negative**; equivalently its
/// vertices run counter-clockwise as the viewer sees them (positive area in NDC, y up). All
/// generators emit triangles counter-clockwise as seen from outside the object, so outward
/// faces are front faces under `Mat4::perspective_rh`.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameGeometry {
    pub width: u32,
    pub height: u32,
    pub vertices: Vec<Vertex>,
    pub triangles: Vec<[u32; 3]>,
    pub cull_backfaces: bool,
    pub background: [u8; 3],
}

/// Everything that can go wrong turning a scene file into frames.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error(transparent)]
    Spec(#[from] SpecError),
    #[error("{}: cannot read OBJ file: {message}", file.display())]
    ObjRead { file: PathBuf, message: String },
    #[error("{}:{line}: malformed OBJ: {message}", file.display())]
    Obj {
        file: PathBuf,
        line: usize,
        message: String,
    },
    #[error("{}: frame {frame} is out of range: the scene has {} (valid 0..={})", file.display(), crate::units::count(*count, "frame"), count.saturating_sub(1))]
    FrameOutOfRange {
        file: PathBuf,
        frame: u32,
        count: u32,
    },
}

/// A loaded scene: meshes built once, frames computed on demand.
#[derive(Clone, Debug)]
pub struct Scene {
    file: PathBuf,
    spec: SceneSpec,
    objects: Vec<Object>,
}

/// One object in world space at frame 0, with what it needs per frame.
#[derive(Clone, Debug)]
struct Object {
    mesh: Mesh,
    normals: Vec<Vec3>,
    colors: Vec<Vec3>,
    motion: Motion,
}

#[derive(Clone, Debug)]
enum Motion {
    Still,
    /// Rotation about an axis through `centre`, `radians` per frame.
    Spin {
        centre: Vec3,
        axis: Vec3,
        radians: f32,
    },
    /// Per part: centroid, axis, radians per frame.
    Tumble(Vec<(Vec3, Vec3, f32)>),
}

impl Scene {
    /// Reads, validates and builds a scene file. OBJ paths are relative to the file.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let spec = crate::spec::scene::load(path)?;
        Scene::from_spec(path, spec)
    }

    /// Builds a scene from a spec (validated again here, so a spec changed in memory, such as
    /// by a sweep's overrides, gets the same checks); `file` locates OBJ files and names
    /// errors.
    pub fn from_spec(file: &Path, spec: SceneSpec) -> Result<Scene, SceneError> {
        spec.validate(file)?;
        check_size(file, &spec)?;
        let ctx = gen::GenContext {
            width: spec.resolution[0],
            height: spec.resolution[1],
        };
        // Paper 001's input files were screen-space triangles with back faces already culled:
        // `precull` drops what frame 0 would cull before counts are made exact.
        let precull = spec.precull.then(|| Precull {
            to_clip: view_projection(&spec, 0),
            width: spec.resolution[0],
            height: spec.resolution[1],
        });
        let objects = spec
            .geometry
            .iter()
            .enumerate()
            .map(|(i, o)| build_object(file, i, o, ctx, precull.as_ref()))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Scene {
            file: file.to_path_buf(),
            spec,
            objects,
        })
    }

    pub fn spec(&self) -> &SceneSpec {
        &self.spec
    }

    pub fn file(&self) -> &Path {
        &self.file
    }

    pub fn frame_count(&self) -> u32 {
        self.spec.frames
    }

    /// One line for `sortsim check`: size, frames, triangles, camera, culling.
    pub fn describe(&self) -> String {
        let [w, h] = self.spec.resolution;
        let camera = match self.spec.camera {
            CameraSpec::Perspective { .. } => "perspective",
            CameraSpec::Screen => "screen",
        };
        format!(
            "scene: {w}x{h}, {}, {}, {} per frame, {camera} camera, back-face culling {}",
            count(self.spec.frames, "frame"),
            count(self.objects.len() as u64, "object"),
            count(self.triangle_count() as u64, "triangle"),
            if self.spec.cull_backfaces {
                "on"
            } else {
                "off"
            }
        )
    }

    /// Triangles per object, in spec order.
    pub fn object_triangle_counts(&self) -> Vec<usize> {
        self.objects
            .iter()
            .map(|o| o.mesh.triangles.len())
            .collect()
    }

    /// Triangles per frame (the same every frame).
    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(|o| o.mesh.triangles.len()).sum()
    }

    /// The geometry of frame `n` (0-based), transformed to clip space and lit.
    pub fn frame(&self, n: u32) -> Result<FrameGeometry, SceneError> {
        self.frame_reusing(n, None)
    }

    /// [`Scene::frame`], filling the vertex and triangle lists of `spare` (an earlier
    /// frame's, no longer needed) instead of fresh ones: a large scene's frame is tens of
    /// megabytes, which fresh pages would have the kernel zero every frame.
    pub fn frame_reusing(
        &self,
        n: u32,
        spare: Option<FrameGeometry>,
    ) -> Result<FrameGeometry, SceneError> {
        if n >= self.spec.frames {
            return Err(SceneError::FrameOutOfRange {
                file: self.file.clone(),
                frame: n,
                count: self.spec.frames,
            });
        }
        let [w, h] = self.spec.resolution;
        let to_clip = view_projection(&self.spec, n);
        let light = Lighting::from(&self.spec.shading);
        let total_v: usize = self.objects.iter().map(|o| o.mesh.positions.len()).sum();
        let (mut vertices, mut triangles) = match spare {
            Some(g) => (g.vertices, g.triangles),
            None => (Vec::new(), Vec::new()),
        };
        vertices.clear();
        vertices.reserve(total_v);
        triangles.clear();
        triangles.reserve(self.triangle_count());
        for object in &self.objects {
            let base = vertices.len() as u32;
            object.emit(n, &to_clip, &light, &mut vertices);
            triangles.extend(object.mesh.triangles.iter().map(|t| t.map(|i| i + base)));
        }
        Ok(FrameGeometry {
            width: w,
            height: h,
            vertices,
            triangles,
            cull_backfaces: self.spec.cull_backfaces,
            background: self.spec.background,
        })
    }
}

/// World space to clip space for frame `n`: the camera, moved by the animation.
fn view_projection(spec: &SceneSpec, n: u32) -> ToClip {
    let [w, h] = spec.resolution;
    match &spec.camera {
        CameraSpec::Screen => ToClip::Screen {
            width: w as f32,
            height: h as f32,
        },
        CameraSpec::Perspective {
            eye,
            target,
            up,
            fov_deg,
            near,
            far,
        } => {
            let (eye, target, up) = match &spec.animation {
                AnimationSpec::Still => (Vec3::from(*eye), Vec3::from(*target), Vec3::from(*up)),
                AnimationSpec::Orbit {
                    axis,
                    degrees_per_frame,
                } => {
                    let q = Quat::from_axis_angle(
                        Vec3::from(*axis).normalize(),
                        (degrees_per_frame * n as f32).to_radians(),
                    );
                    let t = Vec3::from(*target);
                    (t + q * (Vec3::from(*eye) - t), t, q * Vec3::from(*up))
                }
                AnimationSpec::Views { views } => {
                    let v = &views[n as usize % views.len()];
                    (Vec3::from(v.eye), Vec3::from(v.target), Vec3::from(v.up))
                }
            };
            let view = Mat4::look_at_rh(eye, target, up);
            let proj = Mat4::perspective_rh(fov_deg.to_radians(), w as f32 / h as f32, *near, *far);
            ToClip::Perspective(proj * view)
        }
    }
}

/// World space to clip space for one frame.
enum ToClip {
    Perspective(Mat4),
    /// Pixels (x right, y down, depth z) to clip space with w = 1.
    Screen {
        width: f32,
        height: f32,
    },
}

impl ToClip {
    fn apply(&self, p: Vec3) -> Vec4 {
        match self {
            ToClip::Perspective(m) => *m * p.extend(1.0),
            ToClip::Screen { width, height } => {
                Vec4::new(2.0 * p.x / width - 1.0, 1.0 - 2.0 * p.y / height, p.z, 1.0)
            }
        }
    }
}

/// Per-vertex lighting in world space.
enum Lighting {
    Flat,
    Lambert {
        to_light: Vec3,
        ambient: f32,
        diffuse: f32,
    },
}

impl From<&ShadingSpec> for Lighting {
    fn from(s: &ShadingSpec) -> Lighting {
        match s {
            ShadingSpec::Flat => Lighting::Flat,
            ShadingSpec::Gouraud {
                light_dir,
                ambient,
                diffuse,
            } => Lighting::Lambert {
                to_light: Vec3::from(*light_dir).normalize(),
                ambient: *ambient,
                diffuse: *diffuse,
            },
        }
    }
}

impl Lighting {
    fn shade(&self, base: Vec3, normal: Vec3) -> Vec3 {
        match self {
            Lighting::Flat => base,
            Lighting::Lambert {
                to_light,
                ambient,
                diffuse,
            } => (base * (ambient + diffuse * normal.dot(*to_light).max(0.0)))
                .clamp(Vec3::ZERO, Vec3::ONE),
        }
    }
}

impl Object {
    fn emit(&self, n: u32, to_clip: &ToClip, light: &Lighting, out: &mut Vec<Vertex>) {
        let m = &self.mesh;
        let mut put = |i: usize, rot: Quat, about: Vec3| {
            let p = about + rot * (m.positions[i] - about);
            let normal = rot * self.normals[i];
            out.push(Vertex {
                clip: to_clip.apply(p),
                color: light.shade(self.colors[i], normal),
            });
        };
        match &self.motion {
            Motion::Still => {
                (0..m.positions.len()).for_each(|i| put(i, Quat::IDENTITY, Vec3::ZERO))
            }
            Motion::Spin {
                centre,
                axis,
                radians,
            } => {
                let q = Quat::from_axis_angle(*axis, radians * n as f32);
                (0..m.positions.len()).for_each(|i| put(i, q, *centre));
            }
            Motion::Tumble(parts) => {
                let qs: Vec<Quat> = parts
                    .iter()
                    .map(|(_, axis, r)| Quat::from_axis_angle(*axis, r * n as f32))
                    .collect();
                for i in 0..m.positions.len() {
                    let p = m.part[i] as usize;
                    put(i, qs[p], parts[p].0);
                }
            }
        }
    }
}

/// Refuses a scene whose objects would hold more than [`MAX_SCENE_TRIANGLES`] triangles in
/// all, naming the object that crosses it, before any is built. An OBJ file's own triangles
/// are bounded by its size, so it counts only for what its `triangles` field refines it to.
fn check_size(file: &Path, spec: &SceneSpec) -> Result<(), SpecError> {
    let mut total = 0u64;
    for (i, object) in spec.geometry.iter().enumerate() {
        let made = object.generator.as_ref().map_or(0, gen::triangles_at_most);
        let refined = object.triangles.map_or(0, u64::from);
        total = total.saturating_add(made.max(refined));
        if total > MAX_SCENE_TRIANGLES {
            let field = match object.generator {
                Some(_) if made >= refined => format!("geometry[{i}].generator"),
                _ => format!("geometry[{i}].triangles"),
            };
            return Err(SpecError::invalid(
                file,
                field,
                format!(
                    "the scene would hold {total} triangles with this object; the limit is \
                     {MAX_SCENE_TRIANGLES} (sortsim::limits::MAX_SCENE_TRIANGLES)"
                ),
            ));
        }
    }
    Ok(())
}

fn build_object(
    file: &Path,
    index: usize,
    spec: &ObjectSpec,
    ctx: gen::GenContext,
    precull: Option<&Precull>,
) -> Result<Object, SceneError> {
    let mut mesh = match (&spec.generator, &spec.obj) {
        (Some(g), _) => gen::build(g, ctx),
        (None, Some(obj)) => {
            let path = file.parent().unwrap_or(Path::new(".")).join(obj);
            obj::load(&path).map_err(|e| match e {
                // The file could not be read at all: the scene's field is where to fix it.
                SceneError::ObjRead { message, .. } => SceneError::Spec(SpecError::invalid(
                    file,
                    format!("geometry[{index}].obj"),
                    format!("cannot read OBJ file {}: {message}", path.display()),
                )),
                other => other,
            })?
        }
        (None, None) => unreachable!("validated: exactly one of generator and obj"),
    };
    let t = &spec.transform;
    let r = Vec3::from(t.rotate_deg) * std::f32::consts::PI / 180.0;
    let rot = Quat::from_rotation_z(r.z) * Quat::from_rotation_y(r.y) * Quat::from_rotation_x(r.x);
    mesh.transform(Mat4::from_scale_rotation_translation(
        Vec3::from(t.scale),
        rot,
        Vec3::from(t.translate),
    ));
    if let Some(view) = precull {
        precull::prune(&mut mesh, view);
    }
    if let Some(target) = spec.triangles {
        refine::refine_to(&mut mesh, target as usize).map_err(|base| {
            SpecError::invalid(
                file,
                format!("geometry[{index}].triangles"),
                format!(
                    "must be at least the generated count {base}{} (refinement only adds triangles), got {target}",
                    if precull.is_some() { " left after pre-culling" } else { "" }
                ),
            )
        })?;
    }
    let normals = mesh
        .normals
        .clone()
        .unwrap_or_else(|| mesh.smooth_normals());
    let colors = mesh
        .colors
        .clone()
        .unwrap_or_else(|| vec![Vec3::from(spec.color); mesh.positions.len()]);
    let motion = motion(&spec.motion, &mesh);
    Ok(Object {
        mesh,
        normals,
        colors,
        motion,
    })
}

fn motion(spec: &MotionSpec, mesh: &Mesh) -> Motion {
    match spec {
        MotionSpec::Still => Motion::Still,
        MotionSpec::Spin {
            axis,
            degrees_per_frame,
        } => {
            let (lo, hi) = mesh.bounds().unwrap_or((Vec3::ZERO, Vec3::ZERO));
            Motion::Spin {
                centre: (lo + hi) * 0.5,
                axis: Vec3::from(*axis).normalize(),
                radians: degrees_per_frame.to_radians(),
            }
        }
        MotionSpec::Tumble {
            seed,
            degrees_per_frame,
        } => {
            let parts = mesh.part_count() as usize;
            let mut sum = vec![(Vec3::ZERO, 0u32); parts];
            for (p, part) in mesh.positions.iter().zip(&mesh.part) {
                sum[*part as usize].0 += *p;
                sum[*part as usize].1 += 1;
            }
            let mut rng = ChaCha8Rng::seed_from_u64(*seed);
            Motion::Tumble(
                sum.into_iter()
                    .map(|(s, k)| {
                        let axis = gen_axis(&mut rng);
                        let speed = degrees_per_frame.to_radians() * rng.gen_range(0.5..=1.0);
                        (s / k.max(1) as f32, axis, speed)
                    })
                    .collect(),
            )
        }
    }
}

/// A uniformly random unit vector.
fn gen_axis(rng: &mut ChaCha8Rng) -> Vec3 {
    let z: f32 = rng.gen_range(-1.0..1.0);
    let a: f32 = rng.gen_range(0.0..std::f32::consts::TAU);
    let r = (1.0 - z * z).sqrt();
    Vec3::new(r * a.cos(), r * a.sin(), z)
}
