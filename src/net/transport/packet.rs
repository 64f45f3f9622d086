//! `packet`: messages cut into packets that queue for links, under store-and-forward or
//! wormhole switching.
//!
//! Owns per-link FIFO queues and the packet timing:
//! - a message of `b` bytes is cut into `ceil(b / packet_size)` packets (the last one
//!   shorter; a 0-byte message is one empty packet);
//! - packet `k` (cumulative bytes `C_k`) occupies a link for `T(C_k) - T(C_{k-1})`, so the
//!   rounding of `Bandwidth::transfer_time` telescopes and a message's packets together take
//!   exactly `T(b)` on every link;
//! - a message offers one packet at a time to its first hop: packet `k+1` joins the first
//!   link's FIFO when packet `k` has taken it, so the messages queued at a link take turns
//!   packet by packet (the packet-grain version of fair sharing) instead of one message
//!   sending all its packets before the next starts;
//! - a hop acquires its links in route order (one link, or on a crossbar the source's output
//!   port then the destination's input port, held while waiting for the second), each from
//!   its FIFO; a link is free again once the packet's last byte has been put on it;
//! - store-and-forward: a packet is transmitted when it has fully arrived and the hop is
//!   free, and is at the next router `T(packet) + L` after its transmission started;
//! - wormhole: the head of a packet is at the next router `L` after it acquired a hop, and
//!   requests the next hop at once; a hop puts the packet's last byte on its links at
//!   `max(head + T(packet), last byte on the hop before + L)` (a faster hop after a slower
//!   one waits for the bytes to come), frees its links then, and the packet is fully at its
//!   destination `L` after its last hop put the last byte on.
//!
//! Hops run at their links' own rate and latency: a node link (several processors of a node
//! on their switch, see `topology::in_nodes`) at the node's, the others at the network's; a
//! hop's occupancy telescopes per rate, so a message's packets take exactly `T(b)` at each
//! rate. With one kind of link the wormhole rule above is `T(packet) + L` after the head took
//! the last hop (the previous hop's last byte is never later), and a lone message arrives
//! exactly at `Timing::contention_free`; with two kinds, under wormhole too (the slower
//! rate's serialization plus every hop's latency). Under store-and-forward with two kinds
//! the formula, which charges every hop but one of the slowest the first packet, is an upper
//! bound: packet by packet, a shorter last packet and faster hops around the slower ones
//! let a lone message arrive earlier (1,025 bytes across 170 MB/s node links and 17 MB/s
//! network links: 272.241 us against the formula's 272.294).
//! Simplification of wormhole, deliberate: while a head waits for a busy link, the rest of
//! its packet keeps draining into the waiting router (a one-packet input buffer), so a worm
//! never holds a link for waiting downstream. With the textbook rule that a blocked worm
//! freezes in place, dimension-order routing on a ring or torus deadlocks without virtual
//! channels; this rule cannot deadlock and keeps link capacity exact.
//!
//! Must never let two packets transmit on one link at once, never reorder a link's FIFO, and
//! never use floating point for time.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};

use super::{Transport, Usage};
use crate::net::timing::{Hops, Timing};
use crate::net::{Delivered, LinkId, MsgId, Switching};
use crate::units::{Bandwidth, Bytes, SimTime};

