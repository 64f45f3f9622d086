//! Rasterizer throughput, single-threaded: large triangles (pixels written per second) and
//! 4-7 px triangles (triangles set up and drawn per second), through the whole front end
//! (clip space in) and through the back end alone (screen triangles in).
//!
//! Must never feed timings back into the simulator: these are host timings.
//!
//! Set `RASTER_BENCH_CPU_TIME=1` to measure the benchmark thread's on-CPU time (from
//! `/proc/thread-self/schedstat`) instead of wall-clock time: on a machine shared with other
//! jobs the wall clock mostly measures the scheduler.

use criterion::measurement::{Measurement, ValueFormatter, WallTime};
use criterion::{BatchSize, Criterion, Throughput};
use glam::{Vec3, Vec4};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sortsim::raster::*;

const W: u32 = 1024;
const H: u32 = 1024;

fn viewport() -> Viewport {
    Viewport::new(W, H).unwrap()
}

/// Clip-space vertex at pixel (x, y) with depth z, w = 1.
fn at(x: f32, y: f32, z: f32, rgb: Vec3) -> Vertex {
    Vertex {
        clip: Vec4::new(2.0 * x / W as f32 - 1.0, 1.0 - 2.0 * y / H as f32, z, 1.0),
        color: rgb,
    }
}

/// Two Gouraud triangles covering the whole 1024x1024 viewport, with sloped depth.
fn large() -> (Vec<Vertex>, Vec<[u32; 3]>) {
    let v = vec![
        at(0.0, 0.0, 0.2, Vec3::new(1.0, 0.0, 0.0)),
        at(W as f32, 0.0, 0.4, Vec3::new(0.0, 1.0, 0.0)),
        at(W as f32, H as f32, 0.6, Vec3::new(0.0, 0.0, 1.0)),
        at(0.0, H as f32, 0.3, Vec3::new(1.0, 1.0, 0.0)),
    ];
    (v, vec![[0, 2, 1], [0, 3, 2]])
}

/// A jittered grid mesh of Gouraud triangles of 4 to 7 px area (cells of 3.3 px, two
/// triangles each), in row order as a tessellated surface would arrive.
fn grid() -> (Vec<Vertex>, Vec<[u32; 3]>) {
    let mut r = ChaCha8Rng::seed_from_u64(2);
    let cell = 3.3f32;
    let n = (W as f32 / cell) as u32 - 1;
    let mut verts = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let x = (i as f32 + 0.5) * cell + r.gen_range(-0.25..0.25);
            let y = (j as f32 + 0.5) * cell + r.gen_range(-0.25..0.25);
            let rgb = Vec3::new(i as f32 / n as f32, j as f32 / n as f32, 0.5);
            verts.push(at(x, y, r.gen_range(0.2..0.8), rgb));
        }
    }
    let id = |i: u32, j: u32| j * (n + 1) + i;
    let mut tris = Vec::new();
    for j in 0..n {
        for i in 0..n {
            tris.push([id(i, j), id(i, j + 1), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i + 1, j)]);
        }
    }
    (verts, tris)
}

/// `n` random Gouraud triangles of 4 to 7 px area scattered over the screen (every
/// triangle touches cold framebuffer memory: a cache-hostile worst case).
fn small(n: usize) -> (Vec<Vertex>, Vec<[u32; 3]>) {
    let mut r = ChaCha8Rng::seed_from_u64(1);
    let mut verts = Vec::with_capacity(3 * n);
    let mut tris = Vec::with_capacity(n);
    for i in 0..n {
        let (x, y): (f32, f32) = (
            r.gen_range(4.0..W as f32 - 8.0),
            r.gen_range(4.0..H as f32 - 8.0),
        );
        let area: f32 = r.gen_range(4.0..7.0);
        // A right triangle with legs a, b and a*b/2 = area, randomly rotated.
        let a: f32 = r.gen_range(2.0..4.0);
        let b = 2.0 * area / a;
        let t: f32 = r.gen_range(0.0..std::f32::consts::TAU);
        let (s, c) = t.sin_cos();
        let z: f32 = r.gen_range(0.0..1.0);
        let col = || Vec3::new(0.3, 0.5, 0.7);
        verts.push(at(x, y, z, col()));
        verts.push(at(x + a * c, y + a * s, z, col() * 0.5));
        verts.push(at(x - b * s, y + b * c, z, col() * 0.8));
        let k = 3 * i as u32;
        tris.push([k, k + 1, k + 2]);
    }
    (verts, tris)
}

