//! Trace-driven merge-traffic simulation (paper 003, sections 4, 5 and 7): the primitives of a
//! trace are assigned to n processors and each processor is taken to have rendered exactly
//! its primitives' fragments; then the pixel traffic of three merging algorithms is counted.
//!
//! - direct send (section 4, Kubota Denali): every fragment goes to the node owning its pixel:
//!   d*A pixels; with a local z-buffer each node sends only its active pixels.
//! - PixelFlow (section 5): every node streams its whole frame to the next: n*A pixels in
//!   total, A on each of the n links (the last link feeds the frame buffer).
//! - distributed snooping (section 7): after local z-buffering, nodes broadcast their
//!   surviving active pixels in processor order; every listener deletes its pixels a
//!   broadcast pixel hides. The traffic is the pixels actually broadcast; at one pixel it is
//!   the number of processors whose local winner is nearer than every earlier processor's.
//!
//! "Nearer" is always `raster::target::nearer` ((depth, primitive id) order), so the last
//! pixel broadcast at each location is the sequential z-buffer's pixel.
//!
//! Must never rasterize, never read the clock, never iterate a hash map: a replay is a pure
//! function of the trace, the assignment rule, n and the seed.

use super::format::Trace;
use crate::algo::primitives::deal;
use crate::output::plot::Series;
use crate::raster::target::nearer;
use crate::raster::ACTIVE_PIXEL_BYTES;

/// A merging algorithm of paper 003.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Algo {
    DirectSend,
    PixelFlow,
    Snooping,
}

impl Algo {
    pub const ALL: [Algo; 3] = [Algo::DirectSend, Algo::PixelFlow, Algo::Snooping];

    /// The command-line id.
    pub fn name(self) -> &'static str {
        match self {
            Algo::DirectSend => "direct-send",
            Algo::PixelFlow => "pixelflow",
            Algo::Snooping => "snooping",
        }
    }
}

/// How primitives are dealt to processors: the rules of [`crate::algo::primitives`], over
/// the primitives present in the trace in id order (the database order), with primitive
/// sizes in fragments; the random stream is `trace/assign/n=<n>`.
pub use crate::algo::primitives::Deal as Assign;

/// What to replay.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ReplayConfig {
    pub algos: Vec<Algo>,
    /// Processor counts, each at least 1.
    pub procs: Vec<u32>,
    pub assign: Assign,
    pub seed: u64,
    /// Direct send z-buffers locally first and ships only active pixels.
    pub local_zbuffer: bool,
}

/// Depth statistics of a trace, independent of n.
#[derive(Clone, Debug, PartialEq)]
pub struct DepthStats {
    /// Screen area A.
    pub area: u64,
    /// Fragments: d*A, the maximum traffic.
    pub fragments: u64,
    /// Pixel locations with at least one fragment: the minimum traffic.
    pub active: u64,
    /// `histogram[d]` = pixel locations of depth d (d = 0 included), so p_d = histogram[d] / A.
    pub histogram: Vec<u64>,
    /// A * sum_d p_d H_d (equation 3).
    pub expected: f64,
    /// A [(1-a) H_floor(d) + a H_ceil(d)], a = d - floor(d) (equation 4).
    pub even_bound: f64,
}

impl DepthStats {
    /// Depth complexity d.
    pub fn depth(&self) -> f64 {
        self.fragments as f64 / self.area as f64
    }
}

/// Traffic of one algorithm on n processors.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub algo: Algo,
    pub procs: u32,
    /// Pixels sent over the network in total.
    pub pixels: u64,
    /// Pixels on the busiest link (PixelFlow only: A on every link).
    pub per_link_pixels: Option<u64>,
    /// The expected traffic (snooping only).
    pub expected: Option<f64>,
    /// Active pixels summed over the n local frame buffers, when a pass counted them
    /// (paper 003 section 5: "on an 8-node machine only 10% of each local frame buffer
    /// comprises active pixels").
    pub local_active: Option<u64>,
}

impl Row {
    pub fn bytes(&self) -> u64 {
        self.pixels * ACTIVE_PIXEL_BYTES
    }