pub struct Packet {
    timing: Timing,
    /// Rate and latency of a network hop ([`NETWORK`]) and of a node hop ([`NODE`]).
    kinds: [(Bandwidth, SimTime); 2],
    /// `node_link[l]`: link `l` is a node link, a hop of its own at the node's rate and
    /// latency (empty when the network has none).
    node_link: Vec<bool>,
    /// Links a network hop acquires together (the topology's).
    links_per_hop: u32,
    seq: u64,
    events: BinaryHeap<Reverse<(SimTime, u64, Event)>>,
    messages: Vec<MessageState>,
    free_messages: Vec<u32>,
    packets: Vec<PacketState>,
    free_packets: Vec<u32>,
    links: Vec<LinkQueue>,
    /// Messages whose next packet may now be offered to their first hop.
    offers: Vec<u32>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Event {
    /// The packet's head (store-and-forward: the whole packet) reached the router at the
    /// start of its next hop, or its destination.
    Arrive(u32),
    /// The link may be free: hand it to the first waiting packet.
    LinkFree(LinkId),
}

/// Index of a hop kind in [`Packet::kinds`] and in the per-kind times below.
const NETWORK: usize = 0;
const NODE: usize = 1;

struct MessageState {
    msg: MsgId,
    route: Vec<LinkId>,
    packets_left: u64,
    bytes: Bytes,
    /// 1-based index of the next packet to offer; `> count` once all are in the network.
    next_packet: u64,
    count: u64,
    /// `T(C_{k-1})` for the next packet `k`, at each kind's rate.
    sent_before: [SimTime; 2],
}

#[derive(Clone, Copy)]
struct PacketState {
    message: u32,
    /// Occupancy of a hop of each kind: `T(C_k) - T(C_{k-1})` at its rate.
    transmit: [SimTime; 2],
    /// Index in the route of the current hop's first link.
    at: u32,
    /// How many links of the current hop the packet already holds.
    held: u32,
    /// When the packet's last byte is at the router of its current hop (wormhole: its head
    /// may be there earlier).
    tail_here: SimTime,
}

struct LinkQueue {
    /// Free from this instant on; `SimTime::MAX` while held by a packet that still waits for
    /// the other link of its hop.
    busy_until: SimTime,
    waiting: VecDeque<u32>,
    free_event_pending: bool,
    busy: SimTime,
    peak: u32,
}

impl Packet {
    /// The level for `links` links, a network hop taking `links_per_hop` of them;
    /// `node_link` as in `transport::build`.
    pub fn new(timing: Timing, links: usize, links_per_hop: u32, node_link: &[bool]) -> Packet {
        let network = (timing.bandwidth, timing.hop_latency);
        let node = timing
            .node_links
            .map_or(network, |n| (n.bandwidth, n.hop_latency));
        Packet {
            timing,
            kinds: [network, node],
            node_link: node_link.to_vec(),
            links_per_hop,
            seq: 0,
            events: BinaryHeap::new(),
            messages: Vec::new(),
            free_messages: Vec::new(),
            packets: Vec::new(),
            free_packets: Vec::new(),
            links: (0..links)
                .map(|_| LinkQueue {
                    busy_until: SimTime::ZERO,
                    waiting: VecDeque::new(),
                    free_event_pending: false,
                    busy: SimTime::ZERO,
                    peak: 0,
                })
                .collect(),
            offers: Vec::new(),
        }
    }

    fn schedule(&mut self, at: SimTime, event: Event) {
        self.seq += 1;
        self.events.push(Reverse((at, self.seq, event)));
    }

    /// The kind of the hop starting at `link`, and how many links it acquires.
    fn hop_of(&self, link: LinkId) -> (usize, u32) {
        match self.node_link.get(link as usize) {
            Some(true) => (NODE, 1),
            _ => (NETWORK, self.links_per_hop),
        }
    }

    fn new_message(&mut self, msg: MsgId, route: &[LinkId], bytes: Bytes) -> u32 {
        let count = self.timing.packet_count(bytes);
        let state = MessageState {
            msg,
            route: route.to_vec(),
            packets_left: count,
            bytes,
            next_packet: 1,
            count,
            sent_before: [SimTime::ZERO; 2],
        };
        match self.free_messages.pop() {
            Some(slot) => {
                self.messages[slot as usize] = state;
                slot
            }
            None => {
                self.messages.push(state);
                (self.messages.len() - 1) as u32
            }
        }
    }

    fn new_packet(&mut self, message: u32, transmit: [SimTime; 2]) -> u32 {
        let state = PacketState {
            message,
            transmit,
            at: 0,
            held: 0,
            tail_here: SimTime::ZERO,
        };
        match self.free_packets.pop() {
            Some(slot) => {
                self.packets[slot as usize] = state;
                slot
            }
            None => {
                self.packets.push(state);
                (self.packets.len() - 1) as u32
            }
        }
    }

    /// Puts the message's next packet (if any) at its first hop. Its occupancy telescopes
    /// at each kind's rate: `T(C_k) - T(C_{k-1})`, so a message's packets take exactly
    /// `T(b)` on a hop of either kind.
    fn offer_next_packet(&mut self, now: SimTime, message: u32) {
        let size = self.timing.packet_size.get();
        let kinds = if self.node_link.is_empty() { 1 } else { 2 };
        let m = &mut self.messages[message as usize];
        if m.next_packet > m.count {
            return;
        }
        let cumulative = Bytes::new((m.next_packet * size).min(m.bytes.get()));
        let mut transmit = [SimTime::ZERO; 2];
        let per_kind = transmit.iter_mut().zip(&mut m.sent_before).zip(&self.kinds);
        for ((transmit, before), (rate, _)) in per_kind.take(kinds) {
            let sent = rate.transfer_time(cumulative);
            *transmit = sent - *before;
            *before = sent;
        }
        m.next_packet += 1;
        let pkt = self.new_packet(message, transmit);
        self.request(now, pkt);
    }

    /// Offers packets until no message has one ready (iterative: a packet that takes a free
    /// link at once lets the next one be offered, without recursion).
    fn drain_offers(&mut self, now: SimTime) {
        while let Some(message) = self.offers.pop() {
            self.offer_next_packet(now, message);
        }
    }

    /// The link the packet must acquire next, and whether it is the last of its hop.
    fn wanted_link(&self, pkt: u32) -> (LinkId, bool) {
        let p = &self.packets[pkt as usize];
        let route = &self.messages[p.message as usize].route;
        let (_, links) = self.hop_of(route[p.at as usize]);
        (route[(p.at + p.held) as usize], p.held + 1 == links)
    }

