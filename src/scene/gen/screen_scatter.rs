//! Stand-ins for paper 003's pixel traces (Bike, Cube, Zinnia, ...): the traces give only a
//! primitive count, a mean primitive size and a depth complexity, so the stand-in is
//! `count` triangles placed in screen space (for the `screen` camera: x right, y down in
//! pixels, depth z in [0, 1]) with log-normal areas rescaled so their mean is exactly
//! `mean_area_px`, centres uniform over the positions where the triangle fits inside the
//! screen, random depth and colour. Because every triangle is wholly on screen, depth
//! complexity is count * mean / (width * height) by construction.
//!
//! With `background_fraction` > 0 the first two triangles are a "background" quad across the
//! full width covering that fraction of the screen, farthest of all: paper 003's Zinnia had
//! its largest primitive first in database order, which is what made round-robin snooping
//! exceed its expected traffic. The quad counts towards `count` and towards the mean.
//!
//! With `footprint` f < 1 the scattered triangles fall wholly inside a centred rectangle of
//! the screen's aspect and f of its area: the same pixels generated, piled f^-1 times as deep
//! over a share f of the screen. Traced scenes seldom fill their window evenly, and how their
//! depth piles up is what snooping's traffic depends on (paper 003, equation 3); f = 1 is
//! the even scatter, drawn exactly as before the option existed.
//!
//! Owns this shape only. Must never place or light it.

use glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, LogNormal};

use super::GenContext;
use crate::scene::mesh::Mesh;

/// The generator's parameters, as the scene spec gives them.
pub struct Scatter {
    pub count: u32,
    pub mean_area_px: f64,
    pub sigma: f64,
    pub seed: u64,
    pub background_fraction: f64,
    pub footprint: f64,
}

pub fn build(s: Scatter, ctx: GenContext) -> Mesh {
    let mut rng = ChaCha8Rng::seed_from_u64(s.seed);
    let (w, h) = (ctx.width as f64, ctx.height as f64);
    let region = Region::centred(w, h, s.footprint);
    let mut m = Mesh::new();
    let mut colors = Vec::new();
    let mut total = s.count as f64 * s.mean_area_px;
    let mut n = s.count as usize;
    let background_fraction = s.background_fraction;
    if background_fraction > 0.0 && s.count >= 2 {
        let top = (h * (1.0 - background_fraction)) as f32;
        let grey = Vec3::splat(0.3);
        let quad = [
            Vec3::new(0.0, top, 0.999),
            Vec3::new(w as f32, top, 0.999),
            Vec3::new(w as f32, h as f32, 0.999),
            Vec3::new(0.0, h as f32, 0.999),
        ];
        // Front-facing on screen means negative signed area with y down: (0,top) -> (0,h) -> (w,h).
        push_tri(&mut m, &mut colors, [quad[0], quad[3], quad[2]], grey);
        push_tri(&mut m, &mut colors, [quad[0], quad[2], quad[1]], grey);
        total -= w * background_fraction * h;
        n -= 2;
    }
    let areas = areas(&mut rng, n, total.max(0.0), s.sigma, region.w.min(region.h));
    for a in areas {
        let color = Vec3::new(rng.gen(), rng.gen(), rng.gen());
        let tri = place(&mut rng, a, &region);
        push_tri(&mut m, &mut colors, tri, color);
    }
    m.colors = Some(colors);
    m
}

/// `n` log-normal areas scaled to sum to `total`, each capped so it fits on screen.
fn areas(rng: &mut ChaCha8Rng, n: usize, total: f64, sigma: f64, side: f64) -> Vec<f64> {
    if n == 0 {
        return Vec::new();
    }
    let dist = LogNormal::new(0.0, sigma.max(1e-9)).expect("sigma is validated finite and >= 0");
    let mut a: Vec<f64> = (0..n).map(|_| dist.sample(rng)).collect();
    // The cap is the largest equilateral triangle whose circumcircle fits in the screen.
    let cap = 3.0 * 3f64.sqrt() / 4.0 * (0.5 * side).powi(2);
    // Rescale, cap, and rescale the uncapped ones again until the sum is right.
    for _ in 0..8 {
        let sum: f64 = a.iter().sum();
        let k = total / sum;
        a.iter_mut().for_each(|x| *x = (*x * k).min(cap));
    }
    a
}

/// The rectangle the scattered triangles fall in, in pixels.
struct Region {
    x0: f64,
    y0: f64,
    w: f64,
    h: f64,
}

impl Region {
    /// A rectangle of the screen's aspect and `share` of its area, centred; the whole screen
    /// (exactly, so that an even scatter draws what it always drew) when `share` is 1.
    fn centred(w: f64, h: f64, share: f64) -> Region {
        if share >= 1.0 {
            return Region {
                x0: 0.0,
                y0: 0.0,
                w,
                h,
            };
        }
        let side = share.sqrt();
        Region {
            x0: 0.5 * w * (1.0 - side),
            y0: 0.5 * h * (1.0 - side),
            w: w * side,
            h: h * side,
        }
    }
}

/// An equilateral-ish triangle of area `area`, randomly turned and stretched, wholly inside
/// the region, front-facing (negative signed area with y down).
fn place(rng: &mut ChaCha8Rng, area: f64, region: &Region) -> [Vec3; 3] {
    let stretch: f64 = rng.gen_range(0.7..1.4);
    let turn: f64 = rng.gen_range(0.0..std::f64::consts::TAU);
    let r = (4.0 * area / (3.0 * 3f64.sqrt())).sqrt(); // circumradius of the equilateral one
    let pts: Vec<(f64, f64)> = (0..3)
        .map(|k| {
            // Angles decreasing: clockwise in y-down coordinates, i.e. counter-clockwise to the
            // viewer, which is what front-facing means here.
            let a = -(k as f64) * std::f64::consts::TAU / 3.0;
            let (x, y) = (a.cos() * r * stretch, a.sin() * r / stretch);
            (
                x * turn.cos() - y * turn.sin(),
                x * turn.sin() + y * turn.cos(),
            )
        })
        .collect();
    let (lo_x, hi_x) = pts
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, hh), p| (l.min(p.0), hh.max(p.0)));
    let (lo_y, hi_y) = pts
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, hh), p| (l.min(p.1), hh.max(p.1)));
    let cx = region.x0 + pick(rng, -lo_x, region.w - hi_x);
    let cy = region.y0 + pick(rng, -lo_y, region.h - hi_y);
    let z: f32 = rng.gen_range(0.02..0.98);
    let p = pts
        .iter()
        .map(|(x, y)| Vec3::new((cx + x) as f32, (cy + y) as f32, z))
        .collect::<Vec<_>>();
    [p[0], p[1], p[2]]
}

fn pick(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    if hi > lo {
        rng.gen_range(lo..hi)
    } else {
        (lo + hi) * 0.5
    }
}

fn push_tri(m: &mut Mesh, colors: &mut Vec<Vec3>, t: [Vec3; 3], color: Vec3) {
    let part = 0;
    let i = m.vertex(t[0], part);
    let j = m.vertex(t[1], part);
    let k = m.vertex(t[2], part);
    colors.extend([color; 3]);
    m.tri(i, j, k);
}