    /// The mean share of a local frame buffer (A pixels) that is active.
    pub fn local_fraction(&self, local_active: u64, area: u64) -> f64 {
        ratio(local_active, self.procs as u64 * area)
    }
}

/// Everything a replay measured.
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    pub stats: DepthStats,
    pub config: ReplayConfig,
    pub rows: Vec<Row>,
}

/// A trace prepared for replay: fragments regrouped by pixel once.
pub struct Replay<'a> {
    trace: &'a Trace,
    /// Fragments of pixel p are `order[offsets[p]..offsets[p + 1]]`, nearest first
    /// (`nearer`'s (depth, primitive id) order, then generation order): sorted once, so a
    /// pass for any assignment is one linear scan.
    offsets: Vec<u32>,
    order: Vec<u32>,
    /// Primitive of `order[i]`, stored in pixel order for a linear scan.
    prim: Vec<u32>,
    /// Primitive ids present in the trace, ascending, and their fragment counts.
    present: Vec<u32>,
    sizes: Vec<u64>,
    stats: DepthStats,
}

/// Counts of one pass over the pixels for one assignment.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PassCounts {
    /// Active pixels summed over the processors' local frame buffers.
    pub local_active: u64,
    /// Pixels broadcast by distributed snooping.
    pub broadcast: u64,
}

