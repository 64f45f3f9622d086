//! Ellsworth's utilization simulator and performance model (paper 002, "Simulation",
//! "Estimated total time", Figures 4 and 5), without the discrete-event engine.
//!
//! For each frame of a viewing sequence the simulator transforms and classifies the polygons
//! into regions (granularity ratio x N of them), assigns regions to processors by greedy
//! bin packing on *estimated* region times (region overhead plus a constant per polygon,
//! "based only on the number of vertices"), taken from this frame's counts or the previous
//! frame's, and then scores the assignment with a *more accurate* region time (the pixels of
//! each triangle and the scanlines it crosses, from the real rasterizer):
//!
//! ```text
//! utilization = (sum of all region times / N) / (largest processor load)
//! ```
//!
//! assuming no time is lost waiting for data. The performance model adds transformation and
//! redistribution (overlap factor, per-message costs) to the rasterization time the
//! utilization implies, per (N, granularity).
//!
//! Each frame is rasterized once. The accurate times of any region grid are then sums over
//! rectangles of per-pixel tables (a summed-area table of pixel and span-start costs, and a
//! column table of spans crossing a pixel's left edge), and the polygon counts come from one
//! pass over the triangles' pixel bounding boxes per grid; so a frame costs one
//! rasterization plus O(triangles + regions) per distinct region count.
//!
//! Owns this simulator's arithmetic. Must never charge a node, run the engine, or invent a
//! time: every duration is a count times a cost from the machine (or the documented fallback
//! costs below, used only when the machine prices no rasterization operation at all).

use std::collections::BTreeMap;

use crate::algo::image_space::assign::Assignment;
use crate::algo::image_space::buffers::{HEADER_BYTES, TRIANGLE_BYTES};
use crate::algo::image_space::regions::{pixel_bounds, RegionGrid};
use crate::algo::reference::{raster_options, viewport};
use crate::machine::{MachineConfig, Op};
use crate::raster::target::nearer;
use crate::raster::{
    draw_screen_triangle, setup_mesh, Counters, Depth, ScreenRect, ScreenTriangle, Span, Target,
    Viewport,
};
use crate::scene::{Scene, SceneError};
use crate::units::{Bytes, SimTime};

/// Where the per-region counts that drive the assignment come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum CountsMode {
    /// This frame's own counts (paper 002's red curves): the ideal, with a synchronization.
    Current,
    /// The previous frame's counts (black curves, the algorithm's choice); the sequence's
    /// first frame assigns region r to processor r mod N.
    Previous,
    /// No load balancing: region r to processor r mod N in every frame (a baseline).
    Interleaved,
}

impl CountsMode {
    pub const ALL: [CountsMode; 3] = [
        CountsMode::Current,
        CountsMode::Previous,
        CountsMode::Interleaved,
    ];

    /// How the assignment was made, for table titles.
    pub fn describe(self) -> &'static str {
        match self {
            CountsMode::Current => "bin packing on the current frame's counts",
            CountsMode::Previous => "bin packing on the previous frame's counts",
            CountsMode::Interleaved => "no load balancing (region r to processor r mod N)",
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            CountsMode::Current => "current",
            CountsMode::Previous => "previous",
            CountsMode::Interleaved => "interleaved",
        }
    }
}

/// What to simulate. Build with [`Config::new`], which checks every list.
#[derive(Clone, Debug)]
pub struct Config {
    procs: Vec<u32>,
    granularities: Vec<u32>,
    frames: Vec<u32>,
    /// Polygon buffer size for the performance model's message count (paper 002: 4 KB).
    pub buffer: Bytes,
}

impl Config {
    /// Processor counts, granularity ratios and the frames to average over (sorted, without
    /// repeats). Every list must be non-empty and hold no zero.
    pub fn new(
        procs: &[u32],
        granularities: &[u32],
        frames: &[u32],
    ) -> Result<Config, UtilizationError> {
        let clean = |what: &'static str, v: &[u32], zero_ok: bool| {
            let mut v = v.to_vec();
            v.sort_unstable();
            v.dedup();
            if v.is_empty() {
                return Err(UtilizationError::Invalid(format!(
                    "{what}: the list is empty"
                )));
            }
            if !zero_ok && v[0] == 0 {
                return Err(UtilizationError::Invalid(format!(
                    "{what}: 0 is not allowed; expected whole numbers of at least 1"
                )));
            }
            Ok(v)
        };
        let procs = clean("--procs", procs, false)?;
        if let Some(&n) = procs.last().filter(|&&n| n > crate::limits::MAX_NODES) {
            return Err(UtilizationError::Invalid(format!(
                "--procs: {n} processors; at most {} (sortsim::limits::MAX_NODES)",
                crate::limits::MAX_NODES
            )));
        }
        Ok(Config {
            procs,
            granularities: clean("--granularity", granularities, false)?,
            frames: clean("--frames", frames, true)?,
            buffer: Bytes::new(4096),
        })
    }

    pub fn procs(&self) -> &[u32] {
        &self.procs
    }
    pub fn granularities(&self) -> &[u32] {
        &self.granularities
    }
    pub fn frames(&self) -> &[u32] {
        &self.frames
    }
}