fn bench_large<M: Measurement>(c: &mut Criterion<M>) {
    let (verts, tris) = large();
    let vp = viewport();
    let mut g = c.benchmark_group("large_triangles");
    g.sample_size(20);
    g.throughput(Throughput::Elements(u64::from(W * H)));
    g.bench_function("fullscreen_1024x1024_pixels", |b| {
        b.iter_batched_ref(
            || Framebuffer::new(vp),
            |fb| {
                let c = draw_mesh(&verts, &tris, vp, &RasterOptions::default(), fb);
                assert_eq!(c.pixels_written, u64::from(W * H));
            },
            BatchSize::LargeInput,
        )
    });
    g.finish();
}

fn bench_small_group<M: Measurement>(
    c: &mut Criterion<M>,
    name: &str,
    verts: &[Vertex],
    tris: &[[u32; 3]],
) {
    let vp = viewport();
    let opts = RasterOptions::default();
    let mut screen = Vec::new();
    setup_mesh(verts, tris, vp, &opts, &mut screen);
    let mut g = c.benchmark_group(name);
    g.sample_size(20);
    g.throughput(Throughput::Elements(tris.len() as u64));
    g.bench_function("draw_mesh", |b| {
        b.iter_batched_ref(
            || Framebuffer::new(vp),
            |fb| draw_mesh(verts, tris, vp, &opts, fb),
            BatchSize::LargeInput,
        )
    });
    g.bench_function("setup_only", |b| {
        b.iter_batched_ref(
            || Vec::with_capacity(tris.len()),
            |out| setup_mesh(verts, tris, vp, &opts, out),
            BatchSize::LargeInput,
        )
    });
    g.throughput(Throughput::Elements(screen.len() as u64));
    g.bench_function("scan_screen_triangles", |b| {
        b.iter_batched_ref(
            || Framebuffer::new(vp),
            |fb| draw_screen_triangles(&screen, fb),
            BatchSize::LargeInput,
        )
    });
    g.bench_function("scanline_renderer", |b| {
        b.iter_batched_ref(
            || Framebuffer::new(vp),
            |fb| render_scanlines_into(&screen, fb, [0; 3]),
            BatchSize::LargeInput,
        )
    });
    g.finish();
}

fn bench_small<M: Measurement>(c: &mut Criterion<M>) {
    let (verts, tris) = grid();
    bench_small_group(c, "small_triangles_mesh", &verts, &tris);
    let (verts, tris) = small(100_000);
    bench_small_group(c, "small_triangles_scattered", &verts, &tris);
}

/// On-CPU time of the calling thread in nanoseconds (Linux schedstat).
fn thread_cpu_ns() -> u64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next().and_then(|v| v.parse().ok()))
        .unwrap_or(0)
}

/// Criterion measurement of thread CPU time, formatted like wall time.
struct CpuTime;

impl Measurement for CpuTime {
    type Intermediate = u64;
    type Value = u64;
    fn start(&self) -> u64 {
        thread_cpu_ns()
    }
    fn end(&self, i: u64) -> u64 {
        thread_cpu_ns().saturating_sub(i)
    }
    fn add(&self, a: &u64, b: &u64) -> u64 {
        a + b
    }
    fn zero(&self) -> u64 {
        0
    }
    fn to_f64(&self, v: &u64) -> f64 {
        *v as f64
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        WallTime.formatter()
    }
}

fn main() {
    if std::env::var_os("RASTER_BENCH_CPU_TIME").is_some() {
        let mut c = Criterion::default()
            .with_measurement(CpuTime)
            .configure_from_args();
        bench_large(&mut c);
        bench_small(&mut c);
        c.final_summary();
    } else {
        let mut c = Criterion::default().configure_from_args();
        bench_large(&mut c);
        bench_small(&mut c);
        c.final_summary();
    }
}