impl<'a> Replay<'a> {
    pub fn new(trace: &'a Trace) -> Replay<'a> {
        let area = trace.area();
        let mut offsets = vec![0u32; area + 1];
        for &p in trace.pixels() {
            offsets[p as usize + 1] += 1;
        }
        let mut histogram = Vec::new();
        for &count in &offsets[1..] {
            let d = count as usize;
            if histogram.len() <= d {
                histogram.resize(d + 1, 0);
            }
            histogram[d] += 1;
        }
        for p in 0..area {
            offsets[p + 1] += offsets[p];
        }
        let mut next = offsets.clone();
        let mut order = vec![0u32; trace.len()];
        for (i, &p) in trace.pixels().iter().enumerate() {
            order[next[p as usize] as usize] = i as u32;
            next[p as usize] += 1;
        }
        let (depths, prims) = (trace.depths(), trace.prims());
        for p in 0..area {
            let run = &mut order[offsets[p] as usize..offsets[p + 1] as usize];
            if run.len() > 1 {
                run.sort_unstable_by(|&i, &j| {
                    let (zi, pi) = (depths[i as usize], prims[i as usize]);
                    let (zj, pj) = (depths[j as usize], prims[j as usize]);
                    if nearer(zi, pi, zj, pj) {
                        std::cmp::Ordering::Less
                    } else if nearer(zj, pj, zi, pi) {
                        std::cmp::Ordering::Greater
                    } else {
                        i.cmp(&j)
                    }
                });
            }
        }
        let prim = order.iter().map(|&i| prims[i as usize]).collect();
        // Sized by the ids actually present, not the header's count: a damaged but
        // resealed header must not make replay allocate gigabytes.
        let ids = trace.prims().iter().max().map_or(0, |&m| m as usize + 1);
        let mut per_prim = vec![0u64; ids];
        for &p in trace.prims() {
            per_prim[p as usize] += 1;
        }
        let present: Vec<u32> = (0..per_prim.len() as u32)
            .filter(|&p| per_prim[p as usize] > 0)
            .collect();
        let sizes = present.iter().map(|&p| per_prim[p as usize]).collect();
        let stats = depth_stats(area as u64, trace.len() as u64, histogram);
        Replay {
            trace,
            offsets,
            order,
            prim,
            present,
            sizes,
            stats,
        }
    }

    pub fn stats(&self) -> &DepthStats {
        &self.stats
    }

    /// Primitive ids present in the trace, ascending (the database order of the assignment).
    pub fn present(&self) -> &[u32] {
        &self.present
    }

    /// The processor of every primitive id up to the largest present (`u32::MAX` for
    /// primitives without fragments).
    pub fn assignment(&self, rule: Assign, n: u32, seed: u64) -> Vec<u32> {
        let ids = self.present.last().map_or(0, |&m| m as usize + 1);
        let mut out = vec![u32::MAX; ids];
        let stream = format!("trace/assign/n={n}");
        let dealt = deal(
            rule,
            self.present.len(),
            |k| self.sizes[k],
            n,
            seed,
            &stream,
        );
        for (&p, proc) in self.present.iter().zip(dealt) {
            out[p as usize] = proc;
        }
        out
    }

    /// The primitive with the most fragments (lowest id on ties).
    pub fn largest(&self) -> Option<u32> {
        let mut best: Option<(u64, u32)> = None;
        for (&p, &s) in self.present.iter().zip(&self.sizes) {
            if best.is_none_or(|(bs, _)| s > bs) {
                best = Some((s, p));
            }
        }
        best.map(|(_, p)| p)
    }

    /// One pass over every pixel: local active pixels and snooping broadcasts.
    ///
    /// Walking a pixel's fragments nearest first, a fragment of processor p is broadcast
    /// exactly when p is below every processor seen before it: then it is p's local
    /// winner (p had no nearer fragment) and no earlier processor's winner is nearer, so no
    /// earlier broadcast deleted it; otherwise an earlier processor's nearer pixel deleted
    /// it, or it is not p's winner. A processor counts as active at the first fragment seen
    /// from it.
    pub fn pass(&self, assignment: &[u32]) -> PassCounts {
        let mut counts = PassCounts::default();
        let n = assignment
            .iter()
            .filter(|&&p| p != u32::MAX)
            .max()
            .map_or(0, |&m| m as usize + 1);
        // seen[proc] = 1 + the last pixel a fragment of proc was seen at.
        let mut seen = vec![0u32; n];
        for p in 0..self.trace.area() {
            let (a, b) = (self.offsets[p] as usize, self.offsets[p + 1] as usize);
            match b - a {
                0 => continue,
                1 => {
                    counts.local_active += 1;
                    counts.broadcast += 1;
                    continue;
                }
                _ => {}
            }
            let stamp = p as u32 + 1;
            let mut lowest = u32::MAX;
            for &prim in &self.prim[a..b] {
                let proc = assignment[prim as usize];
                if proc < lowest {
                    lowest = proc;
                    counts.broadcast += 1;
                }
                let s = &mut seen[proc as usize];
                if *s != stamp {
                    *s = stamp;
                    counts.local_active += 1;
                }
            }
        }
        counts
    }

    /// The merged image of distributed snooping: per pixel, the fragment index of the last
    /// pixel broadcast (what the global frame buffer holds), `None` where nothing was drawn.
    /// The last broadcast is the nearest of the local winners, the pixel's nearest fragment,
    /// whatever the assignment (the argument documents what is replayed).
    pub fn snoop_image(&self, _assignment: &[u32]) -> Vec<Option<u32>> {
        (0..self.trace.area())
            .map(|p| {
                let (a, b) = (self.offsets[p] as usize, self.offsets[p + 1] as usize);
                (b > a).then(|| self.order[a])
            })
            .collect()
    }

    /// Distributed snooping's traffic in pixels broadcast, for each n of `procs` (no local
    /// z-buffering): the quantity paper 003's Figures 5 and 6 plot.
    pub fn snooping_pixels(&self, assign: Assign, procs: &[u32], seed: u64) -> Vec<u64> {
        self.run(&ReplayConfig {
            algos: vec![Algo::Snooping],
            procs: procs.to_vec(),
            assign,
            seed,
            local_zbuffer: false,
        })
        .rows
        .iter()
        .map(|r| r.pixels)
        .collect()
    }

    /// Replays every algorithm for every n of `config`.
    pub fn run(&self, config: &ReplayConfig) -> Report {
        let mut rows = Vec::new();
        let area = self.stats.area;
        for &n in &config.procs {
            let needs_pass = config.algos.contains(&Algo::Snooping)
                || (config.local_zbuffer && config.algos.contains(&Algo::DirectSend));
            let counts = needs_pass.then(|| {
                let assignment = self.assignment(config.assign, n, config.seed);
                self.pass(&assignment)
            });
            for &algo in &config.algos {
                let row = match algo {
                    Algo::DirectSend => Row {
                        algo,
                        procs: n,
                        pixels: match counts {
                            Some(c) if config.local_zbuffer => c.local_active,
                            _ => self.stats.fragments,
                        },
                        per_link_pixels: None,
                        expected: None,
                        local_active: counts.map(|c| c.local_active),
                    },
                    Algo::PixelFlow => Row {
                        algo,
                        procs: n,
                        pixels: n as u64 * area,
                        per_link_pixels: Some(area),
                        expected: None,
                        local_active: counts.map(|c| c.local_active),
                    },
                    Algo::Snooping => Row {
                        algo,
                        procs: n,
                        pixels: counts.expect("snooping makes a pass").broadcast,
                        per_link_pixels: None,
                        expected: Some(self.stats.expected),
                        local_active: counts.map(|c| c.local_active),
                    },
                };
                rows.push(row);
            }
        }
        Report {
            stats: self.stats.clone(),
            config: config.clone(),
            rows,
        }
    }
}

/// H_d, the d-th harmonic number (H_0 = 0).
pub fn harmonic(d: u64) -> f64 {
    (1..=d).map(|k| 1.0 / k as f64).sum()
}

fn depth_stats(area: u64, fragments: u64, histogram: Vec<u64>) -> DepthStats {
    let mut expected = 0.0;
    let mut h = 0.0;
    for (d, &count) in histogram.iter().enumerate().skip(1) {
        h += 1.0 / d as f64;
        expected += count as f64 * h;
    }
    let d = fragments as f64 / area as f64;
    let lo = d.floor();
    let a = d - lo;
    let even_bound = area as f64 * ((1.0 - a) * harmonic(lo as u64) + a * harmonic(lo as u64 + 1));
    DepthStats {
        area,
        fragments,
        active: area - histogram.first().copied().unwrap_or(0),
        histogram,
        expected,
        even_bound,
    }
}

impl Report {
    /// The table a person reads: one line per algorithm and n.
    pub fn table(&self) -> String {
        let s = &self.stats;
        let mut out = format!(
            "A = {} pixels, {} fragments (d = {:.3}), {} active; snooping expected {:.0} (A sum p_d H_d), even-depth bound {:.0}\n",
            s.area,
            s.fragments,
            s.depth(),
            s.active,
            s.expected,
            s.even_bound
        );
        out.push_str(&format!(
            "assignment {}, seed {}{}\n\n",
            self.config.assign.name(),
            self.config.seed,
            if self.config.local_zbuffer {
                ", direct send z-buffers locally"
            } else {
                ""
            }
        ));
        out.push_str(&format!(
            "{:<12} {:>5} {:>12} {:>14} {:>12} {:>10} {:>12} {:>9} {:>9} {:>9}\n",
            "algorithm",
            "n",
            "observed px",
            "bytes",
            "expected px",
            "min px",
            "max px (dA)",
            "obs/dA",
            "dA/obs",
            "local %"
        ));
        for r in &self.rows {
            out.push_str(&format!(
                "{:<12} {:>5} {:>12} {:>14} {:>12} {:>10} {:>12} {:>9.4} {:>9.3} {:>9}\n",
                r.algo.name(),
                r.procs,
                r.pixels,
                r.bytes(),
                r.expected.map_or("-".into(), |e| format!("{e:.0}")),
                s.active,
                s.fragments,
                ratio(r.pixels, s.fragments),
                ratio(s.fragments, r.pixels),
                r.local_active.map_or("-".into(), |a| format!(
                    "{:.1}",
                    100.0 * r.local_fraction(a, s.area)
                )),
            ));
        }
        out
    }