#[derive(Debug, thiserror::Error)]
pub enum UtilizationError {
    #[error("{0}")]
    Invalid(String),
    #[error(transparent)]
    Scene(#[from] SceneError),
}

/// The per-operation prices the simulator uses, in the machine's terms.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Prices {
    pub transform_vertex: SimTime,
    pub setup_triangle: SimTime,
    pub span: SimTime,
    pub pixel_test: SimTime,
    pub pixel_write: SimTime,
    pub clear_pixel: SimTime,
    pub byte_copy: SimTime,
    /// Per message, sender plus receiver (always the machine's own).
    pub message: SimTime,
    /// Per byte sent and received (always the machine's own).
    pub per_byte: SimTime,
    /// True when the machine prices no rasterization operation and [`Prices::FALLBACK`]
    /// stands in for its operation costs.
    pub fallback: bool,
}

/// Operation costs used when a machine prices none of setup, span, pixel test, pixel write
/// and clear: i860-like magnitudes chosen so that their *ratios* are plausible for an
/// assembly-coded Gouraud z-buffer (a triangle's setup worth about 30 pixels, a span about
/// 3, clearing a pixel less than writing one). Only ratios matter to utilization; the
/// performance model's absolute times are then only indicative.
pub const FALLBACK: [(Op, SimTime); 7] = [
    (Op::TransformVertex, SimTime::from_ns(1000)),
    (Op::SetupTriangle, SimTime::from_ns(3000)),
    (Op::Span, SimTime::from_ns(300)),
    (Op::PixelTest, SimTime::from_ns(100)),
    (Op::PixelWrite, SimTime::from_ns(60)),
    (Op::ClearPixel, SimTime::from_ns(40)),
    (Op::ByteCopy, SimTime::from_ns(20)),
];

impl Prices {
    /// The machine's costs, or [`FALLBACK`] for the operation costs when it prices no
    /// rasterization operation.
    pub fn of(machine: &MachineConfig) -> Prices {
        let costs = &machine.cpu.costs;
        let raster_ops = [
            Op::SetupTriangle,
            Op::Span,
            Op::PixelTest,
            Op::PixelWrite,
            Op::ClearPixel,
        ];
        let fallback = raster_ops.iter().all(|&op| costs.get(op) == SimTime::ZERO);
        let get = |op: Op| {
            if fallback {
                FALLBACK
                    .iter()
                    .find(|(o, _)| *o == op)
                    .map_or(SimTime::ZERO, |(_, t)| *t)
            } else {
                costs.get(op)
            }
        };
        let cpu = &machine.cpu;
        Prices {
            transform_vertex: get(Op::TransformVertex),
            setup_triangle: get(Op::SetupTriangle),
            span: get(Op::Span),
            pixel_test: get(Op::PixelTest),
            pixel_write: get(Op::PixelWrite),
            clear_pixel: get(Op::ClearPixel),
            byte_copy: get(Op::ByteCopy),
            message: cpu.send_overhead + cpu.recv_overhead,
            per_byte: cpu.send_per_byte + cpu.recv_per_byte,
            fallback,
        }
    }

    /// The load balancer's constant per-polygon estimate, "based only on the number of
    /// vertices": a triangle's setup, three spans and six pixels tested and written (the same
    /// default as `sort-middle/ellsworth`'s `polygon-estimate`).
    pub fn polygon_estimate(&self) -> SimTime {
        self.setup_triangle + self.span.times(3) + (self.pixel_test + self.pixel_write).times(6)
    }

    /// A region's overhead, its time with no triangles: clearing its colour and z-buffer.
    pub fn region_overhead(&self, rect: ScreenRect) -> SimTime {
        self.clear_pixel.times(rect.pixels() as u64)
    }
}

/// Expected processor utilization of one assignment: the mean processor load over the
/// largest (1 when there is no work at all).
pub fn utilization(region_times: &[SimTime], owner: &[u32], processors: u32) -> f64 {
    let loads = processor_loads(region_times, owner, processors);
    let total: u128 = loads.iter().map(|t| t.ps() as u128).sum();
    let max = loads.iter().max().map_or(0, |t| t.ps());
    if max == 0 {
        return 1.0;
    }
    (total as f64 / processors as f64) / max as f64
}

/// Each processor's total region time under `owner`.
pub fn processor_loads(region_times: &[SimTime], owner: &[u32], processors: u32) -> Vec<SimTime> {
    let mut loads = vec![SimTime::ZERO; processors as usize];
    for (&t, &p) in region_times.iter().zip(owner) {
        loads[p as usize] += t;
    }
    loads
}

/// One frame reduced to what any region grid needs: the screen triangles' pixel bounding
/// boxes (for the classification and the counts) and per-pixel time tables (for the
/// accurate region times). Built by rasterizing the frame once.
pub struct FrameProfile {
    viewport: Viewport,
    /// Inclusive pixel bounds (x0, y0, x1, y1) of each screen triangle that covers a pixel
    /// centre's box; the same boxes `RegionGrid::touched_by` classifies.
    boxes: Vec<[u16; 4]>,
    /// Summed-area table, (W+1) x (H+1): time of the pixel tests and writes of every pixel,
    /// plus one span for every span starting at that pixel.
    area: Vec<u64>,
    /// Per column x, (H+1) prefix sums over rows of one span's time for every span covering
    /// both pixel x-1 and pixel x: a region starting at column x gets these spans too.
    crossing: Vec<u64>,
    /// Triangles handed to the front end and screen triangles it produced.
    pub triangles_in: u64,
    pub screen_triangles: u64,
    /// The raster work of the whole frame.
    pub counters: Counters,
}

