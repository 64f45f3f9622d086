//! What `sortsim scene-stats` prints: one frame's geometric and rasterized statistics next
//! to the paper's numbers for the scene it stands in for (from `paper::REFERENCES`).
//!
//! Owns assembling and formatting that summary, as text and as JSON. Must never compute statistics itself (that
//! is `stats`) nor hold paper numbers (that is `paper`).

use std::fmt;

use super::paper::{reference, PaperReference, EDGE_REFERENCES};
use super::stats::{
    edge_pixel_fraction, geometric, raster_overlap_factor, rasterized, GeometricStats, RasterStats,
};
use super::{Scene, SceneError};

/// One frame of one scene, measured, with its paper reference if it is a stand-in.
#[derive(Clone, Debug)]
pub struct Summary {
    /// Scene file stem, e.g. `polio-standin`.
    pub scene: String,
    pub frame: u32,
    pub width: u32,
    pub height: u32,
    pub geometric: GeometricStats,
    pub raster: RasterStats,
    /// Overlap factor for a 16 x 16 grid of regions (256 regions, as in paper 002).
    pub overlap_256: f64,
    /// Share of pixels a visible polygon edge passes through (paper 000's supersampled pixels).
    pub edge_pixels: f64,
    pub reference: Option<&'static PaperReference>,
}

/// Measures frame `frame` of `scene`.
pub fn summary(scene: &Scene, frame: u32) -> Result<Summary, SceneError> {
    let geometry = scene.frame(frame)?;
    let name = scene
        .file()
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let (w, h) = (geometry.width, geometry.height);
    Ok(Summary {
        reference: reference(&name),
        scene: name,
        frame,
        width: w,
        height: h,
        geometric: geometric(&geometry),
        raster: rasterized(&geometry),
        overlap_256: raster_overlap_factor(&geometry, w.div_ceil(16), h.div_ceil(16)),
        edge_pixels: edge_pixel_fraction(&geometry),
    })
}

impl fmt::Display for Summary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (g, r) = (&self.geometric, &self.raster);
        let paper = self.reference;
        let cell = |v: Option<String>| v.unwrap_or_else(|| "-".into());
        writeln!(
            f,
            "{} frame {} ({}x{})",
            self.scene, self.frame, self.width, self.height
        )?;
        if let Some(p) = paper {
            writeln!(f, "stands in for paper {}: {}", p.paper, p.source)?;
        }
        writeln!(f, "{:<44} {:>14} {:>12}", "metric", "achieved", "paper")?;
        let mut row = |name: &str, achieved: String, published: Option<String>| {
            writeln!(f, "{name:<44} {achieved:>14} {:>12}", cell(published))
        };
        row(
            "triangles in",
            g.triangles_in.to_string(),
            paper.map(|p| p.triangles.to_string()),
        )?;
        row("front-facing (geometric)", g.front_facing.to_string(), None)?;
        row(
            "drawn, on screen (geometric)",
            g.on_screen.to_string(),
            None,
        )?;
        row(
            "set up by the rasterizer (after cull, clip)",
            r.counters.triangles_set_up.to_string(),
            None,
        )?;
        let mean = paper.and_then(|p| p.mean_area_px).map(|m| format!("{m}"));
        row(
            "mean area px (geometric)",
            format!("{:.3}", g.mean_area_px),
            mean.clone(),
        )?;
        row(
            "mean area px (pixels per set-up triangle)",
            format!("{:.3}", r.mean_area_px),
            mean,
        )?;
        row(
            "median bounding-box side px (geometric)",
            format!("{:.1}", g.median_bbox_side_px),
            None,
        )?;
        let d = paper
            .and_then(|p| p.depth_complexity)
            .map(|d| format!("{d}"));
        row(
            "depth complexity d (geometric)",
            format!("{:.3}", g.depth_complexity),
            d.clone(),
        )?;
        row(
            "depth complexity d (rasterized)",
            format!("{:.3}", r.depth_complexity),
            d,
        )?;
        row("pixels rendered", r.pixels_rendered.to_string(), None)?;
        row("active pixels", r.active_pixels.to_string(), None)?;
        let overlap = paper
            .filter(|p| p.paper == "002")
            .map(|_| "1.09-1.4".to_string());
        row(
            "overlap factor, 256 regions",
            format!("{:.3}", self.overlap_256),
            overlap,
        )?;
        let edge = EDGE_REFERENCES
            .iter()
            .find(|e| e.scene == self.scene)
            .map(|e| format!("{}{}", if e.upper_bound { "< " } else { "~" }, e.fraction));
        row(
            "share of edge pixels (supersampled)",
            format!("{:.3}", self.edge_pixels),
            edge,
        )?;
        let p_d = r.p_d(self.width, self.height);
        let shown: Vec<String> = p_d
            .iter()
            .take(9)
            .enumerate()
            .map(|(d, p)| format!("p{d}={p:.3}"))
            .collect();
        writeln!(
            f,
            "depth histogram: {}{}",
            shown.join(" "),
            if p_d.len() > 9 { " ..." } else { "" }
        )
    }
}

impl Summary {
    /// The summary as `scene-stats --json` prints it: `overlap` is the overlap factor for
    /// regions of `region` pixels.
    pub fn to_json(&self, overlap: f64, region: (u32, u32)) -> serde_json::Value {
        let r = &self.raster;
        let paper = self.reference.map(|p| {
            serde_json::json!({"paper": p.paper, "source": p.source, "triangles": p.triangles,
                "mean_area_px": p.mean_area_px, "depth_complexity": p.depth_complexity, "tolerance": p.tolerance})
        });
        serde_json::json!({
            "scene": self.scene,
            "frame": self.frame,
            "width": self.width,
            "height": self.height,
            "triangles_in": r.counters.triangles_in,
            "triangles_after_culling_and_clipping": r.counters.triangles_set_up,
            "mean_area_px": r.mean_area_px,
            "geometric_mean_area_px": self.geometric.mean_area_px,
            "median_bbox_side_px": self.geometric.median_bbox_side_px,
            "depth_complexity": r.depth_complexity,
            "p_d": r.p_d(self.width, self.height),
            "active_pixels": r.active_pixels,
            "overlap_factor": overlap,
            "overlap_region_px": [region.0, region.1],
            "raster": counters_json(&r.counters),
            "paper": paper,
        })
    }
}

/// A frame's raster counters as `render` and `scene-stats --json` print them.
pub fn counters_json(c: &crate::raster::Counters) -> serde_json::Value {
    serde_json::json!({
        "triangles_in": c.triangles_in,
        "culled_invalid": c.culled_invalid,
        "culled_outside": c.culled_outside,
        "culled_backface": c.culled_backface,
        "culled_zero_area": c.culled_zero_area,
        "clipped": c.clipped,
        "triangles_set_up": c.triangles_set_up,
        "spans": c.spans,
        "pixels_tested": c.pixels_tested,
        "pixels_written": c.pixels_written,
        "bytes_touched": c.bytes_touched,
    })
}
