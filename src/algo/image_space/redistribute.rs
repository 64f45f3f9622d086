//! Redistribution of screen triangles to the processors that rasterize the regions they touch:
//! classification by region, fixed-size buffers per destination, and two-step forwarding
//! through one processor per group (paper 002).
//!
//! A processor's streams: in one-step mode one stream to every other processor; in two-step
//! mode one first-step stream to its forwarder in every other group and one stream to every
//! member of its own group, which carries both its own polygons and those it forwards. The
//! last message of every stream carries the stream's length, so a receiver knows when it has
//! everything even if the network reorders messages of one pair.
//!
//! Owns buffering and forwarding. Must never rasterize, and never hold the shared state
//! borrowed across an `.await`.

use std::cell::RefCell;
use std::rc::Rc;

use super::assign::Assignment;
use super::buffers::{message_bytes, Buffers, ROUTED_TRIANGLE_BYTES, TRIANGLE_BYTES};
use super::two_step::Groups;
use super::{Ctx, Msg, TAG_FORWARD};
use crate::engine::{Filter, Node, SimError};
use crate::machine::{Counts, Op};
use crate::raster::ScreenTriangle;

/// An outgoing message: destination and payload (sizes follow from the payload).
pub(crate) type Outgoing = (u32, Msg);

/// One processor's redistribution state for one frame.
pub(crate) struct Redistributor {
    me: u32,
    processors: u32,
    frame: u32,
    assignment: Rc<Assignment>,
    groups: Option<Groups>,
    /// Per destination processor (one-step: every processor; two-step: own group members).
    direct: Buffers<ScreenTriangle>,
    /// Per group, two-step only: triangles with their final destination, for the forwarder.
    first_step: Option<Buffers<(u32, ScreenTriangle)>>,
    /// Messages sent so far per direct destination and per group (first step).
    sent_direct: Vec<u32>,
    sent_first: Vec<u32>,
    /// Triangles for this processor's own regions.
    pub local: Vec<ScreenTriangle>,
    /// Per-region triangle counts (the load-balancing input).
    pub counts: Vec<u32>,
    /// Conditions left before the direct streams may end: own transformation, and in
    /// two-step mode the forwarding for other groups.
    pending: u32,
    regions: Vec<u32>,
    owners: Vec<u32>,
}

impl Redistributor {
    pub fn new(ctx: &Ctx, me: u32, frame: u32, assignment: Rc<Assignment>) -> Redistributor {
        let n = ctx.n as usize;
        let groups = ctx.settings.groups.clone();
        let forwarding = groups.as_ref().is_some_and(|g| g.forwarded_sources(me) > 0);
        debug_assert!(groups
            .as_ref()
            .is_none_or(|g| g.members(g.group_of(me)).contains(&me)));
        Redistributor {
            me,
            processors: ctx.n,
            frame,
            assignment,
            direct: Buffers::new(n, ctx.settings.buffer, TRIANGLE_BYTES),
            first_step: groups.as_ref().map(|g| {
                Buffers::new(
                    g.count() as usize,
                    ctx.settings.buffer,
                    ROUTED_TRIANGLE_BYTES,
                )
            }),
            sent_direct: vec![0; n],
            sent_first: vec![0; groups.as_ref().map_or(0, |g| g.count() as usize)],
            groups,
            local: Vec::new(),
            counts: vec![0; ctx.settings.grid.count() as usize],
            pending: 1 + forwarding as u32,
            regions: Vec::new(),
            owners: Vec::new(),
        }
    }