impl FrameProfile {
    /// Sets up and rasterizes `frame` once, in primitive order into one z-buffer (so a pixel
    /// is written exactly when the region's own z-buffer would write it in that order).
    pub fn new(scene: &Scene, frame: u32, prices: &Prices) -> Result<FrameProfile, SceneError> {
        let geometry = scene.frame(frame)?;
        let vp = viewport(&geometry);
        let mut tris = Vec::new();
        let front = setup_mesh(
            &geometry.vertices,
            &geometry.triangles,
            vp,
            &raster_options(&geometry),
            &mut tris,
        );
        let mut target = PixelTimes::new(vp, prices);
        let mut counters = Counters::default();
        for t in &tris {
            draw_screen_triangle(t, &mut target, &mut counters);
        }
        let (area, crossing) = target.tables(prices);
        Ok(FrameProfile {
            viewport: vp,
            boxes: boxes(&tris, vp),
            area,
            crossing,
            triangles_in: front.triangles_in,
            screen_triangles: tris.len() as u64,
            counters,
        })
    }

    /// Polygon counts per region of `grid` (the classification `touched_by` does).
    pub fn counts(&self, grid: &RegionGrid) -> Vec<u32> {
        classify(&self.boxes, self.viewport, grid)
    }

    /// The accurate time of every region of `grid` given its polygon counts: its overhead,
    /// one setup per polygon sent to it, and the spans, pixel tests and writes inside it.
    pub fn region_times(&self, grid: &RegionGrid, counts: &[u32], prices: &Prices) -> Vec<SimTime> {
        let w1 = self.viewport.width() as usize + 1;
        let h1 = self.viewport.height() as usize + 1;
        (0..grid.count())
            .map(|r| {
                let rect = grid.rect(r);
                let (x0, y0, x1, y1) = (
                    rect.x0() as usize,
                    rect.y0() as usize,
                    rect.x1() as usize,
                    rect.y1() as usize,
                );
                let inside = self.area[y1 * w1 + x1] + self.area[y0 * w1 + x0]
                    - self.area[y0 * w1 + x1]
                    - self.area[y1 * w1 + x0];
                let entering = self.crossing[x0 * h1 + y1] - self.crossing[x0 * h1 + y0];
                prices.region_overhead(rect)
                    + prices.setup_triangle.times(counts[r as usize] as u64)
                    + SimTime::from_ps(inside + entering)
            })
            .collect()
    }
}

/// Polygon counts of a frame without rasterizing it: what the previous frame contributes.
pub fn frame_counts(scene: &Scene, frame: u32) -> Result<(Viewport, Vec<[u16; 4]>), SceneError> {
    let geometry = scene.frame(frame)?;
    let vp = viewport(&geometry);
    let mut tris = Vec::new();
    setup_mesh(
        &geometry.vertices,
        &geometry.triangles,
        vp,
        &raster_options(&geometry),
        &mut tris,
    );
    Ok((vp, boxes(&tris, vp)))
}

fn boxes(tris: &[ScreenTriangle], vp: Viewport) -> Vec<[u16; 4]> {
    tris.iter()
        .filter_map(|t| pixel_bounds(t, vp))
        .map(|(x0, y0, x1, y1)| [x0 as u16, y0 as u16, x1 as u16, y1 as u16])
        .collect()
}

/// Counts, per region, the boxes that touch it. Column and row lookup tables replace
/// `touched_by`'s divisions; the mapping is the same (a test checks it).
fn classify(boxes: &[[u16; 4]], vp: Viewport, grid: &RegionGrid) -> Vec<u32> {
    let (w, h) = (vp.width() as u64, vp.height() as u64);
    let (cols, rows) = (grid.cols() as u64, grid.rows() as u64);
    let col: Vec<u32> = (0..w).map(|x| (((x + 1) * cols - 1) / w) as u32).collect();
    let row: Vec<u32> = (0..h).map(|y| (((y + 1) * rows - 1) / h) as u32).collect();
    let mut counts = vec![0u32; grid.count() as usize];
    for &[x0, y0, x1, y1] in boxes {
        let (c0, c1) = (col[x0 as usize], col[x1 as usize]);
        for r in row[y0 as usize]..=row[y1 as usize] {
            for c in c0..=c1 {
                counts[(r * grid.cols() + c) as usize] += 1;
            }
        }
    }
    counts
}

/// A whole-screen target that, instead of keeping colours, records what each pixel costs:
/// tests and writes (with a real depth test), span starts, and spans crossing into it.
struct PixelTimes {
    rect: [ScreenRect; 1],
    width: usize,
    depth: Vec<u32>,
    prim: Vec<u32>,
    /// Picoseconds of pixel tests, writes and span starts per pixel.
    time: Vec<u64>,
    /// Spans covering pixel x-1 and pixel x, per pixel.
    crossing: Vec<u32>,
    test: u64,
    write: u64,
    span: u64,
}

