//! The host's front end of a run's later frames, on a thread of its own beside the simulation:
//! each frame's geometry, its vertices prepared for the run's viewport and, for sort-middle,
//! every processor's dealt share (`image_space::dealing`), made in frame order while the
//! simulation works on the frame before.
//!
//! Each of these is a pure function of the scene, the frame and the run's settings, and the
//! frame book takes them for the frames it would have made them for itself, so the thread moves
//! when the host does this work, never what a run simulates, draws or reports (a test compares
//! runs with and without it). A frame the thread has gone past, or one it could not make, the
//! book makes itself as before, and meets the same error there.
//!
//! Owns the thread and the hand-over. Must never see simulated state, and never hold more than
//! the frame it works on and one finished frame waiting to be taken.

use std::ops::Range;
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::Arc;
use std::thread::JoinHandle;

use super::image_space::dealing::{self, Dealt};
use crate::raster::{RasterOptions, VertexCache, Viewport};
use crate::scene::{FrameGeometry, Scene};

/// How sort-middle deals a frame's front end out: to `n` processors in batches of `batch`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Deal {
    pub n: u32,
    pub batch: usize,
    pub options: RasterOptions,
}

impl Deal {
    /// Every processor's share of `geometry`'s front end (`dealing::deal`), its vertices read
    /// through `vertices`: the one call the thread and the book both deal with.
    pub fn over(&self, geometry: &FrameGeometry, vertices: &mut VertexCache) -> Vec<Dealt> {
        dealing::deal(geometry, vertices, &self.options, self.n, self.batch)
    }
}

/// One frame's front end, made ahead.
pub(crate) struct Made {
    pub geometry: FrameGeometry,
    pub vertices: VertexCache,
    /// Every processor's share, when the run deals (sort-middle).
    pub dealt: Option<Vec<Dealt>>,
}

/// A frame's memory, handed back for a later frame to reuse.
pub(crate) type Spare = (FrameGeometry, VertexCache);

pub(crate) struct Ahead {
    made: Option<Receiver<(u32, Made)>>,
    spares: Sender<Spare>,
    /// The frame the thread hands over next.
    next: u32,
    worker: Option<JoinHandle<()>>,
}

impl Ahead {
    /// Starts making `frames` in order, drawn to `viewport`; `None` when there are none or no
    /// thread can be started (the book then makes every frame itself).
    pub fn start(
        scene: Arc<Scene>,
        frames: Range<u32>,
        viewport: Viewport,
        deal: Option<Deal>,
    ) -> Option<Ahead> {
        if frames.is_empty() {
            return None;
        }
        // A rendezvous: a finished frame waits in the thread until the book takes it.
        let (made_tx, made_rx) = mpsc::sync_channel(0);
        let (spares_tx, spares_rx) = mpsc::channel::<Spare>();
        let next = frames.start;
        let worker = std::thread::Builder::new()
            .name("front end".into())
            .spawn(move || {
                for frame in frames {
                    let spare = spares_rx.try_iter().last();
                    let Some(made) = make(&scene, frame, viewport, deal, spare) else {
                        return;
                    };
                    if made_tx.send((frame, made)).is_err() {
                        return;
                    }
                }
            })
            .ok()?;
        Some(Ahead {
            made: Some(made_rx),
            spares: spares_tx,
            next,
            worker: Some(worker),
        })
    }

    /// `frame`'s front end, when the thread has not gone past it (frames before it that were
    /// never asked for are dropped); otherwise `spare` back, for the book to make the frame in
    /// (nothing when the thread stopped after taking it). `spare` goes to the thread before the
    /// wait, so the frame it starts once this one is taken reuses that memory.
    pub fn take(&mut self, frame: u32, spare: Option<Spare>) -> Result<Made, Option<Spare>> {
        let made = match &self.made {
            Some(made) if frame >= self.next => made,
            _ => return Err(spare),
        };
        if let Some(spare) = spare {
            // A thread that has stopped needs no memory.
            let _ = self.spares.send(spare);
        }
        loop {
            let Ok((f, m)) = made.recv() else {
                return Err(None);
            };
            self.next = f + 1;
            if f == frame {
                return Ok(m);
            }
        }
    }
}