    /// Classifies `tris` by region and destination, adding the classification and copying
    /// work to `charge`; returns the buffers that filled up.
    pub fn place(
        &mut self,
        ctx: &Ctx,
        tris: &[ScreenTriangle],
        charge: &mut Counts,
    ) -> Vec<Outgoing> {
        let mut out = Vec::new();
        let mut copied = 0u64;
        for tri in tris {
            self.regions.clear();
            ctx.settings.grid.touched_by(tri, &mut self.regions);
            charge.add(Op::RegionCount, self.regions.len() as u64);
            self.owners.clear();
            for &r in &self.regions {
                self.counts[r as usize] += 1;
                self.owners.push(self.assignment.owner[r as usize]);
            }
            self.owners.sort_unstable();
            self.owners.dedup();
            for i in 0..self.owners.len() {
                let dst = self.owners[i];
                copied += self.route(dst, *tri, &mut out);
            }
        }
        charge.add(Op::ByteCopy, copied);
        out
    }

    /// Puts one triangle on its way to `dst`; returns the bytes copied.
    fn route(&mut self, dst: u32, tri: ScreenTriangle, out: &mut Vec<Outgoing>) -> u64 {
        if dst == self.me {
            self.local.push(tri);
            return 0;
        }
        let frame = self.frame;
        match (&self.groups, &mut self.first_step) {
            (Some(groups), Some(first)) if groups.group_of(dst) != groups.group_of(self.me) => {
                let group = groups.group_of(dst);
                if let Some(tris) = first.push(group as usize, (dst, tri)) {
                    self.sent_first[group as usize] += 1;
                    out.push((
                        groups.forwarder(self.me, group),
                        Msg::Forward {
                            frame,
                            tris,
                            end: None,
                        },
                    ));
                }
                ROUTED_TRIANGLE_BYTES
            }
            _ => {
                self.push_direct(dst, tri, out);
                TRIANGLE_BYTES
            }
        }
    }

    /// Adds a triangle to the direct stream to `dst`, sending the buffer when full.
    fn push_direct(&mut self, dst: u32, tri: ScreenTriangle, out: &mut Vec<Outgoing>) {
        if let Some(tris) = self.direct.push(dst as usize, tri) {
            self.sent_direct[dst as usize] += 1;
            out.push((
                dst,
                Msg::Polygons {
                    frame: self.frame,
                    tris,
                    end: None,
                },
            ));
        }
    }

    /// Ends the first-step streams (two-step) after the own transformation, and the direct
    /// streams once nothing more can enter them.
    pub fn own_transform_done(&mut self) -> Vec<Outgoing> {
        let mut out = Vec::new();
        if let (Some(groups), Some(first)) = (&self.groups, &mut self.first_step) {
            let mine = groups.group_of(self.me);
            for group in (0..groups.count()).filter(|&k| k != mine) {
                let tris = first.take(group as usize);
                let end = Some(self.sent_first[group as usize] + 1);
                out.push((
                    groups.forwarder(self.me, group),
                    Msg::Forward {
                        frame: self.frame,
                        tris,
                        end,
                    },
                ));
            }
        }
        let direct = self.condition_met();
        if out.is_empty() {
            // One-step: the direct streams' ends are all there is (a copy of a message to
            // every processor saved).
            return direct;
        }
        out.extend(direct);
        out
    }

    /// Another condition for ending the direct streams is met; when none is left, flush.
    fn condition_met(&mut self) -> Vec<Outgoing> {
        self.pending -= 1;
        if self.pending > 0 {
            return Vec::new();
        }
        let (me, frame) = (self.me, self.frame);
        self.direct_destinations()
            .filter(|&d| d != me)
            .map(|d| {
                let end = Some(self.sent_direct[d as usize] + 1);
                (
                    d,
                    Msg::Polygons {
                        frame,
                        tris: self.direct.take(d as usize),
                        end,
                    },
                )
            })
            .collect()
    }

    fn direct_destinations(&self) -> std::ops::Range<u32> {
        match &self.groups {
            Some(g) => g.members(g.group_of(self.me)),
            None => 0..self.processors,
        }
    }

    /// Whether this processor forwards first-step polygons for other groups.
    pub fn forwards(&self) -> bool {
        self.groups
            .as_ref()
            .is_some_and(|g| g.forwarded_sources(self.me) > 0)
    }