impl PixelTimes {
    fn new(vp: Viewport, prices: &Prices) -> PixelTimes {
        let n = vp.pixels();
        PixelTimes {
            rect: [vp.rect()],
            width: vp.width() as usize,
            depth: vec![Depth::CLEARED; n],
            prim: vec![u32::MAX; n],
            time: vec![0; n],
            crossing: vec![0; n],
            test: prices.pixel_test.ps(),
            write: prices.pixel_write.ps(),
            span: prices.span.ps(),
        }
    }

    /// The summed-area table of `time` and the per-column prefix sums of `crossing`, priced.
    fn tables(&self, prices: &Prices) -> (Vec<u64>, Vec<u64>) {
        let (w, h) = (self.width, self.time.len() / self.width);
        let mut area = vec![0u64; (w + 1) * (h + 1)];
        for y in 0..h {
            let mut row = 0;
            for x in 0..w {
                row += self.time[y * w + x];
                area[(y + 1) * (w + 1) + x + 1] = area[y * (w + 1) + x + 1] + row;
            }
        }
        let span = prices.span.ps();
        let mut crossing = vec![0u64; (w + 1) * (h + 1)];
        for x in 0..w {
            for y in 0..h {
                crossing[x * (h + 1) + y + 1] =
                    crossing[x * (h + 1) + y] + span * self.crossing[y * w + x] as u64;
            }
        }
        (area, crossing)
    }
}

impl Target for PixelTimes {
    fn rects(&self) -> &[ScreenRect] {
        &self.rect
    }

    fn span(&mut self, _rect: usize, span: &Span<'_>, counters: &mut Counters) {
        let row = span.y() as usize * self.width;
        let prim = span.prim();
        self.time[row + span.x0() as usize] += self.span;
        for f in span.fragments() {
            let i = row + f.x as usize;
            self.time[i] += self.test;
            counters.pixels_tested += 1;
            if nearer(f.z, prim, self.depth[i], self.prim[i]) {
                self.depth[i] = f.z;
                self.prim[i] = prim;
                self.time[i] += self.write;
                counters.pixels_written += 1;
            }
            if f.x > span.x0() {
                self.crossing[i] += 1;
            }
        }
    }
}

/// The simulator's answer for one (N, granularity, counts mode), averaged over the frames.
#[derive(Clone, Debug, PartialEq)]
pub struct Cell {
    pub procs: u32,
    pub granularity: u32,
    pub counts: CountsMode,
    /// Mean over frames of the expected rasterization utilization, 0..=1.
    pub utilization: f64,
    /// The worst frame's utilization.
    pub utilization_min: f64,
    /// Mean regions a screen triangle's bounding box touches.
    pub overlap_factor: f64,
    /// Performance model (Figure 5): mean per-frame times of each stage, in seconds.
    pub transform_s: f64,
    pub redistribute_s: f64,
    pub rasterize_s: f64,
    /// `total_s` over the mean `total_s` of all granularities with the same N and mode.
    pub relative_time: f64,
}

impl Cell {
    pub fn total_s(&self) -> f64 {
        self.transform_s + self.redistribute_s + self.rasterize_s
    }
}

/// Everything one simulation produced.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub frames: Vec<u32>,
    pub prices: Prices,
    /// Mean screen triangles per frame and mean pixels tested per frame (scene context).
    pub mean_screen_triangles: f64,
    pub mean_pixels_tested: f64,
    /// Every (N, granularity, mode), ordered by mode, N, granularity.
    pub cells: Vec<Cell>,
}

impl Outcome {
    pub fn cell(&self, procs: u32, granularity: u32, counts: CountsMode) -> Option<&Cell> {
        self.cells
            .iter()
            .find(|c| c.procs == procs && c.granularity == granularity && c.counts == counts)
    }
}

impl Outcome {
    /// Processor counts and granularities present, ascending.
    fn axes(&self) -> (Vec<u32>, Vec<u32>) {
        let mut procs: Vec<u32> = self.cells.iter().map(|c| c.procs).collect();
        let mut grans: Vec<u32> = self.cells.iter().map(|c| c.granularity).collect();
        procs.sort_unstable();
        procs.dedup();
        grans.sort_unstable();
        grans.dedup();
        (procs, grans)
    }

    /// A table a person reads: rows N, columns granularity, one block per mode, of
    /// `value(cell)` formatted with `digits` decimals.
    pub fn table(
        &self,
        modes: &[CountsMode],
        title: &str,
        digits: usize,
        value: impl Fn(&Cell) -> f64,
    ) -> String {
        let (procs, grans) = self.axes();
        let mut out = String::new();
        for &mode in modes {
            out.push_str(&format!("{title}, {}\n", mode.describe()));
            out.push_str(&format!("{:>6}", "N \\ g"));
            for g in &grans {
                out.push_str(&format!(" {g:>6}"));
            }
            out.push('\n');
            for &n in &procs {
                out.push_str(&format!("{n:>6}"));
                for &g in &grans {
                    match self.cell(n, g, mode) {
                        Some(c) => out.push_str(&format!(" {:>6.*}", digits, value(c))),
                        None => out.push_str(&format!(" {:>6}", "-")),
                    }
                }
                out.push('\n');
            }
            out.push('\n');
        }
        out
    }