    /// One CSV line per algorithm and n.
    pub fn csv(&self) -> String {
        let s = &self.stats;
        let mut out = String::from(
            "algo,assign,procs,local_zbuffer,traffic_pixels,traffic_bytes,per_link_pixels,expected_pixels,even_bound_pixels,min_pixels,max_pixels,ratio_to_max,reduction,local_active_pixels\n",
        );
        for r in &self.rows {
            out.push_str(&format!(
                "{},{},{},{},{},{},{},{},{:.1},{},{},{:.6},{:.6},{}\n",
                r.algo.name(),
                self.config.assign.name(),
                r.procs,
                self.config.local_zbuffer,
                r.pixels,
                r.bytes(),
                r.per_link_pixels.map_or(String::new(), |v| v.to_string()),
                r.expected.map_or(String::new(), |e| format!("{e:.1}")),
                s.even_bound,
                s.active,
                s.fragments,
                ratio(r.pixels, s.fragments),
                ratio(s.fragments, r.pixels),
                r.local_active.map_or(String::new(), |a| a.to_string()),
            ));
        }
        out
    }

    /// The whole report as JSON (units in the key names).
    pub fn json(&self, trace_file: &str) -> serde_json::Value {
        let s = &self.stats;
        let rows: Vec<serde_json::Value> = self
            .rows
            .iter()
            .map(|r| {
                serde_json::json!({
                    "algo": r.algo.name(),
                    "procs": r.procs,
                    "traffic_pixels": r.pixels,
                    "traffic_bytes": r.bytes(),
                    "per_link_pixels": r.per_link_pixels,
                    "local_active_pixels": r.local_active,
                    "local_active_fraction": r.local_active.map(|a| round6(r.local_fraction(a, s.area))),
                    "expected_pixels": r.expected.map(round1),
                    "ratio_to_max": round6(ratio(r.pixels, s.fragments)),
                    "reduction": round6(ratio(s.fragments, r.pixels)),
                })
            })
            .collect();
        serde_json::json!({
            "paper": "003 (Cox and Hanrahan, pixel merging and distributed snooping)",
            "trace": trace_file,
            "assign": self.config.assign.name(),
            "seed": self.config.seed,
            "local_zbuffer": self.config.local_zbuffer,
            "bytes_per_pixel": ACTIVE_PIXEL_BYTES,
            "screen_area_pixels": s.area,
            "fragments": s.fragments,
            "depth_complexity": round6(s.depth()),
            "active_pixels": s.active,
            "depth_histogram_pixels": s.histogram,
            "snooping_expected_pixels": round1(s.expected),
            "snooping_even_depth_bound_pixels": round1(s.even_bound),
            "rows": rows,
        })
    }
}

/// The denominator of a traffic chart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Baseline {
    /// d*A, the straightforward algorithm's traffic (the maximum).
    Maximum,
    /// Active pixels, the least any merge must write (paper 003 Figures 5 and 6's y axis).
    Minimum,
}

