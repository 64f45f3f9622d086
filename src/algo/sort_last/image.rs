//! How the compositing variants (tree, binary swap, radix-k, 2-3 swap) ship a piece of the
//! image, the range of screen positions `lo..hi` in raster order: `dense`, every position as a full-frame
//! record (rgb and z); or `rle`, IceT's sparse image, alternating runs of inactive and active
//! positions, one `RUN_BYTES` header per pair and a record per active position only.
//!
//! Owns the bytes and the work each encoding costs: encoding scans every position of the
//! range (`rle_pixel`) and writes every run (`rle_run`); a compressed composite walks both
//! run lists (`rle_run` per run) and compares only the incoming active pixels
//! (`composite_pixel`), where a dense composite compares every position. Must never decide
//! which pixels survive: merging is `Ctx::merge_rows`, the same for both encodings.

use super::options::ImageEncoding;
use super::pixel::ShippedPixel;
use super::Ctx;
use crate::machine::{Counts, Op};
use crate::units::Bytes;

/// Bytes of one run pair's header: the inactive and the active count, 32 bits each.
pub const RUN_BYTES: u64 = 8;

/// Run pairs (inactive run, active run) describing `pixels`, the active positions of
/// `lo..hi` in raster order: one per active run, plus one for inactive positions after the
/// last active one (or for a range with none active).
pub fn runs<P: ShippedPixel>(pixels: &[P], (_, hi): (u32, u32)) -> u64 {
    run_pairs(pixels.iter().map(|p| p.loc()), hi)
}

/// [`runs`] of increasing active positions `locs` in a range ending at `hi`.
fn run_pairs(locs: impl Iterator<Item = u32>, hi: u32) -> u64 {
    let mut pairs = 0;
    let mut next = None;
    for loc in locs {
        if next != Some(loc) {
            pairs += 1;
        }
        next = Some(loc + 1);
    }
    match next {
        Some(end) if end >= hi => pairs,
        _ => pairs + 1,
    }
}

/// Maximal runs of consecutive positions among increasing `locs`: the run headers of an rle
/// message that carries those pixels and nothing before or after them (direct send's).
pub fn active_runs(locs: impl Iterator<Item = u32>) -> u64 {
    let mut runs = 0;
    let mut next = None;
    for loc in locs {
        if next != Some(loc) {
            runs += 1;
        }
        next = Some(loc + 1);
    }
    runs
}

/// The bytes of the piece `range` with `pixels` active in it.
pub fn bytes<P: ShippedPixel>(ctx: &Ctx, range: (u32, u32), pixels: &[P]) -> Bytes {
    let extra: u64 = pixels.iter().map(P::extra_bytes).sum();
    let records = match ctx.settings.image {
        ImageEncoding::Dense => u64::from(range.1 - range.0),
        ImageEncoding::Rle => pixels.len() as u64,
    };
    let headers = match ctx.settings.image {
        ImageEncoding::Dense => 0,
        ImageEncoding::Rle => runs(pixels, range) * RUN_BYTES,
    };
    Bytes::new(records * ctx.record_bytes() + headers + extra)
}

/// The work of encoding a piece before it is sent (none for dense), looking at `scanned` of
/// its positions (`Ctx::scanned`: all of them, unless bounds rule some out).
pub fn encode_work<P: ShippedPixel>(
    ctx: &Ctx,
    range: (u32, u32),
    scanned: u64,
    pixels: &[P],
) -> Counts {
    match ctx.settings.image {
        ImageEncoding::Dense => Counts::new(),
        ImageEncoding::Rle => {
            let mut work = Counts::of(Op::RlePixel, scanned);
            work += &Counts::of(Op::RleRun, runs(pixels, range));
            work
        }
    }
}

/// What composing `incoming` into `own` over `range` compares (`composite_pixel`), and the
/// run walking a compressed composite adds.
pub fn merge_work<P: ShippedPixel>(
    ctx: &Ctx,
    range: (u32, u32),
    incoming: &[P],
    own: &[P],
) -> (u64, Counts) {
    match ctx.settings.image {
        ImageEncoding::Dense => (u64::from(range.1 - range.0), Counts::new()),
        ImageEncoding::Rle => {
            let walked = runs(incoming, range) + runs(own, range);
            (incoming.len() as u64, Counts::of(Op::RleRun, walked))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Run pairs counted from the active positions equal a walk over every position of
        /// the range; an rle piece never outgrows a dense one by more than its headers.
        #[test]
        fn runs_match_a_walk_and_rle_stays_within_dense_plus_headers(
            active in proptest::collection::vec(any::<bool>(), 1..200)
        ) {
            let hi = active.len() as u32;
            let locs: Vec<u32> = (0..hi).filter(|&i| active[i as usize]).collect();
            let pairs = run_pairs(locs.iter().copied(), hi);
            // A walk: a pair ends where an active run is followed by an inactive position or
            // the range ends; a range ending inactive closes one more (inactive-only) pair.
            let mut walked = 0;
            for i in 0..active.len() {
                let ends_run = active[i] && (i + 1 == active.len() || !active[i + 1]);
                walked += u64::from(ends_run);
            }
            if !active[active.len() - 1] {
                walked += 1;
            }
            prop_assert_eq!(pairs, walked);
            let record = 7;
            let rle = locs.len() as u64 * record + pairs * RUN_BYTES;
            prop_assert!(rle <= u64::from(hi) * record + pairs * RUN_BYTES);
        }
    }
}