    /// One row per cell, with units in the column names.
    pub fn csv(&self) -> String {
        let mut out = String::from(
            "counts,procs,granularity,regions,utilization_pct,utilization_min_pct,overlap_factor,transform_s,redistribute_s,rasterize_s,total_s,relative_time\n",
        );
        for c in &self.cells {
            out.push_str(&format!(
                "{},{},{},{},{:.4},{:.4},{:.5},{:.9},{:.9},{:.9},{:.9},{:.5}\n",
                c.counts.name(),
                c.procs,
                c.granularity,
                c.procs * c.granularity,
                100.0 * c.utilization,
                100.0 * c.utilization_min,
                c.overlap_factor,
                c.transform_s,
                c.redistribute_s,
                c.rasterize_s,
                c.total_s(),
                c.relative_time
            ));
        }
        out
    }

    /// Everything, for utilization.json: the inputs that shaped the numbers, then the cells.
    pub fn json(&self, scene: &str, machine: &str) -> serde_json::Value {
        let p = &self.prices;
        let ns = |t: SimTime| t.ps() as f64 / 1000.0;
        let cells: Vec<serde_json::Value> = self
            .cells
            .iter()
            .map(|c| {
                serde_json::json!({
                    "counts": c.counts.name(), "procs": c.procs, "granularity": c.granularity,
                    "regions": c.procs * c.granularity,
                    "utilization_pct": 100.0 * c.utilization, "utilization_min_pct": 100.0 * c.utilization_min,
                    "overlap_factor": c.overlap_factor, "transform_s": c.transform_s,
                    "redistribute_s": c.redistribute_s, "rasterize_s": c.rasterize_s,
                    "total_s": c.total_s(), "relative_time": c.relative_time,
                })
            })
            .collect();
        serde_json::json!({
            "paper": "002 (Ellsworth), Figures 4 and 5",
            "scene": scene,
            "machine": machine,
            "frames": self.frames,
            "mean_screen_triangles": self.mean_screen_triangles,
            "mean_pixels_tested": self.mean_pixels_tested,
            "costs_ns": {
                "fallback": p.fallback,
                "transform_vertex": ns(p.transform_vertex), "setup_triangle": ns(p.setup_triangle),
                "span": ns(p.span), "pixel_test": ns(p.pixel_test), "pixel_write": ns(p.pixel_write),
                "clear_pixel": ns(p.clear_pixel), "byte_copy": ns(p.byte_copy),
                "message": ns(p.message), "per_byte": ns(p.per_byte),
                "polygon_estimate": ns(p.polygon_estimate()),
            },
            "cells": cells,
        })
    }
}

/// Per-cell sums over frames, before averaging.
#[derive(Clone, Debug, Default)]
struct Sums {
    utilization: f64,
    utilization_min: f64,
    overlap: f64,
    transform: u128,
    redistribute: u128,
    rasterize: u128,
}

/// Runs the utilization simulator over the configured frames of `scene`.
pub fn simulate(
    scene: &Scene,
    machine: &MachineConfig,
    cfg: &Config,
) -> Result<Outcome, UtilizationError> {
    if let Some(&bad) = cfg.frames.iter().find(|&&f| f >= scene.frame_count()) {
        return Err(UtilizationError::Invalid(format!(
            "--frames: frame {bad} is past the end; the scene has frames 0..{}",
            scene.frame_count()
        )));
    }
    let prices = Prices::of(machine);
    let mut sums: BTreeMap<(CountsMode, u32, u32), Sums> = BTreeMap::new();
    // The last frame whose counts are known, kept so that consecutive frames classify once.
    let mut known: Option<(u32, Viewport, Vec<[u16; 4]>)> = None;
    let (mut triangles, mut pixels) = (0u64, 0u64);
    for &frame in &cfg.frames {
        let profile = FrameProfile::new(scene, frame, &prices)?;
        triangles += profile.screen_triangles;
        pixels += profile.counters.pixels_tested;
        // Frame f is balanced with frame f-1's counts; when f-1 was not sampled it is
        // classified (set up, not rasterized) here.
        let fetched;
        let previous: Option<(Viewport, &[[u16; 4]])> = match &known {
            _ if frame == 0 => None,
            Some((f, vp, b)) if *f + 1 == frame => Some((*vp, b.as_slice())),
            _ => {
                fetched = frame_counts(scene, frame - 1)?;
                Some((fetched.0, fetched.1.as_slice()))
            }
        };
        for (&regions, pairs) in &grids(cfg) {
            let grid = RegionGrid::with_count(profile.viewport, regions)
                .ok_or_else(|| too_many(regions, profile.viewport))?;
            let counts = profile.counts(&grid);
            let times = profile.region_times(&grid, &counts, &prices);
            let previous_counts = previous.map(|(vp, b)| classify(b, vp, &grid));
            let overlap = counts.iter().map(|&c| c as u64).sum::<u64>() as f64
                / profile.boxes.len().max(1) as f64;
            for &(n, g) in pairs {
                let model = |max_load: SimTime| {
                    stage_times(&profile, n, overlap, max_load, &prices, cfg.buffer)
                };
                for mode in CountsMode::ALL {
                    let owner = match (mode, &previous_counts) {
                        (CountsMode::Current, _) => balance(&grid, &counts, n, &prices),
                        (CountsMode::Previous, Some(prev)) => balance(&grid, prev, n, &prices),
                        (CountsMode::Previous, None) | (CountsMode::Interleaved, _) => {
                            Assignment::interleaved(regions, n).owner
                        }
                    };
                    let u = utilization(&times, &owner, n);
                    let max_load = processor_loads(&times, &owner, n)
                        .into_iter()
                        .max()
                        .unwrap_or(SimTime::ZERO);
                    let (t, d, r) = model(max_load);
                    let s = sums.entry((mode, n, g)).or_insert(Sums {
                        utilization_min: f64::INFINITY,
                        ..Sums::default()
                    });
                    s.utilization += u;
                    s.utilization_min = s.utilization_min.min(u);
                    s.overlap += overlap;
                    s.transform += t.ps() as u128;
                    s.redistribute += d.ps() as u128;
                    s.rasterize += r.ps() as u128;
                }
            }
        }
        known = Some((frame, profile.viewport, profile.boxes));
    }
    let frames = cfg.frames.len() as f64;
    Ok(Outcome {
        frames: cfg.frames.clone(),
        prices,
        mean_screen_triangles: triangles as f64 / frames,
        mean_pixels_tested: pixels as f64 / frames,
        cells: relative(average(sums, frames)),
    })
}