impl Drop for Ahead {
    fn drop(&mut self) {
        // Without a taker the thread's hand-over fails and it stops, after the frame in hand.
        self.made = None;
        if let Some(worker) = self.worker.take() {
            let _ = worker.join();
        }
    }
}

/// `frame`'s front end, as the book would make it; `None` when the scene cannot give the
/// frame (the book then meets the error itself, at the simulated moment it asks).
fn make(
    scene: &Scene,
    frame: u32,
    viewport: Viewport,
    deal: Option<Deal>,
    spare: Option<Spare>,
) -> Option<Made> {
    let (old_geometry, old_vertices) = spare.unzip();
    let geometry = scene.frame_reusing(frame, old_geometry).ok()?;
    let mut vertices = prepared(&geometry, viewport, old_vertices);
    let dealt = deal.map(|d| d.over(&geometry, &mut vertices));
    Some(Made {
        geometry,
        vertices,
        dealt,
    })
}

/// `geometry`'s vertices, every one prepared for `viewport` (in `spare`'s memory when given).
pub(crate) fn prepared(
    geometry: &FrameGeometry,
    viewport: Viewport,
    spare: Option<VertexCache>,
) -> VertexCache {
    let count = geometry.vertices.len();
    let mut vertices = match spare {
        Some(cache) => cache.emptied(count, viewport),
        None => VertexCache::new(count, viewport),
    };
    vertices.prepare_all(&geometry.vertices);
    vertices
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::algo::reference;

    /// What the frame book makes in place: the geometry, its prepared vertices, and the
    /// shares dealt over them (which read the vertices through the same cache).
    fn made_in_place(scene: &Scene, frame: u32, viewport: Viewport, deal: Deal) -> Made {
        let geometry = scene.frame(frame).unwrap();
        let mut vertices = prepared(&geometry, viewport, None);
        let dealt = dealing::deal(&geometry, &mut vertices, &deal.options, deal.n, deal.batch);
        Made {
            geometry,
            vertices,
            dealt: Some(dealt),
        }
    }

    #[test]
    fn frames_made_ahead_are_those_made_in_place_and_skipped_ones_are_left_to_the_book() {
        let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/p000-tetra-500.json");
        let scene = Arc::new(Scene::load(&file).unwrap());
        let first = scene.frame(0).unwrap();
        let viewport = reference::viewport(&first);
        let deal = Deal {
            n: 5,
            batch: 7,
            options: reference::raster_options(&first),
        };
        let mut ahead = Ahead::start(scene.clone(), 1..6, viewport, Some(deal)).unwrap();
        // Frame 2 is never asked for before 3, so the thread has gone past it; frame 9 is not
        // among those it makes.
        let mut spare = None;
        for (frame, made_ahead) in [
            (1, true),
            (3, true),
            (2, false),
            (4, true),
            (5, true),
            (9, false),
        ] {
            let made = match ahead.take(frame, spare.take()) {
                Ok(made) => made,
                Err(back) => {
                    assert!(!made_ahead, "frame {frame} is made ahead");
                    spare = back;
                    continue;
                }
            };
            assert!(made_ahead, "frame {frame} is left to the book");
            let expected = made_in_place(&scene, frame, viewport, deal);
            assert_eq!(made.geometry, expected.geometry, "frame {frame}");
            assert_eq!(
                format!("{:?}", made.vertices),
                format!("{:?}", expected.vertices),
                "frame {frame}"
            );
            assert_eq!(made.dealt, expected.dealt, "frame {frame}");
            // Its memory goes back for a later frame, which must come out the same in it.
            spare = Some((made.geometry, made.vertices));
        }
    }

    #[test]
    fn a_run_of_one_frame_has_no_thread() {
        let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/p000-tetra-500.json");
        let scene = Arc::new(Scene::load(&file).unwrap());
        let viewport = reference::viewport(&scene.frame(0).unwrap());
        assert!(Ahead::start(scene, 1..1, viewport, None).is_none());
    }
}
