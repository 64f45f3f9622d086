//! Adaptive anti-aliasing across a sort-last machine: every node's fixed Subpixel pool (its
//! rendering and the merges into its buffers draw blocks from it), the frame's subpixel
//! resolution, and the per-node statistics a frame records.
//!
//! One resolution per frame for the whole machine: merges combine samples position by
//! position, so every node must render a frame at the same n x n. Memory adaptation (paper
//! 000, section 4.1) still runs per node: after a frame each node picks the finest grid its
//! own demand (rendering plus merging) fits, and the next frame takes the coarsest of those,
//! fixed when its first node starts it. Where a variant has no frame barrier, a node still
//! busy with the previous frame then has not reported yet, and its older pick counts.
//!
//! Must never render or merge: it only hands out pools, grids and records.

use std::cell::RefCell;
use std::collections::BTreeMap;

use super::super::aa::AaSettings;
use crate::algo::frames::FrameBook;
use crate::engine::{Node, Payload, SimError};
use crate::raster::aa::{adapt, AaMethod, AaStats, AdaptiveConfig, Blocks, Grid, RECLAIM_SPREAD};
use crate::units::Bytes;

/// One node's anti-aliasing state in the frame it is working on.
struct NodeAa {
    render: AaStats,
    blocks: Blocks,
}

/// Adaptive anti-aliasing state of a run (inert without `aa=adaptive`).
pub(crate) struct AaState {
    pub adaptive: bool,
    /// Each node's Subpixel pool.
    pub pool: Bytes,
    reclaim: bool,
    clear: [u8; 3],
    pixels: u64,
    /// Each frame's grid, fixed when its first node asks.
    grids: RefCell<BTreeMap<u32, Grid>>,
    /// Each node's pick for its next frame.
    picks: RefCell<Vec<Grid>>,
    nodes: RefCell<Vec<NodeAa>>,
}

impl AaState {
    /// The state for `n` nodes rendering `pixels` each, cleared to `clear`.
    pub fn new(settings: &AaSettings, n: u32, pixels: u64, clear: [u8; 3]) -> AaState {
        let pool = settings
            .pool
            .unwrap_or(AdaptiveConfig::default_pool(pixels));
        let idle = || NodeAa {
            render: AaStats::default(),
            blocks: Blocks::new(settings.start, Bytes::new(0), clear),
        };
        AaState {
            adaptive: settings.method == AaMethod::Adaptive,
            pool,
            reclaim: settings.reclaim,
            clear,
            pixels,
            grids: RefCell::default(),
            picks: RefCell::new(vec![settings.start; n as usize]),
            nodes: RefCell::new((0..n).map(|_| idle()).collect()),
        }
    }

    /// The subpixel resolution of `frame` (the coarsest of the nodes' picks so far).
    pub fn grid(&self, frame: u32) -> Grid {
        *self.grids.borrow_mut().entry(frame).or_insert_with(|| {
            let picks = self.picks.borrow();
            picks.iter().copied().min().unwrap_or(Grid::X4)
        })
    }

    pub fn reclaim_spread(&self) -> Option<u32> {
        self.reclaim.then_some(RECLAIM_SPREAD)
    }

    /// Starts `frame` on `node`: allocates its pool and empties it.
    pub fn begin<M: Payload>(&self, node: &Node<M>, frame: u32) -> Result<(), SimError> {
        if !self.adaptive {
            return Ok(());
        }
        node.alloc("subpixel pool", self.pool)?;
        let grid = self.grid(frame);
        let blocks = Blocks::new(grid, self.pool, self.clear);
        let render = AaStats {
            grid_side: grid.side(),
            pixels: self.pixels,
            ..AaStats::default()
        };
        self.nodes.borrow_mut()[node.id() as usize] = NodeAa { render, blocks };
        Ok(())
    }

    /// Notes what rendering into the node's pool did (its blocks stay in use).
    pub fn rendered(&self, node: u32, stats: AaStats) {
        let mut nodes = self.nodes.borrow_mut();
        let state = &mut nodes[node as usize];
        state.blocks.absorb(&stats);
        state.render = stats;
    }

    /// Sets the Pixels `node` holds at the end of the frame (when not a full frame).
    pub fn hold_pixels(&self, node: u32, pixels: u64) {
        self.nodes.borrow_mut()[node as usize].render.pixels = pixels;
    }

    /// Returns the rendered frame's blocks to the pool (its pixels were shipped away and
    /// the buffer freed).
    pub fn release_render(&self, node: u32) {
        let mut nodes = self.nodes.borrow_mut();
        let state = &mut nodes[node as usize];
        let cells = state.render.live_cells;
        state.blocks.release(cells);
    }

    /// Runs `f` on the pool merges into `node`'s buffers draw from.
    pub fn with_blocks<R>(&self, node: u32, f: impl FnOnce(&mut Blocks) -> R) -> R {
        f(&mut self.nodes.borrow_mut()[node as usize].blocks)
    }

    /// Ends `frame` on `node`: records its statistics, picks its next grid, frees the pool.
    pub fn end<M: Payload>(
        &self,
        node: &Node<M>,
        frame: u32,
        book: &FrameBook,
        n: u32,
    ) -> Result<(), SimError> {
        if !self.adaptive {
            return Ok(());
        }
        let me = node.id() as usize;
        let stats = {
            let nodes = self.nodes.borrow();
            nodes[me].blocks.stats(nodes[me].render)
        };
        self.picks.borrow_mut()[me] = adapt(&stats);
        book.record(frame, |r| {
            r.aa.resize(n as usize, AaStats::default());
            r.aa[me] = stats;
        });
        node.free("subpixel pool", self.pool)
    }
}