/// The distinct region counts of the configuration, each with the (N, granularity) pairs
/// that share its grid.
fn grids(cfg: &Config) -> BTreeMap<u32, Vec<(u32, u32)>> {
    let mut grids: BTreeMap<u32, Vec<(u32, u32)>> = BTreeMap::new();
    for &n in &cfg.procs {
        for &g in &cfg.granularities {
            grids.entry(n.saturating_mul(g)).or_default().push((n, g));
        }
    }
    grids
}

fn too_many(regions: u32, vp: Viewport) -> UtilizationError {
    UtilizationError::Invalid(format!(
        "{regions} regions (processors x granularity) do not fit a {}x{} screen; use fewer processors or a smaller granularity",
        vp.width(),
        vp.height()
    ))
}

/// Ellsworth's load balancing: estimated region times from polygon counts, then greedy
/// multiple-bin packing (largest first, each to the least-loaded processor).
fn balance(grid: &RegionGrid, counts: &[u32], n: u32, prices: &Prices) -> Vec<u32> {
    let estimate = prices.polygon_estimate();
    let estimates: Vec<SimTime> = (0..grid.count())
        .map(|r| prices.region_overhead(grid.rect(r)) + estimate.times(counts[r as usize] as u64))
        .collect();
    Assignment::greedy(&estimates, &vec![SimTime::ZERO; n as usize]).owner
}

/// The performance model's stages for one frame on N processors (paper 002, "Estimated total
/// time"): an even share of the transformation, the redistribution of each processor's share
/// times the overlap factor (copies, bytes, and at least one message to every other
/// processor), and the rasterization as the largest processor load. No congestion, no load
/// balancing time, as in the paper.
fn stage_times(
    profile: &FrameProfile,
    n: u32,
    overlap: f64,
    max_load: SimTime,
    prices: &Prices,
    buffer: Bytes,
) -> (SimTime, SimTime, SimTime) {
    let n64 = n as u64;
    let transform = prices
        .transform_vertex
        .times(3 * profile.triangles_in.div_ceil(n64));
    // Copies sent per processor: its share of the screen triangles times the overlap factor;
    // the fraction 1/N that stays local is neither sent nor received.
    let copies = (profile.screen_triangles as f64 * overlap / n as f64).round() as u64;
    let remote = copies * (n64 - 1) / n64;
    let bytes = remote * TRIANGLE_BYTES;
    let per_message = buffer
        .get()
        .saturating_sub(HEADER_BYTES)
        .max(TRIANGLE_BYTES);
    let messages = if n == 1 {
        0
    } else {
        (n64 - 1).max(bytes.div_ceil(per_message))
    };
    let redistribute = prices.byte_copy.times(copies * TRIANGLE_BYTES)
        + prices.per_byte.times(bytes)
        + prices.message.times(messages);
    (transform, redistribute, max_load)
}

fn average(sums: BTreeMap<(CountsMode, u32, u32), Sums>, frames: f64) -> Vec<Cell> {
    let secs = |ps: u128| ps as f64 / 1e12 / frames;
    sums.into_iter()
        .map(|((counts, procs, granularity), s)| Cell {
            procs,
            granularity,
            counts,
            utilization: s.utilization / frames,
            utilization_min: s.utilization_min,
            overlap_factor: s.overlap / frames,
            transform_s: secs(s.transform),
            redistribute_s: secs(s.redistribute),
            rasterize_s: secs(s.rasterize),
            relative_time: 0.0,
        })
        .collect()
}

/// Figure 5's normalization: each time over the mean time of all granularities with the same
/// N (and counts mode).
fn relative(mut cells: Vec<Cell>) -> Vec<Cell> {
    let mut means: BTreeMap<(CountsMode, u32), (f64, u32)> = BTreeMap::new();
    for c in &cells {
        let m = means.entry((c.counts, c.procs)).or_default();
        m.0 += c.total_s();
        m.1 += 1;
    }
    for c in &mut cells {
        let (sum, k) = means[&(c.counts, c.procs)];
        let mean = sum / k as f64;
        c.relative_time = if mean > 0.0 { c.total_s() / mean } else { 1.0 };
    }
    cells
}

