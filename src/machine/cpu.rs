//! A node's processor as a cost model: a table of per-operation times and per-message
//! overheads, turning operation counts into simulated time.
//!
//! Must never decide *when* work runs (the engine's cpu queue does that) and never invent a
//! time: every duration is a count times a cost from the machine spec.

use crate::units::{Bytes, SimTime};

/// The operations a machine can charge for. A spec's `cpu.costs` names them in snake case;
/// unnamed operations cost nothing. Adding an operation is adding a variant here.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Op {
    TransformVertex,
    ClipTriangle,
    SetupTriangle,
    Span,
    PixelTest,
    PixelWrite,
    Sample,
    CompositePixel,
    ByteCopy,
    BucketInsert,
    ActiveListOp,
    /// Classifying one triangle into one region it touches (and counting it there).
    RegionCount,
    /// Summing one region's count received from a child of the load-balancing tree: taking
    /// the count out of the message and adding it (paper 002's collection of per-region
    /// counts, whose messages grow with processors x granularity).
    CountSum,
    AssignRegion,
    ClearPixel,
    /// Scanning one position of an image piece while run-length encoding it (IceT's sparse
    /// images, `image=rle`).
    RlePixel,
    /// Writing or walking one run pair of a run-length encoded piece.
    RleRun,
    CoverageMask,
    SubpixelTest,
    SubpixelWrite,
    ReclaimCheck,
    ResolvePixel,
}

impl Op {
    pub const ALL: [Op; 22] = [
        Op::TransformVertex,
        Op::ClipTriangle,
        Op::SetupTriangle,
        Op::Span,
        Op::PixelTest,
        Op::PixelWrite,
        Op::Sample,
        Op::CompositePixel,
        Op::ByteCopy,
        Op::BucketInsert,
        Op::ActiveListOp,
        Op::RegionCount,
        Op::CountSum,
        Op::AssignRegion,
        Op::ClearPixel,
        Op::RlePixel,
        Op::RleRun,
        Op::CoverageMask,
        Op::SubpixelTest,
        Op::SubpixelWrite,
        Op::ReclaimCheck,
        Op::ResolvePixel,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Op::TransformVertex => "transform_vertex",
            Op::ClipTriangle => "clip_triangle",
            Op::SetupTriangle => "setup_triangle",
            Op::Span => "span",
            Op::PixelTest => "pixel_test",
            Op::PixelWrite => "pixel_write",
            Op::Sample => "sample",
            Op::CompositePixel => "composite_pixel",
            Op::ByteCopy => "byte_copy",
            Op::BucketInsert => "bucket_insert",
            Op::ActiveListOp => "active_list_op",
            Op::RegionCount => "region_count",
            Op::CountSum => "count_sum",
            Op::AssignRegion => "assign_region",
            Op::ClearPixel => "clear_pixel",
            Op::RlePixel => "rle_pixel",
            Op::RleRun => "rle_run",
            Op::CoverageMask => "coverage_mask",
            Op::SubpixelTest => "subpixel_test",
            Op::SubpixelWrite => "subpixel_write",
            Op::ReclaimCheck => "reclaim_check",
            Op::ResolvePixel => "resolve_pixel",
        }
    }

    pub fn from_name(name: &str) -> Option<Op> {
        Op::ALL.into_iter().find(|op| op.name() == name)
    }

    /// The operations whose bits are set in `bits` (as [`CostTable::unpriced_in`] gives
    /// them), in `Op::ALL` order.
    pub fn from_bits(bits: u32) -> Vec<Op> {
        Op::ALL
            .iter()
            .copied()
            .filter(|&op| bits & (1 << op as usize) != 0)
            .collect()
    }

    /// The valid names, for error messages.
    pub fn valid_names() -> String {
        Op::ALL
            .iter()
            .map(|op| op.name())
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Time per operation, indexed by `Op`, and which operations the machine prices at all (an
/// operation its file leaves out costs nothing, which a run reports rather than hides).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CostTable {
    per_op: [SimTime; Op::ALL.len()],
    /// Bit `op` set when the machine gives the operation a cost (zero included).
    priced: u32,
}

impl CostTable {
    pub fn set(&mut self, op: Op, cost: SimTime) {
        self.per_op[op as usize] = cost;
        self.priced |= 1 << op as usize;
    }
    pub fn get(&self, op: Op) -> SimTime {
        self.per_op[op as usize]
    }
    /// True when the machine gives `op` a cost (possibly zero, on purpose).
    pub fn is_priced(&self, op: Op) -> bool {
        self.priced & (1 << op as usize) != 0
    }
    /// The operations `counts` performs that the machine leaves unpriced, as a bit set over
    /// `Op` (see [`Op::from_bits`]).
    #[inline]
    pub fn unpriced_in(&self, counts: &Counts) -> u32 {
        counts.used & !self.priced
    }
    /// The time to perform `counts`; `SimTime::MAX` when that passes the largest simulated
    /// time (the engine refuses such a charge). Sums over the operations performed only (a
    /// charge names a few of the table's), in the table's order.
    pub fn time(&self, counts: &Counts) -> SimTime {
        let mut ps: u128 = 0;
        let mut used = counts.used;
        while used != 0 {
            let op = used.trailing_zeros() as usize;
            ps += self.per_op[op].ps() as u128 * counts.n[op] as u128;
            used &= used - 1;
        }
        SimTime::from_ps(u64::try_from(ps).unwrap_or(u64::MAX))
    }
}

impl CostTable {
    /// The operation that contributes most to `counts`' time, as "N x op at COST each" (what
    /// an over-long charge names).
    pub fn largest_term(&self, counts: &Counts) -> String {
        let (op, n, cost) = Op::ALL
            .iter()
            .map(|&op| (op, counts.n[op as usize], self.get(op)))
            .max_by_key(|&(_, n, cost)| cost.ps() as u128 * n as u128)
            .expect("Op::ALL is not empty");
        format!("{n} x {} at {cost} each", op.name())
    }
}

/// Operation counts to be charged together (one `compute` per batch, not per pixel).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    n: [u64; Op::ALL.len()],
    /// Bit `op` set when `n[op]` is not zero: what pricing walks.
    used: u32,
}