    /// The packet is at a router wanting its current hop: take its links, or queue.
    fn request(&mut self, now: SimTime, pkt: u32) {
        loop {
            let (link, last) = self.wanted_link(pkt);
            let q = &mut self.links[link as usize];
            if !q.waiting.is_empty() || q.busy_until > now {
                q.waiting.push_back(pkt);
                q.peak = q.peak.max(q.waiting.len() as u32);
                self.ensure_free_event(link);
                return;
            }
            self.take(now, pkt, link);
            if last {
                self.start_hop(now, pkt);
                return;
            }
        }
    }

    fn take(&mut self, now: SimTime, pkt: u32, link: LinkId) {
        let q = &mut self.links[link as usize];
        debug_assert!(q.busy_until <= now, "two packets on one link");
        q.busy_until = SimTime::MAX;
        self.packets[pkt as usize].held += 1;
    }

    /// Every link of the hop is held: occupy them until the packet's last byte is on them
    /// and schedule its arrival at the next router.
    fn start_hop(&mut self, now: SimTime, pkt: u32) {
        let p = self.packets[pkt as usize];
        let m = &self.messages[p.message as usize];
        let (kind, links) = self.hop_of(m.route[p.at as usize]);
        let hop_links = p.at as usize..(p.at + links) as usize;
        let last_hop = hop_links.end == m.route.len();
        if p.at == 0 {
            self.offers.push(p.message);
        }
        let latency = self.kinds[kind].1;
        let free_at = (now + p.transmit[kind]).max(p.tail_here);
        for i in hop_links {
            let link = self.messages[p.message as usize].route[i];
            let q = &mut self.links[link as usize];
            q.busy_until = free_at;
            q.busy += free_at - now;
            self.ensure_free_event(link);
        }
        self.packets[pkt as usize].tail_here = free_at + latency;
        let next_router = match self.timing.switching {
            Switching::Wormhole if !last_hop => now + latency,
            _ => free_at + latency,
        };
        self.schedule(next_router, Event::Arrive(pkt));
    }

    fn ensure_free_event(&mut self, link: LinkId) {
        let q = &mut self.links[link as usize];
        if q.waiting.is_empty() || q.free_event_pending || q.busy_until == SimTime::MAX {
            return;
        }
        q.free_event_pending = true;
        let at = q.busy_until;
        self.schedule(at, Event::LinkFree(link));
    }

    fn on_link_free(&mut self, now: SimTime, link: LinkId) {
        let q = &mut self.links[link as usize];
        q.free_event_pending = false;
        if q.busy_until > now {
            self.ensure_free_event(link);
            return;
        }
        let Some(pkt) = q.waiting.pop_front() else {
            return;
        };
        let (_, last) = self.wanted_link(pkt);
        self.take(now, pkt, link);
        if last {
            self.start_hop(now, pkt);
        } else {
            self.request(now, pkt);
        }
        self.ensure_free_event(link);
    }

    fn on_arrive(&mut self, now: SimTime, pkt: u32, delivered: &mut Vec<Delivered>) {
        let p = &mut self.packets[pkt as usize];
        p.at += p.held;
        p.held = 0;
        let (message, at) = (p.message, p.at);
        if (at as usize) < self.messages[message as usize].route.len() {
            self.request(now, pkt);
            return;
        }
        self.free_packets.push(pkt);
        let m = &mut self.messages[message as usize];
        m.packets_left -= 1;
        if m.packets_left == 0 {
            delivered.push(Delivered {
                msg: m.msg,
                at: now,
            });
            self.free_messages.push(message);
        }
    }
}

impl Transport for Packet {
    fn inject(
        &mut self,
        now: SimTime,
        msg: MsgId,
        route: &[LinkId],
        _hops: Hops,
        bytes: Bytes,
    ) -> Option<SimTime> {
        // The route says its hops: a node link is one, the network's take `links_per_hop`.
        let message = self.new_message(msg, route, bytes);
        self.offer_next_packet(now, message);
        self.drain_offers(now);
        None
    }

    fn next_event_time(&self) -> Option<SimTime> {
        self.events.peek().map(|Reverse(e)| e.0)
    }

    fn advance(&mut self, now: SimTime, delivered: &mut Vec<Delivered>) {
        while let Some(&Reverse((at, _, event))) = self.events.peek() {
            if at > now {
                break;
            }
            self.events.pop();
            match event {
                Event::Arrive(pkt) => self.on_arrive(at, pkt, delivered),
                Event::LinkFree(link) => self.on_link_free(at, link),
            }
            self.drain_offers(at);
        }
    }

    fn usage(&self, link: LinkId) -> Usage {
        let q = &self.links[link as usize];
        Usage {
            busy: q.busy,
            peak_queue: q.peak,
        }
    }
}