/// Parses a list of whole numbers: items separated by commas, each `N`, a range `A..B` (B
/// excluded) or `A..=B` (B included; `spec::range`), `A..=B:S` (step S) or `A..=B:xF`
/// (times F); or `A,B,...,Z`, which continues the first two
/// as a geometric series when it reaches Z exactly (2,4,...,512) and as an arithmetic one
/// otherwise (1,2,...,12). The result is sorted, without repeats.
pub fn parse_list(text: &str) -> Result<Vec<u32>, String> {
    let items: Vec<&str> = text.split(',').map(str::trim).collect();
    let mut out = Vec::new();
    if let Some(i) = items.iter().position(|s| *s == "..." || *s == "…") {
        if i < 2 || i + 2 != items.len() {
            return Err(format!("'{text}': write an ellipsis as A,B,...,Z"));
        }
        let number = |s: &str| {
            s.parse::<u32>()
                .map_err(|_| format!("'{s}' is not a whole number"))
        };
        for s in &items[..i - 2] {
            out.push(number(s)?);
        }
        let (a, b, z) = (
            number(items[i - 2])?,
            number(items[i - 1])?,
            number(items[i + 1])?,
        );
        if b > a && z >= b {
            // At most this many (an arithmetic series); a geometric one has fewer.
            crate::limits::check_list(text, u64::from(z - a) / u64::from(b - a) + 1)?;
        }
        out.extend(
            series(a, b, z).ok_or_else(|| format!("'{text}': {a},{b},... never reaches {z}"))?,
        );
    } else {
        for item in items {
            out.extend(parse_item(item)?);
            crate::limits::check_list(text, out.len() as u64)?;
        }
    }
    if out.is_empty() {
        return Err(format!("'{text}' is an empty list"));
    }
    out.sort_unstable();
    out.dedup();
    Ok(out)
}

fn parse_item(item: &str) -> Result<Vec<u32>, String> {
    let number = |s: &str| {
        s.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{s}' is not a whole number (in '{item}')"))
    };
    let (range, step) = item.split_once(':').unwrap_or((item, "1"));
    let Some(range) = crate::spec::range::parse(range) else {
        return if item.is_empty() {
            Ok(Vec::new())
        } else {
            Ok(vec![number(item)?])
        };
    };
    let range = range?;
    let (a, b) = (*range.start(), *range.end());
    let mut v = Vec::new();
    if let Some(f) = step.strip_prefix('x') {
        let f = number(f)?;
        if f < 2 || a == 0 {
            return Err(format!("'{item}': a geometric range needs a start of at least 1 and a factor of at least 2"));
        }
        let mut x = a as u64;
        while x <= b as u64 {
            v.push(x as u32);
            x *= f as u64;
        }
    } else {
        let s = number(step)?;
        if s == 0 {
            return Err(format!("'{item}': a step of 0"));
        }
        crate::limits::check_list(item, u64::from(b - a) / u64::from(s) + 1)?;
        v.extend((a..=b).step_by(s as usize));
    }
    Ok(v)
}

