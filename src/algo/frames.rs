//! What every algorithm family's processors share on the host during one run: the scene's
//! geometry per frame and its prepared vertices (computed once per frame, not once per
//! processor, in the memory of the frame dropped before it; a run's later frames made ahead on
//! a thread of their own, `ahead`) and the per-frame records being written (start, end,
//! traffic, rasterization finishing times).
//!
//! Must never hold simulated state: nothing here is charged to the machine, and nothing here
//! may change what a node program decides, only what the run reports.

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::ops::Range;
use std::rc::Rc;
use std::sync::Arc;

use super::ahead::{self, Ahead, Deal};
use super::image_space::dealing::Dealt;
use super::{FrameRecord, RunConfig};
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
    /// The thread making the later frames' front end, when the run has one.
    ahead: RefCell<Option<Ahead>>,
    records: RefCell<BTreeMap<u32, FrameRecord>>,
    /// The frames a recorded timeline covers (`None` when the run records none): each frame's
    /// beginning resumes or pauses it, and no cpu span runs across it.
    timeline_frames: Option<Range<u32>>,
}

/// One frame's geometry and the vertex preparation all processors share: preparing a vertex
/// is a pure function of it and the viewport, so sharing changes no image and no count
/// (the machine is charged per triangle, not per preparation), only the host's time.
#[derive(Clone)]
struct Shared {
    geometry: Rc<FrameGeometry>,
    vertices: Rc<RefCell<VertexCache>>,
    /// Every processor's dealt share, when it was made ahead and not yet taken.
    dealt: Rc<RefCell<Option<Vec<Dealt>>>>,
}

impl Shared {
    fn new(geometry: Rc<FrameGeometry>, viewport: Viewport, spare: Option<VertexCache>) -> Shared {
        let vertices = ahead::prepared(&geometry, viewport, spare);
        Shared::of(geometry, vertices, None)
    }

    fn of(geometry: Rc<FrameGeometry>, vertices: VertexCache, dealt: Option<Vec<Dealt>>) -> Shared {
        Shared {
            geometry,
            vertices: Rc::new(RefCell::new(vertices)),
            dealt: Rc::new(RefCell::new(dealt)),
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
    /// The book of `cfg`'s run, whose cache already holds `first`, the geometry of its first
    /// frame, drawn to `viewport`; the later frames are made ahead (when `cfg` says so), and
    /// dealt out as `deal` says when it is given.
    pub fn new(
        cfg: &RunConfig,
        viewport: Viewport,
        first: Rc<FrameGeometry>,
        deal: Option<Deal>,
    ) -> FrameBook {
        let later = cfg.frames.start + 1..cfg.frames.end;
        let ahead = cfg
            .front_end_ahead
            .then(|| Ahead::start(cfg.scene.clone(), later, viewport, deal))
            .flatten();
        FrameBook {
            scene: cfg.scene.clone(),
            n: cfg.machine.nodes,
            viewport,
            geometry: RefCell::new(BTreeMap::from([(
                cfg.frames.start,
                Shared::new(first, viewport, None),
            )])),
            ahead: RefCell::new(ahead),
            records: RefCell::default(),
            timeline_frames: cfg
                .timeline
                .then(|| cfg.timeline_frames.clone().unwrap_or(cfg.frames.clone())),
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
        let made = match self.ahead.borrow_mut().as_mut() {
            Some(ahead) => ahead.take(frame, spare),
            None => Err(spare),
        };
        let shared = match made {
            Ok(made) => Shared::of(Rc::new(made.geometry), made.vertices, made.dealt),
            Err(spare) => {
                let (old_geometry, old_vertices) = spare.unzip();
                let g = Rc::new(
                    self.scene
                        .frame_reusing(frame, old_geometry)
                        .map_err(|e| node.error(e.to_string()))?,
                );
                Shared::new(g, self.viewport, old_vertices)
            }
        };
        cache.insert(frame, shared.clone());
        Ok(shared)
    }

    /// Every processor's share of `frame`'s front end, when it was made ahead and not yet
    /// taken (the first processor to ask takes it for all, see `image_space::dealing`).
    pub fn take_dealt(&self, frame: u32) -> Option<Vec<Dealt>> {
        let cache = self.geometry.borrow();
        let dealt = cache.get(&frame)?.dealt.borrow_mut().take();
        dealt
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