    /// How many `last` polygon messages this processor's rasterizer must wait for.
    pub fn expected_streams(&self) -> u32 {
        let others = self.direct_destinations().len() as u32 - 1;
        others + self.forwards() as u32
    }
}

/// Sends messages in order, tallying them in the frame record.
pub(crate) async fn send_all(node: &Node<Msg>, ctx: &Ctx, out: Vec<Outgoing>) {
    for (dst, msg) in out {
        let bytes = msg.bytes();
        ctx.count_message(msg.frame(), bytes);
        node.send(dst, bytes, msg).await;
    }
}

/// The forwarding handler of two-step redistribution: copies first-step polygons into the
/// buffers for this group's members until every source that uses this processor has sent
/// its last message. Polygons for this processor itself are posted to its own rasterizer.
pub(crate) async fn forward(
    node: Node<Msg>,
    ctx: Rc<Ctx>,
    state: Rc<RefCell<Redistributor>>,
) -> Result<(), SimError> {
    let me = node.id();
    let (frame, sources) = {
        let s = state.borrow();
        (
            s.frame,
            s.groups.as_ref().map_or(0, |g| g.forwarded_sources(me)),
        )
    };
    let mut for_me = Vec::new();
    let mut arrivals = Streams::new(ctx.n);
    while arrivals.ended() < sources {
        let env = node.recv(Filter::tag(TAG_FORWARD)).await;
        let Msg::Forward {
            frame: f,
            tris,
            end,
        } = env.payload
        else {
            unreachable!("filtered by tag")
        };
        debug_assert_eq!(f, frame, "a first-step message crossed a frame boundary");
        let mut out = Vec::new();
        {
            let mut s = state.borrow_mut();
            for (dst, tri) in tris.iter().copied() {
                if dst == me {
                    for_me.push(tri);
                } else {
                    s.push_direct(dst, tri, &mut out);
                }
            }
        }
        node.compute(&Counts::of(
            Op::ByteCopy,
            tris.len() as u64 * TRIANGLE_BYTES,
        ))
        .await;
        send_all(&node, &ctx, out).await;
        arrivals.arrived(env.src, end);
    }
    node.post(
        me,
        crate::units::SimTime::ZERO,
        Msg::Polygons {
            frame,
            tris: for_me,
            end: Some(1),
        },
    );
    let out = state.borrow_mut().condition_met();
    send_all(&node, &ctx, out).await;
    Ok(())
}

/// Counts the messages of incoming streams until each has delivered as many messages as its
/// last one announced.
pub(crate) struct Streams {
    /// Per sender (indexed by node id): messages seen, and the stream's length once known.
    /// A vector, not a map: a processor of a 512-node frame counts hundreds of thousands of
    /// arrivals.
    seen: Vec<(u32, Option<u32>)>,
    ended: u32,
}

impl Streams {
    /// Streams from any of `senders` nodes.
    pub fn new(senders: u32) -> Streams {
        Streams {
            seen: vec![(0, None); senders as usize],
            ended: 0,
        }
    }

    pub fn arrived(&mut self, src: u32, end: Option<u32>) {
        let (seen, total) = &mut self.seen[src as usize];
        *seen += 1;
        if end.is_some() {
            *total = end;
        }
        if *total == Some(*seen) {
            self.ended += 1;
        }
    }

    pub fn ended(&self) -> u32 {
        self.ended
    }
}

/// The size of a polygon-carrying message.
pub(crate) fn polygon_bytes(msg: &Msg) -> crate::units::Bytes {
    match msg {
        Msg::Polygons { tris, .. } => message_bytes(tris.len(), TRIANGLE_BYTES),
        Msg::Forward { tris, .. } => message_bytes(tris.len(), ROUTED_TRIANGLE_BYTES),
        _ => unreachable!("not a polygon message"),
    }
}
