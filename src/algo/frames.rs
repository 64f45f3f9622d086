//! What every algorithm family's processors share on the host during one run: the scene's
//! geometry per frame and its prepared vertices (computed once per frame, not once per
//! processor, in the memory of the frame dropped before it) and the per-frame records being
//! written (start, end, traffic, rasterization finishing times).
//!
//! Must never hold simulated state: nothing here is charged to the machine, and nothing here
//! may change what a node program decides, only what the run reports.

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::ops::Range;
use std::rc::Rc;
use std::sync::Arc;

use super::FrameRecord;
use crate::engine::{Node, Payload, SimError};
use crate::raster::{VertexCache, Viewport};
use crate::scene::{FrameGeometry, Scene};
use crate::units::{Bytes, SimTime};

/// The host-side book of one run.
pub(crate) struct FrameBook {
    scene: Arc<Scene>,
    n: u32,
    /// Where the run draws: every processor's vertices are prepared for it.
    viewport: Viewport,
    geometry: RefCell<BTreeMap<u32, Shared>>,
    records: RefCell<BTreeMap<u32, FrameRecord>>,
    /// The frames a recorded timeline covers (all when `None`).
    timeline_frames: Option<Range<u32>>,
}

/// One frame's geometry and the vertex preparation all processors share: preparing a vertex
/// is a pure function of it and the viewport, so sharing changes no image and no count
/// (the machine is charged per triangle, not per preparation), only the host's time.
#[derive(Clone)]
struct Shared {
    geometry: Rc<FrameGeometry>,
    vertices: Rc<RefCell<VertexCache>>,
}

impl Shared {
    fn new(geometry: Rc<FrameGeometry>, viewport: Viewport, spare: Option<VertexCache>) -> Shared {
        let count = geometry.vertices.len();
        let mut vertices = match spare {
            Some(cache) => cache.emptied(count, viewport),
            None => VertexCache::new(count, viewport),
        };
        vertices.prepare_all(&geometry.vertices);
        Shared {
            geometry,
            vertices: Rc::new(RefCell::new(vertices)),
        }
    }

    /// Its memory back, unless a processor still holds it.
    fn into_spare(self) -> Option<(FrameGeometry, VertexCache)> {
        let geometry = Rc::try_unwrap(self.geometry).ok()?;
        let vertices = Rc::try_unwrap(self.vertices).ok()?.into_inner();
        Some((geometry, vertices))
    }
}

impl FrameBook {
    /// A book whose cache already holds `first`, the geometry of frame `frame`, drawn to
    /// `viewport`.
    pub fn new(
        scene: Arc<Scene>,
        n: u32,
        viewport: Viewport,
        frame: u32,
        first: Rc<FrameGeometry>,
        timeline_frames: Option<Range<u32>>,
    ) -> FrameBook {
        FrameBook {
            scene,
            n,
            viewport,
            geometry: RefCell::new(BTreeMap::from([(
                frame,
                Shared::new(first, viewport, None),
            )])),
            records: RefCell::default(),
            timeline_frames,
        }
    }

    /// `frame` begins now at `node` (the node that times frames), unless it has begun
    /// already; a timeline limited to some frames is resumed or paused here.
    pub fn begin<M: Payload>(&self, node: &Node<M>, frame: u32) {
        let now = node.now();
        let first = self.record(frame, |r| {
            let first = !r.begun;
            if first {
                (r.start, r.begun) = (now, true);
            }
            first
        });
        if let (true, Some(covered)) = (first, &self.timeline_frames) {
            node.record_timeline(covered.contains(&frame));
        }
    }

    /// The scene's geometry for `frame`, computed on first use and dropped two frames later.
    pub fn geometry<M: Payload>(
        &self,
        node: &Node<M>,
        frame: u32,
    ) -> Result<Rc<FrameGeometry>, SimError> {
        Ok(self.shared(node, frame)?.geometry)
    }

    /// `frame`'s vertices prepared for the run's viewport, shared by every processor (pass
    /// it to `raster::setup_subset` or `raster::draw_subset`; never hold the borrow across
    /// an await).
    pub fn vertices<M: Payload>(
        &self,
        node: &Node<M>,
        frame: u32,
    ) -> Result<Rc<RefCell<VertexCache>>, SimError> {
        Ok(self.shared(node, frame)?.vertices)
    }

    fn shared<M: Payload>(&self, node: &Node<M>, frame: u32) -> Result<Shared, SimError> {
        let mut cache = self.geometry.borrow_mut();
        if let Some(g) = cache.get(&frame) {
            return Ok(g.clone());
        }
        // Frames before the one before are done with; the new frame takes their memory.
        let kept = cache.split_off(&frame.saturating_sub(1));
        let dropped = std::mem::replace(&mut *cache, kept);
        let spare = dropped
            .into_values()
            .filter_map(Shared::into_spare)
            .next_back();
        let (old_geometry, old_vertices) = spare.unzip();
        let g = Rc::new(
            self.scene
                .frame_reusing(frame, old_geometry)
                .map_err(|e| node.error(e.to_string()))?,
        );
        let shared = Shared::new(g, self.viewport, old_vertices);
        cache.insert(frame, shared.clone());
        Ok(shared)
    }

    /// Edits `frame`'s record, creating it on first use.
    pub fn record<R>(&self, frame: u32, f: impl FnOnce(&mut FrameRecord) -> R) -> R {
        let mut records = self.records.borrow_mut();
        let n = self.n as usize;
        let r = records.entry(frame).or_insert_with(|| FrameRecord {
            frame,
            raster_finish: vec![SimTime::ZERO; n],
            polygon_wait: vec![SimTime::ZERO; n],
            ..FrameRecord::default()
        });
        f(r)
    }

    /// Counts one message of `bytes` against `frame`.
    pub fn count_message(&self, frame: u32, bytes: Bytes) {
        self.record(frame, |r| {
            r.bytes += bytes;
            r.messages += 1;
        });
    }

    /// The records, in frame order.
    pub fn records(&self) -> Vec<FrameRecord> {
        self.records.borrow().values().cloned().collect()
    }
}
