//! The front end of one frame (clip, project, snap, cull), run once on the host in triangle
//! order for every processor and dealt out: processor `p` of `n` transforms triangles `p`,
//! `p + n`, `p + 2n`, ... in batches of one buffer's worth, and takes its batches from here
//! already set up.
//!
//! Each processor's own pass over its stride reached triangles and vertices thousands of bytes
//! apart, a cache miss at nearly every step; one pass in order streams them. Owns that host-side
//! order only: a batch holds exactly the screen triangles and counts `setup_subset` gives over
//! that batch (the same triangles, in the same order), so it must never change what a
//! processor is handed, charged or records.

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::ops::Range;

use crate::raster::{setup_subset_into, Counters, RasterOptions, ScreenTriangle, VertexCache};
use crate::scene::FrameGeometry;

/// One processor's share of a frame's front end.
#[derive(Debug, Default, PartialEq)]
pub(crate) struct Dealt {
    tris: Vec<ScreenTriangle>,
    /// Per batch: its screen triangles in `tris`, and what the front end counted for it.
    batches: Vec<(Range<usize>, Counters)>,
}

impl Dealt {
    /// The batches in order: screen triangles and counts, as `setup_subset` over each.
    pub fn batches(&self) -> impl Iterator<Item = (&[ScreenTriangle], Counters)> {
        self.batches
            .iter()
            .map(|(range, c)| (&self.tris[range.clone()], *c))
    }
}

/// The frames whose front end has run, each with the shares not yet taken.
#[derive(Default)]
pub(crate) struct Dealer {
    frames: RefCell<BTreeMap<u32, Vec<Option<Dealt>>>>,
}

impl Dealer {
    /// Processor `me`'s share of `frame`; the first call for the frame makes every
    /// processor's (`deal_all`: [`deal`], or the same made ahead). A frame's shares are dropped
    /// once all are taken, and with them the shares of earlier frames (a processor that never
    /// asked for its own).
    pub fn take(&self, frame: u32, me: u32, deal_all: impl FnOnce() -> Vec<Dealt>) -> Dealt {
        let mut frames = self.frames.borrow_mut();
        let shares = frames
            .entry(frame)
            .or_insert_with(|| deal_all().into_iter().map(Some).collect());
        let dealt = shares[me as usize]
            .take()
            .expect("each processor takes its share of a frame once");
        if shares.iter().all(Option::is_none) {
            let later = frames.split_off(&(frame + 1));
            *frames = later;
        }
        dealt
    }
}

/// Every processor's share of the front end over `geometry`, run in triangle order.
pub(crate) fn deal(
    geometry: &FrameGeometry,
    cache: &mut VertexCache,
    options: &RasterOptions,
    n: u32,
    batch: usize,
) -> Vec<Dealt> {
    let mut shares: Vec<Dealt> = (0..n).map(|_| Dealt::default()).collect();
    // Triangle `t` goes to processor `t % n` as the `t / n`-th of its stride, and that place
    // opens a batch when it is a multiple of `batch`: counted here rather than divided out for
    // each triangle.
    let (mut share_at, mut stride_at) = (0usize, 0usize);
    let mut opens_batch = true;
    for t in 0..geometry.triangles.len() as u32 {
        let share = &mut shares[share_at];
        if opens_batch {
            let at = share.tris.len();
            share.batches.push((at..at, Counters::default()));
        }
        let (range, counts) = share.batches.last_mut().expect("pushed above");
        setup_subset_into(
            &geometry.vertices,
            &geometry.triangles,
            &[t],
            cache,
            options,
            &mut share.tris,
            counts,
        );
        range.end = share.tris.len();
        share_at += 1;
        if share_at == shares.len() {
            share_at = 0;
            stride_at += 1;
            opens_batch = stride_at % batch == 0;
        }
    }
    shares
}

#[cfg(test)]
mod tests {
    use glam::{Vec3, Vec4};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::raster::{setup_subset, CullMode, Vertex, Viewport};

    /// Random triangles over a small viewport: some crossing the near plane or the guard band
    /// (clipped, several screen triangles each), some back-facing, some off screen, some with
    /// a NaN vertex or an index past the vertices.
    fn geometry(seed: u64, triangles: usize) -> FrameGeometry {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let coordinate = |rng: &mut ChaCha8Rng| rng.gen_range(-3.0f32..3.0);
        let mut vertices: Vec<Vertex> = (0..triangles)
            .map(|_| {
                let w = rng.gen_range(-0.2f32..2.0);
                Vertex {
                    clip: Vec4::new(
                        coordinate(&mut rng),
                        coordinate(&mut rng),
                        rng.gen_range(-1.5f32..1.5),
                        w,
                    ),
                    color: Vec3::new(rng.gen(), rng.gen(), rng.gen()),
                }
            })
            .collect();
        vertices[3].clip.x = f32::NAN;
        let count = vertices.len() as u32;
        FrameGeometry {
            width: 48,
            height: 32,
            vertices,
            triangles: (0..triangles)
                .map(|_| [0; 3].map(|_| rng.gen_range(0..count + 2)))
                .collect(),
            cull_backfaces: true,
            background: [0; 3],
        }
    }

    /// Every processor's batches hold exactly what its own `setup_subset` over each batch of
    /// its stride gives, screen triangles in order and counts, for shares that do and do not
    /// divide the triangles, batches of one, and more processors than triangles.
    #[test]
    fn each_share_is_what_the_processor_would_have_set_up_itself() {
        let viewport = Viewport::new(48, 32).unwrap();
        for (cull, seed) in [(CullMode::None, 1), (CullMode::Back, 2)] {
            let options = RasterOptions { cull };
            let g = geometry(seed, 300);
            for (n, batch) in [(1, 7), (5, 1), (8, 13), (7, 64), (512, 3)] {
                let dealer = Dealer::default();
                let mut shared = VertexCache::new(g.vertices.len(), viewport);
                let mut clipped_or_culled = 0;
                for me in 0..n {
                    let dealt = dealer.take(0, me, || deal(&g, &mut shared, &options, n, batch));
                    let stride: Vec<u32> =
                        (me..g.triangles.len() as u32).step_by(n as usize).collect();
                    let mut own = VertexCache::new(g.vertices.len(), viewport);
                    let expected: Vec<(Vec<ScreenTriangle>, Counters)> = stride
                        .chunks(batch)
                        .map(|b| {
                            let mut tris = Vec::new();
                            let c = setup_subset(
                                &g.vertices,
                                &g.triangles,
                                b,
                                &mut own,
                                &options,
                                &mut tris,
                            );
                            (tris, c)
                        })
                        .collect();
                    let got: Vec<(Vec<ScreenTriangle>, Counters)> = dealt
                        .batches()
                        .map(|(tris, c)| (tris.to_vec(), c))
                        .collect();
                    assert_eq!(got, expected, "n {n}, batch {batch}, processor {me}");
                    clipped_or_culled += expected
                        .iter()
                        .map(|(_, c)| c.clipped + c.culled_backface + c.culled_invalid)
                        .sum::<u64>();
                }
                assert!(
                    clipped_or_culled > 0,
                    "the geometry exercises the hard cases"
                );
                assert!(dealer.frames.borrow().is_empty(), "every share was taken");
            }
        }
    }
}
