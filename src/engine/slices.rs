//! Long computations on a time-sliced cpu: while no other program reserves the node's cpu,
//! the executor reserves the slices itself, as many at once as end before anything else is
//! due, instead of waking the program at the end of each.
//!
//! On a cpu with a timeslice a computation is queued a slice at a time: the program wakes as
//! each slice ends, reserves the next one behind whatever other programs queued meanwhile,
//! and waits again. With no other program on the node that is a wake-up and a poll per slice
//! for nothing (a second of work on 2,048 us slices is 489 of them). Here a computation with
//! more than one slice left becomes a *chain*: its wake-up is queued as a slice event, and
//! when the executor takes it, it reserves the next slice itself, exactly as the program
//! would have (same charge, same phase, same timeline span), and then every slice that would
//! end before anything else is due, since nothing can come between them; it queues one slice
//! event for the end of the last, where the program would have queued its wake-up. The
//! program wakes only for its last slice. If another program reserves the node's cpu while
//! the chain runs, the chain ends there: its slice event wakes the program, which goes on
//! slice by slice as before. So every slice starts, ends and is counted where the plain way
//! has it, and the events around it keep their order (the tests compare the two).
//!
//! Chains on several nodes interleave: each one's next end comes before the others' ends
//! of the slice after, so one alone takes a step a slice. When the queue holds nothing but
//! the chains' slice events, the executor takes whole rounds of all of them at once
//! (`State::chains_in_rounds`): the ends of a round come in the same order every round, and
//! each reserves on its own node only.
//!
//! Owns which computations are chains; must never poll a program or reserve a cpu itself.

use super::executor::ProgramId;
use crate::net::NodeId;
use crate::units::SimTime;

/// A computation whose slices the executor reserves for its program.
#[derive(Clone, Copy, Debug)]
pub(super) struct Chain {
    pub program: ProgramId,
    /// Work not reserved yet (more than zero while the chain runs).
    pub left: SimTime,
    /// Where its slice event is queued: the end of the slice reserved last.
    pub at: SimTime,
}

#[derive(Default)]
pub(super) struct Slices {
    /// Each node's chain: one at most, since a chain ends when another program reserves the
    /// node's cpu, and only a reservation starts one.
    by_node: Vec<Option<Chain>>,
    /// How many chains run: a reservation looks at its node's only when some do.
    running: usize,
    /// Programs whose chain ended, with the work left to reserve when they wake: read by the
    /// program then.
    resumed: Vec<(ProgramId, SimTime)>,
}

impl Slices {
    pub fn new(nodes: usize) -> Slices {
        Slices {
            by_node: vec![None; nodes],
            ..Slices::default()
        }
    }

    /// Starts a chain on `node` for `program`, with `left` work to reserve after the slice
    /// whose end, `at`, its slice event is queued at.
    pub fn start(&mut self, node: NodeId, program: ProgramId, left: SimTime, at: SimTime) {
        debug_assert!(left > SimTime::ZERO, "a chain has work left");
        debug_assert!(self.by_node[node as usize].is_none(), "one chain a node");
        self.by_node[node as usize] = Some(Chain { program, left, at });
        self.running += 1;
    }

    /// How many chains run.
    pub fn running(&self) -> usize {
        self.running
    }

    /// The chains that run.
    pub fn chains(&self) -> impl Iterator<Item = &Chain> {
        self.by_node.iter().flatten()
    }

    /// Takes `program`'s chain on `node` at its slice event, to go on (and be started again)
    /// or end; `None` if it has ended, and the event wakes the program.
    pub fn take(&mut self, node: NodeId, program: ProgramId) -> Option<Chain> {
        let slot = &mut self.by_node[node as usize];
        let chain = slot.take_if(|c| c.program == program)?;
        self.running -= 1;
        Some(chain)
    }

    /// Ends `node`'s chain, if it has one, because another reservation is made on its cpu:
    /// its slice event wakes its program, which reserves its next slice there itself.
    #[inline]
    pub fn end_on(&mut self, node: NodeId) {
        if self.running == 0 {
            return;
        }
        if let Some(chain) = self.by_node[node as usize].take() {
            self.running -= 1;
            self.resume_with(chain.program, chain.left);
        }
    }

    /// Notes that `program` wakes with `left` work still to reserve.
    pub fn resume_with(&mut self, program: ProgramId, left: SimTime) {
        self.resumed.push((program, left));
    }

    /// The work `program`, woken after its chain ended, has left to reserve; `None` while its
    /// chain runs.
    pub fn resume(&mut self, program: ProgramId) -> Option<SimTime> {
        let i = self.resumed.iter().position(|&(p, _)| p == program)?;
        Some(self.resumed.swap_remove(i).1)
    }
}