impl Counts {
    pub fn new() -> Counts {
        Counts::default()
    }
    pub fn of(op: Op, n: u64) -> Counts {
        let mut c = Counts::default();
        c.add(op, n);
        c
    }
    pub fn add(&mut self, op: Op, n: u64) -> &mut Counts {
        self.n[op as usize] += n;
        if n > 0 {
            self.used |= 1 << op as usize;
        }
        self
    }
    pub fn get(&self, op: Op) -> u64 {
        self.n[op as usize]
    }
}

impl std::ops::AddAssign<&Counts> for Counts {
    fn add_assign(&mut self, rhs: &Counts) {
        for (a, b) in self.n.iter_mut().zip(rhs.n.iter()) {
            *a += b;
        }
        self.used |= rhs.used;
    }
}

/// A node's processor: operation costs, message overheads, and whether communication runs
/// beside computation (DMA links) or occupies the cpu until the message is delivered.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CpuConfig {
    pub costs: CostTable,
    pub send_overhead: SimTime,
    pub send_per_byte: SimTime,
    pub recv_overhead: SimTime,
    pub recv_per_byte: SimTime,
    /// True: a send costs the cpu only its overhead and the transfer runs beside computation.
    /// False: the sending program stays blocked until the message is delivered.
    pub overlap: bool,
    /// Work is queued on the cpu at most this much at a time (round-robin time slicing).
    pub timeslice: Option<SimTime>,
}

impl CpuConfig {
    pub fn send_cost(&self, bytes: Bytes) -> SimTime {
        // Saturates: the engine refuses a charge of SimTime::MAX by name.
        self.send_overhead
            .saturating_add(self.send_per_byte.times(bytes.get()))
    }
    pub fn recv_cost(&self, bytes: Bytes) -> SimTime {
        self.recv_overhead
            .saturating_add(self.recv_per_byte.times(bytes.get()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for op in Op::ALL {
            assert_eq!(Op::from_name(op.name()), Some(op));
        }
        assert_eq!(Op::from_name("transfrom_vertex"), None);
    }

    #[test]
    fn cost_is_count_times_price() {
        let mut table = CostTable::default();
        table.set(Op::PixelWrite, SimTime::from_ns(50));
        table.set(Op::SetupTriangle, SimTime::from_us(2));
        let mut counts = Counts::of(Op::PixelWrite, 1000);
        counts.add(Op::SetupTriangle, 3).add(Op::Span, 99);
        assert_eq!(table.time(&counts), SimTime::from_us(50 + 6));
    }

    proptest::proptest! {
        /// Pricing over the operations performed gives what pricing every operation of the
        /// table gives, and the unpriced ones are those performed and not priced: counts built
        /// by `add` (zeros included) and by `+=`, tables pricing any subset, costs up to where
        /// a charge saturates.
        #[test]
        fn pricing_what_was_performed_is_pricing_everything(
            priced in proptest::collection::vec(
                proptest::option::of(0u64..1 << 40), Op::ALL.len()),
            first in proptest::collection::vec((0..Op::ALL.len(), 0u64..1 << 30), 0..12),
            second in proptest::collection::vec((0..Op::ALL.len(), 0u64..1 << 30), 0..12),
        ) {
            let mut table = CostTable::default();
            for (op, cost) in Op::ALL.iter().zip(&priced) {
                if let Some(ps) = cost {
                    table.set(*op, SimTime::from_ps(*ps));
                }
            }
            let build = |adds: &[(usize, u64)]| {
                let mut c = Counts::new();
                for &(op, n) in adds {
                    c.add(Op::ALL[op], n);
                }
                c
            };
            let mut counts = build(&first);
            counts += &build(&second);
            let every: u128 = Op::ALL
                .iter()
                .map(|&op| table.get(op).ps() as u128 * counts.get(op) as u128)
                .sum();
            let plain = SimTime::from_ps(u64::try_from(every).unwrap_or(u64::MAX));
            proptest::prop_assert_eq!(table.time(&counts), plain);
            let unpriced: Vec<Op> = Op::ALL
                .iter()
                .copied()
                .filter(|&op| counts.get(op) > 0 && priced[op as usize].is_none())
                .collect();
            proptest::prop_assert_eq!(Op::from_bits(table.unpriced_in(&counts)), unpriced);
        }
    }
}