impl Report {
    /// Paper 003 Figures 5 and 6 as series over n: snooping observed, expected (equation 3),
    /// the even-depth bound (equation 4), maximum and minimum, and direct send when replayed,
    /// each divided by `baseline`. PixelFlow (n*A) is left out: it dwarfs the rest.
    pub fn figure_series(&self, baseline: Baseline) -> Vec<Series> {
        let s = &self.stats;
        let base = match baseline {
            Baseline::Maximum => s.fragments,
            Baseline::Minimum => s.active,
        }
        .max(1) as f64;
        let procs = &self.config.procs;
        let flat = |label: &str, v: f64| {
            Series::new(label, procs.iter().map(|&n| (n as f64, v / base)).collect())
        };
        let observed = |algo: Algo, label: &str| {
            let points: Vec<(f64, f64)> = self
                .rows
                .iter()
                .filter(|r| r.algo == algo)
                .map(|r| (r.procs as f64, r.pixels as f64 / base))
                .collect();
            (!points.is_empty()).then(|| Series::new(label, points))
        };
        let mut out = Vec::new();
        out.extend(observed(Algo::Snooping, "snooping observed"));
        out.push(flat("snooping expected (eq. 3)", s.expected));
        out.push(flat("even-depth bound (eq. 4)", s.even_bound));
        out.push(flat("maximum d*A", s.fragments as f64));
        out.push(flat("minimum (active pixels)", s.active as f64));
        if self.config.local_zbuffer {
            out.extend(observed(Algo::DirectSend, "direct send, local z-buffer"));
        }
        out
    }
}

fn ratio(a: u64, b: u64) -> f64 {
    if b == 0 {
        0.0
    } else {
        a as f64 / b as f64
    }
}

fn round1(v: f64) -> f64 {
    (v * 10.0).round() / 10.0
}

fn round6(v: f64) -> f64 {
    (v * 1e6).round() / 1e6
}