/// a, b, ... up to z: geometric when b is a whole multiple of a and the series hits z,
/// otherwise arithmetic when it hits z.
fn series(a: u32, b: u32, z: u32) -> Option<Vec<u32>> {
    if a >= 1 && b > a && b % a == 0 {
        let f = (b / a) as u64;
        let v: Vec<u32> = std::iter::successors(Some(a as u64), |x| Some(x * f))
            .take_while(|&x| x <= z as u64)
            .map(|x| x as u32)
            .collect();
        if v.last() == Some(&z) {
            return Some(v);
        }
    }
    if b > a && (z - a) % (b - a) == 0 && z >= b {
        return Some((a..=z).step_by((b - a) as usize).collect());
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ps(v: &[u64]) -> Vec<SimTime> {
        v.iter().map(|&x| SimTime::from_ps(x)).collect()
    }

    #[test]
    fn utilization_is_mean_load_over_max_load() {
        // Loads 6 and 2: mean 4, max 6.
        assert!((utilization(&ps(&[4, 2, 2]), &[0, 0, 1], 2) - 4.0 / 6.0).abs() < 1e-12);
        // Perfect balance.
        assert_eq!(utilization(&ps(&[3, 3, 3, 3]), &[0, 1, 2, 3], 4), 1.0);
        // One processor is always fully utilized.
        assert_eq!(utilization(&ps(&[5, 1, 7]), &[0, 0, 0], 1), 1.0);
        // All work on one of four: 25%.
        assert_eq!(utilization(&ps(&[8, 0, 0, 0]), &[0, 1, 2, 3], 4), 0.25);
        // An idle processor without regions still counts in N.
        assert_eq!(utilization(&ps(&[2, 2]), &[0, 1], 4), 0.5);
        // No work at all is not an imbalance.
        assert_eq!(utilization(&ps(&[0, 0]), &[0, 1], 2), 1.0);
    }

    #[test]
    fn loads_sum_each_processors_regions() {
        assert_eq!(
            processor_loads(&ps(&[1, 2, 3, 4]), &[1, 0, 1, 2], 3),
            ps(&[2, 4, 4])
        );
    }

    #[test]
    fn classify_matches_touched_by() {
        let vp = Viewport::new(37, 23).unwrap();
        let boxes = [
            [0u16, 0, 0, 0],
            [3, 4, 20, 5],
            [36, 22, 36, 22],
            [0, 0, 36, 22],
            [10, 10, 11, 19],
        ];
        for count in [1, 6, 12, 35, 60] {
            let grid = RegionGrid::with_count(vp, count).unwrap();
            let counts = classify(&boxes, vp, &grid);
            for (r, &c) in counts.iter().enumerate() {
                let rect = grid.rect(r as u32);
                let expected = boxes
                    .iter()
                    .filter(|b| {
                        (b[0] as u32) < rect.x1()
                            && b[2] as u32 >= rect.x0()
                            && (b[1] as u32) < rect.y1()
                            && b[3] as u32 >= rect.y0()
                    })
                    .count();
                assert_eq!(c as usize, expected, "{count} regions, region {r}");
            }
        }
    }

    #[test]
    fn the_performance_model_charges_shares_copies_and_messages() {
        let profile = FrameProfile {
            viewport: Viewport::new(4, 4).unwrap(),
            boxes: Vec::new(),
            area: Vec::new(),
            crossing: Vec::new(),
            triangles_in: 1000,
            screen_triangles: 800,
            counters: Counters::default(),
        };
        let prices = Prices {
            transform_vertex: SimTime::from_ns(1),
            setup_triangle: SimTime::ZERO,
            span: SimTime::ZERO,
            pixel_test: SimTime::ZERO,
            pixel_write: SimTime::ZERO,
            clear_pixel: SimTime::ZERO,
            byte_copy: SimTime::from_ps(1),
            message: SimTime::from_us(100),
            per_byte: SimTime::ZERO,
            fallback: false,
        };
        let raster = SimTime::from_us(7);
        // One processor: everything local, no message.
        let (t, d, r) = stage_times(&profile, 1, 1.0, raster, &prices, Bytes::new(4096));
        assert_eq!(t, SimTime::from_ns(3000));
        assert_eq!(d, SimTime::from_ps(800 * TRIANGLE_BYTES));
        assert_eq!(r, raster);
        // Eight processors, overlap 1.5: 150 copies each, at least one message to each of
        // the 7 others, and more when the remote bytes need more buffers.
        let (t, d, _) = stage_times(&profile, 8, 1.5, raster, &prices, Bytes::new(4096));
        assert_eq!(t, SimTime::from_ns(3 * 125));
        assert_eq!(
            d,
            SimTime::from_ps(150 * TRIANGLE_BYTES) + SimTime::from_us(700)
        );
        let small = Bytes::new(HEADER_BYTES + 10 * TRIANGLE_BYTES);
        let (_, d, _) = stage_times(&profile, 8, 1.5, raster, &prices, small);
        // 150 * 7 / 8 = 131 remote copies in buffers of 10: 14 messages.
        assert_eq!(
            d,
            SimTime::from_ps(150 * TRIANGLE_BYTES) + SimTime::from_us(1400)
        );
    }

    #[test]
    fn lists_ranges_and_series() {
        assert_eq!(
            parse_list("2,4,...,512").unwrap(),
            vec![2, 4, 8, 16, 32, 64, 128, 256, 512]
        );
        assert_eq!(
            parse_list("1,2,...,12").unwrap(),
            (1..=12).collect::<Vec<_>>()
        );
        // Ranges as Rust reads them: B excluded by `..`, included by `..=`.
        assert_eq!(parse_list("1..12").unwrap(), (1..12).collect::<Vec<_>>());
        assert_eq!(parse_list("1..=12").unwrap(), (1..=12).collect::<Vec<_>>());
        assert_eq!(parse_list("2..=512:x2").unwrap().len(), 9);
        assert_eq!(parse_list("2..512:x2").unwrap().len(), 8);
        assert_eq!(
            parse_list("2..=12:2, 1").unwrap(),
            vec![1, 2, 4, 6, 8, 10, 12]
        );
        assert_eq!(parse_list("2..12:2").unwrap(), vec![2, 4, 6, 8, 10]);
        assert_eq!(parse_list("8,4,8").unwrap(), vec![4, 8]);
        assert!(parse_list("").is_err());
        assert!(parse_list("3..1").is_err());
        assert!(parse_list("3..3").is_err());
        assert!(parse_list("a").is_err());
        assert!(parse_list("2,4,...,9").is_err());
        // Refused before expanding: a range, a stepped range, a series, a long list.
        for big in [
            "1..4294967295",
            "0..4294967295:2",
            "1,2,...,100000",
            "1..4096, 5000..9000",
        ] {
            let e = parse_list(big).unwrap_err();
            assert!(e.contains("the limit is 4096"), "{big}: {e}");
        }
        assert_eq!(parse_list("1..=4096").unwrap().len(), 4096);
        assert!(parse_list("1..4:0").is_err());
    }

    #[test]
    fn config_rejects_zero_and_empty() {
        assert!(Config::new(&[0, 2], &[1], &[0]).is_err());
        assert!(Config::new(&[2], &[0], &[0]).is_err());
        assert!(Config::new(&[], &[1], &[0]).is_err());
        assert!(Config::new(&[2], &[1], &[0]).is_ok());
    }
}
